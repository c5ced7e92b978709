#include "kinetic/core/incircle.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <optional>
#include <type_traits>

#include "core/compensated_horner.hpp"
#include "core/determinants.hpp"
#include "core/float_decision.hpp"
#include "core/incircle_lines.hpp"
#include "core/numeric/bounded_double_double.hpp"
#include "core/numeric/expansion.hpp"
#include "core/numeric/interval.hpp"
#include "kinetic/core/exact_time.hpp"
#include "kinetic/core/motion_table.hpp"

namespace kinetic {

namespace {

using detail::incircle_determinant;
using detail::squared_length_difference;

const MotionPolynomial& coordinate(const InCircle& f, int k) {
  const MovingPoint2& p = f.p[static_cast<std::size_t>(k / 2)];
  return k % 2 == 0 ? *p.x : *p.y;
}

/// The sign when the filtered positions at t decide it, else 0.
int filtered_sign_at(const InCircle& f, Time t) { return detail::filtered_incircle_sign(f, t); }

}  // namespace

MovingPoint2 moving_point(const MotionTable& points, std::uint32_t index) {
  return MovingPoint2{&points.motion(index, 0), &points.motion(index, 1)};
}

ProductCombination orientation(const MotionTable& points, std::uint32_t a, std::uint32_t b,
                               std::uint32_t c) {
  const MovingPoint2 p = moving_point(points, a), q = moving_point(points, b),
                     r = moving_point(points, c);
  return orientation(*p.x, *p.y, *q.x, *q.y, *r.x, *r.y);
}

int LengthComparison::degree_bound() const {
  int d = 0;
  for (const MovingPoint2& q : p) d = std::max({d, q.x->degree, q.y->degree});
  return 2 * d;
}

int InCircle::degree_bound() const {
  int d = 0;
  for (const MovingPoint2& q : p) d = std::max({d, q.x->degree, q.y->degree});
  return 4 * d;
}

int sign_at(const InCircle& f, Time t, PredicateStats* stats) {
  if (const int s = filtered_sign_at(f, t); s != 0) {
    if (stats) ++stats->filtered;
    return s;
  }
  if (stats) ++stats->exact;
  const mpq_class at = rational(t);
  std::array<mpq_class, 8> v;
  for (int k = 0; k < 8; ++k)
    v[static_cast<std::size_t>(k)] = ExactPolynomial::of(coordinate(f, k))(at);
  return sgn(incircle_determinant(v));
}

int sign_after(const InCircle& f, Time t, PredicateStats* stats) {
  if (const int s = sign_at(f, t, stats); s != 0) return s;
  ExactTime at = ExactTime::point(rational(t));
  return at.sign_after(ExactPolynomial::of(f));
}

int compare_squared_distances_at(const MovingPoint2& a, const MovingPoint2& b,
                                 const MovingPoint2& c, const MovingPoint2& d, Time t) {
  const std::array<const MotionPolynomial*, 8> m{a.x, a.y, b.x, b.y, c.x, c.y, d.x, d.y};
  std::array<numeric::Interval, 8> iv;
  for (std::size_t k = 0; k < 8; ++k) {
    const FilteredValue fv = evaluate_filtered(*m[k], t);
    iv[k] = numeric::around(fv.value, fv.error);
  }
  if (const int s = squared_length_difference(iv).sign(); s != 0) return s;
  const mpq_class at = rational(t);
  std::array<mpq_class, 8> q;
  for (std::size_t k = 0; k < 8; ++k) q[k] = ExactPolynomial::of(*m[k])(at);
  return sgn(squared_length_difference(q));
}

LiftingCofactor lifting_cofactor(const InCircle& f, int k) {
  const MovingPoint2 &a = f.p[0], &b = f.p[1], &c = f.p[2], &d = f.p[3];
  const auto orient = [](const MovingPoint2& u, const MovingPoint2& v, const MovingPoint2& w) {
    return orientation(*u.x, *u.y, *v.x, *v.y, *w.x, *w.y);
  };
  switch (k) {
    case 0:
      return {orient(b, c, d), 1};
    case 1:
      return {orient(c, a, d), 1};
    case 2:
      return {orient(a, b, d), 1};
    default:
      return {orient(a, b, c), -1};
  }
}

std::array<int, 4> lifting_order(const std::array<ObjectId, 4>& ids) {
  std::array<int, 4> order{0, 1, 2, 3};
  std::sort(order.begin(), order.end(), [&](int i, int j) {
    return ids[static_cast<std::size_t>(i)] > ids[static_cast<std::size_t>(j)];
  });
  return order;
}

namespace {

/// The perturbed sign, with `after` the sign just after the time of an in-circle or an
/// orientation.
template <class After>
int perturbed(const InCircle& f, const std::array<ObjectId, 4>& ids, const After& after) {
  if (const int s = after(f); s != 0) return s;
  for (const int k : lifting_order(ids)) {
    const LiftingCofactor c = lifting_cofactor(f, k);
    if (const int s = after(c.orientation); s != 0) return c.sign * s;
  }
  return 0;
}

}  // namespace

int perturbed_sign_after(const InCircle& f, const std::array<ObjectId, 4>& ids, Time t,
                         PredicateStats* stats) {
  return perturbed(f, ids, [&](const auto& g) { return sign_after(g, t, stats); });
}

int perturbed_sign_after(const InCircle& f, const std::array<ObjectId, 4>& ids, LazyTime& now) {
  return perturbed(f, ids, [&](const auto& g) { return sign_after(g, now); });
}

namespace {

/// p(t) for every t in [lo, hi], enclosed (interval Horner in t - origin).
numeric::Interval enclose(const MotionPolynomial& p, Time lo, Time hi) {
  const numeric::Interval s{numeric::down(lo - p.origin), numeric::up(hi - p.origin)};
  numeric::Interval v = numeric::Interval::point(p.c[static_cast<std::size_t>(p.degree)]);
  for (int k = p.degree - 1; k >= 0; --k)
    v = v * s + numeric::Interval::point(p.c[static_cast<std::size_t>(k)]);
  return v;
}

bool apart(const MotionPolynomial& a, const MotionPolynomial& b, Time lo, Time hi) {
  const numeric::Interval x = enclose(a, lo, hi), y = enclose(b, lo, hi);
  return x.hi < y.lo || y.hi < x.lo;
}

}  // namespace

bool coincide_at(const MovingPoint2& a, const MovingPoint2& b, LazyTime& now) {
  const Time lo = now.lower(), hi = now.upper();
  if (apart(*a.x, *b.x, lo, hi) || apart(*a.y, *b.y, lo, hi)) return false;
  if (now.is_double()) return compare_at(*a.x, *b.x, lo) == 0 && compare_at(*a.y, *b.y, lo) == 0;
  ExactTime& t = now.exact();
  return t.sign_of(ExactPolynomial::difference(*a.x, *b.x)) == 0 &&
         t.sign_of(ExactPolynomial::difference(*a.y, *b.y)) == 0;
}

int sign_after(const ProductCombination& f, LazyTime& now) {
  if (now.is_double()) return sign_after(f, now.lower());
  // f over now's double bracket in interval arithmetic: when it keeps one sign there, that is
  // its sign at now and just after (the usual case); exact arithmetic otherwise.
  const Time lo = now.lower(), hi = now.upper();
  const auto e = [&](const MotionPolynomial* p) { return enclose(*p, lo, hi); };
  const numeric::Interval v = (e(f.plus[0]) - e(f.plus[1])) * (e(f.plus[2]) - e(f.plus[3])) -
                              (e(f.minus[0]) - e(f.minus[1])) * (e(f.minus[2]) - e(f.minus[3]));
  if (const int s = v.sign(); s != 0) return s;
  return now.exact().sign_after(ExactPolynomial::of(f));
}

int sign_after(const InCircle& f, LazyTime& now) {
  if (now.is_double()) return sign_after(f, now.lower());
  // The same filter over now's bracket first.
  std::array<numeric::Interval, 8> v;
  for (int k = 0; k < 8; ++k)
    v[static_cast<std::size_t>(k)] = enclose(coordinate(f, k), now.lower(), now.upper());
  if (const int s = incircle_determinant(v).sign(); s != 0) return s;
  return now.exact().sign_after(ExactPolynomial::of(f));
}

int sign_after(const LengthComparison& f, LazyTime& now) {
  if (now.is_double()) {
    if (const int s = compare_squared_distances_at(f.p[0], f.p[1], f.p[2], f.p[3], now.lower());
        s != 0)
      return s;
    ExactTime at = ExactTime::point(rational(now.lower()));
    return at.sign_after(ExactPolynomial::of(f));
  }
  return now.exact().sign_after(ExactPolynomial::of(f));
}

int compare_after(const MotionPolynomial& a, const MotionPolynomial& b, LazyTime& now) {
  if (now.is_double()) return compare_after(a, b, now.lower());
  return now.exact().sign_after(ExactPolynomial::difference(a, b));
}

namespace {

using numeric::BoundedDoubleDouble;
using numeric::Expansion;
using numeric::MagnitudeDoubleDouble;

// The coefficient arithmetic of the two representations below: floating-point expansions (exact,
// growing with every product) and bounded double-doubles (a fixed size, enclosed).
void accumulate(Expansion& c, const Expansion& y, bool subtract) {
  if (subtract) {
    c.subtract(y);
  } else {
    c.add(y);
  }
}
void accumulate_product(Expansion& c, const Expansion& x, const Expansion& y) { c.add(x * y); }
bool coefficient_ok(const Expansion& e) { return e.ok(); }
/// An expansion is checked after every product (one that outgrows its capacity stops there).
bool step_ok(const Expansion& e) { return e.ok(); }
void finish(Expansion& e) { e.compress(); }

void accumulate(BoundedDoubleDouble& c, const BoundedDoubleDouble& y, bool subtract) {
  c = subtract ? c - y : c + y;
}
void accumulate_product(BoundedDoubleDouble& c, const BoundedDoubleDouble& x,
                        const BoundedDoubleDouble& y) {
  c = c + x * y;
}
bool coefficient_ok(const BoundedDoubleDouble& b) { return b.finite(); }
/// A double-double once per result (an overflow carries to it: bounded_double_double.hpp).
bool step_ok(const BoundedDoubleDouble& /*b*/) { return true; }
void finish(BoundedDoubleDouble& /*b*/) {}

/// A polynomial in t of degree <= 8 with coefficients in C: the in-circle determinant and the
/// orientation of points on lines and parabolas computed without GMP, exactly in floating-point
/// expansions (Shewchuk's), or enclosed in bounded double-doubles. Not ok() when a motion has
/// degree > 2 or a coefficient leaves its domain or capacity (the caller then decides another
/// way).
template <class C>
struct CoefficientPolynomial {
  static constexpr int kMaxDegree = 8;
  std::array<C, kMaxDegree + 1> a;  // (not zeroed: an Expansion starts empty, a double-double 0)
  int degree = -1;
  bool ok = true;

  /// x(t) of a motion of degree <= 2, in powers of t: c0 + c1 (t - o) + c2 (t - o)^2 =
  /// (c0 - c1 o + c2 o^2) + (c1 - 2 c2 o) t + c2 t^2.
  static CoefficientPolynomial of(const MotionPolynomial& m);

  void finish_all() {
    for (int k = 0; k <= degree; ++k) {
      C& e = a[static_cast<std::size_t>(k)];
      ok = ok && coefficient_ok(e);
      finish(e);
    }
  }

  friend CoefficientPolynomial combine(const CoefficientPolynomial& x,
                                       const CoefficientPolynomial& y, bool subtract) {
    CoefficientPolynomial r = x;
    r.ok = x.ok && y.ok;
    r.degree = std::max(x.degree, y.degree);
    for (int k = 0; k <= y.degree && r.ok; ++k) {
      const auto i = static_cast<std::size_t>(k);
      accumulate(r.a[i], y.a[i], subtract);
    }
    r.finish_all();
    return r;
  }
  friend CoefficientPolynomial operator+(const CoefficientPolynomial& x,
                                         const CoefficientPolynomial& y) {
    return combine(x, y, false);
  }
  friend CoefficientPolynomial operator-(const CoefficientPolynomial& x,
                                         const CoefficientPolynomial& y) {
    return combine(x, y, true);
  }
  friend CoefficientPolynomial operator*(const CoefficientPolynomial& x,
                                         const CoefficientPolynomial& y) {
    CoefficientPolynomial r;
    r.ok = x.ok && y.ok && x.degree + y.degree <= kMaxDegree;
    if (!r.ok || x.degree < 0 || y.degree < 0) return r;
    r.degree = x.degree + y.degree;
    for (int i = 0; i <= x.degree && r.ok; ++i) {
      for (int j = 0; j <= y.degree && r.ok; ++j) {
        C& c = r.a[static_cast<std::size_t>(i + j)];
        accumulate_product(c, x.a[static_cast<std::size_t>(i)], y.a[static_cast<std::size_t>(j)]);
        r.ok = step_ok(c);
      }
    }
    r.finish_all();
    return r;
  }
};

using ExpansionPolynomial = CoefficientPolynomial<Expansion>;
using BoundedPolynomial = CoefficientPolynomial<BoundedDoubleDouble>;

template <>
ExpansionPolynomial ExpansionPolynomial::of(const MotionPolynomial& m) {
  ExpansionPolynomial p;
  if (m.degree > 2) {
    p.ok = false;
    return p;
  }
  const double o = m.origin;
  const Expansion c2o = Expansion(m.c[2]).scaled(o);
  p.a[0] = Expansion(m.c[0]);
  p.a[0].subtract(Expansion(m.c[1]).scaled(o));
  p.a[0].add(c2o.scaled(o));
  p.a[1] = Expansion(m.c[1]);
  p.a[1].subtract(c2o.scaled(2.0));
  p.a[2] = Expansion(m.c[2]);
  p.degree = m.degree;
  p.finish_all();
  return p;
}

template <>
BoundedPolynomial BoundedPolynomial::of(const MotionPolynomial& m) {
  using B = BoundedDoubleDouble;
  BoundedPolynomial p;
  if (m.degree > 2) {
    p.ok = false;
    return p;
  }
  if (m.origin == 0.0) {  // in powers of t already: exact
    for (std::size_t k = 0; k < 3; ++k) p.a[k] = B::exact(m.c[k]);
    p.degree = m.degree;
    p.finish_all();
    return p;
  }
  const B o = B::exact(m.origin);
  const B c2o = B::exact(m.c[2]) * o;
  p.a[0] = (B::exact(m.c[0]) - B::exact(m.c[1]) * o) + c2o * o;
  p.a[1] = B::exact(m.c[1]) - c2o * B::exact(2.0);
  p.a[2] = B::exact(m.c[2]);
  p.degree = m.degree;
  p.finish_all();
  return p;
}

/// The exact value of an expansion (finite components): sum of m_i 2^e_i over one common
/// exponent, in integers, made rational once.
mpq_class rational_of(const Expansion& e) {
  note_gmp_work();
  if (e.size() == 0) return 0;
  int low = 0;
  std::array<double, Expansion::kCapacity> mantissa{};  // integers below 2^53, exact
  std::array<int, Expansion::kCapacity> exponent{};
  for (std::size_t i = 0; i < e.size(); ++i) {
    int x = 0;
    const double f = std::frexp(e[i], &x);  // e[i] = f 2^x, 0.5 <= |f| < 1
    mantissa[i] = std::ldexp(f, 53);
    exponent[i] = x - 53;
    low = i == 0 ? exponent[i] : std::min(low, exponent[i]);
  }
  mpz_class sum = 0, term;
  for (std::size_t i = 0; i < e.size(); ++i) {
    term = mantissa[i];  // mpz from an integral double: exact
    mpz_mul_2exp(term.get_mpz_t(), term.get_mpz_t(), static_cast<mp_bitcnt_t>(exponent[i] - low));
    sum += term;
  }
  mpq_class q(sum);
  if (low > 0) {
    mpq_mul_2exp(q.get_mpq_t(), q.get_mpq_t(), static_cast<mp_bitcnt_t>(low));
  } else if (low < 0) {
    mpq_div_2exp(q.get_mpq_t(), q.get_mpq_t(), static_cast<mp_bitcnt_t>(-low));
  }
  return q;
}

/// The in-circle polynomial of points on lines and parabolas in C (not ok() when a motion's
/// degree exceeds 2 or a coefficient leaves its domain or capacity).
template <class C>
CoefficientPolynomial<C> polynomial_in(const InCircle& f) {
  std::array<CoefficientPolynomial<C>, 8> e;
  for (std::size_t k = 0; k < 8; ++k) {
    e[k] = CoefficientPolynomial<C>::of(coordinate(f, static_cast<int>(k)));
    if (!e[k].ok) return e[k];
  }
  return incircle_determinant(e);
}

/// The five coefficients of the in-circle polynomial of points on lines (every motion of degree
/// <= 1) in the double-double type N: incircle_of_line_rows() on the rows relative to d about
/// t = 0. Depth (MagnitudeDoubleDouble's): a coordinate c0 - c1 o is 0 (origin 0) or 2, a row 3,
/// a coefficient 4 * 3 + 10 = 22.
template <class N>
std::array<N, 5> incircle_of_lines_in(const InCircle& f) {
  struct Line {
    N c0, c1;  // c0 + c1 t
  };
  const auto line = [](const MotionPolynomial& m) {
    Line l{N::exact(m.c[0]), N::exact(m.c[1])};
    if (m.origin != 0.0 && m.degree == 1) l.c0 = l.c0 - l.c1 * N::exact(m.origin);
    return l;
  };
  std::array<Line, 8> v;
  for (std::size_t k = 0; k < 8; ++k) v[k] = line(coordinate(f, static_cast<int>(k)));
  detail::LineRows<N> r;
  for (std::size_t i = 0; i < 3; ++i) {
    r.x0[i] = v[2 * i].c0 - v[6].c0;
    r.x1[i] = v[2 * i].c1 - v[6].c1;
    r.y0[i] = v[2 * i + 1].c0 - v[7].c0;
    r.y1[i] = v[2 * i + 1].c1 - v[7].c1;
  }
  return detail::incircle_of_line_rows(r);
}

/// The in-circle polynomial of points on lines in bounded double-doubles. When every motion's
/// coefficients and origin are at most 2^60 in magnitude, computed with magnitude bounds
/// (depth 22: error at most 23 2^-100 M) and an underflow allowance of 2^-600: each of the fewer
/// than 300 operations errs by at most 2^-1073 on underflow, multiplied later by at most the
/// factors it meets (a difference, at most 2^122, then a lift or cross product, at most 2^246),
/// far below 2^-600; no overflow is possible (every magnitude stays below 2^500). Otherwise
/// with the error carried through every operation.
BoundedPolynomial incircle_of_lines(const InCircle& f) {
  BoundedPolynomial d;
  d.degree = f.degree_bound();  // 4, or 0 when every point stands still
  bool moderate = true;
  for (int k = 0; k < 8 && moderate; ++k) {
    const MotionPolynomial& m = coordinate(f, k);
    moderate =
        std::fabs(m.c[0]) <= 0x1p60 && std::fabs(m.c[1]) <= 0x1p60 && std::fabs(m.origin) <= 0x1p60;
  }
  if (moderate) {
    const std::array<MagnitudeDoubleDouble, 5> c = incircle_of_lines_in<MagnitudeDoubleDouble>(f);
    for (std::size_t k = 0; k < 5; ++k) d.a[k] = c[k].bounded(22, 0x1p-600);
  } else {
    const std::array<BoundedDoubleDouble, 5> c = incircle_of_lines_in<BoundedDoubleDouble>(f);
    for (std::size_t k = 0; k < 5; ++k) d.a[k] = c[k];
  }
  d.finish_all();
  return d;
}

/// The orientation-like product combination (P0 - P1)(P2 - P3) - (M0 - M1)(M2 - M3) of motions
/// of degree <= 2 in C (degree <= 4); not ok() beyond.
template <class C>
CoefficientPolynomial<C> polynomial_in(const ProductCombination& f) {
  std::array<CoefficientPolynomial<C>, 8> e;
  for (std::size_t k = 0; k < 8; ++k) {
    const MotionPolynomial* m = k < 4 ? f.plus[k] : f.minus[k - 4];
    if (m == nullptr) {
      e[k].ok = false;
      return e[k];
    }
    e[k] = CoefficientPolynomial<C>::of(*m);
    if (!e[k].ok) return e[k];
  }
  return (e[0] - e[1]) * (e[2] - e[3]) - (e[4] - e[5]) * (e[6] - e[7]);
}

std::optional<ExpansionPolynomial> incircle_expansions(const InCircle& f) {
  ExpansionPolynomial d = polynomial_in<Expansion>(f);
  if (!d.ok) return std::nullopt;
  return d;
}

std::optional<ExpansionPolynomial> product_expansions(const ProductCombination& f) {
  ExpansionPolynomial d = polynomial_in<Expansion>(f);
  if (!d.ok) return std::nullopt;
  return d;
}

/// d's coefficients up to `degree` as a deferred root's.
LazyTime::ExpansionCoefficients coefficients_of(const ExpansionPolynomial& d, int degree) {
  LazyTime::ExpansionCoefficients coefficients;
  std::array<double, Expansion::kCapacity> components{};
  for (int k = 0; k <= degree; ++k) {
    const Expansion& x = d.a[static_cast<std::size_t>(k)];
    for (std::size_t i = 0; i < x.size(); ++i) components[i] = x[i];
    coefficients.push_back(std::span<const double>(components.data(), x.size()));
  }
  return coefficients;
}

int top_degree(const ExpansionPolynomial& d) {
  int degree = d.degree;
  while (degree >= 0 && d.a[static_cast<std::size_t>(degree)].sign() == 0) --degree;
  return degree;
}

/// d's exact sign at the double t by Horner's rule in expansions; nullopt when an expansion
/// leaves its domain or capacity.
std::optional<int> expansion_sign_at(const ExpansionPolynomial& d, int degree, double t) {
  if (degree < 0) return 0;
  Expansion v = d.a[static_cast<std::size_t>(degree)];
  for (int k = degree; k-- > 0;) {
    v = v.scaled(t);
    v.add(d.a[static_cast<std::size_t>(k)]);
    if (!v.ok()) return std::nullopt;
    v.compress();
  }
  return v.sign();
}

/// When now is a deferred root of c d (c = +-1, d of degree `degree`, compared coefficient by
/// coefficient with the root's expansions): d's sign just after now, -c times the root's sign at
/// its bracket's low end (d vanishes at now and changes sign there, a simple root). 0 otherwise.
int sign_after_own_root(const ExpansionPolynomial& d, int degree, const LazyTime& now) {
  const LazyTime::DeferredPolynomial* root = now.deferred_polynomial();
  if (root == nullptr) return 0;
  const LazyTime::ExpansionCoefficients* q = root->expansions();
  if (q == nullptr || q->size() != static_cast<std::size_t>(degree) + 1) return 0;
  for (const double c_sign : {1.0, -1.0}) {
    bool same = true;
    for (int k = 0; k <= degree && same; ++k) {
      Expansion difference = d.a[static_cast<std::size_t>(k)];
      for (const double x : (*q)[static_cast<std::size_t>(k)]) difference.add(-c_sign * x);
      same = difference.ok() && difference.sign() == 0;
    }
    if (same) return -static_cast<int>(c_sign) * now.deferred_sign_lo();
  }
  return 0;
}

/// The decision on the polynomial d (exact, in expansions) in floating point: its coefficients
/// enclosed in intervals, its exact signs at doubles by compensated Horner first and Horner's
/// rule in expansions where that cannot tell, a failure a deferred root carrying d's expansions.
/// When now is itself a deferred root of +-d (the certificate whose failure now is, seen again
/// after the event), d's sign just after now is that root's. The second filter, behind the
/// bounded double-doubles of decide_bounded().
std::optional<FloatDecision> decide_expansion_polynomial(const ExpansionPolynomial& d,
                                                         const LazyTime& now, Time horizon) {
  const int degree = top_degree(d);
  if (degree < 0) return std::nullopt;  // the zero polynomial (e.g. co-circular for ever)
  // Each coefficient enclosed: the sum of its components in interval arithmetic.
  std::array<numeric::Interval, ExpansionPolynomial::kMaxDegree + 1> c;
  for (int k = 0; k <= degree; ++k) {
    const Expansion& x = d.a[static_cast<std::size_t>(k)];
    numeric::Interval sum = numeric::Interval::point(0.0);
    for (std::size_t i = 0; i < x.size(); ++i) sum = sum + numeric::Interval::point(x[i]);
    c[static_cast<std::size_t>(k)] = sum;
  }
  // d's exact sign at a double: compensated Horner first (degree <= 8), on each coefficient
  // rounded to a double-double (c_k, cl_k) = TwoSum(top component, the rest rounded): c_k + cl_k
  // is within 2^-99 |c_k| of the coefficient (the rest is below 2u |top|, rounded with relative
  // error below 64 u), so 2^-97 sum |c_k| |t|^k more covers it; else Horner's rule in
  // expansions.
  std::array<double, ExpansionPolynomial::kMaxDegree + 1> c_hi{}, c_lo{};
  for (int k = 0; k <= degree; ++k) {
    const auto i = static_cast<std::size_t>(k);
    d.a[i].to_double_double(c_hi[i], c_lo[i]);
  }
  const auto exact_sign = [&](double t) -> std::optional<int> {
    CompensatedValue v = compensated_horner(c_hi.data(), c_lo.data(), degree, t, 0.0);
    if (std::isfinite(v.error)) {
      double m = 0.0;  // sum |c_k| |t|^k, rounded (relative error far below 2^-40)
      for (int k = degree; k >= 0; --k)
        m = m * std::fabs(t) + std::fabs(c_hi[static_cast<std::size_t>(k)]);
      v.error += 0x1p-97 * m;
      if (const int sign = v.sign_if_certain(); sign != 0) return sign;
    }
    return expansion_sign_at(d, degree, t);
  };
  const auto root = [&](double lo, double hi, int sign_lo) {
    return LazyTime::deferred_root(
        std::make_shared<const LazyTime::DeferredPolynomial>(coefficients_of(d, degree)), lo, hi,
        sign_lo);
  };
  return decide_in_floating_point(std::span<const numeric::Interval>(c.data(), degree + 1),
                                  exact_sign, now, horizon, root,
                                  sign_after_own_root(d, degree, now));
}

/// c = +-1 when the in-circle f is the certificate of the deferred root `q` up to the order of
/// its points, f = c q (the determinant is alternating: c is the permutation's parity); 0 when
/// that cannot be told from the motions (which are then compared by their expansions).
int same_certificate(const InCircle& f, const LazyTime::DeferredPolynomial& q) {
  if (q.certificate() != LazyTime::DeferredPolynomial::Certificate::InCircle) return 0;
  std::array<int, 4> image{};
  unsigned used = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    int found = -1;
    for (std::size_t j = 0; j < 4 && found < 0; ++j) {
      if ((used & (1u << j)) == 0 && q.same_motion(2 * j, *f.p[i].x) &&
          q.same_motion(2 * j + 1, *f.p[i].y))
        found = static_cast<int>(j);
    }
    if (found < 0) return 0;
    used |= 1u << static_cast<unsigned>(found);
    image[i] = found;
  }
  int inversions = 0;
  for (std::size_t i = 0; i < 4; ++i)
    for (std::size_t j = i + 1; j < 4; ++j) inversions += image[i] > image[j] ? 1 : 0;
  return inversions % 2 == 0 ? 1 : -1;
}

/// The same for a product combination: the same eight motions (c = 1), or its two products
/// exchanged (c = -1).
int same_certificate(const ProductCombination& f, const LazyTime::DeferredPolynomial& q) {
  if (q.certificate() != LazyTime::DeferredPolynomial::Certificate::Product) return 0;
  const auto matches = [&](const std::array<const MotionPolynomial*, 4>& first,
                           const std::array<const MotionPolynomial*, 4>& second) {
    for (std::size_t k = 0; k < 4; ++k)
      if (!(q.same_motion(k, *first[k]) && q.same_motion(k + 4, *second[k]))) return false;
    return true;
  };
  if (matches(f.plus, f.minus)) return 1;
  if (matches(f.minus, f.plus)) return -1;
  return 0;
}

/// The lazily built representations of one certificate's polynomial, for its exact signs at
/// doubles: bounded double-doubles (compensated Horner with their bounds added), then
/// floating-point expansions (Horner's rule, exact), each built on first need.
template <class Certificate>
class Representations {
 public:
  explicit Representations(const Certificate& f) : f_(f) {}

  /// The polynomial in bounded double-doubles, or null when it leaves their domain.
  const BoundedPolynomial* bounded() {
    if (!bounded_) {
      if constexpr (std::is_same_v<Certificate, InCircle>) {
        if (f_.degree_bound() <= 4) {  // points on lines
          bounded_ = incircle_of_lines(f_);
          return bounded_->ok ? &*bounded_ : nullptr;
        }
      }
      bounded_ = kinetic::polynomial_in<BoundedDoubleDouble>(f_);
    }
    return bounded_->ok ? &*bounded_ : nullptr;
  }
  /// The polynomial in expansions, or null when it leaves their domain or capacity.
  const ExpansionPolynomial* expansions() {
    if (!expansions_) {
      ExpansionPolynomial e = kinetic::polynomial_in<Expansion>(f_);
      expansions_ = e.ok ? std::optional<ExpansionPolynomial>(std::move(e)) : std::nullopt;
    }
    return *expansions_ ? &**expansions_ : nullptr;
  }
  /// The value at t to about double-double accuracy (compensated Horner on the double-doubles:
  /// hi + lo), NaN when they are not available. Steers Newton's method only.
  double accurate_value(double t) {
    const BoundedPolynomial* d = bounded();
    if (d == nullptr) return std::numeric_limits<double>::quiet_NaN();
    std::array<double, BoundedPolynomial::kMaxDegree + 1> hi{}, lo{};
    for (int k = 0; k <= d->degree; ++k) {
      hi[static_cast<std::size_t>(k)] = d->a[static_cast<std::size_t>(k)].hi;
      lo[static_cast<std::size_t>(k)] = d->a[static_cast<std::size_t>(k)].lo;
    }
    const CompensatedValue v = compensated_horner(hi.data(), lo.data(), d->degree, t, 0.0);
    if (!std::isfinite(v.error)) return std::numeric_limits<double>::quiet_NaN();
    return v.hi + v.lo;
  }
  /// The exact sign at the double t; nullopt when neither representation can give it.
  std::optional<int> exact_sign(double t) {
    if (const BoundedPolynomial* d = bounded()) {
      // Compensated Horner on (hi, lo) is within its bound of sum (hi_k + lo_k) t^k, and each
      // coefficient within err_k of the polynomial's, so sum err_k |t|^k more (rounded:
      // multiplied by 1 + 2^-40, plus 2^-1060 for underflow) bounds the error.
      const int degree = d->degree;
      std::array<double, BoundedPolynomial::kMaxDegree + 1> hi{}, lo{};
      double m = 0.0;
      for (int k = degree; k >= 0; --k) {
        const auto i = static_cast<std::size_t>(k);
        hi[i] = d->a[i].hi;
        lo[i] = d->a[i].lo;
        m = m * std::fabs(t) + d->a[i].err;
      }
      CompensatedValue v = compensated_horner(hi.data(), lo.data(), degree, t, 0.0);
      if (std::isfinite(v.error)) {
        v.error = (v.error + m) * BoundedDoubleDouble::kGrow + BoundedDoubleDouble::kTiny;
        if (const int sign = v.sign_if_certain(); sign != 0) return sign;
      }
    }
    const ExpansionPolynomial* e = expansions();
    if (e == nullptr) return std::nullopt;
    return expansion_sign_at(*e, top_degree(*e), t);
  }

 private:
  const Certificate& f_;
  std::optional<BoundedPolynomial> bounded_;
  std::optional<std::optional<ExpansionPolynomial>> expansions_;
};

/// The decision on a certificate f (an in-circle, a product combination) from enclosures `c` of
/// its polynomial's coefficients (the top one not exactly 0): isolation on them, exact signs at
/// doubles from `exact` (double-doubles, then expansions); a failure is a deferred root keeping
/// f's motions, whose expansions are built only if a comparison needs its exact time. Nullopt:
/// the enclosures cannot decide.
template <class Certificate>
std::optional<FloatDecision> decide_enclosed(const Certificate& f,
                                             std::span<const numeric::Interval> c,
                                             Representations<Certificate>& exact,
                                             const LazyTime& now, Time horizon) {
  const auto exact_sign = [&](double t) { return exact.exact_sign(t); };
  const auto root = [&](double lo, double hi, int sign_lo) {
    return LazyTime::deferred_root(std::make_shared<const LazyTime::DeferredPolynomial>(f), lo, hi,
                                   sign_lo);
  };
  // At a deferred root now: when f is that root's certificate (its points in another order),
  // its sign just after now is the root's; otherwise, when f may vanish over now's bracket, its
  // expansions are compared with the root's.
  int sign_after_now = 0;
  if (const LazyTime::DeferredPolynomial* q = now.deferred_polynomial(); q != nullptr) {
    if (const int same = same_certificate(f, *q); same != 0) {
      sign_after_now = -same * now.deferred_sign_lo();
    } else {
      const numeric::Interval bracket{now.lower(), now.upper()};
      numeric::Interval v = c.back();
      for (std::size_t k = c.size() - 1; k-- > 0;) v = v * bracket + c[k];
      if (v.sign() == 0) {
        if (const ExpansionPolynomial* e = exact.expansions())
          sign_after_now = sign_after_own_root(*e, top_degree(*e), now);
      }
    }
  }
  const auto value = [&](double t) { return exact.accurate_value(t); };
  const FunctionRef<double(double)> accurate_value(value);
  return decide_in_floating_point(c, exact_sign, now, horizon, root, sign_after_now,
                                  &accurate_value);
}

/// The enclosures of d's coefficients up to its top one not exactly 0 (empty: d == 0).
template <class C>
std::span<const numeric::Interval> enclosures(const CoefficientPolynomial<C>& d,
                                              std::array<numeric::Interval, 9>& out) {
  int degree = d.degree;
  for (int k = 0; k <= degree; ++k) {
    out[static_cast<std::size_t>(k)] = d.a[static_cast<std::size_t>(k)].enclosure();
  }
  // A top coefficient no operation touched is exactly 0 (a computed one carries at least the
  // underflow allowance, so its enclosure is never [0, 0]: an exactly vanishing leading
  // coefficient, e.g. of points with equal velocities, leaves the Cauchy bound of an infinite
  // horizon undecided and the decision to the expansions).
  while (degree >= 0 && d.a[static_cast<std::size_t>(degree)].is_zero()) --degree;
  return {out.data(), static_cast<std::size_t>(degree + 1)};
}

/// The floating-point decision of an in-circle or a product combination, in two stages, the
/// second tried when the first cannot decide: the polynomial in bounded double-doubles
/// (enclosures about 2^-100 wide; exact signs by compensated Horner, else expansions built then),
/// in expansions (exact coefficients). Nullopt: decide with GMP.
template <class Certificate>
std::optional<FloatDecision> decide_staged(const Certificate& f, const LazyTime& now,
                                           Time horizon) {
  Representations<Certificate> exact(f);
  std::array<numeric::Interval, 9> c;
  if (const BoundedPolynomial* db = exact.bounded()) {
    if (const auto e = enclosures(*db, c); !e.empty()) {
      if (std::optional<FloatDecision> d = decide_enclosed(f, e, exact, now, horizon)) return d;
    }
  }
  const ExpansionPolynomial* de = exact.expansions();
  if (de == nullptr) return std::nullopt;
  return decide_expansion_polynomial(*de, now, horizon);
}

}  // namespace

std::optional<ExactPolynomial> incircle_polynomial_in_expansions(const InCircle& f) {
  const std::optional<ExpansionPolynomial> found = incircle_expansions(f);
  if (!found) return std::nullopt;
  const ExpansionPolynomial& d = *found;
  std::vector<mpq_class> c;
  c.reserve(static_cast<std::size_t>(d.degree + 1));
  for (int k = 0; k <= d.degree; ++k) c.push_back(rational_of(d.a[static_cast<std::size_t>(k)]));
  return ExactPolynomial(std::move(c));
}

void LazyTime::DeferredPolynomial::keep(std::size_t k, const MotionPolynomial& m) {
  assert(m.degree <= 2);
  degree_[k] = static_cast<std::uint8_t>(m.degree);
  motion_[k] = {m.origin, m.c[0], m.c[1], m.c[2]};
}

LazyTime::DeferredPolynomial::DeferredPolynomial(const InCircle& f)
    : certificate_(Certificate::InCircle) {
  for (std::size_t k = 0; k < 8; ++k) keep(k, coordinate(f, static_cast<int>(k)));
}

LazyTime::DeferredPolynomial::DeferredPolynomial(const ProductCombination& f)
    : certificate_(Certificate::Product) {
  for (std::size_t k = 0; k < 4; ++k) {
    keep(k, *f.plus[k]);
    keep(k + 4, *f.minus[k]);
  }
}

MotionPolynomial LazyTime::DeferredPolynomial::motion(std::size_t k) const {
  MotionPolynomial m;
  m.origin = motion_[k][0];
  m.degree = degree_[k];
  for (std::size_t i = 0; i < 3; ++i) m.c[i] = motion_[k][i + 1];
  return m;
}

bool LazyTime::DeferredPolynomial::same_motion(std::size_t k, const MotionPolynomial& m) const {
  if (m.degree != degree_[k] || m.origin != motion_[k][0]) return false;
  for (std::size_t i = 0; i < m.c.size(); ++i)
    if (m.c[i] != (i < 3 ? motion_[k][i + 1] : 0.0)) return false;
  return true;
}

namespace {

InCircle incircle_of(const std::array<MotionPolynomial, 8>& m) {
  InCircle f;
  for (std::size_t i = 0; i < 4; ++i) f.p[i] = MovingPoint2{&m[2 * i], &m[2 * i + 1]};
  return f;
}

ProductCombination product_of(const std::array<MotionPolynomial, 8>& m) {
  ProductCombination f;
  for (std::size_t k = 0; k < 4; ++k) {
    f.plus[k] = &m[k];
    f.minus[k] = &m[k + 4];
  }
  return f;
}

}  // namespace

const LazyTime::ExpansionCoefficients* LazyTime::DeferredPolynomial::expansions() const {
  if (!built_) {
    built_ = true;
    std::array<MotionPolynomial, 8> m;
    for (std::size_t k = 0; k < 8; ++k) m[k] = motion(k);
    const std::optional<ExpansionPolynomial> d = certificate_ == Certificate::InCircle
                                                     ? incircle_expansions(incircle_of(m))
                                                     : product_expansions(product_of(m));
    if (d)
      expansions_ = std::make_unique<ExpansionCoefficients>(coefficients_of(*d, top_degree(*d)));
  }
  return expansions_.get();
}

ExactPolynomial LazyTime::DeferredPolynomial::exact() const {
  std::array<MotionPolynomial, 8> m;
  for (std::size_t k = 0; k < 8; ++k) m[k] = motion(k);
  switch (certificate_) {
    case Certificate::InCircle:
      return ExactPolynomial::of(incircle_of(m));
    case Certificate::Product:
      return ExactPolynomial::of(product_of(m));
    case Certificate::Given:
      break;
  }
  std::vector<mpq_class> c;
  c.reserve(expansions_->size());
  for (std::size_t k = 0; k < expansions_->size(); ++k) {
    const std::span<const double> components = (*expansions_)[k];
    c.push_back(rational_of(Expansion::of_components(components.data(), components.size())));
  }
  return ExactPolynomial(std::move(c));
}

std::optional<FloatDecision> decide_in_floating_point(const InCircle& f, const LazyTime& now,
                                                      Time horizon) {
  return decide_staged(f, now, horizon);
}

std::optional<FloatDecision> decide_in_floating_point(const ProductCombination& f,
                                                      const LazyTime& now, Time horizon) {
  return decide_staged(f, now, horizon);
}

ExactPolynomial ExactPolynomial::of(const InCircle& f) {
  // Points on lines and parabolas: in floating-point expansions, one rational per coefficient.
  if (std::optional<ExactPolynomial> p = incircle_polynomial_in_expansions(f)) return *p;
  std::array<ExactPolynomial, 8> v;
  for (int k = 0; k < 8; ++k) v[static_cast<std::size_t>(k)] = of(coordinate(f, k));
  return incircle_determinant(v);
}

ExactPolynomial ExactPolynomial::of(const LengthComparison& f) {
  std::array<ExactPolynomial, 8> v;
  for (std::size_t k = 0; k < 8; ++k) {
    const MovingPoint2& p = f.p[k / 2];
    v[k] = of(k % 2 == 0 ? *p.x : *p.y);
  }
  return squared_length_difference(v);
}

}  // namespace kinetic
