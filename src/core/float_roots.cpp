#include "kinetic/core/float_roots.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <limits>

namespace kinetic {
namespace {

double horner(std::span<const double> c, int degree, double s) {
  double v = c[degree];
  for (int i = degree - 1; i >= 0; --i) v = v * s + c[i];
  return v;
}

int sign_of(double v) { return (v > 0.0) - (v < 0.0); }

/// Bisection on [u, v] where p(u) and p(v) have opposite non-zero signs: to the last bit when
/// tol == 0; otherwise a safeguarded Newton iteration (bisection where a step leaves the
/// bracket) until the bracket is at most tol wide or a step changes nothing.
double bisect(std::span<const double> c, int degree, double u, double v, int su, double tol) {
  if (tol > 0.0) {
    double x = u + (v - u) * 0.5;
    for (int it = 0; it < 200 && v - u > tol; ++it) {
      double p = c[degree], dp = 0.0;
      for (int i = degree - 1; i >= 0; --i) {
        dp = dp * x + p;
        p = p * x + c[i];
      }
      const int sx = sign_of(p);
      if (sx == 0) return x;
      if (sx == su) {
        u = x;
      } else {
        v = x;
      }
      double next = dp != 0.0 ? x - p / dp : u + (v - u) * 0.5;
      if (!(next > u && next < v)) next = u + (v - u) * 0.5;
      if (next == x) break;
      x = next;
    }
    return x;
  }
  for (int it = 0; it < 2200; ++it) {
    const double mid = u + (v - u) * 0.5;
    if (mid <= u || mid >= v) break;
    const int sm = sign_of(horner(c, degree, mid));
    if (sm == 0) return mid;
    if (sm == su) {
      u = mid;
    } else {
      v = mid;
    }
  }
  return u + (v - u) * 0.5;
}

/// All sign-change roots in [lo, hi] for degree >= 1, ascending.
int roots_rec(std::span<const double> c, int degree, double lo, double hi, FloatRoot* out,
              double tol) {
  if (degree == 1) {
    const double r = -c[0] / c[1];
    if (r >= lo && r <= hi) {
      out[0] = FloatRoot{r, c[1] > 0.0 ? 1 : -1};
      return 1;
    }
    return 0;
  }
  if (degree == 2) {
    const double a = c[2], b = c[1], cc = c[0];
    const double disc = b * b - 4.0 * a * cc;
    if (!(disc > 0.0)) return 0;  // a double root does not change sign; complex roots none
    const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
    double r1 = q / a;
    double r2 = q != 0.0 ? cc / q : -r1;
    if (r1 > r2) std::swap(r1, r2);
    // With a > 0 the parabola falls through r1 and rises through r2; the other way for a < 0.
    const int first = a > 0.0 ? -1 : 1;
    int k = 0;
    if (r1 >= lo && r1 <= hi) out[k++] = FloatRoot{r1, first};
    if (r2 >= lo && r2 <= hi && r2 != r1) out[k++] = FloatRoot{r2, -first};
    return k;
  }
  // Split [lo, hi] at the critical points (sign changes of p'), then bisect monotone pieces.
  std::array<double, kMaxMotionDegree> deriv{};
  for (int i = 1; i <= degree; ++i) deriv[i - 1] = i * c[i];
  std::array<FloatRoot, kMaxMotionDegree> critical{};
  const int m = roots_rec(std::span<const double>(deriv.data(), degree), degree - 1, lo, hi,
                          critical.data(), tol);
  std::array<double, kMaxMotionDegree + 1> cuts{};
  cuts[0] = lo;
  for (int i = 0; i < m; ++i) cuts[i + 1] = critical[i].at;
  cuts[m + 1] = hi;
  const int last = m + 1;
  std::array<int, kMaxMotionDegree + 2> sign{};
  for (int i = 0; i <= last; ++i) sign[i] = sign_of(horner(c, degree, cuts[i]));
  // Sign changes strictly inside a monotone piece are bisected; a zero exactly at a cut is a sign
  // change only when the signs on its two sides differ (a double root at a critical point is a
  // touch, not a crossing). At the window's ends only one side is known: a zero there counts,
  // with the direction of the known side.
  int k = 0;
  auto emit = [&](double r, int direction) {
    if (k < degree && (k == 0 || r > out[k - 1].at)) out[k++] = FloatRoot{r, direction};
  };
  for (int i = 0; i <= last; ++i) {
    if (sign[i] == 0) {
      if (i == 0) {
        if (last > 0 && sign[1] != 0) emit(cuts[0], sign[1]);
      } else if (i == last) {
        if (sign[i - 1] != 0) emit(cuts[i], -sign[i - 1]);
      } else if (sign[i - 1] != 0 && sign[i + 1] != 0 && sign[i - 1] != sign[i + 1]) {
        emit(cuts[i], sign[i + 1]);
      }
    }
    if (i < last && sign[i] != 0 && sign[i + 1] != 0 && sign[i] != sign[i + 1]) {
      emit(bisect(c, degree, cuts[i], cuts[i + 1], sign[i], tol), sign[i + 1]);
    }
  }
  return k;
}

}  // namespace

int float_sign_change_roots(std::span<const double> c, int degree, double lo, double hi,
                            std::span<FloatRoot> out, double tolerance) {
  assert(degree >= 0 && degree <= kMaxMotionDegree);
  assert(out.size() >= static_cast<std::size_t>(degree));
  if (degree == 0 || !(lo <= hi)) return 0;
  if (degree >= 3) {
    // Cauchy's bound: every real root lies in [-B, B].
    double big = 0.0;
    for (int i = 0; i < degree; ++i) big = std::max(big, std::fabs(c[i] / c[degree]));
    const double bound = 1.0 + big;
    lo = std::max(lo, -bound);
    hi = std::min(hi, bound);
    if (!(lo <= hi)) return 0;
  }
  return roots_rec(c, degree, lo, hi, out.data(), tolerance);
}

int float_difference(const MotionPolynomial& upper, const MotionPolynomial& lower,
                     std::span<double> out) {
  assert(out.size() >= static_cast<std::size_t>(kMaxMotionDegree) + 1);
  std::array<double, kMaxMotionDegree + 1> shifted = upper.c;
  const int du = upper.degree;
  if (upper.origin != lower.origin) {
    // Taylor shift of upper to lower.origin, in floating point (rounded).
    const double s = lower.origin - upper.origin;
    for (int k = 0; k < du; ++k) {
      for (int i = du - 1; i >= k; --i) shifted[i] += s * shifted[i + 1];
    }
  }
  int degree = 0;
  for (int i = 0; i <= kMaxMotionDegree; ++i) {
    out[i] = shifted[i] - lower.c[i];
    if (out[i] != 0.0) degree = i;
  }
  return degree;
}

int float_sign_after(std::span<const double> phi, int degree, Time origin, Time t) {
  assert(degree >= 0 && degree <= kMaxMotionDegree);
  std::array<double, kMaxMotionDegree + 1> c{};
  std::copy_n(phi.begin(), degree + 1, c.begin());
  const double s = t - origin;
  if (s != 0.0) {
    for (int k = 0; k < degree; ++k) {  // Taylor shift to t, in floating point (rounded)
      for (int i = degree - 1; i >= k; --i) c[i] += s * c[i + 1];
    }
  }
  for (int k = 0; k <= degree; ++k) {
    if (c[k] != 0.0) return sign_of(c[k]);
  }
  return 0;
}

Time classic_failure_time(std::span<const double> phi, int degree, Time origin, Time t_curr,
                          bool strictly_after) {
  if (degree == 0) return kTimeInfinity;
  std::array<FloatRoot, kMaxMotionDegree> roots{};
  // Search a little before t_curr so that a root at t_curr is an interior point of the window
  // (its direction is then known from both sides); roots in the past are dropped below.
  const double s_lo = (t_curr - origin) - 1e-9 * (1.0 + std::fabs(t_curr - origin));
  const int m =
      float_sign_change_roots(phi, degree, s_lo, std::numeric_limits<double>::max(), roots);
  for (int i = 0; i < m; ++i) {
    if (roots[i].direction > 0) continue;  // phi rises through zero: not a failure
    const Time t = origin + roots[i].at;
    // "Not in the past": equal to t_curr counts, as in the classic KDS (unless strictly_after).
    if (strictly_after ? t > t_curr : t >= t_curr) return t;
  }
  return kTimeInfinity;
}

Time classic_failure_time(const MotionPolynomial& lower, const MotionPolynomial& upper,
                          Time t_curr) {
  if (lower.degree <= 1 && upper.degree <= 1 && lower.origin == upper.origin) {
    // Two lines with one origin (the common case): the same arithmetic as below, unrolled.
    const double c0 = upper.c[0] - lower.c[0], c1 = upper.c[1] - lower.c[1];
    if (!(c1 < 0.0)) return kTimeInfinity;  // rising or constant: no failure
    const double s_lo = (t_curr - lower.origin) - 1e-9 * (1.0 + std::fabs(t_curr - lower.origin));
    const double r = -c0 / c1;
    if (!(r >= s_lo && r <= std::numeric_limits<double>::max())) return kTimeInfinity;
    const Time t = lower.origin + r;
    return t >= t_curr ? t : kTimeInfinity;
  }
  std::array<double, kMaxMotionDegree + 1> phi{};
  const int degree = float_difference(upper, lower, phi);
  return classic_failure_time(phi, degree, lower.origin, t_curr);
}

}  // namespace kinetic
