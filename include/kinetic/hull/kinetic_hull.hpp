#pragma once
// The kinetic convex hull in the plane (Basch, Guibas, Hershberger, "Data structures for mobile
// data": kinetic divide and conquer). The upper and the lower hull are each kept in a balanced
// binary tree over the points: a node's chain is the merge of its two children's chains, and the
// merge is the envelope sweep of the lecture notes, certified by the comparisons it makes:
//  - end certificates: which child's leftmost (rightmost) point is more to the left (right), ties
//    by height then id;
//  - x-certificates: the slope order of two edges of different children that are neighbours in
//    the merged slope order (a product of motion differences, 4 points);
//  - y-certificates: every edge against the other child's vertex for that slope (an orientation,
//    3 points).
// Certificates are polynomials built exactly from the motions (ProductCombination); the scheduler
// decides them (robust: the pretended sign of CROP, EVENTTIME on the same result; classic: exact
// sign just after now, floating-point roots, the failed certificate trusted).
//
// This is the first step of the structure (docs/hull.md states what is left): a node whose
// certificate fails is re-merged in full from its children's chains, and so is each ancestor whose
// child chain changed. The certificate set is that of the sweep (every edge has its
// y-certificate), not yet BGH's reduced set with s-certificates, so a point may take part in
// many certificates and an event costs O(|chain| log n) rather than polylogarithmic time.
//
// The `hull` answer is the exact hull, at now, of the two root chains (the candidates): a convex
// polygon of live points whatever the scheduler did, and the true hull whenever every certificate
// holds at now.
//
// Motions of degree <= 3 (an orientation of degree-k motions has degree 2k <= 6).

#include <cstdint>
#include <memory>
#include <span>
#include <unordered_map>
#include <utility>
#include <vector>

#include "kinetic/core/description.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/preconditions.hpp"
#include "kinetic/core/predicates.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/structure.hpp"

namespace kinetic {

struct HullCounters : ChangeCounters {
  std::uint64_t events = 0;
  std::uint64_t rebuilds = 0;
  std::uint64_t merges = 0;     ///< node merges recomputed, all causes
  std::uint64_t decisions = 0;  ///< certificates decided by the scheduler in merges
  std::uint64_t kept = 0;       ///< certificates a re-merge kept from the node's previous merge
  std::uint64_t queries = 0;
  /// Queries answered by the monotone chain on the candidates (collinear or coincident points
  /// at t, or certificates pending near an event) instead of reading the root chains.
  std::uint64_t query_fallbacks = 0;
  /// Robust scheduling: new certificates whose failure time was <= t_curr (Lemma 4 says none).
  std::uint64_t scheduled_not_in_future = 0;
};

/// Certificates checked against their exact signs at one time (audit_certificates()).
struct HullCertificateAudit {
  std::size_t checked = 0;
  std::size_t wrong = 0;  ///< recorded sign != exact sign at t
  /// Of those, certificates whose polynomial has no root within `window` of t (must be 0).
  std::size_t wrong_without_root_near = 0;
};

class KineticHull {
 public:
  /// What the structure is and takes (core/description.hpp): the registry, the CLI and the
  /// Python class read it.
  [[nodiscard]] static StructureDescription description();

  /// Highest motion degree taken: orientation certificates have degree 2 * 3 = 6, CROP's limit.
  static constexpr int kMaxDegree = 3;

  /// Points are the table's objects (dimension 2).
  KineticHull(const MotionTable& points, Simulator& simulator, const Scheduler& scheduler);
  ~KineticHull();
  KineticHull(const KineticHull&) = delete;
  KineticHull& operator=(const KineticHull&) = delete;

  void initialize();
  EventKind process(const Event& event);
  void insert(std::uint32_t index);
  void remove(std::uint32_t index);
  void motion_changed(std::uint32_t index);

  /// The convex hull at now: point indices counter-clockwise from the lowest-then-leftmost;
  /// points in the relative interior of an edge are not vertices, of points at the same position
  /// at now the smallest id is named (identical motions by their groups; different motions that
  /// meet at a vertex by a search down the tree of chains, name_smallest_coincident(), at times
  /// when the structure changed). Exact on the candidates (the root chains): O(h) exact
  /// predicates when every root certificate holds (the chains are merged in order), O(h log h)
  /// otherwise; plus O(log^2 n) filtered comparisons per vertex at a time a merge ran.
  [[nodiscard]] std::vector<std::uint32_t> hull();
  /// The root chains' points (upper then lower), the candidates hull() is computed from.
  [[nodiscard]] std::vector<std::uint32_t> candidates() const;

  [[nodiscard]] std::size_t size() const { return size_; }
  [[nodiscard]] const HullCounters& counters() const { return counters_; }
  [[nodiscard]] NamedCounters named_counters() const;
  [[nodiscard]] bool initialized() const { return sync_.initialized(); }
  /// Certificates recorded (the comparisons of every node's merge).
  [[nodiscard]] std::size_t certificates() const;
  [[nodiscard]] std::size_t certificates_per_object_max() const;
  /// Invariants: the structure has been told every change of the table; every chain is the
  /// merge of its children's chains replayed from the recorded
  /// certificate signs; chains hold live points; every certificate with a finite failure time
  /// has its event queued and no other event of this structure exists. O(total chain length).
  [[nodiscard]] bool validate() const;
  /// Every recorded certificate against its exact sign at t: how many are wrong, and how many of
  /// those have no root of their polynomial within `window` of t (0 for a correct structure at
  /// now: robust scheduling only misjudges certificates within a CROP cell of a root).
  [[nodiscard]] HullCertificateAudit audit_certificates(Time t, double window) const;

  /// Refuses a motion the hull cannot certify (degree > kMaxDegree, or not 2-D), naming `where`
  /// and the object's id.
  static void require_motion(const MotionTable& points, std::uint32_t index, const char* where);
  /// The degree check for a motion not yet in a table (one polynomial per coordinate) of object
  /// `id`; the table checks the number of coordinates.
  static void require_motion(std::span<const MotionPolynomial> motion, ObjectId id,
                             const char* where);

 private:
  // One comparison of a node's merge and a certificate (a test with its event): laid out in
  // src/hull/kinetic_hull.cpp (not part of the API).
  struct Test;
  struct Certificate;
  struct Decider;
  struct Replay;
  /// A test of `kind` on the points a, b, c, d (no sign).
  [[nodiscard]] static Test test_of(int kind, std::uint32_t a, std::uint32_t b, std::uint32_t c,
                                    std::uint32_t d);
  [[nodiscard]] bool is_leaf(std::size_t node) const { return node >= capacity_; }
  /// sign(orient(a, b, c)) at t, exactly (> 0: a counter-clockwise turn).
  [[nodiscard]] int turn_at(std::uint32_t a, std::uint32_t b, std::uint32_t c, Time t) const;
  /// Rotates a counter-clockwise polygon to start at its lowest-then-leftmost vertex at t
  /// (`at`: the vertices' filtered positions at t, in the polygon's order, when known).
  void start_at_lowest(std::vector<std::uint32_t>& polygon, Time t,
                       const std::vector<FilteredPoint>* at = nullptr) const;
  /// The counter-clockwise polygon (from the lowest-then-leftmost vertex) bounded by an upper
  /// and a lower chain (left to right, point indices) when, at t, both run strictly left to
  /// right between the same two ends and turn strictly (clockwise, counter-clockwise): then it
  /// is the convex hull of their points. Empty otherwise, or for fewer than three vertices.
  [[nodiscard]] std::vector<std::uint32_t> convex_polygon_of(
      const std::vector<std::uint32_t>& upper, const std::vector<std::uint32_t>& lower,
      Time t) const;
  /// Replaces each vertex of `polygon` (a hull at t) by the point with the smallest id among the
  /// points at its position at t. A point at the position of a hull vertex is a vertex of the
  /// hull of every subset holding it and no other point there, so at every node on its path
  /// some point at that position is in the node's chain (upper or lower): the search descends
  /// into the children whose chains hold one, found by galloping on x at t (a chain is sorted by
  /// x on an interval next to t, hence weakly at t). O(log^2 n) per vertex, so hull() runs it
  /// only when a merge ran at t: a point hidden at a vertex's position at t (in no root chain)
  /// that is not there just before or just after t, or that moves linearly relative to the
  /// vertex, enters or leaves the hull at t, which is an event at t. What it leaves: a point on
  /// a curved path touching a vertex's position from inside at an instant with no event.
  void name_smallest_coincident(std::vector<std::uint32_t>& polygon, Time t) const;
  /// Re-merges node v on `side` (0 upper, 1 lower) from its children; true when its chain changed.
  bool merge(std::size_t v, int side);
  /// The scheduler's decision of a certificate (its sign and failure time) at now.
  [[nodiscard]] Scheduler::SignDecision decide(const Certificate& c);
  void cancel_node(std::size_t v, int side);
  /// Unschedules and frees one certificate.
  void release(std::uint32_t id);
  /// Marks every certificate on the point's leaf path that involves it as out of date.
  void forget_tests_of(std::uint32_t index);
  /// Lays the tree out over `capacity` slots with `objects` in the first ones and merges every
  /// node (cancelling every certificate before).
  void lay_out(std::size_t capacity, std::vector<std::uint32_t> objects);
  /// lay_out() of the current points (counted in `rebuilds`).
  void rebuild(std::size_t capacity);
  [[nodiscard]] std::uint32_t allocate_certificate();

  const MotionTable& points_;
  TableSync sync_{points_};
  Simulator& sim_;
  const Scheduler& scheduler_;
  std::uint32_t owner_;
  std::size_t capacity_ = 0;
  std::size_t size_ = 0;
  /// chains_[side][node]: the hull chain of the node's points, left to right (side 1: the upper
  /// hull of (x, -y), i.e. the lower hull).
  std::vector<std::vector<std::uint32_t>> chains_[2];
  /// Certificates of each node's merge, in the order the merge decided them.
  std::vector<std::vector<std::uint32_t>> node_certificates_[2];
  /// The test and sign of each of those certificates, in the same order.
  std::vector<std::vector<Test>> node_tests_[2];
  std::vector<Certificate> certificates_;
  std::vector<std::uint32_t> free_certificates_;
  /// merge()'s scratch: the node's previous certificates and their tests, which of them it
  /// kept, the merged chain.
  std::vector<std::uint32_t> previous_ids_;
  std::vector<Test> previous_tests_;
  std::vector<char> used_;
  std::vector<std::uint32_t> merged_;
  std::vector<std::uint32_t> leaf_of_;  ///< point index -> leaf node (0: absent)
  std::vector<std::uint32_t> free_;     ///< free leaf nodes
  std::size_t queued_ = 0;              ///< this structure's events in the queue
  /// Points with identical motions (the same origins and coefficients), grouped: the hull
  /// reports the smallest id of a group, whichever member the chains hold. Points are bucketed by
  /// a hash of their motion (`motion_hash_`, kept per point so a point leaves the bucket of the
  /// motion it had); a bucket holds the groups whose motions share the hash.
  [[nodiscard]] std::uint64_t motion_hash(std::uint32_t index) const;
  [[nodiscard]] bool same_motion(std::uint32_t a, std::uint32_t b) const;
  /// Groups every live point at once (sorting by hash, motion and id: O(n log n) whatever the
  /// groups' sizes).
  void group_all(const std::vector<std::uint32_t>& objects);
  void join_group(std::uint32_t index);   ///< O(size of its bucket)
  void leave_group(std::uint32_t index);  ///< O(size of its bucket)
  std::unordered_multimap<std::uint64_t, std::uint32_t> buckets_;
  std::vector<std::uint64_t> motion_hash_;  ///< point index -> its motion's hash
  std::vector<std::uint32_t> representative_;
  /// Classic scheduling: the certificate whose event is being processed holds the other way now
  /// (a traditional KDS trusts its event); trusting_ is false otherwise.
  bool trusting_ = false;
  std::unique_ptr<Certificate> trusted_;  ///< allocated once, by the constructor
  HullCounters counters_;
  Time last_merge_time_ = -kTimeInfinity;  ///< when merge() last ran
  /// name_smallest_coincident()'s scratch (Target: laid out in src/hull/kinetic_hull.cpp).
  struct Target;
  mutable std::vector<std::uint32_t> slot_of_;  ///< representative -> its place in the polygon
  mutable std::vector<std::vector<Target>> target_levels_;  ///< the search's targets per depth
};

static_assert(KineticStructure<KineticHull>);

}  // namespace kinetic
