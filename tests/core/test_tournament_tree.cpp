// The kinetic tournament written once (core/tournament_tree.hpp), on its own: lines f_i(t) = a_i +
// b_i t compared just after now (the maximum wins; equal lines: the smaller entry), against a
// brute-force maximum, over the implicit heap and over a hand-made topology. The structures built
// on it (tournament and extent, BVH, closest pair) have their own oracle tests.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <random>
#include <vector>

#include "kinetic/core/simulator.hpp"
#include "kinetic/core/tournament_tree.hpp"

namespace kinetic {
namespace {

struct Lines {
  std::vector<double> a, b;
  const Simulator* sim = nullptr;
  int decisions = 0;

  [[nodiscard]] double at(std::uint32_t i, double t) const { return a[i] + b[i] * t; }
  /// i ahead of j just after now.
  [[nodiscard]] bool ahead(std::uint32_t i, std::uint32_t j) const {
    const double t = sim->now();
    if (at(i, t) != at(j, t)) return at(i, t) > at(j, t);
    if (b[i] != b[j]) return b[i] > b[j];
    return i < j;
  }
  [[nodiscard]] Time failure(std::size_t, std::uint32_t w, std::uint32_t l) const {
    if (b[l] <= b[w]) return kTimeInfinity;  // l never overtakes w
    const double t = (a[w] - a[l]) / (b[l] - b[w]);
    return t > sim->now() ? t : kTimeInfinity;
  }
  Scheduler::MaxDecision decide(std::size_t node, std::uint32_t x, std::uint32_t y) {
    ++decisions;
    const bool first = ahead(x, y);
    return {first, failure(node, first ? x : y, first ? y : x), std::nullopt};
  }
};

/// The entry a brute force finds ahead among `entries` just after now.
std::uint32_t best_of(const Lines& keys, const std::vector<std::uint32_t>& entries) {
  std::uint32_t best = entries.front();
  for (const std::uint32_t e : entries)
    if (keys.ahead(e, best)) best = e;
  return best;
}

TEST(TournamentTree, HeapTopologyIsTheImplicitCompleteTree) {
  const HeapTopology h{8};
  EXPECT_EQ(h.nodes(), 16u);
  EXPECT_EQ(h.parent(1), kNoNode);
  EXPECT_EQ(h.parent(9), 4u);
  EXPECT_EQ(h.children(3), (std::array<std::size_t, 2>{6, 7}));
  EXPECT_TRUE(h.is_leaf(8));
  EXPECT_FALSE(h.is_leaf(7));
  EXPECT_FALSE(h.internal(0));
  EXPECT_TRUE(h.internal(7));
  EXPECT_EQ(h.leaf(3), 11u);
  const HeapTopology one{1};  // the root is the only leaf
  EXPECT_TRUE(one.is_leaf(1));
  EXPECT_EQ(one.leaf(0), 1u);
}

TEST(TournamentTree, KeepsTheMaximumAgainstABruteForceThroughLeafChanges) {
  for (const unsigned seed : {1u, 2u, 3u}) {
    SCOPED_TRACE(::testing::Message() << "seed " << seed);
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> small(0, 3);  // many equal values: ties are the rule
    Simulator sim(0.0);
    const std::uint32_t owner = sim.reserve_owners(1).first;
    Lines lines;
    lines.sim = &sim;
    for (int i = 0; i < 13; ++i) {
      lines.a.push_back(small(rng));
      lines.b.push_back(small(rng) - 1.5);
    }
    TournamentTree<Lines> tree(sim, owner, lines, HeapTopology{16});
    tree.assign(32);
    std::vector<std::uint32_t> in;
    for (std::uint32_t i = 0; i < 13; ++i) {
      tree.set_leaf(tree.topology().leaf(i), i);
      in.push_back(i);
    }
    for (std::size_t v = 16; v-- > 1;) tree.decide(v);
    ASSERT_TRUE(tree.validate());
    EXPECT_EQ(tree.certificates(), 12u);
    EXPECT_EQ(tree.winner(1), best_of(tree.keys(), in));
    // Every certificate is the event of its node, at the failure of [loser behind winner].
    tree.for_each_certificate([&](std::size_t v, std::uint32_t w, std::uint32_t l) {
      const EventHandle h = tree.certificate(v);
      const Time f = tree.keys().failure(v, w, l);
      ASSERT_EQ(h.is_null(), f == kTimeInfinity) << "node " << v;
      if (!h.is_null()) {
        EXPECT_EQ(sim.queue().get(h).time, f);
        EXPECT_EQ(sim.queue().get(h).owner, owner);
        EXPECT_EQ(sim.queue().get(h).payload, v);
      }
    });
    // Leaves emptied and refilled with other lines: each change decided up to the root.
    for (int step = 0; step < 40; ++step) {
      const auto leaf = static_cast<std::uint32_t>(rng() % 16);
      const std::size_t node = tree.topology().leaf(leaf);
      if (tree.winner(node) == kNoIndex && leaf < 13) {
        tree.set_leaf(node, leaf);
        in.push_back(leaf);
      } else if (tree.winner(node) != kNoIndex && in.size() > 1) {
        in.erase(std::find(in.begin(), in.end(), tree.winner(node)));
        tree.set_leaf(node, kNoIndex);
      }
      tree.decide_to_root(tree.topology().parent(node));
      ASSERT_TRUE(tree.validate()) << "step " << step;
      EXPECT_EQ(tree.certificates(), in.size() - 1);
      EXPECT_EQ(tree.winner(1), best_of(tree.keys(), in)) << "step " << step;
    }
    // The ties of the root: every entry whose line is the winner's (and only those).
    std::vector<std::uint32_t> tied;
    const std::uint32_t top = tree.winner(1);
    const auto same = [&](std::uint32_t x) {
      return lines.a[x] == lines.a[top] && lines.b[x] == lines.b[top];
    };
    tree.for_each_tie(1, same, [&](std::uint32_t x) { tied.push_back(x); });
    std::vector<std::uint32_t> want;
    for (const std::uint32_t e : in)
      if (same(e)) want.push_back(e);
    std::sort(tied.begin(), tied.end());
    std::sort(want.begin(), want.end());
    EXPECT_EQ(tied, want);
  }
}

TEST(TournamentTree, ValidateCatchesALeafChangedWithoutItsPath) {
  Simulator sim(0.0);
  Lines lines{{3, 1, 2, 0}, {0, 0, 0, 0}, &sim, 0};
  TournamentTree<Lines> tree(sim, sim.reserve_owners(1).first, lines, HeapTopology{4});
  tree.assign(8);
  for (std::uint32_t i = 0; i < 4; ++i) tree.set_leaf(4 + i, i);
  for (std::size_t v = 4; v-- > 1;) tree.decide(v);
  ASSERT_TRUE(tree.validate());
  ASSERT_EQ(tree.winner(1), 0u);
  tree.set_leaf(4, kNoIndex);  // entry 0 leaves, its path not decided again
  EXPECT_FALSE(tree.validate());
  tree.decide_to_root(2);
  EXPECT_TRUE(tree.validate());
  EXPECT_EQ(tree.winner(1), 2u);
}

TEST(TournamentTree, AnEventClimbsUntilAWinnerStaysAndTheClassicPolicyTrustsIt) {
  // Entry 0 falls (1 - t) below entry 1 (0) at t = 1; entries 2 and 3 stay at -5.
  for (const bool classic : {false, true}) {
    SCOPED_TRACE(classic ? "classic" : "robust");
    Simulator sim(0.0);
    Lines lines{{1, 0, -5, -5}, {-1, 0, 0, 0}, &sim, 0};
    TournamentTree<Lines> tree(sim, sim.reserve_owners(1).first, lines, HeapTopology{4});
    tree.assign(8);
    for (std::uint32_t i = 0; i < 4; ++i) tree.set_leaf(4 + i, i);
    for (std::size_t v = 4; v-- > 1;) tree.decide(v);
    ASSERT_EQ(tree.winner(1), 0u);
    ASSERT_FALSE(tree.certificate(2).is_null());
    EXPECT_EQ(sim.queue().get(tree.certificate(2)).time, 1.0);
    // The simulator pops the event at t = 1 and hands it to the policy.
    struct Policy {
      TournamentTree<Lines>* tree;
      bool classic;
      std::vector<std::size_t> changed;
      EventKind process(const Event& event) {
        const std::size_t v = tree->take_event(event);
        EXPECT_EQ(v, 2u);
        if (classic) {
          const std::uint32_t old = tree->trust_failure(v);
          EXPECT_EQ(old, 0u);
          tree->propagate_traditionally(v, old);
        } else {
          EXPECT_TRUE(tree->decide(v));
          tree->climb(v, [&](std::size_t u) { changed.push_back(u); });
        }
        return EventKind::Internal;
      }
    } policy{&tree, classic, {}};
    ASSERT_EQ(sim.advance_to(2.0, policy), AdvanceOutcome::Reached);
    EXPECT_EQ(sim.counters().events(), 1u);
    const std::vector<std::size_t>& changed = policy.changed;
    EXPECT_EQ(tree.winner(2), 1u);
    EXPECT_EQ(tree.winner(1), 1u);
    if (!classic) {
      EXPECT_EQ(changed, (std::vector<std::size_t>{2, 1}));
    }
    EXPECT_TRUE(tree.validate());
  }
}

/// A hand-made tree: node 0 the root over 1 and 2, node 2 over leaves 3 and 4, node 1 a leaf.
struct SmallTopology {
  [[nodiscard]] bool is_leaf(std::size_t v) const { return v == 1 || v >= 3; }
  [[nodiscard]] bool internal(std::size_t v) const { return v == 0 || v == 2; }
  [[nodiscard]] std::array<std::size_t, 2> children(std::size_t v) const {
    return v == 0 ? std::array<std::size_t, 2>{1, 2} : std::array<std::size_t, 2>{3, 4};
  }
  [[nodiscard]] std::size_t parent(std::size_t v) const {
    return v == 0 ? kNoNode : v <= 2 ? 0 : 2;
  }
};

TEST(TournamentTree, RunsOverAnotherTopology) {
  Simulator sim(0.0);
  Lines lines{{0, 1, 2}, {0, 0, 0}, &sim, 0};
  TournamentTree<Lines, SmallTopology> tree(sim, sim.reserve_owners(1).first, lines);
  tree.assign(5);
  tree.set_leaf(1, 0);
  tree.set_leaf(3, 1);
  tree.set_leaf(4, 2);
  tree.decide(2);
  tree.decide(0);
  EXPECT_EQ(tree.winner(0), 2u);
  EXPECT_EQ(tree.certificates(), 2u);
  EXPECT_TRUE(tree.validate());
  tree.keys().a[0] = 7;  // entry 0's line moved up: its leaf's path decided again
  std::vector<std::size_t> seen;
  tree.climb(1, [&](std::size_t v) { seen.push_back(v); });
  EXPECT_EQ(seen, (std::vector<std::size_t>{1, 0}));
  EXPECT_EQ(tree.winner(0), 0u);
  tree.release(2);
  tree.release(3);
  tree.release(4);
  EXPECT_EQ(tree.certificates(), 1u);  // node 0's, until it is decided again
  tree.decide(0);
  EXPECT_EQ(tree.certificates(), 0u);
  EXPECT_EQ(tree.winner(0), 0u);
}

}  // namespace
}  // namespace kinetic
