// The kinetic rank-based kd-tree (Abam, de Berg, Speckmann, Section 2): the tree equals a fresh
// build from the current ranks after every event (validate()), range answers equal brute force at
// random times, in d = 1..4, for random and degenerate motions (shared coordinates, simultaneous
// swaps on several axes), with inserts, removes and updates, under both schedulers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <vector>

#include "kinetic/core/predicates.hpp"
#include "kinetic/kdtree/kinetic_kdtree.hpp"
#include "kinetic/oracle/oracle.hpp"
#include "kinetic/scenario/generators.hpp"
#include "kinetic/scenario/scenario_json.hpp"
#include "support/box_range_suite.hpp"
#include "support/driver.hpp"
#include "support/replay.hpp"

namespace kinetic {
namespace {

using test::polynomials;

using KdHarness = test::TreeHarness<KineticKdTree>;

std::vector<std::uint32_t> brute_force(const MotionTable& motions, const Box& box, Time t) {
  return oracle::in_box_at(motions, box, t);
}

/// range(box, t), after checking that range_unsorted() gives the same set (each id once) with the
/// same node visits, into a buffer that holds stale ids (it must be cleared). The first query of a
/// run at a time keeps it (values, points, groups' boxes) and the next ones at that time read it.
std::vector<std::uint32_t> ranged(KineticKdTree& tree, const Box& box, Time t) {
  std::vector<std::uint32_t> unsorted{7, 7, 123456};
  tree.range_unsorted(box, t, unsorted);
  const std::uint64_t visits = tree.counters().last_query_visits;
  std::vector<std::uint32_t> sorted = tree.range(box, t);
  EXPECT_EQ(tree.counters().last_query_visits, visits);
  std::sort(unsorted.begin(), unsorted.end());
  EXPECT_EQ(unsorted, sorted) << "range_unsorted() differs from range() at t=" << t;
  return sorted;
}

}  // namespace
}  // namespace kinetic

namespace kinetic::test {

/// The kd-tree in the box-range suite: d = 1 to 4; every range also through range_unsorted().
template <>
struct BoxRangeTraits<KineticKdTree> {
  static constexpr int kMaxDimension = 4;
  static constexpr int kRunDimension = 4;
  static constexpr std::size_t kStaticLargest = 257;
  static constexpr std::size_t kPolyPoints = 40;
  static constexpr std::size_t kChangingPoints = 50;
  static constexpr std::array<LargerRun, 2> kLargerRuns{
      {{400, 2, 5, SchedulerKind::Robust}, {300, 3, 6, SchedulerKind::Robust}}};
  static int mixed_points(int /*d*/) { return 1500; }
  static constexpr int kGridPoints = 60;
  static std::vector<std::uint32_t> range(KineticKdTree& tree, const Box& box, Time t) {
    return ranged(tree, box, t);
  }
  static void after_run(const KineticKdTree& /*tree*/, std::uint64_t /*events*/) {}
};

INSTANTIATE_TYPED_TEST_SUITE_P(KdTree, BoxRangeSuite, ::testing::Types<KineticKdTree>);

}  // namespace kinetic::test

namespace kinetic {
namespace {

using test::random_box;

/// The times 0, 0.5, ..., 0.5 steps.
std::vector<Time> half_steps(int steps) {
  std::vector<Time> out;
  for (int step = 0; step <= steps; ++step) out.push_back(0.5 * step);
  return out;
}

scenario::Scenario make(const std::string& dataset, std::size_t n, int d, std::uint64_t seed,
                        int degree, bool changes) {
  return test::generated(dataset, n, d, seed, degree, changes);
}

/// The range scans and k-nearest searches keep the small subtrees' runs at the query time (the
/// leaves' values, points and groups' boxes) for the next queries at the same time, until the
/// tree changes. At one time, between inserts, removes and updates made at that time (and the
/// compactions they trigger, which move the leaves to other slots), the same small boxes and
/// query points are asked again and again (the kept runs read) and checked against brute force; a
/// point put into a box by an insert or an update is in its answer at once, and out of it once
/// removed or moved away; then inserts at that time until an order is laid out again (a rebuild).
/// d = 2 and 3 (the scans written per dimension).
TEST(KineticKdTree, RunsKeptPerTimeFollowChangesAtOneTime) {
  for (const int d : {2, 3}) {
    const std::uint64_t seed = 70 + static_cast<std::uint64_t>(d);
    SCOPED_TRACE("seed " + std::to_string(seed) + ", d " + std::to_string(d));
    const scenario::Scenario s = make("random-linear", 600, d, seed, 1, false);
    KdHarness h(s, SchedulerKind::Robust, 1e-9);
    const Time t = 0.3;
    ASSERT_EQ(h.advance_to(t), AdvanceOutcome::Reached);
    std::mt19937_64 rng(seed);
    // Small boxes around random points (a few points each: the scans cut by the sides).
    std::vector<Box> boxes;
    std::vector<std::vector<double>> centers;
    const auto idx = h.motions.alive_indices();
    for (int k = 0; k < 24; ++k) {
      const auto p = oracle::position_at(h.motions, idx[rng() % idx.size()], t);
      Box box(static_cast<std::size_t>(d));
      std::vector<double> c(static_cast<std::size_t>(d));
      for (std::size_t a = 0; a < box.size(); ++a) {
        c[a] = p[a] + 0.1;
        box[a] = {p[a] - 0.8, p[a] + 0.9};
      }
      boxes.push_back(box);
      centers.push_back(c);
    }
    // The boxes and the 8 nearest to the first boxes' centers (the k-nearest searches read the same
    // kept runs: in the plane the range scans' own, in 3-D smaller ones), in both orders, so that
    // each kind of query meets runs the other kept and runs it keeps itself.
    const auto check_all = [&](const std::string& when, bool with_nearest = true) {
      SCOPED_TRACE(when);
      for (std::size_t b = 0; b < boxes.size(); ++b) {
        const auto nearest = [&] {
          EXPECT_EQ(h.tree->k_nearest(centers[b], 8, 0.0, t),
                    oracle::k_nearest_at(h.motions, centers[b], 8, t))
              << "box " << b;
        };
        const bool ask = with_nearest && b < 6;  // (the exact oracle is slow: 6 points)
        if (ask && b % 2 == 0) nearest();
        EXPECT_EQ(ranged(*h.tree, boxes[b], t), brute_force(h.motions, boxes[b], t)) << "box " << b;
        if (ask && b % 2 == 1) nearest();
      }
    };
    check_all("at t, first");
    // The runs read are kept: asking again at t evaluates none.
    const std::uint64_t kept = h.tree->counters().runs_kept;
    EXPECT_GT(kept, 0U);
    check_all("at t, again");
    EXPECT_EQ(h.tree->counters().runs_kept, kept);
    std::uniform_real_distribution<double> vel(-1.0, 1.0);
    const auto through = [&](const std::vector<double>& p) {
      scenario::Motion m;
      m.origin = t;
      for (const double x : p) m.coordinates.push_back({x, vel(rng)});
      return m;
    };
    const auto reported = [&](const Box& box, ObjectId id) {
      const std::vector<std::uint32_t> got = h.tree->range(box, t);
      return std::any_of(got.begin(), got.end(),
                         [&](std::uint32_t i) { return h.motions.id(i) == id; });
    };
    const std::uint64_t compactions = h.tree->counters().compactions;
    for (int k = 0; k < 80; ++k) {
      const std::size_t b = static_cast<std::size_t>(k) % boxes.size();
      const ObjectId added = 5000 + static_cast<ObjectId>(k);
      scenario::TimelineOp op;
      op.time = t;
      op.id = added;
      op.op = scenario::OpKind::Insert;
      op.motion = through(centers[b]);
      h.apply(op);
      EXPECT_TRUE(reported(boxes[b], added)) << "after the insert " << k;
      check_all("after the insert " + std::to_string(k), k % 4 == 0);
      // An old point moved into the next box, then the new one removed.
      const ObjectId moved = static_cast<ObjectId>(k * 7 % 600);
      op.id = moved;
      op.op = scenario::OpKind::Update;
      op.motion = through(centers[(b + 1) % boxes.size()]);
      h.apply(op);
      op.id = added;
      op.op = scenario::OpKind::Remove;
      h.apply(op);
      EXPECT_TRUE(reported(boxes[(b + 1) % boxes.size()], moved)) << "after the update " << k;
      EXPECT_FALSE(reported(boxes[b], added)) << "after the remove " << k;
      check_all("after the update and the remove " + std::to_string(k), k % 4 == 0);
      ASSERT_TRUE(h.tree->validate()) << k;
    }
    // The changes moved enough labels for the tree to be laid out again in new slots.
    EXPECT_GT(h.tree->counters().compactions, compactions);
    // Inserts at t until an order is laid out again (a rebuild: new reference time and slots).
    const std::uint64_t rebuilds = h.tree->counters().rebuilds;
    for (int k = 0; k < 4000 && h.tree->counters().rebuilds == rebuilds; ++k) {
      scenario::TimelineOp op;
      op.time = t;
      op.id = 10000 + static_cast<ObjectId>(k);
      op.op = scenario::OpKind::Insert;
      op.motion = through(centers[static_cast<std::size_t>(k) % centers.size()]);
      h.apply(op);
      if (k % 50 == 0) check_all("while inserting, " + std::to_string(k), k % 1000 == 0);
    }
    ASSERT_GT(h.tree->counters().rebuilds, rebuilds);
    check_all("after the rebuild");
    const std::uint64_t rebuilt = h.tree->counters().runs_kept;
    check_all("after the rebuild, again");
    EXPECT_EQ(h.tree->counters().runs_kept, rebuilt);
  }
}

/// The kept runs with motions of degree above 1 (their values NaN: a group's box is then
/// unbounded on that axis and its leaves go through their own evaluation), on some axes of a
/// point and not others: small boxes and the k nearest (k = 1, 5, 40) around the quadratic points
/// at several times against brute force, each kind first in turn (so that each reads runs the other
/// kept and runs it keeps), d = 2 and 3.
TEST(KineticKdTree, KeptRunsWithMotionsOfHigherDegreeOnSomeAxes) {
  for (const int d : {2, 3}) {
    const std::uint64_t seed = 90 + static_cast<std::uint64_t>(d);
    SCOPED_TRACE("seed " + std::to_string(seed) + ", d " + std::to_string(d));
    scenario::Scenario s = make("random-poly", 500, d, seed, 2, false);
    // One point in seven quadratic, on every axis or (every other one) on all but axis 0; the
    // others linear: groups of 8 leaves that mix NaN and finite values on an axis.
    for (std::size_t i = 0; i < s.objects.size(); ++i) {
      auto& c = s.objects[i].motion.coordinates;
      for (std::size_t a = 0; a < c.size(); ++a) {
        const bool quadratic = i % 7 == 0 && !(a == 0 && i % 2 == 0);
        if (!quadratic && c[a].size() > 2) c[a].resize(2);
      }
    }
    KdHarness h(s, SchedulerKind::Robust, 1e-9);
    std::mt19937_64 rng(seed);
    int step = 0;
    for (const Time t : {0.0, 0.2, 0.45, 0.7}) {
      ASSERT_EQ(h.advance_to(t), AdvanceOutcome::Reached);
      const auto idx = h.motions.alive_indices();
      for (int k = 0; k < 12; ++k, ++step) {
        // Around a quadratic point (ids 0, 7, 14, ...), in a box small enough that the other
        // leaves of its group are often outside it.
        const std::uint32_t at = idx[7 * (rng() % (idx.size() / 7))];
        ASSERT_EQ(h.motions.id(at) % 7, 0U);
        const auto p = oracle::position_at(h.motions, at, t);
        Box box(static_cast<std::size_t>(d));
        std::vector<double> q(static_cast<std::size_t>(d));
        for (std::size_t a = 0; a < box.size(); ++a) {
          q[a] = p[a] + 0.01;
          box[a] = {p[a] - 0.3, p[a] + 0.2};
        }
        const std::size_t kk =
            std::array<std::size_t, 3>{1, 5, 40}[static_cast<std::size_t>(k) % 3];
        const auto nearest = [&] {
          EXPECT_EQ(h.tree->k_nearest(q, kk, 0.0, t), oracle::k_nearest_at(h.motions, q, kk, t))
              << "t " << t << ", query " << k;
        };
        if (step % 2 == 0) nearest();
        EXPECT_EQ(ranged(*h.tree, box, t), brute_force(h.motions, box, t)) << "t " << t;
        if (step % 2 == 1) nearest();
      }
    }
    EXPECT_TRUE(h.tree->validate());
  }
}

/// Long mixed sequences: 1,290 inserts, removes and updates growing 100 points to about 1,000,
/// and 900 shrinking 700 to about 150, in the plane and in 3-D, robust and exact. validate()
/// after every change (the tree equals a fresh build from the current labels); 6 boxes against
/// brute force at 30 random times and before every change. The changes are local: the tree is
/// rebuilt only when an order is laid out again (a few times), and points whose labels moved are
/// reinserted unless their key changed only below their leaf.
TEST(KineticKdTree, LongMixedSequencesOfInsertsRemovesUpdates) {
  for (int d = 2; d <= 3; ++d) {
    for (const SchedulerKind kind : {SchedulerKind::Robust, SchedulerKind::Exact}) {
      const auto seed = static_cast<std::uint64_t>(30 + d);
      for (const bool grow : {true, false}) {
        const scenario::Scenario s =
            grow ? test::long_mixed("random-linear", 100, d, seed, 1000, 90, 200)
                 : test::long_mixed("random-linear", 700, d, seed, 100, 650, 150);
        test::check_box_range_run<KineticKdTree>(
            s, kind, seed, false, ranged, [&](const KineticKdTree& tree, std::uint64_t) {
              const KdTreeCounters& c = tree.counters();
              SCOPED_TRACE(grow ? "growing" : "shrinking");
              EXPECT_GE(c.rebuilds, 1u);  // an order laid out again on the way
              EXPECT_LE(c.rebuilds, 4u * static_cast<std::uint64_t>(d));
              EXPECT_GE(c.local_changes + c.rebuilds, grow ? 1290u : 900u);
              // Both kinds of moved labels: those that left the point's leaf as it was and those
              // whose point was deleted and reinserted.
              EXPECT_GT(c.relabel_reinsertions, 0u);
              EXPECT_GT(c.unchanged_relabels, 100u);
            });
        if (::testing::Test::HasFailure()) return;
      }
    }
  }
}

TEST(KineticKdTree, DegenerateSharedCoordinatesAndSimultaneousSwaps) {
  // Points on a small integer grid moving with integer velocities: many equal coordinates at
  // every integer time, and swaps on both axes at the same instants.
  const scenario::Scenario s = test::integer_grid_2d(48, 3, 6.0);
  // Query exactly at the integer times (ties everywhere) and in between.
  for (const SchedulerKind kind :
       {SchedulerKind::Robust, SchedulerKind::Classic, SchedulerKind::Exact}) {
    KdHarness h(s, kind, 1e-9);
    std::mt19937_64 q(9);
    h.check(half_steps(12), true, [&](Time t) {
      for (int k = 0; k < 20; ++k) {
        const Box box = random_box(h.motions, t, q);
        EXPECT_EQ(ranged(*h.tree, box, t), brute_force(h.motions, box, t)) << "t=" << t;
      }
    });
    EXPECT_GT(h.tree->counters().swaps, 50u);
  }
}

/// Events whose swapped points are alone in the skeleton above the first changed key bit leave
/// T(P) as it is; the others delete and reinsert. Both kinds must occur, and the tree must equal
/// a fresh build after each (validate()), in d = 1..4 and at a size where the keys are deep.
TEST(KineticKdTree, EventsThatLeaveTheTreeAndEventsThatReinsert) {
  for (int d = 1; d <= 4; ++d) {
    const std::uint64_t seed = 40 + static_cast<std::uint64_t>(d);
    SCOPED_TRACE("seed " + std::to_string(seed) + ", d " + std::to_string(d));
    const scenario::Scenario s = make("random-linear", 300, d, seed, 1, false);
    KdHarness h(s, SchedulerKind::Robust, 1e-9);
    std::mt19937_64 rng(seed);
    std::uint64_t events = 0;
    while (h.sim.event_due_by(*s.end_time) && events < 3000) {
      ASSERT_EQ(h.sim.process_next(h), AdvanceOutcome::Reached);
      ++events;
      ASSERT_TRUE(h.tree->validate()) << "after event " << events << " at t=" << h.sim.now();
      if (events % 50 == 0) {
        const Time t = h.sim.now();
        const Box box = random_box(h.motions, t, rng);
        EXPECT_EQ(ranged(*h.tree, box, t), brute_force(h.motions, box, t)) << "t=" << t;
      }
    }
    const KdTreeCounters& c = h.tree->counters();
    EXPECT_EQ(c.swaps, events);
    EXPECT_GT(c.reinsertions, 0u);
    // Every n / 8 reinsertions the tree is copied into fresh slots; validate() after each event
    // checked the copies too.
    EXPECT_GE(c.compactions + 1, c.reinsertions / (300 / 8 + 1));
    EXPECT_GT(c.compactions, 0u);
    if (d == 1) {
      // One axis: two adjacent ranks share their key down to the level that separates them,
      // so both points always move.
      EXPECT_EQ(c.unchanged_events, 0u);
      EXPECT_EQ(c.reinsertions, 2 * events);
    } else {
      EXPECT_GT(c.unchanged_events, 0u);
      EXPECT_LE(c.unchanged_events + c.reinsertions, 2 * events);
    }
  }
}

/// Queries stop descending at subtrees of a few leaves and test those leaves along the thread;
/// reinsertions move leaves between slots. Small boxes (many such subtrees cut by the box's
/// sides) after many reinsertions, in 2-D and 3-D, both query paths against brute force; and
/// coincident points (one position shared by many, others crossing it) in d = 1..3.
TEST(KineticKdTree, SmallSubtreesAfterReinsertionsAndCoincidentPoints) {
  for (int d = 2; d <= 3; ++d) {
    const std::uint64_t seed = 110 + static_cast<std::uint64_t>(d);
    SCOPED_TRACE("seed " + std::to_string(seed) + ", d " + std::to_string(d));
    const scenario::Scenario s = make("random-linear", 1500, d, seed, 1, false);
    KdHarness h(s, SchedulerKind::Robust, 1e-9);
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::uint64_t events = 0;
    while (h.sim.event_due_by(*s.end_time) && events < 20000) {
      ASSERT_EQ(h.sim.process_next(h), AdvanceOutcome::Reached);
      if (++events % 1000 != 0) continue;
      const Time t = h.sim.now();
      for (int q = 0; q < 20; ++q) {
        // A box around a random point with sides of a few point spacings.
        const auto idx = h.motions.alive_indices();
        const std::uint32_t c = idx[rng() % idx.size()];
        const double half = (0.5 + 3.0 * u(rng)) * (q % 2 == 0 ? 1.0 : 0.25);
        Box box(static_cast<std::size_t>(d));
        for (int a = 0; a < d; ++a) {
          const double x = h.motions.motion(c, a).evaluate(t);
          box[static_cast<std::size_t>(a)] = {x - half * u(rng), x + half * u(rng)};
        }
        EXPECT_EQ(ranged(*h.tree, box, t), brute_force(h.motions, box, t)) << "t=" << t;
      }
    }
    EXPECT_TRUE(h.tree->validate());
    EXPECT_GT(h.tree->counters().reinsertions, 100u);
    EXPECT_GT(h.tree->counters().compactions, 0u);
  }
  for (int d = 1; d <= 3; ++d) {
    const std::uint64_t seed = 120 + static_cast<std::uint64_t>(d);
    SCOPED_TRACE("seed " + std::to_string(seed) + ", d " + std::to_string(d));
    scenario::Scenario s = test::empty_scenario(d, 0.0, 2.0);
    std::mt19937_64 rng(seed);
    for (int i = 0; i < 70; ++i) {
      scenario::Motion m;
      for (int a = 0; a < d; ++a) {
        if (i < 40) {
          m.coordinates.push_back({1.0, 0.0});  // all at (1, ..., 1), at rest
        } else {
          m.coordinates.push_back({static_cast<double>(rng() % 3),
                                   static_cast<double>(static_cast<int>(rng() % 3) - 1)});
        }
      }
      s.objects.push_back({i, m});
    }
    KdHarness h(s, SchedulerKind::Robust, 1e-9);
    std::mt19937_64 q(seed + 1);
    for (int step = 0; step <= 8; ++step) {
      const Time t = 0.25 * step;
      while (h.sim.event_due_by(t)) {
        ASSERT_EQ(h.sim.process_next(h), AdvanceOutcome::Reached);
        ASSERT_TRUE(h.tree->validate()) << "t=" << h.sim.now();
      }
      ASSERT_EQ(h.sim.advance_to(t, h), AdvanceOutcome::Reached);
      Box point_box(static_cast<std::size_t>(d), {1.0, 1.0});  // exactly the shared position
      EXPECT_EQ(ranged(*h.tree, point_box, t), brute_force(h.motions, point_box, t)) << "t=" << t;
      for (int k = 0; k < 15; ++k) {
        const Box box = random_box(h.motions, t, q);
        EXPECT_EQ(ranged(*h.tree, box, t), brute_force(h.motions, box, t)) << "t=" << t;
      }
    }
  }
}

TEST(KineticKdTree, SizeDepthAndCertificateBounds) {
  const scenario::Scenario s = make("random-linear", 1000, 3, 2, 1, false);
  KdHarness h(s, SchedulerKind::Robust, 1e-9);
  // Lemma 2: depth <= d ceil(log2 n), O(dn) nodes; 2 certificates per point per axis.
  EXPECT_LE(h.tree->depth(), 3 * 10);
  EXPECT_LE(h.tree->node_count(), (2 * 1000 - 1) * 7u);
  EXPECT_GE(h.tree->node_count(), 2 * 1000 - 1u);
  EXPECT_EQ(h.tree->certificates(), 3 * 999u);
  EXPECT_EQ(h.tree->certificates_per_object_max(), 6u);
}

}  // namespace
}  // namespace kinetic

namespace kinetic {
namespace {

/// Right after events of a robust run with a coarse eps, ranks can be briefly wrong. The answer
/// is then a Delta-approximation, Delta = 2 n eps V_max (docs/kdtree.md: an inversion of two
/// points in an array A_i spans at most 2 n eps V_max, Theorem 4 of Abam, Agarwal, de Berg, Yu): a
/// point inside the box is missed, and a point outside it reported (a subtree whose region is
/// certified inside the box is reported without checking its leaves), only within Delta of the
/// box's boundary.
TEST(KineticKdTree, RobustAnswersNearEventsAreDeltaApproximate) {
  const double eps = 1e-3;
  const scenario::Scenario s = make("random-linear", 120, 2, 13, 1, false);
  KdHarness h(s, SchedulerKind::Robust, eps);
  std::mt19937_64 rng(17);
  double v_max = 0.0;
  for (const std::uint32_t i : h.motions.alive_indices())
    for (int a = 0; a < 2; ++a) v_max = std::max(v_max, std::fabs(h.motions.motion(i, a).c[1]));
  const double delta = 2.0 * 120 * eps * v_max;
  std::uint64_t inexact = 0, checked = 0;
  while (h.sim.event_due_by(*s.end_time)) {
    ASSERT_EQ(h.sim.process_next(h), AdvanceOutcome::Reached);
    // Between this event and the next one, and just before the next one (its pair has crossed
    // already, at t_ex < t_pr, and is still in the old order).
    const Time next = h.sim.queue().empty() ? *s.end_time : h.sim.queue().top().time;
    for (int q = 0; q < 2; ++q) {
      const Time t = q == 0 ? h.sim.now() + (next - h.sim.now()) * 0.5
                            : std::max(h.sim.now(), std::nextafter(next, -HUGE_VAL));
      ASSERT_EQ(h.sim.advance_to(t, h), AdvanceOutcome::Reached);  // no event before next
      const Box box = random_box(h.motions, t, rng);
      const std::vector<std::uint32_t> got = ranged(*h.tree, box, t);
      const std::vector<std::uint32_t> want = brute_force(h.motions, box, t);
      ++checked;
      if (got == want) continue;
      ++inexact;
      for (const std::uint32_t p : got) {
        if (std::binary_search(want.begin(), want.end(), p)) continue;
        double excess = 0.0;  // distance outside the box, per axis (the largest)
        for (int a = 0; a < 2; ++a) {
          const double x = h.motions.motion(p, a).evaluate(t);
          excess = std::max({excess, box[static_cast<std::size_t>(a)][0] - x,
                             x - box[static_cast<std::size_t>(a)][1]});
        }
        EXPECT_LE(excess, delta) << "a point far outside the box was reported at t=" << t;
      }
      for (const std::uint32_t p : want) {
        if (std::binary_search(got.begin(), got.end(), p)) continue;
        double gap = HUGE_VAL;  // distance to the box's boundary
        for (int a = 0; a < 2; ++a) {
          const double x = h.motions.motion(p, a).evaluate(t);
          gap = std::min({gap, x - box[static_cast<std::size_t>(a)][0],
                          box[static_cast<std::size_t>(a)][1] - x});
        }
        EXPECT_LE(gap, delta) << "a point deep inside the box was missed at t=" << t;
      }
    }
  }
  EXPECT_GT(checked, 500u);
  std::printf("near-event answers checked: %llu, inexact: %llu\n",
              static_cast<unsigned long long>(checked), static_cast<unsigned long long>(inexact));
}

}  // namespace
}  // namespace kinetic

namespace kinetic {
namespace {

/// A kd-tree over a table the test fills, with its own simulator: advance_to(t) processes its
/// events up to t.
struct DrivenKdTree {
  DrivenKdTree(const MotionTable& motions, SchedulerKind kind, Time end)
      : scheduler(kind, 1e-9, end), tree(motions, sim, scheduler) {
    tree.initialize();
  }
  AdvanceOutcome advance_to(Time t) {
    struct Handler {
      KineticKdTree* tree;
      EventKind process(const Event& e) { return tree->process(e); }
    } handler{&tree};
    return sim.advance_to(t, handler);
  }
  Simulator sim{0.0};
  const Scheduler scheduler;
  KineticKdTree tree;
};

/// The leaf tests compare a side with one margin per query first (the filter's bound for the
/// largest stored coefficients). A far outlier makes that margin about 1e-3 while the other
/// points' own bounds stay near 1e-14; box sides at, just beside and 1e-4 away from points'
/// coordinates then leave the margin undecided, so the leaf's own bound and the exact predicate
/// must decide: both query paths against brute force, and validate() (the stored maxima, the
/// chains) after events, in d = 2 and 3 (inline chains) and 4 (chains apart).
TEST(KineticKdTree, QueryMarginWithAFarOutlierAndSidesNearPoints) {
  for (int d = 2; d <= 4; ++d) {
    const std::uint64_t seed = 130 + static_cast<std::uint64_t>(d);
    SCOPED_TRACE("seed " + std::to_string(seed) + ", d " + std::to_string(d));
    MotionTable motions(d);
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int i = 0; i < 600; ++i) {
      std::vector<MotionPolynomial> p;
      for (int a = 0; a < d; ++a) {
        const double c0 = i == 0 ? 1e12 : 10.0 * u(rng);
        p.push_back(
            MotionPolynomial::from(std::vector<double>{c0, u(rng)}, i % 2 == 0 ? 0.0 : 0.25));
      }
      motions.insert(static_cast<ObjectId>(i), p, 0.0);
    }
    DrivenKdTree driven(motions, SchedulerKind::Classic, 1.0);
    KineticKdTree& tree = driven.tree;
    for (const Time t : {0.0, 0.5}) {
      ASSERT_EQ(driven.advance_to(t), AdvanceOutcome::Reached);
      ASSERT_TRUE(tree.validate());
      const auto alive = motions.alive_indices();
      for (int q = 0; q < 60; ++q) {
        // A box around a random point, each side at a neighbour's coordinate, +- 1e-13 or
        // +- 1e-4 from it.
        Box box(static_cast<std::size_t>(d));
        for (int a = 0; a < d; ++a) {
          const auto pick = [&] {
            const std::uint32_t i = alive[1 + rng() % (alive.size() - 1)];
            const double x = motions.motion(i, a).evaluate(t);
            const double shift[] = {0.0, 1e-13, -1e-13, 1e-4, -1e-4};
            return x + shift[rng() % 5];
          };
          double lo = pick(), hi = pick();
          if (lo > hi) std::swap(lo, hi);
          box[static_cast<std::size_t>(a)] = {lo, hi};
        }
        EXPECT_EQ(ranged(tree, box, t), brute_force(motions, box, t))
            << "t=" << t << " query " << q;
      }
    }
    EXPECT_GT(tree.counters().swaps, 0U);
  }
}

/// Boxes with infinite sides: a side at -infinity or +infinity (or a whole axis unbounded, or a
/// box [+inf, +inf] that holds nothing) against brute force, in the plane and in space (the
/// scans compiled per set of axes) and in 4-D (the general loop), with quadratic points among
/// linear ones, at the build's time and after events. The split after the last point is stored
/// as +infinity, exactly; only the exact path may decide it against an infinite side. The oracle
/// is checked here too, against the same boxes with +-1e300 for +-infinity.
TEST(KineticKdTree, BoxesWithInfiniteSides) {
  for (int d = 2; d <= 4; ++d) {
    const std::uint64_t seed = 170 + static_cast<std::uint64_t>(d);
    SCOPED_TRACE("seed " + std::to_string(seed) + ", d " + std::to_string(d));
    MotionTable motions(d);
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int i = 0; i < 500; ++i) {
      std::vector<MotionPolynomial> p;
      for (int a = 0; a < d; ++a) {
        std::vector<double> c{10.0 * u(rng), u(rng)};
        if (i % 7 == 0) c.push_back(0.3 * u(rng));  // some points quadratic
        p.push_back(MotionPolynomial::from(c, 0.0));
      }
      motions.insert(static_cast<ObjectId>(i), p, 0.0);
    }
    DrivenKdTree driven(motions, SchedulerKind::Robust, 2.0);
    KineticKdTree& tree = driven.tree;
    for (const Time t : {0.0, 0.7, 1.9}) {
      ASSERT_EQ(driven.advance_to(t), AdvanceOutcome::Reached);
      ASSERT_TRUE(tree.validate());
      for (int q = 0; q < 80; ++q) {
        Box box(static_cast<std::size_t>(d));
        for (int a = 0; a < d; ++a) {
          double lo = 12.0 * u(rng), hi = 12.0 * u(rng);
          if (lo > hi) std::swap(lo, hi);
          switch (rng() % 6) {
            case 0:
              lo = -HUGE_VAL;
              break;
            case 1:
              hi = HUGE_VAL;
              break;
            case 2:
              lo = -HUGE_VAL, hi = HUGE_VAL;
              break;
            case 3:
              if (q % 10 == 0) lo = hi = HUGE_VAL;
              break;
            default:
              break;
          }
          box[static_cast<std::size_t>(a)] = {lo, hi};
        }
        // The brute force by hand as well as the oracle's: every coordinate here is below 20 in
        // size, so +-1e300 in place of +-infinity selects the same points, and a lower side at
        // +infinity selects none.
        Box finite = box;
        bool empty = false;
        for (auto& side : finite) {
          empty = empty || side[0] == HUGE_VAL;
          for (double& x : side) x = std::clamp(x, -1e300, 1e300);
        }
        const std::vector<std::uint32_t> want =
            empty ? std::vector<std::uint32_t>{} : brute_force(motions, finite, t);
        ASSERT_EQ(brute_force(motions, box, t), want) << "t=" << t << " query " << q;
        EXPECT_EQ(ranged(tree, box, t), want) << "t=" << t << " query " << q;
      }
    }
    EXPECT_GT(tree.counters().swaps, 0U);
  }
}

/// Found by the structures fuzz harness (issue 47): four points with identical motions and two
/// with identical motions of their own, a point inserted at t = 2 and one at t = 3.5, under every
/// scheduler. The tree must equal a fresh build after every event and every insert, and answer
/// like brute force at every time.
TEST(KineticKdTree, IdenticalGroupsAndInsertsAtPendingEventTimes) {
  const scenario::Scenario s = scenario::parse_scenario(R"({"format":"kinetic-scenario/1",
    "dimension":2,"end_time":6,"objects":[
    {"id":0,"motion":[[3,-0.5,0.25],[-1,-1]]},{"id":1,"motion":[[-3,-0.5],[4,1]]},
    {"id":2,"motion":[[3,-0.5,0.25],[-1,-1]]},{"id":3,"motion":[[-2,1],[0,-0.5,-0.5]]},
    {"id":4,"motion":[[-3,-0.5],[4,1]]},{"id":5,"motion":[[3,-0.5,0.25],[-1,-1]]},
    {"id":6,"motion":[[3,-0.5,0.25],[-1,-1]]}],
    "timeline":[{"time":2,"op":"insert","id":7,"motion":[[-1,1.5],[-4]],"origin":2},
    {"time":3.5,"op":"insert","id":8,"motion":[[-1,0,0.25],[-1.25,-1.5]],"origin":3.5}]})",
                                                        "identical-groups.json");
  for (const SchedulerKind kind :
       {SchedulerKind::Robust, SchedulerKind::Classic, SchedulerKind::Exact}) {
    SCOPED_TRACE(to_string(kind));
    KdHarness h(s, kind, 1e-9);
    ASSERT_TRUE(h.tree->validate());
    std::mt19937_64 rng(47);
    std::vector<Time> probes = half_steps(12);
    for (const Time t : {1.999, 2.0, 2.001, 3.499, 3.5, 3.501}) probes.push_back(t);
    std::sort(probes.begin(), probes.end());
    h.check(probes, true, [&](Time t) {
      for (int q = 0; q < 6; ++q) {
        const Box box = random_box(h.motions, t, rng);
        EXPECT_EQ(ranged(*h.tree, box, t), brute_force(h.motions, box, t)) << "t=" << t;
      }
    });
  }
}

}  // namespace
}  // namespace kinetic
