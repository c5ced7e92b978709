#pragma once
// Test support without a test framework (the fuzz harnesses use it too): whether two motions
// meet within a time window, for oracle checks that must skip times near an event.

#include <array>
#include <cmath>
#include <span>

#include "kinetic/core/float_roots.hpp"
#include "kinetic/core/polynomial.hpp"
#include "kinetic/core/predicates.hpp"

namespace kinetic::test {

/// True when a and b cross or touch somewhere in [lo, hi] (up to the rounding of floating-point
/// roots, widened by a tiny pad): exact signs at the ends, floating-point sign-change roots of
/// a - b inside, and the exact sign at the floating-point critical points (touches).
inline bool cross_within(const MotionPolynomial& a, const MotionPolynomial& b, Time lo, Time hi) {
  const int s_lo = compare_at(a, b, lo), s_hi = compare_at(a, b, hi);
  if (s_lo == 0 || s_hi == 0 || s_lo != s_hi) return true;
  std::array<double, kMaxMotionDegree + 1> d{};
  const int degree = float_difference(a, b, d);
  if (degree == 0) return false;
  std::array<FloatRoot, kMaxMotionDegree> roots{};
  const double pad = 1e-9 * (1.0 + std::abs(lo) + std::abs(hi));
  if (float_sign_change_roots(d, degree, lo - b.origin - pad, hi - b.origin + pad, roots) > 0)
    return true;
  if (degree < 2) return false;
  std::array<double, kMaxMotionDegree> deriv{};
  for (int i = 1; i <= degree; ++i) deriv[i - 1] = i * d[i];
  const int m = float_sign_change_roots(std::span<const double>(deriv.data(), degree), degree - 1,
                                        lo - b.origin, hi - b.origin, roots);
  for (int i = 0; i < m; ++i) {
    if (compare_at(a, b, b.origin + roots[i].at) != s_lo) return true;
  }
  return false;
}

}  // namespace kinetic::test
