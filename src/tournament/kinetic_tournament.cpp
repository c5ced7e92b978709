#include "kinetic/tournament/kinetic_tournament.hpp"

#include <algorithm>
#include <array>
#include <cassert>

#include "kinetic/core/predicates.hpp"

namespace kinetic {

KineticTournament::KineticTournament(const MotionTable& motions, Simulator& simulator,
                                     const Scheduler& scheduler, int axis, Extreme extreme)
    : motions_(motions),
      sim_(simulator),
      scheduler_(scheduler),
      axis_(axis),
      extreme_(extreme),
      owner_(simulator.reserve_owners(1).first) {
  require_axis("KineticTournament", axis, motions.dimension());
  if (extreme != Extreme::Max && extreme != Extreme::Min) {
    precondition_failed("KineticTournament", "extreme is neither Max nor Min");
  }
  simulator.attach(scheduler);
}

std::vector<std::vector<std::optional<std::uint32_t>>> KineticTournament::winner_levels(
    int levels) const {
  std::vector<std::vector<std::optional<std::uint32_t>>> out;
  // Node 1 is the root; level k holds nodes 2^k .. 2^(k+1) - 1 (the leaves at 2^height).
  for (std::size_t first = 1; first < 2 * capacity_ && static_cast<int>(out.size()) < levels;
       first *= 2) {
    std::vector<std::optional<std::uint32_t>> level;
    for (std::size_t v = first; v < 2 * first; ++v) {
      if (winner_[v] == kNoIndex) {
        level.push_back(std::nullopt);
      } else {
        level.push_back(winner_[v]);
      }
    }
    out.push_back(std::move(level));
  }
  return out;
}

NamedCounters KineticTournament::named_counters() const {
  return {{"events", counters_.events},
          {"inserts", counters_.inserts},
          {"removes", counters_.removes},
          {"updates", counters_.updates},
          {"rebuilds", counters_.rebuilds},
          {"nodes_redecided", counters_.nodes_redecided},
          {"scheduled_not_in_future", counters_.scheduled_not_in_future}};
}

Scheduler::MaxDecision KineticTournament::compare(std::uint32_t x, std::uint32_t y) const {
  const Time window_lo = std::max(motions_.valid_from(x), motions_.valid_from(y));
  const MotionPolynomial& px = motions_.motion(x, axis_);
  const MotionPolynomial& py = motions_.motion(y, axis_);
  // For a minimum, x wins when y is the maximum of the two; the certificate [x < y] is then the
  // one COMPUTEMAX(y, x) leaves, [loser < winner] in the max sense.
  return extreme_ == Extreme::Max
             ? scheduler_.compute_max(px, py, sim_.now(), window_lo, sim_.counters())
             : scheduler_.compute_max(py, px, sim_.now(), window_lo, sim_.counters());
}

void KineticTournament::cancel(std::size_t v) { sim_.cancel(certificate_[v]); }

void KineticTournament::schedule(std::size_t v, Time failure, const ExactFailure& exact) {
  if (scheduler_.kind() == SchedulerKind::Robust && failure <= sim_.now())
    ++counters_.scheduled_not_in_future;  // Lemma 4 says this never happens
  // A node's certificate replaced: its event moved in place when it has one (none when the
  // failure is infinite).
  sim_.reschedule(certificate_[v], failure, exact, owner_, static_cast<std::uint32_t>(v));
}

bool KineticTournament::decide(std::size_t v) {
  assert(!is_leaf(v));
  const std::uint32_t a = winner_[2 * v], b = winner_[2 * v + 1];
  const std::uint32_t before = winner_[v];
  std::uint32_t w = kNoIndex;
  if (a == kNoIndex || b == kNoIndex) {
    cancel(v);  // one child: no certificate
    w = a == kNoIndex ? b : a;
  } else {
    ++counters_.nodes_redecided;
    const Scheduler::MaxDecision d = compare(a, b);
    w = d.first_wins ? a : b;
    schedule(v, d.failure, d.exact);
  }
  winner_[v] = w;
  return w != before;
}

void KineticTournament::rebuild(std::size_t capacity) {
  std::vector<std::uint32_t> objects;
  for (std::size_t v = 1; v < certificate_.size(); ++v) cancel(v);
  if (capacity_ > 0) {
    for (std::size_t leaf = capacity_; leaf < 2 * capacity_; ++leaf) {
      if (winner_[leaf] != kNoIndex) objects.push_back(winner_[leaf]);
    }
  }
  std::sort(objects.begin(), objects.end());
  capacity_ = capacity;
  height_ = 0;
  while ((std::size_t{1} << height_) < capacity_) ++height_;
  winner_.assign(2 * capacity_, kNoIndex);
  certificate_.assign(2 * capacity_, EventHandle{});
  leaf_of_.assign(motions_.capacity(), 0);
  free_.clear();
  for (std::size_t k = 0; k < objects.size(); ++k) {
    winner_[capacity_ + k] = objects[k];
    leaf_of_[objects[k]] = static_cast<std::uint32_t>(capacity_ + k);
  }
  for (std::size_t leaf = 2 * capacity_; leaf-- > capacity_ + objects.size();)
    free_.push_back(static_cast<std::uint32_t>(leaf));  // popped lowest first
  size_ = objects.size();
  for (std::size_t v = capacity_; v-- > 1;) decide(v);
  certificates_ = size_ > 0 ? size_ - 1 : 0;
  ++counters_.rebuilds;
}

void KineticTournament::initialize() {
  sync_.note();
  const std::vector<std::uint32_t> objects = motions_.alive_indices();
  std::size_t capacity = 1;
  while (capacity < objects.size()) capacity *= 2;
  for (std::size_t v = 1; v < certificate_.size(); ++v) cancel(v);
  capacity_ = capacity;
  winner_.assign(2 * capacity_, kNoIndex);
  certificate_.assign(2 * capacity_, EventHandle{});
  for (std::size_t k = 0; k < objects.size(); ++k) winner_[capacity_ + k] = objects[k];
  // rebuild() reads the leaves just written and lays the tree out again, deciding every node.
  rebuild(capacity_);
  --counters_.rebuilds;  // the first build is not a rebuild
}

void KineticTournament::certify(std::size_t v, std::uint32_t w, std::uint32_t l) {
  // [l < w] in the extreme's sense, its failure from the scheduler (no decision).
  const Time window_lo = std::max(motions_.valid_from(w), motions_.valid_from(l));
  const MotionPolynomial& pw = motions_.motion(w, axis_);
  const MotionPolynomial& pl = motions_.motion(l, axis_);
  const Time failure =
      extreme_ == Extreme::Max
          ? scheduler_.failure_time(pl, pw, sim_.now(), window_lo, sim_.counters())
          : scheduler_.failure_time(pw, pl, sim_.now(), window_lo, sim_.counters());
  schedule(v, failure, std::nullopt);
}

void KineticTournament::propagate_traditionally(std::size_t v, std::uint32_t old) {
  // The winner of v changed from `old` to winner_[v]. At the parent u: when u's winner was
  // `old`, u is decided again (floating point, Scheduler::compute_max) and the change goes on
  // up; otherwise u's winner came from the other child and is trusted to stay ahead (the new
  // winner below just crossed `old`, which u's winner beat): only u's certificate now watches
  // the new pair, and the walk stops. A node left wrong by a dropped event stays wrong until a
  // change reaches it through its winner's side.
  for (std::size_t u = v / 2; u >= 1; v = u, u /= 2) {
    const std::uint32_t now_below = winner_[v];
    const std::uint32_t before = winner_[u];
    if (before == old) {
      decide(u);  // (old is in neither child now: u's winner changes, the walk goes on)
      continue;
    }
    certify(u, before, now_below);  // before stays ahead of the new winner below
    return;
  }
}

EventKind KineticTournament::process(const Event& event) {
  const std::size_t v = event.payload;
  assert(v >= 1 && v < capacity_);
  certificate_[v] = EventHandle{};  // popped by the simulator
  ++counters_.events;
  const std::uint32_t top_before = winner_[1];
  if (scheduler_.kind() != SchedulerKind::Classic) {
    // Algorithm KINETICTOURNAMENT, lines 5-14: COMPUTEMAX from u towards the root, EVENTTIME for
    // the new certificates (the exact scheduler: exact decisions at the exact event time).
    decide(v);
    for (std::size_t u = v / 2; u >= 1; u /= 2) {
      if (!decide(u)) break;
    }
  } else {
    // A traditional KDS trusts the event: the certificate [loser < winner] failed, so the loser
    // wins now; its new certificate is scheduled from floating-point roots.
    const std::uint32_t a = winner_[2 * v], b = winner_[2 * v + 1];
    assert(a != kNoIndex && b != kNoIndex);
    const std::uint32_t old = winner_[v];
    const std::uint32_t w = old == a ? b : a;
    winner_[v] = w;
    certify(v, w, old);
    if (scheduler_.classic_exact_decisions()) {
      // The careful variant: the ancestors re-decided by exact comparisons (COMPUTEMAX) until
      // one keeps its winner.
      for (std::size_t u = v / 2; u >= 1; u /= 2) {
        if (!decide(u)) break;
      }
    } else {
      propagate_traditionally(v, old);
    }
  }
  if (winner_[1] == top_before) return EventKind::Internal;
  if (sim_.logging_events()) {  // the top changed: [old, new]
    const std::array<ObjectId, 2> ids{motions_.id(top_before), motions_.id(winner_[1])};
    sim_.log_event(extreme_ == Extreme::Max ? "max_change" : "min_change", ids, axis_);
  }
  return EventKind::External;
}

void KineticTournament::insert(std::uint32_t index) {
  sync_.require_inserted("KineticTournament::insert", index);
  assert(motions_.alive_index(index));
  ++counters_.inserts;
  if (leaf_of_.size() < motions_.capacity()) leaf_of_.resize(motions_.capacity(), 0);
  if (free_.empty()) {
    // Full: double the slots and lay the tree out again (amortized O(1) decisions per insert).
    rebuild(std::max<std::size_t>(1, 2 * capacity_));
    // rebuild() kept the old points; the new one takes the first free slot below.
  }
  const std::uint32_t leaf = free_.back();
  free_.pop_back();
  winner_[leaf] = index;
  leaf_of_[index] = leaf;
  ++size_;
  if (size_ >= 2) ++certificates_;
  for (std::size_t u = leaf / 2; u >= 1; u /= 2) decide(u);  // every certificate it joins
}

void KineticTournament::remove(std::uint32_t index) {
  sync_.require_removed("KineticTournament::remove", index);
  assert(index < leaf_of_.size() && leaf_of_[index] != 0);
  ++counters_.removes;
  const std::uint32_t leaf = leaf_of_[index];
  leaf_of_[index] = 0;
  winner_[leaf] = kNoIndex;
  free_.push_back(leaf);
  --size_;
  if (size_ >= 1) --certificates_;
  for (std::size_t u = leaf / 2; u >= 1; u /= 2) decide(u);
}

void KineticTournament::motion_changed(std::uint32_t index) {
  sync_.require_updated("KineticTournament::motion_changed", index);
  assert(index < leaf_of_.size() && leaf_of_[index] != 0);
  ++counters_.updates;
  for (std::size_t u = leaf_of_[index] / 2; u >= 1; u /= 2) decide(u);
}

std::optional<std::uint32_t> KineticTournament::top() const {
  sync_.require_current("KineticTournament::top");
  if (capacity_ == 0 || winner_[1] == kNoIndex) return std::nullopt;
  // Ties at now: the smallest id among the objects equal to the winner now (the oracle's rule;
  // under the exact scheduler at a crossing time the winner is the one ahead just after now).
  // A subtree's winner is its extreme now, so only subtrees whose winner ties are entered.
  const Time t = sim_.now();
  const MotionPolynomial& w = motions_.motion(winner_[1], axis_);
  std::uint32_t best = winner_[1];
  std::vector<std::size_t> stack{1};
  while (!stack.empty()) {
    const std::size_t v = stack.back();
    stack.pop_back();
    if (is_leaf(v)) {
      if (motions_.id(winner_[v]) < motions_.id(best)) best = winner_[v];
      continue;
    }
    for (const std::size_t c : {2 * v, 2 * v + 1}) {
      const std::uint32_t x = winner_[c];
      if (x != kNoIndex && (x == winner_[1] || compare_at(motions_.motion(x, axis_), w, t) == 0))
        stack.push_back(c);
    }
  }
  return best;
}

std::size_t KineticTournament::certificates_per_object_max() const {
  std::vector<std::uint32_t> count(leaf_of_.size(), 0);
  std::uint32_t best = 0;
  for (std::size_t v = 1; v < capacity_; ++v) {
    const std::uint32_t a = winner_[2 * v], b = winner_[2 * v + 1];
    if (a == kNoIndex || b == kNoIndex) continue;
    best = std::max({best, ++count[a], ++count[b]});
  }
  return best;
}

bool KineticTournament::validate() const {
  if (!sync_.current()) return false;
  if (capacity_ == 0) return size_ == 0;
  std::size_t leaves = 0, pairs = 0;
  for (std::size_t leaf = capacity_; leaf < 2 * capacity_; ++leaf) {
    const std::uint32_t x = winner_[leaf];
    if (x == kNoIndex) continue;
    if (!motions_.alive_index(x) || x >= leaf_of_.size() || leaf_of_[x] != leaf) return false;
    ++leaves;
  }
  if (leaves != size_ || leaves + free_.size() != capacity_) return false;
  for (const std::uint32_t leaf : free_) {
    if (leaf < capacity_ || leaf >= 2 * capacity_ || winner_[leaf] != kNoIndex) return false;
  }
  for (std::size_t v = 1; v < capacity_; ++v) {
    const std::uint32_t a = winner_[2 * v], b = winner_[2 * v + 1], w = winner_[v];
    const EventHandle h = certificate_[v];
    if (a == kNoIndex || b == kNoIndex) {
      if (w != (a == kNoIndex ? b : a) || !h.is_null()) return false;
      continue;
    }
    ++pairs;
    if (w != a && w != b) return false;
    if (!h.is_null()) {
      if (!sim_.queue().contains(h)) return false;
      const Event& e = sim_.queue().get(h);
      if (e.owner != owner_ || e.payload != v) return false;
    }
  }
  return pairs == certificates_;
}

TournamentAudit KineticTournament::audit(Time t) const {
  TournamentAudit a;
  const std::optional<std::uint32_t> top_index = top();
  if (!top_index) {
    a.ok = motions_.size() == 0;
    return a;
  }
  a.maintained = *top_index;
  a.true_extreme = *top_index;
  const int want = extreme_ == Extreme::Max ? 1 : -1;
  for (const std::uint32_t i : motions_.alive_indices()) {
    if (compare_at(motions_.motion(i, axis_), motions_.motion(a.true_extreme, axis_), t) * want > 0)
      a.true_extreme = i;
  }
  a.ok = compare_at(motions_.motion(a.true_extreme, axis_), motions_.motion(a.maintained, axis_),
                    t) == 0;
  return a;
}

std::size_t KineticTournament::lemma5_violations(Time t, double eps) const {
  std::size_t bad = 0;
  const int want = extreme_ == Extreme::Max ? 1 : -1;
  for (std::size_t v = 1; v < capacity_; ++v) {
    const std::uint32_t a = winner_[2 * v], b = winner_[2 * v + 1], w = winner_[v];
    if (a == kNoIndex || b == kNoIndex) continue;
    const std::uint32_t l = w == a ? b : a;
    const MotionPolynomial& pw = motions_.motion(w, axis_);
    const MotionPolynomial& pl = motions_.motion(l, axis_);
    if (compare_at(pl, pw, t) * want <= 0) continue;    // the winner is right at t
    if (compare_at(pl, pw, t - eps) * want > 0) ++bad;  // wrong, without a crossing in (t-eps, t)
  }
  return bad;
}

StructureDescription KineticTournament::description() {
  return {"tournament",
          "Tournament",
          ObjectsAre::Points,
          {QueryType::Max, QueryType::Min},
          {"max_change", "min_change"},
          "A kinetic tournament: the object with the largest (extreme='max') or smallest "
          "coordinate on one axis (top()).",
          "kinetic tournaments: the maximum / minimum of points along an axis (one tournament per "
          "axis and extreme that the queries ask for)"};
}

}  // namespace kinetic
