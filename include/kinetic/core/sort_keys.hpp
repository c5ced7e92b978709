#pragma once
// What a kinetic sort sorts: keys, each a function of time read from a MotionTable through a
// narrow interface. A table object owns kKeysPerObject consecutive keys (key = object *
// kKeysPerObject + slot). AxisKeys: one key per object, its motion on one axis (points on a
// line). BoxEndpointKeys (core/boxes.hpp): two keys per box, the low and high sides of its
// projection on one axis (the endpoints of sweep-and-prune). The sort compares keys only through
// these functions, so every decision stays exact whatever a key is made of.

#include <array>
#include <concepts>
#include <cstdint>
#include <vector>

#include "kinetic/core/counters.hpp"
#include "kinetic/core/crop.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/preconditions.hpp"
#include "kinetic/core/predicates.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/time.hpp"

namespace kinetic {

template <class K>
concept SortKeys = requires(K& k, const K& ck, std::uint32_t a, Time t, PredicateStats* stats,
                            const Scheduler& scheduler, Counters& counters, ExactFailure* exact) {
  { K::kKeysPerObject } -> std::convertible_to<std::uint32_t>;
  { ck.table() } -> std::same_as<const MotionTable&>;
  { ck.axis() } -> std::same_as<int>;
  /// The object's keys were (re)read from the table: after initialize, insert, motion change.
  { k.refresh(a) } -> std::same_as<void>;
  /// sign(key a - key b) just after t, exactly; 0 only when they are the same function of t.
  { ck.compare_after(a, a, t, stats) } -> std::same_as<int>;
  /// sign(key a - key b) at t, exactly.
  { ck.compare_at(a, a, t) } -> std::same_as<int>;
  /// Key a's value at t computed in floating point, as a traditional KDS reads it (the classic
  /// scheduler's order, Scheduler::floating_point_decisions()).
  { ck.value_at(a, t) } -> std::same_as<double>;
  /// The fixed order of two keys that are the same function of t.
  { ck.tie_before(a, a) } -> std::same_as<bool>;
  /// The failure time of [lower < upper] (Scheduler::failure_time on the keys' functions; the
  /// exact one in *exact under the exact scheduler).
  { ck.failure_time(scheduler, a, a, t, t, counters, exact) } -> std::same_as<Time>;
};

/// One key per object: its motion on one axis, identical motions ordered by id.
class AxisKeys {
 public:
  static constexpr std::uint32_t kKeysPerObject = 1;
  /// Throws PreconditionError unless 0 <= axis < table.dimension().
  AxisKeys(const MotionTable& table, int axis) : table_(table), axis_(axis) {
    require_axis("KineticSort", axis, table.dimension());
  }

  [[nodiscard]] const MotionTable& table() const { return table_; }
  [[nodiscard]] int axis() const { return axis_; }
  void refresh(std::uint32_t /*object*/) {}
  [[nodiscard]] const MotionPolynomial& motion(std::uint32_t key) const {
    return table_.motion(key, axis_);
  }
  [[nodiscard]] int compare_after(std::uint32_t a, std::uint32_t b, Time t,
                                  PredicateStats* stats) const {
    return kinetic::compare_after(motion(a), motion(b), t, stats);
  }
  [[nodiscard]] int compare_at(std::uint32_t a, std::uint32_t b, Time t) const {
    return kinetic::compare_at(motion(a), motion(b), t);
  }
  [[nodiscard]] double value_at(std::uint32_t a, Time t) const { return motion(a).evaluate(t); }
  [[nodiscard]] bool tie_before(std::uint32_t a, std::uint32_t b) const {
    return table_.id(a) < table_.id(b);
  }
  [[nodiscard]] Time failure_time(const Scheduler& scheduler, std::uint32_t lower,
                                  std::uint32_t upper, Time t_curr, Time window_lo,
                                  Counters& counters, ExactFailure* exact) const {
    return scheduler.failure_time(motion(lower), motion(upper), t_curr, window_lo, counters, exact);
  }

 private:
  const MotionTable& table_;
  int axis_;
};

static_assert(SortKeys<AxisKeys>);

/// SortKeys' comparisons and failure time for keys whose difference key a - key b is a
/// MotionCombination, Keys::difference(a, b): its exact signs and the scheduler's failure time.
template <class Keys>
class CombinationKeys {
 public:
  [[nodiscard]] int compare_after(std::uint32_t a, std::uint32_t b, Time t,
                                  PredicateStats* stats) const {
    return sign_after(keys().difference(a, b), t, stats);
  }
  [[nodiscard]] int compare_at(std::uint32_t a, std::uint32_t b, Time t) const {
    return sign_at(keys().difference(a, b), t);
  }
  [[nodiscard]] Time failure_time(const Scheduler& scheduler, std::uint32_t lower,
                                  std::uint32_t upper, Time t_curr, Time window_lo,
                                  Counters& counters, ExactFailure* exact) const {
    return scheduler.failure_time(keys().difference(upper, lower), t_curr, window_lo, counters,
                                  exact);
  }

 private:
  [[nodiscard]] const Keys& keys() const { return static_cast<const Keys&>(*this); }
};

/// One key per object of a table of dimension 2: a x + b y, for one of eight fixed integer
/// directions (a, b) (the cones of the kinetic closest pair, closest_pair/). A comparison of two
/// keys is the exact sign of the combination a x_u + b y_u - a x_w - b y_w of four motions (a
/// coefficient 2 reads a copy of the motion with its coefficients doubled, exactly), so every
/// decision is exact and every scheduler takes it (robust: CROP on the MotionCombination).
/// Identical key functions are ordered as an infinitesimal translation of each object by
/// id * (1, delta) would order them (delta infinitesimal too): by id, ascending when a > 0 or
/// (a = 0 and b > 0), descending otherwise. One perturbation for every direction, so the eight
/// orders are those of one perturbed point set.
class DirectionKeys : public CombinationKeys<DirectionKeys> {
 public:
  static constexpr std::uint32_t kKeysPerObject = 1;
  struct Direction {
    int a = 0, b = 0;
  };
  /// y, x - y, x, x + y, 2x + y, x + 2y, -x + 2y, -2x + y.
  static constexpr std::array<Direction, 8> kDirections{
      {{0, 1}, {1, -1}, {1, 0}, {1, 1}, {2, 1}, {1, 2}, {-1, 2}, {-2, 1}}};
  /// Throws PreconditionError unless table.dimension() == 2 and 0 <= direction < 8.
  DirectionKeys(const MotionTable& table, int direction);

  [[nodiscard]] const MotionTable& table() const { return table_; }
  /// The direction's index in kDirections (what the sort calls its axis).
  [[nodiscard]] int axis() const { return direction_; }
  [[nodiscard]] Direction direction() const { return kDirections[direction_]; }
  /// Reads the object's motions again (the doubled copies a coefficient 2 needs). Throws
  /// PreconditionError when doubling a coefficient overflows.
  void refresh(std::uint32_t object);
  /// a x(t) + b y(t) in floating point (what a traditional KDS reads).
  [[nodiscard]] double value_at(std::uint32_t object, Time t) const;
  [[nodiscard]] bool tie_before(std::uint32_t a, std::uint32_t b) const {
    return ascending_ids_ ? table_.id(a) < table_.id(b) : table_.id(a) > table_.id(b);
  }
  /// key u - key w as a combination of four motions.
  [[nodiscard]] MotionCombination difference(std::uint32_t u, std::uint32_t w) const;

 private:
  /// |coefficient| times the object's motion on an axis (the zero motion for 0).
  [[nodiscard]] const MotionPolynomial& scaled(std::uint32_t object, int axis, int coefficient) const;

  const MotionTable& table_;
  int direction_;
  bool ascending_ids_;
  std::array<std::vector<MotionPolynomial>, 2> doubled_;  // axis -> object -> 2 x its motion
};

static_assert(SortKeys<DirectionKeys>);

}  // namespace kinetic
