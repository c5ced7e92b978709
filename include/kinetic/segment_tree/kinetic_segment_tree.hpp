#pragma once
// The kinetic segment tree (the KDS lecture notes, "Kinetic Segment Tree"): stabbing queries over
// moving intervals. The 2n endpoint values are kept sorted in an array R (a KineticSort over a
// table whose objects are the endpoints); a segment is the pair of ranks (a_i, b_i) of its ends.
// The tree is a perfect binary tree (heap layout: root 1, children 2v and 2v+1) over the
// elementary intervals EI_j = [R[j], R[j+1]], j = 0..2n-2, at leaves m + j (the array A of the
// notes is implicit: leaf(j) = m + j). Segment s covers the leaves a_s..b_s-1; S(v) is the
// canonical set of node v and L(s) the fragment list of s (the nodes v with s in S(v)), ordered
// left to right.
//
// A swap of R[j] and R[j+1] (a certificate failure) changes, for each of the (at most two)
// segments involved, its leaf range by one leaf at one end (the four cases: a right end moving
// right extends, a left end moving right shrinks, and symmetrically). Extending by leaf j is the
// upward walk of the notes: climb while the brother holds s (the brother is then the end of L(s),
// so the test is O(1)), deleting s from the brothers, and add s at the top. Shrinking is the
// reverse walk down from the end fragment of L(s). Both cost O(h), h the height of the walk,
// which is O(1) on average over j (the Lemma). A segment's own two endpoints meeting (ranks
// a = j, b = j+1 swapped) leaves its leaf range [min, max-1] unchanged.
//
// Inserts, removes and flight-plan updates repair R locally (KineticSort) and rebuild the tree,
// O(n log n) each (counted in `rebuilds`).

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/preconditions.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/structure.hpp"
#include "kinetic/sort/kinetic_sort.hpp"

namespace kinetic {

struct SegmentTreeCounters {
  std::uint64_t swaps = 0;              ///< certificate failures of R (external events)
  std::uint64_t walks = 0;              ///< extend/shrink walks (at most two per swap)
  std::uint64_t walk_height_total = 0;  ///< sum of the heights of those walks (nodes climbed)
  std::uint64_t walk_height_max = 0;
  std::uint64_t own_endpoint_meetings = 0;  ///< swaps of a segment's own two endpoints
  std::uint64_t rebuilds = 0;      ///< full rebuilds of the tree (inserts, removes, updates)
  std::uint64_t ring_resizes = 0;  ///< fragment lists moved to a ring twice or half the size
  std::uint64_t queries = 0;
  std::uint64_t node_visits = 0;  ///< by stabbing queries
};

class KineticSegmentTree {
 public:
  /// `intervals` has dimension 2: coordinate 0 the left end, 1 the right end. The endpoint sort
  /// reserves its owner from the simulator.
  KineticSegmentTree(const MotionTable& intervals, Simulator& simulator,
                     const Scheduler& scheduler);
  ~KineticSegmentTree();
  KineticSegmentTree(const KineticSegmentTree&) = delete;
  KineticSegmentTree& operator=(const KineticSegmentTree&) = delete;

  /// Builds R and the tree from every live interval as just after sim.now(). O(n log n).
  void initialize();
  /// The KDS event handler (a swap in R). O(1) expected, O(log n) worst case.
  EventKind process(const Event& event);

  /// An interval was inserted into / removed from the table / got a new motion there (the table
  /// changes first, then the tree is told).
  /// O(n log n) each (R repaired locally, the tree rebuilt).
  void insert(std::uint32_t index);
  void remove(std::uint32_t index);
  void motion_changed(std::uint32_t index);

  /// Indices (into the interval table) of the intervals containing x at time t (closed
  /// intervals, exact comparisons), ascending by index. Exact when R is sorted at t (no crossing
  /// of two endpoints still pending); with robust scheduling a crossing is processed up to eps
  /// late, and a query in that window may miss or add an interval whose end is within that
  /// motion of x (docs/segment-tree.md, "Stabbing queries").
  /// O(log n + k) plus the sort of the output.
  [[nodiscard]] std::vector<std::uint32_t> stab(double x, Time t);

  /// Throws PreconditionError when the interval with ends `ends` (left, right) has its right end
  /// below its left end somewhere in [from, until] (until may be +infinity): an interval must
  /// never turn inside out. The session checks every interval it is given with it; a search
  /// over the ends' floating-point critical points, certified exactly (find_time_below), so a
  /// dip narrower than their rounding can be missed.
  static void require_interval(const char* where, std::span<const MotionPolynomial> ends, Time from,
                               Time until);

  [[nodiscard]] std::size_t size() const { return segments_.size(); }
  [[nodiscard]] const SegmentTreeCounters& counters() const { return counters_; }
  [[nodiscard]] NamedCounters named_counters() const;
  [[nodiscard]] const KineticSort& endpoint_sort() const { return sort_; }
  /// A node of the tree as a picture needs it: its depth, the leaves it spans (elementary
  /// intervals [R[j], R[j+1]], j = first..last) and its canonical set S(v) (interval indices).
  struct NodeSet {
    int depth = 0;
    std::uint32_t first_leaf = 0, last_leaf = 0;
    std::vector<std::uint32_t> intervals;
  };
  /// The canonical sets of the tree's top `levels` levels, nodes in heap order (root first),
  /// those with an empty set left out. O(nodes + their sets).
  [[nodiscard]] std::vector<NodeSet> canonical_sets(int levels) const;
  /// The endpoints as objects (dimension 1): R holds indices of this table.
  [[nodiscard]] const MotionTable& endpoint_table() const { return endpoints_; }
  /// Total number of fragments (sum of |L(s)|), the tree's size measure (O(n log n)).
  [[nodiscard]] std::size_t fragments() const;
  [[nodiscard]] std::size_t fragments_max() const;
  [[nodiscard]] int height() const { return levels_; }
  [[nodiscard]] std::size_t certificates() const { return sort_.certificates(); }
  /// One certificate per adjacent pair of R; an interval's two endpoints take part in <= 4.
  [[nodiscard]] std::size_t certificates_per_object_max() const {
    return 2 * sort_.certificates_per_object_max();
  }

  /// Every canonical set equals a fresh build's; every fragment list is ordered left to right
  /// and matches the canonical sets (back-pointers both ways); R agrees with the ranks. O(n log n).
  /// initialize() was called.
  [[nodiscard]] bool initialized() const { return sync_.initialized(); }
  [[nodiscard]] bool validate() const;

 private:
  // The records of S(v) and L(s): private layout, defined in the source file.
  struct Entry;
  struct Fragment;

  void rebuild();
  void add_endpoints(std::uint32_t index);
  /// The canonical nodes of the leaves [a, b] below v (spanning [lo, hi]), left to right.
  void decompose(std::vector<std::uint32_t>& out, std::uint32_t v, std::uint32_t lo,
                 std::uint32_t hi, std::uint32_t a, std::uint32_t b);
  [[nodiscard]] std::uint32_t leaf_lo(std::uint32_t s) const;
  [[nodiscard]] std::uint32_t leaf_hi(std::uint32_t s) const;
  void change_range(std::uint32_t s, std::uint32_t old_lo, std::uint32_t old_hi);
  void extend_right(std::uint32_t s, std::uint32_t j);
  void shrink_right(std::uint32_t s, std::uint32_t j);
  void extend_left(std::uint32_t s, std::uint32_t j);
  void shrink_left(std::uint32_t s, std::uint32_t j);
  void note_walk(std::uint64_t h);
  // Ring buffer L(s), sized by its contents.
  static constexpr std::uint8_t kMinRingClass = 2;  // rings of at least 4 fragments
  [[nodiscard]] std::uint32_t ring_capacity(std::uint32_t s) const;
  std::uint32_t allocate_ring(std::uint8_t size_class);
  void resize_ring(std::uint32_t s, std::uint8_t size_class);
  void shrink_ring_if_sparse(std::uint32_t s);
  [[nodiscard]] Fragment& frag(std::uint32_t s, std::uint32_t k);
  [[nodiscard]] const Fragment& frag(std::uint32_t s, std::uint32_t k) const;
  [[nodiscard]] std::uint32_t slot_of(std::uint32_t s, std::uint32_t k) const;
  void push_back(std::uint32_t s, std::uint32_t node);
  void push_front(std::uint32_t s, std::uint32_t node);
  void pop_back(std::uint32_t s);
  void pop_front(std::uint32_t s);
  void attach(std::uint32_t s, std::uint32_t slot, std::uint32_t node);
  void detach(std::uint32_t node, std::uint32_t pos);
  [[nodiscard]] std::uint32_t node_first_leaf(std::uint32_t v) const;
  [[nodiscard]] std::uint32_t node_last_leaf(std::uint32_t v) const;
  [[nodiscard]] std::vector<std::vector<std::uint32_t>> fresh_sets() const;

  const MotionTable& intervals_;
  TableSync sync_{intervals_};  // told of every change to the table
  Simulator& sim_;
  MotionTable endpoints_;                   // objects: endpoints (id 2*id + side), dimension 1
  KineticSort sort_;                        // R
  std::vector<std::uint32_t> endpoint_of_;  // interval index * 2 + side -> endpoint index
  std::vector<std::uint32_t> owner_of_;     // endpoint index -> interval index * 2 + side
  std::vector<std::uint32_t> segments_;     // live interval indices
  // Per interval index: L(s) as a ring of 2^ring_class_ fragments at ring_[ring_base_..].
  std::vector<std::uint32_t> ring_head_;
  std::vector<std::uint32_t> ring_size_;
  std::vector<std::uint32_t> ring_base_;
  std::vector<std::uint8_t> ring_class_;
  std::vector<Fragment> ring_;
  std::array<std::vector<std::uint32_t>, 32> free_rings_;  // free blocks by size class
  std::uint32_t m_ = 1;                                    // leaves (a power of two >= 2n - 1)
  int levels_ = 0;                                         // log2(m)
  std::vector<std::vector<Entry>> sets_;                   // S(v), v in [1, 2m)
  SegmentTreeCounters counters_;
};

static_assert(KineticStructure<KineticSegmentTree>);

}  // namespace kinetic
