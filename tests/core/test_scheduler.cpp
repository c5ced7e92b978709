// The robust scheduler's precision: the CROP grid it uses for a user precision eps.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "kinetic/core/counters.hpp"
#include "kinetic/core/crop.hpp"
#include "kinetic/core/error.hpp"
#include "kinetic/core/float_roots.hpp"
#include "kinetic/core/predicates.hpp"
#include "kinetic/core/scheduler.hpp"
#include "support/schedulers.hpp"

namespace kinetic {
namespace {

TEST(SchedulerGrid, WidthIsLargestPowerOfTwoWithinSqrt3Over2Eps) {
  EXPECT_EQ(Scheduler::grid_width(1e-9), 0x1p-31);  // 2^-30 = 0.93e-9 would exceed 0.866e-9
  EXPECT_EQ(Scheduler::grid_width(1e-8), 0x1p-27);  // 0.745e-8
  EXPECT_EQ(Scheduler::grid_width(1e-7), 0x1p-24);  // 0.596e-7
  EXPECT_EQ(Scheduler::grid_width(1e-6), 0x1p-21);  // 0.477e-6
  EXPECT_EQ(Scheduler::grid_width(1.0), 0.5);
  EXPECT_EQ(Scheduler::grid_width(0x1p-20 / Scheduler::kCropWidthFraction), 0x1p-20);
  for (int e = -60; e <= 20; ++e) {
    for (const double m : {1.0, 1.1, 1.1547, 1.155, 1.5, 1.99}) {
      const double eps = std::ldexp(m, e);
      const double w = Scheduler::grid_width(eps);
      int exponent = 0;
      EXPECT_EQ(std::frexp(w, &exponent), 0.5) << eps;  // a power of two
      // w <= (sqrt 3 / 2) eps, so the RMS of a delay uniform over a cell, w / sqrt 3, is <= eps
      // / 2.
      EXPECT_LE(w / std::sqrt(3.0), eps / 2.0) << eps;
      EXPECT_LE(w, eps * Scheduler::kCropWidthFraction) << eps;
      EXPECT_GT(2.0 * w, eps * Scheduler::kCropWidthFraction) << eps;  // and the largest one
    }
  }
}

TEST(SchedulerGrid, SupportedTimesFollowTheGrid) {
  EXPECT_EQ(Scheduler::max_supported_time(1e-9), 0x1p49 * 0x1p-31);
  // The whole window up to it is one CROP supports (a horizon of +infinity searches that far).
  EXPECT_TRUE(crop_precision_supported(Scheduler::crop_eps(1e-9), 0.0,
                                       Scheduler::max_supported_time(1e-9)));
  EXPECT_TRUE(Scheduler::precision_supported(1e-9, 0.0, 1000.0));
  EXPECT_FALSE(Scheduler::precision_supported(1e-9, 0.0, 1e9));
  EXPECT_FALSE(Scheduler::precision_supported(0.0, 0.0, 1.0));
  EXPECT_FALSE(Scheduler::precision_supported(-1.0, 0.0, 1.0));
}

// The hardening issue, defect 2: eps = 1e294 made the search limit 2^49 w infinite, and CROP
// then searched [0, +infinity) forever. Such an eps is refused; the largest one taken has a
// finite limit, and a robust scheduler at it finds (or rules out) an event in finite time.
TEST(SchedulerGrid, EpsBeyondTheLargestSupportedIsRefused) {
  EXPECT_TRUE(Scheduler::eps_supported(1e-9));
  EXPECT_TRUE(Scheduler::eps_supported(Scheduler::kMaxEps));
  EXPECT_FALSE(Scheduler::eps_supported(1e294));
  EXPECT_FALSE(Scheduler::eps_supported(0.0));
  EXPECT_FALSE(Scheduler::eps_supported(std::nan("")));
  EXPECT_FALSE(Scheduler::eps_supported(INFINITY));
  EXPECT_TRUE(std::isfinite(Scheduler::max_supported_time(Scheduler::kMaxEps)));
  EXPECT_THROW(Scheduler(SchedulerKind::Robust, 1e294), PreconditionError);
  EXPECT_NO_THROW(Scheduler(SchedulerKind::Classic, 1e294));  // classic does not use eps
  const Scheduler widest(SchedulerKind::Robust, Scheduler::kMaxEps);
  EXPECT_EQ(widest.time_limit(), Scheduler::max_supported_time(Scheduler::kMaxEps));
  Counters counters;
  const MotionPolynomial a = MotionPolynomial::from({0.0, 1.0});
  const MotionPolynomial b = MotionPolynomial::from({5.0, -1.0});
  const Time t = widest.failure_time(a, b, 0.0, 0.0, counters);  // [a < b] fails at 2.5
  EXPECT_FALSE(std::isnan(t));
  EXPECT_GE(t, 2.5);
}

TEST(SchedulerGrid, RobustEventTimesLieOnTheGrid) {
  // The event time is the right end of the grid cell holding 1/3.
  const double line[] = {0.0, 1.0};
  const MotionPolynomial moving = MotionPolynomial::from(line);
  const MotionPolynomial fixed = MotionPolynomial::constant(1.0 / 3.0);
  Counters counters;
  // The certificate [t < 1/3] (lower = t, upper = 1/3) fails at t = 1/3 (the double).
  const Scheduler robust(SchedulerKind::Robust, 1e-6, 10.0);
  const Time t = robust.failure_time(moving, fixed, 0.0, 0.0, counters);
  const double w = Scheduler::grid_width(1e-6);
  EXPECT_GT(t, 1.0 / 3.0);
  EXPECT_LT(t - 1.0 / 3.0, w);
  const double j = t / w - 0.5;  // t = (j + 1/2) w
  EXPECT_EQ(j, std::floor(j)) << t;
}

TEST(SchedulerRobust, FailureTimeIsEventTimeOfTheCropCertificate) {
  // failure_time() takes crop_failure_time(), which skips building a CropResult on the linear
  // path: it must return event_time(crop_certificate()) bit for bit, with the same counts, for
  // linear, congruent and general quadratic certificates, at and around their interval ends.
  constexpr std::uint64_t kSeed = 0x5EED5C4D;
  std::mt19937_64 rng(kSeed);
  std::uniform_real_distribution<double> coef(-8.0, 8.0), when(-5.0, 25.0);
  const Scheduler robust(SchedulerKind::Robust, 1e-9, 20.0);
  for (int it = 0; it < 20000; ++it) {
    const int kind = static_cast<int>(rng() % 4);  // linear, congruent, quadratic, mixed
    const double a = kind == 1 ? coef(rng) : 0.0;
    auto motion = [&](int degree, double origin) {
      std::vector<double> c{coef(rng) * 4.0, coef(rng)};
      if (degree == 2) c.push_back(kind == 1 ? a : coef(rng) / 4.0);
      if (rng() % 8 == 0) c[1] = 0.0;
      return MotionPolynomial::from(c, origin);
    };
    const double ou = rng() % 2 ? 0.0 : std::round(when(rng));
    const double ol = rng() % 2 ? ou : when(rng);
    const MotionPolynomial upper = motion(kind == 0 ? 1 : 2, ou);
    const MotionPolynomial lower = motion(kind == 0 || kind == 3 ? 1 : 2, ol);
    const Time window_lo = rng() % 4 == 0 ? -kTimeInfinity : std::round(when(rng));
    Counters probe;
    const CropResult r = robust.crop_certificate(upper, lower, 0.0, window_lo, probe);
    std::vector<Time> times{0.0, when(rng), r.window_lo};
    for (int i = 0; i < r.count; ++i) {
      times.push_back(r.events[i].rho);
      times.push_back(std::nextafter(r.events[i].rho, -kTimeInfinity));
    }
    for (const Time t : times) {
      Counters c1, c2;
      const Time expected = event_time(robust.crop_certificate(upper, lower, t, window_lo, c1), t);
      const Time got = robust.failure_time(lower, upper, t, window_lo, c2);
      ASSERT_EQ(std::bit_cast<std::uint64_t>(got), std::bit_cast<std::uint64_t>(expected))
          << "seed " << kSeed << " it " << it << " t " << t << ": " << got << " vs " << expected;
      ASSERT_EQ(c1.root_isolation_calls, c2.root_isolation_calls)
          << "seed " << kSeed << " it " << it;
      ASSERT_EQ(c1.crop.calls, c2.crop.calls) << "seed " << kSeed << " it " << it;
      ASSERT_EQ(c1.crop.fast_path, c2.crop.fast_path) << "seed " << kSeed << " it " << it;
      ASSERT_EQ(c1.crop.predicates.filtered, c2.crop.predicates.filtered)
          << "seed " << kSeed << " it " << it;
      ASSERT_EQ(c1.crop.predicates.exact, c2.crop.predicates.exact)
          << "seed " << kSeed << " it " << it;
    }
  }
}

// The lines of test::kTieX, kTieY (tests/support/schedulers.hpp): just after t = 1.3, x is above y
// exactly, but floating point (their values, and their difference's coefficients) puts x below
// y there. The classic scheduler decides as a traditional KDS, in floating point; its
// exact-decisions variant the true sign. Both schedule the failure of the sign they decided from
// floating-point roots.
TEST(SchedulerClassic, DecisionsAreFloatingPointAsATraditionalKds) {
  const MotionPolynomial x = MotionPolynomial::from({test::kTieX[0], test::kTieX[1]});
  const MotionPolynomial y = MotionPolynomial::from({test::kTieY[0], test::kTieY[1]});
  const MotionPolynomial zero = MotionPolynomial::from({0.0});
  const Time t = test::kTieTime;
  ASSERT_LT(x.evaluate(t), y.evaluate(t));  // floating point: x below
  ASSERT_GT(compare_after(x, y, t), 0);     // exactly: x above
  Counters counters;
  const Scheduler classic(SchedulerKind::Classic, 1e-9);
  Scheduler careful(SchedulerKind::Classic, 1e-9);
  careful.set_classic_exact_decisions(true);
  EXPECT_TRUE(classic.floating_point_decisions());
  EXPECT_FALSE(careful.floating_point_decisions());
  EXPECT_FALSE(Scheduler(SchedulerKind::Robust, 1e-9).floating_point_decisions());
  EXPECT_FALSE(Scheduler(SchedulerKind::Exact, 1e-9).floating_point_decisions());

  // Two motions (the hull's slope comparisons), a combination of four (box sides: x + 0 against
  // y + 0), a product combination ((x - 0)(1 - 0) - (y - 0)(1 - 0), an orientation's shape).
  const MotionPolynomial one = MotionPolynomial::from({1.0});
  const MotionCombination sides{{&x, &zero}, {&y, &zero}};
  const ProductCombination product{{&x, &zero, &one, &zero}, {&y, &zero, &one, &zero}};
  const Scheduler::SignDecision pair_fp = classic.decide(x, y, t, 0.0, counters);
  const Scheduler::SignDecision sides_fp = classic.decide(sides, t, 0.0, counters);
  const Scheduler::SignDecision product_fp = classic.decide(product, t, 0.0, counters);
  EXPECT_EQ(pair_fp.sign, -1);
  EXPECT_EQ(sides_fp.sign, -1);
  EXPECT_EQ(product_fp.sign, -1);
  // [y - x > 0] rises in floating point from its root at t (not a failure): none.
  EXPECT_EQ(pair_fp.failure, kTimeInfinity);
  EXPECT_EQ(sides_fp.failure, kTimeInfinity);
  EXPECT_EQ(product_fp.failure, kTimeInfinity);
  EXPECT_EQ(careful.decide(x, y, t, 0.0, counters).sign, 1);
  EXPECT_EQ(careful.decide(sides, t, 0.0, counters).sign, 1);
  EXPECT_EQ(careful.decide(product, t, 0.0, counters).sign, 1);
  // COMPUTEMAX from the values: y wins in floating point, x exactly.
  EXPECT_FALSE(classic.compute_max(x, y, t, 0.0, counters).first_wins);
  EXPECT_TRUE(careful.compute_max(x, y, t, 0.0, counters).first_wins);
}

// The classic decision at a floating-point zero, and where the root finder disagrees with the
// value. x - y = t - 1 at t = 1 is 0 in floating point: its derivative decides (rising, +1), and
// the crossing at 1 is no failure of +1. f = a - b t at t = fl(a / b): its value there is
// 1.1e-16 > 0 in floating point, but the root finder puts f's fall at t itself; the decision
// follows the root finder (-1, which holds from t on in floating point), so that re-deciding at
// that event cannot meet it again.
TEST(SchedulerClassic, AFloatingPointZeroAndTheRootFindersSignChange) {
  Counters counters;
  const Scheduler classic(SchedulerKind::Classic, 1e-9);
  const MotionPolynomial rising = MotionPolynomial::from({-1.0, 1.0});
  const MotionPolynomial zero = MotionPolynomial::from({0.0});
  const Scheduler::SignDecision d = classic.decide(rising, zero, 1.0, 0.0, counters);
  EXPECT_EQ(d.sign, 1);
  EXPECT_EQ(d.failure, kTimeInfinity);
  const Scheduler::SignDecision e = classic.decide(zero, rising, 1.0, 0.0, counters);
  EXPECT_EQ(e.sign, -1);
  EXPECT_EQ(e.failure, kTimeInfinity);

  const double a = 0.92684740777084784, b = 1.6887426897944109;
  const Time t = a / b;
  const MotionPolynomial f = MotionPolynomial::from({a, -b});
  ASSERT_GT(f.evaluate(t), 0.0);
  ASSERT_EQ(classic_failure_time(zero, f, t), t);  // [0 < f] fails at t, in floating point
  const Scheduler::SignDecision g = classic.decide(f, zero, t, 0.0, counters);
  EXPECT_EQ(g.sign, -1);
  EXPECT_EQ(g.failure, kTimeInfinity);
}

// Two roots within rounding of t: f = (t - 1)^2 - 1e-40 at t = 1 is -1e-40 there, its roots
// 1 -+ 1e-20 both round to 1. The sign -1 fails at 1 in floating point, so the decision follows
// the root finder (+1), whose failure also rounds to 1: the first one strictly after 1 is taken
// (none), so re-deciding at 1 cannot meet an event at 1 again.
TEST(SchedulerClassic, TwoRootsAtNowDoNotRepeatTheEvent) {
  Counters counters;
  const Scheduler classic(SchedulerKind::Classic, 1e-9);
  const MotionPolynomial f = MotionPolynomial::from({-1e-40, 0.0, 1.0}, 1.0);
  const MotionPolynomial zero = MotionPolynomial::from({0.0}, 1.0);
  const Scheduler::SignDecision d = classic.decide(f, zero, 1.0, 0.0, counters);
  EXPECT_NE(d.sign, 0);
  EXPECT_GT(d.failure, 1.0);
}

/// A failure-time model that schedules every certificate half a time unit ahead.
Time half_ahead(void*, const Scheduler&, const MotionPolynomial&, const MotionPolynomial&,
                Time t_curr, Time, Counters&) {
  return t_curr + 0.5;
}

// With a failure-time model, the traditional classic still decides in floating point and takes
// the model's failure time.
TEST(SchedulerClassic, AFailureTimeModelKeepsFloatingPointDecisions) {
  const MotionPolynomial x = MotionPolynomial::from({test::kTieX[0], test::kTieX[1]});
  const MotionPolynomial y = MotionPolynomial::from({test::kTieY[0], test::kTieY[1]});
  const MotionPolynomial zero = MotionPolynomial::from({0.0});
  const MotionCombination sides{{&x, &zero}, {&y, &zero}};
  const Time t = test::kTieTime;
  Counters counters;
  Scheduler classic(SchedulerKind::Classic, 1e-9);
  classic.set_failure_time_model(&half_ahead, nullptr);
  const Scheduler::SignDecision pair = classic.decide(x, y, t, 0.0, counters);
  const Scheduler::SignDecision combination = classic.decide(sides, t, 0.0, counters);
  EXPECT_EQ(pair.sign, -1);
  EXPECT_EQ(pair.failure, t + 0.5);
  EXPECT_EQ(combination.sign, -1);
  EXPECT_EQ(combination.failure, t + 0.5);
}

}  // namespace
}  // namespace kinetic
