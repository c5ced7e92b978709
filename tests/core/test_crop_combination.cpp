// CROP on a MotionCombination f = plus[0] + plus[1] - minus[0] - minus[1] (four motions with
// different full-mantissa origins, coefficients whose differences round), against the exact
// oracle of tests/support/exact_poly.hpp (rational expansion of the exact sum, Sturm counts,
// exact signs; nothing shared with the library's code). Checks (A1), (A2), (A4) and (A3) as in
// test_crop.cpp, sign_at / sign_after, and the robust scheduler's failure time on combinations.
// Generators use fixed seeds; a failure prints the seed and the case.

#include <gmpxx.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "kinetic/core/crop.hpp"
#include "kinetic/core/scheduler.hpp"
#include "support/crop_check.hpp"
#include "support/exact_poly.hpp"

namespace kinetic {
namespace {

namespace ex = ::kinetic::test::exact;
using ex::Q;
using ex::QPoly;
using test::full_mantissa;
using test::grid_point;
using test::random_motion;
using test::unit;

/// m: plus[0], plus[1], minus[0], minus[1].
struct Case : test::MotionCase<4> {
  [[nodiscard]] MotionCombination combination() const {
    MotionCombination f;
    f.plus = {&m[0], &m[1]};
    f.minus = {&m[2], &m[3]};
    return f;
  }
  [[nodiscard]] QPoly exact() const {
    return ex::sub(ex::add(ex::from_motion(m[0]), ex::from_motion(m[1])),
                   ex::add(ex::from_motion(m[2]), ex::from_motion(m[3])));
  }
};

/// The motion with origin `origin` whose coefficients are those of p about `origin`, each
/// rounded to a double (so that it is close to p, not equal).
MotionPolynomial rounded_motion(const QPoly& p, double origin) {
  const std::vector<Q> c = ex::coefficients_about(p, Q(origin));
  std::array<double, kMaxMotionDegree + 1> d{};
  for (std::size_t i = 0; i < c.size() && i <= static_cast<std::size_t>(kMaxMotionDegree); ++i)
    d[i] = c[i].get_d();
  std::size_t n = c.empty() ? 1 : std::min<std::size_t>(c.size(), kMaxMotionDegree + 1);
  return MotionPolynomial::from(std::span<const double>(d.data(), n), origin);
}

/// Checks a CROP result on a combination against the oracle; returns "" or a failure message.
std::string check(const Case& cs) {
  return test::check_crop(cs.combination(), cs.lo, cs.hi, cs.eps, cs.exact());
}

/// Random combinations, three families:
///  0: four random motions (generic roots);
///  1: planted roots (on grid points, on the window's ends, a few ulps past them) in a target g;
///     plus[1] is g + minus[0] + minus[1] - plus[0] rounded about its own origin, so the exact f is
///     g plus tiny rounding terms: roots a few ulps from the planted ones;
///  2: the planted g exactly: plus[0] - minus[0] = g with one origin, plus[1] == minus[1] with
///     another (roots exactly on grid points and window ends; f == 0 when g == 0).
Case generate(std::mt19937_64& rng, int family) {
  Case cs;
  test::draw_window(rng, cs);
  const int degree = 1 + static_cast<int>(rng() % 5);
  if (family == 0) {
    for (MotionPolynomial& p : cs.m) p = random_motion(rng, degree, full_mantissa(rng, -1), 4);
    return cs;
  }
  // g = a * prod (t - r_i), r_i planted.
  // Family 2 needs g's coefficients about a grid point to be doubles: a short leading factor.
  const double lead = family == 2 ? std::ldexp(static_cast<double>(rng() % 255) - 127.0, -5)
                                  : full_mantissa(rng, static_cast<int>(rng() % 5) - 2);
  QPoly g = ex::constant(Q(lead == 0.0 ? 1.0 : lead));
  const int roots = 1 + static_cast<int>(rng() % 4);
  for (int i = 0; i < roots; ++i) {
    const double r = test::planted_root(rng, cs.lo, cs.hi, cs.eps);
    g = ex::mul(g, ex::linear_root(Q(r)));
  }
  if (family == 2 && rng() % 6 == 0) g = QPoly{};  // f identically zero, different origins
  if (family == 1) {
    cs.m[0] = random_motion(rng, degree, full_mantissa(rng, -1), 4);
    cs.m[2] = random_motion(rng, degree, full_mantissa(rng, -1), 4);
    cs.m[3] = random_motion(rng, degree, full_mantissa(rng, -1), 4);
    const QPoly rest =
        ex::sub(ex::add(g, ex::add(ex::from_motion(cs.m[2]), ex::from_motion(cs.m[3]))),
                ex::from_motion(cs.m[0]));
    cs.m[1] = rounded_motion(rest, full_mantissa(rng, -1));
    return cs;
  }
  // family 2: plus[0] - minus[0] == g exactly about origin o: minus[0] random with short
  // mantissas at o, plus[0] = minus[0] + g when every coefficient sum is a double (else g alone).
  const double o = grid_point(cs.lo, cs.hi, cs.eps, rng);
  const std::vector<Q> gc = ex::coefficients_about(g, Q(o));
  std::array<double, kMaxMotionDegree + 1> pc{}, mc{};
  std::size_t n = std::max<std::size_t>(gc.size(), 1);
  for (std::size_t k = 0; k < n; ++k) {
    const Q gk = k < gc.size() ? gc[k] : Q(0);
    mc[k] = std::ldexp(static_cast<double>(rng() % 1024) - 512.0, -4);
    const Q sum = gk + Q(mc[k]);
    if (!ex::representable(sum) || !ex::representable(gk)) return generate(rng, 1);
    pc[k] = sum.get_d();
  }
  cs.m[0] = MotionPolynomial::from(std::span<const double>(pc.data(), n), o);
  cs.m[2] = MotionPolynomial::from(std::span<const double>(mc.data(), n), o);
  cs.m[1] = random_motion(rng, degree, full_mantissa(rng, -1), 4);
  cs.m[3] = cs.m[1];
  // plus[1] and minus[1]: the same function written about two origins when it is linear and
  // the shift is exact; otherwise the same motion.
  if (cs.m[1].degree >= 1) {
    auto short_value = [&](double v, int bits) {
      return std::ldexp(std::round(std::ldexp(v, bits)), -bits);
    };
    const double o1 = short_value(full_mantissa(rng, -1), 8);
    const double o2 = short_value(full_mantissa(rng, -1), 8);
    const std::array<double, 2> lc{short_value(cs.m[1].c[0], 10), short_value(cs.m[1].c[1], 10)};
    const MotionPolynomial lin = MotionPolynomial::from(lc, o1);
    const QPoly lp = ex::from_motion(lin);
    if (auto other = ex::to_motion(ex::coefficients_about(lp, Q(o2)), o2)) {
      cs.m[1] = lin;
      cs.m[3] = *other;
    }
  }
  return cs;
}

TEST(CropCombination, RandomFourMotionCombinationsAgainstTheOracle) {
  const test::OracleTally t =
      test::crop_against_the_oracle("crop combination", 20261122, 600, generate, 3,
                                    [](const Case& cs) { return cs.combination(); });
  EXPECT_GT(t.with_roots, 200);
  EXPECT_GT(t.zero, 0);
}

/// Two boxes under one gravity: the side combination c_a + h_a - c_b - h_b of two parabolas with
/// the same t^2 coefficient (different origins) and constant half extents is linear; CROP takes
/// its linear path (counted as a fast path) and meets (A1)-(A4) against the oracle, roots planted
/// on and near grid points included.
TEST(CropCombination, EqualGravityCombinationsAreLinear) {
  constexpr std::uint64_t kSeed = 4242;
  std::mt19937_64 rng(kSeed);
  int with_roots = 0;
  std::uint64_t fast = 0, calls = 0;
  for (int i = 0; i < 300; ++i) {
    Case cs;
    test::draw_window(rng, cs);
    const double g = -std::ldexp(1.0, static_cast<int>(rng() % 3));  // -1, -2 or -4
    const auto parabola = [&](double origin) {
      const std::array<double, 3> c{full_mantissa(rng, 1), full_mantissa(rng, 0), g};
      return MotionPolynomial::from(c, origin);
    };
    cs.m[0] = parabola(full_mantissa(rng, -1));
    cs.m[1] = MotionPolynomial::from(std::array<double, 1>{0.25 + unit(rng)}, 0.0);
    cs.m[3] = MotionPolynomial::from(std::array<double, 1>{0.25 + unit(rng)}, 0.0);
    if (i % 2 == 0) {
      cs.m[2] = parabola(full_mantissa(rng, -1));
    } else {
      // A root planted in the window: m2 = m0 + m1 - m3 - slope (t - r), written about m0's
      // origin with every coefficient a double (short mantissas), r a planted root.
      const double r = test::planted_root(rng, cs.lo, cs.hi, cs.eps);
      const QPoly rest =
          ex::sub(ex::add(ex::from_motion(cs.m[0]),
                          ex::sub(ex::from_motion(cs.m[1]), ex::from_motion(cs.m[3]))),
                  ex::mul(ex::constant(Q(0.75)), ex::linear_root(Q(r))));
      const double o = cs.m[0].origin;
      const std::vector<Q> c = ex::coefficients_about(rest, Q(o));
      if (c.size() != 3 || !ex::representable(c[0]) || !ex::representable(c[1]) ||
          !ex::representable(c[2])) {
        cs.m[2] = parabola(full_mantissa(rng, -1));
      } else {
        cs.m[2] = MotionPolynomial::from(
            std::array<double, 3>{c[0].get_d(), c[1].get_d(), c[2].get_d()}, o);
      }
    }
    const std::string e = check(cs);
    EXPECT_TRUE(e.empty()) << "seed " << kSeed << " case " << i << ": " << e << "\n"
                           << cs.describe();
    CropStats stats;
    (void)crop(cs.combination(), cs.lo, cs.hi, cs.eps, &stats);
    fast += stats.fast_path;
    calls += stats.calls;
    if (ex::RootOracle(cs.exact()).count_closed(cs.lo, cs.hi) > 0) ++with_roots;
  }
  EXPECT_EQ(fast, calls);  // every one linear
  EXPECT_GT(with_roots, 50);
}

TEST(CropCombination, SignAfterAndSchedulerFailureTime) {
  constexpr std::uint64_t kSeed = 77;
  std::mt19937_64 rng(kSeed);
  const Scheduler robust(SchedulerKind::Robust, 1e-6, 100.0);
  for (int i = 0; i < 200; ++i) {
    const Case cs = generate(rng, 1 + i % 2);
    const MotionCombination f = cs.combination();
    const QPoly exact = cs.exact();
    // sign_after at a planted-root neighbourhood: the sign of the first non-zero derivative.
    const double t = cs.lo;
    int expected = 0;
    QPoly d = exact;
    while (!d.is_zero()) {
      const int s = ex::sign_at(d, Q(t));
      if (s != 0) {
        expected = s;
        break;
      }
      d = ex::derivative(d);
    }
    EXPECT_EQ(sign_after(f, t), expected) << "seed " << kSeed << " case " << i << "\n"
                                          << cs.describe();
    EXPECT_EQ(sign_at(f, t), ex::sign_at(exact, Q(t)));
    // The robust failure time equals EVENTTIME over crop() on the scheduler's window.
    Counters counters;
    const Time got = robust.failure_time(f, cs.lo, cs.lo, counters);
    const CropResult r = crop(f, cs.lo, 100.0, Scheduler::crop_eps(1e-6));
    EXPECT_EQ(got, event_time(r, cs.lo)) << "seed " << kSeed << " case " << i;
  }
}

/// sign_at and sign_after decide most signs by a floating-point filter before the exact path:
/// every sign must be the exact one, at the planted roots (where the filter must decline: the
/// exact value is 0 or a few ulps), a few ulps around them, at random times of the window and far
/// outside it, in every family (the exact zero of family 2 included), counted so that both
/// outcomes of the filter are exercised.
TEST(CropCombination, FilteredSignsAreTheExactSigns) {
  constexpr std::uint64_t kSeed = 2026;
  std::mt19937_64 rng(kSeed);
  int filtered = 0, exact = 0, zeros = 0;
  for (int i = 0; i < 600; ++i) {
    const Case cs = generate(rng, i % 3);
    const MotionCombination f = cs.combination();
    const QPoly e = cs.exact();
    std::vector<double> times = {
        cs.lo,       cs.hi,      std::nextafter(cs.lo, -1e300), std::nextafter(cs.hi, 1e300),
        cs.lo - 1e6, cs.hi + 1e6};
    for (int k = 0; k < 4; ++k) times.push_back(cs.lo + (cs.hi - cs.lo) * unit(rng));
    for (int k = 0; k < 3; ++k) times.push_back(grid_point(cs.lo, cs.hi, cs.eps, rng));
    for (const double t : times) {
      PredicateStats stats;
      const int want = ex::sign_at(e, Q(t));
      ASSERT_EQ(sign_at(f, t, &stats), want)
          << "seed " << kSeed << " case " << i << " t = " << t << "\n"
          << cs.describe();
      filtered += static_cast<int>(stats.filtered);
      exact += static_cast<int>(stats.exact);
      zeros += want == 0 ? 1 : 0;
      if (want != 0) {
        EXPECT_EQ(sign_after(f, t), want) << "seed " << kSeed << " case " << i << " t = " << t;
      }
    }
  }
  EXPECT_GT(filtered, 1000);  // the filter decides most signs...
  EXPECT_GT(exact, 100);      // ...and declines near the roots
  EXPECT_GT(zeros, 10);
}

}  // namespace
}  // namespace kinetic
