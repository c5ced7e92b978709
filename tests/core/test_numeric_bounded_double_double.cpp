// Bounded double-doubles (core/numeric/bounded_double_double.hpp) against exact rational
// arithmetic (GMP): random expression trees of sums, differences and products over inputs of
// wide and cancelling magnitudes, every result within its bound of the exact value, normalised
// (hi = fl(hi + lo)); tiny inputs whose products underflow still bounded; overflow reported as
// not finite(), never a wrong bound. Fixed seeds, printed on failure.

#include "core/numeric/bounded_double_double.hpp"

#include <gmpxx.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "core/numeric_test_util.hpp"

namespace kinetic {
namespace {

using numeric::BoundedDoubleDouble;
using numeric_test::exact;
using numeric_test::random_double;

struct Node {
  BoundedDoubleDouble value;
  mpq_class exact;
};

/// |exact - (hi + lo)| <= err, exactly; the enclosure holds the exact value; hi = fl(hi + lo).
void expect_bounded(const Node& n, const std::string& where) {
  ASSERT_TRUE(n.value.finite()) << where;
  const mpq_class approx = exact(n.value.hi) + exact(n.value.lo);
  mpq_class gap = n.exact - approx;
  if (gap < 0) gap = -gap;
  ASSERT_LE(gap, exact(n.value.err)) << where << ": hi " << n.value.hi << " lo " << n.value.lo
                                     << " err " << n.value.err;
  const numeric::Interval e = n.value.enclosure();
  ASSERT_TRUE(exact(e.lo) <= n.exact && n.exact <= exact(e.hi)) << where;
  ASSERT_EQ(n.value.hi + n.value.lo, n.value.hi) << where;
}

/// Random trees over a pool: leaves are doubles (exponents in [emin, emax], some cancelling
/// pairs), inner nodes a + b, a - b or a b of two earlier nodes; every node checked.
void run_trees(std::uint64_t seed, int emin, int emax, int rounds, int* bounded_nonzero) {
  std::mt19937_64 rng(seed);
  for (int round = 0; round < rounds; ++round) {
    const std::string where = "seed " + std::to_string(seed) + ", round " + std::to_string(round);
    std::vector<Node> pool;
    for (int i = 0; i < 6; ++i) {
      const double x = random_double(rng, emin, emax);
      pool.push_back({BoundedDoubleDouble::exact(x), exact(x)});
      // A near twin: x (1 + 2^-k), so that differences cancel.
      const double twin = x * (1.0 + std::ldexp(1.0, -static_cast<int>(rng() % 50) - 1));
      pool.push_back({BoundedDoubleDouble::exact(twin), exact(twin)});
    }
    for (int step = 0; step < 24; ++step) {
      const Node& a = pool[rng() % pool.size()];
      const Node& b = pool[rng() % pool.size()];
      Node r;
      switch (rng() % 3) {
        case 0:
          r = {a.value + b.value, a.exact + b.exact};
          break;
        case 1:
          r = {a.value - b.value, a.exact - b.exact};
          break;
        default:
          r = {a.value * b.value, a.exact * b.exact};
          break;
      }
      if (!r.value.finite()) continue;  // overflow: reported, no bound claimed
      expect_bounded(r, where + ", step " + std::to_string(step));
      if (::testing::Test::HasFatalFailure()) return;
      if (r.value.err > 0.0 && r.exact != exact(r.value.hi) + exact(r.value.lo))
        ++*bounded_nonzero;
      pool.push_back(r);
    }
  }
}

TEST(NumericBoundedDoubleDouble, ExpressionTreesStayWithinTheirBounds) {
  int inexact = 0;
  run_trees(20261128, -30, 30, 3000, &inexact);
  if (::testing::Test::HasFatalFailure()) return;
  // The bounds are exercised: many results are not exactly hi + lo (a test of exact results
  // could not tell a missing error term).
  std::printf("[ bdd ] moderate inputs: %d inexact results within their bounds\n", inexact);
  EXPECT_GT(inexact, 10000);
}

TEST(NumericBoundedDoubleDouble, TinyInputsAreBoundedThroughUnderflow) {
  int inexact = 0;
  run_trees(20261129, -560, -250, 2000, &inexact);  // products reach and pass 2^-1074
  if (::testing::Test::HasFatalFailure()) return;
  std::printf("[ bdd ] tiny inputs: %d inexact results within their bounds\n", inexact);
  EXPECT_GT(inexact, 100);
}

/// Magnitude-bounded double-doubles: random trees with each value's depth tracked, every result
/// within ((1 + 2^-100)^d - 1) M (bounded(d, 0)) of the GMP value; inputs up to 2^60 in
/// magnitude, values whose magnitude falls below 2^-800 left out (the underflow regime, where the
/// caller adds its allowance).
TEST(NumericBoundedDoubleDouble, MagnitudeBoundsHoldAtTheirDepth) {
  using numeric::MagnitudeDoubleDouble;
  struct Value {
    MagnitudeDoubleDouble value;
    int depth = 0;
    mpq_class exact;
  };
  constexpr std::uint64_t kSeed = 20261130;
  std::mt19937_64 rng(kSeed);
  int inexact = 0, checked = 0;
  for (int round = 0; round < 3000; ++round) {
    const std::string where = "seed " + std::to_string(kSeed) + ", round " + std::to_string(round);
    std::vector<Value> pool;
    for (int i = 0; i < 6; ++i) {
      const double x = random_double(rng, -60, 59);
      const double twin = x * (1.0 + std::ldexp(1.0, -static_cast<int>(rng() % 50) - 1));
      pool.push_back({MagnitudeDoubleDouble::exact(x), 0, exact(x)});
      pool.push_back({MagnitudeDoubleDouble::exact(twin), 0, exact(twin)});
    }
    for (int step = 0; step < 24; ++step) {
      const Value& a = pool[rng() % pool.size()];
      const Value& b = pool[rng() % pool.size()];
      Value r;
      switch (rng() % 4) {
        case 0:
          r = {a.value + b.value, std::max(a.depth, b.depth) + 1, a.exact + b.exact};
          break;
        case 1:
          r = {a.value - b.value, std::max(a.depth, b.depth) + 1, a.exact - b.exact};
          break;
        case 2:
          r = {a.value.twice(), a.depth, 2 * a.exact};
          break;
        default:
          r = {a.value * b.value, a.depth + b.depth + 1, a.exact * b.exact};
          break;
      }
      if (!(r.value.m >= 0x1p-800 && r.value.m <= 0x1p800)) continue;
      const numeric::BoundedDoubleDouble bound = r.value.bounded(r.depth, 0.0);
      mpq_class gap = r.exact - (exact(bound.hi) + exact(bound.lo));
      if (gap < 0) gap = -gap;
      ASSERT_LE(gap, exact(bound.err)) << where << ", step " << step << ", depth " << r.depth;
      ASSERT_EQ(bound.hi + bound.lo, bound.hi) << where;
      ++checked;
      if (gap > 0) ++inexact;
      pool.push_back(r);
    }
  }
  std::printf("[ bdd ] magnitude bounds: %d results checked, %d inexact\n", checked, inexact);
  EXPECT_GT(inexact, 10000);
}

TEST(NumericBoundedDoubleDouble, OverflowIsNotFinite) {
  const BoundedDoubleDouble big = BoundedDoubleDouble::exact(0x1p600);
  EXPECT_FALSE((big * big).finite());
  EXPECT_TRUE(((big * BoundedDoubleDouble::exact(0x1p400)) + big).finite());  // 2^1000 + 2^600
  EXPECT_FALSE(((big * BoundedDoubleDouble::exact(0x1p424)) + big).finite());
  // A factor beyond Veltkamp's split (2^995) with a small product: the split overflows.
  const BoundedDoubleDouble huge = BoundedDoubleDouble::exact(0x1.8p1000);
  EXPECT_FALSE((huge * BoundedDoubleDouble::exact(0x1.3p-20)).finite());
  // Carried by every later operation.
  const BoundedDoubleDouble bad = big * big;
  EXPECT_FALSE((bad - bad).finite());
  EXPECT_FALSE((bad * BoundedDoubleDouble::exact(0.0)).finite());
  EXPECT_FALSE((BoundedDoubleDouble::exact(1.0) + bad * BoundedDoubleDouble::exact(0.0)).finite());
}

TEST(NumericBoundedDoubleDouble, ExactInputsStayExact) {
  const BoundedDoubleDouble x = BoundedDoubleDouble::exact(3.0);
  EXPECT_TRUE(x.is_zero() == false);
  EXPECT_TRUE(BoundedDoubleDouble{}.is_zero());
  const BoundedDoubleDouble y = x * x - BoundedDoubleDouble::exact(9.0);
  EXPECT_EQ(y.hi + y.lo, 0.0);
  EXPECT_LE(y.err, 0x1p-1000);  // only the underflow allowance
}

}  // namespace
}  // namespace kinetic
