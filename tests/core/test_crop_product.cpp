// CROP, the exact signs and the scheduler's sign decision on a ProductCombination f = (P0 - P1)
// (P2 - P3) - (M0 - M1)(M2 - M3): orientation determinants of three moving points and slope
// comparisons of two moving segments, with motions of degree 1 to 3 and different full-mantissa
// origins, against the exact oracle of tests/support/exact_poly.hpp (rational expansion of the
// products, Sturm counts; nothing shared with the library's code). Degenerate families: roots
// planted on grid points and window ends (points made collinear at a chosen time), points
// collinear for ever, coincident points. Fixed seeds, printed on failure.

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
#include "kinetic/core/float_roots.hpp"
#include "kinetic/core/scheduler.hpp"
#include "support/crop_check.hpp"
#include "support/exact_poly.hpp"

namespace kinetic {
namespace {

namespace ex = ::kinetic::test::exact;
using ex::Q;
using ex::QPoly;
using test::exact_sign_after;
using test::full_mantissa;
using test::grid_point;
using test::motion_of;
using test::random_motion;
using test::short_motion;
using test::short_value;
using test::unit;

/// Eight motions; `slope` tells how f is formed from them: an orientation of the points
/// (m[0], m[1]), (m[2], m[3]), (m[4], m[5]), or the comparison of the slopes of segments
/// (m[0..1] to m[2..3]) and (m[4..5] to m[6..7]).
struct Case : test::MotionCase<8> {
  bool slope = false;

  [[nodiscard]] ProductCombination product() const {
    if (!slope) return orientation(m[0], m[1], m[2], m[3], m[4], m[5]);
    // (y_b - y_a)(x_d - x_c) - (y_d - y_c)(x_b - x_a)
    return ProductCombination{{&m[3], &m[1], &m[6], &m[4]}, {&m[7], &m[5], &m[2], &m[0]}};
  }
  [[nodiscard]] QPoly exact() const {
    auto e = [&](int i) { return ex::from_motion(m[static_cast<std::size_t>(i)]); };
    if (!slope) {
      return ex::sub(ex::mul(ex::sub(e(2), e(0)), ex::sub(e(5), e(1))),
                     ex::mul(ex::sub(e(3), e(1)), ex::sub(e(4), e(0))));
    }
    return ex::sub(ex::mul(ex::sub(e(3), e(1)), ex::sub(e(6), e(4))),
                   ex::mul(ex::sub(e(7), e(5)), ex::sub(e(2), e(0))));
  }
  [[nodiscard]] std::string describe() const {
    return test::describe_motions(family + (slope ? " (slopes)" : " (orientation)"), m, lo, hi,
                                  eps);
  }
};

/// Families:
///  0: random motions of degree 1-3, random origins (generic roots);
///  1: c made collinear with a and b at a planted time t0 (a grid point, a window end, a few ulps
///     off), c = a + lambda (b - a) + (t - t0) v, rounded about its own origin (roots a few ulps
///     from t0) or exact when every coefficient is a double;
///  2: permanently degenerate: c on the line ab for ever (c = a + lambda (b - a) exactly),
///     c coincident with a, a == b, or two parallel segments (f == 0);
///  3: slope comparisons of two random moving segments.
Case generate(std::mt19937_64& rng, int family) {
  Case cs;
  test::draw_window(rng, cs);
  const int degree = test::draw_motions_up_to_cubic(rng, cs.m);
  if (family == 0) {
    cs.family = "random";
    return cs;
  }
  if (family == 3) {
    cs.family = "slopes";
    cs.slope = true;
    return cs;
  }
  // a and b with short coefficients about one short origin, so that exact combinations fit.
  const double o = test::short_origin_near(cs.lo);
  for (int i = 0; i < 4; ++i) cs.m[static_cast<std::size_t>(i)] = short_motion(rng, degree, o);
  const double lambda = std::ldexp(static_cast<double>(rng() % 33) - 8.0, -3);
  auto along = [&](int k) {  // a_k + lambda (b_k - a_k), exactly
    return ex::add(ex::from_motion(cs.m[static_cast<std::size_t>(k)]),
                   ex::scale(ex::sub(ex::from_motion(cs.m[static_cast<std::size_t>(k + 2)]),
                                     ex::from_motion(cs.m[static_cast<std::size_t>(k)])),
                             Q(lambda)));
  };
  if (family == 2) {
    cs.family = "degenerate";
    switch (rng() % 3) {
      case 0:  // on the line for ever
        for (int k = 0; k < 2; ++k) {
          if (auto c = ex::to_motion(ex::coefficients_about(along(k), Q(o)), o))
            cs.m[static_cast<std::size_t>(4 + k)] = *c;
        }
        break;
      case 1:  // c coincident with a
        cs.m[4] = cs.m[0];
        cs.m[5] = cs.m[1];
        break;
      default:  // a == b
        cs.m[2] = cs.m[0];
        cs.m[3] = cs.m[1];
        break;
    }
    return cs;
  }
  cs.family = "planted";
  const double t0 = test::planted_root(rng, cs.lo, cs.hi, cs.eps);
  const std::array<double, 2> v{short_value(rng), short_value(rng)};
  for (int k = 0; k < 2; ++k) {
    const QPoly c = ex::add(along(k), ex::scale(ex::linear_root(Q(t0)), Q(v[k])));
    const double oc = (rng() & 1) != 0 ? o : full_mantissa(rng, -1);
    cs.m[static_cast<std::size_t>(4 + k)] = motion_of(c, oc);
  }
  return cs;
}

TEST(CropProduct, OrientationsAndSlopeComparisonsAgainstTheOracle) {
  int quadratic = 0, quadratic_fast = 0;
  const test::OracleTally t = test::crop_against_the_oracle(
      "crop product", 20261124, 800, generate, 4, [&](const Case& cs) {
        EXPECT_LE(cs.product().degree_bound(), kMaxMotionDegree);
        if (cs.product().degree_bound() == 2) {
          // Products of linear motions take CROP's quadratic path (checked like every case).
          CropStats stats;
          (void)crop(cs.product(), cs.lo, cs.hi, cs.eps, &stats);
          ++quadratic;
          // The quadratic path never subdivides (the general path's seeded subdivision counts
          // in fast_path too, but examines Bernstein boxes).
          quadratic_fast += stats.fast_path > 0 && stats.bernstein_boxes == 0 ? 1 : 0;
        }
        return cs.product();
      });
  std::printf("[ crop product ] %d of degree 2, %d of them finished by the quadratic path\n",
              quadratic, quadratic_fast);
  EXPECT_GT(quadratic_fast, quadratic / 2);
  t.expect_roots_and_zeros();
}

TEST(CropProduct, SignsAndTheSchedulersDecision) {
  constexpr std::uint64_t kSeed = 4242;
  std::mt19937_64 rng(kSeed);
  const auto& [robust, classic, careful] = test::DecidingSchedulers(1e-6, 100.0);
  int past_roots = 0, classic_finite = 0, classic_beyond = 0, float_differs = 0, float_followed = 0;
  for (int i = 0; i < 400; ++i) {
    const Case cs = generate(rng, i % 4);
    const ProductCombination f = cs.product();
    const QPoly exact = cs.exact();
    const std::string where = test::case_context(kSeed, i, cs);
    // Exact signs at the window's start (a planted root may sit exactly there).
    const double t = cs.lo;
    EXPECT_EQ(sign_at(f, t), ex::sign_at(exact, Q(t))) << where;
    EXPECT_EQ(sign_after(f, t), exact_sign_after(exact, t)) << where;

    // Robust: the pretended sign of CROP(f) on the scheduler's window and EVENTTIME of the
    // certificate it leaves, always in the future (Lemma 4); 0 / infinity for f == 0. The
    // pretended sign is the exact sign just after t unless a root lies within a grid cell of t
    // (the CROP interval holding t).
    Counters counters;
    const Time window_lo = cs.lo - 0.25;
    if (test::expect_robust_decision(robust, f, f, t, window_lo, exact, counters, where))
      ++past_roots;
    // Classic (a traditional KDS): the floating-point sign just after t of f's Taylor
    // coefficients at t approximated in double, never an exact predicate; where the
    // floating-point root finder puts a failure of that sign at t itself, the other sign. Its
    // failure is the first floating-point root of sign * f not before t.
    std::array<double, kMaxMotionDegree + 1> phi{};
    approximate_taylor(f, t, phi);
    int degree = 0;
    for (int k = 0; k <= kMaxMotionDegree; ++k) {
      if (phi[k] != 0.0) degree = k;
    }
    const int float_sign = float_sign_after(phi, degree, t, t);
    const Scheduler::SignDecision fp = classic.decide(f, t, window_lo, counters);
    if (fp.sign == float_sign) {
      ++float_followed;
    } else {
      // Only the root finder's sign change at t itself turns the decision around.
      std::array<double, kMaxMotionDegree + 1> g = phi;
      for (double& x : g) x *= float_sign;
      EXPECT_EQ(classic_failure_time(g, degree, t, t), t) << where;
      EXPECT_EQ(fp.sign, -float_sign) << where;
    }
    if (fp.failure != kTimeInfinity) {
      EXPECT_GT(fp.failure, t) << where;
    }
    if (fp.sign != exact_sign_after(exact, t)) ++float_differs;
    // Away from the roots of f (none within 1e-3 of t) and from the zero polynomial, the
    // floating-point sign is the exact one.
    if (!exact.is_zero() && ex::RootOracle(exact).count_closed(t - 1e-3, t + 1e-3) == 0) {
      EXPECT_EQ(fp.sign, exact_sign_after(exact, t)) << where;
    }

    // Classic with exact decisions: the exact sign just after t, and a floating-point root of f
    // not before t. Within the horizon (100) it is a root of f; beyond it, rounding noise in
    // coefficients that cancel exactly can invent roots (the classic scheduler's weakness; such
    // times are never reached).
    const Scheduler::SignDecision c =
        test::expect_careful_decision(careful, f, t, window_lo, exact, counters, where);
    if (c.failure > 100.0 && c.failure != kTimeInfinity) ++classic_beyond;
    if (c.failure <= 100.0) ++classic_finite;
  }
  std::printf(
      "[ crop product ] seed %llu: %d decisions near a root, %d classic failures within "
      "the horizon, %d beyond it; traditional classic: %d signs as floating point reads them, "
      "%d differing from the exact sign\n",
      static_cast<unsigned long long>(kSeed), past_roots, classic_finite, classic_beyond,
      float_followed, float_differs);
  EXPECT_GT(past_roots, 0);
  EXPECT_GT(classic_finite, 50);
  // The degenerate family (f == 0 exactly, or roots planted at t) is where floating point and
  // the exact sign part: the traditional classic must be seen to follow floating point there.
  EXPECT_GT(float_differs, 0);
}

TEST(CropProduct, DegreeBound) {
  const MotionPolynomial cubic = MotionPolynomial::from({0.0, 1.0, 0.0, 1.0});
  const MotionPolynomial line = MotionPolynomial::from({1.0, 2.0});
  const MotionPolynomial quartic = MotionPolynomial::from({0.0, 0.0, 0.0, 0.0, 1.0});
  EXPECT_EQ(orientation(cubic, cubic, line, line, line, line).degree_bound(), 6);
  EXPECT_EQ(orientation(line, line, line, line, line, line).degree_bound(), 2);
  EXPECT_EQ(orientation(quartic, quartic, line, line, line, line).degree_bound(), 8);
  EXPECT_EQ(orientation(quartic, line, line, line, line, line).degree_bound(), 5);
}

}  // namespace
}  // namespace kinetic
