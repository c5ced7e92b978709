#include "kinetic/sweep_and_prune/kinetic_sweep_and_prune.hpp"

#include <algorithm>
#include <array>
#include <memory>

namespace kinetic {
namespace {
constexpr std::uint32_t low_key(std::uint32_t box) { return 2 * box; }
constexpr std::uint32_t high_key(std::uint32_t box) { return 2 * box + 1; }
}  // namespace

KineticSweepAndPrune::KineticSweepAndPrune(const MotionTable& boxes, Simulator& simulator,
                                           const Scheduler& scheduler)
    : BoxContacts(boxes, simulator, "KineticSweepAndPrune::colliding_pairs",
                  "KineticSweepAndPrune::contact_changes"),
      dimension_(box_dimension(boxes)) {
  require_box_table(boxes, "KineticSweepAndPrune");
  for (int axis = 0; axis < dimension_; ++axis) {
    sorts_.add(std::make_unique<KineticEndpointSort>(boxes, simulator, scheduler, axis));
  }
}

NamedCounters KineticSweepAndPrune::named_counters() const {
  return {{"swaps", counters_.swaps},
          {"contact_begins", counters_.contact_begins},
          {"contact_ends", counters_.contact_ends},
          {"instant_contacts", counters_.instant_contacts},
          {"overlap_checks", counters_.overlap_checks},
          {"inserts", counters_.inserts},
          {"removes", counters_.removes},
          {"updates", counters_.updates},
          {"queries", counters_.queries}};
}

bool KineticSweepAndPrune::overlap_on(std::uint32_t a, std::uint32_t b, int axis) const {
  const KineticEndpointSort& s = sorts_[static_cast<std::size_t>(axis)];
  return s.rank(low_key(a)) < s.rank(high_key(b)) && s.rank(low_key(b)) < s.rank(high_key(a));
}

bool KineticSweepAndPrune::overlap_elsewhere(std::uint32_t a, std::uint32_t b, int skip) const {
  for (int axis = 0; axis < dimension_; ++axis) {
    if (axis != skip && !overlap_on(a, b, axis)) return false;
  }
  return true;
}

void KineticSweepAndPrune::add_contact(std::uint32_t a, std::uint32_t b, bool log_it) {
  if (!begin_contact(a, b)) return;
  ++contacts_of_[a];
  ++contacts_of_[b];
  if (log_it) {
    ++counters_.contact_begins;
    log_contact(true, a, b);
  }
}

void KineticSweepAndPrune::drop_contact(std::uint32_t a, std::uint32_t b, bool log_it) {
  if (!end_contact(a, b)) return;
  --contacts_of_[a];
  --contacts_of_[b];
  if (log_it) {
    ++counters_.contact_ends;
    log_contact(false, a, b);
  }
}

std::vector<std::uint64_t> KineticSweepAndPrune::sweep() const {
  // Along axis 0: a box is active from its low side to its high side; a low side meets every
  // active box, and those pairs overlap on axis 0 (each one's low before the other's high).
  std::vector<std::uint64_t> out;
  if (dimension_ == 0) return out;
  std::vector<std::uint32_t> active;
  std::vector<std::uint32_t> slot(boxes_.capacity(), kNoIndex);
  for (const std::uint32_t key : sorts_[0].order()) {
    const std::uint32_t box = BoxEndpointKeys::box_of(key);
    if (BoxEndpointKeys::side_of(key) == BoxSide::Low) {
      for (const std::uint32_t other : active) {
        if (overlap_elsewhere(box, other, 0)) out.push_back(PairSet::key(box, other));
      }
      slot[box] = static_cast<std::uint32_t>(active.size());
      active.push_back(box);
    } else {
      const std::uint32_t at = slot[box];
      active[at] = active.back();
      slot[active[at]] = at;
      active.pop_back();
      slot[box] = kNoIndex;
    }
  }
  return out;
}

void KineticSweepAndPrune::initialize() {
  for (const std::uint32_t i : boxes_.alive_indices())
    require_box(i, "KineticSweepAndPrune::initialize");
  sync_.note();
  sorts_.initialize();
  clear_contacts();
  contacts_of_.assign(boxes_.capacity(), 0);
  for (const std::uint64_t k : sweep()) add_contact(PairSet::first(k), PairSet::second(k), false);
  // Boxes that touch at the start and part just after it: a query at the start reports them.
  for (const auto& [a, b] : touching_only_at(boxes_, contact_set(), sim_.now()))
    ended_.note_now(sim_, a, b);
}

EventKind KineticSweepAndPrune::process(const Event& event) {
  const auto axis = static_cast<int>(sorts_.member_of(event));
  const KineticEndpointSort::Swap swap = sorts_[static_cast<std::size_t>(axis)].process_swap(event);
  ++counters_.swaps;
  const std::uint32_t a = BoxEndpointKeys::box_of(swap.up);
  const std::uint32_t b = BoxEndpointKeys::box_of(swap.down);
  const BoxSide up = BoxEndpointKeys::side_of(swap.up);
  if (a == b || up == BoxEndpointKeys::side_of(swap.down)) return EventKind::Internal;
  if (up == BoxSide::High) {
    // a's high side moved past b's low side: they overlap on this axis from now on.
    ++counters_.overlap_checks;
    if (!overlap_elsewhere(a, b, axis)) {
      note_if_touching(a, b, axis);
      return EventKind::Internal;
    }
    add_contact(a, b, true);
    return EventKind::External;
  }
  // a's low side moved past b's high side: they are apart on this axis.
  if (!contact_set().contains(a, b)) {
    note_if_touching(a, b, axis);
    return EventKind::Internal;
  }
  drop_contact(a, b, true);
  return EventKind::External;
}

void KineticSweepAndPrune::note_if_touching(std::uint32_t a, std::uint32_t b, int axis) {
  // Apart just after now, yet the closed boxes may touch now (a corner passing a corner: one
  // axis starts to overlap as another stops): a query now reports them. Checked exactly, the
  // swap's axis (if any) last: its sides meet now under the exact scheduler.
  if (!boxes_overlap_at(boxes_, a, b, sim_.now(), axis)) return;
  ++counters_.instant_contacts;
  ended_.note_now(sim_, a, b);
}

void KineticSweepAndPrune::find_contacts_of(std::uint32_t i) {
  for (const std::uint32_t j : boxes_.alive_indices()) {
    if (j == i) continue;
    ++counters_.overlap_checks;
    if (overlap_elsewhere(i, j, -1)) {
      add_contact(i, j, false);
    } else {
      note_if_touching(i, j, -1);  // apart just after now, maybe touching now
    }
  }
}

void KineticSweepAndPrune::drop_contacts_of(std::uint32_t i) {
  if (contacts_of_[i] == 0) return;
  std::vector<std::uint64_t> mine;
  for (const std::uint64_t k : contact_set().keys()) {
    if (PairSet::first(k) == i || PairSet::second(k) == i) mine.push_back(k);
  }
  for (const std::uint64_t k : mine) drop_contact(PairSet::first(k), PairSet::second(k), false);
}

void KineticSweepAndPrune::insert(std::uint32_t index) {
  sync_.require_inserted("KineticSweepAndPrune::insert", index);
  require_box(index, "KineticSweepAndPrune::insert");
  ++counters_.inserts;
  if (contacts_of_.size() < boxes_.capacity()) contacts_of_.resize(boxes_.capacity(), 0);
  sorts_.insert(index);
  find_contacts_of(index);
}

void KineticSweepAndPrune::remove(std::uint32_t index) {
  sync_.require_removed("KineticSweepAndPrune::remove", index);
  ++counters_.removes;
  sorts_.remove(index);
  drop_contacts_of(index);
}

void KineticSweepAndPrune::motion_changed(std::uint32_t index) {
  sync_.require_updated("KineticSweepAndPrune::motion_changed", index);
  require_box(index, "KineticSweepAndPrune::motion_changed");
  ++counters_.updates;
  // A change of velocity leaves the box where it is in every order (no contact changes); a
  // jump or a new size may move its sides past others: then its contacts are found again.
  bool moved = false;
  for (KineticEndpointSort& s : sorts_.members()) {
    const std::uint32_t lo = s.rank(low_key(index)), hi = s.rank(high_key(index));
    s.motion_changed(index);
    moved = moved || s.rank(low_key(index)) != lo || s.rank(high_key(index)) != hi;
  }
  if (!moved) return;
  drop_contacts_of(index);
  find_contacts_of(index);
}

bool KineticSweepAndPrune::validate() const {
  if (!sync_.current() || !sorts_.validate()) return false;
  std::vector<std::uint64_t> expected = sweep();
  if (expected.size() != contact_set().size()) return false;
  std::vector<std::uint32_t> count(boxes_.capacity(), 0);
  for (const std::uint64_t k : expected) {
    if (!contact_set().contains(PairSet::first(k), PairSet::second(k))) return false;
    ++count[PairSet::first(k)];
    ++count[PairSet::second(k)];
  }
  for (std::size_t i = 0; i < count.size(); ++i) {
    if (count[i] != (i < contacts_of_.size() ? contacts_of_[i] : 0)) return false;
  }
  return true;
}

std::size_t KineticSweepAndPrune::bytes() const {
  // Per key and axis: its place in the order, its position and its certificate's handle.
  const std::size_t per_key = 2 * sizeof(std::uint32_t) + sizeof(EventHandle);
  return static_cast<std::size_t>(dimension_) * 2 * boxes_.capacity() * per_key +
         contact_set().bytes() + contacts_of_.capacity() * sizeof(std::uint32_t);
}

namespace {

/// The loop guard's bounds: the events are those of one kinetic sort of the 2n box sides per axis
/// (an insert or update changes two keys).
LoopGuard sweep_and_prune_event_bounds(const RunBounds& b) {
  return crossing_guard(static_cast<std::uint64_t>(b.dimension), 2 * b.max_objects,
                        2 * b.motion_changes, b.max_degree);
}

}  // namespace

StructureDescription KineticSweepAndPrune::description() {
  return StructureDescription{
      "sweep-and-prune",
      "SweepAndPrune",
      ObjectsAre::Boxes,
      {QueryType::CollidingPairs},
      {"contact_begin", "contact_end"},
      "Kinetic sweep-and-prune over moving boxes (colliding_pairs()); centers (n, d, k) and"
      " half_extents (n, d).",
      "kinetic sweep-and-prune over moving boxes (the box sides kinetically sorted per axis, "
      "contacts begun and ended at the swaps): all pairs of boxes in contact"}
      .limit_dimensions(1, 3, "boxes in 1 to 3 dimensions")
      .bound_events(sweep_and_prune_event_bounds);
}

}  // namespace kinetic
