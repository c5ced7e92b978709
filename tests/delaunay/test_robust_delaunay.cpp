// The kinetic Delaunay triangulation under the robust scheduler (CROP at eps, events processed at
// the ends of their grid cells, out of order within a cell) against the brute-force oracle. The
// guarantee asserted: after the simulator reaches t, the triangles are exactly the Delaunay
// triangulation just after the grid point at or before t (the harness computes that point from
// the grid's definition and asks the oracle there), and validate() holds after every event (a
// plane triangulation once an instant's events are done: every finite triangle counter-clockwise,
// every certificate holding or due, a hull that winds once). The precisions run from 1e-9 (cells
// far narrower than the gaps between events) to coarse ones (0.05 to 1: many events per cell,
// triangles inverted within a cell, repairs). Fixed seeds, printed on failure.

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <cstdio>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "kinetic/core/crop.hpp"
#include "kinetic/core/error.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/delaunay/kinetic_delaunay.hpp"
#include "support/delaunay_run.hpp"

namespace kinetic {
namespace {

using test::DelaunayRun;
using test::linear;
using test::Motion;
using test::play;
using test::Totals;

test::Scenarios<KineticDelaunay> robust(double eps) {
  test::Scenarios<KineticDelaunay> s;
  s.kind = SchedulerKind::Robust;
  s.eps = eps;
  s.tag = ", robust, eps " + std::to_string(eps);
  return s;
}

/// The counters the coarse runs add up, to show the fold repairs ran.
struct Folds {
  std::uint64_t repairs = 0, local_repairs = 0, deferrals = 0, rebuilds = 0, flips = 0,
                turbulent_checks = 0;
  [[nodiscard]] std::string summary() const {
    std::ostringstream os;
    os << flips << " flips, " << repairs << " folds repaired (" << local_repairs << " locally), "
       << deferrals << " deferrals, " << rebuilds << " builds, " << turbulent_checks
       << " orientations looked at again after a turbulent cell";
    return os.str();
  }
};
std::function<void(DelaunayRun<KineticDelaunay>&)> count_into(Folds& f) {
  return [&f](DelaunayRun<KineticDelaunay>& run) {
    const DelaunayCounters& c = run.dt->counters();
    f.repairs += c.repairs;
    f.local_repairs += c.local_repairs;
    f.deferrals += c.deferrals;
    f.rebuilds += c.rebuilds;
    f.flips += c.flips;
    f.turbulent_checks += c.turbulent_checks;
  };
}

TEST(RobustDelaunay, RandomLinesAtFinePrecisionAgainstTheOracle) {
  const Totals totals = robust(1e-9).random_lines();
  EXPECT_GT(totals.events, 100u);
  EXPECT_GT(totals.triangles, 500u);
}

/// Coarse grids: many flips share a cell, so a triangle may turn clockwise before its in-circle
/// flip is processed; the triangulation is repaired and equals the oracle's at the grid point.
TEST(RobustDelaunay, RandomLinesAtCoarsePrecisionsAgainstTheOracle) {
  Folds folds;
  for (const double eps : {0.05, 0.3, 1.0}) {
    auto s = robust(eps);
    s.after = count_into(folds);
    const Totals totals = s.random_lines();
    EXPECT_GT(totals.probes, 100u) << "eps " << eps;
    if (::testing::Test::HasFailure()) return;
  }
  std::printf("[ robust delaunay ] coarse random lines: %s\n", folds.summary().c_str());
  EXPECT_GT(folds.repairs, 0u);  // the coarse grids did fold the triangulation
}

/// Many points in a small square at a coarse precision: folds within a cell are common, and most
/// are repaired locally (a vertex out and in again) rather than by building again.
TEST(RobustDelaunay, FoldsWithinACellAreRepairedLocally) {
  Folds folds;
  Totals totals;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    std::mt19937_64 rng(seed * 101);
    DelaunayRun<KineticDelaunay> run(0.0, 8.0, SchedulerKind::Robust, 0.125);
    std::uniform_real_distribution<double> u(-5.0, 5.0), v(-2.0, 2.0);
    for (int i = 0; i < 60; ++i) run.add(i, linear(u(rng), u(rng), v(rng), v(rng)));
    run.start();
    play(run, 8.0, 12, {}, seed, seed % 2 == 0, 1, totals,
         "60 points in a square, eps 0.125, seed " + std::to_string(seed));
    if (::testing::Test::HasFailure()) return;
    count_into(folds)(run);
  }
  std::printf("[ robust delaunay ] 60 points, eps 0.125: %s\n", folds.summary().c_str());
  EXPECT_GT(folds.repairs, 0u);
  EXPECT_GT(folds.local_repairs, 0u);
  // Some folds have no vertex to take out and put back (on the hull, or no simple link): those
  // are built again, and the runs above validated after them too.
  EXPECT_GT(folds.repairs, folds.local_repairs);
}

TEST(RobustDelaunay, IntegerGridsCoCircularAndCollidingAgainstTheOracle) {
  EXPECT_GT(robust(1e-9).integer_grids().events, 50u);
  EXPECT_GT(robust(0.25).integer_grids().probes, 50u);
}

TEST(RobustDelaunay, CollisionCourseAgainstTheOracle) {
  (void)robust(1e-9).collision_course();
  (void)robust(0.1).collision_course();
}

TEST(RobustDelaunay, IdenticalGroupsThroughUpdatesAndRemovesInEveryOrder) {
  EXPECT_GT(robust(1e-9).identical_groups().probes, 100u);
}

/// A grid translating as one: co-circular for ever, every tie broken by the lifting
/// perturbation, under CROP's decisions too (its in-circle polynomials are zero: the cofactors'
/// decide).
TEST(RobustDelaunay, TranslatingGridIsCoCircularForEver) {
  for (const double eps : {1e-9, 0.5}) {
    Totals totals;
    DelaunayRun<KineticDelaunay> run(0.0, 4.0, SchedulerKind::Robust, eps);
    ObjectId id = 0;
    for (int x = 0; x < 4; ++x) {
      for (int y = 0; y < 4; ++y) run.add(id++, linear(x, y, 0.5, -0.25));
    }
    run.start();
    play(run, 4.0, 6, {1.0, 2.0}, 5, true, 1, totals,
         "translating grid, robust, eps " + std::to_string(eps));
  }
}

TEST(RobustDelaunay, RefusesParabolasNamingTheDegreeLimit) {
  MotionTable table(2);
  for (int p = 0; p < 3; ++p) (void)table.insert(p, linear(p, p * p, 1, -p));
  Simulator sim(0.0);
  Scheduler scheduler(SchedulerKind::Robust, 1e-9, 10.0);
  KineticDelaunay dt(table, sim, scheduler);
  dt.initialize();
  const std::uint32_t i = table.insert(7, test::parabola(0, 0, 1, 0, 0.5, 0)).index;
  try {
    dt.insert(i);
    ADD_FAILURE() << "accepted a parabola under the robust scheduler";
  } catch (const PreconditionError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("object 7"), std::string::npos) << what;
    EXPECT_NE(what.find("degree <= 1 under the robust scheduler"), std::string::npos) << what;
  }
}

/// A triangle that turns over and back within one grid cell: a = (0, 0), b = (1, t),
/// c = (2.04 - t, 1.0403) have orient(a, b, c) = t^2 - 2.04 t + 1.0403 = (t - 1.01)(t - 1.03),
/// both roots in the cell (0.96875, 1.03125) of eps = 0.1 (w = 1/16). CROP reports no event
/// there (a turbulent interval, A4); the scheduler names the cell's end, and the triangulation
/// looks at the triangle again there (and audits its hull), staying valid throughout.
TEST(RobustDelaunay, ATriangleTurningOverAndBackWithinACellIsLookedAtAgain) {
  const Motion a = linear(0.0, 0.0, 0.0, 0.0), b = linear(1.0, 0.0, 0.0, 1.0),
               c = linear(2.04, 1.0403, -1.0, 0.0);
  const Scheduler scheduler(SchedulerKind::Robust, 0.1, 4.0);
  ASSERT_EQ(Scheduler::grid_width(0.1), 0.0625);
  const ProductCombination f = orientation(a[0], a[1], b[0], b[1], c[0], c[1]);
  Counters counters;
  Time turbulent = 0.0;
  const Scheduler::SignDecision d = scheduler.decide(f, 0.5, 0.0, counters, &turbulent);
  EXPECT_EQ(d.sign, 1);
  EXPECT_EQ(d.failure, kTimeInfinity);  // no event: it ends counter-clockwise
  EXPECT_EQ(turbulent, 1.03125);
  Time none = 0.0;
  (void)scheduler.decide(f, 1.5, 0.0, counters, &none);
  EXPECT_EQ(none, kTimeInfinity);  // none after 1.5

  Totals totals;
  std::mt19937_64 rng(17);
  DelaunayRun<KineticDelaunay> run(0.0, 4.0, SchedulerKind::Robust, 0.1);
  run.add(0, a);
  run.add(1, b);
  run.add(2, c);
  run.add(3, linear(-3.0, -3.0, 0.0, 0.0));
  run.add(4, linear(4.0, -2.0, 0.0, 0.0));
  run.start();
  ASSERT_TRUE(run.advance(2.0, totals, "a triangle turning over and back"));
  ASSERT_TRUE(run.check(totals, rng, "a triangle turning over and back"));
  EXPECT_GT(run.dt->counters().turbulent_checks, 0u);
}

}  // namespace
}  // namespace kinetic
