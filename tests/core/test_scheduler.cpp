// The robust scheduler's precision: the CROP grid it uses for a user precision eps.
#include <gtest/gtest.h>

#include <cmath>

#include "kinetic/core/crop.hpp"
#include "kinetic/core/scheduler.hpp"

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
  EXPECT_EQ(Scheduler::max_supported_time(1e-9), 0x1p50 * 0x1p-31);
  EXPECT_TRUE(Scheduler::precision_supported(1e-9, 0.0, 1000.0));
  EXPECT_FALSE(Scheduler::precision_supported(1e-9, 0.0, 1e9));
  EXPECT_FALSE(Scheduler::precision_supported(0.0, 0.0, 1.0));
  EXPECT_FALSE(Scheduler::precision_supported(-1.0, 0.0, 1.0));
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

}  // namespace
}  // namespace kinetic
