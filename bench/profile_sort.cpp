// One kinetic sorting run for instruction-count profiling (docs/performance/robust-vs-classic.md):
// the inputs of bench_sort's robust-vs-classic comparison, one KineticSort over the whole window
// with one scheduler, no repetitions and no timing, so that a run under `valgrind --tool=callgrind`
// takes seconds. Usage:
//
//   profile_sort <linear|quadratic|grids|parabola> <classic|robust|exact> [n]
//
// n defaults to 1000 (linear, quadratic) and 900 (grids, parabola). The inputs are bench_sort's:
// random-linear over [0, 30], random-poly of degree 2 over [0, 7.5] (seed 1), GRIDS and PARABOLA
// in their own windows; eps = 1e-9, objects valid from the window's start. Prints the counters
// and the exact audit of the final order.

#include <cstdio>
#include <cstdlib>
#include <span>
#include <string>

#include "harness.hpp"
#include "kinetic/core/counters.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/polynomial.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/scenario/generators.hpp"
#include "kinetic/sort/kinetic_sort.hpp"

using kinetic::bench::out;

int main(int argc, char** argv) {
  std::string input = "linear", scheduler_name = "robust";
  std::size_t n = 0;
  kinetic::bench::Harness harness("profile_sort",
                                  "one kinetic sorting run to profile (perf record, callgrind)");
  harness.positional("input", input, "linear, quadratic, grids or parabola", true);
  harness.positional("scheduler", scheduler_name, "classic, robust or exact", true);
  harness.positional("n", n, "points (0: 900 for grids and parabola, 1000 otherwise)", false);
  harness.parse(argc, argv);
  const bool paper = input == "grids" || input == "parabola";
  if (!(input == "linear" || input == "quadratic" || paper) ||
      !(scheduler_name == "classic" || scheduler_name == "robust" || scheduler_name == "exact")) {
    std::fprintf(stderr, "profile_sort: unknown input or scheduler (--help lists them)\n");
    return 2;
  }
  if (n == 0) n = paper ? 900 : 1000;
  harness.configured();

  kinetic::scenario::GeneratorOptions options;
  options.n = n;
  options.seed = 1;
  options.dimension = 1;
  options.degree = 2;
  if (input == "quadratic") {
    options.start_time = 0.0;
    options.end_time = 7.5;
  }
  const std::string dataset = input == "linear"      ? "random-linear"
                              : input == "quadratic" ? "random-poly"
                                                     : input;
  const kinetic::scenario::Scenario s = kinetic::scenario::generate(dataset, options);
  kinetic::Time start = s.start_time;
  kinetic::Time end = s.end_time.value_or(s.start_time);
  if (input == "linear") {
    start = 0.0;
    end = 30.0;
  }

  kinetic::MotionTable motions(1);
  for (const auto& object : s.objects) {
    const kinetic::MotionPolynomial p =
        kinetic::MotionPolynomial::from(object.motion.coordinates.at(0), object.motion.origin);
    motions.insert(object.id, std::span(&p, 1), start);
  }
  kinetic::Simulator sim(start);
  const kinetic::Scheduler scheduler(scheduler_name == "robust"  ? kinetic::SchedulerKind::Robust
                                     : scheduler_name == "exact" ? kinetic::SchedulerKind::Exact
                                                                 : kinetic::SchedulerKind::Classic,
                                     1e-9, end);
  kinetic::KineticSort sort(motions, sim, scheduler, 0);
  sort.initialize();
  const kinetic::AdvanceOutcome outcome = sim.advance_to(end, sort);
  const kinetic::Counters& c = sim.counters();
  const bool audit = sort.audit(end).ok;
  out("%s %s n=%zu window=[%g, %g]: events %llu, failure-time computations %llu (CROP fast path "
      "%llu), exact fallbacks %llu, events in the past %llu, audit %s\n",
      input.c_str(), scheduler_name.c_str(), n, start, end,
      static_cast<unsigned long long>(c.events()),
      static_cast<unsigned long long>(c.root_isolation_calls),
      static_cast<unsigned long long>(c.crop.fast_path),
      static_cast<unsigned long long>(c.exact_fallbacks()),
      static_cast<unsigned long long>(c.events_in_past), audit ? "ok" : "FAILED");
  return outcome == kinetic::AdvanceOutcome::Reached && audit ? 0 : 1;
}
