#include "kinetic/core/polynomial.hpp"

#include <algorithm>
#include <cassert>
#include <cfloat>
#include <cmath>

namespace kinetic {

MotionPolynomial MotionPolynomial::from(std::span<const double> coefficients, Time origin) {
  MotionPolynomial p;
  p.origin = origin;
  std::size_t n = coefficients.size();
  while (n > 1 && coefficients[n - 1] == 0.0) --n;
  assert(n >= 1 && n <= static_cast<std::size_t>(kMaxMotionDegree) + 1);
  for (std::size_t i = 0; i < n; ++i) p.c[i] = coefficients[i];
  p.degree = static_cast<int>(n) - 1;
  if (p.degree < 0) p.degree = 0;
  return p;
}

MotionPolynomial MotionPolynomial::constant(double value) {
  MotionPolynomial p;
  p.c[0] = value;
  return p;
}

double MotionPolynomial::evaluate(Time t) const {
  const double u = t - origin;
  double v = c[degree];
  for (int i = degree - 1; i >= 0; --i) v = v * u + c[i];
  return v;
}

double MotionPolynomial::derivative(Time t) const {
  if (degree == 0) return 0.0;
  const double u = t - origin;
  double v = degree * c[degree];
  for (int i = degree - 1; i >= 1; --i) v = v * u + i * c[i];
  return v;
}

int FilteredValue::sign_if_certain() const {
  if (!std::isfinite(value) || !std::isfinite(error)) return 0;
  if (value > error) return 1;
  if (value < -error) return -1;
  return 0;
}

namespace {

/// Horner on c[0..degree] at s = t - origin with a rigorous error bound.
/// Error analysis (unit roundoff u = 2^-53, n = degree):
///  - fl(t - origin) = (t - origin)(1 + d), |d| <= u, so each power |s^i - s_true^i| <=
///    gamma_i |s|^i;
///  - Horner on the rounded s contributes at most gamma_{2n} * sum |c_i| |s|^i;
///  - the absolute-value sum itself is computed in floating point (relative error gamma_{2n}).
/// (4n + 4) u * fl(sum |c_i||s|^i) dominates all three terms with room to spare; `extra_units`
/// more units cover errors already in the coefficients (relative, at most u each). Underflow
/// adds at most one smallest-normal per operation, and an error made at step j is multiplied by
/// |s| in each of the (at most n) later steps.
FilteredValue filtered_horner(const std::array<double, kMaxMotionDegree + 1>& c, int degree,
                              double s, double extra_units) {
  const double as = std::fabs(s);
  double v = c[degree];
  double m = std::fabs(c[degree]);
  for (int i = degree - 1; i >= 0; --i) {
    v = v * s + c[i];
    m = m * as + std::fabs(c[i]);
  }
  const double unit = std::ldexp(1.0, -53);
  const double n = static_cast<double>(degree);
  double growth = 1.0 + 1e-10;  // max(1, |s|)^n, by multiplication (deterministic everywhere)
  for (int i = 0; i < degree; ++i) growth *= std::max(1.0, as);
  FilteredValue out;
  out.value = v;
  out.error = (4.0 * n + 4.0 + extra_units) * unit * m * (1.0 + 1e-10) +
              (2.0 * n + 2.0 + extra_units) * DBL_MIN * growth;
  return out;
}

}  // namespace

FilteredValue evaluate_filtered(const MotionPolynomial& p, Time t) {
  return filtered_horner(p.c, p.degree, t - p.origin, 0.0);
}

FilteredValue evaluate_difference_filtered(const MotionPolynomial& a, const MotionPolynomial& b,
                                           Time t) {
  assert(a.origin == b.origin);
  // The polynomial with coefficients fl(a_i - b_i): each subtraction adds a relative error of
  // at most u to its coefficient (it is exact when the result is subnormal), i.e. at most
  // u * sum |d_i||s|^i more; two extra units cover it.
  const int degree = std::max(a.degree, b.degree);
  std::array<double, kMaxMotionDegree + 1> d{};
  for (int i = 0; i <= degree; ++i) d[i] = a.c[i] - b.c[i];
  return filtered_horner(d, degree, t - a.origin, 2.0);
}

}  // namespace kinetic
