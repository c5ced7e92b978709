// The kd-tree's trace snapshot (docs/trace-format.md): every order carries the slot of each key
// and the number of slots U of its gapped sort, exactly as the structure's sorts hold them, after
// the build, every event and every insert, remove and update (the orders laid out again on the
// way); and the tree rebuilt from the snapshot alone by the rule of docs/kdtree.md (what the
// viewer draws, docs/viewer.md) has the library's node count and depth.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <map>
#include <set>
#include <vector>

#include "kinetic/kdtree/kinetic_kdtree.hpp"
#include "run/registry.hpp"
#include "support/driver.hpp"

namespace kinetic {
namespace {

using Json = run::detail::Json;

/// T(P) from a snapshot's slots: an x_i-node at skeleton depth s (i = s mod d) halves the label
/// range of its x_i-parent ([0, U_i - 1] first), the side a point takes being bit floor(s / d)
/// of its label from the top; an active node where the points take both sides, a leaf where a
/// point is alone (right below its active parent), and on each edge into an active node one chain
/// node per (axis, side) of the degree-one nodes above it. Its node count (active nodes, leaves,
/// chain nodes: KineticKdTree::node_count()) and its depth (the deepest leaf's).
struct SlotTree {
  std::size_t nodes = 0;
  std::uint32_t depth = 0;
};

SlotTree tree_from_slots(const Json& orders) {
  const std::size_t d = orders.size();
  std::vector<std::uint32_t> log(d);
  std::map<long long, std::vector<std::uint64_t>> labels;  // id -> its slot on every axis
  for (std::size_t a = 0; a < d; ++a) {
    const auto u = orders[a]["slot_count"].get<std::uint64_t>();
    log[a] = static_cast<std::uint32_t>(std::bit_width(u) - 1);
    const Json& ids = orders[a]["ids"];
    for (std::size_t k = 0; k < ids.size(); ++k) {
      std::vector<std::uint64_t>& l = labels[ids[k].get<long long>()];
      l.resize(d);
      l[a] = orders[a]["slots"][k].get<std::uint64_t>();
    }
  }
  std::vector<std::vector<std::uint64_t>> points;
  for (auto& [id, l] : labels) points.push_back(std::move(l));
  const auto bit = [&](std::size_t p, std::uint32_t s) -> int {
    const std::size_t a = s % d;
    const std::uint32_t level = s / static_cast<std::uint32_t>(d);
    if (level >= log[a]) return 0;
    return static_cast<int>((points[p][a] >> (log[a] - 1 - level)) & 1U);
  };
  SlotTree out;
  if (points.size() == 1) out.nodes = 1;
  const auto build = [&](auto& self, std::vector<std::size_t> pts, std::uint32_t depth) -> void {
    std::uint32_t s = depth;
    for (;; ++s) {
      const bool split = std::any_of(pts.begin(), pts.end(),
                                     [&](std::size_t p) { return bit(p, s) != bit(pts[0], s); });
      if (split) break;
      ASSERT_LT(s, 64U * d) << "two points with the same labels";
    }
    std::set<std::pair<std::size_t, int>> chain;  // (axis, side) of the degree-one nodes above
    for (std::uint32_t u = depth; u < s; ++u) chain.insert({u % d, bit(pts[0], u)});
    out.nodes += 1 + chain.size();
    std::array<std::vector<std::size_t>, 2> sides;
    for (const std::size_t p : pts) sides[static_cast<std::size_t>(bit(p, s))].push_back(p);
    for (const std::vector<std::size_t>& side : sides) {
      if (side.size() == 1) {
        ++out.nodes;
        out.depth = std::max(out.depth, s + 1);
      } else {
        self(self, side, s + 1);
      }
    }
  };
  if (points.size() >= 2) {
    std::vector<std::size_t> all(points.size());
    for (std::size_t p = 0; p < all.size(); ++p) all[p] = p;
    build(build, all, 0);
  }
  return out;
}

/// The snapshot of `tree` now against its sorts and its tree.
void check_snapshot(KineticKdTree& tree, const MotionTable& motions, Time now) {
  const Json j =
      run::detail::slotted_orders_snapshot(tree, run::detail::AnswerContext{motions, now});
  ASSERT_EQ(j["orders"].size(), static_cast<std::size_t>(tree.dimension()));
  for (int a = 0; a < tree.dimension(); ++a) {
    SCOPED_TRACE(a);
    const Json& o = j["orders"][static_cast<std::size_t>(a)];
    const KineticSort& sort = tree.sort(a);
    EXPECT_EQ(o["axis"], a);
    const auto u = o["slot_count"].get<std::uint64_t>();
    EXPECT_EQ(u, sort.slots());
    EXPECT_TRUE(std::has_single_bit(u)) << "U = " << u << " is a power of two";
    const Json& ids = o["ids"];
    const Json& slots = o["slots"];
    ASSERT_EQ(ids.size(), motions.size());
    ASSERT_EQ(slots.size(), ids.size());
    EXPECT_GE(u, ids.size());
    for (std::size_t k = 0; k < slots.size(); ++k) {
      const auto slot = slots[k].get<std::uint64_t>();
      EXPECT_LT(slot, u);
      if (k > 0) {
        EXPECT_LT(slots[k - 1].get<std::uint64_t>(), slot) << "slots increase";
      }
      // The key at that slot is that object, whose rank in the sort is that slot.
      const std::uint32_t index = sort.order()[slot];
      ASSERT_NE(index, kNoIndex);
      EXPECT_EQ(ids[k].get<ObjectId>(), motions.id(index));
      EXPECT_EQ(sort.rank(index), slot);
    }
  }
  const SlotTree rebuilt = tree_from_slots(j["orders"]);
  EXPECT_EQ(rebuilt.nodes, tree.node_count()) << "at t = " << now;
  EXPECT_EQ(rebuilt.depth, static_cast<std::uint32_t>(tree.depth())) << "at t = " << now;
}

/// Plays the scenario with the snapshot checked at the start, after every event and at every
/// timeline entry's time (before it; after it at the next event or probe). Returns the values
/// of U_0 seen.
std::set<std::uint64_t> check_run(const scenario::Scenario& s) {
  test::TreeHarness<KineticKdTree> h(s, SchedulerKind::Robust, 1e-9);
  std::set<std::uint64_t> slot_counts;
  const auto check = [&](Time t) {
    check_snapshot(*h.tree, h.motions, t);
    slot_counts.insert(h.tree->sort(0).slots());
  };
  check(h.sim.now());
  const std::vector<Time> probes{s.end_time.value_or(1.0)};
  const std::uint64_t events = h.check(probes, false, check, [&] { check(h.sim.now()); });
  EXPECT_GT(events, 20U);
  return slot_counts;
}

TEST(TraceSnapshot, KdTreeOrdersCarryTheSortsSlotsAndRebuildTheTreeInDimensions1To3) {
  for (int d = 1; d <= 3; ++d) {
    SCOPED_TRACE(d);
    check_run(test::generated("random-linear", 50, d, 40 + static_cast<std::uint64_t>(d), 1, true));
  }
}

TEST(TraceSnapshot, KdTreeSlotsFollowInsertsRemovesAndNewLayouts) {
  // 30 points, 90 inserts, 25 removes and 10 updates: the orders are laid out again on the way
  // (U changes).
  const std::set<std::uint64_t> slot_counts =
      check_run(test::long_mixed("random-linear", 30, 2, 5, 90, 25, 10));
  EXPECT_GE(slot_counts.size(), 2U) << "U never changed";
}

}  // namespace
}  // namespace kinetic
