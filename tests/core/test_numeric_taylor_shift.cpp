// The Taylor shift (core/numeric/taylor_shift.hpp) in the four arithmetics CROP and the
// predicates use it in: exact in rationals and dyadics (checked against p(s + u) expanded by the
// binomial theorem), an enclosure in intervals, and in doubles a value inside that enclosure.

#include "core/numeric/taylor_shift.hpp"

#include <gmpxx.h>
#include <gtest/gtest.h>

#include <array>
#include <random>

#include "core/numeric/dyadic.hpp"
#include "core/numeric/interval.hpp"
#include "core/numeric_test_util.hpp"

namespace kinetic {
namespace {

constexpr int kMax = 6;
using numeric_test::exact;
using numeric_test::exact_dyadic;
using numeric_test::hex;
using numeric_test::random_double;

/// The coefficients of p(s + u) by the binomial theorem, exactly.
std::array<mpq_class, kMax + 1> expanded(const std::array<double, kMax + 1>& c, int degree,
                                         const mpq_class& s) {
  std::array<mpq_class, kMax + 1> out;
  for (auto& v : out) v = 0;
  for (int i = 0; i <= degree; ++i) {
    mpq_class power = 1;  // s^(i - k), k from i down to 0
    mpz_class binom = 1;  // C(i, k)
    for (int k = i; k >= 0; --k) {
      out[k] += exact(c[i]) * binom * power;
      power *= s;
      if (k > 0) binom = binom * k / (i - k + 1);
    }
  }
  return out;
}

struct Case {
  std::array<double, kMax + 1> c{};
  int degree = 0;
  double a = 0.0, b = 0.0;  // shift by s = a - b
};

Case random_case(std::mt19937_64& rng) {
  Case k;
  k.degree = static_cast<int>(rng() % (kMax + 1));
  for (int i = 0; i <= k.degree; ++i) k.c[i] = random_double(rng, -30, 30);
  k.a = random_double(rng, -20, 20);
  k.b = rng() % 5 == 0 ? k.a : random_double(rng, -20, 20);  // s = 0 sometimes
  return k;
}

TEST(NumericTaylorShift, RationalsAndDyadicsAreExact) {
  constexpr unsigned kSeed = 20261123;
  std::mt19937_64 rng(kSeed);
  for (int trial = 0; trial < 2000; ++trial) {
    const Case k = random_case(rng);
    const mpq_class s = exact(k.a) - exact(k.b);
    const auto want = expanded(k.c, k.degree, s);
    std::array<mpq_class, kMax + 1> q;
    std::array<numeric::Dyadic, kMax + 1> dq;
    for (int i = 0; i <= kMax; ++i) {
      q[i] = exact(k.c[i]);
      dq[i] = numeric::dyadic(k.c[i]);
    }
    numeric::taylor_shift(q, k.degree, s);
    numeric::taylor_shift(dq, k.degree, numeric::dyadic(k.a) + (-numeric::dyadic(k.b)));
    for (int i = 0; i <= kMax; ++i) {
      ASSERT_EQ(q[i], want[i]) << "seed " << kSeed << " trial " << trial << " k " << i;
      ASSERT_EQ(exact_dyadic(dq[i].m, dq[i].e), want[i])
          << "seed " << kSeed << " trial " << trial << " k " << i;
    }
  }
}

TEST(NumericTaylorShift, IntervalsEncloseTheExactShiftAndTheDoubleOne) {
  constexpr unsigned kSeed = 20261124;
  std::mt19937_64 rng(kSeed);
  int strict = 0;  // enclosures that are not a single point (the test exercises rounding)
  for (int trial = 0; trial < 2000; ++trial) {
    const Case k = random_case(rng);
    const numeric::Interval s = numeric::exact_difference(k.a, k.b);
    const auto want = expanded(k.c, k.degree, exact(k.a) - exact(k.b));
    std::array<numeric::Interval, kMax + 1> iq;
    std::array<double, kMax + 1> dq = k.c;
    for (int i = 0; i <= kMax; ++i) iq[i] = numeric::Interval::point(k.c[i]);
    numeric::taylor_shift(iq, k.degree, s);
    numeric::taylor_shift(dq, k.degree, k.a - k.b);
    for (int i = 0; i <= kMax; ++i) {
      ASSERT_LE(exact(iq[i].lo), want[i])
          << "seed " << kSeed << " trial " << trial << " k " << i << " a " << hex(k.a);
      ASSERT_GE(exact(iq[i].hi), want[i])
          << "seed " << kSeed << " trial " << trial << " k " << i << " a " << hex(k.a);
      // Rounding is monotone, so the double steps on members of the intervals stay inside them.
      ASSERT_LE(iq[i].lo, dq[i]) << "seed " << kSeed << " trial " << trial << " k " << i;
      ASSERT_GE(iq[i].hi, dq[i]) << "seed " << kSeed << " trial " << trial << " k " << i;
      if (i > k.degree) {
        ASSERT_EQ(dq[i], k.c[i]) << "untouched above the degree";
      }
      strict += iq[i].lo < iq[i].hi ? 1 : 0;
    }
    if (k.a == k.b) {  // s = 0: nothing moves
      for (int i = 0; i <= kMax; ++i) ASSERT_EQ(dq[i], k.c[i]);
    }
  }
  EXPECT_GT(strict, 1000);
}

TEST(NumericTaylorShift, SmallIntegerShiftIsExactInDoubles) {
  // p(u) = (u - 1)^3 = u^3 - 3u^2 + 3u - 1 shifted by 1 is u^3.
  std::array<double, kMax + 1> q{-1.0, 3.0, -3.0, 1.0};
  numeric::taylor_shift(q, 3, 1.0);
  const std::array<double, kMax + 1> want{0.0, 0.0, 0.0, 1.0};
  EXPECT_EQ(q, want);
}

}  // namespace
}  // namespace kinetic
