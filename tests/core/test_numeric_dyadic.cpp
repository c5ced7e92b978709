// Exact dyadic arithmetic (core/numeric/dyadic.hpp), both forms, checked against GMP rationals
// on random and extreme doubles (subnormals, DBL_MAX, zeros).

#include "core/numeric/dyadic.hpp"

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

using numeric::Dyadic;
using numeric_test::exact;
using numeric_test::exact_dyadic;
using numeric_test::hex;
using numeric_test::random_double;

mpq_class value(const Dyadic& d) { return exact_dyadic(d.m, d.e); }

const std::vector<double>& extremes() {
  static const std::vector<double> v = {0.0,
                                        -0.0,
                                        1.0,
                                        -3.0,
                                        0.1,
                                        DBL_MAX,
                                        -DBL_MAX,
                                        DBL_MIN,
                                        std::numeric_limits<double>::denorm_min(),
                                        -std::numeric_limits<double>::denorm_min(),
                                        std::nextafter(DBL_MIN, 0.0),
                                        std::ldexp(1.0, 1023),
                                        std::ldexp(1.0, -1074)};
  return v;
}

TEST(NumericDyadic, PartsAreExactAndOdd) {
  const std::uint64_t seed = 0xd1ad0001;
  std::mt19937_64 rng(seed);
  std::vector<double> xs = extremes();
  for (int it = 0; it < 20000; ++it) xs.push_back(random_double(rng, -1080, 1023));
  for (const double x : xs) {
    std::int64_t m = 0;
    long e = 0;
    numeric::dyadic_parts(x, m, e);
    EXPECT_EQ(exact_dyadic(mpz_class(static_cast<long>(m)), e), exact(x))
        << "seed=" << seed << " x=" << hex(x);
    if (x == 0.0) {
      EXPECT_EQ(m, 0);
      EXPECT_EQ(e, 0);
    } else {
      EXPECT_EQ(m % 2 != 0, true) << hex(x);
      EXPECT_LT(m < 0 ? -m : m, std::int64_t{1} << 53) << hex(x);
      EXPECT_GE(e, -1074) << hex(x);
      EXPECT_LE(e, 1023) << hex(x);
    }
    EXPECT_EQ(value(numeric::dyadic(x)), exact(x)) << hex(x);
    if (HasFailure()) return;
  }
}

TEST(NumericDyadic, ValueArithmeticIsExact) {
  const std::uint64_t seed = 0xd1ad0002;
  std::mt19937_64 rng(seed);
  const std::vector<double>& ext = extremes();
  for (int it = 0; it < 3000; ++it) {
    std::array<double, 4> x{};
    for (double& v : x) {
      v = rng() % 8 == 0 ? ext[rng() % ext.size()] : random_double(rng, -1080, 1023);
    }
    const std::array<Dyadic, 4> d{numeric::dyadic(x[0]), numeric::dyadic(x[1]),
                                  numeric::dyadic(x[2]), numeric::dyadic(x[3])};
    const std::array<mpq_class, 4> q{exact(x[0]), exact(x[1]), exact(x[2]), exact(x[3])};
    const std::string where = "seed=" + std::to_string(seed) + " it=" + std::to_string(it) +
                              " x={" + hex(x[0]) + ", " + hex(x[1]) + ", " + hex(x[2]) + ", " +
                              hex(x[3]) + "}";
    EXPECT_EQ(value(d[0] + d[1]), q[0] + q[1]) << where;
    EXPECT_EQ(value(d[0] + (-d[0])), 0) << where;
    EXPECT_EQ(value(d[0] * d[1] + (-(d[2] * d[3]))), q[0] * q[1] - q[2] * q[3]) << where;
    // A Taylor-shift step and a Horner step, as CROP's exact fallbacks take them.
    EXPECT_EQ(value((d[0] + d[1] * d[2]) * d[3] + d[1]), (q[0] + q[1] * q[2]) * q[3] + q[1])
        << where;
    if (HasFailure()) return;
  }
}

/// Raw-form accumulation of doubles, as the predicates' exact stage does.
struct Raw {
  mpz_t z, tmp;
  long ez = 0;
  Raw() {
    mpz_init(z);
    mpz_init(tmp);
  }
  ~Raw() {
    mpz_clear(z);
    mpz_clear(tmp);
  }
  Raw(const Raw&) = delete;
  Raw& operator=(const Raw&) = delete;
  void add(double x) {
    std::int64_t m = 0;
    long e = 0;
    numeric::dyadic_parts(x, m, e);
    numeric::dyadic_add_small(z, ez, m, e, tmp);
  }
  [[nodiscard]] mpq_class value() const { return exact_dyadic(mpz_class(z), ez); }
};

TEST(NumericDyadic, RawAccumulationAndComparisonAreExact) {
  const std::uint64_t seed = 0xd1ad0003;
  std::mt19937_64 rng(seed);
  const std::vector<double>& ext = extremes();
  int equal = 0;
  for (int it = 0; it < 3000; ++it) {
    Raw a, b;
    mpq_class qa = 0, qb = 0;
    const int n = static_cast<int>(rng() % 6);
    for (int i = 0; i < n; ++i) {
      const double x = rng() % 8 == 0 ? ext[rng() % ext.size()] : random_double(rng, -1080, 1023);
      a.add(x);
      qa += exact(x);
      // b: the same value half of the time, so that the two sums are often exactly equal.
      const double y = rng() % 2 == 0 ? x : random_double(rng, -1080, 1023);
      b.add(y);
      qb += exact(y);
    }
    const std::string where = "seed=" + std::to_string(seed) + " it=" + std::to_string(it);
    EXPECT_EQ(a.value(), qa) << where;
    EXPECT_EQ(b.value(), qb) << where;
    const int expected = sgn(qa - qb);
    equal += expected == 0;
    EXPECT_EQ(numeric::dyadic_difference_sign(a.z, a.ez, b.z, b.ez), expected) << where;
    if (HasFailure()) return;
  }
  EXPECT_GT(equal, 100) << "seed=" << seed;
  // Equal values with different exponents compare equal.
  Raw x, y;
  x.add(3.0);
  y.add(1.0);
  y.add(2.0);
  y.add(0.25);
  y.add(-0.25);
  EXPECT_EQ(numeric::dyadic_difference_sign(x.z, x.ez, y.z, y.ez), 0);
}

}  // namespace
}  // namespace kinetic
