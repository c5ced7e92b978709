#pragma once
// The kinetic range tree (Basch, Guibas and Zhang; Abam, Agarwal, de Berg, Yu, Section 5) for
// points moving in d dimensions, with orthogonal range queries, maintained with one kinetic sort
// per axis.
//
// Structure. A level-j tree (axis j, j = 0 .. d - 2) is a perfectly balanced binary tree over
// the positions of a block of points sorted by their rank on axis j: a node covering positions
// [s, e] (e > s) has the children [s, m] and [m + 1, e], m = s + (e - s) / 2; a node with one
// position is a leaf. Every node with two positions or more stores its points sorted by axis
// j + 1, which is the block of the level-(j + 1) structure of that node; at the last level
// (j + 1 = d - 1) that block is just a sorted array. The primary block (level 0) is the whole
// set sorted by axis 0. Since the tree's shape depends only on the block's size, a swap never
// changes it, only which point sits at which position.
//
// Layout. The blocks of level j are stored in arrays ORD_j[k_1 .. k_j] of n entries, one array
// per tuple of depths (the depth of the node chosen in each of the trees above): the node at
// depth k of the level-(j - 1) tree over positions [s, e] of ORD_{j-1}[k_1 .. k_{j-1}] stores its
// block at positions [s, e] of ORD_j[k_1 .. k_{j-1}, k]. With H = ceil(log2 n) there are
// (H + 1)^j arrays at level j, so the space is O(n log^(d-1) n); with each entry comes the
// point's position in that array (POS_j, indexed by point), so an update finds a point in O(1).
//
// Events. A swap of the adjacent points p, q of A_a (axis a) changes:
//  * every level-a block holding both: they are adjacent there too (a block is sorted by the
//    global rank), so they swap places; and, if a < d - 1, the nodes of that block's tree
//    strictly below the lowest common ancestor of their two positions: on p's side p is replaced
//    by q and vice versa. At the last level (a + 1 = d - 1) a replacement moves q to its place in
//    the node's sorted array (cost: the entries between them, counted in `shifts`); above it
//    (d >= 3) the node's (d - a - 1)-dimensional structure is rebuilt (its size is that of the
//    node; the sizes halve down the path, so the total is O(size of the LCA's child)).
//  * for j < a, the nodes of level-j trees holding both (the ancestors of the two points' lowest
//    common ancestor, inclusive): the change is applied recursively to their level-(j + 1)
//    structures.
//  Blocks holding only one of p, q keep their order (its rank moves by one past a point they
//  do not hold). For d = 2: an x-swap touches the two paths below the LCA (expected O(log n)
//  shifts for a random adjacent pair, O(n) in the worst case); a y-swap swaps two adjacent
//  entries in the arrays of the O(log n) common ancestors.
//
// Queries walk the trees as usual (binary searches over each block's order, the canonical nodes
// of the position range, recursively), O(log^d n + k). Positions are compared exactly (a double
// evaluation of a compact copy of the linear motions with a rigorous bound first). With the
// robust scheduler an order may be briefly unsorted; the searches just follow the arrays, and the
// answer is a Delta-approximation with Delta = n eps V_max (Abam, Agarwal, de Berg, Yu, Theorem 8).
//
// Flight-plan updates (motion_changed) keep n, hence every tree's shape. They are handled one
// axis at a time: the sort of axis a repositions the point p (rank r to r'), and the move is
// replayed on the structure as |r' - r| adjacent swaps of p with the points it passed, in order
// (up past the points now at r, r + 1, .., r' - 1, or down past those now at r, r - 1, ..,
// r' + 1), each by the event code (swap_in) on the intermediate order. This is sound because an
// event's update never reads the ranks of its own axis: at level a it follows the positions
// (POS_a), which hold the intermediate order, and below it (levels > a) it reads the ranks of
// the axes > a, whose sorts are updated only after axis a (so they still agree with the stored
// blocks); the levels < a are sorted by axes already updated. The sorts move only the entries
// between r and r' (KineticSort::motion_changed), so an update costs O(d log n) comparisons
// plus its swaps, each at most the cost of an event's update. The new ranks are found first
// (KineticSort::rank_after_update); when the swaps of all axes exceed update_swap_limit()
// (default 3n/2: measured, a rebuild costs as much as 2.2-3 n replayed swaps in 2-D at
// n = 10^5 and 1.4-1.7 n in 3-D at n = 3000 and 10^4; a random new motion moves a point by
// about n / 3 places per axis), the sorts are updated and the structure is rebuilt instead.
// Counted in `local_updates`, `update_rebuilds` and `replayed_swaps`.
//
// Inserts and removes update the sorts in place, then rebuild the structure (O(n log^(d-1) n),
// counted in `rebuilds`, as are the updates' rebuilds).

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "kinetic/core/geometry.hpp"
#include "kinetic/core/ids.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/preconditions.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/structure.hpp"
#include "kinetic/core/structure_group.hpp"
#include "kinetic/sort/kinetic_sort.hpp"

namespace kinetic {

struct RangeTreeCounters {
  std::vector<std::uint64_t> swaps_by_axis;  ///< swaps in A_i, per axis
  std::uint64_t swaps = 0;                   ///< all swaps
  std::uint64_t nodes_touched = 0;           ///< tree nodes whose stored block changed, all events
  std::uint64_t adjacent_swaps = 0;          ///< two adjacent entries of a block exchanged
  std::uint64_t replacements = 0;            ///< a point replaced by another in a node's block
  std::uint64_t shifts = 0;                  ///< array entries moved by replacements (last level)
  std::uint64_t rebuilt_entries = 0;  ///< entries written by node-structure rebuilds (d >= 3)
  std::uint64_t rebuilds = 0;         ///< full rebuilds (inserts, removes, updates)
  std::uint64_t local_updates = 0;    ///< flight-plan updates replayed as adjacent swaps
  std::uint64_t update_rebuilds = 0;  ///< flight-plan updates that rebuilt (beyond the limit)
  std::uint64_t replayed_swaps = 0;   ///< adjacent swaps replayed by updates (all axes)
  std::uint64_t queries = 0;
  std::uint64_t node_visits = 0;  ///< tree nodes and binary-search steps visited by queries
  std::uint64_t last_query_visits = 0;
  std::uint64_t last_event_nodes = 0;  ///< nodes touched by the last event
};

class KineticRangeTree {
 public:
  /// One kinetic sort per axis of the table (each reserves its owner from the simulator).
  /// Precondition: 1 <= d <= 8.
  KineticRangeTree(const MotionTable& motions, Simulator& simulator, const Scheduler& scheduler);
  ~KineticRangeTree();
  KineticRangeTree(const KineticRangeTree&) = delete;
  KineticRangeTree& operator=(const KineticRangeTree&) = delete;

  /// Sorts every axis at sim.now() and builds the tree. O(n log^(d-1) n).
  void initialize();
  /// The KDS event handler (an event of one of the sorts).
  EventKind process(const Event& event);

  /// Inserts and removes (each after the change in the table): the sorts are updated in place,
  /// then the structure is rebuilt.
  void insert(std::uint32_t index);
  void remove(std::uint32_t index);
  /// A flight-plan update (the table's motion of `index` was replaced): the move on each axis is
  /// replayed as adjacent swaps, or the structure is rebuilt when they would exceed
  /// update_swap_limit() in total.
  void motion_changed(std::uint32_t index);
  /// The most adjacent swaps (all axes) one flight-plan update replays; beyond, it rebuilds.
  /// kAutoLimit (the default) means 3n/2; 0 always rebuilds.
  static constexpr std::size_t kAutoLimit = SIZE_MAX;
  void set_update_swap_limit(std::size_t limit) { update_swap_limit_ = limit; }
  [[nodiscard]] std::size_t update_swap_limit() const {
    return update_swap_limit_ == kAutoLimit ? n_ + n_ / 2 : update_swap_limit_;
  }

  /// Object indices inside the closed box at time t (= sim.now() for a kinetic answer),
  /// ascending. Positions are compared exactly.
  [[nodiscard]] std::vector<std::uint32_t> range(const Box& box, Time t);

  [[nodiscard]] int dimension() const { return d_; }
  [[nodiscard]] std::size_t size() const { return n_; }
  [[nodiscard]] const RangeTreeCounters& counters() const { return counters_; }
  [[nodiscard]] NamedCounters named_counters() const;
  /// Entries stored in the blocks of every level (the space measure, n log^(d-1) n order).
  [[nodiscard]] std::size_t stored_entries() const;
  /// Bytes of the arrays (entries and positions, with the unused slots of the layout).
  [[nodiscard]] std::size_t memory_bytes() const;
  /// Certificates alive (one per adjacent pair per axis) and per point at most (2 per axis).
  [[nodiscard]] std::size_t certificates() const;
  [[nodiscard]] std::size_t certificates_per_object_max() const;
  [[nodiscard]] const KineticSort& sort(int axis) const {
    return sorts_[static_cast<std::size_t>(axis)];
  }

  /// The blocks equal a fresh build from the current orders, the positions agree, the stored
  /// entries are within n (ceil(log2 n) + 1)^(d-1) per level; the sorts validate.
  /// O(n log^(d-1) n).
  /// initialize() was called.
  [[nodiscard]] bool initialized() const { return sync_.initialized(); }
  [[nodiscard]] bool validate() const;

 private:
  // Private layout, defined in the source file: the arrays of one level (Level), the query's
  // state (Query), the queries' copy of a motion (Linear).
  struct Level;
  struct Query;
  struct Linear;
  using Layout = std::vector<Level>;  // d levels

  [[nodiscard]] std::uint32_t rank_of(std::uint32_t point, int axis) const {
    return sorts_[static_cast<std::size_t>(axis)].rank(point);
  }
  /// Index of the array of level j + 1 under array `a` of level j at depth k.
  [[nodiscard]] std::size_t child_array(std::size_t a, std::uint32_t k) const {
    return a * (height_ + 1) + k;
  }
  void build_all(Layout& out) const;
  /// Builds the structures below the block [s, e] of array `a` of level j (its tree's nodes'
  /// blocks, recursively); the block itself is in place. Returns the entries written.
  std::uint64_t build_block(Layout& l, int j, std::size_t a, std::uint32_t s,
                            std::uint32_t e) const;
  void rebuild();
  /// The queries' copy of the point's motions (linear_).
  void refresh_linear(std::uint32_t point);
  /// The swap of x and y (adjacent in A_axis) in the block [s, e] of array `a` of level j,
  /// which holds both.
  void swap_in(int j, std::size_t a, std::uint32_t s, std::uint32_t e, int axis, std::uint32_t x,
               std::uint32_t y);
  /// In the block [s, e] of array `a` of level j: `old_point` is replaced by `new_point`.
  void replace_in(int j, std::size_t a, std::uint32_t s, std::uint32_t e, std::uint32_t old_point,
                  std::uint32_t new_point);
  void set(Layout& l, int j, std::size_t a, std::uint32_t i, std::uint32_t p) const;
  /// sign(x_axis(t) - v) for the point, exactly.
  [[nodiscard]] int compare(std::uint32_t point, int axis, double v, Time t) const;
  [[nodiscard]] bool inside_from(std::uint32_t point, int axis, const Query& q) const;
  void search(int j, std::size_t a, std::uint32_t s, std::uint32_t e, Query& q) const;
  void canonical(int j, std::size_t a, std::uint32_t s, std::uint32_t e, std::uint32_t k,
                 std::uint32_t lo, std::uint32_t hi, Query& q) const;
  /// Ids ascending (a bitmap for large answers, as the kd-tree).
  void sort_ids(std::vector<std::uint32_t>& out);

  const MotionTable& motions_;
  TableSync sync_{motions_};  // told of every change to the table
  Simulator& sim_;
  int d_;
  StructureGroup<KineticSort> sorts_;  // one per axis
  std::size_t n_ = 0;
  std::size_t cap_ = 0;
  std::size_t height_ = 0;  // ceil(log2 n)
  Layout layout_;
  std::size_t update_swap_limit_ = kAutoLimit;
  std::vector<Linear> linear_;             // linear_[point * d + axis]
  std::vector<std::uint64_t> seen_;        // scratch of sort_ids(): a bit per index
  std::vector<std::uint64_t> seen_words_;  // and a bit per word of seen_
  RangeTreeCounters counters_;
};

static_assert(KineticStructure<KineticRangeTree>);

}  // namespace kinetic
