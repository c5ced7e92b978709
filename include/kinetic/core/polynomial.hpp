#pragma once
// Polynomial motions: one polynomial per coordinate, coefficients in ascending powers of
// (t - origin). The numbers of a scenario are the exact truth: a coefficient or an origin is a
// double, i.e. a dyadic rational, and every sign decision made on these polynomials is exact
// (see predicates.hpp). Plain floating-point evaluation below is for display, errors and the
// classic scheduler only.

#include <array>
#include <cstdint>
#include <initializer_list>
#include <span>

#include "kinetic/core/time.hpp"

namespace kinetic {

/// Highest polynomial degree a motion may have. Certificates of sorting compare two motions, so
/// their polynomials have this degree too. Scenarios with higher degrees are refused on input.
inline constexpr int kMaxMotionDegree = 6;

/// x(t) = sum_{i=0}^{degree} c[i] * (t - origin)^i, exactly (no rounding anywhere).
struct MotionPolynomial {
  Time origin = 0.0;
  /// Index of the highest non-zero coefficient; 0 for constants, including the zero polynomial.
  int degree = 0;
  std::array<double, kMaxMotionDegree + 1> c{};

  /// Builds from ascending coefficients (trailing zeros trimmed). Throws PreconditionError
  /// unless 1 <= coefficients.size() <= kMaxMotionDegree + 1 once trailing zeros are trimmed and
  /// every coefficient and the origin are finite.
  static MotionPolynomial from(std::span<const double> coefficients, Time origin = 0.0);
  /// The same from a list: `MotionPolynomial::from({x0, v, a / 2})` is x0 + v t + (a/2) t^2.
  static MotionPolynomial from(std::initializer_list<double> coefficients, Time origin = 0.0) {
    return from(std::span<const double>(coefficients.begin(), coefficients.size()), origin);
  }

  /// Constant polynomial.
  static MotionPolynomial constant(double value);

  /// Rounded floating-point value at t (Horner in (t - origin)); not for decisions.
  [[nodiscard]] double evaluate(Time t) const;

  /// Rounded floating-point derivative at t; not for decisions.
  [[nodiscard]] double derivative(Time t) const;

  /// True when the motion is the zero polynomial.
  [[nodiscard]] bool is_zero() const { return degree == 0 && c[0] == 0.0; }

  friend bool operator==(const MotionPolynomial&, const MotionPolynomial&) = default;
};

/// a(t) - b(t) as one motion polynomial, for certificates that compare differences of motions
/// (e.g. side lengths x_j - x_i against y_l - y_k). `exact` tells whether `p` is that difference
/// exactly, i.e. the same function of t with double coefficients: so when the origins agree (or
/// one motion is constant) and every coefficient subtraction is exact (checked by TwoSum). Then
/// comparing two such polynomials (predicates, CROP) decides on the exact differences. Otherwise
/// `p` is the difference with each coefficient rounded to nearest, after a floating-point Taylor
/// shift of b to a's origin when the origins differ: its coefficients are within a few units in
/// the last place of the exact ones, and callers count such cases.
/// When the rounded coefficients overflow (beyond the doubles), `overflow` is set, `exact` is
/// false and `p` holds them saturated at the largest double (a NaN of inf - inf as 0): a finite
/// stand-in that callers must not decide on.
struct MotionDifference {
  MotionPolynomial p;
  bool exact = false;
  bool overflow = false;
};
[[nodiscard]] MotionDifference motion_difference(const MotionPolynomial& a,
                                                 const MotionPolynomial& b);

/// A floating-point value with a rigorous bound on its distance to the exact value.
/// `certain()` is false when the bound cannot separate the value from zero (or overflowed).
struct FilteredValue {
  double value = 0.0;
  double error = 0.0;                         ///< |value - exact| <= error, when finite
  [[nodiscard]] int sign_if_certain() const;  ///< -1 / +1 when certain, 0 when undecided
};

/// Horner evaluation at t with a rigorous a-priori error bound that accounts for the rounding of
/// (t - origin), every multiplication and addition, and underflow.
[[nodiscard]] FilteredValue evaluate_filtered(const MotionPolynomial& p, Time t);

/// a(t) - b(t) for motions with the same origin, evaluated as one polynomial (coefficients
/// subtracted first, then Horner), with a rigorous error bound. Much tighter than the difference
/// of two evaluate_filtered() values when a and b are far from 0 but close to each other, as two
/// neighbours in a sorted order are. Precondition: a.origin == b.origin.
[[nodiscard]] FilteredValue evaluate_difference_filtered(const MotionPolynomial& a,
                                                         const MotionPolynomial& b, Time t);

/// A value known to within a rigorous bound as an unevaluated sum: the exact value lies in
/// [hi + lo - error, hi + lo + error] (hi + lo taken exactly). Produced by the compensated
/// evaluations below, the second filter stage of the predicates.
struct CompensatedValue {
  double hi = 0.0;
  double lo = 0.0;
  double error = 0.0;  ///< |hi + lo - exact| <= error, when finite
  /// -1 / +1 when certain, 0 when undecided (including overflow, NaN and the cases the
  /// error-free transformations cannot cover, which set error to +infinity).
  [[nodiscard]] int sign_if_certain() const;
};

/// p(t) by compensated Horner (error-free TwoSum / TwoProduct, Graillat-Langlois-Louvet) at
/// t - origin taken exactly as the double-double s + e, with a rigorous a-priori error bound of
/// order u^2 * sum |c_i| |s|^i (u = 2^-53) instead of the u * sum |c_i| |s|^i of
/// evaluate_filtered(). See polynomial.cpp for the analysis.
[[nodiscard]] CompensatedValue evaluate_compensated(const MotionPolynomial& p, Time t);

/// a(t) - b(t) by compensated Horner, for any origins: with equal origins the coefficients are
/// subtracted exactly (TwoSum) and the difference is evaluated as one polynomial; with different
/// origins each motion is evaluated on its own and the two results are subtracted exactly.
[[nodiscard]] CompensatedValue evaluate_difference_compensated(const MotionPolynomial& a,
                                                               const MotionPolynomial& b, Time t);

/// The Taylor coefficients of p at t (p(t + h) = sum_k out[k] h^k, out[k] = 0 beyond p.degree),
/// each by compensated Horner on the coefficients C(i, k) c_i (split exactly by TwoProduct),
/// with a rigorous bound; an entry whose bound cannot be established has error = +infinity.
void taylor_compensated(const MotionPolynomial& p, Time t,
                        std::array<CompensatedValue, kMaxMotionDegree + 1>& out);

/// The scaled Bernstein coefficients gamma_i = sum_{k <= i} C(n - k, i - k) d_k w^k of
/// f = a - b on [lo, hi] (d_k the Taylor coefficients of f at lo, w = hi - lo, n = degree),
/// from taylor_compensated() in double-double arithmetic with a running rigorous error bound.
/// Returns false when no bound can be given (hi - lo not exact, a TwoProduct that could
/// underflow); an entry may still have a non-finite part (overflow). Entries beyond n are 0.
/// Preconditions: degree <= kMaxMotionDegree, lo < hi.
[[nodiscard]] bool bernstein_compensated(const MotionPolynomial& a, const MotionPolynomial& b,
                                         int degree, Time lo, Time hi,
                                         std::array<CompensatedValue, kMaxMotionDegree + 1>& gamma);

}  // namespace kinetic
