#include "kinetic/core/crop.hpp"

#include <gmpxx.h>

#include <algorithm>
#include <cassert>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <limits>

#include "kinetic/core/float_roots.hpp"

namespace kinetic {
namespace {

// ---------------------------------------------------------------------------------------------
// Interval arithmetic with outward rounding. Each operation is done in round-to-nearest and then
// widened: for a normal result x, fl(x - |x| 2^-52) <= x - ulp(x)/2 <= the exact value (and
// symmetrically upward); the 2^-1070 term covers subnormal and underflowed results.
inline double down(double x) { return (x - std::fabs(x) * 0x1p-52) - 0x1p-1070; }
inline double up(double x) { return (x + std::fabs(x) * 0x1p-52) + 0x1p-1070; }

struct Iv {
  double lo = 0.0, hi = 0.0;
  static Iv point(double v) { return Iv{v, v}; }
  [[nodiscard]] int sign() const {  // certain sign, or 0 when the interval may contain 0
    if (lo > 0.0) return 1;
    if (hi < 0.0) return -1;
    return 0;
  }
};

inline Iv operator+(Iv a, Iv b) { return Iv{down(a.lo + b.lo), up(a.hi + b.hi)}; }
inline Iv operator-(Iv a, Iv b) { return Iv{down(a.lo - b.hi), up(a.hi - b.lo)}; }
inline Iv operator*(Iv a, Iv b) {
  const double p1 = a.lo * b.lo, p2 = a.lo * b.hi, p3 = a.hi * b.lo, p4 = a.hi * b.hi;
  return Iv{down(std::min(std::min(p1, p2), std::min(p3, p4))),
            up(std::max(std::max(p1, p2), std::max(p3, p4)))};
}
inline Iv scale(Iv a, double k) {  // k >= 0, an exact small integer
  return Iv{down(a.lo * k), up(a.hi * k)};
}

/// x - y as an interval; a point when the subtraction is exact (checked by TwoSum).
Iv exact_difference(double x, double y) {
  const double d = x - y;
  const double z = d - x;
  const double err = (x - (d - z)) + (-y - z);
  if (err == 0.0) return Iv::point(d);
  return Iv{down(d), up(d)};
}

constexpr int kN = kMaxMotionDegree;

/// Coefficients of p(a + u) in powers of u, as intervals (Taylor shift in interval arithmetic).
void shifted(const MotionPolynomial& p, double a, std::array<Iv, kN + 1>& q) {
  for (int i = 0; i <= kN; ++i) q[i] = Iv::point(i <= p.degree ? p.c[i] : 0.0);
  if (a == p.origin) return;
  const Iv s = exact_difference(a, p.origin);
  for (int k = 0; k < p.degree; ++k) {
    for (int i = p.degree - 1; i >= k; --i) q[i] = q[i] + s * q[i + 1];
  }
}

// ---------------------------------------------------------------------------------------------
// Exact dyadic arithmetic (m * 2^e with a GMP integer m): every double is one, and sums,
// differences and products of them stay dyadic, so the exact Bernstein coefficients of
// upper - lower on a box with double ends are dyadic too. Used only when the interval
// enclosures cannot decide a sign.
struct Dyadic {
  mpz_class m;
  long e = 0;
};

Dyadic dyadic(double v) {
  Dyadic d;
  if (v == 0.0) return d;
  int exponent = 0;
  const double f = std::frexp(v, &exponent);  // v = f * 2^exponent, 0.5 <= |f| < 1
  d.m = static_cast<long>(std::ldexp(f, 53));
  d.e = exponent - 53;
  return d;
}

Dyadic operator+(const Dyadic& a, const Dyadic& b) {
  if (a.m == 0) return b;
  if (b.m == 0) return a;
  Dyadic r;
  if (a.e <= b.e) {
    mpz_class t;
    mpz_mul_2exp(t.get_mpz_t(), b.m.get_mpz_t(), static_cast<mp_bitcnt_t>(b.e - a.e));
    r.m = a.m + t;
    r.e = a.e;
  } else {
    mpz_class t;
    mpz_mul_2exp(t.get_mpz_t(), a.m.get_mpz_t(), static_cast<mp_bitcnt_t>(a.e - b.e));
    r.m = t + b.m;
    r.e = b.e;
  }
  return r;
}

Dyadic operator-(const Dyadic& a) {
  Dyadic r = a;
  r.m = -r.m;
  return r;
}

Dyadic operator*(const Dyadic& a, const Dyadic& b) {
  Dyadic r;
  r.m = a.m * b.m;
  r.e = a.e + b.e;
  return r;
}

/// Exact Taylor coefficients of p at a.
void exact_shifted(const MotionPolynomial& p, double a,
                   std::array<Dyadic, kMaxMotionDegree + 1>& q) {
  for (int i = 0; i <= kMaxMotionDegree; ++i) q[i] = dyadic(i <= p.degree ? p.c[i] : 0.0);
  if (a == p.origin) return;
  const Dyadic s = dyadic(a) + (-dyadic(p.origin));
  for (int k = 0; k < p.degree; ++k) {
    for (int i = p.degree - 1; i >= k; --i) q[i] = q[i] + s * q[i + 1];
  }
}

/// Coefficients of p(s + u) from those of p(u), in plain floating point (guesses only).
void taylor_shift(std::array<double, kMaxMotionDegree + 1>& q, int degree, double s) {
  if (s == 0.0) return;
  for (int k = 0; k < degree; ++k) {
    for (int i = degree - 1; i >= k; --i) q[i] += s * q[i + 1];
  }
}

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
        degree_(std::max(upper.degree, lower.degree)) {}

  [[nodiscard]] int degree() const { return degree_; }
  [[nodiscard]] const MotionPolynomial& upper() const { return upper_; }
  [[nodiscard]] const MotionPolynomial& lower() const { return lower_; }

  /// Exact sign of f(t).
  int sign(Time t) const {
    return compare_at(upper_, lower_, t, stats_ ? &stats_->predicates : nullptr);
  }

  /// Scaled Bernstein coefficients of f on [a, b] (gamma_i = C(n, i) * beta_i, same signs as the
  /// Bernstein coefficients beta_i): gamma_i = sum_{k <= i} C(n - k, i - k) d_k (b - a)^k, where
  /// d_k are the Taylor coefficients of f at a. Rigorous enclosures.
  void bernstein(double a, double b, std::array<Iv, kN + 1>& gamma) const {
    if (stats_) ++stats_->bernstein_boxes;
    std::array<Iv, kN + 1> qu, ql;
    shifted(upper_, a, qu);
    shifted(lower_, a, ql);
    const Iv w = exact_difference(b, a);
    Iv wk = Iv::point(1.0);
    std::array<Iv, kN + 1> e;
    for (int k = 0; k <= degree_; ++k) {
      e[k] = (qu[k] - ql[k]) * wk;
      wk = wk * w;
    }
    for (int i = 0; i <= degree_; ++i) {
      Iv g = e[0];
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
    std::array<CompensatedValue, kN + 1> dd;
    if (bernstein_compensated(upper_, lower_, degree_, a, b, dd)) {
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
    exact_shifted(upper_, a, qu);
    exact_shifted(lower_, a, ql);
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
    std::array<double, kN + 1> qu = upper_.c, ql = lower_.c;
    taylor_shift(qu, upper_.degree, a - upper_.origin);
    taylor_shift(ql, lower_.degree, a - lower_.origin);
    for (int k = 0; k <= kN; ++k) d[k] = qu[k] - ql[k];
  }

 private:
  const MotionPolynomial& upper_;
  const MotionPolynomial& lower_;
  CropStats* stats_;
  int degree_;
};

/// The grid: points (j + 1/2) w. Indices are exact integers stored in int64.
struct Grid {
  double w;
  [[nodiscard]] double at(std::int64_t j) const { return (static_cast<double>(j) + 0.5) * w; }
  /// Largest j with at(j) <= t.
  [[nodiscard]] std::int64_t floor_index(double t) const {
    std::int64_t j = static_cast<std::int64_t>(std::floor(t / w - 0.5));
    while (at(j) > t) --j;
    while (at(j + 1) <= t) ++j;
    return j;
  }
};

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
  Cropper(const MotionPolynomial& upper, const MotionPolynomial& lower, double eps,
          CropStats* stats, std::vector<CropInterval>* all)
      : f_(upper, lower, stats), grid_{crop_grid_width(eps)}, stats_(stats), all_(all) {}

  CropResult run(Time lo, Time hi) {
    std::int64_t ja = grid_.floor_index(lo);
    std::int64_t jb = grid_.floor_index(hi);
    if (grid_.at(jb) < hi || jb == ja) ++jb;
    if (f_.degree() <= 2 && linear_fast_path(ja, jb)) return result_;
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
        return result_;
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
      return result_;
    }
    if (f_.degree() <= 1) {
      // A non-zero polynomial of degree <= 1 is monotone: a sign change between the window's
      // ends is its only root; equal signs mean none.
      if (sa != sb) locate_single(ja, jb, sa, sb);
      return result_;
    }
    seeded_subdivision(ja, jb, sa, sb, guesses);
    return result_;
  }

 private:
  /// Degree <= 1 with the guess verified by two exact signs: f is monotone, so a sign change
  /// across one cell is its only root, and a window end with the sign beyond the root proves
  /// there is none inside. Returns false (nothing emitted) when the guess cannot be verified.
  bool linear_fast_path(std::int64_t ja, std::int64_t jb) {
    const MotionPolynomial& u = f_.upper();
    const MotionPolynomial& l = f_.lower();
    // The slope of f: c[1] - c[1], plus 2 c2 (o_l - o_u) when both are congruent parabolas
    // (equal c[2]: the squares cancel exactly and f is linear, as in the paper's PARABOLA).
    Iv slope_iv = exact_difference(u.c[1], l.c[1]);
    if (f_.degree() == 2) {
      if (u.degree != 2 || l.degree != 2 || u.c[2] != l.c[2]) return false;
      slope_iv = slope_iv + Iv::point(2.0 * u.c[2]) * exact_difference(l.origin, u.origin);
    }
    const int slope = slope_iv.sign();
    if (slope == 0) return false;
    const double a = grid_.at(ja);
    const double value = u.evaluate(a) - l.evaluate(a);
    const double r = a - value / (0.5 * slope_iv.lo + 0.5 * slope_iv.hi);
    const std::int64_t j =
        std::isfinite(r) ? std::clamp(grid_.floor_index(std::clamp(r, a, grid_.at(jb))), ja, jb - 1)
                         : ja;
    const int s0 = f_.sign(grid_.at(j));
    const int s1 = f_.sign(grid_.at(j + 1));
    result_.window_lo = a;
    result_.window_hi = grid_.at(jb);
    if (s0 == -slope && s1 == slope) {
      result_.sign_first = -slope;
      emit(CropInterval{grid_.at(j), grid_.at(j + 1), static_cast<std::int8_t>(s0),
                        static_cast<std::int8_t>(s1)});
    } else if (j == ja && s0 == slope) {
      result_.sign_first = slope;  // the root is before the window
    } else if (j + 1 == jb && s1 == -slope) {
      result_.sign_first = -slope;  // the root is after the window
    } else {
      return false;
    }
    if (stats_) ++stats_->fast_path;
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
    const int m = degree > 0 ? float_sign_change_roots(d, degree, 0.0, b - a, guesses) : 0;
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
    for (int i = 0; i < k; ++i) {
      if (!done && cells[i] > gap_start) subdivide(gap_start, cells[i]);
      emit(found[i]);
      gap_start = cells[i] + 1;
    }
    if (!done && gap_start < jb) subdivide(gap_start, jb);
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
    std::array<Iv, kN + 1> gamma;
    const int n = f_.degree();
    while (top > 0) {
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
    if (jb - ja > 1) {
      const double a = grid_.at(ja);
      std::array<double, kN + 1> d;
      f_.approximate_at(a, d);
      const double r = a + guess_root(d, std::max(1, f_.degree()), grid_.at(jb) - a, sa);
      std::int64_t j = std::clamp(grid_.floor_index(r), ja, jb - 1);
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
    if (all_) all_->push_back(iv);
    if (iv.is_event()) {
      assert(result_.count < kN);
      if (result_.count < kN) result_.events[result_.count++] = iv;
    } else {
      ++result_.turbulent_count;
    }
  }

  static constexpr double kInf = std::numeric_limits<double>::infinity();

  Certificate f_;
  Grid grid_;
  CropStats* stats_;
  std::vector<CropInterval>* all_;
  CropResult result_;
};

}  // namespace

double crop_grid_width(double eps) {
  assert(eps > 0.0 && std::isfinite(eps));
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

CropResult crop(const MotionPolynomial& upper, const MotionPolynomial& lower, Time lo, Time hi,
                double eps, CropStats* stats, std::vector<CropInterval>* all_intervals) {
  assert(lo <= hi && std::isfinite(lo) && std::isfinite(hi));
  assert(crop_precision_supported(eps, lo, hi));
  if (stats) ++stats->calls;
  if (upper == lower) {
    CropResult r;
    r.identically_zero = true;
    r.window_lo = lo;
    r.window_hi = hi;
    return r;
  }
  Cropper cropper(upper, lower, eps, stats, all_intervals);
  return cropper.run(lo, hi);
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

Time event_time(const CropResult& r, Time t_curr) {
  if (r.identically_zero) return kTimeInfinity;
  int last = 0;
  while (last < r.count && r.events[last].rho <= t_curr) ++last;
  const int chi = last == 0 ? r.sign_first : r.events[last - 1].sign_right;
  if (chi < 0) return last == 0 ? r.window_lo : r.events[last - 1].rho;
  return last < r.count ? r.events[last].rho : kTimeInfinity;
}

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
