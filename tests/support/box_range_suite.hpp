#pragma once
// The oracle suite every structure answering closed-box range queries over points runs (the
// kd-tree, the range tree), as typed tests: a static build against brute force, random motions
// with validate() after every event under every scheduler, quadratic motions, inserts, removes
// and updates, larger runs, and queries over mixed origins, degrees and offsets of 1e9 with
// answers as large as the set. What differs by structure (its sizes, how a range is asked, what
// its counters must show after a run) is its BoxRangeTraits<Tree>, which the test file that
// instantiates the suite defines:
//
//   template <> struct BoxRangeTraits<KineticKdTree> { ... };
//   INSTANTIATE_TYPED_TEST_SUITE_P(KdTree, BoxRangeSuite, ::testing::Types<KineticKdTree>);
//
// Tests only.

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/oracle/oracle.hpp"
#include "support/driver.hpp"
#include "support/replay.hpp"

namespace kinetic::test {

/// What the suite needs to know of a structure:
///  - kMaxDimension: the static build and the mixed queries run d = 1 .. kMaxDimension;
///  - kRunDimension: random motions under every scheduler run d = 1 .. kRunDimension;
///  - kStaticLargest: the largest static build (with 1, 2, 3, 7 and 64 points);
///  - kPolyPoints, kChangingPoints: points of the quadratic runs and of the runs with changes;
///  - kLargerRuns: the larger runs with queries only ({n, d, seed, scheduler});
///  - mixed_points(d): points of the mixed-queries test (a quarter removed);
///  - kGridPoints: points of the integer grid test (with an equal trajectory for every eighth);
///  - range(tree, box, t): the ids' indices in the box, ascending (and whatever the structure's
///    other query paths must agree with);
///  - after_run(tree, events): what its counters must show after a run.
template <class Tree>
struct BoxRangeTraits;

struct LargerRun {
  std::size_t n;
  int d;
  std::uint64_t seed;
  SchedulerKind kind;
};

template <class Tree>
class BoxRangeSuite : public ::testing::Test {
 protected:
  static void check_run(const scenario::Scenario& s, SchedulerKind kind, std::uint64_t seed,
                        bool validate_each) {
    check_box_range_run<Tree>(s, kind, seed, validate_each, BoxRangeTraits<Tree>::range,
                              BoxRangeTraits<Tree>::after_run);
  }
};

TYPED_TEST_SUITE_P(BoxRangeSuite);

TYPED_TEST_P(BoxRangeSuite, StaticBuildMatchesBruteForce) {
  using Traits = BoxRangeTraits<TypeParam>;
  for (int d = 1; d <= Traits::kMaxDimension; ++d) {
    for (const std::size_t n : {std::size_t{1}, std::size_t{2}, std::size_t{3}, std::size_t{7},
                                std::size_t{64}, Traits::kStaticLargest}) {
      const scenario::Scenario s = generated("random-linear", n, d, 10 + n, 1, false);
      TreeHarness<TypeParam> h(s, SchedulerKind::Robust, 1e-9);
      ASSERT_TRUE(h.tree->validate()) << "d " << d << " n " << n;
      EXPECT_EQ(h.tree->size(), n);
      std::mt19937_64 rng(n * 31 + static_cast<std::uint64_t>(d));
      for (int q = 0; q < 40; ++q) {
        const Box box = random_box(h.motions, 0.0, rng);
        EXPECT_EQ(Traits::range(*h.tree, box, 0.0), oracle::in_box_at(h.motions, box, 0.0))
            << "d " << d << " n " << n;
      }
    }
  }
}

TYPED_TEST_P(BoxRangeSuite, RandomMotionsEveryEventValidated) {
  using Traits = BoxRangeTraits<TypeParam>;
  for (int d = 1; d <= Traits::kRunDimension; ++d) {
    for (const SchedulerKind kind :
         {SchedulerKind::Robust, SchedulerKind::Classic, SchedulerKind::Exact}) {
      this->check_run(generated("random-linear", 40, d, static_cast<std::uint64_t>(d), 1, false),
                      kind, static_cast<std::uint64_t>(d), true);
    }
  }
  // Quadratic motions, d = 2 and 3.
  for (int d = 2; d <= 3; ++d) {
    this->check_run(generated("random-poly", Traits::kPolyPoints, d, 7, 2, false),
                    SchedulerKind::Robust, 7, true);
  }
}

TYPED_TEST_P(BoxRangeSuite, InsertsRemovesUpdates) {
  using Traits = BoxRangeTraits<TypeParam>;
  for (int d = 1; d <= 3; ++d) {
    this->check_run(generated("random-linear", Traits::kChangingPoints, d, 21, 1, true),
                    SchedulerKind::Robust, 21, true);
  }
}

TYPED_TEST_P(BoxRangeSuite, LargerRunsQueriesOnly) {
  for (const LargerRun& r : BoxRangeTraits<TypeParam>::kLargerRuns)
    this->check_run(generated("random-linear", r.n, r.d, r.seed, 1, false), r.kind, r.seed, false);
}

/// Mixed origins (0 or anywhere in [-5, 5]), degrees 0 to 2, a seventh of the points offset by
/// 1e9, a quarter removed before the build; 30 random boxes and the box holding everything at
/// three times, validate() at each.
TYPED_TEST_P(BoxRangeSuite, QueriesWithMixedOriginsDegreesAndLargeAnswers) {
  using Traits = BoxRangeTraits<TypeParam>;
  for (int d = 1; d <= Traits::kMaxDimension; ++d) {
    const std::uint64_t seed = 90 + static_cast<std::uint64_t>(d);
    SCOPED_TRACE("seed " + std::to_string(seed) + ", d " + std::to_string(d));
    MotionTable motions(d);
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<ObjectHandle> handles;
    const int count = Traits::mixed_points(d);
    for (int i = 0; i < count; ++i) {
      std::vector<MotionPolynomial> p;
      const double origin = (i % 3 == 0) ? 0.0 : 5.0 * u(rng);
      const double offset = (i % 7 == 0) ? 1e9 : 0.0;
      for (int a = 0; a < d; ++a) {
        std::vector<double> c{offset + 30.0 * u(rng)};
        if (i % 5 != 0) c.push_back(u(rng));
        if (i % 11 == 0) c.push_back(0.1 * u(rng));
        p.push_back(MotionPolynomial::from(c, origin));
      }
      handles.push_back(motions.insert(static_cast<ObjectId>(i), p, -10.0));
    }
    for (int i = 0; i < count; i += 4) motions.remove(handles[static_cast<std::size_t>(i)]);
    Simulator sim(0.0);
    const Scheduler scheduler(SchedulerKind::Robust, 1e-9, 1.0);
    TypeParam tree(motions, sim, scheduler);
    tree.initialize();
    ASSERT_TRUE(tree.validate());
    for (const Time t : {0.0, 0.37, 1.0}) {
      struct Handler {
        TypeParam* tree;
        EventKind process(const Event& e) { return tree->process(e); }
      } handler{&tree};
      ASSERT_EQ(sim.advance_to(t, handler), AdvanceOutcome::Reached);
      ASSERT_TRUE(tree.validate());
      for (int q = 0; q < 30; ++q) {
        const Box box = random_box(motions, t, rng);
        EXPECT_EQ(Traits::range(tree, box, t), oracle::in_box_at(motions, box, t))
            << "t=" << t << " query " << q;
      }
      const Box all(static_cast<std::size_t>(d), {-1e300, 1e300});
      EXPECT_EQ(Traits::range(tree, all, t), oracle::in_box_at(motions, all, t));
      EXPECT_EQ(tree.range(all, t).size(), motions.size());
    }
  }
}

/// Integer grid positions and velocities in d = 1 .. kMaxDimension: shared coordinates on every
/// axis at integer times, equal trajectories (every eighth point twice), simultaneous swaps on
/// several axes; every event validated under every scheduler, queries at the tie times (boxes
/// ending on shared coordinates) against brute force.
TYPED_TEST_P(BoxRangeSuite, DegenerateGridEqualTrajectoriesSimultaneousSwaps) {
  using Traits = BoxRangeTraits<TypeParam>;
  for (int d = 1; d <= Traits::kMaxDimension; ++d) {
    const std::uint64_t seed = 70 + static_cast<std::uint64_t>(d);
    SCOPED_TRACE("seed " + std::to_string(seed) + ", d " + std::to_string(d));
    scenario::Scenario s = empty_scenario(d, 0.0, 4.0);
    std::mt19937_64 rng(seed);
    for (int i = 0; i < Traits::kGridPoints; ++i) {
      scenario::Motion m;
      for (int a = 0; a < d; ++a) {
        m.coordinates.push_back(
            {static_cast<double>(rng() % 4), static_cast<double>(static_cast<int>(rng() % 5) - 2)});
      }
      s.objects.push_back({i, m});
      if (i % 8 == 0) s.objects.push_back({1000 + i, m});  // an equal trajectory
    }
    std::vector<Time> times;
    for (int step = 0; step <= 8; ++step) times.push_back(0.5 * step);
    for (const SchedulerKind kind :
         {SchedulerKind::Robust, SchedulerKind::Classic, SchedulerKind::Exact}) {
      TreeHarness<TypeParam> h(s, kind, 1e-9);
      std::mt19937_64 q(seed + 1);
      h.check(times, true, [&](Time t) {
        for (int k = 0; k < 15; ++k) {
          const Box box = random_box(h.motions, t, q);
          EXPECT_EQ(Traits::range(*h.tree, box, t), oracle::in_box_at(h.motions, box, t))
              << "t=" << t;
        }
      });
      EXPECT_GT(h.tree->counters().swaps, 20u);
    }
  }
}

REGISTER_TYPED_TEST_SUITE_P(BoxRangeSuite, StaticBuildMatchesBruteForce,
                            RandomMotionsEveryEventValidated, InsertsRemovesUpdates,
                            LargerRunsQueriesOnly, QueriesWithMixedOriginsDegreesAndLargeAnswers,
                            DegenerateGridEqualTrajectoriesSimultaneousSwaps);

}  // namespace kinetic::test
