// The kinetic BVH with its kinetic separation list (bvh/): the same oracle checks as
// sweep-and-prune (validate() after every event; colliding_pairs() against the brute force at
// random times, every difference explained by a crossing within the delay bound; every contact
// event against the exact contact intervals), and what is its own: node boxes equal to their
// leaves' bounding boxes at any time, the list collapsing back when boxes part, the rebuild
// policy, and the same contacts as sweep-and-prune event for event.
#include "kinetic/bvh/kinetic_bvh.hpp"

#include <gtest/gtest.h>

#include <map>
#include <set>
#include <string>

#include "support/collision.hpp"

namespace kinetic {
namespace {

using namespace test::collision;  // NOLINT: the shared collision checks

TEST(Bvh, OracleEveryFamilyEveryDimensionBothSchedulers) {
  oracle_every_family_every_dimension<KineticBvh>();
}
TEST(Bvh, InsertsRemovesUpdatesAgreeWithTheOracle) { inserts_removes_updates<KineticBvh>(); }
TEST(Bvh, FaceToFaceContactHoldsForTheWholeInterval) { face_to_face_contact_holds<KineticBvh>(); }
TEST(Bvh, ManySimultaneousContacts) { many_simultaneous_contacts<KineticBvh>(); }
TEST(Bvh, ContactEventsMatchTheExactContactIntervals) {
  contact_events_match_exact_intervals<KineticBvh>();
}

/// The two kinetic broad phases report the same contact events, in the same order, on a
/// generic scene; the BVH does far fewer events.
TEST(Bvh, SameContactEventsAsSweepAndPrune) {
  same_contact_events_as_sweep_and_prune<KineticBvh>();
}

/// Boxes that meet and part again: the list expands while they overlap and collapses back to
/// the same separated front when they have parted.
TEST(Bvh, ContactChangesMakeTheAnswerFromThePreviousOne) {
  contact_changes_agree<KineticBvh>();
}
TEST(Bvh, APileAtRestReportsNoContactChanges) {
  contact_changes_of_a_pile_at_rest<KineticBvh>();
}
TEST(Bvh, TheListCollapsesBackWhenBoxesPart) {
  // Two clusters of 8 boxes passing through each other along x, apart before and after.
  std::vector<BoxMotion> boxes;
  for (int i = 0; i < 8; ++i) {
    boxes.push_back({{{-20.0 + (i % 4), 2.0}, {3.0 * (i / 4)}}, {0.4, 0.4}});
    boxes.push_back({{{20.0 + (i % 4), -2.0}, {3.0 * (i / 4) + 0.5}}, {0.4, 0.4}});
  }
  Harness<KineticBvh> h(boxes_scenario(2, boxes, 20.0), SchedulerKind::Robust, 1e-9);
  const KineticBvh::ListSizes before = h.tree->list_sizes();
  ASSERT_EQ(h.advance_to(10.0, true), AdvanceOutcome::Reached);  // x = 0: all overlapping
  EXPECT_GT(h.tree->contacts(), 0u);
  const KineticBvh::ListSizes during = h.tree->list_sizes();
  EXPECT_GT(during.expanded + during.contact, before.expanded + before.contact);
  ASSERT_EQ(h.advance_to(20.0, true), AdvanceOutcome::Reached);  // apart again
  EXPECT_EQ(h.tree->contacts(), 0u);
  const KineticBvh::ListSizes after = h.tree->list_sizes();
  EXPECT_GT(h.tree->counters().collapses, 0u);
  EXPECT_LE(after.separated + after.expanded + after.contact,
            during.separated + during.expanded + during.contact);
  EXPECT_EQ(after.contact, 0u);
}

/// The picture of the list (sketch_pairs, as traces write it): with every level listed it holds
/// every pair of the list, in the states list_sizes() counts; with fewer levels, exactly the
/// pairs between listed nodes.
TEST(Bvh, SketchPairsAreTheListsPairsBetweenListedNodes) {
  std::mt19937_64 rng(17);
  const scenario::Scenario s = boxes_scenario(2, family("random", 2, 80, rng), 10.0);
  Harness<KineticBvh> h(s, SchedulerKind::Robust, 1e-9);
  for (const double t : {0.0, 2.5, 5.0}) {
    ASSERT_EQ(h.advance_to(t, true), AdvanceOutcome::Reached);
    const KineticBvh::ListSizes sizes = h.tree->list_sizes();
    std::map<std::string, std::size_t> by_state;
    for (const KineticBvh::PairSketch& p : h.tree->sketch_pairs(64)) ++by_state[p.state];
    EXPECT_EQ(by_state["separated"], sizes.separated) << "t " << t;
    EXPECT_EQ(by_state["expanded"], sizes.expanded) << "t " << t;
    EXPECT_EQ(by_state["contact"], sizes.contact) << "t " << t;
    EXPECT_EQ(by_state["self"], sizes.self) << "t " << t;
    EXPECT_EQ(sizes.contact, h.tree->contacts());
    // Three levels: 7 nodes; every pair listed is between two of them, each self pair of an
    // internal node among them is there.
    const std::vector<KineticBvh::NodeSketch> nodes = h.tree->sketch(3);
    ASSERT_EQ(nodes.size(), 7u);
    std::size_t selfs = 0;
    for (const KineticBvh::PairSketch& p : h.tree->sketch_pairs(3)) {
      EXPECT_LT(p.a, nodes.size());
      EXPECT_LT(p.b, nodes.size());
      selfs += std::string(p.state) == "self" ? 1 : 0;
    }
    EXPECT_EQ(selfs, 7u) << "t " << t;
  }
}

/// The quality policy: boxes that scatter far from their build order degrade the tree's
/// surface-area cost; the policy rebuilds it (counted) and keeps the ratio bounded, and the
/// contacts stay exact through the rebuilds.
TEST(Bvh, RebuildPolicyBoundsTheSurfaceAreaRatio) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<BoxMotion> boxes;
  for (int i = 0; i < 300; ++i)
    boxes.push_back({{{5 * u(rng), 4 * u(rng)}, {5 * u(rng), 4 * u(rng)}}, {0.3, 0.3}});
  const scenario::Scenario s = boxes_scenario(2, boxes, 6.0);
  Harness<KineticBvh> kept(s, SchedulerKind::Robust, 1e-9);
  kept.tree->set_rebuild_policy(false);
  Harness<KineticBvh> policy(s, SchedulerKind::Robust, 1e-9);
  EXPECT_DOUBLE_EQ(policy.tree->quality_ratio(), 1.0);
  for (const Time t : {1.0, 2.0, 4.0, 6.0}) {
    ASSERT_EQ(kept.advance_to(t), AdvanceOutcome::Reached);
    ASSERT_EQ(policy.advance_to(t), AdvanceOutcome::Reached);
    EXPECT_TRUE(policy.tree->validate());
    EXPECT_EQ(ids_of(policy.motions, policy.tree->colliding_pairs(t)),
              ids_of(policy.motions, oracle::colliding_pairs_at(policy.motions, t)));
  }
  EXPECT_GT(kept.tree->quality_ratio(), KineticBvh::rebuild_ratio());
  EXPECT_GT(policy.tree->counters().rebuilds, 0u);
  EXPECT_LT(policy.tree->quality_ratio(), kept.tree->quality_ratio());
}

/// A cluster of boxes scrambling beside a rest of boxes that do not move (touching face to
/// face on a grid): the tree's excess cost is all in the cluster's subtree, and the quality
/// policy rebuilds that subtree, not the tree. Dyadic coordinates (exact arithmetic stays
/// cheap).
scenario::Scenario cluster_beside_rest(int d, std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const auto eighths = [&](int lo, int hi) {  // a multiple of 1/8 in [lo, hi]
    return static_cast<double>(8 * lo +
                               static_cast<int>(rng() % static_cast<unsigned>(8 * (hi - lo) + 1))) /
           8.0;
  };
  std::vector<BoxMotion> boxes;
  for (std::size_t i = 0; i < n / 3; ++i) {  // at rest: unit boxes side by side, x in [9, 9 + n/3]
    BoxMotion m;
    for (int k = 0; k < d; ++k) {
      const double at =
          k == 0 ? 10.0 + 2.0 * static_cast<double>(i / 2) : 2.0 * static_cast<double>(i % 2);
      m.center.push_back({at});
      m.half.push_back(1.0);
    }
    boxes.push_back(m);
  }
  while (boxes.size() < n) {  // the cluster: x in [-60, -44], every other axis in [0, 8]
    BoxMotion m;
    for (int k = 0; k < d; ++k) {
      m.center.push_back({k == 0 ? eighths(-60, -44) : eighths(0, 8), eighths(-4, 4)});
      m.half.push_back(eighths(0, 1) / 2.0 + 0.25);
    }
    boxes.push_back(m);
  }
  return boxes_scenario(d, boxes, 10.0);
}

/// Local rebuilds keep the list exact: validate() after every event and colliding_pairs()
/// against the oracle at random times (check_queries), under every scheduler, with and without
/// a churn of inserts, removes and updates; the logged contact events replay to the contact set;
/// under the exact scheduler they are the events of the run without rebuilds, in the same order.
TEST(Bvh, LocalRebuildsKeepTheListExact) {
  constexpr std::uint64_t kCheckEvery = 128;
  struct Logged {
    Time time;
    std::string kind;
    ObjectId a, b;
    bool operator==(const Logged&) const = default;
  };
  const auto record = [](void* context, Time t, const char* kind, std::span<const ObjectId> ids,
                         int) {
    static_cast<std::vector<Logged>*>(context)->push_back({t, kind, ids[0], ids[1]});
  };
  for (int d = 2; d <= 3; ++d) {
    const std::uint64_t seed = 8300 + static_cast<std::uint64_t>(d);
    const scenario::Scenario quiet = cluster_beside_rest(d, 96, seed);
    std::mt19937_64 rng(seed);
    const scenario::Scenario churned = with_changes(quiet, "random", rng, 40);
    for (const SchedulerKind sk :
         {SchedulerKind::Robust, SchedulerKind::Classic, SchedulerKind::Exact}) {
      for (const scenario::Scenario* s : {&quiet, &churned}) {
        SCOPED_TRACE("d " + std::to_string(d) + ", seed " + std::to_string(seed) + ", " +
                     to_string(sk) + (s == &churned ? ", churned" : ""));
        const Outcome o = check_queries<KineticBvh>(
            *s, sk, seed, 1, [](KineticBvh& t) { t.set_quality_check_interval(kCheckEvery); });
        if (::testing::Test::HasFailure()) return;
        EXPECT_GT(o.contacts, 0u);
        Harness<KineticBvh> h(*s, sk, 1e-9);
        const auto contact_set = [&](Time t) {  // the pairs of the maintained set
          std::set<std::pair<ObjectId, ObjectId>> out;
          for (const auto& [a, b] : ids_of(h.motions, h.tree->colliding_pairs(t)))
            if (h.tree->in_contact(h.motions.find(a)->index, h.motions.find(b)->index))
              out.emplace(a, b);
          return out;
        };
        std::set<std::pair<ObjectId, ObjectId>> replayed = contact_set(s->start_time);
        std::vector<Logged> log;
        h.sim.set_event_log(record, &log);
        h.tree->set_quality_check_interval(kCheckEvery);
        ASSERT_EQ(h.advance_to(*s->end_time), AdvanceOutcome::Reached);
        const BvhCounters& c = h.tree->counters();
        for (const Logged& l : log) {
          if (l.kind == "contact_begin") {
            EXPECT_TRUE(replayed.emplace(l.a, l.b).second) << "begun twice: " << l.a << ", " << l.b;
          } else if (l.kind == "contact_end") {
            EXPECT_EQ(replayed.erase({l.a, l.b}), 1u) << "ended, not begun: " << l.a << ", " << l.b;
          }
        }
        if (s == &quiet) {  // the removed boxes' contacts end without events under churn
          EXPECT_EQ(replayed, contact_set(*s->end_time));
          // The cluster's subtree, never the tree.
          EXPECT_GT(c.local_rebuilds, 0u);
          EXPECT_EQ(c.local_rebuilds, c.rebuilds);
          EXPECT_LE(c.rebuilt_leaves, c.rebuilds * s->objects.size() / 2);
        }
        EXPECT_EQ(c.contact_begins + c.contact_ends, log.size());
        if (sk != SchedulerKind::Exact) continue;
        Harness<KineticBvh> kept(*s, sk, 1e-9);
        kept.tree->set_rebuild_policy(false);
        kept.tree->set_quality_check_interval(kCheckEvery);
        std::vector<Logged> kept_log;
        kept.sim.set_event_log(record, &kept_log);
        ASSERT_EQ(kept.advance_to(*s->end_time), AdvanceOutcome::Reached);
        EXPECT_EQ(kept.tree->counters().rebuilds, 0u);
        // Events at one instant in a canonical order (the queue's order of simultaneous events
        // depends on which certificates exist).
        const auto canonical = [](std::vector<Logged>& l) {
          std::stable_sort(l.begin(), l.end(), [](const Logged& x, const Logged& y) {
            return std::tie(x.time, x.a, x.b, x.kind) < std::tie(y.time, y.a, y.b, y.kind);
          });
        };
        canonical(log);
        canonical(kept_log);
        EXPECT_TRUE(log == kept_log)
            << log.size() << " events with rebuilds, " << kept_log.size() << " without";
      }
    }
  }
}

/// Inserts and removes are local: a long churn (200 changes on a handful of boxes, then every
/// box removed and new ones inserted into the empty tree) keeps validate() and the oracle's
/// pairs after every event and change, under every scheduler, and never rebuilds the tree;
/// updates that jump far from the leaf's sibling move the leaf (remove and insert).
TEST(Bvh, InsertsAndRemovesAreLocalUnderChurn) {
  std::uint64_t moved = 0, updates = 0;  // jumps that moved a leaf; all updates
  for (const SchedulerKind sk :
       {SchedulerKind::Robust, SchedulerKind::Classic, SchedulerKind::Exact}) {
    for (int d = 1; d <= 3; ++d) {
      for (const char* kind : {"random", "grid", "identical"}) {
        const std::uint64_t seed = 8100 + static_cast<std::uint64_t>(d);
        SCOPED_TRACE(std::string(kind) + ", d " + std::to_string(d) + ", seed " +
                     std::to_string(seed) + ", " + to_string(sk));
        std::mt19937_64 rng(seed);
        scenario::Scenario s =
            with_changes(boxes_scenario(d, family(kind, d, 4, rng), 10.0), kind, rng, 200);
        // Drain: every box alive at 9.5 removed, then 12 inserted into the empty tree (the
        // changes drawn after 9.5 left out: a timeline is in time order).
        std::erase_if(s.timeline, [](const scenario::TimelineOp& op) { return op.time >= 9.5; });
        std::set<ObjectId> alive;
        for (const auto& o : s.objects) alive.insert(o.id);
        std::size_t inserts = 0, removes = 0;
        for (const auto& op : s.timeline) {
          if (op.op == scenario::OpKind::Insert) alive.insert(op.id), ++inserts;
          if (op.op == scenario::OpKind::Remove) alive.erase(op.id), ++removes;
        }
        for (const ObjectId id : alive) {
          scenario::TimelineOp op;
          op.time = 9.5;
          op.op = scenario::OpKind::Remove;
          op.id = id;
          op.file_index = s.timeline.size();
          s.timeline.push_back(op);
          ++removes;
        }
        for (int i = 0; i < 12; ++i) {
          const BoxMotion m = draw(std::string(kind) == "identical" ? "grid" : kind, d, rng);
          scenario::TimelineOp op;
          op.time = 9.75;
          op.op = scenario::OpKind::Insert;
          op.id = static_cast<ObjectId>(5000 + i);
          op.motion = to_motion(m);
          op.half_extents = m.half;
          op.file_index = s.timeline.size();
          s.timeline.push_back(op);
          ++inserts;
        }
        const Outcome o = check_queries<KineticBvh>(s, sk, seed, 1);
        if (::testing::Test::HasFailure()) return;
        EXPECT_LE(o.differing, 3u);
        EXPECT_GT(inserts, 40u);
        EXPECT_GT(removes, 40u);
        Harness<KineticBvh> h(s, sk, 1e-9);
        h.tree->set_rebuild_policy(false);
        (void)h.check({}, false, [](Time) {});
        EXPECT_EQ(h.tree->counters().inserts, inserts);
        EXPECT_EQ(h.tree->counters().removes, removes);
        EXPECT_EQ(h.tree->counters().rebuilds, 0u);
        EXPECT_EQ(h.tree->nodes(), 2 * h.motions.size() - 1);
        EXPECT_TRUE(h.tree->validate());
        moved += h.tree->counters().moved_leaves;
        updates += h.tree->counters().updates;
      }
    }
  }
  // Some updates jump far from the leaf's sibling (the leaf moved), not all.
  EXPECT_GT(moved, 0u);
  EXPECT_LT(moved, updates);
}

/// An overlap certificate is kept when its node side's winner changes at an event (the old
/// winner's inequality still implies the node's), and rescheduled when the box it was computed
/// from changes its motion. Here b = [-3, -1] overlaps node A = {a1, a2} through a1's low side
/// (-1.5); a2's low side t^2 - 4t + 2 passes below a1's at t = 2 - sqrt(0.5) (A's winner
/// changes, the certificate is kept from a1); a1 jumps away at t = 2; A's low side is then
/// a2's, above b's high side after t = 3: the pair (b, A) must be collapsed by t = 3.5.
TEST(Bvh, AKeptOverlapCertificateFollowsAnUpdateOfItsOldWinner) {
  for (const SchedulerKind sk :
       {SchedulerKind::Robust, SchedulerKind::Classic, SchedulerKind::Exact}) {
    SCOPED_TRACE(to_string(sk));
    const std::vector<BoxMotion> boxes{{{{-2.0}}, {1.0}},             // b
                                       {{{0.0}}, {1.5}},              // a1
                                       {{{3.0, -4.0, 1.0}}, {1.0}}};  // a2: center t^2 - 4t + 3
    scenario::Scenario s = boxes_scenario(1, boxes, 4.0);
    scenario::TimelineOp jump;
    jump.time = 2.0;
    jump.op = scenario::OpKind::Update;
    jump.id = 1;
    jump.motion = {{{100.0}}, 2.0};
    jump.file_index = 0;
    s.timeline.push_back(jump);
    Harness<KineticBvh> h(s, sk, 1e-9);
    h.tree->set_rebuild_policy(false);
    EXPECT_EQ(h.tree->list_sizes().expanded, 1u);  // (b, A)
    const std::vector<Time> probes{1.9, 3.5};
    (void)h.check(probes, true, [&](Time t) {
      EXPECT_TRUE(h.tree->audit(t)) << "t = " << t;
      if (t == 3.5) {
        EXPECT_EQ(h.tree->list_sizes().expanded, 0u);  // (b, A) collapsed at t = 3
        EXPECT_TRUE(h.tree->colliding_pairs(t).empty());
      }
    });
    EXPECT_GT(h.tree->counters().lazy_keeps, 0u);
  }
}

TEST(Bvh, RefusesATableOfPointsAndBadBoxes) {
  expect_broad_phase_refusals<KineticBvh>(1, [](KineticBvh& bvh, MotionTable& boxes) {
    const std::vector<MotionPolynomial> bad{MotionPolynomial::from({0.0}),
                                            MotionPolynomial::from({-1.0})};
    const ObjectHandle h = boxes.insert(1, bad);
    EXPECT_THROW(bvh.insert(h.index), PreconditionError);
  });
}

}  // namespace
}  // namespace kinetic
