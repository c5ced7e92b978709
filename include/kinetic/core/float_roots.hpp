#pragma once
// Real roots of polynomials computed in plain floating point: no certification. This is what a
// traditional KDS does to compute certificate failure times, and it is kept here as the `classic`
// scheduler that the seed paper (000, Section 6) compares against -- including its weaknesses:
// close pairs of roots can be missed or invented, and a root at t_curr can land on either side.

#include <span>

#include "kinetic/core/polynomial.hpp"

namespace kinetic {

/// A root where a polynomial changes sign, computed in floating point.
struct FloatRoot {
  double at = 0.0;
  /// -1: the polynomial goes from positive to negative there (falling); +1: rising.
  int direction = 0;
};

/// Roots where p(s) = sum_i c[i] s^i changes sign, in [lo, hi], ascending, computed in double.
/// Closed forms for degree 1 and 2 (the numerically stable quadratic formula), monotone pieces
/// between the critical points and bisection above (to the last bit; with a tolerance > 0, a
/// safeguarded Newton iteration until the root's bracket is at most that wide: guesses that
/// are verified afterwards, as CROP's). Writes at most `degree` roots to `out` and returns how
/// many. Precondition: 0 <= degree <= kMaxMotionDegree, c[degree] != 0 unless degree == 0,
/// out.size() >= degree.
int float_sign_change_roots(std::span<const double> c, int degree, double lo, double hi,
                            std::span<FloatRoot> out, double tolerance = 0.0);

/// The difference upper - lower as a polynomial in (t - lower.origin), computed in double (a
/// rounded copy when the origins differ). Returns the degree; `out` gets kMaxMotionDegree + 1
/// coefficients.
int float_difference(const MotionPolynomial& upper, const MotionPolynomial& lower,
                     std::span<double> out);

/// The sign of phi(t) = sum_i phi[i] (t - origin)^i just after t as a traditional KDS reads it,
/// all in floating point: the sign of phi's Taylor coefficients at t (a Taylor shift in double)
/// taken in order, the value first, then the first non-zero derivative where the value is 0.
/// 0 only when every shifted coefficient is 0. Never an exact predicate: near a root the value's
/// rounding decides.
[[nodiscard]] int float_sign_after(std::span<const double> phi, int degree, Time origin, Time t);

/// The classic failure time of a certificate valid while phi > 0, phi(t) = sum_i phi[i] (t -
/// origin)^i given in floating point: the earliest root where phi falls from positive to negative
/// that is not in the past (>= t_curr; > t_curr when `strictly_after`), or +infinity.
/// Precondition: phi[degree] != 0 unless degree == 0.
[[nodiscard]] Time classic_failure_time(std::span<const double> phi, int degree, Time origin,
                                        Time t_curr, bool strictly_after = false);

/// The classic failure time of the certificate [lower < upper] at t_curr: the earliest root of
/// upper - lower (computed in floating point) where it falls from positive to negative and that is
/// not in the past (>= t_curr), or +infinity. A traditional KDS schedules exactly this.
[[nodiscard]] Time classic_failure_time(const MotionPolynomial& lower,
                                        const MotionPolynomial& upper, Time t_curr);

}  // namespace kinetic
