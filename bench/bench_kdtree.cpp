// Kinetic kd-tree benchmark (plain timing program, docs/performance/kdtree.md).
//
//  1. The query bound (Theorem 4): node visits of random boxes / (d^2 n^(1-1/d) + d k), over n,
//     d = 2 and 3.
//  2. Cost per event at n = 10^5 (2-D and 3-D), random linear motion, robust (eps 1e-9) and
//     classic schedulers.
//  3. Range query time against static peers built on the same positions at the same time, on the
//     same boxes: nanoflann (KDTreeSingleIndexAdaptor: ball around the box + filter), CGAL
//     Kd_tree (Fuzzy_iso_box search) and Boost.Geometry rtree (rstar, bulk loaded, intersects).
//     Every peer's answer is checked against the kinetic tree's on every timed query. The
//     kinetic tree is timed twice: range() (ids sorted, its contract) and range_unsorted() (the
//     same set unsorted, like the peers' answers); the private caches are flushed before each
//     timed pass, and the passes are interleaved over rounds (7, --quick 3) whose median is
//     reported, so that a slow moment of a shared machine does not fall on one structure.
//  3b. k nearest (k = 1, 10) against the same peers (nanoflann knnSearch, CGAL
//     Orthogonal_k_neighbor_search, Boost.Geometry nearest), checked rank by rank by distance,
//     and the break-even query rate against rebuilding each peer per query.
//  4. Q queries at arbitrary times over the horizon: the kinetic run + its queries against
//     rebuilding a peer before each query; the break-even query rate.
//  5. Inserts and removes at n = 10^5: 10^4 of each, alternating (local; amortized CPU time).
//  6. The three schedulers side by side (classic, robust, exact), 2-D, n and horizon of
//     section 2.
//
// Peers are benchmark-only dependencies: a missing one is reported as "not available".
// Options: --sizes=1000,...  (section 1)  --n=N (sections 2-5, 100000)  --seed=S  --quick
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <functional>
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
#include "kinetic/scenario/generators.hpp"
#include "scheduler_table.hpp"

#if defined(KINETIC_BENCH_HAVE_NANOFLANN)
#include <nanoflann.hpp>
#endif
#if defined(KINETIC_BENCH_HAVE_CGAL)
#include <CGAL/Fuzzy_iso_box.h>
#include <CGAL/Kd_tree.h>
#include <CGAL/Orthogonal_k_neighbor_search.h>
#include <CGAL/Search_traits_2.h>
#include <CGAL/Search_traits_3.h>
#include <CGAL/Search_traits_adapter.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/property_map.h>
#endif
#if defined(KINETIC_BENCH_HAVE_BOOST_GEOMETRY)
#include <boost/geometry.hpp>
#include <boost/geometry/index/rtree.hpp>
#include <boost/iterator/function_output_iterator.hpp>
#endif

using kinetic::bench::median_passes;
using kinetic::bench::out;

namespace {

using kinetic::bench::cpu_now;
using kinetic::bench::wall_now;

using kinetic::Box;
using kinetic::KineticKdTree;
using kinetic::MotionPolynomial;
using kinetic::MotionTable;
using kinetic::Scheduler;
using kinetic::SchedulerKind;
using kinetic::Simulator;
using Ids = std::vector<std::uint32_t>;

struct Handler {
  KineticKdTree* tree;
  kinetic::EventKind process(const kinetic::Event& e) { return tree->process(e); }
};

/// random-linear in d dimensions: positions uniform in [0, n^(1/d)]^d, velocities in [-1, 1]^d.
void fill(MotionTable& motions, int d, std::size_t n, std::uint64_t seed) {
  kinetic::scenario::GeneratorOptions o;
  o.n = n;
  o.seed = seed;
  o.dimension = d;
  const kinetic::scenario::Scenario s = kinetic::scenario::generate("random-linear", o);
  std::uint32_t expected = 0;
  for (const auto& obj : s.objects) {
    std::vector<MotionPolynomial> p;
    for (const auto& c : obj.motion.coordinates)
      p.push_back(MotionPolynomial::from(c, obj.motion.origin));
    const auto h = motions.insert(obj.id, p, 0.0);
    if (h.index != expected++) {
      std::fprintf(stderr, "unexpected object index\n");
      std::exit(2);
    }
  }
}

/// Positions at t (row-major n x d), evaluated in doubles: what a static structure is built on.
std::vector<double> positions(const MotionTable& motions, int d, double t) {
  const std::size_t n = motions.size();
  std::vector<double> out(n * static_cast<std::size_t>(d));
  for (std::uint32_t i = 0; i < n; ++i) {
    for (int a = 0; a < d; ++a)
      out[i * static_cast<std::size_t>(d) + static_cast<std::size_t>(a)] =
          motions.motion(i, a).evaluate(t);
  }
  return out;
}

std::array<std::vector<double>, 2> extent(const std::vector<double>& pos, int d) {
  std::array<std::vector<double>, 2> e{std::vector<double>(static_cast<std::size_t>(d), HUGE_VAL),
                                       std::vector<double>(static_cast<std::size_t>(d), -HUGE_VAL)};
  for (std::size_t i = 0; i < pos.size(); ++i) {
    const std::size_t a = i % static_cast<std::size_t>(d);
    e[0][a] = std::min(e[0][a], pos[i]);
    e[1][a] = std::max(e[1][a], pos[i]);
  }
  return e;
}

/// Box classes. "random": per axis two uniform values in the points' extent, sorted (every side
/// cuts the set; k ~ n / 3^d). "k=K": a cube centred at a uniform position of the extent whose
/// expected count is K (side = extent * (K / n)^(1/d)).
Box make_box(const std::array<std::vector<double>, 2>& ext, int d, std::size_t n, double k,
             std::mt19937_64& rng) {
  Box box(static_cast<std::size_t>(d));
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int a = 0; a < d; ++a) {
    const double lo = ext[0][static_cast<std::size_t>(a)], hi = ext[1][static_cast<std::size_t>(a)];
    if (k <= 0.0) {
      double x = lo + (hi - lo) * u(rng), y = lo + (hi - lo) * u(rng);
      if (x > y) std::swap(x, y);
      box[static_cast<std::size_t>(a)] = {x, y};
    } else {
      const double side = (hi - lo) * std::pow(k / static_cast<double>(n), 1.0 / d);
      const double c = lo + (hi - lo) * u(rng);
      box[static_cast<std::size_t>(a)] = {c - side / 2, c + side / 2};
    }
  }
  return box;
}

// ---------------------------------------------------------------------------------------------
// Answer checks.

struct Check {
  std::uint64_t queries = 0, boundary_ties = 0, mismatches = 0;
};

/// Compares a peer's answer (any order) with the kinetic one (ascending). A difference is a tie
/// when the point lies within 1e-12 of a box side (in doubles at t); otherwise a mismatch.
void compare(const Ids& kinetic_ids, Ids peer, const Box& box, const std::vector<double>& pos,
             int d, const char* who, Check& c) {
  ++c.queries;
  std::sort(peer.begin(), peer.end());
  if (peer == kinetic_ids) return;
  Ids diff;
  std::set_symmetric_difference(kinetic_ids.begin(), kinetic_ids.end(), peer.begin(), peer.end(),
                                std::back_inserter(diff));
  bool tie_only = true;
  for (const std::uint32_t i : diff) {
    bool near = false;
    for (int a = 0; a < d; ++a) {
      const double x = pos[i * static_cast<std::size_t>(d) + static_cast<std::size_t>(a)];
      const auto& b = box[static_cast<std::size_t>(a)];
      near = near || std::fabs(x - b[0]) <= 1e-12 || std::fabs(x - b[1]) <= 1e-12;
    }
    tie_only = tie_only && near;
  }
  if (tie_only) {
    ++c.boundary_ties;
  } else {
    ++c.mismatches;
    out("MISMATCH (%s): kinetic %zu ids, peer %zu ids, %zu differ\n", who, kinetic_ids.size(),
        peer.size(), diff.size());
  }
}

// ---------------------------------------------------------------------------------------------
// Static peers, built from the positions at one time.

struct Peer {
  std::string name;
  virtual ~Peer() = default;
  virtual void build(const std::vector<double>& pos) = 0;
  virtual void query(const Box& box, Ids& out) const = 0;
  /// The k nearest to q (its own order; checked by distance).
  virtual void k_nearest(const double* q, std::size_t k, Ids& out) const = 0;
};

#if defined(KINETIC_BENCH_HAVE_NANOFLANN)
struct Cloud {
  const std::vector<double>* pos = nullptr;
  std::size_t d = 0;
  [[nodiscard]] std::size_t kdtree_get_point_count() const { return pos->size() / d; }
  [[nodiscard]] double kdtree_get_pt(std::size_t i, std::size_t a) const {
    return (*pos)[i * d + a];
  }
  template <class B>
  bool kdtree_get_bbox(B& /*unused*/) const {
    return false;
  }
};

/// nanoflann 1.4 has no box query: the box is searched as its circumscribed ball (L2, squared
/// radius widened by 1e-9 relative so that corners are inside), and a custom result set keeps
/// the points inside the closed box.
template <int D>
struct NanoflannPeer : Peer {
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Cloud>,
                                                   Cloud, D, std::uint32_t>;
  struct BoxResult {
    const Cloud* cloud;
    const Box* box;
    double r2;
    Ids* out;
    bool addPoint(double /*dist*/, std::uint32_t i) {
      for (std::size_t a = 0; a < D; ++a) {
        const double x = cloud->kdtree_get_pt(i, a);
        if (x < (*box)[a][0] || x > (*box)[a][1]) return true;
      }
      out->push_back(i);
      return true;
    }
    [[nodiscard]] double worstDist() const { return r2; }
    [[nodiscard]] bool full() const { return true; }
  };
  Cloud cloud;
  std::unique_ptr<Tree> tree;
  NanoflannPeer() { name = "nanoflann"; }
  void build(const std::vector<double>& pos) override {
    cloud.pos = &pos;
    cloud.d = D;
    tree = std::make_unique<Tree>(D, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  }
  void query(const Box& box, Ids& out) const override {
    std::array<double, D> c{};
    double r2 = 0.0;
    for (std::size_t a = 0; a < D; ++a) {
      c[a] = 0.5 * (box[a][0] + box[a][1]);
      const double h = 0.5 * (box[a][1] - box[a][0]);
      r2 += h * h;
    }
    BoxResult res{&cloud, &box, r2 * (1 + 1e-9) + 1e-300, &out};
    tree->findNeighbors(res, c.data(), nanoflann::SearchParams(32, 0.0F, false));
  }
  void k_nearest(const double* q, std::size_t k, Ids& out) const override {
    out.resize(k);
    std::array<double, 64> d2{};
    out.resize(tree->knnSearch(q, k, out.data(), d2.data()));
  }
};
#endif

#if defined(KINETIC_BENCH_HAVE_CGAL)
template <int D>
struct CgalPeer : Peer {
  using K = CGAL::Simple_cartesian<double>;
  using Point = std::conditional_t<D == 2, K::Point_2, K::Point_3>;
  using Base = std::conditional_t<D == 2, CGAL::Search_traits_2<K>, CGAL::Search_traits_3<K>>;
  using Traits =
      CGAL::Search_traits_adapter<std::uint32_t, typename CGAL::Pointer_property_map<Point>::type,
                                  Base>;
  using Tree = CGAL::Kd_tree<Traits>;
  using PeerBox = CGAL::Fuzzy_iso_box<Traits>;
  std::vector<Point> points;
  std::unique_ptr<Tree> tree;
  CgalPeer() { name = "CGAL Kd_tree"; }
  static Point make(const double* x) {
    if constexpr (D == 2) {
      return Point(x[0], x[1]);
    } else {
      return Point(x[0], x[1], x[2]);
    }
  }
  void build(const std::vector<double>& pos) override {
    const std::size_t n = pos.size() / D;
    points.resize(n);
    std::vector<std::uint32_t> ids(n);
    for (std::size_t i = 0; i < n; ++i) {
      points[i] = make(&pos[i * D]);
      ids[i] = static_cast<std::uint32_t>(i);
    }
    tree = std::make_unique<Tree>(ids.begin(), ids.end(), typename Tree::Splitter(),
                                  Traits(CGAL::make_property_map(points)));
    tree->build();
  }
  void query(const Box& box, Ids& out) const override {
    std::array<double, D> lo{}, hi{};
    for (std::size_t a = 0; a < D; ++a) {
      lo[a] = box[a][0];
      hi[a] = box[a][1];
    }
    const PeerBox q(make(lo.data()), make(hi.data()), 0.0, tree->traits());
    tree->search(std::back_inserter(out), q);
  }
  using Knn = CGAL::Orthogonal_k_neighbor_search<Traits>;
  void k_nearest(const double* q, std::size_t k, Ids& out) const override {
    const typename Knn::Distance distance(tree->traits().point_property_map());
    const Knn search(*tree, make(q), static_cast<unsigned>(k), 0.0, true, distance);
    for (auto it = search.begin(); it != search.end(); ++it) out.push_back(it->first);
  }
};
#endif

#if defined(KINETIC_BENCH_HAVE_BOOST_GEOMETRY)
template <int D>
struct BoostPeer : Peer {
  using Point = boost::geometry::model::point<double, D, boost::geometry::cs::cartesian>;
  using PeerBox = boost::geometry::model::box<Point>;
  using Value = std::pair<Point, std::uint32_t>;
  using Tree = boost::geometry::index::rtree<Value, boost::geometry::index::rstar<16>>;
  std::unique_ptr<Tree> tree;
  BoostPeer() { name = "Boost.Geometry rtree"; }
  static Point make(const double* x) {
    Point p;
    boost::geometry::set<0>(p, x[0]);
    boost::geometry::set<1>(p, x[1]);
    if constexpr (D == 3) boost::geometry::set<2>(p, x[2]);
    return p;
  }
  void build(const std::vector<double>& pos) override {
    const std::size_t n = pos.size() / D;
    std::vector<Value> values(n);
    for (std::size_t i = 0; i < n; ++i)
      values[i] = {make(&pos[i * D]), static_cast<std::uint32_t>(i)};
    tree = std::make_unique<Tree>(values.begin(), values.end());  // packing (bulk loading)
  }
  void query(const Box& box, Ids& out) const override {
    std::array<double, D> lo{}, hi{};
    for (std::size_t a = 0; a < D; ++a) {
      lo[a] = box[a][0];
      hi[a] = box[a][1];
    }
    const PeerBox b(make(lo.data()), make(hi.data()));
    tree->query(
        boost::geometry::index::intersects(b),
        boost::make_function_output_iterator([&out](const Value& v) { out.push_back(v.second); }));
  }
  void k_nearest(const double* q, std::size_t k, Ids& out) const override {
    tree->query(
        boost::geometry::index::nearest(make(q), static_cast<unsigned>(k)),
        boost::make_function_output_iterator([&out](const Value& v) { out.push_back(v.second); }));
  }
};
#endif

template <int D>
std::vector<std::unique_ptr<Peer>> make_peers() {
  std::vector<std::unique_ptr<Peer>> peers;
#if defined(KINETIC_BENCH_HAVE_NANOFLANN)
  peers.push_back(std::make_unique<NanoflannPeer<D>>());
#endif
#if defined(KINETIC_BENCH_HAVE_CGAL)
  peers.push_back(std::make_unique<CgalPeer<D>>());
#endif
#if defined(KINETIC_BENCH_HAVE_BOOST_GEOMETRY)
  peers.push_back(std::make_unique<BoostPeer<D>>());
#endif
  return peers;
}

void print_missing_peers() {
#if !defined(KINETIC_BENCH_HAVE_NANOFLANN)
  out("  peer nanoflann: not available\n");
#endif
#if !defined(KINETIC_BENCH_HAVE_CGAL)
  out("  peer CGAL Kd_tree: not available\n");
#endif
#if !defined(KINETIC_BENCH_HAVE_BOOST_GEOMETRY)
  out("  peer Boost.Geometry rtree: not available\n");
#endif
}

// ---------------------------------------------------------------------------------------------
// 1. The query bound.

void section_bound(const std::vector<std::size_t>& sizes, std::uint64_t seed, int boxes) {
  out("\n1. Query bound: node visits / (d^2 n^(1-1/d) + d k), %d boxes per class, t = 0\n", boxes);
  out("| d | n | boxes | mean k | mean visits | mean visits / bound | max visits / bound | "
      "max visits / (d^2 n^(1-1/d)) |\n");
  out("|---:|---:|---|---:|---:|---:|---:|---:|\n");
  for (const int d : {2, 3}) {
    for (const std::size_t n : sizes) {
      MotionTable motions(d);
      fill(motions, d, n, seed);
      Simulator sim(0.0);
      const Scheduler sched(SchedulerKind::Classic, 1e-9, 1e-9);
      KineticKdTree tree(motions, sim, sched);
      tree.initialize();
      const std::vector<double> pos = positions(motions, d, 0.0);
      const auto ext = extent(pos, d);
      const double base = d * d * std::pow(static_cast<double>(n), 1.0 - 1.0 / d);
      for (const double kk : {0.0, 100.0}) {
        std::mt19937_64 rng(seed * 7919 + n + static_cast<std::uint64_t>(d));
        double sum_k = 0, sum_v = 0, sum_r = 0, max_r = 0, max_b = 0;
        for (int q = 0; q < boxes; ++q) {
          const Box box = make_box(ext, d, n, kk, rng);
          const Ids ids = tree.range(box, 0.0);
          const auto v = static_cast<double>(tree.counters().last_query_visits);
          const double k = static_cast<double>(ids.size());
          const double r = v / (base + d * k);
          sum_k += k;
          sum_v += v;
          sum_r += r;
          max_r = std::max(max_r, r);
          max_b = std::max(max_b, v / base);
        }
        out("| %d | %zu | %s | %.0f | %.0f | %.3f | %.3f | %.3f |\n", d, n,
            kk == 0.0 ? "random" : "k=100", sum_k / boxes, sum_v / boxes, sum_r / boxes, max_r,
            max_b);
        std::fflush(stdout);
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// 2-5 at one n.

struct Timed {
  double seconds = 0;
  std::uint64_t count = 0;
};

template <int D>
bool sections_motion(std::size_t n, std::uint64_t seed, double horizon, int q_interleaved,
                     int boxes_per_class, int rounds, Check& check) {
  constexpr int d = D;
  out("\n=== d = %d, n = %zu, horizon [0, %g] ===\n", d, n, horizon);
  MotionTable motions(d);
  fill(motions, d, n, seed);
  auto peers = make_peers<D>();

  // 2. Classic run (no queries).
  double classic_cpu = 0, classic_wall = 0;
  std::uint64_t classic_events = 0;
  {
    Simulator sim(0.0);
    const Scheduler sched(SchedulerKind::Classic, 1e-9, horizon);
    KineticKdTree tree(motions, sim, sched);
    tree.initialize();
    Handler h{&tree};
    const double c0 = cpu_now(), w0 = wall_now();
    (void)sim.advance_to(horizon, h);
    classic_cpu = cpu_now() - c0;
    classic_wall = wall_now() - w0;
    classic_events = tree.counters().swaps;
  }

  // Robust run, with q_interleaved queries at evenly spaced times (section 4).
  Simulator sim(0.0);
  const Scheduler sched(SchedulerKind::Robust, 1e-9, horizon);
  KineticKdTree tree(motions, sim, sched);
  double c0 = cpu_now();
  tree.initialize();
  const double init_cpu = cpu_now() - c0;
  Handler h{&tree};
  double advance_cpu = 0, advance_wall = 0;
  Timed kq;
  std::vector<Timed> eval(peers.size()), build(peers.size()), pq(peers.size());
  std::mt19937_64 rng(seed * 31 + static_cast<std::uint64_t>(d));
  for (int q = 0; q < q_interleaved; ++q) {
    const double t = horizon * (q + 1) / q_interleaved;
    c0 = cpu_now();
    const double w0 = wall_now();
    (void)sim.advance_to(t, h);
    advance_cpu += cpu_now() - c0;
    advance_wall += wall_now() - w0;
    const std::vector<double> pos0 = positions(motions, d, t);
    const Box box = make_box(extent(pos0, d), d, n, 1000.0, rng);
    c0 = cpu_now();
    const Ids kids = tree.range(box, t);
    kq.seconds += cpu_now() - c0;
    ++kq.count;
    for (std::size_t p = 0; p < peers.size(); ++p) {
      c0 = cpu_now();
      const std::vector<double> pos = positions(motions, d, t);
      eval[p].seconds += cpu_now() - c0;
      c0 = cpu_now();
      peers[p]->build(pos);
      build[p].seconds += cpu_now() - c0;
      Ids out;
      c0 = cpu_now();
      peers[p]->query(box, out);
      pq[p].seconds += cpu_now() - c0;
      compare(kids, std::move(out), box, pos, d, peers[p]->name.c_str(), check);
    }
  }
  const std::uint64_t robust_events = tree.counters().swaps;
  const bool valid = tree.validate();

  out("\n2. Events over [0, %g] (n = %zu, d = %d): setup (sorts + build) %.3f s; tree "
      "validate() after the run: %s; robust run: %llu reinsertions, %llu compactions\n",
      horizon, n, d, init_cpu, valid ? "ok" : "FAIL",
      static_cast<unsigned long long>(tree.counters().reinsertions),
      static_cast<unsigned long long>(tree.counters().compactions));
  out("| scheduler | events (swaps) | events per unit time | CPU s | us/event | wall/CPU |\n");
  out("|---|---:|---:|---:|---:|---:|\n");
  out("| classic | %llu | %.3g | %.3f | %.3f | %.2f |\n",
      static_cast<unsigned long long>(classic_events),
      static_cast<double>(classic_events) / horizon, classic_cpu,
      1e6 * classic_cpu / static_cast<double>(std::max<std::uint64_t>(1, classic_events)),
      classic_wall / std::max(1e-9, classic_cpu));
  out("| robust eps 1e-9 | %llu | %.3g | %.3f | %.3f | %.2f |\n",
      static_cast<unsigned long long>(robust_events), static_cast<double>(robust_events) / horizon,
      advance_cpu,
      1e6 * advance_cpu / static_cast<double>(std::max<std::uint64_t>(1, robust_events)),
      advance_wall / std::max(1e-9, advance_cpu));
  std::fflush(stdout);

  // 3. Query times at t = horizon, same boxes for every structure.
  const double t = horizon;
  const std::vector<double> pos = positions(motions, d, t);
  const auto ext = extent(pos, d);
  for (std::size_t p = 0; p < peers.size(); ++p) peers[p]->build(pos);
  out("\n3. Range queries at t = %g (n = %zu, d = %d): us per query (CPU), %d boxes per class, "
      "the median of %d interleaved rounds (each pass after a cache flush); peers built on the "
      "positions at t\n",
      t, n, d, boxes_per_class, rounds);
  out("| boxes | mean k | kinetic range() (std::sort of its answer) | kinetic "
      "range_unsorted() | mean visits |");
  for (const auto& p : peers) out(" %s |", p->name.c_str());
  out(" range() / best peer | range_unsorted() / best peer |\n|---|---:|---:|---:|---:|");
  for (std::size_t p = 0; p < peers.size(); ++p) out("---:|");
  out("---:|---:|\n");
  std::string pending_note;  // printed after the table
  for (const double kk : {10.0, 1000.0, 0.0}) {
    std::vector<Box> boxes;
    for (int b = 0; b < boxes_per_class; ++b) boxes.push_back(make_box(ext, d, n, kk, rng));
    // The passes: range() (its answers sorted: part of its contract), range_unsorted() (one
    // fresh vector per box, as for the peers), each peer; interleaved over the rounds.
    std::vector<Ids> kin(boxes.size()), unsorted(boxes.size());
    std::vector<std::vector<Ids>> outs(peers.size());
    // The first class's first pass: the scans evaluate the runs they read at t (the leaves'
    // values, points and groups' boxes) and keep them for the next queries at t (only section
    // 4's last query, one k=1000 box, came at t before).
    double first_pass = -1.0;
    if (kk == 10.0) {
      kinetic::bench::flush_caches();
      const double c = cpu_now();
      for (std::size_t b = 0; b < boxes.size(); ++b) tree.range_unsorted(boxes[b], t, unsorted[b]);
      first_pass = (cpu_now() - c) / static_cast<double>(boxes.size());
    }
    const std::uint64_t v0 = tree.counters().node_visits;
    const std::vector<double> s = median_passes(rounds, 2 + peers.size(), [&](std::size_t k) {
      double c = 0;
      if (k == 0) {
        c = cpu_now();
        for (std::size_t b = 0; b < boxes.size(); ++b) kin[b] = tree.range(boxes[b], t);
      } else if (k == 1) {
        unsorted.assign(boxes.size(), Ids{});
        c = cpu_now();
        for (std::size_t b = 0; b < boxes.size(); ++b)
          tree.range_unsorted(boxes[b], t, unsorted[b]);
      } else {
        outs[k - 2].assign(boxes.size(), Ids{});
        c = cpu_now();
        for (std::size_t b = 0; b < boxes.size(); ++b)
          peers[k - 2]->query(boxes[b], outs[k - 2][b]);
      }
      return (cpu_now() - c) / static_cast<double>(boxes.size());
    });
    const double kin_s = s[0], uns_s = s[1];
    const double visits = static_cast<double>(tree.counters().node_visits - v0) /
                          static_cast<double>(2 * rounds * static_cast<int>(boxes.size()));
    double sum_k = 0;
    for (const auto& ids : kin) sum_k += static_cast<double>(ids.size());
    // The share of range() spent sorting its answer (ascending ids, part of its contract; the
    // peers' answers are not sorted): the same answers, shuffled untimed, sorted timed.
    double sort_s = 0;
    for (const auto& ids : kin) {
      Ids copy = ids;
      std::shuffle(copy.begin(), copy.end(), rng);
      c0 = cpu_now();
      std::sort(copy.begin(), copy.end());
      sort_s += cpu_now() - c0;
    }
    sort_s /= static_cast<double>(boxes.size());
    for (std::size_t b = 0; b < boxes.size(); ++b) {
      std::sort(unsorted[b].begin(), unsorted[b].end());
      if (unsorted[b] != kin[b]) {
        ++check.mismatches;
        out("MISMATCH (range_unsorted): %zu ids, range() %zu ids\n", unsorted[b].size(),
            kin[b].size());
      }
    }
    out("| %s | %.0f | %.2f (sort %.2f) | %.2f | %.0f |",
        kk == 0.0 ? "random" : (kk == 10.0 ? "k=10" : "k=1000"),
        sum_k / static_cast<double>(boxes.size()), 1e6 * kin_s, 1e6 * sort_s, 1e6 * uns_s, visits);
    double best = HUGE_VAL;
    for (std::size_t p = 0; p < peers.size(); ++p) {
      best = std::min(best, s[2 + p]);
      out(" %.2f |", 1e6 * s[2 + p]);
      for (std::size_t b = 0; b < boxes.size(); ++b)
        compare(kin[b], std::move(outs[p][b]), boxes[b], pos, d, peers[p]->name.c_str(), check);
    }
    if (peers.empty()) {
      out(" - | - |\n");
    } else {
      out(" %.2f | %.2f |\n", kin_s / best, uns_s / best);
    }
    if (first_pass >= 0.0) {
      char line[200];
      std::snprintf(line, sizeof line,
                    "the k=10 boxes' first pass at t (the scans evaluate the runs they read at t "
                    "and keep them): %.2f us per query (range_unsorted)\n",
                    1e6 * first_pass);
      pending_note = line;
    }
    std::fflush(stdout);
  }
  out("%s", pending_note.c_str());

  // 3b. k nearest at t = horizon, k = 1 and 10, from points uniform in the points' extent.
  const double K = advance_cpu / horizon;  // kinetic CPU per unit time
  out("\n3b. k nearest at t = %g (n = %zu, d = %d): us per query (CPU), %d query points "
      "uniform in the points' extent, the median of %d interleaved rounds as in section 3; "
      "peers built on the positions at t. Break-even: queries "
      "per unit time above which the kinetic tree (its run, %.3g CPU s per unit time, and its "
      "queries) beats evaluating the positions, building the peer and querying it per query "
      "(evaluate and build as in section 4)\n",
      t, n, d, boxes_per_class, rounds, K);
  out("| k | kinetic k_nearest() | mean visits |");
  for (const auto& p : peers) out(" %s |", p->name.c_str());
  out(" kinetic / best peer |");
  for (const auto& p : peers) out(" break-even vs %s |", p->name.c_str());
  out("\n|---:|---:|---:|");
  for (std::size_t p = 0; p < 2 * peers.size() + 1; ++p) out("---:|");
  out("\n");
  std::string first_lines;  // the first passes, printed after the table
  for (const std::size_t k : {std::size_t{1}, std::size_t{10}}) {
    std::vector<std::array<double, D>> qs(static_cast<std::size_t>(boxes_per_class));
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (auto& q : qs)
      for (std::size_t a = 0; a < D; ++a) q[a] = ext[0][a] + (ext[1][a] - ext[0][a]) * u(rng);
    auto distance = [&](std::uint32_t i, const std::array<double, D>& q) {
      double s2 = 0;
      for (std::size_t a = 0; a < D; ++a) s2 += (pos[i * D + a] - q[a]) * (pos[i * D + a] - q[a]);
      return std::sqrt(s2);
    };
    std::vector<Ids> kin(qs.size());
    std::vector<std::vector<Ids>> outs(peers.size());
    Ids buffer;
    // The first pass with nothing kept at t: one point's motion given again (the same motion, a
    // change all the same: the point is erased and reinserted, the tree stays the one a build
    // gives), which drops what the queries before kept at this time; the searches then evaluate
    // the runs they read and keep them.
    {
      const std::uint32_t p = motions.alive_indices().front();
      std::vector<MotionPolynomial> same;
      for (int a = 0; a < d; ++a) same.push_back(motions.motion(p, a));
      motions.update(motions.handle(p), same, t);
      tree.motion_changed(p);
      sim.note_external_change();
    }
    kinetic::bench::flush_caches();
    const double first_c = cpu_now();
    for (std::size_t j = 0; j < qs.size(); ++j) tree.k_nearest(qs[j], k, 0.0, t, buffer);
    const double first_pass = (cpu_now() - first_c) / static_cast<double>(qs.size());
    const std::uint64_t v0 = tree.counters().node_visits;
    const std::vector<double> s = median_passes(rounds, 1 + peers.size(), [&](std::size_t p) {
      double c = 0;
      if (p == 0) {
        c = cpu_now();
        for (std::size_t j = 0; j < qs.size(); ++j) {
          tree.k_nearest(qs[j], k, 0.0, t, buffer);
          kin[j] = buffer;
        }
      } else {
        outs[p - 1].assign(qs.size(), Ids{});
        c = cpu_now();
        for (std::size_t j = 0; j < qs.size(); ++j)
          peers[p - 1]->k_nearest(qs[j].data(), k, outs[p - 1][j]);
      }
      return (cpu_now() - c) / static_cast<double>(qs.size());
    });
    const double kin_s = s[0];
    const double visits = static_cast<double>(tree.counters().node_visits - v0) /
                          static_cast<double>(rounds * static_cast<int>(qs.size()));
    out("| %zu | %.2f | %.0f |", k, 1e6 * kin_s, visits);
    double best = HUGE_VAL;
    std::vector<double> peer_s(peers.size());
    for (std::size_t p = 0; p < peers.size(); ++p) {
      peer_s[p] = s[1 + p];
      best = std::min(best, peer_s[p]);
      out(" %.2f |", 1e6 * peer_s[p]);
      // The same distances rank by rank (the peers order ties their own way).
      for (std::size_t j = 0; j < qs.size(); ++j) {
        ++check.queries;
        std::vector<double> a, b;
        for (const std::uint32_t i : kin[j]) a.push_back(distance(i, qs[j]));
        for (const std::uint32_t i : outs[p][j]) b.push_back(distance(i, qs[j]));
        std::sort(b.begin(), b.end());
        bool same = a.size() == b.size();
        for (std::size_t r = 0; same && r < a.size(); ++r)
          same = std::fabs(a[r] - b[r]) <= 1e-12 * (1.0 + a[r]);
        if (!same) {
          ++check.mismatches;
          out("MISMATCH (k_nearest, %s): k = %zu\n", peers[p]->name.c_str(), k);
        }
      }
    }
    out(" %.2f |", peers.empty() ? 0.0 : kin_s / best);
    const double qn = static_cast<double>(q_interleaved);
    for (std::size_t p = 0; p < peers.size(); ++p) {
      const double per = (eval[p].seconds + build[p].seconds) / qn + peer_s[p];
      out(" %.3g |", per > kin_s ? K / (per - kin_s) : HUGE_VAL);
    }
    out("\n");
    char line[120];
    std::snprintf(line, sizeof line, "k = %zu: %.2f us per query (%.2fx the best peer)\n", k,
                  1e6 * first_pass, peers.empty() ? 0.0 : first_pass / best);
    first_lines += line;
    std::fflush(stdout);
  }
  out("first pass at t with nothing kept (after a change at t: the searches evaluate the runs they "
      "read and keep them):\n%s",
      first_lines.c_str());

  // 4. Q queries at arbitrary times over the horizon.
  const double kq_s = kq.seconds / static_cast<double>(std::max<std::uint64_t>(1, kq.count));
  out("\n4. %d queries (k=1000 boxes) at evenly spaced times over [0, %g] (n = %zu, d = %d): "
      "kinetic = robust run + its queries; a peer evaluates the n positions at the query "
      "time, builds, queries\n",
      q_interleaved, horizon, n, d);
  out("| structure | per query: evaluate | build | query | total per query | total over the "
      "%d queries | break-even (queries per unit time) |\n",
      q_interleaved);
  out("|---|---:|---:|---:|---:|---:|---:|\n");
  out("| kinetic (run %.3f s = %.3g s per unit time) | - | - | %.1f us | %.1f us | %.3f s | - |\n",
      advance_cpu, K, 1e6 * kq_s, 1e6 * kq_s, advance_cpu + kq.seconds);
  for (std::size_t p = 0; p < peers.size(); ++p) {
    const double qn = static_cast<double>(q_interleaved);
    const double e = eval[p].seconds / qn, b = build[p].seconds / qn, qq = pq[p].seconds / qn;
    const double per = e + b + qq;
    out("| %s | %.0f us | %.0f us | %.1f us | %.0f us | %.3f s | %.3g |\n", peers[p]->name.c_str(),
        1e6 * e, 1e6 * b, 1e6 * qq, 1e6 * per, per * qn, per > kq_s ? K / (per - kq_s) : HUGE_VAL);
  }
  std::fflush(stdout);

  // 5. Inserts and removes: 10^4 of each, alternating (n stays the same), local.
  constexpr std::size_t kChanges = 10000;
  out("\n5. Inserts and removes at t = %g (n = %zu, d = %d): %zu new random points inserted and "
      "%zu random live points removed, alternating\n",
      t, n, d, kChanges, kChanges);
  const kinetic::KdTreeCounters before = tree.counters();
  const kinetic::bench::ChurnTimes times = kinetic::bench::churn(
      tree, motions, kChanges, static_cast<kinetic::ObjectId>(10 * n), t,
      [&](std::size_t) {
        std::vector<MotionPolynomial> p;
        std::uniform_real_distribution<double> u(0.0, 1.0);
        for (int a = 0; a < d; ++a) {
          const double side =
              ext[1][static_cast<std::size_t>(a)] - ext[0][static_cast<std::size_t>(a)];
          const std::array<double, 2> c{ext[0][static_cast<std::size_t>(a)] + side * u(rng),
                                        2 * u(rng) - 1};
          p.push_back(MotionPolynomial::from(c, t));
        }
        return p;
      },
      rng);
  sim.note_external_change();
  const kinetic::KdTreeCounters& after = tree.counters();
  out("| operation | mean CPU us | trees rebuilt (an order laid out again) | points reinserted "
      "for moved labels, per operation | validate |\n|---|---:|---:|---:|---|\n");
  const bool valid2 = tree.validate();
  out("| insert | %.2f | %llu | %.2f | %s |\n",
      1e6 * times.insert_seconds / static_cast<double>(kChanges),
      static_cast<unsigned long long>(after.rebuilds - before.rebuilds),
      static_cast<double>(after.relabel_reinsertions - before.relabel_reinsertions) /
          static_cast<double>(2 * kChanges),
      valid2 ? "ok" : "FAIL");
  out("| remove | %.2f | | | |\n", 1e6 * times.remove_seconds / static_cast<double>(kChanges));
  out("| (initialize: sorts + build) | %.0f | | | |\n", 1e6 * init_cpu);
  std::fflush(stdout);
  return valid && valid2;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::size_t> sizes = {1000, 10000, 100000, 1000000};
  std::size_t n = 100000;
  std::uint64_t seed = 1;
  bool quick = false;
  kinetic::bench::Harness harness(
      "bench_kdtree",
      "the kinetic rank-based kd-tree (range and k-nearest queries) against static "
      "peers rebuilt per query (nanoflann, CGAL, Boost.Geometry); times "
      "are process CPU");
  harness.sizes(sizes, "section 1's sizes n");
  harness.option("--n", n, "points in sections 2-5");
  harness.seed(seed);
  harness.quick(quick, "sizes 10^3 to 10^5 and a tenth of the swaps");
  harness.parse(argc, argv);
  if (quick && !harness.given("--sizes")) sizes = {1000, 10000, 100000};
  harness.configured();
  // Horizons giving about 2 * 10^6 swaps at any n (a tenth with --quick): a pair crosses on
  // an axis within [0, T] with probability ~ (2/3) T / n^(1/d), so swaps ~ n^(2-1/d) T.
  const double scale = quick ? 0.1 : 1.0;
  const double horizon2 =
      0.1 * scale * std::sqrt(1e5 / static_cast<double>(n)) * 1e5 / static_cast<double>(n);
  const double c3 = std::cbrt(1e5 / static_cast<double>(n));
  const double horizon3 = 0.01 * scale * c3 * c3 * 1e5 / static_cast<double>(n);
  const int q_interleaved = quick ? 10 : 40;
  const int boxes_bound = quick ? 100 : 200;
  const int boxes_query = quick ? 100 : 300;
  const int rounds = quick ? 3 : 7;  // sections 3 and 3b: the median of interleaved rounds
  const double wall0 = wall_now(), cpu0 = cpu_now();

  out("bench_kdtree: kinetic rank-based kd-tree, dataset random-linear (positions uniform in\n");
  out("  [0, n^(1/d)]^d, velocities uniform in [-1, 1]^d), seed %llu\n",
      static_cast<unsigned long long>(seed));
  out("  section 1 sizes:");
  for (const std::size_t s : sizes) out(" %zu", s);
  out("; sections 2-5: n = %zu, horizons %g (2-D) and %g (3-D), robust eps 1e-9\n", n, horizon2,
      horizon3);
  print_missing_peers();
#if defined(KINETIC_BENCH_HAVE_NANOFLANN)
  out("  peer nanoflann %d.%d.%d: KDTreeSingleIndexAdaptor (L2, leaf size 10), box searched "
      "as its circumscribed ball + filter\n",
      NANOFLANN_VERSION >> 8, (NANOFLANN_VERSION >> 4) & 0xF, NANOFLANN_VERSION & 0xF);
#endif
#if defined(KINETIC_BENCH_HAVE_CGAL)
  out("  peer CGAL %s: Kd_tree (Search_traits_2/3 + adapter for ids, default sliding "
      "midpoint splitter, bucket 10), Fuzzy_iso_box eps 0\n",
      CGAL_VERSION_STR);
#endif
#if defined(KINETIC_BENCH_HAVE_BOOST_GEOMETRY)
  out("  peer Boost %d.%d: geometry::index::rtree<rstar<16>>, bulk loaded (packing), "
      "query(intersects(box))\n",
      BOOST_VERSION / 100000, BOOST_VERSION / 100 % 1000);
#endif

  section_bound(sizes, seed, boxes_bound);
  Check check;
  bool ok = sections_motion<2>(n, seed, horizon2, q_interleaved, boxes_query, rounds, check);
  ok = sections_motion<3>(n, seed, horizon3, q_interleaved, boxes_query, rounds, check) && ok;

  out("\nAnswer checks: %llu peer answers compared with the kinetic tree's, %llu differ only "
      "by a point within 1e-12 of a box side, %llu mismatches\n",
      static_cast<unsigned long long>(check.queries),
      static_cast<unsigned long long>(check.boundary_ties),
      static_cast<unsigned long long>(check.mismatches));
  {  // 6. The three schedulers side by side (exact beside robust and classic), 2-D.
    MotionTable side(2);
    fill(side, 2, n, seed);
    kinetic::bench::print_scheduler_table<kinetic::KineticKdTree>(
        "kd-tree (2-D)", "random-linear", side, 0.0, horizon2, 1e-9, quick ? 10.0 : 30.0);
  }
  const double wall = wall_now() - wall0, cpu = cpu_now() - cpu0;
  out("Whole run: %.1f s wall, %.1f s CPU (wall/CPU %.2f: above 1, other processes shared "
      "the core)\n",
      wall, cpu, wall / std::max(1e-9, cpu));
  return check.mismatches == 0 && ok ? 0 : 1;
}
