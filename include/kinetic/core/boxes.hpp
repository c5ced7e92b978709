#pragma once
// Moving boxes in a MotionTable (`objects_are: "boxes"` in a scenario). An object of a table of
// d-dimensional boxes has 2d coordinates: its center's motion on coordinates 0..d-1 and its half
// extents, constant polynomials >= 0, on coordinates d..2d-1. The box is the closed
// [c_k(t) - h_k, c_k(t) + h_k] on every axis k. A side c_k - h_k is never formed in floating
// point (it would be rounded): side comparisons are exact signs of combinations of the center
// motions and the half extents (MotionCombination, core/crop.hpp).

#include <array>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "kinetic/core/crop.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/pair_set.hpp"
#include "kinetic/core/polynomial.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/sort_keys.hpp"

namespace kinetic {

/// The table dimension holding boxes of dimension d.
[[nodiscard]] constexpr int boxes_table_dimension(int d) { return 2 * d; }
/// The boxes' dimension of a table of boxes.
[[nodiscard]] inline int box_dimension(const MotionTable& boxes) { return boxes.dimension() / 2; }

[[nodiscard]] inline const MotionPolynomial& center(const MotionTable& boxes, std::uint32_t index,
                                                    int axis) {
  return boxes.motion(index, axis);
}
[[nodiscard]] inline const MotionPolynomial& half_extent(const MotionTable& boxes,
                                                         std::uint32_t index, int axis) {
  return boxes.motion(index, box_dimension(boxes) + axis);
}

/// The surface measure of a d-dimensional box with side lengths len[0..d-1]: its length (d = 1),
/// half perimeter (2) or half area (3). What a bounding volume hierarchy's surface-area cost
/// sums.
[[nodiscard]] inline double surface_measure(int d, const std::array<double, 3>& len) {
  return d == 1   ? len[0]
         : d == 2 ? len[0] + len[1]
                  : len[0] * len[1] + len[1] * len[2] + len[0] * len[2];
}

/// A box's row of a table (centers, then half extents): an even number of coordinates and
/// every half extent a constant >= 0. Throws PreconditionError naming the id and the axis.
void require_box_motion(std::span<const MotionPolynomial> motion, ObjectId id, const char* where);
/// The same for a box already in the table.
void require_box_row(const MotionTable& boxes, std::uint32_t index, const char* where);

/// A pair of table indices of boxes, `first` the one with the smaller id.
using IndexPair = std::pair<std::uint32_t, std::uint32_t>;
/// The pairs of a contact set (box table indices) as the `colliding_pairs` answer: each
/// (smaller id, larger id), sorted by ids. O(k log k).
[[nodiscard]] std::vector<IndexPair> pairs_by_ids(const MotionTable& boxes, const PairSet& pairs);

/// The contacts that ended at the current instant, under the exact scheduler: boxes are closed,
/// so two boxes whose contact ends at t still touch at t, and a `colliding_pairs` query at t
/// reports them beside the contacts that hold after t. Kept per instant (Simulator::instant()):
/// a new instant or an external change forgets them. Other schedulers' events come at or after
/// the true time, where the boxes seldom still touch: noted when they do (checked exactly). A
/// structure also notes the pairs that touch only at its start (touching_only_at).
class EndedContacts {
 public:
  /// A contact that ended by an event: under the exact scheduler at its exact time, where the
  /// boxes touch; under the others when the event is processed at a time where they still touch
  /// (checked exactly; e.g. a classic event at a crossing time that is a double).
  void note(const Simulator& sim, const MotionTable& boxes, std::uint32_t a, std::uint32_t b);
  /// A pair that touches at the current time but not just after it, found by a change made at
  /// that time (initialize, insert, a flight-plan update): noted under every scheduler, since
  /// the time is exact.
  void note_now(const Simulator& sim, std::uint32_t a, std::uint32_t b) {
    if (sim.instant() != instant_) {
      pairs_.clear();
      instant_ = sim.instant();
    }
    pairs_.emplace_back(a, b);
  }
  /// pairs_by_ids(boxes, contacts) and the live pairs that ended at sim's instant and are not
  /// in contact again, in the same order.
  [[nodiscard]] std::vector<IndexPair> answer(const MotionTable& boxes, const PairSet& contacts,
                                              const Simulator& sim) const;
  /// The live pairs that ended at sim's instant and are not in `contacts`: the pairs of
  /// answer() beyond the contact set, unsorted, each once.
  [[nodiscard]] std::vector<IndexPair> touching_only(const MotionTable& boxes,
                                                     const PairSet& contacts,
                                                     const Simulator& sim) const;

 private:
  std::uint64_t instant_ = ~std::uint64_t{0};
  std::vector<IndexPair> pairs_;
};

/// The pairs of live boxes that overlap at t (closed) and are not in `contacts` (the pairs
/// overlapping just after t, as a structure keeps them): the contacts that end exactly at t,
/// which a query at t still reports. All boxes by a sweep along axis 0 at t (O(n log n + k)
/// exact comparisons, k the pairs overlapping on axis 0 at t).
/// Each pair (smaller id first) once.
[[nodiscard]] std::vector<IndexPair> touching_only_at(const MotionTable& boxes,
                                                      const PairSet& contacts, Time t);

/// Which side of a box on an axis.
enum class BoxSide : std::int8_t { Low = 0, High = 1 };

/// sign(side s of box a on `axis` - side u of box b on `axis`) at t, exactly.
[[nodiscard]] int compare_sides_at(const MotionTable& boxes, std::uint32_t a, BoxSide s,
                                   std::uint32_t b, BoxSide u, int axis, Time t);

/// Whether boxes a and b overlap at t (closed: touching counts), exactly: on every axis
/// low(a) <= high(b) and low(b) <= high(a). `last_axis` (when >= 0) is checked after the others:
/// the axis where the sides are known to meet at t, whose equality only the exact stage proves.
[[nodiscard]] bool boxes_overlap_at(const MotionTable& boxes, std::uint32_t a, std::uint32_t b,
                                    Time t, int last_axis = -1);

/// The sort keys of the boxes' projections on one axis (the endpoints of sweep-and-prune): box
/// i owns key 2i (its low side c - h) and key 2i + 1 (its high side c + h). A key's function is
/// the center's motion plus a signed constant, never rounded into one polynomial: a comparison
/// of two keys is the exact sign of the MotionCombination c_a + o_a - c_b - o_b (o = -h or +h).
/// Keys that are the same function of t are ordered low before high (so boxes that touch for an
/// interval overlap, as closed boxes do), then by id.
class BoxEndpointKeys : public CombinationKeys<BoxEndpointKeys> {
 public:
  static constexpr std::uint32_t kKeysPerObject = 2;
  /// Throws PreconditionError unless the table holds boxes (an even dimension) and 0 <= axis <
  /// box_dimension(boxes).
  BoxEndpointKeys(const MotionTable& boxes, int axis);

  [[nodiscard]] static std::uint32_t key(std::uint32_t box, BoxSide side) {
    return 2 * box + static_cast<std::uint32_t>(side);
  }
  [[nodiscard]] static std::uint32_t box_of(std::uint32_t key) { return key / 2; }
  [[nodiscard]] static BoxSide side_of(std::uint32_t key) { return static_cast<BoxSide>(key & 1); }

  [[nodiscard]] const MotionTable& table() const { return boxes_; }
  [[nodiscard]] int axis() const { return axis_; }
  /// Reads the box's half extent on this axis again (its negation is kept for the low key).
  void refresh(std::uint32_t box);
  /// c(t) + o(t) in floating point: the side a traditional sweep-and-prune reads.
  [[nodiscard]] double value_at(std::uint32_t a, Time t) const {
    return center(boxes_, box_of(a), axis_).evaluate(t) + offset(a).evaluate(t);
  }
  [[nodiscard]] bool tie_before(std::uint32_t a, std::uint32_t b) const {
    if (side_of(a) != side_of(b)) return side_of(a) == BoxSide::Low;
    return boxes_.id(box_of(a)) < boxes_.id(box_of(b));
  }
  /// sign(key a - key b) as the scheduler decides it at t_curr, with the failure time of that
  /// sign (Scheduler::decide on the exact combination).
  [[nodiscard]] Scheduler::SignDecision decide(const Scheduler& scheduler, std::uint32_t a,
                                               std::uint32_t b, Time t_curr, Time window_lo,
                                               Counters& counters) const {
    return scheduler.decide(difference(a, b), t_curr, window_lo, counters);
  }

 private:
  friend class CombinationKeys<BoxEndpointKeys>;
  /// key a - key b = c_a + o_a - (c_b + o_b).
  [[nodiscard]] MotionCombination difference(std::uint32_t a, std::uint32_t b) const {
    return MotionCombination{{&center(boxes_, box_of(a), axis_), &offset(a)},
                             {&center(boxes_, box_of(b), axis_), &offset(b)}};
  }
  [[nodiscard]] const MotionPolynomial& offset(std::uint32_t key) const {
    return side_of(key) == BoxSide::High ? half_extent(boxes_, box_of(key), axis_)
                                         : negated_extent_[box_of(key)];
  }

  const MotionTable& boxes_;
  int axis_;
  std::vector<MotionPolynomial> negated_extent_;  // box index -> -h on this axis
};

static_assert(SortKeys<BoxEndpointKeys>);

}  // namespace kinetic
