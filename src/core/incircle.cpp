#include "kinetic/core/incircle.hpp"

#include <algorithm>
#include <type_traits>

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
  return now.exact().sign_after(ExactPolynomial::of(f));
}

int sign_after(const InCircle& f, LazyTime& now) {
  if (now.is_double()) return sign_after(f, now.lower());
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

ExactPolynomial ExactPolynomial::of(const InCircle& f) {
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
