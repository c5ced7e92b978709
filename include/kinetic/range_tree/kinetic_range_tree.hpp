#pragma once
// The kinetic range tree (Basch, Guibas and Zhang; Abam, Agarwal, de Berg, Yu, Section 5) for
// points moving in d dimensions, with orthogonal range queries, maintained with one kinetic sort
// per axis.
//
// Structure. The sorts keep the gapped layout (a packed-memory array over U slots, U a power of
// two; KineticSort, SortLayout::Gapped): a point's label on axis i is its slot in A_i. The
// primary tree halves the slots [0, U - 1] of A_0; every tree below it halves the positions of
// its block the same way, so every node of every level is a dyadic interval of [0, U - 1]. A
// block is an array of as many positions as its node has slots; it holds the node's points,
// sorted by their label on the next axis, and vacant positions (the node's empty slots) spread
// between them. A node with two positions or more stores its block; at the last level
// (j + 1 = d - 1) the block is just a sorted array with vacancies.
//
// Layout. The blocks of level j are stored in arrays ORD_j[k_1 .. k_j] of U entries, one array
// per tuple of depths (the depth of the node chosen in each of the trees above): the node at
// depth k of a level-(j - 1) tree over positions [s, e] of ORD_{j-1}[k_1 .. k_{j-1}] stores its
// block at positions [s, e] of ORD_j[k_1 .. k_{j-1}, k]. With H = log2 U there are (H + 1)^j
// tuples at level j; only the arrays under nodes of two positions or more are stored (the
// tuples whose depths sum to less than H), so the space is O(U log^(d-1) U); with each entry
// comes the point's position in that array (POS_j, indexed by point), so an update finds a
// point in O(1).
//
// Four operations on a block keep this true, each applied to the blocks below it:
//  * vacate: a point's entry becomes vacant, here and in every block below it (O(1) per block);
//  * place: a point enters the block at its place in the block's order (a binary search that
//    skips vacancies) and takes a vacancy next to it, or the entries between it and the nearest
//    vacancy (within kShiftReach) shift one position toward that vacancy, or the smallest aligned
//    window around it with room enough (density <= 7/8) is spread evenly. An entry that moves
//    changes the nodes of its block's tree that hold it (those strictly below the lowest common
//    ancestor of its two positions), so below the last level the move is applied to the blocks
//    below, as a vacate and a place;
//  * a batch of moves vacates every moved point from the nodes it leaves before it places any in
//    the nodes it enters, so no block ever holds more points than positions;
//  * a vacate that leaves a run of kMaxVacantRun vacancies spreads the smallest aligned window
//    around it with enough points (the searches skip vacancies one by one).
//
// Events. A swap of the adjacent points p, q of A_a (axis a) changes every level-a block holding
// both: they are adjacent there (up to vacancies), so they exchange positions, and, if a < d - 1,
// the nodes of that block's tree strictly below the lowest common ancestor of the two positions
// change: on p's side p is replaced by q and vice versa (a batch of two moves). For j < a, the
// nodes of level-j trees holding both (the ancestors of their lowest common ancestor, inclusive)
// apply the swap to their blocks below. Blocks holding only one of p, q keep their order. For
// d = 2: an x-swap vacates and places the two points in the nodes below their lowest common
// ancestor (O(log n) of them for a random adjacent pair, each a binary search and a few shifts);
// a y-swap exchanges two entries in the blocks of the O(log n) common ancestors.
//
// Inserts, removes and flight-plan updates are local. The point's entries are vacated (remove,
// update), the sorts change (an insert or remove moves a few keys in each sort's layout,
// relabeled()), the primary mirror reads the slots the sort touched, the keys whose slot moved
// in A_0 move between the primary's nodes (a batch of moves), and the point is placed (insert,
// update) in the blocks of the nodes holding its new slot. Labels moved on the other axes keep
// their order, so those blocks do not change. When A_0 is laid out again (U doubled or halved)
// the structure is rebuilt (counted in `rebuilds`).
//
// Queries walk the trees as usual (binary searches over each block's order skipping vacancies,
// the canonical nodes of the position range, recursively), O(log^d n + k). Positions are compared
// exactly (a double evaluation of a compact copy of the linear motions with a rigorous bound
// first). With the robust scheduler an order may be briefly unsorted; the searches just follow
// the arrays, and the answer is a Delta-approximation with Delta = n eps V_max (Abam, Agarwal,
// de Berg, Yu, Theorem 8).

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "kinetic/core/description.hpp"
#include "kinetic/core/geometry.hpp"
#include "kinetic/core/ids.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/structure.hpp"
#include "kinetic/sort/axis_sorted_points.hpp"
#include "kinetic/sort/kinetic_sort.hpp"

namespace kinetic {

struct RangeTreeCounters {
  std::vector<std::uint64_t> swaps_by_axis;  ///< swaps in A_i, per axis
  std::uint64_t swaps = 0;                   ///< all swaps
  std::uint64_t nodes_touched = 0;   ///< blocks changed (exchanges, vacates, places), all events
  std::uint64_t adjacent_swaps = 0;  ///< two entries of a block exchanged (an event's own axis)
  std::uint64_t replacements = 0;    ///< events: a point replaced by the other in a node below
  std::uint64_t placements = 0;      ///< a point placed in a block (events, moves, changes)
  std::uint64_t vacated = 0;         ///< a point's entry in a block made vacant
  std::uint64_t shifts = 0;          ///< entries shifted one position toward a vacancy by a place
  std::uint64_t window_spreads = 0;  ///< windows of a block spread evenly (both kinds below)
  std::uint64_t gap_spreads = 0;     ///< ... of them after a vacate left a long vacant run
  std::uint64_t spread_entries = 0;  ///< entries written by those spreads
  std::uint64_t relabel_moves = 0;   ///< keys an insert / remove / update moved in A_0's slots
  std::uint64_t local_changes = 0;   ///< inserts, removes and updates done locally
  std::uint64_t rebuilds = 0;        ///< full rebuilds (A_0 laid out again)
  std::uint64_t queries = 0;
  std::uint64_t node_visits = 0;  ///< tree nodes and binary-search steps visited by queries
  std::uint64_t last_query_visits = 0;
  std::uint64_t last_event_nodes = 0;  ///< blocks changed by the last event
};

/// The sorts, the table's sync, the measures read off the sorts and range() are the base's
/// (sort/axis_sorted_points.hpp).
class KineticRangeTree final : public AxisSortedPoints {
 public:
  /// What the structure is and takes (core/description.hpp): the registry, the CLI and the
  /// Python class read it.
  [[nodiscard]] static StructureDescription description();

  /// One kinetic sort per axis of the table, in the gapped layout (each reserves its owner from
  /// the simulator). Precondition: 1 <= d <= 8.
  KineticRangeTree(const MotionTable& motions, Simulator& simulator, const Scheduler& scheduler);
  ~KineticRangeTree();
  KineticRangeTree(const KineticRangeTree&) = delete;
  KineticRangeTree& operator=(const KineticRangeTree&) = delete;

  /// Sorts every axis at sim.now() and builds the tree. O(U log^(d-1) U).
  void initialize();
  /// The KDS event handler (an event of one of the sorts).
  EventKind process(const Event& event);

  /// Inserts, removes and flight-plan updates (each after the change in the table), local: the
  /// point's entries are vacated / placed and the keys A_0's layout moved change nodes (header
  /// comment). A rebuild only when A_0 is laid out again (U doubled or halved).
  void insert(std::uint32_t index);
  void remove(std::uint32_t index);
  void motion_changed(std::uint32_t index);

  /// Positions of every block array: the slots U of A_0.
  [[nodiscard]] std::size_t slots() const { return u_; }
  [[nodiscard]] const RangeTreeCounters& counters() const { return counters_; }
  [[nodiscard]] NamedCounters named_counters() const;
  /// Entries stored in the blocks of every level (the space measure, n log^(d-1) n order).
  [[nodiscard]] std::size_t stored_entries() const;
  /// Bytes of the arrays (entries and positions, with the vacant and unused positions).
  [[nodiscard]] std::size_t memory_bytes() const;

  /// The level-0 array mirrors A_0; every stored entry's position map agrees, its point lies in
  /// its node (its position in the array above is in the same dyadic interval), each block is
  /// increasing in the labels of its axis, every array below a node of two positions or more
  /// holds all of that level's points and nothing else; the sorts validate.
  /// O(U log^(d-1) U).
  [[nodiscard]] bool validate() const;

  /// How far place() looks for a vacancy on either side before it spreads a window.
  static constexpr std::uint32_t kShiftReach = 32;
  /// A vacate that leaves a run of this many vacancies in a block spreads a window around it
  /// (the searches skip vacancies one by one, so their runs must stay short).
  static constexpr std::uint32_t kMaxVacantRun = 64;
  /// The longest run of vacant positions in a block (of two positions or more, below level 0)
  /// that holds at least one point: shorter than kMaxVacantRun unless a block's points are too
  /// few to spread (fewer than one per kMaxVacantRun / 2 positions). A diagnostic, O(stored
  /// positions).
  [[nodiscard]] std::size_t longest_vacant_run() const;

 private:
  // Private layout, defined in the source file: the arrays of one level (Level), the query's
  // state (Query), the queries' copy of a motion (Linear), one entry's move in a block (Move).
  struct Level;
  struct Query;
  struct Linear;
  struct Move;
  struct PosView;
  using Layout = std::vector<Level>;  // d levels

  [[nodiscard]] std::uint32_t label(std::uint32_t point, int axis) const {
    return sorts_[static_cast<std::size_t>(axis)].rank(point);
  }
  /// Index of the array of level j + 1 under array `a` of level j at depth k.
  [[nodiscard]] std::size_t child_array(std::size_t a, std::uint32_t k) const {
    return a * (height_ + 1) + k;
  }
  [[nodiscard]] std::uint32_t* ord_of(int j, std::size_t a);
  [[nodiscard]] PosView pos_of(int j, std::size_t a);
  void build_all(Layout& out) const;
  /// Builds the blocks below the block [s, s + size) of array `a` of level j (its tree's nodes'
  /// blocks, recursively); the block itself is in place. Returns the entries written.
  std::uint64_t build_block(Layout& l, int j, std::size_t a, std::uint32_t s,
                            std::uint32_t size) const;
  void rebuild();
  /// The queries' copy of the point's motions (linear_).
  void refresh_linear(std::uint32_t point);

  // The block operations (header comment). `size` is the block's size (a power of two),
  // `s` its first position.
  void vacate(int j, std::size_t a, std::uint32_t size, std::uint32_t point);
  void place(int j, std::size_t a, std::uint32_t s, std::uint32_t size, std::uint32_t point);
  /// Places `point`, at position `at` of the block of size `size` of array `a` of level j, in
  /// the blocks of the nodes holding `at` (j < d - 1).
  void place_below(int j, std::size_t a, std::uint32_t size, std::uint32_t at, std::uint32_t point);
  /// The entries of moves_[j] changed positions in a block of size `size` of array `a`: each
  /// leaves the nodes below it that hold its old position only and enters those holding its new
  /// position only; every vacate before any place.
  void move_below(int j, std::size_t a, std::uint32_t size);
  /// No vacancy within kShiftReach: the smallest aligned window around `at` with room is spread
  /// evenly with `point` in it (the moved entries in moves_[j]). Returns the point's position.
  std::uint32_t spread_window(int j, std::size_t a, std::uint32_t s, std::uint32_t size,
                              std::uint32_t at, std::uint32_t point);
  /// Spreads the window [w0, w0 + w) of array `a` of level j evenly, with `point` inserted before
  /// position `at` unless it is kNoIndex; the moved entries in moves_[j] (below the last
  /// level). Returns the point's position.
  std::uint32_t respread(int j, std::size_t a, std::uint32_t w0, std::uint32_t w, std::uint32_t at,
                         std::uint32_t point);
  /// After a vacate at position i: a run of kMaxVacantRun vacancies through i spreads the
  /// smallest aligned window around it with enough entries, and moves them below.
  void close_gap(int j, std::size_t a, std::uint32_t size, std::uint32_t i);
  /// The swap of x and y (adjacent in A_axis) in the block of size `size` of array `a` of level
  /// j, which holds both.
  void swap_in(int j, std::size_t a, std::uint32_t size, int axis, std::uint32_t x,
               std::uint32_t y);
  /// After the sorts changed: the primary mirror, the moved keys, the point's own place.
  /// `own` is the inserted or updated point, kNoIndex for a remove.
  void follow_sorts(std::uint32_t own, std::uint64_t generation);

  /// sign(x_axis(t) - v) for the point, exactly.
  [[nodiscard]] int compare(std::uint32_t point, int axis, double v, Time t) const;
  [[nodiscard]] bool inside_from(std::uint32_t point, int axis, const Query& q) const;
  void search(int j, std::size_t a, std::uint32_t s, std::uint32_t size, Query& q) const;
  void canonical(int j, std::size_t a, std::uint32_t s, std::uint32_t size, std::uint32_t k,
                 std::uint32_t lo, std::uint32_t hi, Query& q) const;
  /// Ids ascending (a bitmap for large answers, as the kd-tree).
  void query(const Box& box, Time t, std::vector<std::uint32_t>& out) override;

  std::size_t cap_ = 0;
  std::size_t u_ = 0;       // slots of A_0, the positions of every array
  std::size_t height_ = 0;  // log2 U
  Layout layout_;
  std::vector<std::vector<Move>> moves_;            // per level: a block's moved entries
  std::vector<std::vector<std::uint32_t>> window_;  // per level: spread_window()'s entries
  std::vector<Linear> linear_;                      // linear_[point * d + axis]
  RangeTreeCounters counters_;
};

static_assert(KineticStructure<KineticRangeTree>);

}  // namespace kinetic
