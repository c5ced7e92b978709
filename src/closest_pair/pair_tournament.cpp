#include "kinetic/closest_pair/pair_tournament.hpp"

#include <algorithm>
#include <cassert>

#include "kinetic/core/exact_time.hpp"

namespace kinetic {

PairTournament::PairTournament(const MotionTable& points, Simulator& simulator,
                               const Scheduler& scheduler)
    : tree_(simulator, simulator.reserve_owners(1).first,
            Keys{&points, &simulator, &scheduler, {}, 0}) {}

LengthComparison PairTournament::Keys::comparison(std::uint32_t x, std::uint32_t y) const {
  const Pair& a = pair[x];
  const Pair& b = pair[y];
  return LengthComparison{{moving_point(*points, a[0]), moving_point(*points, a[1]),
                           moving_point(*points, b[0]), moving_point(*points, b[1])}};
}

Time PairTournament::Keys::window_lo(std::uint32_t x, std::uint32_t y) const {
  Time t = -kTimeInfinity;
  for (const std::uint32_t leaf : {x, y})
    for (const std::uint32_t p : pair[leaf]) t = std::max(t, points->valid_from(p));
  return t;
}

bool PairTournament::Keys::tie_before(std::uint32_t x, std::uint32_t y) const {
  const auto ids = [&](std::uint32_t leaf) {
    const ObjectId i = points->id(pair[leaf][0]), j = points->id(pair[leaf][1]);
    return i < j ? std::array<ObjectId, 2>{i, j} : std::array<ObjectId, 2>{j, i};
  };
  return ids(x) < ids(y);
}

Scheduler::MaxDecision PairTournament::Keys::decide(std::size_t /*node*/, std::uint32_t a,
                                                    std::uint32_t b) {
  if (const Pair& x = pair[a], &y = pair[b];
      (x[0] == y[0] && x[1] == y[1]) || (x[0] == y[1] && x[1] == y[0])) {
    // The same pair in two leaves (a candidate of both its points): equal for ever, no
    // certificate (a root isolation would find the zero polynomial the long way).
    return {false, kTimeInfinity, std::nullopt};
  }
  ++decisions;
  // f = |a|^2 - |b|^2: a wins (is shorter) just after now when f < 0.
  Scheduler::SignDecision d =
      scheduler->decide(comparison(a, b), sim->now(), window_lo(a, b), sim->counters());
  return {d.sign < 0 || (d.sign == 0 && tie_before(a, b)), d.failure, std::move(d.exact)};
}

void PairTournament::touch(std::uint32_t leaf) {
  if (changed_leaf_[leaf] != 0) return;
  changed_leaf_[leaf] = 1;
  changed_leaves_.push_back(leaf);
}

void PairTournament::set(std::uint32_t leaf, std::uint32_t a, std::uint32_t b) {
  assert(leaf < capacity() && a != b && a != kNoIndex && b != kNoIndex);
  tree_.keys().pair[leaf] = {a, b};
  touch(leaf);
}

void PairTournament::clear(std::uint32_t leaf) {
  assert(leaf < capacity());
  tree_.keys().pair[leaf] = {kNoIndex, kNoIndex};
  touch(leaf);
}

void PairTournament::lay_out(std::size_t capacity) {
  tree_.keys().pair.resize(capacity, Pair{kNoIndex, kNoIndex});
  changed_leaf_.assign(capacity, 0);
  changed_leaves_.clear();
  tree_.assign(2 * capacity);  // every certificate cancelled
  tree_.topology().capacity = capacity;
}

void PairTournament::reset(std::size_t count) {
  std::size_t capacity = 1;
  while (capacity < count) capacity *= 2;
  tree_.keys().pair.clear();
  lay_out(capacity);
}

void PairTournament::reserve(std::size_t count) {
  if (count <= capacity()) return;
  std::size_t capacity = std::max<std::size_t>(1, this->capacity());
  while (capacity < count) capacity *= 2;
  lay_out(capacity);  // the pairs kept
  decide_all();
}

void PairTournament::decide_all() {
  tree_.cancel_all();
  for (std::uint32_t l = 0; l < capacity(); ++l) {
    tree_.set_leaf(tree_.topology().leaf(l), entry(l));
    changed_leaf_[l] = 0;
  }
  changed_leaves_.clear();
  for (std::size_t v = capacity(); v-- > 1;) tree_.decide(v);
}

bool PairTournament::decide(std::size_t v) {
  const bool changed = tree_.decide(v);
  const std::uint32_t w = tree_.winner(v);
  return changed || (w != kNoIndex && changed_leaf_[w] != 0);
}

void PairTournament::update() {
  if (changed_leaves_.empty()) return;
  changed_.clear();
  for (const std::uint32_t l : changed_leaves_) {
    tree_.set_leaf(tree_.topology().leaf(l), entry(l));
    if (capacity() > 1)
      changed_.push_back(static_cast<std::uint32_t>(tree_.topology().leaf(l) / 2));
  }
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
  const std::size_t v = tree_.take_event(event);
  assert(v >= 1 && v < capacity() && changed_leaves_.empty());
  ++counters_.events;
  if (tree_.decide(v)) tree_.climb(v);
}

void PairTournament::ties(std::vector<Pair>& out) {
  if (capacity() == 0 || tree_.winner(1) == kNoIndex) return;
  const Keys& keys = tree_.keys();
  const Pair w = keys.pair[tree_.winner(1)];
  const MovingPoint2 wa = moving_point(*keys.points, w[0]), wb = moving_point(*keys.points, w[1]);
  const Time t = keys.sim->now();
  counters_.tie_visits += tree_.for_each_tie(
      1,
      [&](std::uint32_t x) {
        const Pair& e = keys.pair[x];
        // The winner's own pair in another leaf (a candidate of both its points) ties without
        // a comparison (an exact one would reach rational arithmetic: the lengths are equal).
        const bool same = (e[0] == w[0] && e[1] == w[1]) || (e[0] == w[1] && e[1] == w[0]);
        return same ||
               compare_squared_distances_at(moving_point(*keys.points, e[0]),
                                            moving_point(*keys.points, e[1]), wa, wb, t) == 0;
      },
      [&](std::uint32_t x) { out.push_back(keys.pair[x]); });
}

void PairTournament::count_certificates(std::vector<std::uint32_t>& count) const {
  tree_.for_each_certificate([&](std::size_t, std::uint32_t w, std::uint32_t l) {
    for (const std::uint32_t leaf : {w, l})
      for (const std::uint32_t p : tree_.keys().pair[leaf]) ++count[p];
  });
}

bool PairTournament::validate() const {
  if (!changed_leaves_.empty()) return false;  // every change taken
  const Keys& keys = tree_.keys();
  LazyTime now = keys.sim->exact_now();
  const bool exact = keys.scheduler->kind() == SchedulerKind::Exact;
  for (std::uint32_t l = 0; l < capacity(); ++l) {
    const Pair& p = keys.pair[l];
    if (tree_.winner(tree_.topology().leaf(l)) != entry(l)) return false;
    if (p[0] != kNoIndex &&
        (p[0] == p[1] || !keys.points->alive_index(p[0]) || !keys.points->alive_index(p[1])))
      return false;
  }
  return tree_.validate([&](std::size_t, std::uint32_t w, std::uint32_t l, const Event* event) {
    // Under the exact scheduler the winner is also the shorter just after now (ties by ids),
    // unless its event is due now.
    const bool due = event != nullptr && event->time <= now.upper();
    if (!exact || due) return true;
    const int s = sign_after(keys.comparison(w, l), now);  // |w|^2 - |l|^2
    return !(s > 0 || (s == 0 && keys.tie_before(l, w)));
  });
}

}  // namespace kinetic
