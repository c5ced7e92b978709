// The in-circle of points on lines in floating point with a-priori error bounds, and the search
// for its first failure on CROP's grid (incircle_lines.hpp). Every rounding bound below is written
// with u = 2^-53 (round to nearest, no FMA: the build uses -ffp-contract=off) and
// gamma_k = k u / (1 - k u), and is then rounded up generously to a power of two.
#include "core/incircle_lines.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <span>

#include "core/determinants.hpp"
#include "kinetic/core/float_roots.hpp"
#include "kinetic/core/polynomial.hpp"

namespace kinetic::detail {
namespace {

/// Magnitudes above this are refused: then no product of four of them (and of the factors 2 and
/// the sums in the determinant) overflows, and an underflowed intermediate contributes at most
/// kUnderflow to a coefficient (below).
constexpr double kMaxMagnitude = 0x1p100;
/// Each rounding to a subnormal or zero errs by at most 2^-1075; at most a few hundred of them,
/// each multiplied afterwards by at most 2^203 (a lift coefficient and a sum), stay below
/// 2^-860, added to every bound.
constexpr double kUnderflow = 0x1p-860;
/// The rounding of the determinant's program (incircle_of_line_rows() or incircle_of_rows() in
/// determinants.hpp) on its computed inputs. Its depth, counted so that relative errors compose (a
/// sum's depth is its operands' largest plus one, a product's their sum plus one), is at most 10
/// from the rows (depth 0): a lift 2, a minor 3, a term 6, a coefficient 10. So it errs by at most
/// gamma_10 < 11 u times the same program on the inputs' magnitudes, itself computed low by at most
/// a factor (1 - gamma_10): 2^-48 = 32 u.
constexpr double kProgramBound = 0x1p-48;
/// The propagated input errors, computed in double on non-negative numbers (three roundings per
/// operation along at most ten levels, and a few more in the inputs' own error terms): low by at
/// most a factor (1 - gamma_64), which this inflation more than makes up.
constexpr double kPropagatedInflation = 1.0 + 0x1p-40;
/// Evaluations on the coefficients: Horner (gamma_8), or a Taylor shift (gamma_8), a scaling by
/// powers of the span (gamma_5) and the binomial transform to Bernstein coefficients (gamma_6),
/// relative to the same steps on the coefficients' magnitudes: gamma_19 < 20 u <= 2^-47 = 64 u.
constexpr double kEvaluationBound = 0x1p-47;
/// The data bound, itself computed by Horner on non-negative numbers (low by at most gamma_8).
constexpr double kDataBoundInflation = 1.0 + 0x1p-48;
/// Bernstein spans examined by one search before it gives up to the general path.
constexpr int kBoxBudget = 24;
constexpr double kU = 0x1p-53;

/// A computed value v, a bound m >= |v| of its magnitude, and a bound d >= |v - x| of its
/// distance from the exact value x of the same program on exact inputs, propagated from the
/// inputs' errors (the program's own roundings are bounded apart, by kProgramBound m). The inputs
/// are differences of nearby positions, so m follows the differences, not the positions.
struct Bd {
  double v, m, d;
  friend Bd operator+(Bd a, Bd b) { return {a.v + b.v, a.m + b.m, a.d + b.d}; }
  friend Bd operator-(Bd a, Bd b) { return {a.v - b.v, a.m + b.m, a.d + b.d}; }
  /// |a b - x y| <= |a - x| |b| + |x| |b - y| <= a.d b.m + (a.m + a.d) b.d.
  friend Bd operator*(Bd a, Bd b) { return {a.v * b.v, a.m * b.m, a.d * b.m + (a.m + a.d) * b.d}; }
  /// 2 x, exactly.
  [[nodiscard]] Bd twice() const { return {2.0 * v, 2.0 * m, 2.0 * d}; }
  /// A bound of the exact value's distance from v: propagated, the program's, underflow.
  [[nodiscard]] double bound() const {
    return kPropagatedInflation * d + kProgramBound * m + kUnderflow;
  }
  /// A bound of the exact value's magnitude.
  [[nodiscard]] double magnitude() const { return m + d; }
};

/// A moving coordinate at t: its computed value, a bound of that value's error, and its rate
/// (lines only).
struct Coordinate {
  double value, error, rate;
};

/// A line P = c0 + c1 (t - o) at t: |P~ - P| <= gamma_3 (|c0| + |c1| |t - o|), bounded by 4 u
/// times that scale computed in double (low by at most a factor 1 - gamma_2). Constants are exact.
bool line_at(const MotionPolynomial& p, double t, Coordinate& out) {
  if (p.degree > 1) return false;
  if (p.degree == 0) {
    out = {p.c[0], 0.0, 0.0};
    return true;
  }
  const double s = t - p.origin;
  out = {p.c[0] + p.c[1] * s, 4.0 * kU * (std::fabs(p.c[0]) + std::fabs(p.c[1]) * std::fabs(s)),
         p.c[1]};
  return true;
}

/// Any motion at t (evaluate_filtered's rigorous bound), without a rate.
Coordinate position_at(const MotionPolynomial& p, double t) {
  Coordinate c;
  if (line_at(p, t, c)) return c;
  const FilteredValue fv = evaluate_filtered(p, t);
  return {fv.value, fv.error, 0.0};
}

/// x~ = P~ - Q~: |x~ - x| <= err_P + err_Q + u |P~ - Q~| <= err_P + err_Q + 2 u |x~|.
Bd difference(const Coordinate& p, const Coordinate& q) {
  const double v = p.value - q.value;
  return {v, std::fabs(v), p.error + q.error + 2.0 * kU * std::fabs(v)};
}
/// The rates' difference: one rounding, |v - x| <= u |x| <= 2 u |v|.
Bd rate_difference(const Coordinate& p, const Coordinate& q) {
  const double v = p.rate - q.rate;
  return {v, std::fabs(v), 2.0 * kU * std::fabs(v)};
}

double horner(const std::array<double, 5>& c, double s) {
  return (((c[4] * s + c[3]) * s + c[2]) * s + c[1]) * s + c[0];
}

/// The quartic holding * p, its coefficients' bounds and magnitudes.
struct Quartic {
  std::array<double, 5> a{}, e{}, abs{};
};

int sign_at_offset(const Quartic& q, double s) {
  const double v = horner(q.a, s);
  const double bound =
      horner(q.e, s) * kDataBoundInflation + kEvaluationBound * horner(q.abs, s) + kUnderflow;
  if (!(std::isfinite(v) && std::isfinite(bound))) return 0;
  return v > bound ? 1 : (v < -bound ? -1 : 0);
}

/// True when q > 0 on [alpha, alpha + h] is certified by its Bernstein coefficients there.
bool positive_on_span(const Quartic& q, double alpha, double h) {
  std::array<double, 5> t = q.a, m = q.abs;
  if (alpha != 0.0) {
    for (int i = 0; i < 4; ++i) {
      for (int k = 3; k >= i; --k) {
        t[k] += alpha * t[k + 1];
        m[k] += alpha * m[k + 1];
      }
    }
  }
  double hk = 1.0;
  for (int k = 1; k <= 4; ++k) {
    hk *= h;
    t[k] *= hk;
    m[k] *= hk;
  }
  const double b0 = t[0];
  const double b1 = t[0] + 0.25 * t[1];
  const double b2 = t[0] + 0.5 * t[1] + t[2] / 6.0;
  const double b3 = t[0] + 0.75 * t[1] + 0.5 * t[2] + 0.25 * t[3];
  const double b4 = t[0] + t[1] + t[2] + t[3] + t[4];
  const double bound = horner(q.e, alpha + h) * kDataBoundInflation +
                       kEvaluationBound * (m[0] + m[1] + m[2] + m[3] + m[4]) + kUnderflow;
  const double low = std::min({b0, b1, b2, b3, b4});
  return std::isfinite(bound) && low > bound;  // NaN compares false
}

/// q > 0 at every grid point of the cells [lo, hi] (offsets lo w .. hi w): spans certified
/// positive, halved where they are not, single cells by their ends' signs. False when the budget
/// runs out or a grid point is not certified positive.
bool positive_at_grid_points(const Quartic& q, double w, std::int64_t lo, std::int64_t hi,
                             int& budget) {
  std::array<std::pair<std::int64_t, std::int64_t>, 64> stack;
  int top = 0;
  stack[top++] = {lo, hi};
  while (top > 0) {
    const auto [a, b] = stack[--top];
    if (budget-- <= 0) return false;
    const double alpha = static_cast<double>(a) * w;
    if (b - a <= 1) {
      if (sign_at_offset(q, alpha) <= 0 && a != 0) return false;
      if (b != a && sign_at_offset(q, static_cast<double>(b) * w) <= 0) return false;
      continue;
    }
    if (positive_on_span(q, alpha, static_cast<double>(b - a) * w)) continue;
    if (top + 2 > static_cast<int>(stack.size())) return false;
    const std::int64_t mid = a + (b - a) / 2;
    stack[top++] = {mid, b};
    stack[top++] = {a, mid};
  }
  return true;
}

/// A floating-point guess of the first root of q in (0, S] where q falls through 0 (q > 0 at 0),
/// to within `tol`: the critical points split [0, S] (roughly: they only choose the pieces), the
/// first piece whose ends' signs go from + to - is searched by a safeguarded Newton iteration.
/// NaN when no piece changes sign.
double first_root_guess(const std::array<double, 5>& a, double S, double tol) {
  int degree = 4;
  while (degree > 0 && a[static_cast<std::size_t>(degree)] == 0.0) --degree;
  if (degree == 0) return std::nan("");
  std::array<double, 4> deriv{};
  for (int i = 1; i <= degree; ++i) deriv[i - 1] = i * a[static_cast<std::size_t>(i)];
  std::array<FloatRoot, 4> critical{};
  int m = 0;
  if (degree >= 2) {
    m = float_sign_change_roots(std::span<const double>(deriv.data(), 4), degree - 1, 0.0, S,
                                critical, S * 0x1p-10);
  }
  double left = 0.0, vl = horner(a, 0.0);
  for (int i = 0; i <= m; ++i) {
    const double right = i < m ? critical[static_cast<std::size_t>(i)].at : S;
    if (!(right > left)) continue;
    const double vr = horner(a, right);
    if (vl > 0.0 && vr <= 0.0) {
      if (vr == 0.0) return right;
      double u = left, v = right, x = left + 0.5 * (right - left);
      for (int it = 0; it < 100 && v - u > tol; ++it) {
        double p = a[4], dp = 0.0;
        for (int k = 3; k >= 0; --k) {
          dp = dp * x + p;
          p = p * x + a[static_cast<std::size_t>(k)];
        }
        if (p == 0.0) return x;
        if (p > 0.0) {
          u = x;
        } else {
          v = x;
        }
        double next = dp != 0.0 ? x - p / dp : u + 0.5 * (v - u);
        if (!(next > u && next < v)) next = u + 0.5 * (v - u);
        if (next == x) break;
        x = next;
      }
      return x;
    }
    left = right;
    vl = vr;
  }
  return std::nan("");
}

}  // namespace

bool incircle_of_lines_at(const InCircle& f, double g, BoundedTaylor& out) {
  std::array<Coordinate, 8> p;
  for (std::size_t k = 0; k < 8; ++k) {
    const MovingPoint2& q = f.p[k / 2];
    if (!line_at(k % 2 == 0 ? *q.x : *q.y, g, p[k])) return false;
  }
  // Rows i = a, b, c relative to d: x = X + U s, y = Y + V s.
  LineRows<Bd> r;
  double largest = 0.0;
  for (std::size_t i = 0; i < 3; ++i) {
    r.x0[i] = difference(p[2 * i], p[6]);
    r.y0[i] = difference(p[2 * i + 1], p[7]);
    r.x1[i] = rate_difference(p[2 * i], p[6]);
    r.y1[i] = rate_difference(p[2 * i + 1], p[7]);
    largest = std::max({largest, r.x0[i].magnitude(), r.y0[i].magnitude(), r.x1[i].magnitude(),
                        r.y1[i].magnitude()});
  }
  if (!(largest <= kMaxMagnitude)) return false;  // also NaN
  const std::array<Bd, 5> d = incircle_of_line_rows(r);
  for (std::size_t k = 0; k < 5; ++k) {
    out.c[k] = d[k].v;
    out.e[k] = d[k].bound();
    if (!std::isfinite(out.e[k])) return false;
  }
  return true;
}

int filtered_incircle_sign(const InCircle& f, Time t) {
  std::array<Coordinate, 8> p;
  for (std::size_t k = 0; k < 8; ++k) {
    const MovingPoint2& q = f.p[k / 2];
    p[k] = position_at(k % 2 == 0 ? *q.x : *q.y, t);
  }
  std::array<Bd, 3> x, y;
  double largest = 0.0;
  for (std::size_t i = 0; i < 3; ++i) {
    x[i] = difference(p[2 * i], p[6]);
    y[i] = difference(p[2 * i + 1], p[7]);
    largest = std::max({largest, x[i].magnitude(), y[i].magnitude()});
  }
  if (!(largest <= kMaxMagnitude)) return 0;  // also NaN
  const Bd d = incircle_of_rows(x, y);
  const double bound = d.bound();
  if (!std::isfinite(bound)) return 0;
  return d.v > bound ? 1 : (d.v < -bound ? -1 : 0);
}

int certified_sign(const BoundedTaylor& p, double s) {
  Quartic q;
  q.a = p.c;
  q.e = p.e;
  for (std::size_t k = 0; k < 5; ++k) q.abs[k] = std::fabs(p.c[k]);
  return sign_at_offset(q, s);
}

std::optional<Time> first_failure_on_grid(const BoundedTaylor& p, int holding, double g, double w,
                                          std::int64_t cells, std::uint64_t* boxes) {
  assert(holding == 1 || holding == -1);
  assert(cells >= 1);
  Quartic q;
  for (std::size_t k = 0; k < 5; ++k) {
    q.a[k] = holding * p.c[k];
    q.e[k] = p.e[k];
    q.abs[k] = std::fabs(p.c[k]);
  }
  int budget = kBoxBudget;
  const auto spent = [&]() {
    if (boxes) *boxes += static_cast<std::uint64_t>(kBoxBudget - std::max(budget, 0));
  };
  const double span = static_cast<double>(cells) * w;
  // No failure in the window: one span (usually) certifies it.
  if (positive_on_span(q, 0.0, span)) {
    --budget;
    spent();
    return kTimeInfinity;
  }
  --budget;
  const double r = first_root_guess(q.a, span, 0.25 * w);
  std::optional<Time> answer;
  if (std::isnan(r)) {
    // No guess: the window may still be free of failures at grid points.
    if (positive_at_grid_points(q, w, 0, cells, budget)) answer = kTimeInfinity;
    spent();
    return answer;
  }
  // The first grid point after the guess; one step either way when rounding put the guess in
  // the neighbouring cell.
  std::int64_t j = std::clamp(static_cast<std::int64_t>(std::floor(r / w)) + 1,
                              static_cast<std::int64_t>(1), cells);
  int sj = sign_at_offset(q, static_cast<double>(j) * w);
  if (sj > 0 && j < cells) sj = sign_at_offset(q, static_cast<double>(++j) * w);
  if (sj < 0 && j > 1 && sign_at_offset(q, static_cast<double>(j - 1) * w) < 0) {
    sj = sign_at_offset(q, static_cast<double>(--j) * w);
  }
  if (sj < 0 && (j == 1 || positive_at_grid_points(q, w, 0, j - 1, budget))) {
    answer = g + static_cast<double>(j) * w;
  }
  spent();
  return answer;
}

}  // namespace kinetic::detail
