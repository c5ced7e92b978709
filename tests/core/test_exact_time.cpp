// Exact event times (core/exact_time.hpp) against the rational oracle of
// tests/support/exact_poly.hpp (its own expansion, gcd, Sturm counts; nothing shared with the
// library's code): motions expanded exactly, every real root isolated and counted, equal roots of
// different polynomials recognised (the degenerate case the exact scheduler orders), distinct
// roots closer than any double apart ordered, signs at and just after a root. Fixed seeds,
// printed on failure.

#include "kinetic/core/exact_time.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "kinetic/core/scheduler.hpp"
#include "support/crop_check.hpp"
#include "support/exact_poly.hpp"

namespace kinetic {
namespace {

namespace ex = ::kinetic::test::exact;
using ex::Q;
using ex::QPoly;

QPoly oracle(const ExactPolynomial& p) { return QPoly(p.coefficients()); }

ExactPolynomial poly(std::vector<mpq_class> c) { return ExactPolynomial(std::move(c)); }

/// prod (t - r_i) * lead, the r_i rationals.
ExactPolynomial with_roots(const std::vector<mpq_class>& roots, const mpq_class& lead) {
  ExactPolynomial p = poly({lead});
  for (const mpq_class& r : roots) p = p * poly({mpq_class(-r), mpq_class(1)});
  return p;
}

TEST(ExactTime, MotionsExpandExactly) {
  constexpr std::uint64_t kSeed = 31;
  std::mt19937_64 rng(kSeed);
  for (int i = 0; i < 200; ++i) {
    const int degree = static_cast<int>(rng() % (kMaxMotionDegree + 1));
    const MotionPolynomial m = test::random_motion(rng, degree, test::full_mantissa(rng, -1), 3);
    EXPECT_TRUE(oracle(ExactPolynomial::of(m)) == ex::from_motion(m))
        << "seed " << kSeed << " case " << i;
  }
}

// Signs at rational times: dyadic coefficients at dyadic times are taken in integers (no
// rational normalisation); they equal the sign of the rational value, for dyadic and other
// coefficients and times, zeros included.
TEST(ExactPolynomial, SignsAtDyadicAndOtherTimesEqualTheRationalValue) {
  std::mt19937_64 rng(23);
  std::uniform_int_distribution<int> small(-8, 8), shift(-6, 6);
  int zeros = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const bool dyadic = trial % 4 != 0;
    std::vector<mpq_class> c;
    const int degree = 1 + trial % 6;
    for (int k = 0; k <= degree; ++k) {
      mpq_class q(small(rng), dyadic ? 1 : 3);
      if (shift(rng) > 0)
        mpq_mul_2exp(q.get_mpq_t(), q.get_mpq_t(), static_cast<unsigned>(shift(rng) + 6));
      else
        mpq_div_2exp(q.get_mpq_t(), q.get_mpq_t(), static_cast<unsigned>(shift(rng) + 6));
      q.canonicalize();
      c.push_back(q);
    }
    // Half of them with a root r (dyadic) that is one of the times asked.
    mpq_class r(small(rng), 1 << (trial % 4));
    r.canonicalize();
    ExactPolynomial f(c);
    if (trial % 2 == 0) f = f * ExactPolynomial({-r, mpq_class(1)});
    for (int k = 0; k < 6; ++k) {
      mpq_class t(small(rng), trial % 3 == 0 ? 3 : 1 << (k % 4));
      t.canonicalize();
      if (k == 0) t = r;
      const mpq_class v = f(t);
      zeros += v == 0;
      ASSERT_EQ(f.sign_at(t), sgn(v)) << "trial " << trial << " t = " << t;
    }
  }
  EXPECT_GT(zeros, 50);
}

// The views a polynomial keeps of its coefficients (double enclosures, dyadic integers) follow
// coefficients changed in place: the gcd's normalisation by its leading coefficient.
TEST(ExactPolynomial, ViewsFollowTheGcdNormalisation) {
  const ExactPolynomial f({mpq_class(2), mpq_class(-4)});  // 2 - 4t
  EXPECT_EQ(f.sign_at(mpq_class(0)), 1);
  EXPECT_EQ(f.enclosure().front()[0], 2.0);
  const ExactPolynomial g = ExactPolynomial::gcd(f, ExactPolynomial());  // t - 1/2
  EXPECT_EQ(g.sign_at(mpq_class(0)), -1);
  EXPECT_EQ(g.enclosure().front()[0], -0.5);
}

TEST(ExactTime, EveryRootIsolatedAndCounted) {
  constexpr std::uint64_t kSeed = 32;
  std::mt19937_64 rng(kSeed);
  int total = 0, points = 0;
  for (int i = 0; i < 300; ++i) {
    // Planted rational roots (some repeated, some at the window's ends, some dyadic), times a
    // random factor without real roots half of the time.
    std::vector<mpq_class> roots;
    const int k = 1 + static_cast<int>(rng() % 5);
    for (int j = 0; j < k; ++j) {
      const long num = static_cast<long>(rng() % 41) - 20;
      const long den = 1 + static_cast<long>(rng() % 7);
      roots.emplace_back(num, den);
      roots.back().canonicalize();
      if (rng() % 4 == 0) roots.push_back(roots.back());  // a double root
    }
    ExactPolynomial f = with_roots(roots, mpq_class(1 + static_cast<long>(rng() % 5)));
    if (rng() % 2 == 0) f = f * poly({mpq_class(2), mpq_class(0), mpq_class(1)});  // t^2 + 2
    const double lo = static_cast<double>(static_cast<long>(rng() % 9) - 4);
    const double hi = lo + 1.0 + static_cast<double>(rng() % 6);
    const std::vector<ExactTime> found = isolate_roots(f, rational(lo), rational(hi));
    const ex::RootOracle o(oracle(f));
    ASSERT_EQ(static_cast<int>(found.size()), o.count_half_open(lo, hi))
        << "seed " << kSeed << " case " << i;
    const QPoly sf = o.square_free();
    for (std::size_t j = 0; j < found.size(); ++j) {
      const ExactTime& t = found[j];
      // In (lo, hi]: a point after lo, an interval's root strictly inside it.
      EXPECT_TRUE(t.is_point() ? t.lo() > rational(lo) : t.lo() >= rational(lo)) << "case " << i;
      EXPECT_LE(t.hi(), rational(hi));
      if (t.is_point()) {
        ++points;
        EXPECT_EQ(ex::eval(oracle(f), Q(t.lo())), 0) << "case " << i;
      } else {
        EXPECT_LT(ex::sign_at(sf, Q(t.lo())) * ex::sign_at(sf, Q(t.hi())), 0) << "case " << i;
      }
      if (j > 0) {
        EXPECT_LE(found[j - 1].hi(), t.lo());  // ascending, disjoint
      }
      EXPECT_LE(t.lower(), t.lo().get_d());
      EXPECT_GE(t.upper(), t.hi().get_d());
    }
    total += static_cast<int>(found.size());
  }
  EXPECT_GT(total, 150);  // the windows hold roots (218 with this seed)
  EXPECT_GT(points, 20);  // roots at a bisection point or a window end: points (37)
}

/// sqrt(2) as the root of two different polynomials, in different intervals: equal, by the gcd.
TEST(ExactTime, EqualIrrationalRootsOfDifferentPolynomialsAreEqual) {
  const ExactPolynomial two = poly({mpq_class(-2), mpq_class(0), mpq_class(1)});  // t^2 - 2
  const ExactPolynomial p1 = two * poly({mpq_class(-3), mpq_class(1)});
  const ExactPolynomial p2 = two * poly({mpq_class(1), mpq_class(1)}) * poly({mpq_class(1, 3), 1});
  std::vector<ExactTime> r1 = isolate_roots(p1, mpq_class(1), mpq_class(2));
  std::vector<ExactTime> r2 = isolate_roots(p2, mpq_class(0), mpq_class(3));
  ASSERT_EQ(r1.size(), 1u);
  ASSERT_EQ(r2.size(), 1u);
  bool by_gcd = false;
  EXPECT_EQ(compare(r1[0], r2[0], &by_gcd), 0);
  EXPECT_TRUE(by_gcd);
  EXPECT_EQ(compare(r2[0], r1[0]), 0);
  // A rational point equals the root of a linear factor.
  std::vector<ExactTime> half = isolate_roots(poly({mpq_class(-1), mpq_class(2)}), 0, 1);
  ASSERT_EQ(half.size(), 1u);
  ExactTime p = ExactTime::point(rational(0.5));
  EXPECT_EQ(compare(half[0], p), 0);
  EXPECT_TRUE(half[0].is_point());
}

/// sqrt(2) and sqrt(2 + 10^-30): 3.5e-31 apart, far below a double's spacing there.
TEST(ExactTime, RootsCloserThanAnyDoubleAreOrdered) {
  const mpq_class tiny(mpz_class(1), mpz_class("1000000000000000000000000000000"));
  const ExactPolynomial a = poly({mpq_class(-2), 0, 1});
  const ExactPolynomial b = poly({mpq_class(-2 - tiny), 0, 1});
  ExactTime ra = isolate_roots(a, 0, 2)[0];
  ExactTime rb = isolate_roots(b, 0, 2)[0];
  bool by_gcd = true;
  EXPECT_EQ(compare(ra, rb, &by_gcd), -1);
  EXPECT_FALSE(by_gcd);
  EXPECT_EQ(compare(rb, ra), 1);
  EXPECT_GT(ra.refinements() + rb.refinements(), 100u);  // past a double's precision
  EXPECT_EQ(ra.lower(), rb.lower());                     // the same double bracket
}

TEST(ExactTime, SignsAtAndJustAfterARoot) {
  const ExactPolynomial two = poly({mpq_class(-2), 0, 1});  // root sqrt(2)
  ExactTime r = isolate_roots(two, 1, 2)[0];
  // f vanishing at sqrt(2): 0 at, the first non-zero derivative's sign after.
  EXPECT_EQ(r.sign_of(two * poly({mpq_class(-5), 1})), 0);
  EXPECT_EQ(r.sign_after(two * poly({mpq_class(-5), 1})), -1);  // f' = 2 sqrt2 (sqrt2 - 5)
  EXPECT_EQ(r.sign_of(two * two), 0);
  EXPECT_EQ(r.sign_after(two * two), 1);  // a double root: f'' > 0
  EXPECT_EQ(r.sign_after(ExactPolynomial()), 0);
  // f not vanishing there, against the oracle: the sign at a rational inside the interval once
  // it is narrower than f's roots' distance (f has rational roots only).
  constexpr std::uint64_t kSeed = 33;
  std::mt19937_64 rng(kSeed);
  for (int i = 0; i < 100; ++i) {
    std::vector<mpq_class> roots;
    for (int j = 0; j < 3; ++j) roots.emplace_back(static_cast<long>(rng() % 400) - 200, 100);
    const ExactPolynomial f = with_roots(roots, mpq_class(rng() % 2 == 0 ? 1 : -1));
    ExactTime t = isolate_roots(two, 1, 2)[0];
    const int got = t.sign_of(f);
    // sqrt(2) is irrational: f(sqrt 2) != 0; 1.41421356 < sqrt 2 < 1.41421357 and no root of f
    // (multiples of 1/100) lies between.
    EXPECT_EQ(got, ex::sign_at(oracle(f), Q(mpq_class(141421356, 100000000))))
        << "seed " << kSeed << " case " << i;
    EXPECT_EQ(t.sign_after(f), got);
  }
}

/// Random pairs of roots of random polynomials: compare() is antisymmetric and agrees with the
/// order of the separated intervals, and the refined intervals still hold their roots.
TEST(ExactTime, CompareIsAConsistentOrder) {
  constexpr std::uint64_t kSeed = 34;
  std::mt19937_64 rng(kSeed);
  std::vector<ExactTime> all;
  std::vector<ExactPolynomial> of;
  for (int i = 0; i < 12; ++i) {
    std::vector<mpq_class> c;
    for (int k = 0; k <= 3; ++k) c.emplace_back(static_cast<long>(rng() % 21) - 10);
    const ExactPolynomial f = poly(c);
    if (f.degree() < 1) continue;
    for (ExactTime& t : isolate_roots(f, -20, 20)) {
      all.push_back(t);
      of.push_back(f.square_free());
    }
  }
  ASSERT_GT(all.size(), 12u);
  for (std::size_t i = 0; i < all.size(); ++i) {
    for (std::size_t j = 0; j < all.size(); ++j) {
      ExactTime a = all[i], b = all[j];
      const int ab = compare(a, b);
      ExactTime a2 = all[i], b2 = all[j];
      EXPECT_EQ(compare(b2, a2), -ab) << "seed " << kSeed << " " << i << " " << j;
      if (i == j) {
        EXPECT_EQ(ab, 0);
      }
      if (ab < 0) {
        EXPECT_LE(a.lo(), b.hi());
      }
      if (!a.is_point()) {
        EXPECT_LT(ex::sign_at(oracle(of[i]), Q(a.lo())) * ex::sign_at(oracle(of[i]), Q(a.hi())), 0);
      }
    }
  }
}

/// decide_exact: the sign just after now and the first sign change after now, touching roots
/// (even multiplicity) skipped, now itself a root (the crossing being processed) or an
/// irrational root of another certificate, against the planted roots.
TEST(ExactTime, DecisionsFailAtTheNextSignChange) {
  constexpr std::uint64_t kSeed = 35;
  std::mt19937_64 rng(kSeed);
  int failing = 0, touching_skipped = 0;
  // Roots at quarters (doubles: found at interval ends) and at thirds and 1/1000003ths (inside
  // the floating-point isolation's intervals, some closer together than it resolves).
  for (int i = 0; i < 900; ++i) {
    struct Root {
      mpq_class r;
      int multiplicity;
    };
    std::vector<Root> planted;
    std::vector<mpq_class> all;
    const int k = 1 + static_cast<int>(rng() % 4);
    const long denominator = i < 300 ? 4 : (i < 600 ? 3 : 1000003);
    const long span = i < 600 ? 41 : 41 * 1000003 / 4;
    for (int j = 0; j < k; ++j) {
      mpq_class r(static_cast<long>(rng() % static_cast<std::uint64_t>(span)) - span / 2,
                  denominator);
      r.canonicalize();
      const int m = 1 + static_cast<int>(rng() % 3);
      planted.push_back({r, m});
      for (int x = 0; x < m; ++x) all.push_back(r);
    }
    const ExactPolynomial f = with_roots(all, mpq_class(rng() % 2 == 0 ? 1 : -1));
    // now: a planted root (an event being processed), a rational, or sqrt(2) + j.
    ExactTime now;
    const int which = static_cast<int>(rng() % 3);
    if (which == 0) {
      now = ExactTime::point(planted[rng() % planted.size()].r);
    } else if (which == 1) {
      now = ExactTime::point(mpq_class(static_cast<long>(rng() % 81) - 40, 8));
    } else {
      const long shift = static_cast<long>(rng() % 9) - 4;
      const std::vector<ExactTime> roots =
          isolate_roots(poly({mpq_class(shift * shift - 2), mpq_class(-2 * shift), 1}),
                        mpq_class(shift), mpq_class(shift + 2));  // sqrt(2) + shift
      ASSERT_EQ(roots.size(), 1u);
      now = roots[0];
    }
    const mpq_class horizon(40);
    ExactTime at = now;
    const ExactDecision d = decide_exact(f, at, horizon);
    // Expected: the sign of f just after now from the planted factorisation, and the smallest
    // planted root > now of odd multiplicity (a sum of multiplicities at one root counts).
    std::map<mpq_class, int> mult;
    for (const Root& p : planted) mult[p.r] += p.multiplicity;
    ExactTime probe = now;
    const int want_sign = probe.sign_after(f);
    EXPECT_EQ(d.sign, want_sign);
    std::optional<mpq_class> want;
    for (const auto& [r, m] : mult) {
      ExactTime pr = ExactTime::point(r);
      ExactTime nw = now;
      if (compare(pr, nw) <= 0) continue;
      if (m % 2 == 1) {
        want = r;
        break;
      }
      ++touching_skipped;
    }
    ASSERT_EQ(d.fails, want.has_value()) << "seed " << kSeed << " case " << i;
    if (want) {
      ++failing;
      ExactTime w = ExactTime::point(*want);
      ExactTime got = d.failure;
      EXPECT_EQ(compare(got, w), 0) << "seed " << kSeed << " case " << i;
      // Just before the failure f has the decided sign, just after the other.
      EXPECT_EQ(ex::sign_at(oracle(f), Q(*want - mpq_class(1, 1000000))), d.sign);
      EXPECT_EQ(ex::sign_at(oracle(f), Q(*want + mpq_class(1, 1000000))), -d.sign);
    }
  }
  EXPECT_GT(failing, 300);
  EXPECT_GT(touching_skipped, 60);
  // The zero polynomial: no sign, no failure.
  ExactTime t = ExactTime::point(0);
  EXPECT_EQ(decide_exact(ExactPolynomial(), t, 10).sign, 0);
}

/// The scheduler's exact decisions on motions: a crossing at a time that is no double (4/3), a
/// tangency that is no failure, a decision at the crossing time itself, an infinite horizon, and
/// the robust scheduler's failure time within its grid after the exact one.
TEST(ExactTime, SchedulerDecidesExactlyOnMotions) {
  Counters counters;
  const Scheduler bounded(SchedulerKind::Robust, 1e-9, 10.0);
  const Scheduler open(SchedulerKind::Robust, 1e-9);  // infinite horizon
  const MotionPolynomial upper = MotionPolynomial::from(std::array<double, 2>{2.0, -1.0}, 0.0);
  const MotionPolynomial lower = MotionPolynomial::from(std::array<double, 2>{0.0, 0.5}, 0.0);
  const mpq_class four_thirds(4, 3);
  for (const Scheduler* s : {&bounded, &open}) {
    ExactTime now = ExactTime::point(0);
    const ExactDecision d = s->decide_exact(upper, lower, now, counters);
    EXPECT_EQ(d.sign, 1);
    ASSERT_TRUE(d.fails);
    ExactTime got = d.failure;
    ExactTime want = ExactTime::point(four_thirds);
    EXPECT_EQ(compare(got, want), 0);
    // At the crossing itself: the sign just after is the other one, and no later failure.
    ExactTime at = d.failure;
    const ExactDecision after = s->decide_exact(upper, lower, at, counters);
    EXPECT_EQ(after.sign, -1);
    EXPECT_FALSE(after.fails);
  }
  // (t - 1)^2 against 0: touches at 1 and holds again: never a failure.
  const MotionPolynomial touch = MotionPolynomial::from(std::array<double, 3>{0.0, 0.0, 1.0}, 1.0);
  const MotionPolynomial zero = MotionPolynomial::from(std::array<double, 1>{0.0}, 0.0);
  ExactTime now = ExactTime::point(0);
  const ExactDecision t = bounded.decide_exact(touch, zero, now, counters);
  EXPECT_EQ(t.sign, 1);
  EXPECT_FALSE(t.fails);
  // The robust failure time lies at or after the exact one, within one grid cell.
  const Scheduler::SignDecision r = bounded.decide(upper, lower, 0.0, 0.0, counters);
  ExactTime robust = ExactTime::point(rational(r.failure));
  ExactTime exact_time = ExactTime::point(four_thirds);
  EXPECT_GE(compare(robust, exact_time), 0);
  EXPECT_LE(rational(r.failure) - four_thirds, mpq_class(Scheduler::grid_width(1e-9)));
  EXPECT_GT(counters.root_isolation_calls, 4u);
}

}  // namespace
}  // namespace kinetic

namespace kinetic {
namespace {

// A root that is itself a double (an integer time of a grid) inside a bracket with rational ends
// is never a midpoint of rational bisection, and the doubles on either side of it are two apart:
// tighten() must still end, with the time exactly that double.
TEST(ExactTime, TightenEndsOnARootThatIsADouble) {
  for (const int root : {5, 1, -3, 64}) {
    const ExactPolynomial p = ExactPolynomial(std::vector<mpq_class>{mpq_class(-root), 1}) *
                              ExactPolynomial(std::vector<mpq_class>{mpq_class(1000), 1});
    ExactTime t = ExactTime::root(p.square_free(), mpq_class(root) - mpq_class(2, 3),
                                  mpq_class(root) + mpq_class(1, 7));
    t.tighten();
    EXPECT_TRUE(t.is_point() || t.upper() == std::nextafter(t.lower(), 1e300)) << root;
    EXPECT_LE(t.lower(), root);
    EXPECT_GE(t.upper(), root);
    EXPECT_EQ(t.sign_of(p), 0) << root;
  }
}

}  // namespace
}  // namespace kinetic

namespace kinetic {
namespace {

// Coefficients beyond the doubles (a product of two coordinates near 1e300): the floating-point
// filters have no finite enclosure and leave the decision to exact arithmetic; no crash.
TEST(ExactTime, DecisionsWithCoefficientsBeyondTheDoubles) {
  const mpq_class big = mpq_class(1e300) * mpq_class(1e300);
  // f = big (t - 1)(t - 3): negative on (1, 3).
  const ExactPolynomial f = ExactPolynomial(std::vector<mpq_class>{3 * big, -4 * big, big});
  ExactTime now = ExactTime::point(2);
  const ExactDecision d = decide_exact(f, now, mpq_class(10));
  EXPECT_EQ(d.sign, -1);
  ASSERT_TRUE(d.fails);
  ExactTime three = ExactTime::point(3);
  ExactTime failure = d.failure;
  EXPECT_EQ(compare(failure, three), 0);
  ExactTime later = ExactTime::point(mpq_class(5, 2));
  EXPECT_EQ(later.sign_of(f), -1);
  // An infinite-looking horizon beyond the doubles.
  ExactTime from = ExactTime::point(0);
  const ExactDecision e = decide_exact(f, from, big);
  EXPECT_EQ(e.sign, 1);
  ASSERT_TRUE(e.fails);
  ExactTime one = ExactTime::point(1);
  ExactTime first = e.failure;
  EXPECT_EQ(compare(first, one), 0);
}

}  // namespace
}  // namespace kinetic
