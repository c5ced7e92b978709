#pragma once
// The contact set of a kinetic broad phase over a table of moving boxes (core/boxes.hpp): what
// the kinetic BVHs and kinetic sweep-and-prune share, written once. The base holds the table and
// its sync, the simulator, the pairs in contact as the structure maintains them (a PairSet of
// table indices, changed only through begin_contact / end_contact / clear_contacts) and the
// contacts that ended at the current instant (EndedContacts); it answers `colliding_pairs` and
// `contact_changes` from them, logs the contact_begin / contact_end events, and checks what a
// table of boxes must be. A structure keeps the set by its own certificates and counts the
// queries in its counters (count_query()).

#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "kinetic/core/boxes.hpp"
#include "kinetic/core/ids.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/pair_set.hpp"
#include "kinetic/core/polynomial.hpp"
#include "kinetic/core/preconditions.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/time.hpp"

namespace kinetic {

/// A pair of boxes (ids, the smaller first) whose contact changed, and when.
struct ContactChange {
  ObjectId a = 0;
  ObjectId b = 0;
  Time time = 0.0;
  friend bool operator==(const ContactChange&, const ContactChange&) = default;
};

/// The answer of BoxContacts::contact_changes(t): how the `colliding_pairs` answer at t differs
/// from the one at the previous call's time, and the contacts in between that neither holds.
/// Each list sorted by ids.
struct ContactChanges {
  /// In the answer at t, not in the previous one. time: when the contact began (the last time,
  /// if it began more than once; t for boxes that only touch at t).
  std::vector<ContactChange> begun;
  /// In the previous answer, not at t (removed boxes' contacts too). time: when it ended (the
  /// last time).
  std::vector<ContactChange> ended;
  /// In neither answer, yet in contact in between: the contacts a query per frame misses.
  /// time: when the first of them began.
  std::vector<ContactChange> touched;
};

class BoxContacts {
 public:
  BoxContacts(const BoxContacts&) = delete;
  BoxContacts& operator=(const BoxContacts&) = delete;

  /// A box's motion as a table row (centers, then half extents): every half extent a constant
  /// >= 0. Throws PreconditionError naming the id and the axis otherwise (the Session checks it
  /// before the table changes; initialize, insert and update check the table's rows).
  static void require_motion(std::span<const MotionPolynomial> motion, ObjectId id,
                             const char* where) {
    require_box_motion(motion, id, where);
  }

  /// Every pair of boxes in contact at t = sim.now(), from the maintained contact set: pairs of
  /// table indices, each (smaller id, larger id), sorted by ids, with the contacts that ended at
  /// t (closed boxes still touch then). O(k log k) for k contacts. Exact when every certificate
  /// holds at t (classic scheduling processes a failure at its floating-point time; robust
  /// scheduling within its delay bound after the exact one, so a pair whose contact began or
  /// ended within that delay before t may still be reported as before). Throws
  /// PreconditionError at another time, before initialize() or after an untold change of the
  /// table.
  [[nodiscard]] std::vector<IndexPair> colliding_pairs(Time t);
  /// The broad phase's per-frame report, at the cost of what changed: the pairs that began and
  /// ended contact since the previous call, and those whose contact began and ended in between
  /// (ContactChanges). The first call reports every pair of colliding_pairs(t) as begun (O(k log
  /// k)); each later one costs O(c log c) for the c contact changes since the previous call, so a
  /// scene at rest costs nothing per call. Applying begun and ended to the previous answer gives
  /// colliding_pairs(t). Exact as colliding_pairs is; throws as it does.
  [[nodiscard]] ContactChanges contact_changes(Time t);
  /// The number of pairs in contact.
  [[nodiscard]] std::size_t contacts() const { return contacts_.size(); }
  /// Whether boxes a and b (table indices) are a pair of the contact set. O(1).
  [[nodiscard]] bool in_contact(std::uint32_t a, std::uint32_t b) const {
    return contacts_.contains(a, b);
  }
  /// initialize() was called.
  [[nodiscard]] bool initialized() const { return sync_.initialized(); }

 protected:
  /// `query_where` and `changes_where` name colliding_pairs() and contact_changes() in their
  /// refusals ("KineticBvh::colliding_pairs").
  BoxContacts(const MotionTable& boxes, Simulator& simulator, const char* query_where,
              const char* changes_where)
      : boxes_(boxes), sim_(simulator), query_where_(query_where), changes_where_(changes_where) {}
  ~BoxContacts() = default;

  /// Throws PreconditionError (naming `structure`) unless the table holds boxes (an even
  /// dimension: centers, then half extents) in 1 to 3 dimensions.
  static void require_box_table(const MotionTable& boxes, const char* structure);
  /// The box's row of the table (require_box_row).
  void require_box(std::uint32_t index, const char* where) const {
    require_box_row(boxes_, index, where);
  }
  /// A colliding_pairs() or contact_changes() query, counted in the structure's counters.
  virtual void count_query() = 0;

  /// The pairs in contact (box table indices).
  [[nodiscard]] const PairSet& contact_set() const { return contacts_; }
  /// Boxes a and b (table indices, both in the table, ids readable) enter the contact set; false
  /// when they were in it. Not an event: log_contact() logs one.
  bool begin_contact(std::uint32_t a, std::uint32_t b);
  /// Boxes a and b leave the contact set (a removed box's id is still readable); false when they
  /// were not in it.
  bool end_contact(std::uint32_t a, std::uint32_t b);
  /// Every pair leaves the contact set.
  void clear_contacts();
  /// The external event contact_begin / contact_end of boxes a and b at now, in the simulator's
  /// log (ids, the smaller first); an ended contact is noted for queries at this instant.
  void log_contact(bool begins, std::uint32_t a, std::uint32_t b);

  const MotionTable& boxes_;
  TableSync sync_{boxes_};
  Simulator& sim_;
  EndedContacts ended_;  // contacts that ended at the current instant (exact scheduler)

 private:
  /// A change of the contact set since the last contact_changes() call, in order.
  struct Journaled {
    ObjectId a;
    ObjectId b;
    Time time;
    bool begins;
  };
  using IdPair = std::pair<ObjectId, ObjectId>;
  void journal(std::uint32_t a, std::uint32_t b, bool begins);
  /// The pairs of the answer at now that are not in the contact set (they touch only now), as
  /// id pairs sorted.
  [[nodiscard]] std::vector<IdPair> touching_only_now() const;

  PairSet contacts_;  // box index pairs
  const char* query_where_;
  const char* changes_where_;
  bool tracking_ = false;                // contact_changes() was called: changes are journaled
  std::vector<Journaled> journal_;       // since the last contact_changes() call
  std::vector<IdPair> touching_before_;  // touching_only_now() at that call
  Time last_call_ = 0.0;
};

}  // namespace kinetic
