// CROP and the robust and classic schedulers' decisions on the in-circle determinant of four
// points moving on lines (InCircle, degree 4 in t: its Taylor coefficients computed by the
// determinant in truncated polynomial arithmetic), with different full-mantissa origins, against
// the exact oracle of tests/support/exact_poly.hpp. Degenerate families: co-circular at a
// planted time (a grid point, a window end, a few ulps off), co-circular for ever (the corners of
// a translating square), all four on a moving line for ever, a point coincident with another.
// Fixed seeds, printed on failure.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/incircle_lines.hpp"
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
using test::full_mantissa;
using test::motion_of;
using test::random_motion;
using test::short_value;
using test::unit;

/// m[0..7] = a.x, a.y, b.x, b.y, c.x, c.y, d.x, d.y.
struct Case : test::MotionCase<8> {
  double planted = std::nan("");  ///< family 1: where the four are co-circular

  [[nodiscard]] InCircle incircle() const {
    return InCircle{{MovingPoint2{&m[0], &m[1]}, MovingPoint2{&m[2], &m[3]},
                     MovingPoint2{&m[4], &m[5]}, MovingPoint2{&m[6], &m[7]}}};
  }
  [[nodiscard]] QPoly exact() const {
    auto e = [&](int i) { return ex::from_motion(m[static_cast<std::size_t>(i)]); };
    const QPoly adx = ex::sub(e(0), e(6)), ady = ex::sub(e(1), e(7));
    const QPoly bdx = ex::sub(e(2), e(6)), bdy = ex::sub(e(3), e(7));
    const QPoly cdx = ex::sub(e(4), e(6)), cdy = ex::sub(e(5), e(7));
    const auto lift = [](const QPoly& x, const QPoly& y) {
      return ex::add(ex::mul(x, x), ex::mul(y, y));
    };
    const auto cross = [](const QPoly& a, const QPoly& b, const QPoly& c, const QPoly& d) {
      return ex::sub(ex::mul(a, b), ex::mul(c, d));
    };
    return ex::add(ex::sub(ex::mul(lift(adx, ady), cross(bdx, cdy, bdy, cdx)),
                           ex::mul(lift(bdx, bdy), cross(adx, cdy, ady, cdx))),
                   ex::mul(lift(cdx, cdy), cross(adx, bdy, ady, bdx)));
  }
};

/// Families:
///  0: random lines, random origins (generic roots);
///  1: a, b, c at the corners (0, 0), (2s, 0), (0, 2s) of a right triangle moving as one (a
///     translation w t), d through the fourth corner (2s, 2s) of its circle's square at a
///     planted t0 with its own velocity: co-circular at t0;
///  2: for ever degenerate: the corners of a translating square (co-circular for ever), four
///     points on one moving line, d coincident with a.
Case generate(std::mt19937_64& rng, int family) {
  Case cs;
  test::draw_window(rng, cs);
  for (MotionPolynomial& p : cs.m) p = random_motion(rng, 1, full_mantissa(rng, -1), 3);
  if (family == 0) {
    cs.family = "random lines";
    return cs;
  }
  const double o = test::short_origin_near(cs.lo);
  const double s = std::ldexp(1.0 + static_cast<double>(rng() % 8), -2);
  const std::array<double, 2> w{short_value(rng), short_value(rng)};
  const auto line = [&](double x, double v) { return MotionPolynomial::from({x, v}, o); };
  const std::array<std::array<double, 2>, 4> corner{
      {{0, 0}, {2 * s, 0}, {0, 2 * s}, {2 * s, 2 * s}}};
  for (std::size_t i = 0; i < 4; ++i) {
    cs.m[2 * i] = line(corner[i][0] + short_value(rng), w[0]);
    cs.m[2 * i + 1] = line(corner[i][1] + short_value(rng), w[1]);
  }
  // The same offset for all four (a translation).
  const double dx = cs.m[0].c[0], dy = cs.m[1].c[0];
  for (std::size_t i = 0; i < 4; ++i) {
    cs.m[2 * i] = line(corner[i][0] + dx, w[0]);
    cs.m[2 * i + 1] = line(corner[i][1] + dy, w[1]);
  }
  if (family == 1) {
    cs.family = "planted";
    const double t0 = test::planted_root(rng, cs.lo, cs.hi, cs.eps);
    cs.planted = t0;
    const QPoly tt = ex::linear_root(Q(t0));
    const double oc = (rng() & 1) != 0 ? o : full_mantissa(rng, -1);
    for (int k = 0; k < 2; ++k) {
      const QPoly base = ex::from_motion(cs.m[static_cast<std::size_t>(6 + k)]);
      cs.m[static_cast<std::size_t>(6 + k)] =
          motion_of(ex::add(base, ex::scale(tt, Q(short_value(rng)))), oc);
    }
    return cs;
  }
  cs.family = "degenerate";
  switch (rng() % 3) {
    case 0:  // the square's corners, translating: co-circular for ever
      break;
    case 1:  // four points on the moving line through a and b
      for (std::size_t i = 2; i < 4; ++i) {
        const double lambda = static_cast<double>(i);  // c = a + 2 (b - a), d = a + 3 (b - a)
        for (int k = 0; k < 2; ++k) {
          const QPoly a = ex::from_motion(cs.m[static_cast<std::size_t>(k)]);
          const QPoly b = ex::from_motion(cs.m[static_cast<std::size_t>(2 + k)]);
          cs.m[2 * i + static_cast<std::size_t>(k)] =
              motion_of(ex::add(a, ex::scale(ex::sub(b, a), Q(lambda))), o);
        }
      }
      break;
    default:  // d on a
      cs.m[6] = cs.m[0];
      cs.m[7] = cs.m[1];
      break;
  }
  return cs;
}

TEST(CropInCircle, CropAgainstTheOracle) {
  const test::OracleTally t = test::crop_against_the_oracle(
      "crop in-circle", 2026112901, 450, generate, 3, [](const Case& cs) {
        EXPECT_LE(cs.incircle().degree_bound(), 4);
        return cs.incircle();
      });
  t.expect_roots_and_zeros();
}

TEST(CropInCircle, TheSchedulersDecisions) {
  constexpr std::uint64_t kSeed = 291129;
  std::mt19937_64 rng(kSeed);
  const auto& [robust, classic, careful] = test::DecidingSchedulers(1e-6, 100.0);
  int near_roots = 0, classic_finite = 0;
  for (int i = 0; i < 300; ++i) {
    const Case cs = generate(rng, i % 3);
    const InCircle f = cs.incircle();
    const QPoly exact = cs.exact();
    const std::string where = test::case_context(kSeed, i, cs);
    const double t = cs.lo;
    Counters counters;
    const Time window_lo = cs.lo - 0.25;
    if (test::expect_robust_decision(robust, f, f, t, window_lo, exact, counters, where))
      ++near_roots;
    const Scheduler::SignDecision fp = classic.decide(f, t, window_lo, counters);
    if (fp.failure != kTimeInfinity) {
      EXPECT_GT(fp.failure, t) << where;
    }
    const Scheduler::SignDecision c =
        test::expect_careful_decision(careful, f, t, window_lo, exact, counters, where);
    if (c.failure <= 100.0) ++classic_finite;
  }
  std::printf(
      "[ crop in-circle ] seed %llu: %d robust decisions near a root, %d classic failures\n",
      static_cast<unsigned long long>(kSeed), near_roots, classic_finite);
  EXPECT_GT(near_roots, 0);
  EXPECT_GT(classic_finite, 30);
}

/// The search from a grid point that stops at the first failure (crop_first_failure, the robust
/// Delaunay triangulation's decision) gives the time event_time() gives over the whole CROP result
/// of any window starting before it, at fine and coarse grids, on every family (planted roots
/// put co-circular instants on grid points and a few ulps off them); and the scheduler's
/// decide_from_grid_point() gives decide()'s decision whenever decide()'s pretended sign is the
/// sign at the grid point.
TEST(CropInCircle, TheSearchFromAGridPointStopsAtTheFirstFailureWithCropsTime) {
  constexpr std::uint64_t kSeed = 2026112902;
  std::mt19937_64 rng(kSeed);
  int searched = 0, failing = 0, zero_at_grid = 0;
  for (int i = 0; i < 600; ++i) {
    const Case cs = generate(rng, i % 3);
    const InCircle f = cs.incircle();
    const double span = cs.hi - cs.lo;
    for (int k = 0; k < 4; ++k) {
      const double t = cs.lo + span * unit(rng);
      const Time g = crop_grid_floor(t, cs.eps);
      const int s = sign_at(f, g);
      const std::string where = test::case_context(kSeed, i, t, cs);
      if (s == 0) {
        ++zero_at_grid;
        continue;
      }
      ++searched;
      const Time window_lo = cs.lo - 0.25 * span * unit(rng);
      const CropResult whole = crop(f, std::min(window_lo, g), cs.hi, cs.eps);
      const Time want = event_time(s > 0 ? whole : negated(whole), t);
      const Time got = crop_first_failure(f, s, g, cs.hi, cs.eps, t);
      EXPECT_EQ(got, want) << where;
      if (got != kTimeInfinity) ++failing;
    }
    if (::testing::Test::HasFailure()) break;
  }
  std::printf(
      "[ crop in-circle ] seed %llu: %d searches from a grid point, %d ending at a "
      "failure, %d grid points on a root\n",
      static_cast<unsigned long long>(kSeed), searched, failing, zero_at_grid);
  EXPECT_GT(failing, searched / 5);
  EXPECT_GT(zero_at_grid, 0);

  for (const double eps : {1e-9, 0.25}) {
    const Scheduler robust(SchedulerKind::Robust, eps, 100.0);
    int agreeing = 0;
    for (int i = 0; i < 300; ++i) {
      const Case cs = generate(rng, i % 3);
      const InCircle f = cs.incircle();
      const Time t = cs.lo + (cs.hi - cs.lo) * unit(rng);
      const Time window_lo = cs.lo - 0.25;
      Counters counters;
      const Scheduler::SignDecision d = robust.decide(f, t, window_lo, counters);
      const int s = sign_at(f, Scheduler::grid_floor(eps, t));
      if (s == 0 || d.sign != s) continue;
      ++agreeing;
      const Scheduler::SignDecision fast =
          robust.decide_from_grid_point(f, s, t, window_lo, counters);
      EXPECT_EQ(fast.sign, d.sign) << "eps " << eps << " case " << i << "\n" << cs.describe();
      EXPECT_EQ(fast.failure, d.failure) << "eps " << eps << " case " << i << "\n" << cs.describe();
    }
    EXPECT_GT(agreeing, 150) << "eps " << eps;
  }
}

TEST(CropInCircle, PointsOnParabolasAreRefusedByRobustAndClassic) {
  const MotionPolynomial parabola = MotionPolynomial::from({0.0, 0.0, 1.0});
  const MotionPolynomial line = MotionPolynomial::from({1.0, 2.0});
  const InCircle f{{MovingPoint2{&parabola, &line}, MovingPoint2{&line, &line},
                    MovingPoint2{&line, &parabola}, MovingPoint2{&line, &line}}};
  EXPECT_EQ(f.degree_bound(), 8);
  for (const SchedulerKind kind : {SchedulerKind::Robust, SchedulerKind::Classic}) {
    const Scheduler s(kind, 1e-6, 100.0);
    Counters counters;
    EXPECT_THROW((void)s.decide(f, 0.0, 0.0, counters), PreconditionError) << to_string(kind);
  }
}

}  // namespace
}  // namespace kinetic

namespace kinetic {
namespace {

/// Four points near one another far from the origin (coordinates about 1e5, neighbours about 1
/// apart, full-mantissa origins): where the in-circle's value is small against the positions'
/// magnitudes, so the error bounds must follow the differences, not the positions.
Case far_cluster(std::mt19937_64& rng) {
  Case cs;
  cs.family = "far cluster";
  test::draw_window(rng, cs, 20);
  const double cx = 1e5 * (1.0 + unit(rng)), cy = -1e5 * (1.0 + unit(rng));
  for (std::size_t i = 0; i < 4; ++i) {
    const double o = full_mantissa(rng, -1);
    cs.m[2 * i] = MotionPolynomial::from({cx + 2.0 * unit(rng), short_value(rng)}, o);
    cs.m[2 * i + 1] = MotionPolynomial::from({cy + 2.0 * unit(rng), short_value(rng)}, o);
  }
  return cs;
}

/// Case i of the four families: generate()'s and the far cluster.
Case any_family(std::mt19937_64& rng, int i) {
  return i % 4 == 3 ? far_cluster(rng) : generate(rng, i % 4);
}

/// The bounds of the in-circle's coefficients (src/core/incircle_lines.hpp) hold the exact
/// Taylor coefficients at the grid point, and the filtered sign at a point is the exact sign
/// whenever it decides; both decide nearly everywhere on generic input (a bound that is not
/// tight enough would send everything to the slow paths).
TEST(CropInCircle, TheBoundedCoefficientsHoldTheExactOnes) {
  constexpr std::uint64_t kSeed = 2026120102;
  std::mt19937_64 rng(kSeed);
  int signs = 0, decided = 0, generic = 0, decided_generic = 0;
  for (int i = 0; i < 800; ++i) {
    const Case cs = any_family(rng, i);
    const InCircle f = cs.incircle();
    const QPoly exact = cs.exact();
    const double t = cs.lo + (cs.hi - cs.lo) * unit(rng);
    const std::string where = test::case_context(kSeed, i, t, cs);
    detail::BoundedTaylor bt;
    ASSERT_TRUE(detail::incircle_of_lines_at(f, t, bt)) << where;
    const std::vector<Q> want = ex::coefficients_about(exact, Q(t));
    for (std::size_t k = 0; k < 5; ++k) {
      const Q c = k < want.size() ? want[k] : Q(0);
      EXPECT_LE(abs(Q(bt.c[k]) - c), Q(bt.e[k])) << "coefficient " << k << " " << where;
    }
    const int s = detail::filtered_incircle_sign(f, t);
    const int truth = ex::sign_at(exact, t);
    ++signs;
    if (s != 0) {
      ++decided;
      EXPECT_EQ(s, truth) << where;
    }
    EXPECT_TRUE(detail::certified_sign(bt, 0.0) == 0 || detail::certified_sign(bt, 0.0) == truth)
        << where;
    if (cs.family == "random lines" || cs.family == "far cluster") {
      ++generic;
      decided_generic += s != 0 ? 1 : 0;
    }
    if (::testing::Test::HasFailure()) break;
  }
  std::printf("[ crop in-circle ] seed %llu: %d filtered signs, %d decided (%d of %d generic)\n",
              static_cast<unsigned long long>(kSeed), signs, decided, decided_generic, generic);
  EXPECT_GE(decided_generic, generic * 95 / 100);
}

/// Scheduler::decide_after_grid_point (the robust Delaunay triangulation's in-circle decision:
/// one evaluation at the grid point for the sign and the search) gives the sign just after the
/// grid point and decide_from_grid_point()'s decision, as the two calls would, on every family;
/// at times whose grid point is a planted co-circular instant too, where the exact sign just
/// after it and CROP's pretended sign differ (the decision must keep both).
TEST(CropInCircle, TheDecisionAfterAGridPointIsTheSignThereAndTheSearch) {
  constexpr std::uint64_t kSeed = 2026120103;
  std::mt19937_64 rng(kSeed);
  int decided = 0, holding = 0, zero_at_grid = 0, pretended_differs = 0;
  for (int i = 0; i < 900; ++i) {
    const Case cs = any_family(rng, i);
    const InCircle f = cs.incircle();
    // A scheduler whose grid is the case's (so that planted instants are grid points).
    const double eps = 1.2 * cs.eps;
    const Scheduler robust(SchedulerKind::Robust, eps, cs.hi + 1.0);
    ASSERT_EQ(Scheduler::grid_width(eps), cs.eps);
    std::vector<Time> times{cs.lo + (cs.hi - cs.lo) * unit(rng)};
    if (!std::isnan(cs.planted)) {
      times.push_back(cs.planted);  // now at the grid point (an event processed there)
      times.push_back(cs.planted + 0.5 * cs.eps * unit(rng));
    }
    for (const Time t : times) {
      const Time g = Scheduler::grid_floor(eps, t);
      const std::string where = test::case_context(kSeed, i, t, cs);
      for (const int h : {-1, 1}) {
        Counters counters, reference_counters;
        int s = 2;
        const Scheduler::SignDecision d =
            robust.decide_after_grid_point(f, h, t, cs.lo, counters, s);
        const int want_sign = sign_after(f, g);
        ASSERT_EQ(s, want_sign) << where;
        ++decided;
        if (s != h) {
          EXPECT_EQ(d.sign, s) << where;
          EXPECT_EQ(d.failure, kTimeInfinity) << where;
          continue;
        }
        ++holding;
        const Scheduler::SignDecision want =
            robust.decide_from_grid_point(f, h, t, cs.lo, reference_counters);
        EXPECT_EQ(d.sign, want.sign) << where;
        EXPECT_EQ(d.failure, want.failure) << where;
        if (sign_at(f, g) == 0) ++zero_at_grid;
        if (d.sign != s) ++pretended_differs;
      }
    }
    if (::testing::Test::HasFailure()) break;
  }
  std::printf(
      "[ crop in-circle ] seed %llu: %d decisions, %d holding at the grid point, %d with f = 0 "
      "there, %d where CROP's pretended sign differs\n",
      static_cast<unsigned long long>(kSeed), decided, holding, zero_at_grid, pretended_differs);
  EXPECT_GT(holding, decided / 4);
  EXPECT_GT(pretended_differs, 0);
}

/// The in-circle of points on lines in floating point with error bounds
/// (src/core/incircle_lines.hpp): its coefficients' bounds hold against the exact Taylor
/// coefficients, its certified signs are the exact signs, and the search from a grid point gives
/// CROP's general answer whenever it answers, on every family, at fine and coarse grids.
TEST(CropInCircle, TheBoundedFloatSearchGivesCropsAnswer) {
  constexpr std::uint64_t kSeed = 2026120101;
  std::mt19937_64 rng(kSeed);
  int searched = 0, answered = 0, failing = 0;
  for (int i = 0; i < 900; ++i) {
    const Case cs = any_family(rng, i);
    const InCircle f = cs.incircle();
    const double span = cs.hi - cs.lo;
    const double t = cs.lo + span * unit(rng);
    const Time g = crop_grid_floor(t, cs.eps);
    const std::string where = test::case_context(kSeed, i, t, cs);
    detail::BoundedTaylor bt;
    ASSERT_TRUE(detail::incircle_of_lines_at(f, g, bt)) << where;
    const int s = sign_at(f, g);
    EXPECT_TRUE(detail::certified_sign(bt, 0.0) == 0 || detail::certified_sign(bt, 0.0) == s)
        << where;
    if (s == 0) continue;
    ++searched;
    CropStats general_stats, bounded_stats;
    const Time want =
        detail::crop_first_failure(f, nullptr, s, g, cs.hi, cs.eps, t, &general_stats);
    const Time got = detail::crop_first_failure(f, &bt, s, g, cs.hi, cs.eps, t, &bounded_stats);
    EXPECT_EQ(got, want) << where;
    answered += static_cast<int>(bounded_stats.bounded_float);
    if (want != kTimeInfinity) ++failing;
    if (::testing::Test::HasFailure()) break;
  }
  std::printf(
      "[ crop in-circle ] seed %llu: %d searches, %d answered in bounded floating point, %d "
      "ending at a failure\n",
      static_cast<unsigned long long>(kSeed), searched, answered, failing);
  EXPECT_GT(failing, searched / 5);
  EXPECT_GT(answered, searched * 3 / 4);
}

}  // namespace
}  // namespace kinetic
