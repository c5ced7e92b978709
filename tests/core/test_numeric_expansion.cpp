// Floating-point expansions (core/numeric/expansion.hpp) against exact rational arithmetic (GMP):
// sums, differences, products and their signs on random and cancelling inputs; the domain
// (factors beyond 2^+-480, capacity) reported, never a wrong value; sum_sign's filter and exact
// stage. Fixed seeds, printed on failure.

#include "core/numeric/expansion.hpp"

#include <gmpxx.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "core/numeric_test_util.hpp"

namespace kinetic {
namespace {

using numeric::Expansion;
using numeric_test::exact;
using numeric_test::random_double;

mpq_class value(const Expansion& e) {
  mpq_class v = 0;
  for (std::size_t i = 0; i < e.size(); ++i) v += exact(e[i]);
  return v;
}

int sign(const mpq_class& x) { return sgn(x); }

/// The components are non-zero and in strictly increasing magnitude (non-overlapping ones are).
void expect_well_formed(const Expansion& e, const std::string& where) {
  for (std::size_t i = 0; i < e.size(); ++i) {
    ASSERT_NE(e[i], 0.0) << where;
    if (i > 0) {
      ASSERT_LT(std::fabs(e[i - 1]), std::fabs(e[i])) << where;
    }
  }
}

TEST(NumericExpansion, ArithmeticIsExact) {
  constexpr std::uint64_t kSeed = 20261125;
  std::mt19937_64 rng(kSeed);
  for (int round = 0; round < 3000; ++round) {
    const std::string where = "seed " + std::to_string(kSeed) + ", round " + std::to_string(round);
    // Cancelling inputs: b close to a, c close to -a*b.
    const double a = random_double(rng, -40, 40);
    const double b = rng() % 2 == 0 ? random_double(rng, -40, 40) : a * (1.0 + 0x1p-30);
    const double c = random_double(rng, -40, 40);
    const double d = rng() % 2 == 0 ? random_double(rng, -40, 40) : -c;
    Expansion x = Expansion::difference(a, b);  // a - b
    Expansion y = Expansion::difference(c, d);  // c - d
    ASSERT_TRUE(x.ok() && y.ok()) << where;
    EXPECT_EQ(value(x), exact(a) - exact(b)) << where;
    const Expansion p = x * y;
    ASSERT_TRUE(p.ok()) << where;
    const mpq_class want_p = (exact(a) - exact(b)) * (exact(c) - exact(d));
    EXPECT_EQ(value(p), want_p) << where;
    EXPECT_EQ(p.sign(), sign(want_p)) << where;
    expect_well_formed(p, where);
    Expansion q = p;
    q.subtract(x.scaled(c));  // (a - b)(c - d) - (a - b) c = -(a - b) d
    ASSERT_TRUE(q.ok()) << where;
    const mpq_class want_q = -(exact(a) - exact(b)) * exact(d);
    EXPECT_EQ(value(q), want_q) << where;
    EXPECT_EQ(q.sign(), sign(want_q)) << where;
    expect_well_formed(q, where);
    // Compressed: the same value, no more components, still well formed.
    Expansion compressed = q;
    compressed.compress();
    EXPECT_EQ(value(compressed), want_q) << where;
    EXPECT_LE(compressed.size(), q.size()) << where;
    EXPECT_EQ(compressed.sign(), sign(want_q)) << where;
    expect_well_formed(compressed, where);
    // An exact zero: p - p.
    Expansion z = p;
    z.subtract(p);
    EXPECT_EQ(z.sign(), 0) << where;
    EXPECT_EQ(z.size(), 0u) << where;
  }
}

TEST(NumericExpansion, OutsideTheDomainIsReportedNotWrong) {
  const Expansion big = Expansion(0x1p500);
  EXPECT_FALSE(big.scaled(3.0).ok());                  // a factor beyond 2^480
  EXPECT_FALSE(Expansion(3.0).scaled(0x1p-500).ok());  // a factor below 2^-480
  EXPECT_TRUE(Expansion(3.0).scaled(0x1p-480).ok());
  EXPECT_FALSE(Expansion(0.0).scaled(0x1p900).ok());  // the factor itself out of the domain
  EXPECT_FALSE(Expansion(std::nan("")).ok());
  EXPECT_FALSE(Expansion::difference(0x1p1023, -0x1p1023).ok());  // overflows
  // Capacity: a sum of many scattered powers of two needs one component each.
  Expansion e;
  for (int k = 0; k < 70; ++k) e.add(std::ldexp(1.0, 60 * k - 2000));
  EXPECT_FALSE(e.ok());
  // Operations on a not-ok expansion stay not ok.
  Expansion f = e;
  f.add(1.0);
  EXPECT_FALSE(f.ok());
  EXPECT_FALSE((f * Expansion(2.0)).ok());
}

TEST(NumericExpansion, SumSignIsExact) {
  constexpr std::uint64_t kSeed = 20261127;
  std::mt19937_64 rng(kSeed);
  std::size_t zeros = 0, tiny = 0;
  for (int round = 0; round < 5000; ++round) {
    const std::string where = "seed " + std::to_string(kSeed) + ", round " + std::to_string(round);
    const std::size_t n = 2 + rng() % 20;
    std::vector<double> t;
    mpq_class want = 0;
    for (std::size_t i = 0; i + 1 < n; ++i) {
      t.push_back(random_double(rng, -60, 60));
      want += exact(t.back());
    }
    // The last term cancels the others (to zero, or to a tiny remainder of either sign).
    const int mode = static_cast<int>(rng() % 3);
    double last = -want.get_d();
    if (mode == 1) last = std::nextafter(last, 0.0);
    if (mode == 2) last = random_double(rng, -60, 60);
    t.push_back(last);
    want += exact(last);
    if (want == 0) ++zeros;
    if (want != 0 && abs(want) < 1e-10) ++tiny;
    EXPECT_EQ(numeric::sum_sign(t.data(), t.size()), sign(want)) << where;
  }
  EXPECT_GT(zeros, 50u);
  EXPECT_GT(tiny, 100u);
}

}  // namespace
}  // namespace kinetic
