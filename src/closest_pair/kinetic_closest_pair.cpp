#include "kinetic/closest_pair/kinetic_closest_pair.hpp"

#include <algorithm>
#include <cassert>
#include <stdexcept>

#include "kinetic/core/exact_time.hpp"
#include "kinetic/core/free_list.hpp"
#include "kinetic/core/incircle.hpp"

namespace kinetic {

KineticClosestPair::KineticClosestPair(const MotionTable& points, Simulator& simulator,
                                       const Scheduler& scheduler)
    : points_(points),
      sim_(simulator),
      scheduler_(scheduler),
      dt_(points, simulator, scheduler),
      owner_(simulator.reserve_owners(1).first) {}

NamedCounters KineticClosestPair::named_counters() const {
  NamedCounters out = dt_.named_counters();
  for (NamedCounter& c : out) {
    if (c.name == "events") c.name = "flip_events";
    if (c.name == "rebuilds") c.name = "triangulation_rebuilds";
    if (c.name == "queries") c.name = "triangulation_queries";
  }
  out.insert(out.begin(), {{"events", dt_.counters().events + counters_.events},
                           {"tournament_events", counters_.events},
                           {"edge_inserts", counters_.edge_inserts},
                           {"edge_removes", counters_.edge_removes},
                           {"rebuilds", counters_.rebuilds},
                           {"nodes_redecided", counters_.nodes_redecided},
                           {"queries", counters_.queries},
                           {"tie_visits", counters_.tie_visits}});
  return out;
}

KineticClosestPair::Pair KineticClosestPair::ends(std::uint32_t record) const {
  return {PairSet::first(key_[record]), PairSet::second(key_[record])};
}

LengthComparison KineticClosestPair::comparison(std::uint32_t x, std::uint32_t y) const {
  const Pair a = ends(x), b = ends(y);
  return LengthComparison{{moving_point(points_, a[0]), moving_point(points_, a[1]),
                           moving_point(points_, b[0]), moving_point(points_, b[1])}};
}

bool KineticClosestPair::tie_before(std::uint32_t x, std::uint32_t y) const {
  const auto ids = [&](std::uint32_t r) {
    const Pair e = ends(r);
    const ObjectId i = points_.id(e[0]), j = points_.id(e[1]);
    return i < j ? std::array<ObjectId, 2>{i, j} : std::array<ObjectId, 2>{j, i};
  };
  return ids(x) < ids(y);
}

void KineticClosestPair::cancel(std::size_t v) {
  EventHandle& h = certificate_[v];
  if (!h.is_null()) {
    if (sim_.queue().contains(h)) {
      sim_.queue().remove(h);
      --queued_;
    }
    h = EventHandle{};
  }
}

bool KineticClosestPair::decide(std::size_t v) {
  assert(!is_leaf(v));
  const std::uint32_t a = winner_[2 * v], b = winner_[2 * v + 1];
  const std::uint32_t before = winner_[v];
  cancel(v);
  std::uint32_t w = kNoIndex;
  if (a == kNoIndex || b == kNoIndex) {
    w = a == kNoIndex ? b : a;
  } else {
    ++counters_.nodes_redecided;
    // f = |a|^2 - |b|^2: a wins (is shorter) just after now when f < 0.
    const Scheduler::SignDecision d = scheduler_.decide(comparison(a, b), sim_.counters());
    w = d.sign < 0 || (d.sign == 0 && tie_before(a, b)) ? a : b;
    if (d.failure != kTimeInfinity) {
      certificate_[v] = sim_.schedule(d.failure, d.exact, owner_, static_cast<std::uint32_t>(v));
      ++queued_;
    }
  }
  winner_[v] = w;
  return w != before;
}

void KineticClosestPair::layout(std::size_t capacity) {
  for (std::size_t v = 1; v < certificate_.size(); ++v) cancel(v);
  capacity_ = capacity;
  winner_.assign(2 * capacity_, kNoIndex);
  certificate_.assign(2 * capacity_, EventHandle{});
  for (std::uint32_t r = 0; r < key_.size(); ++r) {
    if (held_[r] > 0) winner_[capacity_ + r] = r;
  }
  certificates_ = edges_.size() > 0 ? edges_.size() - 1 : 0;
  for (std::size_t v = capacity_; v-- > 1;) decide(v);
  changed_.clear();  // every node decided
}

void KineticClosestPair::reread_edges() {
  ++counters_.rebuilds;
  edges_.clear();
  record_of_.clear();
  key_.clear();
  held_.clear();
  free_records_.clear();
  freed_records_.clear();
  grow_ = false;
  dt_.edges(scratch_edges_);
  for (const Pair& e : scratch_edges_) {
    edges_.insert(e[0], e[1]);
    record_of_.push_back(static_cast<std::uint32_t>(key_.size()));
    key_.push_back(PairSet::key(e[0], e[1]));
    held_.push_back(2);  // every edge has two triangles (the vertex at infinity closes the hull)
  }
  std::size_t capacity = 1;
  while (capacity < key_.size()) capacity *= 2;
  layout(capacity);
  dt_.clear_edge_changes();
}

void KineticClosestPair::add_edge(std::uint32_t a, std::uint32_t b) {
  const std::uint32_t r = take_record(key_, free_records_);
  if (held_.size() < key_.size()) held_.resize(key_.size(), 0);
  key_[r] = PairSet::key(a, b);
  held_[r] = 1;
  edges_.insert(a, b);
  record_of_.push_back(r);
  ++counters_.edge_inserts;
  // Full: the tree is laid out again for more leaves once the batch is taken (deciding now could
  // read edges of the batch that are gone, their points with them).
  if (r >= capacity_) grow_ = true;
  if (grow_) return;
  winner_[capacity_ + r] = r;
  if (edges_.size() >= 2) ++certificates_;
  changed_.push_back(static_cast<std::uint32_t>((capacity_ + r) / 2));
}

void KineticClosestPair::remove_edge(std::size_t position) {
  const std::uint32_t r = record_of_[position];
  const Pair e = ends(r);
  edges_.erase(e[0], e[1]);  // the last position takes this one's place
  record_of_[position] = record_of_.back();
  record_of_.pop_back();
  freed_records_.push_back(r);  // reused after this batch: a record names one edge per batch
  held_[r] = 0;
  ++counters_.edge_removes;
  if (grow_) return;  // laid out again at the end of the batch
  winner_[capacity_ + r] = kNoIndex;
  if (edges_.size() >= 1) --certificates_;
  changed_.push_back(static_cast<std::uint32_t>((capacity_ + r) / 2));
}

void KineticClosestPair::decide_changed() {
  // Level by level from the leaves up: the changed nodes of one level are decided once each, and
  // their parents join the next level when their winner changed. Leaves of one tree all lie on
  // one level, so the nodes of changed_ do too.
  while (!changed_.empty()) {
    std::sort(changed_.begin(), changed_.end());
    changed_.erase(std::unique(changed_.begin(), changed_.end()), changed_.end());
    next_changed_.clear();
    for (const std::uint32_t v : changed_) {
      if (v >= 1 && decide(v) && v > 1) next_changed_.push_back(v / 2);
    }
    changed_.swap(next_changed_);
  }
}

void KineticClosestPair::take_edge_changes() {
  if (dt_.edges_rebuilt()) {
    changed_.clear();
    reread_edges();
    return;
  }
  for (const KineticDelaunay::EdgeChange& c : dt_.edge_changes()) {
    const std::size_t pos = edges_.position(c.a, c.b);
    if (c.delta > 0) {
      if (pos == PairSet::npos) {
        add_edge(c.a, c.b);
      } else {
        ++held_[record_of_[pos]];
      }
    } else {
      if (pos == PairSet::npos || held_[record_of_[pos]] == 0) {
        throw std::logic_error(
            "KineticClosestPair: the triangulation reported a missing edge leaving (an internal "
            "failure; please report the scenario)");
      }
      if (--held_[record_of_[pos]] == 0) remove_edge(pos);
    }
  }
  dt_.clear_edge_changes();
  if (grow_) {
    // Double the leaves until every record has one, and decide every node on the batch's
    // final edges (amortized O(1) decisions per edge).
    std::size_t capacity = std::max<std::size_t>(1, 2 * capacity_);
    while (capacity < key_.size()) capacity *= 2;
    grow_ = false;
    layout(capacity);
  } else {
    decide_changed();
  }
  free_records_.insert(free_records_.end(), freed_records_.begin(), freed_records_.end());
  freed_records_.clear();
}

void KineticClosestPair::initialize() {
  dt_.record_edge_changes(true);
  dt_.initialize();
  reread_edges();
  --counters_.rebuilds;  // the first build is not a rebuild
}

EventKind KineticClosestPair::process(const Event& event) {
  const std::uint32_t top_before = winner_.size() > 1 ? winner_[1] : kNoIndex;
  const std::uint64_t key_before = top_before == kNoIndex ? 0 : key_[top_before];
  if (event.owner == owner_) {
    const std::size_t v = event.payload;
    assert(v >= 1 && v < capacity_);
    certificate_[v] = EventHandle{};  // popped by the simulator
    --queued_;
    ++counters_.events;
    if (decide(v)) {
      for (std::size_t u = v / 2; u >= 1; u /= 2) {
        if (!decide(u)) break;
      }
    }
  } else {
    (void)dt_.process(event);
    take_edge_changes();
  }
  const std::uint32_t top = winner_.size() > 1 ? winner_[1] : kNoIndex;
  if (top == top_before && (top == kNoIndex || key_[top] == key_before)) return EventKind::Internal;
  if (sim_.logging_events() && top != kNoIndex) {
    const Pair e = ends(top);
    std::array<ObjectId, 2> ids{points_.id(e[0]), points_.id(e[1])};
    std::sort(ids.begin(), ids.end());
    sim_.log_event("pair_change", ids);
  }
  return EventKind::External;
}

void KineticClosestPair::insert(std::uint32_t index) {
  dt_.insert(index);
  take_edge_changes();
}

void KineticClosestPair::remove(std::uint32_t index) {
  dt_.remove(index);
  take_edge_changes();
}

void KineticClosestPair::motion_changed(std::uint32_t index) {
  dt_.motion_changed(index);
  take_edge_changes();
}

std::optional<std::array<std::uint32_t, 2>> KineticClosestPair::closest_pair() {
  ++counters_.queries;
  if (dt_.flat()) return dt_.closest_pair();
  // Every edge as short as the winner now: a subtree whose winner is longer now holds none (its
  // winner is the shortest of the subtree just after now, hence now too).
  scratch_edges_.clear();
  if (capacity_ > 0 && winner_[1] != kNoIndex) {
    const Pair w = ends(winner_[1]);
    const MovingPoint2 wa = moving_point(points_, w[0]), wb = moving_point(points_, w[1]);
    const Time t = sim_.now();
    stack_.assign(1, 1);
    while (!stack_.empty()) {
      const std::size_t v = stack_.back();
      stack_.pop_back();
      ++counters_.tie_visits;
      if (is_leaf(v)) {
        scratch_edges_.push_back(ends(winner_[v]));
        continue;
      }
      for (const std::size_t c : {2 * v, 2 * v + 1}) {
        const std::uint32_t x = winner_[c];
        if (x == kNoIndex) continue;
        const Pair e = ends(x);
        if (x == winner_[1] ||
            compare_squared_distances_at(moving_point(points_, e[0]), moving_point(points_, e[1]),
                                         wa, wb, t) == 0)
          stack_.push_back(static_cast<std::uint32_t>(c));
      }
    }
  }
  return dt_.closest_pair_among(scratch_edges_);
}

std::size_t KineticClosestPair::certificates() const { return dt_.certificates() + certificates_; }

std::size_t KineticClosestPair::certificates_per_object_max() const {
  std::vector<std::uint32_t> count(points_.capacity(), 0);
  std::uint32_t best = 0;
  for (std::size_t v = 1; v < capacity_; ++v) {
    const std::uint32_t a = winner_[2 * v], b = winner_[2 * v + 1];
    if (a == kNoIndex || b == kNoIndex) continue;
    for (const std::uint32_t r : {a, b}) {
      for (const std::uint32_t p : ends(r)) best = std::max(best, ++count[p]);
    }
  }
  return dt_.certificates_per_object_max() + best;
}

bool KineticClosestPair::validate() const {
  if (!dt_.validate()) return false;
  if (!dt_.edge_changes().empty() || dt_.edges_rebuilt()) return false;  // all taken
  // The same edges as the triangulation, each held twice.
  std::vector<Pair> current;
  dt_.edges(current);
  if (current.size() != edges_.size()) return false;
  for (const Pair& e : current) {
    const std::size_t pos = edges_.position(e[0], e[1]);
    if (pos == PairSet::npos || held_[record_of_[pos]] != 2) return false;
  }
  if (record_of_.size() != edges_.size()) return false;
  for (std::size_t pos = 0; pos < record_of_.size(); ++pos) {
    const std::uint32_t r = record_of_[pos];
    if (r >= key_.size() || key_[r] != edges_.keys()[pos] || r >= capacity_ ||
        winner_[capacity_ + r] != r)
      return false;
  }
  std::size_t leaves = 0;
  for (std::size_t leaf = capacity_; leaf < 2 * capacity_; ++leaf) {
    if (winner_[leaf] != kNoIndex) ++leaves;
  }
  if (leaves != edges_.size()) return false;
  // The tournament: winners from the children, the shorter just after now unless due now.
  LazyTime now = sim_.exact_now();
  std::size_t pairs = 0, queued = 0;
  for (std::size_t v = 1; v < capacity_; ++v) {
    const std::uint32_t a = winner_[2 * v], b = winner_[2 * v + 1], w = winner_[v];
    const EventHandle h = certificate_[v];
    if (a == kNoIndex || b == kNoIndex) {
      if (w != (a == kNoIndex ? b : a) || !h.is_null()) return false;
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
      ++queued;
    }
    const std::uint32_t l = w == a ? b : a;
    const int s = sign_after(comparison(w, l), now);  // |w|^2 - |l|^2
    if (!due && (s > 0 || (s == 0 && !tie_before(w, l)))) return false;
  }
  // No other events of the tournament (every one scheduled, popped or cancelled was counted).
  return pairs == certificates_ && queued == queued_;
}

}  // namespace kinetic
