// motion_difference(): a - b as one polynomial, with an honest exactness flag, checked against an
// exact rational expansion (GMP).

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "kinetic/core/polynomial.hpp"
#include "support/exact_poly.hpp"

namespace kinetic {
namespace {

using test::exact::from_motion;
using test::exact::sub;

MotionPolynomial poly(std::initializer_list<double> c, double origin = 0.0) {
  return MotionPolynomial::from(std::vector<double>(c), origin);
}

TEST(MotionDifference, ExactWhenRepresentable) {
  // Same origin, coefficient differences exact (integers, Sterbenz).
  const auto a = poly({3.0, 0.75, -2.0}, 1.5);
  const auto b = poly({1.0, 0.5, -2.0}, 1.5);
  const MotionDifference d = motion_difference(a, b);
  EXPECT_TRUE(d.exact);
  EXPECT_EQ(from_motion(d.p), sub(from_motion(a), from_motion(b)));
  EXPECT_EQ(d.p.degree, 1);  // the t^2 terms cancel
  // A constant against a motion with another origin: the motion's origin is kept.
  const MotionDifference e = motion_difference(poly({4.0}), a);
  EXPECT_TRUE(e.exact);
  EXPECT_EQ(from_motion(e.p), sub(from_motion(poly({4.0})), from_motion(a)));
}

TEST(MotionDifference, FlagIsHonestOnRandomInputs) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  int exact = 0, inexact = 0;
  for (int k = 0; k < 2000; ++k) {
    const double oa = (rng() % 3 == 0) ? u(rng) : 0.0;
    const double ob = (rng() % 3 == 0) ? u(rng) : 0.0;
    const auto a = poly({u(rng), u(rng), (rng() % 2) ? u(rng) : 0.0}, oa);
    const auto b = (rng() % 4 == 0) ? poly({std::round(u(rng))}) : poly({u(rng), u(rng)}, ob);
    const MotionDifference d = motion_difference(a, b);
    const auto want = sub(from_motion(a), from_motion(b));
    if (d.exact) {
      ++exact;
      EXPECT_EQ(from_motion(d.p), want) << "k " << k;
    } else {
      ++inexact;
      // Rounded: the value at a few times is close to the exact difference.
      for (const double t : {-1.0, 0.0, 2.5}) {
        const double got = d.p.evaluate(t);
        const double ref = a.evaluate(t) - b.evaluate(t);
        EXPECT_NEAR(got, ref, 1e-9 * (1.0 + std::abs(ref))) << "k " << k;
      }
    }
  }
  EXPECT_GT(inexact, 0);
  EXPECT_GE(exact, 0);
}

}  // namespace
}  // namespace kinetic
