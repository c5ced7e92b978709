#pragma once
// Preconditions of the public API, checked in every build type: a call that would otherwise give
// a wrong answer (or touch memory it must not) throws PreconditionError with a message that says
// what was wrong and where, e.g. "KineticKdTree::range: the box has 1 axis, the structure 2". The
// checks cost O(1) (or O(d)) per call at the API, never per event.
//
// TableSync is how a structure knows that it has been told of every change to its motion table:
// the table counts its changes (MotionTable::version()), the structure notes the count whenever it
// has caught up (initialize, insert, remove, motion_changed), and a query or validate() compares.

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>

#include "kinetic/core/error.hpp"
#include "kinetic/core/geometry.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/time.hpp"

namespace kinetic {

/// A query at time t on a structure whose simulator is at `now`: they must be equal (a structure
/// is correct at its simulator's time only; advance first).
inline void require_query_time(const char* where, Time t, Time now) {
  if (t != now) {
    precondition_failed(where, "query at t = " + format_number(t) +
                                   " but the structure is at t = " + format_number(now) +
                                   " (advance the simulator to t first; a structure answers at "
                                   "its current time only)");
  }
}

/// A box with one [lo, hi] pair per axis of a structure of dimension d, no NaN (lo > hi is the
/// empty box).
void require_box(const char* where, const Box& box, int dimension);

/// A structure over a table of `dimension` coordinates supports lo..hi of them (`what` says which
/// objects, e.g. "points in the plane").
/// A query point (nearest, k_nearest, farthest): `coordinates` == dimension, every one finite;
/// eps finite and >= 0.
void require_query_point(const char* where, std::span<const double> q, int dimension, double eps);
void require_dimension(const char* where, int dimension, int lo, int hi, const char* what);

/// An axis 0 <= axis < dimension of the table.
void require_axis(const char* where, int axis, int dimension);

/// The structure's record of its table: initialized, and told of every change.
class TableSync {
 public:
  explicit TableSync(const MotionTable& table) : table_(table) {}
  /// The structure has caught up with the table (after initialize, insert, remove,
  /// motion_changed).
  void note() {
    seen_ = table_.version();
    initialized_ = true;
  }
  [[nodiscard]] bool initialized() const { return initialized_; }
  /// Initialized, and no change to the table since the structure last caught up.
  [[nodiscard]] bool current() const { return initialized_ && seen_ == table_.version(); }
  /// Throws unless current(): names the missing call.
  void require_current(const char* where) const {
    if (!current()) fail(where);
  }
  /// insert(index): initialized, and the object is in the table (it joins the table first).
  /// Notes the table's state: the structure catches up with this call.
  void require_inserted(const char* where, std::uint32_t index) {
    require_object(where, index, true, "insert it into the table first");
  }
  /// remove(index): initialized, and the object has left the table (the table changes first).
  void require_removed(const char* where, std::uint32_t index) {
    require_object(where, index, false, "remove it from the table first");
  }
  /// motion_changed(index): initialized, and the object is in the table.
  void require_updated(const char* where, std::uint32_t index) {
    require_object(where, index, true, "it is not an object of the table");
  }

 private:
  [[noreturn]] void fail(const char* where) const;
  void require_object(const char* where, std::uint32_t index, bool alive, const char* hint) {
    if (!initialized_ || table_.alive_index(index) != alive) object_failed(where, index, hint);
    note();
  }
  [[noreturn]] void object_failed(const char* where, std::uint32_t index, const char* hint) const;

  const MotionTable& table_;
  std::uint64_t seen_ = 0;
  bool initialized_ = false;
};

/// A point query's checks (k_nearest): the structure current with its table, t == now, and
/// require_query_point(q, dimension, eps).
inline void require_point_query_at(const char* where, const TableSync& sync, Time t, Time now,
                                   std::span<const double> q, int dimension, double eps) {
  sync.require_current(where);
  require_query_time(where, t, now);
  require_query_point(where, q, dimension, eps);
}

}  // namespace kinetic
