#include "kinetic/closest_pair/kinetic_cone_closest_pair.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>

#include "kinetic/core/error.hpp"
#include "kinetic/core/exact_time.hpp"
#include "kinetic/core/incircle.hpp"

namespace kinetic {

namespace {

/// Directions of DirectionKeys::kDirections: the cones' sides, then their targets.
constexpr int kY = 0, kXMinusY = 1, kX = 2, kXPlusY = 3, kFirstTarget = 4;

/// Cone c < 4 (angles [45 c, 45 (c + 1)) degrees): q lies in p's cone when, in each of the two
/// side orders, q comes after p (after = true) or before it; the opposite cone c + 4 has both
/// sides turned. The target of cone c is direction kFirstTarget + c, scanned forward (c < 4) or
/// backward (c >= 4).
struct ConeSides {
  std::array<int, 2> side;
  std::array<bool, 2> after;
};
constexpr std::array<ConeSides, 4> kSides{{
    {{kY, kXMinusY}, {true, true}},   // [0, 45): y > y_p, x - y > (x - y)_p
    {{kXMinusY, kX}, {false, true}},  // [45, 90): x - y < (x - y)_p, x > x_p
    {{kX, kXPlusY}, {false, true}},   // [90, 135): x < x_p, x + y > (x + y)_p
    {{kXPlusY, kY}, {false, true}},   // [135, 180): x + y < (x + y)_p, y > y_p
}};

constexpr int target_of(int c) { return kFirstTarget + c % 4; }
constexpr bool forward(int c) { return c < 4; }
constexpr std::size_t kNoSlot = KineticDirectionSort::kNoSlot;

}  // namespace

KineticConeClosestPair::KineticConeClosestPair(const MotionTable& points, Simulator& simulator,
                                               const Scheduler& scheduler)
    : points_(points),
      sim_(simulator),
      scheduler_(scheduler),
      sorts_{},
      tournament_(points, simulator, scheduler) {
  if (points.dimension() != 2) {
    precondition_failed("KineticConeClosestPair",
                        "the closest pair is kept for points in the plane (a table of dimension "
                        "2), not of dimension " +
                            std::to_string(points.dimension()));
  }
  for (int d = 0; d < 8; ++d) {
    sorts_[static_cast<std::size_t>(d)] =
        std::make_unique<KineticDirectionSort>(points, simulator, scheduler, d);
  }
  first_sort_owner_ = sorts_[0]->owners().first;
}

KineticConeClosestPair::~KineticConeClosestPair() = default;

void KineticConeClosestPair::require_motion(std::span<const MotionPolynomial> motion, ObjectId id,
                                            const char* where) {
  for (std::size_t axis = 0; axis < motion.size(); ++axis) {
    const MotionPolynomial& m = motion[axis];
    if (m.degree > kMaxDegree) {
      precondition_failed(where, "object " + std::to_string(id) +
                                     ": the closest pair takes "
                                     "motions of degree <= 3 (its length certificates have twice "
                                     "the degree, CROP at most 6), got degree " +
                                     std::to_string(m.degree));
    }
    for (int k = 0; k <= m.degree; ++k) {
      if (std::fabs(m.c[static_cast<std::size_t>(k)]) >= std::ldexp(1.0, kCoefficientLog2)) {
        precondition_failed(where, "object " + std::to_string(id) +
                                       ": the closest pair takes motion coefficients of "
                                       "magnitude < 2^1023 (twice a coordinate must be a "
                                       "double)");
      }
    }
  }
}

NamedCounters KineticConeClosestPair::named_counters() const {
  return {{"events", counters_.swaps + counters_.tournament_events},
          {"swaps", counters_.swaps},
          {"tournament_events", counters_.tournament_events},
          {"candidate_changes", counters_.candidate_changes},
          {"scans", counters_.scans},
          {"scan_steps", counters_.scan_steps},
          {"nodes_redecided", tournament_.counters().nodes_redecided},
          {"queries", counters_.queries},
          {"tie_visits", tournament_.counters().tie_visits},
          {"coincidence_passes", counters_.coincidence_passes},
          {"brute_force_passes", counters_.brute_force_passes}};
}

bool KineticConeClosestPair::in_cone(int c, std::uint32_t p, std::uint32_t q) const {
  if (p == q) return false;
  const ConeSides& s = kSides[static_cast<std::size_t>(c % 4)];
  for (std::size_t k = 0; k < 2; ++k) {
    const KineticDirectionSort& o = *sorts_[static_cast<std::size_t>(s.side[k])];
    const bool after = o.rank(q) > o.rank(p);
    if (after != (s.after[k] == forward(c))) return false;
  }
  return true;
}

std::size_t KineticConeClosestPair::after(int c, std::size_t slot) const {
  if (forward(c)) {
    return slot + 1 < sorts_[static_cast<std::size_t>(target_of(c))]->slots() ? slot + 1 : kNoSlot;
  }
  return slot > 0 ? slot - 1 : kNoSlot;
}

bool KineticConeClosestPair::scans_before(int c, std::uint32_t q, std::uint32_t r) const {
  const KineticDirectionSort& o = *sorts_[static_cast<std::size_t>(target_of(c))];
  return forward(c) ? o.rank(q) < o.rank(r) : o.rank(q) > o.rank(r);
}

std::uint32_t KineticConeClosestPair::scan(int c, std::uint32_t p, std::size_t from) {
  ++counters_.scans;
  const auto order = sorts_[static_cast<std::size_t>(target_of(c))]->order();
  for (std::size_t slot = from; slot != kNoSlot; slot = after(c, slot)) {
    ++counters_.scan_steps;
    const std::uint32_t q = order[slot];
    if (in_cone(c, p, q)) return q;
  }
  return kNoIndex;
}

void KineticConeClosestPair::set_candidate(int c, std::uint32_t p, std::uint32_t q) {
  const auto k = static_cast<std::size_t>(c);
  std::vector<std::uint32_t>& n = neighbour_[k];
  std::vector<std::uint32_t>& head = head_[k];
  std::vector<std::uint32_t>& next = next_[k];
  std::vector<std::uint32_t>& prev = prev_[k];
  const std::uint32_t old = n[p];
  if (old == q) return;
  ++counters_.candidate_changes;
  if (old != kNoIndex) {  // unlink p from old's list
    if (prev[p] != kNoIndex) {
      next[prev[p]] = next[p];
    } else {
      head[old] = next[p];
    }
    if (next[p] != kNoIndex) prev[next[p]] = prev[p];
  }
  n[p] = q;
  prev[p] = kNoIndex;
  next[p] = kNoIndex;
  if (q != kNoIndex) {
    next[p] = head[q];
    if (head[q] != kNoIndex) prev[head[q]] = p;
    head[q] = p;
    tournament_.set(leaf(c, p), p, q);
  } else {
    tournament_.clear(leaf(c, p));
  }
}

const std::vector<std::uint32_t>& KineticConeClosestPair::candidate_of(int c, std::uint32_t q) {
  const auto k = static_cast<std::size_t>(c);
  scratch_.clear();
  for (std::uint32_t p = head_[k][q]; p != kNoIndex; p = next_[k][p]) scratch_.push_back(p);
  return scratch_;
}

void KineticConeClosestPair::rescan(int c, std::uint32_t p) {
  const KineticDirectionSort& o = *sorts_[static_cast<std::size_t>(target_of(c))];
  set_candidate(c, p, scan(c, p, after(c, o.rank(p))));
}

void KineticConeClosestPair::reconsider(int c, std::uint32_t p, std::uint32_t q) {
  const std::uint32_t current = neighbour_[static_cast<std::size_t>(c)][p];
  if (scans_before(c, p, q) && in_cone(c, p, q)) {
    if (current == kNoIndex || scans_before(c, q, current)) set_candidate(c, p, q);
    return;
  }
  if (current != q) return;
  if (!scans_before(c, p, q)) {
    rescan(c, p);  // q went behind p in the scan
    return;
  }
  // q left the cone where it stood: the points between p and q are not in it (they were not,
  // and only q's place against p changed).
  const KineticDirectionSort& o = *sorts_[static_cast<std::size_t>(target_of(c))];
  set_candidate(c, p, scan(c, p, after(c, o.rank(q))));
}

void KineticConeClosestPair::on_swap(int direction, std::uint32_t up, std::uint32_t down) {
  if (direction < kFirstTarget) {
    // A side order: up and down changed sides against each other, nothing else did.
    for (int c = 0; c < kCones; ++c) {
      const ConeSides& s = kSides[static_cast<std::size_t>(c % 4)];
      if (s.side[0] != direction && s.side[1] != direction) continue;
      reconsider(c, up, down);
      reconsider(c, down, up);
    }
    return;
  }
  // A target order: `down` moved ahead of `up` in the forward scan, `up` ahead of `down` in the
  // backward one.
  for (const int c : {direction - kFirstTarget, direction - kFirstTarget + 4}) {
    const std::uint32_t x = forward(c) ? down : up;  // moved ahead
    const std::uint32_t y = forward(c) ? up : down;  // passed
    for (const std::uint32_t p : candidate_of(c, y)) reconsider(c, p, x);
    reconsider(c, y, x);
    reconsider(c, x, y);
  }
}

void KineticConeClosestPair::grow() {
  const std::size_t cap = points_.capacity();
  for (int c = 0; c < kCones; ++c) {
    const auto k = static_cast<std::size_t>(c);
    if (neighbour_[k].size() >= cap) continue;
    neighbour_[k].resize(cap, kNoIndex);
    head_[k].resize(cap, kNoIndex);
    next_[k].resize(cap, kNoIndex);
    prev_[k].resize(cap, kNoIndex);
  }
  tournament_.reserve(cap * kCones);
}

void KineticConeClosestPair::check_motion(std::uint32_t index, const char* where) const {
  const std::array<MotionPolynomial, 2> m{points_.motion(index, 0), points_.motion(index, 1)};
  require_motion(m, points_.id(index), where);
}

void KineticConeClosestPair::initialize() {
  for (const std::uint32_t i : points_.alive_indices())
    check_motion(i, "KineticConeClosestPair::initialize");
  for (auto& s : sorts_) s->initialize();
  const std::size_t cap = points_.capacity();
  for (int c = 0; c < kCones; ++c) {
    const auto k = static_cast<std::size_t>(c);
    neighbour_[k].assign(cap, kNoIndex);
    head_[k].assign(cap, kNoIndex);
    next_[k].assign(cap, kNoIndex);
    prev_[k].assign(cap, kNoIndex);
  }
  tournament_.reset(cap * kCones);
  for (int c = 0; c < kCones; ++c) {
    for (const std::uint32_t p : sorts_[0]->order()) rescan(c, p);
  }
  tournament_.decide_all();
  sync_.note();
}

EventKind KineticConeClosestPair::process(const Event& event) {
  const std::uint32_t top_before = tournament_.winner();
  const std::optional<PairTournament::Pair> pair_before =
      top_before == kNoIndex ? std::nullopt : tournament_.pair(top_before);
  if (event.owner == tournament_.owner()) {
    ++counters_.tournament_events;
    tournament_.process(event);
  } else {
    const int direction = static_cast<int>(event.owner - first_sort_owner_);
    assert(direction >= 0 && direction < 8);
    const KineticDirectionSort::Swap s =
        sorts_[static_cast<std::size_t>(direction)]->process_swap(event);
    ++counters_.swaps;
    on_swap(direction, s.up, s.down);
    tournament_.update();
  }
  const std::uint32_t top = tournament_.winner();
  const std::optional<PairTournament::Pair> pair =
      top == kNoIndex ? std::nullopt : tournament_.pair(top);
  const auto unordered = [](const std::optional<PairTournament::Pair>& p) {
    if (!p) return std::array<std::uint32_t, 2>{kNoIndex, kNoIndex};
    return std::array<std::uint32_t, 2>{std::min((*p)[0], (*p)[1]), std::max((*p)[0], (*p)[1])};
  };
  if (unordered(pair) == unordered(pair_before)) return EventKind::Internal;
  if (sim_.logging_events() && pair) {
    std::array<ObjectId, 2> ids{points_.id((*pair)[0]), points_.id((*pair)[1])};
    std::sort(ids.begin(), ids.end());
    sim_.log_event("pair_change", ids);
  }
  return EventKind::External;
}

void KineticConeClosestPair::refresh_object(std::uint32_t index) {
  for (int c = 0; c < kCones; ++c) {
    const auto k = static_cast<std::size_t>(c);
    // The points whose candidate it was: found again from scratch (it may have jumped).
    for (const std::uint32_t p : candidate_of(c, index)) {
      set_candidate(c, p, kNoIndex);
      rescan(c, p);
    }
    rescan(c, index);
    if (neighbour_[k][index] != kNoIndex)
      tournament_.set(leaf(c, index), index, neighbour_[k][index]);
    // Every other point: the object may now be its candidate.
    for (const std::uint32_t p : sorts_[0]->order()) {
      if (p != index) reconsider(c, p, index);
    }
  }
}

void KineticConeClosestPair::insert(std::uint32_t index) {
  sync_.require_inserted("KineticConeClosestPair::insert", index);
  check_motion(index, "KineticConeClosestPair::insert");
  for (auto& s : sorts_) s->insert(index);
  grow();
  refresh_object(index);
  tournament_.update();
}

void KineticConeClosestPair::motion_changed(std::uint32_t index) {
  sync_.require_updated("KineticConeClosestPair::motion_changed", index);
  check_motion(index, "KineticConeClosestPair::motion_changed");
  for (auto& s : sorts_) s->motion_changed(index);
  refresh_object(index);
  tournament_.update();
}

void KineticConeClosestPair::remove(std::uint32_t index) {
  sync_.require_removed("KineticConeClosestPair::remove", index);
  // The points whose candidate it was lose it; they are scanned again once it left the orders.
  std::vector<std::pair<int, std::uint32_t>> orphans;
  for (int c = 0; c < kCones; ++c) {
    for (const std::uint32_t p : candidate_of(c, index)) {
      set_candidate(c, p, kNoIndex);
      orphans.emplace_back(c, p);
    }
    set_candidate(c, index, kNoIndex);
  }
  for (auto& s : sorts_) s->remove(index);
  for (const auto& [c, p] : orphans) rescan(c, p);
  tournament_.update();
}

std::optional<std::array<std::uint32_t, 2>> KineticConeClosestPair::closest_pair() {
  sync_.require_current("KineticConeClosestPair::closest_pair");
  ++counters_.queries;
  if (points_.size() < 2) return std::nullopt;
  ties_.clear();
  tournament_.ties(ties_);
  const auto ids = [&](std::uint32_t a, std::uint32_t b) {
    const ObjectId i = points_.id(a), j = points_.id(b);
    return i < j ? std::array<ObjectId, 2>{i, j} : std::array<ObjectId, 2>{j, i};
  };
  if (ties_.empty()) {
    // No candidate at all: possible only when the maintained orders disagree about every pair
    // (robust or classic, points within a few rho of each other, e.g. two points passing
    // through each other): every pair is compared exactly now (O(n^2), only then).
    ++counters_.brute_force_passes;
    const auto live = sorts_[0]->order();
    for (std::size_t i = 0; i < live.size(); ++i) {
      for (std::size_t j = i + 1; j < live.size(); ++j) ties_.push_back({live[i], live[j]});
    }
    const Time now = sim_.now();
    PairTournament::Pair shortest = ties_.front();
    for (const PairTournament::Pair& e : ties_) {
      const int s = compare_squared_distances_at(
          moving_point(points_, e[0]), moving_point(points_, e[1]),
          moving_point(points_, shortest[0]), moving_point(points_, shortest[1]), now);
      if (s < 0) shortest = e;
    }
    const MovingPoint2 sa = moving_point(points_, shortest[0]),
                       sb = moving_point(points_, shortest[1]);
    std::erase_if(ties_, [&](const PairTournament::Pair& e) {
      return compare_squared_distances_at(moving_point(points_, e[0]), moving_point(points_, e[1]),
                                          sa, sb, now) != 0;
    });
  }
  PairTournament::Pair best = ties_.front();
  for (const PairTournament::Pair& e : ties_) {
    if (ids(e[0], e[1]) < ids(best[0], best[1])) best = e;
  }
  const Time t = sim_.now();
  const MovingPoint2 a = moving_point(points_, best[0]), b = moving_point(points_, best[1]);
  if (compare_squared_distances_at(a, b, a, a, t) == 0) {
    // Points at one place now: the cones do not see every such pair, so every point is placed
    // exactly and the smallest pair of ids among points at one place is taken.
    ++counters_.coincidence_passes;
    std::vector<std::uint32_t> all(sorts_[0]->order().begin(), sorts_[0]->order().end());
    const auto place = [&](std::uint32_t u, std::uint32_t w) {
      const int sx = compare_at(points_.motion(u, 0), points_.motion(w, 0), t);
      if (sx != 0) return sx < 0;
      const int sy = compare_at(points_.motion(u, 1), points_.motion(w, 1), t);
      if (sy != 0) return sy < 0;
      return points_.id(u) < points_.id(w);
    };
    std::sort(all.begin(), all.end(), place);
    const auto same_place = [&](std::uint32_t u, std::uint32_t w) {
      return compare_at(points_.motion(u, 0), points_.motion(w, 0), t) == 0 &&
             compare_at(points_.motion(u, 1), points_.motion(w, 1), t) == 0;
    };
    // Each place's run is ordered by id: its first two are its smallest pair.
    bool found = false;
    for (std::size_t i = 0; i + 1 < all.size(); ++i) {
      if (i > 0 && same_place(all[i - 1], all[i])) continue;  // not the start of a run
      if (!same_place(all[i], all[i + 1])) continue;
      if (!found || ids(all[i], all[i + 1]) < ids(best[0], best[1])) best = {all[i], all[i + 1]};
      found = true;
    }
  }
  if (points_.id(best[0]) > points_.id(best[1])) std::swap(best[0], best[1]);
  return best;
}

std::size_t KineticConeClosestPair::certificates() const {
  std::size_t n = tournament_.certificates();
  for (const auto& s : sorts_) n += s->certificates();
  return n;
}

std::size_t KineticConeClosestPair::certificates_per_object_max() const {
  std::vector<std::uint32_t> count(points_.capacity(), 0);
  tournament_.count_certificates(count);
  const std::uint32_t best = count.empty() ? 0 : *std::max_element(count.begin(), count.end());
  return sorts_.size() * sorts_[0]->certificates_per_object_max() + best;
}

bool KineticConeClosestPair::validate() const {
  if (!sync_.current()) return false;
  for (const auto& s : sorts_) {
    if (!s->validate()) return false;
  }
  const auto live = sorts_[0]->order();
  for (int c = 0; c < kCones; ++c) {
    const auto k = static_cast<std::size_t>(c);
    const auto order = sorts_[static_cast<std::size_t>(target_of(c))]->order();
    for (const std::uint32_t p : live) {
      // The first point after p in the scan that lies in p's cone, by brute force.
      std::uint32_t want = kNoIndex;
      const std::size_t from = sorts_[static_cast<std::size_t>(target_of(c))]->rank(p);
      for (std::size_t slot = after(c, from); slot != kNoSlot; slot = after(c, slot)) {
        if (in_cone(c, p, order[slot])) {
          want = order[slot];
          break;
        }
      }
      if (neighbour_[k][p] != want) return false;
      const std::optional<PairTournament::Pair> e = tournament_.pair(leaf(c, p));
      if ((want == kNoIndex) != !e) return false;
      if (e && ((*e)[0] != p || (*e)[1] != want)) return false;
    }
    // The reverse lists: each point once, in the list of its candidate.
    std::size_t listed = 0, with = 0;
    for (const std::uint32_t q : live) {
      std::uint32_t before = kNoIndex;
      for (std::uint32_t p = head_[k][q]; p != kNoIndex; p = next_[k][p]) {
        if (neighbour_[k][p] != q || prev_[k][p] != before) return false;
        before = p;
        if (++listed > live.size()) return false;
      }
    }
    for (const std::uint32_t p : live) with += neighbour_[k][p] != kNoIndex ? 1 : 0;
    if (listed != with) return false;
  }
  // Leaves of points not in the table are empty.
  for (std::uint32_t l = 0; l < tournament_.leaves(); ++l) {
    const std::uint32_t p = l / kCones;
    if (tournament_.pair(l) && (p >= points_.capacity() || !points_.alive_index(p))) return false;
  }
  return tournament_.validate();
}

namespace {

/// The loop guard's bounds. The eight orders' swaps are crossings of pairs along eight directions.
/// A swap changes at most n + 2 candidates (the reverse list of the point passed, and the two
/// swapped), and each changed candidate and each length event re-decides at most the height of
/// the tournament (< 64) of nodes, each of which fails at most once per instant (a new decision
/// fails strictly later) and, over a run, at most 6 times per piece of motion (a length
/// comparison has degree <= 6).
LoopGuard cone_closest_pair_event_bounds(const RunBounds& b) {
  const LoopGuard swaps = crossing_guard(8, b.max_objects, b.motion_changes, b.max_degree);
  const std::uint64_t n = std::max<std::uint64_t>(1, b.max_objects);
  const std::uint64_t nodes = 8 * n;
  LoopGuard g;
  g.max_events_per_instant =
      saturating_product({swaps.max_events_per_instant, (n + 2) * 64 + 1}) + nodes * 64;
  g.max_events_total = saturating_product({swaps.max_events_total, (n + 2) * 64 * 6 + 1}) +
                       saturating_product({nodes, 64, 6, b.motion_changes + 1});
  return g;
}

}  // namespace

StructureDescription KineticConeClosestPair::description() {
  return StructureDescription{
      "closest-pair",
      "ClosestPair",
      ObjectsAre::Points,
      {QueryType::ClosestPair},
      {"pair_change"},
      "The kinetic closest pair of points in the plane from cones (closest_pair()); every "
      "scheduler, robust by default (the answer within the bound of docs/closest-pair.md).",
      "kinetic closest pair of points in the plane (each point's candidates in eight cones, kept "
      "with kinetic sorted orders along eight directions, and a kinetic tournament over their "
      "lengths; Basch, Guibas, Zhang): the closest pair"}
      .limit_dimensions(2, 2, "points in the plane")
      .limit_degree(
          KineticConeClosestPair::kMaxDegree,
          "its length certificates have twice the motions' degree, and CROP takes at most 6")
      .limit_coefficients(KineticConeClosestPair::kCoefficientLog2,
                          "its orders along 2x + y and x + 2y read twice a coordinate exactly")
      .bound_events(cone_closest_pair_event_bounds);
}

}  // namespace kinetic
