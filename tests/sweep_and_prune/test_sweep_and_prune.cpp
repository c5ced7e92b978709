// Kinetic sweep-and-prune (sweep_and_prune/): validate() after every event (the contact set
// equal to a sweep of the maintained orders); colliding_pairs() against the brute-force oracle
// at random times, every difference explained by a side crossing within the scheduler's delay
// before the probe; every contact_begin / contact_end logged against the oracle's exact contact
// intervals (none lost, none invented, each within the delay bound of its exact time); random,
// integer-grid (simultaneous crossings, face-to-face contacts), identical, zero-extent, resting
// and quadratic boxes in 1 to 3 dimensions, with inserts, removes and updates, both schedulers.
#include "kinetic/sweep_and_prune/kinetic_sweep_and_prune.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "kinetic/core/pair_set.hpp"
#include "kinetic/oracle/oracle.hpp"
#include "support/collision.hpp"

namespace kinetic {
namespace {

using namespace test::collision;  // NOLINT: the shared collision checks
using SapHarness = Harness<KineticSweepAndPrune>;

TEST(SweepAndPrune, OracleEveryFamilyEveryDimensionBothSchedulers) {
  oracle_every_family_every_dimension<KineticSweepAndPrune>();
}
TEST(SweepAndPrune, InsertsRemovesUpdatesAgreeWithTheOracle) {
  inserts_removes_updates<KineticSweepAndPrune>();
}
TEST(SweepAndPrune, FaceToFaceContactHoldsForTheWholeInterval) {
  face_to_face_contact_holds<KineticSweepAndPrune>();
}
TEST(SweepAndPrune, ManySimultaneousContacts) {
  many_simultaneous_contacts<KineticSweepAndPrune>();
}
TEST(SweepAndPrune, ContactEventsMatchTheExactContactIntervals) {
  contact_events_match_exact_intervals<KineticSweepAndPrune>();
}

/// A bounce: the velocity changes, the position does not; the contact set stays and no box
/// moves in any order (the update costs O(d log n)).
TEST(SweepAndPrune, ContactChangesMakeTheAnswerFromThePreviousOne) {
  contact_changes_agree<KineticSweepAndPrune>();
}
TEST(SweepAndPrune, APileAtRestReportsNoContactChanges) {
  contact_changes_of_a_pile_at_rest<KineticSweepAndPrune>();
}
TEST(SweepAndPrune, AVelocityChangeKeepsEveryContact) {
  scenario::Scenario s = boxes_scenario(
      2, {{{{0, 1}, {0}}, {1, 1}}, {{{1.5, 1}, {1}}, {1, 1}}, {{{10, -1}, {0}}, {1, 1}}}, 10.0);
  SapHarness h(s, SchedulerKind::Robust, 1e-9);
  ASSERT_EQ(h.advance_to(2.0, true), AdvanceOutcome::Reached);
  EXPECT_EQ(ids_of(h.motions, h.tree->colliding_pairs(2.0)), (Pairs{{0, 1}}));
  const std::uint32_t box = h.motions.find(1)->index;
  scenario::TimelineOp up;
  up.time = 2.0;
  up.op = scenario::OpKind::Update;
  up.id = 1;
  up.motion = {{{3.5, -2}, {1}}, 2.0};  // at t = 2 still at 3.5, now moving left
  const std::uint32_t before = h.tree->sort(0).rank(BoxEndpointKeys::key(box, BoxSide::Low));
  h.apply(up);
  EXPECT_EQ(h.tree->sort(0).rank(BoxEndpointKeys::key(box, BoxSide::Low)), before);
  EXPECT_TRUE(h.tree->validate());
  EXPECT_EQ(ids_of(h.motions, h.tree->colliding_pairs(2.0)), (Pairs{{0, 1}}));
  EXPECT_EQ(h.tree->counters().overlap_checks, 0u);  // nothing was searched again
  // Box 1 now leaves box 0 (at t = 19/6); box 0 meets box 2 (from t = 4 on, apart again after
  // t = 6): probes away from those instants.
  for (const Time t : {3.0, 4.5, 5.0, 5.5, 6.5}) {
    ASSERT_EQ(h.advance_to(t, true), AdvanceOutcome::Reached);
    EXPECT_EQ(ids_of(h.motions, h.tree->colliding_pairs(t)),
              ids_of(h.motions, oracle::colliding_pairs_at(h.motions, t)))
        << "t = " << t;
  }
}

TEST(SweepAndPrune, RefusesATableOfPointsAndBadQueries) {
  expect_broad_phase_refusals<KineticSweepAndPrune>(
      2, [](KineticSweepAndPrune& sap, MotionTable& /*boxes*/) {
        EXPECT_TRUE(sap.colliding_pairs(0.0).empty());
        EXPECT_THROW((void)sap.colliding_pairs(1.0), PreconditionError);  // another time
      });
}

TEST(PairSet, AgreesWithAnOrderedSet) {
  std::mt19937_64 rng(3);
  PairSet set;
  std::set<std::pair<std::uint32_t, std::uint32_t>> ref;
  for (int step = 0; step < 200000; ++step) {
    std::uint32_t a = static_cast<std::uint32_t>(rng() % 300),
                  b = static_cast<std::uint32_t>(rng() % 300);
    if (a == b) continue;
    const std::pair<std::uint32_t, std::uint32_t> key{std::min(a, b), std::max(a, b)};
    if (rng() % 3 == 0) {
      EXPECT_EQ(set.erase(a, b), ref.erase(key) == 1);
    } else {
      EXPECT_EQ(set.insert(a, b), ref.insert(key).second);
    }
    if (step % 5000 == 0) {
      ASSERT_EQ(set.size(), ref.size());
      std::set<std::pair<std::uint32_t, std::uint32_t>> got;
      for (const std::uint64_t k : set.keys()) got.insert({PairSet::first(k), PairSet::second(k)});
      ASSERT_EQ(got, ref);
      for (const auto& [x, y] : ref) ASSERT_TRUE(set.contains(y, x));
    }
  }
}

}  // namespace
}  // namespace kinetic
