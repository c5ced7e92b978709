// CROP, the exact signs and the robust and classic schedulers' decisions on the difference of two
// squared lengths of moving points, f = |a - b|^2 - |c - d|^2 (LengthComparison, read as a sum
// of four products: LengthComparison::products()), with motions of degree 1 to 3 and different
// full-mantissa origins, against the exact oracle of tests/support/exact_poly.hpp (rational
// expansion, Sturm counts; nothing shared with the library's code). Degenerate families: equal
// lengths at a planted time (a grid point, a window end, a few ulps off), equal for ever (a
// segment turned by a right angle, or translated), a point pair that coincides (a == b), both
// pairs coincident (f == 0). Fixed seeds, printed on failure.

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
#include "kinetic/core/error.hpp"
#include "kinetic/core/incircle.hpp"
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
using test::motion_of;
using test::short_motion;
using test::short_value;

/// m[0..7] = a.x, a.y, b.x, b.y, c.x, c.y, d.x, d.y.
struct Case : test::MotionCase<8> {
  [[nodiscard]] LengthComparison lengths() const {
    return LengthComparison{{MovingPoint2{&m[0], &m[1]}, MovingPoint2{&m[2], &m[3]},
                             MovingPoint2{&m[4], &m[5]}, MovingPoint2{&m[6], &m[7]}}};
  }
  [[nodiscard]] QPoly exact() const {
    auto e = [&](int i) { return ex::from_motion(m[static_cast<std::size_t>(i)]); };
    auto sq = [&](int i, int j) {
      const QPoly d = ex::sub(e(i), e(j));
      return ex::mul(d, d);
    };
    return ex::sub(ex::add(sq(0, 2), sq(1, 3)), ex::add(sq(4, 6), sq(5, 7)));
  }
};

/// Families:
///  0: random motions of degree 1-3, random origins (generic roots);
///  1: d = c + J (a - b) + (t - t0) v (J a right angle): |c - d| = |a - b| at a planted t0;
///  2: for ever degenerate: d = c + J (a - b) or d = c + (a - b) (f == 0); a == b (f = -|c -
///     d|^2, double roots where c meets d); a == b and c == d (f == 0).
Case generate(std::mt19937_64& rng, int family) {
  Case cs;
  test::draw_window(rng, cs);
  const int degree = test::draw_motions_up_to_cubic(rng, cs.m);
  if (family == 0) {
    cs.family = "random";
    return cs;
  }
  const double o = test::short_origin_near(cs.lo);
  for (int i = 0; i < 6; ++i) cs.m[static_cast<std::size_t>(i)] = short_motion(rng, degree, o);
  auto e = [&](int i) { return ex::from_motion(cs.m[static_cast<std::size_t>(i)]); };
  // J (a - b) = (-(a_y - b_y), a_x - b_x).
  const QPoly turned_x = ex::sub(e(3), e(1)), turned_y = ex::sub(e(0), e(2));
  if (family == 1) {
    cs.family = "planted";
    const double t0 = test::planted_root(rng, cs.lo, cs.hi, cs.eps);
    const QPoly tt = ex::linear_root(Q(t0));
    const double oc = (rng() & 1) != 0 ? o : full_mantissa(rng, -1);
    cs.m[6] = motion_of(ex::add(ex::add(e(4), turned_x), ex::scale(tt, Q(short_value(rng)))), oc);
    cs.m[7] = motion_of(ex::add(ex::add(e(5), turned_y), ex::scale(tt, Q(short_value(rng)))), oc);
    return cs;
  }
  cs.family = "degenerate";
  switch (rng() % 4) {
    case 0:  // turned by a right angle: equal for ever
      cs.m[6] = motion_of(ex::add(e(4), turned_x), o);
      cs.m[7] = motion_of(ex::add(e(5), turned_y), o);
      break;
    case 1:  // translated: equal for ever
      cs.m[6] = motion_of(ex::add(e(4), ex::sub(e(0), e(2))), o);
      cs.m[7] = motion_of(ex::add(e(5), ex::sub(e(1), e(3))), o);
      break;
    case 2:  // a == b
      cs.m[2] = cs.m[0];
      cs.m[3] = cs.m[1];
      break;
    default:  // a == b, c == d
      cs.m[2] = cs.m[0];
      cs.m[3] = cs.m[1];
      cs.m[6] = cs.m[4];
      cs.m[7] = cs.m[5];
      break;
  }
  return cs;
}

TEST(CropLengths, CropAgainstTheOracle) {
  const test::OracleTally t =
      test::crop_against_the_oracle("crop lengths", 20261129, 600, generate, 3, [](const Case& cs) {
        const ProductSum f = cs.lengths().products();
        EXPECT_EQ(f.degree_bound(), cs.lengths().degree_bound());
        return f;
      });
  t.expect_roots_and_zeros();
}

TEST(CropLengths, SignsAndTheSchedulersDecisions) {
  constexpr std::uint64_t kSeed = 1129;
  std::mt19937_64 rng(kSeed);
  const auto& [robust, classic, careful] = test::DecidingSchedulers(1e-6, 100.0);
  int near_roots = 0, classic_finite = 0;
  for (int i = 0; i < 400; ++i) {
    const Case cs = generate(rng, i % 3);
    const LengthComparison f = cs.lengths();
    const QPoly exact = cs.exact();
    const std::string where = test::case_context(kSeed, i, cs);
    const double t = cs.lo;
    EXPECT_EQ(sign_at(f.products(), t), ex::sign_at(exact, Q(t))) << where;
    EXPECT_EQ(sign_after(f.products(), t), exact_sign_after(exact, t)) << where;

    // Robust: the pretended sign of CROP(f) and EVENTTIME of the certificate it leaves, in the
    // future (Lemma 4); 0 / infinity for f == 0.
    Counters counters;
    const Time window_lo = cs.lo - 0.25;
    if (test::expect_robust_decision(robust, f, f.products(), t, window_lo, exact, counters, where))
      ++near_roots;
    // Classic: failures in the future; away from roots the floating-point sign is the exact one.
    const Scheduler::SignDecision fp = classic.decide(f, t, window_lo, counters);
    if (fp.failure != kTimeInfinity) {
      EXPECT_GT(fp.failure, t) << where;
    }
    if (!exact.is_zero() && ex::RootOracle(exact).count_closed(t - 1e-3, t + 1e-3) == 0) {
      EXPECT_EQ(fp.sign, exact_sign_after(exact, t)) << where;
    }
    // Classic with exact decisions: the exact sign, a failure that is a root of f.
    const Scheduler::SignDecision c =
        test::expect_careful_decision(careful, f, t, window_lo, exact, counters, where);
    if (c.failure <= 100.0) ++classic_finite;
  }
  std::printf("[ crop lengths ] seed %llu: %d robust decisions near a root, %d classic failures\n",
              static_cast<unsigned long long>(kSeed), near_roots, classic_finite);
  EXPECT_GT(near_roots, 0);
  EXPECT_GT(classic_finite, 50);
}

TEST(CropLengths, MotionsOfDegreeFourAreRefusedByRobustAndClassic) {
  const MotionPolynomial quartic = MotionPolynomial::from({0.0, 0.0, 0.0, 0.0, 1.0});
  const MotionPolynomial line = MotionPolynomial::from({1.0, 2.0});
  const LengthComparison f{{MovingPoint2{&quartic, &line}, MovingPoint2{&line, &line},
                            MovingPoint2{&line, &line}, MovingPoint2{&line, &quartic}}};
  EXPECT_EQ(f.degree_bound(), 8);
  for (const SchedulerKind kind : {SchedulerKind::Robust, SchedulerKind::Classic}) {
    const Scheduler s(kind, 1e-6, 100.0);
    Counters counters;
    try {
      (void)s.decide(f, 0.0, 0.0, counters);
      ADD_FAILURE() << "degree 8 taken by " << to_string(kind);
    } catch (const PreconditionError& e) {
      EXPECT_NE(std::string(e.what()).find("degree 8"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace kinetic
