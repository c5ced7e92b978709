// MotionPolynomial construction and floating-point evaluation, and the rigorous error bound of
// evaluate_filtered checked against an exact rational (GMP) evaluation written here.

#include "kinetic/core/polynomial.hpp"

#include <gmpxx.h>
#include <gtest/gtest.h>

#include <array>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace kinetic {
namespace {

// ---------------------------------------------------------------------------------------------
// Independent exact oracle: Horner in rationals on s = t - origin (no rounding anywhere).
mpq_class exact_eval(const MotionPolynomial& p, Time t) {
  const mpq_class s = mpq_class(t) - mpq_class(p.origin);
  mpq_class v(p.c[p.degree]);
  for (int i = p.degree - 1; i >= 0; --i) v = v * s + mpq_class(p.c[i]);
  return v;
}

int sgn_q(const mpq_class& v) { return sgn(v); }

std::string describe(const MotionPolynomial& p, Time t) {
  std::ostringstream os;
  os.precision(17);
  os << std::hexfloat << "origin=" << p.origin << " t=" << t << " c={";
  for (int i = 0; i <= p.degree; ++i) os << (i ? ", " : "") << p.c[i];
  os << "}";
  return os.str();
}

/// A random double: random sign, full 53-bit mantissa (or a short one, so that cancellation can
/// be exact), binary exponent uniform in [emin, emax]. Results below DBL_MIN are subnormal.
double random_double(std::mt19937_64& rng, int emin, int emax) {
  std::uniform_int_distribution<int> ex(emin, emax);
  std::uint64_t mant = rng() & ((std::uint64_t{1} << 53) - 1);
  if (rng() % 4 == 0) mant &= ~((std::uint64_t{1} << 45) - 1);  // short mantissa
  mant |= std::uint64_t{1} << 52;
  const double m = std::ldexp(static_cast<double>(mant), -53);  // in [0.5, 1)
  const double v = std::ldexp(m, ex(rng));
  return (rng() & 1) ? -v : v;
}

struct Ranges {
  int coef_min, coef_max;      // exponent range of coefficients
  int origin_min, origin_max;  // exponent range of the origin
  int off_min, off_max;        // exponent range of t - origin
};

MotionPolynomial random_polynomial(std::mt19937_64& rng, const Ranges& r, int degree) {
  std::array<double, kMaxMotionDegree + 1> c{};
  for (int i = 0; i <= degree; ++i) {
    c[i] = (rng() % 8 == 0) ? 0.0 : random_double(rng, r.coef_min, r.coef_max);
  }
  if (c[degree] == 0.0) c[degree] = random_double(rng, r.coef_min, r.coef_max);
  const double origin = (rng() % 5 == 0) ? 0.0 : random_double(rng, r.origin_min, r.origin_max);
  return MotionPolynomial::from(std::span<const double>(c.data(), degree + 1), origin);
}

/// Checks the filter on (p, t): when value and error are finite, |value - exact| <= error, and a
/// certain sign is the exact sign. Returns true when the bound was checkable (finite).
bool check_filter(const MotionPolynomial& p, Time t, std::uint64_t seed, int iteration,
                  int* certain_count) {
  const FilteredValue f = evaluate_filtered(p, t);
  const mpq_class exact = exact_eval(p, t);
  const int s = f.sign_if_certain();
  if (s != 0) {
    ++*certain_count;
    EXPECT_EQ(s, sgn_q(exact)) << "sign_if_certain wrong; seed=" << seed
                               << " iteration=" << iteration << " " << describe(p, t)
                               << " value=" << f.value << " error=" << f.error;
  }
  if (!std::isfinite(f.value) || !std::isfinite(f.error)) return false;
  const mpq_class actual = abs(mpq_class(f.value) - exact);
  EXPECT_LE(cmp(actual, mpq_class(f.error)), 0)
      << "error bound violated; seed=" << seed << " iteration=" << iteration << " "
      << describe(p, t) << std::hexfloat << " value=" << f.value << " error=" << f.error
      << " |value-exact|~" << actual.get_d();
  return true;
}

// ---------------------------------------------------------------------------------------------
// Construction.

TEST(PolynomialFrom, TrimsTrailingZeros) {
  const std::vector<double> c = {1.0, 2.0, 0.0, 0.0};
  const MotionPolynomial p = MotionPolynomial::from(c, 3.5);
  EXPECT_EQ(p.degree, 1);
  EXPECT_EQ(p.origin, 3.5);
  EXPECT_EQ(p.c[0], 1.0);
  EXPECT_EQ(p.c[1], 2.0);
  for (int i = 2; i <= kMaxMotionDegree; ++i) EXPECT_EQ(p.c[i], 0.0) << i;
  EXPECT_FALSE(p.is_zero());
}

TEST(PolynomialFrom, AllZerosIsTheZeroPolynomial) {
  const std::vector<double> c = {0.0, 0.0, 0.0};
  const MotionPolynomial p = MotionPolynomial::from(c);
  EXPECT_EQ(p.degree, 0);
  EXPECT_TRUE(p.is_zero());
  EXPECT_EQ(p, MotionPolynomial::constant(0.0));
  const std::vector<double> single = {0.0};
  EXPECT_TRUE(MotionPolynomial::from(single).is_zero());
  // -0.0 is a zero too.
  const std::vector<double> neg = {-0.0, -0.0};
  EXPECT_TRUE(MotionPolynomial::from(neg).is_zero());
  EXPECT_EQ(MotionPolynomial::from(neg).degree, 0);
}

TEST(PolynomialFrom, KeepsInteriorZerosAndFullDegree) {
  const std::vector<double> c = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -2.0};
  const MotionPolynomial p = MotionPolynomial::from(c, -1.0);
  EXPECT_EQ(p.degree, 6);
  EXPECT_EQ(p.c[6], -2.0);
  EXPECT_FALSE(p.is_zero());
  // More than 7 coefficients are fine once the trailing zeros are trimmed.
  const std::vector<double> padded = {1.0, 0.0, 3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  const MotionPolynomial q = MotionPolynomial::from(padded);
  EXPECT_EQ(q.degree, 2);
  EXPECT_EQ(q.c[2], 3.0);
}

TEST(PolynomialFrom, ConstantAndEquality) {
  const MotionPolynomial k = MotionPolynomial::constant(-4.25);
  EXPECT_EQ(k.degree, 0);
  EXPECT_EQ(k.origin, 0.0);
  EXPECT_EQ(k.c[0], -4.25);
  EXPECT_FALSE(k.is_zero());
  const std::vector<double> c = {-4.25};
  EXPECT_EQ(MotionPolynomial::from(c), k);
  EXPECT_NE(MotionPolynomial::from(c, 1.0), k);  // a different origin is a different record
}

// ---------------------------------------------------------------------------------------------
// Floating-point evaluation on known polynomials (all values below are exact in double).

TEST(PolynomialEvaluate, KnownValuesAndDerivatives) {
  // p(t) = 1 + 2 (t-1) + 3 (t-1)^2
  const std::vector<double> c = {1.0, 2.0, 3.0};
  const MotionPolynomial p = MotionPolynomial::from(c, 1.0);
  EXPECT_EQ(p.evaluate(1.0), 1.0);
  EXPECT_EQ(p.evaluate(3.0), 17.0);  // s = 2: 1 + 4 + 12
  EXPECT_EQ(p.evaluate(0.0), 2.0);   // s = -1: 1 - 2 + 3
  EXPECT_EQ(p.derivative(1.0), 2.0);
  EXPECT_EQ(p.derivative(3.0), 14.0);  // 2 + 6 s
  EXPECT_EQ(p.derivative(0.0), -4.0);

  // q(t) = (t-2)^3 = -8 + 12 t - 6 t^2 + t^3 (origin 0)
  const std::vector<double> q3 = {-8.0, 12.0, -6.0, 1.0};
  const MotionPolynomial q = MotionPolynomial::from(q3);
  for (int k = -5; k <= 9; ++k) {
    const double t = k * 0.5;
    EXPECT_EQ(q.evaluate(t), (t - 2) * (t - 2) * (t - 2)) << t;
    EXPECT_EQ(q.derivative(t), 3 * (t - 2) * (t - 2)) << t;
  }

  // Constants: derivative 0.
  EXPECT_EQ(MotionPolynomial::constant(7.0).evaluate(123.0), 7.0);
  EXPECT_EQ(MotionPolynomial::constant(7.0).derivative(123.0), 0.0);

  // Degree 6 monomial at a far origin: s^6 with s = 3.
  const std::vector<double> m6 = {0, 0, 0, 0, 0, 0, 1.0};
  const MotionPolynomial m = MotionPolynomial::from(m6, 1e6);
  EXPECT_EQ(m.evaluate(1e6 + 3.0), 729.0);
  EXPECT_EQ(m.derivative(1e6 + 3.0), 6.0 * 243.0);
}

TEST(PolynomialEvaluate, DerivativeMatchesExactDerivativeOnRandomSmallPolynomials) {
  const std::uint64_t seed = 0x5eed0001;
  std::mt19937_64 rng(seed);
  for (int it = 0; it < 500; ++it) {
    // Small integer coefficients and dyadic s: every operation is exact in double.
    const int degree = static_cast<int>(rng() % (kMaxMotionDegree + 1));
    std::array<double, kMaxMotionDegree + 1> c{};
    for (int i = 0; i <= degree; ++i) c[i] = static_cast<double>(static_cast<int>(rng() % 21) - 10);
    const double origin = static_cast<double>(static_cast<int>(rng() % 41) - 20) / 4.0;
    const double t = static_cast<double>(static_cast<int>(rng() % 41) - 20) / 4.0;
    const MotionPolynomial p =
        MotionPolynomial::from(std::span<const double>(c.data(), degree + 1), origin);
    const mpq_class s = mpq_class(t) - mpq_class(origin);
    mpq_class d = 0;
    for (int i = p.degree; i >= 1; --i) d = d * s + mpq_class(i) * mpq_class(p.c[i]);
    EXPECT_EQ(mpq_class(p.derivative(t)), d)
        << "seed=" << seed << " it=" << it << " " << describe(p, t);
    EXPECT_EQ(mpq_class(p.evaluate(t)), exact_eval(p, t)) << "seed=" << seed << " it=" << it;
  }
}

// ---------------------------------------------------------------------------------------------
// FilteredValue::sign_if_certain.

TEST(PolynomialFiltered, SignIfCertainRules) {
  EXPECT_EQ((FilteredValue{1.0, 0.5}).sign_if_certain(), 1);
  EXPECT_EQ((FilteredValue{-1.0, 0.5}).sign_if_certain(), -1);
  EXPECT_EQ((FilteredValue{0.5, 0.5}).sign_if_certain(), 0);  // value == error: undecided
  EXPECT_EQ((FilteredValue{-0.5, 0.5}).sign_if_certain(), 0);
  EXPECT_EQ((FilteredValue{0.0, 0.0}).sign_if_certain(), 0);
  EXPECT_EQ((FilteredValue{1e-300, 0.0}).sign_if_certain(), 1);
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ((FilteredValue{inf, 0.0}).sign_if_certain(), 0);
  EXPECT_EQ((FilteredValue{-inf, 0.0}).sign_if_certain(), 0);
  EXPECT_EQ((FilteredValue{nan, 0.0}).sign_if_certain(), 0);
  EXPECT_EQ((FilteredValue{1.0, inf}).sign_if_certain(), 0);
  EXPECT_EQ((FilteredValue{1.0, nan}).sign_if_certain(), 0);
}

TEST(PolynomialFiltered, ExactZeroIsNeverCertain) {
  // (t-3)^2 = 9 - 6t + t^2 at t = 3: the value is exactly 0 and the filter must not decide.
  const std::vector<double> c = {9.0, -6.0, 1.0};
  const MotionPolynomial p = MotionPolynomial::from(c);
  const FilteredValue f = evaluate_filtered(p, 3.0);
  EXPECT_EQ(f.sign_if_certain(), 0);
  EXPECT_GE(f.error, 0.0);
  // The zero polynomial.
  EXPECT_EQ(evaluate_filtered(MotionPolynomial::constant(0.0), 5.0).sign_if_certain(), 0);
  // A non-zero constant is certain.
  EXPECT_EQ(evaluate_filtered(MotionPolynomial::constant(-2.0), 5.0).sign_if_certain(), -1);
}

// ---------------------------------------------------------------------------------------------
// The error bound of evaluate_filtered against the exact value.

void run_bound_check(std::uint64_t seed, const Ranges& ranges, int iterations, bool cancel,
                     double min_checked_fraction, double min_certain_fraction = 0.0) {
  std::mt19937_64 rng(seed);
  int checked = 0, certain = 0;
  for (int it = 0; it < iterations; ++it) {
    const int degree = static_cast<int>(rng() % (kMaxMotionDegree + 1));
    MotionPolynomial p = random_polynomial(rng, ranges, degree);
    const double off = random_double(rng, ranges.off_min, ranges.off_max);
    const Time t = p.origin + off;
    if (!std::isfinite(t)) continue;
    if (cancel && p.degree >= 1) {
      // Make the constant term cancel the rest (to rounding), plus a few ulps: the exact value
      // is tiny and of either sign, the case where a too-small bound decides wrongly.
      MotionPolynomial rest = p;
      rest.c[0] = 0.0;
      const double r = rest.evaluate(t);
      if (std::isfinite(r) && r != 0.0) {
        const int k = static_cast<int>(rng() % 9) - 4;
        double c0 = -r;
        for (int j = 0; j < std::abs(k); ++j) c0 = std::nextafter(c0, k > 0 ? 1e308 : -1e308);
        p.c[0] = c0;
      }
    }
    if (check_filter(p, t, seed, it, &certain)) ++checked;
    if (::testing::Test::HasFailure()) return;  // one report is enough
  }
  EXPECT_GE(checked, static_cast<int>(min_checked_fraction * iterations))
      << "too few finite cases; seed=" << seed;
  // Not vacuous: the filter does decide (most) well-separated cases.
  EXPECT_GE(certain, static_cast<int>(min_certain_fraction * iterations))
      << "the filter decided too few cases; seed=" << seed;
}

TEST(PolynomialFiltered, BoundHoldsOnModeratePolynomials) {
  run_bound_check(0x5eed1001, Ranges{-30, 30, -20, 20, -30, 30}, 4000, false, 0.99, 0.95);
}

TEST(PolynomialFiltered, BoundHoldsWithCancellation) {
  run_bound_check(0x5eed1002, Ranges{-30, 30, -20, 20, -10, 10}, 4000, true, 0.99);
}

TEST(PolynomialFiltered, BoundHoldsWithHugeAndTinyNormalCoefficients) {
  // Coefficients from 2^-700 to 2^700, s up to 2^45: no overflow, no underflow.
  run_bound_check(0x5eed1003, Ranges{-700, 400, -40, 40, -40, 45}, 4000, false, 0.9);
  run_bound_check(0x5eed1004, Ranges{-700, 400, -40, 40, -40, 45}, 2000, true, 0.9);
}

TEST(PolynomialFiltered, BoundHoldsWithTFarFromOrigin) {
  // Origins around 2^50 and t on the other side: t - origin is rounded.
  run_bound_check(0x5eed1005, Ranges{-20, 20, 40, 55, 40, 56}, 3000, false, 0.99);
  run_bound_check(0x5eed1006, Ranges{-20, 20, 40, 55, 40, 56}, 2000, true, 0.99);
}

TEST(PolynomialFiltered, BoundHoldsNearOverflow) {
  // Large coefficients and |s|: many cases overflow (value or error infinite, not checked);
  // finite ones must still be bounded.
  run_bound_check(0x5eed1007, Ranges{800, 1000, -10, 10, 0, 8}, 2000, false, 0.3);
}

TEST(PolynomialFiltered, BoundHoldsInTheUnderflowRange) {
  // Subnormal and near-underflow coefficients with |s| > 1: a product that underflows loses
  // absolute accuracy ~2^-1075, and later multiplications by s amplify that loss.
  run_bound_check(0x5eed1008, Ranges{-1074, -960, -4, 4, 0, 45}, 4000, false, 0.99);
  run_bound_check(0x5eed1009, Ranges{-1074, -960, -4, 4, 0, 45}, 2000, true, 0.99);
}

TEST(PolynomialFiltered, UnderflowAmplifiedBySLaterStepsIsBounded) {
  // Minimal deterministic case. p(s) = 3 * 2^-1074 * s^6 at s = 2^30 + 1/2 (origin 0).
  // Horner's first product c6 * s = (3 * 2^30 + 1.5) * 2^-1074 is subnormal and rounds to
  // (3 * 2^30 + 2) * 2^-1074: an absolute error of 2^-1075, multiplied by s^5 ~ 2^150 in the
  // later steps, i.e. |value - exact| ~ 2^-925, while sum |c_i||s|^i ~ 2^-892 gives a relative
  // bound of only ~2^-940.
  const double c6 = 3.0 * std::ldexp(1.0, -1074);
  const double t = std::ldexp(1.0, 30) + 0.5;
  std::array<double, 7> c{0, 0, 0, 0, 0, 0, c6};
  const MotionPolynomial p = MotionPolynomial::from(c);
  const FilteredValue f = evaluate_filtered(p, t);
  const mpq_class exact = exact_eval(p, t);
  ASSERT_TRUE(std::isfinite(f.value) && std::isfinite(f.error));
  const mpq_class actual = abs(mpq_class(f.value) - exact);
  EXPECT_LE(cmp(actual, mpq_class(f.error)), 0)
      << std::hexfloat << "value=" << f.value << " error=" << f.error << " |value-exact|~"
      << actual.get_d();

  // The same loss flips a certain sign: make c0 cancel the midpoint of value and exact value.
  const mpq_class mid = (mpq_class(f.value) + exact) / 2;
  c[0] = -mid.get_d();
  const MotionPolynomial q = MotionPolynomial::from(c);
  const FilteredValue g = evaluate_filtered(q, t);
  const int exact_sign = sgn_q(exact_eval(q, t));
  ASSERT_NE(exact_sign, 0);
  const int certain = g.sign_if_certain();
  EXPECT_TRUE(certain == 0 || certain == exact_sign)
      << std::hexfloat << "c0=" << c[0] << " value=" << g.value << " error=" << g.error
      << " sign_if_certain=" << certain << " exact sign=" << exact_sign;
}

}  // namespace
}  // namespace kinetic

namespace kinetic {
namespace {

// ---------------------------------------------------------------------------------------------
// The compensated stage (evaluate_compensated, evaluate_difference_compensated): its bound
// against the exact value, and its sign against the exact sign, on random and adversarial inputs.

/// Checks one compensated result against the exact value. Returns true when it was checkable
/// (hi, lo and error finite); counts certain signs.
bool check_compensated(const CompensatedValue& c, const mpq_class& exact, int* certain,
                       const std::string& where) {
  const int s = c.sign_if_certain();
  if (s != 0) {
    ++*certain;
    EXPECT_EQ(s, sgn_q(exact)) << "compensated sign wrong; " << where << std::hexfloat
                               << " hi=" << c.hi << " lo=" << c.lo << " error=" << c.error;
  }
  if (!std::isfinite(c.hi) || !std::isfinite(c.lo) || !std::isfinite(c.error)) return false;
  const mpq_class actual = abs(mpq_class(c.hi) + mpq_class(c.lo) - exact);
  EXPECT_LE(cmp(actual, mpq_class(c.error)), 0)
      << "compensated bound violated; " << where << std::hexfloat << " hi=" << c.hi
      << " lo=" << c.lo << " error=" << c.error << " |hi+lo-exact|~" << actual.get_d();
  return true;
}

std::string where_is(std::uint64_t seed, int it, const MotionPolynomial& p, Time t) {
  return "seed=" + std::to_string(seed) + " iteration=" + std::to_string(it) + " " +
         describe(p, t);
}

/// c0 := -(exact value of the rest at t, rounded to a double) moved by k ulps, k in [-4, 4]:
/// the exact value is then tiny (a few ulps of c0, or exactly 0) and of either sign, far below
/// what plain Horner can resolve.
void cancel_exactly(std::mt19937_64& rng, MotionPolynomial& p, Time t) {
  if (p.degree < 1) return;
  MotionPolynomial rest = p;
  rest.c[0] = 0.0;
  const double r = exact_eval(rest, t).get_d();
  if (!std::isfinite(r) || r == 0.0) return;
  const int k = static_cast<int>(rng() % 9) - 4;
  double c0 = -r;
  for (int j = 0; j < std::abs(k); ++j) c0 = std::nextafter(c0, k > 0 ? 1e308 : -1e308);
  p.c[0] = c0;
}

struct CompensatedCounts {
  int checked = 0, certain = 0, filter_certain = 0;
};

CompensatedCounts run_compensated_check(std::uint64_t seed, const Ranges& ranges, int iterations,
                                        bool cancel) {
  std::mt19937_64 rng(seed);
  CompensatedCounts n;
  for (int it = 0; it < iterations && !::testing::Test::HasFailure(); ++it) {
    const int degree = static_cast<int>(rng() % (kMaxMotionDegree + 1));
    MotionPolynomial p = random_polynomial(rng, ranges, degree);
    const Time t = p.origin + random_double(rng, ranges.off_min, ranges.off_max);
    if (!std::isfinite(t)) continue;
    if (cancel) cancel_exactly(rng, p, t);
    const mpq_class exact = exact_eval(p, t);
    if (check_compensated(evaluate_compensated(p, t), exact, &n.certain,
                          where_is(seed, it, p, t))) {
      ++n.checked;
    }
    if (evaluate_filtered(p, t).sign_if_certain() != 0) ++n.filter_certain;
  }
  return n;
}

TEST(PolynomialCompensated, BoundHoldsOnModeratePolynomials) {
  const CompensatedCounts n =
      run_compensated_check(0xc0e1001, Ranges{-30, 30, -20, 20, -30, 30}, 4000, false);
  EXPECT_GE(n.checked, 3960);
  EXPECT_GE(n.certain, n.filter_certain);  // never worse than the first stage here
}

TEST(PolynomialCompensated, BoundHoldsAndDecidesUnderHeavyCancellation) {
  // The exact value is a few ulps of c0 (or 0): plain Horner decides almost none of these, the
  // compensated stage most of those whose terms are not much larger than c0.
  const CompensatedCounts n =
      run_compensated_check(0xc0e1002, Ranges{-30, 30, -20, 20, -10, 10}, 6000, true);
  EXPECT_GE(n.checked, 5940);
  EXPECT_GE(n.certain, 3 * n.filter_certain);
  EXPECT_GE(n.certain, 6000 / 3);
}

TEST(PolynomialCompensated, BoundHoldsWithHugeAndTinyNormalCoefficients) {
  run_compensated_check(0xc0e1003, Ranges{-700, 400, -40, 40, -40, 45}, 4000, false);
  run_compensated_check(0xc0e1004, Ranges{-700, 400, -40, 40, -40, 45}, 3000, true);
}

TEST(PolynomialCompensated, BoundHoldsWithTFarFromOrigin) {
  // t - origin is rounded: its error e is carried exactly (TwoSum) through e * p'(s).
  const CompensatedCounts a =
      run_compensated_check(0xc0e1005, Ranges{-20, 20, 40, 55, 40, 56}, 3000, false);
  EXPECT_GE(a.checked, 2970);
  const CompensatedCounts b =
      run_compensated_check(0xc0e1006, Ranges{-20, 20, 40, 55, 40, 56}, 3000, true);
  EXPECT_GE(b.checked, 2970);
}

TEST(PolynomialCompensated, BoundHoldsNearOverflow) {
  const CompensatedCounts n =
      run_compensated_check(0xc0e1007, Ranges{800, 1000, -10, 10, 0, 8}, 2000, false);
  EXPECT_GE(n.checked, 100);
}

TEST(PolynomialCompensated, BoundHoldsInTheUnderflowRange) {
  // Subnormal and near-underflow coefficients: TwoProduct is not exact there, so the stage
  // must either bound the loss or give up (undecided), never decide wrongly.
  run_compensated_check(0xc0e1008, Ranges{-1074, -960, -4, 4, 0, 45}, 4000, false);
  run_compensated_check(0xc0e1009, Ranges{-1074, -960, -4, 4, 0, 45}, 3000, true);
  run_compensated_check(0xc0e100a, Ranges{-1074, -900, -4, 4, -60, 0}, 3000, true);
  // The deterministic case of UnderflowAmplifiedBySLaterStepsIsBounded, with c0 cancelling.
  const double t = std::ldexp(1.0, 30) + 0.5;
  std::array<double, 7> c{0, 0, 0, 0, 0, 0, 3.0 * std::ldexp(1.0, -1074)};
  c[0] = -exact_eval(MotionPolynomial::from(c), t).get_d();
  const MotionPolynomial q = MotionPolynomial::from(c);
  // Here the first product underflows: the stage must give up (TwoProduct is not exact).
  int certain = 0;
  EXPECT_FALSE(check_compensated(evaluate_compensated(q, t), exact_eval(q, t), &certain,
                                 describe(q, t)));
  EXPECT_EQ(certain, 0);
}

/// sum c_i x^i = lead * prod (x - roots_k), expanded in doubles (rounded; the exact polynomial is
/// whatever the doubles say).
MotionPolynomial from_roots(const std::vector<double>& roots, double lead, double origin) {
  std::array<double, kMaxMotionDegree + 1> c{};
  c[0] = lead;
  int n = 0;
  for (double r : roots) {
    for (int i = n + 1; i >= 1; --i) c[i] = c[i - 1] - r * c[i];
    c[0] = -r * c[0];
    ++n;
  }
  return MotionPolynomial::from(std::span<const double>(c.data(), n + 1), origin);
}

TEST(PolynomialCompensated, DecidesGridPointsNearSimpleRootsOfADegreeSixPolynomial) {
  // The case that motivated the stage: six simple roots in [72, 98], origin 0, coefficients up
  // to ~2^38, signs at grid points k 2^-31 near each root. Plain Horner's bound (~1e-2 here)
  // cannot decide them; the compensated one (~1e-16) decides all that are not exact zeros.
  const std::vector<double> roots = {72.25, 77.5, 81.125, 86.75, 91.0625, 97.875};
  for (double origin : {0.0, 50.0, 0x1.91eb851eb851fp+6}) {
    std::vector<double> shifted;  // the roots in s = t - origin (rounded: still near r)
    for (double r : roots) shifted.push_back(r - origin);
    const MotionPolynomial p = from_roots(shifted, 1.25, origin);
    int certain = 0, filter_certain = 0, checked = 0;
    for (double r : roots) {
      for (int k = -40; k <= 40; ++k) {
        const Time t = r + std::ldexp(static_cast<double>(k) + 0.5, -31);
        const mpq_class exact = exact_eval(p, t);
        if (check_compensated(evaluate_compensated(p, t), exact, &certain, describe(p, t))) {
          ++checked;
        }
        if (evaluate_filtered(p, t).sign_if_certain() != 0) ++filter_certain;
      }
    }
    EXPECT_EQ(checked, 6 * 81);
    EXPECT_EQ(certain, 6 * 81) << "origin " << origin;
    if (origin == 0.0) {
      EXPECT_LT(filter_certain, certain / 2);
    }
  }
}

/// The exact a(t) - b(t).
mpq_class exact_difference(const MotionPolynomial& a, const MotionPolynomial& b, Time t) {
  return exact_eval(a, t) - exact_eval(b, t);
}

CompensatedCounts run_difference_check(std::uint64_t seed, const Ranges& ranges, int iterations,
                                       bool same_origin) {
  std::mt19937_64 rng(seed);
  CompensatedCounts n;
  for (int it = 0; it < iterations && !::testing::Test::HasFailure(); ++it) {
    MotionPolynomial a =
        random_polynomial(rng, ranges, static_cast<int>(rng() % (kMaxMotionDegree + 1)));
    MotionPolynomial b =
        random_polynomial(rng, ranges, static_cast<int>(rng() % (kMaxMotionDegree + 1)));
    if (same_origin) b.origin = a.origin;
    const Time t = a.origin + random_double(rng, ranges.off_min, ranges.off_max);
    if (!std::isfinite(t)) continue;
    // Make b cancel a at t: b's constant term := a(t) - (rest of b)(t), rounded, +- ulps. Half
    // of the time b shares a's leading coefficients (as neighbours in a sorted order do).
    if (rng() % 2 == 0) {
      for (int i = 1; i <= std::min(a.degree, b.degree); ++i) {
        if (rng() % 2 == 0) b.c[i] = a.c[i];
      }
    }
    MotionPolynomial rest = b;
    rest.c[0] = 0.0;
    const double target = mpq_class(exact_eval(a, t) - exact_eval(rest, t)).get_d();
    if (std::isfinite(target)) {
      const int k = static_cast<int>(rng() % 9) - 4;
      double c0 = target;
      for (int j = 0; j < std::abs(k); ++j) c0 = std::nextafter(c0, k > 0 ? 1e308 : -1e308);
      b.c[0] = c0;
      b = MotionPolynomial::from(std::span<const double>(b.c.data(), kMaxMotionDegree + 1),
                                 b.origin);
    }
    const std::string where = "seed=" + std::to_string(seed) + " iteration=" +
                              std::to_string(it) + " a: " + describe(a, t) +
                              " b: " + describe(b, t);
    if (check_compensated(evaluate_difference_compensated(a, b, t), exact_difference(a, b, t),
                          &n.certain, where)) {
      ++n.checked;
    }
  }
  return n;
}

/// The difference bound on moderate values (5000 cases seeded with `seed`: at least 4950
/// checked, a quarter certain) and on large origins and offsets (3000 cases, seed + 1).
void check_difference_bound(std::uint64_t seed, bool same_origin) {
  const CompensatedCounts n =
      run_difference_check(seed, Ranges{-30, 30, -20, 20, -30, 30}, 5000, same_origin);
  EXPECT_GE(n.checked, 4950);
  EXPECT_GE(n.certain, 5000 / 4);
  run_difference_check(seed + 1, Ranges{-20, 20, 40, 55, 40, 56}, 3000, same_origin);
}

TEST(PolynomialCompensated, DifferenceBoundHoldsWithDifferentOrigins) {
  check_difference_bound(0xc0e2001, false);
  run_difference_check(0xc0e2003, Ranges{-700, 400, -40, 40, -40, 45}, 3000, false);
}

TEST(PolynomialCompensated, DifferenceBoundHoldsWithTheSameOrigin) {
  check_difference_bound(0xc0e2004, true);
}

TEST(PolynomialCompensated, DifferenceBoundHoldsInTheUnderflowRange) {
  run_difference_check(0xc0e2006, Ranges{-1074, -960, -4, 4, 0, 45}, 3000, false);
  run_difference_check(0xc0e2007, Ranges{-1074, -960, -4, 4, 0, 45}, 3000, true);
  run_difference_check(0xc0e2008, Ranges{800, 1000, -10, 10, 0, 8}, 2000, false);
}

TEST(PolynomialCompensated, ExactCasesAndSignRules) {
  // Constants and t == origin are exact (error 0).
  const MotionPolynomial k = MotionPolynomial::constant(-0x1p-1074);
  EXPECT_EQ(evaluate_compensated(k, 12.0).error, 0.0);
  const std::array<double, 3> c{0.0, 3.0, -1.0};
  const MotionPolynomial p = MotionPolynomial::from(c, 7.5);
  const CompensatedValue at_origin = evaluate_compensated(p, 7.5);
  EXPECT_EQ(at_origin.hi, 0.0);
  EXPECT_EQ(at_origin.error, 0.0);
  EXPECT_EQ(at_origin.sign_if_certain(), 0);  // an exact zero is never "certain"
  // Non-finite parts are never certain.
  EXPECT_EQ((CompensatedValue{std::numeric_limits<double>::infinity(), 0.0, 0.0}).sign_if_certain(),
            0);
  EXPECT_EQ((CompensatedValue{1.0, 0.0, std::numeric_limits<double>::infinity()}).sign_if_certain(),
            0);
  EXPECT_EQ((CompensatedValue{1.0, -0.5, 0.25}).sign_if_certain(), 1);
  EXPECT_EQ((CompensatedValue{-1.0, 0.5, 0.25}).sign_if_certain(), -1);
  EXPECT_EQ((CompensatedValue{1.0, -0.5, 0.5}).sign_if_certain(), 0);
}

}  // namespace
}  // namespace kinetic

namespace kinetic {
namespace {

// ---------------------------------------------------------------------------------------------
// taylor_compensated and bernstein_compensated (the first try of CROP's exact Bernstein
// fallback) against exact rational Taylor and Bernstein coefficients.

mpq_class binomial_q(int n, int k) {
  mpq_class r = 1;
  for (int i = 1; i <= k; ++i) r = r * (n - k + i) / i;
  return r;
}

/// Exact Taylor coefficients of p at t: d_k = sum_{i >= k} C(i, k) c_i (t - origin)^(i - k).
std::array<mpq_class, kMaxMotionDegree + 1> exact_taylor_at(const MotionPolynomial& p, Time t) {
  const mpq_class s = mpq_class(t) - mpq_class(p.origin);
  std::array<mpq_class, kMaxMotionDegree + 1> d;
  for (int k = 0; k <= kMaxMotionDegree; ++k) {
    d[k] = 0;
    mpq_class sp = 1;
    for (int i = k; i <= p.degree; ++i) {
      d[k] += binomial_q(i, k) * mpq_class(p.c[i]) * sp;
      sp *= s;
    }
  }
  return d;
}

/// Exact gamma_i = sum_{k <= i} C(n - k, i - k) d_k w^k for f = a - b on [lo, hi].
std::array<mpq_class, kMaxMotionDegree + 1> exact_gamma(const MotionPolynomial& a,
                                                        const MotionPolynomial& b, int n, Time lo,
                                                        Time hi) {
  const auto da = exact_taylor_at(a, lo), db = exact_taylor_at(b, lo);
  const mpq_class w = mpq_class(hi) - mpq_class(lo);
  std::array<mpq_class, kMaxMotionDegree + 1> gamma;
  for (int i = 0; i <= n; ++i) {
    mpq_class g = 0, wk = 1;
    for (int k = 0; k <= i; ++k) {
      g += binomial_q(n - k, i - k) * (da[k] - db[k]) * wk;
      wk *= w;
    }
    gamma[i] = g;
  }
  return gamma;
}

std::array<int, kMaxMotionDegree + 1> exact_bernstein(const MotionPolynomial& a,
                                                      const MotionPolynomial& b, int n, Time lo,
                                                      Time hi) {
  const auto gamma = exact_gamma(a, b, n, lo, hi);
  std::array<int, kMaxMotionDegree + 1> signs{};
  for (int i = 0; i <= n; ++i) signs[i] = sgn(gamma[i]);
  return signs;
}

/// Moves a.c[0] so that gamma_i of a - b on [lo, hi] (which changes by C(n, i) times the change
/// of c_0) becomes tiny: a few ulps of c_0 times C(n, i), of either sign, or 0.
void cancel_gamma(std::mt19937_64& rng, MotionPolynomial& a, const MotionPolynomial& b, Time lo,
                  Time hi) {
  const int n = std::max(a.degree, b.degree);
  if (n < 1) return;
  const int i = static_cast<int>(rng() % static_cast<unsigned>(n + 1));
  const mpq_class g = exact_gamma(a, b, n, lo, hi)[i];
  const double c0 = mpq_class(mpq_class(a.c[0]) - g / binomial_q(n, i)).get_d();
  if (!std::isfinite(c0)) return;
  const int k = static_cast<int>(rng() % 7) - 3;
  double v = c0;
  for (int j = 0; j < std::abs(k); ++j) v = std::nextafter(v, k > 0 ? 1e308 : -1e308);
  a.c[0] = v;
}

TEST(PolynomialCompensated, TaylorCoefficientBoundsHold) {
  const std::uint64_t seed = 0xc0e3001;
  std::mt19937_64 rng(seed);
  const Ranges ranges[] = {Ranges{-30, 30, -20, 20, -30, 30}, Ranges{-20, 20, 40, 55, 40, 56},
                           Ranges{-700, 400, -40, 40, -40, 45},
                           Ranges{-1074, -960, -4, 4, 0, 45}, Ranges{800, 1000, -10, 10, 0, 8}};
  int checked = 0, certain = 0;
  for (int it = 0; it < 5000 && !HasFailure(); ++it) {
    const Ranges& r = ranges[it % 5];
    MotionPolynomial p =
        random_polynomial(rng, r, static_cast<int>(rng() % (kMaxMotionDegree + 1)));
    const Time t = p.origin + random_double(rng, r.off_min, r.off_max);
    if (!std::isfinite(t)) continue;
    if (rng() % 2 == 0) cancel_exactly(rng, p, t);
    std::array<CompensatedValue, kMaxMotionDegree + 1> d;
    taylor_compensated(p, t, d);
    const auto exact = exact_taylor_at(p, t);
    for (int k = 0; k <= kMaxMotionDegree; ++k) {
      if (check_compensated(d[k], exact[k], &certain,
                            where_is(seed, it, p, t) + " k=" + std::to_string(k))) {
        ++checked;
      }
    }
  }
  EXPECT_GE(checked, 5000 * 7 / 2);
  EXPECT_GE(certain, 5000 * 2);
}

/// Compares bernstein_compensated's bounds and certified signs with the exact ones on (a, b, [lo, hi]); counts the
/// boxes it decided.
void check_bernstein(const MotionPolynomial& a, const MotionPolynomial& b, Time lo, Time hi,
                     int* decided, const std::string& where) {
  const int n = std::max(a.degree, b.degree);
  // The bound of every coefficient against the exact one.
  std::array<CompensatedValue, kMaxMotionDegree + 1> gamma;
  if (bernstein_compensated(a, b, n, lo, hi, gamma)) {
    const auto exact_values = exact_gamma(a, b, n, lo, hi);
    int unused = 0;
    for (int i = 0; i <= n; ++i) {
      check_compensated(gamma[i], exact_values[i], &unused, where + " gamma_" + std::to_string(i));
    }
  }
  std::array<int, kMaxMotionDegree + 1> signs{};
  if (!bernstein_compensated(a, b, n, lo, hi, gamma)) return;
  for (int i = 0; i <= n; ++i) {
    signs[i] = gamma[i].sign_if_certain();
    if (signs[i] == 0) return;  // not certified: CROP decides the box exactly
  }
  ++*decided;
  const auto exact = exact_bernstein(a, b, n, lo, hi);
  for (int i = 0; i <= n; ++i) {
    ASSERT_EQ(signs[i], exact[i]) << where << " i=" << i << std::hexfloat << " lo=" << lo
                                  << " hi=" << hi << " b: " << describe(b, lo);
  }
}

TEST(PolynomialCompensated, BernsteinSignsAreExactWhenCertified) {
  const std::uint64_t seed = 0xc0e3002;
  std::mt19937_64 rng(seed);
  const Ranges ranges[] = {Ranges{-30, 30, -20, 20, -30, 30}, Ranges{-20, 20, 40, 55, 40, 56},
                           Ranges{-700, 400, -40, 40, -40, 45},
                           Ranges{-1074, -960, -4, 4, 0, 45}};
  int decided = 0;
  for (int it = 0; it < 20000 && !HasFailure(); ++it) {
    const Ranges& r = ranges[it % 4];
    MotionPolynomial a =
        random_polynomial(rng, r, static_cast<int>(rng() % (kMaxMotionDegree + 1)));
    MotionPolynomial b = it % 3 == 0 ? MotionPolynomial::constant(0.0)
                                     : random_polynomial(rng, r, static_cast<int>(rng() % 4));
    if (it % 3 == 1) b.origin = a.origin;
    const Time lo = a.origin + random_double(rng, r.off_min, r.off_max);
    const Time hi = lo + std::fabs(random_double(rng, -40, 2));
    if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo < hi)) continue;
    if (it % 2 == 0) cancel_gamma(rng, a, b, lo, hi);  // adversarial: one gamma_i ~ 0
    check_bernstein(a, b, lo, hi, &decided, where_is(seed, it, a, lo));
  }
  EXPECT_GE(decided, 20000 / 5);
}

TEST(PolynomialCompensated, BernsteinSignsNearCloseRootsOnTheGrid) {
  // Boxes of the 2^-30 grid around a pair of roots 2^-40 apart, a root on a box end, and a
  // double root, for CROP's two ways of writing f: one motion against zero, and two motions
  // with different origins whose difference has those roots.
  const std::uint64_t seed = 0xc0e3003;
  std::mt19937_64 rng(seed);
  const double w = 0x1p-30;
  int decided = 0;
  for (int it = 0; it < 3000 && !HasFailure(); ++it) {
    const double origin = std::ldexp(std::floor(std::ldexp(static_cast<double>(rng() % 100), 10)), -10);
    const double gap = (it % 3 == 0) ? 0.0 : std::ldexp(1.0, -static_cast<int>(20 + rng() % 30));
    std::vector<double> roots = {0.0, gap};  // in s = t - origin
    const int extra = static_cast<int>(rng() % 5);
    for (int k = 0; k < extra; ++k) roots.push_back(random_double(rng, -4, 6));
    const MotionPolynomial a = from_roots(roots, random_double(rng, -2, 2), origin);
    const std::int64_t j0 = static_cast<std::int64_t>(std::floor(origin / w)) -
                            static_cast<std::int64_t>(rng() % 64);
    const std::int64_t len = 1 + static_cast<std::int64_t>(rng() % 128);
    const Time lo = (static_cast<double>(j0) + 0.5) * w;
    const Time hi = (static_cast<double>(j0 + len) + 0.5) * w;
    check_bernstein(a, MotionPolynomial::constant(0.0), lo, hi, &decided, "vs zero");
    // f = a - b with b a line at another origin (the different-origin path).
    const std::vector<double> cb = {random_double(rng, -3, 6), random_double(rng, -3, 2)};
    const MotionPolynomial b = MotionPolynomial::from(cb, 0x1.8p5);
    check_bernstein(a, b, lo, hi, &decided, "vs a line");
  }
  EXPECT_GE(decided, 3000 / 2);
}

}  // namespace
}  // namespace kinetic
