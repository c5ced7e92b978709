#pragma once
// The kinetic segment tree (the KDS lecture notes, "Kinetic Segment Tree"): stabbing queries over
// moving intervals. The 2n endpoint values are kept sorted in an array R (a KineticSort over a
// table whose objects are the endpoints), in its gapped layout: R has U slots (a power of two),
// some empty, and a segment is the pair of slots (a_i, b_i) of its ends (labels that keep the
// order, not ranks). The tree is a perfect binary tree (heap layout: root 1, children 2v and
// 2v+1) over the elementary intervals EI_j = [R[j], R[next(j)]], j = 0..U-1, at leaves U + j (the
// array A of the notes is implicit: leaf(j) = U + j); an empty slot j is an elementary interval
// of length zero at the value of the next key. Segment s covers the leaves a_s..b_s-1; S(v) is the
// canonical set of node v and L(s) the fragment list of s (the nodes v with s in S(v)), ordered
// left to right.
//
// A swap of R[j] and R[k] (k = next(j): j + 1 unless j ends its segment of the gapped array; a
// certificate failure) changes, for each of the (at most two) segments involved, its leaf range
// at one end by k - j leaves, one leaf at a time (the four cases: a right end moving right
// extends, a left end moving right shrinks, and symmetrically). Extending by leaf j is the
// upward walk of the notes: climb while the brother holds s (the brother is then the end of L(s),
// so the test is O(1)), deleting s from the brothers, and add s at the top. Shrinking is the
// reverse walk down from the end fragment of L(s). Both cost O(h), h the height of the walk,
// which is O(1) on average over j (the Lemma). A segment's own two endpoints meeting (slots
// a = j, b = k swapped) leaves its leaf range [min, max-1] unchanged.
//
// Inserts, removes and flight-plan updates are local: the sort places or takes out the two
// endpoints, shifting at most a segment of R (and, amortized, O(log^2 n) keys when a window of
// R is spread); every interval with an endpoint that moved gets its leaf range adjusted by the
// same walks (or, when it moved farther than the tree is high, L(s) decomposed again), and the
// interval itself is decomposed (O(log n)) or taken out of its canonical sets. Only when R is
// laid out again (U doubled or halved, every Theta(n) inserts or removes) is the tree rebuilt,
// O(n log n), counted in `rebuilds`.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "kinetic/core/description.hpp"
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
  std::uint64_t rebuilds = 0;  ///< full rebuilds of the tree (initialize, R laid out again)
  std::uint64_t refits = 0;    ///< leaf ranges adjusted for endpoints an insert / remove moved
  std::uint64_t redecompositions = 0;  ///< fragment lists decomposed again (far moves, updates)
  std::uint64_t ring_resizes = 0;      ///< fragment lists moved to a ring twice or half the size
  std::uint64_t queries = 0;
  std::uint64_t node_visits = 0;  ///< by stabbing queries
};

class KineticSegmentTree {
 public:
  /// What the structure is and takes (core/description.hpp): the registry, the CLI and the
  /// Python class read it.
  [[nodiscard]] static StructureDescription description();

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
  /// changes first, then the tree is told). O(log n) comparisons and walks, plus O(log^2 n)
  /// amortized moved endpoints and their walks (see the header comment).
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
  /// A node of the tree as a picture needs it: its depth, the leaves it spans as ranks of R
  /// (elementary intervals [R[j], R[j+1]] of the keys in order, j = first..last) and its
  /// canonical set S(v) (interval indices).
  struct NodeSet {
    int depth = 0;
    std::uint32_t first_leaf = 0, last_leaf = 0;
    std::vector<std::uint32_t> intervals;
  };
  /// The canonical sets of the tree's top `levels` levels, nodes in heap order (root first),
  /// those with an empty set or spanning only empty slots of R left out. O(U + their sets).
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
  /// Room for interval indices below the table's capacity.
  void grow();
  /// L(s) from nothing (a fresh ring): the canonical nodes of its leaf range.
  void decompose_into_ring(std::uint32_t s);
  /// L(s) emptied and its ring freed.
  void clear_ring(std::uint32_t s);
  /// The leaf range of s follows its endpoints' current slots: walks, or L(s) decomposed again.
  void refit(std::uint32_t s);
  /// After a change of R: the tree rebuilt if R was laid out again, else refit() for every
  /// interval with a moved endpoint (other than `own`, whose caller handles it).
  void follow_sort(std::uint64_t generation_before, std::uint32_t own);

  /// The canonical nodes of the leaves [a, b] below v (spanning [lo, hi]), left to right.
  void decompose(std::vector<std::uint32_t>& out, std::uint32_t v, std::uint32_t lo,
                 std::uint32_t hi, std::uint32_t a, std::uint32_t b);
  [[nodiscard]] std::uint32_t leaf_lo(std::uint32_t s) const;
  [[nodiscard]] std::uint32_t leaf_hi(std::uint32_t s) const;

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
  std::vector<std::uint32_t> segment_at_;   // interval index -> its place in segments_
  // Per interval index: the leaf range L(s) covers (a_s .. b_s - 1) as last fitted.
  std::vector<std::uint32_t> range_lo_;
  std::vector<std::uint32_t> range_hi_;
  std::vector<std::uint32_t> touched_;        // follow_sort: the intervals to refit
  std::vector<std::uint32_t> nodes_scratch_;  // decompose_into_ring
  std::vector<std::uint64_t> touched_mark_;
  std::uint64_t touch_round_ = 0;
  std::uint64_t generation_ = 0;  // sort_.layout_generation() the tree was built for
  // Per interval index: L(s) as a ring of 2^ring_class_ fragments at ring_[ring_base_..].
  std::vector<std::uint32_t> ring_head_;
  std::vector<std::uint32_t> ring_size_;
  std::vector<std::uint32_t> ring_base_;
  std::vector<std::uint8_t> ring_class_;
  std::vector<Fragment> ring_;
  std::array<std::vector<std::uint32_t>, 32> free_rings_;  // free blocks by size class
  std::uint32_t m_ = 1;                                    // leaves: the slots of R
  int levels_ = 0;                                         // log2(m)
  std::vector<std::vector<Entry>> sets_;                   // S(v), v in [1, 2m)
  SegmentTreeCounters counters_;
};

static_assert(KineticStructure<KineticSegmentTree>);

}  // namespace kinetic
