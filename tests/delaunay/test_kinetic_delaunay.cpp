// The kinetic Delaunay triangulation against the brute-force oracle (every triangle whose circle
// is empty just after t, co-circular ties by the lifting perturbation by ids), under the exact
// scheduler: random lines and parabolas, integer grids (co-circular and collinear at every
// integer time, points passing through each other), a translating grid (co-circular for ever),
// collinear points (flat), points on a collision course, identical motions, with inserts,
// removes and flight-plan updates. validate() after every event; at probe times the triangles,
// the closest pair and exact nearest neighbours equal the oracle's. Fixed seeds, printed on
// failure.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "kinetic/core/error.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/delaunay/kinetic_delaunay.hpp"
#include "kinetic/oracle/oracle.hpp"
#include "support/delaunay_run.hpp"

namespace kinetic {
namespace {

using test::DelaunayRun;
using test::linear;
using test::Motion;
using test::parabola;
using test::play;
using test::Totals;

TEST(KineticDelaunay, RandomLinesAgainstTheOracle) {
  const Totals totals = test::Scenarios<KineticDelaunay>{}.random_lines();
  EXPECT_GT(totals.events, 100u);
  EXPECT_GT(totals.triangles, 500u);
}

TEST(KineticDelaunay, RandomParabolasAgainstTheOracle) {
  EXPECT_GT(test::Scenarios<KineticDelaunay>{}.random_parabolas().events, 10u);
}

/// Points of a small integer grid with integer velocities: co-circular and collinear quadruples
/// at every integer time, points passing through each other, identical motions.
TEST(KineticDelaunay, IntegerGridsCoCircularAndCollidingAgainstTheOracle) {
  EXPECT_GT(test::Scenarios<KineticDelaunay>{}.integer_grids().events, 50u);
}

/// A grid translating as one: every square's four corners are co-circular for ever, so every
/// tie is broken by the lifting perturbation, in the kinetic structure and the oracle alike.
TEST(KineticDelaunay, TranslatingGridIsCoCircularForEver) {
  Totals totals;
  DelaunayRun<KineticDelaunay> run(0.0, 4.0);
  ObjectId id = 0;
  for (int x = 0; x < 4; ++x) {
    for (int y = 0; y < 4; ++y) run.add(id++, linear(x, y, 0.5, -0.25));
  }
  run.start();
  play(run, 4.0, 6, {1.0, 2.0}, 5, true, 1, totals, "translating grid");
}

TEST(KineticDelaunay, CollinearPointsStayFlatUntilAPointLeavesTheLine) {
  Totals totals;
  std::mt19937_64 rng(3);
  DelaunayRun<KineticDelaunay> run(0.0, 10.0);
  for (int i = 0; i < 6; ++i) run.add(i, linear(i, 2.0 * i, 0.5 - 0.2 * i, 1.0 - 0.4 * i));
  run.start();
  EXPECT_TRUE(run.dt->triangles().empty());
  ASSERT_TRUE(run.advance(2.0, totals, "collinear"));
  ASSERT_TRUE(run.check(totals, rng, "collinear"));
  const std::uint32_t off = run.table.insert(10, linear(1.0, -3.0, 0.0, 0.0), 2.0).index;
  run.dt->insert(off);
  ASSERT_TRUE(run.dt->validate());
  ASSERT_TRUE(run.check(totals, rng, "collinear plus one"));
  EXPECT_FALSE(run.dt->triangles().empty());
  ASSERT_TRUE(run.advance(6.0, totals, "collinear plus one"));
  ASSERT_TRUE(run.check(totals, rng, "collinear plus one, later"));
  run.table.remove(run.table.handle(off));
  run.dt->remove(off);
  ASSERT_TRUE(run.dt->validate());
  EXPECT_TRUE(run.dt->triangles().empty());
  ASSERT_TRUE(run.check(totals, rng, "collinear again"));
}

/// Points on a circle moving through its centre: all meet at t = 1 and pass through each other;
/// and pairs that collide head on.
TEST(KineticDelaunay, CollisionCourseAgainstTheOracle) {
  (void)test::Scenarios<KineticDelaunay>{}.collision_course();
}

TEST(KineticDelaunay, IdenticalMotionsAreOneVertexNamedByTheSmallestId) {
  (void)test::Scenarios<KineticDelaunay>{}.copies();
}

/// Groups of identical motions through updates onto the group's motion and removes in every
/// order (a crash found by fuzzing).
TEST(KineticDelaunay, IdenticalGroupsThroughUpdatesAndRemovesInEveryOrder) {
  EXPECT_GT(test::Scenarios<KineticDelaunay>{}.identical_groups().probes, 100u);
}

/// Removes and flight-plan updates are local (hull vertices peeled, inner ones by ear clipping of
/// the hole, then flips): a long mixed sequence on random points, the oracle after every
/// change, and (almost) none of them building again.
TEST(KineticDelaunay, RemovesAndUpdatesAreLocalAgainstTheOracle) {
  const auto [start, c] = test::Scenarios<KineticDelaunay>{}.mixed_changes(10.0);
  const std::uint64_t built = start.rebuilds;
  std::printf("[ delaunay ] 40 removes and updates: %llu local, %llu built again\n",
              static_cast<unsigned long long>(c.local_removals),
              static_cast<unsigned long long>(c.rebuilds - built));
  EXPECT_GE(c.local_removals, 35u);
  EXPECT_LE(c.rebuilds - built, 5u);
}

/// Copies on a grid translating as one (co-circular for ever): when the copy that stands for a
/// group leaves, the next (another id) takes its place, and the ties the perturbation breaks by
/// id are decided again.
TEST(KineticDelaunay, CopiesOnACoCircularGridTakeTheirVertexPlace) {
  Totals totals;
  std::mt19937_64 rng(31);
  DelaunayRun<KineticDelaunay> run(0.0, 4.0);
  ObjectId id = 10;
  for (int x = 0; x < 4; ++x) {
    for (int y = 0; y < 4; ++y) run.add(id++, linear(x, y, 0.5, 0.25));
  }
  // Copies of three grid points, one with a smaller id than every grid point.
  run.add(1, linear(1, 1, 0.5, 0.25));
  run.add(40, linear(2, 1, 0.5, 0.25));
  run.add(41, linear(1, 2, 0.5, 0.25));
  run.start();
  ASSERT_TRUE(run.check(totals, rng, "copies on a grid"));
  for (const ObjectId gone : {ObjectId{1}, ObjectId{15}, ObjectId{16}, ObjectId{14}}) {
    ASSERT_TRUE(run.advance(run.sim.now() + 0.5, totals, "copies on a grid"));
    const std::uint32_t i = run.table.find(gone)->index;
    run.table.remove(run.table.handle(i));
    run.dt->remove(i);
    ASSERT_TRUE(run.dt->validate()) << "after removing " << gone;
    ASSERT_TRUE(run.check(totals, rng, "copies on a grid, " + std::to_string(gone) + " gone"));
  }
}

TEST(KineticDelaunay, RefusesTheClassicSchedulerAndHighDegrees) {
  test::expect_refusals<KineticDelaunay>({SchedulerKind::Classic}, "robust or the exact scheduler");
}

}  // namespace
}  // namespace kinetic
