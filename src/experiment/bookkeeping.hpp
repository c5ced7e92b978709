#pragma once
// The bookkeeping every experiment does around its runs (private to the experiment layer): its
// options checked and kept, its scenario's generator options, a run's wall time, and each
// finished run reported on the progress stream and kept.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <ostream>
#include <stdexcept>
#include <string>
#include <utility>

#include "kinetic/core/scheduler.hpp"
#include "kinetic/scenario/generators.hpp"
#include "kinetic/scenario/scenario.hpp"

namespace kinetic::experiment::detail {

/// An experiment with its options, checked first (the experiment's check_options(), which throws
/// PreconditionError).
template <class Experiment, class Options>
Experiment checked_experiment(const Options& options) {
  check_options(options);
  Experiment e;
  e.options = options;
  return e;
}

/// The generator options of an experiment's scenario: its n and seed, the rest as generated.
template <class Options>
scenario::GeneratorOptions generator_options(const Options& options) {
  scenario::GeneratorOptions g;
  g.n = options.n;
  g.seed = options.seed;
  return g;
}

/// A run of `scheduler` (eps: the robust one's precision) over the points of `s`, generated as
/// `dataset`, in s's window. Throws std::invalid_argument, naming the experiment, unless s is 1-D
/// points with an end time.
template <class Run>
Run line_run(const scenario::Scenario& s, const std::string& dataset, SchedulerKind scheduler,
             double eps, const char* experiment) {
  if (s.dimension != 1 || s.objects_are != scenario::ObjectsAre::Points || !s.end_time) {
    throw std::invalid_argument(std::string("the ")
                                    .append(experiment)
                                    .append(" experiment needs 1-D points and an end_time"));
  }
  Run r;
  r.dataset = dataset;
  r.n = s.objects.size();
  r.scheduler = scheduler;
  r.eps = scheduler == SchedulerKind::Robust ? eps : 0.0;
  r.start = s.start_time;
  r.end = *s.end_time;
  return r;
}

/// Wall-clock seconds since `start`.
inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// Moves a finished run into `experiment.runs`, first reported on `progress` (when given) as
/// "  <scenario> n=<n> <label>: <count> <what>, <seconds> s".
template <class Experiment, class Run>
void keep_run(Experiment& experiment, Run& r, std::ostream* progress, const std::string& scenario,
              std::size_t n, const std::string& label, std::uint64_t count, const char* what) {
  if (progress) {
    *progress << "  " << scenario << " n=" << n << " " << label << ": " << count << " " << what
              << ", " << r.seconds << " s\n";
    progress->flush();
  }
  experiment.runs.push_back(std::move(r));
}

}  // namespace kinetic::experiment::detail
