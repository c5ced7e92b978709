// LazyTime: exact times that stay doubles and low-degree roots until they must be exact.
//
// A certificate f = upper - lower of two motions of degree <= 2 is kept as
//   g(t) = a0 + a1 (t - o) + a2 (t - o)^2,   g = +-f, its leading coefficient > 0,
// with every a_k an exact floating-point expansion (numeric/expansion.hpp). Its roots are
// bracketed between adjacent doubles by exact signs of g at doubles; two such roots are
// compared without GMP when their brackets overlap and they are both linear (a 2 x 2
// determinant) or of the same quadratic (their order). See docs/exact-design.md.

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cassert>
#include <cmath>
#include <limits>
#include <span>

#include "core/compensated_horner.hpp"
#include "core/numeric/expansion.hpp"
#include "core/numeric/ordinal.hpp"
#include "kinetic/core/exact_time.hpp"

namespace kinetic {
namespace {

using numeric::Expansion;

/// g(t) = a[0] + a[1] (t - o) + a[2] (t - o)^2, exactly.
struct Form {
  double o = 0.0;
  std::array<Expansion, 3> a;
  [[nodiscard]] bool ok() const { return a[0].ok() && a[1].ok() && a[2].ok(); }
  [[nodiscard]] int degree() const {
    for (int k = 2; k >= 0; --k)
      if (a[static_cast<std::size_t>(k)].sign() != 0) return k;
    return -1;
  }
};

/// sum of sign_i * p_i (degrees <= 2, at most four terms): in powers of (t - o) when all have
/// the origin o, else in powers of t (o = 0).
struct Term {
  const MotionPolynomial* p;
  double sign;
};
void form_of(std::span<const Term> terms, Form& f, bool absolute = false) {
  const double o = terms[0].p->origin;
  if (!absolute && terms.size() == 2 && terms[1].p->origin == o) {  // one TwoSum per coefficient
    f.o = o;
    for (std::size_t k = 0; k < 3; ++k)
      f.a[k].assign_sum(terms[0].sign * terms[0].p->c[k], terms[1].sign * terms[1].p->c[k]);
    return;
  }
  if (!absolute &&
      std::all_of(terms.begin(), terms.end(), [&](const Term& x) { return x.p->origin == o; })) {
    f.o = o;
    for (const Term& x : terms)
      for (std::size_t k = 0; k < 3; ++k) f.a[k].add(x.sign * x.p->c[k]);  // (in place: large)
    return;
  }
  // p(t) = c0 + c1 (t - o) + c2 (t - o)^2 = (c0 - c1 o + c2 o^2) + (c1 - 2 c2 o) t + c2 t^2.
  for (const Term& x : terms) {
    const MotionPolynomial& p = *x.p;
    const Expansion c2o = Expansion(p.c[2]).scaled(p.origin);
    f.a[0].add(x.sign * p.c[0]);
    f.a[0].add(Expansion(-x.sign * p.c[1]).scaled(p.origin));
    f.a[0].add(c2o.scaled(x.sign * p.origin));
    f.a[1].add(x.sign * p.c[1]);
    f.a[1].add(c2o.scaled(-2.0 * x.sign));
    f.a[2].add(x.sign * p.c[2]);
  }
}

/// An expansion rounded to a double (relative error a few u).
double approx(const Expansion& e) {
  double v = 0.0;
  for (std::size_t i = 0; i < e.size(); ++i) v += e[i];
  return v;
}

/// sign g(x), exactly: a floating-point filter, else expansions. `ok` is cleared (and 0
/// returned) outside the expansions' domain.
int sign_at(const Form& f, double x, bool& ok) {
  const double d = x - f.o;
  const double a0 = approx(f.a[0]), a1 = approx(f.a[1]), a2 = approx(f.a[2]);
  const double v = a0 + d * (a1 + d * a2);
  const double magnitude = std::fabs(a0) + std::fabs(a1 * d) + std::fabs(a2 * d * d);
  // The rounded coefficients (<= 3u each), d (u), d^2 (2u) and Horner's four operations err by
  // less than 12u times the magnitude; 2^-48 = 32u of it, and 2^-1000 for underflow, suffice.
  if (std::isfinite(magnitude) && std::fabs(v) > 0x1p-48 * magnitude + 0x1p-1000)
    return v > 0.0 ? 1 : -1;
  // Compensated Horner second (each coefficient a double-double: TwoSum of its top component
  // and the rest rounded, within 2^-99 of it, as in the floating-point decisions): decides near
  // a root, where the filter above cannot, at a fraction of the exact sum's cost.
  {
    double s = 0.0, e = 0.0;
    numeric::two_sum(x, -f.o, s, e);
    std::array<double, 3> hi{}, lo{};
    double m = 0.0;
    for (std::size_t k = 3; k-- > 0;) {
      f.a[k].to_double_double(hi[k], lo[k]);
      m = m * std::fabs(s) + std::fabs(hi[k]);
    }
    if (std::isfinite(s)) {
      CompensatedValue c = compensated_horner(hi.data(), lo.data(), 2, s, e);
      c.error += 0x1p-96 * m;  // the coefficients' rounding (|x - o| <= |s| (1 + u))
      if (std::isfinite(c.error))
        if (const int sign = c.sign_if_certain(); sign != 0) return sign;
    }
  }
  // Exactly: x - o == s + e (TwoSum), (x - o)^2 == the six terms of s s + 2 s e + e e
  // (TwoProduct), and every product of a coefficient component with one of these two terms
  // more: g(x) as a sum of at most 64 exact terms, when every factor is in the domain.
  double s = 0.0, e = 0.0;
  numeric::two_sum(x, -f.o, s, e);
  std::array<double, 6> sq{};
  numeric::two_product(s, s, sq[1], sq[0]);
  numeric::two_product(2.0 * s, e, sq[3], sq[2]);
  numeric::two_product(e, e, sq[5], sq[4]);
  const std::size_t n_sq = e == 0.0 ? 2 : 6;
  const std::size_t n_d = e == 0.0 ? 2 : 4;  // terms of a1 component times (s + e)
  const std::size_t n_terms = f.a[0].size() + n_d * f.a[1].size() + 2 * n_sq * f.a[2].size();
  bool in_domain = std::isfinite(s) && Expansion::in_domain(s) && Expansion::in_domain(2.0 * s) &&
                   Expansion::in_domain(e) && n_terms <= Expansion::kCapacity;
  for (std::size_t i = 0; i < n_sq && in_domain; ++i) in_domain = Expansion::in_domain(sq[i]);
  for (std::size_t k = 1; k < 3 && in_domain; ++k)
    for (std::size_t i = 0; i < f.a[k].size(); ++i)
      in_domain = in_domain && Expansion::in_domain(f.a[k][i]);
  if (in_domain) {
    std::array<double, Expansion::kCapacity> t;
    std::size_t n = 0;
    for (std::size_t i = 0; i < f.a[0].size(); ++i) t[n++] = f.a[0][i];
    for (std::size_t i = 0; i < f.a[1].size(); ++i) {
      numeric::two_product(f.a[1][i], s, t[n + 1], t[n]);
      if (e != 0.0) numeric::two_product(f.a[1][i], e, t[n + 3], t[n + 2]);
      n += n_d;
    }
    for (std::size_t i = 0; i < f.a[2].size(); ++i) {
      for (std::size_t j = 0; j < n_sq; ++j) {
        numeric::two_product(f.a[2][i], sq[j], t[n + 1], t[n]);
        n += 2;
      }
    }
    return numeric::sum_sign(t.data(), n);
  }
  const Expansion dd = Expansion::difference(x, f.o);
  Expansion g = f.a[1] * dd;
  if (f.a[2].size() > 0) g.add((f.a[2] * dd) * dd);
  g.add(f.a[0]);
  if (!g.ok()) {
    ok = false;
    return 0;
  }
  return g.sign();
}

/// sign g(x), exactly, for g of degree <= 1 whose two coefficients have at most two components
/// each (the difference of two linear motions of one origin): the at most ten exact terms of
/// a0 + a1 (x - o) summed by sum_sign (a filter, then exactly). `ok` is cleared (and 0
/// returned) outside the expansions' domain.
int sign_at_linear(const Form& f, double x, bool& ok) {
  double s = 0.0, e = 0.0;
  numeric::two_sum(x, -f.o, s, e);
  if (!std::isfinite(s) || !Expansion::in_domain(s) || !Expansion::in_domain(e)) {
    ok = false;
    return 0;
  }
  if (e == 0.0 && f.a[1].size() == 1 && f.a[0].size() <= 1) {  // the common case: 3 terms
    const double c = f.a[1][0];
    if (!Expansion::in_domain(c)) {
      ok = false;
      return 0;
    }
    std::array<double, 3> t{f.a[0].size() == 1 ? f.a[0][0] : 0.0, 0.0, 0.0};
    numeric::two_product(c, s, t[2], t[1]);
    return numeric::sum_sign(t.data(), 3);
  }
  std::array<double, 10> t;
  std::size_t n = 0;
  for (std::size_t i = 0; i < f.a[0].size(); ++i) t[n++] = f.a[0][i];
  for (std::size_t i = 0; i < f.a[1].size(); ++i) {
    const double c = f.a[1][i];
    if (!Expansion::in_domain(c)) {
      ok = false;
      return 0;
    }
    numeric::two_product(c, s, t[n + 1], t[n]);
    n += 2;
    if (e != 0.0) {
      numeric::two_product(c, e, t[n + 1], t[n]);
      n += 2;
    }
  }
  return numeric::sum_sign(t.data(), n);
}

/// The sign of a1^2 - 4 a0 a2 for g of degree 2 (coefficients of at most LazyTime::kTerms
/// components): a filter on the rounded coefficients (each within 4u of its value, so the
/// rounded discriminant is within 12u (a1^2 + 4 |a0 a2|) of the exact one; 2^-46 = 128u of it
/// decides), else expansions. 2 (not a sign) outside the expansions' domain.
int discriminant_sign(const Form& f) {
  const double a0 = approx(f.a[0]), a1 = approx(f.a[1]), a2 = approx(f.a[2]);
  const double p = a1 * a1, q = 4.0 * a0 * a2, d = p - q;
  const double magnitude = p + std::fabs(q);
  if (std::isfinite(magnitude) && magnitude >= 0x1p-900 && std::fabs(d) > 0x1p-46 * magnitude)
    return d > 0.0 ? 1 : -1;
  Expansion disc = f.a[1] * f.a[1];
  disc.subtract((f.a[0] * f.a[2]).scaled(4.0));
  if (!disc.ok()) return 2;
  return disc.sign();
}

using numeric::next_double;

/// A root's place: the double lo == hi, or strictly between the adjacent doubles lo < hi.
struct Bracket {
  double lo = 0.0, hi = 0.0;
};

/// The one root of g in [left, right] (left may be -inf, right +inf), where g is monotone:
/// rising = +1 (g < 0 before the root, > 0 after) or -1. A finite end is known to lie on its
/// side of the root. From `start`, steps doubling towards the root until the sign changes, then
/// bisection on doubles. nullopt outside the domain (or an estimate beyond the doubles).
std::optional<Bracket> bracket_root(const Form& f, int rising, double start, double left,
                                    double right) {
  bool ok = true;
  const bool linear = f.a[2].size() == 0 && f.a[0].size() <= 2 && f.a[1].size() <= 2;
  auto side = [&](double x) {  // -1 before the root
    return (linear ? sign_at_linear(f, x, ok) : sign_at(f, x, ok)) * rising;
  };
  if (!std::isfinite(start)) return std::nullopt;
  start = std::clamp(start, left, right);
  int s = side(start);
  if (!ok) return std::nullopt;
  if (s == 0) return Bracket{start, start};
  double lo = start, hi = start;  // side(lo) < 0 < side(hi) once both are found
  double step = next_double(std::abs(start), true) - std::abs(start);
  for (int k = 0;; ++k, step *= 2) {
    if (k > 2100) return std::nullopt;
    if (s < 0) {  // the root is to the right of lo
      const double y = std::min(right, std::max(next_double(lo, true), lo + step));
      if (!std::isfinite(y)) return std::nullopt;
      const int sy = side(y);
      if (!ok) return std::nullopt;
      if (sy == 0) return Bracket{y, y};
      if (sy > 0) {
        hi = y;
        break;
      }
      lo = y;
    } else {  // to the left of hi
      const double y = std::max(left, std::min(next_double(hi, false), hi - step));
      if (!std::isfinite(y)) return std::nullopt;
      const int sy = side(y);
      if (!ok) return std::nullopt;
      if (sy == 0) return Bracket{y, y};
      if (sy < 0) {
        lo = y;
        break;
      }
      hi = y;
    }
  }
  while (next_double(lo, true) < hi) {
    const double m = lo + (hi - lo) / 2;
    const int sm = side(m);
    if (!ok) return std::nullopt;
    if (sm == 0) return Bracket{m, m};
    (sm < 0 ? lo : hi) = m;
  }
  return Bracket{lo, hi};
}

/// sign(ra - rb) for the linear roots ra = oa - A0 / A1, rb = ob - B0 / B1: the sign of
/// (oa - ob) A1 B1 - A0 B1 + B0 A1 times sign(A1 B1). nullopt outside the expansions' domain.
[[gnu::noinline]] std::optional<int> compare_linear(double oa, const Expansion& a0,
                                                   const Expansion& a1, double ob,
                                  const Expansion& b0, const Expansion& b1) {
  Expansion d = b0 * a1;
  d.subtract(a0 * b1);
  if (oa != ob) d.add(Expansion::difference(oa, ob) * (a1 * b1));
  if (!d.ok() || a1.sign() == 0 || b1.sign() == 0) return std::nullopt;
  return d.sign() * a1.sign() * b1.sign();
}

/// An expansion's exact value.
mpq_class value(const Expansion& e) {
  mpq_class v = 0;
  for (std::size_t i = 0; i < e.size(); ++i) v += rational(e[i]);
  return v;
}

}  // namespace

LazyTime LazyTime::point(double t) {
  LazyTime x(Kind::Double);
  x.lo_ = x.hi_ = t;
  return x;
}

LazyTime LazyTime::of(ExactTime t) {
  LazyTime x(Kind::General);
  t.tighten();
  x.lo_ = t.lower();
  x.hi_ = t.upper();
  x.exact_ = std::make_unique<ExactTime>(std::move(t));
  return x;
}

LazyTime LazyTime::deferred_root(std::shared_ptr<const DeferredPolynomial> polynomial, double lo,
                                 double hi, int sign_lo) {
  assert(polynomial != nullptr && lo < hi && (sign_lo == 1 || sign_lo == -1));
  LazyTime x(Kind::Deferred);
  x.lo_ = lo;
  x.hi_ = hi;
  x.deferred_ = std::move(polynomial);
  x.deferred_sign_lo_ = static_cast<std::int8_t>(sign_lo);
  return x;
}

LazyTime::LazyTime(const LazyTime& other)
    : exact_(other.exact_ ? std::make_unique<ExactTime>(*other.exact_) : nullptr),
      deferred_(other.deferred_) {
  copy_plain(other);
}

LazyTime& LazyTime::operator=(const LazyTime& other) {
  if (this != &other) *this = LazyTime(other);
  return *this;
}

/// The friend of LazyTime that builds its low-degree roots and compares them.
struct LowDegreeRoots {
  static std::optional<LowDegreeDecision> decide(Form& f, const LazyTime& now);
  /// decide() with the failure root built in `failure` (reset unless it fails): the form the
  /// scheduler uses, so that the root is not moved on its way to the queue.
  static std::optional<LowDegreeSign> decide_into(Form& f, const LazyTime& now,
                                                  ExactFailure& failure);
  static bool same_polynomial(const LazyTime& a, const LazyTime& b);
  /// compare_without_gmp() past its quick cases (out of line: its expansions make a large
  /// frame).
  [[gnu::noinline]] static std::optional<int> compare_slowly(const LazyTime& a, const LazyTime& b);
};

std::optional<LowDegreeDecision> decide_low_degree(const MotionPolynomial& upper,
                                                   const MotionPolynomial& lower,
                                                   const LazyTime& now) {
  if (upper.degree > 2 || lower.degree > 2) return std::nullopt;
  Form f;
  const Term terms[2] = {{&upper, 1.0}, {&lower, -1.0}};
  form_of(terms, f);
  return LowDegreeRoots::decide(f, now);
}

std::optional<LowDegreeSign> decide_low_degree_into(const MotionPolynomial& upper,
                                                    const MotionPolynomial& lower,
                                                    const LazyTime& now, ExactFailure& failure) {
  failure.reset();
  if (upper.degree > 2 || lower.degree > 2) return std::nullopt;
  Form f;
  const Term terms[2] = {{&upper, 1.0}, {&lower, -1.0}};
  form_of(terms, f);
  return LowDegreeRoots::decide_into(f, now, failure);
}

namespace {
/// The form of a combination plus[0] + plus[1] - minus[0] - minus[1]; false when a motion is
/// missing or of degree > 2.
bool combination_form(const MotionCombination& c, Form& f) {
  const MotionPolynomial* all[4] = {c.plus[0], c.plus[1], c.minus[0], c.minus[1]};
  for (const MotionPolynomial* p : all)
    if (p == nullptr || p->degree > 2) return false;
  const Term terms[4] = {
      {c.plus[0], 1.0}, {c.plus[1], 1.0}, {c.minus[0], -1.0}, {c.minus[1], -1.0}};
  form_of(terms, f);
  return true;
}
}  // namespace

std::optional<LowDegreeDecision> decide_low_degree(const MotionCombination& c,
                                                   const LazyTime& now) {
  Form f;
  if (!combination_form(c, f)) return std::nullopt;
  return LowDegreeRoots::decide(f, now);
}

std::optional<LowDegreeSign> decide_low_degree_into(const MotionCombination& c,
                                                    const LazyTime& now, ExactFailure& failure) {
  failure.reset();
  Form f;
  if (!combination_form(c, f)) return std::nullopt;
  return LowDegreeRoots::decide_into(f, now, failure);
}

namespace {

/// sum_i sign_i (A_i - B_i)(C_i - D_i) of motions of degree <= 1 (the four motions of product i
/// at m[4 i .. 4 i + 3]): degree <= 2, its coefficients sums of products of expansions. One basis
/// for every factor: (t - o) when all motions have the origin o, else powers of t. False when a
/// motion's degree exceeds 1.
bool product_form(std::span<const MotionPolynomial* const> m, std::span<const double> sign,
                  Form& f) {
  for (const MotionPolynomial* p : m)
    if (p == nullptr || p->degree > 1) return false;
  const bool absolute = !std::all_of(
      m.begin(), m.end(), [&](const MotionPolynomial* p) { return p->origin == m[0]->origin; });
  for (std::size_t i = 0; i < sign.size(); ++i) {
    Form d[2];
    for (std::size_t j = 0; j < 2; ++j) {
      const Term terms[2] = {{m[4 * i + 2 * j], 1.0}, {m[4 * i + 2 * j + 1], -1.0}};
      form_of(terms, d[j], absolute);
    }
    f.o = d[0].o;
    const double s = sign[i];
    Expansion a0 = d[0].a[0] * d[1].a[0], a2 = d[0].a[1] * d[1].a[1];
    Expansion a1 = d[0].a[0] * d[1].a[1];
    a1.add(d[0].a[1] * d[1].a[0]);
    if (s > 0) {
      f.a[0].add(a0);
      f.a[1].add(a1);
      f.a[2].add(a2);
    } else {
      f.a[0].subtract(a0);
      f.a[1].subtract(a1);
      f.a[2].subtract(a2);
    }
  }
  return true;
}

}  // namespace

std::optional<LowDegreeDecision> decide_low_degree(const ProductCombination& c,
                                                   const LazyTime& now) {
  // (P0 - P1)(P2 - P3) - (M0 - M1)(M2 - M3), each factor of degree <= 1.
  const MotionPolynomial* const m[8] = {c.plus[0],  c.plus[1],  c.plus[2],  c.plus[3],
                                        c.minus[0], c.minus[1], c.minus[2], c.minus[3]};
  const double sign[2] = {1.0, -1.0};
  Form f;
  if (!product_form(m, sign, f)) return std::nullopt;
  return LowDegreeRoots::decide(f, now);
}

std::optional<LowDegreeDecision> decide_low_degree(const LengthComparison& c, const LazyTime& now) {
  // (ax - bx)^2 + (ay - by)^2 - (cx - dx)^2 - (cy - dy)^2, each difference of degree <= 1.
  const MovingPoint2 &a = c.p[0], &b = c.p[1], &q = c.p[2], &d = c.p[3];
  const MotionPolynomial* const m[16] = {a.x, b.x, a.x, b.x, a.y, b.y, a.y, b.y,
                                         q.x, d.x, q.x, d.x, q.y, d.y, q.y, d.y};
  const double sign[4] = {1.0, 1.0, -1.0, -1.0};
  Form f;
  if (!product_form(m, sign, f)) return std::nullopt;
  return LowDegreeRoots::decide(f, now);
}

std::optional<LowDegreeDecision> LowDegreeRoots::decide(Form& f, const LazyTime& now) {
  ExactFailure failure;
  const std::optional<LowDegreeSign> s = decide_into(f, now, failure);
  if (!s) return std::nullopt;
  LowDegreeDecision out;
  out.sign = s->sign;
  out.fails = s->fails;
  if (s->fails) out.failure = std::move(*failure);
  return out;
}

std::optional<LowDegreeSign> LowDegreeRoots::decide_into(Form& f, const LazyTime& now,
                                                         ExactFailure& failure) {
  failure.reset();
  if (!f.ok()) return std::nullopt;
  for (Expansion& e : f.a) e.compress();
  for (const Expansion& e : f.a)
    if (e.size() > LazyTime::kTerms) return std::nullopt;  // long: GMP decides
  LowDegreeSign out;
  const int degree = f.degree();
  if (degree <= 0) {  // a constant: never changes sign
    out.sign = degree < 0 ? 0 : f.a[0].sign();
    return out;
  }
  const int sign_at_end = f.a[static_cast<std::size_t>(degree)].sign();
  if (sign_at_end < 0)  // g = -f: leading coefficient > 0
    for (Expansion& e : f.a) e.negate();
  // The root in `failure`, built in place.
  auto make_root = [&](const Bracket& b, int index) {
    LazyTime& x = failure.emplace();
    if (b.lo == b.hi) {
      x.lo_ = x.hi_ = b.lo;  // a double (the default kind)
      return;
    }
    x.kind_ = LazyTime::Kind::Root;
    x.degree_ = static_cast<std::uint8_t>(degree);
    x.index_ = static_cast<std::uint8_t>(index);
    x.lo_ = b.lo;
    x.hi_ = b.hi;
    x.o_ = f.o;
    for (std::size_t k = 0; k < 3; ++k) {
      x.n_[k] = static_cast<std::uint8_t>(f.a[k].size());
      for (std::size_t i = 0; i < f.a[k].size(); ++i) x.a_[k][i] = f.a[k][i];
    }
  };
  // f changes sign at each root: just after now it has its sign at the end times -1 per root
  // still ahead. settle(root, n): `root` is the first of the n roots not known to be at or
  // before now; it is placed against now (nullopt: not without GMP) and fails f if after it.
  auto settle = [&](int roots_ahead) -> std::optional<LowDegreeSign> {
    const std::optional<int> order = compare_without_gmp(*failure, now);
    if (!order) {
      failure.reset();
      return std::nullopt;
    }
    if (*order <= 0) --roots_ahead;
    out.sign = roots_ahead % 2 == 0 ? sign_at_end : -sign_at_end;
    out.fails = *order > 0;
    if (!out.fails) failure.reset();
    return out;
  };
  const double inf = std::numeric_limits<double>::infinity();
  const double a0 = approx(f.a[0]), a1 = approx(f.a[1]);
  if (degree == 1) {  // g rises through its one root, near o - a0 / a1
    const std::optional<Bracket> b = bracket_root(f, 1, f.o - a0 / a1, -inf, inf);
    if (!b) return std::nullopt;
    make_root(*b, 0);
    return settle(1);
  }
  // Degree 2, a2 > 0: two roots exactly when the discriminant a1^2 - 4 a0 a2 is > 0 (= 0: a
  // touching double root, no sign change).
  const int disc = discriminant_sign(f);
  if (disc == 2) return std::nullopt;
  if (disc <= 0) {
    out.sign = sign_at_end;
    return out;
  }
  // The vertex splits the roots: g falls through the first before it and rises through the
  // second after it. A double near the vertex where g < 0 splits them as well; when there is
  // none the roots lie within a double or two of each other: GMP decides.
  const double a2 = approx(f.a[2]);
  const double vertex = f.o - a1 / (2.0 * a2);
  bool ok = true;
  if (!std::isfinite(vertex) || sign_at(f, vertex, ok) >= 0 || !ok) return std::nullopt;
  const double root_disc = std::sqrt(std::max(0.0, a1 * a1 - 4.0 * a0 * a2));
  const double q = -0.5 * (a1 + std::copysign(root_disc, a1));  // stable: no cancellation
  double e1 = f.o + q / a2, e2 = q != 0.0 ? f.o + a0 / q : vertex;
  if (e2 < e1) std::swap(e1, e2);
  // The first root is before now when some double x <= now, before the vertex, has g(x) < 0
  // (one sign, usually by the filter): then the second root alone is bracketed.
  const double x = e1 + 0x1p-30 * (std::abs(e1) + std::abs(f.o)) + 0x1p-1000;
  const bool first_passed =
      std::isfinite(x) && x < vertex && x <= now.lower() && sign_at(f, x, ok) < 0 && ok;
  if (!first_passed) {
    const std::optional<Bracket> b1 = bracket_root(f, -1, e1, -inf, vertex);
    if (!b1) return std::nullopt;
    make_root(*b1, 0);
    std::optional<LowDegreeSign> d = settle(2);
    if (!d || d->fails) return d;  // undecided, or both roots ahead: the first fails f
  }
  const std::optional<Bracket> b2 = bracket_root(f, 1, e2, vertex, inf);
  if (!b2) return std::nullopt;
  make_root(*b2, 1);
  return settle(1);
}

ExactTime& LazyTime::exact() {
  if (!exact_) {
    if (kind_ == Kind::Double) {
      exact_ = std::make_unique<ExactTime>(ExactTime::point(rational(lo_)));
    } else if (kind_ == Kind::Deferred) {
      exact_ = std::make_unique<ExactTime>(ExactTime::root_with_sign(
          deferred_->exact(), rational(lo_), rational(hi_), deferred_sign_lo_));
    } else {  // Root: of g(t) = a0 + a1 (t - o) + a2 (t - o)^2
      std::array<mpq_class, 3> a;
      for (std::size_t k = 0; k < 3; ++k)
        a[k] = value(Expansion::of_components(a_[k].data(), n_[k]));
      const mpq_class o = rational(o_);
      if (degree_ == 1) {
        exact_ = std::make_unique<ExactTime>(ExactTime::point(o - a[0] / a[1]));
      } else {  // in powers of t; square-free (two simple roots), one of them in (lo, hi)
        ExactPolynomial p({a[0] - a[1] * o + a[2] * o * o, a[1] - 2 * a[2] * o, a[2]});
        exact_ = std::make_unique<ExactTime>(
            ExactTime::root(std::move(p), rational(lo_), rational(hi_)));
      }
    }
  }
  return *exact_;
}

void LazyTime::sync() {
  if (exact_) {
    lo_ = std::max(lo_, exact_->lower());
    hi_ = std::min(hi_, exact_->upper());
  }
}

int order_by_brackets(const LazyTime& a, const LazyTime& b) {
  // A low-degree root lies strictly inside its bracket; a double is its bracket; a general
  // time lies in its closed bracket.
  const bool a_open = a.kind_ == LazyTime::Kind::Root || a.kind_ == LazyTime::Kind::Deferred;
  const bool b_open = b.kind_ == LazyTime::Kind::Root || b.kind_ == LazyTime::Kind::Deferred;
  if (a.hi_ < b.lo_ || (a.hi_ == b.lo_ && (a_open || b_open))) return -1;
  if (b.hi_ < a.lo_ || (b.hi_ == a.lo_ && (a_open || b_open))) return 1;
  return 0;
}

std::optional<int> compare_without_gmp(const LazyTime& a, const LazyTime& b) {
  if (const int c = order_by_brackets(a, b)) return c;
  using Kind = LazyTime::Kind;
  if (a.kind_ == Kind::Double && b.kind_ == Kind::Double) return 0;
  if (a.kind_ != Kind::Root || b.kind_ != Kind::Root) return std::nullopt;
  if (a.degree_ == 1 && b.degree_ == 1 && a.o_ == b.o_ && a.n_[0] <= 1 && a.n_[1] == 1 &&
      b.n_[0] <= 1 && b.n_[1] == 1) {
    // The common case (GRIDS: integer coefficients): sign(b0 a1 - a0 b1) from two exact
    // products, when the factors are in the expansions' domain.
    const double x0 = a.n_[0] == 1 ? a.a_[0][0] : 0.0, y0 = b.n_[0] == 1 ? b.a_[0][0] : 0.0;
    const double x1 = a.a_[1][0], y1 = b.a_[1][0];
    if (Expansion::in_domain(x0) && Expansion::in_domain(y0) && Expansion::in_domain(x1) &&
        Expansion::in_domain(y1)) {
      const int sign_x1 = x1 > 0.0 ? 1 : -1, sign_y1 = y1 > 0.0 ? 1 : -1;
      // A filter first: the rounded determinant, when its error bound decides.
      const double p0 = y0 * x1, q0 = x0 * y1, d = p0 - q0;
      if (std::fabs(d) > 0x1p-50 * (std::fabs(p0) + std::fabs(q0)))
        return (d > 0.0 ? 1 : -1) * sign_x1 * sign_y1;
      double p = 0.0, e = 0.0, q = 0.0, r = 0.0;
      numeric::two_product(y0, x1, p, e);
      numeric::two_product(-x0, y1, q, r);
      return numeric::expansion_sum_sign(e, p, r, q) * sign_x1 * sign_y1;
    }
  }
  return LowDegreeRoots::compare_slowly(a, b);
}

std::optional<int> LowDegreeRoots::compare_slowly(const LazyTime& a, const LazyTime& b) {
  auto expansion = [](const LazyTime& x, std::size_t k) {
    return Expansion::of_components(x.a_[k].data(), x.n_[k]);
  };
  if (a.degree_ == 1 && b.degree_ == 1)
    return compare_linear(a.o_, expansion(a, 0), expansion(a, 1), b.o_, expansion(b, 0),
                          expansion(b, 1));
  // The roots of one quadratic (the same g: the pair that just swapped, seen from either
  // side) are ordered by their index.
  if (same_polynomial(a, b)) return (a.index_ > b.index_) - (a.index_ < b.index_);
  return std::nullopt;
}

bool LowDegreeRoots::same_polynomial(const LazyTime& a, const LazyTime& b) {
  // Equal values, not equal representations: an expansion is not canonical (the same sum added
  // in another order may keep other components).
  if (a.degree_ != b.degree_ || a.o_ != b.o_) return false;
  for (std::size_t k = 0; k < 3; ++k) {
    Expansion d = Expansion::of_components(a.a_[k].data(), a.n_[k]);
    d.subtract(Expansion::of_components(b.a_[k].data(), b.n_[k]));
    if (!d.ok() || d.sign() != 0) return false;
  }
  return true;
}

int compare(LazyTime& a, LazyTime& b) {
  if (const std::optional<int> c = compare_without_gmp(a, b)) return *c;
  const int c = compare(a.exact(), b.exact());
  a.sync();
  b.sync();
  return c;
}

}  // namespace kinetic
