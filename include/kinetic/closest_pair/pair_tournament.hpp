#pragma once
// A kinetic tournament (a minimum) over pairs of moving points in the plane, keyed by their
// squared distances: the kinetic priority queue of Basch, Guibas and Hershberger, "Data
// structures for mobile data", with pairs as its elements. The closest-pair structures put their
// candidate pairs in its leaves (closest_pair/): the cones' candidates of
// KineticConeClosestPair.
//
// The tree is core/tournament_tree.hpp's over leaves numbered 0 .. leaves() - 1; its entries are
// leaf numbers, and each leaf holds a pair of table indices or nothing. A
// caller sets and clears leaves in a batch, then calls update(): the nodes above the changed
// leaves are decided again, level by level, each once, up to where neither the winner nor the
// pair it holds changed. A node with two non-empty children has one certificate, [|winner|^2 <=
// |loser|^2], a LengthComparison of the two pairs' four points (degree 2k for motions of degree
// k) decided by the scheduler of the run: robust (one CROP of its four products), classic, or
// exact. When it fails the node and those above it are decided again. Pairs of equal length for
// ever are ordered by their ids (smaller pair first).
//
// Bounds: O(leaves) certificates; a leaf change costs O(log leaves) decisions; a query reads the
// root, and the subtrees whose winner ties it now.

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "kinetic/core/incircle.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/tournament_tree.hpp"

namespace kinetic {

struct PairTournamentCounters {
  std::uint64_t events = 0;           ///< length certificates that failed
  std::uint64_t nodes_redecided = 0;  ///< length comparisons decided by the scheduler
  std::uint64_t tie_visits = 0;       ///< nodes visited by ties()
};

class PairTournament {
 public:
  using Pair = std::array<std::uint32_t, 2>;
  /// Reserves one owner tag from the simulator for the certificates' events.
  PairTournament(const MotionTable& points, Simulator& simulator, const Scheduler& scheduler);

  /// Leaves: at least `count`, every one empty, no certificate.
  void reset(std::size_t count);
  /// Room for at least `count` leaves, the pairs kept (the tree is laid out again and every node
  /// decided when it grows).
  void reserve(std::size_t count);
  [[nodiscard]] std::size_t leaves() const { return capacity(); }
  /// Leaf `leaf` holds the pair {a, b} (table indices, a != b) / nothing, from the next update().
  void set(std::uint32_t leaf, std::uint32_t a, std::uint32_t b);
  void clear(std::uint32_t leaf);
  [[nodiscard]] std::optional<Pair> pair(std::uint32_t leaf) const {
    const Pair& p = tree_.keys().pair[leaf];
    if (p[0] == kNoIndex) return std::nullopt;
    return p;
  }
  /// Decides the nodes above the leaves changed since the last update().
  void update();
  /// Decides every node again (after the pairs' motions changed).
  void decide_all();

  [[nodiscard]] std::uint32_t owner() const { return tree_.owner(); }
  /// A certificate of this tournament failed: its node and those above are decided again.
  void process(const Event& event);

  /// The leaf of the shortest pair (just after now; robust: as the certificates tell), or
  /// kNoIndex when every leaf is empty.
  [[nodiscard]] std::uint32_t winner() const { return capacity() > 0 ? tree_.winner(1) : kNoIndex; }
  /// The winner, and every pair in a leaf as short as the winner at now (exact comparisons at
  /// now): the subtrees whose winner is longer at now are skipped. Appended to `out`.
  void ties(std::vector<Pair>& out);

  /// Nodes with two non-empty children (each has a certificate).
  [[nodiscard]] std::size_t certificates() const { return tree_.certificates(); }
  /// Per point, the certificates it takes part in, added into `count` (indexed by table index).
  void count_certificates(std::vector<std::uint32_t>& count) const;
  [[nodiscard]] PairTournamentCounters counters() const {
    PairTournamentCounters c = counters_;
    c.nodes_redecided = tree_.keys().decisions;
    return c;
  }
  /// Invariants: every node's winner is one of its children's, its certificate queued under
  /// this owner for it or none, the counts right; under the exact scheduler also the shorter
  /// just after now (ties by ids) unless its event is due now. Exact arithmetic: for tests.
  [[nodiscard]] bool validate() const;

 private:
  /// The tournament's entries: leaves, compared by their pairs' squared lengths
  /// (core/tournament_tree.hpp's Keys), with the pairs and the count of their decisions.
  struct Keys {
    const MotionTable* points;
    Simulator* sim;
    const Scheduler* scheduler;
    std::vector<Pair> pair;  ///< leaf -> its pair ({kNoIndex, kNoIndex}: empty)
    std::uint64_t decisions = 0;
    /// Leaf x's pair is shorter than leaf y's just after now (equal for ever: by their ids).
    Scheduler::MaxDecision decide(std::size_t node, std::uint32_t x, std::uint32_t y);
    [[nodiscard]] bool tie_before(std::uint32_t x, std::uint32_t y) const;
    [[nodiscard]] LengthComparison comparison(std::uint32_t x, std::uint32_t y) const;
    [[nodiscard]] Time window_lo(std::uint32_t x, std::uint32_t y) const;
  };

  [[nodiscard]] std::size_t capacity() const { return tree_.topology().capacity; }
  /// Arrays for `capacity` leaves (the pairs kept, new leaves empty), no event, no winner.
  void lay_out(std::size_t capacity);
  /// Re-decides node v; true when its winner, or the pair its winner holds, changed.
  bool decide(std::size_t v);
  void touch(std::uint32_t leaf);
  [[nodiscard]] std::uint32_t entry(std::uint32_t leaf) const {
    return tree_.keys().pair[leaf][0] == kNoIndex ? kNoIndex : leaf;
  }

  TournamentTree<Keys> tree_;
  std::vector<std::uint8_t> changed_leaf_;  ///< leaf changed in this batch
  std::vector<std::uint32_t> changed_leaves_, changed_, next_changed_;
  PairTournamentCounters counters_;  ///< (the decisions' count is the keys')
};

}  // namespace kinetic
