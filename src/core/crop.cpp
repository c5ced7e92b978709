#include "kinetic/core/crop.hpp"

#include <gmpxx.h>

#include <algorithm>
#include <bit>
#include <cassert>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <type_traits>

#include "core/determinants.hpp"
#include "core/incircle_lines.hpp"
#include "core/numeric/dyadic.hpp"
#include "core/numeric/eft.hpp"
#include "core/numeric/interval.hpp"
#include "core/numeric/linear_filter.hpp"
#include "core/numeric/taylor_shift.hpp"
#include "kinetic/core/float_roots.hpp"
#include "kinetic/core/incircle.hpp"

namespace kinetic {
namespace {

// The numeric layer (core/numeric/, docs/numeric.md): interval arithmetic with outward rounding,
// error-free transformations and exact dyadic arithmetic, each with its bound stated there.
using numeric::down;
using numeric::Dyadic;
using numeric::dyadic;
using numeric::exact_difference;
using numeric::Interval;
using numeric::scale;
using numeric::up;

constexpr int kN = kMaxMotionDegree;

/// Coefficients of p(a + u) in powers of u, as intervals (Taylor shift in interval arithmetic).
void shifted(const MotionPolynomial& p, double a, std::array<Interval, kN + 1>& q) {
  for (int i = 0; i <= kN; ++i) q[i] = Interval::point(i <= p.degree ? p.c[i] : 0.0);
  if (a == p.origin) return;
  numeric::taylor_shift(q, p.degree, exact_difference(a, p.origin));
}

/// Exact Taylor coefficients of p at a.
void exact_shifted(const MotionPolynomial& p, double a,
                   std::array<Dyadic, kMaxMotionDegree + 1>& q) {
  for (int i = 0; i <= kMaxMotionDegree; ++i) q[i] = dyadic(i <= p.degree ? p.c[i] : 0.0);
  if (a == p.origin) return;
  numeric::taylor_shift(q, p.degree, dyadic(a) + (-dyadic(p.origin)));
}

/// Coefficients of p(s + u) from those of p(u), in plain floating point (guesses only).
void taylor_shift(std::array<double, kMaxMotionDegree + 1>& q, int degree, double s) {
  if (s == 0.0) return;
  numeric::taylor_shift(q, degree, s);
}

/// A polynomial in u truncated above degree kN over T (Interval, Dyadic, double): the Taylor
/// coefficients of a certificate built from motions by +, - and *, whose degree is at most kN
/// (so nothing is truncated).
template <class T>
struct Truncated {
  std::array<T, kN + 1> c{};
  int deg = kN;  ///< coefficients above it are 0 (products skip them)
  friend Truncated operator+(const Truncated& a, const Truncated& b) {
    Truncated r;
    r.deg = std::max(a.deg, b.deg);
    for (int k = 0; k <= r.deg; ++k) r.c[k] = a.c[k] + b.c[k];
    return r;
  }
  friend Truncated operator-(const Truncated& a, const Truncated& b) {
    Truncated r;
    r.deg = std::max(a.deg, b.deg);
    for (int k = 0; k <= r.deg; ++k) {
      if constexpr (std::is_same_v<T, Dyadic>) {
        r.c[k] = a.c[k] + (-b.c[k]);  // (dyadics have no binary minus)
      } else {
        r.c[k] = a.c[k] - b.c[k];
      }
    }
    return r;
  }
  friend Truncated operator*(const Truncated& a, const Truncated& b) {
    Truncated r;
    r.deg = std::min(kN, a.deg + b.deg);
    for (int i = 0; i <= a.deg; ++i) {
      for (int j = 0; j <= b.deg && i + j <= kN; ++j) r.c[i + j] = r.c[i + j] + a.c[i] * b.c[j];
    }
    return r;
  }
};

/// The exact sign of a + b - c - d by error-free sums, or nullopt outside their domain.
std::optional<int> exact_sum_sign(double a, double b, double c, double d) {
  constexpr double kLimit = 0x1p1020;  // expansion_sum_sign's domain, with room for one sum
  if (!(std::abs(a) <= kLimit && std::abs(b) <= kLimit && std::abs(c) <= kLimit &&
        std::abs(d) <= kLimit)) {
    return std::nullopt;
  }
  // (a - c) + (b - d) as two exact two-term expansions, then the sign of their exact sum.
  double s1 = 0.0, e1 = 0.0, s2 = 0.0, e2 = 0.0;
  numeric::two_sum(a, -c, s1, e1);
  numeric::two_sum(b, -d, s2, e2);
  return numeric::expansion_sum_sign(e1, s1, e2, s2);
}

/// The certificate functions built from several motions, f = plus[0] + plus[1] - minus[0] -
/// minus[1] (a MotionCombination) or a signed sum of products of motion differences (a
/// ProductCombination, (P0 - P1)(P2 - P3) - (M0 - M1)(M2 - M3), or a ProductSum of up to four
/// products), seen only through their Taylor coefficients at a point: enclosed with outward
/// rounding, exact (GMP) or approximate. Nothing is rounded into a copy of f.
struct Terms {
  enum class Kind { kSum, kProduct, kInCircle };
  Kind kind = Kind::kSum;
  /// kSum: plus[0], plus[1], minus[0], minus[1]; kProduct: product k is (m[4k] - m[4k + 1])
  /// (m[4k + 2] - m[4k + 3]), added for even k and subtracted for odd k.
  std::array<const MotionPolynomial*, 4 * ProductSum::kMaxProducts> m{};
  int products = 0;  ///< kProduct: how many
  int degree = 0;
  /// kInCircle: the exact Taylor coefficients at origin(), once computed.
  mutable std::optional<std::array<Dyadic, kN + 1>> exact_base;
  /// kInCircle: an enclosure of the Taylor coefficients at *enclosed_at, once computed.
  mutable std::optional<double> enclosed_at;
  mutable std::array<Interval, kN + 1> enclosed{};

  explicit Terms(const MotionCombination& f)
      : kind(Kind::kSum),
        m{f.plus[0], f.plus[1], f.minus[0], f.minus[1]},
        degree(std::max(
            {f.plus[0]->degree, f.plus[1]->degree, f.minus[0]->degree, f.minus[1]->degree})) {}
  explicit Terms(const ProductCombination& f)
      : kind(Kind::kProduct),
        m{f.plus[0],  f.plus[1],  f.plus[2],  f.plus[3],
          f.minus[0], f.minus[1], f.minus[2], f.minus[3]},
        products(2),
        degree(f.degree_bound()) {}
  /// The in-circle determinant of four moving points (kInCircle: m[0..7] = a_x, a_y, ..., d_y).
  explicit Terms(const InCircle& f) : kind(Kind::kInCircle), degree(f.degree_bound()) {
    for (std::size_t k = 0; k < 8; ++k) {
      const MovingPoint2& p = f.p[k / 2];
      m[k] = k % 2 == 0 ? p.x : p.y;
    }
  }
  explicit Terms(const ProductSum& f)
      : kind(Kind::kProduct), products(f.count), degree(f.degree_bound()) {
    for (int k = 0; k < f.count; ++k)
      for (int j = 0; j < 4; ++j) m[static_cast<std::size_t>(4 * k + j)] = f.factors[k][j];
  }

  /// kInCircle: the determinant it stands for.
  [[nodiscard]] InCircle incircle() const {
    return InCircle{{MovingPoint2{m[0], m[1]}, MovingPoint2{m[2], m[3]}, MovingPoint2{m[4], m[5]},
                     MovingPoint2{m[6], m[7]}}};
  }

  /// The origin the frame is taken at.
  [[nodiscard]] double origin() const { return std::isnan(origin_at) ? m[0]->origin : origin_at; }
  /// Where the frame is taken (NaN: the first motion's origin), e.g. the start of a search.
  double origin_at = std::numeric_limits<double>::quiet_NaN();

  /// Coefficients of f(a + u) as intervals containing the exact ones. `direct`: computed at a
  /// (tighter) rather than shifted there from an enclosure at another point.
  void enclose(double a, std::array<Interval, kN + 1>& out, bool direct = false) const {
    std::array<Interval, kN + 1> q;
    if (kind == Kind::kInCircle) {
      // The determinant is enclosed once, at the first point asked (its products of
      // polynomials in interval arithmetic cost tens of Taylor shifts), and shifted to every
      // other point in interval arithmetic: still an enclosure, a little wider.
      const auto determinant_at = [&](double x) {
        std::array<Truncated<Interval>, 8> v;
        for (std::size_t k = 0; k < 8; ++k) {
          shifted(*m[k], x, v[k].c);
          v[k].deg = m[k]->degree;
        }
        return detail::incircle_determinant(v).c;
      };
      if (direct && enclosed_at && a != *enclosed_at) {
        out = determinant_at(a);
        return;
      }
      if (!enclosed_at) {
        enclosed = determinant_at(a);
        enclosed_at = a;
      }
      out = enclosed;
      if (a != *enclosed_at) numeric::taylor_shift(out, degree, exact_difference(a, *enclosed_at));
      return;
    }
    if (kind == Kind::kSum) {
      for (int k = 0; k <= kN; ++k) out[k] = Interval::point(0.0);
      for (int j = 0; j < 4; ++j) {
        shifted(*m[j], a, q);
        for (int k = 0; k <= degree; ++k) out[k] = j < 2 ? out[k] + q[k] : out[k] - q[k];
      }
      return;
    }
    std::array<Interval, kN + 1> x, y;
    for (int k = 0; k <= kN; ++k) out[k] = Interval::point(0.0);
    for (int term = 0; term < products; ++term) {
      const MotionPolynomial* const* t = &m[4 * term];
      shifted(*t[0], a, x);
      shifted(*t[1], a, q);
      const int dx = std::max(t[0]->degree, t[1]->degree);
      for (int k = 0; k <= dx; ++k) x[k] = x[k] - q[k];
      shifted(*t[2], a, y);
      shifted(*t[3], a, q);
      const int dy = std::max(t[2]->degree, t[3]->degree);
      for (int k = 0; k <= dy; ++k) y[k] = y[k] - q[k];
      for (int i = 0; i <= dx; ++i) {
        for (int j = 0; j <= dy && i + j <= kN; ++j) {
          out[i + j] = term % 2 == 0 ? out[i + j] + x[i] * y[j] : out[i + j] - x[i] * y[j];
        }
      }
    }
  }

  /// The exact Taylor coefficients of f at t (GMP).
  [[nodiscard]] std::array<Dyadic, kN + 1> exact(double t) const {
    std::array<Dyadic, kN + 1> sum, q;
    if (kind == Kind::kInCircle) {
      // The exact coefficients at the first motion's origin, computed once (eight Taylor shifts
      // and the determinant in dyadic polynomials), then shifted exactly to t.
      if (!exact_base) {
        std::array<Truncated<Dyadic>, 8> v;
        for (std::size_t k = 0; k < 8; ++k) {
          exact_shifted(*m[k], origin(), v[k].c);
          v[k].deg = m[k]->degree;
        }
        exact_base = detail::incircle_determinant(v).c;
      }
      std::array<Dyadic, kN + 1> at = *exact_base;
      if (t != origin()) numeric::taylor_shift(at, degree, dyadic(t) + (-dyadic(origin())));
      return at;
    }
    if (kind == Kind::kSum) {
      for (int j = 0; j < 4; ++j) {
        exact_shifted(*m[j], t, q);
        for (int k = 0; k <= kN; ++k) sum[k] = j < 2 ? sum[k] + q[k] : sum[k] + (-q[k]);
      }
      return sum;
    }
    std::array<Dyadic, kN + 1> x, y;
    for (int term = 0; term < products; ++term) {
      const MotionPolynomial* const* f = &m[4 * term];
      exact_shifted(*f[0], t, x);
      exact_shifted(*f[1], t, q);
      for (int k = 0; k <= kN; ++k) x[k] = x[k] + (-q[k]);
      exact_shifted(*f[2], t, y);
      exact_shifted(*f[3], t, q);
      for (int k = 0; k <= kN; ++k) y[k] = y[k] + (-q[k]);
      const int dx = std::max(f[0]->degree, f[1]->degree);
      const int dy = std::max(f[2]->degree, f[3]->degree);
      for (int i = 0; i <= dx; ++i) {
        if (x[i].m == 0) continue;
        for (int j = 0; j <= dy && i + j <= kN; ++j) {
          if (y[j].m == 0) continue;
          const Dyadic p = x[i] * y[j];
          sum[i + j] = term % 2 == 0 ? sum[i + j] + p : sum[i + j] + (-p);
        }
      }
    }
    return sum;
  }

  /// Floating-point Taylor coefficients of f at a: a guess only, every use is verified by exact
  /// signs.
  void approximate(double a, std::array<double, kN + 1>& d) const {
    d = {};
    if (kind == Kind::kInCircle && enclosed_at && a == *enclosed_at) {
      for (int k = 0; k <= degree; ++k) d[k] = 0.5 * enclosed[k].lo + 0.5 * enclosed[k].hi;
      return;
    }
    std::array<double, kN + 1> q;
    auto at = [&](const MotionPolynomial* p) {
      q = p->c;
      taylor_shift(q, p->degree, a - p->origin);
      return q;
    };
    if (kind == Kind::kInCircle) {
      std::array<Truncated<double>, 8> v;
      for (std::size_t k = 0; k < 8; ++k) {
        v[k].c = at(m[k]);
        v[k].deg = m[k]->degree;
      }
      d = detail::incircle_determinant(v).c;
      return;
    }
    if (kind == Kind::kSum) {
      for (int j = 0; j < 4; ++j) {
        const std::array<double, kN + 1> v = at(m[j]);
        for (int k = 0; k <= kN; ++k) d[k] += j < 2 ? v[k] : -v[k];
      }
      return;
    }
    for (int term = 0; term < products; ++term) {
      const MotionPolynomial* const* f = &m[4 * term];
      std::array<double, kN + 1> x = at(f[0]), y = at(f[2]);
      const std::array<double, kN + 1> x1 = at(f[1]), y1 = at(f[3]);
      for (int k = 0; k <= kN; ++k) {
        x[k] -= x1[k];
        y[k] -= y1[k];
      }
      for (int i = 0; i <= kN; ++i) {
        for (int j = 0; i + j <= kN; ++j) d[i + j] += term % 2 == 0 ? x[i] * y[j] : -(x[i] * y[j]);
      }
    }
  }
};

// ---------------------------------------------------------------------------------------------
// f = upper - lower as one polynomial in s = t - origin ("the frame"), computed once per CROP
// call: approximate coefficients d[k] with rigorous bounds r[k] >= |d[k] - F_k|, F_k the exact
// coefficients. It serves the sign filter (every exact sign CROP decides goes through it first),
// the root guesses and the discriminant filter of the quadratic path.
//  - Same origins, or one motion constant (its coefficients do not depend on the origin): d[k] is
//    the rounded difference of the coefficients and r[k] its exact rounding error (TwoSum), 0 when
//    the subtraction is exact.
//  - Different origins: upper is Taylor-shifted to lower's origin in floating point, with an
//    a-priori bound of the rounding errors (as evaluate_filtered() bounds a Horner evaluation).
// Non-finite values (overflow) make the filter undecided, never wrong: comparisons with NaN are
// false.
struct Frame {
  double origin = 0.0;
  int degree = 0;
  bool shifted = false;  ///< upper was Taylor-shifted (different origins): r[k] are a-priori bounds
  std::array<double, kN + 1> d{}, r{};

  /// For a quadratic d (d[2] != 0): floating-point guesses, to be verified by exact signs, of its
  /// vertex and its two real roots in ascending order (NaN when the computed discriminant is < 0).
  struct QuadraticGuesses {
    double vertex, root_lo, root_hi;
  };
  [[nodiscard]] QuadraticGuesses quadratic_guess_points() const {
    const double d0 = d[0], d1 = d[1], d2 = d[2];
    QuadraticGuesses g{origin + (-d1 / (2.0 * d2)), std::numeric_limits<double>::quiet_NaN(),
                       std::numeric_limits<double>::quiet_NaN()};
    const double disc = d1 * d1 - 4.0 * d0 * d2;
    if (disc >= 0.0) {
      const double q = -0.5 * (d1 + std::copysign(std::sqrt(disc), d1));
      const double r1 = q / d2;
      const double r2 = q != 0.0 ? d0 / q : r1;
      g.root_lo = origin + std::min(r1, r2);
      g.root_hi = origin + std::max(r1, r2);
    }
    return g;
  }

  Frame(const MotionPolynomial& u, const MotionPolynomial& l, int n) : degree(n) {
    if (u.origin == l.origin || l.degree == 0 || u.degree == 0) {
      origin = u.degree == 0 ? l.origin : u.origin;
      if (n == 2 && u.degree == 2 && l.degree == 2) {
        // The quadratic certificates of kinetic sorting: the same steps, unrolled.
        difference(u.c[0], l.c[0], 0);
        difference(u.c[1], l.c[1], 1);
        difference(u.c[2], l.c[2], 2);
        return;
      }
      for (int k = 0; k <= n; ++k) {
        difference(k <= u.degree ? u.c[k] : 0.0, k <= l.degree ? l.c[k] : 0.0, k);
      }
      return;
    }
    // Taylor shift of upper to h = fl(lower.origin - upper.origin) by synthetic division, and the
    // same recurrence on |c| and |h| (all terms positive) for the bound. Each shifted coefficient
    // is sum_i C(i, k) c_i h^(i - k) with at most 3n roundings on every term (n multiplications
    // and n additions, and the rounding of h in each power), so its error is at most
    // gamma_{3n} M_k <= (4n + 4) u M_k (M_k the sum of the absolute terms, computed here with
    // relative error gamma_{2n}); subtracting lower's coefficient adds u |d_k| <= u (M_k + |l_k|)
    // more. Underflow: one smallest-normal per operation, times at most max(1, |h|)^n later.
    // Nothing is exact then, even when the subtractions happen to be.
    origin = l.origin;
    shifted = true;
    const double h = l.origin - u.origin;
    const double ah = std::fabs(h);
    std::array<double, kN + 1> q{}, m{};
    for (int k = 0; k <= u.degree; ++k) {
      q[k] = u.c[k];
      m[k] = std::fabs(u.c[k]);
    }
    numeric::taylor_shift(q, u.degree, h);
    numeric::taylor_shift(m, u.degree, ah);
    const double big = std::max(1.0, ah);
    double growth = 1.0 + 1e-10;
    for (int i = 0; i < u.degree; ++i) growth *= big;
    const double nn = static_cast<double>(n);
    for (int k = 0; k <= n; ++k) {
      const double y = k <= l.degree ? l.c[k] : 0.0;
      d[k] = q[k] - y;
      r[k] = (4.0 * nn + 6.0) * 0x1p-53 * (m[k] + std::fabs(y)) * (1.0 + 1e-10) +
             (2.0 * nn + 2.0) * DBL_MIN * growth;
    }
  }

  /// f built from several motions (Terms: a MotionCombination or a ProductCombination): its
  /// Taylor coefficients at the origin of its first motion enclosed in interval arithmetic with
  /// outward rounding (Terms::enclose(): exact when the origins agree and no product rounds), so
  /// the exact coefficient F_k lies in an interval [lo_k, hi_k]; d[k] is a point of it and r[k]
  /// an upper bound of max(hi_k - d[k], d[k] - lo_k), hence of |d[k] - F_k|. Never exact
  /// (shifted). Non-finite enclosures give non-finite d or r: the filter is undecided there.
  Frame(const Terms& f, int n) : degree(n) {
    origin = f.origin();
    shifted = true;
    std::array<Interval, kN + 1> sum{};
    f.enclose(origin, sum);
    for (int k = 0; k <= n; ++k) {
      d[k] = 0.5 * sum[k].lo + 0.5 * sum[k].hi;
      r[k] = std::max(up(sum[k].hi - d[k]), up(d[k] - sum[k].lo));
      if (!std::isfinite(d[k]) || !std::isfinite(r[k]))
        r[k] = std::numeric_limits<double>::infinity();
    }
  }

  /// d[k] = x - y rounded, r[k] = |its rounding error| (TwoSum(x, -y): d[k] + e == x - y
  /// exactly).
  void difference(double x, double y, int k) {
    double v = 0.0, e = 0.0;
    numeric::two_sum(x, -y, v, e);
    d[k] = v;
    r[k] = std::fabs(e);
  }

  /// True when every r[k] == 0: the d[k] are the exact coefficients (never after a shift, where
  /// the r[k] are a-priori bounds).
  [[nodiscard]] bool exact() const {
    if (shifted) return false;
    for (int k = 0; k <= degree; ++k) {
      if (!(r[k] == 0.0)) return false;
    }
    return true;
  }

  /// The sign of f(t) when the filter can certify it, 0 otherwise.
  /// Bound: Horner on d at s = fl(t - origin) is within (4n + 4) u sum |d_k||s|^k (plus underflow
  /// terms) of sum d_k (t - origin)^k, the analysis of evaluate_filtered() (polynomial.cpp); the
  /// coefficient errors add at most sum r_k |t - origin|^k <= (1 + 1e-10) fl(sum r_k |s|^k) (the
  /// relative errors of fl(t - origin) and of the n + n roundings of that sum, n <= 6), plus one
  /// smallest-normal per rounding that underflows, times at most max(1, |s|)^n.
  [[nodiscard]] int filtered_sign(double t) const { return sign_of(d, r, degree, t); }

  /// The same for f'(t), degree 2 only: f' = d1 + 2 d2 s (times 2 is exact unless it overflows,
  /// which the bound then reports as undecided).
  [[nodiscard]] int filtered_derivative_sign(double t) const {
    const std::array<double, kN + 1> dd{d[1], 2.0 * d[2]}, rr{r[1], 2.0 * r[2]};
    return sign_of(dd, rr, 1, t);
  }

  /// Floating-point value of f(t) (a guess only).
  [[nodiscard]] double approximate(double t) const {
    const double s = t - origin;
    double v = d[degree];
    for (int i = degree - 1; i >= 0; --i) v = v * s + d[i];
    return v;
  }

 private:
  [[nodiscard]] int sign_of(const std::array<double, kN + 1>& c,
                            const std::array<double, kN + 1>& rad, int n, double t) const {
    // Unrolled for each degree: this runs for every exact sign CROP decides.
    if (n == 2) return sign_n<2>(c, rad, t);  // the quadratic path, first
    switch (n) {
      case 0:
        return sign_n<0>(c, rad, t);
      case 1:
        return sign_n<1>(c, rad, t);
      case 2:
        return sign_n<2>(c, rad, t);
      case 3:
        return sign_n<3>(c, rad, t);
      case 4:
        return sign_n<4>(c, rad, t);
      case 5:
        return sign_n<5>(c, rad, t);
      default:
        return sign_n<6>(c, rad, t);
    }
  }

  /// The filter's error bound for |s| = as (the analysis above): every operation is a rounded
  /// sum, product or max of non-negative numbers, each monotone in its operands, so the bound
  /// computed for any as >= |fl(t - origin)| is at least the bound for t itself.
  template <int N>
  [[nodiscard]] static double error_n(const std::array<double, kN + 1>& c,
                                      const std::array<double, kN + 1>& rad, double as) {
    static_assert(N <= kN);
    double m = std::fabs(c[N]), e = rad[N];
    for (int i = N - 1; i >= 0; --i) {
      m = m * as + std::fabs(c[i]);
      e = e * as + rad[i];
    }
    const double big = std::max(1.0, as);
    double growth = 1.0 + 1e-10;  // max(1, |s|)^N
    for (int i = 0; i < N; ++i) growth *= big;
    constexpr double kUnits = 4.0 * N + 4.0, kMins = 3.0 * N + 3.0;
    return (kUnits * 0x1p-53 * m + e) * (1.0 + 1e-10) + kMins * DBL_MIN * growth;
  }

  /// Horner's value at s = fl(t - origin), the filter's approximation of f(t).
  template <int N>
  [[nodiscard]] static double horner_n(const std::array<double, kN + 1>& c, double s) {
    double v = c[N];
    for (int i = N - 1; i >= 0; --i) v = v * s + c[i];
    return v;
  }

  template <int N>
  [[nodiscard]] int sign_n(const std::array<double, kN + 1>& c,
                           const std::array<double, kN + 1>& rad, double t) const {
    const double s = t - origin;
    const double v = horner_n<N>(c, s);
    const double error = error_n<N>(c, rad, std::fabs(s));
    if (v > error) return 1;
    if (v < -error) return -1;
    return 0;
  }

 public:
  /// The filter of degree 2 on a whole window [lo, hi] (lo <= hi): one error bound computed
  /// once for the largest |fl(t - origin)| there, which is max(|fl(lo - origin)|,
  /// |fl(hi - origin)|) as rounding is monotone, so that a sign costs a Horner evaluation and a
  /// comparison. Certain where it answers (error_n is monotone); the pointwise filter is tighter.
  class WindowFilter2 {
   public:
    WindowFilter2(const Frame& f, double lo, double hi)
        : lo_(lo),
          hi_(hi),
          origin_(f.origin),
          d0_(f.d[0]),
          d1_(f.d[1]),
          d2_(f.d[2]),
          error_(
              error_n<2>(f.d, f.r, std::max(std::fabs(lo - f.origin), std::fabs(hi - f.origin)))) {}
    /// -1 / +1 when certain, 0 otherwise (including t outside [lo, hi]).
    [[nodiscard]] int sign(double t) const {
      if (!(t >= lo_ && t <= hi_)) return 0;
      const double s = t - origin_;
      const double v = (d2_ * s + d1_) * s + d0_;  // horner_n<2>
      if (v > error_) return 1;
      if (v < -error_) return -1;
      return 0;
    }

   private:
    double lo_, hi_, origin_, d0_, d1_, d2_, error_;
  };
};

// ---------------------------------------------------------------------------------------------
// Exact dyadic arithmetic (core/numeric/dyadic.hpp): the exact Taylor and Bernstein coefficients
// of upper - lower on a box with double ends are dyadic. Used only when the interval enclosures
// cannot decide a sign.

/// Binomial coefficients C(n, k) for n <= kN.
constexpr double binomial(int n, int k) {
  double r = 1.0;
  for (int i = 1; i <= k; ++i) r = r * (n - k + i) / i;
  return r;
}

/// The exact f = upper - lower, seen through intervals on boxes [a, b].
class Certificate {
 public:
  Certificate(const MotionPolynomial& upper, const MotionPolynomial& lower, CropStats* stats)
      : upper_(upper),
        lower_(lower),
        stats_(stats),
        degree_(std::max(upper.degree, lower.degree)),
        frame_(upper, lower, degree_) {}

  /// A function built from several motions (a MotionCombination or a ProductCombination, as
  /// Terms, which must outlive this): the same interface, every sign exact (the frame's filter,
  /// then GMP on the exact function), only the general path (no lean or linear or quadratic
  /// shortcuts, no compensated stage).
  Certificate(const Terms& f, CropStats* stats)
      : upper_(*f.m[0]),
        lower_(*f.m[1]),
        stats_(stats),
        terms_(&f),
        degree_(f.degree),
        frame_(f, degree_) {}

  /// True for a combination of several motions: upper() and lower() are then only two of them.
  [[nodiscard]] bool combination() const { return terms_ != nullptr; }

  /// For f of degree bound 2: the exact sign of its t^2 coefficient (a constant), 0 when it
  /// vanishes (f is then of degree <= 1 and the quadratic path does not apply). A pair compares
  /// the two leading coefficients; a combination's enclosure decides, else GMP.
  [[nodiscard]] int leading_sign_degree_2() const {
    if (!combination()) {
      const double u2 = upper_.degree == 2 ? upper_.c[2] : 0.0;
      const double l2 = lower_.degree == 2 ? lower_.c[2] : 0.0;
      return u2 == l2 ? 0 : (u2 > l2 ? 1 : -1);
    }
    const Frame& fr = frame_;
    const Interval f2{down(fr.d[2] - fr.r[2]), up(fr.d[2] + fr.r[2])};
    if (const int s = f2.sign(); s != 0) return s;
    if (terms_->kind == Terms::Kind::kSum) {
      // The t^2 coefficient of a sum does not depend on the origin: the exact sign of
      // c2(plus 0) + c2(plus 1) - c2(minus 0) - c2(minus 1), by error-free sums.
      const auto c2 = [&](int j) { return terms_->m[j]->degree >= 2 ? terms_->m[j]->c[2] : 0.0; };
      if (const std::optional<int> s = exact_sum_sign(c2(0), c2(1), c2(2), c2(3))) return *s;
    }
    return sgn(exact_taylor(fr.origin)[2].m);
  }

  [[nodiscard]] int degree() const { return degree_; }
  [[nodiscard]] const MotionPolynomial& upper() const { return upper_; }
  [[nodiscard]] const MotionPolynomial& lower() const { return lower_; }
  [[nodiscard]] const Frame& frame() const { return frame_; }

  /// Exact sign of f(t): the frame's filter, then the predicates (their filter, then GMP).
  int sign(Time t) const {
    const int s = frame_.filtered_sign(t);
    if (s != 0) {
      if (stats_) ++stats_->predicates.filtered;
      return s;
    }
    if (combination() && terms_->kind == Terms::Kind::kInCircle) {
      // The in-circle predicate (core/incircle.hpp): the positions at t enclosed first, their
      // determinant filtered against its own magnitudes, rationals only where that fails.
      return kinetic::sign_at(terms_->incircle(), t, stats_ ? &stats_->predicates : nullptr);
    }
    if (combination()) {
      if (stats_) ++stats_->predicates.exact;
      return sgn(exact_taylor(t)[0].m);
    }
    return compare_at(upper_, lower_, t, stats_ ? &stats_->predicates : nullptr);
  }

  /// The exact Taylor coefficients of a combination at t (GMP).
  [[nodiscard]] std::array<Dyadic, kN + 1> exact_taylor(Time t) const { return terms_->exact(t); }

  /// Exact sign of f'(t), degree 2 (the quadratic path).
  int derivative_sign(Time t) const {
    const int s = frame_.filtered_derivative_sign(t);
    if (s != 0) {
      if (stats_) ++stats_->predicates.filtered;
      return s;
    }
    // f'(t) is the Taylor coefficient of order 1 of f at t: exact in dyadic arithmetic (GMP).
    if (stats_) ++stats_->predicates.exact;
    if (combination()) return sgn(exact_taylor(t)[1].m);
    std::array<Dyadic, kN + 1> qu, ql;
    exact_shifted(upper_, t, qu);
    exact_shifted(lower_, t, ql);
    return sgn((qu[1] + (-ql[1])).m);
  }

  /// Exact sign of the discriminant F1^2 - 4 F0 F2 of f, degree 2 (it does not depend on the
  /// origin): an interval filter on the frame, then error-free transformations when the frame is
  /// exact, then GMP.
  int discriminant_sign() const {
    const Frame& fr = frame_;
    auto enclose = [&](int k) { return Interval{down(fr.d[k] - fr.r[k]), up(fr.d[k] + fr.r[k])}; };
    const Interval f0 = enclose(0), f1 = enclose(1), f2 = enclose(2);
    const int filtered = (f1 * f1 - scale(f0 * f2, 4.0)).sign();
    if (filtered != 0) {
      if (stats_) ++stats_->predicates.filtered;
      return filtered;
    }
    // Inside two_product()'s domain (eft.hpp): every factor is 0 or normal of magnitude in
    // (2^-300, 2^302), every non-zero product in (2^-600, 2^602); the expansions are far from
    // overflow.
    auto in_range = [](double v) {
      const double a = std::fabs(v);
      return a == 0.0 || (a > 0x1p-300 && a < 0x1p300);
    };
    if (combination()) {
      // The exact Taylor coefficients at the frame's origin (GMP), as the exact signs do.
      if (stats_) ++stats_->predicates.exact;
      const std::array<Dyadic, kN + 1> q = exact_taylor(fr.origin);
      const Dyadic disc = q[1] * q[1] + (-(dyadic(4.0) * q[0] * q[2]));
      return sgn(disc.m);
    }
    if (fr.exact() && in_range(fr.d[0]) && in_range(fr.d[1]) && in_range(fr.d[2])) {
      if (stats_) ++stats_->predicates.filtered;
      double p1 = 0.0, e1 = 0.0, p2 = 0.0, e2 = 0.0;
      numeric::two_product(fr.d[1], fr.d[1], p1, e1);
      numeric::two_product(4.0 * fr.d[0], fr.d[2], p2, e2);
      return numeric::expansion_sum_sign(e1, p1, -e2, -p2);
    }
    if (stats_) ++stats_->predicates.exact;
    std::array<Dyadic, kN + 1> qu, ql;
    exact_shifted(upper_, fr.origin, qu);
    exact_shifted(lower_, fr.origin, ql);
    const Dyadic f0x = qu[0] + (-ql[0]), f1x = qu[1] + (-ql[1]), f2x = qu[2] + (-ql[2]);
    const Dyadic disc = f1x * f1x + (-(dyadic(4.0) * f0x * f2x));
    return sgn(disc.m);
  }

  /// Scaled Bernstein coefficients of f on [a, b] (gamma_i = C(n, i) * beta_i, same signs as the
  /// Bernstein coefficients beta_i): gamma_i = sum_{k <= i} C(n - k, i - k) d_k (b - a)^k, where
  /// d_k are the Taylor coefficients of f at a. Rigorous enclosures.
  void bernstein(double a, double b, std::array<Interval, kN + 1>& gamma,
                 bool direct = false) const {
    if (stats_ && !direct) ++stats_->bernstein_boxes;
    std::array<Interval, kN + 1> qu, ql;
    if (combination()) {
      terms_->enclose(a, qu, direct);  // qu: f, enclosed; ql = 0
      for (int k = 0; k <= kN; ++k) ql[k] = Interval::point(0.0);
    } else {
      shifted(upper_, a, qu);
      shifted(lower_, a, ql);
    }
    const Interval w = exact_difference(b, a);
    Interval wk = Interval::point(1.0);
    std::array<Interval, kN + 1> e;
    for (int k = 0; k <= degree_; ++k) {
      e[k] = (qu[k] - ql[k]) * wk;
      wk = wk * w;
    }
    for (int i = 0; i <= degree_; ++i) {
      Interval g = e[0];
      if (i > 0) g = scale(e[0], binomial(degree_, i));
      for (int k = 1; k <= i; ++k) g = g + scale(e[k], binomial(degree_ - k, i - k));
      gamma[i] = g;
    }
  }

  /// Exact signs of the scaled Bernstein coefficients of f on [a, b] (the fallback when an
  /// enclosure straddles zero): certified in double-double when its bounds decide every sign
  /// (gamma_0 = f(a) and gamma_n = f(b), which may be exact zeros, by the exact predicate),
  /// otherwise computed exactly with GMP.
  void exact_bernstein_signs(double a, double b, std::array<int, kN + 1>& signs) const {
    if (combination() && terms_->kind == Terms::Kind::kInCircle) {
      // The enclosure computed at a itself (not shifted there) often decides.
      std::array<Interval, kN + 1> gamma;
      bernstein(a, b, gamma, true);
      bool certain = true;
      for (int i = 0; i <= degree_; ++i) {
        signs[i] = gamma[i].sign();
        certain = certain && signs[i] != 0;
      }
      if (certain) return;
    }
    std::array<CompensatedValue, kN + 1> dd;
    if (!combination() && bernstein_compensated(upper_, lower_, degree_, a, b, dd)) {
      bool certain = true;
      for (int i = 1; i < degree_; ++i) {
        signs[i] = dd[i].sign_if_certain();
        certain = certain && signs[i] != 0;
      }
      if (certain) {
        signs[0] = dd[0].sign_if_certain();
        if (signs[0] == 0) signs[0] = sign(a);
        signs[degree_] = dd[degree_].sign_if_certain();
        if (signs[degree_] == 0) signs[degree_] = sign(b);
        return;
      }
    }
    if (stats_) ++stats_->exact_boxes;
    std::array<Dyadic, kN + 1> qu, ql, e;
    if (combination()) {
      qu = exact_taylor(a);  // ql stays 0
    } else {
      exact_shifted(upper_, a, qu);
      exact_shifted(lower_, a, ql);
    }
    const Dyadic w = dyadic(b) + (-dyadic(a));
    Dyadic wk = dyadic(1.0);
    for (int k = 0; k <= degree_; ++k) {
      e[k] = (qu[k] + (-ql[k])) * wk;
      wk = wk * w;
    }
    for (int i = 0; i <= degree_; ++i) {
      Dyadic g;
      for (int k = 0; k <= i; ++k) {
        Dyadic term = e[k];
        term.m *= static_cast<unsigned long>(binomial(degree_ - k, i - k));
        g = g + term;
      }
      signs[i] = sgn(g.m);
    }
  }

  /// Floating-point Taylor coefficients at a (midpoints of the enclosures), for root guesses.
  void approximate_at(double a, std::array<double, kN + 1>& d) const {
    // Plain floating point: a guess only, every use is verified by exact signs.
    if (combination()) {
      terms_->approximate(a, d);
      return;
    }
    std::array<double, kN + 1> qu = upper_.c, ql = lower_.c;
    taylor_shift(qu, upper_.degree, a - upper_.origin);
    taylor_shift(ql, lower_.degree, a - lower_.origin);
    for (int k = 0; k <= kN; ++k) d[k] = qu[k] - ql[k];
  }

 private:
  const MotionPolynomial& upper_;
  const MotionPolynomial& lower_;
  CropStats* stats_;
  const Terms* terms_ = nullptr;  ///< the combination, or nullptr for upper - lower
  int degree_;
  Frame frame_;
};

/// The grid: points (j + 1/2) w. Indices are exact integers stored in int64.
struct Grid {
  double w;
  /// 1 / w when it is a normal double (w is a power of two: t / w == t * (1 / w) exactly, barring
  /// an underflow that floor_index() corrects), else 0 (divide).
  double inverse;
  explicit Grid(double width) : w(width), inverse(reciprocal(width)) {}
  /// The grid of crop_grid_width(eps): for a normal eps, w = 2^e is eps with its significand
  /// bits cleared and 1 / w = 2^-e is normal iff e + 1023 <= 2045; otherwise as above.
  static Grid for_eps(double eps) {
    const std::uint64_t biased = std::bit_cast<std::uint64_t>(eps) >> 52;  // e + 1023, eps > 0
    if (biased >= 1 && biased <= 2045) {
      return Grid(std::bit_cast<double>(biased << 52),
                  std::bit_cast<double>((2046 - biased) << 52));
    }
    return Grid(crop_grid_width(eps));
  }
  /// 1 / w by the exponent alone (w = 2^e normal, 2^-e normal too), without a division.
  static double reciprocal(double width) {
    const std::uint64_t biased = std::bit_cast<std::uint64_t>(width) >> 52;  // e + 1023
    if (biased < 1 || biased > 2045 || width != std::bit_cast<double>(biased << 52)) return 0.0;
    return std::bit_cast<double>((2046 - biased) << 52);
  }
  [[nodiscard]] double at(std::int64_t j) const { return (static_cast<double>(j) + 0.5) * w; }

 private:
  Grid(double width, double inv) : w(width), inverse(inv) {}

 public:
  /// Largest j with at(j) <= t. Precondition: |t| < 2^52 w (every caller's t is a window end or
  /// a point clamped into the window). No floor() library call on this hot path: floor of an
  /// exact t / w - 1/2 by truncation, or (tiny grids, huge indices) the truncation corrected by
  /// exact comparisons with grid points.
  [[nodiscard]] std::int64_t floor_index(double t) const {
    if (inverse != 0.0) {
      // t * (1 / w) is exact (a power-of-two scaling; an underflow only moves it within
      // (-1/2, 1/2)), and so is x = t / w - 1/2 while |x| < 2^50: then floor(x) is the answer,
      // as at(j) <= t <=> j <= x.
      const double x = t * inverse - 0.5;
      if (std::fabs(x) < 0x1p50) {
        std::int64_t j = static_cast<std::int64_t>(x);
        if (static_cast<double>(j) > x) --j;
        return j;
      }
    }
    std::int64_t j = static_cast<std::int64_t>((inverse != 0.0 ? t * inverse : t / w) - 0.5);
    while (at(j) > t) --j;
    while (at(j + 1) <= t) ++j;
    return j;
  }
};

/// For f strictly monotone on the window [a, b] of grid cells [ja, jb) (rising: slope = +1,
/// falling: -1), its root guessed in cell j: the sign of f all over the window when the root is
/// outside it, else 0. Only a window end the guess points at is evaluated (`sign`), its sign left
/// in s0 (at a) or s1 (at b).
template <class Sign>
int sign_beyond_window(std::int64_t j, std::int64_t ja, std::int64_t jb, int slope, double a,
                       double b, Sign&& sign, int& s0, int& s1) {
  int beyond = 0;
  if (j == ja) {
    s0 = sign(a);
    if (s0 == slope) beyond = slope;  // the root is before the window
  }
  if (beyond == 0 && j + 1 == jb) {
    s1 = sign(b);
    if (s1 == -slope) beyond = -slope;  // the root is after the window
  }
  return beyond;
}

/// A safeguarded Newton iteration for the single root of p(u) = sum d_k u^k in (0, W), where p
/// has sign s0 at 0 (and the opposite sign at W). Floating point: a guess, verified by the caller.
double guess_root(const std::array<double, kN + 1>& d, int n, double W, int s0) {
  double lo = 0.0, hi = W;
  double x = 0.5 * W;
  for (int it = 0; it < 60; ++it) {
    double v = d[n], dv = 0.0;
    for (int i = n - 1; i >= 0; --i) {
      dv = dv * x + v;
      v = v * x + d[i];
    }
    const int sv = (v > 0.0) - (v < 0.0);
    if (sv == 0) return x;
    if (sv == s0) {
      lo = x;
    } else {
      hi = x;
    }
    double next = dv != 0.0 ? x - v / dv : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (next == x || hi - lo <= 0.0) break;
    x = next;
  }
  return x;
}

class Cropper {
 public:
  /// Writes into `result` (a default-constructed CropResult), which the caller returns.
  Cropper(const MotionPolynomial& upper, const MotionPolynomial& lower, double eps,
          CropStats* stats, std::vector<CropInterval>* all, CropResult& result)
      : f_(upper, lower, stats),
        grid_(Grid::for_eps(eps)),
        stats_(stats),
        all_(all),
        result_(result) {}
  Cropper(const Terms& f, double eps, CropStats* stats, std::vector<CropInterval>* all,
          CropResult& result)
      : f_(f, stats), grid_(Grid::for_eps(eps)), stats_(stats), all_(all), result_(result) {}

  /// Stops the search once an event interval ending after `t` with sign `failing` at its right
  /// end has been emitted (the intervals come out in ascending order, so the result holds every
  /// event up to it: EVENTTIME of the certificate failing there, without the rest).
  void stop_at_first(Time t, int failing) {
    stop_after_ = t;
    stop_sign_ = failing;
  }

  void run(Time lo, Time hi) {
    std::int64_t ja = grid_.floor_index(lo);
    std::int64_t jb = grid_.floor_index(hi);
    if (grid_.at(jb) < hi || jb == ja) ++jb;
    if (f_.degree() <= 2 && linear_fast_path(ja, jb)) return;
    if (f_.degree() == 2 && quadratic_path(ja, jb)) return;
    Guesses guesses;
    if (f_.degree() >= 2) {
      verify_guesses(ja, jb, guesses);
      if (exact_degree() && guesses.k == f_.degree()) {
        // Every root of f is in a verified cell, each cell holds exactly one: nothing else to
        // search, and the sign before the first cell is the sign at the window's start.
        result_.window_lo = grid_.at(ja);
        result_.window_hi = grid_.at(jb);
        result_.sign_first = guesses.found[0].sign_left;
        for (int i = 0; i < guesses.k; ++i) emit(guesses.found[i]);
        if (stats_) ++stats_->fast_path;
        return;
      }
    }
    int sa = f_.sign(grid_.at(ja));
    int sb = f_.sign(grid_.at(jb));
    // Window ends must not be roots: widen by one cell (f has at most `degree` roots).
    for (int guard = 0; sa == 0 && guard <= kN + 1; ++guard) sa = f_.sign(grid_.at(--ja));
    for (int guard = 0; sb == 0 && guard <= kN + 1; ++guard) sb = f_.sign(grid_.at(++jb));
    result_.window_lo = grid_.at(ja);
    result_.window_hi = grid_.at(jb);
    result_.sign_first = sa;
    if (sa == 0 || sb == 0) {
      // Zero at kN + 2 consecutive grid points: f is the zero polynomial.
      result_.identically_zero = true;
      result_.sign_first = 0;
      return;
    }
    if (f_.degree() <= 1) {
      // A non-zero polynomial of degree <= 1 is monotone: a sign change between the window's
      // ends is its only root; equal signs mean none.
      if (sa != sb) locate_single(ja, jb, sa, sb);
      return;
    }
    seeded_subdivision(ja, jb, sa, sb, guesses);
    return;
  }

 private:
  /// f linear (degree <= 1, or congruent parabolas): the guess verified by two exact signs (f is
  /// monotone, so a sign change across one cell is its only root, and a window end with the sign
  /// beyond the root proves there is none inside), else the exact signs at the window's ends and
  /// a located root. Returns false (nothing emitted) when f is not linear or vanishes exactly at
  /// an end of the window (the general path widens the window then).
  bool linear_fast_path(std::int64_t ja, std::int64_t jb) {
    if (f_.combination()) return linear_combination_path(ja, jb);
    const MotionPolynomial& u = f_.upper();
    const MotionPolynomial& l = f_.lower();
    // The slope of f: c[1] - c[1], plus 2 c2 (o_l - o_u) when both are congruent parabolas
    // (equal c[2]: the squares cancel exactly and f is linear, as in the paper's PARABOLA).
    if (f_.degree() == 2 && (u.degree != 2 || l.degree != 2 || u.c[2] != l.c[2])) return false;
    Interval slope_iv = exact_difference(u.c[1], l.c[1]);
    if (f_.degree() == 2) {
      slope_iv = slope_iv + Interval::point(2.0 * u.c[2]) * exact_difference(l.origin, u.origin);
    }
    const int slope = slope_iv.sign();
    const double a = grid_.at(ja);
    const double value = f_.frame().approximate(a);
    const double r = a - value / (0.5 * slope_iv.lo + 0.5 * slope_iv.hi);
    bool done = false;
    if (slope != 0) {
      done = monotone(ja, jb, slope, r);
    } else {
      // The slope may be 0 (e.g. congruent parabolas with the same apex: f is constant). f is
      // linear all the same: equal signs at the window's ends mean no root, different ones one.
      const int sa = f_.sign(a);
      const int sb = f_.sign(grid_.at(jb));
      if (sa != 0 && sb != 0) {
        result_.sign_first = sa;
        result_.window_lo = a;
        result_.window_hi = grid_.at(jb);
        if (sa != sb) locate(ja, jb, sa, sb, r);
        done = true;
      }
    }
    if (done && stats_) ++stats_->fast_path;
    return done;
  }

  /// A combination that is linear: degree <= 1, or degree bound 2 with t^2 terms that cancel
  /// exactly (two boxes under the same gravity). Its slope is a constant whose sign the frame's
  /// enclosure of f' decides (else the general path); the root guessed from the frame is
  /// verified by exact signs as for a pair.
  bool linear_combination_path(std::int64_t ja, std::int64_t jb) {
    if (f_.degree() == 2 && f_.leading_sign_degree_2() != 0) return false;
    const Frame& fr = f_.frame();
    const Interval slope_iv{down(fr.d[1] - fr.r[1]), up(fr.d[1] + fr.r[1])};
    const int slope = slope_iv.sign();
    if (slope == 0) return false;
    const double a = grid_.at(ja);
    const double r = a - fr.approximate(a) / fr.d[1];
    const bool done = monotone(ja, jb, slope, r);
    if (done && stats_) ++stats_->fast_path;
    return done;
  }

  /// f strictly monotone on the window [at(ja), at(jb)], rising (slope = +1) or falling (-1);
  /// r a guess of its root (+-infinity: after / before the window; NaN: none). The guessed cell is
  /// checked by two exact signs: a sign change across it is the only root, and a window end with
  /// the sign beyond the root proves there is none inside. Returns false (nothing emitted) when the
  /// guess cannot be verified.
  bool monotone_guess(std::int64_t ja, std::int64_t jb, int slope, double r) {
    const double a = grid_.at(ja), b = grid_.at(jb);
    const std::int64_t j =
        std::isnan(r) ? ja : std::clamp(grid_.floor_index(std::clamp(r, a, b)), ja, jb - 1);
    // A guessed cell at a window end is checked from that end first: one sign may settle it.
    int s0 = 2, s1 = 2;  // 2: not evaluated
    // The sign of f all over the window when the root is outside it.
    const int beyond = sign_beyond_window(
        j, ja, jb, slope, a, b, [&](double t) { return f_.sign(t); }, s0, s1);
    if (beyond != 0) {
      result_.sign_first = beyond;
      result_.window_lo = a;
      result_.window_hi = b;
      return true;
    }
    if (s0 == 2) s0 = f_.sign(grid_.at(j));
    if (s0 != -slope) return false;
    if (s1 == 2) s1 = f_.sign(grid_.at(j + 1));
    if (s1 != slope) return false;
    result_.sign_first = -slope;
    result_.window_lo = a;
    result_.window_hi = b;
    emit(CropInterval{grid_.at(j), grid_.at(j + 1), static_cast<std::int8_t>(s0),
                      static_cast<std::int8_t>(s1)});
    return true;
  }

  /// f strictly monotone on [at(ja), at(jb)]: the guess first, then exact signs at the window's
  /// ends and a located root. Returns false (nothing emitted) only when f vanishes at an end (the
  /// general path widens the window then).
  bool monotone(std::int64_t ja, std::int64_t jb, int slope, double r) {
    if (monotone_guess(ja, jb, slope, r)) return true;
    const int sa = f_.sign(grid_.at(ja));
    const int sb = f_.sign(grid_.at(jb));
    if (sa == 0 || sb == 0) return false;
    result_.sign_first = sa;
    result_.window_lo = grid_.at(ja);
    result_.window_hi = grid_.at(jb);
    if (sa != sb) locate(ja, jb, sa, sb, r);
    return true;
  }

  /// Degree exactly 2 (the leading coefficients differ), the derivative split. f' is linear, so
  /// the grid point next to the vertex v (where f' = 0) splits the window into two pieces where f
  /// is strictly monotone and the cell holding v. Let sigma be the sign of the leading
  /// coefficient and g = sigma f (convex): with k the largest grid index where g'(at(k)) <= 0
  /// (exact signs of f', found from a guess of v, bisection when the guess misses),
  ///  - [A, at(k)]: g falls strictly; a root there iff g(A) > 0 > g(at(k));
  ///  - [at(k + 1), B]: g rises strictly; a root there iff g(at(k + 1)) < 0 < g(B);
  ///  - the vertex cell [at(k), at(k + 1)]: g convex with its minimum inside. Different end signs:
  ///    one root, an event. Both negative: no root. Both positive: a root iff the minimum
  ///    g(v) = -disc / (4 |F2|) <= 0, i.e. the discriminant disc >= 0 (exact sign); then the cell
  ///    is turbulent (two simple roots or a double root in it).
  /// Each monotone piece needs its end signs only when its inner end has the sign that allows a
  /// root, and a root found is located from its quadratic-formula guess, verified by exact
  /// signs. Returns false (nothing emitted) when f vanishes exactly at a grid point it looks at;
  /// the general path handles those.
  bool quadratic_path(std::int64_t ja, std::int64_t jb) {
    const int sigma = f_.leading_sign_degree_2();
    if (sigma == 0) return false;
    const Frame& fr = f_.frame();
    // Guesses (floating point, verified): the vertex and the two roots.
    const auto [vertex, root_lo, root_hi] = fr.quadratic_guess_points();
    const double a = grid_.at(ja), b = grid_.at(jb);
    if (vertex >= a && vertex < b && quadratic_guesses(ja, jb, root_lo, root_hi)) {
      if (stats_) ++stats_->fast_path;
      return true;
    }
    auto gd = [&](std::int64_t j) { return sigma * f_.derivative_sign(grid_.at(j)); };
    // k in [ja - 1, jb]: ja - 1 when g' > 0 on the whole window, jb when g' <= 0 at its end.
    std::int64_t k = 0;
    bool found = false;
    if (!(vertex >= a)) {
      k = ja - 1;
      found = gd(ja) > 0;
    } else if (!(vertex < b)) {
      k = jb;
      found = gd(jb) <= 0;
    } else {
      k = std::clamp(grid_.floor_index(vertex), ja, jb - 1);
      found = gd(k) <= 0 && gd(k + 1) > 0;
    }
    if (!found) {
      if (gd(ja) > 0) {
        k = ja - 1;
      } else if (gd(jb) <= 0) {
        k = jb;
      } else {
        std::int64_t lo_k = ja, hi_k = jb;  // g' <= 0 at lo_k, > 0 at hi_k
        while (hi_k - lo_k > 1) {
          const std::int64_t mid = lo_k + (hi_k - lo_k) / 2;
          if (gd(mid) <= 0) {
            lo_k = mid;
          } else {
            hi_k = mid;
          }
        }
        k = lo_k;
      }
    }
    // Without real root guesses g > 0 (probably) all over the window: guess the root before the
    // window when g rises, after it when g falls.
    constexpr double kInfinity = std::numeric_limits<double>::infinity();
    bool done = false;
    if (k < ja) {
      done = monotone(ja, jb, sigma, std::isnan(root_hi) ? -kInfinity : root_hi);
    } else if (k >= jb) {
      done = monotone(ja, jb, -sigma, std::isnan(root_lo) ? kInfinity : root_lo);
    } else {
      done = split(ja, jb, k, sigma, root_lo, root_hi);
    }
    if (done && stats_) ++stats_->fast_path;
    return done;
  }

  /// With the vertex guessed inside the window, the root guesses first (as cheap as the split
  /// when they verify): f has exactly two roots (degree 2), so two verified sign-change cells
  /// account for all of them, and one verified cell with different signs at the window's ends
  /// (an odd number of roots inside) is the only root in the window. Returns false (nothing
  /// emitted) otherwise.
  bool quadratic_guesses(std::int64_t ja, std::int64_t jb, double root_lo, double root_hi) {
    const double a = grid_.at(ja), b = grid_.at(jb);
    std::array<CropInterval, 2> found{};
    int k = 0;
    std::int64_t next_free = ja;
    for (const double r : {root_lo, root_hi}) {
      if (!(r >= a && r <= b)) continue;
      const std::int64_t j = std::clamp(grid_.floor_index(r), ja, jb - 1);
      if (j < next_free) continue;
      const int s0 = f_.sign(grid_.at(j));
      const int s1 = f_.sign(grid_.at(j + 1));
      if (s0 == 0 || s1 == 0 || s0 == s1) continue;
      found[k++] = CropInterval{grid_.at(j), grid_.at(j + 1), static_cast<std::int8_t>(s0),
                                static_cast<std::int8_t>(s1)};
      next_free = j + 1;
    }
    if (k == 0) return false;
    if (k == 1) {
      const int sa = found[0].lambda == a ? found[0].sign_left : f_.sign(a);
      const int sb = found[0].rho == b ? found[0].sign_right : f_.sign(b);
      if (sa == 0 || sb == 0 || sa == sb) return false;
    }
    result_.sign_first = found[0].sign_left;
    result_.window_lo = a;
    result_.window_hi = b;
    for (int i = 0; i < k; ++i) emit(found[i]);
    return true;
  }

  /// The split case of quadratic_path(): ja <= k < jb, g' <= 0 at at(k), g' > 0 at at(k + 1).
  bool split(std::int64_t ja, std::int64_t jb, std::int64_t k, int sigma, double root_lo,
             double root_hi) {
    const int sl = f_.sign(grid_.at(k));
    const int sr = f_.sign(grid_.at(k + 1));
    if (sl == 0 || sr == 0) return false;
    int sa = sl, sb = sr;  // the signs at the window's ends, when implied
    bool left_root = false, right_root = false;
    if (k > ja && sigma * sl < 0) {
      sa = f_.sign(grid_.at(ja));
      if (sa == 0) return false;
      left_root = sa != sl;
    }
    if (k + 1 < jb && sigma * sr < 0) {
      sb = f_.sign(grid_.at(jb));
      if (sb == 0) return false;
      right_root = sb != sr;
    }
    // Only now is the result written: nothing above emitted anything.
    result_.sign_first = sa;
    result_.window_lo = grid_.at(ja);
    result_.window_hi = grid_.at(jb);
    const double vertex_guess = 0.5 * grid_.at(k) + 0.5 * grid_.at(k + 1);
    if (left_root) locate(ja, k, sa, sl, std::isfinite(root_lo) ? root_lo : vertex_guess);
    if (sl != sr || (sigma * sl > 0 && f_.discriminant_sign() >= 0)) {
      emit(CropInterval{grid_.at(k), grid_.at(k + 1), static_cast<std::int8_t>(sl),
                        static_cast<std::int8_t>(sr)});
    }
    if (right_root) locate(k + 1, jb, sr, sb, std::isfinite(root_hi) ? root_hi : vertex_guess);
    return true;
  }

  /// Floating-point guesses of the roots seed the search: a guessed cell whose exact end signs
  /// differ is emitted at once, and only the gaps between such cells are subdivided (usually a
  /// single Bernstein box each proves them empty). Correct whatever the guesses are.
  /// Cells guessed in floating point and verified by exact signs (a sign change across a cell
  /// proves a root in it), ascending.
  struct Guesses {
    std::array<CropInterval, kN> found{};
    std::array<std::int64_t, kN> cells{};
    int k = 0;
  };

  void verify_guesses(std::int64_t ja, std::int64_t jb, Guesses& g) const {
    const double a = grid_.at(ja), b = grid_.at(jb);
    std::array<double, kN + 1> d;
    f_.approximate_at(a, d);
    int degree = f_.degree();
    while (degree > 0 && d[degree] == 0.0) --degree;
    std::array<FloatRoot, kN> guesses{};
    // Guesses to within a quarter cell: each is verified by the exact signs at its cell's ends.
    const int m =
        degree > 0 ? float_sign_change_roots(d, degree, 0.0, b - a, guesses, 0.25 * grid_.w) : 0;
    std::int64_t next_free = ja;
    for (int i = 0; i < m; ++i) {
      const std::int64_t j = std::clamp(grid_.floor_index(a + guesses[i].at), ja, jb - 1);
      if (j < next_free) continue;
      const int s0 = f_.sign(grid_.at(j));
      const int s1 = f_.sign(grid_.at(j + 1));
      if (s0 == 0 || s1 == 0 || s0 == s1) continue;
      g.found[g.k] = CropInterval{grid_.at(j), grid_.at(j + 1), static_cast<std::int8_t>(s0),
                                  static_cast<std::int8_t>(s1)};
      g.cells[g.k++] = j;
      next_free = j + 1;
    }
  }

  /// True when the degree of f is known exactly: the leading coefficients differ (the leading
  /// coefficient of a motion does not change when its origin moves).
  [[nodiscard]] bool exact_degree() const {
    // A combination's leading coefficient may cancel: its degree is only an upper bound.
    if (f_.combination()) return false;
    const MotionPolynomial& u = f_.upper();
    const MotionPolynomial& l = f_.lower();
    return u.degree != l.degree || u.c[u.degree] != l.c[l.degree];
  }

  /// Floating-point guesses of the roots seed the search: verified cells are emitted as they
  /// are, and only the gaps between them are subdivided (usually a single Bernstein box each
  /// proves them empty). Correct whatever the guesses are.
  void seeded_subdivision(std::int64_t ja, std::int64_t jb, int sa, int sb, const Guesses& g) {
    const std::array<CropInterval, kN>& found = g.found;
    const std::array<std::int64_t, kN>& cells = g.cells;
    const int k = g.k;
    // Counting argument: with the exact degree d known (the leading coefficients differ), f has
    // at most d roots, and the number in the window has the parity of the sign change between
    // its ends. If fewer than two roots are unaccounted for and the parity matches, there are
    // none left, and the gaps need no search.
    const int unaccounted = f_.degree() - k;
    const bool done = exact_degree() && unaccounted < 2 && (k % 2 == 1) == (sa != sb);
    std::int64_t gap_start = ja;
    for (int i = 0; i < k && !stopped_; ++i) {
      if (!done && cells[i] > gap_start) subdivide(gap_start, cells[i]);
      if (stopped_) break;
      emit(found[i]);
      gap_start = cells[i] + 1;
    }
    if (!done && !stopped_ && gap_start < jb) subdivide(gap_start, jb);
    if (k > 0 && stats_) ++stats_->fast_path;
  }

 private:
  void subdivide(std::int64_t ja0, std::int64_t jb0) {
    // Depth-first, left to right, so that intervals come out in ascending order.
    struct Box {
      std::int64_t ja, jb;
    };
    std::array<Box, 256> stack;
    int top = 0;
    stack[top++] = Box{ja0, jb0};
    std::array<Interval, kN + 1> gamma;
    const int n = f_.degree();
    while (top > 0 && !stopped_) {
      const Box box = stack[--top];
      const double a = grid_.at(box.ja), b = grid_.at(box.jb);
      f_.bernstein(a, b, gamma);
      std::array<int, kN + 1> signs{};
      bool certain = true;
      for (int i = 0; i <= n; ++i) {
        signs[i] = gamma[i].sign();
        certain = certain && signs[i] != 0;
      }
      // An enclosure straddles zero: decide the signs exactly, so that the subdivision depends on
      // the roots (and their separation), not on the rounding of the coefficients.
      if (!certain) f_.exact_bernstein_signs(a, b, signs);
      // Descartes' rule on Bernstein coefficients (zeros skipped): the number of roots in the
      // open box is at most the number of sign changes, and of the same parity when f does not
      // vanish at the box's ends.
      int changes = 0, previous = 0;
      for (int i = 0; i <= n; ++i) {
        if (signs[i] == 0) continue;
        if (previous != 0 && signs[i] != previous) ++changes;
        previous = signs[i];
      }
      const bool ends_nonzero = signs[0] != 0 && signs[n] != 0;
      if (ends_nonzero && changes == 0) continue;  // f keeps one sign on the closed box
      if (ends_nonzero && changes == 1) {
        // Exactly one (simple) root in the open box.
        locate_single(box.ja, box.jb, signs[0], signs[n]);
        continue;
      }
      if (box.jb - box.ja == 1 || top + 2 > static_cast<int>(stack.size())) {
        emit_cell(box.ja, box.jb);
        continue;
      }
      const std::int64_t mid = box.ja + (box.jb - box.ja) / 2;
      stack[top++] = Box{mid, box.jb};
      stack[top++] = Box{box.ja, mid};
    }
  }

  /// The box (ja, jb) holds exactly one root, a simple one; sa, sb are the exact signs at its
  /// ends. Finds its grid cell: a floating-point guess verified by exact signs, then bisection.
  void locate_single(std::int64_t ja, std::int64_t jb, int sa, int sb) {
    double r = grid_.at(ja);
    if (jb - ja > 1) {
      const double a = grid_.at(ja);
      std::array<double, kN + 1> d;
      f_.approximate_at(a, d);
      r = a + guess_root(d, std::max(1, f_.degree()), grid_.at(jb) - a, sa);
    }
    locate(ja, jb, sa, sb, r);
  }

  /// As locate_single(), with a guess r of the root (any double; NaN: none).
  void locate(std::int64_t ja, std::int64_t jb, int sa, int sb, double r) {
    if (jb - ja > 1 && std::isfinite(r)) {
      std::int64_t j =
          std::clamp(grid_.floor_index(std::clamp(r, grid_.at(ja), grid_.at(jb))), ja, jb - 1);
      // Verify the guessed cell; the signs found narrow the bracket either way.
      if (j > ja) {
        const int s = f_.sign(grid_.at(j));
        if (s == 0) return emit_zero(grid_.at(j), sa, sb);
        if (s == sa) {
          ja = j;
        } else {
          jb = j;
        }
      }
      if (jb - ja > 1 && j + 1 < jb && j + 1 > ja) {
        const int s = f_.sign(grid_.at(j + 1));
        if (s == 0) return emit_zero(grid_.at(j + 1), sa, sb);
        if (s == sb) {
          jb = j + 1;
        } else {
          ja = j + 1;
        }
      }
    }
    while (jb - ja > 1) {
      const std::int64_t mid = ja + (jb - ja) / 2;
      const int s = f_.sign(grid_.at(mid));
      if (s == 0) return emit_zero(grid_.at(mid), sa, sb);
      if (s == sa) {
        ja = mid;
      } else {
        jb = mid;
      }
    }
    emit(CropInterval{grid_.at(ja), grid_.at(jb), static_cast<std::int8_t>(sa),
                      static_cast<std::int8_t>(sb)});
  }

  /// A simple root exactly at the grid point g: the interval (pred(g), succ(g)).
  void emit_zero(double g, int sa, int sb) {
    emit(CropInterval{std::nextafter(g, -kInf), std::nextafter(g, kInf),
                      static_cast<std::int8_t>(sa), static_cast<std::int8_t>(sb)});
  }

  /// Nearest double below (above) g where f is not zero, and the sign there.
  double nudge(double g, double direction, int& s) const {
    double t = g;
    for (int guard = 0; guard <= kN + 1; ++guard) {
      t = std::nextafter(t, direction);
      s = f_.sign(t);
      if (s != 0) return t;
    }
    return t;  // unreachable for a non-zero polynomial of degree <= kN
  }

  /// A leaf cell that may hold roots. Its ends are grid points; where f vanishes exactly at one,
  /// that root gets its own tiny interval and the cell stops one double short of it.
  void emit_cell(std::int64_t ja, std::int64_t jb) {
    double lambda = grid_.at(ja), rho = grid_.at(jb);
    int sl = f_.sign(lambda), sr = f_.sign(rho);
    if (sl == 0) lambda = nudge(lambda, kInf, sl);  // the zero itself was emitted by the left cell
    double zero_lo = 0.0, zero_hi = 0.0;
    int zero_sl = 0, zero_sr = 0;
    const bool right_zero = sr == 0;
    if (right_zero) {
      const double g = rho;
      rho = nudge(g, -kInf, sr);
      zero_lo = rho;
      zero_sl = sr;
      zero_hi = nudge(g, kInf, zero_sr);
    }
    if (lambda < rho) {
      emit(CropInterval{lambda, rho, static_cast<std::int8_t>(sl), static_cast<std::int8_t>(sr)});
    }
    if (right_zero) {
      emit(CropInterval{zero_lo, zero_hi, static_cast<std::int8_t>(zero_sl),
                        static_cast<std::int8_t>(zero_sr)});
    }
  }

  void emit(const CropInterval& iv) {
    if (stopped_) return;
    if (all_) all_->push_back(iv);
    if (iv.is_event()) {
      assert(result_.count < kN);
      if (result_.count < kN) result_.events[result_.count++] = iv;
      stopped_ = stop_sign_ != 0 && iv.sign_right == stop_sign_ && iv.rho > stop_after_;
    } else {
      ++result_.turbulent_count;
    }
  }

  static constexpr double kInf = std::numeric_limits<double>::infinity();

  Certificate f_;
  Grid grid_;
  CropStats* stats_;
  std::vector<CropInterval>* all_;
  CropResult& result_;
  Time stop_after_ = 0.0;
  int stop_sign_ = 0;  ///< 0: the whole window
  bool stopped_ = false;
};

/// f = upper - lower when it is linear: f(t) = D0 + D1 (t - origin) exactly, known through
/// approximations d0, d1 with rigorous bounds r0 >= |d0 - D0|, r1 >= |d1 - D1|. The Frame above
/// specialised to the hot path of kinetic sorting (two motions of degree <= 1, or congruent
/// parabolas, whose squares cancel: D2 = 0 exactly), unrolled, with the same error analysis.
struct Line {
  double origin = 0.0, d0 = 0.0, d1 = 0.0, r0 = 0.0, r1 = 0.0;

  /// d = x - y rounded, r = |its rounding error| (TwoSum, exact), as in Frame.
  static void difference(double x, double y, double& d, double& r) {
    double e = 0.0;
    numeric::two_sum(x, -y, d, e);
    r = std::fabs(e);
  }

  /// Two motions of degree <= 1 (the degree of a constant motion is 0 and its c[1] is not read).
  static Line of_linear(const MotionPolynomial& u, const MotionPolynomial& l) {
    Line f;
    const double u0 = u.c[0], l0 = l.c[0];
    const double u1 = u.degree == 1 ? u.c[1] : 0.0, l1 = l.degree == 1 ? l.c[1] : 0.0;
    // D1 = u1 - l1 whatever the origins (moving an origin keeps the leading coefficient).
    difference(u1, l1, f.d1, f.r1);
    if (u.origin == l.origin || l.degree == 0 || u.degree == 0) {
      // As Frame: one frame for both, coefficient differences with their exact rounding errors.
      f.origin = u.degree == 0 ? l.origin : u.origin;
      difference(u0, l0, f.d0, f.r0);
      return f;
    }
    // Different origins: upper shifted to lower's origin, h = fl(o_l - o_u): Frame's synthetic
    // division and bound for n = 1, (4n + 6) u (M_0 + |l_0|) (1 + 1e-10) + (2n + 2) DBL_MIN
    // max(1, |h|)^n (1 + 1e-10), with M_0 = |u_0| + |h| |u_1|.
    f.origin = l.origin;
    const double h = l.origin - u.origin;
    const double ah = std::fabs(h);
    const double q0 = u0 + h * u1;
    const double m0 = std::fabs(u0) + ah * std::fabs(u1);
    const double growth = std::max(1.0, ah) * (1.0 + 1e-10);
    f.d0 = q0 - l0;
    f.r0 = 10.0 * 0x1p-53 * (m0 + std::fabs(l0)) * (1.0 + 1e-10) + 4.0 * DBL_MIN * growth;
    return f;
  }

  /// Two parabolas with the same leading coefficient A = u.c[2] = l.c[2] (degree 2 both).
  static Line of_congruent(const MotionPolynomial& u, const MotionPolynomial& l) {
    Line f;
    if (u.origin == l.origin) {
      // The squares cancel exactly: D0 = u0 - l0, D1 = u1 - l1.
      f.origin = u.origin;
      difference(u.c[0], l.c[0], f.d0, f.r0);
      difference(u.c[1], l.c[1], f.d1, f.r1);
      return f;
    }
    // Frame's Taylor shift of upper to h = fl(o_l - o_u) for n = 2, unrolled (the same operations
    // in the same order), and its bound (4n + 6) u (M_k + |l_k|) (1 + 1e-10) + (2n + 2) DBL_MIN
    // max(1, |h|)^n (1 + 1e-10). The shifted leading coefficient is A exactly, so D2 = 0.
    f.origin = l.origin;
    const double h = l.origin - u.origin;
    const double ah = std::fabs(h);
    const double a = u.c[2], aa = std::fabs(a);
    double q1 = u.c[1] + h * a;
    double m1 = std::fabs(u.c[1]) + ah * aa;
    const double q0 = u.c[0] + h * q1;
    const double m0 = std::fabs(u.c[0]) + ah * m1;
    q1 = q1 + h * a;
    m1 = m1 + ah * aa;
    const double big = std::max(1.0, ah);
    const double growth = (1.0 + 1e-10) * big * big;
    const double under = 6.0 * DBL_MIN * growth;
    f.d0 = q0 - l.c[0];
    f.r0 = 14.0 * 0x1p-53 * (m0 + std::fabs(l.c[0])) * (1.0 + 1e-10) + under;
    f.d1 = q1 - l.c[1];
    f.r1 = 14.0 * 0x1p-53 * (m1 + std::fabs(l.c[1])) * (1.0 + 1e-10) + under;
    return f;
  }

  /// The sign of f(t) when certain, 0 otherwise: Frame::sign_n<1> (Horner of degree 1 at
  /// s = fl(t - origin), (4n + 4) u sum |d_k||s|^k + sum r_k |s|^k, times 1 + 1e-10, plus
  /// (3n + 3) DBL_MIN max(1, |s|)^n (1 + 1e-10), n = 1).
  [[nodiscard]] int filtered_sign(double t) const {
    const double s = t - origin;
    const double as = std::fabs(s);
    const double v = d1 * s + d0;
    const double m = std::fabs(d1) * as + std::fabs(d0);
    const double e = r1 * as + r0;
    const double growth = (1.0 + 1e-10) * std::max(1.0, as);
    const double error = (8.0 * 0x1p-53 * m + e) * (1.0 + 1e-10) + 6.0 * DBL_MIN * growth;
    if (v > error) return 1;
    if (v < -error) return -1;
    return 0;
  }
};

/// The hot path of kinetic sorting: f = upper - lower linear (`f`), with the exact sign of its
/// slope known (`slope`, 0 when f is a constant): two motions of degree <= 1, or congruent
/// parabolas. The same decisions as Cropper's linear fast path (a guessed cell verified by exact
/// signs, a window end with the sign beyond the root), without building a Cropper. Returns false,
/// with `out` untouched, when it cannot finish (f vanishes at a grid point it looks at, or the
/// guess misses a root inside the window); the general code then starts afresh.
template <class Out>
bool crop_linear(const MotionPolynomial& u, const MotionPolynomial& l, const Line& f, int slope,
                 Time lo, Time hi, double eps, CropStats* stats, std::vector<CropInterval>* all,
                 Out& out) {
  const Grid grid = Grid::for_eps(eps);
  const std::int64_t ja = grid.floor_index(lo);
  std::int64_t jb = grid.floor_index(hi);
  if (grid.at(jb) < hi || jb == ja) ++jb;
  const double a = grid.at(ja), b = grid.at(jb);
  // Exact signs: the filter, then the predicates (their filter, compensated Horner, GMP).
  auto sign = [&](double t) {
    const int s = f.filtered_sign(t);
    if (s != 0) {
      if (stats) ++stats->predicates.filtered;
      return s;
    }
    return compare_at(u, l, t, stats ? &stats->predicates : nullptr);
  };
  int beyond = 0;  // the sign of f all over the window when it has no root there
  int s0 = 2, s1 = 2;
  std::int64_t j = ja;
  if (slope == 0) {
    beyond = sign(a);  // f is a constant
    if (beyond == 0) return false;
  } else {
    // The root of the approximate line (a guess: every use is verified by exact signs).
    const double r = f.origin - f.d0 / f.d1;
    if (r > a) j = r < b ? std::min(grid.floor_index(r), jb - 1) : jb - 1;
    beyond = sign_beyond_window(j, ja, jb, slope, a, b, sign, s0, s1);
  }
  if (beyond != 0) {
    out.window_lo = a;
    out.window_hi = b;
    out.sign_first = beyond;
    if (stats) ++stats->fast_path;
    return true;
  }
  const double x0 = grid.at(j), x1 = grid.at(j + 1);
  if (s0 == 2) s0 = sign(x0);
  if (s0 != -slope) return false;
  if (s1 == 2) s1 = sign(x1);
  if (s1 != slope) return false;
  const CropInterval cell{x0, x1, static_cast<std::int8_t>(s0), static_cast<std::int8_t>(s1)};
  out.window_lo = a;
  out.window_hi = b;
  out.sign_first = s0;
  out.events[0] = cell;
  out.count = 1;
  if (all) all->push_back(cell);
  if (stats) ++stats->fast_path;
  return true;
}

}  // namespace

Time crop_grid_floor(Time t, double eps) {
  const Grid grid = Grid::for_eps(eps);
  return grid.at(grid.floor_index(t));
}

double crop_grid_width(double eps) {
  assert(eps > 0.0 && std::isfinite(eps));
  if (eps >= DBL_MIN) {
    // A normal eps: clearing its significand bits leaves the power of two 2^floor(log2 eps).
    return std::bit_cast<double>(std::bit_cast<std::uint64_t>(eps) & 0xfff0000000000000ULL);
  }
  int exponent = 0;
  const double mantissa = std::frexp(eps, &exponent);  // eps = mantissa * 2^exponent, [0.5, 1)
  (void)mantissa;
  return std::ldexp(1.0, exponent - 1);  // 2^(exponent-1) <= eps < 2^exponent
}

bool crop_precision_supported(double eps, Time lo, Time hi) {
  if (!(eps > 0.0) || !std::isfinite(eps) || !std::isfinite(lo) || !std::isfinite(hi)) return false;
  const double w = crop_grid_width(eps);
  const double m = std::max(std::fabs(lo), std::fabs(hi)) + 4.0 * w;
  const double ulp = std::nextafter(m, kTimeInfinity) - m;
  // A root exactly on a grid point gets the interval (pred g, succ g), widened over neighbouring
  // doubles that are roots too: at most kMaxMotionDegree + 1 ulps, which must stay <= w.
  return w >= (kMaxMotionDegree + 2) * ulp && m < 0x1p52 * w;
}

namespace {

/// The paths of crop() that need no Cropper. Writes the result into `out` and returns kDone, or
/// kZero (upper == lower: the caller writes the identically-zero result), or kGeneral with `out`
/// untouched (the general code then starts afresh).
enum class Route { kDone, kZero, kGeneral };

/// The intervals a lean path found, kept until it finishes: nothing is written to the result
/// before that, so that it can still hand the call to the general code.
struct LeanCells {
  std::array<CropInterval, 3> cells{};
  int n = 0;
  void add(double lambda, double rho, int sl, int sr) {
    cells[n++] =
        CropInterval{lambda, rho, static_cast<std::int8_t>(sl), static_cast<std::int8_t>(sr)};
  }
};

/// Writes a lean path's result, as Cropper::emit() would, in ascending order.
template <class Out>
void write_lean(Out& out, double a, double b, int sign_first, const LeanCells& found,
                CropStats* stats, std::vector<CropInterval>* all) {
  out.window_lo = a;
  out.window_hi = b;
  out.sign_first = sign_first;
  for (int i = 0; i < found.n; ++i) {
    const CropInterval& iv = found.cells[i];
    if (all) all->push_back(iv);
    if (iv.is_event()) {
      out.events[out.count++] = iv;
    } else {
      ++out.turbulent_count;
    }
  }
  if (stats) ++stats->fast_path;
}

/// Cropper::quadratic_path() without a Cropper (degree exactly 2, sigma = the exact sign of the
/// leading coefficient of f): the same decisions (docs/crop.md, step 4), so the same result.
/// Returns false, with `out` untouched, where the Cropper would bisect (a guess that misses) or
/// finds f zero at a grid point it looks at: the general code then starts afresh.
template <class Out>
bool crop_quadratic(const MotionPolynomial& u, const MotionPolynomial& l, int sigma, Time lo,
                    Time hi, double eps, CropStats* stats, std::vector<CropInterval>* all,
                    Out& out) {
  const Certificate f(u, l, stats);
  const Grid grid = Grid::for_eps(eps);
  const std::int64_t ja = grid.floor_index(lo);
  std::int64_t jb = grid.floor_index(hi);
  if (grid.at(jb) < hi || jb == ja) ++jb;
  const double a = grid.at(ja), b = grid.at(jb);
  const Frame& fr = f.frame();
  // Guesses (floating point, verified): the vertex and the two roots.
  const auto [vertex, root_lo, root_hi] = fr.quadratic_guess_points();
  // Exact signs of f at grid points of the window: the window-wide filter, then
  // Certificate::sign() (the pointwise filter, then the predicates).
  const Frame::WindowFilter2 window_filter(fr, a, b);
  auto sign = [&](double t) {
    const int v = window_filter.sign(t);
    if (v != 0) {
      if (stats) ++stats->predicates.filtered;
      return v;
    }
    return f.sign(t);
  };
  // The grid cell holding a guess r in [x, y] (grid points at indices jx < jy).
  auto cell_of = [&](double r, std::int64_t jx, std::int64_t jy) {
    return std::clamp(grid.floor_index(std::clamp(r, grid.at(jx), grid.at(jy))), jx, jy - 1);
  };
  LeanCells found;
  const bool vertex_inside = vertex >= a && vertex < b;
  if (vertex_inside) {
    // Cropper::quadratic_guesses(): two verified sign changes account for both roots; one with
    // different signs at the window's ends is the only root inside.
    std::int64_t next_free = ja;
    for (const double r : {root_lo, root_hi}) {
      if (!(r >= a && r <= b)) continue;
      const std::int64_t j = std::clamp(grid.floor_index(r), ja, jb - 1);
      if (j < next_free) continue;
      const double x0 = grid.at(j), x1 = grid.at(j + 1);
      const int s0 = sign(x0);
      const int s1 = sign(x1);
      if (s0 == 0 || s1 == 0 || s0 == s1) continue;
      found.add(x0, x1, s0, s1);
      next_free = j + 1;
    }
    if (found.n == 2) {
      write_lean(out, a, b, found.cells[0].sign_left, found, stats, all);
      return true;
    }
    if (found.n == 1) {
      const CropInterval& c = found.cells[0];
      const int sa = c.lambda == a ? c.sign_left : sign(a);
      const int sb = c.rho == b ? c.sign_right : sign(b);
      if (sa != 0 && sb != 0 && sa != sb) {
        write_lean(out, a, b, c.sign_left, found, stats, all);
        return true;
      }
    }
    found.n = 0;
  }
  // The derivative split: k = the largest grid index with g'(at(k)) <= 0, g = sigma f, from the
  // vertex guess (the Cropper bisects when it misses: not here).
  auto gd = [&](std::int64_t j) { return sigma * f.derivative_sign(grid.at(j)); };
  std::int64_t k = 0;
  if (!(vertex >= a)) {
    k = ja - 1;
    if (!(gd(ja) > 0)) return false;
  } else if (!(vertex < b)) {
    k = jb;
    if (!(gd(jb) <= 0)) return false;
  } else {
    k = std::clamp(grid.floor_index(vertex), ja, jb - 1);
    if (!(gd(k) <= 0 && gd(k + 1) > 0)) return false;
  }
  // A monotone piece [at(x), at(y)] whose end signs sx != sy are known (exactly one root in
  // it): its cell, from the guess r, verified by exact signs (Cropper::locate() without the
  // bisection).
  auto locate = [&](std::int64_t jx, std::int64_t jy, int sx, int sy, double r) {
    if (jy - jx == 1) {
      found.add(grid.at(jx), grid.at(jy), sx, sy);
      return true;
    }
    if (!std::isfinite(r)) return false;
    const std::int64_t j = cell_of(r, jx, jy);
    const double x0 = grid.at(j), x1 = grid.at(j + 1);
    const int s0 = j == jx ? sx : sign(x0);
    if (s0 != sx) return false;
    const int s1 = j + 1 == jy ? sy : sign(x1);
    if (s1 != sy) return false;
    found.add(x0, x1, s0, s1);
    return true;
  };
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  if (k < ja || k >= jb) {
    // Cropper::monotone(): f strictly monotone on the window, rising (slope = +1) or falling.
    const int slope = k < ja ? sigma : -sigma;
    double r = k < ja ? root_hi : root_lo;
    if (std::isnan(r)) r = k < ja ? -kInfinity : kInfinity;
    const std::int64_t j = std::isnan(r) ? ja : cell_of(r, ja, jb);
    int s0 = 2, s1 = 2;  // 2: not evaluated
    // The sign of f all over the window when the root is outside it.
    const int beyond = sign_beyond_window(j, ja, jb, slope, a, b, sign, s0, s1);
    if (beyond != 0) {
      write_lean(out, a, b, beyond, found, stats, all);
      return true;
    }
    const double x0 = grid.at(j), x1 = grid.at(j + 1);
    if (s0 == 2) s0 = sign(x0);
    if (s1 == 2 && s0 == -slope) s1 = sign(x1);
    if (s0 == -slope && s1 == slope) {
      found.add(x0, x1, s0, s1);
      write_lean(out, a, b, -slope, found, stats, all);
      return true;
    }
    // The guess missed: the signs at the window's ends, and a located root.
    const int sa = j == ja && s0 != 2 ? s0 : sign(a);
    const int sb = j + 1 == jb && s1 != 2 ? s1 : sign(b);
    if (sa == 0 || sb == 0) return false;
    if (sa != sb && !locate(ja, jb, sa, sb, r)) return false;
    write_lean(out, a, b, sa, found, stats, all);
    return true;
  }
  // Cropper::split(): ja <= k < jb.
  const int sl = sign(grid.at(k));
  const int sr = sign(grid.at(k + 1));
  if (sl == 0 || sr == 0) return false;
  int sa = sl, sb = sr;  // the signs at the window's ends, when implied
  bool left_root = false, right_root = false;
  if (k > ja && sigma * sl < 0) {
    sa = sign(a);
    if (sa == 0) return false;
    left_root = sa != sl;
  }
  if (k + 1 < jb && sigma * sr < 0) {
    sb = sign(b);
    if (sb == 0) return false;
    right_root = sb != sr;
  }
  const double vertex_guess = 0.5 * grid.at(k) + 0.5 * grid.at(k + 1);
  if (left_root && !locate(ja, k, sa, sl, std::isfinite(root_lo) ? root_lo : vertex_guess))
    return false;
  if (sl != sr || (sigma * sl > 0 && f.discriminant_sign() >= 0))
    found.add(grid.at(k), grid.at(k + 1), sl, sr);
  if (right_root && !locate(k + 1, jb, sr, sb, std::isfinite(root_hi) ? root_hi : vertex_guess))
    return false;
  write_lean(out, a, b, sa, found, stats, all);
  return true;
}

template <class Out>
Route crop_lean(const MotionPolynomial& upper, const MotionPolynomial& lower, Time lo, Time hi,
                double eps, CropStats* stats, std::vector<CropInterval>* all, Out& out) {
  if (upper.degree <= 1 && lower.degree <= 1) {
    const double u1 = upper.degree == 1 ? upper.c[1] : 0.0;
    const double l1 = lower.degree == 1 ? lower.c[1] : 0.0;
    const int slope = (u1 > l1) - (u1 < l1);
    // A non-zero slope tells the motions apart: the comparison is needed for constants only.
    if (slope == 0 && upper == lower) return Route::kZero;
    return crop_linear(upper, lower, Line::of_linear(upper, lower), slope, lo, hi, eps, stats, all,
                       out)
               ? Route::kDone
               : Route::kGeneral;
  }
  if (upper.degree == 2 && lower.degree == 2 && upper.c[2] == lower.c[2]) {
    // Congruent parabolas (the paper's PARABOLA): f is linear with slope
    // D1 = c1 - c1 + 2 c2 (o_l - o_u): its sign by comparisons when c1 == c1, else enclosed;
    // 0 (f constant) exactly when both terms are.
    const bool same_c1 = upper.c[1] == lower.c[1];
    int slope = 0;
    if (same_c1) {
      const int sign_h = (lower.origin > upper.origin) - (lower.origin < upper.origin);
      slope = upper.c[2] > 0.0 ? sign_h : -sign_h;
    } else {
      const Interval slope_iv =
          exact_difference(upper.c[1], lower.c[1]) +
          Interval::point(2.0 * upper.c[2]) * exact_difference(lower.origin, upper.origin);
      slope = slope_iv.sign();
    }
    const bool constant = same_c1 && upper.origin == lower.origin;
    if (constant && upper == lower) return Route::kZero;
    if (slope == 0 && !constant) return Route::kGeneral;
    return crop_linear(upper, lower, Line::of_congruent(upper, lower), slope, lo, hi, eps, stats,
                       all, out)
               ? Route::kDone
               : Route::kGeneral;
  }
  if (upper.degree <= 2 && lower.degree <= 2) {
    // Degree exactly 2 when the leading coefficients differ (equal ones were handled above).
    const double u2 = upper.degree == 2 ? upper.c[2] : 0.0;
    const double l2 = lower.degree == 2 ? lower.c[2] : 0.0;
    if (u2 != l2) {
      return crop_quadratic(upper, lower, u2 > l2 ? 1 : -1, lo, hi, eps, stats, all, out)
                 ? Route::kDone
                 : Route::kGeneral;
    }
  }
  return upper == lower ? Route::kZero : Route::kGeneral;
}

/// The general code: identically zero, or a Cropper.
void crop_general(Route route, const MotionPolynomial& upper, const MotionPolynomial& lower,
                  Time lo, Time hi, double eps, CropStats* stats, std::vector<CropInterval>* all,
                  CropResult& result) {
  if (route == Route::kZero) {
    result.identically_zero = true;
    result.window_lo = lo;
    result.window_hi = hi;
    return;
  }
  Cropper cropper(upper, lower, eps, stats, all, result);
  cropper.run(lo, hi);
}

/// The result of crop_lean() on its own: at most two event intervals (degree <= 2), never
/// identically zero.
struct LeanResult {
  std::array<CropInterval, 2> events{};
  int count = 0;
  int turbulent_count = 0;
  int sign_first = 0;
  bool identically_zero = false;
  Time window_lo = 0.0, window_hi = 0.0;
};

/// EVENTTIME over any result type with the fields of CropResult.
template <class R>
Time event_time_of(const R& r, Time t_curr) {
  if (r.identically_zero) return kTimeInfinity;
  int last = 0;
  while (last < r.count && r.events[last].rho <= t_curr) ++last;
  const int chi = last == 0 ? r.sign_first : r.events[last - 1].sign_right;
  if (chi < 0) return last == 0 ? r.window_lo : r.events[last - 1].rho;
  return last < r.count ? r.events[last].rho : kTimeInfinity;
}

}  // namespace

CropResult crop(const MotionPolynomial& upper, const MotionPolynomial& lower, Time lo, Time hi,
                double eps, CropStats* stats, std::vector<CropInterval>* all_intervals) {
  assert(lo <= hi && std::isfinite(lo) && std::isfinite(hi));
  assert(crop_precision_supported(eps, lo, hi));
  if (stats) ++stats->calls;
  CropResult result;  // the one object every path returns (no copies)
  const Route route = crop_lean(upper, lower, lo, hi, eps, stats, all_intervals, result);
  if (route != Route::kDone)
    crop_general(route, upper, lower, lo, hi, eps, stats, all_intervals, result);
  return result;
}

Time crop_event_time(const MotionPolynomial& upper, const MotionPolynomial& lower, Time lo, Time hi,
                     double eps, Time t_curr, CropStats* stats) {
  assert(lo <= hi && std::isfinite(lo) && std::isfinite(hi));
  assert(crop_precision_supported(eps, lo, hi));
  if (stats) ++stats->calls;
  // The same steps as crop(), only the result of the lean paths is kept in a smaller object.
  LeanResult lean;
  const Route route = crop_lean(upper, lower, lo, hi, eps, stats, nullptr, lean);
  if (route == Route::kDone) return event_time_of(lean, t_curr);
  CropResult result;
  crop_general(route, upper, lower, lo, hi, eps, stats, nullptr, result);
  return event_time_of(result, t_curr);
}

namespace {

CropResult crop_terms(const Terms& f, Time lo, Time hi, double eps, CropStats* stats,
                      std::vector<CropInterval>* all_intervals) {
  assert(lo <= hi && std::isfinite(lo) && std::isfinite(hi));
  assert(crop_precision_supported(eps, lo, hi));
  if (stats) ++stats->calls;
  CropResult result;
  Cropper cropper(f, eps, stats, all_intervals, result);
  cropper.run(lo, hi);
  return result;
}

int sign_at_terms(const Terms& f, Time t, PredicateStats* stats) {
  CropStats local;
  const Certificate c(f, &local);
  const int s = c.sign(t);
  if (stats) {
    stats->filtered += local.predicates.filtered;
    stats->exact += local.predicates.exact;
  }
  return s;
}

int sign_after_terms(const Terms& f, Time t, PredicateStats* stats) {
  const int s = sign_at_terms(f, t, stats);
  if (s != 0) return s;
  // f(t) = 0: the sign of the first non-zero Taylor coefficient at t, exactly.
  if (stats) ++stats->exact;
  const std::array<Dyadic, kN + 1> q = f.exact(t);
  for (int k = 1; k <= kN; ++k) {
    if (q[k].m != 0) return sgn(q[k].m);
  }
  return 0;
}

}  // namespace

CropResult crop(const MotionCombination& f, Time lo, Time hi, double eps, CropStats* stats,
                std::vector<CropInterval>* all_intervals) {
  assert(f.plus[0] && f.plus[1] && f.minus[0] && f.minus[1]);
  return crop_terms(Terms(f), lo, hi, eps, stats, all_intervals);
}

Time crop_event_time(const MotionCombination& f, Time lo, Time hi, double eps, Time t_curr,
                     CropStats* stats) {
  return event_time_of(crop(f, lo, hi, eps, stats), t_curr);
}

std::optional<int> constant_sign(const MotionCombination& f) {
  if (f.plus[0]->degree != 0 || f.plus[1]->degree != 0 || f.minus[0]->degree != 0 ||
      f.minus[1]->degree != 0) {
    return std::nullopt;
  }
  return exact_sum_sign(f.plus[0]->c[0], f.plus[1]->c[0], f.minus[0]->c[0], f.minus[1]->c[0]);
}

namespace {

/// sign(f(t)) when a floating-point filter certifies it, 0 otherwise: the four motions evaluated
/// on their own, each within its rigorous bound (numeric::filtered_value), and summed
/// (numeric::sum_sign). No Taylor shift, no intervals: most comparisons of a structure's
/// certificates at a time (box sides, coordinates) are far from 0 and end here.
int filtered_sign_at(const MotionCombination& f, Time t) {
  using numeric::filtered_value;
  return numeric::sum_sign(filtered_value(*f.plus[0], t), filtered_value(*f.plus[1], t),
                           filtered_value(*f.minus[0], t), filtered_value(*f.minus[1], t));
}

/// sign(f(t)) when decided without the exact path: f constant (its exact sign, 0 included) or
/// the filter's certain sign; nullopt otherwise. A nonzero sign at t holds just after t too.
std::optional<int> cheap_sign_at(const MotionCombination& f, Time t, PredicateStats* stats) {
  std::optional<int> s = constant_sign(f);
  if (!s) {
    if (const int x = filtered_sign_at(f, t); x != 0) s = x;
  }
  if (s && stats != nullptr) ++stats->filtered;
  return s;
}

}  // namespace

int sign_at(const MotionCombination& f, Time t, PredicateStats* stats) {
  if (const std::optional<int> s = cheap_sign_at(f, t, stats)) return *s;
  return sign_at_terms(Terms(f), t, stats);
}

int sign_after(const MotionCombination& f, Time t, PredicateStats* stats) {
  if (const std::optional<int> s = cheap_sign_at(f, t, stats)) return *s;
  return sign_after_terms(Terms(f), t, stats);
}

int ProductCombination::degree_bound() const {
  const auto deg = [](const MotionPolynomial* a, const MotionPolynomial* b) {
    return std::max(a->degree, b->degree);
  };
  return std::max(deg(plus[0], plus[1]) + deg(plus[2], plus[3]),
                  deg(minus[0], minus[1]) + deg(minus[2], minus[3]));
}

ProductCombination orientation(const MotionPolynomial& ax, const MotionPolynomial& ay,
                               const MotionPolynomial& bx, const MotionPolynomial& by,
                               const MotionPolynomial& cx, const MotionPolynomial& cy) {
  // (x_b - x_a)(y_c - y_a) - (y_b - y_a)(x_c - x_a)
  return ProductCombination{{&bx, &ax, &cy, &ay}, {&by, &ay, &cx, &ax}};
}

CropResult crop(const ProductCombination& f, Time lo, Time hi, double eps, CropStats* stats,
                std::vector<CropInterval>* all_intervals) {
  assert(f.degree_bound() <= kMaxMotionDegree);
  return crop_terms(Terms(f), lo, hi, eps, stats, all_intervals);
}

Time crop_event_time(const ProductCombination& f, Time lo, Time hi, double eps, Time t_curr,
                     CropStats* stats) {
  return event_time_of(crop(f, lo, hi, eps, stats), t_curr);
}

namespace {

/// An enclosure of a(t) - b(t): one Horner evaluation of the difference when the origins agree,
/// else two, each with evaluate_filtered()'s rigorous bound, widened outward.
numeric::Interval difference_at(const MotionPolynomial& a, const MotionPolynomial& b, Time t) {
  if (a.origin == b.origin) {
    const FilteredValue d = evaluate_difference_filtered(a, b, t);
    return numeric::around(d.value, d.error);
  }
  const FilteredValue x = evaluate_filtered(a, t), y = evaluate_filtered(b, t);
  return numeric::around(x.value, x.error) - numeric::around(y.value, y.error);
}

/// The sign of f(t) when enclosures of its four factors at t decide it, else 0 (a non-finite
/// end compares false and leaves it undecided). The first stage of sign_at: no frame, no Taylor
/// shift, a few Horner evaluations.
int filtered_sign_at(const ProductCombination& f, Time t) {
  const auto factor = [&](const std::array<const MotionPolynomial*, 4>& m, int k) {
    return difference_at(*m[2 * k], *m[2 * k + 1], t);
  };
  const numeric::Interval plus = factor(f.plus, 0) * factor(f.plus, 1);
  const numeric::Interval minus = factor(f.minus, 0) * factor(f.minus, 1);
  return (plus - minus).sign();
}

}  // namespace

namespace {
/// The largest k with out[k] != 0 (0 when none).
int top_nonzero(const std::array<double, kMaxMotionDegree + 1>& out) {
  int degree = 0;
  for (int k = 0; k <= kMaxMotionDegree; ++k) {
    if (out[static_cast<std::size_t>(k)] != 0.0) degree = k;
  }
  return degree;
}
}  // namespace

int approximate_taylor(const ProductCombination& f, Time t,
                       std::array<double, kMaxMotionDegree + 1>& out) {
  Terms(f).approximate(t, out);
  return top_nonzero(out);
}

int ProductSum::degree_bound() const {
  int d = 0;
  for (int k = 0; k < count; ++k) {
    const auto& f = factors[static_cast<std::size_t>(k)];
    d = std::max(d, std::max(f[0]->degree, f[1]->degree) + std::max(f[2]->degree, f[3]->degree));
  }
  return d;
}

namespace {
/// The sign of f(t) when enclosures of its factors at t decide it, else 0 (filtered_sign_at of a
/// ProductCombination, for any number of products).
int filtered_sign_at(const ProductSum& f, Time t) {
  numeric::Interval sum = numeric::Interval::point(0.0);
  for (int k = 0; k < f.count; ++k) {
    const auto& m = f.factors[static_cast<std::size_t>(k)];
    const numeric::Interval p = difference_at(*m[0], *m[1], t) * difference_at(*m[2], *m[3], t);
    sum = k % 2 == 0 ? sum + p : sum - p;
  }
  return sum.sign();
}
}  // namespace

Time crop_first_failure(const InCircle& f, int holding, Time lo, Time hi, double eps, Time t_curr,
                        CropStats* stats) {
  detail::BoundedTaylor at_lo;
  const bool bounded = detail::incircle_of_lines_at(f, lo, at_lo);
  return detail::crop_first_failure(f, bounded ? &at_lo : nullptr, holding, lo, hi, eps, t_curr,
                                    stats);
}

namespace detail {

Time crop_first_failure(const InCircle& f, const BoundedTaylor* at_lo, int holding, Time lo,
                        Time hi, double eps, Time t_curr, CropStats* stats) {
  assert(holding == 1 || holding == -1);
  assert(lo <= hi && std::isfinite(lo) && std::isfinite(hi));
  assert(crop_precision_supported(eps, lo, hi));
  if (stats) ++stats->calls;
  const Grid grid = Grid::for_eps(eps);
  if (at_lo != nullptr) {
    // The window's cells as Cropper::run() takes them; lo is a grid point.
    const std::int64_t ja = grid.floor_index(lo);
    std::int64_t jb = grid.floor_index(hi);
    if (grid.at(jb) < hi || jb == ja) ++jb;
    if (grid.at(ja) == lo && lo <= t_curr && t_curr < grid.at(ja + 1)) {
      std::uint64_t boxes = 0;
      const std::optional<Time> first =
          first_failure_on_grid(*at_lo, holding, lo, grid.w, jb - ja, &boxes);
      if (stats) stats->bernstein_boxes += boxes;
      if (first) {
        if (stats) ++stats->bounded_float;
        return *first;
      }
    }
  }
  CropResult result;
  Terms terms(f);
  terms.origin_at = lo;  // the frame where the search starts
  Cropper cropper(terms, eps, stats, nullptr, result);
  cropper.stop_at_first(t_curr, -holding);
  cropper.run(lo, hi);
  return event_time(holding > 0 ? result : negated(result), t_curr);
}

}  // namespace detail

CropResult crop(const InCircle& f, Time lo, Time hi, double eps, CropStats* stats,
                std::vector<CropInterval>* all_intervals) {
  assert(f.degree_bound() <= kMaxMotionDegree);
  return crop_terms(Terms(f), lo, hi, eps, stats, all_intervals);
}

int approximate_taylor(const InCircle& f, Time t, std::array<double, kMaxMotionDegree + 1>& out) {
  Terms(f).approximate(t, out);
  return top_nonzero(out);
}

CropResult crop(const ProductSum& f, Time lo, Time hi, double eps, CropStats* stats,
                std::vector<CropInterval>* all_intervals) {
  assert(f.degree_bound() <= kMaxMotionDegree);
  return crop_terms(Terms(f), lo, hi, eps, stats, all_intervals);
}

namespace {

/// sign_at (after = false) or sign_after of a product certificate: its factors' enclosures at t
/// first (filtered_sign_at), then its terms exactly.
template <class F>
int filtered_then_exact(const F& f, Time t, PredicateStats* stats, bool after) {
  assert(f.degree_bound() <= kMaxMotionDegree);
  if (const int s = filtered_sign_at(f, t); s != 0) {
    if (stats) ++stats->filtered;
    return s;
  }
  return after ? sign_after_terms(Terms(f), t, stats) : sign_at_terms(Terms(f), t, stats);
}

}  // namespace

int sign_at(const ProductCombination& f, Time t, PredicateStats* stats) {
  return filtered_then_exact(f, t, stats, false);
}
int sign_after(const ProductCombination& f, Time t, PredicateStats* stats) {
  return filtered_then_exact(f, t, stats, true);
}
int sign_at(const ProductSum& f, Time t, PredicateStats* stats) {
  return filtered_then_exact(f, t, stats, false);
}
int sign_after(const ProductSum& f, Time t, PredicateStats* stats) {
  return filtered_then_exact(f, t, stats, true);
}

int approximate_taylor(const ProductSum& f, Time t, std::array<double, kMaxMotionDegree + 1>& out) {
  Terms(f).approximate(t, out);
  return top_nonzero(out);
}

CropResult negated(const CropResult& r) {
  CropResult out = r;
  out.sign_first = -r.sign_first;
  for (int i = 0; i < r.count; ++i) {
    out.events[i].sign_left = static_cast<std::int8_t>(-r.events[i].sign_left);
    out.events[i].sign_right = static_cast<std::int8_t>(-r.events[i].sign_right);
  }
  return out;
}

}  // namespace kinetic

namespace kinetic {

int pretended_sign(const CropResult& r, Time t_curr) {
  int last = 0;
  while (last < r.count && r.events[last].rho <= t_curr) ++last;
  return last == 0 ? r.sign_first : r.events[last - 1].sign_right;
}

Time event_time(const CropResult& r, Time t_curr) { return event_time_of(r, t_curr); }

Time last_root_before(const MotionPolynomial& upper, const MotionPolynomial& lower, Time rho,
                      double span, double tolerance) {
  Time a = rho - span, b = rho;
  const int sb = compare_at(upper, lower, b);
  if (sb == 0) return b;
  if (compare_at(upper, lower, a) == sb) return rho;
  // Invariant: sign(a) != sign(b) = sb; keep the right-most sign change reachable by bisection.
  while (b - a > tolerance) {
    const Time mid = a + (b - a) * 0.5;
    if (mid <= a || mid >= b) break;
    const int s = compare_at(upper, lower, mid);
    if (s == 0) return mid;
    if (s == sb) {
      b = mid;
    } else {
      a = mid;
    }
  }
  return a + (b - a) * 0.5;
}

}  // namespace kinetic
