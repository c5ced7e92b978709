#pragma once
// Interval arithmetic with outward rounding, on top of round-to-nearest doubles (no change of
// the rounding mode): each operation is done in round to nearest and its result widened.
//
// Bound. For a real r and x = fl(r) (round to nearest, x finite):
//   down(x) <= r <= up(x).
// A normal x is within ulp(x) / 2 <= 2^-53 |x| of r, and fl(x - |x| 2^-52) <= x - ulp(x) (the
// double x - ulp(x) lies between the exact x - |x| 2^-52 and x; rounding is monotone), so
// down(x) <= x - ulp(x) / 2 <= r (symmetrically for up). A subnormal or underflowed x is within
// 2^-1075 of r; the 2^-1070 term covers it. Hence every operation below encloses the exact
// operation on every pair of reals taken from its operands: if alpha in a, beta in b, then
// alpha + beta in a + b, alpha - beta in a - b, alpha * beta in a * b, alpha * k in scale(a, k).
//
// Domain: the operands' ends finite (their results may overflow). A result end that overflows
// is -infinity (lower) or +infinity (upper), still a bound, or NaN (down(+infinity),
// up(-infinity)), which compares false, so sign() is never wrong there, only undecided.
// + and - keep this with infinite operand ends too. operator* does not: with a zero end and an
// infinite end, 0 * infinity is NaN, which std::min / std::max may skip, dropping the corner
// that holds 0 ([-2, 0] * [-infinity, -1] gives [2, +infinity]). CROP's products stay clear of
// that: the multipliers of its Taylor shifts and Bernstein powers (a - origin, b - a) have
// non-zero ends of one sign, two points give four equal corners (all NaN or none), and its
// discriminant filter would need one coefficient's enclosure to end exactly at 0 (a widened end
// of +-2^-1070) while another's overflows.
//
// Users: CROP (crop.cpp): the Bernstein enclosures of its subdivision, the Taylor coefficients
// of a MotionCombination, the slope of a linear certificate and the discriminant filter; the
// filter of a ProductCombination's sign at t (the products of its four factors' enclosures: an
// end is exactly 0 only when a factor's enclosure ends at 0, which down() / up() never return
// for a finite non-zero value, and a non-finite factor end leaves the sign undecided); the
// linear filter's cuts (linear_filter.hpp: below_cut() / above_cut() widen fl(b -/+ error)
// outward by down() / up(), infinite values kept as they are).

#include <algorithm>
#include <cmath>

#include "core/numeric/eft.hpp"

namespace kinetic::numeric {

/// A lower bound of every real r with fl(r) == x (see above).
inline double down(double x) { return (x - std::fabs(x) * 0x1p-52) - 0x1p-1070; }
/// An upper bound of every real r with fl(r) == x (see above).
inline double up(double x) { return (x + std::fabs(x) * 0x1p-52) + 0x1p-1070; }

/// The closed interval [lo, hi] of the reals; a point when lo == hi.
struct Interval {
  double lo = 0.0, hi = 0.0;
  static Interval point(double v) { return Interval{v, v}; }
  /// The certain sign of every member, or 0 when the interval may contain 0 (or has a NaN end).
  [[nodiscard]] int sign() const {
    if (lo > 0.0) return 1;
    if (hi < 0.0) return -1;
    return 0;
  }
};

/// Every real within `error` of `value` (a filtered evaluation's value and rigorous bound).
inline Interval around(double value, double error) {
  return Interval{down(value - error), up(value + error)};
}

inline Interval operator+(Interval a, Interval b) {
  return Interval{down(a.lo + b.lo), up(a.hi + b.hi)};
}
inline Interval operator-(Interval a, Interval b) {
  return Interval{down(a.lo - b.hi), up(a.hi - b.lo)};
}
inline Interval operator*(Interval a, Interval b) {
  const double p1 = a.lo * b.lo, p2 = a.lo * b.hi, p3 = a.hi * b.lo, p4 = a.hi * b.hi;
  return Interval{down(std::min(std::min(p1, p2), std::min(p3, p4))),
                  up(std::max(std::max(p1, p2), std::max(p3, p4)))};
}
/// a * x for the double x (a point): two products where operator* takes four.
inline Interval times_point(Interval a, double x) {
  const double p = a.lo * x, q = a.hi * x;
  return x >= 0.0 ? Interval{down(p), up(q)} : Interval{down(q), up(p)};
}
/// a * k for k >= 0, an exact small integer.
inline Interval scale(Interval a, double k) { return Interval{down(a.lo * k), up(a.hi * k)}; }

/// x - y as an interval: the point fl(x - y) when the subtraction is exact (TwoSum's error is
/// 0), otherwise fl(x - y) widened.
inline Interval exact_difference(double x, double y) {
  double d = 0.0, err = 0.0;
  two_sum(x, -y, d, err);
  if (err == 0.0) return Interval::point(d);
  return Interval{down(d), up(d)};
}

}  // namespace kinetic::numeric
