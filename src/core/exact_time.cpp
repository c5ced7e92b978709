#include "kinetic/core/exact_time.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <utility>

namespace kinetic {
namespace {

int sign(const mpq_class& x) { return mpq_sgn(x.get_mpq_t()); }

/// x(t) = sum c_i (t - o)^i in powers of t.
std::vector<mpq_class> expand(const MotionPolynomial& m) {
  const mpq_class o(m.origin);
  std::vector<mpq_class> out(static_cast<std::size_t>(m.degree) + 1);
  // Horner in (t - o): out = out * (t - o) + c_i, from the highest coefficient down.
  std::vector<mpq_class> acc;
  for (int i = m.degree; i >= 0; --i) {
    std::vector<mpq_class> next(acc.size() + 1);
    for (std::size_t k = 0; k < acc.size(); ++k) {
      next[k + 1] += acc[k];
      next[k] -= acc[k] * o;
    }
    next[0] += mpq_class(m.c[static_cast<std::size_t>(i)]);
    acc = std::move(next);
  }
  return acc;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// ExactPolynomial

ExactPolynomial::ExactPolynomial(std::vector<mpq_class> c) : c_(std::move(c)) { trim(); }

void ExactPolynomial::trim() {
  while (!c_.empty() && c_.back() == 0) c_.pop_back();
}

ExactPolynomial ExactPolynomial::of(const MotionPolynomial& m) {
  return ExactPolynomial(expand(m));
}

ExactPolynomial ExactPolynomial::difference(const MotionPolynomial& upper,
                                            const MotionPolynomial& lower) {
  return of(upper) - of(lower);
}

ExactPolynomial ExactPolynomial::of(const MotionCombination& f) {
  return of(*f.plus[0]) + of(*f.plus[1]) - of(*f.minus[0]) - of(*f.minus[1]);
}

ExactPolynomial ExactPolynomial::of(const ProductCombination& f) {
  return (of(*f.plus[0]) - of(*f.plus[1])) * (of(*f.plus[2]) - of(*f.plus[3])) -
         (of(*f.minus[0]) - of(*f.minus[1])) * (of(*f.minus[2]) - of(*f.minus[3]));
}

mpq_class ExactPolynomial::operator()(const mpq_class& t) const {
  mpq_class v = 0;
  for (std::size_t k = c_.size(); k-- > 0;) v = v * t + c_[k];
  return v;
}

int ExactPolynomial::sign_at(const mpq_class& t) const { return sign((*this)(t)); }

ExactPolynomial ExactPolynomial::derivative() const {
  std::vector<mpq_class> d;
  for (std::size_t k = 1; k < c_.size(); ++k) d.push_back(c_[k] * static_cast<long>(k));
  return ExactPolynomial(std::move(d));
}

ExactPolynomial operator+(const ExactPolynomial& a, const ExactPolynomial& b) {
  std::vector<mpq_class> c(std::max(a.c_.size(), b.c_.size()));
  for (std::size_t k = 0; k < a.c_.size(); ++k) c[k] += a.c_[k];
  for (std::size_t k = 0; k < b.c_.size(); ++k) c[k] += b.c_[k];
  return ExactPolynomial(std::move(c));
}

ExactPolynomial operator-(const ExactPolynomial& a, const ExactPolynomial& b) {
  std::vector<mpq_class> c(std::max(a.c_.size(), b.c_.size()));
  for (std::size_t k = 0; k < a.c_.size(); ++k) c[k] += a.c_[k];
  for (std::size_t k = 0; k < b.c_.size(); ++k) c[k] -= b.c_[k];
  return ExactPolynomial(std::move(c));
}

ExactPolynomial operator*(const ExactPolynomial& a, const ExactPolynomial& b) {
  if (a.is_zero() || b.is_zero()) return {};
  std::vector<mpq_class> c(a.c_.size() + b.c_.size() - 1);
  for (std::size_t i = 0; i < a.c_.size(); ++i) {
    for (std::size_t j = 0; j < b.c_.size(); ++j) c[i + j] += a.c_[i] * b.c_[j];
  }
  return ExactPolynomial(std::move(c));
}

void ExactPolynomial::divide(const ExactPolynomial& a, const ExactPolynomial& b, ExactPolynomial& q,
                             ExactPolynomial& r) {
  assert(!b.is_zero());
  std::vector<mpq_class> rem = a.c_;
  std::vector<mpq_class> quo(a.c_.size() >= b.c_.size() ? a.c_.size() - b.c_.size() + 1 : 0);
  const mpq_class& lead = b.c_.back();
  const std::size_t nb = b.c_.size();
  for (std::size_t k = rem.size(); k >= nb; --k) {  // k - 1: the degree being removed
    if (rem[k - 1] == 0) continue;
    const mpq_class f = rem[k - 1] / lead;
    const std::size_t shift = k - nb;
    quo[shift] = f;
    for (std::size_t j = 0; j < nb; ++j) rem[shift + j] -= f * b.c_[j];
  }
  q = ExactPolynomial(std::move(quo));
  r = ExactPolynomial(std::move(rem));
}

ExactPolynomial ExactPolynomial::gcd(ExactPolynomial a, ExactPolynomial b) {
  while (!b.is_zero()) {
    ExactPolynomial q, r;
    divide(a, b, q, r);
    a = std::move(b);
    b = std::move(r);
  }
  if (a.is_zero()) return a;
  const mpq_class lead = a.c_.back();
  for (mpq_class& x : a.c_) x /= lead;
  return a;
}

ExactPolynomial ExactPolynomial::square_free() const {
  if (degree() <= 0) return *this;
  const ExactPolynomial g = gcd(*this, derivative());
  ExactPolynomial q, r;
  divide(*this, g, q, r);
  assert(r.is_zero());
  return q;
}

// ---------------------------------------------------------------------------------------------
// SturmSequence

SturmSequence::SturmSequence(const ExactPolynomial& p) {
  assert(!p.is_zero());
  seq_.push_back(p);
  ExactPolynomial d = p.derivative();
  if (d.is_zero()) return;
  seq_.push_back(std::move(d));
  for (;;) {
    ExactPolynomial q, r;
    ExactPolynomial::divide(seq_[seq_.size() - 2], seq_.back(), q, r);
    if (r.is_zero()) break;
    seq_.push_back(ExactPolynomial() - r);
  }
}

int SturmSequence::variations(const mpq_class& x) const {
  int v = 0, last = 0;
  for (const ExactPolynomial& p : seq_) {
    const int s = p.sign_at(x);
    if (s == 0) continue;
    if (last != 0 && s != last) ++v;
    last = s;
  }
  return v;
}

int SturmSequence::count(const mpq_class& a, const mpq_class& b) const {
  return variations(a) - variations(b);
}

// ---------------------------------------------------------------------------------------------
// ExactTime

ExactTime ExactTime::point(const mpq_class& t) {
  ExactTime e;
  e.point_ = true;
  e.lo_ = t;
  e.hi_ = t;
  return e;
}

ExactTime ExactTime::root(ExactPolynomial p, mpq_class lo, mpq_class hi) {
  ExactTime e;
  e.point_ = false;
  e.sign_lo_ = p.sign_at(lo);
  assert(lo < hi && e.sign_lo_ != 0 && p.sign_at(hi) == -e.sign_lo_);
  e.p_ = std::move(p);
  e.lo_ = std::move(lo);
  e.hi_ = std::move(hi);
  return e;
}

double ExactTime::lower() const {
  double d = lo_.get_d();
  if (mpq_class(d) > lo_) d = std::nextafter(d, -std::numeric_limits<double>::infinity());
  return d;
}

double ExactTime::upper() const {
  double d = hi_.get_d();
  if (mpq_class(d) < hi_) d = std::nextafter(d, std::numeric_limits<double>::infinity());
  return d;
}

void ExactTime::split_at(const mpq_class& m) {
  assert(!point_ && lo_ < m && m < hi_);
  ++refinements_;
  const int s = p_.sign_at(m);
  if (s == 0) {
    point_ = true;
    lo_ = m;
    hi_ = m;
    p_ = ExactPolynomial();
  } else if (s == sign_lo_) {
    lo_ = m;
  } else {
    hi_ = m;
  }
}

void ExactTime::refine() {
  if (point_) return;
  split_at(mpq_class((lo_ + hi_) / 2));
}

namespace {
/// True when b is at most one double above a.
bool adjacent(double a, double b) {
  return !(b > std::nextafter(a, std::numeric_limits<double>::infinity()));
}
}  // namespace

void ExactTime::tighten() {
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> c;
  for (int round = 0; round < 3 && !point_ && !adjacent(lower(), upper()); ++round) {
    if (c.empty()) {
      for (const mpq_class& q : p_.coefficients()) c.push_back(q.get_d());
    }
    // A floating-point guess: bisection on the rounded polynomial inside the bracket.
    double a = lower(), b = upper();
    auto value = [&](double x) {
      double v = 0.0;
      for (std::size_t k = c.size(); k-- > 0;) v = v * x + c[k];
      return v;
    };
    const bool rising = sign_lo_ < 0;
    for (int i = 0; i < 1100 && !adjacent(a, b); ++i) {
      const double m = a + (b - a) / 2;
      if (!(m > a && m < b)) break;
      const double v = value(m);
      if (v == 0.0) {
        a = b = m;
        break;
      }
      if ((v < 0) == rising) {
        a = m;
      } else {
        b = m;
      }
    }
    // Exact signs at the guess and its neighbours shrink the bracket around the true root.
    const double g = a;
    for (const double x : {std::nextafter(g, -inf), g, std::nextafter(g, inf),
                           std::nextafter(std::nextafter(g, inf), inf)}) {
      if (point_) break;
      const mpq_class q(x);
      if (lo_ < q && q < hi_) split_at(q);
    }
  }
  while (!point_ && !adjacent(lower(), upper())) refine();
}

int compare(ExactTime& a, ExactTime& b, bool* equal_by_gcd) {
  if (equal_by_gcd != nullptr) *equal_by_gcd = false;
  bool tried_gcd = false;
  for (;;) {
    // A proper interval's root lies strictly inside it; a point is its bound.
    if (a.hi_ < b.lo_ || (a.hi_ == b.lo_ && !(a.point_ && b.point_))) return -1;
    if (b.hi_ < a.lo_ || (b.hi_ == a.lo_ && !(a.point_ && b.point_))) return 1;
    if (a.point_ && b.point_) return 0;  // overlapping points: the same rational
    if (a.point_) {  // inside b's open interval: where b's root is, by b's sign there
      b.split_at(a.lo_);
      continue;
    }
    if (b.point_) {
      a.split_at(b.lo_);
      continue;
    }
    if (!tried_gcd) {
      // Both roots in the open intersection I: equal exactly when gcd(pa, pb) has a root in I
      // (each polynomial has one root there, simple, and the gcd is non-zero at I's ends,
      // which are ends of a or b where their polynomials are not 0).
      tried_gcd = true;
      const ExactPolynomial g = ExactPolynomial::gcd(a.p_, b.p_);
      if (g.degree() >= 1) {
        const mpq_class lo = std::max(a.lo_, b.lo_), hi = std::min(a.hi_, b.hi_);
        if (g.sign_at(lo) * g.sign_at(hi) < 0) {
          if (equal_by_gcd != nullptr) *equal_by_gcd = true;
          return 0;
        }
      }
    }
    a.refine();
    b.refine();
  }
}

int ExactTime::sign_of(const ExactPolynomial& f) {
  if (f.is_zero()) return 0;
  if (point_) return f.sign_at(lo_);
  // f vanishes at the root exactly when gcd(f, p) has a root in (lo, hi).
  const ExactPolynomial g = ExactPolynomial::gcd(f, p_);
  if (g.degree() >= 1 && g.sign_at(lo_) * g.sign_at(hi_) < 0) return 0;
  // Otherwise refine until f has no root in [lo, hi]: its sign there is the answer.
  const ExactPolynomial s = f.square_free();
  if (s.degree() <= 0) return f.sign_at(lo_);
  const SturmSequence sturm(s);
  while (!point_) {
    if (s.sign_at(lo_) != 0 && sturm.count(lo_, hi_) == 0) return f.sign_at(hi_);
    refine();
  }
  return f.sign_at(lo_);
}

int ExactTime::sign_after(const ExactPolynomial& f) {
  for (ExactPolynomial g = f; !g.is_zero(); g = g.derivative()) {
    const int s = sign_of(g);
    if (s != 0) return s;
  }
  return 0;
}

ExactDecision decide_exact(const ExactPolynomial& f, ExactTime& now, const mpq_class& horizon) {
  ExactDecision d;
  if (f.degree() <= 1) {  // a constant, or one rational root: no isolation
    if (f.degree() < 1) {
      d.sign = f.is_zero() ? 0 : sgn(f.coefficients()[0]);
      return d;
    }
    const int slope = sgn(f.coefficients()[1]);
    ExactTime root = ExactTime::point(-f.coefficients()[0] / f.coefficients()[1]);
    const int c = compare(root, now);
    d.sign = c > 0 ? -slope : slope;  // just after now: before the root, or at/after it
    if (c > 0 && root.lo() <= horizon) {
      d.fails = true;
      d.failure = std::move(root);
    }
    return d;
  }
  d.sign = now.sign_after(f);
  if (d.sign == 0 || !(now.lo() < horizon)) return d;
  // Between two consecutive roots f keeps its sign, so the first root after now where the sign
  // just after differs from d.sign is where the certificate fails.
  for (ExactTime& r : isolate_roots(f, now.lo(), horizon)) {
    if (compare(r, now) <= 0) continue;
    if (r.sign_after(f) != d.sign) {
      d.fails = true;
      d.failure = std::move(r);
      return d;
    }
  }
  return d;
}

std::vector<ExactTime> isolate_roots(const ExactPolynomial& f, const mpq_class& lo,
                                     const mpq_class& hi) {
  assert(!f.is_zero() && lo < hi);
  std::vector<ExactTime> out;
  const ExactPolynomial s = f.square_free();
  if (s.degree() <= 0) return out;
  const SturmSequence sturm(s);
  // Depth-first, right half pushed first: the roots come out ascending.
  std::vector<std::pair<mpq_class, mpq_class>> stack{{lo, hi}};
  while (!stack.empty()) {
    auto [a, b] = std::move(stack.back());
    stack.pop_back();
    const int k = sturm.count(a, b);
    if (k == 0) continue;
    if (k >= 2) {
      const mpq_class m = (a + b) / 2;
      stack.emplace_back(m, b);
      stack.emplace_back(a, m);
      continue;
    }
    // One root in (a, b]: at b, or shrink (a, b] until its ends are not roots.
    for (;;) {
      if (s.sign_at(b) == 0) {
        out.push_back(ExactTime::point(b));
        break;
      }
      if (s.sign_at(a) != 0) {
        out.push_back(ExactTime::root(s, a, b));
        break;
      }
      const mpq_class m = (a + b) / 2;
      if (sturm.count(a, m) == 1) {
        b = m;
      } else {
        a = m;
      }
    }
  }
  return out;
}

}  // namespace kinetic
