// In-circle and orientation decisions of the exact scheduler made in floating point
// (core/float_decision.hpp):
// every decision the filters take is held against the GMP decision (decide_exact on the exact
// polynomial at the exact now): the same sign just after now, the same failure or none, the
// failure at the same exact time. Random points on lines and parabolas, integer and
// half-integer coefficients (co-circular and collinear at many instants, tangencies), points
// co-circular at a double time taken as now (a root at now: the filters must leave it to GMP),
// now a double or the bracket of another certificate's root, finite and infinite horizons.
// Fixed seeds, printed on failure.

#include "core/float_decision.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "kinetic/core/exact_time.hpp"
#include "kinetic/core/incircle.hpp"

namespace kinetic {
namespace {

using Motion = std::array<MotionPolynomial, 2>;

struct Tally {
  int cases = 0, fast = 0, fast_failures = 0, deferred = 0;
};

/// Holds the floating-point decision (when the filters take it) against the GMP decision; its
/// failure, when it has one, in `failure`.
template <class Certificate>
void check_certificate(const Certificate& f, const LazyTime& now, Time horizon, Tally& tally,
                       const std::string& what, LazyTime* failure) {
  ++tally.cases;
  const std::optional<FloatDecision> fast = decide_in_floating_point(f, now, horizon);
  if (!fast) return;
  ++tally.fast;
  LazyTime gmp_now = now;
  const mpq_class h(std::isfinite(horizon) ? horizon : std::numeric_limits<double>::max());
  const ExactPolynomial exact_f = ExactPolynomial::of(f);
  ExactDecision e = decide_exact(exact_f, gmp_now.exact(), h);
  ASSERT_EQ(fast->sign, e.sign) << what;
  ASSERT_EQ(fast->fails, e.fails) << what;
  if (!fast->fails) return;
  ++tally.fast_failures;
  if (!fast->failure.is_double()) ++tally.deferred;
  if (failure != nullptr) *failure = fast->failure;
  LazyTime mine = fast->failure;
  LazyTime theirs = LazyTime::of(std::move(e.failure));
  ASSERT_EQ(compare(mine, theirs), 0)
      << what << ": failure in [" << fast->failure.lower() << ", " << fast->failure.upper() << "]";
  // The failure is not before now.
  LazyTime now_copy = now;
  ASSERT_GE(compare(mine, now_copy), 0) << what;
}

void check(const std::array<Motion, 4>& p, const LazyTime& now, Time horizon, Tally& tally,
           const std::string& what, LazyTime* failure = nullptr) {
  InCircle f;
  for (std::size_t i = 0; i < 4; ++i) f.p[i] = MovingPoint2{&p[i][0], &p[i][1]};
  check_certificate(f, now, horizon, tally, what, failure);
}

/// The orientation of three moving points (a ProductCombination of degree <= 4).
void check_orientation(const std::array<Motion, 3>& p, const LazyTime& now, Time horizon,
                       Tally& tally, const std::string& what, LazyTime* failure = nullptr) {
  const ProductCombination f = orientation(p[0][0], p[0][1], p[1][0], p[1][1], p[2][0], p[2][1]);
  check_certificate(f, now, horizon, tally, what, failure);
}

MotionPolynomial random_motion(std::mt19937_64& rng, bool integers) {
  std::uniform_real_distribution<double> u(-5.0, 5.0);
  std::uniform_int_distribution<int> small(-6, 6);
  const int degree = static_cast<int>(rng() % 3);
  std::array<double, 3> c{};
  for (int k = 0; k <= degree; ++k)
    c[static_cast<std::size_t>(k)] = integers ? small(rng) / 2.0 : u(rng);
  return MotionPolynomial::from(
      std::span<const double>(c.data(), static_cast<std::size_t>(degree) + 1));
}

/// A time now (quarters for half-integer motions) and a horizon after it (infinite one time in
/// three), drawn in this order.
std::pair<double, Time> draw_now_and_horizon(std::mt19937_64& rng, bool integers) {
  std::uniform_real_distribution<double> time(-3.0, 8.0);
  const double t = integers ? std::round(time(rng) * 4.0) / 4.0 : time(rng);
  const Time horizon =
      rng() % 3 == 0 ? kTimeInfinity : t + 1.0 + 9.0 * static_cast<double>(rng() % 1000) / 1000.0;
  return {t, horizon};
}

/// The points' certificate (an in-circle of four, an orientation of three) decided at a time now
/// and a horizon drawn from rng, as case i of the run seeded with `seed`; when the failure it
/// finds is a deferred root (the certificate 0 there, changing sign), decided again at that
/// failure as the points are and as each of `others` rearranges them (its name appended to the
/// case's), into at_own_root.
template <std::size_t N>
void check_now_and_at_own_failure(
    const std::array<Motion, N>& p, std::mt19937_64& rng, bool integers, std::uint64_t seed, int i,
    Tally& tally, Tally& at_own_root,
    const std::vector<std::pair<std::array<Motion, N>, const char*>>& others) {
  const auto decide = [](const std::array<Motion, N>& q, const LazyTime& now, Time horizon,
                         Tally& t, const std::string& what, LazyTime* failure = nullptr) {
    if constexpr (N == 4) {
      check(q, now, horizon, t, what, failure);
    } else {
      check_orientation(q, now, horizon, t, what, failure);
    }
  };
  const auto [t, horizon] = draw_now_and_horizon(rng, integers);
  const std::string what = "seed " + std::to_string(seed) + " case " + std::to_string(i);
  LazyTime failure = LazyTime::point(kTimeInfinity);
  decide(p, LazyTime::point(t), horizon, tally, what, &failure);
  if (::testing::Test::HasFatalFailure()) return;
  if (failure.deferred_polynomial() == nullptr) return;
  decide(p, failure, horizon, at_own_root, what + " (at its own failure)");
  for (const auto& [q, name] : others) decide(q, failure, horizon, at_own_root, what + name);
}

/// 3000 cases of N points from draw(rng, integers), random (integers false, seeded with
/// `seed_random`) and half-integer (`seed_half`), each decided now and at its own failure
/// (check_now_and_at_own_failure, with others(p) the points rearranged); then
/// expect(integers, tally, at_own_root) for each of the two runs.
template <std::size_t N, class Draw, class Others, class Expect>
void agree_with_gmp(std::uint64_t seed_random, std::uint64_t seed_half, const Draw& draw,
                    const Others& others, const Expect& expect) {
  for (const bool integers : {false, true}) {
    const std::uint64_t seed = integers ? seed_half : seed_random;
    std::mt19937_64 rng(seed);
    Tally tally, at_own_root;
    for (int i = 0; i < 3000; ++i) {
      const std::array<Motion, N> p = draw(rng, integers);
      check_now_and_at_own_failure<N>(p, rng, integers, seed, i, tally, at_own_root, others(p));
      if (::testing::Test::HasFatalFailure()) return;
    }
    expect(integers, tally, at_own_root);
  }
}

/// One run's tallies on a line: "[ float ] <what>, <random or half-integers>: ...".
void print_tallies(const char* what, bool integers, const Tally& tally, const Tally& at_own_root) {
  std::printf(
      "[ float ] %s, %s: %d cases, %d decided in floating point (%d failures, %d deferred); at "
      "their own failure %d of %d\n",
      what, integers ? "half-integers" : "random", tally.cases, tally.fast, tally.fast_failures,
      tally.deferred, at_own_root.fast, at_own_root.cases);
}

/// N points of random_motion()s, both axes of each drawn in turn.
template <std::size_t N>
std::array<Motion, N> random_motions(std::mt19937_64& rng, bool integers) {
  std::array<Motion, N> p;
  for (Motion& m : p) m = {random_motion(rng, integers), random_motion(rng, integers)};
  return p;
}

TEST(FloatDecision, RandomAndHalfIntegerMotionsAgreeWithGmp) {
  // At its own failure (a deferred root: the certificate 0 there, changing sign), the same
  // four points decided again, as they are and in another order (the flipped edge's
  // certificate): the sign just after is known from the deferred root's polynomial.
  agree_with_gmp<4>(
      47, 48, random_motions<4>,
      [](const std::array<Motion, 4>& p) {
        return std::vector<std::pair<std::array<Motion, 4>, const char*>>{
            {{p[1], p[2], p[3], p[0]}, " (cycled, at its failure)"}};
      },
      [](bool integers, const Tally& tally, const Tally& at_own_root) {
        std::printf(
            "[ float ] %s: %d cases, %d decided in floating point (%d failures, %d deferred)\n",
            integers ? "half-integers" : "random", tally.cases, tally.fast, tally.fast_failures,
            tally.deferred);
        // The filters take most decisions (3000 and 2988 of 3000 since exact signs at doubles
        // are filtered by compensated Horner, 2074 and 2983 before; the rest: roots closer than
        // the subdivision resolves, search ends beyond 2^64, roots at now).
        EXPECT_GT(tally.fast, tally.cases / 2);
        EXPECT_GT(tally.deferred, 300);
        std::printf(
            "[ float ] at their own deferred failure: %d cases, %d decided in floating point\n",
            at_own_root.cases, at_own_root.fast);
        EXPECT_GT(at_own_root.fast, at_own_root.cases * 3 / 4);
      });
}

/// Points on lines only (the in-circle of degree 4 built by incircle.cpp's written-out
/// determinant of lines in bounded double-doubles), with origins 0 and elsewhere (the constant
/// coefficient c0 - c1 o then rounded and bounded), random and half-integer (co-circular at many
/// instants, for ever, tangent), decided again at their own failure as they are and cycled.
TEST(FloatDecision, PointsOnLinesAgreeWithGmp) {
  const auto lines = [](std::mt19937_64& rng, bool integers) {
    std::uniform_real_distribution<double> u(-5.0, 5.0), origin(-3.0, 3.0);
    std::uniform_int_distribution<int> small(-6, 6);
    std::array<Motion, 4> p;
    for (Motion& m : p) {
      for (MotionPolynomial& axis : m) {
        const double c0 = integers ? small(rng) / 2.0 : u(rng);
        const double c1 = integers ? small(rng) / 2.0 : u(rng);
        const double o = rng() % 2 == 0 ? 0.0 : (integers ? small(rng) / 4.0 : origin(rng));
        axis = MotionPolynomial::from({c0, c1}, o);
      }
    }
    return p;
  };
  agree_with_gmp<4>(
      67, 68, lines,
      [](const std::array<Motion, 4>& p) {
        return std::vector<std::pair<std::array<Motion, 4>, const char*>>{
            {{p[1], p[2], p[3], p[0]}, " (cycled)"}, {{p[1], p[0], p[2], p[3]}, " (two swapped)"}};
      },
      [](bool integers, const Tally& tally, const Tally& at_own_root) {
        print_tallies("points on lines", integers, tally, at_own_root);
        EXPECT_GT(tally.fast, tally.cases * 9 / 10);
        EXPECT_GT(tally.deferred, 300);
        EXPECT_GT(at_own_root.fast, at_own_root.cases * 3 / 4);
      });
}

/// Orientations of three points on lines and parabolas (degree <= 4: the hull on curved motions),
/// random and half-integer (collinear at many instants, for ever, tangent), decided again at
/// their own failure as they are, cycled (the same polynomial) and reversed (its negation).
TEST(FloatDecision, OrientationsAgreeWithGmp) {
  agree_with_gmp<3>(
      57, 58, random_motions<3>,
      [](const std::array<Motion, 3>& p) {
        return std::vector<std::pair<std::array<Motion, 3>, const char*>>{
            {{p[1], p[2], p[0]}, " (cycled)"}, {{p[1], p[0], p[2]}, " (reversed)"}};
      },
      [](bool integers, const Tally& tally, const Tally& at_own_root) {
        print_tallies("orientations", integers, tally, at_own_root);
        EXPECT_GT(tally.fast, tally.cases / 2);
        EXPECT_GT(tally.deferred, 200);
        EXPECT_GT(at_own_root.fast, at_own_root.cases * 3 / 4);
      });
}

/// Coordinates far from 1 (every coefficient scaled by 2^k, k up to +-500, about 1e+-150): a
/// fast decision, when the filters take one, is still the GMP one (in-circles and
/// orientations); the filters decline where their domains end.
TEST(FloatDecision, ScaledCoordinatesAgreeWithGmp) {
  constexpr std::uint64_t kSeed = 59;
  std::mt19937_64 rng(kSeed);
  Tally incircles, orientations;
  for (int i = 0; i < 1200; ++i) {
    const int scale = std::array<int, 6>{-500, -150, -60, 60, 150, 500}[rng() % 6];
    const auto scaled = [&](MotionPolynomial m) {
      for (double& c : m.c) c = std::ldexp(c, scale);
      return m;
    };
    std::array<Motion, 4> p;
    for (Motion& m : p)
      m = {scaled(random_motion(rng, rng() % 2 == 0)), scaled(random_motion(rng, false))};
    const double t = std::round(std::uniform_real_distribution<double>(-3.0, 8.0)(rng) * 8) / 8;
    const Time horizon = rng() % 2 == 0 ? kTimeInfinity : t + 10.0;
    const std::string what = "seed " + std::to_string(kSeed) + " case " + std::to_string(i) +
                             " scale 2^" + std::to_string(scale);
    check(p, LazyTime::point(t), horizon, incircles, what);
    check_orientation({p[0], p[1], p[2]}, LazyTime::point(t), horizon, orientations, what);
    if (::testing::Test::HasFatalFailure()) return;
  }
  std::printf(
      "[ float ] scaled: in-circles %d of %d decided in floating point, orientations %d "
      "of %d\n",
      incircles.fast, incircles.cases, orientations.fast, orientations.cases);
  EXPECT_GT(incircles.fast, incircles.cases / 4);
  EXPECT_GT(orientations.fast, orientations.cases / 2);
}

// Points on a circle of radius 5 (integer points) at t = 1, moving on lines and parabolas with
// integer velocities: co-circular at now = 1, the certificate 0 there. The filters must leave
// such decisions to GMP (or take them right); just after, and from the brackets of those roots
// taken as now, they decide.
TEST(FloatDecision, CoCircularAtNowAndNowOnAnotherRootAgreeWithGmp) {
  const std::array<std::array<double, 2>, 12> circle{{{5, 0},
                                                      {4, 3},
                                                      {3, 4},
                                                      {0, 5},
                                                      {-3, 4},
                                                      {-4, 3},
                                                      {-5, 0},
                                                      {-4, -3},
                                                      {-3, -4},
                                                      {0, -5},
                                                      {3, -4},
                                                      {4, -3}}};
  std::mt19937_64 rng(49);
  std::uniform_int_distribution<int> v(-3, 3);
  Tally at_root, on_bracket;
  for (int i = 0; i < 1500; ++i) {
    std::array<Motion, 4> p;
    std::array<std::size_t, 4> pick{};
    for (std::size_t k = 0; k < 4; ++k) {
      bool fresh = false;
      while (!fresh) {
        pick[k] = rng() % circle.size();
        fresh = true;
        for (std::size_t j = 0; j < k; ++j) fresh = fresh && pick[j] != pick[k];
      }
      const bool curved = rng() % 2 == 0;
      const std::array<double, 3> x{circle[pick[k]][0], double(v(rng)),
                                    curved ? v(rng) / 2.0 : 0.0};
      const std::array<double, 3> y{circle[pick[k]][1], double(v(rng)),
                                    curved ? v(rng) / 2.0 : 0.0};
      p[k] = {MotionPolynomial::from(std::span<const double>(x.data(), 3), 1.0),
              MotionPolynomial::from(std::span<const double>(y.data(), 3), 1.0)};
    }
    const std::string what = "seed 49 case " + std::to_string(i);
    check(p, LazyTime::point(1.0), rng() % 2 == 0 ? kTimeInfinity : 6.0, at_root, what);
    if (::testing::Test::HasFatalFailure()) return;
    // Now on the bracket of this certificate's next root after 1 (decided exactly).
    InCircle f;
    for (std::size_t k = 0; k < 4; ++k) f.p[k] = MovingPoint2{&p[k][0], &p[k][1]};
    ExactTime one = ExactTime::point(mpq_class(1));
    ExactDecision next = decide_exact(ExactPolynomial::of(f), one, mpq_class(50));
    if (!next.fails) continue;
    const LazyTime root = LazyTime::of(std::move(next.failure));
    check(p, root, 50.0, on_bracket, what + " (now: its next root)");
    if (::testing::Test::HasFatalFailure()) return;
    // And another certificate of three of the points and a fourth, at that now.
    std::array<Motion, 4> q = p;
    q[3] = {MotionPolynomial::from({double(v(rng)), 0.5}), MotionPolynomial::from({2.0, -0.25})};
    check(q, root, 50.0, on_bracket, what + " (another certificate at that now)");
    if (::testing::Test::HasFatalFailure()) return;
  }
  std::printf(
      "[ float ] co-circular at now: %d cases, %d decided in floating point; now on a "
      "root's bracket: %d cases, %d decided (%d failures)\n",
      at_root.cases, at_root.fast, on_bracket.cases, on_bracket.fast, on_bracket.fast_failures);
  EXPECT_GT(on_bracket.fast, on_bracket.cases / 4);
}

// A deferred root compares with the times around it by its bracket, and exactly (its exact time
// built from the expansions) with a time in the same bracket.
TEST(FloatDecision, DeferredRootsCompareExactly) {
  // (t - 1/3)(t + 7): the root 1/3 between adjacent doubles; f = t^2 + 20/3 t - 7/3 is not
  // dyadic, so take 3 f = 3 t^2 + 20 t - 7.
  LazyTime::ExpansionCoefficients given;
  for (const double c : {-7.0, 20.0, 3.0}) given.push_back(std::span<const double>(&c, 1));
  const auto coefficients = std::make_shared<const LazyTime::DeferredPolynomial>(given);
  const double third = 1.0 / 3.0;
  const double lo = mpq_class(third) < mpq_class(1, 3) ? third : std::nextafter(third, 0.0);
  const double hi = std::nextafter(lo, 1.0);
  LazyTime r = LazyTime::deferred_root(coefficients, lo, hi, -1);
  LazyTime below = LazyTime::point(lo), above = LazyTime::point(hi);
  EXPECT_EQ(compare(below, r), -1);
  EXPECT_EQ(compare(r, above), -1);
  EXPECT_FALSE(r.is_exact_built());  // decided by the brackets
  LazyTime same = LazyTime::of(ExactTime::point(mpq_class(1, 3)));
  EXPECT_EQ(compare(r, same), 0);
  EXPECT_TRUE(r.is_exact_built());
  LazyTime copy = r;
  LazyTime other = LazyTime::of(
      ExactTime::point(mpq_class(1, 3) + mpq_class(1, 1 << 30) / (1 << 30) / (1 << 30)));
  EXPECT_EQ(compare(copy, other), -1);
}

}  // namespace
}  // namespace kinetic
