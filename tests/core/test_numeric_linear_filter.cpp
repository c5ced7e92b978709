// The linear filter and the certified comparison (core/numeric/linear_filter.hpp), checked
// against the exact x(t) = c0 + c1 (t - origin) in GMP rationals on random and adversarial
// motions: the bound holds, a decided comparison is right, NaN and overflow never decide, and
// the bound is monotone (the kd-tree's per-query margin relies on it); and the cuts that turn a
// shared bound into one comparison per value (below_cut / above_cut) are on the safe side.

#include "core/numeric/linear_filter.hpp"

#include <gmpxx.h>
#include <gtest/gtest.h>

#include <array>
#include <bit>
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

struct Motion {
  double c0, c1, origin;
};

mpq_class exact_at(const Motion& m, double t) {
  return exact(m.c0) + exact(m.c1) * (exact(t) - exact(m.origin));
}

std::string describe(const Motion& m, double t) {
  return "c0=" + hex(m.c0) + " c1=" + hex(m.c1) + " origin=" + hex(m.origin) + " t=" + hex(t);
}

/// Probes b around the filtered value and the exact one: every decided sign must be right.
void check_comparisons(const Motion& m, double t, const FilteredValue& f, const mpq_class& x,
                       const std::string& where) {
  const double v = f.value, err = f.error;
  const double xd = x.get_d();
  std::vector<double> probes = {v,
                                std::nextafter(v, -DBL_MAX),
                                std::nextafter(v, DBL_MAX),
                                v - err,
                                v + err,
                                v - 2.0 * err,
                                v + 2.0 * err,
                                v - 1.5 * err,
                                v + 1.5 * err,
                                xd,
                                std::nextafter(xd, -DBL_MAX),
                                std::nextafter(xd, DBL_MAX)};
  for (const double b : probes) {
    if (!std::isfinite(b)) continue;
    const int s = numeric::linear_sign_versus(m.c0, m.c1, m.origin, t, b);
    EXPECT_EQ(s, numeric::sign_versus(f, b));
    if (s != 0) {
      EXPECT_EQ(s, sgn(x - exact(b))) << where << " b=" << hex(b);
    }
  }
}

/// One regime of random motions: exponent ranges of c0, c1, the origin and t - origin.
struct Regime {
  int c0_min, c0_max, c1_min, c1_max, origin_min, origin_max, off_min, off_max;
};

void run_regime(std::uint64_t seed, const Regime& r, int iterations, int min_finite,
                int min_decided) {
  std::mt19937_64 rng(seed);
  int finite = 0, decided = 0;
  for (int it = 0; it < iterations; ++it) {
    const Motion m{random_double(rng, r.c0_min, r.c0_max), random_double(rng, r.c1_min, r.c1_max),
                   random_double(rng, r.origin_min, r.origin_max)};
    const double t = m.origin + random_double(rng, r.off_min, r.off_max);
    if (!std::isfinite(t)) continue;
    const std::string where =
        "seed=" + std::to_string(seed) + " it=" + std::to_string(it) + " " + describe(m, t);
    const FilteredValue f = numeric::linear_filtered(m.c0, m.c1, m.origin, t);
    EXPECT_EQ(std::bit_cast<std::uint64_t>(numeric::linear_value(m.c0, m.c1, m.origin, t)),
              std::bit_cast<std::uint64_t>(f.value))
        << where;
    const mpq_class x = exact_at(m, t);
    if (std::isfinite(f.value) && std::isfinite(f.error)) {
      ++finite;
      EXPECT_LE(abs(exact(f.value) - x), exact(f.error)) << where;
      // The filter decides against a b well away from x: x's rounding, shifted by 4 bounds.
      const double far = f.value + 4.0 * f.error + 4.0 * DBL_MIN;
      if (std::isfinite(far) && numeric::sign_versus(f, far) != 0) ++decided;
    }
    check_comparisons(m, t, f, x, where);
    if (::testing::Test::HasFailure()) return;
  }
  EXPECT_GE(finite, min_finite) << "seed=" << seed;
  EXPECT_GE(decided, min_decided) << "seed=" << seed;
}

TEST(NumericLinearFilter, BoundHoldsAndDecidedSignsAreRight) {
  // Ordinary scenario coordinates.
  run_regime(0x11f0001, Regime{-10, 10, -10, 10, -5, 10, -20, 10}, 20000, 20000, 15000);
  // Far-out origins and times close to them (t - origin rounds), steep slopes.
  run_regime(0x11f0002, Regime{-5, 40, 20, 60, 30, 60, -40, 5}, 20000, 20000, 15000);
  // Tiny coefficients and offsets: subnormal and underflowing products.
  run_regime(0x11f0003, Regime{-1074, -1000, -600, -500, -10, 10, -600, -400}, 20000, 20000, 0);
  // Near overflow: some values and bounds overflow (never decided then).
  run_regime(0x11f0004, Regime{900, 1023, 500, 1000, -5, 5, 0, 600}, 20000, 5000, 0);
}

TEST(NumericLinearFilter, ComparisonWithAnExactValue) {
  // error == 0: value is X itself; b one unit away on either side, subnormal too.
  const double tiny = std::numeric_limits<double>::denorm_min();
  for (const double v : {1.0, -1.0, 3.0, DBL_MIN, tiny, -tiny, 1e300, DBL_MAX, 0.0}) {
    for (const double b : {std::nextafter(v, -DBL_MAX), std::nextafter(v, DBL_MAX), v}) {
      const int s = numeric::sign_versus(v, 0.0, b);
      EXPECT_EQ(s, sgn(exact(v) - exact(b))) << "v=" << hex(v) << " b=" << hex(b);
    }
  }
}

TEST(NumericLinearFilter, NanAndOverflowNeverDecide) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const double b : {-1e300, -1.0, 0.0, 1.0, 1e300}) {
    // A NaN slope marks a motion of degree above 1.
    EXPECT_EQ(numeric::linear_sign_versus(1.0, nan, 0.0, 5.0, b), 0);
    // c1 (t - origin) overflows.
    EXPECT_EQ(numeric::linear_sign_versus(0.0, DBL_MAX, 0.0, 4.0, b), 0);
    EXPECT_EQ(numeric::linear_sign_versus(0.0, -DBL_MAX, 0.0, 4.0, b), 0);
    // t - origin overflows, with a zero slope too (0 * inf).
    EXPECT_EQ(numeric::linear_sign_versus(1.0, 1.0, -DBL_MAX, DBL_MAX, b), 0);
    EXPECT_EQ(numeric::linear_sign_versus(1.0, 0.0, -DBL_MAX, DBL_MAX, b), 0);
    EXPECT_EQ(numeric::sign_versus(0.0, nan, b), 0);
    EXPECT_EQ(numeric::sign_versus(nan, 1.0, b), 0);
    EXPECT_EQ(numeric::sign_versus(inf, inf, b), 0);
  }
  // A constant motion is decided away from its value.
  EXPECT_EQ(numeric::linear_sign_versus(2.0, 0.0, 7.0, 1e9, 1.0), 1);
  EXPECT_EQ(numeric::linear_sign_versus(2.0, 0.0, 7.0, 1e9, 3.0), -1);
}

TEST(NumericLinearFilter, CutsCertifyAndAreTight) {
  // below_cut(b, e) <= b - e and above_cut(b, e) >= b + e exactly (so value < below_cut
  // certifies X < b for every X within e of value), over random magnitudes, subnormal ones
  // included; and each is within a few units of b -/+ e (not a cut that decides nothing).
  const std::uint64_t seed = 0x11f0101;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> mant(-1.0, 1.0);
  std::uniform_int_distribution<int> ex(-1074, 1000);
  int checked = 0;
  for (int i = 0; i < 20000; ++i) {
    // Each draw in its own statement, so that a seed gives the same values with any compiler.
    const double b_mant = mant(rng);
    const int b_exp = ex(rng);
    const double b = std::ldexp(b_mant, b_exp);
    const double e_mant = mant(rng);
    // Mostly a bound 2^-30 of |b| (as a query's margin against a box side); b = 0 has no
    // exponent (ilogb(0) is INT_MIN): a random one then.
    const int e_exp = i % 4 == 0 || b == 0.0 ? ex(rng) : std::ilogb(b) - 30;
    const double e = std::fabs(std::ldexp(e_mant, e_exp));
    if (!std::isfinite(b) || !std::isfinite(e)) continue;
    const double lo = numeric::below_cut(b, e), hi = numeric::above_cut(b, e);
    ASSERT_TRUE(std::isfinite(lo) && std::isfinite(hi)) << "seed=" << seed << " i=" << i;
    const mpq_class below = exact(b) - exact(e), above = exact(b) + exact(e);
    EXPECT_LE(exact(lo), below) << "seed=" << seed << " b=" << hex(b) << " e=" << hex(e);
    EXPECT_GE(exact(hi), above) << "seed=" << seed << " b=" << hex(b) << " e=" << hex(e);
    // Tight: no more than 4 units of the cut's own magnitude (and a subnormal step) away.
    const mpq_class slack_lo = (below - exact(lo)), slack_hi = (exact(hi) - above);
    const mpq_class unit_lo = exact(std::fabs(lo)) * exact(0x1p-50) + exact(0x1p-1068);
    const mpq_class unit_hi = exact(std::fabs(hi)) * exact(0x1p-50) + exact(0x1p-1068);
    EXPECT_LE(slack_lo, unit_lo) << "seed=" << seed << " b=" << hex(b) << " e=" << hex(e);
    EXPECT_LE(slack_hi, unit_hi) << "seed=" << seed << " b=" << hex(b) << " e=" << hex(e);
    ++checked;
  }
  EXPECT_GT(checked, 19000);
  // Infinite sides: nothing is below -infinity or above +infinity, every finite value is below
  // +infinity and above -infinity; an undefined b -/+ e (infinity against an infinite bound)
  // is a NaN, which no comparison passes.
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(numeric::below_cut(-inf, 1.0), -inf);
  EXPECT_EQ(numeric::above_cut(inf, 1.0), inf);
  EXPECT_EQ(numeric::below_cut(inf, 1.0), inf);
  EXPECT_EQ(numeric::above_cut(-inf, 1.0), -inf);
  EXPECT_EQ(numeric::below_cut(1.0, inf), -inf);
  EXPECT_EQ(numeric::above_cut(1.0, inf), inf);
  EXPECT_TRUE(std::isnan(numeric::below_cut(inf, inf)));
  EXPECT_TRUE(std::isnan(numeric::above_cut(-inf, inf)));
  EXPECT_TRUE(std::isnan(numeric::below_cut(1.0, nan)));
  EXPECT_TRUE(std::isnan(numeric::above_cut(nan, 1.0)));
  // b itself is never certified, not even with e = 0; a value a few units from it is.
  EXPECT_FALSE(1.0 < numeric::below_cut(1.0, 0.0));
  EXPECT_FALSE(1.0 > numeric::above_cut(1.0, 0.0));
  EXPECT_TRUE(1.0 - 0x3p-53 < numeric::below_cut(1.0, 0.0));
  EXPECT_TRUE(1.0 + 0x3p-52 > numeric::above_cut(1.0, 0.0));
  EXPECT_FALSE(0.0 < numeric::below_cut(0.0, 0.0));
  EXPECT_FALSE(0.0 > numeric::above_cut(0.0, 0.0));
}

TEST(NumericLinearFilter, BoundIsMonotone) {
  const std::uint64_t seed = 0x11f0005;
  std::mt19937_64 rng(seed);
  for (int it = 0; it < 20000; ++it) {
    const double c0 = random_double(rng, -1074, 1000), c1 = random_double(rng, -1074, 1000);
    const double s = random_double(rng, -1074, 1000);
    auto grow = [&](double x) { return std::fabs(x) * (1.0 + static_cast<double>(rng() % 4)); };
    const double e = numeric::linear_filtered(c0, c1, 0.0, s).error;
    const double e2 = numeric::linear_filtered(grow(c0), grow(c1), 0.0, grow(s)).error;
    if (std::isnan(e) || std::isnan(e2)) continue;
    EXPECT_LE(e, e2) << "seed=" << seed << " it=" << it << " c0=" << hex(c0) << " c1=" << hex(c1)
                     << " s=" << hex(s);
    // The sign of c0, c1 and s does not change the bound.
    EXPECT_EQ(e, numeric::linear_filtered(-c0, -c1, 0.0, -s).error) << "seed=" << seed;
    if (HasFailure()) return;
  }
}

/// linear_minus_compensated(): the bound holds against the exact x(t) - q, and it is tight: about
/// u |x(t) - q| where linear_filtered() has 8 u (|c0| + |c1 (t - origin)|), so a query point next
/// to a point far from the origin is decided without exact arithmetic.
TEST(NumericLinearFilter, CompensatedDifferenceBoundHoldsAndIsTight) {
  const std::uint64_t seed = 0x11f0006;
  std::mt19937_64 rng(seed);
  struct Case {
    int c0_min, c0_max, c1_min, c1_max, origin_min, origin_max, off_min, off_max;
  };
  // Ordinary coordinates; far origins and steep slopes; tiny and subnormal values; near overflow.
  const std::array<Case, 4> cases{Case{-10, 10, -10, 10, -5, 10, -20, 10},
                                  Case{-5, 40, 20, 60, 30, 60, -40, 5},
                                  Case{-1074, -1000, -600, -500, -10, 10, -600, -400},
                                  Case{900, 1023, 500, 1000, -5, 5, 0, 600}};
  int tight = 0, near = 0;
  for (std::size_t c = 0; c < cases.size(); ++c) {
    const Case& r = cases[c];
    for (int it = 0; it < 20000; ++it) {
      const Motion m{random_double(rng, r.c0_min, r.c0_max), random_double(rng, r.c1_min, r.c1_max),
                     random_double(rng, r.origin_min, r.origin_max)};
      double t = m.origin + random_double(rng, r.off_min, r.off_max);
      if (rng() % 8 == 0) t = m.origin;  // t - origin == 0
      const mpq_class x = exact_at(m, t);
      // q at x(t) rounded, one or a few ulps off it, or anywhere.
      double q = x.get_d();
      if (!std::isfinite(q)) continue;
      switch (rng() % 4) {
        case 0:
          break;
        case 1:
          q = std::nextafter(q, (rng() & 1) != 0 ? DBL_MAX : -DBL_MAX);
          break;
        case 2:
          q = q + q * 0x1p-30 * static_cast<double>(static_cast<int>(rng() % 9) - 4);
          break;
        default:
          q = random_double(rng, r.c0_min, r.c0_max);
          break;
      }
      if (!std::isfinite(q)) continue;
      const FilteredValue f = numeric::linear_minus_compensated(m.c0, m.c1, m.origin, t, q);
      const std::string where = "seed=" + std::to_string(seed) + " case " + std::to_string(c) +
                                " it=" + std::to_string(it) + " " + describe(m, t) + " q=" + hex(q);
      if (std::isnan(f.error)) continue;  // undecided is allowed (outside the domain)
      const mpq_class diff = x - exact(q);
      mpq_class off = exact(f.value) - diff;
      if (off < 0) off = -off;
      ASSERT_LE(off, exact(f.error)) << where;
      // Tight where the domain is ordinary: within 2^-50 |x - q| plus 2^-100 of the terms.
      if (c < 2) {
        const double terms = std::fabs(m.c0) + std::fabs(m.c1 * (t - m.origin)) + std::fabs(q);
        EXPECT_LE(f.error, 0x1p-50 * std::fabs(f.value) + 0x1p-100 * terms + 8 * DBL_MIN) << where;
        ++tight;
        if (std::fabs(f.value) < 0x1p-20 * terms) ++near;
      }
    }
  }
  // The cases above met the regime that matters: q within 2^-20 of the coordinates' size.
  EXPECT_GE(tight, 30000) << "seed=" << seed;
  EXPECT_GE(near, 5000) << "seed=" << seed;
}

TEST(NumericLinearFilter, CompensatedDifferenceIsUndecidedOnNanAndOverflow) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(std::isnan(numeric::linear_minus_compensated(1.0, nan, 0.0, 5.0, 1.0).error));
  EXPECT_TRUE(std::isnan(numeric::linear_minus_compensated(1.0, nan, 5.0, 5.0, 1.0).error));
  EXPECT_TRUE(std::isnan(numeric::linear_minus_compensated(1.0, inf, 5.0, 5.0, 1.0).error));
  EXPECT_TRUE(std::isnan(numeric::linear_minus_compensated(0.0, DBL_MAX, 0.0, 4.0, 1.0).error));
  EXPECT_TRUE(
      std::isnan(numeric::linear_minus_compensated(1.0, 1.0, -DBL_MAX, DBL_MAX, 1.0).error));
  EXPECT_TRUE(
      std::isnan(numeric::linear_minus_compensated(DBL_MAX, 0.0, 0.0, 1.0, -DBL_MAX).error));
  // Exact inputs: no error beyond the bound's floor.
  const FilteredValue f = numeric::linear_minus_compensated(3.0, 2.0, 1.0, 5.0, 11.0);
  EXPECT_EQ(f.value, 0.0);
  EXPECT_LE(f.error, 4 * DBL_MIN * (1 + 1e-9));
}

}  // namespace
}  // namespace kinetic
