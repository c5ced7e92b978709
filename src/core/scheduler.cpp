#include "kinetic/core/scheduler.hpp"

#include <cassert>

#include "kinetic/core/float_roots.hpp"

namespace kinetic {

const char* to_string(SchedulerKind kind) {
  switch (kind) {
    case SchedulerKind::Classic:
      return "classic";
    case SchedulerKind::Robust:
      return "robust";
    case SchedulerKind::Exact:
      return "exact";
  }
  return "?";
}

std::optional<SchedulerKind> scheduler_from_string(const std::string& name) {
  if (name == "classic") return SchedulerKind::Classic;
  if (name == "robust") return SchedulerKind::Robust;
  if (name == "exact") return SchedulerKind::Exact;
  return std::nullopt;
}

bool scheduler_available(SchedulerKind kind) { return kind == SchedulerKind::Classic; }

Time Scheduler::failure_time(const MotionPolynomial& lower, const MotionPolynomial& upper,
                             Time t_curr, Counters& counters) const {
  assert(scheduler_available(kind_));
  ++counters.root_isolation_calls;
  return classic_failure_time(lower, upper, t_curr);
}

}  // namespace kinetic
