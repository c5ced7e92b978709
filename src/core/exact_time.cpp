#include "kinetic/core/exact_time.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <utility>

#include "core/float_decision.hpp"
#include "core/numeric/interval.hpp"
#include "core/numeric/ordinal.hpp"

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

ExactPolynomial::ExactPolynomial(std::vector<mpq_class> c) : c_(std::move(c)) {
  note_gmp_work();
  trim();
}

void ExactPolynomial::trim() {
  while (!c_.empty() && c_.back() == 0) c_.pop_back();
  forget_views();
}

void ExactPolynomial::forget_views() {
  enclosure_.clear();
  dyadic_.clear();
  dyadic_state_ = 0;
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

namespace {

/// log2 of a positive power of two, or -1 when q's denominator is not one.
long dyadic_exponent(const mpz_class& den) {
  if (mpz_popcount(den.get_mpz_t()) != 1) return -1;
  return static_cast<long>(mpz_scan1(den.get_mpz_t(), 0));
}

/// l c_k for l the lcm of the denominators: integers, the coefficients times a positive factor.
std::vector<mpz_class> integer_coefficients(const std::vector<mpq_class>& c) {
  mpz_class l = 1;
  for (const mpq_class& q : c) mpz_lcm(l.get_mpz_t(), l.get_mpz_t(), q.get_den_mpz_t());
  std::vector<mpz_class> z(c.size());
  for (std::size_t k = 0; k < c.size(); ++k) {
    mpz_divexact(z[k].get_mpz_t(), l.get_mpz_t(), c[k].get_den_mpz_t());
    z[k] *= c[k].get_num();
  }
  return z;
}

}  // namespace

mpq_class dyadic_at_or_below(const mpq_class& q) {
  if (dyadic_exponent(q.get_den()) >= 0) return q;
  // floor(q 2^k) / 2^k with 2^k above q's denominator.
  const mp_bitcnt_t k = mpz_sizeinbase(q.get_den_mpz_t(), 2) + 2;
  mpz_class scaled;
  mpz_mul_2exp(scaled.get_mpz_t(), q.get_num_mpz_t(), k);
  mpz_fdiv_q(scaled.get_mpz_t(), scaled.get_mpz_t(), q.get_den_mpz_t());
  mpz_class den;
  mpz_setbit(den.get_mpz_t(), k);
  mpq_class out(scaled, den);
  out.canonicalize();
  return out;
}

mpq_class dyadic_at_or_above(const mpq_class& q) { return -dyadic_at_or_below(-q); }

int ExactPolynomial::sign_at(const mpq_class& t) const {
  if (c_.empty()) return 0;
  if (dyadic_state_ == 0) {
    // c_k = n_k / 2^e_k: integers C_k = n_k 2^(E - e_k) over 2^E, E the largest e_k.
    long top = 0;
    bool dyadic = true;
    for (const mpq_class& q : c_) {
      const long e = dyadic_exponent(q.get_den());
      if (e < 0) {
        dyadic = false;
        break;
      }
      top = std::max(top, e);
    }
    dyadic_state_ = dyadic ? 1 : 2;
    if (dyadic) {
      dyadic_.clear();
      for (const mpq_class& q : c_) {
        mpz_class z = q.get_num();
        const long e = dyadic_exponent(q.get_den());
        mpz_mul_2exp(z.get_mpz_t(), z.get_mpz_t(), static_cast<mp_bitcnt_t>(top - e));
        dyadic_.push_back(std::move(z));
      }
    }
  }
  const long g = dyadic_state_ == 1 ? dyadic_exponent(t.get_den()) : -1;
  if (g < 0) return sign((*this)(t));
  // t = M / 2^g: 2^(E + g d) f(t) = v_0 with v_d = C_d, v_k = v_(k+1) M + C_k 2^(g (d - k)):
  // integers only, the same sign as f(t).
  const mpz_class& m = t.get_num();
  const std::size_t d = dyadic_.size() - 1;
  mpz_class v = dyadic_[d], term;
  for (std::size_t k = d; k-- > 0;) {
    v *= m;
    mpz_mul_2exp(term.get_mpz_t(), dyadic_[k].get_mpz_t(),
                 static_cast<mp_bitcnt_t>(static_cast<unsigned long>(g) * (d - k)));
    v += term;
  }
  return sgn(v);
}

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

namespace {
thread_local const std::atomic<bool>* g_exact_interrupt = nullptr;
}  // namespace

ExactInterruptScope::ExactInterruptScope(const std::atomic<bool>* flag)
    : previous_(g_exact_interrupt) {
  g_exact_interrupt = flag;
}
ExactInterruptScope::~ExactInterruptScope() { g_exact_interrupt = previous_; }

void poll_exact_interrupt() {
  if (g_exact_interrupt != nullptr && g_exact_interrupt->load(std::memory_order_relaxed))
    throw ExactInterrupted();
}

void ExactPolynomial::divide(const ExactPolynomial& a, const ExactPolynomial& b, ExactPolynomial& q,
                             ExactPolynomial& r) {
  assert(!b.is_zero());
  std::vector<mpq_class> rem = a.c_;
  std::vector<mpq_class> quo(a.c_.size() >= b.c_.size() ? a.c_.size() - b.c_.size() + 1 : 0);
  const mpq_class& lead = b.c_.back();
  const std::size_t nb = b.c_.size();
  for (std::size_t k = rem.size(); k >= nb; --k) {  // k - 1: the degree being removed
    poll_exact_interrupt();
    if (rem[k - 1] == 0) continue;
    const mpq_class f = rem[k - 1] / lead;
    const std::size_t shift = k - nb;
    quo[shift] = f;
    for (std::size_t j = 0; j < nb; ++j) rem[shift + j] -= f * b.c_[j];
  }
  q = ExactPolynomial(std::move(quo));
  r = ExactPolynomial(std::move(rem));
}

ExactPolynomial ExactPolynomial::positive_remainder(const ExactPolynomial& a,
                                                    const ExactPolynomial& b) {
  assert(!b.is_zero());
  // Integer coefficients (each polynomial times a positive factor).
  std::vector<mpz_class> rem = integer_coefficients(a.c_);
  const std::vector<mpz_class> div = integer_coefficients(b.c_);
  const std::size_t nb = div.size();
  const mpz_class& lead = div.back();
  const mpz_class scale = abs(lead);
  const int lead_sign = sgn(lead);
  mpz_class top, t;
  // Each step removes the top term: rem <- |L| rem - sgn(L) rem_top x^shift b. After k steps rem
  // is |L|^k (a mod b), with integers only.
  for (std::size_t k = rem.size(); k >= nb; --k) {
    poll_exact_interrupt();
    if (rem[k - 1] == 0) continue;
    top = rem[k - 1];
    if (lead_sign < 0) top = -top;
    const std::size_t shift = k - nb;
    for (std::size_t j = 0; j < shift; ++j) rem[j] *= scale;
    for (std::size_t j = 0; j < nb; ++j) {
      t = top * div[j];
      rem[shift + j] *= scale;
      rem[shift + j] -= t;
    }
  }
  rem.resize(std::min(rem.size(), nb - 1));
  std::vector<mpq_class> out(rem.begin(), rem.end());
  return ExactPolynomial(std::move(out)).primitive_part();
}

ExactPolynomial ExactPolynomial::gcd(ExactPolynomial a, ExactPolynomial b) {
  // A primitive remainder sequence: each remainder is a positive multiple of the Euclidean
  // one, with coprime integer coefficients (no rational coefficients growing step by step).
  if (!a.is_zero()) a = a.primitive_part();
  if (!b.is_zero()) b = b.primitive_part();
  while (!b.is_zero()) {
    ExactPolynomial r = positive_remainder(a, b);
    a = std::move(b);
    b = std::move(r);
  }
  if (a.is_zero()) return a;
  const mpq_class lead = a.c_.back();
  for (mpq_class& x : a.c_) x /= lead;
  a.forget_views();  // the coefficients changed in place
  return a;
}

ExactPolynomial ExactPolynomial::time_scaled(int e) const {
  std::vector<mpq_class> c = c_;
  for (std::size_t k = 1; k < c.size(); ++k) {
    const long shift = static_cast<long>(e) * static_cast<long>(k);
    if (shift > 0)
      mpq_mul_2exp(c[k].get_mpq_t(), c[k].get_mpq_t(), static_cast<unsigned long>(shift));
    if (shift < 0)
      mpq_div_2exp(c[k].get_mpq_t(), c[k].get_mpq_t(), static_cast<unsigned long>(-shift));
  }
  return ExactPolynomial(std::move(c));
}

ExactPolynomial ExactPolynomial::square_free() const {
  if (degree() <= 0) return *this;
  const ExactPolynomial g = gcd(*this, derivative());
  if (g.degree() <= 0) return *this;  // already square-free (g is monic: 1)
  ExactPolynomial q, r;
  divide(*this, g, q, r);
  assert(r.is_zero());
  return q.primitive_part();
}

ExactPolynomial ExactPolynomial::primitive_part() const {
  // The integers l c_k divided by their gcd: coprime.
  std::vector<mpz_class> z = integer_coefficients(c_);
  mpz_class g = 0;
  for (const mpz_class& v : z) mpz_gcd(g.get_mpz_t(), g.get_mpz_t(), v.get_mpz_t());
  std::vector<mpq_class> out;
  out.reserve(z.size());
  for (mpz_class& v : z) {
    if (g > 1) mpz_divexact(v.get_mpz_t(), v.get_mpz_t(), g.get_mpz_t());
    out.emplace_back(v);
  }
  return ExactPolynomial(std::move(out));
}

// ---------------------------------------------------------------------------------------------
// SturmSequence

SturmSequence::SturmSequence(const ExactPolynomial& p) {
  assert(!p.is_zero());
  // Each member is kept as its primitive part (a positive multiple: the same signs, so the same
  // variations): integer coefficients, so that its signs at dyadic points are read with integers
  // only (sign_at), and the remainders' coefficients stay small (a primitive remainder sequence).
  seq_.push_back(p.primitive_part());
  ExactPolynomial d = seq_.back().derivative();
  if (d.is_zero()) return;
  seq_.push_back(d.primitive_part());
  for (;;) {
    ExactPolynomial r = ExactPolynomial::positive_remainder(seq_[seq_.size() - 2], seq_.back());
    if (r.is_zero()) break;
    seq_.push_back(ExactPolynomial() - r);
  }
}

int SturmSequence::variations(const mpq_class& x) const {
  poll_exact_interrupt();
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
  note_gmp_work();
  ExactTime e;
  e.point_ = true;
  e.lo_ = t;
  e.hi_ = t;
  return e;
}

ExactTime ExactTime::root_with_sign(ExactPolynomial p, mpq_class lo, mpq_class hi, int sign_lo) {
  note_gmp_work();
  ExactTime e;
  e.point_ = false;
  e.sign_lo_ = sign_lo;
  assert(lo < hi && sign_lo != 0 && p.sign_at(lo) == sign_lo && p.sign_at(hi) == -sign_lo);
  e.p_ = std::move(p);
  e.lo_ = std::move(lo);
  e.hi_ = std::move(hi);
  return e;
}

ExactTime ExactTime::root(ExactPolynomial p, mpq_class lo, mpq_class hi) {
  note_gmp_work();
  ExactTime e;
  e.point_ = false;
  e.sign_lo_ = p.sign_at(lo);
  assert(lo < hi && e.sign_lo_ != 0 && p.sign_at(hi) == -e.sign_lo_);
  e.p_ = std::move(p);
  e.lo_ = std::move(lo);
  e.hi_ = std::move(hi);
  return e;
}

namespace {
/// The double nearest q when q is within the doubles' range, else the infinity on q's side (a
/// rational beyond the largest double: GMP's conversion is then not defined, and a double
/// infinity must never be turned back into a rational).
double to_double_or_infinity(const mpq_class& q) {
  static const mpq_class largest(std::numeric_limits<double>::max());
  if (q > largest) return std::numeric_limits<double>::infinity();
  if (q < -largest) return -std::numeric_limits<double>::infinity();
  return q.get_d();
}
}  // namespace

double ExactTime::lower() const {
  double d = to_double_or_infinity(lo_);
  if (std::isfinite(d) && mpq_class(d) > lo_)
    d = std::nextafter(d, -std::numeric_limits<double>::infinity());
  return d;
}

double ExactTime::upper() const {
  double d = to_double_or_infinity(hi_);
  if (std::isfinite(d) && mpq_class(d) < hi_)
    d = std::nextafter(d, std::numeric_limits<double>::infinity());
  return d;
}

void ExactTime::split_at(const mpq_class& m) {
  assert(!point_ && lo_ < m && m < hi_);
  poll_exact_interrupt();
  note_gmp_work();
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

namespace {

mpq_class power_of_two(long e) {
  mpq_class p = 1;
  if (e >= 0) mpq_mul_2exp(p.get_mpq_t(), p.get_mpq_t(), static_cast<mp_bitcnt_t>(e));
  else mpq_div_2exp(p.get_mpq_t(), p.get_mpq_t(), static_cast<mp_bitcnt_t>(-e));
  return p;
}

/// floor(log2 q) for q > 0, exactly.
long floor_log2(const mpq_class& q) {
  const long e = static_cast<long>(mpz_sizeinbase(q.get_num_mpz_t(), 2)) -
                 static_cast<long>(mpz_sizeinbase(q.get_den_mpz_t(), 2));
  // 2^(e - 1) < q < 2^(e + 1): settle which side of 2^e it is.
  return q >= power_of_two(e) ? e : e - 1;
}

/// A dyadic point strictly inside (a, b), a < b, for a bisection: the midpoint, unless the
/// interval spans many binary orders of magnitude on one side of 0, where the power of two
/// halfway between the ends' exponents is taken instead (so that an interval from near 0 or
/// near 1 to a bound like 2^1000 is narrowed in about ten steps, not a thousand).
mpq_class split_point(const mpq_class& a, const mpq_class& b) {
  if (sgn(a) < 0 && sgn(b) > 0) return mpq_class(0);
  if (sgn(b) <= 0 && sgn(a) < 0) return -split_point(-b, -a);
  // 0 <= a < b.
  const long eb = floor_log2(b);
  long ea = sgn(a) == 0 ? std::min(eb, 0L) - 1 : floor_log2(a) + 1;  // 2^ea > a
  if (sgn(a) == 0 && eb > 2) ea = 0;  // from 0 towards 1 first
  if (eb - ea >= 2) {
    const mpq_class m = power_of_two(ea + (eb - ea) / 2);
    if (a < m && m < b) return m;
  }
  return mpq_class((a + b) / 2);
}

}  // namespace

std::optional<long> magnitude_beyond(const MotionPolynomial& m, int log2) {
  std::optional<long> out;
  for (const mpq_class& c : expand(m)) {
    if (sign(c) == 0) continue;
    const long e = floor_log2(abs(c));
    if (e >= -log2 && e < log2) continue;
    if (!out || std::abs(e) > std::abs(*out)) out = e;
  }
  return out;
}

void ExactTime::refine() {
  if (point_) return;
  split_at(split_point(lo_, hi_));
}

using numeric::adjacent;
using numeric::ordinal_midpoint;

void ExactTime::tighten() {
  const double inf = std::numeric_limits<double>::infinity();
  // A bracket reaching beyond the doubles is cut at the largest double first: its root is then
  // either beyond every double (lower() is the largest, upper() infinity: adjacent) or within.
  static const mpq_class largest(std::numeric_limits<double>::max());
  if (!point_ && lo_ < largest && largest < hi_) split_at(largest);
  if (!point_ && lo_ < -largest && -largest < hi_) split_at(-largest);
  std::vector<double> c;
  for (int round = 0; round < 3 && !point_ && !adjacent(lower(), upper()); ++round) {
    if (!std::isfinite(lower()) || !std::isfinite(upper())) break;
    if (c.empty()) {
      for (const mpq_class& q : p_.coefficients()) c.push_back(to_double_or_infinity(q));
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
      const double m = ordinal_midpoint(a, b);
      if (!(m > a && m < b)) break;
      const double v = value(m);
      if (v == 0.0) {
        a = b = m;
        break;
      }
      if (std::isnan(v)) break;
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
      if (!std::isfinite(x)) continue;
      const mpq_class q(x);
      if (lo_ < q && q < hi_) split_at(q);
    }
  }
  // Bisection over the doubles inside the bracket: a root that is itself a double (an integer
  // time of a grid) is never a midpoint of rational bisection, and the doubles on either side
  // of it are two apart, so it is found by splitting at doubles; a bracket with no double inside
  // has adjacent doubles around it. Halving the doubles between the bracket's ends: at most 64
  // splits.
  while (!point_ && !adjacent(lower(), upper())) {
    const double l = lower(), h = upper();
    if (!std::isfinite(l) || !std::isfinite(h)) break;  // (cut at the largest double above)
    const mpq_class middle(ordinal_midpoint(l, h));
    const mpq_class above(std::nextafter(l, inf));
    if (lo_ < middle && middle < hi_) {
      split_at(middle);
    } else if (lo_ < above && above < hi_) {
      split_at(above);
    } else {
      refine();
    }
  }
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

namespace {

/// Every real within the double rounding of q: [q, q] when q is a double, else the two doubles
/// around it; the whole line when q is beyond the doubles (no finite enclosure).
numeric::Interval enclose_rational(const mpq_class& q) {
  const double d = to_double_or_infinity(q);
  if (!std::isfinite(d)) return numeric::Interval{-HUGE_VAL, HUGE_VAL};
  const mpq_class e(d);
  if (e == q) return numeric::Interval::point(d);
  return e < q ? numeric::Interval{d, std::nextafter(d, HUGE_VAL)}
               : numeric::Interval{std::nextafter(d, -HUGE_VAL), d};
}

numeric::Interval interval(const std::array<double, 2>& e) { return {e[0], e[1]}; }

/// True when |x| is 0 or within [2^-64, 2^64]: times where the floating-point filters work on
/// f as it is.
bool moderate(double x) {
  const double m = std::fabs(x);
  return m == 0.0 || (m >= 0x1p-64 && m <= 0x1p64);
}

/// The filters' view of f on times [a, b] (a < b, finite), as f(2^e s) for s in [a', b']: the
/// time scaled by a power of two when a or b is not moderate (far from 1, where the powers of
/// t leave the doubles), so that s is about 1. `coefficients`: the enclosures of f(2^e s)'s
/// coefficients (scaled by one more power of two, exactly; signs unchanged); false when the
/// scaled ends are not exact (a far below b in magnitude: the caller subdivides first).
struct TimeScaled {
  std::vector<numeric::Interval> coefficients;
  double a = 0.0, b = 0.0;
};
bool time_scaled(const ExactPolynomial& f, double a, double b, TimeScaled& out) {
  out.coefficients.clear();
  if (moderate(a) && moderate(b)) {
    for (const auto& e : f.enclosure()) out.coefficients.push_back(interval(e));
    out.a = a;
    out.b = b;
    return true;
  }
  const int e = std::max(a == 0.0 ? std::numeric_limits<int>::min() : std::ilogb(a),
                         b == 0.0 ? std::numeric_limits<int>::min() : std::ilogb(b));
  out.a = std::ldexp(a, -e);
  out.b = std::ldexp(b, -e);
  if (std::ldexp(out.a, e) != a || std::ldexp(out.b, e) != b) return false;
  const ExactPolynomial g = f.time_scaled(e);
  for (const auto& x : g.enclosure()) out.coefficients.push_back(interval(x));
  return true;
}

/// The sign of f on every t in [lo, hi] when interval arithmetic decides it (the coefficients
/// and the ends rounded outwards), else 0.
int enclosed_sign(const ExactPolynomial& f, double lo, double hi) {
  if (f.is_zero()) return 0;
  TimeScaled scaled;
  if (!time_scaled(f, lo, hi, scaled)) return 0;
  const auto& c = scaled.coefficients;
  const numeric::Interval t{scaled.a, scaled.b};
  numeric::Interval v = c.back();
  for (std::size_t k = c.size() - 1; k-- > 0;) v = v * t + c[k];
  return v.sign();
}

/// The Bernstein coefficients on [a, b] (a < b, finite) of the polynomial whose coefficients (in
/// powers of t) are enclosed by `c`, in interval arithmetic (the ends rounded outwards), written
/// to t[0, c.size()).
void bernstein_coefficients(std::span<const numeric::Interval> c, double a, double b,
                            numeric::Interval* t) {
  const std::size_t n = c.size();
  std::copy(c.begin(), c.end(), t);
  // Taylor coefficients at a (repeated synthetic division), then scaled by (b - a)^k.
  const numeric::Interval at = numeric::Interval::point(a);
  for (std::size_t i = 0; i + 1 < n; ++i) {
    for (std::size_t k = n - 1; k-- > i;) t[k] = t[k] + numeric::times_point(t[k + 1], a);
  }
  const numeric::Interval width = numeric::Interval::point(b) - at;
  numeric::Interval power = numeric::Interval::point(1.0);
  for (std::size_t k = 1; k < n; ++k) {
    power = power * width;
    t[k] = t[k] * power;
  }
  // b_i = sum_{k <= i} C(i, k) / C(d, k) t_k: with u_k = t_k / C(d, k) (C(d, k) an exact
  // integer), b_i = sum_{k <= i} C(i, k) u_k, the binomial transform of u, by Pascal's rule in
  // d (d + 1) / 2 additions (v_i += v_(i-1) for i from d down to j, j = 1..d).
  const std::size_t d = n - 1;
  assert(d <= 54);        // k C(d, k) below 2^53: every product and quotient below is exact
  double binomial = 1.0;  // C(d, k), exact (the structures' certificates have d <= 24)
  for (std::size_t k = 1; k <= d; ++k) {
    binomial = binomial * static_cast<double>(d - k + 1) / static_cast<double>(k);
    t[k] = numeric::Interval{numeric::down(t[k].lo / binomial), numeric::up(t[k].hi / binomial)};
  }
  for (std::size_t j = 1; j <= d; ++j)
    for (std::size_t i = d; i >= j; --i) t[i] = t[i] + t[i - 1];
}

/// The signs that Bernstein coefficients t[0, n) on [a, b] prove: the number of sign changes
/// along them, or -1 when one of them may be 0. `end_sign`, when given, is asked for the exact
/// sign of the polynomial at a or b when the first or the last coefficient (its value there)
/// cannot be signed (nullopt: not known; -1 is returned then, and when the value there is 0).
/// With `two_is_enough`, 2 as soon as two changes are seen (first and final then unset).
int count_variations(const numeric::Interval* t, std::size_t n, double a, double b, int* first,
                     int* final, const FunctionRef<std::optional<int>(double)>* end_sign,
                     bool two_is_enough) {
  const std::size_t d = n - 1;
  int last = 0, changes = 0;
  for (std::size_t i = 0; i <= d; ++i) {
    int s = t[i].sign();
    if (s == 0 && end_sign != nullptr && (i == 0 || i == d)) {
      const std::optional<int> e = (*end_sign)(i == 0 ? a : b);  // b_0 = f(a), b_d = f(b)
      if (e) s = *e;
    }
    if (s == 0) return -1;
    if (last != 0 && s != last) ++changes;
    if (i == 0 && first != nullptr) *first = s;
    last = s;
    // Two changes already: the caller splits whatever the rest (first and final unused).
    if (two_is_enough && changes == 2) return 2;
  }
  if (final != nullptr) *final = last;
  return changes;
}

/// bernstein_coefficients() and count_variations() in one (no end signs asked).
int bernstein_variations(std::span<const numeric::Interval> c, double a, double b, int* first,
                         int* final) {
  // The coefficients in scratch: on the stack up to degree 31 (every certificate of the
  // structures), else on the heap.
  constexpr std::size_t kInline = 32;
  std::array<numeric::Interval, kInline> inline_scratch;
  std::vector<numeric::Interval> heap_scratch;
  numeric::Interval* t = inline_scratch.data();
  if (c.size() > kInline) {
    heap_scratch.resize(c.size());
    t = heap_scratch.data();
  }
  bernstein_coefficients(c, a, b, t);
  return count_variations(t, c.size(), a, b, first, final, nullptr, false);
}

/// The Bernstein coefficients of [l, m] and [m, r] from those of [l, r] (d + 1 of them each) by
/// de Casteljau's algorithm, each step w_i = combine(w_i, w_(i+1)), an enclosure of
/// (1 - lambda) w_i + lambda w_(i+1) for lambda = (m - l) / (r - l).
template <class Combine>
void de_casteljau_split(const numeric::Interval* b, std::size_t d, Combine&& combine,
                        numeric::Interval* left, numeric::Interval* right) {
  std::array<numeric::Interval, 16> w;
  std::copy(b, b + d + 1, w.begin());
  left[0] = w[0];
  right[d] = w[d];
  for (std::size_t j = 1; j <= d; ++j) {
    for (std::size_t i = 0; i + j <= d; ++i) w[i] = combine(w[i], w[i + 1]);
    left[j] = w[0];
    right[d - j] = w[d - j];
  }
}

/// de_casteljau_split when m is exactly the midpoint: each step a sum and an exact halving.
void split_in_halves(const numeric::Interval* b, std::size_t d, numeric::Interval* left,
                     numeric::Interval* right) {
  de_casteljau_split(
      b, d,
      [](numeric::Interval x, numeric::Interval y) {
        const numeric::Interval s = x + y;
        numeric::Interval h{s.lo * 0.5, s.hi * 0.5};  // exact unless it underflows...
        if (!(std::fabs(s.lo) >= 0x1p-1020)) h.lo = numeric::down(h.lo);
        if (!(std::fabs(s.hi) >= 0x1p-1020)) h.hi = numeric::up(h.hi);
        return h;
      },
      left, right);
}

/// de_casteljau_split when m is any point of (l, r), lambda enclosed in `ratio`: the true ratio
/// is in it, so each step's convex combination in interval arithmetic encloses the true one and
/// the halves' coefficients enclose those of f on [l, m] and [m, r].
void split_at_ratio(const numeric::Interval* b, std::size_t d, numeric::Interval ratio,
                    numeric::Interval* left, numeric::Interval* right) {
  const numeric::Interval rest{numeric::down(1.0 - ratio.hi), numeric::up(1.0 - ratio.lo)};
  de_casteljau_split(
      b, d,
      [&](numeric::Interval x, numeric::Interval y) { return x * rest + y * ratio; }, left,
      right);
}

/// The same for f, on the scaled time when a or b is far from 1 (time_scaled).
int bernstein_variations(const ExactPolynomial& f, double a, double b, int* first = nullptr,
                         int* final = nullptr) {
  TimeScaled scaled;
  if (!time_scaled(f, a, b, scaled)) return -1;
  return bernstein_variations(scaled.coefficients, scaled.a, scaled.b, first, final);
}

/// The same in rational arithmetic (exact): zero coefficients carry no sign (Descartes' bound
/// on the roots in the open interval still holds), and the ends' signs are f(a) and f(b),
/// possibly 0 (a root at an end, which the count does not see).
int exact_bernstein_variations(const ExactPolynomial& f, double a, double b, int* first,
                               int* final) {
  const auto& c = f.coefficients();
  const std::size_t n = c.size();
  std::vector<mpq_class> t(c.begin(), c.end());
  const mpq_class at(a);
  for (std::size_t i = 0; i + 1 < n; ++i) {
    for (std::size_t k = n - 1; k-- > i;) t[k] += t[k + 1] * at;
  }
  const mpq_class width = mpq_class(b) - at;
  mpq_class power = 1;
  for (std::size_t k = 1; k < n; ++k) {
    power *= width;
    t[k] *= power;
  }
  const std::size_t d = n - 1;
  int last = 0, changes = 0;
  for (std::size_t i = 0; i <= d; ++i) {
    mpq_class sum = 0;
    mpz_class cik = 1, cdk = 1;
    for (std::size_t k = 0; k <= i; ++k) {
      if (k > 0) {
        cik = cik * static_cast<unsigned long>(i - k + 1) / static_cast<unsigned long>(k);
        cdk = cdk * static_cast<unsigned long>(d - k + 1) / static_cast<unsigned long>(k);
      }
      sum += t[k] * mpq_class(cik, cdk);
    }
    const int s = sgn(sum);
    if (i == 0 && first != nullptr) *first = s;
    if (i == d && final != nullptr) *final = s;
    if (s == 0) continue;
    if (last != 0 && s != last) ++changes;
    last = s;
  }
  return changes;
}

enum class Isolation { NoRoot, Root, Undecided };

/// Where to split [l, r] in the subdivision: the middle, or, when the ends differ in magnitude
/// by more than 2^32 (or one of them is not moderate and the other is 0 or of the other
/// sign), at 0 or the geometric middle of their exponents, so that a dozen splits reach any
/// scale between 2^-1074 and 2^1024 (halving would take a thousand).
double subdivision_point(double l, double r) {
  if (l < 0.0 && r > 0.0 && !(moderate(l) && moderate(r))) return 0.0;
  const double lo = std::fabs(l), hi = std::fabs(r);
  const double small = std::min(lo, hi), large = std::max(lo, hi);
  if (large > 0x1p32 * std::max(small, std::numeric_limits<double>::denorm_min())) {
    const int e_small = small == 0.0 ? -1074 : std::ilogb(small);
    const double m = std::ldexp(1.0, (e_small + std::ilogb(large)) / 2);
    const double signed_m = r > 0.0 ? m : -m;
    if (signed_m > l && signed_m < r) return signed_m;
  }
  return l + (r - l) / 2;
}

/// The first root of f after the exact time `now` and up to b, isolated in floating point:
/// Bernstein subdivision of [now.lower(), b], left to right. An interval with no sign change in
/// its (enclosed) Bernstein coefficients has no root, one with exactly one has exactly one,
/// simple (Descartes' rule for the Bernstein basis), with the signs of f at its ends those of
/// its first and last coefficients. Whether that root is after now is told by `sign_after_now`
/// (f's sign just after now): it is when f still has its left end's sign just after now. Root:
/// (lo, hi) holding it, f(lo) of sign `sign_lo`, no root of f in (now, lo]. Undecided: roots
/// closer than the subdivision resolves, or coefficients the enclosures cannot sign.
/// The subdivision of isolate_first_root over (a, b], now within [a, after]; `variations(l, r,
/// narrow, first, final)` counts the sign changes of f's Bernstein coefficients on [l, r] (-1:
/// not decided, split further; kUndecided: give up).
constexpr int kUndecided = -2;
template <class Variations>
Isolation isolate_first_root_with(Variations&& variations, double a, double after,
                                  int sign_after_now, double b, double& lo, double& hi,
                                  int& sign_lo) {
  if (!(a < b) || !std::isfinite(a) || !std::isfinite(b)) return Isolation::Undecided;
  // Depth first, the left half on top: the stack holds one pending right half per level.
  constexpr std::size_t kStack = 256;
  struct Pending {  // no initializers: the stack is not cleared per call (4 KiB)
    double l, r;
  };
  std::array<Pending, kStack> stack;
  std::size_t size = 0;
  stack[size++] = {a, b};
  int budget = 400;
  while (size > 0) {
    const auto [l, r] = stack[--size];
    if (--budget < 0) return Isolation::Undecided;
    int first = 0, final = 0;
    const double m = subdivision_point(l, r);
    const bool narrow = !(m > l && m < r) || r - l <= 0x1p-30 * (1.0 + std::fabs(l));
    const int v = variations(l, r, narrow, &first, &final);
    if (v == kUndecided) return Isolation::Undecided;
    if (v == 0) continue;
    if (v == 1 && (l > after || (l >= a && r > after))) {
      // One simple root in (l, r). It is after now unless now is at or past it, where f has
      // the right end's sign just after now; when l > after it is after now anyway.
      if (l <= after && sign_after_now == final) continue;  // at or before now
      lo = l;
      hi = r;
      sign_lo = first;
      return Isolation::Root;
    }
    if (r <= a) continue;
    if (!(m > l && m < r) || size + 2 > kStack) return Isolation::Undecided;
    stack[size++] = {m, r};  // right half after the left one
    stack[size++] = {l, m};
  }
  return Isolation::NoRoot;
}

Isolation isolate_first_root(const ExactPolynomial& f, const ExactTime& now, int sign_after_now,
                             double b, double& lo, double& hi, int& sign_lo) {
  const auto variations = [&](double l, double r, bool narrow, int* first, int* final) {
    const int v = bernstein_variations(f, l, r, first, final);
    if (v >= 0 || !narrow) return v;
    // Near a root the enclosures cannot sign f: the same coefficients exactly (a root at an
    // end, f(l) or f(r) = 0, lies outside the open interval the count is about).
    const int exact = exact_bernstein_variations(f, l, r, first, final);
    return *first == 0 || *final == 0 ? kUndecided : exact;  // a root at an end
  };
  return isolate_first_root_with(variations, now.lower(), now.upper(), sign_after_now, b, lo, hi,
                                 sign_lo);
}

}  // namespace

std::optional<FloatDecision> decide_in_floating_point(
    std::span<const numeric::Interval> c,
    FunctionRef<std::optional<int>(double)> exact_sign, const LazyTime& now, Time horizon,
    FunctionRef<LazyTime(double, double, int)> root, int sign_after_now,
    const FunctionRef<double(double)>* accurate_value) {
  const double a = now.lower(), after = now.upper();
  if (c.empty() || c.size() > 16 || !moderate(a) || !moderate(after)) return std::nullopt;
  // f over [a, after], now's bracket: one sign there is f's sign just after now.
  const auto value_over = [&](numeric::Interval t) {
    numeric::Interval v = c.back();
    for (std::size_t k = c.size() - 1; k-- > 0;) v = v * t + c[k];
    return v.sign();
  };
  FloatDecision d;
  d.sign = sign_after_now != 0 ? sign_after_now : value_over(numeric::Interval{a, after});
  if (d.sign == 0) return std::nullopt;
  if (after >= horizon) {
    if (a >= horizon) return d;  // no failure after the horizon (as decide_exact)
    return std::nullopt;         // now's bracket straddles the horizon
  }
  // The search ends at the horizon, or at Cauchy's bound on the roots, 1 + max |c_k / c_d|.
  double end = horizon;
  if (!std::isfinite(end)) {
    const numeric::Interval lead = c.back();
    if (lead.sign() == 0) return std::nullopt;
    const double least = std::min(std::fabs(lead.lo), std::fabs(lead.hi));
    double largest = 0.0;
    for (std::size_t k = 0; k + 1 < c.size(); ++k)
      largest = std::max({largest, std::fabs(c[k].lo), std::fabs(c[k].hi)});
    end = numeric::up(1.0 + numeric::up(largest / least));
    if (!(after < end)) return d;  // every root is at or below |t| < end
  }
  if (!moderate(end)) return std::nullopt;
  // Bernstein coefficients of the intervals the subdivision visits. A visited interval's halves
  // are made from its coefficients by de Casteljau (at 1/2, exactly, when its split point is
  // exactly its midpoint; at the enclosed ratio otherwise), kept on a stack in the order the
  // subdivision visits them (right half below the left); an interval not found there (halves the
  // subdivision never took, or a width r - l that is not a double) is computed from the
  // coefficients in powers of t.
  const std::size_t n = c.size();
  constexpr std::size_t kMaxKept = 16;  // coefficients per interval (degree <= 15)
  struct Halves {  // no initializers: the stack below is not cleared per decision
    double l, r;
    std::array<std::array<double, 2>, kMaxKept> b;
  };
  constexpr std::size_t kKept = 64;
  std::array<Halves, kKept> kept;
  std::size_t kept_size = 0;
  const auto keep = [&](double l, double r, const numeric::Interval* b) {
    Halves& h = kept[kept_size++];
    h.l = l;
    h.r = r;
    for (std::size_t i = 0; i < n; ++i) h.b[i] = {b[i].lo, b[i].hi};
  };
  const auto variations = [&](double l, double r, bool narrow, int* first, int* final) {
    std::array<numeric::Interval, kMaxKept> b;
    bool found = false;
    while (kept_size > 0 && !found) {
      const Halves& h = kept[--kept_size];
      found = h.l == l && h.r == r;
      for (std::size_t i = 0; found && i < n; ++i) b[i] = {h.b[i][0], h.b[i][1]};
    }
    if (!found) bernstein_coefficients(c, l, r, b.data());
    const int v = count_variations(b.data(), n, l, r, first, final, &exact_sign, true);
    if (v != 0 && v != 1 && kept_size + 2 <= kKept) {
      // Split next (most likely): the halves, when the split point is the exact midpoint.
      const double m = subdivision_point(l, r);
      double e1 = 0.0, e2 = 0.0, width = 0.0, middle = 0.0;
      numeric::two_sum(r, -l, width, e1);
      numeric::two_sum(l, width / 2, middle, e2);
      std::array<numeric::Interval, kMaxKept> left, right;
      bool split = false;
      if (m > l && m < r && e1 == 0.0 && e2 == 0.0 && middle == m && width / 2 * 2 == width) {
        split_in_halves(b.data(), n - 1, left.data(), right.data());
        split = true;
      } else if (m > l && m < r && e1 == 0.0) {
        // Another split point: the ratio (m - l) / (r - l) enclosed (r - l exact, m - l
        // rounded outwards unless exact).
        double part = 0.0, e3 = 0.0;
        numeric::two_sum(m, -l, part, e3);
        const numeric::Interval above = e3 == 0.0 ? numeric::Interval::point(part)
                                                  : numeric::Interval{numeric::down(part),
                                                                      numeric::up(part)};
        const numeric::Interval ratio{numeric::down(above.lo / width),
                                      numeric::up(above.hi / width)};
        if (ratio.lo >= 0.0 && ratio.hi <= 1.0) {
          split_at_ratio(b.data(), n - 1, ratio, left.data(), right.data());
          split = true;
        }
      }
      if (split) {
        keep(m, r, right.data());  // visited after the left half
        keep(l, m, left.data());
      }
    }
    return v < 0 && narrow ? kUndecided : v;
  };
  double lo = 0.0, hi = 0.0;
  int sign_lo = 0;
  switch (isolate_first_root_with(variations, a, after, d.sign, end, lo, hi, sign_lo)) {
    case Isolation::NoRoot:
      return d;
    case Isolation::Undecided:
      return std::nullopt;
    case Isolation::Root:
      break;
  }
  // One simple root in (lo, hi), f(lo) of sign sign_lo and f(hi) of the other (the first and
  // last Bernstein coefficients are f's values there): narrowed to adjacent doubles by f's
  // signs at the doubles between, in interval arithmetic, exactly where that cannot tell.
  // First Newton's method on the rounded polynomial (the midpoints of the enclosures) for an
  // estimate, then signs at doubles from it outwards (one double, then doubling steps) until they
  // change, then bisection: usually two or three signs near the root, where the intervals cannot
  // tell and each sign is exact (expansions), instead of one per bisection step.
  std::optional<double> at;  // the root, when it is a double
  const auto sign_at = [&](double m) -> std::optional<int> {
    const int s = value_over(numeric::Interval::point(m));
    if (s != 0) return s;
    return exact_sign(m);
  };
  // (lo, hi) narrows to m by its sign; true when m is the root.
  const auto split = [&](double m) -> std::optional<bool> {
    const std::optional<int> s = sign_at(m);
    if (!s) return std::nullopt;
    if (*s == 0) {
      at = m;
      return true;
    }
    (*s == sign_lo ? lo : hi) = m;
    return false;
  };
  if (!adjacent(lo, hi) && moderate(lo) && moderate(hi)) {
    double x = lo + (hi - lo) / 2;
    // Newton's method on the rounded polynomial, then (when the caller has one) two steps with
    // f's value in double-double accuracy: the estimate within a double or two of the root, where
    // the rounded polynomial leaves it tens to thousands of doubles away. The rounded polynomial
    // and its derivative at x by Horner's rule.
    const auto rounded = [&](double y, double& v, double& dv) {
      v = 0.0;
      dv = 0.0;
      for (std::size_t i = c.size(); i-- > 0;) {
        dv = dv * y + v;
        v = v * y + (c[i].lo / 2 + c[i].hi / 2);
      }
    };
    for (int k = 0; k < 8; ++k) {
      double v = 0.0, dv = 0.0;
      rounded(x, v, dv);
      const double next = x - v / dv;
      if (!(next > lo && next < hi)) break;
      const bool done = next == x;
      x = next;
      if (done) break;
    }
    for (int k = 0; accurate_value != nullptr && k < 2; ++k) {
      double v = 0.0, dv = 0.0;
      rounded(x, v, dv);
      v = (*accurate_value)(x);
      const double next = x - v / dv;  // NaN (no accurate value) fails the test below
      if (!(next > lo && next < hi) || next == x) break;
      x = next;
    }
    // From the estimate, a double at a time and then doubling steps towards the sign change.
    const std::optional<bool> root_at_x = split(x);
    if (!root_at_x) return std::nullopt;
    double step = 0.0;
    for (int k = 0; !*root_at_x && !at && !adjacent(lo, hi) && k < 64; ++k) {
      const bool up = lo == x;  // the root is above x
      const double from = x;
      const double toward = numeric::next_double(from, up);
      step = step == 0.0 ? std::fabs(toward - from) : step * 2;
      const double y = up ? std::min(from + step, hi) : std::max(from - step, lo);
      if (y == lo || y == hi || !(y > lo && y < hi)) break;
      const std::optional<bool> found = split(y);
      if (!found) return std::nullopt;
      if (*found) break;
      if ((up && hi == y) || (!up && lo == y)) break;  // passed the root: bisect from here
      x = y;
    }
  }
  while (!at && !adjacent(lo, hi)) {
    const double m = moderate(lo) && moderate(hi) ? lo + (hi - lo) / 2 : ordinal_midpoint(lo, hi);
    if (!(m > lo && m < hi)) return std::nullopt;
    const std::optional<bool> found = split(m);
    if (!found) return std::nullopt;
  }
  const double failure_hi = at ? *at : hi;
  const double failure_lo = at ? *at : lo;
  if (failure_hi <= horizon) {
    d.fails = true;
    d.failure = at ? LazyTime::point(*at) : root(lo, hi, sign_lo);
  } else if (!(failure_lo > horizon)) {
    return std::nullopt;  // within one double of the horizon
  }
  return d;
}

const std::vector<std::array<double, 2>>& ExactPolynomial::enclosure() const {
  if (enclosure_.size() != c_.size()) {
    enclosure_.clear();
    // Scaled by a power of two so that the largest coefficient is about 1: exact, and the signs
    // of f anywhere (all the filters read) are unchanged, while coefficients beyond the doubles
    // (motions of extreme magnitude multiplied out) get finite enclosures the filters can use.
    long top = std::numeric_limits<long>::min();
    for (const mpq_class& q : c_) {
      if (sgn(q) == 0) continue;
      top = std::max(top, static_cast<long>(mpz_sizeinbase(q.get_num_mpz_t(), 2)) -
                              static_cast<long>(mpz_sizeinbase(q.get_den_mpz_t(), 2)));
    }
    for (const mpq_class& q : c_) {
      mpq_class scaled = q;
      if (top > 64)
        mpq_div_2exp(scaled.get_mpq_t(), scaled.get_mpq_t(), static_cast<unsigned long>(top));
      if (top < -64 && top != std::numeric_limits<long>::min())
        mpq_mul_2exp(scaled.get_mpq_t(), scaled.get_mpq_t(), static_cast<unsigned long>(-top));
      const numeric::Interval e = enclose_rational(scaled);
      enclosure_.push_back({e.lo, e.hi});
    }
  }
  return enclosure_;
}

int ExactTime::sign_of(const ExactPolynomial& f) {
  if (f.is_zero()) return 0;
  if (point_) return f.sign_at(lo_);
  // Interval arithmetic over the bracket first: exact only when f may vanish there.
  if (const int s = enclosed_sign(f, lower(), upper()); s != 0) return s;
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
  // The first root after now isolated in floating point (Bernstein subdivision, interval
  // arithmetic) when it can be: no Sturm sequence, no square-free part.
  double end = to_double_or_infinity(horizon);
  if (std::isfinite(end) && mpq_class(end) < horizon) end = std::nextafter(end, HUGE_VAL);
  double lo = 0.0, hi = 0.0;
  int sign_lo = 0;
  switch (!std::isfinite(end) ? Isolation::Undecided
                              : isolate_first_root(f, now, d.sign, end, lo, hi, sign_lo)) {
    case Isolation::NoRoot:
      return d;
    case Isolation::Root: {
      // Exactly one root, simple, in (lo, hi), after now: f changes sign there. The bracket is
      // narrowed towards adjacent doubles by f's signs at double midpoints, in interval
      // arithmetic while it decides (so the exact time seldom needs rational bisection).
      const auto middle = [](double l, double h) {
        return moderate(l) && moderate(h) ? l + (h - l) / 2 : ordinal_midpoint(l, h);
      };
      for (double m = middle(lo, hi); m > lo && m < hi; m = middle(lo, hi)) {
        const int s = enclosed_sign(f, m, m);
        if (s == 0) break;
        (s == sign_lo ? lo : hi) = m;
      }
      const mpq_class qh(hi);
      if (qh > horizon) break;  // (rare: the exact path below decides)
      d.fails = true;
      d.failure = ExactTime::root_with_sign(f, mpq_class(lo), qh, sign_lo);
      return d;
    }
    case Isolation::Undecided:
      break;
  }
  // Between two consecutive roots f keeps its sign, so the first root after now where the sign
  // just after differs from d.sign is where the certificate fails. The isolation starts at a
  // dyadic time at or just below now (now is not dyadic after a linear certificate's rational
  // root): its bisection points are then dyadic too, where the Sturm sequence's signs are read
  // with integers only; the roots at or before now it may find are skipped.
  for (ExactTime& r : isolate_roots(f, dyadic_at_or_below(now.lo()), horizon)) {
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
      const mpq_class m = split_point(a, b);
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
      const mpq_class m = split_point(a, b);
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
