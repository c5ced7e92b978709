// The kinetic BVH over fat boxes (fat_bvh/): the collision structures' oracle checks
// (validate() after every event and change; colliding_pairs() against the brute force at random
// times, every difference explained by a crossing within the delay bound; every contact event
// against the exact contact intervals; the same contact events as sweep-and-prune), and what is
// its own: the dynamic tree of fat boxes against brute-force queries under churn, boxes at rest
// making no event, and fewer events than the exact-box tree.
#include "kinetic/fat_bvh/kinetic_fat_bvh.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "kinetic/bvh/kinetic_bvh.hpp"
#include "kinetic/fat_bvh/fat_box_tree.hpp"
#include "kinetic/scenario/generators.hpp"
#include "support/collision.hpp"

namespace kinetic {
namespace {

using namespace test::collision;  // NOLINT: the shared collision checks

TEST(FatBvh, OracleEveryFamilyEveryDimensionBothSchedulers) {
  oracle_every_family_every_dimension<KineticFatBvh>();
}
TEST(FatBvh, InsertsRemovesUpdatesAgreeWithTheOracle) { inserts_removes_updates<KineticFatBvh>(); }
TEST(FatBvh, FaceToFaceContactHoldsForTheWholeInterval) {
  face_to_face_contact_holds<KineticFatBvh>();
}
TEST(FatBvh, ManySimultaneousContacts) { many_simultaneous_contacts<KineticFatBvh>(); }
TEST(FatBvh, ContactEventsMatchTheExactContactIntervals) {
  contact_events_match_exact_intervals<KineticFatBvh>();
}
TEST(FatBvh, SameContactEventsAsSweepAndPrune) {
  same_contact_events_as_sweep_and_prune<KineticFatBvh>();
}

/// Thin and fat fattening (a lookahead of 0 extents, a tiny margin; and 8 extents): the answers
/// do not depend on it, only the work does.
TEST(FatBvh, ContactChangesMakeTheAnswerFromThePreviousOne) {
  contact_changes_agree<KineticFatBvh>();
}
TEST(FatBvh, APileAtRestReportsNoContactChanges) {
  contact_changes_of_a_pile_at_rest<KineticFatBvh>();
}
TEST(FatBvh, AnyFatteningGivesTheOraclesAnswers) {
  // Pairs settled as apart for ever without root isolation, and pair events (certificates that
  // did need it), over all runs: both paths of the classification meet the oracle here.
  std::uint64_t apart_for_ever = 0, pair_events = 0;
  for (const double lookahead : {0.0, 8.0}) {
    for (int d = 1; d <= 3; ++d) {
      const std::uint64_t seed = 90 + static_cast<std::uint64_t>(d);
      SCOPED_TRACE("lookahead " + std::to_string(lookahead) + ", d " + std::to_string(d) +
                   ", seed " + std::to_string(seed));
      std::mt19937_64 rng(seed);
      const scenario::Scenario s =
          with_changes(boxes_scenario(d, family("random", d, 30, rng), 10.0), "random", rng, 20);
      for (const SchedulerKind sk :
           {SchedulerKind::Robust, SchedulerKind::Classic, SchedulerKind::Exact}) {
        Harness<KineticFatBvh> h(s, sk, 1e-9);
        h.tree->set_fattening(lookahead, lookahead == 0.0 ? 1e-6 : 0.5);
        h.tree->initialize();  // again, with this fattening
        ASSERT_TRUE(h.tree->validate());
        std::vector<Time> probes;
        for (int i = 1; i < 40; ++i) probes.push_back(0.25 * i + 0.0123);
        h.check(probes, true, [&](Time t) {
          ASSERT_TRUE(h.tree->audit(t)) << "t = " << t << ", " << to_string(sk);
          EXPECT_EQ(ids_of(h.motions, h.tree->colliding_pairs(t)),
                    ids_of(h.motions, oracle::colliding_pairs_at(h.motions, t)))
              << "t = " << t << ", " << to_string(sk);
        });
        if (lookahead == 0.0) {
          EXPECT_GT(h.tree->counters().refits, 100u);
        }
        apart_for_ever += h.tree->counters().pairs_apart_for_ever;
        pair_events += h.tree->counters().pair_events;
      }
    }
  }
  EXPECT_GT(apart_for_ever, 100u);
  EXPECT_GT(pair_events, 100u);
}

/// A pile at rest (boxes stacked face to face, none moving) makes no event at all, and a box
/// flying past it costs only its own refits and the pairs it meets.
TEST(FatBvh, BoxesAtRestMakeNoEvents) {
  std::vector<BoxMotion> pile;
  for (int i = 0; i < 10; ++i) {
    for (int j = 0; j < 10; ++j) pile.push_back({{{2.0 * i}, {2.0 * j}}, {1, 1}});
  }
  for (const SchedulerKind sk :
       {SchedulerKind::Robust, SchedulerKind::Classic, SchedulerKind::Exact}) {
    SCOPED_TRACE(to_string(sk));
    Harness<KineticFatBvh> rest(boxes_scenario(2, pile, 100.0), sk, 1e-9);
    ASSERT_EQ(rest.advance_to(100.0, true), AdvanceOutcome::Reached);
    EXPECT_EQ(rest.sim.counters().events(), 0u);
    EXPECT_EQ(rest.tree->contacts(), 2u * 10 * 9 + 2u * 9 * 9);  // faces and corners touch
    EXPECT_EQ(ids_of(rest.motions, rest.tree->colliding_pairs(100.0)),
              ids_of(rest.motions, oracle::colliding_pairs_at(rest.motions, 100.0)));
    std::vector<BoxMotion> with_flyer = pile;
    with_flyer.push_back({{{-10.0, 1.0}, {-10.0}}, {0.5, 0.5}});  // below the pile, y = -10
    Harness<KineticFatBvh> fly(boxes_scenario(2, with_flyer, 100.0), sk, 1e-9);
    ASSERT_EQ(fly.advance_to(100.0, true), AdvanceOutcome::Reached);
    EXPECT_GT(fly.tree->counters().refits, 10u);
    EXPECT_EQ(fly.tree->counters().pair_events, 0u);  // it never comes near the pile
    EXPECT_EQ(fly.sim.counters().events(),
              fly.tree->counters().refits + fly.tree->counters().containment_checks);
  }
}

/// On boxes that travel about their size per unit time (boxes-linear) the fat boxes' events are
/// a fraction of the exact-box tree's (node sides and node pairs), with the same contacts.
TEST(FatBvh, FewerEventsThanTheExactBoxTree) {
  for (int d = 2; d <= 3; ++d) {
    scenario::GeneratorOptions g;
    g.n = 1000;
    g.seed = 300 + static_cast<std::uint64_t>(d);
    g.dimension = d;
    g.end_time = 5.0;
    const scenario::Scenario s = scenario::generate("boxes-linear", g);
    Harness<KineticFatBvh> fat(s, SchedulerKind::Robust, 1e-9);
    Harness<KineticBvh> bvh(s, SchedulerKind::Robust, 1e-9);
    ASSERT_EQ(fat.advance_to(5.0), AdvanceOutcome::Reached);
    ASSERT_EQ(bvh.advance_to(5.0), AdvanceOutcome::Reached);
    EXPECT_EQ(fat.tree->counters().contact_begins, bvh.tree->counters().contact_begins);
    EXPECT_EQ(fat.tree->counters().contact_ends, bvh.tree->counters().contact_ends);
    // n = 1000: 4,032 against 5,694 in 2-D, 4,125 against 12,594 in 3-D (the exact-box tree's
    // events grow with the tree's depth and the dimension; a refit does not).
    EXPECT_LT((d == 2 ? 1 : 2) * fat.sim.counters().events(), bvh.sim.counters().events())
        << "d " << d << ": " << fat.sim.counters().events() << " against "
        << bvh.sim.counters().events();
  }
}

/// The dynamic tree of constant boxes, built top down, then under random inserts and removes:
/// valid after each (links, node boxes the exact bounding boxes of their children, heights), its
/// queries the brute force's.
TEST(FatBoxTree, QueriesAgreeWithBruteForceUnderChurn) {
  for (int d = 1; d <= 3; ++d) {
    const std::uint64_t seed = 11 + static_cast<std::uint64_t>(d);
    SCOPED_TRACE("d " + std::to_string(d) + ", seed " + std::to_string(seed));
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> at(-50.0, 50.0), size(0.0, 4.0);
    const auto draw = [&] {
      ConstantBox b;
      for (std::size_t k = 0; k < static_cast<std::size_t>(d); ++k) {
        b.lo[k] = std::floor(at(rng));  // integers: boxes that touch
        b.hi[k] = b.lo[k] + std::floor(size(rng));
      }
      return b;
    };
    FatBoxTree tree(d);
    std::vector<ConstantBox> boxes;
    std::vector<std::uint32_t> alive;
    // Built top down over 300 boxes first, then changed one leaf at a time.
    for (std::uint32_t i = 0; i < 300; ++i) {
      boxes.push_back(draw());
      alive.push_back(i);
    }
    std::vector<std::uint32_t> leaf = tree.build(boxes, alive);
    ASSERT_TRUE(tree.validate());
    ASSERT_EQ(tree.leaves(), 300u);
    for (std::uint32_t i = 0; i < 300; ++i) ASSERT_EQ(tree.item(leaf[i]), i);
    for (int step = 0; step < 3000; ++step) {
      if (alive.empty() || rng() % 3 != 0) {
        const auto item = static_cast<std::uint32_t>(boxes.size());
        boxes.push_back(draw());
        leaf.push_back(tree.insert(boxes.back(), item));
        alive.push_back(item);
      } else {
        const std::size_t at_k = rng() % alive.size();
        tree.remove(leaf[alive[at_k]]);
        alive[at_k] = alive.back();
        alive.pop_back();
      }
      ASSERT_TRUE(tree.validate()) << "step " << step;
      if (step % 50 != 0) continue;
      const ConstantBox q = draw();
      std::set<std::uint32_t> got, want;
      tree.query(q, [&](std::uint32_t item) { EXPECT_TRUE(got.insert(item).second); });
      for (const std::uint32_t i : alive) {
        if (boxes_meet(boxes[i], q, d)) want.insert(i);
      }
      ASSERT_EQ(got, want) << "step " << step;
    }
    EXPECT_GT(tree.rotations(), 0u);
  }
}

TEST(FatBvh, RefusesATableOfPointsAndBadBoxes) {
  expect_broad_phase_refusals<KineticFatBvh>(2, [](KineticFatBvh& fat, MotionTable& boxes) {
    const std::vector<MotionPolynomial> bad{
        MotionPolynomial::from({0.0}), MotionPolynomial::from({0.0}),
        MotionPolynomial::from({-1.0}), MotionPolynomial::from({1.0})};
    const ObjectHandle h = boxes.insert(1, bad);
    EXPECT_THROW(fat.insert(h.index), PreconditionError);
    EXPECT_THROW(fat.set_fattening(-1.0, 0.1), PreconditionError);
    EXPECT_THROW(fat.set_fattening(1.0, 0.0), PreconditionError);
  });
}

}  // namespace
}  // namespace kinetic
