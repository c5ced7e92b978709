#pragma once
// Error-free transformations of doubles: a rounded result and its exact rounding error.
//
// Model: IEEE-754 binary64, round to nearest (ties to even), gradual underflow, no fused
// multiply-add. The project builds with -ffp-contract=off, so every + - * below is one correctly
// rounded operation and TwoProduct is Dekker's (no std::fma). u = 2^-53 is the unit roundoff.
//
// Users: the compensated evaluations of polynomial.cpp (compensated Horner, Taylor and Bernstein
// coefficients in double-double), the exact coefficient differences of crop.cpp and
// polynomial.cpp (motion_difference), and the discriminant sign of CROP's quadratic path.

#include <array>
#include <cmath>

namespace kinetic::numeric {

/// Knuth's TwoSum: s = fl(a + b) and s + e == a + b exactly, with |e| <= u |s| (e == 0 when s is
/// subnormal or zero). Domain: a, b finite and fl(a + b) finite; then no intermediate operation
/// overflows either (Boldo, Graillat and Muller, 2017). Outside it (an overflowing sum, an infinite
/// or NaN operand) s or e is infinite or NaN, which every caller treats as "not exact" /
/// "undecided". The difference x - y is two_sum(x, -y): fl(x + (-y)) is fl(x - y) bit for bit.
inline void two_sum(double a, double b, double& s, double& e) {
  s = a + b;
  const double z = s - a;
  e = (a - (s - z)) + (b - z);
}

/// Veltkamp's splitting: a == hi + lo exactly, each with at most 26 significant bits, for finite
/// a with |a| <= 2^995 (then (2^27 + 1) a does not overflow).
inline void split(double a, double& hi, double& lo) {
  const double c = 134217729.0 * a;  // 2^27 + 1
  hi = c - (c - a);
  lo = a - hi;
}

/// Dekker's TwoProduct: p = fl(a b) and p + e == a b exactly, |e| <= u |p|, in either case
///  (i)  a and b normal (|a|, |b| >= 2^-1022) with |a|, |b| <= 2^995 and
///       2^-960 <= |p| <= 2^1021: no split overflows, no partial product overflows, and
///       e_a + e_b >= e_min + 53 - 1 = -970 (e_x the exponent of x), so none underflows;
///  (ii) a == 0 or b == 0, the other finite with magnitude <= 2^995: then p == e == 0 (up to
///       the sign of zero).
/// Outside the domain the result is some finite or non-finite pair without a guarantee; the
/// callers check it first (two_product_safe() for one factor and the product, the other factor
/// separately; CROP's discriminant keeps every factor 0 or within (2^-300, 2^302)).
inline void two_product(double a, double b, double& p, double& e) {
  p = a * b;
  double ah = 0.0, al = 0.0, bh = 0.0, bl = 0.0;
  split(a, ah, al);
  split(b, bh, bl);
  e = ((ah * bh - p) + ah * bl + al * bh) + al * bl;
}

/// The half of two_product()'s domain that concerns a and the product p = fl(a b): a == 0, or a
/// normal with |a| <= 2^995 and 2^-960 <= |p| <= 2^1021. The caller checks b (normal with
/// |b| <= 2^995) once.
inline bool two_product_safe(double a, double p) {
  const double aa = std::fabs(a), ap = std::fabs(p);
  return a == 0.0 || (aa >= 0x1p-1022 && aa <= 0x1p995 && ap >= 0x1p-960 && ap <= 0x1p1021);
}

/// Exact sign of (x1 + x0) + (y1 + y0), where (x0, x1) and (y0, y1) are non-overlapping
/// expansions in increasing magnitude (as two_product() and two_sum() make them: (e, p)), all
/// finite with magnitudes <= 2^1021 (then no partial sum overflows). Shewchuk's
/// EXPANSION-SUM gives a non-overlapping expansion of the exact sum, whose sign is that of its
/// largest non-zero component.
inline int expansion_sum_sign(double x0, double x1, double y0, double y1) {
  std::array<double, 4> h{x0, x1, 0.0, 0.0};
  double q = y0;
  two_sum(q, h[0], q, h[0]);
  two_sum(q, h[1], q, h[1]);
  h[2] = q;
  q = y1;
  two_sum(q, h[1], q, h[1]);
  two_sum(q, h[2], q, h[2]);
  h[3] = q;
  for (int i = 3; i >= 0; --i) {
    if (h[i] > 0.0) return 1;
    if (h[i] < 0.0) return -1;
  }
  return 0;
}

}  // namespace kinetic::numeric
