#pragma once
// Test support: an exact polynomial oracle over the rationals (GMP), independent of the library's
// arithmetic. Header-only, tests only. It reads MotionPolynomial as plain data (origin and
// coefficients) and calls none of the library's functions.
//
//  - QPoly: polynomials in powers of t with mpq_class coefficients; exact expansion of a motion
//    (Taylor shift from its origin to 0), +, -, *, derivative, division with remainder, gcd.
//  - RootOracle: for a non-zero f, the square-free part, Yun's square-free decomposition and
//    Sturm sequences (as primitive integer polynomials, evaluated exactly at doubles by
//    homogenised Horner in mpz_class). Counts distinct real roots in half-open, open and closed
//    intervals with double (or rational) ends, counts roots of odd multiplicity, gives the exact
//    sign of f at a double and approximates the real roots for failure messages.

#include <gmpxx.h>

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "kinetic/core/polynomial.hpp"

namespace kinetic::test::exact {

using Q = mpq_class;
using Z = mpz_class;

/// A polynomial in powers of t, ascending; trimmed (the zero polynomial has no coefficients).
struct QPoly {
  std::vector<Q> c;

  QPoly() = default;
  explicit QPoly(std::vector<Q> coefficients) : c(std::move(coefficients)) { trim(); }

  void trim() {
    while (!c.empty() && sgn(c.back()) == 0) c.pop_back();
  }
  [[nodiscard]] int degree() const { return static_cast<int>(c.size()) - 1; }  // -1 for zero
  [[nodiscard]] bool is_zero() const { return c.empty(); }
  [[nodiscard]] const Q& lead() const { return c.back(); }
  friend bool operator==(const QPoly& a, const QPoly& b) { return a.c == b.c; }
};

/// C(n, k) (exact; n <= 62 for the table, which covers every use here).
inline long binomial(int n, int k) {
  static const auto table = [] {
    std::array<std::array<long, 63>, 63> t{};
    for (std::size_t i = 0; i < 63; ++i) {
      t[i][0] = 1;
      for (std::size_t j = 1; j <= i; ++j) t[i][j] = t[i - 1][j - 1] + (j < i ? t[i - 1][j] : 0);
    }
    return t;
  }();
  assert(0 <= k && k <= n && n < 63);
  return table[static_cast<std::size_t>(n)][static_cast<std::size_t>(k)];
}

inline QPoly constant(const Q& v) { return QPoly({v}); }

/// x - r.
inline QPoly linear_root(const Q& r) { return QPoly({Q(-r), Q(1)}); }

inline QPoly add(const QPoly& a, const QPoly& b) {
  std::vector<Q> out(std::max(a.c.size(), b.c.size()), Q(0));
  for (std::size_t i = 0; i < a.c.size(); ++i) out[i] += a.c[i];
  for (std::size_t i = 0; i < b.c.size(); ++i) out[i] += b.c[i];
  return QPoly(std::move(out));
}

inline QPoly neg(const QPoly& a) {
  QPoly out = a;
  for (auto& x : out.c) x = -x;
  return out;
}

inline QPoly sub(const QPoly& a, const QPoly& b) { return add(a, neg(b)); }

inline QPoly scale(const QPoly& a, const Q& s) {
  std::vector<Q> out = a.c;
  for (auto& x : out) x *= s;
  return QPoly(std::move(out));
}

inline QPoly mul(const QPoly& a, const QPoly& b) {
  if (a.is_zero() || b.is_zero()) return {};
  std::vector<Q> out(a.c.size() + b.c.size() - 1, Q(0));
  for (std::size_t i = 0; i < a.c.size(); ++i)
    for (std::size_t j = 0; j < b.c.size(); ++j) out[i + j] += a.c[i] * b.c[j];
  return QPoly(std::move(out));
}

inline QPoly power(const QPoly& a, int k) {
  QPoly r = constant(1);
  for (int i = 0; i < k; ++i) r = mul(r, a);
  return r;
}

inline QPoly derivative(const QPoly& a) {
  std::vector<Q> out;
  for (std::size_t i = 1; i < a.c.size(); ++i) out.push_back(a.c[i] * static_cast<long>(i));
  return QPoly(std::move(out));
}

/// p(x + delta) expanded in powers of x (a Taylor shift).
inline QPoly shift(const QPoly& p, const Q& delta) {
  std::vector<Q> out(p.c.size(), Q(0));
  if (sgn(delta) == 0) return p;
  std::vector<Q> dp(p.c.size(), Q(1));  // delta^j
  for (std::size_t j = 1; j < dp.size(); ++j) dp[j] = dp[j - 1] * delta;
  for (std::size_t k = 0; k < p.c.size(); ++k) {
    if (sgn(p.c[k]) == 0) continue;
    for (std::size_t j = 0; j <= k; ++j) {
      const std::size_t i = k - j;
      out[i] += p.c[k] * dp[j] * binomial(static_cast<int>(k), static_cast<int>(i));
    }
  }
  return QPoly(std::move(out));
}

/// The polynomial sum c[i] (t - origin)^i, expanded in powers of t.
inline QPoly about(const std::vector<Q>& c, const Q& origin) { return shift(QPoly(c), Q(-origin)); }

/// The exact motion sum p.c[i] (t - p.origin)^i in powers of t. Reads every stored coefficient
/// (not only up to p.degree) so that a wrong `degree` field cannot hide terms.
inline QPoly from_motion(const MotionPolynomial& p) {
  std::vector<Q> c;
  for (double x : p.c) c.emplace_back(x);
  return about(c, Q(p.origin));
}

/// Coefficients of p in powers of (t - origin).
inline std::vector<Q> coefficients_about(const QPoly& p, const Q& origin) {
  return shift(p, origin).c;
}

inline Q eval(const QPoly& p, const Q& x) {
  Q v = 0;
  for (std::size_t i = p.c.size(); i-- > 0;) v = v * x + p.c[i];
  return v;
}

/// Division with remainder: a = q b + r, deg r < deg b. Precondition: b != 0.
inline std::pair<QPoly, QPoly> divmod(const QPoly& a, const QPoly& b) {
  assert(!b.is_zero());
  std::vector<Q> r = a.c;
  const int db = b.degree();
  if (a.degree() < db) return {QPoly(), a};
  std::vector<Q> q(static_cast<std::size_t>(a.degree() - db + 1), Q(0));
  for (int k = a.degree(); k >= db; --k) {
    const Q f = r[static_cast<std::size_t>(k)] / b.lead();
    q[static_cast<std::size_t>(k - db)] = f;
    if (sgn(f) == 0) continue;
    for (int i = 0; i <= db; ++i) r[static_cast<std::size_t>(k - db + i)] -= f * b.c[i];
  }
  r.resize(static_cast<std::size_t>(db));
  return {QPoly(std::move(q)), QPoly(std::move(r))};
}

/// a / b when b divides a exactly (asserted).
inline QPoly exact_div(const QPoly& a, const QPoly& b) {
  auto [q, r] = divmod(a, b);
  assert(r.is_zero());
  (void)r;
  return q;
}

inline QPoly monic(const QPoly& a) {
  if (a.is_zero()) return a;
  return scale(a, Q(1) / a.lead());
}

/// Monic gcd (zero only when both are zero).
inline QPoly gcd(QPoly a, QPoly b) {
  while (!b.is_zero()) {
    QPoly r = divmod(a, b).second;
    a = std::move(b);
    b = std::move(r);
  }
  return monic(a);
}

// ---------------------------------------------------------------------------------------------
// Exact evaluation at doubles with integer polynomials.

/// A positive multiple of p with coprime integer coefficients (same signs everywhere).
inline std::vector<Z> primitive_integer(const QPoly& p) {
  Z l = 1;
  for (const auto& x : p.c) mpz_lcm(l.get_mpz_t(), l.get_mpz_t(), x.get_den_mpz_t());
  std::vector<Z> out;
  Z g = 0;
  for (const auto& x : p.c) {
    out.push_back(Z(x.get_num() * (l / x.get_den())));
    mpz_gcd(g.get_mpz_t(), g.get_mpz_t(), out.back().get_mpz_t());
  }
  if (g > 1)
    for (auto& x : out) x /= g;
  return out;
}

/// x = m * 2^e exactly, m an integer (|m| < 2^53). Precondition: x finite.
struct Dyadic {
  Z m;
  long e = 0;
};

inline Dyadic to_dyadic(double x) {
  assert(std::isfinite(x));
  Dyadic d;
  if (x == 0.0) return d;
  int ex = 0;
  const double fr = std::frexp(x, &ex);  // x = fr 2^ex, 0.5 <= |fr| < 1
  d.m = Z(std::ldexp(fr, 53));           // an integer, exactly
  d.e = static_cast<long>(ex) - 53;
  return d;
}

/// sign(p(x)) for an integer polynomial p and a double x, exactly (homogenised Horner; the
/// temporaries are reused, so no allocation once they have grown).
inline int sign_integer_at(const std::vector<Z>& p, const Dyadic& x) {
  if (p.empty()) return 0;
  const std::size_t n = p.size() - 1;
  thread_local Z v, xv, pw;
  mpz_set(v.get_mpz_t(), p[n].get_mpz_t());
  if (n == 0) return sgn(v);
  if (x.e >= 0) {
    mpz_mul_2exp(xv.get_mpz_t(), x.m.get_mpz_t(), static_cast<mp_bitcnt_t>(x.e));
    for (std::size_t i = n; i-- > 0;) {
      mpz_mul(v.get_mpz_t(), v.get_mpz_t(), xv.get_mpz_t());
      mpz_add(v.get_mpz_t(), v.get_mpz_t(), p[i].get_mpz_t());
    }
  } else {
    // 2^(s n) p(m / 2^s) = sum p[i] m^i 2^(s (n - i)): Horner with p[i] * 2^(s (n - i)).
    const auto s = static_cast<mp_bitcnt_t>(-x.e);
    mpz_set_ui(pw.get_mpz_t(), 1);
    for (std::size_t i = n; i-- > 0;) {
      mpz_mul_2exp(pw.get_mpz_t(), pw.get_mpz_t(), s);
      mpz_mul(v.get_mpz_t(), v.get_mpz_t(), x.m.get_mpz_t());
      mpz_addmul(v.get_mpz_t(), p[i].get_mpz_t(), pw.get_mpz_t());
    }
  }
  return sgn(v);
}

inline int sign_at(const QPoly& p, double x) {
  return sign_integer_at(primitive_integer(p), to_dyadic(x));
}

inline int sign_at(const QPoly& p, const Q& x) { return sgn(eval(p, x)); }

// ---------------------------------------------------------------------------------------------
// Sturm sequences and root counting.

/// Integer polynomial helpers for the primitive pseudo-remainder sequence.
inline int int_degree(const std::vector<Z>& p) { return static_cast<int>(p.size()) - 1; }

inline void int_trim(std::vector<Z>& p) {
  while (!p.empty() && sgn(p.back()) == 0) p.pop_back();
}

/// p divided by the (positive) gcd of its coefficients.
inline void make_primitive(std::vector<Z>& p) {
  Z g = 0;
  for (const auto& x : p) mpz_gcd(g.get_mpz_t(), g.get_mpz_t(), x.get_mpz_t());
  if (g > 1)
    for (auto& x : p) mpz_divexact(x.get_mpz_t(), x.get_mpz_t(), g.get_mpz_t());
}

/// lc(b)^(deg a - deg b + 1) a mod b (pseudo-remainder). Precondition: deg a >= deg b >= 0.
inline std::vector<Z> pseudo_remainder(std::vector<Z> r, const std::vector<Z>& b) {
  const int db = int_degree(b);
  const Z& lb = b.back();
  for (int k = int_degree(r); k >= db; --k) {
    const Z q = r[static_cast<std::size_t>(k)];
    for (auto& x : r) x *= lb;
    for (int i = 0; i <= db; ++i)
      r[static_cast<std::size_t>(k - db + i)] -= q * b[static_cast<std::size_t>(i)];
  }
  r.resize(static_cast<std::size_t>(db));
  int_trim(r);
  return r;
}

/// The Sturm sequence p, p', -rem, ... of an integer polynomial, each member replaced by a
/// positive multiple with coprime integer coefficients (same signs everywhere).
class Sturm {
 public:
  Sturm() = default;
  /// Precondition: p non-zero. Counting roots needs p square-free (see square_free()).
  explicit Sturm(std::vector<Z> p) {
    int_trim(p);
    assert(!p.empty());
    make_primitive(p);
    std::vector<Z> d;
    for (std::size_t i = 1; i < p.size(); ++i) d.push_back(p[i] * static_cast<long>(i));
    push(std::move(p));
    int_trim(d);
    if (d.empty()) return;
    make_primitive(d);
    push(std::move(d));
    for (;;) {
      const std::vector<Z>& a = seq_[seq_.size() - 2];
      const std::vector<Z>& b = seq_.back();
      std::vector<Z> r = pseudo_remainder(a, b);
      if (r.empty()) break;
      make_primitive(r);
      // prem = lc(b)^k rem: the next member is -rem up to a positive factor.
      const int k = int_degree(a) - int_degree(b) + 1;
      const bool flip = !(sgn(b.back()) < 0 && k % 2 == 1);  // -sign(lc(b))^k
      if (flip)
        for (auto& x : r) x = -x;
      push(std::move(r));
    }
  }
  explicit Sturm(const QPoly& p) : Sturm(primitive_integer(p)) {}

  /// True when gcd(p, p') (the last member) is a constant.
  [[nodiscard]] bool square_free() const { return !seq_.empty() && degrees_.back() == 0; }

  /// Sign variations at a double (zeros skipped) and the sign of p there.
  struct At {
    int variations = 0;
    int sign = 0;
  };
  [[nodiscard]] At at(double x) const {
    const Dyadic d = to_dyadic(x);
    At out;
    int last = 0;
    for (std::size_t i = 0; i < seq_.size(); ++i) {
      const int g = sign_integer_at(seq_[i], d);
      if (i == 0) out.sign = g;
      if (g == 0) continue;
      if (last != 0 && g != last) ++out.variations;
      last = g;
    }
    return out;
  }
  [[nodiscard]] int variations(double x) const { return at(x).variations; }
  /// Sign variations at +infinity (plus = true) or -infinity.
  [[nodiscard]] int variations_at_infinity(bool plus) const {
    int v = 0, last = 0;
    for (std::size_t i = 0; i < seq_.size(); ++i) {
      int g = leads_[i];
      if (!plus && degrees_[i] % 2 == 1) g = -g;
      if (last != 0 && g != last) ++v;
      last = g;
    }
    return v;
  }
  /// Distinct real roots in (a, b], [a, b] and (a, b) from the values at the ends (Sturm's
  /// theorem for a square-free p; a and b may be roots).
  static int half_open(const At& a, const At& b) { return a.variations - b.variations; }
  static int closed(const At& a, const At& b) { return half_open(a, b) + (a.sign == 0); }
  static int open(const At& a, const At& b) { return half_open(a, b) - (b.sign == 0); }

  [[nodiscard]] int count_half_open(double a, double b) const {
    return a < b ? half_open(at(a), at(b)) : 0;
  }
  [[nodiscard]] int count_all() const {
    return variations_at_infinity(false) - variations_at_infinity(true);
  }
  [[nodiscard]] int sign(double x) const { return sign_integer_at(seq_.front(), to_dyadic(x)); }
  [[nodiscard]] int count_open(double a, double b) const { return a < b ? open(at(a), at(b)) : 0; }
  [[nodiscard]] int count_closed(double a, double b) const {
    if (a > b) return 0;
    if (a == b) return sign(a) == 0 ? 1 : 0;
    return closed(at(a), at(b));
  }

 private:
  void push(std::vector<Z> p) {
    degrees_.push_back(int_degree(p));
    leads_.push_back(sgn(p.back()));
    seq_.push_back(std::move(p));
  }
  std::vector<std::vector<Z>> seq_;
  std::vector<int> degrees_;
  std::vector<int> leads_;
};

/// Everything the CROP tests need to know about a non-zero polynomial f.
class RootOracle {
 public:
  /// Precondition: f non-zero.
  explicit RootOracle(const QPoly& f) : f_(f), f_int_(primitive_integer(f)) {
    assert(!f.is_zero());
    if (f.degree() == 0) return;
    // The Sturm chain of f ends with gcd(f, f'): when that is a constant, f is square-free (the
    // common case) and the chain serves every count.
    Sturm chain(f_int_);
    if (chain.square_free()) {
      sqfree_ = monic(f);
      factors_.push_back({1, sqfree_});
      sturm_ = std::move(chain);
      return;
    }
    // Yun's square-free decomposition: f = lead * prod_i a_i^i, a_i monic, square-free, coprime.
    const QPoly fp = derivative(f);
    const QPoly a0 = gcd(f, fp);
    QPoly b = exact_div(f, a0);
    QPoly c = exact_div(fp, a0);
    QPoly d = sub(c, derivative(b));
    int i = 1;
    while (b.degree() > 0) {
      QPoly a = gcd(b, d);
      if (a.degree() > 0) factors_.push_back({i, a});
      b = exact_div(b, a);
      c = exact_div(d, a);
      d = sub(c, derivative(b));
      ++i;
    }
    QPoly sqfree = constant(1), odd = constant(1);
    for (const auto& [m, a] : factors_) {
      sqfree = mul(sqfree, a);
      if (m % 2 == 1) odd = mul(odd, a);
    }
    sqfree_ = monic(sqfree);
    assert(sqfree_ == monic(exact_div(f, a0)));
    sturm_ = Sturm(sqfree_);
    odd_is_sqfree_ = odd.degree() == sqfree_.degree();
    if (odd.degree() > 0 && !odd_is_sqfree_) odd_sturm_ = Sturm(odd);
  }

  [[nodiscard]] const QPoly& f() const { return f_; }
  [[nodiscard]] const QPoly& square_free() const { return sqfree_; }
  /// (multiplicity, monic square-free factor) pairs of Yun's decomposition.
  [[nodiscard]] const std::vector<std::pair<int, QPoly>>& factors() const { return factors_; }

  /// Exact sign of f at a double.
  [[nodiscard]] int sign(double x) const { return sign_integer_at(f_int_, to_dyadic(x)); }

  [[nodiscard]] int count_half_open(double a, double b) const {
    return f_.degree() == 0 ? 0 : sturm_.count_half_open(a, b);
  }
  [[nodiscard]] int count_open(double a, double b) const {
    return f_.degree() == 0 ? 0 : sturm_.count_open(a, b);
  }
  [[nodiscard]] int count_closed(double a, double b) const {
    return f_.degree() == 0 ? 0 : sturm_.count_closed(a, b);
  }
  [[nodiscard]] int count_all() const { return f_.degree() == 0 ? 0 : sturm_.count_all(); }
  /// Distinct roots of odd multiplicity (where f changes sign) in (a, b).
  [[nodiscard]] int count_odd_open(double a, double b) const {
    if (odd_is_sqfree_) return count_open(a, b);
    return odd_sturm_ ? odd_sturm_->count_open(a, b) : 0;
  }
  /// Everything about one point, evaluated once: the sign of f and the Sturm values of the
  /// square-free part and of the odd-multiplicity part.
  struct Point {
    double x = 0.0;
    int sign_f = 0;
    Sturm::At sq, odd;
  };
  [[nodiscard]] Point point(double x) const {
    Point p;
    p.x = x;
    p.sign_f = sign(x);
    if (f_.degree() == 0) return p;
    p.sq = sturm_.at(x);
    if (odd_is_sqfree_) {
      p.odd = p.sq;
    } else if (odd_sturm_) {
      p.odd = odd_sturm_->at(x);
    }
    return p;
  }
  /// Distinct roots in (a, b), [a, b]; roots of odd multiplicity in (a, b). a.x <= b.x.
  [[nodiscard]] int open(const Point& a, const Point& b) const {
    return f_.degree() == 0 || !(a.x < b.x) ? 0 : Sturm::open(a.sq, b.sq);
  }
  [[nodiscard]] int closed(const Point& a, const Point& b) const {
    if (f_.degree() == 0 || a.x > b.x) return 0;
    if (a.x == b.x) return a.sign_f == 0 ? 1 : 0;
    return Sturm::closed(a.sq, b.sq);
  }
  [[nodiscard]] int odd_open(const Point& a, const Point& b) const {
    if (f_.degree() == 0 || !(a.x < b.x) || (!odd_is_sqfree_ && !odd_sturm_)) return 0;
    return Sturm::open(a.odd, b.odd);
  }

  /// Distinct roots of multiplicity exactly m in (a, b).
  [[nodiscard]] int count_multiplicity_open(int m, double a, double b) const {
    for (const auto& [k, s] : by_multiplicity())
      if (k == m) return s.count_open(a, b);
    return 0;
  }

  /// Approximations of the distinct real roots in [a, b] (bisection on doubles to adjacent
  /// doubles), ascending, with their multiplicities: for failure messages.
  [[nodiscard]] std::vector<std::pair<double, int>> approximate_roots(double a, double b) const {
    std::vector<std::pair<double, int>> out;
    if (f_.degree() <= 0 || a > b) return out;
    for (const auto& [m, s] : by_multiplicity()) {
      if (s.sign(a) == 0) out.push_back({a, m});
      isolate(s, a, b, m, out);
    }
    std::sort(out.begin(), out.end());
    return out;
  }

 private:
  static void isolate(const Sturm& s, double a, double b, int m,
                      std::vector<std::pair<double, int>>& out) {
    const int n = s.count_half_open(a, b);
    if (n == 0) return;
    const double mid = a / 2 + b / 2;
    if (!(a < mid && mid < b)) {  // adjacent doubles: the root is in (a, b]
      out.push_back({b, m});
      return;
    }
    isolate(s, a, mid, m, out);
    isolate(s, mid, b, m, out);
  }

  /// Sturm sequences of the factors of each multiplicity (built on first use).
  const std::vector<std::pair<int, Sturm>>& by_multiplicity() const {
    if (sturm_by_multiplicity_.size() != factors_.size()) {
      sturm_by_multiplicity_.clear();
      for (const auto& [m, a] : factors_) sturm_by_multiplicity_.push_back({m, Sturm(a)});
    }
    return sturm_by_multiplicity_;
  }

  QPoly f_;
  std::vector<Z> f_int_;
  QPoly sqfree_;
  std::vector<std::pair<int, QPoly>> factors_;
  mutable std::vector<std::pair<int, Sturm>> sturm_by_multiplicity_;
  Sturm sturm_;
  bool odd_is_sqfree_ = true;
  std::optional<Sturm> odd_sturm_;
};

// ---------------------------------------------------------------------------------------------
// Doubles.

/// True when q is exactly a finite double.
inline bool representable(const Q& q) {
  const double d = q.get_d();
  return std::isfinite(d) && Q(d) == q;
}

/// The motion sum c[i] (t - origin)^i if every coefficient is exactly a double and the degree
/// fits; nullopt otherwise.
inline std::optional<MotionPolynomial> to_motion(const std::vector<Q>& c, double origin) {
  std::array<double, kMaxMotionDegree + 1> d{};
  for (std::size_t i = 0; i < c.size(); ++i) {
    if (sgn(c[i]) == 0) continue;
    if (i > static_cast<std::size_t>(kMaxMotionDegree) || !representable(c[i])) return std::nullopt;
    d[i] = c[i].get_d();
  }
  return MotionPolynomial::from(d, origin);
}

inline std::string hex(double x) {
  std::ostringstream os;
  os << std::hexfloat << x;
  return os.str();
}

}  // namespace kinetic::test::exact
