#include "kinetic/core/predicates.hpp"

#include <gmpxx.h>

#include <algorithm>
#include <array>
#include <cassert>
#include <cfloat>
#include <cmath>
#include <cstdint>

#include "core/numeric/dyadic.hpp"
#include "core/numeric/interval.hpp"
#include "core/numeric/linear_filter.hpp"
#include "core/numeric/taylor_shift.hpp"
#include "kinetic/core/float_roots.hpp"
#include "kinetic/core/gmp_work.hpp"

namespace kinetic {
namespace {

// mpq_class from a double is exact: every finite double is a dyadic rational.
mpq_class exact(double v) {
  note_gmp_work();
  return mpq_class(v);
}

/// Exact Taylor coefficients of p at t: p(t + h) = sum_k out[k] h^k.
void exact_taylor(const MotionPolynomial& p, Time t,
                  std::array<mpq_class, kMaxMotionDegree + 1>& out) {
  const mpq_class s = exact(t) - exact(p.origin);
  for (int k = 0; k <= kMaxMotionDegree; ++k) out[k] = 0;
  for (int i = 0; i <= p.degree; ++i) out[i] = exact(p.c[i]);
  numeric::taylor_shift(out, p.degree, s);  // exact in rationals
}

mpq_class exact_value(const MotionPolynomial& p, Time t) {
  const mpq_class s = exact(t) - exact(p.origin);
  mpq_class v = exact(p.c[p.degree]);
  for (int i = p.degree - 1; i >= 0; --i) v = v * s + exact(p.c[i]);
  return v;
}

int sgn_raw(mpq_srcptr v) { return mpq_sgn(v); }

// ---------------------------------------------------------------------------------------------
// The exact fallback of sign_at / compare_at (stage 3). Every double is M * 2^E with an integer
// M, |M| < 2^53, and sums and products of such numbers stay of that form: p(t) is computed
// exactly as V * 2^E with a GMP integer V (core/numeric/dyadic.hpp), without rationals (no gcd)
// and, once the thread's buffers have grown, without allocation.

/// A dyadic number V * 2^E; V is one of the scratch integers below.
struct DyadicScratch {
  mpz_t s, v, a, tmp;  // s: t - origin; v, a: values; tmp: alignment
  DyadicScratch() {
    mpz_init2(s, 256);
    mpz_init2(v, 512);
    mpz_init2(a, 512);
    mpz_init2(tmp, 512);
  }
  ~DyadicScratch() {
    mpz_clear(s);
    mpz_clear(v);
    mpz_clear(a);
    mpz_clear(tmp);
  }
  DyadicScratch(const DyadicScratch&) = delete;
  DyadicScratch& operator=(const DyadicScratch&) = delete;
};

DyadicScratch& scratch() {
  thread_local DyadicScratch s;
  return s;
}

/// v * 2^ev = p(t) exactly (Horner in dyadic integers at s = t - origin, itself exact).
void exact_dyadic_value(const MotionPolynomial& p, Time t, mpz_t v, long& ev, DyadicScratch& w) {
  std::int64_t m = 0;
  long e = 0, es = 0;
  mpz_set_ui(w.s, 0);
  numeric::dyadic_parts(t, m, e);
  numeric::dyadic_add_small(w.s, es, m, e, w.tmp);
  numeric::dyadic_parts(-p.origin, m, e);
  numeric::dyadic_add_small(w.s, es, m, e, w.tmp);
  mpz_set_ui(v, 0);
  ev = 0;
  numeric::dyadic_parts(p.c[p.degree], m, e);
  numeric::dyadic_add_small(v, ev, m, e, w.tmp);
  for (int i = p.degree - 1; i >= 0; --i) {
    mpz_mul(v, v, w.s);
    ev += es;
    numeric::dyadic_parts(p.c[i], m, e);
    numeric::dyadic_add_small(v, ev, m, e, w.tmp);
  }
  if (mpz_sgn(v) == 0) ev = 0;
}

int exact_sign(const MotionPolynomial& p, Time t) {
  DyadicScratch& w = scratch();
  long ev = 0;
  exact_dyadic_value(p, t, w.v, ev, w);
  return mpz_sgn(w.v);
}

int exact_sign_of_difference(const MotionPolynomial& a, const MotionPolynomial& b, Time t) {
  DyadicScratch& w = scratch();
  long ea = 0, eb = 0;
  exact_dyadic_value(a, t, w.a, ea, w);
  exact_dyadic_value(b, t, w.v, eb, w);
  return numeric::dyadic_difference_sign(w.a, ea, w.v, eb);
}

int sign_of_difference(const FilteredValue& a, const FilteredValue& b) {
  if (!std::isfinite(a.value) || !std::isfinite(b.value) || !std::isfinite(a.error) ||
      !std::isfinite(b.error)) {
    return 0;
  }
  const double d = a.value - b.value;
  const double unit = std::ldexp(1.0, -53);
  // fl(d) differs from a.value - b.value by at most unit * |fl(d)|; the two values differ from
  // the exact ones by at most a.error + b.error.
  const double bound =
      (a.error + b.error) * (1.0 + 4.0 * unit) + 2.0 * unit * std::fabs(d) + DBL_MIN;
  if (d > bound) return 1;
  if (d < -bound) return -1;
  return 0;
}

/// A sign decided by the cheapest test that can: the filter's (`filtered`, 0 when it cannot
/// tell), then the compensated evaluation's, then exact arithmetic; counted in stats.
template <class Compensated, class Exact>
int cheapest_sign(int filtered, Compensated&& compensated, Exact&& exact, PredicateStats* stats) {
  if (filtered != 0) {
    if (stats) ++stats->filtered;
    return filtered;
  }
  const int s = compensated();
  if (s != 0) {
    if (stats) {
      ++stats->filtered;
      ++stats->compensated;
    }
    return s;
  }
  if (stats) ++stats->exact;
  return exact();
}

}  // namespace

int sign_at(const MotionPolynomial& p, Time t, PredicateStats* stats) {
  return cheapest_sign(
      evaluate_filtered(p, t).sign_if_certain(),
      [&] { return evaluate_compensated(p, t).sign_if_certain(); },
      [&] { return exact_sign(p, t); }, stats);
}

int compare_at_value(const MotionPolynomial& p, double x, Time t, PredicateStats* stats) {
  const int s = numeric::sign_versus(evaluate_filtered(p, t), x);
  if (s != 0) return s;
  return compare_at(p, MotionPolynomial::constant(x), t, stats);
}

int compare_at(const MotionPolynomial& a, const MotionPolynomial& b, Time t,
               PredicateStats* stats) {
  // Same origin: subtract the coefficients first (tight near a crossing of two far-out
  // neighbours); otherwise bound each motion on its own.
  return cheapest_sign(
      a.origin == b.origin ? evaluate_difference_filtered(a, b, t).sign_if_certain()
                           : sign_of_difference(evaluate_filtered(a, t), evaluate_filtered(b, t)),
      [&] { return evaluate_difference_compensated(a, b, t).sign_if_certain(); },
      [&] { return exact_sign_of_difference(a, b, t); }, stats);
}

int compare_after(const MotionPolynomial& a, const MotionPolynomial& b, Time t,
                  PredicateStats* stats) {
  const int s = compare_at(a, b, t, stats);
  if (s != 0) return s;
  // a(t) == b(t) exactly: the order just after t is the sign of the first non-zero Taylor
  // coefficient of a - b at t.
  std::array<mpq_class, kMaxMotionDegree + 1> ta, tb;
  exact_taylor(a, t, ta);
  exact_taylor(b, t, tb);
  for (int k = 1; k <= kMaxMotionDegree; ++k) {
    const mpq_class d = ta[k] - tb[k];
    const int sd = sgn_raw(d.get_mpq_t());
    if (sd != 0) return sd;
  }
  return 0;
}

std::optional<Time> find_time_below(const MotionPolynomial& a, const MotionPolynomial& b, Time lo,
                                    Time hi) {
  if (compare_at(a, b, lo) < 0) return lo;
  if (std::isfinite(hi) && compare_at(a, b, hi) < 0) return hi;
  if (std::isinf(hi)) {
    // Behaviour at +infinity: the sign of the leading coefficient of a - b (exactly, via the
    // order just after a time beyond every root would need a root bound; the Taylor expansion
    // at lo gives the same leading coefficient).
    std::array<mpq_class, kMaxMotionDegree + 1> ta, tb;
    exact_taylor(a, lo, ta);
    exact_taylor(b, lo, tb);
    for (int k = kMaxMotionDegree; k >= 1; --k) {
      const mpq_class d = ta[k] - tb[k];
      const int sd = sgn_raw(d.get_mpq_t());
      if (sd == 0) continue;
      if (sd > 0) break;
      // a - b -> -infinity: walk out until the sign is certified negative.
      // Steps of at least |lo| so that t moves even when lo + 1 == lo.
      for (double step = std::max(1.0, std::fabs(lo)); std::isfinite(lo + step); step *= 2.0) {
        if (compare_at(a, b, lo + step) < 0) return lo + step;
      }
      break;
    }
  }
  // Critical points of a - b (floating point), then the exact sign there.
  std::array<double, kMaxMotionDegree + 1> diff{};
  const int degree = float_difference(a, b, diff);
  if (degree < 2) return std::nullopt;
  std::array<double, kMaxMotionDegree> deriv{};
  for (int i = 1; i <= degree; ++i) deriv[i - 1] = i * diff[i];
  std::array<FloatRoot, kMaxMotionDegree> crit{};
  const double origin = b.origin;
  const double s_lo = lo - origin;
  const double s_hi = std::isfinite(hi) ? hi - origin : std::numeric_limits<double>::max();
  // Critical points are extrema of a - b: sign changes of the derivative.
  const int m = float_sign_change_roots(std::span<const double>(deriv.data(), degree), degree - 1,
                                        s_lo, s_hi, crit);
  for (int i = 0; i < m; ++i) {
    const Time t = origin + crit[i].at;
    if (t < lo || t > hi) continue;
    // Probe the rounded critical point and its neighbours.
    for (Time probe :
         {t, std::nextafter(t, kTimeMinusInfinity), std::nextafter(t, kTimeInfinity)}) {
      if (probe >= lo && probe <= hi && compare_at(a, b, probe) < 0) return probe;
    }
  }
  return std::nullopt;
}

double value_at(const MotionPolynomial& p, Time t) {
  // First by compensated Horner: p(t) = r + e + d exactly, r = fl(hi + lo) and e its TwoSum
  // error (|e| <= ulp(r) / 2), |d| <= c.error. When e + d has a certain sign and stays within the
  // gap to r's neighbour on that side, p(t) lies strictly between two consecutive doubles (or is
  // r itself when e == d == 0), and its rounding toward zero is read off. Otherwise (p(t) at or
  // near a double, a result of 0, or no bound) exactly.
  const CompensatedValue c = evaluate_compensated(p, t);
  if (std::isfinite(c.hi) && std::isfinite(c.lo) && std::isfinite(c.error)) {
    double r = 0.0, e = 0.0;
    numeric::two_sum(c.hi, c.lo, r, e);
    if (std::isfinite(r) && r != 0.0) {
      if (e == 0.0 && c.error == 0.0) return r;
      const double reach = (std::fabs(e) + c.error) * (1.0 + 0x1p-50);  // >= |e| + |d|
      if (e > c.error) {                                                // p(t) in (r, next(r))
        const double up = std::nextafter(r, HUGE_VAL);
        if (reach < up - r && up != 0.0) return r > 0.0 ? r : up;
      } else if (-e > c.error) {  // p(t) in (previous(r), r)
        const double down = std::nextafter(r, -HUGE_VAL);
        if (reach < r - down && down != 0.0) return r > 0.0 ? down : r;
      }
    }
  }
  return exact_value(p, t).get_d();
}

double point_distance_at(std::span<const MotionPolynomial* const> point, std::span<const double> q,
                         Time t) {
  assert(point.size() == q.size());
  mpq_class squared = 0;
  for (std::size_t a = 0; a < point.size(); ++a) {
    const mpq_class d = exact_value(*point[a], t) - exact(q[a]);
    squared += d * d;
  }
  // sqrt in 128-bit binary floating point (GMP's exponent range has no underflow here), then
  // rounded toward zero to a double: relative error <= 2^-127 + 2^-52 for normal results.
  mpf_class root(squared, 128);
  mpf_sqrt(root.get_mpf_t(), root.get_mpf_t());
  return root.get_d();
}

namespace {
numeric::Interval enclosure(const FilteredValue& v) { return numeric::around(v.value, v.error); }
}  // namespace

FilteredPoint filtered_point(const MotionPolynomial& x, const MotionPolynomial& y, Time t) {
  return {evaluate_filtered(x, t), evaluate_filtered(y, t)};
}

int filtered_compare(const FilteredValue& a, const FilteredValue& b) {
  return (enclosure(a) - enclosure(b)).sign();
}

int filtered_orientation(const FilteredPoint& a, const FilteredPoint& b, const FilteredPoint& c) {
  const numeric::Interval ax = enclosure(a.x), ay = enclosure(a.y);
  const numeric::Interval det =
      (enclosure(b.x) - ax) * (enclosure(c.y) - ay) - (enclosure(b.y) - ay) * (enclosure(c.x) - ax);
  return det.sign();
}

int compare_distances_at(std::span<const MotionPolynomial* const> a,
                         std::span<const MotionPolynomial* const> b, std::span<const double> q,
                         Time t) {
  assert(a.size() == q.size() && b.size() == q.size());
  numeric::Interval da{0.0, 0.0}, db{0.0, 0.0};
  for (std::size_t k = 0; k < q.size(); ++k) {
    const numeric::Interval x = enclosure(evaluate_filtered(*a[k], t)) - numeric::around(q[k], 0.0);
    const numeric::Interval y = enclosure(evaluate_filtered(*b[k], t)) - numeric::around(q[k], 0.0);
    da = da + x * x;
    db = db + y * y;
  }
  if (const int s = (da - db).sign(); s != 0) return s;
  mpq_class difference = 0;
  for (std::size_t k = 0; k < q.size(); ++k) {
    const mpq_class x = exact_value(*a[k], t) - exact(q[k]);
    const mpq_class y = exact_value(*b[k], t) - exact(q[k]);
    difference += x * x - y * y;
  }
  return sgn(difference);
}

}  // namespace kinetic
