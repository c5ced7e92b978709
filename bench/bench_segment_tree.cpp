// Kinetic segment tree benchmark (plain timing program, docs/performance/segment-tree.md).
//
//  1. Walk heights over n: random linear intervals, the kinetic run until E swaps; the average
//     and largest height of the extend/shrink walks (the lecture's Lemma: O(1) on average),
//     CPU time per swap, fragments per segment.
//  2. At n (default 10^5): stab query time of the tree against a linear scan of the intervals
//     (both with the same exact comparisons; every answer checked equal).
//  3. Q stabbing queries spread over the horizon of those E swaps: the kinetic run + its queries
//     against rebuilding the tree (sort + build) before each query; the break-even query rate.
//  4. The three schedulers side by side (classic, robust, exact) over that horizon.
//  5. At n: C inserts of new random intervals and C removes of random live ones (alternating,
//     at the time the run reached), each local; amortized time per operation against a rebuild
//     (the build of step 2); the tree validated and stab answers checked after them.
//
// Options: --n=N (100000)  --events=E (200000)  --queries=Q (2000)  --max-n=M (100000)
//          --changes=C (10000)  --seed=S  --quick
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <iterator>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "churn.hpp"
#include "harness.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/predicates.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/segment_tree/kinetic_segment_tree.hpp"
#include "run_sizes.hpp"
#include "scheduler_table.hpp"

#if defined(KINETIC_BENCH_HAVE_CGAL)
#include <CGAL/Segment_tree_k.h>
#endif

using kinetic::bench::out;

namespace {

using kinetic::bench::cpu_now;

using kinetic::KineticSegmentTree;
using kinetic::MotionPolynomial;
using kinetic::MotionTable;
using kinetic::Scheduler;
using kinetic::SchedulerKind;
using kinetic::Simulator;

/// n random linear intervals over [0, 1000] at t = 0: left end uniform, length up to 1 % of the
/// range, speeds in [-1, 1], lengths growing at up to 0.01 per unit of time (never inside out).
void fill(MotionTable& m, std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (std::size_t i = 0; i < n; ++i) {
    const double a = 1000.0 * u(rng), v = 2.0 * u(rng) - 1.0;
    const double w = 10.0 * u(rng), g = 0.01 * u(rng);
    const std::array<double, 2> l{a, v}, r{a + w, v + g};
    const std::array<MotionPolynomial, 2> c{MotionPolynomial::from(l), MotionPolynomial::from(r)};
    m.insert(static_cast<kinetic::ObjectId>(i), c, 0.0);
  }
}

struct Run {
  MotionTable motions{2};
  Simulator sim{0.0};
  Scheduler scheduler{SchedulerKind::Robust, 1e-9, 1e6};
  std::unique_ptr<KineticSegmentTree> tree;
  kinetic::EventKind process(const kinetic::Event& e) { return tree->process(e); }
};

std::vector<std::uint32_t> scan(const MotionTable& m, double x, kinetic::Time t) {
  const MotionPolynomial q = MotionPolynomial::constant(x);
  std::vector<std::uint32_t> out;
  const std::size_t n = m.capacity();
  for (std::uint32_t i = 0; i < n; ++i) {
    if (kinetic::compare_at(m.motion(i, 0), q, t) <= 0 &&
        kinetic::compare_at(m.motion(i, 1), q, t) >= 0)
      out.push_back(i);
  }
  return out;
}

#if defined(KINETIC_BENCH_HAVE_CGAL)
/// CGAL's Segment_tree_1 over (left, right, index) triples. CGAL's intervals are half-open
/// [low, high); a stab at x is the enclosing query of the window [x, nextafter(x)).
struct CgalTraits {
  using Key = double;
  using Key_1 = double;
  struct Interval {
    double lo, hi;
    std::uint32_t index;
  };
  struct key_1 {
    double operator()(double k) const { return k; }
  };
  struct low_1 {
    double operator()(const Interval& i) const { return i.lo; }
  };
  struct high_1 {
    double operator()(const Interval& i) const { return i.hi; }
  };
  struct compare_1 {
    bool operator()(double a, double b) const { return a < b; }
  };
};
using CgalTree = CGAL::Segment_tree_1<CgalTraits>;
#endif

}  // namespace

int main(int argc, char** argv) {
  kinetic::bench::RunSizes o;
  std::size_t max_n = 100000;
  std::uint64_t seed = 1;
  bool quick = false;
  kinetic::bench::Harness harness(
      "bench_segment_tree",
      "the kinetic segment tree over moving intervals (stabbing queries, "
      "changes) against CGAL's segment tree rebuilt per query; robust "
      "scheduler, eps 1e-9");
  o.declare(harness, "intervals");
  harness.option("--max-n", max_n, "the largest n of section 1");
  harness.seed(seed);
  harness.quick(quick, "n = 10^4, 2 10^4 events, 200 queries");
  harness.parse(argc, argv);
  if (quick) {  // what the command line does not give
    o.quick(harness, 10000, 20000, 200);
    if (!harness.given("--max-n")) max_n = 10000;
  }
  harness.configured();

  // 1. Walk heights over n.
  out("\n| n | swaps | avg walk height | max walk height | tree height | us/swap | "
      "fragments/segment (avg, max) |\n|---|---|---|---|---|---|---|\n");
  for (std::size_t n = 1000; n <= max_n; n *= 10) {
    Run r;
    fill(r.motions, n, seed);
    r.tree = std::make_unique<KineticSegmentTree>(r.motions, r.sim, r.scheduler);
    r.tree->initialize();
    const double c0 = cpu_now();
    std::uint64_t done = 0;
    while (done < o.events && !r.sim.queue().empty()) {
      (void)r.sim.process_next(r);
      ++done;
    }
    const double c1 = cpu_now();
    const auto& c = r.tree->counters();
    out("| %zu | %llu | %.3f | %llu | %d | %.3f | %.2f, %zu |\n", n,
        static_cast<unsigned long long>(c.swaps),
        c.walks ? static_cast<double>(c.walk_height_total) / static_cast<double>(c.walks) : 0.0,
        static_cast<unsigned long long>(c.walk_height_max), r.tree->height(),
        1e6 * (c1 - c0) / static_cast<double>(std::max<std::uint64_t>(1, done)),
        static_cast<double>(r.tree->fragments()) / static_cast<double>(n), r.tree->fragments_max());
  }

  // 2 and 3 at n.
  Run r;
  fill(r.motions, o.n, seed);
  r.tree = std::make_unique<KineticSegmentTree>(r.motions, r.sim, r.scheduler);
  const double b0 = cpu_now();
  r.tree->initialize();
  const double build = cpu_now() - b0;
  const double e0 = cpu_now();
  std::uint64_t done = 0;
  while (done < o.events && !r.sim.queue().empty()) {
    (void)r.sim.process_next(r);
    ++done;
  }
  const double events_cpu = cpu_now() - e0;
  const double horizon = r.sim.now();
  std::mt19937_64 rng(seed + 7);
  std::uniform_real_distribution<double> ux(0.0, 1000.0);
  const double t = r.sim.now();
  double tree_q = 0.0, scan_q = 0.0;
  std::size_t answered = 0, mismatches = 0;
  for (std::size_t q = 0; q < o.queries; ++q) {
    const double x = ux(rng);
    const double q0 = cpu_now();
    const auto a = r.tree->stab(x, t);
    const double q1 = cpu_now();
    const auto b = scan(r.motions, x, t);
    const double q2 = cpu_now();
    tree_q += q1 - q0;
    scan_q += q2 - q1;
    answered += a.size();
    if (a != b) ++mismatches;
  }
  const double per_tree = tree_q / static_cast<double>(o.queries);
  const double per_scan = scan_q / static_cast<double>(o.queries);
  out("\nn = %zu: build (sort + tree) %.3f s; %llu swaps over [0, %.4g], %.3f us/swap\n", o.n,
      build, static_cast<unsigned long long>(done), horizon,
      1e6 * events_cpu / static_cast<double>(std::max<std::uint64_t>(1, done)));
  out("stab: tree %.2f us/query, linear scan %.2f us/query (avg k = %.1f, %zu answers "
      "differ)\n",
      1e6 * per_tree, 1e6 * per_scan,
      static_cast<double>(answered) / static_cast<double>(o.queries), mismatches);
#if defined(KINETIC_BENCH_HAVE_CGAL)
  {
    // The same intervals at time t, as doubles (the tree's exact answers are compared by count:
    // CGAL's intervals are half-open and built on rounded positions).
    std::vector<CgalTraits::Interval> input;
    for (std::uint32_t i = 0; i < r.motions.capacity(); ++i) {
      input.push_back({r.motions.motion(i, 0).evaluate(t), r.motions.motion(i, 1).evaluate(t), i});
    }
    const double g0 = cpu_now();
    CgalTree cgal(input.begin(), input.end());
    const double g1 = cpu_now();
    std::mt19937_64 rng2(seed + 7);
    double cgal_q = 0.0;
    std::size_t cgal_answered = 0;
    std::vector<CgalTraits::Interval> found;
    for (std::size_t q = 0; q < o.queries; ++q) {
      const double x = ux(rng2);
      found.clear();
      const double q0 = cpu_now();
      cgal.enclosing_query(CgalTraits::Interval{x, std::nextafter(x, 2000.0), 0},
                           std::back_inserter(found));
      const double q1 = cpu_now();
      cgal_q += q1 - q0;
      cgal_answered += found.size();
    }
    out("stab: CGAL Segment_tree_1 (built at t in %.3f s) %.2f us/query (avg k = %.1f)\n", g1 - g0,
        1e6 * cgal_q / static_cast<double>(o.queries),
        static_cast<double>(cgal_answered) / static_cast<double>(o.queries));
  }
#else
  out("stab: CGAL Segment_tree_1: not available\n");
#endif
  // 3. Q queries over the horizon: kinetic = events + Q queries; rebuild = Q (build + query).
  const double Q = static_cast<double>(o.queries);
  const double kinetic_total = events_cpu + Q * per_tree;
  const double rebuild_total = Q * (build + per_tree);
  const double break_even = events_cpu / build;  // queries over the horizon
  out("Q = %zu queries over the horizon: kinetic %.3f s, rebuild per query %.3f s; "
      "break-even at %.1f queries per horizon (%.3g per unit of time)\n",
      o.queries, kinetic_total, rebuild_total, break_even,
      horizon > 0 ? break_even / horizon : 0.0);

  // 4. The three schedulers side by side (exact beside robust and classic) over that horizon.
  MotionTable side_by_side(2);
  fill(side_by_side, o.n, seed);
  kinetic::bench::print_scheduler_table<KineticSegmentTree>(
      "segment tree", "random linear intervals", side_by_side, 0.0, horizon, 1e-9, 20.0);

  // 5. Inserts and removes, alternating, at the time the run reached.
  {
    std::mt19937_64 crng(seed + 11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const std::uint64_t rebuilds0 = r.tree->counters().rebuilds;
    const std::uint64_t refits0 = r.tree->counters().refits;
    const auto w0 = kinetic::bench::wall_now();
    const kinetic::bench::ChurnTimes times = kinetic::bench::churn(
        *r.tree, r.motions, o.changes, static_cast<kinetic::ObjectId>(o.n), t,
        [&](std::size_t) {
          const double a = 1000.0 * u(crng), v = 2.0 * u(crng) - 1.0;
          const double w = 10.0 * u(crng), g = 0.01 * u(crng);
          return std::array<MotionPolynomial, 2>{
              MotionPolynomial::from(std::array<double, 2>{a - v * t, v}),
              MotionPolynomial::from(std::array<double, 2>{a + w - (v + g) * t, v + g})};
        },
        crng);
    const double insert_cpu = times.insert_seconds, remove_cpu = times.remove_seconds;
    const double wall = kinetic::bench::wall_now() - w0;
    const double ops = static_cast<double>(std::max<std::size_t>(1, o.changes));
    const bool valid = r.tree->validate();
    std::size_t wrong = 0;
    for (int q = 0; q < 50; ++q) {
      const double x = ux(rng);
      if (r.tree->stab(x, t) != scan(r.motions, x, t)) ++wrong;
    }
    out("\n5. Inserts and removes at n = %zu, t = %.4g: %zu of each, alternating: insert %.2f us, "
        "remove %.2f us (CPU, amortized; wall for both %.2f us per pair); a rebuild (step 2's "
        "build) costs %.0f inserts; tree rebuilt %llu times (R laid out again), %llu intervals "
        "refitted; validate() %s, %zu of 50 stab answers differ from a scan\n",
        o.n, t, o.changes, 1e6 * insert_cpu / ops, 1e6 * remove_cpu / ops, 1e6 * wall / ops,
        build / (insert_cpu / ops),
        static_cast<unsigned long long>(r.tree->counters().rebuilds - rebuilds0),
        static_cast<unsigned long long>(r.tree->counters().refits - refits0),
        valid ? "ok" : "FAILED", wrong);
    mismatches += wrong + (valid ? 0 : 1);
  }
  return mismatches == 0 ? 0 : 1;
}
