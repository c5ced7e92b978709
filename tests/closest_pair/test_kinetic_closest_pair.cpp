// The kinetic closest pair (a kinetic tournament over the Delaunay edges' lengths) against the
// brute-force oracle, under the exact scheduler: random lines and parabolas, integer grids (equal
// lengths and points meeting at every integer time), a translating grid (equal lengths for ever:
// ties by ids), points on a collision course, collinear points (no triangulation), identical
// motions, and long mixed sequences of inserts, removes and updates. validate() after every
// event (the tournament's edges are the triangulation's, every node's winner the shorter just
// after now); at probe times the closest pair equals the oracle's, and the distance it names
// equals the smallest distance found by longest-side kd-tree nearest-neighbour queries. Fixed
// seeds, printed on failure.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "kinetic/closest_pair/kinetic_closest_pair.hpp"
#include "kinetic/core/error.hpp"
#include "kinetic/longest_side_kdtree/longest_side_kdtree.hpp"
#include "support/delaunay_run.hpp"

namespace kinetic {
namespace {

using test::linear;
using test::Motion;
using test::parabola;
using test::play;
using test::Totals;
using PairRun = test::DelaunayRun<KineticClosestPair>;

double position(const MotionTable& table, std::uint32_t i, int axis, Time t) {
  return table.motion(i, axis).evaluate(t);
}

/// The closest pair's distance against the kd-tree: for every point p, a longest-side kd-tree
/// over the other points (built at t) answers the nearest point to p's position (eps = 0); the
/// smallest of those distances is the closest pair's (positions rounded to doubles: a relative
/// tolerance of 1e-9).
void check_against_kdtree(PairRun& run, const std::string& where) {
  const Time t = run.sim.now();
  const auto pair = run.dt->closest_pair();
  const auto alive = run.table.alive_indices();
  if (!pair || alive.size() > 24) return;
  const auto dist = [&](std::uint32_t a, std::uint32_t b) {
    return std::hypot(position(run.table, a, 0, t) - position(run.table, b, 0, t),
                      position(run.table, a, 1, t) - position(run.table, b, 1, t));
  };
  double best = std::numeric_limits<double>::infinity();
  for (const std::uint32_t p : alive) {
    MotionTable others(2);
    std::vector<std::uint32_t> index_of;
    for (const std::uint32_t q : alive) {
      if (q == p) continue;
      const std::array<MotionPolynomial, 2> m{run.table.motion(q, 0), run.table.motion(q, 1)};
      const std::uint32_t k = others.insert(run.table.id(q), m).index;
      if (index_of.size() <= k) index_of.resize(k + 1);
      index_of[k] = q;
    }
    Simulator sim(t);
    Scheduler scheduler(SchedulerKind::Robust, 1e-9, t + 1.0);
    LongestSideKdTree tree(others, sim, scheduler);
    tree.initialize();
    const auto near =
        tree.nearest({position(run.table, p, 0, t), position(run.table, p, 1, t)}, 0.0, t);
    ASSERT_TRUE(near.has_value()) << where;
    best = std::min(best, dist(p, index_of[*near]));
  }
  const double got = dist((*pair)[0], (*pair)[1]);
  EXPECT_NEAR(got, best, 1e-9 * (1.0 + best))
      << where << " at t=" << t << ": the closest pair (" << run.table.id((*pair)[0]) << ", "
      << run.table.id((*pair)[1]) << ") against the kd-tree's nearest neighbours";
}

TEST(KineticClosestPair, RandomLinesAgainstTheOracleAndTheKdTree) {
  std::uint64_t tournament_events = 0, edge_changes = 0, rebuilds = 0;
  test::Scenarios<KineticClosestPair> scenarios;
  scenarios.extra = check_against_kdtree;
  scenarios.after = [&](PairRun& run) {
    const ClosestPairCounters& c = run.dt->counters();
    tournament_events += c.events;
    edge_changes += c.edge_inserts + c.edge_removes;
    rebuilds += c.rebuilds;
  };
  const Totals totals = scenarios.random_lines();
  std::printf(
      "[ closest-pair ] %llu events, %llu tournament events, %llu edge changes, %llu "
      "edge sets read again\n",
      static_cast<unsigned long long>(totals.events),
      static_cast<unsigned long long>(tournament_events),
      static_cast<unsigned long long>(edge_changes), static_cast<unsigned long long>(rebuilds));
  EXPECT_GT(totals.events, 100u);
  EXPECT_GT(tournament_events, 20u);  // the lengths' own certificates fail, not only flips
  EXPECT_GT(edge_changes, 100u);      // flips reach the tournament as edge changes
}

TEST(KineticClosestPair, RandomParabolasAgainstTheOracle) {
  EXPECT_GT(test::Scenarios<KineticClosestPair>{}.random_parabolas().events, 10u);
}

/// Integer grids with integer velocities: many edges of equal length at once, points meeting at
/// integer times (distance 0), simultaneous flips and length events; and the kd-tree's nearest.
TEST(KineticClosestPair, IntegerGridsWithTiesAndCollisionsAgainstTheOracle) {
  test::Scenarios<KineticClosestPair> scenarios;
  scenarios.extra = check_against_kdtree;
  EXPECT_GT(scenarios.integer_grids().events, 50u);
}

/// A grid translating as one: every unit edge has the same length for ever, so the tournament
/// decides by ids, and the answer is the smallest pair of ids among them.
TEST(KineticClosestPair, TranslatingGridTiesForEverByIds) {
  Totals totals;
  PairRun run(0.0, 4.0);
  ObjectId id = 0;
  for (int x = 0; x < 4; ++x) {
    for (int y = 0; y < 4; ++y) run.add(id++, linear(x, y, 0.5, -0.25));
  }
  run.start();
  const auto pair = run.dt->closest_pair();
  ASSERT_TRUE(pair.has_value());
  EXPECT_EQ(run.table.id((*pair)[0]), 0);
  EXPECT_EQ(run.table.id((*pair)[1]), 1);
  play(run, 4.0, 6, {1.0, 2.0}, 5, true, 1, totals, "translating grid");
}

TEST(KineticClosestPair, CollisionCourseAgainstTheOracle) {
  (void)test::Scenarios<KineticClosestPair>{}.collision_course();
}

/// Points collinear for ever have no triangulation: the answer comes from the pass over all
/// pairs; a point off the line brings the triangulation (and the tournament) in, and taking it
/// out again leaves it flat.
TEST(KineticClosestPair, CollinearPointsThenATriangulation) {
  Totals totals;
  std::mt19937_64 rng(3);
  PairRun run(0.0, 10.0);
  for (int i = 0; i < 6; ++i) run.add(i, linear(i, 2.0 * i, 0.5 - 0.2 * i, 1.0 - 0.4 * i));
  run.start();
  EXPECT_EQ(run.dt->edges(), 0u);
  ASSERT_TRUE(run.advance(2.0, totals, "collinear"));
  ASSERT_TRUE(run.check(totals, rng, "collinear"));
  const std::uint32_t off = run.table.insert(10, linear(1.0, -3.0, 0.0, 0.0), 2.0).index;
  run.dt->insert(off);
  ASSERT_TRUE(run.dt->validate());
  EXPECT_GT(run.dt->edges(), 0u);
  ASSERT_TRUE(run.check(totals, rng, "collinear plus one"));
  ASSERT_TRUE(run.advance(6.0, totals, "collinear plus one"));
  ASSERT_TRUE(run.check(totals, rng, "collinear plus one, later"));
  run.table.remove(run.table.handle(off));
  run.dt->remove(off);
  ASSERT_TRUE(run.dt->validate());
  EXPECT_EQ(run.dt->edges(), 0u);
  ASSERT_TRUE(run.check(totals, rng, "collinear again"));
}

TEST(KineticClosestPair, IdenticalMotionsAreAtDistanceZero) {
  (void)test::Scenarios<KineticClosestPair>{}.copies();
}

/// Groups of identical motions through updates onto the group's motion and removes in every
/// order (a crash found by fuzzing).
TEST(KineticClosestPair, IdenticalGroupsThroughUpdatesAndRemovesInEveryOrder) {
  EXPECT_GT(test::Scenarios<KineticClosestPair>{}.identical_groups().probes, 100u);
}

/// A long mixed sequence of inserts, removes and updates: every change reaches the tournament
/// as edge changes (the triangulation's local repairs), not as a new layout.
TEST(KineticClosestPair, InsertsRemovesAndUpdatesAreLocal) {
  const auto [start, c] = test::Scenarios<KineticClosestPair>{}.mixed_changes(20.0);
  const std::uint64_t laid_out = start.rebuilds;
  std::printf("[ closest-pair ] 60 changes: %llu edges in, %llu out, %llu laid out again\n",
              static_cast<unsigned long long>(c.edge_inserts),
              static_cast<unsigned long long>(c.edge_removes),
              static_cast<unsigned long long>(c.rebuilds - laid_out));
  EXPECT_LE(c.rebuilds - laid_out, 5u);
  EXPECT_GT(c.edge_inserts, 200u);
}

TEST(KineticClosestPair, RefusesOtherSchedulersAndHighDegrees) {
  test::expect_refusals<KineticClosestPair>({SchedulerKind::Robust, SchedulerKind::Classic},
                                            "exact scheduler");
}

TEST(LengthComparison, ExactPolynomialAndDecisions) {
  // |a b|^2 - |c d|^2 with a = (t, 0), b = (0, 0), c = (0, 0), d = (1, 1): t^2 - 2, one sign
  // change after 0 at sqrt(2).
  const MotionPolynomial ax = MotionPolynomial::from({0, 1}), zero = MotionPolynomial::from({0}),
                         one = MotionPolynomial::from({1});
  const LengthComparison f{{MovingPoint2{&ax, &zero}, MovingPoint2{&zero, &zero},
                            MovingPoint2{&zero, &zero}, MovingPoint2{&one, &one}}};
  EXPECT_EQ(f.degree_bound(), 2);
  const ExactPolynomial p = ExactPolynomial::of(f);
  ASSERT_EQ(p.degree(), 2);
  EXPECT_EQ(p.coefficients()[0], -2);
  EXPECT_EQ(p.coefficients()[1], 0);
  EXPECT_EQ(p.coefficients()[2], 1);
  Simulator sim(0.0);
  Scheduler scheduler(SchedulerKind::Exact, 1e-9, 10.0);
  sim.attach(scheduler);
  const Scheduler::SignDecision d = scheduler.decide(f, sim.counters());
  EXPECT_EQ(d.sign, -1);
  ASSERT_TRUE(d.exact);
  EXPECT_LT(d.failure, std::sqrt(2.0) + 1e-12);
  EXPECT_GT(d.failure, std::sqrt(2.0) - 1e-12);
  LazyTime at_two = LazyTime::point(2.0);
  EXPECT_EQ(sign_after(f, at_two), 1);
  Scheduler robust(SchedulerKind::Robust, 1e-9, 10.0);
  EXPECT_THROW((void)robust.decide(f, sim.counters()), PreconditionError);
}

}  // namespace
}  // namespace kinetic
