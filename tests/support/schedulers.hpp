#pragma once
// Test support: the scheduler variants the tests run. The classic scheduler decides in floating
// point as a traditional KDS does (Scheduler::floating_point_decisions()); its variant with exact
// decisions (Scheduler::set_classic_exact_decisions) keeps floating-point failure times but takes
// every decision exactly. Oracle tests that hold a structure to exact answers on degenerate input
// (equal trajectories, ties at update times) run the variant with exact decisions; the traditional
// classic is run beside them for what it promises (validate() after every event, termination) and
// for being the traditional one.

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

inline std::string to_string(const SchedulerChoice& c) {
  return c.classic_exact_decisions ? "classic with exact decisions" : kinetic::to_string(c.kind);
}

}  // namespace kinetic::test
