// The gapped layout of the kinetic sort (SortLayout::Gapped, a packed-memory array) against the
// dense layout in the same simulator: long mixed sequences of inserts, removes and flight-plan
// updates between events, growing from nothing to thousands of keys and back, with equal and
// crossing motions. After every change both sorts hold the same keys in the same order, the gapped
// one validates (segments packed, within their density bounds, events on adjacent keys) and
// relabeled() names every key whose slot changed and touched_slots() every slot whose key did.
// Under the exact scheduler both layouts hold the same order after every change and every advance
// (the order just after now, ties by id); under the robust one the order may be briefly wrong near
// a crossing, so an insert's binary search may end at another place in each, and the gapped order
// is checked against the true one (every inverted adjacent pair crosses within 1e-6 of now). Fixed
// seeds, printed on failure.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "kinetic/core/boxes.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/structure_group.hpp"
#include "kinetic/sort/kinetic_sort.hpp"
#include "support/crossing.hpp"

namespace kinetic {
namespace {

template <class Sort>
std::vector<std::uint32_t> keys_in_order(const Sort& s) {
  std::vector<std::uint32_t> out;
  for (const std::uint32_t x : s.order()) {
    if (x != kNoIndex) out.push_back(x);
  }
  return out;
}

/// The two layouts of one sort in one simulator: points (one key each) or the sides of 1-D boxes
/// (two keys each, a center and a constant half extent: sweep-and-prune's endpoint lists).
template <class Sort>
struct PairOf {
  static constexpr bool kBoxes = Sort::kKeysPerObject == 2;
  MotionTable motions{kBoxes ? 2 : 1};
  Simulator sim;
  Scheduler scheduler;
  StructureGroup<Sort> group;
  Sort* dense = nullptr;
  Sort* gapped = nullptr;
  PairOf(SchedulerKind kind, Time horizon) : sim(0.0), scheduler(kind, 1e-9, horizon) {
    dense = &group.add(std::make_unique<Sort>(motions, sim, scheduler, 0));
    gapped = &group.add(std::make_unique<Sort>(motions, sim, scheduler, 0, SortLayout::Gapped));
  }
};
using Pair = PairOf<KineticSort>;

/// Key k of an object's keys in the sort (the object's index for points; its low and high side
/// for boxes).
template <class Sort>
std::uint32_t key_of(std::uint32_t object, std::uint32_t k) {
  return object * Sort::kKeysPerObject + k;
}

/// The slots of every key before a change, to check relabeled() after it.
template <class Sort>
std::vector<std::uint32_t> slots_of(const Sort& s, const MotionTable& m) {
  constexpr std::uint32_t K = Sort::kKeysPerObject;
  std::vector<std::uint32_t> out(K * m.capacity(), kNoIndex);
  for (const std::uint32_t i : m.alive_indices()) {
    for (std::uint32_t k = 0; k < K; ++k) out[key_of<Sort>(i, k)] = s.rank(key_of<Sort>(i, k));
  }
  return out;
}

/// `own`: the object changed (its keys are not told).
template <class Sort>
::testing::AssertionResult relabeled_exactly(const Sort& s, const MotionTable& m,
                                             const std::vector<std::uint32_t>& before,
                                             std::uint64_t generation_before, std::uint32_t own) {
  if (s.layout_generation() != generation_before) return ::testing::AssertionSuccess();
  constexpr std::uint32_t K = Sort::kKeysPerObject;
  std::vector<std::uint32_t> moved;
  for (const std::uint32_t object : m.alive_indices()) {
    for (std::uint32_t k = 0; k < K; ++k) {
      const std::uint32_t i = key_of<Sort>(object, k);
      if (object != own && i < before.size() && before[i] != kNoIndex && before[i] != s.rank(i))
        moved.push_back(i);
    }
  }
  // relabeled_from(): the slot each told key held before the change; no key told twice.
  if (s.relabeled_from().size() != s.relabeled().size())
    return ::testing::AssertionFailure() << "relabeled_from() and relabeled() differ in size";
  for (std::size_t k = 0; k < s.relabeled().size(); ++k) {
    const std::uint32_t i = s.relabeled()[k];
    if (i / K == own)
      return ::testing::AssertionFailure() << "the object's own key " << i << " told";
    if (i >= before.size() || before[i] == kNoIndex)
      return ::testing::AssertionFailure() << "key " << i << " told, but it had no slot";
    if (s.relabeled_from()[k] != before[i])
      return ::testing::AssertionFailure() << "key " << i << " told it left slot "
                                           << s.relabeled_from()[k] << ", it held " << before[i];
  }
  std::vector<std::uint32_t> told(s.relabeled().begin(), s.relabeled().end());
  std::sort(told.begin(), told.end());
  if (std::adjacent_find(told.begin(), told.end()) != told.end())
    return ::testing::AssertionFailure()
           << "key " << *std::adjacent_find(told.begin(), told.end()) << " told twice";
  // A key may be told although it came back to its slot (moved twice); every key that moved
  // must be told.
  for (const std::uint32_t i : moved) {
    if (!std::binary_search(told.begin(), told.end(), i))
      return ::testing::AssertionFailure() << "key " << i << " moved and was not told";
  }
  return ::testing::AssertionSuccess();
}

/// A key's motion (a box's side: rounded, for crossing windows only).
template <class Sort>
MotionPolynomial key_motion(const MotionTable& m, std::uint32_t key) {
  if constexpr (Sort::kKeysPerObject == 1) {
    return m.motion(key, 0);
  } else {
    MotionPolynomial p = center(m, BoxEndpointKeys::box_of(key), 0);
    p.c[0] += (BoxEndpointKeys::side_of(key) == BoxSide::High ? 1.0 : -1.0) *
              half_extent(m, BoxEndpointKeys::box_of(key), 0).c[0];
    return p;
  }
}

/// Every adjacent pair out of order at t crosses within [t - delta, t + delta].
template <class Sort>
::testing::AssertionResult sorted_but_near_crossings(const Sort& s, const MotionTable& m, Time t,
                                                     double delta) {
  const std::vector<std::uint32_t> order = keys_in_order(s);
  for (std::size_t j = 0; j + 1 < order.size(); ++j) {
    const MotionPolynomial a = key_motion<Sort>(m, order[j]);
    const MotionPolynomial b = key_motion<Sort>(m, order[j + 1]);
    if (s.keys().compare_at(order[j], order[j + 1], t) <= 0) continue;
    if (!test::cross_within(a, b, t - delta, t + delta))
      return ::testing::AssertionFailure()
             << "keys " << order[j] << ", " << order[j + 1] << " at t=" << t;
  }
  return ::testing::AssertionSuccess();
}

/// Grows to `peak` keys by inserts (with removes and updates mixed in), then shrinks to a few,
/// advancing time between changes; checks both layouts agree after every change.
template <class Sort = KineticSort>
void mixed_run(std::uint64_t seed, std::size_t peak, SchedulerKind kind) {
  SCOPED_TRACE("seed " + std::to_string(seed) + ", peak " + std::to_string(peak) + ", " +
               to_string(kind));
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Time horizon = 1e9;
  PairOf<Sort> p(kind, horizon);
  p.group.initialize();
  std::vector<ObjectHandle> live;
  ObjectId next_id = 0;
  Time t = 0.0;
  std::uint64_t relayouts = 0, spreads_seen = 0;
  const auto random_motion = [&](Time at) {
    // Lines through a small range (many crossings), a fifth of them copies of a live motion
    // (identical trajectories), some constant (many ties at one value), parabolas.
    if (!live.empty() && rng() % 5 == 0)
      return p.motions.motion(live[rng() % live.size()].index, 0);
    if (rng() % 4 == 0) {
      // Small integers: a parabola c (t - t0)^2 + l(t) touching the line l at t0 (a tangency,
      // no crossing), and lines and constants equal to many others.
      const auto ri = [&](int lo, int hi) {
        return static_cast<double>(lo +
                                   static_cast<int>(rng() % static_cast<unsigned>(hi - lo + 1)));
      };
      const double t0 = ri(1, 8) + 0.5 * ri(0, 1), c = ri(0, 2), a = ri(-3, 3), b = ri(-1, 1);
      return MotionPolynomial::from(std::vector<double>{a + c * t0 * t0, b - 2 * c * t0, c}, 0.0);
    }
    const double slope = rng() % 7 == 0 ? 0.0 : u(rng);
    return MotionPolynomial::from(std::vector<double>{rng() % 9 == 0 ? 0.5 : 100.0 * u(rng), slope},
                                  at);
  };
  // A row of the table: the motion, or a box's center and its constant half extent (zero,
  // one value shared by many, or random: touching and identical sides).
  const auto random_row = [&](Time at) {
    std::vector<MotionPolynomial> row{random_motion(at)};
    if constexpr (PairOf<Sort>::kBoxes) {
      const unsigned pick = static_cast<unsigned>(rng() % 4);
      const double h = pick == 0 ? 0.0 : pick == 1 ? 0.5 : 5.0 * (0.5 + 0.5 * u(rng));
      row.push_back(MotionPolynomial::constant(h));
    }
    return row;
  };
  const std::size_t steps = 3 * peak;
  for (std::size_t step = 0; step < steps; ++step) {
    const bool growing = step < 2 * peak;
    const int kind_of_change = static_cast<int>(rng() % 10);
    const std::uint64_t generation = p.gapped->layout_generation();
    const std::vector<std::uint32_t> before = slots_of(*p.gapped, p.motions);
    const std::vector<std::uint32_t> slots_before(p.gapped->order().begin(),
                                                  p.gapped->order().end());
    std::uint32_t own = kNoIndex;
    if (live.empty() || (growing ? kind_of_change < 6 : kind_of_change < 2)) {
      const std::vector<MotionPolynomial> m = random_row(t);
      const ObjectHandle h = p.motions.insert(next_id++, m, t);
      live.push_back(h);
      own = h.index;
      p.group.insert(h.index);
    } else if (kind_of_change < 9 || !growing) {
      const std::size_t k = rng() % live.size();
      own = live[k].index;
      p.motions.remove(live[k]);
      live.erase(live.begin() + static_cast<std::ptrdiff_t>(k));
      p.group.remove(own);
    } else {
      const ObjectHandle h = live[rng() % live.size()];
      const std::vector<MotionPolynomial> m = random_row(t);
      p.motions.update(h, m, t);
      own = h.index;
      p.group.motion_changed(h.index);
    }
    p.sim.note_external_change();
    ASSERT_TRUE(p.gapped->validate()) << "step " << step;
    ASSERT_TRUE(p.dense->validate()) << "step " << step;
    if (kind == SchedulerKind::Exact) {
      ASSERT_EQ(keys_in_order(*p.gapped), keys_in_order(*p.dense)) << "step " << step << " t=" << t;
    }
    ASSERT_TRUE(relabeled_exactly(*p.gapped, p.motions, before, generation, own))
        << "step " << step;
    if (p.gapped->layout_generation() == generation) {
      // touched_slots() covers every slot whose key changed, and no more than the segments the
      // keys moved in (a structure above reads them again).
      std::vector<bool> touched(slots_before.size(), false);
      std::size_t length = 0;
      for (const auto& [lo, hi] : p.gapped->touched_slots()) {
        length += hi + 1 - lo;
        for (std::size_t j = lo; j <= hi && j < touched.size(); ++j) touched[j] = true;
      }
      for (std::size_t j = 0; j < slots_before.size(); ++j) {
        if (!touched[j]) {
          ASSERT_EQ(p.gapped->order()[j], slots_before[j]) << "slot " << j << " step " << step;
        }
      }
      ASSERT_LE(length, 8 * Sort::kGapSegment * (2 + p.gapped->relabeled().size()))
          << "step " << step;
    }
    if (p.gapped->layout_generation() != generation) {
      ++relayouts;
    } else {
      // A spread: the keys of more than one segment moved.
      std::size_t length = 0;
      for (const auto& [lo, hi] : p.gapped->touched_slots()) length += hi + 1 - lo;
      if (length > Sort::kGapSegment) ++spreads_seen;
    }
    if (step % 7 == 0) {
      t += 0.05 * static_cast<double>(rng() % 5);
      ASSERT_EQ(p.sim.advance_to(t, p.group), AdvanceOutcome::Reached);
      ASSERT_TRUE(p.gapped->validate()) << "step " << step;
      if (kind == SchedulerKind::Exact) {
        ASSERT_EQ(keys_in_order(*p.gapped), keys_in_order(*p.dense)) << "step " << step;
        ASSERT_TRUE(p.gapped->audit(t).ok) << "step " << step;
      } else if (kind == SchedulerKind::Robust) {
        ASSERT_TRUE(sorted_but_near_crossings(*p.dense, p.motions, t, 1e-6))
            << "dense step " << step;
        ASSERT_TRUE(sorted_but_near_crossings(*p.gapped, p.motions, t, 1e-6)) << "step " << step;
      }
    }
  }
  // The run grew past one segment and shrank back: the array was laid out again both ways, and
  // shifts inside segments moved keys.
  EXPECT_GE(relayouts, 4u);
  EXPECT_GT(spreads_seen, 5u) << "spreads";
  if (kind == SchedulerKind::Exact) {
    EXPECT_EQ(p.gapped->counters().swaps, p.dense->counters().swaps);
  }
  EXPECT_GT(p.gapped->counters().swaps, 100u);
}

TEST(GappedSort, LongMixedSequencesAgreeWithTheDenseLayout) {
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    mixed_run(seed, seed % 2 == 0 ? 1500 : 300, SchedulerKind::Exact);
    if (HasFatalFailure()) return;
  }
}

TEST(GappedSort, LongMixedSequencesRobustAndClassic) {
  for (std::uint64_t seed = 21; seed <= 24; ++seed) {
    mixed_run(seed, 800, seed % 2 == 0 ? SchedulerKind::Robust : SchedulerKind::Classic);
    if (HasFatalFailure()) return;
  }
}

/// Sweep-and-prune's endpoint lists (two keys per box: its low and high side) in the gapped
/// layout: an object's keys placed, taken out and moved together, the certificates between its
/// own keys never scheduled on a key that is leaving.
TEST(GappedSort, BoxSidesAgreeWithTheDenseLayout) {
  for (std::uint64_t seed = 31; seed <= 32; ++seed) {
    mixed_run<KineticEndpointSort>(seed, seed % 2 == 0 ? 1000 : 250, SchedulerKind::Exact);
    if (HasFatalFailure()) return;
  }
  for (std::uint64_t seed = 41; seed <= 42; ++seed) {
    mixed_run<KineticEndpointSort>(seed, 300,
                                   seed % 2 == 0 ? SchedulerKind::Robust : SchedulerKind::Classic);
    if (HasFatalFailure()) return;
  }
}

/// Inserting always at the same place (keys arriving in increasing order, all at the end, or
/// all between the same two keys) overflows one segment after another: windows spread and the
/// array doubles; the slots stay within U and every segment within its bounds.
TEST(GappedSort, AdversarialInsertOrders) {
  for (int pattern = 0; pattern < 3; ++pattern) {
    SCOPED_TRACE("pattern " + std::to_string(pattern));
    Pair p(SchedulerKind::Robust, 1e9);
    p.group.initialize();
    for (int i = 0; i < 3000; ++i) {
      double x = pattern == 0 ? i : pattern == 1 ? -i : 0.5 + 0x1p-30 * (i % 2 == 0 ? i : -i);
      const std::array<MotionPolynomial, 1> m{MotionPolynomial::constant(x)};
      const ObjectHandle h = p.motions.insert(i, m, 0.0);
      p.group.insert(h.index);
      if (i % 97 == 0 || i < 70) {
        ASSERT_TRUE(p.gapped->validate()) << "insert " << i;
      }
    }
    ASSERT_TRUE(p.gapped->validate());
    ASSERT_EQ(keys_in_order(*p.gapped), keys_in_order(*p.dense));
    // density <= 3/4 after every insert (else the array doubles)
    EXPECT_LE(4 * p.gapped->size(), 3 * p.gapped->slots());
    // Removing in order from the front empties segments one after another.
    for (std::uint32_t i = 0; i < 2990; ++i) {
      const std::uint32_t index = keys_in_order(*p.dense).front();
      p.motions.remove(p.motions.handle(index));
      p.group.remove(index);
      if (i % 97 == 0 || i > 2950) {
        ASSERT_TRUE(p.gapped->validate()) << "remove " << i;
      }
    }
    EXPECT_EQ(p.gapped->size(), 10u);
    EXPECT_LE(p.gapped->slots(), 64u);  // halved back to what 10 keys need
    ASSERT_EQ(keys_in_order(*p.gapped), keys_in_order(*p.dense));
  }
}

}  // namespace
}  // namespace kinetic
