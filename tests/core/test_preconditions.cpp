// Every misuse of the library that used to give a wrong answer silently now throws
// PreconditionError with a message that names the call and what was wrong (issue: the library as
// a user meets it). One test per misuse; each also shows the correct use answering right.

#include "kinetic/core/preconditions.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/polynomial.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/hull/kinetic_hull.hpp"
#include "kinetic/kdtree/kinetic_kdtree.hpp"
#include "kinetic/longest_side_kdtree/longest_side_kdtree.hpp"
#include "kinetic/range_tree/kinetic_range_tree.hpp"
#include "kinetic/segment_tree/kinetic_segment_tree.hpp"
#include "kinetic/session/session.hpp"
#include "kinetic/sort/kinetic_sort.hpp"
#include "kinetic/tournament/kinetic_tournament.hpp"

namespace kinetic {
namespace {

MotionPolynomial linear(double c0, double c1) {
  return MotionPolynomial::from(std::array<double, 2>{c0, c1});
}

/// Runs f and returns the message of the PreconditionError it throws ("" when none).
template <class F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const PreconditionError& e) {
    return e.what();
  }
  return "";
}

#define EXPECT_REFUSED(call, needle)                                                    \
  do {                                                                                  \
    const std::string what_ = message_of([&] { (void)(call); });                        \
    EXPECT_NE(what_.find(needle), std::string::npos) << "message: \"" << what_ << "\""; \
  } while (0)

/// n points on lines of slope -2i (point i at x = i): every pair crosses once in [0, 1]; a
/// simulator at 0 and a scheduler (the default one unless given) for a structure over them.
struct Crossing {
  MotionTable table{1};
  Simulator sim{0.0};
  Scheduler scheduler;

  explicit Crossing(int n) { fill(n); }
  Crossing(int n, SchedulerKind kind, double eps, Time horizon) : scheduler(kind, eps, horizon) {
    fill(n);
  }

 private:
  void fill(int n) {
    for (int i = 0; i < n; ++i) {
      const std::array<MotionPolynomial, 1> m{linear(i, -2.0 * i)};
      table.insert(i, m);
    }
  }
};

TEST(Preconditions, AdvancingPastTheHorizonIsRefused) {
  Crossing crossing(5, SchedulerKind::Robust, 1e-9, 10.0);
  auto& [table, sim, scheduler] = crossing;
  KineticSort sort(table, sim, scheduler, 0);
  sort.initialize();
  EXPECT_EQ(sim.horizon(), 10.0);
  ASSERT_EQ(sim.advance_to(10.0, sort), AdvanceOutcome::Reached);  // up to the horizon: fine
  EXPECT_REFUSED(sim.advance_to(12.0, sort), "after the scheduler's horizon 10");
  EXPECT_EQ(sim.now(), 10.0);  // nothing moved
  EXPECT_REFUSED(sim.advance_to(std::nan(""), sort), "t is NaN");
}

TEST(Preconditions, AQueryAtAnotherTimeThanTheSimulatorsIsRefused) {
  MotionTable table(2);
  for (int i = 0; i < 50; ++i) {
    const std::array<MotionPolynomial, 2> m{linear(i, 1.0 - 0.04 * i), linear(50 - i, 0.5)};
    table.insert(i, m);
  }
  Simulator sim(0.0);
  const Scheduler scheduler;
  KineticKdTree kd(table, sim, scheduler);
  kd.initialize();
  ASSERT_EQ(sim.advance_to(10.0, kd), AdvanceOutcome::Reached);
  const Box box{{0.0, 30.0}, {0.0, 60.0}};
  EXPECT_NO_THROW((void)kd.range(box, 10.0));
  EXPECT_REFUSED(kd.range(box, 12.0), "query at t = 12 but the structure is at t = 10");
}

TEST(Preconditions, AMotionChangedBehindTheStructuresBackIsCaught) {
  Crossing crossing(4);
  auto& [table, sim, scheduler] = crossing;
  KineticTournament max(table, sim, scheduler, 0, Extreme::Max);
  max.initialize();
  EXPECT_TRUE(max.validate());
  const std::array<MotionPolynomial, 1> jump{linear(100.0, 0.0)};
  table.update(table.handle(0), jump, 0.0);  // the structure is not told
  EXPECT_FALSE(max.validate());
  EXPECT_REFUSED(max.top(), "the motion table changed without the structure being told");
  max.motion_changed(0);  // told: right again
  EXPECT_TRUE(max.validate());
  EXPECT_EQ(table.id(*max.top()), 0);
}

TEST(Preconditions, AdvancingAnUninitializedStructureIsRefused) {
  Crossing crossing(3);
  auto& [table, sim, scheduler] = crossing;
  KineticSort sort(table, sim, scheduler, 0);
  EXPECT_FALSE(sort.initialized());
  EXPECT_REFUSED(sim.advance_to(1.0, sort), "not initialized");
  EXPECT_REFUSED(sim.run_until_empty(sort), "not initialized");
  KineticKdTree kd(table, sim, scheduler);
  EXPECT_REFUSED(kd.range(Box{{0.0, 1.0}}, 0.0), "not initialized");
  sort.initialize();
  EXPECT_EQ(sim.advance_to(1.0, sort), AdvanceOutcome::Reached);
  EXPECT_EQ(sort.order().size(), 3u);
}

TEST(Preconditions, ABoxOfTheWrongDimensionIsRefused) {
  MotionTable table(2);
  for (int i = 0; i < 5; ++i) {
    const std::array<MotionPolynomial, 2> m{linear(i, 0.0), linear(i, 0.0)};
    table.insert(i, m);
  }
  Simulator sim(0.0);
  const Scheduler scheduler;
  KineticKdTree kd(table, sim, scheduler);
  kd.initialize();
  EXPECT_REFUSED(kd.range(Box{{0.0, 10.0}}, 0.0), "the box has 1 axis, the structure 2");
  EXPECT_REFUSED(kd.range(Box{{0.0, 1.0}, {0.0, std::nan("")}}, 0.0), "axis 1 is NaN");
  EXPECT_EQ(kd.range(Box{{0.0, 10.0}, {0.0, 10.0}}, 0.0).size(), 5u);
}

TEST(Preconditions, ADuplicateIdOrTheWrongNumberOfCoordinatesIsRefused) {
  MotionTable table(2);
  const std::array<MotionPolynomial, 2> ok{linear(0.0, 1.0), linear(1.0, 0.0)};
  table.insert(7, ok);
  const std::array<MotionPolynomial, 1> short_motion{linear(0.0, 1.0)};
  EXPECT_REFUSED(table.insert(7, short_motion), "1 coordinates for a table of dimension 2");
  EXPECT_REFUSED(table.insert(7, ok), "id 7 is present already");
  EXPECT_REFUSED(table.insert(8, short_motion), "1 coordinates for a table of dimension 2");
  EXPECT_EQ(table.size(), 1u);
  EXPECT_REFUSED(table.update(table.handle(0), short_motion), "1 coordinates");
  const ObjectHandle h = table.handle(0);
  table.remove(h);
  EXPECT_REFUSED(table.remove(h), "not alive");
}

TEST(Preconditions, ADegreeAboveTheMaximumIsRefused) {
  const std::vector<double> nine(9, 1.0);
  EXPECT_REFUSED(MotionPolynomial::from(nine),
                 "9 coefficients make degree 8 (the degree is at most 6)");
  const std::vector<double> trailing{1.0, 2.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  EXPECT_EQ(MotionPolynomial::from(trailing).degree, 1);  // trailing zeros are trimmed first
  EXPECT_REFUSED(MotionPolynomial::from(std::vector<double>{}), "no coefficients");
  EXPECT_REFUSED(MotionPolynomial::from(std::vector<double>{1.0, HUGE_VAL}), "c1 is not finite");
  // A polynomial written by hand is checked where it enters the table.
  MotionPolynomial bad;
  bad.degree = 2;  // leading coefficient zero
  MotionTable table(1);
  const std::array<MotionPolynomial, 1> m{bad};
  EXPECT_REFUSED(table.insert(1, m), "leading coefficient c2 is zero");
}

TEST(Preconditions, RemoveAndInsertFollowTheTableFirstProtocol) {
  Crossing crossing(4);
  auto& [table, sim, scheduler] = crossing;
  KineticSort sort(table, sim, scheduler, 0);
  sort.initialize();
  EXPECT_REFUSED(sort.remove(1), "index 1 is still in the table (remove it from the table first)");
  table.remove(table.handle(1));
  sort.remove(1);
  EXPECT_TRUE(sort.validate());
  EXPECT_REFUSED(sort.insert(1), "index 1 is not in the table (insert it into the table first)");
}

// The hull checks the protocol before it reads a motion (an index not in the table is refused,
// never read), and a motion it refuses (degree above 3) leaves it untold: its queries then say
// the table changed without it.
TEST(Preconditions, TheHullFollowsTheTableFirstProtocolAndRefusesHighDegrees) {
  MotionTable table(2);
  for (int i = 0; i < 4; ++i) {
    const std::array<MotionPolynomial, 2> m{linear(i, 1.0), linear(i * i, -1.0)};
    table.insert(i, m);
  }
  Simulator sim(0.0);
  const Scheduler scheduler;
  KineticHull hull(table, sim, scheduler);
  hull.initialize();
  EXPECT_REFUSED(hull.insert(7), "index 7 is not in the table (insert it into the table first)");
  EXPECT_REFUSED(hull.remove(1), "index 1 is still in the table (remove it from the table first)");
  table.remove(table.handle(1));
  hull.remove(1);
  EXPECT_TRUE(hull.validate());
  EXPECT_REFUSED(hull.insert(1), "index 1 is not in the table (insert it into the table first)");
  const std::array<MotionPolynomial, 2> quartic{MotionPolynomial::from({0.0, 0.0, 0.0, 0.0, 1.0}),
                                                linear(0.0, 0.0)};
  const ObjectHandle h = table.insert(9, quartic);
  EXPECT_REFUSED(hull.insert(h.index), "object 9 moves with degree 4 on axis 0");
  EXPECT_REFUSED((void)hull.hull(), "KineticHull::hull");
  EXPECT_FALSE(hull.validate());
}

TEST(Preconditions, TheDefaultSchedulerIsRobust) {
  EXPECT_EQ(Scheduler().kind(), SchedulerKind::Robust);
}

}  // namespace
}  // namespace kinetic

namespace kinetic {
namespace {

/// Builds S over a table of `dimension` coordinates (with constructor arguments `args` after
/// the table, simulator and scheduler) and returns the PreconditionError's message ("" when
/// the construction is accepted).
template <class S, class... Args>
std::string construction_refused(int dimension, Args... args) {
  MotionTable table(dimension);
  Simulator sim(0.0);
  Scheduler sched;
  return message_of([&] { S s(table, sim, sched, args...); });
}

TEST(Preconditions, AStructureOnATableOfAnUnsupportedDimensionIsRefused) {
  EXPECT_NE(construction_refused<LongestSideKdTree>(3).find(
                "LongestSideKdTree: the table has dimension 3; this structure takes points in "
                "the plane (dimension 2)"),
            std::string::npos);
  EXPECT_NE(construction_refused<KineticSegmentTree>(1).find("dimension 1; this structure takes "
                                                             "intervals"),
            std::string::npos);
  EXPECT_NE(construction_refused<KineticRangeTree>(9).find("dimension 9"), std::string::npos);
  EXPECT_NE(construction_refused<KineticKdTree>(65).find("dimension 65"), std::string::npos);
  // The supported dimensions are accepted.
  EXPECT_EQ(construction_refused<LongestSideKdTree>(2), "");
  EXPECT_EQ(construction_refused<KineticSegmentTree>(2), "");
  EXPECT_EQ(construction_refused<KineticRangeTree>(8), "");
  EXPECT_EQ(construction_refused<KineticKdTree>(64), "");
  // And through a session, which builds the structure at once.
  EXPECT_NE(message_of([] { Session<LongestSideKdTree> s(3); }).find("LongestSideKdTree"),
            std::string::npos);
}

TEST(Preconditions, ASortOrTournamentOnAnAxisTheTableDoesNotHaveIsRefused) {
  EXPECT_NE(construction_refused<KineticSort>(2, 2).find("KineticSort: axis 2 of a table of "
                                                         "dimension 2 (0 to 1)"),
            std::string::npos);
  EXPECT_NE(construction_refused<KineticSort>(1, -1).find("axis -1"), std::string::npos);
  EXPECT_NE(construction_refused<KineticTournament>(1, 1, Extreme::Max).find("axis 1"),
            std::string::npos);
  EXPECT_EQ(construction_refused<KineticSort>(2, 1), "");
  EXPECT_EQ(construction_refused<KineticTournament>(3, 2, Extreme::Min), "");
}

}  // namespace
}  // namespace kinetic
