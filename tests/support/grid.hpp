#pragma once
// The robust scheduler's grid, from its definition (docs/crop.md, "Grid width"), for tests that
// ask an oracle where a structure's guarantee puts its answer.

#include <cmath>

#include "kinetic/core/time.hpp"

namespace kinetic::test {

/// The robust scheduler's grid point at or before t for precision eps: (j + 1/2) w with w the
/// largest power of two <= (sqrt(3) / 2) eps.
inline Time grid_point_before(Time t, double eps) {
  const double w = std::exp2(std::floor(std::log2(eps * 0.8660254037844386)));
  Time g = (std::floor(t / w - 0.5) + 0.5) * w;
  while (g > t) g -= w;
  while (g + w <= t) g += w;
  return g;
}

}  // namespace kinetic::test
