#pragma once
// The kinetic rank-based longest-side kd-tree (Abam, de Berg, Speckmann, Section 3) for points
// moving in the plane: (1+eps)-nearest, (1-eps)-farthest and
// eps-approximate range queries (disk or simple polygon), plus exact box range queries.
//
// The skeleton S(P). Each axis i has a fixed binary halving of its labels [0, U_i - 1] (the
// one-dimensional rank-based tree T_i of the paper over ranks as labels: a point's label on axis
// i is its slot in the gapped layout of the sort A_i, U_i a power of two, as in the rank-based
// kd-tree, include/kinetic/kdtree/): a range [lo, hi] with at least two labels has median
// m = lo + (hi - lo + 1) / 2, left half [lo, m - 1], right half [m, hi]. A node v of S has one
// range per axis, (h_0, h_1) (nodes of T_0 and T_1, numbered as a heap: root 1, children 2h and
// 2h + 1), and region(v) = [x_0(end_0(lo(h_0))), x_0(end_0(hi(h_0) + 1))] x [same on axis 1],
// where end_i(L) is the point at the first occupied label >= L of A_i (the last point when there
// is none): the root's region is the bounding box, and a side of every region is the difference
// of the coordinates of two points. v splits orthogonal to its longest side, axis a, at the
// median label of h_a: points of lower label go left, the others right, and the child's range on
// axis a is the half. A node with one point is a leaf. A node with two points or more has at
// least two labels on both axes, so both sides are elements below.
//
// Side lengths and region certificates. Every range h of T_i with at least two labels has a
// length x_i(end_i(hi(h) + 1)) - x_i(end_i(lo(h))) (an "element", kept as a polynomial and set
// again when an event or a change moves one of its end points). The split axis of a node v = (h_0,
// h_1) of S is its longer side: "just after now", exactly (the traditional classic scheduler: the
// lengths in floating point at now), and identical lengths broken by a fixed order (axis 1). The
// paper keeps all elements in one sorted side-length list; its adjacent pairs cross about n^3 times
// (almost all of them pairs that are not the two sides of any region, dropped events), so we
// certify only what the tree reads: every node of S with two points or more (a "live region": the
// active nodes and the degree-one nodes on the edges above active nodes) has one certificate [the
// shorter side < the longer side], and its stored split axis is what the tree follows. Nodes of S
// with one point decide nothing in T; their axis is computed when asked. The paper rejects
// per-region certificates because one length can be a side of many regions (a point may be in O(n)
// certificates, an ordering event may reschedule O(n) of them); here a range h is a side of at most
// |h| / 2 live regions per level of S (they hold disjoint sets of its points), so an ordering event
// at a uniformly random rank reschedules O(log^2 n) of them in expectation (counted as
// region_reschedules; docs/longest-side-kdtree.md has the measured figures), and every longest-side
// event processed changes the tree.
//
// The tree T(P). As in the rank-based kd-tree (include/kinetic/kdtree/), a point's path down S
// depends only on its own labels (and on the split axes), so S is the trie of the points' keys. We
// store the active nodes and the leaves (a compressed trie, 2n - 1 nodes) with their S-ranges,
// hence their regions, and count the kept degree-one nodes of the paper (the at most four on each
// edge that define a side of the region below); Theorem 8(i): size O(n), depth <= log2 U_0 +
// log2 U_1 (the paper's 2 ceil(log2 n) with U_i = O(n) in place of n).
//
// Events (Theorem 10):
//  - ordering event (two points swap in A_i, from the KineticSort of axis i): the two points are
//    deleted and reinserted with their new labels (O(log n)); the elements that have one of the
//    two points as an end get their new length polynomials (the lengths are continuous, so no
//    region's longer side changes) and the certificates of the live regions they are sides of
//    are rescheduled;
//  - longest-side event (a live region's two sides cross): the node v of S changes its split
//    axis, and the two levels of S below v are regrouped (Figure 3: the four grandchildren keep
//    their subtrees), O(log n) with the search for v. When lengths tied with v's sides make v's
//    children split otherwise, the subtree below v is rebuilt instead (counted).
// Inserts, removes and motion updates are local (the paper leaves them open): the sorts insert or
// remove one label and move a few others (relabeled()); the elements with a moved end get their
// new lengths, the points whose path in S changed are deleted and reinserted, and the live
// regions with a changed side are rescheduled, or change their split axis now (as a longest-side
// event) when their longer side changed. Only a new layout of a sort (U_i doubled or halved,
// once per Theta(n) changes) rebuilds everything (counted).

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <limits>
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
#include "kinetic/core/pair_set.hpp"
#include "kinetic/core/preconditions.hpp"
#include "kinetic/core/query_round.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/structure.hpp"
#include "kinetic/core/structure_group.hpp"
#include "kinetic/sort/kinetic_sort.hpp"

namespace kinetic {

struct LongestSideCounters {
  std::uint64_t ordering_events = 0;      ///< swaps in A_0 or A_1
  std::uint64_t longest_side_events = 0;  ///< a live region's sides crossed: its split axis changed
  std::uint64_t reinsertions = 0;         ///< points deleted and reinserted (ordering events)
  /// Ordering events whose two points kept their paths in S (labels changed below the leaves).
  std::uint64_t unchanged_events = 0;
  /// Region certificates recomputed because an ordering event moved an end of one of their sides.
  std::uint64_t region_reschedules = 0;
  std::uint64_t longest_side_events_rebuilt_below =
      0;                             ///< real ones handled by rebuilding below v (ties)
  std::uint64_t rebuilt_points = 0;  ///< points of those rebuilt subtrees
  /// Full rebuilds: a sort laid out again by an insert, remove or update (U_i doubled or halved).
  std::uint64_t rebuilds = 0;
  std::uint64_t local_changes = 0;  ///< inserts, removes and updates done in place
  /// Points deleted and reinserted because a change moved their label above their leaf.
  std::uint64_t relabel_reinsertions = 0;
  /// Moved labels that left the point's path in S as it was (no reinsertion).
  std::uint64_t unchanged_relabels = 0;
  /// Live regions whose longer side a change (not a crossing) made the other one: split on it
  /// at once, as a longest-side event.
  std::uint64_t change_axis_flips = 0;
  /// Lengths that are not one double polynomial (motion_difference() inexact): their
  /// certificates use the exact four-motion combination (see docs), never a rounded length.
  std::uint64_t combined_lengths = 0;
  std::uint64_t queries = 0;
  /// Regions met by queries: trie nodes, and in the searches (nearest, farthest, k_nearest)
  /// each bucket and each point a bucket scan meets.
  std::uint64_t node_visits = 0;
  std::uint64_t last_query_visits = 0;
};

class LongestSideKdTree {
 public:
  /// What the structure is and takes (core/description.hpp): the registry, the CLI and the
  /// Python class read it.
  [[nodiscard]] static StructureDescription description();

  /// Reserves three owners from the simulator: the sorts of axes 0 and 1, then the regions.
  /// Precondition: motions.dimension() == 2.
  LongestSideKdTree(const MotionTable& motions, Simulator& simulator, const Scheduler& scheduler);
  ~LongestSideKdTree();
  LongestSideKdTree(const LongestSideKdTree&) = delete;
  LongestSideKdTree& operator=(const LongestSideKdTree&) = delete;

  /// Sorts both axes at sim.now(), builds the tree, and schedules every certificate.
  /// O(n log n).
  void initialize();
  /// The KDS event handler.
  EventKind process(const Event& event);

  /// Inserts, removes and motion updates (each after the change in the table), in place: the
  /// points whose labels moved are reinserted, the lengths with a moved end set again and their
  /// regions rescheduled (or split on their new longer side). A sort laid out again (U_i
  /// doubled or halved) rebuilds everything.
  void insert(std::uint32_t index);
  void remove(std::uint32_t index);
  void motion_changed(std::uint32_t index);

  /// A point whose distance to q at time t is at most (1 + eps) times the smallest one (see
  /// docs/longest-side-kdtree.md for the rounding argument); nullopt when empty. eps >= 0.
  [[nodiscard]] std::optional<std::uint32_t> nearest(std::array<double, 2> q, double eps, Time t);
  /// The k points nearest to q at t (all when fewer), by increasing distance, equal distances by
  /// id: exact away from events for eps = 0, each distance within (1 + eps) of the true one of
  /// its rank for eps > 0 (a depth-first search over the regions, nearer first, core/k_nearest.hpp;
  /// docs/longest-side-kdtree.md). q has 2 finite coordinates, eps finite >= 0, t == now.
  [[nodiscard]] std::vector<std::uint32_t> k_nearest(std::span<const double> q, std::size_t k,
                                                     double eps, Time t);
  /// A point whose distance to q is at least (1 - eps) times the largest one. eps >= 0.
  [[nodiscard]] std::optional<std::uint32_t> farthest(std::array<double, 2> q, double eps, Time t);
  /// Every point inside the shape, plus possibly points within eps * diam(shape) of it;
  /// ascending indices.
  [[nodiscard]] std::vector<std::uint32_t> approx_range(const Shape& shape, double eps, Time t);
  /// Points inside the closed box, compared exactly; ascending indices.
  [[nodiscard]] std::vector<std::uint32_t> range(const Box& box, Time t);

  [[nodiscard]] std::size_t size() const { return n_; }
  [[nodiscard]] const LongestSideCounters& counters() const { return counters_; }
  [[nodiscard]] NamedCounters named_counters() const;
  [[nodiscard]] const KineticSort& sort(int axis) const {
    return sorts_[static_cast<std::size_t>(axis)];
  }
  /// Nodes of T(P): trie nodes plus kept degree-one nodes.
  [[nodiscard]] std::size_t node_count() const;
  /// Depth of T(P) in skeleton levels: the largest leaf depth.
  [[nodiscard]] int depth() const;
  /// Live regions: nodes of S with two points or more, one certificate each.
  [[nodiscard]] std::size_t live_regions() const { return region_keys_.size(); }
  /// An active node of T(P) as a picture needs it: region(v) = [x_0(lo[0]), x_0(top[0])] x
  /// [x_1(lo[1]), x_1(top[1])] (the points, table indices, whose coordinates bound it; its box at
  /// any time follows from their motions), and its split: orthogonal to `axis` through the
  /// point `split`, the point of median rank in v's range on that axis.
  struct CellSketch {
    int depth = 0;  ///< active nodes above it
    std::array<std::uint32_t, 2> lo{}, top{};
    int axis = 0;
    std::uint32_t split = 0;
  };
  /// The active nodes of T(P) in its top `levels` levels of active nodes, breadth first from
  /// the root (leaves are not listed). O(nodes listed).
  [[nodiscard]] std::vector<CellSketch> sketch(int levels) const;
  /// Certificates alive: the two sorts' (one per adjacent pair) and one per live region.
  [[nodiscard]] std::size_t certificates() const;
  /// The largest number of certificates one point takes part in. O(n log n).
  [[nodiscard]] std::size_t certificates_per_object_max() const;

  /// The tree equals a fresh build from the current labels and split axes; the live regions are
  /// exactly the nodes of S with two points or more, each with its certificate scheduled and the
  /// current length polynomials; size <= 5(2n - 1) and depth <= log2 U_0 + log2 U_1; the sorts
  /// validate. O(n log n).
  /// initialize() was called.
  [[nodiscard]] bool initialized() const { return sync_.initialized(); }
  [[nodiscard]] bool validate() const;
  /// Every live region splits orthogonal to a longest side at time t (exact comparisons of the
  /// true lengths).
  [[nodiscard]] bool audit_regions(Time t) const;

 private:
  // A node of S (its range on each axis), the trie of T and its nodes, a live region: private
  // layout, defined in the source file.
  struct State;
  struct Node;
  struct Trie;
  struct Region;

  // T_i: the halving of the labels [0, U_i - 1] of axis i (U_i = 2^log_space_[i]); the range
  // h at level l = floor(log2 h) is [(h - 2^l) U_i / 2^l, (h - 2^l + 1) U_i / 2^l - 1].
  [[nodiscard]] std::uint32_t range_size(int axis, std::uint32_t h) const {
    return std::uint32_t{1} << (log_space_[static_cast<std::size_t>(axis)] -
                                (static_cast<std::uint32_t>(std::bit_width(h)) - 1));
  }
  [[nodiscard]] std::uint32_t lo(int axis, std::uint32_t h) const {
    const std::uint32_t first = std::bit_floor(h);
    return (h - first) * range_size(axis, h);
  }
  [[nodiscard]] std::uint32_t median(int axis, std::uint32_t h) const {
    return lo(axis, h) + range_size(axis, h) / 2;
  }
  /// The ranges of T_i with at least two labels (the elements): h < U_i.
  [[nodiscard]] std::uint32_t space(int axis) const {
    return std::uint32_t{1} << log_space_[static_cast<std::size_t>(axis)];
  }
  /// end_i(L): the point at the first occupied label >= L of A_i, or the last point when there
  /// is none (kNoIndex when A_i is empty).
  [[nodiscard]] std::uint32_t end_point(int axis, std::size_t label) const;
  /// The points whose coordinates bound range h on axis i: end_i(lo(h)) and end_i(hi(h) + 1).
  [[nodiscard]] std::uint32_t lo_point(int axis, std::uint32_t h) const {
    return end_point(axis, lo(axis, h));
  }
  [[nodiscard]] std::uint32_t top_point(int axis, std::uint32_t h) const {
    return end_point(axis, std::size_t{lo(axis, h)} + range_size(axis, h));
  }
  [[nodiscard]] std::uint32_t element(int axis, std::uint32_t h) const {
    return static_cast<std::uint32_t>(axis) * table_size_ + h;
  }
  /// A point's label on an axis: its slot in the sort.
  [[nodiscard]] std::uint32_t rank_of(std::uint32_t point, int axis) const {
    return sorts_[static_cast<std::size_t>(axis)].rank(point);
  }
  /// Appends the elements of axis `axis` with an end label L in [first, last] (last <= U_i):
  /// the ranges that start at L or end just before it.
  void ends_in(int axis, std::size_t first, std::size_t last,
               std::vector<std::uint32_t>& out) const;
  /// Appends the elements whose end point is the point at slot j of A_axis.
  void ends_at_slot(int axis, std::size_t j, std::vector<std::uint32_t>& out) const;
  /// The split axis of an S node with these ranges: a live region's stored axis, otherwise its
  /// longer side just after now (fresh_axis).
  [[nodiscard]] int split_axis(const State& s) const;
  [[nodiscard]] int fresh_axis(const State& s) const;
  /// The side of the S node's split on `axis` that `point` lies on.
  [[nodiscard]] int side_of(std::uint32_t point, const State& s, int axis) const;
  [[nodiscard]] static State child_state(State s, int axis, int side);

  void rebuild_tables();
  void set_length(std::uint32_t e);
  void rebuild_lengths();
  // Live regions: records found by their ranges (region_keys_), linked into one list per side
  // element, each with its certificate (payload: the record).
  [[nodiscard]] std::uint32_t find_region(const State& s) const;
  /// A region's two sides as elements: {the shorter (off its axis), the longer (on its axis)}.
  [[nodiscard]] std::array<std::uint32_t, 2> sides(const Region& g) const;
  void add_region(const State& s);
  void remove_region(const State& s);
  void clear_regions();
  void schedule_region(std::uint32_t r);
  /// f(s) for the nodes s of S with two points or more from s (on the edge above trie node
  /// `node`, or node's own state) down through node's subtree, parents first.
  template <class F>
  void for_each_live(std::uint32_t node, State s, F&& f) const;
  /// The nodes of S on the edge from `from` down to `to` (both included), `to` below `from`.
  template <class F>
  void for_each_on_path(State from, const State& to, F&& f) const;
  /// L_b - L_a as the exact combination of the four end motions.
  [[nodiscard]] MotionCombination length_difference(std::uint32_t a, std::uint32_t b) const;
  /// sign(L_a - L_b) just after t / at t, exactly (one polynomial each when both are exact).
  int compare_lengths_after(std::uint32_t a, std::uint32_t b, Time t, PredicateStats* stats) const;
  [[nodiscard]] int compare_lengths_at(std::uint32_t a, std::uint32_t b, Time t) const;
  bool side_before_after_now(std::uint32_t a, std::uint32_t b) const;
  EventKind process_region(const Event& event);
  /// A real side-length event at the node v of S (ranges v, skeleton depth `depth`, points those
  /// of trie node u): the A/B/C/D regrouping of Figure 3, O(1) trie nodes. False (nothing
  /// changed) when v's children do not split on the other axis before and after.
  bool regroup(std::uint32_t u, const State& v, std::uint32_t depth, int old_axis, int new_axis);
  template <class ItemSpan>
  std::uint32_t assemble(ItemSpan items, State s, std::uint32_t depth, std::uint32_t parent,
                         int first_axis, int second_axis, int level);
  /// Rebuilds the subtree of T below v from its points. O(|P(v)| log n).
  void rebuild_below(std::uint32_t u, const State& v, std::uint32_t depth);

  std::uint32_t new_node(Trie& t) const;
  void set_chain(Trie& t, std::uint32_t node) const;
  /// node's representative changed: the ancestors whose leftmost leaf is below it take it.
  void reps_up(Trie& t, std::uint32_t node) const;
  std::uint32_t build(Trie& t, std::vector<std::uint32_t>& points, std::size_t begin,
                      std::size_t end, State s, std::uint32_t depth, std::uint32_t parent) const;
  void build_all(Trie& t) const;
  void rebuild();
  /// The sorts' layout generations, taken before a change for follow_sorts().
  [[nodiscard]] std::array<std::uint64_t, 2> layout_generations() const;
  /// An insert, remove or update of `index` (kind 0, 1, 2) after the sorts changed: in place
  /// unless a sort was laid out again.
  void follow_sorts(std::uint32_t index, int kind, const std::array<std::uint64_t, 2>& generation);
  /// The point's label on `axis` went from `was` to `now`: its path in S stays the same (the
  /// label changed only below its leaf).
  [[nodiscard]] bool keeps_path(std::uint32_t point, int axis, std::size_t was,
                                std::size_t now) const;
  /// A live region's longer side is now its other side: it splits on that one (the regrouping
  /// of a longest-side event; false when it was rebuilt below instead).
  bool flip_region(std::uint32_t r);
  void erase(std::uint32_t point);
  void insert_point(std::uint32_t point);
  /// The trie node whose points are P(v) for the node v of S with ranges `target` and two
  /// points or more, and v's depth; kNoIndex when there is none.
  std::uint32_t locate(const State& target, std::uint32_t& depth_out) const;
  /// f(leaf) for every leaf of node's subtree (node itself when it is one), left to right.
  template <class F>
  void for_each_leaf(const Trie& t, std::uint32_t node, F&& f) const;
  /// The points of node's subtree, left to right, appended to out.
  void collect(const Trie& t, std::uint32_t node, std::vector<std::uint32_t>& out) const;
  void release(Trie& t, std::uint32_t node) const;
  bool same(const Trie& a, std::uint32_t x, const Trie& b, std::uint32_t y) const;

  /// Coordinate bounds of region(state) at t, enlarged by the evaluation error bounds.
  /// A cell's box in the plane: per axis [lo, hi].
  using CellBox = std::array<std::array<double, 2>, 2>;
  [[nodiscard]] CellBox region_box(const State& s, Time t) const;
  /// region_box() of a trie node, cached per query time: the boxes stay valid while the time
  /// and the structure (no event, insert, remove, update or rebuild since: mutations_) do, so
  /// the queries at one time share the upper levels' boxes. boxes_at(t) first, once per query.
  void boxes_at(Time t);
  [[nodiscard]] const CellBox& node_box(std::uint32_t node, Time t);
  [[nodiscard]] std::array<double, 2> point_at(std::uint32_t p, Time t, double& error) const;
  [[nodiscard]] int compare_to(const MotionPolynomial& p, double x, Time t) const;
  /// d(point, q) at t and a bound `error` on each coordinate's (the bounds' 2 error covers d's).
  [[nodiscard]] double leaf_distance(std::uint32_t point, std::array<double, 2> q, Time t,
                                     double& error) const;
  /// The same from the point's position p and bound `error` as point_at() gives them.
  [[nodiscard]] double leaf_distance_from(std::uint32_t point, std::array<double, 2> p,
                                          std::array<double, 2> q, Time t, double& error) const;
  /// leaf_distance_from()'s answer where the filtered position's bound is too coarse for it:
  /// from the motions (compensated differences, else the exact squared distance).
  [[nodiscard]] double refined_distance(std::uint32_t point, std::array<double, 2> q, Time t,
                                        double& error) const;
  void finish_query(std::uint64_t visits);
  /// nearest()'s, farthest()'s and k_nearest()'s search over the regions, with `search` what is
  /// sought (longest_side_kdtree.cpp: NearestSearch, FarthestSearch, KNearestSearch): its best
  /// point, if it has one.
  template <class Search>
  std::optional<std::uint32_t> search(std::array<double, 2> q, Time t, Search& search);
  template <class Search>
  void search_below(std::uint32_t node, std::array<double, 2> q, Time t, Search& search,
                    std::uint64_t& visits);
  /// approx_range()'s and range()'s depth-first search over the trie: visit(node, v, out) reports
  /// what it can of node v into out and is true when v's children are to be searched; returns out
  /// sorted.
  template <class Visit>
  std::vector<std::uint32_t> depth_first(Visit&& visit);
  void require_point_query(const char* where, std::array<double, 2> q, double eps, Time t) const;
  void require_shape_query(const char* where, const Shape& shape, double eps, Time t) const;

  NearestCandidates nearest_;  // a k_nearest query's candidates (storage reused)
  /// node_box()'s cache: a node's box is current when its stamp is box_round_.round, which moves on
  /// at a new query time or after a change (mutations_ counts events and changes).
  struct CachedBox {
    CellBox box{};
    std::uint64_t stamp = 0;
    /// A bucket's points at this time: the first in bucket_points_ (kNoIndex: not yet); read
    /// with the box (an entry is 48 bytes with it, 40 without).
    std::uint32_t bucket = kNoIndex;
  };
  /// The searches scan a subtree of at most this many leaves (a bucket) instead of descending it:
  /// its points' positions at the query time, filled by the first query that reaches it at that
  /// time (bucket_at()) and read one after the other by the next ones.
  static constexpr std::uint32_t kBucket = 16;
  /// A point's position at the buckets' time: point_at()'s values and bound.
  struct BucketPoint {
    double x = 0.0, y = 0.0, error = 0.0;
    std::uint32_t point = kNoIndex;
  };
  /// The buckets' points of the current round (cleared when box_round_ starts a new one).
  std::vector<BucketPoint> bucket_points_;
  /// The bucket at node (leaves <= kBucket, its box current), filled at t if it is not yet.
  [[nodiscard]] const BucketPoint* bucket_at(std::uint32_t node, Time t);
  /// Small pages: the first query fills it lazily, and a huge page's first touch could stall it
  /// for milliseconds (the kernel compacting memory for it).
  std::vector<CachedBox> box_cache_;
  QueryRound box_round_;         // the boxes' and buckets' round (core/query_round.hpp)
  std::uint64_t mutations_ = 0;  // events and changes
  const MotionTable& motions_;
  TableSync sync_{motions_};  // told of every change to the table
  Simulator& sim_;
  const Scheduler& scheduler_;
  std::uint32_t region_owner_ = 0;     // the region certificates' events
  StructureGroup<KineticSort> sorts_;  // one per axis
  std::size_t n_ = 0;
  std::uint32_t table_size_ = 0;  // element ids: axis * table_size_ + h, h < U_axis <= table_size_
  std::array<std::uint32_t, 2> log_space_{};  // log2 U_i
  std::vector<std::uint32_t> moved_;          // a local change: the points to reinsert
  std::vector<std::uint64_t> moved_mark_;
  std::uint64_t moved_round_ = 0;
  std::vector<State> flip_candidates_;  // a local change: the live regions with a changed side
  // Elements (axis * table_size_ + h): their lengths.
  std::vector<MotionPolynomial> length_;
  std::vector<std::uint8_t> length_exact_;
  /// The end motions of each length (top, lo): the exact length is ends_[e][0] - ends_[e][1].
  std::vector<std::array<MotionPolynomial, 2>> ends_;
  std::vector<Region> regions_;
  std::vector<std::uint32_t> free_regions_;
  PairSet region_keys_;                     // {h_0, table_size_ + h_1} of the live regions
  std::vector<std::uint32_t> region_of_;    // the record of region_keys_.keys()[k]
  std::vector<std::uint32_t> region_head_;  // per element: the first live region it is a side of
  std::vector<std::uint32_t> changed_;      // scratch: the elements an ordering event moves
  std::unique_ptr<Trie> trie_;              // T
  std::vector<std::uint32_t> leaf_of_;
  /// A point's two motions as the searches read them at the leaves, when both have degree <= 1:
  /// the table's coefficients and origins, copied (c1 NaN: a higher degree, read from the table).
  /// One line per point instead of the table's two 72-byte entries.
  struct alignas(64) LeafMotion {
    std::array<double, 2> c0{}, c1{}, origin{};
  };
  HugeVector<LeafMotion> leaf_motion_;
  /// leaf_motion_ of `point` from the table (after its insert or update, and at a rebuild).
  void set_leaf_motion(std::uint32_t point);
  /// The copy of `point`'s motions (numeric::linear_parts() per axis).
  [[nodiscard]] LeafMotion leaf_motion_of(std::uint32_t point) const;
  LongestSideCounters counters_;
};

static_assert(KineticStructure<LongestSideKdTree>);

}  // namespace kinetic
