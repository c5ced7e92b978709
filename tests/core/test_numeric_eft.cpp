// The error-free transformations of core/numeric/eft.hpp (TwoSum, TwoProduct, the sign of an
// expansion sum), checked against exact rational arithmetic (GMP) on random and adversarial
// inputs, inside the domains their header states.

#include "core/numeric/eft.hpp"

#include <gmpxx.h>
#include <gtest/gtest.h>

#include <algorithm>
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

using numeric_test::exact;
using numeric_test::hex;
using numeric_test::random_double;

/// Checks hi + lo == r exactly and |lo| <= 2^-53 |hi|, both finite.
void expect_error_free(double hi, double lo, const mpq_class& r, const std::string& args) {
  ASSERT_TRUE(std::isfinite(hi) && std::isfinite(lo)) << args;
  EXPECT_EQ(exact(hi) + exact(lo), r) << args;
  mpq_class bound = abs(exact(hi));
  mpq_div_2exp(bound.get_mpq_t(), bound.get_mpq_t(), 53);
  EXPECT_LE(abs(exact(lo)), bound) << args;
}

/// Checks s == fl(a + b), s + e == a + b and |e| <= 2^-53 |s|.
void check_two_sum(double a, double b, const std::string& where) {
  double s = 0.0, e = 0.0;
  numeric::two_sum(a, b, s, e);
  const std::string args = where + " a=" + hex(a) + " b=" + hex(b);
  EXPECT_EQ(s, a + b) << args;
  expect_error_free(s, e, exact(a) + exact(b), args);
}

TEST(NumericEft, TwoSumIsExactOnRandomInputs) {
  const std::uint64_t seed = 0x2a5e0001;
  std::mt19937_64 rng(seed);
  for (int it = 0; it < 20000; ++it) {
    // Exponent ranges from subnormal to near overflow, close or far apart.
    const int ea = std::uniform_int_distribution<int>(-1080, 1023)(rng);
    const int spread = std::uniform_int_distribution<int>(0, 3)(rng) == 0 ? 200 : 60;
    const double a = random_double(rng, ea, ea);
    const double b = random_double(rng, std::max(-1080, ea - spread), std::min(1023, ea + spread));
    if (!std::isfinite(a + b)) continue;  // outside the domain: the sum overflows
    check_two_sum(a, b, "seed=" + std::to_string(seed) + " it=" + std::to_string(it));
    if (HasFailure()) return;
  }
}

TEST(NumericEft, TwoSumIsExactOnAdversarialInputs) {
  const double max = DBL_MAX, tiny = std::numeric_limits<double>::denorm_min();
  const std::vector<std::pair<double, double>> cases = {
      {max, -max},
      {max, -tiny},
      {max, std::ldexp(1.0, 969)},  // a quarter of max's ulp: rounds back to max
      {-max, -std::ldexp(1.0, 969)},
      {max, -std::ldexp(1.0, 1023)},
      {std::ldexp(1.0, 1023), std::ldexp(1.0, 1022)},
      {1.0, std::ldexp(1.0, -53)},  // ties to even
      {1.0, std::ldexp(3.0, -54)},
      {1.0 + std::ldexp(1.0, -52), std::ldexp(1.0, -53)},
      {DBL_MIN, -tiny},
      {tiny, tiny},
      {-tiny, 3.0 * tiny},
      {0.0, -0.0},
      {-0.0, -0.0},
      {1e308, -1e-308},
      {std::nextafter(1.0, 0.0), std::ldexp(1.0, -106)},
  };
  for (const auto& [a, b] : cases) {
    check_two_sum(a, b, "adversarial");
    check_two_sum(b, a, "adversarial, swapped");
  }
}

/// Case (i) of two_product()'s domain.
bool in_product_domain(double a, double b, double p) {
  const double aa = std::fabs(a), ab = std::fabs(b), ap = std::fabs(p);
  return aa >= DBL_MIN && ab >= DBL_MIN && aa <= 0x1p995 && ab <= 0x1p995 && ap >= 0x1p-960 &&
         ap <= 0x1p1021;
}

/// Checks p == fl(a b), p + e == a b and |e| <= 2^-53 |p|.
void check_two_product(double a, double b, const std::string& where) {
  double p = 0.0, e = 0.0;
  numeric::two_product(a, b, p, e);
  const std::string args = where + " a=" + hex(a) + " b=" + hex(b);
  EXPECT_EQ(p, a * b) << args;
  expect_error_free(p, e, exact(a) * exact(b), args);
}

TEST(NumericEft, TwoProductIsExactInItsDomain) {
  const std::uint64_t seed = 0x2a5e0002;
  std::mt19937_64 rng(seed);
  int checked = 0, safe = 0;
  for (int it = 0; it < 20000; ++it) {
    const double a = random_double(rng, -1022, 995);
    const double b = random_double(rng, -1022, 995);
    const double p = a * b;
    if (!in_product_domain(a, b, p)) continue;
    ++checked;
    // two_product_safe() checks a and p; b is normal and <= 2^995 here.
    if (numeric::two_product_safe(a, p)) ++safe;
    check_two_product(a, b, "seed=" + std::to_string(seed) + " it=" + std::to_string(it));
    if (HasFailure()) return;
  }
  EXPECT_GT(checked, 5000) << "seed=" << seed;
  EXPECT_EQ(safe, checked) << "seed=" << seed;
}

TEST(NumericEft, TwoProductIsExactAtTheEdgesOfItsDomain) {
  const double ones = std::nextafter(2.0, 0.0);  // 53 one bits
  const std::vector<std::pair<double, double>> cases = {
      {0x1p995, 0x1p26},
      {std::ldexp(ones, 994), std::ldexp(ones, 25)},  // p just below 2^1021
      {-std::ldexp(ones, 994), std::ldexp(ones, 25)},
      {std::ldexp(1.0, -480), std::ldexp(1.0, -480)},  // p == 2^-960
      {std::ldexp(ones, -481), std::ldexp(ones, -480)},
      {DBL_MIN, 0x1p62},
      {-DBL_MIN, 0x1p995},
      {ones, ones},
      {1.0 + 0x1p-52, 1.0 - 0x1p-53},
      {3.0, 1.0 / 3.0},
      {0.1, 0.1},
  };
  for (const auto& [a, b] : cases) {
    ASSERT_TRUE(in_product_domain(a, b, a * b)) << hex(a) << " " << hex(b);
    check_two_product(a, b, "edge");
    check_two_product(b, a, "edge, swapped");
  }
  // Case (ii): a zero factor and any finite other of magnitude <= 2^995.
  for (const double other : {0x1p995, -1.5, DBL_MIN, std::numeric_limits<double>::denorm_min()}) {
    for (const double zero : {0.0, -0.0}) {
      double p = 1.0, e = 1.0;
      numeric::two_product(zero, other, p, e);
      EXPECT_EQ(p, 0.0) << hex(other);
      EXPECT_EQ(e, 0.0) << hex(other);
      numeric::two_product(other, zero, p, e);
      EXPECT_EQ(p, 0.0) << hex(other);
      EXPECT_EQ(e, 0.0) << hex(other);
    }
  }
}

TEST(NumericEft, TwoProductOutsideItsDomainIsNotExact) {
  // The stated conditions are needed: an underflowing product's error is below the subnormal
  // range (no double holds it), and a factor above 2^995 overflows the splitting.
  const double a = std::ldexp(1.0 + 0x1p-52, -520);
  double p = 0.0, e = 0.0;
  numeric::two_product(a, a, p, e);
  EXPECT_FALSE(numeric::two_product_safe(a, p));
  EXPECT_NE(exact(p) + exact(e), exact(a) * exact(a));
  numeric::two_product(DBL_MAX, 0.5, p, e);
  EXPECT_FALSE(numeric::two_product_safe(DBL_MAX, p));
  EXPECT_FALSE(std::isfinite(e));
}

TEST(NumericEft, TwoProductOnCropsDiscriminantFactors) {
  // CROP's discriminant: every factor 0 or of magnitude in (2^-300, 2^302).
  const std::uint64_t seed = 0x2a5e0003;
  std::mt19937_64 rng(seed);
  for (int it = 0; it < 20000; ++it) {
    const double a = random_double(rng, -299, 301);
    const double b = random_double(rng, -299, 301);
    ASSERT_TRUE(in_product_domain(a, b, a * b)) << "seed=" << seed << " it=" << it;
    check_two_product(a, b, "seed=" + std::to_string(seed) + " it=" + std::to_string(it));
    if (HasFailure()) return;
  }
}

int exact_sign(const mpq_class& v) { return sgn(v); }

/// sign(d1^2 - 4 d0 d2) as CROP's quadratic path computes it, against GMP.
void check_discriminant(double d0, double d1, double d2, const std::string& where) {
  double p1 = 0.0, e1 = 0.0, p2 = 0.0, e2 = 0.0;
  numeric::two_product(d1, d1, p1, e1);
  numeric::two_product(4.0 * d0, d2, p2, e2);
  const int s = numeric::expansion_sum_sign(e1, p1, -e2, -p2);
  const mpq_class disc = exact(d1) * exact(d1) - 4 * exact(d0) * exact(d2);
  EXPECT_EQ(s, exact_sign(disc)) << where << " d0=" << hex(d0) << " d1=" << hex(d1)
                                 << " d2=" << hex(d2);
}

TEST(NumericEft, ExpansionSumSignIsExact) {
  const std::uint64_t seed = 0x2a5e0004;
  std::mt19937_64 rng(seed);
  for (int it = 0; it < 20000; ++it) {
    const std::string where = "seed=" + std::to_string(seed) + " it=" + std::to_string(it);
    const double d1 = random_double(rng, -140, 140);
    const double d2 = random_double(rng, -140, 140);
    // d0 close to d1^2 / (4 d2): the discriminant cancels to a few units, or to 0.
    double d0 = d1 * d1 / (4.0 * d2);
    const int steps = std::uniform_int_distribution<int>(-3, 3)(rng);
    for (int i = 0; i < std::abs(steps); ++i) d0 = std::nextafter(d0, steps > 0 ? 1e300 : -1e300);
    check_discriminant(d0, d1, d2, where);
    // An exact zero: d1 = 2 x, d0 = x y, d2 = x / y with every step exact.
    const double x = random_double(rng, -100, 100);
    const double y = std::ldexp(1.0, std::uniform_int_distribution<int>(-40, 40)(rng));
    check_discriminant(x * y, 2.0 * x, x / y, where + " (zero)");
    // Independent expansions: the sign of a b + c d.
    const double a = random_double(rng, -200, 200), b = random_double(rng, -200, 200);
    const double c = rng() % 2 == 0 ? -a : random_double(rng, -200, 200);
    const double d = rng() % 2 == 0 ? b : random_double(rng, -200, 200);
    double p = 0.0, e = 0.0, q = 0.0, f = 0.0;
    numeric::two_product(a, b, p, e);
    numeric::two_product(c, d, q, f);
    EXPECT_EQ(numeric::expansion_sum_sign(e, p, f, q),
              exact_sign(exact(a) * exact(b) + exact(c) * exact(d)))
        << where << " a=" << hex(a) << " b=" << hex(b) << " c=" << hex(c) << " d=" << hex(d);
    if (HasFailure()) return;
  }
}

}  // namespace
}  // namespace kinetic
