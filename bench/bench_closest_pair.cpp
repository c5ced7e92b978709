// Kinetic closest pair benchmark (plain timing program).
//
//  1. Events over the window [0, 10] of random-linear (2-D) input, n in --sizes: the kinetic
//     closest pair (a tournament over the Delaunay edges) against the kinetic Delaunay
//     triangulation alone in the same run, so the tournament's share is measured: CPU per unit
//     simulated time of each and their ratio, events (the triangulation's flips and the
//     tournament's length events), cost per event, edge changes per flip. Every event loop has a
//     CPU budget (--budget); rates are those of what was processed.
//  2. Q closest-pair queries at random sorted times in the part of the window processed: the
//     kinetic closest_pair() (the tournament's winner, ties walked) against the triangulation's
//     pass over all its edges, and against what a user would do without a KDS: evaluate the
//     positions in double and sort and sweep them. The distances are compared on every query.
//     The break-even query rate: the tournament's event CPU per unit time over (sweep - kinetic
//     query) per query.
//
//  3. The closest pair from cones (KineticConeClosestPair, the `closest-pair` structure) under
//     the exact, robust and classic schedulers: events over the window, cost per event, candidate
//     changes and scan lengths, CPU per unit time against the exact scheduler's; queries against
//     evaluate + sort + sweep, the largest excess of the answer's distance over the sweep's.
//
// Options: --sizes=1000,10000  --quick (n <= 10000)  --budget=SECONDS (20)  --queries=Q (200)
//          --seed=S
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "harness.hpp"
#include "kinetic/closest_pair/kinetic_closest_pair.hpp"
#include "kinetic/closest_pair/kinetic_cone_closest_pair.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/delaunay/kinetic_delaunay.hpp"
#include "planar_points.hpp"

using kinetic::bench::out;

namespace {

using kinetic::KineticClosestPair;
using kinetic::KineticConeClosestPair;
using kinetic::KineticDelaunay;
using kinetic::MotionTable;
using kinetic::Scheduler;
using kinetic::SchedulerKind;
using kinetic::Simulator;
using kinetic::bench::cpu_now;

constexpr double kStart = 0.0, kEnd = 10.0;  // the dataset's window
using kinetic::bench::distances_differ;
using kinetic::bench::per;
using kinetic::bench::process_within_budget;
using kinetic::bench::timed_initialize;

/// The CPU of the queries of one run: the structure's closest_pair(), and the recomputation in
/// double (positions evaluated, then sorted and swept).
struct QueryCpu {
  double kinetic = 0, evaluate = 0, sweep = 0;
};

/// Queries at Q sorted random times (query_times()) on a fresh run of S over the motions (the
/// same events up to `span`): at each, the structure's closest pair beside its recomputation in
/// double, each timed into the result; then visit(s, pair, pair_distance, best) with the squared
/// distances of the pair's two points and of the recomputation's closest two.
template <class S, class Visit>
QueryCpu time_queries(const MotionTable& motions, const Scheduler& sched, std::uint64_t seed,
                      double span, int queries, Visit&& visit) {
  Simulator qsim(kStart);
  S qs(motions, qsim, sched);
  qs.initialize();
  QueryCpu cpu;
  for (const double t : kinetic::bench::query_times(seed, kStart, span, queries)) {
    (void)qsim.advance_to(t, qs);
    double c0 = cpu_now();
    const auto pair = qs.closest_pair();
    cpu.kinetic += cpu_now() - c0;
    c0 = cpu_now();
    const auto pos = kinetic::bench::positions(motions, t);
    cpu.evaluate += cpu_now() - c0;
    c0 = cpu_now();
    const double best = kinetic::bench::sweep_closest(pos);
    cpu.sweep += cpu_now() - c0;
    const double d =
        pair ? kinetic::bench::squared_distance(motions, (*pair)[0], (*pair)[1], t) : -1.0;
    visit(qs, pair, d, best);
  }
  return cpu;
}

void run(std::size_t n, std::uint64_t seed, double budget, int queries) {
  const MotionTable motions = kinetic::bench::planar_table("random-linear", n, seed, kStart);
  const Scheduler sched(SchedulerKind::Exact, 1e-9, kEnd);
  // The triangulation alone, as the baseline of the tournament's share.
  Simulator dsim(kStart);
  KineticDelaunay dt(motions, dsim, sched);
  dt.initialize();
  const auto d0 = dt.counters();
  const auto dl = process_within_budget(dsim, dt, kEnd, budget);
  const double dt_per_time = dl.cpu / (dl.reached - kStart);
  // The closest pair.
  Simulator sim(kStart);
  KineticClosestPair cp(motions, sim, sched);
  const double init = timed_initialize(cp);
  const auto t0 = cp.counters();
  const auto f0 = cp.triangulation().counters();
  const auto l = process_within_budget(sim, cp, kEnd, budget);
  const double span = l.reached - kStart;
  const std::uint64_t flips = cp.triangulation().counters().events - f0.events;
  const std::uint64_t length_events = cp.counters().events - t0.events;
  const std::uint64_t edge_changes =
      cp.counters().edge_inserts + cp.counters().edge_removes - t0.edge_inserts - t0.edge_removes;
  const std::uint64_t decided = cp.counters().nodes_redecided - t0.nodes_redecided;
  const double cp_per_time = l.cpu / span;
  out("| %zu | %.3f | %zu | %llu | %llu | %.4g | %s | %.1f | %.2f | %.1f | %.3g | %.3g | %.2f |\n",
      n, init, cp.edges(), static_cast<unsigned long long>(flips),
      static_cast<unsigned long long>(length_events), span, l.stopped ? "budget" : "done",
      1e6 * per(l.cpu, flips + length_events), per(static_cast<double>(edge_changes), flips),
      per(static_cast<double>(decided), flips + length_events), cp_per_time, dt_per_time,
      cp_per_time / dt_per_time);
  (void)d0;
  std::fflush(stdout);

  // 2. Queries on a fresh run over [0, reached] (same events), at sorted random times.
  double edge_pass = 0;
  int mismatched = 0;
  const QueryCpu cpu = time_queries<KineticClosestPair>(
      motions, sched, seed, span, queries,
      [&](KineticClosestPair& qcp, const auto& pair, double d, double best) {
        const double p0 = cpu_now();
        const auto pass = qcp.triangulation().closest_pair();
        edge_pass += cpu_now() - p0;
        if (pair != pass) ++mismatched;
        if (pair && distances_differ(d, best)) ++mismatched;
      });
  const double nq = static_cast<double>(std::max(1, queries));
  const double gain = (cpu.evaluate + cpu.sweep - cpu.kinetic) / nq;
  const double breakeven = gain > 0 ? cp_per_time / gain : HUGE_VAL;
  out("  queries (n = %zu, %d at times in [0, %.4g]): kinetic closest_pair() %.2f us; the "
      "triangulation's pass over its edges %.1f us; evaluate + sort + sweep in double %.1f us "
      "(evaluate %.1f); answers differ in %d; break-even %.4g queries per unit time\n",
      n, queries, span, 1e6 * cpu.kinetic / nq, 1e6 * edge_pass / nq,
      1e6 * (cpu.evaluate + cpu.sweep) / nq, 1e6 * cpu.evaluate / nq, mismatched, breakeven);
  std::fflush(stdout);
}

/// The closest pair from cones under one scheduler: events over the window (CPU budget), then Q
/// queries at sorted random times against evaluate + sort + sweep in double. Returns the event
/// CPU per unit time.
double run_cones(std::size_t n, std::uint64_t seed, double budget, int queries, SchedulerKind kind,
                 double exact_per_time) {
  const MotionTable motions = kinetic::bench::planar_table("random-linear", n, seed, kStart);
  const Scheduler sched(kind, 1e-9, kEnd);
  Simulator sim(kStart);
  KineticConeClosestPair cp(motions, sim, sched);
  const double init = timed_initialize(cp);
  const auto k0 = cp.counters();
  const auto r0 = cp.tournament().counters();
  const auto l = process_within_budget(sim, cp, kEnd, budget);
  const double span = l.reached - kStart;
  const std::uint64_t swaps = cp.counters().swaps - k0.swaps;
  const std::uint64_t length_events = cp.counters().tournament_events - k0.tournament_events;
  const std::uint64_t events = swaps + length_events;
  const double per_time = l.cpu / span;
  out("| %zu | %s | %.3f | %zu | %llu | %llu | %.4g | %s | %.2f | %.2f | %.1f | %.2f | %.3g | %s "
      "|\n",
      n, kinetic::to_string(kind), init, cp.certificates(), static_cast<unsigned long long>(swaps),
      static_cast<unsigned long long>(length_events), span, l.stopped ? "budget" : "done",
      1e6 * per(l.cpu, events),
      per(static_cast<double>(cp.counters().candidate_changes - k0.candidate_changes), events),
      per(static_cast<double>(cp.counters().scan_steps - k0.scan_steps),
          cp.counters().scans - k0.scans),
      per(static_cast<double>(cp.tournament().counters().nodes_redecided - r0.nodes_redecided),
          events),
      per_time,
      exact_per_time > 0 ? (std::to_string(per_time / exact_per_time).substr(0, 5)).c_str() : "-");
  std::fflush(stdout);
  // Queries on a fresh run (the same events up to the span processed).
  double worst = 0;
  int differ = 0;
  const QueryCpu cpu = time_queries<KineticConeClosestPair>(
      motions, sched, seed, span, queries,
      [&](KineticConeClosestPair&, const auto& pair, double d, double best) {
        if (!pair) return;
        if (distances_differ(d, best)) ++differ;
        worst = std::max(worst, std::sqrt(d) - std::sqrt(best));
      });
  const double nq = static_cast<double>(std::max(1, queries));
  const double gain = (cpu.evaluate + cpu.sweep - cpu.kinetic) / nq;
  out("  queries (%s, n = %zu, %d): closest_pair() %.2f us; evaluate + sort + sweep %.1f us; "
      "distances differ in %d (largest excess %.3g); break-even %.4g queries per unit time\n",
      kinetic::to_string(kind), n, queries, 1e6 * cpu.kinetic / nq,
      1e6 * (cpu.evaluate + cpu.sweep) / nq, differ, worst, gain > 0 ? per_time / gain : HUGE_VAL);
  std::fflush(stdout);
  return per_time;
}

}  // namespace

int main(int argc, char** argv) {
  kinetic::bench::PlanarOptions o;
  o.queries = 200;
  kinetic::bench::Harness harness(
      "bench_closest_pair",
      "the kinetic closest pair (a tournament over the Delaunay edges, exact scheduler) on "
      "random-linear 2-D points; times are process CPU");
  kinetic::bench::parse_planar_options(harness, argc, argv, o);
  out("# kinetic closest pair (tournament over the Delaunay edges), exact scheduler, "
      "random-linear 2-D, window [0, %g], budget %g s CPU per event loop, %d queries, seed %llu\n",
      kEnd, o.budget, o.queries, static_cast<unsigned long long>(o.seed));
  out("\n| n | init s | edges | flips | length events | time processed | loop | us / event | "
      "edge changes / flip | decisions / event | CPU s / unit time | Delaunay alone | ratio |\n");
  out("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const std::size_t n : o.sizes) run(n, o.seed, o.budget, o.queries);
  out("\n# the closest pair from cones (KineticConeClosestPair: eight direction orders, each "
      "point's candidate per cone, a tournament over the candidates), the three schedulers; eps "
      "1e-9 (robust); ratio: CPU per unit time over the exact scheduler's\n");
  out("\n| n | scheduler | init s | certificates | swaps | length events | time processed | loop "
      "| us / event | candidate changes / event | points per scan | decisions / event | CPU s / "
      "unit time | ratio to exact |\n");
  out("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const std::size_t n : o.sizes) {
    const double exact = run_cones(n, o.seed, o.budget, o.queries, SchedulerKind::Exact, 0.0);
    for (const SchedulerKind kind : {SchedulerKind::Robust, SchedulerKind::Classic})
      (void)run_cones(n, o.seed, o.budget, o.queries, kind, exact);
  }
  return 0;
}
