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
    sorts_.add(std::make_unique<KineticEndpointSort>(boxes, simulator, scheduler, axis,
                                                     SortLayout::Gapped));
  }
  straddlers_.resize(static_cast<std::size_t>(dimension_));
  straddler_generation_.assign(static_cast<std::size_t>(dimension_), ~std::uint64_t{0});
}

NamedCounters KineticSweepAndPrune::named_counters() const {
  return {{"swaps", counters_.swaps},
          {"contact_begins", counters_.contact_begins},
          {"contact_ends", counters_.contact_ends},
          {"instant_contacts", counters_.instant_contacts},
          {"overlap_checks", counters_.overlap_checks},
          {"contact_candidates", counters_.contact_candidates},
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
    if (key == kNoIndex) continue;  // an empty slot of the gapped layout
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
  for (int axis = 0; axis < dimension_; ++axis) refresh_straddlers(axis);
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
  refresh_straddler_key(axis, swap.up);
  refresh_straddler_key(axis, swap.down);
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

void KineticSweepAndPrune::refresh_straddler_key(int axis, std::uint32_t key) {
  const KineticEndpointSort& s = sorts_[static_cast<std::size_t>(axis)];
  detail::StraddlerIndex& index = straddlers_[static_cast<std::size_t>(axis)];
  const std::uint32_t box = BoxEndpointKeys::box_of(key);
  if (BoxEndpointKeys::side_of(key) == BoxSide::Low) {
    index.set(s.rank(key), s.rank(high_key(box)) + 1);
  } else {
    index.set(s.rank(key), 0);
    index.set(s.rank(low_key(box)), s.rank(key) + 1);
  }
}

std::vector<std::uint32_t> KineticSweepAndPrune::straddler_leaves(int axis) const {
  const KineticEndpointSort& s = sorts_[static_cast<std::size_t>(axis)];
  std::vector<std::uint32_t> leaves(s.slots(), 0);
  for (std::size_t j = 0; j < s.slots(); ++j) {
    const std::uint32_t key = s.order()[j];
    if (key != kNoIndex && BoxEndpointKeys::side_of(key) == BoxSide::Low)
      leaves[j] = s.rank(high_key(BoxEndpointKeys::box_of(key))) + 1;
  }
  return leaves;
}

void KineticSweepAndPrune::refresh_straddlers(int axis) {
  const auto a = static_cast<std::size_t>(axis);
  const KineticEndpointSort& s = sorts_[a];
  detail::StraddlerIndex& index = straddlers_[a];
  if (index.slots() != s.slots() || straddler_generation_[a] != s.layout_generation()) {
    // Every key may have a new slot: the index is built again from the order, O(U).
    index.set_all_leaves_then_build(straddler_leaves(axis));
    straddler_generation_[a] = s.layout_generation();
    return;
  }
  // Only the touched slots changed content; a high side among them also decides its low side's
  // leaf, wherever that is.
  for (const auto& [first, last] : s.touched_slots()) {
    for (std::size_t j = first; j <= last; ++j) {
      const std::uint32_t key = s.order()[j];
      if (key == kNoIndex) {
        index.set(j, 0);
      } else {
        refresh_straddler_key(axis, key);
      }
    }
  }
}

void KineticSweepAndPrune::collect_candidates(std::uint32_t i, bool touching_now) {
  // The axis whose order has the fewest slots between i's sides.
  int best = 0;
  std::size_t best_span = ~std::size_t{0};
  for (int axis = 0; axis < dimension_; ++axis) {
    const KineticEndpointSort& s = sorts_[static_cast<std::size_t>(axis)];
    const std::size_t span = s.rank(high_key(i)) - s.rank(low_key(i));
    if (span < best_span) {
      best_span = span;
      best = axis;
    }
  }
  const KineticEndpointSort& s = sorts_[static_cast<std::size_t>(best)];
  const std::span<const std::uint32_t> order = s.order();
  std::size_t lo = s.rank(low_key(i)), hi = s.rank(high_key(i));
  if (touching_now) {
    // Sides just before i's low side (or just after its high side) at or beyond it now belong to
    // boxes apart from i just after now that may touch it now (the order is as just after now).
    const Time now = sim_.now();
    for (std::size_t b = s.prev_slot(lo);
         b != KineticEndpointSort::kNoSlot && s.keys().compare_at(order[b], low_key(i), now) >= 0;
         b = s.prev_slot(b))
      lo = b;
    for (std::size_t b = s.next_slot(hi);
         b != KineticEndpointSort::kNoSlot && s.keys().compare_at(order[b], high_key(i), now) <= 0;
         b = s.next_slot(b))
      hi = b;
  }
  if (seen_.size() < boxes_.capacity()) seen_.resize(boxes_.capacity(), 0);
  if (++stamp_ == 0) {  // the stamps wrapped: every mark cleared once
    std::fill(seen_.begin(), seen_.end(), 0);
    stamp_ = 1;
  }
  seen_[i] = stamp_;
  candidates_.clear();
  const auto take = [&](std::uint32_t key) {
    const std::uint32_t box = BoxEndpointKeys::box_of(key);
    if (seen_[box] == stamp_) return;
    seen_[box] = stamp_;
    candidates_.push_back(box);
  };
  for (std::size_t j = lo; j != KineticEndpointSort::kNoSlot && j <= hi; j = s.next_slot(j))
    take(order[j]);
  straddlers_[static_cast<std::size_t>(best)].report(lo, static_cast<std::uint32_t>(hi + 1),
                                                     [&](std::size_t j) { take(order[j]); });
  counters_.contact_candidates += candidates_.size();
}

void KineticSweepAndPrune::find_contacts_of(std::uint32_t i) {
  collect_candidates(i, true);
  for (const std::uint32_t j : candidates_) {
    ++counters_.overlap_checks;
    if (overlap_elsewhere(i, j, -1)) {
      add_contact(i, j, false);
    } else {
      note_if_touching(i, j, -1);  // apart just after now, maybe touching now
    }
  }
}

std::vector<std::uint32_t> KineticSweepAndPrune::contacts_of(std::uint32_t i) {
  // A contact overlaps i on every axis in the maintained orders: it is a candidate.
  std::vector<std::uint32_t> mine;
  if (i >= contacts_of_.size() || contacts_of_[i] == 0) return mine;
  collect_candidates(i, false);
  for (const std::uint32_t j : candidates_) {
    if (contact_set().contains(i, j)) mine.push_back(j);
  }
  return mine;
}

void KineticSweepAndPrune::insert(std::uint32_t index) {
  sync_.require_inserted("KineticSweepAndPrune::insert", index);
  require_box(index, "KineticSweepAndPrune::insert");
  ++counters_.inserts;
  if (contacts_of_.size() < boxes_.capacity()) contacts_of_.resize(boxes_.capacity(), 0);
  sorts_.insert(index);
  for (int axis = 0; axis < dimension_; ++axis) refresh_straddlers(axis);
  find_contacts_of(index);
}

void KineticSweepAndPrune::remove(std::uint32_t index) {
  sync_.require_removed("KineticSweepAndPrune::remove", index);
  ++counters_.removes;
  // Its contacts are read off the orders while its sides are still in them.
  for (const std::uint32_t j : contacts_of(index)) drop_contact(index, j, false);
  sorts_.remove(index);
  for (int axis = 0; axis < dimension_; ++axis) refresh_straddlers(axis);
}

void KineticSweepAndPrune::motion_changed(std::uint32_t index) {
  sync_.require_updated("KineticSweepAndPrune::motion_changed", index);
  require_box(index, "KineticSweepAndPrune::motion_changed");
  ++counters_.updates;
  // A change of velocity leaves the box where it is in every order (no contact changes); a
  // jump or a new size may move its sides past others: then its contacts are found again.
  const std::vector<std::uint32_t> before = contacts_of(index);
  const auto neighbours = [&](const KineticEndpointSort& s) {
    std::array<std::uint32_t, 4> out{};
    std::size_t k = 0;
    for (const std::uint32_t key : {low_key(index), high_key(index)}) {
      const std::size_t p = s.rank(key);
      const std::size_t b = s.prev_slot(p), n = s.next_slot(p);
      out[k++] = b == KineticEndpointSort::kNoSlot ? kNoIndex : s.order()[b];
      out[k++] = n == KineticEndpointSort::kNoSlot ? kNoIndex : s.order()[n];
    }
    return out;
  };
  bool moved = false;
  for (int axis = 0; axis < dimension_; ++axis) {
    KineticEndpointSort& s = sorts_[static_cast<std::size_t>(axis)];
    const std::array<std::uint32_t, 4> was = neighbours(s);
    s.motion_changed(index);
    refresh_straddlers(axis);
    moved = moved || neighbours(s) != was;
  }
  if (!moved) return;
  for (const std::uint32_t j : before) drop_contact(index, j, false);
  find_contacts_of(index);
}

bool KineticSweepAndPrune::validate() const {
  if (!sync_.current() || !sorts_.validate()) return false;
  // A box's low side before its high side on every axis (h >= 0; equal sides in tie order).
  for (const std::uint32_t i : boxes_.alive_indices()) {
    for (const KineticEndpointSort& s : sorts_.members()) {
      if (s.rank(low_key(i)) >= s.rank(high_key(i))) return false;
    }
  }
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
  // Each axis's straddler index holds each low side's high slot, its maxima consistent.
  for (int axis = 0; axis < dimension_; ++axis) {
    const detail::StraddlerIndex& index = straddlers_[static_cast<std::size_t>(axis)];
    const std::vector<std::uint32_t> leaves = straddler_leaves(axis);
    if (index.slots() != leaves.size() || !index.consistent()) return false;
    for (std::size_t j = 0; j < leaves.size(); ++j) {
      if (index.leaf(j) != leaves[j]) return false;
    }
  }
  return true;
}

std::size_t KineticSweepAndPrune::bytes() const {
  // Per slot and axis: its key, its certificate's handle and its valid-from time; per key its
  // slot; the straddler indexes.
  std::size_t total = contact_set().bytes() + contacts_of_.capacity() * sizeof(std::uint32_t) +
                      seen_.capacity() * sizeof(std::uint32_t);
  for (int axis = 0; axis < dimension_; ++axis) {
    const auto a = static_cast<std::size_t>(axis);
    total += sorts_[a].slots() * (sizeof(std::uint32_t) + sizeof(EventHandle) + sizeof(double)) +
             2 * boxes_.capacity() * sizeof(std::uint32_t) + straddlers_[a].bytes();
  }
  return total;
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
