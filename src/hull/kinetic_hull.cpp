#include "kinetic/hull/kinetic_hull.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cstring>
#include <string>

#include "kinetic/core/crop.hpp"
#include "kinetic/core/free_list.hpp"
#include "kinetic/core/predicates.hpp"

namespace kinetic {

// The records behind KineticHull (declared in its header, laid out here).

/// name_smallest_coincident()'s target: a vertex of the answer (its place in the polygon), a
/// point of a chain at its position and its x at the query time.
struct KineticHull::Target {
  std::uint32_t slot;
  std::uint32_t point;
  FilteredValue x;
};

/// One comparison of a node's merge: its kind and points, and the sign decided. Kept both in
/// the certificate and beside the certificate's id in the node's list, so that a re-merge
/// finds the tests it asks again without touching the certificates.
struct KineticHull::Test {
  std::uint32_t p[4] = {kNoIndex, kNoIndex, kNoIndex, kNoIndex};
  std::int8_t kind = 0;  ///< Kind in kinetic_hull.cpp
  std::int8_t sign = 0;  ///< the decided sign (0: the polynomial is zero, a tie broken by rule)
  /// The same comparison (the sign aside).
  [[nodiscard]] bool same_test(const Test& o) const {
    return p[0] == o.p[0] && p[1] == o.p[1] && p[2] == o.p[2] && p[3] == o.p[3] && kind == o.kind;
  }
};

/// A test of a node's merge on one side, with its event.
struct KineticHull::Certificate {
  std::uint32_t node = 0;
  std::int8_t side = 0;
  Test test;
  EventHandle handle;
  [[nodiscard]] bool same_test(const Certificate& o) const {
    return node == o.node && side == o.side && test.same_test(o.test);
  }
};

namespace {

/// What a certificate compares (side s = +1 for the upper hull, -1 for the lower one, which is the
/// upper hull of (x, -y)); each is the sign of a polynomial f:
enum Kind : std::int8_t {
  kX = 0,       ///< f = x_b - x_a (p = a, b): > 0 when a is strictly left of b
  kY = 1,       ///< f = s (y_a - y_b) (p = a, b): > 0 when a is higher (on this side)
  kSlope = 2,   ///< f = s (slope(a a') - slope(b b')) times the edges' positive x-extents
  kOrient = 3,  ///< f = s orient(u, u', w): < 0 when w is below the line of u u'
  /// A node's test marked out of date (its event was processed, or one of its points changed
  /// motion): never kept by a re-merge, whose certificate it releases.
  kStale = -1,
};

}  // namespace

namespace {
constexpr int kRed = 0, kBlue = 1;
}  // namespace

KineticHull::Test KineticHull::test_of(int kind, std::uint32_t a, std::uint32_t b, std::uint32_t c,
                                       std::uint32_t d) {
  Test t;
  t.kind = static_cast<std::int8_t>(kind);
  t.p[0] = a;
  t.p[1] = b;
  t.p[2] = c;
  t.p[3] = d;
  return t;
}

/// Makes the decisions of one node's merge: a test the node's previous merge made already keeps
/// its certificate (its sign and its queued event: nothing about it changed), any other is asked
/// of the scheduler and scheduled; each is recorded in the node's list, in the order the merge
/// decided them. A re-merge after a local change asks the same tests in the same order except
/// near the change, so the previous list is searched from a cursor (a short window ahead).
struct KineticHull::Decider {
  KineticHull& hull;
  std::uint32_t node;
  int side;
  std::size_t cursor = 0;

  static constexpr std::size_t kWindow = 64;
  static constexpr std::size_t kNone = ~std::size_t{0};

  /// The position among the node's previous certificates of an unused one making test t, or
  /// kNone. The merge asks its tests in the previous merge's order except where the chains
  /// changed, so the search runs over a window of tests ahead of the cursor (the tests sit beside
  /// the ids: the search touches no certificate). A test further away is decided afresh:
  /// correct, only a decision more.
  std::size_t find_previous(const Test& t) const {
    const std::vector<Test>& tests = hull.previous_tests_;
    const std::size_t end = std::min(tests.size(), cursor + kWindow);
    for (std::size_t k = cursor; k < end; ++k) {
      if (tests[k].same_test(t) && !hull.used_[k]) return k;
    }
    return kNone;
  }

  int operator()(Kind kind, std::uint32_t a, std::uint32_t b, std::uint32_t c = kNoIndex,
                 std::uint32_t d = kNoIndex) {
    Test test = test_of(kind, a, b, c, d);
    const std::size_t found = find_previous(test);
    if (found != kNone) {
      hull.used_[found] = 1;
      cursor = found + 1;
      ++hull.counters_.kept;
      hull.node_certificates_[side][node].push_back(hull.previous_ids_[found]);
      hull.node_tests_[side][node].push_back(hull.previous_tests_[found]);
      return hull.previous_tests_[found].sign;
    }
    ++hull.counters_.decisions;
    Certificate cert;
    cert.node = node;
    cert.side = static_cast<std::int8_t>(side);
    cert.test = test;
    const Scheduler::SignDecision decision = hull.decide(cert);
    test.sign = static_cast<std::int8_t>(decision.sign);
    cert.test.sign = test.sign;
    const std::uint32_t id = hull.allocate_certificate();
    if (decision.failure != kTimeInfinity) {
      if (hull.scheduler_.kind() == SchedulerKind::Robust && decision.failure <= hull.sim_.now())
        ++hull.counters_.scheduled_not_in_future;
      cert.handle = hull.sim_.schedule(decision.failure, decision.exact, hull.owner_, id);
      ++hull.queued_;
    }
    hull.certificates_[id] = cert;
    hull.node_certificates_[side][node].push_back(id);
    hull.node_tests_[side][node].push_back(test);
    return decision.sign;
  }
};

/// Replays a node's merge from its recorded signs (validate()): the k-th decision must be the
/// k-th recorded test; a mismatch is noted.
struct KineticHull::Replay {
  const KineticHull& hull;
  std::uint32_t node;
  int side;
  std::size_t next = 0;
  bool mismatch = false;

  int operator()(Kind kind, std::uint32_t a, std::uint32_t b, std::uint32_t c = kNoIndex,
                 std::uint32_t d = kNoIndex) {
    const std::vector<std::uint32_t>& list = hull.node_certificates_[side][node];
    if (next >= list.size() ||
        !hull.certificates_[list[next]].test.same_test(test_of(kind, a, b, c, d))) {
      mismatch = true;
      return 1;
    }
    return hull.certificates_[list[next++]].test.sign;
  }
};

KineticHull::KineticHull(const MotionTable& points, Simulator& simulator,
                         const Scheduler& scheduler)
    : points_(points),
      sim_(simulator),
      scheduler_(scheduler),
      owner_(simulator.reserve_owners(1).first),
      trusted_(std::make_unique<Certificate>()) {
  if (points.dimension() != 2) {
    precondition_failed("KineticHull",
                        "the convex hull takes points in the plane (dimension 2), "
                        "not dimension " +
                            std::to_string(points.dimension()));
  }
  simulator.attach(scheduler);
}

KineticHull::~KineticHull() = default;

void KineticHull::require_motion(std::span<const MotionPolynomial> motion, ObjectId id,
                                 const char* where) {
  for (std::size_t axis = 0; axis < motion.size(); ++axis) {
    const int degree = motion[axis].degree;
    if (degree > kMaxDegree) {
      precondition_failed(where, "object " + std::to_string(id) + " moves with degree " +
                                     std::to_string(degree) + " on axis " + std::to_string(axis) +
                                     "; the convex hull takes motions of degree <= 3 (its "
                                     "orientation certificates have twice the motions' degree, "
                                     "and CROP isolates roots up to degree 6)");
    }
  }
}

void KineticHull::require_motion(const MotionTable& points, std::uint32_t index,
                                 const char* where) {
  const std::array<MotionPolynomial, 2> motion{points.motion(index, 0), points.motion(index, 1)};
  require_motion(motion, points.id(index), where);
}

std::uint64_t KineticHull::motion_hash(std::uint32_t index) const {
  std::uint64_t h = 0x243f6a8885a308d3ULL;
  const auto mix = [&](double v) {
    v += 0.0;  // -0 and +0 are the same coefficient
    std::uint64_t bits = 0;
    std::memcpy(&bits, &v, sizeof bits);
    h = (h ^ bits) * 0x9e3779b97f4a7c15ULL;
    h ^= h >> 31;
  };
  for (int axis = 0; axis < 2; ++axis) {
    const MotionPolynomial& p = points_.motion(index, axis);
    mix(p.origin);
    mix(static_cast<double>(p.degree));
    for (int k = 0; k <= p.degree; ++k) mix(p.c[static_cast<std::size_t>(k)]);
  }
  return h;
}

bool KineticHull::same_motion(std::uint32_t a, std::uint32_t b) const {
  return points_.motion(a, 0) == points_.motion(b, 0) &&
         points_.motion(a, 1) == points_.motion(b, 1);
}

void KineticHull::group_all(const std::vector<std::uint32_t>& objects) {
  motion_hash_.assign(points_.capacity(), 0);
  representative_.assign(points_.capacity(), kNoIndex);
  buckets_.clear();
  buckets_.reserve(objects.size());
  std::vector<std::uint32_t> order(objects);
  for (const std::uint32_t i : order) motion_hash_[i] = motion_hash(i);
  // By hash, then by motion (lexicographically, so that equal motions are adjacent), then by id.
  const auto motion_less = [&](std::uint32_t a, std::uint32_t b) {
    for (int axis = 0; axis < 2; ++axis) {
      const MotionPolynomial& p = points_.motion(a, axis);
      const MotionPolynomial& q = points_.motion(b, axis);
      if (p.origin != q.origin) return p.origin < q.origin;
      if (p.degree != q.degree) return p.degree < q.degree;
      for (int k = 0; k <= p.degree; ++k) {
        const double u = p.c[static_cast<std::size_t>(k)], v = q.c[static_cast<std::size_t>(k)];
        if (u != v) return u < v;
      }
    }
    return false;
  };
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    if (motion_hash_[a] != motion_hash_[b]) return motion_hash_[a] < motion_hash_[b];
    if (motion_less(a, b)) return true;
    if (motion_less(b, a)) return false;
    return points_.id(a) < points_.id(b);
  });
  for (std::size_t k = 0; k < order.size(); ++k) {
    const std::uint32_t i = order[k];
    const bool starts_group =
        k == 0 || motion_hash_[order[k - 1]] != motion_hash_[i] || !same_motion(order[k - 1], i);
    representative_[i] = starts_group ? i : representative_[order[k - 1]];
    buckets_.emplace(motion_hash_[i], i);
  }
}

void KineticHull::join_group(std::uint32_t index) {
  if (motion_hash_.size() < points_.capacity()) motion_hash_.resize(points_.capacity(), 0);
  if (representative_.size() < points_.capacity())
    representative_.resize(points_.capacity(), kNoIndex);
  motion_hash_[index] = motion_hash(index);
  const auto [first, last] = buckets_.equal_range(motion_hash_[index]);
  std::uint32_t best = index;
  for (auto it = first; it != last; ++it) {
    if (same_motion(it->second, index) && points_.id(it->second) < points_.id(best))
      best = it->second;
  }
  representative_[index] = best;
  if (best != index) {
    buckets_.emplace(motion_hash_[index], index);
    return;
  }
  // The new point has the smallest id of its group: it represents every member.
  for (auto it = first; it != last; ++it) {
    if (same_motion(it->second, index)) representative_[it->second] = index;
  }
  buckets_.emplace(motion_hash_[index], index);
}

void KineticHull::leave_group(std::uint32_t index) {
  // The table may have dropped the point already (remove): its group is read from the
  // representatives, not from its motion.
  const std::uint32_t rep = representative_[index];
  const auto [first, last] = buckets_.equal_range(motion_hash_[index]);
  auto self = last;
  std::uint32_t next = kNoIndex;
  for (auto it = first; it != last; ++it) {
    const std::uint32_t m = it->second;
    if (m == index) {
      self = it;
    } else if (rep == index && representative_[m] == index &&
               (next == kNoIndex || points_.id(m) < points_.id(next))) {
      next = m;
    }
  }
  if (next != kNoIndex) {
    for (auto it = first; it != last; ++it) {
      if (it->second != index && representative_[it->second] == index)
        representative_[it->second] = next;
    }
  }
  assert(self != last);
  buckets_.erase(self);
  representative_[index] = kNoIndex;
}

NamedCounters KineticHull::named_counters() const {
  return {{"events", counters_.events},
          {"inserts", counters_.inserts},
          {"removes", counters_.removes},
          {"updates", counters_.updates},
          {"rebuilds", counters_.rebuilds},
          {"merges", counters_.merges},
          {"decisions", counters_.decisions},
          {"kept", counters_.kept},
          {"queries", counters_.queries},
          {"query_fallbacks", counters_.query_fallbacks},
          {"scheduled_not_in_future", counters_.scheduled_not_in_future}};
}

std::uint32_t KineticHull::allocate_certificate() {
  return take_record(certificates_, free_certificates_);
}

namespace {

/// The polynomial of a certificate, built exactly from the motions.
struct CertificateFunction {
  bool pair = false;
  const MotionPolynomial* upper = nullptr;  ///< pair: f = upper - lower
  const MotionPolynomial* lower = nullptr;
  ProductCombination product;
};

CertificateFunction function_of(const MotionTable& m, int kind, int side, const std::uint32_t* p) {
  CertificateFunction f;
  const auto x = [&](int i) { return &m.motion(p[i], 0); };
  const auto y = [&](int i) { return &m.motion(p[i], 1); };
  switch (kind) {
    case kX:
      f.pair = true;
      f.upper = x(1);
      f.lower = x(0);
      break;
    case kY:
      f.pair = true;
      f.upper = side == 0 ? y(0) : y(1);
      f.lower = side == 0 ? y(1) : y(0);
      break;
    case kSlope:
      // (y_a' - y_a)(x_b' - x_b) - (y_b' - y_b)(x_a' - x_a), p = a, a', b, b'
      f.product = ProductCombination{{y(1), y(0), x(3), x(2)}, {y(3), y(2), x(1), x(0)}};
      break;
    default:  // kOrient: (x_u' - x_u)(y_w - y_u) - (y_u' - y_u)(x_w - x_u), p = u, u', w
      f.product = orientation(*x(0), *y(0), *x(1), *y(1), *x(2), *y(2));
      break;
  }
  if (!f.pair && side == 1) std::swap(f.product.plus, f.product.minus);
  return f;
}

}  // namespace

Scheduler::SignDecision KineticHull::decide(const Certificate& c) {
  Time window_lo = -kTimeInfinity;
  for (const std::uint32_t q : c.test.p) {
    if (q != kNoIndex) window_lo = std::max(window_lo, points_.valid_from(q));
  }
  const CertificateFunction f = function_of(points_, c.test.kind, c.side, c.test.p);
  const Time now = sim_.now();
  if (trusting_ && trusted_->same_test(c)) {
    // Classic: the certificate whose event this is holds the other way now.
    Scheduler::SignDecision d;
    d.sign = -trusted_->test.sign;
    if (f.pair) {
      d.failure =
          d.sign > 0 ? scheduler_.failure_time(*f.lower, *f.upper, now, window_lo, sim_.counters())
                     : scheduler_.failure_time(*f.upper, *f.lower, now, window_lo, sim_.counters());
    } else {
      d.failure = scheduler_.failure_time(f.product, d.sign, now, window_lo, sim_.counters());
    }
    return d;
  }
  if (f.pair) return scheduler_.decide(*f.upper, *f.lower, now, window_lo, sim_.counters());
  return scheduler_.decide(f.product, now, window_lo, sim_.counters());
}

namespace {

/// The envelope sweep merging the upper chains r and b (left to right) of two disjoint point
/// sets into the upper chain of their union, deciding every comparison through `decide`. In the
/// dual the chains are upper envelopes of lines; the sweep walks the edges of both chains in
/// decreasing slope order, keeps each colour's current vertex, and asks at each edge whether the
/// other colour's current vertex lies below the edge's line. Ties (a zero polynomial): a vertex on
/// an edge's line for ever is kept; at the ends, height then the smaller id decide.
template <class Decide, class IdOf>
void sweep(const std::vector<std::uint32_t>& r, const std::vector<std::uint32_t>& b, Decide& decide,
           const IdOf& id_of, std::vector<std::uint32_t>& out) {
  const std::vector<std::uint32_t>* chain[2] = {&r, &b};
  // Which colour wins at slope +infinity (the leftmost point) and at -infinity (the rightmost).
  // `by_x` tells whether the x-test decided (not a tie).
  bool by_x = false;
  const auto end_winner = [&](std::uint32_t pr, std::uint32_t pb, bool left) {
    const int sx = left ? decide(kX, pr, pb) : decide(kX, pb, pr);
    by_x = sx != 0;
    if (sx != 0) return sx > 0 ? kRed : kBlue;
    const int sy = decide(kY, pr, pb);
    if (sy != 0) return sy > 0 ? kRed : kBlue;
    return id_of(pr) < id_of(pb) ? kRed : kBlue;
  };
  const int first = end_winner(r.front(), b.front(), true);
  // Two single points: the rightmost test is the leftmost one read backwards (the same
  // polynomial), decided once so that the two can never disagree: the other point is rightmost,
  // or the same one when their x-motions are equal (then height and id decide both ends).
  const int last = r.size() == 1 && b.size() == 1 ? (by_x ? 1 - first : first)
                                                  : end_winner(r.back(), b.back(), false);
  std::size_t cur[2] = {0, 0};
  out.clear();
  const auto push = [&](std::uint32_t q) {
    if (out.empty() || out.back() != q) out.push_back(q);
  };
  int winner = first;
  push((*chain[winner])[0]);
  while (cur[kRed] + 1 < r.size() || cur[kBlue] + 1 < b.size()) {
    int c = kRed;
    if (cur[kRed] + 1 == r.size()) {
      c = kBlue;
    } else if (cur[kBlue] + 1 < b.size()) {
      // The edge of larger slope comes first; equal slopes for ever: red first.
      const int s =
          decide(kSlope, r[cur[kRed]], r[cur[kRed] + 1], b[cur[kBlue]], b[cur[kBlue] + 1]);
      c = s >= 0 ? kRed : kBlue;
    }
    const int o = 1 - c;
    const std::vector<std::uint32_t>& mine = *chain[c];
    const std::uint32_t u = mine[cur[c]], u2 = mine[cur[c] + 1], w = (*chain[o])[cur[o]];
    // At this edge's slope, its colour wins when the other's vertex is strictly below its line.
    // On the line for ever (a zero polynomial), both are kept: the query drops collinear points
    // and keeps the smallest id of coincident ones.
    const int at = decide(kOrient, u, u2, w) < 0 ? c : o;
    if (at != winner) {
      // The envelopes crossed in the interval before this slope: a bridge.
      push(at == c ? u : w);
      winner = at;
    }
    ++cur[c];
    if (winner == c) push(u2);
  }
  if (winner != last) push((*chain[last])[cur[last]]);
}

}  // namespace

void KineticHull::release(std::uint32_t id) {
  Certificate& c = certificates_[id];
  if (sim_.cancel(c.handle)) --queued_;
  c = Certificate{};
  free_certificates_.push_back(id);
}

void KineticHull::cancel_node(std::size_t v, int side) {
  for (const std::uint32_t id : node_certificates_[side][v]) release(id);
  node_certificates_[side][v].clear();
  node_tests_[side][v].clear();
}

void KineticHull::forget_tests_of(std::uint32_t index) {
  for (int side = 0; side < 2; ++side) {
    for (std::size_t u = leaf_of_[index] / 2; u >= 1; u /= 2) {
      for (Test& c : node_tests_[side][u]) {
        if (c.p[0] == index || c.p[1] == index || c.p[2] == index || c.p[3] == index)
          c.kind = kStale;
      }
    }
  }
}

bool KineticHull::merge(std::size_t v, int side) {
  assert(!is_leaf(v));
  ++counters_.merges;
  last_merge_time_ = sim_.now();
  // The node's certificates move to the scratch lists (capacities are swapped, not freed).
  previous_ids_.swap(node_certificates_[side][v]);
  previous_tests_.swap(node_tests_[side][v]);
  node_certificates_[side][v].clear();
  node_tests_[side][v].clear();
  used_.assign(previous_ids_.size(), 0);
  const std::vector<std::uint32_t>& r = chains_[side][2 * v];
  const std::vector<std::uint32_t>& b = chains_[side][2 * v + 1];
  std::vector<std::uint32_t>& merged = merged_;
  if (r.empty() || b.empty()) {
    merged = r.empty() ? b : r;
  } else {
    Decider decide{*this, static_cast<std::uint32_t>(v), side};
    const auto id_of = [&](std::uint32_t q) { return points_.id(q); };
    sweep(r, b, decide, id_of, merged);
  }
  for (std::size_t k = 0; k < previous_ids_.size(); ++k) {
    if (!used_[k]) release(previous_ids_[k]);
  }
  if (merged == chains_[side][v]) return false;
  chains_[side][v].swap(merged);
  return true;
}

void KineticHull::lay_out(std::size_t capacity, std::vector<std::uint32_t> objects) {
  for (int side = 0; side < 2; ++side) {
    for (std::size_t v = 1; v < node_certificates_[side].size(); ++v) cancel_node(v, side);
  }
  std::sort(objects.begin(), objects.end());
  capacity_ = capacity;
  for (int side = 0; side < 2; ++side) {
    chains_[side].assign(2 * capacity_, {});
    node_certificates_[side].assign(2 * capacity_, {});
    node_tests_[side].assign(2 * capacity_, {});
  }
  leaf_of_.assign(points_.capacity(), 0);
  free_.clear();
  for (std::size_t k = 0; k < objects.size(); ++k) {
    for (int side = 0; side < 2; ++side) chains_[side][capacity_ + k] = {objects[k]};
    leaf_of_[objects[k]] = static_cast<std::uint32_t>(capacity_ + k);
  }
  for (std::size_t leaf = 2 * capacity_; leaf-- > capacity_ + objects.size();)
    free_.push_back(static_cast<std::uint32_t>(leaf));
  size_ = objects.size();
  for (int side = 0; side < 2; ++side) {
    for (std::size_t v = capacity_; v-- > 1;) merge(v, side);
  }
}

void KineticHull::rebuild(std::size_t capacity) {
  std::vector<std::uint32_t> objects;
  for (std::size_t leaf = capacity_; leaf < 2 * capacity_; ++leaf) {
    if (!chains_[0][leaf].empty()) objects.push_back(chains_[0][leaf][0]);
  }
  lay_out(capacity, std::move(objects));
  ++counters_.rebuilds;
}

void KineticHull::initialize() {
  std::vector<std::uint32_t> objects = points_.alive_indices();
  for (const std::uint32_t i : objects) require_motion(points_, i, "KineticHull::initialize");
  sync_.note();
  group_all(objects);
  std::size_t capacity = 1;
  while (capacity < objects.size()) capacity *= 2;
  lay_out(capacity, std::move(objects));
}

EventKind KineticHull::process(const Event& event) {
  assert(event.payload < certificates_.size());
  Certificate& c = certificates_[event.payload];
  c.handle = EventHandle{};  // popped by the simulator
  --queued_;
  ++counters_.events;
  const std::size_t v = c.node;
  const int side = c.side;
  const Test failed = c.test;  // (merges may move the certificates)
  if (scheduler_.kind() == SchedulerKind::Classic) {
    trusting_ = true;
    *trusted_ = c;
  }
  // The re-merge decides this test afresh.
  {
    const std::vector<std::uint32_t>& ids = node_certificates_[side][v];
    const auto at = std::find(ids.begin(), ids.end(), event.payload);
    assert(at != ids.end());
    node_tests_[side][v][static_cast<std::size_t>(at - ids.begin())].kind = kStale;
  }
  // Re-merge the node; while its chain changes, its parent's input changed too. The event is
  // external when the root's chain changed.
  bool external = false;
  for (std::size_t u = v; u >= 1 && merge(u, side); u /= 2) external = u == 1;
  trusting_ = false;
  if (external) sim_.note_external_change();
  if (external && sim_.logging_events()) {  // the points of the test that failed
    std::array<ObjectId, 4> ids{};
    std::size_t k = 0;
    for (const std::uint32_t p : failed.p) {
      if (p != kNoIndex) ids[k++] = points_.id(p);
    }
    std::vector<ObjectId> sorted(ids.begin(), ids.begin() + static_cast<std::ptrdiff_t>(k));
    std::sort(sorted.begin(), sorted.end());
    sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
    sim_.log_event("hull_change", sorted);
  }
  return external ? EventKind::External : EventKind::Internal;
}

void KineticHull::insert(std::uint32_t index) {
  // A refused motion leaves the structure untold: its queries then report the table changed.
  // (An index not in the table is refused by the sync check, which reads no motion.)
  if (points_.alive_index(index)) require_motion(points_, index, "KineticHull::insert");
  sync_.require_inserted("KineticHull::insert", index);
  ++counters_.inserts;
  if (leaf_of_.size() < points_.capacity()) leaf_of_.resize(points_.capacity(), 0);
  if (free_.empty()) rebuild(std::max<std::size_t>(1, 2 * capacity_));
  const std::uint32_t leaf = free_.back();
  free_.pop_back();
  for (int side = 0; side < 2; ++side) chains_[side][leaf] = {index};
  leaf_of_[index] = leaf;
  join_group(index);
  ++size_;
  for (int side = 0; side < 2; ++side) {
    for (std::size_t u = leaf / 2; u >= 1; u /= 2) merge(u, side);
  }
}

void KineticHull::remove(std::uint32_t index) {
  sync_.require_removed("KineticHull::remove", index);
  assert(index < leaf_of_.size() && leaf_of_[index] != 0);
  ++counters_.removes;
  const std::uint32_t leaf = leaf_of_[index];
  leaf_of_[index] = 0;
  leave_group(index);
  for (int side = 0; side < 2; ++side) chains_[side][leaf].clear();
  free_.push_back(leaf);
  --size_;
  for (int side = 0; side < 2; ++side) {
    for (std::size_t u = leaf / 2; u >= 1; u /= 2) merge(u, side);
  }
}

void KineticHull::motion_changed(std::uint32_t index) {
  if (points_.alive_index(index)) require_motion(points_, index, "KineticHull::motion_changed");
  sync_.require_updated("KineticHull::motion_changed", index);
  assert(index < leaf_of_.size() && leaf_of_[index] != 0);
  ++counters_.updates;
  leave_group(index);
  join_group(index);
  // Every certificate the point takes part in is on its leaf's path: re-decide them all.
  forget_tests_of(index);
  for (int side = 0; side < 2; ++side) {
    for (std::size_t u = leaf_of_[index] / 2; u >= 1; u /= 2) merge(u, side);
  }
}

std::vector<std::uint32_t> KineticHull::candidates() const {
  std::vector<std::uint32_t> out;
  if (capacity_ == 0) return out;
  out = chains_[0][1];
  out.insert(out.end(), chains_[1][1].begin(), chains_[1][1].end());
  return out;
}

int KineticHull::turn_at(std::uint32_t a, std::uint32_t b, std::uint32_t c, Time t) const {
  const auto& m = points_;
  return sign_at(orientation(m.motion(a, 0), m.motion(a, 1), m.motion(b, 0), m.motion(b, 1),
                             m.motion(c, 0), m.motion(c, 1)),
                 t);
}

void KineticHull::start_at_lowest(std::vector<std::uint32_t>& polygon, Time t,
                                  const std::vector<FilteredPoint>* at) const {
  const auto& x = [&](std::uint32_t q) -> const MotionPolynomial& { return points_.motion(q, 0); };
  const auto& y = [&](std::uint32_t q) -> const MotionPolynomial& { return points_.motion(q, 1); };
  // sign(coordinate of polygon[j] - that of polygon[k]): the filtered positions first when given.
  const auto compare = [&](std::size_t j, std::size_t k, int axis) {
    if (at != nullptr) {
      const FilteredPoint &p = (*at)[j], &q = (*at)[k];
      if (const int s = filtered_compare(axis == 0 ? p.x : p.y, axis == 0 ? q.x : q.y); s != 0)
        return s;
    }
    return axis == 0 ? compare_at(x(polygon[j]), x(polygon[k]), t)
                     : compare_at(y(polygon[j]), y(polygon[k]), t);
  };
  std::size_t start = 0;
  for (std::size_t j = 1; j < polygon.size(); ++j) {
    const int sy = compare(j, start, 1);
    if (sy < 0 || (sy == 0 && compare(j, start, 0) < 0)) start = j;
  }
  std::rotate(polygon.begin(), polygon.begin() + static_cast<std::ptrdiff_t>(start), polygon.end());
}

std::vector<std::uint32_t> KineticHull::convex_polygon_of(const std::vector<std::uint32_t>& upper,
                                                          const std::vector<std::uint32_t>& lower,
                                                          Time t) const {
  if (upper.size() < 2 || lower.size() < 2 || upper.size() + lower.size() < 5 ||
      upper.front() != lower.front() || upper.back() != lower.back())
    return {};
  // Counter-clockwise: the lower chain left to right, then the upper one right to left without
  // its two ends. Each vertex's position at t is evaluated once (with its rigorous bound); a
  // comparison the bounds cannot decide is decided exactly from the motions.
  std::vector<std::uint32_t> polygon(lower);
  polygon.insert(polygon.end(), upper.rbegin() + 1, upper.rend() - 1);
  std::vector<FilteredPoint> at(polygon.size());
  for (std::size_t k = 0; k < polygon.size(); ++k)
    at[k] = filtered_point(points_.motion(polygon[k], 0), points_.motion(polygon[k], 1), t);
  // Around the polygon every vertex must turn strictly counter-clockwise (lower chain: strictly
  // left to right; upper chain: strictly right to left).
  const std::size_t m = polygon.size(), right = lower.size() - 1;
  for (std::size_t k = 0; k < m; ++k) {
    const std::size_t next = k + 1 == m ? 0 : k + 1, after = next + 1 == m ? 0 : next + 1;
    // x strictly increasing along the lower chain (k < right), decreasing along the upper one.
    int sx = filtered_compare(at[next].x, at[k].x);
    if (sx == 0)
      sx = compare_at(points_.motion(polygon[next], 0), points_.motion(polygon[k], 0), t);
    if (sx != (k < right ? 1 : -1)) return {};
    int turn = filtered_orientation(at[k], at[next], at[after]);
    if (turn == 0) turn = turn_at(polygon[k], polygon[next], polygon[after], t);
    if (turn != 1) return {};
  }
  start_at_lowest(polygon, t, &at);
  return polygon;
}

std::vector<std::uint32_t> KineticHull::hull() {
  sync_.require_current("KineticHull::hull");
  ++counters_.queries;
  if (capacity_ == 0) return {};
  const Time t = sim_.now();
  const auto& x = [&](std::uint32_t q) -> const MotionPolynomial& { return points_.motion(q, 0); };
  const auto& y = [&](std::uint32_t q) -> const MotionPolynomial& { return points_.motion(q, 1); };
  // Exact (x, y, id) order at t; coincident points: the smallest id stays.
  const auto before = [&](std::uint32_t a, std::uint32_t b) {
    if (a == b) return false;
    const int sx = compare_at(x(a), x(b), t);
    if (sx != 0) return sx < 0;
    const int sy = compare_at(y(a), y(b), t);
    if (sy != 0) return sy < 0;
    return points_.id(a) < points_.id(b);
  };
  // The candidates: both root chains, each a point with identical motions standing for its
  // group (the smallest id).
  std::vector<std::uint32_t> chain[2];
  for (int side = 0; side < 2; ++side) {
    chain[side] = chains_[side][1];
    for (std::uint32_t& q : chain[side]) q = representative_[q];
  }
  // When the root's certificates hold at t the chains are the hull's: the upper chain turns
  // strictly clockwise, the lower one strictly counter-clockwise, both strictly left to right
  // between the same two ends. Then the polygon they bound is convex with every candidate a
  // vertex, i.e. it is the hull of the candidates: about 2h exact predicates, nothing sorted.
  // Of points at one position the smallest id: searched only when a merge ran at t (see
  // name_smallest_coincident() for when that finds every such point).
  const bool merged_now = t == last_merge_time_;
  if (auto polygon = convex_polygon_of(chain[0], chain[1], t); !polygon.empty()) {
    if (merged_now) name_smallest_coincident(polygon, t);
    return polygon;
  }
  ++counters_.query_fallbacks;
  // Otherwise (near an event, collinear or coincident points at t): Andrew's monotone chain on
  // the candidates. Each chain is in (x, y, id) order already when its certificates hold at t
  // (checked, O(h)), so one merge orders them; otherwise they are sorted.
  bool ordered = true;
  for (int side = 0; side < 2; ++side) {
    for (std::size_t k = 1; ordered && k < chain[side].size(); ++k)
      ordered = !before(chain[side][k], chain[side][k - 1]);
  }
  std::vector<std::uint32_t> p(chain[0].size() + chain[1].size());
  if (ordered) {
    std::merge(chain[0].begin(), chain[0].end(), chain[1].begin(), chain[1].end(), p.begin(),
               before);
  } else {
    std::copy(chain[1].begin(), chain[1].end(),
              std::copy(chain[0].begin(), chain[0].end(), p.begin()));
    std::sort(p.begin(), p.end(), before);
  }
  std::vector<std::uint32_t> u;
  for (const std::uint32_t q : p) {
    if (!u.empty() && (u.back() == q || (compare_at(x(u.back()), x(q), t) == 0 &&
                                         compare_at(y(u.back()), y(q), t) == 0)))
      continue;
    u.push_back(q);
  }
  if (u.size() <= 2) {
    if (u.size() == 2 && compare_at(y(u[1]), y(u[0]), t) < 0) std::swap(u[0], u[1]);
    return u;
  }
  // Andrew's monotone chain on the candidates, strict turns only.
  std::vector<std::uint32_t> h(2 * u.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < u.size(); ++i) {
    while (k >= 2 && turn_at(h[k - 2], h[k - 1], u[i], t) <= 0) --k;
    h[k++] = u[i];
  }
  for (std::size_t i = u.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && turn_at(h[k - 2], h[k - 1], u[i], t) <= 0) --k;
    h[k++] = u[i];
  }
  h.resize(k - 1);  // the last is the first again
  start_at_lowest(h, t);
  if (merged_now) name_smallest_coincident(h, t);
  return h;
}

void KineticHull::name_smallest_coincident(std::vector<std::uint32_t>& polygon, Time t) const {
  if (polygon.empty()) return;
  // sign(x(q) - x(g)) at t for a target g, and whether q is at g's position (points with the
  // same motion are: no exact comparison needed).
  const auto compare_x = [&](std::uint32_t q, const Target& g) {
    if (q == g.point) return 0;
    const int s = filtered_compare(evaluate_filtered(points_.motion(q, 0), t), g.x);
    if (s != 0) return s;
    if (representative_[q] == representative_[g.point]) return 0;
    return compare_at(points_.motion(q, 0), points_.motion(g.point, 0), t);
  };
  const auto same_y = [&](std::uint32_t q, const Target& g) {
    return representative_[q] == representative_[g.point] ||
           compare_at(points_.motion(q, 1), points_.motion(g.point, 1), t) == 0;
  };
  // The polygon's vertex of each representative (valid where the polygon agrees).
  if (slot_of_.size() < points_.capacity()) slot_of_.resize(points_.capacity(), 0);
  std::vector<std::uint32_t> best(polygon);
  for (std::uint32_t k = 0; k < polygon.size(); ++k) slot_of_[polygon[k]] = k;
  const int leaf_depth = static_cast<int>(std::bit_width(capacity_)) - 1;
  for (int side = 0; side < 2; ++side) {
    const auto& chains = chains_[side];
    // The root chain's points that stand for a polygon vertex (in x order at t): the targets.
    if (target_levels_.size() < static_cast<std::size_t>(leaf_depth) + 1)
      target_levels_.resize(static_cast<std::size_t>(leaf_depth) + 1);
    auto& root_targets = target_levels_[0];
    root_targets.clear();
    for (const std::uint32_t q : chains[1]) {
      const std::uint32_t r = representative_[q];
      if (r < slot_of_.size() && slot_of_[r] < polygon.size() && polygon[slot_of_[r]] == r)
        root_targets.push_back({slot_of_[r], q, evaluate_filtered(points_.motion(q, 0), t)});
    }
    // Depth first: every node's targets are points of its chain at a vertex's position, in x
    // order; a child holds a target's point when the point's leaf is below it, and otherwise is
    // searched (galloping from the previous target's place: both lists are in x order).
    const auto visit = [&](auto&& self, std::size_t v, int depth) -> void {
      const auto& targets = target_levels_[static_cast<std::size_t>(depth)];
      if (is_leaf(v)) {
        for (const Target& g : targets) {
          const std::uint32_t q = representative_[g.point];
          if (points_.id(q) < points_.id(best[g.slot])) best[g.slot] = q;
        }
        return;
      }
      for (const std::size_t child : {2 * v, 2 * v + 1}) {
        auto& below = target_levels_[static_cast<std::size_t>(depth) + 1];
        below.clear();
        const auto& chain = chains[child];
        std::size_t cursor = 0;
        for (const Target& g : targets) {
          if ((leaf_of_[g.point] >> (leaf_depth - depth - 1)) == child) {
            below.push_back(g);
            continue;
          }
          // The first chain point at or right of the target's x, from the cursor on.
          std::size_t step = 1, lo = cursor, hi = cursor;
          while (hi < chain.size() && compare_x(chain[hi], g) < 0) {
            lo = hi + 1;
            hi += step;
            step *= 2;
          }
          hi = std::min(hi, chain.size());
          while (lo < hi) {
            const std::size_t mid = lo + (hi - lo) / 2;
            if (compare_x(chain[mid], g) < 0)
              lo = mid + 1;
            else
              hi = mid;
          }
          cursor = lo;
          for (std::size_t k = lo; k < chain.size() && compare_x(chain[k], g) == 0; ++k) {
            if (same_y(chain[k], g)) {
              below.push_back({g.slot, chain[k], g.x});
              break;
            }
          }
        }
        if (!below.empty()) self(self, child, depth + 1);
      }
    };
    if (!root_targets.empty()) visit(visit, 1, 0);
  }
  polygon = std::move(best);
}

std::size_t KineticHull::certificates() const {
  std::size_t n = 0;
  for (int side = 0; side < 2; ++side) {
    for (const auto& list : node_certificates_[side]) n += list.size();
  }
  return n;
}

std::size_t KineticHull::certificates_per_object_max() const {
  std::vector<std::uint32_t> count(points_.capacity(), 0);
  std::uint32_t best = 0;
  for (int side = 0; side < 2; ++side) {
    for (const auto& list : node_certificates_[side]) {
      for (const std::uint32_t id : list) {
        const Certificate& c = certificates_[id];
        for (int i = 0; i < 4; ++i) {
          const std::uint32_t q = c.test.p[i];
          if (q == kNoIndex) continue;
          bool repeated = false;
          for (int j = 0; j < i; ++j) repeated = repeated || c.test.p[j] == q;
          if (!repeated) best = std::max(best, ++count[q]);
        }
      }
    }
  }
  return best;
}

bool KineticHull::validate() const {
  if (!sync_.current()) return false;  // the table changed without telling the structure
  if (capacity_ == 0) return size_ == 0;
  // Groups of identical motions: every live point in its bucket, represented by the member of
  // its group with the smallest id.
  if (buckets_.size() != size_) return false;
  for (const auto& [hash, i] : buckets_) {
    if (!points_.alive_index(i) || leaf_of_[i] == 0 || motion_hash_[i] != hash ||
        motion_hash(i) != hash)
      return false;
    const std::uint32_t rep = representative_[i];
    if (rep >= points_.capacity() || !points_.alive_index(rep) || !same_motion(i, rep))
      return false;
    const auto [first, last] = buckets_.equal_range(hash);
    for (auto it = first; it != last; ++it) {
      if (same_motion(it->second, i) && points_.id(it->second) < points_.id(rep)) return false;
    }
  }
  std::size_t queued = 0;
  for (int side = 0; side < 2; ++side) {
    for (std::size_t leaf = capacity_; leaf < 2 * capacity_; ++leaf) {
      const auto& chain = chains_[side][leaf];
      if (chain.size() > 1) return false;
      if (chain.size() == 1 && (!points_.alive_index(chain[0]) || leaf_of_[chain[0]] != leaf))
        return false;
      if (!node_certificates_[side][leaf].empty()) return false;
    }
    for (std::size_t v = capacity_; v-- > 1;) {
      const auto& r = chains_[side][2 * v];
      const auto& b = chains_[side][2 * v + 1];
      std::vector<std::uint32_t> expected;
      if (r.empty() || b.empty()) {
        expected = r.empty() ? b : r;
        if (!node_certificates_[side][v].empty()) return false;
      } else {
        Replay replay{*this, static_cast<std::uint32_t>(v), side};
        const auto id_of = [&](std::uint32_t q) { return points_.id(q); };
        sweep(r, b, replay, id_of, expected);
        if (replay.mismatch || replay.next != node_certificates_[side][v].size()) return false;
      }
      if (expected != chains_[side][v]) return false;
      if (node_tests_[side][v].size() != node_certificates_[side][v].size()) return false;
      for (std::size_t k = 0; k < node_certificates_[side][v].size(); ++k) {
        const Certificate& c = certificates_[node_certificates_[side][v][k]];
        const Test& test = node_tests_[side][v][k];
        if (c.node != v || c.side != side || !test.same_test(c.test) || test.sign != c.test.sign)
          return false;
        if (!c.handle.is_null()) {
          if (!sim_.queue().contains(c.handle)) return false;
          const Event& e = sim_.queue().get(c.handle);
          if (e.owner != owner_ || e.payload != node_certificates_[side][v][k]) return false;
          ++queued;
        }
      }
    }
  }
  return queued == queued_;
}

HullCertificateAudit KineticHull::audit_certificates(Time t, double window) const {
  HullCertificateAudit a;
  for (int side = 0; side < 2; ++side) {
    for (const auto& list : node_certificates_[side]) {
      for (const std::uint32_t id : list) {
        const Certificate& c = certificates_[id];
        const CertificateFunction f = function_of(points_, c.test.kind, c.side, c.test.p);
        const auto sign_at_time = [&](Time s) {
          return f.pair ? compare_at(*f.upper, *f.lower, s) : sign_at(f.product, s);
        };
        ++a.checked;
        const int exact = f.pair ? compare_after(*f.upper, *f.lower, t) : sign_after(f.product, t);
        if (exact == c.test.sign) continue;
        ++a.wrong;
        // A root within the window: a sign change or a zero between t - window and t + window.
        const int lo = sign_at_time(t - window), hi = sign_at_time(t + window);
        const bool root_near = lo == 0 || hi == 0 || lo != hi || sign_at_time(t) != lo;
        if (!root_near) ++a.wrong_without_root_near;
      }
    }
  }
  return a;
}

namespace {

/// The loop guard's bounds. A certificate is a test on at most 4 points (2 sides), a polynomial of
/// degree <= 2 * 3 = 6 per piece of its motions: at one instant each test fails at most once, and
/// over a run at most 6 times per motion piece of each of its points. So at most 2 n^4 tests per
/// instant and 2 * 6 * 4 * changes * n^3 + 2 * 6 n^4 over a run: loose, but a scheduling loop at
/// small n still trips it (and at large n the bound saturates to none).
LoopGuard hull_event_bounds(const RunBounds& b) {
  const std::uint64_t n = b.max_objects;
  const std::uint64_t degree = static_cast<std::uint64_t>(std::max(1, 2 * b.max_degree));
  LoopGuard g;
  g.max_events_per_instant = saturating_product({2, n, n, n, n});
  const std::uint64_t per_instant = g.max_events_per_instant;
  const std::uint64_t changes = saturating_product({8, degree, b.motion_changes, n, n, n});
  const std::uint64_t all = saturating_product({degree, per_instant});
  constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();
  g.max_events_total = all >= kMax - 16 - changes ? kMax : all + changes + 16;
  return g;
}

}  // namespace

StructureDescription KineticHull::description() {
  return StructureDescription{
      "hull",
      "Hull",
      ObjectsAre::Points,
      {QueryType::Hull},
      {"hull_change"},
      "The kinetic convex hull of points in the plane (hull()).",
      "kinetic convex hull of points in the plane (kinetic divide and conquer over the upper and "
      "lower hulls): the hull's ids counter-clockwise from the lowest-then-leftmost point"}
      .limit_dimensions(2, 2, "points in the plane")
      .limit_degree(
          KineticHull::kMaxDegree,
          "its orientation certificates have twice the motions' degree, and CROP isolates roots up "
          "to degree 6")
      .bound_events(hull_event_bounds);
}

}  // namespace kinetic
