#pragma once
// Double-double numbers with a rigorous error bound: a value known to lie within `err` of
// hi + lo. The filter in front of the floating-point expansions for the in-circle and orientation
// polynomials of moving points (incircle.cpp): the same polynomial products as the expansions,
// at a fixed cost per operation instead of growing expansions, and enclosures about 2^-100 wide
// relative to the terms instead of the 2^-52 of interval arithmetic.
//
// Model: as eft.hpp (IEEE-754 binary64, round to nearest, no fused multiply-add). u = 2^-53.
// Invariant of every finite() value: hi = fl(hi + lo) (a TwoSum result, so |lo| <= u |hi|), and the
// exact value x it stands for satisfies |x - (hi + lo)| <= err.
//
// Sum a + b. (s, e) = TwoSum(a.hi, b.hi) is exact; l = fl(a.lo + b.lo) and t = fl(e + l) err by at
// most u |a.lo + b.lo| + u |e + l| <= 2u (1 + u)(|e| + |a.lo| + |b.lo|), which 2^-50 times the
// computed sum of the three magnitudes covers (that sum is rounded down by at most (1 - u)^2);
// (hi, lo) = TwoSum(s, t) is exact. The error: a.err + b.err plus that rounding.
//
// Product a b. With A = a.hi + a.lo, B = b.hi + b.lo: A B = p + pe + a.hi b.lo + a.lo b.hi +
// a.lo b.lo exactly, (p, pe) = TwoProduct(a.hi, b.hi) (exact inside eft.hpp's domain; see
// Overflow and underflow below). The three small products and three sums are rounded, at most
// 4u (1 + 3u) X in all with X = |pe| + |a.hi b.lo| + |a.lo b.hi| + |a.lo b.lo|, which 2^-50 X
// (computed, rounded down by at most (1 - u)^6) covers; (hi, lo) = TwoSum(p, t) is exact. The
// operands' own errors propagate as |A| b.err + |B| a.err + a.err b.err, |A| <= |a.hi| + |a.lo|.
//
// The error terms are sums and products of non-negative doubles, each rounded (down by at most a
// factor 1 - u): fewer than 16 roundings per operation, so multiplying the rounded bound by
// kGrow = 1 + 2^-40 makes it an upper bound again.
//
// Overflow and underflow, checked once per result instead of per operation (finite()): an
// operation that overflows (a sum, a product, Veltkamp's split of a factor beyond 2^995, a
// partial product of TwoProduct near 2^1023) makes an infinity or a NaN, which every later
// operation carries into its hi, lo or err (no comparison or min / max is taken of a value), so
// a result whose parts are all finite met no overflow. Underflow leaves TwoSum exact and makes a
// product (TwoProduct's partial products, a small term, an error term) err by at most 2^-1075
// absolutely, a handful per operation, which the 2^-1060 added to every bound covers.

#include <cmath>

#include "core/numeric/eft.hpp"
#include "core/numeric/interval.hpp"

namespace kinetic::numeric {

/// The double-double arithmetic both types below share (their bounds differ, not their values).
/// Sum: (hi, lo) = TwoSum(s, e + (a_lo + b_lo)) with (s, e) = TwoSum(a_hi, b_hi); returns e.
inline double double_double_sum(double a_hi, double a_lo, double b_hi, double b_lo, double& hi,
                                double& lo) {
  double s = 0.0, e = 0.0;
  two_sum(a_hi, b_hi, s, e);
  two_sum(s, e + (a_lo + b_lo), hi, lo);
  return e;
}
/// Product: (hi, lo) = TwoSum(p, pe + ((a_hi b_lo + a_lo b_hi) + a_lo b_lo)) with (p, pe) =
/// TwoProduct(a_hi, b_hi); returns |pe| + |a_hi b_lo| + |a_lo b_hi| + |a_lo b_lo| (rounded), the X
/// of the rounding bound.
inline double double_double_product(double a_hi, double a_lo, double b_hi, double b_lo,
                                    double& hi, double& lo) {
  double p = 0.0, pe = 0.0;
  two_product(a_hi, b_hi, p, pe);
  const double c1 = a_hi * b_lo, c2 = a_lo * b_hi, c3 = a_lo * b_lo;
  two_sum(p, pe + ((c1 + c2) + c3), hi, lo);
  return ((std::fabs(pe) + std::fabs(c1)) + std::fabs(c2)) + std::fabs(c3);
}

/// The operations both types below derive alike from their parts, hi, lo and the bound kBound
/// (an error or a magnitude), and their sum.
template <class DoubleDouble>
struct DoubleDoubleOperations {
  /// a + (-b): the value negated, its bound the same.
  friend DoubleDouble operator-(const DoubleDouble& a, DoubleDouble b) {
    b.hi = -b.hi;
    b.lo = -b.lo;
    return a + b;
  }
  /// 2 x, exactly: the value and its bound doubled (no rounding, so neither an error nor a depth
  /// grows; an overflow shows in BoundedDoubleDouble's finite()).
  [[nodiscard]] DoubleDouble twice() const {
    DoubleDouble r = static_cast<const DoubleDouble&>(*this);
    r.hi *= 2.0;
    r.lo *= 2.0;
    r.*DoubleDouble::kBound *= 2.0;
    return r;
  }
};

struct BoundedDoubleDouble : DoubleDoubleOperations<BoundedDoubleDouble> {
  double hi = 0.0, lo = 0.0;
  double err = 0.0;  ///< |x - (hi + lo)| <= err
  static constexpr double BoundedDoubleDouble::*kBound = &BoundedDoubleDouble::err;

  static constexpr double kGrow = 1.0 + 0x1p-40;
  static constexpr double kTiny = 0x1p-1060;

  /// The double x, exactly (finite() unless x is not).
  static BoundedDoubleDouble exact(double x) {
    BoundedDoubleDouble r;
    r.hi = x;
    return r;
  }

  /// True when no operation overflowed on the way to this value: then the bound holds.
  [[nodiscard]] bool finite() const {
    return std::isfinite(hi) && std::isfinite(lo) && std::isfinite(err);
  }

  /// Every real the value may be: [hi - (|lo| + err), hi + (|lo| + err)], rounded outwards.
  [[nodiscard]] Interval enclosure() const {
    const double r = up(std::fabs(lo) + err);
    return Interval{down(hi - r), up(hi + r)};
  }
  /// True when the value is exactly 0 (a coefficient no operation touched).
  [[nodiscard]] bool is_zero() const { return hi == 0.0 && lo == 0.0 && err == 0.0; }

  friend BoundedDoubleDouble operator+(const BoundedDoubleDouble& a,
                                       const BoundedDoubleDouble& b) {
    BoundedDoubleDouble r;
    const double e = double_double_sum(a.hi, a.lo, b.hi, b.lo, r.hi, r.lo);
    const double rounding = 0x1p-50 * (std::fabs(e) + std::fabs(a.lo) + std::fabs(b.lo));
    r.err = ((a.err + b.err) + rounding) * kGrow + kTiny;
    return r;
  }
  friend BoundedDoubleDouble operator*(const BoundedDoubleDouble& a,
                                       const BoundedDoubleDouble& b) {
    BoundedDoubleDouble r;
    const double x = double_double_product(a.hi, a.lo, b.hi, b.lo, r.hi, r.lo);
    const double ma = std::fabs(a.hi) + std::fabs(a.lo), mb = std::fabs(b.hi) + std::fabs(b.lo);
    const double rounding = 0x1p-50 * x;
    r.err = (((ma * b.err + mb * a.err) + a.err * b.err) + rounding) * kGrow + kTiny;
    return r;
  }
};

/// A double-double that carries, instead of an error, a bound m on its magnitude expression M
/// (the same expression over the inputs' absolute values, every + and - a +): half the work of a
/// BoundedDoubleDouble per operation, for expressions whose depth is known in advance.
///
/// Bound. Define the depth d of a value: 0 for an input, max(d_a, d_b) + 1 for a + b or a - b,
/// d_a + d_b + 1 for a b. Then |x - (hi + lo)| <= ((1 + 2^-100)^d - 1) M + eta, where eta covers
/// underflow. Induction: the rounding of one operation is at most 2^-100 times its M. A sum
/// rounds by at most 2^-50 (|e| + |a.lo| + |b.lo|) (as above) with |e| <= u (|a.hi| + |b.hi|),
/// |lo| <= u |hi| and |hi| <= (1 + u)(1 + theta) M for the operands, so by at most
/// 2^-101.9 (M_a + M_b); a product by at most 2^-50 X with X <= 3.001 u |a.hi| |b.hi|, so by at
/// most 2^-101.4 M_a M_b. The operands' errors propagate as for BoundedDoubleDouble, which keeps
/// the form ((1 + 2^-100)^d - 1) M (the standard argument for a relative error per operation).
/// Underflow makes an operation err by at most 4 2^-1075 more, absolutely, and each such error is
/// multiplied later by at most the magnitudes of the factors it meets: the caller bounds them.
/// The magnitude m is itself rounded down by at most (1 - u) per operation: m (1 + 2^-40) bounds
/// M for depths below 2^10. No overflow check: the caller bounds the inputs so that none can
/// occur.
struct MagnitudeDoubleDouble : DoubleDoubleOperations<MagnitudeDoubleDouble> {
  double hi = 0.0, lo = 0.0;
  double m = 0.0;  ///< the magnitude expression, rounded
  static constexpr double MagnitudeDoubleDouble::*kBound = &MagnitudeDoubleDouble::m;

  static MagnitudeDoubleDouble exact(double x) {
    MagnitudeDoubleDouble r;
    r.hi = x;
    r.m = std::fabs(x);
    return r;
  }

  friend MagnitudeDoubleDouble operator+(const MagnitudeDoubleDouble& a,
                                         const MagnitudeDoubleDouble& b) {
    MagnitudeDoubleDouble r;
    double_double_sum(a.hi, a.lo, b.hi, b.lo, r.hi, r.lo);
    r.m = a.m + b.m;
    return r;
  }
  friend MagnitudeDoubleDouble operator*(const MagnitudeDoubleDouble& a,
                                         const MagnitudeDoubleDouble& b) {
    MagnitudeDoubleDouble r;
    double_double_product(a.hi, a.lo, b.hi, b.lo, r.hi, r.lo);  // (its X unused)
    r.m = a.m * b.m;
    return r;
  }

  /// The bound above for a value of depth at most `depth` (<= 1000), with `underflow` the
  /// caller's eta: as a BoundedDoubleDouble.
  [[nodiscard]] BoundedDoubleDouble bounded(int depth, double underflow) const {
    // (1 + 2^-100)^d - 1 <= d 2^-100 (1 + d 2^-100) <= (d + 1) 2^-100 for d <= 1000.
    BoundedDoubleDouble r;
    r.hi = hi;
    r.lo = lo;
    r.err = (static_cast<double>(depth + 1) * 0x1p-100) * m * (1.0 + 0x1p-40) + underflow;
    return r;
  }
};

}  // namespace kinetic::numeric
