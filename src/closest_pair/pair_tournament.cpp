#include "kinetic/closest_pair/pair_tournament.hpp"

#include <algorithm>
#include <cassert>

#include "kinetic/core/exact_time.hpp"

namespace kinetic {

PairTournament::PairTournament(const MotionTable& points, Simulator& simulator,
                               const Scheduler& scheduler)
    : points_(points),
      sim_(simulator),
      scheduler_(scheduler),
      owner_(simulator.reserve_owners(1).first) {}

LengthComparison PairTournament::comparison(std::uint32_t x, std::uint32_t y) const {
  const Pair& a = pair_[x];
  const Pair& b = pair_[y];
  return LengthComparison{{moving_point(points_, a[0]), moving_point(points_, a[1]),
                           moving_point(points_, b[0]), moving_point(points_, b[1])}};
}

Time PairTournament::window_lo(std::uint32_t x, std::uint32_t y) const {
  Time t = -kTimeInfinity;
  for (const std::uint32_t leaf : {x, y})
    for (const std::uint32_t p : pair_[leaf]) t = std::max(t, points_.valid_from(p));
  return t;
}

bool PairTournament::tie_before(std::uint32_t x, std::uint32_t y) const {
  const auto ids = [&](std::uint32_t leaf) {
    const ObjectId i = points_.id(pair_[leaf][0]), j = points_.id(pair_[leaf][1]);
    return i < j ? std::array<ObjectId, 2>{i, j} : std::array<ObjectId, 2>{j, i};
  };
  return ids(x) < ids(y);
}

void PairTournament::touch(std::uint32_t leaf) {
  if (changed_leaf_[leaf] != 0) return;
  changed_leaf_[leaf] = 1;
  changed_leaves_.push_back(leaf);
}

void PairTournament::set(std::uint32_t leaf, std::uint32_t a, std::uint32_t b) {
  assert(leaf < capacity_ && a != b && a != kNoIndex && b != kNoIndex);
  pair_[leaf] = {a, b};
  touch(leaf);
}

void PairTournament::clear(std::uint32_t leaf) {
  assert(leaf < capacity_);
  pair_[leaf] = {kNoIndex, kNoIndex};
  touch(leaf);
}

void PairTournament::lay_out(std::size_t capacity) {
  for (EventHandle& h : certificate_) sim_.cancel(h);
  pair_.resize(capacity, Pair{kNoIndex, kNoIndex});
  changed_leaf_.assign(capacity, 0);
  changed_leaves_.clear();
  capacity_ = capacity;
  winner_.assign(2 * capacity_, kNoIndex);
  certificate_.assign(2 * capacity_, EventHandle{});
  both_.assign(2 * capacity_, 0);
  certificates_ = 0;
}

void PairTournament::reset(std::size_t count) {
  std::size_t capacity = 1;
  while (capacity < count) capacity *= 2;
  pair_.clear();
  lay_out(capacity);
}

void PairTournament::reserve(std::size_t count) {
  if (count <= capacity_) return;
  std::size_t capacity = std::max<std::size_t>(1, capacity_);
  while (capacity < count) capacity *= 2;
  lay_out(capacity);  // the pairs kept
  decide_all();
}

void PairTournament::decide_all() {
  for (EventHandle& h : certificate_) sim_.cancel(h);
  for (std::uint32_t l = 0; l < capacity_; ++l) {
    winner_[capacity_ + l] = pair_[l][0] == kNoIndex ? kNoIndex : l;
    changed_leaf_[l] = 0;
  }
  if (capacity_ == 1) winner_[1] = pair_[0][0] == kNoIndex ? kNoIndex : 0;
  changed_leaves_.clear();
  for (std::size_t v = capacity_; v-- > 1;) decide(v);
}

bool PairTournament::decide(std::size_t v) {
  assert(!is_leaf(v));
  const std::uint32_t a = winner_[2 * v], b = winner_[2 * v + 1];
  const std::uint32_t before = winner_[v];
  EventHandle& h = certificate_[v];
  const std::uint8_t both = a != kNoIndex && b != kNoIndex ? 1 : 0;
  certificates_ = certificates_ + both - both_[v];
  both_[v] = both;
  std::uint32_t w = kNoIndex;
  if (a == kNoIndex || b == kNoIndex) {
    sim_.cancel(h);
    w = a == kNoIndex ? b : a;
  } else if (const Pair &x = pair_[a], &y = pair_[b];
             (x[0] == y[0] && x[1] == y[1]) || (x[0] == y[1] && x[1] == y[0])) {
    // The same pair in two leaves (a candidate of both its points): equal for ever, no
    // certificate (a root isolation would find the zero polynomial the long way).
    sim_.cancel(h);
    w = b;
  } else {
    ++counters_.nodes_redecided;
    // f = |a|^2 - |b|^2: a wins (is shorter) just after now when f < 0.
    Scheduler::SignDecision d =
        scheduler_.decide(comparison(a, b), sim_.now(), window_lo(a, b), sim_.counters());
    w = d.sign < 0 || (d.sign == 0 && tie_before(a, b)) ? a : b;
    sim_.reschedule(h, d.failure, std::move(d.exact), owner_, static_cast<std::uint32_t>(v));
  }
  winner_[v] = w;
  return w != before || (w != kNoIndex && changed_leaf_[w] != 0);
}

void PairTournament::update() {
  if (changed_leaves_.empty()) return;
  changed_.clear();
  for (const std::uint32_t l : changed_leaves_) {
    winner_[capacity_ + l] = pair_[l][0] == kNoIndex ? kNoIndex : l;
    if (capacity_ > 1) changed_.push_back(static_cast<std::uint32_t>((capacity_ + l) / 2));
  }
  if (capacity_ == 1) winner_[1] = pair_[0][0] == kNoIndex ? kNoIndex : 0;
  // Level by level from the leaves up: each changed node is decided once, and its parent joins
  // the next level when its winner (or its winner's pair) changed.
  while (!changed_.empty()) {
    std::sort(changed_.begin(), changed_.end());
    changed_.erase(std::unique(changed_.begin(), changed_.end()), changed_.end());
    next_changed_.clear();
    for (const std::uint32_t v : changed_) {
      if (decide(v) && v > 1) next_changed_.push_back(v / 2);
    }
    changed_.swap(next_changed_);
  }
  for (const std::uint32_t l : changed_leaves_) changed_leaf_[l] = 0;
  changed_leaves_.clear();
}

void PairTournament::process(const Event& event) {
  assert(event.owner == owner_);
  std::size_t v = event.payload;
  assert(v >= 1 && v < capacity_);
  certificate_[v] = EventHandle{};  // popped by the simulator
  ++counters_.events;
  while (decide(v) && v > 1) v /= 2;
}

void PairTournament::ties(std::vector<Pair>& out) {
  const std::uint32_t top = winner();
  if (top == kNoIndex) return;
  const Pair w = pair_[top];
  const MovingPoint2 wa = moving_point(points_, w[0]), wb = moving_point(points_, w[1]);
  const Time t = sim_.now();
  stack_.assign(1, 1);
  while (!stack_.empty()) {
    const std::size_t v = stack_.back();
    stack_.pop_back();
    ++counters_.tie_visits;
    if (is_leaf(v) || capacity_ == 1) {
      out.push_back(pair_[winner_[v]]);
      continue;
    }
    for (const std::size_t c : {2 * v, 2 * v + 1}) {
      const std::uint32_t x = winner_[c];
      if (x == kNoIndex) continue;
      const Pair& e = pair_[x];
      // The winner's own pair in another leaf (a candidate of both its points) ties without a
      // comparison (an exact one would reach rational arithmetic: the lengths are equal).
      const bool same = (e[0] == w[0] && e[1] == w[1]) || (e[0] == w[1] && e[1] == w[0]);
      if (same || compare_squared_distances_at(moving_point(points_, e[0]),
                                               moving_point(points_, e[1]), wa, wb, t) == 0)
        stack_.push_back(static_cast<std::uint32_t>(c));
    }
  }
}

void PairTournament::count_certificates(std::vector<std::uint32_t>& count) const {
  for (std::size_t v = 1; v < capacity_; ++v) {
    const std::uint32_t a = winner_[2 * v], b = winner_[2 * v + 1];
    if (a == kNoIndex || b == kNoIndex) continue;
    for (const std::uint32_t leaf : {a, b})
      for (const std::uint32_t p : pair_[leaf]) ++count[p];
  }
}

bool PairTournament::validate() const {
  if (!changed_leaves_.empty()) return false;  // every change taken
  LazyTime now = sim_.exact_now();
  const bool exact = scheduler_.kind() == SchedulerKind::Exact;
  for (std::uint32_t l = 0; l < capacity_; ++l) {
    const std::size_t node = capacity_ == 1 ? 1 : capacity_ + l;
    if (winner_[node] != (pair_[l][0] == kNoIndex ? kNoIndex : l)) return false;
    if (pair_[l][0] != kNoIndex &&
        (pair_[l][0] == pair_[l][1] || !points_.alive_index(pair_[l][0]) ||
         !points_.alive_index(pair_[l][1])))
      return false;
  }
  std::size_t pairs = 0;
  for (std::size_t v = 1; v < capacity_; ++v) {
    const std::uint32_t a = winner_[2 * v], b = winner_[2 * v + 1], w = winner_[v];
    const EventHandle h = certificate_[v];
    if (a == kNoIndex || b == kNoIndex) {
      if (w != (a == kNoIndex ? b : a) || !h.is_null() || both_[v] != 0) return false;
      continue;
    }
    ++pairs;
    if (w != a && w != b) return false;
    bool due = false;
    if (!h.is_null()) {
      if (!sim_.queue().contains(h)) return false;
      const Event& e = sim_.queue().get(h);
      if (e.owner != owner_ || e.payload != v) return false;
      due = e.time <= now.upper();
    }
    if (exact && !due) {
      const std::uint32_t l = w == a ? b : a;
      const int s = sign_after(comparison(w, l), now);  // |w|^2 - |l|^2
      if (s > 0 || (s == 0 && tie_before(l, w))) return false;
    }
  }
  return pairs == certificates_;
}

}  // namespace kinetic
