#pragma once
// The kinetic rank-based kd-tree (Abam, de Berg, Speckmann, Section 2)
// for points moving in d dimensions, with orthogonal range queries.
//
// The skeleton S(P): an x_i-node v (i = depth mod d) has a range of ranks range(v) on axis i,
// the first or second half of its x_i-parent's range ([0, n-1] at the first x_i-node); its
// splitting hyperplane passes through the point whose rank in A_i is the median of range(v):
// points of lower rank go left, the others right.
//
// Ranks as labels (what makes inserts and removes local; the paper leaves them open, since a
// new point changes n and every rank after it). Each A_i is kept in the kinetic sort's gapped
// layout: U_i slots (a power of two, U_i = Theta(n)), some empty, and a point's "rank" on axis i
// is its slot there, a label that keeps the order. S(P) halves [0, U_i - 1] instead of
// [0, n - 1] (so the side taken at level l is bit l of the label from the top), and the split of
// a range with median label m passes through the first point at a label >= m (+infinity if
// none): points with lower labels are at or below it, the others at or above. This is the
// rank-based tree of the same points ranked among U_i positions per axis with the empty ones
// left out, so the skeleton, Lemma 2's depth (d log2 U_i) and Theorem 4's query bound hold with
// U_i = O(n) in place of n. An insert or remove moves a few labels (the rest of one segment
// of an A_i, or a spread window); only those points, and the new or removed one, are deleted
// and reinserted as for an event. A node holding one point is a leaf. The tree
// T(P) keeps the active nodes (two non-empty children), the leaves, and those degree-one nodes
// whose hyperplanes bound the region of the highest active descendant (at most 2d per active
// node); it has n leaves, O(dn) nodes, depth <= d ceil(log2 n) (Lemma 2), and answers a range
// query in O(d^2 n^(1-1/d) + d k) (Theorem 4).
//
// Representation. Since range(v) and the side taken at v depend only on a point's rank on v's
// axis, every point has a key (its bit sequence down S); S is the binary trie of the keys,
// stopped where a point is alone. We store the active nodes and the leaves (a compressed trie,
// 2n - 1 nodes) and, on each edge, the kept degree-one nodes between them (its "chain": axis,
// median rank, side). A split refers to the rank of its point, so its coordinate is that of
// A_i[median] at query time and a swap of two points elsewhere never touches it.
//
// Kinetization (Theorem 5): the arrays A_i are kept by the core's kinetic sorting, one
// KineticSort per axis, with their certificates and the scheduler's (robust) event times. When
// p and q swap in A_i, only their keys change, and only below the skeleton depth where their
// ranks separate: a point whose leaf lies above that depth keeps its place (T(P) does not
// change for it), the others are deleted and reinserted (O(d log n)); the rest of the tree is
// untouched. Inserts, removes and flight-plan updates place or take out the point in each A_i
// (O(log n) comparisons), then delete and reinsert the points whose labels moved (O(log^2 n)
// amortized per axis, about one segment's worth in practice); when an A_i is laid out again (its
// U_i doubles or halves, once per Theta(n) inserts or removes) the tree is rebuilt (O(dn log n),
// counted).
//
// Queries read the split motions from per-axis arrays by label (laid out in the halvings'
// breadth-first order, split_slot()), the leaves' motions at the leaves, and report a subtree
// inside the box as one run of the leaves' left-to-right thread; a subtree of at most kBucket
// leaves (range_bucket() for a range query) cut by the box is not descended: its leaves are
// tested from its run at the query time (in 2-D and 3-D: their values, points and groups' boxes,
// kept for the next queries at that time; kept_run()), or one by one along the thread in other
// dimensions. Leaves have their own slots, laid out in thread order by a build, so such runs are
// read mostly sequentially; the active nodes a query reads come next, packed together
// (upper()), then the others.

#include <array>
#include <bit>
#include <cassert>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "kinetic/core/description.hpp"
#include "kinetic/core/geometry.hpp"
#include "kinetic/core/huge_pages.hpp"
#include "kinetic/core/ids.hpp"
#include "kinetic/core/k_nearest.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/query_round.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/structure.hpp"
#include "kinetic/sort/axis_sorted_points.hpp"
#include "kinetic/sort/kinetic_sort.hpp"

namespace kinetic {

struct KdTreeCounters {
  std::uint64_t swaps = 0;                 ///< swaps in the arrays A_i
  std::uint64_t reinsertions = 0;          ///< points deleted and reinserted for swaps
  std::uint64_t unchanged_events = 0;      ///< swaps that left T(P) unchanged (no reinsertion)
  std::uint64_t nodes_created = 0;         ///< trie nodes created by reinsertions
  std::uint64_t nodes_removed = 0;         ///< trie nodes removed by deletions
  std::uint64_t rebuilds = 0;              ///< full rebuilds (an order A_i laid out again)
  std::uint64_t local_changes = 0;         ///< inserts, removes and updates done without a rebuild
  std::uint64_t relabel_reinsertions = 0;  ///< points reinserted since a change moved a label
  std::uint64_t unchanged_relabels = 0;    ///< moved labels that left the point's leaf as it was
  /// Copies of the tree into fresh slots (the same tree, its storage in query order again),
  /// after every n / 8 reinsertions.
  std::uint64_t compactions = 0;
  std::uint64_t queries = 0;
  /// Tree nodes (trie nodes and chain nodes) whose split or point queries compared with the box,
  /// the leaves tested in small subtrees included, and the groups of a run kept at the query time
  /// whose box was tested (docs/kdtree.md).
  std::uint64_t node_visits = 0;
  std::uint64_t last_query_visits = 0;
  /// Small subtrees' runs evaluated at a query time and kept for the next queries at that time
  /// (2-D and 3-D; a query that finds them kept reads them: docs/kdtree.md).
  std::uint64_t runs_kept = 0;
};

/// The sorts, the table's sync, the measures read off the sorts and range() are the base's
/// (sort/axis_sorted_points.hpp).
class KineticKdTree final : public AxisSortedPoints {
 public:
  /// What the structure is and takes (core/description.hpp): the registry, the CLI and the
  /// Python class read it.
  [[nodiscard]] static StructureDescription description();

  /// One kinetic sort per axis of the table (each reserves its owner from the simulator).
  /// Precondition: 1 <= d <= 64.
  KineticKdTree(const MotionTable& motions, Simulator& simulator, const Scheduler& scheduler);
  ~KineticKdTree();
  KineticKdTree(const KineticKdTree&) = delete;
  KineticKdTree& operator=(const KineticKdTree&) = delete;

  /// Sorts every axis at sim.now() and builds the tree. O(dn log n).
  void initialize();
  /// The KDS event handler (an event of one of the sorts).
  EventKind process(const Event& event);

  /// Inserts, removes and motion updates (each after the change in the table): the sorts are
  /// updated in place, then the point and those whose labels moved are deleted and reinserted
  /// (see the header comment).
  void insert(std::uint32_t index);
  void remove(std::uint32_t index);
  void motion_changed(std::uint32_t index);

  /// The same set as range(box, t), in no particular order, written to `out` (cleared first; a
  /// buffer with less room gets room for 16 ids at once; its capacity is reused, so a caller
  /// that keeps the buffer allocates nothing). The same exact
  /// comparisons and the same guarantees as range(); only the final sort by id is left out.
  void range_unsorted(const Box& box, Time t, std::vector<std::uint32_t>& out);

  /// The k points nearest to q at t (all when fewer), by increasing distance, equal distances by
  /// id (docs/kdtree.md): exact away from events for eps = 0; for eps > 0 each distance within
  /// (1 + eps) of the true one of its rank. A depth-first search, nearer child first, that
  /// skips a region when its lower bound on the distance (from the splits' coordinates at t) is
  /// above the k-th best so far (core/k_nearest.hpp). Preconditions: q has d finite
  /// coordinates, eps finite >= 0, t == now.
  [[nodiscard]] std::vector<std::uint32_t> k_nearest(std::span<const double> q, std::size_t k,
                                                     double eps, Time t);
  /// The same into `out` (its capacity reused).
  void k_nearest(std::span<const double> q, std::size_t k, double eps, Time t,
                 std::vector<std::uint32_t>& out);
  /// k_nearest with k = 1: empty when there are no points.
  [[nodiscard]] std::optional<std::uint32_t> nearest(std::span<const double> q, double eps, Time t);

  [[nodiscard]] const KdTreeCounters& counters() const { return counters_; }
  [[nodiscard]] NamedCounters named_counters() const;
  /// Nodes of T(P): trie nodes plus chain nodes.
  [[nodiscard]] std::size_t node_count() const;
  /// Depth of T(P) in skeleton levels: the largest leaf depth.
  [[nodiscard]] int depth() const;

  /// The tree equals a fresh build from the current ranks; node count <= (2n - 1)(2d + 1) and
  /// depth <= d ceil(log2 n); the sorts validate. O(dn log n).
  [[nodiscard]] bool validate() const;

 private:
  /// A query stops descending at a subtree of at most this many leaves and tests its leaves
  /// there (from the subtree's kept run in 2-D and 3-D; T(P) itself is not changed).
  static constexpr std::uint32_t kBucket = 32;
  /// A range query's bucket: kBucket in the plane, twice that from d = 3 on, where a box's
  /// boundary crosses more small regions and a scan costs less than the descent it replaces
  /// (docs/performance/kdtree.md). The k-nearest search keeps kBucket.
  [[nodiscard]] std::uint32_t range_bucket() const { return d_ >= 3 ? 2 * kBucket : kBucket; }
  /// The capacity a query's output buffer gets at least (one allocation for a small answer).
  static constexpr std::size_t kFirstCapacity = 16;
  /// Chains of up to this many entries (2d <= kInline: d <= 3) are kept inside the node, so a
  /// query reads a node and its chain from one cache line; for d > 3 they are kept in
  /// Trie::chains.
  static constexpr std::uint32_t kInline = 6;
  // The trie, its node records (a node and its chain in one 64-byte record for d <= 3) and
  // chain entries: private layout, defined in the source file.
  struct ChainEntry;
  struct Node;
  /// A motion as the queries' floating-point filter reads it (defined in the source file).
  struct Linear;
  struct Trie;

  /// Where the motion at label m of an axis with labels [0, 2^log) is kept in by_rank_: the
  /// labels in the order of the halvings (the median of [0, 2^log) first, then those of its
  /// halves, and so on: Eytzinger's layout of the implicit search tree). The median one halving
  /// below the split at place e is at 2e or 2e + 1, two halvings below at 4e..4e + 3: one cache
  /// line, asked for ahead without reading the nodes (visit(); a hint: where the descent's next
  /// split on the axis lies deeper, the line is only wasted).
  [[nodiscard]] static std::size_t split_slot(std::uint32_t m, std::uint32_t log) {
    assert(log <= 32 && std::uint64_t{m} < (std::uint64_t{1} << log));
    if (m == 0) return 0;
    const int low = std::countr_zero(m);
    return (std::size_t{1} << (log - 1 - static_cast<std::uint32_t>(low))) + ((m >> low) >> 1);
  }
  /// The motion of the split at `label` on the axis (from by_rank_).
  [[nodiscard]] const Linear& split_motion(int axis, std::uint32_t label) const;
  [[nodiscard]] Linear& row_entry(int axis, std::uint32_t label);
  [[nodiscard]] std::uint32_t rank_of(std::uint32_t point, int axis) const {
    return sorts_[static_cast<std::size_t>(axis)].rank(point);
  }
  /// The side taken by `point` at skeleton depth `depth`.
  [[nodiscard]] int bit(std::uint32_t point, std::uint32_t depth) const;
  /// The median rank of the range at skeleton depth `depth` on the path of `point`.
  [[nodiscard]] std::uint32_t median(std::uint32_t point, std::uint32_t depth) const;
  void rebuild_tables();
  /// by_rank_[axis] over the slots [lo, hi] and the empty slots before lo read again.
  void refresh_rows(int axis, std::size_t lo, std::size_t hi);
  /// After a change of sort `axis`: false if it was laid out again (a rebuild is due), else its
  /// rows refreshed and the points it moved noted in moved_ (other than `own`).
  bool follow_sort(int axis, std::uint64_t generation, std::uint32_t own);
  /// linear_ and coef_max_ for one point (after an insert or update).
  void set_linear(std::uint32_t point);
  /// The motion about reference_, and in `error` the bound on its stored c0 at reference_.
  [[nodiscard]] Linear to_linear(const MotionPolynomial& p, double& error) const;
  /// coef_max_ and reference_error_ cover the motion l (its c0 within `error`).
  void note_linear(const Linear& l, double error);
  /// A filtered value's bound `own` (of c0 + c1 (t - T) as stored) widened to the true x(t).
  [[nodiscard]] double filter_error(double own) const;
  /// The stored motion l at t with its bound widened by filter_error().
  [[nodiscard]] FilteredValue filtered(const Linear& l, Time t) const;
  /// At least the filter's error bound of every stored motion at t (from coef_max_ and
  /// reference_error_): a side farther than this from a box side is decided without its own
  /// bound.
  [[nodiscard]] double query_margin(Time t) const;
  /// Delete and reinsert the points in moved_; then `own` is inserted (kNoIndex: none).
  void reinsert_moved(std::uint32_t own);
  /// An insert, remove or update of `index`: `change` applied to every sort, then the tree
  /// rebuilt if an order was laid out again, else reinsert_moved(reinsert).
  template <class Change>
  void change_sorts(std::uint32_t index, std::uint32_t reinsert, Change&& change);
  /// A slot for a leaf or an active node: a freed one, a fresh one of a layout (for an active
  /// node, among the upper ones when `read_by_queries`; ignored for a leaf and once a layout's
  /// slots are all taken), or a new one at the end.
  std::uint32_t new_node(Trie& t, bool leaf, bool read_by_queries) const;
  /// The layout of the active nodes. A node below `parent` (the root: kNoIndex) is an upper one
  /// when its parent has more than kBucket leaves: a k-nearest query descends below such a
  /// parent, so it reads the node, at least to stop there (a range query, whose bucket is
  /// range_bucket(), reads a subset of them). A build and a compaction give the upper nodes the
  /// first inner slots, together in preorder (a few n / kBucket nodes: under a megabyte at
  /// n = 10^5), and the rest, which only the events read, the slots after them.
  [[nodiscard]] static bool upper(const Trie& t, std::uint32_t parent);
  /// The axis of the splits at skeleton depth `depth`.
  [[nodiscard]] int axis_of(std::uint32_t depth) const {
    return static_cast<int>(depth % static_cast<std::uint32_t>(d_));
  }
  /// The node's chain recomputed from the current ranks (top-down); returns its size.
  std::uint32_t logical_chain(const Trie& t, std::uint32_t node,
                              std::array<ChainEntry, 128>& chain) const;
  void set_chain(Trie& t, std::uint32_t node) const;
  [[nodiscard]] bool inline_chains() const { return 2 * static_cast<std::uint32_t>(d_) <= kInline; }
  /// Entry k of the node's chain (top-down), from the node or from Trie::chains.
  [[nodiscard]] ChainEntry chain_entry(const Trie& t, std::uint32_t node, std::uint32_t k) const;
  /// The point's motion on the axis, from linear_.
  [[nodiscard]] Linear linear(std::uint32_t point, int axis) const;
  void refresh_linear();
  void layout(Trie& t, std::size_t points) const;
  void set_leaf(Trie& t, std::uint32_t node, std::uint32_t point) const;
  /// Trie::coef of a leaf (one leaf; every leaf of a fresh build).
  void set_leaf_motions(Trie& t, std::uint32_t node) const;
  void fill_leaf_motions(Trie& t) const;
  std::uint32_t build(Trie& t, std::vector<std::uint32_t>& points, std::size_t lo, std::size_t hi,
                      std::uint32_t depth, std::uint32_t parent) const;
  void build_all(Trie& t) const;
  void erase(std::uint32_t point);
  void insert_point(std::uint32_t point);
  void rebuild();
  /// Copies trie_ into fresh slots in a build's order (leaves in thread order, then the active
  /// nodes as upper() says), without recomputing anything: O(dn).
  void compact();
  std::uint32_t copy_subtree(const Trie& from, std::uint32_t x, Trie& to, std::uint32_t parent);
  bool same(const Trie& a, std::uint32_t x, const Trie& b, std::uint32_t y) const;
  /// sign(p(t) - x), exactly: a filtered evaluation first, the exact predicate when needed.
  [[nodiscard]] int compare_to(const MotionPolynomial& p, double x, Time t) const;
  struct SideCuts;
  struct Query;
  void refresh_coefficients();
  /// sign(x(t) - b) for a leaf's motion l of `point` on the axis: its own filter bound, then the
  /// exact predicate (out of line: the queries' margin decides most sides first).
  [[gnu::noinline]] int leaf_side(const Linear& l, std::uint32_t point, int axis, double b,
                                  Time t) const;
  /// The point of `leaf` is inside the box at q.t on the sides in lo_need / hi_need (bit per
  /// axis), exactly.
  [[nodiscard]] bool inside(std::uint32_t leaf, std::uint32_t point, const Query& q,
                            std::uint64_t lo_need, std::uint64_t hi_need) const;
  /// The split A_axis[median] (its stored motion: split_motion(axis, median)) against the box
  /// side pair b at t, exactly: bit 0 set iff b[0] <= c, bit 1 set iff c <= b[1] (`cut`: b
  /// against query_margin(t)).
  [[nodiscard]] int split_vs_box(int axis, std::uint32_t median, const Linear& motion,
                                 const std::array<double, 2>& b, Time t, const SideCuts& cut) const;

  void report(std::uint32_t node, std::vector<std::uint32_t>& out) const;
  /// The threads and spans agree with a depth-first walk of the trie.
  [[nodiscard]] bool threads_valid() const;
  /// Every node's stored chain (inline in the node for d <= 3) equals its chain recomputed from
  /// the current ranks; unused inline slots are zero.
  [[nodiscard]] bool chains_valid() const;
  /// by_rank_, linear_ and the leaves' motions agree with the table and the orders.
  [[nodiscard]] bool query_data_valid() const;
  /// The children's first reads asked for ahead (the k-nearest descent's software pipeline;
  /// a range query, which often leaves one child, was no faster with it).
  void prefetch_children(const Node& v) const;
  /// Asks for the lines of by_rank_ that hold the splits on `axis` one and two halvings below
  /// the split at place `place` of its row (split_slot(): the descent's next splits on that
  /// axis, whichever way it goes).
  void prefetch_splits_below(int axis, std::size_t place) const;
  void visit(std::uint32_t node, Query& q, std::uint64_t lo_in, std::uint64_t hi_in) const;
  /// Tests the leaves of a small subtree (a bucket at query time: its kept run in 2-D and 3-D,
  /// scan_fixed(); else one by one along the thread), on
  /// the box sides that lo_in / hi_in (as in visit()) do not certify.
  void scan(std::uint32_t node, Query& q, std::uint64_t lo_in, std::uint64_t hi_in) const;
  /// scan() in D = 2 or 3 dimensions, on the sides in lo_need / hi_need.
  template <int D>
  void scan_fixed(std::uint32_t node, Query& q, std::uint64_t lo_need, std::uint64_t hi_need) const;
  void query(const Box& box, Time t, std::vector<std::uint32_t>& out) override;
  struct NearestQuery;
  /// The k-nearest search below `node`: `gap2[a]` is a lower bound on (x_a - q_a)^2 over the
  /// node's parent's region, `rd` their sum.
  void nearest_visit(std::uint32_t node, NearestQuery& nq, double rd, double* gap2) const;
  /// The k-nearest search in a small subtree (d = D, 2 or 3): its run at t, kept (kept_run()),
  /// group by group; gap2 as in nearest_visit(), for the subtree's region.
  template <int D>
  void nearest_scan(std::uint32_t node, NearestQuery& nq, const double* gap2) const;
  /// Offers `point` to the candidates with an enclosure of its distance, from the squared
  /// distance of its leaf's filtered coordinates.
  void nearest_offer(std::uint32_t point, double squared, NearestQuery& nq) const;

  /// log2(U_i): the label space of axis i is [0, U_i - 1] (its sort's slots); bit l from the top
  /// of a label is the side taken at the l-th halving.
  std::vector<std::uint32_t> log_space_;
  std::vector<std::uint32_t> moved_;  // a local change: the points whose labels moved
  std::vector<std::uint64_t> moved_mark_;
  std::uint64_t moved_round_ = 0;
  std::unique_ptr<Trie> trie_;
  struct LeafRef;  // a point's leaf and the leaf's depth (read by every event)
  std::vector<LeafRef> leaf_of_;
  std::uint64_t moved_since_layout_ = 0;  // reinsertions since the last build or compaction
  /// by_rank_[i][split_slot(r)]: the motion of A_i[r] on axis i (swapped with the order on every
  /// event), so a split at label r reads its coefficients in one place; an empty slot holds the
  /// motion of the next point (+infinity after the last).
  std::vector<HugeVector<Linear>> by_rank_;
  HugeVector<Linear> linear_;  // linear_[point * d + i]: the point's motion on axis i
  /// max |c0| and max |c1| (finite slopes) over linear_ (every motion a query reads is a copy
  /// of one of them).
  std::unique_ptr<Linear> coef_max_;
  /// The time the stored motions are written about (the last build's), and the largest bound
  /// on a stored c0's error at that time.
  Time reference_ = 0.0;
  double reference_error_ = 0.0;
  KdTreeCounters counters_;
  NearestCandidates nearest_;  // a k_nearest query's candidates (its storage reused)
  std::vector<SideCuts> cuts_;  // a range query's box sides against its margin, per axis
  std::vector<std::pair<std::uint32_t, double>> nearest_undo_;  // the search's gap changes
  /// The small subtrees' runs at the query time (d = 2 and 3: keeps_values()), kept for the next
  /// queries at the same time while the tree does not change (no event, insert, remove, update,
  /// compaction or rebuild since: mutations_). The first range scan or k-nearest search of a run
  /// in the round writes (kept_run()), in the run's left-to-right order: each leaf's values
  /// c1 (t - T) + c0 (what a scan computes from the leaf's coefficients), its point, and the
  /// bounding box of the values of each group of kGroup consecutive leaves. The scans read them
  /// from one contiguous place: a group beyond a box side (or farther from the query point than
  /// the candidates' limit) is skipped, a group inside every tested side is reported whole, the
  /// others are tested leaf by leaf (docs/kdtree.md). value_round_ is the query time's round
  /// (core/query_round.hpp); the pools are emptied when it starts (they keep their size, so a
  /// round reuses their memory). A cache: mutable, written by the queries.
  static constexpr std::uint32_t kGroup = 8;
  struct KeptRun {
    std::uint64_t round = 0;  // the run of this node was kept in this round
    std::uint64_t at = 0;     // its first leaf's place in the pools (a multiple of kGroup)
  };
  /// A kept run where the pools hold it: leaf i's values value[i d + axis] and point point[i],
  /// group g's box box[g 2d + axis] (lowest) and box[g 2d + d + axis] (highest).
  struct RunView {
    const double* value;
    const std::uint32_t* point;
    const double* box;
    std::size_t count;   // leaves
    std::size_t groups;  // (count + kGroup - 1) / kGroup
  };
  mutable HugeVector<KeptRun> kept_run_;          // by node
  mutable HugeVector<double> kept_value_;         // leaf i of a run at `at`: [(at + i) d + axis]
  mutable HugeVector<std::uint32_t> kept_point_;  // its point: [at + i]
  /// Group g's box: [(at / kGroup + g) 2d + axis] the lowest value, [... + d + axis] the highest;
  /// -infinity and +infinity on an axis where a value is NaN (a motion of degree above 1).
  mutable HugeVector<double> kept_box_;
  mutable std::size_t kept_used_ = 0;  // the pools' leaves in use this round (they only grow)
  mutable std::uint64_t runs_kept_ = 0;  // counters_.runs_kept, counted by kept_run()
  QueryRound value_round_;
  std::uint64_t mutations_ = 0;  // events and changes
  [[nodiscard]] bool keeps_values() const { return d_ == 2 || d_ == 3; }
  /// The run of `node` (a subtree a query scans) at the current round's time, in the pools:
  /// kept already, or computed and kept now (d = D, 2 or 3).
  template <int D>
  RunView kept_run(std::uint32_t node) const;
  /// value_round_.begin() for a query at t: empties the pools when a round starts, sizes
  /// kept_run_.
  void begin_value_round(Time t);
};

static_assert(KineticStructure<KineticKdTree>);

}  // namespace kinetic
