#pragma once
// The contact set of a kinetic broad phase over a table of moving boxes (core/boxes.hpp): what
// the kinetic BVH and kinetic sweep-and-prune share, written once. The base holds the table and
// its sync, the simulator, the pairs in contact as the structure maintains them (a PairSet of
// table indices) and the contacts that ended at the current instant (EndedContacts); it answers
// `colliding_pairs` from them and checks what a table of boxes must be. A structure keeps the
// set by its own certificates and counts the queries in its counters (count_query()).

#include <cstddef>
#include <cstdint>
#include <span>
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
  /// The number of pairs in contact.
  [[nodiscard]] std::size_t contacts() const { return contacts_.size(); }
  /// Whether boxes a and b (table indices) are a pair of the contact set. O(1).
  [[nodiscard]] bool in_contact(std::uint32_t a, std::uint32_t b) const {
    return contacts_.contains(a, b);
  }
  /// initialize() was called.
  [[nodiscard]] bool initialized() const { return sync_.initialized(); }

 protected:
  /// `query_where` names colliding_pairs() in its refusals ("KineticBvh::colliding_pairs").
  BoxContacts(const MotionTable& boxes, Simulator& simulator, const char* query_where)
      : boxes_(boxes), sim_(simulator), query_where_(query_where) {}
  ~BoxContacts() = default;

  /// Throws PreconditionError (naming `structure`) unless the table holds boxes (an even
  /// dimension: centers, then half extents) in 1 to 3 dimensions.
  static void require_box_table(const MotionTable& boxes, const char* structure);
  /// The box's row of the table (require_box_row).
  void require_box(std::uint32_t index, const char* where) const {
    require_box_row(boxes_, index, where);
  }
  /// A colliding_pairs() query, counted in the structure's counters.
  virtual void count_query() = 0;

  const MotionTable& boxes_;
  TableSync sync_{boxes_};
  Simulator& sim_;
  PairSet contacts_;     // box index pairs
  EndedContacts ended_;  // contacts that ended at the current instant (exact scheduler)

 private:
  const char* query_where_;
};

}  // namespace kinetic
