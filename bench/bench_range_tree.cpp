// Kinetic range tree benchmark (plain timing program, docs/performance/range-tree.md).
//
// n points in 2-D, dataset random-linear (positions uniform in [0, sqrt n]^2, velocities uniform
// in [-1, 1]^2), as bench_kdtree.
//  1. Build and space: the kinetic range tree (sorts + build), its bytes per point, beside the
//     kinetic kd-tree and CGAL's Range_tree_2 (heap bytes measured with mallinfo2).
//  2. Events over the horizon, robust (eps 1e-9) and classic: time per event by axis (x-swaps
//     change the nodes below the pair's lowest common ancestor, y-swaps swap adjacent entries in
//     the blocks of the common ancestors), nodes touched and array shifts per event; the kinetic
//     kd-tree on the same motions for reference.
//  3. Range queries at the end of the horizon on the same boxes: the kinetic range tree, the
//     kinetic kd-tree and CGAL's Range_tree_2 built on the positions at that time (every answer
//     compared with the kinetic range tree's; CGAL's window is half-open [lo, hi)).
//  4. Q queries at evenly spaced times over the horizon: the kinetic run plus its queries against
//     rebuilding CGAL's Range_tree_2 before each query; the break-even query rate.
//  5. Inserts and removes, 10^4 of each alternating (local: vacate / place in the blocks of the
//     point's path, keys moved in A_0 change nodes); 5b. flight-plan updates (small velocity
//     changes, small moves, random new motions), local too.
//  6. Events in 3-D (n = 10^4); 6b. flight-plan updates in 3-D.
//  7. The three schedulers side by side (classic, robust, exact), 2-D, n and horizon of
//     section 2.
//
// CGAL is a benchmark-only dependency: without it the CGAL columns read "not available".
// Options: --n=N (100000)  --seed=S  --quick (a tenth of the horizon, fewer boxes)
#include <malloc.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <iterator>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "churn.hpp"
#include "harness.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/kdtree/kinetic_kdtree.hpp"
#include "kinetic/range_tree/kinetic_range_tree.hpp"
#include "kinetic/scenario/generators.hpp"
#include "scheduler_table.hpp"

#if defined(KINETIC_BENCH_HAVE_CGAL)
#include <CGAL/Cartesian.h>
#include <CGAL/Range_segment_tree_traits.h>
#include <CGAL/Range_tree_k.h>
#endif

using kinetic::bench::out;

namespace {

using kinetic::bench::cpu_now;
using kinetic::bench::heap_bytes;
using kinetic::bench::thread_now;
using kinetic::bench::wall_now;

using kinetic::Box;
using kinetic::KineticKdTree;
using kinetic::KineticRangeTree;
using kinetic::MotionPolynomial;
using kinetic::MotionTable;
using kinetic::Scheduler;
using kinetic::SchedulerKind;
using kinetic::Simulator;
using Ids = std::vector<std::uint32_t>;

void fill(MotionTable& motions, std::size_t n, std::uint64_t seed) {
  kinetic::scenario::GeneratorOptions o;
  o.n = n;
  o.seed = seed;
  o.dimension = motions.dimension();
  const kinetic::scenario::Scenario s = kinetic::scenario::generate("random-linear", o);
  for (const auto& obj : s.objects) {
    std::vector<MotionPolynomial> p;
    for (const auto& c : obj.motion.coordinates) {
      p.push_back(MotionPolynomial::from(c, obj.motion.origin));
    }
    motions.insert(obj.id, p, 0.0);
  }
}

std::vector<double> positions(const MotionTable& motions, double t) {
  std::vector<double> out(motions.capacity() * 2, 0.0);
  for (const std::uint32_t i : motions.alive_indices()) {
    for (int a = 0; a < 2; ++a)
      out[i * 2 + static_cast<std::size_t>(a)] = motions.motion(i, a).evaluate(t);
  }
  return out;
}

/// "random": two uniform values per axis in [0, side] (k ~ n / 9); "k=K": a square of expected
/// count K centred at a uniform position.
Box make_box(double side, std::size_t n, double k, std::mt19937_64& rng) {
  Box box(2);
  std::uniform_real_distribution<double> u(0.0, side);
  for (int a = 0; a < 2; ++a) {
    if (k <= 0.0) {
      double x = u(rng), y = u(rng);
      if (x > y) std::swap(x, y);
      box[static_cast<std::size_t>(a)] = {x, y};
    } else {
      const double w = side * std::sqrt(k / static_cast<double>(n));
      const double c = u(rng);
      box[static_cast<std::size_t>(a)] = {c - w / 2, c + w / 2};
    }
  }
  return box;
}

struct RtHandler {
  KineticRangeTree* tree;
  std::array<double, 3> seconds{};
  std::array<std::uint64_t, 3> count{};
  std::array<std::uint64_t, 3> nodes{};
  std::array<std::uint64_t, 3> shifts{};
  std::array<std::uint64_t, 3> placed{};
  bool timed = true;
  kinetic::EventKind process(const kinetic::Event& e) {
    const std::size_t axis = e.owner;
    const std::uint64_t s0 = tree->counters().shifts;
    const std::uint64_t r0 = tree->counters().placements;
    kinetic::EventKind k;
    if (timed) {
      const double t0 = thread_now();
      k = tree->process(e);
      seconds[axis] += thread_now() - t0;
    } else {
      k = tree->process(e);
    }
    ++count[axis];
    nodes[axis] += tree->counters().last_event_nodes;
    shifts[axis] += tree->counters().shifts - s0;
    placed[axis] += tree->counters().placements - r0;
    return k;
  }
};
struct KdHandler {
  KineticKdTree* tree;
  kinetic::EventKind process(const kinetic::Event& e) { return tree->process(e); }
};

#if defined(KINETIC_BENCH_HAVE_CGAL)
using CgalK = CGAL::Cartesian<double>;
using CgalTraits = CGAL::Range_tree_map_traits_2<CgalK, std::uint32_t>;
using CgalTree = CGAL::Range_tree_2<CgalTraits>;
using CgalKey = CgalTraits::Key;
using CgalInterval = CgalTraits::Interval;

std::unique_ptr<CgalTree> cgal_build(const std::vector<double>& pos, const MotionTable& motions) {
  std::vector<CgalKey> keys;
  keys.reserve(motions.size());
  for (const std::uint32_t i : motions.alive_indices()) {
    keys.emplace_back(CgalK::Point_2(pos[i * 2], pos[i * 2 + 1]), i);
  }
  return std::make_unique<CgalTree>(keys.begin(), keys.end());
}
void cgal_query(const CgalTree& tree, const Box& box, Ids& out) {
  std::vector<CgalKey> hits;
  // CGAL's window is [lo, hi): widen hi to the next double to make it closed.
  const CgalInterval win(
      CgalK::Point_2(box[0][0], box[1][0]),
      CgalK::Point_2(std::nextafter(box[0][1], HUGE_VAL), std::nextafter(box[1][1], HUGE_VAL)));
  const_cast<CgalTree&>(tree).window_query(win, std::back_inserter(hits));
  out.clear();
  for (const auto& h : hits) out.push_back(h.second);
  std::sort(out.begin(), out.end());
}
#endif

/// Flight-plan updates of random points at sim.now(), one table row per kind of new motion (CPU
/// per motion_changed() call). Returns validate() after them.
bool update_table(KineticRangeTree& tree, MotionTable& motions, Simulator& sim, double side,
                  int ops, std::uint64_t seed) {
  const int d = motions.dimension();
  out("local = the point vacated and placed again, keys moved in A_0 change nodes; a random "
      "point per update, mean of %d per row, CPU\n",
      ops);
  out("| new motion | us/update | placements/update | shifts/update | window spreads | local | "
      "rebuilt |\n|---|---:|---:|---:|---:|---:|---:|\n");
  std::mt19937_64 urng(seed + 17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const char* names[] = {"velocity +- 0.1, same position", "moved by up to 1 per axis",
                         "random (uniform position and velocity)"};
  for (int kind = 0; kind < 3; ++kind) {
    const kinetic::RangeTreeCounters before = tree.counters();
    double cpu = 0.0;
    for (int i = 0; i < ops; ++i) {
      const auto idx = motions.alive_indices();
      const std::uint32_t p = idx[urng() % idx.size()];
      std::vector<MotionPolynomial> m;
      for (int a = 0; a < d; ++a) {
        const MotionPolynomial& old = motions.motion(p, a);
        const double x = old.evaluate(sim.now()), v = old.derivative(sim.now());
        const std::vector<double> c =
            kind == 0   ? std::vector<double>{x, v + 0.1 * u(urng)}
            : kind == 1 ? std::vector<double>{x + u(urng), v}
                        : std::vector<double>{side * 0.5 * (1.0 + u(urng)), u(urng)};
        m.push_back(MotionPolynomial::from(c, sim.now()));
      }
      motions.update(motions.handle(p), m, sim.now());
      const double c0 = cpu_now();
      tree.motion_changed(p);
      cpu += cpu_now() - c0;
      sim.note_external_change();
    }
    const kinetic::RangeTreeCounters& after = tree.counters();
    out("| %s | %.2f | %.1f | %.1f | %llu | %llu | %llu |\n", names[kind], 1e6 * cpu / ops,
        static_cast<double>(after.placements - before.placements) / ops,
        static_cast<double>(after.shifts - before.shifts) / ops,
        static_cast<unsigned long long>(after.window_spreads - before.window_spreads),
        static_cast<unsigned long long>(after.local_changes - before.local_changes),
        static_cast<unsigned long long>(after.rebuilds - before.rebuilds));
  }
  const bool valid = tree.validate();
  out("validate after the updates: %s\n", valid ? "ok" : "FAILED");
  return valid;
}

struct Check {
  std::uint64_t queries = 0, mismatches = 0;
};

}  // namespace

/// Builds a Tree over the motions at t = 0 (robust scheduler, its events queued up to the
/// horizon) between two readings of the heap and the process CPU; then report(tree, CPU ms, heap
/// bytes added) while the tree is alive.
template <class Tree, class Report>
void build_at_zero(const MotionTable& motions, double horizon, Report&& report) {
  Simulator sim(0.0);
  const Scheduler sched(SchedulerKind::Robust, 1e-9, horizon);
  const std::size_t h0 = heap_bytes();
  const double c0 = cpu_now();
  Tree tree(motions, sim, sched);
  tree.initialize();
  const double c1 = cpu_now();
  const std::size_t h1 = heap_bytes();
  report(tree, 1e3 * (c1 - c0), static_cast<double>(h1 - h0));
}

int main(int argc, char** argv) {
  std::size_t n = 100000;
  std::uint64_t seed = 1;
  bool quick = false;
  kinetic::bench::Harness harness(
      "bench_range_tree",
      "the kinetic range tree (2-D, range queries) against CGAL's range "
      "tree rebuilt per query; times are CPU (process, or thread per "
      "event)");
  harness.option("--n", n, "points");
  harness.seed(seed);
  harness.quick(quick, "a tenth of the swaps, fewer boxes");
  harness.parse(argc, argv);
  harness.configured();
  // As bench_kdtree: about 2 * 10^6 swaps at any n (a tenth with --quick).
  const double scale = quick ? 0.1 : 1.0;
  const double horizon =
      0.1 * scale * std::sqrt(1e5 / static_cast<double>(n)) * 1e5 / static_cast<double>(n);
  const int boxes = quick ? 100 : 300;
  const int q_interleaved = quick ? 10 : 40;
  const double side = std::sqrt(static_cast<double>(n));
  const double wall0 = wall_now(), cpu0 = cpu_now();

  out("bench_range_tree: kinetic range tree (2-D), dataset random-linear (positions uniform "
      "in [0, sqrt n]^2, velocities uniform in [-1, 1]^2), n = %zu, seed %llu, horizon "
      "[0, %g]%s\n",
      n, static_cast<unsigned long long>(seed), horizon, quick ? " (--quick)" : "");
#if defined(KINETIC_BENCH_HAVE_CGAL)
  out("  peer CGAL %s: Range_tree_2<Range_tree_map_traits_2<Cartesian<double>, id>> built "
      "on the positions at the query time, window_query with hi widened to the next "
      "double (closed box)\n",
      CGAL_VERSION_STR);
#else
  out("  peer CGAL Range_tree_2: not available\n");
#endif

  MotionTable motions(2);
  fill(motions, n, seed);
  Check check;

  // 1. Build and space.
  out("\n1. Build at t = 0 and space\n");
  out("| structure | build CPU ms | heap bytes per point | stored entries per point |\n");
  out("|---|---:|---:|---:|\n");
  const auto per_point = [&](double x) { return x / static_cast<double>(n); };
  build_at_zero<KineticRangeTree>(
      motions, horizon, [&](const KineticRangeTree& tree, double ms, double heap) {
        out("| kinetic range tree (sorts + build; events queued) | %.1f | %.0f (arrays %.0f) | "
            "%.1f |\n",
            ms, per_point(heap), per_point(static_cast<double>(tree.memory_bytes())),
            per_point(static_cast<double>(tree.stored_entries())));
      });
  build_at_zero<KineticKdTree>(motions, horizon, [&](const KineticKdTree&, double ms, double heap) {
    out("| kinetic kd-tree (sorts + build; events queued) | %.1f | %.0f | - |\n", ms,
        per_point(heap));
  });
#if defined(KINETIC_BENCH_HAVE_CGAL)
  {
    const std::vector<double> pos = positions(motions, 0.0);
    const std::size_t h0 = heap_bytes();
    const double c0 = cpu_now();
    const auto t = cgal_build(pos, motions);
    const double c1 = cpu_now();
    const std::size_t h1 = heap_bytes();
    out("| CGAL Range_tree_2 (static) | %.1f | %.0f | - |\n", 1e3 * (c1 - c0),
        static_cast<double>(h1 - h0) / static_cast<double>(n));
  }
#endif

  // 2. Events.
  out("\n2. Events over [0, %g]: CPU per event by axis (thread CPU around each process() "
      "call)\n",
      horizon);
  out("| structure, scheduler | axis | events | us/event | nodes touched/event | array "
      "shifts/event |\n|---|---|---:|---:|---:|---:|\n");
  double run_cpu = 0.0;
  std::uint64_t run_events = 0;
  for (const SchedulerKind kind : {SchedulerKind::Robust, SchedulerKind::Classic}) {
    Simulator sim(0.0);
    const Scheduler sched(kind, 1e-9, horizon);
    KineticRangeTree tree(motions, sim, sched);
    tree.initialize();
    RtHandler h{&tree};
    const double c0 = cpu_now();
    if (sim.advance_to(horizon, h) != kinetic::AdvanceOutcome::Reached) {
      out("run did not reach the horizon\n");
      return 1;
    }
    const double c1 = cpu_now();
    for (int a = 0; a < 2; ++a) {
      const auto c =
          static_cast<double>(std::max<std::uint64_t>(1, h.count[static_cast<std::size_t>(a)]));
      out("| range tree, %s | %s | %llu | %.3f | %.2f | %.2f |\n",
          kind == SchedulerKind::Robust ? "robust eps 1e-9" : "classic", a == 0 ? "x" : "y",
          static_cast<unsigned long long>(h.count[static_cast<std::size_t>(a)]),
          1e6 * h.seconds[static_cast<std::size_t>(a)] / c,
          static_cast<double>(h.nodes[static_cast<std::size_t>(a)]) / c,
          static_cast<double>(h.shifts[static_cast<std::size_t>(a)]) / c);
    }
    out("| range tree, %s | run total (incl. scheduling) | %llu | %.3f | | |\n",
        kind == SchedulerKind::Robust ? "robust eps 1e-9" : "classic",
        static_cast<unsigned long long>(h.count[0] + h.count[1]),
        1e6 * (c1 - c0) / static_cast<double>(std::max<std::uint64_t>(1, h.count[0] + h.count[1])));
    if (kind == SchedulerKind::Robust) {
      run_cpu = c1 - c0;
      run_events = h.count[0] + h.count[1];
    }
  }
  {
    Simulator sim(0.0);
    const Scheduler sched(SchedulerKind::Robust, 1e-9, horizon);
    KineticKdTree tree(motions, sim, sched);
    tree.initialize();
    KdHandler h{&tree};
    const double c0 = cpu_now();
    (void)sim.advance_to(horizon, h);
    const double c1 = cpu_now();
    const auto e = tree.counters().swaps;
    out("| kd-tree, robust eps 1e-9 | run total (incl. scheduling) | %llu | %.3f | | |\n",
        static_cast<unsigned long long>(e),
        1e6 * (c1 - c0) / static_cast<double>(std::max<std::uint64_t>(1, e)));
  }

  // 3. Queries at the end of the horizon.
  Simulator sim(0.0);
  const Scheduler sched(SchedulerKind::Robust, 1e-9, horizon);
  KineticRangeTree tree(motions, sim, sched);
  tree.initialize();
  Simulator ksim(0.0);
  KineticKdTree kd(motions, ksim, sched);
  kd.initialize();
  {
    RtHandler h{&tree};
    h.timed = false;
    (void)sim.advance_to(horizon, h);
    KdHandler kh{&kd};
    (void)ksim.advance_to(horizon, kh);
  }
  const double t = horizon;
  const std::vector<double> pos = positions(motions, t);
#if defined(KINETIC_BENCH_HAVE_CGAL)
  const auto cgal = cgal_build(pos, motions);
#endif
  out("\n3. Range queries at t = %g: mean CPU us per query, %d boxes per class, answers "
      "sorted by id\n",
      t, boxes);
  out("| boxes | mean k | range tree | mean visits | kd-tree | CGAL Range_tree_2 | range "
      "tree / CGAL | range tree / kd-tree |\n|---|---:|---:|---:|---:|---:|---:|---:|\n");
  std::mt19937_64 rng(seed + 7);
  for (const double k : {0.0, 10.0, 100.0, 1000.0}) {
    std::vector<Box> bs;
    for (int b = 0; b < boxes; ++b) bs.push_back(make_box(side, n, k, rng));
    std::vector<Ids> mine(bs.size());
    const std::uint64_t v0 = tree.counters().node_visits;
    double c0 = cpu_now();
    for (std::size_t b = 0; b < bs.size(); ++b) mine[b] = tree.range(bs[b], t);
    const double rt_s = (cpu_now() - c0) / static_cast<double>(bs.size());
    const double visits =
        static_cast<double>(tree.counters().node_visits - v0) / static_cast<double>(bs.size());
    double mean_k = 0;
    for (const auto& m : mine) mean_k += static_cast<double>(m.size());
    mean_k /= static_cast<double>(bs.size());
    c0 = cpu_now();
    for (std::size_t b = 0; b < bs.size(); ++b) {
      const Ids got = kd.range(bs[b], t);
      ++check.queries;
      if (got != mine[b]) ++check.mismatches;
    }
    const double kd_s = (cpu_now() - c0) / static_cast<double>(bs.size());
    double cg_s = NAN;
#if defined(KINETIC_BENCH_HAVE_CGAL)
    {
      Ids out;
      std::vector<Ids> theirs(bs.size());
      c0 = cpu_now();
      for (std::size_t b = 0; b < bs.size(); ++b) cgal_query(*cgal, bs[b], theirs[b]);
      cg_s = (cpu_now() - c0) / static_cast<double>(bs.size());
      for (std::size_t b = 0; b < bs.size(); ++b) {
        ++check.queries;
        if (theirs[b] != mine[b]) ++check.mismatches;
      }
    }
#endif
    out("| %s | %.0f | %.2f | %.0f | %.2f | %.2f | %.2f | %.2f |\n",
        k <= 0.0 ? "random" : ("k=" + std::to_string(static_cast<int>(k))).c_str(), mean_k,
        1e6 * rt_s, visits, 1e6 * kd_s, 1e6 * cg_s, rt_s / cg_s, rt_s / kd_s);
  }

  // 4. Q queries over the horizon: kinetic vs rebuilding CGAL's range tree per query.
  {
    Simulator qsim(0.0);
    KineticRangeTree qtree(motions, qsim, sched);
    qtree.initialize();
    RtHandler h{&qtree};
    h.timed = false;
    std::mt19937_64 qrng(seed + 11);
    double query_cpu = 0.0, eval_cpu = 0.0, build_cpu = 0.0, cquery_cpu = 0.0, advance_cpu = 0.0;
    for (int q = 1; q <= q_interleaved; ++q) {
      const double tq = horizon * q / q_interleaved;
      const double r0 = cpu_now();
      (void)qsim.advance_to(tq, h);
      advance_cpu += cpu_now() - r0;
      const Box box = make_box(side, n, 1000.0, qrng);
      const double a = cpu_now();
      const Ids mine = qtree.range(box, tq);
      query_cpu += cpu_now() - a;
#if defined(KINETIC_BENCH_HAVE_CGAL)
      const double b0 = cpu_now();
      const std::vector<double> p = positions(motions, tq);
      const double b1 = cpu_now();
      auto ct = cgal_build(p, motions);
      const double b2 = cpu_now();
      Ids theirs;
      cgal_query(*ct, box, theirs);
      const double b3 = cpu_now();
      ct.reset();  // a rebuild per query frees the previous tree: counted with the build
      const double b4 = cpu_now();
      eval_cpu += b1 - b0;
      build_cpu += (b2 - b1) + (b4 - b3);
      cquery_cpu += b3 - b2;
      ++check.queries;
      if (theirs != mine) ++check.mismatches;
#endif
    }
    const double total = advance_cpu + query_cpu;
    const double per_rebuild = (eval_cpu + build_cpu + cquery_cpu) / q_interleaved;
    out("\n4. %d queries (k=1000 boxes) at evenly spaced times over [0, %g]: kinetic run "
        "+ queries against rebuilding CGAL's Range_tree_2 per query (CPU)\n",
        q_interleaved, horizon);
    out("| structure | per query: evaluate | build (and free) | query | total over the horizon |\n"
        "|---|---:|---:|---:|---:|\n");
    out("| kinetic range tree (run %.3f s, %llu events) | - | - | %.1f us | %.3f s |\n",
        total - query_cpu, static_cast<unsigned long long>(qtree.counters().swaps),
        1e6 * query_cpu / q_interleaved, total);
#if defined(KINETIC_BENCH_HAVE_CGAL)
    out("| CGAL Range_tree_2 rebuilt per query | %.1f ms | %.1f ms | %.1f us | %.3f s |\n",
        1e3 * eval_cpu / q_interleaved, 1e3 * build_cpu / q_interleaved,
        1e6 * cquery_cpu / q_interleaved, per_rebuild * q_interleaved);
    const double kinetic_rate = (total - query_cpu) / horizon;  // CPU s per unit time
    out("Break-even: the kinetic range tree costs %.3g CPU s per unit time plus %.1f us "
        "per query; a rebuild per query costs %.1f ms, so kinetic wins above %.3g "
        "queries per unit time (%.3g over this horizon)\n",
        kinetic_rate, 1e6 * query_cpu / q_interleaved, 1e3 * per_rebuild,
        kinetic_rate / (per_rebuild - query_cpu / q_interleaved),
        kinetic_rate * horizon / (per_rebuild - query_cpu / q_interleaved));
#else
    (void)per_rebuild;
#endif
    (void)run_cpu;
    (void)run_events;
  }

  // 5. Inserts and removes.
  {
    const std::size_t changes = quick ? 2000 : 10000;
    const kinetic::Time t5 = sim.now();
    out("\n5. Inserts and removes at t = %g (n = %zu, 2-D): %zu new random points inserted and "
        "%zu random live points removed, alternating\n",
        t5, n, changes, changes);
    std::mt19937_64 crng(seed + 5);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const kinetic::RangeTreeCounters before = tree.counters();
    const kinetic::bench::ChurnTimes times = kinetic::bench::churn(
        tree, motions, changes, static_cast<kinetic::ObjectId>(10 * n), t5,
        [&](std::size_t) {
          std::vector<MotionPolynomial> p;
          for (int a = 0; a < 2; ++a) {
            const std::array<double, 2> c{side * u(crng), 2 * u(crng) - 1};
            p.push_back(MotionPolynomial::from(c, t5));
          }
          return p;
        },
        crng);
    sim.note_external_change();
    const kinetic::RangeTreeCounters& after = tree.counters();
    const bool valid = tree.validate();
    const auto per = static_cast<double>(2 * changes);
    out("| operation | mean CPU us | rebuilds (A_0 laid out again) | keys moved in A_0 / op | "
        "placements / op | shifts / op | window spreads | validate |\n"
        "|---|---:|---:|---:|---:|---:|---:|---|\n");
    out("| insert | %.2f | %llu | %.2f | %.1f | %.1f | %llu | %s |\n",
        1e6 * times.insert_seconds / static_cast<double>(changes),
        static_cast<unsigned long long>(after.rebuilds - before.rebuilds),
        static_cast<double>(after.relabel_moves - before.relabel_moves) / per,
        static_cast<double>(after.placements - before.placements) / per,
        static_cast<double>(after.shifts - before.shifts) / per,
        static_cast<unsigned long long>(after.window_spreads - before.window_spreads),
        valid ? "ok" : "FAILED");
    out("| remove | %.2f | | | | | | |\n",
        1e6 * times.remove_seconds / static_cast<double>(changes));
    if (!valid) ++check.mismatches;
  }

  // 5b. Flight-plan updates (local).
  out("\n5b. Flight-plan updates at t = %g (n = %zu, 2-D)\n", sim.now(), n);
  if (!update_table(tree, motions, sim, side, quick ? 4 : 20, seed)) ++check.mismatches;

  // 6. Events in 3-D (an x-swap vacates and places the pair in the 2-D structures below the
  // LCA, a y-swap in the z-blocks below the y-LCA of the common x-ancestors).
  {
    const std::size_t n3 = quick ? 3000 : 10000;
    MotionTable m3(3);
    fill(m3, n3, seed);
    const double c = std::cbrt(static_cast<double>(n3));
    const double h3 =
        (quick ? 0.2 : 1.0) * 2e5 / (static_cast<double>(n3) * static_cast<double>(n3) / c);
    Simulator s3(0.0);
    const Scheduler sch3(SchedulerKind::Robust, 1e-9, h3);
    const std::size_t heap0 = heap_bytes();
    KineticRangeTree t3(m3, s3, sch3);
    t3.initialize();
    const std::size_t heap1 = heap_bytes();
    RtHandler h{&t3};
    (void)s3.advance_to(h3, h);
    const bool valid = t3.validate();
    out("\n6. Events in 3-D: n = %zu, horizon [0, %g], robust eps 1e-9; %.0f heap bytes per "
        "point, %.1f stored entries per point; validate %s\n",
        n3, h3, static_cast<double>(heap1 - heap0) / static_cast<double>(n3),
        static_cast<double>(t3.stored_entries()) / static_cast<double>(n3),
        valid ? "ok" : "FAILED");
    out("| axis | events | us/event | nodes touched/event | shifts/event | placements/event "
        "|\n|---|---:|---:|---:|---:|---:|\n");
    for (std::size_t a = 0; a < 3; ++a) {
      const auto e = static_cast<double>(std::max<std::uint64_t>(1, h.count[a]));
      out("| %c | %llu | %.2f | %.2f | %.2f | %.1f |\n", "xyz"[a],
          static_cast<unsigned long long>(h.count[a]), 1e6 * h.seconds[a] / e,
          static_cast<double>(h.nodes[a]) / e, static_cast<double>(h.shifts[a]) / e,
          static_cast<double>(h.placed[a]) / e);
    }
    if (!valid) ++check.mismatches;
    out("\n6b. Flight-plan updates in 3-D at t = %g (n = %zu)\n", s3.now(), n3);
    if (!update_table(t3, m3, s3, c, quick ? 4 : 20, seed)) ++check.mismatches;
  }

  {  // 7. The three schedulers side by side (exact beside robust and classic).
    MotionTable side_by_side(2);
    fill(side_by_side, n, seed);
    kinetic::bench::print_scheduler_table<kinetic::KineticRangeTree>(
        "range tree (2-D)", "random-linear", side_by_side, 0.0, horizon, 1e-9, quick ? 10.0 : 30.0);
  }
  out("\nAnswer checks: %llu answers compared with the kinetic range tree's, %llu "
      "mismatches\n",
      static_cast<unsigned long long>(check.queries),
      static_cast<unsigned long long>(check.mismatches));
  const double wall = wall_now() - wall0, cpu = cpu_now() - cpu0;
  out("Whole run: %.1f s wall, %.1f s CPU (wall/CPU %.2f)\n", wall, cpu,
      wall / std::max(1e-9, cpu));
  return check.mismatches == 0 ? 0 : 1;
}
