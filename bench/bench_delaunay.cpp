// Kinetic Delaunay triangulation benchmark (plain timing program), the exact and the robust
// scheduler side by side (the classic one is refused by the structure).
//
//  1. Events over the window [0, 10] of random-linear (2-D) input, n in --sizes: initialize CPU,
//     events per unit simulated time, cost per event (CPU of the event loop / events), flips,
//     rebuilds, certificate decisions per event; robust: folds repaired (locally), rechecks. Every
//     run has a CPU budget (--budget) for its event loop: the loop stops when it is spent, and the
//     rates are those of what was processed.
//  2. Q Delaunay queries at random sorted times in the part of the window processed: the kinetic
//     triangulation (advance to the query time, then triangles(), only triangles() timed as the
//     query) against recomputing the triangulation on the positions at that time: evaluate every
//     motion in double (timed), then CGAL's Delaunay_triangulation_2 (Epick: exact predicates,
//     inexact constructions). Triangle counts are compared on every query. The break-even query
//     rate: the kinetic structure's event CPU per unit time over (recompute - kinetic query) per
//     query; above it, keeping the triangulation kinetic is cheaper.
//  3. Closest pair: the kinetic triangulation's closest_pair() (a pass over its edges) against
//     a brute force over the positions in double (sort by x, sweep) at the same times; the pairs
//     are compared.
//
// CGAL is a benchmark-only dependency: when missing, "peer CGAL: not available".
// Options: --sizes=1000,10000  --quick (n <= 10000)  --budget=SECONDS (20)  --queries=Q (50)
//          --seed=S  --eps=E (the robust scheduler's precision, 1e-9)
//          --schedulers=exact,robust (the default: both)
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "harness.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/delaunay/kinetic_delaunay.hpp"
#include "kinetic/scenario/generators.hpp"
#include "planar_points.hpp"

#if defined(KINETIC_BENCH_HAVE_CGAL)
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/version.h>
#endif

using kinetic::bench::out;

namespace {

using kinetic::Counters;
using kinetic::KineticDelaunay;
using kinetic::MotionTable;
using kinetic::Scheduler;
using kinetic::SchedulerKind;
using kinetic::Simulator;
using kinetic::bench::cpu_now;

constexpr double kStart = 0.0, kEnd = 10.0;  // the dataset's window
using kinetic::bench::per;

using kinetic::bench::positions;
using kinetic::bench::squared_distance;
using kinetic::bench::sweep_closest;

struct Figures {
  double init_cpu = 0, loop_cpu = 0, reached = 0;
  bool stopped = false;
  std::uint64_t events = 0, flips = 0, rebuilds = 0, decisions = 0, repairs = 0, local = 0,
                rechecks = 0;
  double gmp_decisions = 0.0;  ///< the share of the scheduler's decisions that reached GMP
  /// Robust: CROP calls, and Bernstein boxes per call whose signs needed exact arithmetic.
  std::uint64_t crop_calls = 0, exact_boxes = 0, bounded_float = 0;
  std::size_t certificates = 0;
};

void run(std::size_t n, std::uint64_t seed, double budget, int queries, SchedulerKind kind,
         double eps) {
  const MotionTable motions = kinetic::bench::planar_table("random-linear", n, seed, kStart);
  Simulator sim(kStart);
  const Scheduler sched(kind, eps, kEnd);
  KineticDelaunay dt(motions, sim, sched);
  Figures f;
  f.init_cpu = kinetic::bench::timed_initialize(dt);
  f.certificates = dt.certificates();
  const auto after_init = dt.counters();
  const Counters sim_after_init = sim.counters();
  // 1. The event loop under the budget.
  const auto loop = kinetic::bench::process_within_budget(sim, dt, kEnd, budget);
  f.loop_cpu = loop.cpu;
  f.reached = loop.reached;
  f.stopped = loop.stopped;
  f.events = dt.counters().events - after_init.events;
  f.flips = dt.counters().flips - after_init.flips;
  f.rebuilds = dt.counters().rebuilds - after_init.rebuilds;
  f.decisions = dt.counters().decisions - after_init.decisions;
  f.repairs = dt.counters().repairs - after_init.repairs;
  f.local = dt.counters().local_repairs - after_init.local_repairs;
  f.rechecks = dt.counters().rechecks - after_init.rechecks;
  {
    const Counters& c = sim.counters();
    const std::uint64_t all = c.exact_decisions - sim_after_init.exact_decisions;
    const std::uint64_t gmp = c.exact_decisions_gmp - sim_after_init.exact_decisions_gmp;
    f.gmp_decisions = all == 0 ? 0.0 : static_cast<double>(gmp) / static_cast<double>(all);
    f.crop_calls = c.crop.calls - sim_after_init.crop.calls;
    f.exact_boxes = c.crop.exact_boxes - sim_after_init.crop.exact_boxes;
    f.bounded_float = c.crop.bounded_float - sim_after_init.crop.bounded_float;
  }
  const double span = f.reached - kStart;
  const double events_per_time = static_cast<double>(f.events) / span;
  const double us_event = 1e6 * per(f.loop_cpu, f.events);
  out("| %s | %zu | %.3f | %zu | %llu | %.4g | %s | %.4g | %.1f | %llu | %llu | %llu (%llu) | "
      "%llu | %.1f | %.1f%% |\n",
      kinetic::to_string(kind), n, f.init_cpu, f.certificates,
      static_cast<unsigned long long>(f.events), span, f.stopped ? "budget" : "done",
      events_per_time, us_event, static_cast<unsigned long long>(f.flips),
      static_cast<unsigned long long>(f.rebuilds), static_cast<unsigned long long>(f.repairs),
      static_cast<unsigned long long>(f.local), static_cast<unsigned long long>(f.rechecks),
      static_cast<double>(f.decisions) / static_cast<double>(std::max<std::uint64_t>(1, f.events)),
      100.0 * f.gmp_decisions);
  if (kind == SchedulerKind::Robust) {
    const kinetic::DelaunayCounters& c = dt.counters();
    out("  CROP (n = %zu): %llu calls (%llu in-circles answered in bounded floating point), %.3f "
        "boxes per call with exact signs; deferrals %llu, "
        "refused flips %llu, collisions %llu, unwound %llu (builds after the start: each "
        "one of these, or a repair with no local way)\n",
        n, static_cast<unsigned long long>(f.crop_calls),
        static_cast<unsigned long long>(f.bounded_float),
        static_cast<double>(f.exact_boxes) /
            static_cast<double>(std::max<std::uint64_t>(1, f.crop_calls)),
        static_cast<unsigned long long>(c.deferrals - after_init.deferrals),
        static_cast<unsigned long long>(c.refused_flips - after_init.refused_flips),
        static_cast<unsigned long long>(c.collisions - after_init.collisions),
        static_cast<unsigned long long>(c.unwound - after_init.unwound));
  }
  std::fflush(stdout);

  // 2. and 3. Queries on a fresh run over [0, reached] (same events), at sorted random times.
  Simulator qsim(kStart);
  KineticDelaunay qdt(motions, qsim, sched);
  qdt.initialize();
  double kinetic_query = 0, evaluate = 0, cgal = 0, pair_kinetic = 0, pair_sweep = 0;
  int mismatched = 0, pair_mismatched = 0, cgal_queries = 0;
  for (const double t : kinetic::bench::query_times(seed, kStart, span, queries)) {
    (void)qsim.advance_to(t, qdt);
    double c0 = cpu_now();
    const auto tri = qdt.triangles();
    kinetic_query += cpu_now() - c0;
    c0 = cpu_now();
    const auto pos = positions(motions, t);
    evaluate += cpu_now() - c0;
#if defined(KINETIC_BENCH_HAVE_CGAL)
    using K = CGAL::Exact_predicates_inexact_constructions_kernel;
    std::vector<K::Point_2> pts;
    pts.reserve(pos.size());
    for (const auto& p : pos) pts.emplace_back(p[0], p[1]);
    c0 = cpu_now();
    CGAL::Delaunay_triangulation_2<K> cdt(pts.begin(), pts.end());
    cgal += cpu_now() - c0;
    ++cgal_queries;
    if (cdt.number_of_faces() != tri.size()) ++mismatched;
#endif
    c0 = cpu_now();
    const auto pair = qdt.closest_pair();
    pair_kinetic += cpu_now() - c0;
    c0 = cpu_now();
    const double best = sweep_closest(pos);
    pair_sweep += cpu_now() - c0;
    if (pair) {
      const double d = squared_distance(motions, (*pair)[0], (*pair)[1], t);
      if (kinetic::bench::distances_differ(d, best)) ++pair_mismatched;
    }
  }
  const double nq = static_cast<double>(std::max(1, queries));
  const double kinetic_us = 1e6 * kinetic_query / nq;
  const double recompute_us = 1e6 * (evaluate + cgal) / nq;
  const double event_cpu_per_time = f.loop_cpu / span;
  if (cgal_queries > 0) {
    const double gain = (evaluate + cgal - kinetic_query) / nq;
    const double breakeven = gain > 0 ? event_cpu_per_time / gain : HUGE_VAL;
    out("  queries (%s, n = %zu, %d at times in [0, %.4g]): kinetic triangles() %.1f us; "
        "recompute %.1f us (evaluate %.1f + CGAL %.1f); triangle counts differ in %d; break-even "
        "%.4g queries per unit time (event CPU %.3g s per unit time)\n",
        kinetic::to_string(kind), n, queries, span, kinetic_us, recompute_us, 1e6 * evaluate / nq,
        1e6 * cgal / nq, mismatched, breakeven, event_cpu_per_time);
  } else {
    out("  queries (%s, n = %zu): kinetic triangles() %.1f us; peer CGAL: not available\n",
        kinetic::to_string(kind), n, kinetic_us);
  }
  out("  closest pair (%s, n = %zu): kinetic closest_pair() %.1f us (exact at the triangulation's "
      "time, over the Delaunay edges); sweep over x in double %.1f us (evaluate %.1f us more); "
      "distances differ in %d\n",
      kinetic::to_string(kind), n, 1e6 * pair_kinetic / nq, 1e6 * pair_sweep / nq,
      1e6 * evaluate / nq, pair_mismatched);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  kinetic::bench::PlanarOptions o;
  o.queries = 50;
  kinetic::bench::Harness harness(
      "bench_delaunay",
      "the kinetic Delaunay triangulation, exact and robust schedulers, on random-linear 2-D "
      "points, against CGAL rebuilt per query; times are process CPU");
  kinetic::bench::parse_planar_options(harness, argc, argv, o);
  out("# kinetic Delaunay triangulation, exact and robust (eps %g) schedulers, random-linear "
      "2-D, window [0, %g], budget %g s CPU per event loop, %d queries, seed %llu\n",
      o.eps, kEnd, o.budget, o.queries, static_cast<unsigned long long>(o.seed));
#if defined(KINETIC_BENCH_HAVE_CGAL)
  out("# peer: CGAL %s Delaunay_triangulation_2 (Epick), rebuilt per query\n", CGAL_VERSION_STR);
#else
  out("# peer CGAL: not available\n");
#endif
  out("\n| scheduler | n | init s | certificates | events | time processed | loop | events / "
      "unit time | us / event | flips | rebuilds | folds repaired (locally) | rechecks | "
      "decisions / event | decisions reaching GMP |\n");
  out("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  std::vector<SchedulerKind> kinds;
  for (const std::string& name :
       o.schedulers.empty() ? std::vector<std::string>{"exact", "robust"} : o.schedulers) {
    const auto kind = kinetic::scheduler_from_string(name);
    if (!kind || *kind == SchedulerKind::Classic) {
      std::fprintf(stderr, "bench_delaunay: --schedulers takes exact and robust, not %s\n",
                   name.c_str());
      return 2;
    }
    kinds.push_back(*kind);
  }
  for (const std::size_t n : o.sizes) {
    for (const SchedulerKind kind : kinds) run(n, o.seed, o.budget, o.queries, kind, o.eps);
  }
  return 0;
}
