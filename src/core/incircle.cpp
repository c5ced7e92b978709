#include "kinetic/core/incircle.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <type_traits>

#include "core/compensated_horner.hpp"
#include "core/float_decision.hpp"
#include "core/numeric/expansion.hpp"
#include "core/numeric/interval.hpp"
#include "kinetic/core/exact_time.hpp"
#include "kinetic/core/motion_table.hpp"

namespace kinetic {

namespace {

/// The in-circle determinant of a, b, c, d from their coordinates, in any arithmetic closed under
/// +, -, * (intervals, rationals, exact polynomials).
template <class N>
N incircle_determinant(const std::array<N, 8>& v) {
  const N adx = v[0] - v[6], ady = v[1] - v[7];
  const N bdx = v[2] - v[6], bdy = v[3] - v[7];
  const N cdx = v[4] - v[6], cdy = v[5] - v[7];
  const N alift = adx * adx + ady * ady;
  const N blift = bdx * bdx + bdy * bdy;
  const N clift = cdx * cdx + cdy * cdy;
  return N(alift * (bdx * cdy - bdy * cdx) - blift * (adx * cdy - ady * cdx) +
           clift * (adx * bdy - ady * bdx));
}

/// |a - b|^2 - |c - d|^2 from the coordinates a_x, a_y, b_x, ..., d_y, in any arithmetic closed
/// under +, -, *.
template <class N>
N squared_length_difference(const std::array<N, 8>& v) {
  const N abx = v[0] - v[2], aby = v[1] - v[3], cdx = v[4] - v[6], cdy = v[5] - v[7];
  return N((abx * abx + aby * aby) - (cdx * cdx + cdy * cdy));
}

const MotionPolynomial& coordinate(const InCircle& f, int k) {
  const MovingPoint2& p = f.p[static_cast<std::size_t>(k / 2)];
  return k % 2 == 0 ? *p.x : *p.y;
}

/// The sign when the filtered positions at t decide it, else 0.
int filtered_sign_at(const InCircle& f, Time t) {
  std::array<numeric::Interval, 8> v;
  for (int k = 0; k < 8; ++k) {
    const FilteredValue fv = evaluate_filtered(coordinate(f, k), t);
    v[static_cast<std::size_t>(k)] = numeric::around(fv.value, fv.error);
  }
  return incircle_determinant(v).sign();
}

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

using numeric::Expansion;

/// A polynomial in t of degree <= 8 with floating-point expansion coefficients: the in-circle
/// determinant of points on lines and parabolas computed exactly without GMP (Shewchuk's
/// expansions), then made rational once. Not ok() when a motion has degree > 2 or an expansion
/// leaves its domain or capacity (the caller then computes in rationals).
struct ExpansionPolynomial {
  static constexpr int kMaxDegree = 8;
  std::array<Expansion, kMaxDegree + 1> a;  // (not zeroed: each Expansion starts empty)
  int degree = -1;
  bool ok = true;

  /// x(t) of a motion of degree <= 2, in powers of t: c0 + c1 (t - o) + c2 (t - o)^2 =
  /// (c0 - c1 o + c2 o^2) + (c1 - 2 c2 o) t + c2 t^2.
  static ExpansionPolynomial of(const MotionPolynomial& m) {
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
    p.finish();
    return p;
  }

  void finish() {
    for (int k = 0; k <= degree; ++k) {
      Expansion& e = a[static_cast<std::size_t>(k)];
      ok = ok && e.ok();
      e.compress();
    }
  }

  friend ExpansionPolynomial combine(const ExpansionPolynomial& x, const ExpansionPolynomial& y,
                                     bool subtract) {
    ExpansionPolynomial r = x;
    r.ok = x.ok && y.ok;
    r.degree = std::max(x.degree, y.degree);
    for (int k = 0; k <= y.degree && r.ok; ++k) {
      const auto i = static_cast<std::size_t>(k);
      if (subtract) {
        r.a[i].subtract(y.a[i]);
      } else {
        r.a[i].add(y.a[i]);
      }
    }
    r.finish();
    return r;
  }
  friend ExpansionPolynomial operator+(const ExpansionPolynomial& x, const ExpansionPolynomial& y) {
    return combine(x, y, false);
  }
  friend ExpansionPolynomial operator-(const ExpansionPolynomial& x, const ExpansionPolynomial& y) {
    return combine(x, y, true);
  }
  friend ExpansionPolynomial operator*(const ExpansionPolynomial& x, const ExpansionPolynomial& y) {
    ExpansionPolynomial r;
    r.ok = x.ok && y.ok && x.degree + y.degree <= kMaxDegree;
    if (!r.ok || x.degree < 0 || y.degree < 0) return r;
    r.degree = x.degree + y.degree;
    for (int i = 0; i <= x.degree && r.ok; ++i) {
      for (int j = 0; j <= y.degree && r.ok; ++j) {
        Expansion& c = r.a[static_cast<std::size_t>(i + j)];
        c.add(x.a[static_cast<std::size_t>(i)] * y.a[static_cast<std::size_t>(j)]);
        r.ok = c.ok();
      }
    }
    r.finish();
    return r;
  }
};

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

/// The in-circle polynomial of points on lines and parabolas in floating-point expansions;
/// nullopt when a motion's degree exceeds 2 or the expansions leave their domain or capacity.
std::optional<ExpansionPolynomial> incircle_expansions(const InCircle& f) {
  std::array<ExpansionPolynomial, 8> e;
  for (std::size_t k = 0; k < 8; ++k) {
    e[k] = ExpansionPolynomial::of(coordinate(f, static_cast<int>(k)));
    if (!e[k].ok) return std::nullopt;
  }
  std::optional<ExpansionPolynomial> d = incircle_determinant(e);
  if (!d->ok) return std::nullopt;
  return d;
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

namespace {

/// The decision on the polynomial d (exact, in expansions) in floating point: its coefficients
/// enclosed in intervals, its exact signs at doubles by Horner's rule in expansions, a failure a
/// deferred root carrying d's expansions. When now is itself a deferred root of +-d (the
/// certificate whose failure now is, seen again after the event), d's sign just after now is
/// that root's.
std::optional<FloatDecision> decide_expansion_polynomial(const ExpansionPolynomial& d,
                                                         const LazyTime& now, Time horizon) {
  int degree = d.degree;
  while (degree >= 0 && d.a[static_cast<std::size_t>(degree)].sign() == 0) --degree;
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
  const bool compensated = degree <= 8;
  if (compensated) {
    for (int k = 0; k <= degree; ++k) {
      const auto i = static_cast<std::size_t>(k);
      d.a[i].to_double_double(c_hi[i], c_lo[i]);
    }
  }
  const auto exact_sign = [&](double t) -> std::optional<int> {
    if (compensated) {
      CompensatedValue v = compensated_horner(c_hi.data(), c_lo.data(), degree, t, 0.0);
      if (std::isfinite(v.error)) {
        double m = 0.0;  // sum |c_k| |t|^k, rounded (relative error far below 2^-40)
        for (int k = degree; k >= 0; --k)
          m = m * std::fabs(t) + std::fabs(c_hi[static_cast<std::size_t>(k)]);
        v.error += 0x1p-97 * m;
        if (const int sign = v.sign_if_certain(); sign != 0) return sign;
      }
    }
    Expansion v = d.a[static_cast<std::size_t>(degree)];
    for (int k = degree; k-- > 0;) {
      v = v.scaled(t);
      v.add(d.a[static_cast<std::size_t>(k)]);
      if (!v.ok()) return std::nullopt;
      v.compress();
    }
    return v.sign();
  };
  const auto root = [&](double lo, double hi, int sign_lo) {
    auto coefficients = std::make_shared<LazyTime::ExpansionCoefficients>();
    std::array<double, Expansion::kCapacity> components{};
    for (int k = 0; k <= degree; ++k) {
      const Expansion& x = d.a[static_cast<std::size_t>(k)];
      for (std::size_t i = 0; i < x.size(); ++i) components[i] = x[i];
      coefficients->push_back(std::span<const double>(components.data(), x.size()));
    }
    return LazyTime::deferred_root(std::move(coefficients), lo, hi, sign_lo);
  };
  // Now the failure of +-d itself (a deferred root of the same polynomial: e.g. the flipped
  // edge's certificate, of the same four points): d vanishes at now and changes sign there, a
  // simple root; just after now it has the sign of +-d's at its bracket's high end.
  int sign_after_now = 0;
  if (const LazyTime::ExpansionCoefficients* q = now.deferred_coefficients();
      q != nullptr && q->size() == static_cast<std::size_t>(degree) + 1) {
    for (const double c_sign : {1.0, -1.0}) {
      bool same = true;
      for (int k = 0; k <= degree && same; ++k) {
        Expansion difference = d.a[static_cast<std::size_t>(k)];
        for (const double x : (*q)[static_cast<std::size_t>(k)]) difference.add(-c_sign * x);
        same = difference.ok() && difference.sign() == 0;
      }
      if (same) {
        sign_after_now = -static_cast<int>(c_sign) * now.deferred_sign_lo();
        break;
      }
    }
  }
  return decide_in_floating_point(std::span<const numeric::Interval>(c.data(), degree + 1),
                                  exact_sign, now, horizon, root, sign_after_now);
}

/// The orientation-like product combination (P0 - P1)(P2 - P3) - (M0 - M1)(M2 - M3) of motions
/// of degree <= 2 in floating-point expansions (degree <= 4); nullopt beyond.
std::optional<ExpansionPolynomial> product_expansions(const ProductCombination& f) {
  std::array<ExpansionPolynomial, 8> e;
  for (std::size_t k = 0; k < 8; ++k) {
    const MotionPolynomial* m = k < 4 ? f.plus[k] : f.minus[k - 4];
    if (m == nullptr) return std::nullopt;
    e[k] = ExpansionPolynomial::of(*m);
    if (!e[k].ok) return std::nullopt;
  }
  std::optional<ExpansionPolynomial> d =
      (e[0] - e[1]) * (e[2] - e[3]) - (e[4] - e[5]) * (e[6] - e[7]);
  if (!d->ok) return std::nullopt;
  return d;
}

}  // namespace

std::optional<FloatDecision> decide_in_floating_point(const InCircle& f, const LazyTime& now,
                                                      Time horizon) {
  const std::optional<ExpansionPolynomial> found = incircle_expansions(f);
  if (!found) return std::nullopt;
  return decide_expansion_polynomial(*found, now, horizon);
}

std::optional<FloatDecision> decide_in_floating_point(const ProductCombination& f,
                                                      const LazyTime& now, Time horizon) {
  const std::optional<ExpansionPolynomial> found = product_expansions(f);
  if (!found) return std::nullopt;
  return decide_expansion_polynomial(*found, now, horizon);
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
