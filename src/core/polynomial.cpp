#include "kinetic/core/polynomial.hpp"

#include "core/compensated_horner.hpp"

#include <algorithm>
#include <cassert>
#include <cfloat>
#include <cmath>
#include <limits>

#include "core/numeric/eft.hpp"
#include "core/numeric/taylor_shift.hpp"
#include "kinetic/core/preconditions.hpp"

namespace kinetic {

using numeric::two_product;
using numeric::two_product_safe;
using numeric::two_sum;

MotionPolynomial MotionPolynomial::from(std::span<const double> coefficients, Time origin) {
  MotionPolynomial p;
  p.origin = origin;
  std::size_t n = coefficients.size();
  while (n > 1 && coefficients[n - 1] == 0.0) --n;
  if (n == 0) precondition_failed("MotionPolynomial::from", "no coefficients");
  if (n > static_cast<std::size_t>(kMaxMotionDegree) + 1) {
    precondition_failed("MotionPolynomial::from",
                        std::to_string(n) + " coefficients make degree " + std::to_string(n - 1) +
                            " (the degree is at most " + std::to_string(kMaxMotionDegree) + ")");
  }
  if (!std::isfinite(origin)) precondition_failed("MotionPolynomial::from", "origin not finite");
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(coefficients[i])) {
      precondition_failed("MotionPolynomial::from",
                          "coefficient c" + std::to_string(i) + " is not finite");
    }
    p.c[i] = coefficients[i];
  }
  p.degree = static_cast<int>(n) - 1;
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

MotionDifference motion_difference(const MotionPolynomial& a, const MotionPolynomial& b) {
  MotionDifference out;
  std::array<double, kMaxMotionDegree + 1> c{};
  bool exact = true;
  // a - b, coefficient by coefficient, with TwoSum's error term telling exactness.
  auto subtract = [&exact](double x, double y) {
    double s = 0.0, err = 0.0;
    two_sum(x, -y, s, err);
    if (err != 0.0 || !std::isfinite(s)) exact = false;
    return s;
  };
  Time origin = a.origin;
  // Coefficients above both degrees are zero in both (0 - 0: zero, exact).
  const int top = std::max(a.degree, b.degree);
  if (a.origin == b.origin || b.degree == 0 || a.degree == 0) {
    if (a.degree == 0 && b.degree != 0) origin = b.origin;
    for (int i = 0; i <= top; ++i)
      c[static_cast<std::size_t>(i)] =
          subtract(a.c[static_cast<std::size_t>(i)], b.c[static_cast<std::size_t>(i)]);
  } else {
    // b(t) = sum_i b_i (s + h)^i with s = t - a.origin, h = a.origin - b.origin: Taylor shift by
    // repeated synthetic division, in floating point (not exact in general).
    exact = false;
    std::array<double, kMaxMotionDegree + 1> q = b.c;
    numeric::taylor_shift(q, b.degree, a.origin - b.origin);
    for (int i = 0; i <= top; ++i)
      c[static_cast<std::size_t>(i)] =
          subtract(a.c[static_cast<std::size_t>(i)], q[static_cast<std::size_t>(i)]);
  }
  // Beyond the doubles (coefficients of extreme magnitude, or a Taylor shift across extreme
  // origins): the rounded difference is not a motion. It is flagged (`overflow`, never exact)
  // and kept finite, so that no caller meets an infinity; callers decide on the exact motions.
  for (double& x : c) {
    if (std::isfinite(x)) continue;
    out.overflow = true;
    exact = false;
    x = std::isnan(x) ? 0.0 : std::copysign(std::numeric_limits<double>::max(), x);
  }
  out.p = MotionPolynomial::from(c, origin);
  out.exact = exact;
  return out;
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

namespace {

// ---------------------------------------------------------------------------------------------
// The second filter stage: compensated Horner. u = 2^-53 is the unit roundoff. Nothing below
// relies on fused multiply-adds: the project builds with -ffp-contract=off, so every operation
// is one IEEE-754 round-to-nearest operation, and TwoProduct is Dekker's (no std::fma). TwoSum,
// TwoProduct and the domain where they are exact: core/numeric/eft.hpp.

constexpr double kUnit = 0x1p-53;

CompensatedValue undecided() {
  CompensatedValue out;
  out.error = std::numeric_limits<double>::infinity();
  return out;
}

}  // namespace

/// Compensated Horner for P(x) = sum_{i <= n} (c_i + cl_i) x^i at the exact point x = s + e
/// (s, e doubles, |e| <= u |s|), where cl (may be null: all zero) holds small corrections with
/// |cl_i| <= u |c_i|, as TwoSum leaves them. Returns hi + lo and a rigorous bound on its error.
///
/// Algorithm. Horner with error-free transformations at s (Graillat, Langlois, Louvet,
/// "Compensated Horner scheme", 2005): r_n = c_n, and for i = n-1 .. 0
///   (p_i, pi_i) = TwoProduct(r_{i+1}, s),  (r_i, sigma_i) = TwoSum(p_i, c_i),
/// which gives exactly  p_c(s) = r_0 + Q(s),  Q(x) = sum_{i<n} (pi_i + sigma_i) x^i.
/// Then  P(s + e) = r_0 + Q(s) + e p_c'(s) + R2 + p_cl(s + e),  with
/// R2 = sum_i c_i sum_{k>=2} C(i, k) e^k s^(i-k). The result is hi = r_0 and
/// lo = fl(fl(fl(Q) + fl(e * d)) + fl(p_cl(s))), Q, d = p_c'(s) (Horner on (i+1) c_{i+1}) and
/// p_cl(s) in plain Horner.
///
/// Error bound. Let m~ = sum |c_i| |s|^i, gamma_k = k u / (1 - k u), and n <= 8 (so that
/// (1 + gamma_2n)^n and the other factors dropped "to first order" stay below 1 + 2^-40).
///  - |p_i|, |r_i| <= (1 + gamma_2n) sum_{j>=i} |c_j| |s|^(j-i), and |pi_i| <= u |p_i|,
///    |sigma_i| <= u |r_i|, so sum (|pi_i| + |sigma_i|) |s|^i <= 2 n u (1 + gamma_2n) m~; Horner
///    on the rounded coefficients fl(pi_i + sigma_i) errs by at most gamma_2n times that:
///    4 n^2 u^2 m~ (to first order; every "to first order" below hides a factor 1 + 2^-40).
///  - |d - p_c'(s)| <= gamma_2n sum i |c_i| |s|^(i-1) and |e| <= u |s|, |s| sum i |c_i||s|^(i-1)
///    <= n m~: e (d - p_c') and the rounding of e * d add (2 n^2 + n) u^2 m~.
///  - |R2| <= m~ ((1 + u)^n - 1 - n u) <= (n^2 / 2) u^2 m~.
///  - |p_cl(s + e) - fl(p_cl(s))| <= (n u + gamma_2n) u m~ = 3 n u^2 m~.
///  - the two additions forming lo: |fl(Q)| + |fl(e d)| + |fl(p_cl)| <= (3 n + 1) u m~, each
///    rounding at most u times that: (6 n + 2) u^2 m~.
/// Total (6.5 n^2 + 10 n + 2) u^2 m~; the bound uses (8 n^2 + 12 n + 8) u^2 fl(m~) (1 + 2^-40),
/// which also covers fl(m~) >= (1 - u)^(2n) m~ and the rounding of the bound itself.
/// Underflow: TwoSum stays exact; TwoProduct is only used where two_product_safe() holds
/// (otherwise the result is "undecided"); each of the at most 5 n + 1 plain multiplications may
/// add 2^-1075, amplified by at most max(1, |s|)^(n+1) later: (8 n + 8) 2^-1060
/// max(1, |s|)^(n+1) covers it many times over. Overflow makes hi, lo or the bound non-finite,
/// hence undecided.
CompensatedValue compensated_horner(const double* c, const double* cl, int n, double s, double e) {
  CompensatedValue out;
  if (n == 0 || (s == 0.0 && e == 0.0)) {
    // P is the constant c_0 + cl_0, or x == 0: the value is c_0 + cl_0 exactly.
    out.hi = c[0];
    out.lo = cl != nullptr ? cl[0] : 0.0;
    return out;
  }
  const double as = std::fabs(s);
  if (!(as >= 0x1p-1022 && as <= 0x1p995)) return undecided();
  double r = c[n];
  double q = 0.0, d = 0.0, ql = cl != nullptr ? cl[n] : 0.0, m = std::fabs(c[n]);
  bool safe = true;
  for (int i = n - 1; i >= 0; --i) {
    d = d * s + static_cast<double>(i + 1) * c[i + 1];
    double p = 0.0, pi = 0.0, sigma = 0.0;
    two_product(r, s, p, pi);
    safe = safe && two_product_safe(r, p);
    two_sum(p, c[i], r, sigma);
    q = q * s + (pi + sigma);
    if (cl != nullptr) ql = ql * s + cl[i];
    m = m * as + std::fabs(c[i]);
  }
  if (!safe) return undecided();
  const double nn = static_cast<double>(n);
  double growth = 1.0;  // max(1, |s|)^(n+1), by multiplication (deterministic everywhere)
  for (int i = 0; i <= n; ++i) growth *= std::max(1.0, as);
  out.hi = r;
  out.lo = (q + e * d) + ql;
  out.error = (8.0 * nn * nn + 12.0 * nn + 8.0) * (kUnit * kUnit) * m * (1.0 + 0x1p-40) +
              (8.0 * nn + 8.0) * 0x1p-1060 * growth;
  return out;
}

int CompensatedValue::sign_if_certain() const {
  if (!std::isfinite(hi) || !std::isfinite(lo) || !std::isfinite(error)) return 0;
  // v = fl(hi + lo) is within u |v| of hi + lo (exactly hi + lo when it is subnormal). The bound
  // below, rounded, is still >= error + u |v| (+ 2^-1074 covers an underflowing product).
  const double v = hi + lo;
  const double bound = error * (1.0 + 0x1p-50) + 0x1p-51 * std::fabs(v) + 0x1p-1074;
  if (v > bound) return 1;
  if (v < -bound) return -1;
  return 0;
}

CompensatedValue evaluate_compensated(const MotionPolynomial& p, Time t) {
  // t - origin == s + e exactly (TwoSum); s infinite when it overflows (then undecided).
  double s = 0.0, e = 0.0;
  two_sum(t, -p.origin, s, e);
  return compensated_horner(p.c.data(), nullptr, p.degree, s, e);
}

CompensatedValue evaluate_difference_compensated(const MotionPolynomial& a,
                                                 const MotionPolynomial& b, Time t) {
  if (a.origin == b.origin) {
    // a_i - b_i == dh_i + dl_i exactly (TwoSum), |dl_i| <= u |dh_i|: one polynomial.
    const int n = std::max(a.degree, b.degree);
    std::array<double, kMaxMotionDegree + 1> dh{}, dl{};
    bool any_low = false;
    for (int i = 0; i <= n; ++i) {
      two_sum(a.c[i], -b.c[i], dh[i], dl[i]);
      any_low = any_low || dl[i] != 0.0;
    }
    double s = 0.0, e = 0.0;
    two_sum(t, -a.origin, s, e);
    return compensated_horner(dh.data(), any_low ? dl.data() : nullptr, n, s, e);
  }
  const CompensatedValue va = evaluate_compensated(a, t);
  const CompensatedValue vb = evaluate_compensated(b, t);
  // (va.hi + va.lo) - (vb.hi + vb.lo) = hi + l + va.lo - vb.lo exactly (TwoSum on the high
  // parts); lo = fl(fl(l + va.lo) - vb.lo) errs by at most 2 u (1 + 2 u) (|l| + |va.lo| +
  // |vb.lo|), bounded below with a factor 2 to spare (the 2^-1070 covers an underflowing product).
  CompensatedValue out;
  double l = 0.0;
  two_sum(va.hi, -vb.hi, out.hi, l);
  out.lo = (l + va.lo) - vb.lo;
  out.error = (va.error + vb.error) * (1.0 + 0x1p-50) +
              0x1p-51 * (std::fabs(l) + std::fabs(va.lo) + std::fabs(vb.lo)) + 0x1p-1070;
  return out;
}

void taylor_compensated(const MotionPolynomial& p, Time t,
                        std::array<CompensatedValue, kMaxMotionDegree + 1>& out) {
  for (CompensatedValue& v : out) v = CompensatedValue{};
  double s = 0.0, e = 0.0;
  two_sum(t, -p.origin, s, e);
  // d_k = sum_{i >= k} C(i, k) c_i (t - origin)^(i - k): a polynomial of degree n - k in
  // t - origin whose coefficients C(i, k) c_i == hi + lo exactly (TwoProduct; |lo| <= u |hi|,
  // as compensated_horner() requires).
  std::array<double, kMaxMotionDegree + 1> ch{}, cl{};
  for (int k = 0; k <= p.degree; ++k) {
    bool safe = true;
    bool any_low = false;
    double binom = 1.0;  // C(i, k) for i = k, k + 1, ... (exact small integers)
    for (int i = k; i <= p.degree; ++i) {
      if (i > k) binom = binom * static_cast<double>(i) / static_cast<double>(i - k);
      if (binom == 1.0) {
        ch[i - k] = p.c[i];
        cl[i - k] = 0.0;
      } else {
        two_product(p.c[i], binom, ch[i - k], cl[i - k]);
        safe = safe && two_product_safe(p.c[i], ch[i - k]);
        any_low = any_low || cl[i - k] != 0.0;
      }
    }
    out[k] = safe ? compensated_horner(ch.data(), any_low ? cl.data() : nullptr, p.degree - k, s, e)
                  : undecided();
  }
}

namespace {

/// A double-double with a rigorous error bound: the exact value lies in hi + lo +- err.
/// Operations keep the bound (relative roundings at most u each, bounded with a factor 2 to
/// spare; 2^-1070 per operation covers underflowing products; additions are exact when they
/// underflow). A non-finite part or an unsafe TwoProduct makes the result undecidable.
struct BoundedDD {
  double hi = 0.0, lo = 0.0, err = 0.0;
};

/// x - y: TwoSum on the high parts, the low parts added in floating point.
/// |fl(fl(x.lo - y.lo) + e) - (x.lo - y.lo + e)| <= 2 u (1 + u) (|x.lo| + |y.lo| + |e|).
BoundedDD dd_sub(const BoundedDD& x, const BoundedDD& y) {
  double s = 0.0, e = 0.0;
  two_sum(x.hi, -y.hi, s, e);
  const double t = (x.lo - y.lo) + e;
  BoundedDD r;
  two_sum(s, t, r.hi, r.lo);
  r.err = (x.err + y.err) * (1.0 + 0x1p-50) +
          0x1p-51 * (std::fabs(x.lo) + std::fabs(y.lo) + std::fabs(e)) + 0x1p-1070;
  return r;
}

BoundedDD dd_add(const BoundedDD& x, const BoundedDD& y) {
  return dd_sub(x, BoundedDD{-y.hi, -y.lo, y.err});
}

/// x * w for a double w (exact factor): TwoProduct on the high part (checked safe),
/// |fl(pi + fl(x.lo w)) - (pi + x.lo w)| <= 2 u (1 + u) (|pi| + |x.lo w|) + 2^-1075.
BoundedDD dd_mul(const BoundedDD& x, double w, bool& safe) {
  double p = 0.0, pi = 0.0;
  two_product(x.hi, w, p, pi);
  safe = safe && two_product_safe(x.hi, p);
  const double q = x.lo * w;
  BoundedDD r;
  two_sum(p, pi + q, r.hi, r.lo);
  r.err =
      x.err * std::fabs(w) * (1.0 + 0x1p-50) + 0x1p-51 * (std::fabs(q) + std::fabs(pi)) + 0x1p-1070;
  return r;
}

}  // namespace

bool bernstein_compensated(const MotionPolynomial& a, const MotionPolynomial& b, int degree,
                           Time lo, Time hi,
                           std::array<CompensatedValue, kMaxMotionDegree + 1>& gamma) {
  for (CompensatedValue& g : gamma) g = CompensatedValue{};
  double w = 0.0, we = 0.0;
  two_sum(hi, -lo, w, we);
  const double aw = std::fabs(w);
  if (we != 0.0 || !(aw >= 0x1p-1022 && aw <= 0x1p995)) return false;  // w exact and safe
  std::array<CompensatedValue, kMaxMotionDegree + 1> ta, tb;
  taylor_compensated(a, lo, ta);
  taylor_compensated(b, lo, tb);
  bool safe = true;
  // e_k = (a_k - b_k) w^k.
  std::array<BoundedDD, kMaxMotionDegree + 1> e;
  for (int k = 0; k <= degree; ++k) {
    BoundedDD x = dd_sub(BoundedDD{ta[k].hi, ta[k].lo, ta[k].error},
                         BoundedDD{tb[k].hi, tb[k].lo, tb[k].error});
    for (int j = 0; j < k; ++j) x = dd_mul(x, w, safe);
    e[k] = x;
  }
  for (int i = 0; i <= degree; ++i) {
    BoundedDD g;
    double binom = 1.0;  // C(n - k, i - k), from k = i down to 0
    for (int k = i; k >= 0; --k) {
      if (k < i) {
        binom = binom * static_cast<double>(degree - k) / static_cast<double>(i - k);
      }
      g = dd_add(g, binom == 1.0 ? e[k] : dd_mul(e[k], binom, safe));
    }
    gamma[i] = CompensatedValue{g.hi, g.lo, g.err};
  }
  return safe;
}

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
