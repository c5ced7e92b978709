#pragma once
// Moving boxes in a MotionTable (`objects_are: "boxes"` in a scenario). An object of a table of
// d-dimensional boxes has 2d coordinates: its center's motion on coordinates 0..d-1 and its half
// extents, constant polynomials >= 0, on coordinates d..2d-1. The box is the closed
// [c_k(t) - h_k, c_k(t) + h_k] on every axis k. A side c_k - h_k is never formed in floating
// point (it would be rounded): side comparisons are exact signs of combinations of the center
// motions and the half extents (MotionCombination, core/crop.hpp).

#include <cstdint>

#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/polynomial.hpp"

namespace kinetic {

/// The table dimension holding boxes of dimension d.
[[nodiscard]] constexpr int boxes_table_dimension(int d) { return 2 * d; }
/// The boxes' dimension of a table of boxes.
[[nodiscard]] inline int box_dimension(const MotionTable& boxes) { return boxes.dimension() / 2; }

[[nodiscard]] inline const MotionPolynomial& center(const MotionTable& boxes, std::uint32_t index,
                                                    int axis) {
  return boxes.motion(index, axis);
}
[[nodiscard]] inline const MotionPolynomial& half_extent(const MotionTable& boxes,
                                                         std::uint32_t index, int axis) {
  return boxes.motion(index, box_dimension(boxes) + axis);
}

/// Which side of a box on an axis.
enum class BoxSide : std::int8_t { Low = 0, High = 1 };

/// sign(side s of box a on `axis` - side u of box b on `axis`) at t, exactly.
[[nodiscard]] int compare_sides_at(const MotionTable& boxes, std::uint32_t a, BoxSide s,
                                   std::uint32_t b, BoxSide u, int axis, Time t);

/// Whether boxes a and b overlap at t (closed: touching counts), exactly: on every axis
/// low(a) <= high(b) and low(b) <= high(a).
[[nodiscard]] bool boxes_overlap_at(const MotionTable& boxes, std::uint32_t a, std::uint32_t b,
                                    Time t);

}  // namespace kinetic
