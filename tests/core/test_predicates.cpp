// The exact predicates (sign_at, compare_at, compare_after, find_time_below, value_at) against an
// independent exact oracle written here: rational (GMP) Horner for values and a binomial
// re-expansion for Taylor coefficients -- no code shared with the library.

#include "kinetic/core/predicates.hpp"

#include <gmpxx.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace kinetic {
namespace {

// ---------------------------------------------------------------------------------------------
// Oracle.

using Q = mpq_class;
using QPoly = std::vector<Q>;  // ascending coefficients

Q exact_eval(const MotionPolynomial& p, Time t) {
  const Q s = Q(t) - Q(p.origin);
  Q v(p.c[p.degree]);
  for (int i = p.degree - 1; i >= 0; --i) v = v * s + Q(p.c[i]);
  return v;
}

Q binomial(int n, int k) {
  Q r = 1;
  for (int i = 1; i <= k; ++i) r = r * (n - k + i) / i;
  return r;
}

/// q(x) = sum_k T[k] (x + delta)^k, expanded: the coefficients of the same function about a point
/// moved by -delta (used both for Taylor coefficients and for changing origins).
QPoly reexpand(const QPoly& T, const Q& delta) {
  QPoly out(T.size(), Q(0));
  for (std::size_t k = 0; k < T.size(); ++k) {
    Q dp = 1;  // delta^(k - i), built for i = k down to 0
    for (std::size_t j = 0; j <= k; ++j) {
      const std::size_t i = k - j;
      out[i] += T[k] * binomial(static_cast<int>(k), static_cast<int>(i)) * dp;
      dp *= delta;
    }
  }
  return out;
}

QPoly coefficients(const MotionPolynomial& p) {
  QPoly c;
  for (int i = 0; i <= kMaxMotionDegree; ++i) c.emplace_back(p.c[i]);
  return c;
}

/// Exact Taylor coefficients of p at t: p(t + h) = sum_k out[k] h^k.
QPoly exact_taylor(const MotionPolynomial& p, Time t) {
  return reexpand(coefficients(p), Q(t) - Q(p.origin));
}

/// sign(a - b) just after t, from the oracle's Taylor coefficients.
int oracle_after(const MotionPolynomial& a, const MotionPolynomial& b, Time t) {
  const QPoly ta = exact_taylor(a, t), tb = exact_taylor(b, t);
  for (std::size_t k = 0; k < ta.size(); ++k) {
    const int s = sgn(Q(ta[k] - tb[k]));
    if (s != 0) return s;
  }
  return 0;
}

bool representable(const Q& q) {
  const double d = q.get_d();
  return std::isfinite(d) && Q(d) == q;
}

/// The polynomial with exact coefficients c about origin, if every coefficient is a double.
std::optional<MotionPolynomial> to_motion(const QPoly& c, double origin) {
  if (c.size() > static_cast<std::size_t>(kMaxMotionDegree) + 1) {
    for (std::size_t i = kMaxMotionDegree + 1; i < c.size(); ++i) {
      if (sgn(c[i]) != 0) return std::nullopt;
    }
  }
  std::array<double, kMaxMotionDegree + 1> d{};
  for (std::size_t i = 0; i < c.size() && i <= static_cast<std::size_t>(kMaxMotionDegree); ++i) {
    if (!representable(c[i])) return std::nullopt;
    d[i] = c[i].get_d();
  }
  return MotionPolynomial::from(d, origin);
}

QPoly multiply(const QPoly& a, const QPoly& b) {
  QPoly out(a.size() + b.size() - 1, Q(0));
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t j = 0; j < b.size(); ++j) out[i + j] += a[i] * b[j];
  return out;
}

QPoly add(QPoly a, const QPoly& b) {
  if (a.size() < b.size()) a.resize(b.size(), Q(0));
  for (std::size_t i = 0; i < b.size(); ++i) a[i] += b[i];
  return a;
}

std::string describe(const MotionPolynomial& p) {
  std::ostringstream os;
  os << std::hexfloat << "{origin=" << p.origin << " c=[";
  for (int i = 0; i <= p.degree; ++i) os << (i ? ", " : "") << p.c[i];
  os << "]}";
  return os.str();
}

std::string hex(double t) {
  std::ostringstream os;
  os << std::hexfloat << t;
  return os.str();
}

double random_double(std::mt19937_64& rng, int emin, int emax) {
  std::uniform_int_distribution<int> ex(emin, emax);
  std::uint64_t mant = rng() & ((std::uint64_t{1} << 53) - 1);
  if (rng() % 4 == 0) mant &= ~((std::uint64_t{1} << 45) - 1);
  mant |= std::uint64_t{1} << 52;
  const double v = std::ldexp(std::ldexp(static_cast<double>(mant), -53), ex(rng));
  return (rng() & 1) ? -v : v;
}

int rand_int(std::mt19937_64& rng, int lo, int hi) {
  return std::uniform_int_distribution<int>(lo, hi)(rng);
}

/// A small dyadic k / 2^shift with |k| <= range.
Q small_dyadic(std::mt19937_64& rng, int range, int shift) {
  Q q(rand_int(rng, -range, range));
  for (int i = 0; i < shift; ++i) q /= 2;
  return q;
}

MotionPolynomial random_polynomial(std::mt19937_64& rng, int emin, int emax, double origin) {
  const int degree = rand_int(rng, 0, kMaxMotionDegree);
  std::array<double, kMaxMotionDegree + 1> c{};
  for (int i = 0; i <= degree; ++i) c[i] = (rng() % 6 == 0) ? 0.0 : random_double(rng, emin, emax);
  if (c[degree] == 0.0) c[degree] = 1.0;
  return MotionPolynomial::from(c, origin);
}

/// Checks sign_at against the oracle; counts the calls in `calls`.
void check_sign_at(const MotionPolynomial& p, Time t, PredicateStats& stats, std::uint64_t& calls,
                   const std::string& where) {
  const int expected = sgn(exact_eval(p, t));
  ++calls;
  EXPECT_EQ(sign_at(p, t, &stats), expected) << where << " p=" << describe(p) << " t=" << hex(t);
}

void check_compare_at(const MotionPolynomial& a, const MotionPolynomial& b, Time t,
                      PredicateStats& stats, std::uint64_t& calls, const std::string& where) {
  const int expected = sgn(Q(exact_eval(a, t) - exact_eval(b, t)));
  ++calls;
  EXPECT_EQ(compare_at(a, b, t, &stats), expected)
      << where << " a=" << describe(a) << " b=" << describe(b) << " t=" << hex(t);
  // Antisymmetry.
  EXPECT_EQ(compare_at(b, a, t), -expected) << where;
}

std::string where(std::uint64_t seed, int it) {
  return "seed=" + std::to_string(seed) + " it=" + std::to_string(it);
}

/// The decisions of a random run: the predicates' statistics and the calls made.
struct Decisions {
  PredicateStats stats;
  std::uint64_t calls = 0;
};

/// `iterations` random cases from an rng seeded with `seed`, until one fails: case_at(rng, stats,
/// calls, where(seed, it)) checks predicates against the oracle, counting its calls. Every call
/// must then be in the statistics once, filtered or exact.
template <class Case>
Decisions random_decisions(std::uint64_t seed, int iterations, const Case& case_at) {
  std::mt19937_64 rng(seed);
  Decisions d;
  for (int it = 0; it < iterations && !::testing::Test::HasFailure(); ++it) {
    case_at(rng, d.stats, d.calls, where(seed, it));
  }
  EXPECT_EQ(d.stats.filtered + d.stats.exact, d.calls);
  return d;
}

// ---------------------------------------------------------------------------------------------
// sign_at / compare_at: fixed cases.

TEST(PredicatesSignAt, KnownExactZeros) {
  PredicateStats stats;
  const std::vector<double> sq = {9.0, -6.0, 1.0};  // (t-3)^2
  const MotionPolynomial p = MotionPolynomial::from(sq);
  EXPECT_EQ(sign_at(p, 3.0, &stats), 0);
  EXPECT_EQ(stats.exact, 1u);  // a zero can only be decided exactly
  EXPECT_EQ(sign_at(p, std::nextafter(3.0, 4.0)), 1);
  EXPECT_EQ(sign_at(p, std::nextafter(3.0, 2.0)), 1);
  EXPECT_EQ(sign_at(p, 100.0, &stats), 1);
  EXPECT_EQ(stats.filtered, 1u);

  // -(t-1)^3 about origin 1: zero at 1, negative just after, positive just before.
  const std::vector<double> cube = {0.0, 0.0, 0.0, -1.0};
  const MotionPolynomial c = MotionPolynomial::from(cube, 1.0);
  EXPECT_EQ(sign_at(c, 1.0), 0);
  EXPECT_EQ(sign_at(c, std::nextafter(1.0, 2.0)), -1);
  EXPECT_EQ(sign_at(c, std::nextafter(1.0, 0.0)), 1);

  // The zero polynomial is zero everywhere.
  EXPECT_EQ(sign_at(MotionPolynomial::constant(0.0), -7.5), 0);
  EXPECT_EQ(sign_at(MotionPolynomial::constant(-0.0), 1e300), 0);

  // (t - 0.1)(t - 0.3) with the roots 0.1 and 0.3 as doubles: zeros exactly at those doubles.
  const double r1 = 0.1, r2 = 0.3;
  const Q prod = Q(r1) * Q(r2);
  ASSERT_FALSE(representable(prod));  // the product is not a double: not an exact polynomial
  // ... so use the factored form about origin r1: (t - r1)(t - r1 - (r2 - r1)).
  const Q d = Q(r2) - Q(r1);
  ASSERT_TRUE(representable(d));
  const std::vector<double> f = {0.0, -d.get_d(), 1.0};
  const MotionPolynomial g = MotionPolynomial::from(f, r1);
  EXPECT_EQ(sign_at(g, r1), 0);
  EXPECT_EQ(sign_at(g, r2), 0);
  EXPECT_EQ(sign_at(g, 0.2), -1);
  EXPECT_EQ(sign_at(g, std::nextafter(r2, 1.0)), 1);
  EXPECT_EQ(sign_at(g, std::nextafter(r2, 0.0)), -1);
}

TEST(PredicatesCompareAt, IdenticalFunctionsWithDifferentOrigins) {
  // 1 + 2t + 3t^2 == 17 + 14 (t-2) + 3 (t-2)^2.
  const std::vector<double> ca = {1.0, 2.0, 3.0};
  const std::vector<double> cb = {17.0, 14.0, 3.0};
  const MotionPolynomial a = MotionPolynomial::from(ca, 0.0);
  const MotionPolynomial b = MotionPolynomial::from(cb, 2.0);
  for (double t : {-1e6, -3.25, 0.0, 1.0 / 3.0, 2.0, 1e-300, 12345.678}) {
    EXPECT_EQ(compare_at(a, b, t), 0) << t;
    EXPECT_EQ(compare_after(a, b, t), 0) << t;
  }
}

TEST(PredicatesCompareAt, StatsCountEveryDecision) {
  PredicateStats stats;
  const std::vector<double> ca = {1.0, 1.0};
  const MotionPolynomial a = MotionPolynomial::from(ca);
  const MotionPolynomial b = MotionPolynomial::constant(3.0);
  EXPECT_EQ(compare_at(a, b, 0.0, &stats), -1);
  EXPECT_EQ(compare_at(a, b, 2.0, &stats), 0);
  EXPECT_EQ(compare_at(a, b, 5.0, &stats), 1);
  EXPECT_EQ(stats.filtered + stats.exact, 3u);
  EXPECT_GE(stats.exact, 1u);  // the tie at 2
  EXPECT_GE(stats.filtered, 1u);
}

TEST(PredicatesStages, CompensatedStageDecidesNearRootsWithoutGmp) {
  // p = (t - 72.25)(t - 77.5)(t - 81)(t - 86.75)(t - 91.5)(t - 97) expanded exactly (every
  // coefficient of the exact product is an integer times 2^-6 below 2^53: a double), origin
  // 0, at the grid points (j + 1/2) 2^-31 nearest each root: plain Horner's bound (~1e-2)
  // cannot decide these signs, the compensated stage does, GMP is never needed, and the signs
  // are the oracle's. Then the same against a motion with another origin.
  const std::vector<Q> roots = {Q(289, 4), Q(155, 2), Q(81), Q(347, 4), Q(183, 2), Q(97)};
  QPoly c = {Q(1)};
  for (const Q& r : roots) c = multiply(c, QPoly{-r, Q(1)});
  const std::optional<MotionPolynomial> p = to_motion(c, 0.0);
  ASSERT_TRUE(p.has_value());
  // The same function about origin 37.5 (exact re-expansion: still dyadic doubles).
  const std::optional<MotionPolynomial> p37 = to_motion(reexpand(c, Q(75, 2)), 37.5);
  ASSERT_TRUE(p37.has_value());
  const std::vector<double> cb = {-3.0, 0.25};
  const MotionPolynomial line = MotionPolynomial::from(cb, 12.125);  // crosses p too
  PredicateStats stats, cmp_stats;
  std::uint64_t calls = 0, cmp_calls = 0;
  for (const Q& r : roots) {
    const double root = r.get_d();
    for (int k = -8; k <= 8; ++k) {
      const Time t = root + std::ldexp(static_cast<double>(k) + 0.5, -31);
      check_sign_at(*p, t, stats, calls, "near root " + hex(root));
      check_compare_at(*p, MotionPolynomial::constant(0.0), t, cmp_stats, cmp_calls, "vs zero");
      check_compare_at(*p, line, t, cmp_stats, cmp_calls, "vs line");
    }
  }
  EXPECT_EQ(stats.exact, 0u);
  EXPECT_EQ(stats.filtered, calls);
  EXPECT_GE(stats.compensated, calls / 2);
  EXPECT_LE(stats.compensated, stats.filtered);
  EXPECT_EQ(cmp_stats.exact, 0u);
  EXPECT_GE(cmp_stats.compensated, cmp_calls / 2);
  // Equal functions with different origins: a tie everywhere, left to GMP, never decided
  // wrongly by the compensated stage.
  PredicateStats tie_stats;
  std::uint64_t tie_calls = 0;
  for (const Q& r : roots) {
    const Time t = r.get_d() + 0x1p-31;
    check_compare_at(*p, *p37, t, tie_stats, tie_calls, "equal functions");
  }
  EXPECT_EQ(tie_stats.exact, tie_calls);
}

// ---------------------------------------------------------------------------------------------
// sign_at / compare_at: random cases against the oracle (>= 10^4 decisions in all).

TEST(PredicatesSignAt, RandomGeneralCases) {
  const Decisions d =
      random_decisions(0x9e3779b97f4a7c15ull, 2500,
                       [](std::mt19937_64& rng, PredicateStats& stats, std::uint64_t& calls,
                          const std::string& what) {
                         const double origin = (rng() % 4 == 0) ? 0.0 : random_double(rng, -10, 30);
                         const MotionPolynomial p = random_polynomial(rng, -40, 40, origin);
                         const double t = (rng() % 2) ? origin + random_double(rng, -30, 20)
                                                      : random_double(rng, -10, 30);
                         check_sign_at(p, t, stats, calls, what);
                       });
  EXPECT_GT(d.stats.filtered, d.calls / 2);  // the filter does its job on generic inputs
}

TEST(PredicatesSignAt, RandomExactZerosAndNeighbours) {
  // p = lead * prod (s - r_i) with dyadic roots (some repeated) about a dyadic origin: exactly
  // zero at t = origin + r_i; at the next doubles on either side the value is tiny.
  const std::uint64_t seed = 20240601;
  std::mt19937_64 rng(seed);
  PredicateStats stats;
  std::uint64_t calls = 0, zeros = 0;
  for (int it = 0; it < 1500 && !HasFailure(); ++it) {
    const int degree = rand_int(rng, 1, kMaxMotionDegree);
    std::vector<Q> roots;
    QPoly poly = {Q(rand_int(rng, 1, 7) * (rng() % 2 ? 1 : -1))};
    const int lead_shift = rand_int(rng, -8, 8);
    for (int i = 0; i < std::abs(lead_shift); ++i)
      poly[0] = lead_shift > 0 ? Q(poly[0] * 2) : Q(poly[0] / 2);
    for (int i = 0; i < degree; ++i) {
      const Q r = (!roots.empty() && rng() % 4 == 0) ? roots[rng() % roots.size()]
                                                     : small_dyadic(rng, 40, 2);
      roots.push_back(r);
      poly = multiply(poly, QPoly{-r, Q(1)});
    }
    const double origin = (rng() % 3 == 0) ? 0.0 : small_dyadic(rng, 1 << 20, 3).get_d();
    const auto p = to_motion(poly, origin);
    if (!p) continue;
    for (const Q& r : roots) {
      const Q tq = Q(origin) + r;
      ASSERT_TRUE(representable(tq));
      const double t = tq.get_d();
      check_sign_at(*p, t, stats, calls, where(seed, it) + " (root)");
      EXPECT_EQ(sign_at(*p, t), 0) << where(seed, it);
      ++zeros;
      check_sign_at(*p, std::nextafter(t, kTimeInfinity), stats, calls,
                    where(seed, it) + " (next up)");
      check_sign_at(*p, std::nextafter(t, kTimeMinusInfinity), stats, calls,
                    where(seed, it) + " (next down)");
    }
    check_sign_at(*p, origin + small_dyadic(rng, 1000, 3).get_d(), stats, calls, where(seed, it));
  }
  EXPECT_GE(zeros, 2000u);
  EXPECT_GE(stats.exact, zeros);  // every exact zero went to the exact fallback
  EXPECT_EQ(stats.filtered + stats.exact, calls);
}

TEST(PredicatesSignAt, RandomCancellationHeavyCases) {
  // Expanded (s - a)^d with a close to 1 (rounded coefficients) evaluated next to a, and
  // polynomials whose constant term cancels the rest to a few ulps. Most values are far below
  // the filter's error bound; those the filter does decide must be right.
  const Decisions d = random_decisions(
      777001, 1500,
      [](std::mt19937_64& rng, PredicateStats& stats, std::uint64_t& calls,
         const std::string& what) {
        const int degree = rand_int(rng, 2, kMaxMotionDegree);
        const double a =
            1.0 + std::ldexp(static_cast<double>(rand_int(rng, 1, 1000)), -rand_int(rng, 20, 45));
        std::array<double, kMaxMotionDegree + 1> c{};
        for (int i = 0; i <= degree; ++i) {
          c[i] = binomial(degree, i).get_d() * std::pow(-a, degree - i);
        }
        const double origin = (rng() % 2) ? 0.0 : random_double(rng, 0, 20);
        const MotionPolynomial p = MotionPolynomial::from(c, origin);
        double t = origin + a;
        for (int k = rand_int(rng, -50, 50); k != 0; k += (k > 0 ? -1 : 1)) {
          t = std::nextafter(t, k > 0 ? kTimeInfinity : kTimeMinusInfinity);
        }
        check_sign_at(p, t, stats, calls, what + " (power)");

        // Constant term cancelling the rest at t, up to a few ulps.
        MotionPolynomial q = random_polynomial(rng, -20, 20, random_double(rng, -5, 25));
        if (q.degree == 0) return;
        const double tq = q.origin + random_double(rng, -10, 10);
        MotionPolynomial rest = q;
        rest.c[0] = 0.0;
        double c0 = -rest.evaluate(tq);
        for (int k = rand_int(rng, -3, 3); k != 0; k += (k > 0 ? -1 : 1)) {
          c0 = std::nextafter(c0, k > 0 ? 1e308 : -1e308);
        }
        q.c[0] = c0;
        check_sign_at(q, tq, stats, calls, what + " (cancel)");
      });
  EXPECT_GT(d.stats.exact, 0u);  // these do reach the exact fallback
}

TEST(PredicatesCompareAt, RandomCasesWithDifferentOrigins) {
  // b is a re-expanded about another origin (exactly), plus a perturbation of 0 or a few ulps
  // of its constant term; and a = B + P where P has known roots, so a and b tie exactly there.
  const std::uint64_t seed = 4242;
  std::mt19937_64 rng(seed);
  PredicateStats stats;
  std::uint64_t calls = 0, ties = 0, made = 0;
  for (int it = 0; it < 2500 && !HasFailure(); ++it) {
    const double base = small_dyadic(rng, 1 << 22, 3).get_d();
    const Q oa = Q(base) + small_dyadic(rng, 64, 3);
    const Q ob(base);
    const int degree = rand_int(rng, 0, kMaxMotionDegree);
    QPoly B;
    for (int i = 0; i <= degree; ++i) B.push_back(small_dyadic(rng, 64, 4));
    // P = prod (x - r_i) about oa, degree <= 6 - 0.
    const int pd = rand_int(rng, 1, kMaxMotionDegree);
    QPoly P = {Q(rng() % 2 ? 1 : -1)};
    std::vector<Q> roots;
    for (int i = 0; i < pd; ++i) {
      roots.push_back(small_dyadic(rng, 40, 2));
      P = multiply(P, QPoly{-roots.back(), Q(1)});
    }
    const QPoly B_at_a = reexpand(B, Q(oa - ob));  // B about oa
    const auto a = to_motion(add(B_at_a, P), oa.get_d());
    const auto b = to_motion(B, ob.get_d());
    const auto b_shifted = to_motion(B_at_a, oa.get_d());
    if (!a || !b || !b_shifted) continue;
    ++made;
    const std::string w = where(seed, it);
    // b and b_shifted are the same function.
    const double tr = base + small_dyadic(rng, 2000, 3).get_d();
    check_compare_at(*b, *b_shifted, tr, stats, calls, w + " (same function)");
    EXPECT_EQ(compare_at(*b, *b_shifted, tr), 0) << w;
    // Perturbed constant term: never a tie.
    MotionPolynomial bp = *b_shifted;
    const int k = rand_int(rng, 1, 3) * (rng() % 2 ? 1 : -1);
    for (int j = 0; j < std::abs(k); ++j) bp.c[0] = std::nextafter(bp.c[0], k > 0 ? 1e308 : -1e308);
    check_compare_at(bp, *b, tr, stats, calls, w + " (perturbed)");
    EXPECT_EQ(compare_at(bp, *b, tr), k > 0 ? 1 : -1) << w;
    // Exact ties at the roots of P, and their neighbours.
    for (const Q& r : roots) {
      const Q tq = oa + r;
      ASSERT_TRUE(representable(tq));
      const double t = tq.get_d();
      check_compare_at(*a, *b, t, stats, calls, w + " (tie)");
      ++ties;
      check_compare_at(*a, *b, std::nextafter(t, kTimeInfinity), stats, calls, w + " (tie+)");
      check_compare_at(*a, *b, std::nextafter(t, kTimeMinusInfinity), stats, calls, w + " (tie-)");
    }
  }
  EXPECT_GE(made, 1500u);
  EXPECT_GE(ties, 3000u);
  EXPECT_EQ(stats.filtered + stats.exact, calls);
}

TEST(PredicatesCompareAt, RandomGeneralPairsIncludingHugeValues) {
  random_decisions(99991, 1500,
                   [](std::mt19937_64& rng, PredicateStats& stats, std::uint64_t& calls,
                      const std::string& what) {
                     const int e = (rng() % 3 == 0) ? 200 : 20;
                     const MotionPolynomial a =
                         random_polynomial(rng, -e, e, random_double(rng, -5, 40));
                     MotionPolynomial b = random_polynomial(rng, -e, e, random_double(rng, -5, 40));
                     const double t = a.origin + random_double(rng, -20, 20);
                     if (rng() % 2) {
                       // Make b(t) equal a(t) to rounding: cancellation in a - b.
                       const double av = a.evaluate(t);
                       b.c[0] = 0.0;
                       const double bv = b.evaluate(t);
                       if (std::isfinite(av - bv)) b.c[0] = av - bv;
                     }
                     check_compare_at(a, b, t, stats, calls, what);
                   });
}

// ---------------------------------------------------------------------------------------------
// The filter's underflow case (see PolynomialFiltered.UnderflowAmplifiedBySLaterStepsIsBounded):
// the predicates must stay exact with subnormal coefficients.

TEST(PredicatesSignAt, SubnormalCoefficientsStayExact) {
  // p(s) = c0 + 3 * 2^-1074 * s^6 at s = 2^30 + 1/2, c0 chosen between the rounded and the
  // exact value of the s^6 term: the exact sign is -1.
  const double c6 = 3.0 * std::ldexp(1.0, -1074);
  const double t = std::ldexp(1.0, 30) + 0.5;
  const Q top = Q(c6) * Q(t) * Q(t) * Q(t) * Q(t) * Q(t) * Q(t);
  std::array<double, 7> c{0, 0, 0, 0, 0, 0, c6};
  const MotionPolynomial mono = MotionPolynomial::from(c);
  const Q rounded(evaluate_filtered(mono, t).value);
  c[0] = -Q((rounded + top) / 2).get_d();
  const MotionPolynomial p = MotionPolynomial::from(c);
  const int expected = sgn(exact_eval(p, t));
  ASSERT_NE(expected, 0);
  EXPECT_EQ(sign_at(p, t), expected) << describe(p) << " t=" << hex(t);
  // Same thing through compare_at: p vs 0, and the s^6 term vs -c0.
  EXPECT_EQ(compare_at(p, MotionPolynomial::constant(0.0), t), expected);
  EXPECT_EQ(compare_at(mono, MotionPolynomial::constant(-c[0]), t), expected);
}

TEST(PredicatesSignAt, RandomSubnormalCancellation) {
  // Random tiny coefficients (subnormal or just above), |s| up to 2^40, constant term
  // cancelling the rest to its rounding error: sign_at must agree with the oracle.
  const std::uint64_t seed = 31337;
  std::mt19937_64 rng(seed);
  std::uint64_t calls = 0;
  PredicateStats stats;
  int failures = 0;
  for (int it = 0; it < 2000 && failures < 3; ++it) {
    MotionPolynomial q = random_polynomial(rng, -1074, -1000, 0.0);
    if (q.degree == 0) continue;
    const double t = random_double(rng, 0, 40);
    MotionPolynomial rest = q;
    rest.c[0] = 0.0;
    const double rounded = rest.evaluate(t);
    if (!std::isfinite(rounded)) continue;
    // Between the rounded and the exact value of the rest: the sign of the sum is decided by the
    // rounding error of the rest, which the filter's bound must cover.
    double c0 = -Q((Q(rounded) + exact_eval(rest, t)) / 2).get_d();
    for (int k = rand_int(rng, -3, 3); k != 0; k += (k > 0 ? -1 : 1)) {
      c0 = std::nextafter(c0, k > 0 ? 1e308 : -1e308);
    }
    q.c[0] = c0;
    const int expected = sgn(exact_eval(q, t));
    ++calls;
    const int got = sign_at(q, t, &stats);
    if (got != expected) ++failures;
    EXPECT_EQ(got, expected) << where(seed, it) << " p=" << describe(q) << " t=" << hex(t);
  }
  EXPECT_EQ(stats.filtered + stats.exact, calls);
}

// ---------------------------------------------------------------------------------------------
// compare_after.

TEST(PredicatesCompareAfter, TiesResolvedByTheFirstNonZeroDerivative) {
  const MotionPolynomial zero = MotionPolynomial::constant(0.0);
  // t^2 vs 0 at 0: a touch from above, +1 after.
  const std::vector<double> sq = {0.0, 0.0, 1.0};
  EXPECT_EQ(compare_after(MotionPolynomial::from(sq), zero, 0.0), 1);
  EXPECT_EQ(compare_after(zero, MotionPolynomial::from(sq), 0.0), -1);
  // -(t-1)^3 vs 0 at 1: -1 after.
  const std::vector<double> cube = {0.0, 0.0, 0.0, -1.0};
  EXPECT_EQ(compare_after(MotionPolynomial::from(cube, 1.0), zero, 1.0), -1);
  // ... and the same cube written about origin 0: -(t^3 - 3t^2 + 3t - 1).
  const std::vector<double> cube0 = {1.0, -3.0, 3.0, -1.0};
  EXPECT_EQ(compare_after(MotionPolynomial::from(cube0), zero, 1.0), -1);
  // Not a tie: compare_after is the order at t.
  EXPECT_EQ(compare_after(MotionPolynomial::from(cube0), zero, 0.0), 1);
  EXPECT_EQ(compare_after(MotionPolynomial::from(cube0), zero, 2.0), -1);
  // Crossing with a simple root: (t-1) vs 0 at 1 -> +1.
  const std::vector<double> lin = {0.0, 1.0};
  EXPECT_EQ(compare_after(MotionPolynomial::from(lin, 1.0), zero, 1.0), 1);
  // Identical functions (different origins): 0.
  const std::vector<double> ca = {1.0, 2.0, 3.0};
  const std::vector<double> cb = {17.0, 14.0, 3.0};
  EXPECT_EQ(compare_after(MotionPolynomial::from(ca), MotionPolynomial::from(cb, 2.0), 2.0), 0);
  EXPECT_EQ(compare_after(MotionPolynomial::from(ca), MotionPolynomial::from(cb, 2.0), -0.75), 0);
  // The zero polynomial against itself.
  EXPECT_EQ(compare_after(zero, zero, 3.0), 0);
}

TEST(PredicatesCompareAfter, TieBrokenOnlyByTheFifthDerivative) {
  // About t = 1: a = 1 + h + h^2 + h^3 + h^4 + 2 h^5 + h^6,
  //              b = 1 + h + h^2 + h^3 + h^4 -   h^5 + 7 h^6, b written about origin -1.
  const QPoly ta = {1, 1, 1, 1, 1, 2, 1};
  const QPoly tb = {1, 1, 1, 1, 1, -1, 7};
  const auto a = to_motion(ta, 1.0);
  const auto b = to_motion(reexpand(tb, Q(-2)), -1.0);  // p(-1 + x) = sum tb_k (x - 2)^k
  ASSERT_TRUE(a && b);
  EXPECT_EQ(compare_at(*a, *b, 1.0), 0);
  EXPECT_EQ(compare_after(*a, *b, 1.0), 1);
  EXPECT_EQ(compare_after(*b, *a, 1.0), -1);
  EXPECT_EQ(oracle_after(*a, *b, 1.0), 1);  // the oracle agrees with the hand computation
  // Swap the sign of the fifth-order difference.
  const QPoly tc = {1, 1, 1, 1, 1, 3, -5};
  const auto c = to_motion(reexpand(tc, Q(-2)), -1.0);
  ASSERT_TRUE(c);
  EXPECT_EQ(compare_after(*a, *c, 1.0), -1);
  // Only the sixth order differs.
  const QPoly td = {1, 1, 1, 1, 1, 2, 0.5};
  const auto d = to_motion(reexpand(td, Q(3)), 4.0);
  ASSERT_TRUE(d);
  EXPECT_EQ(compare_after(*a, *d, 1.0), 1);
  EXPECT_EQ(compare_after(*d, *a, 1.0), -1);
}

TEST(PredicatesCompareAfter, RandomTiesAgainstTheOracle) {
  // a and b share their first j Taylor coefficients at t (j = 0..7), written about different
  // origins.
  const std::uint64_t seed = 1618033;
  std::mt19937_64 rng(seed);
  int made = 0, ties = 0;
  for (int it = 0; it < 1500 && !HasFailure(); ++it) {
    const Q tq = small_dyadic(rng, 1 << 16, 3);
    const double t = tq.get_d();
    QPoly TA(kMaxMotionDegree + 1), TB(kMaxMotionDegree + 1);
    const int j = rand_int(rng, 0, kMaxMotionDegree + 1);
    for (int k = 0; k <= kMaxMotionDegree; ++k) {
      TA[k] = (rng() % 3 == 0) ? Q(0) : small_dyadic(rng, 64, 4);
      TB[k] = (k < j || rng() % 4 == 0) ? TA[k] : small_dyadic(rng, 64, 4);
    }
    const Q oa = tq + small_dyadic(rng, 32, 2), ob = tq + small_dyadic(rng, 32, 2);
    const auto a = to_motion(reexpand(TA, Q(oa - tq)), oa.get_d());
    const auto b = to_motion(reexpand(TB, Q(ob - tq)), ob.get_d());
    if (!a || !b) continue;
    ++made;
    int expected = 0;
    for (int k = 0; k <= kMaxMotionDegree && expected == 0; ++k) expected = sgn(Q(TA[k] - TB[k]));
    ASSERT_EQ(oracle_after(*a, *b, t), expected) << "oracle self-check " << where(seed, it);
    if (sgn(Q(TA[0] - TB[0])) == 0) ++ties;
    PredicateStats stats;
    EXPECT_EQ(compare_after(*a, *b, t, &stats), expected)
        << where(seed, it) << " a=" << describe(*a) << " b=" << describe(*b) << " t=" << hex(t);
    EXPECT_EQ(compare_after(*b, *a, t), -expected) << where(seed, it);
  }
  EXPECT_GE(made, 1000);
  EXPECT_GE(ties, 700);
}

// ---------------------------------------------------------------------------------------------
// find_time_below.

void expect_certified_below(const std::optional<Time>& r, const MotionPolynomial& a,
                            const MotionPolynomial& b, Time lo, Time hi, const std::string& w) {
  ASSERT_TRUE(r.has_value()) << w;
  EXPECT_GE(*r, lo) << w;
  EXPECT_LE(*r, hi) << w;
  EXPECT_LT(sgn(Q(exact_eval(a, *r) - exact_eval(b, *r))), 0) << w << " at " << hex(*r);
}

TEST(PredicatesFindTimeBelow, FindsANarrowDip) {
  // a - b = (t-2)^2 - 1e-6 over [0, 10]: negative on (2 - 1e-3, 2 + 1e-3) only.
  const std::vector<double> ca = {4.0 - 1e-6, -4.0, 1.0};
  const MotionPolynomial a = MotionPolynomial::from(ca);
  const MotionPolynomial b = MotionPolynomial::constant(0.0);
  expect_certified_below(find_time_below(a, b, 0.0, 10.0), a, b, 0.0, 10.0, "dip");
  // The same difference with a and b both moving, about different origins:
  // b = 5 + (t - 7) = t - 2, a = b + (t-2)^2 - 1e-6 = (4 - 1e-6 - 2) - 3t + t^2.
  const std::vector<double> cb = {5.0, 1.0};
  const MotionPolynomial b2 = MotionPolynomial::from(cb, 7.0);
  const auto a2 = to_motion(add(QPoly{Q(4.0 - 1e-6), Q(-4), Q(1)}, QPoly{Q(-2), Q(1)}), 0.0);
  ASSERT_TRUE(a2);
  expect_certified_below(find_time_below(*a2, b2, 0.0, 10.0), *a2, b2, 0.0, 10.0, "dip with b");
  // The dip outside the window is not found: [3, 10].
  EXPECT_FALSE(find_time_below(a, b, 3.0, 10.0).has_value());
}

TEST(PredicatesFindTimeBelow, NonNegativeDifferencesGiveNullopt) {
  const MotionPolynomial zero = MotionPolynomial::constant(0.0);
  const std::vector<double> touch = {4.0, -4.0, 1.0};  // (t-2)^2: touches 0 at 2
  const MotionPolynomial t2 = MotionPolynomial::from(touch);
  EXPECT_FALSE(find_time_below(t2, zero, 0.0, 10.0).has_value());
  EXPECT_FALSE(find_time_below(t2, zero, 0.0, kTimeInfinity).has_value());
  EXPECT_FALSE(find_time_below(t2, zero, 2.0, 2.0).has_value());
  // (t-2)^4 about origin 2 and (t-1)^2 (t-3)^2: touches only.
  const std::vector<double> q4 = {0, 0, 0, 0, 1.0};
  EXPECT_FALSE(
      find_time_below(MotionPolynomial::from(q4, 2.0), zero, -5.0, kTimeInfinity).has_value());
  const auto w = to_motion(
      multiply(multiply(QPoly{-1, 1}, QPoly{-1, 1}), multiply(QPoly{-3, 1}, QPoly{-3, 1})), 0.0);
  ASSERT_TRUE(w);
  EXPECT_FALSE(find_time_below(*w, zero, -10.0, kTimeInfinity).has_value());
  // Equal functions.
  EXPECT_FALSE(find_time_below(t2, t2, 0.0, kTimeInfinity).has_value());
  // Strictly positive, growing.
  const std::vector<double> pos = {1.0, 0.0, 1.0};
  EXPECT_FALSE(find_time_below(MotionPolynomial::from(pos), zero, -1e6, kTimeInfinity).has_value());
  // Positive with leading coefficient > 0 and a zero at the window's end: still not below.
  const std::vector<double> lin = {0.0, 1.0};
  EXPECT_FALSE(
      find_time_below(MotionPolynomial::from(lin, 3.0), zero, 3.0, kTimeInfinity).has_value());
}

TEST(PredicatesFindTimeBelow, BelowAtTheEndsAndAtInfinity) {
  const MotionPolynomial zero = MotionPolynomial::constant(0.0);
  // Negative at lo.
  const std::vector<double> lin = {0.0, 1.0};  // t - 3
  const MotionPolynomial a = MotionPolynomial::from(lin, 3.0);
  expect_certified_below(find_time_below(a, zero, 0.0, 10.0), a, zero, 0.0, 10.0, "at lo");
  // Negative only at hi: b - a = 3 - t on [0, 3.5].
  expect_certified_below(find_time_below(zero, a, 0.0, 3.5), zero, a, 0.0, 3.5, "at hi");
  // Negative only as t -> infinity: 5 - t on [0, inf).
  const std::vector<double> dec = {5.0, -1.0};
  const MotionPolynomial d = MotionPolynomial::from(dec);
  expect_certified_below(find_time_below(d, zero, 0.0, kTimeInfinity), d, zero, 0.0, kTimeInfinity,
                         "at infinity");
  // A cubic that eventually falls: -(t - 100)^3 + 1 about 100 on [0, inf) is negative for t > 101.
  const std::vector<double> cub = {1.0, 0.0, 0.0, -1.0};
  const MotionPolynomial e = MotionPolynomial::from(cub, 100.0);
  expect_certified_below(find_time_below(e, zero, 100.5, kTimeInfinity), e, zero, 100.5,
                         kTimeInfinity, "cubic at infinity");
  // A dip far out with hi = +infinity: (t - 1000)^2 - 1.
  const std::vector<double> far = {-1.0, 0.0, 1.0};
  const MotionPolynomial f = MotionPolynomial::from(far, 1000.0);
  expect_certified_below(find_time_below(f, zero, 0.0, kTimeInfinity), f, zero, 0.0, kTimeInfinity,
                         "far dip");
}

TEST(PredicatesFindTimeBelow, AtInfinityFromAFarLowerEnd) {
  // a - b = -t on [lo, +inf) with lo = -1e16 (or 1e17 + 64 - t from lo = 1e17): negative for
  // every t beyond the root, so a time must be found. lo + 1.0 == lo for such lo.
  const MotionPolynomial zero = MotionPolynomial::constant(0.0);
  const std::vector<double> neg = {0.0, -1.0};
  const MotionPolynomial a = MotionPolynomial::from(neg);
  for (double lo : {-10.0, -1e15, -1e16, -1e20, -1e300}) {
    expect_certified_below(find_time_below(a, zero, lo, kTimeInfinity), a, zero, lo, kTimeInfinity,
                           "lo=" + hex(lo));
  }
  const std::vector<double> c = {1e17 + 64.0, -1.0};
  const MotionPolynomial b = MotionPolynomial::from(c);
  expect_certified_below(find_time_below(b, zero, 1e17, kTimeInfinity), b, zero, 1e17,
                         kTimeInfinity, "lo=1e17");
}

TEST(PredicatesFindTimeBelow, RandomWideDipsAgainstTheOracle) {
  // a - b = lead * prod (s - r_i) with distinct dyadic roots at least 1/2 apart, so every dip is
  // wide; b is random, a = b + that product (different origins). A dip exists in [lo, hi] iff
  // the oracle sees a negative value at lo, hi or a midpoint between consecutive roots.
  const std::uint64_t seed = 8675309;
  std::mt19937_64 rng(seed);
  int found = 0, none = 0;
  for (int it = 0; it < 400 && !HasFailure(); ++it) {
    const int degree = rand_int(rng, 1, kMaxMotionDegree);
    std::vector<Q> roots;
    while (static_cast<int>(roots.size()) < degree) {
      const Q r = small_dyadic(rng, 40, 2);
      bool ok = true;
      for (const Q& x : roots) ok = ok && abs(Q(x - r)) >= Q(1, 2);
      if (ok) roots.push_back(r);
    }
    std::sort(roots.begin(), roots.end());
    QPoly P = {Q(rng() % 2 ? 1 : -1)};
    for (const Q& r : roots) P = multiply(P, QPoly{-r, Q(1)});
    const Q oa = small_dyadic(rng, 400, 3), ob = small_dyadic(rng, 400, 3);
    QPoly B;
    const int bd = rand_int(rng, 0, kMaxMotionDegree);
    for (int i = 0; i <= bd; ++i) B.push_back(small_dyadic(rng, 32, 3));
    const auto b = to_motion(B, ob.get_d());
    const auto a = to_motion(add(reexpand(B, Q(oa - ob)), P), oa.get_d());
    if (!a || !b) continue;
    const double lo = Q(oa + small_dyadic(rng, 48, 2)).get_d();
    const bool infinite = rng() % 3 == 0;
    const double hi =
        infinite ? kTimeInfinity : lo + small_dyadic(rng, 48, 2).get_d() * (rng() % 2 ? 1 : -1);
    if (!(lo <= hi)) continue;
    // Oracle: is a - b negative somewhere in [lo, hi]?
    auto diff_sign = [&](const Q& t) {
      return sgn(Q(exact_eval(*a, t.get_d()) - exact_eval(*b, t.get_d())));
    };
    bool dip = false;
    std::vector<Q> probes = {Q(lo)};
    if (!infinite) probes.push_back(Q(hi));
    for (std::size_t i = 0; i + 1 < roots.size(); ++i)
      probes.push_back(oa + (roots[i] + roots[i + 1]) / 2);
    probes.push_back(oa + roots.back() + 1);
    probes.push_back(oa + roots.front() - 1);
    for (const Q& t : probes) {
      if (t >= Q(lo) && (infinite || t <= Q(hi)) && representable(t) && diff_sign(t) < 0)
        dip = true;
    }
    // Beyond the last probe the sign is that of the leading coefficient (no more roots).
    const std::string w = where(seed, it) + " a=" + describe(*a) + " b=" + describe(*b) +
                          " lo=" + hex(lo) + " hi=" + hex(hi);
    const auto r = find_time_below(*a, *b, lo, hi);
    if (dip) {
      ++found;
      expect_certified_below(r, *a, *b, lo, hi, w);
    } else {
      ++none;
      EXPECT_FALSE(r.has_value()) << w << " returned " << (r ? hex(*r) : "");
    }
  }
  EXPECT_GE(found, 100);
  EXPECT_GE(none, 30);
}

// ---------------------------------------------------------------------------------------------
// value_at: the exact value rounded toward zero.

/// v is `exact` rounded toward zero: |v| <= |exact|, the same sign (or zero), and the next
/// double away from zero overshoots.
::testing::AssertionResult rounded_toward_zero(double v, const Q& exact) {
  if (cmp(abs(Q(v)), abs(exact)) > 0) return ::testing::AssertionFailure() << v << " overshoots";
  if (v != 0.0 && (v > 0) != (sgn(exact) > 0))
    return ::testing::AssertionFailure() << v << " has the wrong sign";
  const double away = std::nextafter(v, sgn(exact) >= 0 ? kTimeInfinity : kTimeMinusInfinity);
  if (sgn(exact) != 0 && cmp(abs(Q(away)), abs(exact)) <= 0)
    return ::testing::AssertionFailure() << v << " is not the last double before the value";
  return ::testing::AssertionSuccess();
}

TEST(PredicatesValueAt, RoundsTheExactValueTowardZero) {
  const std::uint64_t seed = 55;
  std::mt19937_64 rng(seed);
  for (int it = 0; it < 1000 && !HasFailure(); ++it) {
    const MotionPolynomial p = random_polynomial(rng, -20, 20, random_double(rng, -5, 20));
    const double t = p.origin + random_double(rng, -10, 10);
    ASSERT_TRUE(std::isfinite(value_at(p, t)));
    EXPECT_TRUE(rounded_toward_zero(value_at(p, t), exact_eval(p, t))) << where(seed, it);
  }
  const std::vector<double> c = {1.0, 0.0, 1.0};
  EXPECT_EQ(value_at(MotionPolynomial::from(c, 1.0), 3.0), 5.0);
  // Values exactly at a double, just beside one and at tiny magnitudes, of both signs: where the
  // rounding toward zero cannot be read off a floating-point evaluation.
  for (int it = 0; it < 2000 && !HasFailure(); ++it) {
    std::vector<double> k;
    const int degree = 1 + static_cast<int>(rng() % 3);
    for (int j = 0; j <= degree; ++j)
      k.push_back(static_cast<double>(static_cast<int>(rng() % 9) - 4));
    if (k.back() == 0.0) k.back() = 1.0;
    if (it % 3 == 1) k[0] += 0x1p-60;  // just beside an integer
    if (it % 3 == 2) {
      for (double& x : k) x = std::ldexp(x, -1040);  // subnormal values
    }
    const MotionPolynomial p = MotionPolynomial::from(std::span<const double>(k), 0.5);
    const double t = 0.5 + static_cast<double>(static_cast<int>(rng() % 17) - 8) * 0.25;
    EXPECT_TRUE(rounded_toward_zero(value_at(p, t), exact_eval(p, t))) << where(seed, 1000 + it);
  }
}

// ---------------------------------------------------------------------------------------------
// filtered_compare / filtered_orientation: a decided sign is the exact one; an exact zero is
// never decided.

TEST(PredicatesFilteredPoint, DecidedSignsAreExactAndZerosAreUndecided) {
  const std::uint64_t seed = 61;
  std::mt19937_64 rng(seed);
  int decided = 0, zeros = 0;
  for (int it = 0; it < 3000 && !HasFailure(); ++it) {
    const double t = random_double(rng, -4, 4);
    MotionPolynomial m[3][2];
    for (auto& point : m) {
      for (auto& axis : point) axis = random_polynomial(rng, -8, 8, random_double(rng, -2, 2));
    }
    // Every third case: c on the line of a and b at t (a + 2 (b - a) for linear motions with
    // small integer coefficients, so the orientation is exactly zero), and c = a.
    if (it % 3 == 0) {
      for (int axis = 0; axis < 2; ++axis) {
        const double a0 = std::round(random_double(rng, -8, 8)),
                     a1 = std::round(random_double(rng, -3, 3));
        const double b0 = std::round(random_double(rng, -8, 8)),
                     b1 = std::round(random_double(rng, -3, 3));
        m[0][axis] = MotionPolynomial::from({a0, a1});
        m[1][axis] = MotionPolynomial::from({b0, b1});
        m[2][axis] = (it % 2 == 0) ? MotionPolynomial::from({2 * b0 - a0, 2 * b1 - a1})
                                   : MotionPolynomial::from({a0, a1});
      }
    }
    FilteredPoint p[3];
    Q x[3], y[3];
    for (int k = 0; k < 3; ++k) {
      p[k] = filtered_point(m[k][0], m[k][1], t);
      x[k] = exact_eval(m[k][0], t);
      y[k] = exact_eval(m[k][1], t);
    }
    const int exact = sgn(Q((x[1] - x[0]) * (y[2] - y[0]) - (y[1] - y[0]) * (x[2] - x[0])));
    const int filtered = filtered_orientation(p[0], p[1], p[2]);
    if (exact == 0) ++zeros;
    if (filtered != 0) {
      ++decided;
      EXPECT_EQ(filtered, exact) << where(seed, it);
    }
    EXPECT_TRUE(exact != 0 || filtered == 0) << where(seed, it);
    const int cmp_exact = sgn(Q(x[0] - x[1]));
    const int cmp_filtered = filtered_compare(p[0].x, p[1].x);
    EXPECT_TRUE(cmp_filtered == 0 || cmp_filtered == cmp_exact) << where(seed, it);
    EXPECT_TRUE(cmp_exact != 0 || cmp_filtered == 0) << where(seed, it);
  }
  EXPECT_GE(zeros, 900);     // the constructed collinear and coincident cases
  EXPECT_GE(decided, 1500);  // the filter decides the random ones
}

}  // namespace
}  // namespace kinetic
