// Interval arithmetic with outward rounding (core/numeric/interval.hpp), checked against exact
// rational arithmetic (GMP): down()/up() bracket every rounded result, each operation encloses
// the exact operation on members of its operands, and sign() is never wrong, also when ends
// overflow.

#include "core/numeric/interval.hpp"

#include <gmpxx.h>
#include <gtest/gtest.h>

#include <array>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/numeric_test_util.hpp"

namespace kinetic {
namespace {

using numeric::Interval;
using numeric_test::exact;
using numeric_test::hex;
using numeric_test::random_double;

/// lo <= r <= hi for the ends that are not NaN (an infinite end bounds its side).
bool encloses(const Interval& iv, const mpq_class& r) {
  const bool lo_ok = std::isnan(iv.lo) || iv.lo == -std::numeric_limits<double>::infinity() ||
                     (iv.lo != std::numeric_limits<double>::infinity() && exact(iv.lo) <= r);
  const bool hi_ok = std::isnan(iv.hi) || iv.hi == std::numeric_limits<double>::infinity() ||
                     (iv.hi != -std::numeric_limits<double>::infinity() && exact(iv.hi) >= r);
  return lo_ok && hi_ok;
}

/// sign() is 0 or the sign of r.
bool sign_ok(const Interval& iv, const mpq_class& r) {
  return iv.sign() == 0 || iv.sign() == sgn(r);
}

TEST(NumericInterval, DownAndUpBracketEveryRoundedResult) {
  const std::uint64_t seed = 0x1a7e0001;
  std::mt19937_64 rng(seed);
  for (int it = 0; it < 20000; ++it) {
    // Operands from the subnormal range to near overflow: results normal, subnormal or zero.
    const int ea = std::uniform_int_distribution<int>(-1075, 1023)(rng);
    const double a = random_double(rng, ea, ea);
    const double b = random_double(rng, std::max(-1075, ea - 60), std::min(1023, ea + 60));
    const double c = random_double(rng, -1075, 1023);
    const std::array<std::pair<double, mpq_class>, 3> results = {
        std::pair{a + b, exact(a) + exact(b)}, std::pair{a - b, exact(a) - exact(b)},
        std::pair{a * c, exact(a) * exact(c)}};
    for (const auto& [x, r] : results) {
      if (!std::isfinite(x)) continue;  // an overflow: not a rounded result of r
      EXPECT_LE(exact(numeric::down(x)), r) << "seed=" << seed << " it=" << it << " x=" << hex(x);
      EXPECT_GE(exact(numeric::up(x)), r) << "seed=" << seed << " it=" << it << " x=" << hex(x);
    }
    if (HasFailure()) return;
  }
}

TEST(NumericInterval, DownAndUpAtTheEdges) {
  const double tiny = std::numeric_limits<double>::denorm_min();
  for (const double x : {0.0, -0.0, tiny, -tiny, DBL_MIN, -DBL_MIN, 1.0, -1.0, DBL_MAX, -DBL_MAX}) {
    EXPECT_LT(numeric::down(x), x) << hex(x);
    EXPECT_GT(numeric::up(x), x) << hex(x);
  }
  // 1 + 2^-53 rounds to 1 (a tie, to even), 1 - 2^-54 too.
  EXPECT_GE(exact(numeric::up(1.0)), exact(1.0) + exact(0x1p-53));
  EXPECT_LE(exact(numeric::down(1.0)), exact(1.0) - exact(0x1p-54));
  // An overflowed end: down(+inf) is NaN (undecided), up(+inf) stays +inf.
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(std::isnan(numeric::down(inf)));
  EXPECT_EQ(numeric::up(inf), inf);
  EXPECT_EQ(numeric::down(-inf), -inf);
  EXPECT_TRUE(std::isnan(numeric::up(-inf)));
}

/// A random interval and exact members of it: its ends and an interior point.
struct Sampled {
  Interval iv;
  std::array<mpq_class, 3> members;
};

Sampled random_interval(std::mt19937_64& rng, int emin, int emax) {
  double a = random_double(rng, emin, emax);
  double b = rng() % 4 == 0 ? a : random_double(rng, emin, emax);
  if (b < a) std::swap(a, b);
  Sampled s{Interval{a, b}, {exact(a), exact(b), exact(a)}};
  mpq_class t(static_cast<long>(rng() % 1000), 1000);
  s.members[2] = exact(a) + t * (exact(b) - exact(a));
  return s;
}

TEST(NumericInterval, OperationsEncloseTheExactOperation) {
  const std::uint64_t seed = 0x1a7e0002;
  std::mt19937_64 rng(seed);
  for (int it = 0; it < 5000; ++it) {
    const int e = std::uniform_int_distribution<int>(-1070, 1000)(rng);
    const Sampled x = random_interval(rng, e - 20, std::min(1020, e + 20));
    const Sampled y = random_interval(rng, e - 20, std::min(1020, e + 20));
    const double k = static_cast<double>(rng() % 21);
    const Interval sum = x.iv + y.iv, difference = x.iv - y.iv, product = x.iv * y.iv;
    const Interval scaled = numeric::scale(x.iv, k);
    const std::string where = "seed=" + std::to_string(seed) + " it=" + std::to_string(it) +
                              " x=[" + hex(x.iv.lo) + ", " + hex(x.iv.hi) + "] y=[" + hex(y.iv.lo) +
                              ", " + hex(y.iv.hi) + "]";
    for (const mpq_class& alpha : x.members) {
      EXPECT_TRUE(encloses(scaled, alpha * static_cast<long>(k))) << where << " k=" << k;
      EXPECT_TRUE(sign_ok(scaled, alpha * static_cast<long>(k))) << where << " k=" << k;
      for (const mpq_class& beta : y.members) {
        EXPECT_TRUE(encloses(sum, alpha + beta)) << where;
        EXPECT_TRUE(encloses(difference, alpha - beta)) << where;
        EXPECT_TRUE(encloses(product, alpha * beta)) << where;
        EXPECT_TRUE(sign_ok(sum, alpha + beta)) << where;
        EXPECT_TRUE(sign_ok(difference, alpha - beta)) << where;
        EXPECT_TRUE(sign_ok(product, alpha * beta)) << where;
      }
    }
    if (HasFailure()) return;
  }
}

/// Exact members of an interval: its ends and their midpoint; a member far beyond DBL_MAX
/// stands for the reals an infinite end admits.
std::vector<mpq_class> members(const Interval& iv) {
  const double inf = std::numeric_limits<double>::infinity();
  mpq_class huge(1);
  mpq_mul_2exp(huge.get_mpq_t(), huge.get_mpq_t(), 1100);
  const mpq_class lo = iv.lo == -inf ? mpq_class(-huge) : exact(iv.lo);
  const mpq_class hi = iv.hi == inf ? huge : exact(iv.hi);
  return {lo, hi, (lo + hi) / 2};
}

std::string describe(const Interval& a, const Interval& b) {
  return "a=[" + hex(a.lo) + ", " + hex(a.hi) + "] b=[" + hex(b.lo) + ", " + hex(b.hi) + "]";
}

/// An enclosure of r whose sign() is right.
bool rigorous(const Interval& iv, const mpq_class& r) { return encloses(iv, r) && sign_ok(iv, r); }

TEST(NumericInterval, SignIsNeverWrongWhenResultsOverflow) {
  // Operands with finite ends whose results overflow (every operation), and operands with
  // infinite ends (sums and differences only: the domain of the product excludes them).
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<Interval> ivs = {{DBL_MAX / 2, DBL_MAX},
                                     {-DBL_MAX, -DBL_MAX / 2},
                                     {0.0, 0.0},
                                     {0.0, 2.0},
                                     {-2.0, 0.0},
                                     {-3.0, 5.0},
                                     {1e300, 1e308},
                                     {-1e308, 4.0},
                                     {1.0, inf},
                                     {-inf, -1.0},
                                     {-inf, inf},
                                     {0.0, inf},
                                     {-inf, 0.0},
                                     {DBL_MAX, inf}};
  auto finite = [](const Interval& iv) { return std::isfinite(iv.lo) && std::isfinite(iv.hi); };
  for (const Interval& a : ivs) {
    for (const Interval& b : ivs) {
      const Interval sum = a + b, difference = a - b, twice = (a + b) - (b - a);
      const bool product_domain = finite(a) && finite(b);
      const Interval product = a * b, scaled = numeric::scale(a, 16.0);
      for (const mpq_class& alpha : members(a)) {
        for (const mpq_class& beta : members(b)) {
          const std::string where = describe(a, b);
          EXPECT_TRUE(rigorous(sum, alpha + beta)) << where;
          EXPECT_TRUE(rigorous(difference, alpha - beta)) << where;
          EXPECT_TRUE(rigorous(twice, 2 * alpha)) << where;
          if (product_domain) {
            EXPECT_TRUE(rigorous(product, alpha * beta)) << where;
            EXPECT_TRUE(rigorous(scaled, alpha * 16)) << where;
          }
        }
      }
    }
  }
}

TEST(NumericInterval, ProductWithAZeroEndAndAnInfiniteEndIsOutsideTheDomain) {
  // Why the header excludes it: 0 * infinity is NaN, std::min skips it, and the corner holding
  // 0 is lost. CROP never forms this product.
  const double inf = std::numeric_limits<double>::infinity();
  const Interval p = Interval{-2.0, 0.0} * Interval{-inf, -1.0};
  EXPECT_GT(p.lo, 0.0);  // although 0 * (-1) == 0 is a product of members
}

TEST(NumericInterval, ExactDifferenceIsAPointExactlyWhenTheSubtractionIs) {
  const std::uint64_t seed = 0x1a7e0003;
  std::mt19937_64 rng(seed);
  int points = 0;
  for (int it = 0; it < 20000; ++it) {
    const int e = std::uniform_int_distribution<int>(-1075, 1022)(rng);
    const double x = random_double(rng, e, e);
    const double y = random_double(rng, std::max(-1075, e - 60), std::min(1022, e + 60));
    const Interval d = numeric::exact_difference(x, y);
    const mpq_class r = exact(x) - exact(y);
    const std::string where = "seed=" + std::to_string(seed) + " it=" + std::to_string(it) +
                              " x=" + hex(x) + " y=" + hex(y);
    if (d.lo == d.hi) {
      ++points;
      EXPECT_EQ(exact(d.lo), r) << where;
    } else {
      EXPECT_NE(exact(x - y), r) << where;
      EXPECT_TRUE(encloses(d, r)) << where;
    }
    EXPECT_TRUE(sign_ok(d, r)) << where;
    if (HasFailure()) return;
  }
  EXPECT_GT(points, 1000) << "seed=" << seed;
}

}  // namespace
}  // namespace kinetic
