#pragma once
// Event scheduling policies: how a certificate's failure time is computed and which times are
// scheduled. The structures ask the scheduler; they never compute failure times themselves, so
// the robust scheduling of seed paper 000 (EVENTTIME over CROP) slots in here for every structure.

#include <optional>
#include <string>

#include "kinetic/core/counters.hpp"
#include "kinetic/core/polynomial.hpp"

namespace kinetic {

enum class SchedulerKind {
  /// Traditional KDS scheduling: failure times computed in floating point, the first one not in
  /// the past is scheduled (paper 000, Sections 1 and 6, the baseline).
  Classic,
  /// Out-of-order-safe scheduling: EVENTTIME over CROP root isolation (paper 000, Sections 2-3).
  Robust,
  /// Exact event order.
  Exact,
};

[[nodiscard]] const char* to_string(SchedulerKind kind);
[[nodiscard]] std::optional<SchedulerKind> scheduler_from_string(const std::string& name);
/// True when this build implements the scheduler.
[[nodiscard]] bool scheduler_available(SchedulerKind kind);

class Scheduler {
 public:
  explicit Scheduler(SchedulerKind kind = SchedulerKind::Classic, double eps = 1e-9)
      : kind_(kind), eps_(eps) {}

  [[nodiscard]] SchedulerKind kind() const { return kind_; }
  [[nodiscard]] double eps() const { return eps_; }

  /// The time at which to schedule the failure of certificate [lower < upper], computed at
  /// t_curr, or +infinity when it is not to be scheduled. Classic: the first floating-point
  /// sign-change root not in the past (it may equal t_curr, as in a traditional KDS).
  /// Precondition: scheduler_available(kind()).
  [[nodiscard]] Time failure_time(const MotionPolynomial& lower, const MotionPolynomial& upper,
                                  Time t_curr, Counters& counters) const;

 private:
  SchedulerKind kind_;
  double eps_;
};

}  // namespace kinetic
