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
#include <cstdio>
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

/// Churn at scale: 400 changes (inserts, removes, jumps, new sizes, bounces) among about 400
/// boxes in 2-D and 3-D, on dyadic coordinates and times (sides meet exactly; identical boxes,
/// zero extents, faces touching). After every change validate() (the orders, the contact set
/// equal to a sweep, the straddler indexes' leaves and maxima) and, under the exact scheduler,
/// audit() after every tenth (the orders sorted exactly at the change's time). The searches for
/// a changed box's contacts meet only boxes near it: on average fewer than a fifth of the boxes
/// per change (about 1/25 in 2-D, 1/10 in 3-D), where a pass over all boxes meets all of them.
TEST(SweepAndPrune, ChurnAtScaleSearchesOnlyNearTheChangedBox) {
  for (const SchedulerKind sk : {SchedulerKind::Exact, SchedulerKind::Robust}) {
    for (int d = 2; d <= 3; ++d) {
      const std::uint64_t seed =
          9100 + 10 * static_cast<std::uint64_t>(sk) + static_cast<std::uint64_t>(d);
      SCOPED_TRACE("seed " + std::to_string(seed) + ", d " + std::to_string(d) + ", " +
                   to_string(sk));
      std::mt19937_64 rng(seed);
      const std::size_t n = 400;
      // About one contact per box: side L with n (2h)^d ~ L^d, h = 1/2.
      const double side = d == 2 ? 2.0 * std::sqrt(double(n)) : 2.0 * std::cbrt(double(n));
      const auto eighths = [&](double lo, double hi) {
        const auto k = static_cast<std::int64_t>(8.0 * (hi - lo));
        return lo +
               static_cast<double>(static_cast<std::int64_t>(rng() % std::uint64_t(k + 1))) / 8.0;
      };
      std::vector<BoxMotion> made;
      const auto draw_box = [&]() {
        if (!made.empty() && rng() % 12 == 0) return made[rng() % made.size()];  // identical
        BoxMotion m;
        for (int a = 0; a < d; ++a) {
          m.center.push_back({eighths(0.0, side), eighths(-1.0, 1.0)});
          m.half.push_back(rng() % 9 == 0 ? 0.0 : 0.5);
        }
        made.push_back(m);
        return m;
      };
      std::vector<BoxMotion> boxes;
      for (std::size_t i = 0; i < n; ++i) boxes.push_back(draw_box());
      scenario::Scenario s = boxes_scenario(d, boxes, 100.0);
      SapHarness h(s, sk, 1e-9);
      ASSERT_TRUE(h.tree->validate());
      std::vector<ObjectId> alive;
      for (std::size_t i = 0; i < n; ++i) alive.push_back(static_cast<ObjectId>(i));
      ObjectId next_id = 100000;
      Time t = 0.0;
      std::uint64_t changes = 0;
      for (int step = 0; step < 400; ++step) {
        if (step % 30 == 0) {
          t += 0.0078125;
          ASSERT_EQ(h.advance_to(t), AdvanceOutcome::Reached);
        }
        scenario::TimelineOp op;
        op.time = t;
        const int what = static_cast<int>(rng() % 10);
        const BoxMotion m = draw_box();
        if (what < 4 || alive.size() < 2) {
          op.op = scenario::OpKind::Insert;
          op.id = next_id++;
          alive.push_back(op.id);
          op.motion = {m.center, t};
          op.half_extents = m.half;
        } else if (what < 7) {
          op.op = scenario::OpKind::Remove;
          const std::size_t k = rng() % alive.size();
          op.id = alive[k];
          alive.erase(alive.begin() + static_cast<std::ptrdiff_t>(k));
        } else {
          op.op = scenario::OpKind::Update;
          op.id = alive[rng() % alive.size()];
          op.motion = {m.center, t};
          if (what == 9) {
            // A bounce: the same position now, a new velocity.
            const std::uint32_t box = h.motions.find(op.id)->index;
            for (int a = 0; a < d; ++a)
              op.motion.coordinates[static_cast<std::size_t>(a)][0] =
                  center(h.motions, box, a).evaluate(t);
          } else if (what == 8) {
            op.half_extents = m.half;  // a jump with a new size
          }
        }
        h.apply(op);
        ++changes;
        ASSERT_TRUE(h.tree->validate()) << "step " << step << " t=" << t;
        // Under the exact scheduler the orders are sorted at t (every tenth change: O(n) exact
        // comparisons, many of them ties), so the contact set (equal to their sweep, by
        // validate()) is the brute force's answer just after t. (The brute force itself, O(n^2)
        // exact comparisons, is asked on the small scenes of the other tests.)
        if (sk == SchedulerKind::Exact && step % 10 == 0) {
          ASSERT_TRUE(h.tree->audit(t)) << "step " << step << " t=" << t;
        }
      }
      const SweepAndPruneCounters& c = h.tree->counters();
      EXPECT_GT(c.contact_candidates, 0u);
      EXPECT_LT(c.contact_candidates, changes * n / 5)
          << "candidates per change: " << double(c.contact_candidates) / double(changes);
      EXPECT_GT(h.tree->colliding_pairs(t).size(), 0u);
      EXPECT_GT(c.swaps, 300u);  // the boxes moved between the changes
      std::printf("churn d=%d %s: %llu swaps, %.1f candidates per change\n", d, to_string(sk),
                  static_cast<unsigned long long>(c.swaps),
                  double(c.contact_candidates) / double(changes));
    }
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
