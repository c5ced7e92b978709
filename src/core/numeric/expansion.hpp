#pragma once
// Floating-point expansions: exact sums and products of doubles without GMP (Shewchuk, "Adaptive
// precision floating-point arithmetic and fast robust geometric predicates"). A value is the exact
// sum of its components, non-overlapping and in increasing magnitude, zeros eliminated; its sign
// is the sign of its last (largest) component.
//
// Model: as eft.hpp (IEEE-754 binary64, round to nearest, no fused multiply-add). Domain: every
// product is taken of factors that are 0 or of magnitude in [2^-480, 2^480] (then two_product()
// is exact: no split or partial product overflows or underflows, and sums of up to kCapacity
// products of magnitude <= 2^960 cannot overflow). An operation outside the domain, or one that
// would exceed the fixed capacity, marks the result not ok(); its value is then meaningless and
// the caller decides another way (the exact scheduler: with GMP). No allocation.
//
// User: LazyTime's comparison of two linear roots (exact_time.cpp), the 2 x 2 determinant sign
// that decides equal crossing times of different pairs (GRIDS, PARABOLA) without GMP; the
// certificates of degree <= 2 (lazy_time.cpp); the in-circle polynomial of points on lines and
// parabolas (incircle.cpp).

#include <array>
#include <cmath>
#include <cstddef>

#include "core/numeric/eft.hpp"

namespace kinetic::numeric {

class Expansion {
 public:
  static constexpr std::size_t kCapacity = 64;

  /// Zero.
  Expansion() = default;
  /// The double x (not ok() unless finite).
  explicit Expansion(double x) {
    ok_ = std::isfinite(x);
    if (x != 0.0) c_[n_++] = x;
  }
  /// a - b, exactly (not ok() unless a, b and fl(a - b) are finite).
  static Expansion difference(double a, double b) {
    Expansion r(a);
    r.add(-b);
    return r;
  }

  /// Becomes a + b, exactly, by one TwoSum (in place: an expansion is large); not ok() unless
  /// a, b and fl(a + b) are finite.
  void assign_sum(double a, double b) {
    double s = 0.0, e = 0.0;
    two_sum(a, b, s, e);
    ok_ = std::isfinite(s) && std::isfinite(e);
    n_ = 0;
    if (e != 0.0) c_[n_++] = e;
    if (s != 0.0) c_[n_++] = s;
  }

  /// The expansion with components c[0, n) (non-overlapping, increasing magnitude, non-zero, as
  /// this class makes them); n <= kCapacity.
  static Expansion of_components(const double* c, std::size_t n) {
    Expansion r;
    for (std::size_t i = 0; i < n; ++i) r.c_[i] = c[i];
    r.n_ = n;
    return r;
  }

  /// True when x may be a factor of a product: 0, or of magnitude in [2^-480, 2^480].
  static bool in_domain(double x) {
    const double a = std::fabs(x);
    return x == 0.0 || (a >= 0x1p-480 && a <= 0x1p480);
  }

  [[nodiscard]] bool ok() const { return ok_; }
  /// The value as a double-double hi + lo = TwoSum(top component, the rest summed in floating
  /// point): |lo| <= u |hi|, and hi + lo is within 2^-99 |hi| of the value (the rest of a
  /// non-overlapping expansion is below 2u |top| and its rounded sum errs by less than 64 u of
  /// that). The compensated filters' coefficients (lazy_time.cpp, incircle.cpp).
  void to_double_double(double& hi, double& lo) const {
    double rest = 0.0;
    for (std::size_t i = 0; i + 1 < n_; ++i) rest += c_[i];
    two_sum(n_ > 0 ? c_[n_ - 1] : 0.0, rest, hi, lo);
  }

  /// -1, 0 or 1: the exact sign (meaningful only when ok()).
  [[nodiscard]] int sign() const {
    if (n_ == 0) return 0;
    return c_[n_ - 1] > 0.0 ? 1 : -1;
  }
  [[nodiscard]] std::size_t size() const { return n_; }
  [[nodiscard]] double operator[](std::size_t i) const { return c_[i]; }

  /// this += b (Shewchuk's GROW-EXPANSION with zero elimination).
  void add(double b) {
    if (!std::isfinite(b)) ok_ = false;
    if (!ok_) return;
    if (n_ + 1 > kCapacity) {
      ok_ = false;
      return;
    }
    double q = b;
    std::size_t h = 0;
    for (std::size_t i = 0; i < n_; ++i) {
      double s = 0.0, e = 0.0;
      two_sum(q, c_[i], s, e);
      q = s;
      if (e != 0.0) c_[h++] = e;  // h <= i: writes only what was read
    }
    if (q != 0.0 || h == 0) c_[h++] = q;
    n_ = h;
    if (n_ == 1 && c_[0] == 0.0) n_ = 0;
    if (!std::isfinite(q)) ok_ = false;
  }

  /// this += f (EXPANSION-SUM: f's components grown in one by one).
  void add(const Expansion& f) {
    if (!f.ok_) ok_ = false;
    for (std::size_t j = 0; j < f.n_ && ok_; ++j) add(f.c_[j]);
  }

  /// this -= f.
  void subtract(const Expansion& f) {
    if (!f.ok_) ok_ = false;
    for (std::size_t j = 0; j < f.n_ && ok_; ++j) add(-f.c_[j]);
  }

  /// The same value in as few components as Shewchuk's COMPRESS gives (non-adjacent, increasing
  /// magnitude): a long sum of products shrinks to about as many doubles as its value needs.
  void compress() {
    if (n_ < 2) return;
    std::array<double, kCapacity> h;
    double q = c_[n_ - 1];
    std::size_t bottom = n_ - 1;
    for (std::size_t i = n_ - 1; i-- > 0;) {
      double s = 0.0, e = 0.0;
      two_sum(q, c_[i], s, e);
      if (e != 0.0) {
        h[bottom--] = s;
        q = e;
      } else {
        q = s;
      }
    }
    std::size_t top = 0;
    for (std::size_t i = bottom + 1; i < n_; ++i) {
      double s = 0.0, e = 0.0;
      two_sum(h[i], q, s, e);
      q = s;
      if (e != 0.0) c_[top++] = e;
    }
    c_[top++] = q;
    n_ = top;
    if (n_ == 1 && c_[0] == 0.0) n_ = 0;
  }

  /// this = -this.
  void negate() {
    for (std::size_t i = 0; i < n_; ++i) c_[i] = -c_[i];
  }
  friend Expansion operator-(Expansion f) {
    f.negate();
    return f;
  }

  /// this * b (Shewchuk's SCALE-EXPANSION with zero elimination).
  [[nodiscard]] Expansion scaled(double b) const {
    Expansion r;
    r.ok_ = ok_ && in_domain(b);
    if (!r.ok_ || n_ == 0 || b == 0.0) return r;
    if (2 * n_ > kCapacity) {
      r.ok_ = false;
      return r;
    }
    double q = 0.0, hh = 0.0;
    if (!in_domain(c_[0])) {
      r.ok_ = false;
      return r;
    }
    two_product(c_[0], b, q, hh);
    if (hh != 0.0) r.c_[r.n_++] = hh;
    for (std::size_t i = 1; i < n_; ++i) {
      if (!in_domain(c_[i])) {
        r.ok_ = false;
        return r;
      }
      double p1 = 0.0, p0 = 0.0, s = 0.0;
      two_product(c_[i], b, p1, p0);
      two_sum(q, p0, s, hh);
      if (hh != 0.0) r.c_[r.n_++] = hh;
      two_sum(p1, s, q, hh);
      if (hh != 0.0) r.c_[r.n_++] = hh;
    }
    if (q != 0.0 || r.n_ == 0) r.c_[r.n_++] = q;
    if (r.n_ == 1 && r.c_[0] == 0.0) r.n_ = 0;
    return r;
  }

  /// a * b, exactly (the sum of a scaled by each component of b).
  friend Expansion operator*(const Expansion& a, const Expansion& b) {
    Expansion r;
    r.ok_ = a.ok_ && b.ok_;
    for (std::size_t j = 0; j < b.n_ && r.ok_; ++j) r.add(a.scaled(b.c_[j]));
    return r;
  }

 private:
  std::array<double, kCapacity> c_;  // only c_[0, n_) is meaningful (not zeroed: hot path)
  std::size_t n_ = 0;
  bool ok_ = true;
};

/// The exact sign of t[0] + ... + t[n-1] (finite doubles, each of magnitude <= 2^960, n <= 64),
/// in three stages: the recursive sum S (|S - sum| <= gamma_{n-1} sum |t_i|, so |S| above
/// n 2^-52 sum |t_i| decides); Ogita, Rump and Oishi's Sum2 (a cascade of TwoSums, the result
/// as if summed in twice the precision: |r - sum| <= u |sum| + gamma_{n-1}^2 sum |t_i|, so |r|
/// above 4 n^2 2^-106 sum |t_i| decides); else an exact expansion sum.
inline int sum_sign(const double* t, std::size_t n) {
  double sum = 0.0, magnitude = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    sum += t[i];
    magnitude += std::fabs(t[i]);
  }
  // (the bounds' own rounding is covered by the factors 2 and 4)
  const auto nn = static_cast<double>(n);
  if (std::fabs(sum) > nn * 0x1p-52 * magnitude) return sum > 0.0 ? 1 : -1;
  double s = 0.0, e = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    double err = 0.0;
    two_sum(s, t[i], s, err);
    e += err;
  }
  const double r = s + e;
  if (std::fabs(r) > 4.0 * nn * nn * 0x1p-106 * magnitude) return r > 0.0 ? 1 : -1;
  Expansion x;
  for (std::size_t i = 0; i < n; ++i) x.add(t[i]);
  return x.sign();
}

}  // namespace kinetic::numeric
