// Floating-point (uncertified) root finding of the classic scheduler: accuracy on well-separated
// roots, directions, the [lo, hi] window, double roots, float_difference and classic_failure_time.

#include "kinetic/core/float_roots.hpp"

#include <gmpxx.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace kinetic {
namespace {

using Q = mpq_class;

/// Exact coefficients of lead * prod (s - r_i); every root and lead must make them doubles.
std::vector<double> from_roots(double lead, const std::vector<double>& roots) {
  std::vector<Q> c = {Q(lead)};
  for (double r : roots) {
    std::vector<Q> next(c.size() + 1, Q(0));
    for (std::size_t i = 0; i < c.size(); ++i) {
      next[i + 1] += c[i];
      next[i] -= c[i] * Q(r);
    }
    c = next;
  }
  std::vector<double> out;
  for (const Q& q : c) {
    const double d = q.get_d();
    EXPECT_EQ(Q(d), q) << "test setup: coefficient not a double";
    out.push_back(d);
  }
  return out;
}

std::vector<FloatRoot> roots_of(const std::vector<double>& c, double lo, double hi) {
  const int degree = static_cast<int>(c.size()) - 1;
  std::vector<FloatRoot> out(std::max(degree, 1));
  const int m = float_sign_change_roots(c, degree, lo, hi, out);
  EXPECT_GE(m, 0);
  EXPECT_LE(m, std::max(degree, 0));
  out.resize(static_cast<std::size_t>(std::max(m, 0)));
  for (std::size_t i = 1; i < out.size(); ++i)
    EXPECT_LT(out[i - 1].at, out[i].at) << "not ascending";
  return out;
}

std::string show(const std::vector<double>& c, const std::vector<FloatRoot>& r) {
  std::ostringstream os;
  os.precision(17);
  os << "c=[";
  for (std::size_t i = 0; i < c.size(); ++i) os << (i ? ", " : "") << c[i];
  os << "] roots=[";
  for (std::size_t i = 0; i < r.size(); ++i)
    os << (i ? ", " : "") << r[i].at << "(" << r[i].direction << ")";
  os << "]";
  return os.str();
}

/// Expected direction at the j-th (ascending) of d simple roots of lead * prod (s - r_i).
int direction_at(double lead, int d, int j) {
  const int s = lead > 0 ? 1 : -1;
  return ((d - 1 - j) % 2 == 0) ? s : -s;
}

void expect_roots(double lead, std::vector<double> roots, double lo, double hi, double rel,
                  const std::string& w) {
  std::sort(roots.begin(), roots.end());
  const std::vector<double> c = from_roots(lead, roots);
  const std::vector<FloatRoot> got = roots_of(c, lo, hi);
  std::vector<std::pair<double, int>> expected;
  for (std::size_t j = 0; j < roots.size(); ++j) {
    if (roots[j] >= lo && roots[j] <= hi) {
      expected.emplace_back(
          roots[j], direction_at(lead, static_cast<int>(roots.size()), static_cast<int>(j)));
    }
  }
  ASSERT_EQ(got.size(), expected.size()) << w << " " << show(c, got);
  for (std::size_t j = 0; j < got.size(); ++j) {
    EXPECT_NEAR(got[j].at, expected[j].first, rel * std::max(1.0, std::fabs(expected[j].first)))
        << w << " root " << j << " " << show(c, got);
    EXPECT_EQ(got[j].direction, expected[j].second) << w << " root " << j << " " << show(c, got);
  }
}

constexpr double kBig = 1e300;

// ---------------------------------------------------------------------------------------------

TEST(FloatRoots, KnownSeparatedRootsEveryDegree) {
  const std::vector<std::vector<double>> sets = {
      {2.5},
      {-1.0, 3.0},
      {-2.0, 0.5, 4.0},
      {-3.0, -1.0, 1.5, 6.0},
      {-4.0, -1.5, 0.0, 2.0, 5.0},
      {-3.5, -1.0, 0.25, 2.0, 4.75, 8.0},
      {1.0, 2.0, 3.0, 4.0, 5.0, 6.0},
      {-1000.0, -10.0, 0.125, 10.0, 1000.0},
      {0.0009765625, 1.0, 1024.0},
  };
  for (const auto& roots : sets) {
    for (double lead : {1.0, -1.0, 0.25, -8.0}) {
      std::ostringstream w;
      w << "lead=" << lead << " degree=" << roots.size();
      expect_roots(lead, roots, -kBig, kBig, 1e-12, w.str());
    }
  }
}

TEST(FloatRoots, RandomSeparatedRoots) {
  // Distinct dyadic roots k/8 in [-3, 3], at least 3/4 apart; lead = +-2^e.
  const std::uint64_t seed = 123456789;
  std::mt19937_64 rng(seed);
  for (int it = 0; it < 600 && !HasFailure(); ++it) {
    const int d = 1 + static_cast<int>(rng() % kMaxMotionDegree);
    std::vector<double> roots;
    while (static_cast<int>(roots.size()) < d) {
      const double r = static_cast<double>(static_cast<int>(rng() % 49) - 24) / 8.0;
      bool ok = true;
      for (double x : roots) ok = ok && std::fabs(x - r) >= 0.75;
      if (ok) roots.push_back(r);
    }
    const double lead = std::ldexp(rng() % 2 ? 1.0 : -1.0, static_cast<int>(rng() % 21) - 10);
    expect_roots(lead, roots, -kBig, kBig, 1e-12,
                 "seed=" + std::to_string(seed) + " it=" + std::to_string(it));
  }
}

TEST(FloatRoots, Directions) {
  // 2s - 1: rising at 0.5; 1 - 2s: falling.
  {
    const std::vector<double> c = {-1.0, 2.0};
    const auto r = roots_of(c, -10, 10);
    ASSERT_EQ(r.size(), 1u);
    EXPECT_EQ(r[0].at, 0.5);
    EXPECT_EQ(r[0].direction, 1);
  }
  {
    const std::vector<double> c = {1.0, -2.0};
    const auto r = roots_of(c, -10, 10);
    ASSERT_EQ(r.size(), 1u);
    EXPECT_EQ(r[0].direction, -1);
  }
  // (s-1)(s-3): falls at 1, rises at 3. -(s-1)(s-3): the other way.
  {
    const auto r = roots_of(from_roots(1.0, {1.0, 3.0}), -10, 10);
    ASSERT_EQ(r.size(), 2u);
    EXPECT_EQ(r[0].at, 1.0);
    EXPECT_EQ(r[0].direction, -1);
    EXPECT_EQ(r[1].at, 3.0);
    EXPECT_EQ(r[1].direction, 1);
    const auto n = roots_of(from_roots(-1.0, {1.0, 3.0}), -10, 10);
    ASSERT_EQ(n.size(), 2u);
    EXPECT_EQ(n[0].direction, 1);
    EXPECT_EQ(n[1].direction, -1);
  }
  // A triple root changes sign: (s-2)^3 rises at 2.
  {
    const auto r = roots_of(from_roots(1.0, {2.0, 2.0, 2.0}), -10, 10);
    ASSERT_EQ(r.size(), 1u);
    EXPECT_NEAR(r[0].at, 2.0, 1e-4);  // a triple root is ill-conditioned
    EXPECT_EQ(r[0].direction, 1);
  }
}

TEST(FloatRoots, WindowExcludesOutsideRoots) {
  const std::vector<double> roots = {1.0, 2.0, 3.0, 4.0};
  expect_roots(1.0, roots, 1.5, 3.5, 1e-12, "[1.5, 3.5]");
  expect_roots(1.0, roots, 4.5, kBig, 1e-12, "[4.5, big]");
  expect_roots(1.0, roots, -kBig, 0.5, 1e-12, "[-big, 0.5]");
  // Closed window: roots exactly at the ends are included.
  expect_roots(1.0, roots, 2.0, 3.0, 0.0, "[2, 3]");
  expect_roots(-1.0, {-1.0, 2.0}, 2.0, 5.0, 0.0, "quadratic, root at lo");
  expect_roots(1.0, {-1.0, 2.0}, -3.0, -1.0, 0.0, "quadratic, root at hi");
  expect_roots(3.0, {0.75}, 0.75, 0.75, 0.0, "linear, degenerate window");
  expect_roots(1.0, {-1.0, 0.5, 2.0, 3.0, 7.0, 9.0}, 0.5, 7.0, 1e-12,
               "degree 6, roots at both ends");
  // Empty window and constants.
  const std::vector<double> c = from_roots(1.0, {1.0, 2.0});
  EXPECT_TRUE(roots_of(c, 3.0, 2.0).empty());
  const std::vector<double> k = {5.0};
  EXPECT_TRUE(roots_of(k, -kBig, kBig).empty());
}

TEST(FloatRoots, NoRealRootsAndQuadraticDoubleRootsAreNotReported) {
  // s^2 + 1 and (s^2 + 1)(s^2 + 4): no real roots.
  const std::vector<double> c2 = {1.0, 0.0, 1.0};
  EXPECT_TRUE(roots_of(c2, -kBig, kBig).empty());
  const std::vector<double> c4 = {4.0, 0.0, 5.0, 0.0, 1.0};
  EXPECT_TRUE(roots_of(c4, -kBig, kBig).empty());
  // (s-1)^2: a double root does not change sign.
  const std::vector<double> sq = from_roots(1.0, {1.0, 1.0});
  EXPECT_TRUE(roots_of(sq, -kBig, kBig).empty()) << show(sq, roots_of(sq, -kBig, kBig));
  EXPECT_TRUE(roots_of(from_roots(-2.0, {1.0, 1.0}), -kBig, kBig).empty());
  EXPECT_TRUE(roots_of(from_roots(0.5, {-3.0, -3.0}), -kBig, kBig).empty());
}

TEST(FloatRoots, HigherDegreeDoubleRootsAreNotReported) {
  // (s-1)^2 (s-3)^2: only touches, no sign change anywhere.
  const std::vector<double> q = from_roots(1.0, {1.0, 1.0, 3.0, 3.0});
  EXPECT_TRUE(roots_of(q, -kBig, kBig).empty()) << show(q, roots_of(q, -kBig, kBig));
  // (s-1)^2 (s+5): changes sign at -5 only; the double root 1 is also a critical point, where the
  // polynomial evaluates to exactly 0.
  const std::vector<double> c = from_roots(1.0, {1.0, 1.0, -5.0});
  const auto r = roots_of(c, -kBig, kBig);
  EXPECT_EQ(r.size(), 1u) << show(c, r);
  if (!r.empty()) {
    EXPECT_EQ(r[0].at, -5.0);
    EXPECT_EQ(r[0].direction, 1);
  }
  // (s-1)^2 (s-2)(s-4): sign changes at 2 and 4 only.
  const std::vector<double> d = from_roots(1.0, {1.0, 1.0, 2.0, 4.0});
  const auto rd = roots_of(d, -kBig, kBig);
  EXPECT_EQ(rd.size(), 2u) << show(d, rd);
  if (rd.size() == 2) {
    EXPECT_NEAR(rd[0].at, 2.0, 1e-12);
    EXPECT_NEAR(rd[1].at, 4.0, 1e-12);
  }
  // Whatever is reported, sign-change roots alternate in direction.
  for (const auto& roots : {r, rd, roots_of(q, -kBig, kBig)}) {
    for (std::size_t i = 1; i < roots.size(); ++i) {
      EXPECT_NE(roots[i - 1].direction, roots[i].direction)
          << "consecutive roots " << i - 1 << ", " << i;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// float_difference.

TEST(FloatRoots, FloatDifferenceSameAndDifferentOrigins) {
  std::array<double, kMaxMotionDegree + 1> out{};
  const std::vector<double> cu = {1.0, 2.0, 3.0};
  const std::vector<double> cl = {1.0, 2.0};
  // Same origin: plain coefficient difference.
  EXPECT_EQ(float_difference(MotionPolynomial::from(cu, 1.0), MotionPolynomial::from(cl, 1.0), out),
            2);
  EXPECT_EQ(out[0], 0.0);
  EXPECT_EQ(out[1], 0.0);
  EXPECT_EQ(out[2], 3.0);
  for (int i = 3; i <= kMaxMotionDegree; ++i) EXPECT_EQ(out[i], 0.0);
  // Different origins: upper = 1 + 2t + 3t^2 (origin 0) == 17 + 14 (t-2) + 3 (t-2)^2;
  // lower = 10 + (t - 2): difference about 2 is 7 + 13 x + 3 x^2.
  const std::vector<double> cl2 = {10.0, 1.0};
  EXPECT_EQ(
      float_difference(MotionPolynomial::from(cu, 0.0), MotionPolynomial::from(cl2, 2.0), out), 2);
  EXPECT_EQ(out[0], 7.0);
  EXPECT_EQ(out[1], 13.0);
  EXPECT_EQ(out[2], 3.0);
  // Identical functions: degree 0, all zero.
  const std::vector<double> same = {17.0, 14.0, 3.0};
  EXPECT_EQ(
      float_difference(MotionPolynomial::from(cu, 0.0), MotionPolynomial::from(same, 2.0), out), 0);
  for (int i = 0; i <= kMaxMotionDegree; ++i) EXPECT_EQ(out[i], 0.0) << i;
}

// ---------------------------------------------------------------------------------------------
// classic_failure_time(lower, upper, t_curr): first falling root of upper - lower at >= t_curr.

MotionPolynomial poly(std::vector<double> c, double origin = 0.0) {
  return MotionPolynomial::from(c, origin);
}

TEST(FloatRoots, ClassicFailureTimePicksTheFirstFallingRoot) {
  const MotionPolynomial zero = MotionPolynomial::constant(0.0);
  // upper - lower = (t-1)(t-3): falls at 1, rises at 3.
  const MotionPolynomial u = poly(from_roots(1.0, {1.0, 3.0}));
  EXPECT_EQ(classic_failure_time(zero, u, 0.0), 1.0);
  EXPECT_EQ(classic_failure_time(zero, u, -100.0), 1.0);
  EXPECT_EQ(classic_failure_time(zero, u, 2.0), kTimeInfinity);  // only a rising root left
  EXPECT_EQ(classic_failure_time(zero, u, 5.0), kTimeInfinity);
  // upper - lower = (t-1)(t-3)(t-5): rises at 1, falls at 3, rises at 5.
  const MotionPolynomial v = poly(from_roots(1.0, {1.0, 3.0, 5.0}));
  EXPECT_EQ(classic_failure_time(zero, v, 0.0), 3.0);
  EXPECT_EQ(classic_failure_time(zero, v, 3.5), kTimeInfinity);
  // -(t-1)(t-3)(t-5)(t-7) is negative before 1: rises at 1 and 5, falls at 3 and 7.
  const MotionPolynomial w = poly(from_roots(-1.0, {1.0, 3.0, 5.0, 7.0}));
  EXPECT_NEAR(classic_failure_time(zero, w, 0.0), 3.0, 1e-12);
  EXPECT_NEAR(classic_failure_time(zero, w, 3.5), 7.0, 1e-12);
  EXPECT_EQ(classic_failure_time(zero, w, 7.5), kTimeInfinity);
  // Different origins: lower = 2 + (t - 10), upper = 1 about 0, so upper - lower = 9 - t.
  EXPECT_EQ(classic_failure_time(poly({2.0, 1.0}, 10.0), MotionPolynomial::constant(1.0), 0.0),
            9.0);
}

TEST(FloatRoots, ClassicFailureTimeRootAtTCurrIsNotInThePast) {
  const MotionPolynomial zero = MotionPolynomial::constant(0.0);
  // Linear: 1 - t falls at 1.
  EXPECT_EQ(classic_failure_time(zero, poly({1.0, -1.0}), 1.0), 1.0);
  EXPECT_EQ(classic_failure_time(zero, poly({1.0, -1.0}), std::nextafter(1.0, 2.0)), kTimeInfinity);
  // Quadratic (t-1)(t-3) at t_curr = 1.
  EXPECT_EQ(classic_failure_time(zero, poly(from_roots(1.0, {1.0, 3.0})), 1.0), 1.0);
  // Cubic (t-1)(t-3)(t-5) at t_curr = 3.
  EXPECT_EQ(classic_failure_time(zero, poly(from_roots(1.0, {1.0, 3.0, 5.0})), 3.0), 3.0);
  // Different origins: lower = t - 2 about 2 (i.e. t - 2), upper = 0.5 about 0 -> upper - lower
  // = 2.5 - t falls at 2.5.
  EXPECT_EQ(classic_failure_time(poly({0.0, 1.0}, 2.0), MotionPolynomial::constant(0.5), 2.5), 2.5);
  EXPECT_EQ(classic_failure_time(poly({0.0, 1.0}, 2.0), MotionPolynomial::constant(0.5), 0.0), 2.5);
}

TEST(FloatRoots, ClassicFailureTimeInfinityWhenNothingFalls) {
  const MotionPolynomial zero = MotionPolynomial::constant(0.0);
  EXPECT_EQ(classic_failure_time(zero, MotionPolynomial::constant(1.0), 0.0), kTimeInfinity);
  EXPECT_EQ(classic_failure_time(zero, zero, 0.0), kTimeInfinity);                   // identical
  EXPECT_EQ(classic_failure_time(zero, poly({1.0, 1.0}), 0.0), kTimeInfinity);       // rising
  EXPECT_EQ(classic_failure_time(zero, poly({1.0, 0.0, 1.0}), 0.0), kTimeInfinity);  // no roots
  // Same function written about different origins: float_difference is exactly zero here.
  EXPECT_EQ(classic_failure_time(poly({1.0, 2.0, 3.0}), poly({17.0, 14.0, 3.0}, 2.0), 0.0),
            kTimeInfinity);
  // A touch (t-2)^2 is not a failure (no sign change).
  EXPECT_EQ(classic_failure_time(zero, poly(from_roots(1.0, {2.0, 2.0})), 0.0), kTimeInfinity);
}

TEST(FloatRoots, ClassicFailureTimeIgnoresATouchOfHigherDegree) {
  // upper - lower = (t-1)^2 (t+5) is >= 0 on [0, inf) and only touches 0 at t = 1: the
  // certificate [lower < upper] never fails there.
  const MotionPolynomial zero = MotionPolynomial::constant(0.0);
  const MotionPolynomial u = poly(from_roots(1.0, {1.0, 1.0, -5.0}));
  EXPECT_EQ(classic_failure_time(zero, u, 0.0), kTimeInfinity);
  // upper - lower = (t-1)^2 (t-2)(t-4): touches 0 at 1, first goes negative at 2.
  const MotionPolynomial v = poly(from_roots(1.0, {1.0, 1.0, 2.0, 4.0}));
  EXPECT_NEAR(classic_failure_time(zero, v, 0.0), 2.0, 1e-12);
}

}  // namespace
}  // namespace kinetic
