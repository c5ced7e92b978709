#pragma once
// Test support: the scheduler variants the tests run. The classic scheduler decides in floating
// point as a traditional KDS does (Scheduler::floating_point_decisions()); its variant with exact
// decisions (Scheduler::set_classic_exact_decisions) keeps floating-point failure times but takes
// every decision exactly. Oracle tests that hold a structure to exact answers on degenerate input
// (equal trajectories, ties at update times) run the variant with exact decisions; the traditional
// classic is run beside them for what it promises (validate() after every event, termination) and
// for being the traditional one.

#include <array>
#include <string>

#include "kinetic/core/scheduler.hpp"

namespace kinetic::test {

struct SchedulerChoice {
  SchedulerKind kind = SchedulerKind::Classic;
  bool classic_exact_decisions = false;

  SchedulerChoice(SchedulerKind k) : kind(k) {}  // NOLINT(google-explicit-constructor)
  SchedulerChoice(SchedulerKind k, bool exact_decisions)
      : kind(k), classic_exact_decisions(exact_decisions) {}

  /// Sets the variant on a scheduler of kind `kind`; returns it.
  Scheduler& configure(Scheduler& s) const {
    s.set_classic_exact_decisions(classic_exact_decisions);
    return s;
  }
  [[nodiscard]] bool traditional_classic() const {
    return kind == SchedulerKind::Classic && !classic_exact_decisions;
  }
};

/// The classic scheduler with exact decisions.
inline const SchedulerChoice kClassicExactDecisions{SchedulerKind::Classic, true};

/// The schedulers of the oracle tests: robust, the traditional classic, classic with exact
/// decisions, exact; and the three that decide differently (no robust).
inline const SchedulerChoice kEverySchedulerChoice[] = {
    SchedulerKind::Robust, SchedulerKind::Classic, kClassicExactDecisions, SchedulerKind::Exact};
inline const SchedulerChoice kDecidingSchedulerChoices[] = {
    SchedulerKind::Classic, kClassicExactDecisions, SchedulerKind::Exact};

/// Two lines x(t) = x[0] + x[1] t and y(t) = y[0] + y[1] t whose floating-point and exact orders
/// at t = kTieTime differ. They cross 8.1e-18 after it: just after kTieTime, x is above y exactly
/// (x - y = +1.0e-17 there), but x(kTieTime) < y(kTieTime) in floating point (one ulp apart), and
/// the coefficients of x - y computed in floating point vanish at kTieTime, where their negative
/// slope decides "x below". Tests pin with them that the traditional classic decides in floating
/// point.
inline constexpr std::array<double, 2> kTieX{0.63941616144475599, -2.540065863414021};
inline constexpr std::array<double, 2> kTieY{-1.011027190274201, -1.2704940543994387};
inline constexpr double kTieTime = 1.3;

inline std::string to_string(const SchedulerChoice& c) {
  return c.classic_exact_decisions ? "classic with exact decisions" : kinetic::to_string(c.kind);
}

}  // namespace kinetic::test
