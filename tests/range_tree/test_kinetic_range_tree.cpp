// The kinetic range tree (Abam, Agarwal, de Berg, Yu, Section 5): the structure keeps its
// invariants after every event and change (validate()), range answers equal brute force at
// times away from events in d = 1..3 for random and degenerate motions (shared coordinates, equal
// trajectories, simultaneous swaps on several axes, GRIDS), with inserts, removes and updates,
// under both schedulers; and, with the robust scheduler, every answer (right after events too)
// is a Delta-approximation with Delta = n eps V_max (Theorem 8).
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <vector>

#include "kinetic/core/predicates.hpp"
#include "kinetic/oracle/oracle.hpp"
#include "kinetic/range_tree/kinetic_range_tree.hpp"
#include "kinetic/scenario/generators.hpp"
#include "support/box_range_suite.hpp"
#include "support/driver.hpp"

namespace kinetic {
namespace {

using test::polynomials;

using RtHarness = test::TreeHarness<KineticRangeTree>;

std::vector<std::uint32_t> brute_force(const MotionTable& motions, const Box& box, Time t) {
  return oracle::in_box_at(motions, box, t);
}

using test::random_box;

/// Every swap is one axis's: the per-axis counts add up to the events.
void swaps_add_up(const KineticRangeTree& tree, std::uint64_t events) {
  std::uint64_t by_axis = 0;
  for (const std::uint64_t e : tree.counters().swaps_by_axis) by_axis += e;
  EXPECT_EQ(by_axis, events);
}

/// The range tree's oracle check (test::check_box_range_run).
void check_run(const scenario::Scenario& s, SchedulerKind kind, std::uint64_t seed,
               bool validate_each) {
  test::check_box_range_run<KineticRangeTree>(
      s, kind, seed, validate_each,
      [](KineticRangeTree& tree, const Box& box, Time t) { return tree.range(box, t); },
      swaps_add_up);
}

}  // namespace
}  // namespace kinetic

namespace kinetic::test {

/// The range tree in the box-range suite: static builds and mixed queries in d = 1 to 3
/// (FourDimensions below runs d = 4), fewer points than the kd-tree (it is slower to build).
template <>
struct BoxRangeTraits<KineticRangeTree> {
  static constexpr int kMaxDimension = 3;
  static constexpr int kRunDimension = 3;
  static constexpr std::size_t kStaticLargest = 200;
  static constexpr std::size_t kPolyPoints = 30;
  static constexpr std::size_t kChangingPoints = 40;
  static constexpr std::array<LargerRun, 2> kLargerRuns{
      {{300, 2, 5, SchedulerKind::Robust}, {120, 3, 6, SchedulerKind::Classic}}};
  static int mixed_points(int d) { return d == 3 ? 600 : 1200; }
  static constexpr int kGridPoints = 48;
  static std::vector<std::uint32_t> range(KineticRangeTree& tree, const Box& box, Time t) {
    return tree.range(box, t);
  }
  static void after_run(const KineticRangeTree& tree, std::uint64_t events) {
    swaps_add_up(tree, events);
  }
};

INSTANTIATE_TYPED_TEST_SUITE_P(RangeTree, BoxRangeSuite, ::testing::Types<KineticRangeTree>);

}  // namespace kinetic::test

namespace kinetic {
namespace {

scenario::Scenario make(const std::string& dataset, std::size_t n, int d, std::uint64_t seed,
                        int degree, bool changes) {
  return test::generated(dataset, n, d, seed, degree, changes);
}

/// Long mixed sequences: 1,290 inserts, removes and updates growing 100 points to about 1,000,
/// and 900 shrinking 700 to about 150, d = 1, 2, 3, robust and exact (classic on the growing
/// run). validate() after every change (every entry in its node, blocks in label order, every
/// array complete); 6 boxes against brute force at 30 random times and before every change.
/// The changes are local: the tree is rebuilt only when A_0 is laid out again (a few times);
/// keys moved in A_0 change nodes, and places shift entries or spread windows.
TEST(KineticRangeTree, LongMixedSequencesOfInsertsRemovesUpdates) {
  for (int d = 1; d <= 3; ++d) {
    for (const SchedulerKind kind :
         {SchedulerKind::Robust, SchedulerKind::Exact, SchedulerKind::Classic}) {
      const auto seed = static_cast<std::uint64_t>(40 + d);
      for (const bool grow : {true, false}) {
        if (kind == SchedulerKind::Classic && !grow) continue;
        if (d == 3 && kind != SchedulerKind::Robust) continue;  // the slowest; robust covers it
        const scenario::Scenario s =
            grow ? test::long_mixed("random-linear", 100, d, seed, 1000, 90, 200)
                 : test::long_mixed("random-linear", 700, d, seed, 100, 650, 150);
        test::check_box_range_run<KineticRangeTree>(
            s, kind, seed, false,
            [](KineticRangeTree& tree, const Box& box, Time t) { return tree.range(box, t); },
            [&](const KineticRangeTree& tree, std::uint64_t) {
              const RangeTreeCounters& c = tree.counters();
              SCOPED_TRACE(grow ? "growing" : "shrinking");
              EXPECT_GE(c.rebuilds, 1u);  // A_0 laid out again on the way
              EXPECT_LE(c.rebuilds, 12u);
              EXPECT_EQ(c.local_changes + c.rebuilds, grow ? 1290u : 900u);
              EXPECT_GT(c.relabel_moves, 0u);
              if (d > 1) {
                EXPECT_GT(c.shifts, 0u);
                EXPECT_GT(c.placements, 0u);
              }
            });
        if (::testing::Test::HasFailure()) return;
      }
    }
  }
}

/// Inserts clustered on one axis: 600 points join 200 with their y (and z) in a band a
/// thousandth of the others' spread and at rest there, x anywhere. The band's run in every block
/// above soon has no vacancy within kShiftReach, so places spread windows (below the last level
/// too, in 3-D, where the moved entries change the z-blocks); every change validated, boxes
/// against brute force before every change and at 30 random times.
TEST(KineticRangeTree, ClusteredInsertsSpreadWindows) {
  for (const int d : {2, 3}) {
    scenario::Scenario s = make("random-linear", 200, d, 71, 1, false);
    std::mt19937_64 rng(71);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const Time end = *s.end_time;
    for (int k = 0; k < 600; ++k) {
      scenario::TimelineOp op;
      op.time = s.start_time + (end - s.start_time) * (k + 1) / 601.0;
      op.op = scenario::OpKind::Insert;
      op.id = static_cast<ObjectId>(10000 + k);
      op.motion.coordinates.push_back({14.0 * u(rng), 2.0 * u(rng) - 1.0});
      for (int a = 1; a < d; ++a) op.motion.coordinates.push_back({7.0 + 0.01 * u(rng), 0.0});
      op.motion.origin = op.time;
      s.timeline.push_back(op);
    }
    test::check_box_range_run<KineticRangeTree>(
        s, SchedulerKind::Robust, 71, false,
        [](KineticRangeTree& tree, const Box& box, Time t) { return tree.range(box, t); },
        [&](const KineticRangeTree& tree, std::uint64_t) {
          const RangeTreeCounters& c = tree.counters();
          SCOPED_TRACE("d " + std::to_string(d));
          EXPECT_GT(c.window_spreads, 0u);
          EXPECT_GT(c.spread_entries, 64u * c.window_spreads / 2);
          EXPECT_EQ(c.local_changes + c.rebuilds, 600u);
          EXPECT_GE(c.local_changes, 590u);
        });
  }
}

/// Removing a band: every point whose y (at the start) lies in the middle 40 % of the spread
/// leaves, one at a time, then 200 points join in that band. Without closing the gaps, every
/// block above would keep a vacant run across the band, which the searches skip one by one;
/// with it, after the removes and at the end no block with a point has a run of
/// kMaxVacantRun vacancies. d = 2 and 3; every change validated, boxes against brute force
/// before every change and at 30 random times.
TEST(KineticRangeTree, RemovingABandKeepsVacantRunsShort) {
  for (const int d : {2, 3}) {
    SCOPED_TRACE("d " + std::to_string(d));
    scenario::Scenario s = make("random-linear", d == 2 ? 1500 : 600, d, 81, 1, false);
    std::mt19937_64 rng(81);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const Time end = *s.end_time;
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (const auto& o : s.objects) {
      lo = std::min(lo, o.motion.coordinates[1][0]);
      hi = std::max(hi, o.motion.coordinates[1][0]);
    }
    const double b0 = lo + 0.3 * (hi - lo), b1 = lo + 0.7 * (hi - lo);
    std::size_t removed = 0;
    for (const auto& o : s.objects) {
      const double y = o.motion.coordinates[1][0];
      if (y < b0 || y > b1) continue;
      scenario::TimelineOp op;
      op.time = s.start_time + (end - s.start_time) * 1e-3 * static_cast<double>(removed + 1) /
                                   static_cast<double>(s.objects.size());
      op.op = scenario::OpKind::Remove;
      op.id = o.id;
      s.timeline.push_back(op);
      ++removed;
    }
    const Time refill = s.start_time + (end - s.start_time) * 0.5;
    for (int k = 0; k < 200; ++k) {
      scenario::TimelineOp op;
      op.time = refill + (end - s.start_time) * 1e-3 * (k + 1);
      op.op = scenario::OpKind::Insert;
      op.id = static_cast<ObjectId>(50000 + k);
      op.motion.coordinates.push_back({lo + (hi - lo) * u(rng), 2.0 * u(rng) - 1.0});
      op.motion.coordinates.push_back({b0 + (b1 - b0) * u(rng), 2.0 * u(rng) - 1.0});
      for (int a = 2; a < d; ++a) op.motion.coordinates.push_back({lo + (hi - lo) * u(rng), 0.0});
      op.motion.origin = op.time;
      s.timeline.push_back(op);
    }
    ASSERT_GT(removed, s.objects.size() / 3);
    test::TreeHarness<KineticRangeTree> h(s, SchedulerKind::Robust, 1e-9);
    std::size_t changes = 0;
    for (const scenario::TimelineOp& op : s.timeline) {
      ASSERT_EQ(h.sim.advance_to(op.time, h), AdvanceOutcome::Reached);
      for (int q = 0; q < 2; ++q) {
        const Box box = random_box(h.motions, op.time, rng);
        EXPECT_EQ(h.tree->range(box, op.time), brute_force(h.motions, box, op.time));
      }
      h.apply(op);
      ++changes;
      ASSERT_TRUE(h.tree->validate()) << "after change " << changes << " at t=" << op.time;
      if (changes == removed) {
        EXPECT_LT(h.tree->longest_vacant_run(), KineticRangeTree::kMaxVacantRun);
      }
    }
    EXPECT_LT(h.tree->longest_vacant_run(), KineticRangeTree::kMaxVacantRun);
    EXPECT_GT(h.tree->counters().gap_spreads, 0u);
    EXPECT_EQ(h.tree->counters().local_changes + h.tree->counters().rebuilds, removed + 200);
  }
}

/// An x-swap changes the nodes below the two points' lowest common ancestor (each a vacate and a
/// place); a y-swap exchanges two entries in every block that holds both. Both kinds occur, and
/// the structure keeps its invariants after each event.
TEST(KineticRangeTree, PrimaryAndSecondarySwapsTouchWhatTheyShould) {
  const scenario::Scenario s = make("random-linear", 200, 2, 44, 1, false);
  RtHarness h(s, SchedulerKind::Robust, 1e-9);
  const std::size_t levels = static_cast<std::size_t>(std::bit_width(h.tree->slots())) - 1;
  EXPECT_EQ(h.tree->slots(), 512u);  // the gapped A_0 at density <= 1/2
  std::uint64_t events = 0;
  while (!h.sim.queue().empty() && events < 1500) {
    ASSERT_EQ(h.sim.process_next(h), AdvanceOutcome::Reached);
    ++events;
    ASSERT_TRUE(h.tree->validate()) << "after event " << events << " at t=" << h.sim.now();
  }
  const RangeTreeCounters& c = h.tree->counters();
  EXPECT_GT(c.swaps_by_axis[0], 100u);
  EXPECT_GT(c.swaps_by_axis[1], 100u);
  EXPECT_GT(c.replacements, 0u);
  // d = 2: every replacement is one vacate and one place, and nothing else changes a block.
  EXPECT_EQ(c.placements, c.replacements);
  EXPECT_EQ(c.vacated, c.replacements);
  // An x-swap swaps the pair in A_0 once; a y-swap swaps it in the blocks of the common primary
  // ancestors, at most one per depth with nodes of two slots or more (log2 512 = 9).
  EXPECT_LE(c.adjacent_swaps, c.swaps_by_axis[0] + c.swaps_by_axis[1] * levels);
  // An x-swap changes two paths of at most log2 U - 1 nodes below the root.
  EXPECT_LE(c.replacements, c.swaps_by_axis[0] * 2 * (levels - 1));
  EXPECT_EQ(c.rebuilds, 0u);
  EXPECT_EQ(h.tree->certificates(), 2 * 199u);
  EXPECT_EQ(h.tree->certificates_per_object_max(), 4u);
  // Space: n entries in A_0 and n at every depth of the primary tree with nodes of two slots.
  EXPECT_EQ(h.tree->stored_entries(), 200u * (1 + levels));
}

/// The worst case of an x-swap: the two points of ranks n/2 - 1 and n/2 (separated at the root)
/// cross, so every node on both paths below the root changes; the two points are at the opposite
/// ends of the y-order. The other points stand still on a grid.
TEST(KineticRangeTree, SwapSeparatedAtTheRoot) {
  for (const int d : {2, 3}) {
    SCOPED_TRACE("d " + std::to_string(d));
    scenario::Scenario s;
    s.dimension = d;
    s.start_time = 0.0;
    s.end_time = 3.0;  // the movers reach the grid points 30 and 33 only at t = 4
    const int n = 64;
    for (int i = 0; i < n; ++i) {
      scenario::Motion m;
      const bool mover = i == n / 2 - 1 || i == n / 2;
      const double x = mover ? (i == n / 2 - 1 ? 31.0 : 32.0) : static_cast<double>(i);
      m.coordinates.push_back({x, mover ? (i == n / 2 - 1 ? 0.5 : -0.5) : 0.0});
      // y: the two movers at the opposite ends of the y-order (shifts across everything).
      for (int a = 1; a < d; ++a) {
        const double y = i == n / 2 - 1 ? -1.0
                         : i == n / 2   ? 100.0
                                        : static_cast<double>((i * 37) % n);
        m.coordinates.push_back({y, 0.0});
      }
      s.objects.push_back({i, m});
    }
    for (const SchedulerKind kind :
         {SchedulerKind::Robust, SchedulerKind::Classic, SchedulerKind::Exact}) {
      RtHarness h(s, kind, 1e-9);
      std::uint64_t events = 0;
      std::mt19937_64 rng(5);
      while (h.sim.event_due_by(*s.end_time)) {
        ASSERT_EQ(h.sim.process_next(h), AdvanceOutcome::Reached);
        ++events;
        ASSERT_TRUE(h.tree->validate()) << "t=" << h.sim.now();
      }
      ASSERT_EQ(h.sim.advance_to(3.0, h), AdvanceOutcome::Reached);
      for (int q = 0; q < 20; ++q) {
        const Box box = random_box(h.motions, 3.0, rng);
        EXPECT_EQ(h.tree->range(box, 3.0), brute_force(h.motions, box, 3.0));
      }
      const RangeTreeCounters& c = h.tree->counters();
      EXPECT_EQ(events, 1u);
      EXPECT_EQ(c.swaps_by_axis[0], 1u);
      // Below the root: two paths of log2(128) - 1 = 6 nodes with blocks (sizes 64 .. 2).
      EXPECT_EQ(h.tree->slots(), 128u);
      EXPECT_EQ(c.replacements, 12u);
      if (d == 2) {
        // Each replacement is a vacate and a place (a binary search, then the nearest vacancy),
        // not a walk across the node's y-order.
        EXPECT_EQ(c.placements, 12u);
        EXPECT_EQ(c.vacated, 12u);
        EXPECT_LE(c.shifts, 12u * KineticRangeTree::kShiftReach);
      } else {
        // The points also leave and enter the z-blocks below each node's y-tree.
        EXPECT_GT(c.placements, 12u);
        EXPECT_EQ(c.placements, c.vacated);
      }
    }
  }
}

/// d = 4: the recursion one level deeper (static build, random motions, every event validated).
TEST(KineticRangeTree, FourDimensions) {
  const scenario::Scenario s = make("random-linear", 24, 4, 4, 1, false);
  check_run(s, SchedulerKind::Robust, 4, true);
}

/// The paper's GRIDS input (1-D: points on a grid, many simultaneous crossings) on both axes of
/// a 2-D scenario: object i takes its x motion from GRIDS point i and its y motion from point
/// n - 1 - i.
TEST(KineticRangeTree, GridsDataset) {
  scenario::GeneratorOptions o;
  o.n = 64;
  o.dimension = 1;
  o.seed = 3;
  o.queries = 0;
  const scenario::Scenario g = scenario::generate("grids", o);
  scenario::Scenario s = g;
  s.dimension = 2;
  const std::size_t n = g.objects.size();
  for (std::size_t i = 0; i < n; ++i) {
    s.objects[i].motion.coordinates.push_back(g.objects[n - 1 - i].motion.coordinates[0]);
    ASSERT_EQ(g.objects[n - 1 - i].motion.origin, g.objects[i].motion.origin);
  }
  for (const SchedulerKind kind :
       {SchedulerKind::Robust, SchedulerKind::Classic, SchedulerKind::Exact}) {
    check_run(s, kind, 3, true);
  }
}

/// A flight-plan update of point i at time t, of one of the kinds below: 0 a small velocity
/// change (same position), 1 a random new motion anywhere, 2 the trajectory of another point
/// (equal trajectories), 3 another point's motion on one random axis (equal coordinates on it),
/// 4 standing still beyond one end of every axis, 5 moving out fast on one axis, 6 the same
/// motion again (no rank changes).
std::vector<MotionPolynomial> new_motion(const MotionTable& motions, std::uint32_t i, Time t,
                                         int kind, std::mt19937_64& rng) {
  const int d = motions.dimension();
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto idx = motions.alive_indices();
  const std::uint32_t other = idx[rng() % idx.size()];
  std::vector<MotionPolynomial> out;
  const int axis_pick = static_cast<int>(rng() % static_cast<std::uint64_t>(d));
  const bool high = rng() % 2 == 0;
  for (int a = 0; a < d; ++a) {
    const MotionPolynomial& m = motions.motion(i, a);
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (const std::uint32_t j : idx) {
      const double x = motions.motion(j, a).evaluate(t);
      lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
    const double v = m.derivative(t);
    const std::vector<double> small{m.evaluate(t), v + 1e-3 * u(rng)};
    const std::vector<double> random{lo + (hi - lo) * 0.5 * (1.0 + u(rng)), u(rng)};
    const double gap = 1.0 + 0.5 * u(rng);  // no crossings exactly at the test's times
    const std::vector<double> beyond{high ? hi + gap : lo - gap, 0.0};
    switch (kind) {
      case 0:
        out.push_back(MotionPolynomial::from(small, t));
        break;
      case 1:
        out.push_back(MotionPolynomial::from(random, t));
        break;
      case 2:
        out.push_back(motions.motion(other, a));
        break;
      case 3:
        out.push_back(a == axis_pick ? motions.motion(other, a) : MotionPolynomial::from(small, t));
        break;
      case 4:
        out.push_back(MotionPolynomial::from(beyond, t));
        break;
      case 5: {
        const double speed = 50.0 + 10.0 * u(rng);
        const std::vector<double> fast{m.evaluate(t), high ? speed : -speed};
        out.push_back(a == axis_pick ? MotionPolynomial::from(fast, t) : m);
        break;
      }
      default:
        out.push_back(m);
        break;
    }
  }
  return out;
}

/// Flight-plan updates are local (the point vacated, the sorts changed, the moved keys and the
/// point placed again): d = 1..4, every scheduler, every kind of update above at random times
/// between events; validate() after every event and update, answers against brute force after
/// every update. The traditional classic orders an updated point by floating-point values at t,
/// and keeps orders its floating-point roots left wrong: its answers are checked only while
/// every axis is sorted at t (KineticSort::audit); both kinds of update must occur, most of them
/// checked.
TEST(KineticRangeTree, FlightPlanUpdatesAreLocal) {
  std::uint64_t traditional_unsorted = 0, traditional_checked = 0;
  for (int d = 1; d <= 4; ++d) {
    for (const test::SchedulerChoice kind : test::kEverySchedulerChoice) {
      for (const std::uint64_t round : {0u, 1u, 2u}) {
        const std::uint64_t seed = 300 + static_cast<std::uint64_t>(d * 10) + round;
        SCOPED_TRACE("seed " + std::to_string(seed) + ", " + to_string(kind) + ", d " +
                     std::to_string(d));
        scenario::Scenario s = make("random-linear", d == 4 ? 24 : 50, d, seed, 1, false);
        // Equal trajectories and integer coordinates shared on some axes.
        for (std::size_t k = 0; k + 1 < s.objects.size(); k += 9) {
          s.objects[k + 1].motion = s.objects[k].motion;
        }
        RtHarness h(s, kind, 1e-9);
        std::mt19937_64 rng(seed);
        const Time end = *s.end_time;
        std::uint64_t updates = 0;
        for (int step = 1; step <= 40; ++step) {
          const Time t = s.start_time + (end - s.start_time) * step / 40.0;
          while (h.sim.event_due_by(t)) {
            ASSERT_EQ(h.sim.process_next(h), AdvanceOutcome::Reached);
            ASSERT_TRUE(h.tree->validate()) << "after an event at t=" << h.sim.now();
          }
          ASSERT_EQ(h.sim.advance_to(t, h), AdvanceOutcome::Reached);
          for (int u = 0; u < 3; ++u) {
            const auto idx = h.motions.alive_indices();
            const std::uint32_t i = idx[rng() % idx.size()];
            const int what = static_cast<int>(rng() % 7);
            const std::vector<MotionPolynomial> m = new_motion(h.motions, i, t, what, rng);
            h.session().update(h.motions.id(i), m);  // at t: the table, then the tree
            ++updates;
            ASSERT_TRUE(h.tree->validate()) << "after an update of kind " << what << " at t=" << t;
            if (kind.traditional_classic()) {
              bool sorted = true;
              for (int a = 0; a < d; ++a) sorted = sorted && h.tree->sort(a).audit(t).ok;
              if (!sorted) {
                ++traditional_unsorted;
                continue;
              }
              ++traditional_checked;
            }
            for (int q = 0; q < 3; ++q) {
              const Box box = random_box(h.motions, t, rng);
              EXPECT_EQ(h.tree->range(box, t), brute_force(h.motions, box, t))
                  << "after an update of kind " << what << " at t=" << t;
            }
          }
        }
        EXPECT_TRUE(h.tree->validate());
        const RangeTreeCounters& c = h.tree->counters();
        // n does not change: A_0 is not laid out again, every update is local.
        EXPECT_EQ(c.local_changes, updates);
        EXPECT_EQ(c.rebuilds, 0u);
      }
    }
  }
  std::printf(
      "[ range tree ] traditional classic: %llu updates left an order unsorted at t, %llu checked "
      "against brute force\n",
      static_cast<unsigned long long>(traditional_unsorted),
      static_cast<unsigned long long>(traditional_checked));
  EXPECT_GT(traditional_unsorted, 0u);
  // Most of its answers are still checked (1,440 updates in all).
  EXPECT_GE(traditional_checked, 600u);
}

/// An update to the far end of both axes and back, and one that changes nothing: each vacates
/// the point's entries (one in A_0, one per depth below) and places them again, locally.
TEST(KineticRangeTree, FlightPlanUpdatesToTheEnds) {
  const scenario::Scenario s = make("random-linear", 64, 2, 9, 1, false);
  RtHarness h(s, SchedulerKind::Robust, 1e-9);
  const std::uint32_t i = h.motions.alive_indices()[0];
  const Time t0 = h.sim.now();
  const auto depths = static_cast<std::uint64_t>(std::bit_width(h.tree->slots())) - 1;
  std::uint64_t updates = 0;
  for (const double x : {1e6, -1e6, -1e6}) {
    const std::vector<MotionPolynomial> m{MotionPolynomial::from(std::vector<double>{x, 0.0}, t0),
                                          MotionPolynomial::from(std::vector<double>{x, 0.0}, t0)};
    const RangeTreeCounters before = h.tree->counters();
    h.session().update(h.motions.id(i), m);  // at t0: the table, then the tree
    ++updates;
    ASSERT_TRUE(h.tree->validate());
    const RangeTreeCounters& c = h.tree->counters();
    EXPECT_EQ(c.local_changes, updates);
    EXPECT_EQ(c.rebuilds, 0u);
    // Its entry in A_0 (written back from the sort) and one per depth with nodes of two slots
    // or more, vacated and placed; a key moved in A_0 is vacated and placed as often.
    EXPECT_EQ(c.vacated - before.vacated, c.placements - before.placements + 1);
    EXPECT_GE(c.placements - before.placements, depths);
    // First (x < every point) or last in both orders.
    const std::uint32_t first = h.tree->sort(0).order()[h.tree->sort(0).slot_at_or_after(0)];
    EXPECT_EQ(first == i, x < 0);
    for (int q = 0; q < 20; ++q) {
      std::mt19937_64 rng(static_cast<std::uint64_t>(q));
      const Box box = random_box(h.motions, t0, rng);
      EXPECT_EQ(h.tree->range(box, t0), brute_force(h.motions, box, t0));
    }
  }
}

using test::speed_bound;

/// Theorem 8: Q(t) is a Delta-approximation of S(t) ∩ R, Delta = n eps V_max, V_max the largest
/// speed over [t - eps, t]: every reported point lies in R widened by Delta, every point of R
/// shrunk by Delta is reported (L_inf).
::testing::AssertionResult delta_approximate(const RtHarness& h, const Box& box, Time t, double eps,
                                             const std::vector<std::uint32_t>& got, bool* exact) {
  const std::vector<std::uint32_t> want = brute_force(h.motions, box, t);
  *exact = got == want;
  if (*exact) return ::testing::AssertionSuccess();
  const int d = h.motions.dimension();
  double v_max = 0.0, magnitude = 0.0;
  for (const std::uint32_t i : h.motions.alive_indices()) {
    for (int a = 0; a < d; ++a) {
      v_max = std::max(v_max, speed_bound(h.motions.motion(i, a), t - eps, t));
      magnitude = std::max(magnitude, std::fabs(h.motions.motion(i, a).evaluate(t)));
    }
  }
  const double delta =
      static_cast<double>(h.motions.size()) * eps * v_max + 8.0 * magnitude * 0x1p-52;
  std::vector<std::uint32_t> sorted = got;
  if (!std::is_sorted(sorted.begin(), sorted.end())) {
    return ::testing::AssertionFailure() << "ids not ascending";
  }
  for (const std::uint32_t p : got) {
    for (int a = 0; a < d; ++a) {
      const double x = value_at(h.motions.motion(p, a), t);
      const auto& b = box[static_cast<std::size_t>(a)];
      if (x < b[0] - delta || x > b[1] + delta) {
        return ::testing::AssertionFailure()
               << "reported id " << h.motions.id(p) << " lies " << std::max(b[0] - x, x - b[1])
               << " outside the box, Delta " << delta << " t=" << t;
      }
    }
  }
  for (const std::uint32_t i : h.motions.alive_indices()) {
    if (std::binary_search(got.begin(), got.end(), i)) continue;
    bool deep = true;
    for (int a = 0; a < d && deep; ++a) {
      const double x = value_at(h.motions.motion(i, a), t);
      const auto& b = box[static_cast<std::size_t>(a)];
      deep = x >= b[0] + delta && x <= b[1] - delta;
    }
    if (deep) {
      return ::testing::AssertionFailure() << "id " << h.motions.id(i) << " deeper than Delta "
                                           << delta << " inside the box was missed at t=" << t;
    }
  }
  return ::testing::AssertionSuccess();
}

/// Robust runs with a coarse eps: right after events, just before the next event (its pair may
/// have crossed already) and at random times, every answer is a Delta-approximation; answers
/// at random times with a fine eps are exact.
TEST(KineticRangeTree, Theorem8RobustAnswersAreDeltaApproximate) {
  std::uint64_t inexact = 0, checked = 0;
  for (int d = 1; d <= 3; ++d) {
    for (const int degree : {1, 2}) {
      const double eps = degree == 1 ? 1e-3 : 1e-4;
      const std::uint64_t seed = 13 + static_cast<std::uint64_t>(d * 10 + degree);
      SCOPED_TRACE("seed " + std::to_string(seed) + ", d " + std::to_string(d) + ", degree " +
                   std::to_string(degree));
      const scenario::Scenario s = make(degree == 1 ? "random-linear" : "random-poly",
                                        d == 3 ? 50 : 90, d, seed, degree, false);
      RtHarness h(s, SchedulerKind::Robust, eps);
      std::mt19937_64 rng(seed);
      std::uint64_t events = 0;
      while (h.sim.event_due_by(*s.end_time) && events < 800) {
        ASSERT_EQ(h.sim.process_next(h), AdvanceOutcome::Reached);
        ++events;
        const Time next = h.sim.queue().empty() ? *s.end_time : h.sim.queue().top().time;
        for (int q = 0; q < 3; ++q) {
          const Time t = q == 0   ? h.sim.now()
                         : q == 1 ? h.sim.now() + (std::max(next, h.sim.now()) - h.sim.now()) * 0.5
                                  : std::max(h.sim.now(), std::nextafter(next, -HUGE_VAL));
          ASSERT_EQ(h.sim.advance_to(t, h), AdvanceOutcome::Reached);  // no event before next
          const Box box = random_box(h.motions, t, rng);
          bool exact = false;
          ASSERT_TRUE(delta_approximate(h, box, t, eps, h.tree->range(box, t), &exact));
          ++checked;
          if (!exact) ++inexact;
        }
      }
      EXPECT_TRUE(h.tree->validate());
    }
  }
  EXPECT_GT(checked, 2000u);
  std::printf("Theorem 8: answers checked %llu, inexact (within Delta) %llu\n",
              static_cast<unsigned long long>(checked), static_cast<unsigned long long>(inexact));
}

}  // namespace
}  // namespace kinetic
