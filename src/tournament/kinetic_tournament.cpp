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
      tree_(simulator, simulator.reserve_owners(1).first,
            Keys{&motions, &simulator, &scheduler, axis, extreme, &counters_}) {
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
  for (std::size_t first = 1; first < 2 * capacity() && static_cast<int>(out.size()) < levels;
       first *= 2) {
    std::vector<std::optional<std::uint32_t>> level;
    for (std::size_t v = first; v < 2 * first; ++v) {
      if (tree_.winner(v) == kNoIndex) {
        level.push_back(std::nullopt);
      } else {
        level.push_back(tree_.winner(v));
      }
    }
    out.push_back(std::move(level));
  }
  return out;
}

NamedCounters KineticTournament::named_counters() const {
  const TournamentCounters& c = counters_;
  return {{"events", c.events},
          {"inserts", c.inserts},
          {"removes", c.removes},
          {"updates", c.updates},
          {"rebuilds", c.rebuilds},
          {"nodes_redecided", c.nodes_redecided},
          {"scheduled_not_in_future", c.scheduled_not_in_future}};
}

Scheduler::MaxDecision KineticTournament::Keys::decide(std::size_t /*node*/, std::uint32_t x,
                                                       std::uint32_t y) {
  ++counters->nodes_redecided;
  const Time window_lo = std::max(motions->valid_from(x), motions->valid_from(y));
  const MotionPolynomial& px = motions->motion(x, axis);
  const MotionPolynomial& py = motions->motion(y, axis);
  // For a minimum, x wins when y is the maximum of the two; the certificate [x < y] is then the
  // one COMPUTEMAX(y, x) leaves, [loser < winner] in the max sense.
  Scheduler::MaxDecision d =
      extreme == Extreme::Max
          ? scheduler->compute_max(px, py, sim->now(), window_lo, sim->counters())
          : scheduler->compute_max(py, px, sim->now(), window_lo, sim->counters());
  if (scheduler->kind() == SchedulerKind::Robust && d.failure <= sim->now())
    ++counters->scheduled_not_in_future;  // Lemma 4 says this never happens
  return d;
}

Time KineticTournament::Keys::failure(std::size_t /*node*/, std::uint32_t w,
                                      std::uint32_t l) const {
  // [l < w] in the extreme's sense, its failure from the scheduler (no decision).
  const Time window_lo = std::max(motions->valid_from(w), motions->valid_from(l));
  const MotionPolynomial& pw = motions->motion(w, axis);
  const MotionPolynomial& pl = motions->motion(l, axis);
  return extreme == Extreme::Max
             ? scheduler->failure_time(pl, pw, sim->now(), window_lo, sim->counters())
             : scheduler->failure_time(pw, pl, sim->now(), window_lo, sim->counters());
}

void KineticTournament::rebuild(std::size_t capacity) {
  std::vector<std::uint32_t> objects;
  for (std::size_t leaf = this->capacity(); leaf < 2 * this->capacity(); ++leaf) {
    if (tree_.winner(leaf) != kNoIndex) objects.push_back(tree_.winner(leaf));
  }
  std::sort(objects.begin(), objects.end());
  tree_.assign(2 * capacity);  // every certificate cancelled
  tree_.topology().capacity = capacity;
  height_ = 0;
  while ((std::size_t{1} << height_) < capacity) ++height_;
  leaf_of_.assign(motions_.capacity(), 0);
  free_.clear();
  for (std::size_t k = 0; k < objects.size(); ++k) {
    tree_.set_leaf(capacity + k, objects[k]);
    leaf_of_[objects[k]] = static_cast<std::uint32_t>(capacity + k);
  }
  for (std::size_t leaf = 2 * capacity; leaf-- > capacity + objects.size();)
    free_.push_back(static_cast<std::uint32_t>(leaf));  // popped lowest first
  size_ = objects.size();
  for (std::size_t v = capacity; v-- > 1;) tree_.decide(v);
  ++counters_.rebuilds;
}

void KineticTournament::initialize() {
  sync_.note();
  const std::vector<std::uint32_t> objects = motions_.alive_indices();
  std::size_t capacity = 1;
  while (capacity < objects.size()) capacity *= 2;
  tree_.assign(2 * capacity);
  tree_.topology().capacity = capacity;
  for (std::size_t k = 0; k < objects.size(); ++k) tree_.set_leaf(capacity + k, objects[k]);
  // rebuild() reads the leaves just written and lays the tree out again, deciding every node.
  rebuild(capacity);
  --counters_.rebuilds;  // the first build is not a rebuild
}

EventKind KineticTournament::process(const Event& event) {
  const std::size_t v = tree_.take_event(event);
  assert(v >= 1 && v < capacity());
  ++counters_.events;
  const std::uint32_t top_before = tree_.winner(1);
  if (scheduler_.kind() != SchedulerKind::Classic) {
    // Algorithm KINETICTOURNAMENT, lines 5-14: COMPUTEMAX from u towards the root, EVENTTIME for
    // the new certificates (the exact scheduler: exact decisions at the exact event time).
    tree_.decide(v);
    tree_.climb(v);
  } else {
    // A traditional KDS trusts the event: the certificate [loser < winner] failed, so the loser
    // wins now; its new certificate is scheduled from floating-point roots.
    const std::uint32_t old = tree_.trust_failure(v);
    if (scheduler_.classic_exact_decisions()) {
      // The careful variant: the ancestors re-decided by exact comparisons (COMPUTEMAX) until
      // one keeps its winner.
      tree_.climb(v);
    } else {
      tree_.propagate_traditionally(v, old);
    }
  }
  if (tree_.winner(1) == top_before) return EventKind::Internal;
  if (sim_.logging_events()) {  // the top changed: [old, new]
    const std::array<ObjectId, 2> ids{motions_.id(top_before), motions_.id(tree_.winner(1))};
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
    rebuild(std::max<std::size_t>(1, 2 * capacity()));
    // rebuild() kept the old points; the new one takes the first free slot below.
  }
  const std::uint32_t leaf = free_.back();
  free_.pop_back();
  tree_.set_leaf(leaf, index);
  leaf_of_[index] = leaf;
  ++size_;
  tree_.decide_to_root(tree_.topology().parent(leaf));  // every certificate it joins
}

void KineticTournament::remove(std::uint32_t index) {
  sync_.require_removed("KineticTournament::remove", index);
  assert(index < leaf_of_.size() && leaf_of_[index] != 0);
  ++counters_.removes;
  const std::uint32_t leaf = leaf_of_[index];
  leaf_of_[index] = 0;
  tree_.set_leaf(leaf, kNoIndex);
  free_.push_back(leaf);
  --size_;
  tree_.decide_to_root(tree_.topology().parent(leaf));
}

void KineticTournament::motion_changed(std::uint32_t index) {
  sync_.require_updated("KineticTournament::motion_changed", index);
  assert(index < leaf_of_.size() && leaf_of_[index] != 0);
  ++counters_.updates;
  tree_.decide_to_root(tree_.topology().parent(leaf_of_[index]));
}

std::optional<std::uint32_t> KineticTournament::top() const {
  sync_.require_current("KineticTournament::top");
  if (capacity() == 0 || tree_.winner(1) == kNoIndex) return std::nullopt;
  // Ties at now: the smallest id among the objects equal to the winner now (the oracle's rule;
  // under the exact scheduler at a crossing time the winner is the one ahead just after now).
  // A subtree's winner is its extreme now, so only subtrees whose winner ties are entered.
  const Time t = sim_.now();
  const MotionPolynomial& w = motions_.motion(tree_.winner(1), axis_);
  std::uint32_t best = tree_.winner(1);
  tree_.for_each_tie(
      1, [&](std::uint32_t x) { return compare_at(motions_.motion(x, axis_), w, t) == 0; },
      [&](std::uint32_t x) {
        if (motions_.id(x) < motions_.id(best)) best = x;
      });
  return best;
}

std::size_t KineticTournament::certificates_per_object_max() const {
  std::vector<std::uint32_t> count(leaf_of_.size(), 0);
  std::uint32_t best = 0;
  tree_.for_each_certificate([&](std::size_t, std::uint32_t w, std::uint32_t l) {
    best = std::max({best, ++count[w], ++count[l]});
  });
  return best;
}

bool KineticTournament::validate() const {
  if (!sync_.current()) return false;
  if (capacity() == 0) return size_ == 0;
  std::size_t leaves = 0;
  for (std::size_t leaf = capacity(); leaf < 2 * capacity(); ++leaf) {
    const std::uint32_t x = tree_.winner(leaf);
    if (x == kNoIndex) continue;
    if (!motions_.alive_index(x) || x >= leaf_of_.size() || leaf_of_[x] != leaf) return false;
    ++leaves;
  }
  if (leaves != size_ || leaves + free_.size() != capacity()) return false;
  for (const std::uint32_t leaf : free_) {
    if (leaf < capacity() || leaf >= 2 * capacity() || tree_.winner(leaf) != kNoIndex) return false;
  }
  return tree_.validate();
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
  tree_.for_each_certificate([&](std::size_t, std::uint32_t w, std::uint32_t l) {
    const MotionPolynomial& pw = motions_.motion(w, axis_);
    const MotionPolynomial& pl = motions_.motion(l, axis_);
    if (compare_at(pl, pw, t) * want <= 0) return;      // the winner is right at t
    if (compare_at(pl, pw, t - eps) * want > 0) ++bad;  // wrong, without a crossing in (t-eps, t)
  });
  return bad;
}

namespace {

/// The loop guard's bounds: a certificate at a node fails only when its two points cross (at
/// their lowest common ancestor), so a tournament is bounded like one sort.
LoopGuard tournament_event_bounds(const RunBounds& b) {
  return crossing_guard(1, b.max_objects, b.motion_changes, b.max_degree);
}

}  // namespace

StructureDescription KineticTournament::description() {
  return StructureDescription{
      "tournament",
      "Tournament",
      ObjectsAre::Points,
      {QueryType::Max, QueryType::Min},
      {"max_change", "min_change"},
      "A kinetic tournament: the object with the largest (extreme='max') or smallest "
      "coordinate on one axis (top()).",
      "kinetic tournaments: the maximum / minimum of points along an axis (one tournament per "
      "axis and extreme that the queries ask for)"}
      .bound_events(tournament_event_bounds);
}

}  // namespace kinetic
