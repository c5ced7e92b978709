#pragma once
// Kinetic sweep-and-prune: the broad phase of physics engines (the incremental sort of box
// endpoints per axis, Baraff; Cohen, Lin, Manocha, Ponamgi) with its swaps processed at their
// times. On every axis a kinetic sort keeps the 2n sides of the boxes in order
// (KineticEndpointSort: exact comparisons of center +- half extent, touching sides ordered low
// before high). Two boxes overlap on an axis exactly when, in that axis's maintained order, each
// one's low side comes before the other's high side; they are in contact when they overlap on
// every axis. A swap of a high side past a low side of another box starts an overlap on that axis
// (the pair enters the contact set when the other axes agree, read off the ranks in O(d)); a
// swap of a low side past a high side ends one (the pair leaves the set). Those two are the
// external events, contact_begin and contact_end; every other swap is internal.
//
// The contact set is a PairSet (flat hash set): colliding_pairs() reads it, never sweeps.
// The orders are packed-memory arrays (SortLayout::Gapped): a box's sides are placed or taken out
// with O(log n) comparisons and O(log^2 n) moved keys, amortized. Its contacts are found on the
// axis where its sides are fewest slots apart: the boxes with a side between its two sides (a scan
// of that range), and those straddling it, found by a max-tree of each low side's high slot
// (StraddlerIndex), O((k + 1) log n) for k of them. An insert, remove or moving update is
// therefore O(d log^2 n + the boxes overlapping it on that axis) amortized, never a pass over all
// boxes; an update that keeps the box where it is in every order (a change of velocity, as a
// bounce) changes no contact.

#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "kinetic/core/box_contacts.hpp"
#include "kinetic/core/boxes.hpp"
#include "kinetic/core/description.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/structure.hpp"
#include "kinetic/core/structure_group.hpp"
#include "kinetic/sort/kinetic_sort.hpp"
#include "kinetic/sweep_and_prune/straddler_index.hpp"

namespace kinetic {

struct SweepAndPruneCounters : ChangeCounters {
  std::uint64_t swaps = 0;           ///< endpoint swaps on all axes (every event)
  std::uint64_t contact_begins = 0;  ///< external events: a pair entered the contact set
  std::uint64_t contact_ends = 0;    ///< external events: a pair left it
  /// pairs apart just after a swap whose closed boxes touch at its time (reported by a query
  /// then, a contact of zero duration)
  std::uint64_t instant_contacts = 0;
  std::uint64_t overlap_checks = 0;  ///< rank tests of a pair on the other axes
  /// boxes met by the searches for an inserted, removed or moved box's contacts (on the axis
  /// where its sides are fewest slots apart)
  std::uint64_t contact_candidates = 0;
  std::uint64_t queries = 0;
};

/// The contact set, colliding_pairs() and the table's checks are the base's
/// (core/box_contacts.hpp).
class KineticSweepAndPrune final : public BoxContacts {
 public:
  /// What the structure is and takes (core/description.hpp): the registry, the CLI and the
  /// Python class read it.
  [[nodiscard]] static StructureDescription description();

  /// `boxes`: a table of boxes (core/boxes.hpp: 2d coordinates, d = 1..3). Throws
  /// PreconditionError for another table.
  KineticSweepAndPrune(const MotionTable& boxes, Simulator& simulator, const Scheduler& scheduler);

  /// Sorts the sides on every axis as just after sim.now(), schedules their certificates and
  /// finds the contacts by one sweep along axis 0. O(d n log n + pairs overlapping on axis 0).
  void initialize();
  /// An endpoint swap on one axis; External when a contact began or ended.
  EventKind process(const Event& event);
  void insert(std::uint32_t index);
  void remove(std::uint32_t index);
  void motion_changed(std::uint32_t index);

  [[nodiscard]] int dimension() const { return dimension_; }
  [[nodiscard]] const KineticEndpointSort& sort(int axis) const {
    return sorts_[static_cast<std::size_t>(axis)];
  }
  /// The sorts' invariants, and the contact set equal to the pairs that overlap on every axis in
  /// the maintained orders (recomputed by a sweep), with the per-box contact counts. O(d n log n
  /// + k).
  [[nodiscard]] bool validate() const;
  /// Oracle audit at t: every side order is sorted at t (exact comparisons), so that the answer
  /// at t is exact. O(d n).
  [[nodiscard]] bool audit(Time t) const {
    for (const KineticEndpointSort& s : sorts_.members()) {
      if (!s.audit(t).ok) return false;
    }
    return true;
  }
  [[nodiscard]] std::size_t certificates() const { return sorts_.certificates(); }
  [[nodiscard]] std::size_t certificates_per_object_max() const {
    return sorts_.certificates_per_object_max();
  }
  [[nodiscard]] const SweepAndPruneCounters& counters() const { return counters_; }
  [[nodiscard]] NamedCounters named_counters() const;
  /// Bytes held by the orders, the certificates' handles and the contact set.
  [[nodiscard]] std::size_t bytes() const;

 private:
  /// a and b overlap on `axis` in its maintained order.
  [[nodiscard]] bool overlap_on(std::uint32_t a, std::uint32_t b, int axis) const;
  /// a and b overlap on every axis but `skip` (-1: every axis).
  [[nodiscard]] bool overlap_elsewhere(std::uint32_t a, std::uint32_t b, int skip) const;
  void add_contact(std::uint32_t a, std::uint32_t b, bool log);
  void drop_contact(std::uint32_t a, std::uint32_t b, bool log);
  /// a and b apart just after now (after a swap of their opposite sides on `axis`, or -1 at an
  /// insert or update): notes them for queries now when their closed boxes touch now (exactly).
  void note_if_touching(std::uint32_t a, std::uint32_t b, int axis);
  /// Box i's contacts (no event logged: a timeline change, not an event), from candidates().
  [[nodiscard]] std::vector<std::uint32_t> contacts_of(std::uint32_t i);
  /// Adds every contact of box i, and notes the boxes apart just after now that touch it now.
  void find_contacts_of(std::uint32_t i);
  /// The boxes whose sides are, in the maintained order of the axis where i's two sides are
  /// fewest slots apart, between i's or around them (every box that overlaps i on that axis),
  /// into candidates_. With `touching_now`, the range is first widened over the sides next to
  /// i's whose value now equals or passes i's (boxes apart just after now that touch it now).
  void collect_candidates(std::uint32_t i, bool touching_now);
  /// The straddler index of `axis` after a change of its sort (the slots it touched, or all).
  void refresh_straddlers(int axis);
  /// The leaves of `axis`'s index that `key` decides (its own slot, and its low side's).
  void refresh_straddler_key(int axis, std::uint32_t key);
  [[nodiscard]] std::vector<std::uint32_t> straddler_leaves(int axis) const;
  /// The pairs overlapping on every axis, by a sweep along axis 0 (initialize, validate).
  [[nodiscard]] std::vector<std::uint64_t> sweep() const;
  void count_query() override { ++counters_.queries; }

  int dimension_;
  StructureGroup<KineticEndpointSort> sorts_;  // one per axis
  std::vector<std::uint32_t> contacts_of_;     // box index -> number of its contacts
  std::vector<detail::StraddlerIndex> straddlers_;   // one per axis, over its sort's slots
  std::vector<std::uint64_t> straddler_generation_;  // the sort's layout generation they follow
  std::vector<std::uint32_t> candidates_;            // collect_candidates()
  std::vector<std::uint32_t> seen_;                  // box -> stamp_ when taken as a candidate
  std::uint32_t stamp_ = 0;
  SweepAndPruneCounters counters_;
};

static_assert(KineticStructure<KineticSweepAndPrune>);

}  // namespace kinetic
