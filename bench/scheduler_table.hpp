#pragma once
// The three schedulers side by side on one structure: the same motions run under classic,
// robust (eps) and exact, each cut at a CPU budget; events per
// second, the cost per event against robust measured in the same run, and validate() at the end.
// Every structure's bench prints this table (docs/scheduling.md, "The three schedulers").

#include <algorithm>
#include <cstdint>
#include <cstdio>

#include "harness.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"

namespace kinetic::bench {

struct SchedulerRun {
  SchedulerKind kind = SchedulerKind::Robust;
  std::uint64_t events = 0, equal_time_groups = 0;
  /// Exact: decisions and close comparisons, and how many of them reached GMP.
  std::uint64_t decisions = 0, decisions_gmp = 0, comparisons = 0, comparisons_gmp = 0;
  double cpu = 0.0;      ///< seconds advancing (initialize() not included)
  double reached = 0.0;  ///< simulated time reached
  bool completed = true, valid = true;
};

/// One run of structure S (constructed from a copy of `motions`, its simulator, the scheduler
/// and `extra...`) over [start, end], in 64 slices, stopped after the slice that exceeds
/// `budget` CPU seconds.
template <class S, class... Extra>
SchedulerRun run_scheduler(const MotionTable& motions, double start, double end, SchedulerKind kind,
                           double eps, double budget, const Extra&... extra) {
  MotionTable table = motions;
  Simulator sim(start);
  const Scheduler scheduler(kind, eps, end);
  S structure(table, sim, scheduler, extra...);
  structure.initialize();
  SchedulerRun r;
  r.kind = kind;
  constexpr int kSlices = 64;
  const double c0 = cpu_now();
  for (int k = 1; k <= kSlices; ++k) {
    const double t = k == kSlices ? end : start + (end - start) * k / kSlices;
    (void)sim.advance_to(t, structure);
    r.reached = t;
    if (k < kSlices && cpu_now() - c0 > budget) {
      r.completed = false;
      break;
    }
  }
  r.cpu = cpu_now() - c0;
  r.events = sim.counters().events();  // internal and external (KDS terms)
  r.equal_time_groups = sim.counters().equal_time_groups;
  r.decisions = sim.counters().exact_decisions;
  r.decisions_gmp = sim.counters().exact_decisions_gmp;
  r.comparisons = sim.counters().exact_comparisons;
  r.comparisons_gmp = sim.counters().exact_comparisons_gmp;
  r.valid = structure.validate();
  return r;
}

/// Prints the table for structure S (`name`) on `motions` (`input` names them) over
/// [start, end].
template <class S, class... Extra>
void print_scheduler_table(const char* name, const char* input, const MotionTable& motions,
                           double start, double end, double eps, double budget,
                           const Extra&... extra) {
  out("\n== Schedulers side by side: %s on %s, n = %zu, window [%g, %g], robust eps = %g, "
      "each run cut after %g CPU s (all figures from this run) ==\n",
      name, input, motions.size(), start, end, eps, budget);
  out("| scheduler | events | reached t | CPU s | events/s | us/event | per event / robust | "
      "equal-time groups | GMP: decisions, close comparisons | validate() |\n"
      "|---|---:|---:|---:|---:|---:|---:|---:|---:|---|\n");
  SchedulerRun runs[3];
  const SchedulerKind kinds[3] = {SchedulerKind::Classic, SchedulerKind::Robust,
                                  SchedulerKind::Exact};
  for (int i = 0; i < 3; ++i)
    runs[i] = run_scheduler<S>(motions, start, end, kinds[i], eps, budget, extra...);
  auto per_event = [](const SchedulerRun& r) {
    return r.cpu / static_cast<double>(std::max<std::uint64_t>(1, r.events));
  };
  auto share = [](std::uint64_t part, std::uint64_t whole) {
    return whole == 0 ? 0.0 : 100.0 * static_cast<double>(part) / static_cast<double>(whole);
  };
  for (const SchedulerRun& r : runs) {
    char gmp[96] = "-";
    if (r.kind == SchedulerKind::Exact) {
      std::snprintf(
          gmp, sizeof gmp, "%.1f%% of %llu, %.1f%% of %llu", share(r.decisions_gmp, r.decisions),
          static_cast<unsigned long long>(r.decisions), share(r.comparisons_gmp, r.comparisons),
          static_cast<unsigned long long>(r.comparisons));
    }
    out("| %s | %llu | %g%s | %.3f | %.3g | %.3f | %.2f | %llu | %s | %s |\n", to_string(r.kind),
        static_cast<unsigned long long>(r.events), r.reached, r.completed ? "" : " (cut)", r.cpu,
        static_cast<double>(r.events) / std::max(1e-9, r.cpu), 1e6 * per_event(r),
        per_event(r) / std::max(1e-300, per_event(runs[1])),
        static_cast<unsigned long long>(r.equal_time_groups), gmp, r.valid ? "ok" : "FAIL");
  }
  std::fflush(stdout);
}

}  // namespace kinetic::bench
