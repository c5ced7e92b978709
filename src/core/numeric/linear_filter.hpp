#pragma once
// The floating-point filter of a linear motion x(t) = c0 + c1 (t - origin) (doubles c0, c1,
// origin, t; the exact x(t) is meant), and the certified comparison of a filtered value with a
// double. The hot path of the kd-tree's and the range tree's range queries; the predicates'
// compare_at_value() uses the comparison.
//
// Bound (linear_filtered()). With s = fl(t - origin), v = fl(fl(c1 s) + c0) and
// m = fl(fl(|c1| |s|) + |c0|):
//   |v - x(t)| <= 8 u m (1 + 1e-10) + 4 DBL_MIN max(1, |s|) (1 + 1e-10),  u = 2^-53,
// evaluate_filtered()'s bound (polynomial.cpp) for degree n = 1, (4n + 4) u m (1 + 1e-10) +
// (2n + 2) DBL_MIN max(1, |s|)^n (1 + 1e-10): three roundings of relative error u each (the
// first-order error is at most 3 u |c1 (t - origin)| + u |c0|), and an underflowing product adds
// at most 2^-1075. It bounds a constant motion (c1 == 0) too. A NaN c1 (the callers' mark of a
// motion of degree above 1), a NaN or infinite input, or an overflow make the bound NaN or
// infinite: every comparison is then undecided.
// Monotone: every step of the bound is a rounded sum, product or max of non-negative numbers,
// so the bound computed for |c0'| >= |c0|, |c1'| >= |c1| and |s'| >= |s| is at least the bound
// for c0, c1, s (the kd-tree computes one margin for a whole query from this).

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <limits>

#include "core/numeric/bounded_double_double.hpp"
#include "core/numeric/interval.hpp"
#include "kinetic/core/polynomial.hpp"

namespace kinetic::numeric {

/// A motion's linear parts as the structures' filters store them: c0, the slope c1 (0 for degree
/// 0) and the origin; c1 is NaN when the degree is above 1 (the mark above: a filter on these
/// parts then decides nothing, and the caller's exact path reads the motion itself).
struct LinearParts {
  double c0 = 0.0;
  double c1 = 0.0;
  double origin = 0.0;
};
inline LinearParts linear_parts(const MotionPolynomial& p) {
  const double c1 =
      p.degree > 1 ? std::numeric_limits<double>::quiet_NaN() : (p.degree == 1 ? p.c[1] : 0.0);
  return {p.c[0], c1, p.origin};
}

/// fl(c1 fl(t - origin) + c0), linear_filtered()'s value alone (the same operations).
inline double linear_value(double c0, double c1, double origin, double t) {
  return c1 * (t - origin) + c0;
}

/// x(t) = c0 + c1 (t - origin) with the rigorous bound above: |value - x(t)| <= error.
inline FilteredValue linear_filtered(double c0, double c1, double origin, double t) {
  const double s = t - origin;
  const double as = std::fabs(s);
  const double v = c1 * s + c0;
  const double m = std::fabs(c1) * as + std::fabs(c0);
  const double growth = (1.0 + 1e-10) * std::max(1.0, as);
  return {v, 8.0 * 0x1p-53 * m * (1.0 + 1e-10) + 4.0 * DBL_MIN * growth};
}

/// The factor of sign_versus(): fl(fl(b - v) * kShrink) <= b - v whenever b - v > 0 (the
/// relative error of fl(b - v), at most u, and of the product are absorbed by 1 - 2u).
inline constexpr double kShrink = 1.0 - 0x1p-52;

/// sign(X - b) for the exact X with |value - X| <= error (in the extended reals; a NaN error or
/// value decides nothing), when the bound certifies it; 0 otherwise. Certain: b - X >=
/// (b - value) - error >= fl(fl(b - value) * kShrink) - error > 0, and symmetrically.
inline int sign_versus(double value, double error, double b) {
  if ((b - value) * kShrink > error) return -1;
  if ((value - b) * kShrink > error) return 1;
  return 0;
}

inline int sign_versus(const FilteredValue& x, double b) {
  return sign_versus(x.value, x.error, b);
}

/// sign_versus() with the error bound shared by many values and b fixed, as one comparison per
/// value: a double c <= b - error (in the reals), so that value < c certifies X < b for the
/// exact X with |value - X| <= error. b may be infinite (-infinity: nothing is below it; +infinity:
/// every finite X is); a NaN (nothing certified) when b - error is undefined.
inline double below_cut(double b, double error) {
  const double y = b - error;
  return std::isinf(y) ? y : down(y);
}
/// The mirror of below_cut(): a double c >= b + error, so that value > c certifies X > b.
inline double above_cut(double b, double error) {
  const double y = b + error;
  return std::isinf(y) ? y : up(y);
}

/// sign(x(t) - b) for x(t) = c0 + c1 (t - origin) when the filter certifies it, 0 otherwise.
inline int linear_sign_versus(double c0, double c1, double origin, double t, double b) {
  return sign_versus(linear_filtered(c0, c1, origin, t), b);
}

/// x(t) - q for x(t) = c0 + c1 (t - origin) in double-double arithmetic with its rigorous bound
/// (BoundedDoubleDouble: (c0 - q) + c1 (t - origin), each step's rounding about 2^-100 of its
/// terms), rounded to its leading double hi: the value is within |lo| + err of x(t) - q, about
/// u |x(t) - q| plus 2^-100 of the terms, where linear_filtered() has 8 u (|c0| + |c1 (t -
/// origin)|). What decides distances far below the coordinates' magnitude (a query point next
/// to a point) without exact arithmetic. An overflow or a NaN or infinite input makes the error
/// NaN: undecided.
inline FilteredValue linear_minus_compensated(double c0, double c1, double origin, double t,
                                              double q) {
  using D = BoundedDoubleDouble;
  const D x = (D::exact(c0) - D::exact(q)) + D::exact(c1) * (D::exact(t) - D::exact(origin));
  if (!x.finite()) return {x.hi, std::numeric_limits<double>::quiet_NaN()};
  return {x.hi, up(std::fabs(x.lo) + x.err)};
}

/// p(t) with a rigorous bound: linear_filtered() for degree <= 1 (inline, the common motions),
/// evaluate_filtered() above.
inline FilteredValue filtered_value(const MotionPolynomial& p, Time t) {
  if (p.degree <= 1) return linear_filtered(p.c[0], p.degree == 1 ? p.c[1] : 0.0, p.origin, t);
  return evaluate_filtered(p, t);
}

/// sign(v1 + v2 - v3 - v4) for the exact values V_i with |v_i - V_i| <= e_i when the bound
/// certifies it, 0 otherwise. fl(fl(v1 + v2) - fl(v3 + v4)) is within u (|v1 + v2| + |v3 + v4|)
/// + u |v1 + v2 - v3 - v4| <= 2 (1 + u) u sum |v_i| of the exact sum of the v_i (u = 2^-53;
/// sums do not underflow), so sum e_i + 3 u sum |v_i|, with a relative margin for its own
/// roundings, bounds the whole error.
inline int sum_sign(const FilteredValue& v1, const FilteredValue& v2, const FilteredValue& v3,
                    const FilteredValue& v4) {
  const double value = (v1.value + v2.value) - (v3.value + v4.value);
  const double magnitude =
      std::fabs(v1.value) + std::fabs(v2.value) + std::fabs(v3.value) + std::fabs(v4.value);
  const double error =
      ((v1.error + v2.error) + (v3.error + v4.error) + 3.0 * 0x1p-53 * magnitude) * (1.0 + 1e-10);
  return sign_versus(value, error, 0.0);
}

}  // namespace kinetic::numeric
