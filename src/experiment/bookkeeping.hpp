#pragma once
// The bookkeeping every experiment does around its runs (private to the experiment layer): its
// options checked and kept, its scenario's generator options, a run's wall time, each finished
// run reported on the progress stream and kept, and the runs done on several threads.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <mutex>
#include <optional>
#include <ostream>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

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

/// A finished run reported on `progress` (when given) as
/// "  <scenario> n=<n> <label>: <count> <what>, <seconds> s".
inline void report_run(std::ostream* progress, const std::string& scenario, std::size_t n,
                       const std::string& label, std::uint64_t count, const char* what,
                       double seconds) {
  if (!progress) return;
  *progress << "  " << scenario << " n=" << n << " " << label << ": " << count << " " << what
            << ", " << seconds << " s\n";
  progress->flush();
}

/// Moves a finished run into `experiment.runs`, first reported (report_run).
template <class Experiment, class Run>
void keep_run(Experiment& experiment, Run& r, std::ostream* progress, const std::string& scenario,
              std::size_t n, const std::string& label, std::uint64_t count, const char* what) {
  report_run(progress, scenario, n, label, count, what, r.seconds);
  experiment.runs.push_back(std::move(r));
}

/// Runs job(i) for every i in [0, count) on `workers` threads (at most one per job; 1: one
/// after the other on this thread) and returns the results in the order of i, whatever the order
/// they finished in: each run is independent and deterministic, so the results are those of the
/// sequential runs. `done(result)` is called as each finishes, one at a time (progress).
/// The first exception a job throws is rethrown once every thread has stopped.
template <class Run, class Job, class Done>
std::vector<Run> run_jobs(std::size_t count, unsigned workers, Job&& job, Done&& done) {
  std::vector<std::optional<Run>> out(count);
  if (workers <= 1 || count <= 1) {
    for (std::size_t i = 0; i < count; ++i) {
      out[i] = job(i);
      done(*out[i]);
    }
  } else {
    std::atomic<std::size_t> next{0};
    std::mutex lock;
    std::exception_ptr error;
    const auto work = [&] {
      for (std::size_t i = next++; i < count; i = next++) {
        try {
          Run r = job(i);
          const std::lock_guard<std::mutex> hold(lock);
          out[i] = std::move(r);
          done(*out[i]);
        } catch (...) {
          const std::lock_guard<std::mutex> hold(lock);
          if (!error) error = std::current_exception();
          next = count;
          return;
        }
      }
    };
    std::vector<std::thread> threads;
    const std::size_t n = std::min<std::size_t>(workers, count);
    for (std::size_t w = 0; w < n; ++w) threads.emplace_back(work);
    for (std::thread& t : threads) t.join();
    if (error) std::rethrow_exception(error);
  }
  std::vector<Run> runs;
  runs.reserve(count);
  for (std::optional<Run>& r : out) runs.push_back(std::move(*r));
  return runs;
}

}  // namespace kinetic::experiment::detail
