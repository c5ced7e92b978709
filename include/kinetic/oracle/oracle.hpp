#pragma once
// The brute-force oracle: the true answer at any time, computed from the motions alone with exact
// comparisons. Tests, audits and experiments hold the kinetic structures against it.

#include <cstdint>
#include <span>
#include <vector>

#include "kinetic/core/motion_table.hpp"

namespace kinetic::oracle {

/// Live objects sorted by coordinate `axis` at time t; equal values ordered as just after t, then
/// by id. O(n log n) exact comparisons.
[[nodiscard]] std::vector<std::uint32_t> sorted_at(const MotionTable& motions, int axis, Time t);

/// True when `order` lists values that are non-decreasing at t (exactly): a correct sorted order,
/// whatever it does with ties.
[[nodiscard]] bool is_sorted_at(const MotionTable& motions, std::span<const std::uint32_t> order,
                                int axis, Time t);

/// An object with the largest / smallest coordinate `axis` at t (ties: the smallest id).
/// Precondition: motions.size() > 0.
[[nodiscard]] std::uint32_t max_at(const MotionTable& motions, int axis, Time t);
[[nodiscard]] std::uint32_t min_at(const MotionTable& motions, int axis, Time t);

/// The geometric error of a maintained order (paper 000, Section 6):
/// err(t) = max_i |y_i(t) - z_i(t)|, y the maintained order, z the true one; values are the exact
/// ones rounded to doubles.
[[nodiscard]] double sorting_error(const MotionTable& motions, std::span<const std::uint32_t> order,
                                   int axis, Time t);

}  // namespace kinetic::oracle
