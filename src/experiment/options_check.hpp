#pragma once
// The checks both experiments make of their options before anything runs (private to the
// experiment layer): at least two objects, at least one bin, every eps a robust precision.

#include <cstddef>
#include <string>
#include <vector>

#include "kinetic/core/error.hpp"
#include "kinetic/core/scheduler.hpp"

namespace kinetic::experiment::detail {

inline void require_options(const char* where, std::size_t n, std::size_t bins,
                            const std::vector<double>& eps) {
  if (n < 2) precondition_failed(where, "n = " + std::to_string(n) + " (at least 2 objects)");
  if (bins < 1) precondition_failed(where, "bins = 0 (at least 1)");
  for (const double e : eps) {
    if (!Scheduler::eps_supported(e)) {
      precondition_failed(where, "eps = " + format_number(e) +
                                     " (a robust precision: positive, finite, at most " +
                                     format_number(Scheduler::kMaxEps) + ")");
    }
  }
}

}  // namespace kinetic::experiment::detail
