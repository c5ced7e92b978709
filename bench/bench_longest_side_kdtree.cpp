// Kinetic longest-side kd-tree benchmark (plain timing program,
// docs/performance/longest-side-kdtree.md).
//
//  1. Build at t0: the kinetic structure (two sorts, the side-length list with its CROP
//     certificates, the tree) against static peers built on the positions at t0.
//  2. (1+eps)-nearest query time at n: the kinetic tree with eps = 0, 0.1, 0.5 against nanoflann
//     (exact 1-NN, KDTreeSingleIndexAdaptor), CGAL's Kd_tree (Orthogonal_k_neighbor_search,
//     K = 1, same eps) and Boost.Geometry's rtree (R*, packed; exact 1-NN). Every answer is
//     checked: its distance <= (1 + eps) * the exact nearest
//     distance (nanoflann's, or brute force when nanoflann is missing). The first pass at t0
//     (which fills the regions' box cache) is timed alone; then the passes of every structure
//     are interleaved over rounds (7, --quick 3), each after a cache flush, and the medians
//     reported.
//  3. Events: the kinetic run from t0 until E events are processed; event rate per unit of
//     simulated time (ordering and longest-side, real and dropped) and CPU time per event.
//  3b. Section 2's queries again at the time the events reached, on the tree as they left it
//     (the peers rebuilt on the positions then).
//  4. Q queries spread over that horizon: the kinetic run + its queries (each at a new time,
//     so each costs what section 2's first pass costs) against rebuilding a peer before each
//     query; the break-even query rate.
//  5. The three schedulers side by side (classic, robust, exact) over section 3's horizon.
//  6. C inserts and C removes, alternating, at the end of section 3's run: CPU time of each
//     (local: the points whose labels moved are reinserted), validate() after.
//
// Peers are benchmark-only dependencies: a missing one is reported as "not available".
// Options: --n=N (100000)  --events=E (200000)  --queries=Q (2000)  --changes=C (10000)
//          --seed=S  --quick
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
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
#include "kinetic/longest_side_kdtree/longest_side_kdtree.hpp"
#include "kinetic/scenario/generators.hpp"
#include "run_sizes.hpp"
#include "scheduler_table.hpp"

#if defined(KINETIC_BENCH_HAVE_NANOFLANN)
#include <nanoflann.hpp>
#endif
#if defined(KINETIC_BENCH_HAVE_CGAL)
#include <CGAL/Orthogonal_k_neighbor_search.h>
#include <CGAL/Search_traits_2.h>
#include <CGAL/Simple_cartesian.h>
#endif
#if defined(KINETIC_BENCH_HAVE_BOOST_GEOMETRY)
#include <boost/geometry.hpp>
#include <boost/geometry/index/rtree.hpp>
#include <boost/iterator/function_output_iterator.hpp>
#include <boost/version.hpp>
#endif

using kinetic::bench::out;

namespace {

using kinetic::bench::cpu_now;
using kinetic::bench::wall_now;

using kinetic::LongestSideKdTree;
using kinetic::MotionPolynomial;
using kinetic::MotionTable;
using kinetic::Scheduler;
using kinetic::SchedulerKind;
using kinetic::Simulator;
using Pt = std::array<double, 2>;

struct Handler {
  LongestSideKdTree* tree;
  kinetic::EventKind process(const kinetic::Event& e) { return tree->process(e); }
};

/// A static nearest-neighbour peer built on the positions at one time.
struct Peer {
  std::string name;
  bool exact_only = false;  // no eps: timed and checked at eps 0 only
  virtual ~Peer() = default;
  virtual void build(const std::vector<Pt>& pos) = 0;
  /// The index of a (1 + eps)-nearest point; eps is ignored by exact peers.
  virtual std::uint32_t nearest(Pt q, double eps) const = 0;
};

#if defined(KINETIC_BENCH_HAVE_NANOFLANN)
struct Cloud {
  const std::vector<Pt>* pos = nullptr;
  [[nodiscard]] std::size_t kdtree_get_point_count() const { return pos->size(); }
  [[nodiscard]] double kdtree_get_pt(std::size_t i, std::size_t a) const { return (*pos)[i][a]; }
  template <class B>
  bool kdtree_get_bbox(B& /*unused*/) const {
    return false;
  }
};
struct NanoflannPeer : Peer {
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Cloud>,
                                                   Cloud, 2, std::uint32_t>;
  Cloud cloud;
  std::unique_ptr<Tree> tree;
  NanoflannPeer() {
    name = "nanoflann (exact 1-NN)";
    exact_only = true;
  }
  void build(const std::vector<Pt>& pos) override {
    cloud.pos = &pos;
    tree = std::make_unique<Tree>(2, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  }
  std::uint32_t nearest(Pt q, double /*eps*/) const override {
    std::uint32_t idx = 0;
    double d2 = 0.0;
    nanoflann::KNNResultSet<double, std::uint32_t> rs(1);
    rs.init(&idx, &d2);
    tree->findNeighbors(rs, q.data(), nanoflann::SearchParams(32, 0.0F, false));
    return idx;
  }
};
#endif

#if defined(KINETIC_BENCH_HAVE_CGAL)
struct CgalPeer : Peer {
  using K = CGAL::Simple_cartesian<double>;
  using Traits = CGAL::Search_traits_2<K>;
  using Search = CGAL::Orthogonal_k_neighbor_search<Traits>;
  using Tree = Search::Tree;
  std::vector<K::Point_2> points;
  std::unique_ptr<Tree> tree;
  const std::vector<Pt>* pos = nullptr;
  CgalPeer() { name = "CGAL Kd_tree (K = 1, eps)"; }
  void build(const std::vector<Pt>& p) override {
    pos = &p;
    points.clear();
    for (const Pt& x : p) points.emplace_back(x[0], x[1]);
    tree = std::make_unique<Tree>(points.begin(), points.end());
    tree->build();
  }
  std::uint32_t nearest(Pt q, double eps) const override {
    const Search s(*tree, K::Point_2(q[0], q[1]), 1, eps);
    const K::Point_2 found = s.begin()->first;
    // The index is not needed for timing; report the position's index by a linear search only
    // when checking (see check()): here return a sentinel and let the caller use distance().
    last = {found.x(), found.y()};
    return UINT32_MAX;
  }
  mutable Pt last{};
};
#endif

#if defined(KINETIC_BENCH_HAVE_BOOST_GEOMETRY)
struct BoostPeer : Peer {
  using Point = boost::geometry::model::point<double, 2, boost::geometry::cs::cartesian>;
  using Value = std::pair<Point, std::uint32_t>;
  using Tree = boost::geometry::index::rtree<Value, boost::geometry::index::rstar<16>>;
  std::unique_ptr<Tree> tree;
  BoostPeer() {
    name = "Boost.Geometry rtree (exact 1-NN)";
    exact_only = true;
  }
  void build(const std::vector<Pt>& pos) override {
    std::vector<Value> values(pos.size());
    for (std::size_t i = 0; i < pos.size(); ++i) {
      values[i] = {Point(pos[i][0], pos[i][1]), static_cast<std::uint32_t>(i)};
    }
    tree = std::make_unique<Tree>(values.begin(), values.end());  // packing (bulk loading)
  }
  std::uint32_t nearest(Pt q, double /*eps*/) const override {
    std::uint32_t found = UINT32_MAX;
    tree->query(
        boost::geometry::index::nearest(Point(q[0], q[1]), 1),
        boost::make_function_output_iterator([&found](const Value& v) { found = v.second; }));
    return found;
  }
};
#endif

double dist(Pt a, Pt b) { return std::hypot(a[0] - b[0], a[1] - b[1]); }

[[maybe_unused]] double brute_nearest(const std::vector<Pt>& pos, Pt q) {
  double best = HUGE_VAL;
  for (const Pt& p : pos) best = std::min(best, dist(p, q));
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  kinetic::bench::RunSizes sizes;
  std::uint64_t seed = 1;
  bool quick = false;
  kinetic::bench::Harness harness(
      "bench_longest_side_kdtree",
      "the kinetic rank-based longest-side kd-tree ((1+eps)-nearest, range, "
      "changes) against static peers (nanoflann, CGAL, Boost.Geometry); times are process "
      "CPU");
  sizes.declare(harness, "points");
  harness.seed(seed);
  harness.quick(quick, "n = 10^4, 5 10^4 events, 500 queries");
  harness.parse(argc, argv);
  if (quick) {  // what the command line does not give
    sizes.quick(harness, 10000, 50000, 500);
  }
  harness.configured();
  const double wall0 = wall_now(), cpu0 = cpu_now();
  out("bench_longest_side_kdtree: kinetic rank-based longest-side kd-tree, dataset "
      "random-linear\n");
  out("  (positions uniform in [0, n^(1/2)]^2, velocities uniform in [-1, 1]^2), n = %zu, "
      "seed %llu, robust eps 1e-9\n",
      sizes.n, static_cast<unsigned long long>(seed));
  std::vector<std::unique_ptr<Peer>> peers;
#if defined(KINETIC_BENCH_HAVE_NANOFLANN)
  peers.push_back(std::make_unique<NanoflannPeer>());
  out("  peer nanoflann %d.%d.%d: KDTreeSingleIndexAdaptor (L2, leaf size 10), exact 1-NN\n",
      NANOFLANN_VERSION >> 8, (NANOFLANN_VERSION >> 4) & 0xF, NANOFLANN_VERSION & 0xF);
#else
  out("  peer nanoflann: not available\n");
#endif
#if defined(KINETIC_BENCH_HAVE_CGAL)
  peers.push_back(std::make_unique<CgalPeer>());
  out("  peer CGAL %s: Kd_tree (Search_traits_2, sliding midpoint, bucket 10), "
      "Orthogonal_k_neighbor_search K = 1 with eps\n",
      CGAL_VERSION_STR);
#else
  out("  peer CGAL Kd_tree: not available\n");
#endif
#if defined(KINETIC_BENCH_HAVE_BOOST_GEOMETRY)
  peers.push_back(std::make_unique<BoostPeer>());
  out("  peer Boost.Geometry %d.%d: rtree (R*, 16 per node, packed), nearest K = 1 (exact)\n",
      BOOST_VERSION / 100000, BOOST_VERSION / 100 % 1000);
#else
  out("  peer Boost.Geometry rtree: not available\n");
#endif

  kinetic::scenario::GeneratorOptions o;
  o.n = sizes.n;
  o.dimension = 2;
  o.seed = seed;
  const kinetic::scenario::Scenario s = kinetic::scenario::generate("random-linear", o);
  MotionTable motions(2);
  for (const auto& obj : s.objects) {
    std::vector<MotionPolynomial> m;
    for (const auto& c : obj.motion.coordinates)
      m.push_back(MotionPolynomial::from(c, obj.motion.origin));
    motions.insert(obj.id, m, s.start_time);
  }
  const double t0 = s.start_time;
  Simulator sim(t0);
  const Scheduler scheduler(SchedulerKind::Robust, 1e-9, *s.end_time);
  LongestSideKdTree tree(motions, sim, scheduler);
  auto positions = [&](double t) {
    std::vector<Pt> pos(sizes.n);
    for (std::uint32_t i = 0; i < sizes.n; ++i)
      pos[i] = {motions.motion(i, 0).evaluate(t), motions.motion(i, 1).evaluate(t)};
    return pos;
  };

  // 1. Build.
  out("\n## 1. Build at t0 = %g\n", t0);
  double c = cpu_now();
  tree.initialize();
  const double build_kinetic = cpu_now() - c;
  out("  kinetic (2 sorts, %zu live regions, %zu certificates, tree of %zu nodes, depth %d): "
      "%.3f s\n",
      tree.live_regions(), tree.certificates(), tree.node_count(), tree.depth(), build_kinetic);
  std::vector<Pt> pos = positions(t0);
  std::vector<double> peer_build(peers.size(), 0.0);
  for (std::size_t k = 0; k < peers.size(); ++k) {
    c = cpu_now();
    peers[k]->build(pos);
    peer_build[k] = cpu_now() - c;
    out("  %-28s %.4f s\n", peers[k]->name.c_str(), peer_build[k]);
  }

  // 2. Nearest queries at t0.
  out("\n## 2. (1+eps)-nearest at t0, %zu random query points in the bounding box\n",
      sizes.queries);
  double lo[2] = {HUGE_VAL, HUGE_VAL}, hi[2] = {-HUGE_VAL, -HUGE_VAL};
  for (const Pt& p : pos) {
    for (int a = 0; a < 2; ++a) {
      lo[a] = std::min(lo[a], p[static_cast<std::size_t>(a)]);
      hi[a] = std::max(hi[a], p[static_cast<std::size_t>(a)]);
    }
  }
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Pt> qs;
  for (std::size_t i = 0; i < sizes.queries; ++i)
    qs.push_back({lo[0] + (hi[0] - lo[0]) * u(rng), lo[1] + (hi[1] - lo[1]) * u(rng)});
  std::uint64_t violations = 0;
  const int rounds = quick ? 3 : 7;
  // The queries qs at time t on the positions pos_t (the peers built on them): the first pass
  // at t (it fills the regions' box cache, node_box()) timed alone, then every structure's
  // passes interleaved over the rounds, each after a cache flush, and the medians printed; every
  // answer checked against the exact nearest distance. Returns the first pass's us per query;
  // peer_us gets each peer's (at eps 0.1 where it has one, else 0).
  const auto time_nearest = [&](double t, const std::vector<Pt>& pos_t,
                                std::vector<double>& peer_us) {
    std::vector<double> exact(qs.size());
#if defined(KINETIC_BENCH_HAVE_NANOFLANN)
    for (std::size_t i = 0; i < qs.size(); ++i)
      exact[i] = dist(pos_t[peers[0]->nearest(qs[i], 0.0)], qs[i]);
#else
    for (std::size_t i = 0; i < qs.size(); ++i) exact[i] = brute_nearest(pos_t, qs[i]);
#endif
    c = cpu_now();
    for (const Pt& q : qs) (void)tree.nearest(q, 0.0, t);
    const double first_us = (cpu_now() - c) / static_cast<double>(qs.size()) * 1e6;
    out("  first pass at t = %g (fills the regions' box cache; eps 0): %.2f us / query\n", t,
        first_us);
    const std::array<double, 3> epss{0.0, 0.1, 0.5};
    struct Pass {
      int peer;  // -1: the kinetic tree
      double eps;
    };
    std::vector<Pass> passes;
    for (const double eps : epss) passes.push_back({-1, eps});
    for (std::size_t k = 0; k < peers.size(); ++k) {
      for (const double eps : epss) {
        if (eps > 0.0 && peers[k]->exact_only) continue;
        passes.push_back({static_cast<int>(k), eps});
      }
    }
    std::vector<std::vector<std::uint32_t>> answers(epss.size());
    std::vector<double> visits(epss.size(), 0.0);
    double sink = 0.0;
    const std::vector<double> per =
        kinetic::bench::median_passes(rounds, passes.size(), [&](std::size_t j) {
          const Pass& p = passes[j];
          double seconds = 0.0;
          if (p.peer < 0) {
            const std::size_t e = j;  // the kinetic passes come first, one per eps
            const std::uint64_t v0 = tree.counters().node_visits;
            answers[e].clear();
            answers[e].reserve(qs.size());
            c = cpu_now();
            for (const Pt& q : qs) answers[e].push_back(*tree.nearest(q, p.eps, t));
            seconds = cpu_now() - c;
            visits[e] = static_cast<double>(tree.counters().node_visits - v0) /
                        static_cast<double>(qs.size());
          } else {
            const auto k = static_cast<std::size_t>(p.peer);
            c = cpu_now();
            for (const Pt& q : qs) sink += peers[k]->nearest(q, p.eps);
            seconds = cpu_now() - c;
          }
          return seconds / static_cast<double>(qs.size());
        });
    (void)sink;
    out("  medians of %d interleaved rounds, each pass after a cache flush:\n", rounds);
    out("  %-34s %12s %14s %12s\n", "structure", "eps", "us / query", "visits");
    peer_us.assign(peers.size(), 0.0);
    for (std::size_t j = 0; j < passes.size(); ++j) {
      const Pass& p = passes[j];
      const double us = per[j] * 1e6;
      if (p.peer < 0) {
        for (std::size_t i = 0; i < qs.size(); ++i) {
          if (dist(pos_t[answers[j][i]], qs[i]) > (1.0 + p.eps) * exact[i] + 1e-9) ++violations;
        }
        out("  %-34s %12g %14.2f %12.1f\n", "kinetic longest-side kd-tree", p.eps, us, visits[j]);
      } else {
        const auto k = static_cast<std::size_t>(p.peer);
        if (p.eps == 0.1 || peer_us[k] == 0.0) peer_us[k] = us;
        out("  %-34s %12g %14.2f %12s\n", peers[k]->name.c_str(), p.eps, us, "-");
      }
    }
#if defined(KINETIC_BENCH_HAVE_CGAL)
    // Check CGAL's answers too (its returned point's distance).
    for (std::size_t k = 0; k < peers.size(); ++k) {
      auto* cg = dynamic_cast<CgalPeer*>(peers[k].get());
      if (cg == nullptr) continue;
      for (std::size_t i = 0; i < qs.size(); ++i) {
        cg->nearest(qs[i], 0.1);
        if (dist(cg->last, qs[i]) > 1.1 * exact[i] + 1e-9) ++violations;
      }
    }
#endif
#if defined(KINETIC_BENCH_HAVE_BOOST_GEOMETRY)
    // And Boost's (the distance of the point it returns).
    for (std::size_t k = 0; k < peers.size(); ++k) {
      const auto* bp = dynamic_cast<const BoostPeer*>(peers[k].get());
      if (bp == nullptr) continue;
      for (std::size_t i = 0; i < qs.size(); ++i) {
        if (dist(pos_t[bp->nearest(qs[i], 0.0)], qs[i]) > exact[i] + 1e-9) ++violations;
      }
    }
#endif
    out("  answers checked against the exact nearest distance: %llu violations so far\n",
        static_cast<unsigned long long>(violations));
    return first_us;
  };
  // Section 4's queries come at distinct times: each pays what a first pass pays.
  std::vector<double> peer_query_us;
  const double first_pass_us = time_nearest(t0, pos, peer_query_us);

  // 3. Events.
  out("\n## 3. Events from t0 until %llu are processed\n",
      static_cast<unsigned long long>(sizes.events));
  Handler h{&tree};
  c = cpu_now();
  std::uint64_t events = 0;
  while (events < sizes.events && !sim.queue().empty()) {
    sim.process_next(h);
    ++events;
  }
  const double event_cpu = cpu_now() - c;
  const double span = sim.now() - t0;
  const auto& lc = tree.counters();
  const double rate = static_cast<double>(events) / span;
  const double per_event_us = event_cpu / static_cast<double>(events) * 1e6;
  out("  simulated span %.3g (window [%g, %g]); %.3f s CPU, %.2f us per event\n", span, t0,
      *s.end_time, event_cpu, per_event_us);
  out("  ordering %llu, longest-side %llu (rebuilt below v %llu); %llu region certificates "
      "rescheduled by ordering events; %llu lengths certified as exact four-motion combinations "
      "(not double polynomials)\n",
      static_cast<unsigned long long>(lc.ordering_events),
      static_cast<unsigned long long>(lc.longest_side_events),
      static_cast<unsigned long long>(lc.longest_side_events_rebuilt_below),
      static_cast<unsigned long long>(lc.region_reschedules),
      static_cast<unsigned long long>(lc.combined_lengths));
  out("  event rate %.3g per unit of time: kinetic maintenance costs %.3g s CPU per unit "
      "of time\n",
      rate, rate * per_event_us * 1e-6);

  // 3b. The same queries after the events: the trie as the events left it (points deleted and
  // reinserted, regions split again), the peers built afresh on the positions at that time.
  const double t1 = sim.now();
  out("\n## 3b. (1+eps)-nearest after the events, at t1 = %g, the same query points; peers "
      "built on the positions at t1\n",
      t1);
  const std::vector<Pt> pos1 = positions(t1);
  for (auto& p : peers) p->build(pos1);
  std::vector<double> peer_query_us_after;
  (void)time_nearest(t1, pos1, peer_query_us_after);

  // 4. Q queries over that horizon: kinetic vs rebuilding a peer before each query.
  out("\n## 4. Q queries over the horizon [t0, t0 + %.3g]: kinetic (events + queries) vs "
      "rebuild a peer per query (build + query)\n",
      span);
  out("  %8s %16s", "Q", "kinetic (s)");
  for (const auto& p : peers) out(" %28s", (p->name + " (s)").c_str());
  out("\n");
  for (const int q : {1, 10, 100, 1000, 10000}) {
    const double kinetic_total = event_cpu + q * first_pass_us * 1e-6;
    out("  %8d %16.4f", q, kinetic_total);
    for (std::size_t k = 0; k < peers.size(); ++k) {
      out(" %28.4f", q * (peer_build[k] + peer_query_us[k] * 1e-6));
    }
    out("\n");
  }
  for (std::size_t k = 0; k < peers.size(); ++k) {
    const double per_query_saving = peer_build[k] + peer_query_us[k] * 1e-6 - first_pass_us * 1e-6;
    out("  break-even vs %s: %.3g queries per unit of time (kinetic cheaper above)\n",
        peers[k]->name.c_str(), rate * per_event_us * 1e-6 / per_query_saving);
  }
  // 5. The three schedulers side by side (exact beside robust and classic), over section 3's
  // horizon on the same motions.
  kinetic::bench::print_scheduler_table<LongestSideKdTree>("longest-side kd-tree", "random-linear",
                                                           motions, t0, t0 + span, 1e-9, 20.0);
  // 6. Inserts and removes: C of each, alternating (n stays the same), local.
  {
    const double t = sim.now();
    out("\n## 6. Inserts and removes at t = %g (n = %zu): %zu new random points inserted and %zu "
        "random live points removed, alternating\n",
        t, sizes.n, sizes.changes, sizes.changes);
    double box_lo[2] = {HUGE_VAL, HUGE_VAL}, box_hi[2] = {-HUGE_VAL, -HUGE_VAL};
    for (const std::uint32_t i : motions.alive_indices()) {
      for (int a = 0; a < 2; ++a) {
        const double x = motions.motion(i, a).evaluate(t);
        box_lo[a] = std::min(box_lo[a], x);
        box_hi[a] = std::max(box_hi[a], x);
      }
    }
    const kinetic::LongestSideCounters before = tree.counters();
    const kinetic::bench::ChurnTimes times = kinetic::bench::churn(
        tree, motions, sizes.changes, static_cast<kinetic::ObjectId>(10 * sizes.n), t,
        [&](std::size_t) {
          std::array<MotionPolynomial, 2> m;
          for (int a = 0; a < 2; ++a) {
            const std::array<double, 2> coeffs{box_lo[a] + (box_hi[a] - box_lo[a]) * u(rng),
                                               2 * u(rng) - 1};
            m[static_cast<std::size_t>(a)] = MotionPolynomial::from(coeffs, t);
          }
          return m;
        },
        rng);
    const double insert_cpu = times.insert_seconds, remove_cpu = times.remove_seconds;
    sim.note_external_change();
    const kinetic::LongestSideCounters& after = tree.counters();
    const bool valid_after = tree.validate();
    if (!valid_after) ++violations;
    const double ops = 2.0 * static_cast<double>(sizes.changes);
    out("| operation | mean CPU us | full rebuilds (an order laid out again) | points reinserted "
        "per operation | region certificates rescheduled per operation | regions split on "
        "their other side per operation | validate |\n"
        "|---|---:|---:|---:|---:|---:|---|\n");
    out("| insert | %.2f | %llu | %.2f | %.2f | %.3f | %s |\n",
        1e6 * insert_cpu / static_cast<double>(sizes.changes),
        static_cast<unsigned long long>(after.rebuilds - before.rebuilds),
        static_cast<double>(after.relabel_reinsertions - before.relabel_reinsertions) / ops,
        static_cast<double>(after.region_reschedules - before.region_reschedules) / ops,
        static_cast<double>(after.change_axis_flips - before.change_axis_flips) / ops,
        valid_after ? "ok" : "FAIL");
    out("| remove | %.2f | | | | | |\n", 1e6 * remove_cpu / static_cast<double>(sizes.changes));
    out("| (initialize: sorts + build) | %.0f | | | | | |\n", 1e6 * build_kinetic);
  }
  const double wall = wall_now() - wall0, cpu = cpu_now() - cpu0;
  out("\nWhole run: %.1f s wall, %.1f s CPU (wall/CPU %.2f: above 1, other processes shared "
      "the core)\n",
      wall, cpu, wall / std::max(1e-9, cpu));
  return violations == 0 ? 0 : 1;
}
