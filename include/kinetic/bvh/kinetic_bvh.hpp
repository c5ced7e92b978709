#pragma once
// The kinetic AABB tree (BVH) with its kinetic separation list (Zachmann and Weller, kinetic AABB
// hierarchies and kinetic separation lists; the KDS lecture notes: "the tournament tree as a
// building block for the kinetic box").
//
// The tree. A binary tree over the boxes, built once by median splits (the axis where the
// centers spread most). Each node's box is the bounding box of its leaves, kept exactly at every
// time without refitting: per axis and side, the node keeps the leaf whose side is extreme (a
// kinetic tournament over the tree itself: the winner of a node is the better of its children's
// winners, certified by one comparison of two box sides), 2d certificates per internal node.
//
// The separation list. The self-traversal of the tree (the pairs of nodes whose boxes a
// BVH-vs-BVH test would visit) is kept as a set of node pairs, each in one state:
//  - separated (the front): the two boxes are apart on some axis; one certificate, a side of one
//    below the opposite side of the other. When it fails and no other axis separates them, the
//    pair is expanded;
//  - expanded: the two boxes overlap (2d certificates, one per inequality low <= high); their
//    children pairs are in the set. When one fails, the pair is collapsed back to separated (its
//    descendant pairs leave the set);
//  - contact: two leaves whose boxes overlap (2d certificates): a pair of colliding boxes;
//    entering and leaving this state are the external events contact_begin / contact_end;
//  - self: a node paired with itself (always overlapping): its children pairs are in the set.
// A certificate compares two box sides (each the side of a node's current winner leaf, exact
// combination signs as in core/boxes.hpp); when a winner changes, the certificates watching that
// node side are rescheduled (intrusive watch lists).
//
// colliding_pairs() reads the contact pairs, never traverses. Flight-plan updates, inserts and
// removes are local:
//  - an update re-decides the leaf's ancestors while the box is their extreme, and reschedules
//    the certificates watching the sides it provides;
//  - an insert descends to the leaf whose box grows least in surface measure, puts a new node
//    there with that leaf and the new one as children, re-decides the ancestors, and re-points
//    the pairs of the old leaf to the new node (reclassified: its box contains the leaf's);
//  - a remove replaces the leaf's parent by its sibling, and the parent's pairs by the
//    sibling's; the pairs of the removed leaf go with them.
// Each touches O(depth) tournament nodes and the list pairs of the nodes it changes. The tree is
// rebuilt when its surface-area cost has grown beyond rebuild_ratio() times a fresh build's
// (checked every n events, counted).

#include <array>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "kinetic/core/box_contacts.hpp"
#include "kinetic/core/boxes.hpp"
#include "kinetic/core/description.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/structure.hpp"
#include "kinetic/core/tournament_tree.hpp"

namespace kinetic {

struct BvhCounters : ChangeCounters {
  std::uint64_t tournament_events = 0;  ///< a node's side certificate failed
  std::uint64_t winner_changes = 0;     ///< node sides whose leaf changed
  std::uint64_t separation_events = 0;  ///< a separated pair's certificate failed
  std::uint64_t overlap_events = 0;     ///< an overlapping pair's certificate failed
  std::uint64_t expansions = 0;
  std::uint64_t collapses = 0;
  std::uint64_t contact_begins = 0;
  std::uint64_t contact_ends = 0;
  /// leaf pairs apart just after a change whose closed boxes touch at its time (reported by a
  /// query then, a contact of zero duration)
  std::uint64_t instant_contacts = 0;
  std::uint64_t reschedules = 0;  ///< certificates rescheduled after a winner change
  /// overlap certificates kept at a winner change (still sufficient: see Cert)
  std::uint64_t lazy_keeps = 0;
  std::uint64_t rebuilds = 0;        ///< a subtree or the whole tree rebuilt (the quality policy)
  std::uint64_t local_rebuilds = 0;  ///< of those, a subtree below the root
  std::uint64_t rebuilt_leaves = 0;  ///< the leaves under the rebuilt subtrees, summed
  /// updates that moved the box's leaf (far from its sibling at the change: a jump)
  std::uint64_t moved_leaves = 0;
  std::uint64_t quality_checks = 0;
  std::uint64_t queries = 0;
};

/// The contact set, colliding_pairs() (read off the separation list's contact pairs) and the
/// table's checks are the base's (core/box_contacts.hpp).
class KineticBvh final : public BoxContacts {
 public:
  /// What the structure is and takes (core/description.hpp): the registry, the CLI and the
  /// Python class read it.
  [[nodiscard]] static StructureDescription description();

  /// `boxes`: a table of boxes (core/boxes.hpp: 2d coordinates, d = 1..3).
  KineticBvh(const MotionTable& boxes, Simulator& simulator, const Scheduler& scheduler);
  ~KineticBvh();
  KineticBvh(const KineticBvh&) = delete;
  KineticBvh& operator=(const KineticBvh&) = delete;

  void initialize();
  EventKind process(const Event& event);
  /// Local: a new leaf beside the leaf whose box grows least, its ancestors re-decided, the old
  /// leaf's pairs moved to the new node. Contacts the box has at insertion are not events.
  void insert(std::uint32_t index);
  /// Local: the leaf's sibling takes its parent's place (and its pairs). Its contacts end
  /// without events.
  void remove(std::uint32_t index);
  /// Local: the leaf's ancestors' tournaments and every certificate watching them; a box that
  /// moved far from its sibling (a jump) has its leaf removed and inserted again where it is.
  void motion_changed(std::uint32_t index);

  /// Oracle audit at t: every certificate (the nodes' tournaments and the list's pairs) holds at
  /// t, exactly, so that the answer at t is exact. O(n + list).
  [[nodiscard]] bool audit(Time t) const;

  /// The surface-area cost of the tree at now (sum over internal nodes of their boxes' surface
  /// areas, in double) divided by that of a fresh median build: 1 right after a build.
  [[nodiscard]] double quality_ratio() const;
  /// The policy: checked every max(1024, 4n) events; when quality_ratio() exceeds this, the
  /// smallest subtree whose rebuild alone brings the ratio back to rebuild_target() is rebuilt
  /// (the whole tree when the excess cost is spread over both children of every candidate).
  [[nodiscard]] static constexpr double rebuild_ratio() { return 1.5; }
  [[nodiscard]] static constexpr double rebuild_target() { return 1.25; }
  void set_rebuild_policy(bool on) { rebuild_policy_ = on; }
  /// Check the quality every `events` events (0: the default, max(1024, 4n)); a smaller
  /// interval keeps the tree closer to a fresh build at the cost of more checks (each O(n log n)).
  void set_quality_check_interval(std::uint64_t events) { check_interval_ = events; }

  [[nodiscard]] int dimension() const { return d_; }
  /// Every node's winners are one of its children's (the decisions themselves are the
  /// scheduler's: exact, CROP's pretended signs, or floating point), every
  /// certificate is scheduled and linked where it watches, the pair set is closed (children of
  /// expanded and self pairs present, nothing else), every separated pair separated and every
  /// other pair overlapping in the maintained boxes, the contacts the contact pairs.
  [[nodiscard]] bool validate() const;
  [[nodiscard]] std::size_t certificates() const;
  [[nodiscard]] std::size_t certificates_per_object_max() const;
  [[nodiscard]] const BvhCounters& counters() const { return counters_; }
  [[nodiscard]] NamedCounters named_counters() const;
  /// Pairs in the separation list by state, for reports and tests.
  struct ListSizes {
    std::size_t separated = 0, expanded = 0, contact = 0, self = 0;
  };
  [[nodiscard]] ListSizes list_sizes() const;
  /// A node of the tree as a picture needs it: its depth, and per axis the boxes (table indices)
  /// whose low and whose high side bound it (its tournaments' winners).
  struct NodeSketch {
    int depth = 0;
    std::vector<std::array<std::uint32_t, 2>> sides;  ///< per axis: {low side's box, high's}
  };
  /// The nodes of the tree's top `levels` levels, breadth first from the root (a picture of the
  /// hierarchy's boxes; the boxes' extents follow from the motions). O(nodes listed * d).
  [[nodiscard]] std::vector<NodeSketch> sketch(int levels) const;
  /// A pair of the separation list between two nodes of sketch(levels) (their positions in it),
  /// with its state: "separated" (the front), "expanded", "contact" or "self".
  struct PairSketch {
    std::uint32_t a = 0, b = 0;
    const char* state = "";
  };
  /// The separation list's pairs whose two nodes are both in sketch(levels), depth first from
  /// the root's self pair. O(pairs listed).
  [[nodiscard]] std::vector<PairSketch> sketch_pairs(int levels) const;
  /// Nodes of the tree (2n - 1 for n boxes).
  [[nodiscard]] std::size_t nodes() const;

 private:
  // The records of the tree, of the separation list and of its certificates, and the scratch of
  // a pair's decisions: laid out in src/bvh/kinetic_bvh.cpp (not part of the API).
  enum class State : std::uint8_t;
  struct Node;
  struct PairRecord;
  struct Cert;
  struct PairDecisions;
  struct ChildPairs;

  /// The nodes of the top `levels` levels with their depths, breadth first from the root: the
  /// order of sketch() and the positions sketch_pairs() names.
  [[nodiscard]] std::vector<std::pair<std::uint32_t, int>> sketch_order(int levels) const;

  // The tree and its tournaments (core/tournament_tree.hpp): the entries are boxes, compared on
  // one axis and side (Keys), over the hierarchy's nodes (Topology).
  struct SideKeys {
    const KineticBvh* bvh;
    /// Box a's side beats box b's in slot s (High: not below; Low: not above; identical sides:
    /// a, the left child's), as the scheduler decides it now.
    [[nodiscard]] Scheduler::MaxDecision decide(std::size_t s, std::uint32_t a,
                                                std::uint32_t b) const;
  };
  struct SideTopology {
    const KineticBvh* bvh;
    [[nodiscard]] bool is_leaf(std::size_t s) const;
    [[nodiscard]] bool internal(std::size_t s) const;
    [[nodiscard]] std::array<std::size_t, 2> children(std::size_t s) const;
    [[nodiscard]] std::size_t parent(std::size_t s) const;
  };
  void build();
  std::uint32_t build_range(std::vector<std::uint32_t>& boxes, std::size_t lo, std::size_t hi,
                            std::uint32_t parent);
  [[nodiscard]] std::size_t slot(std::uint32_t node, int axis, BoxSide side) const {
    return (static_cast<std::size_t>(node) * static_cast<std::size_t>(d_) +
            static_cast<std::size_t>(axis)) *
               2 +
           static_cast<std::size_t>(side);
  }
  [[nodiscard]] std::uint32_t key(std::uint32_t node, int axis, BoxSide side) const {
    return BoxEndpointKeys::key(tree_.winner(slot(node, axis, side)), side);
  }
  /// Decides the node's winner for (axis, side) from its children's, as just after now
  /// (Scheduler::decide), and schedules its certificate. Returns whether the winner changed.
  bool decide(std::uint32_t node, int axis, BoxSide side);
  void on_tournament_event(const Event& event);
  /// After node's winner for (axis, side) changed: its ancestors, and the watchers.
  void winner_changed(std::uint32_t node, int axis, BoxSide side);

  // The separation list.
  /// sign(side x - side y) as the scheduler decides it now, with its failure time.
  [[nodiscard]] Scheduler::SignDecision compare(std::uint32_t x, BoxSide sx, std::uint32_t y,
                                                BoxSide sy, int axis) const;
  /// Whether certificate c holds given sign(upper - lower): > 0 for a separated pair, <= 0 (a
  /// low side not above a high side: touching is overlap) for an overlapping one.
  [[nodiscard]] bool holds(std::uint32_t c, int sign) const;
  [[nodiscard]] const Scheduler::SignDecision& decision(std::uint32_t a, std::uint32_t b, int k,
                                                        PairDecisions& out) const;
  /// An axis and direction on which boxes of nodes a and b are strictly apart just after now:
  /// (axis, a_below_b) or axis -1 (then every decision of `out` is known).
  [[nodiscard]] std::pair<int, bool> separating(std::uint32_t a, std::uint32_t b,
                                                PairDecisions& out) const;
  std::uint32_t add_pair(std::uint32_t a, std::uint32_t b);
  void classify(std::uint32_t pair);  // a new pair: separated, or expanded / contact / self
  /// Classifies a pair whose certificates were dropped, with the decisions known so far.
  void reclassify(std::uint32_t pair, PairDecisions& decisions);
  void make_separated(std::uint32_t pair, int axis, bool a_below_b, const PairDecisions& decisions);
  /// Expanded or contact (2d certificates), every decision known.
  void make_overlapping(std::uint32_t pair, const PairDecisions& decisions);
  void expand_children(std::uint32_t pair);
  void collapse(std::uint32_t pair);  // removes the pair's descendants
  void drop_certs(std::uint32_t pair);
  void remove_pair(std::uint32_t pair);
  /// The certificate on decision k of the pair (its decision already made).
  std::uint32_t add_cert(std::uint32_t pair, int k, const Scheduler::SignDecision& decided);
  /// (Re)schedules c from a fresh decision, or from `decided` when given (made at now).
  void schedule_cert(std::uint32_t c, const Scheduler::SignDecision* decided = nullptr);
  void on_cert_event(std::uint32_t c);
  void link(std::uint32_t c, int end);
  void unlink(std::uint32_t c, int end);
  [[nodiscard]] std::size_t watch_slot(std::uint32_t c, int end) const;
  void children_pairs(std::uint32_t a, std::uint32_t b, ChildPairs& out) const;
  /// Calls f(c) for every certificate c watching slot s (the next link read first: f may
  /// reschedule c, which keeps its links).
  template <class F>
  void for_each_watcher(std::size_t s, F&& f) const;
  /// A contact began or ended: counted and logged, unless quiet_.
  void note_contact(bool begins, std::uint32_t box_a, std::uint32_t box_b);
  /// Whether the closed boxes of nodes a and b (their winners' sides) overlap now, exactly;
  /// `first_axis` is checked first (where they are apart just after now, usually strictly).
  [[nodiscard]] bool overlap_now(std::uint32_t a, std::uint32_t b, int first_axis) const;
  /// A pair made separated at a change now: the leaf pairs below it whose closed boxes touch
  /// now (a corner passing a corner) are noted for queries now. Nothing when the pair's own
  /// boxes are apart now (the usual case: one exact comparison decided by its filter).
  void note_touching_now(std::uint32_t pair, int axis);
  void clear_all();
  void maybe_rebuild();
  /// insert() and remove() without their checks and counts (a moved leaf: both).
  void attach_leaf(std::uint32_t index);
  void detach_leaf(std::uint32_t index);
  /// The box at now would make its parent's surface measure more than twice its sibling's.
  [[nodiscard]] bool far_from_sibling(std::uint32_t box) const;
  /// The internal nodes and the leaves' boxes of the subtree of `node`.
  void subtree(std::uint32_t node, std::vector<std::uint32_t>& internal_nodes,
               std::vector<std::uint32_t>& boxes) const;
  /// The surface-area cost of a fresh median build over `boxes` (centers: centers_now()).
  [[nodiscard]] double fresh_cost(std::vector<std::uint32_t>& boxes,
                                  const std::vector<double>& centers) const;
  /// The subtree of `node` (internal, not the root) built again by the median builder over its
  /// leaves at now; the pairs of `node` with other nodes and its self pair collapsed and
  /// classified again. Its contacts are kept; those the new list decides otherwise are logged
  /// as events.
  void rebuild_subtree(std::uint32_t node, const std::vector<double>& centers);
  [[nodiscard]] double cost(std::span<const std::uint32_t> internal_nodes) const;
  /// The surface measure of a box with these side lengths (surface_measure, core/boxes.hpp).
  [[nodiscard]] double surface(const std::array<double, 3>& len) const {
    return surface_measure(d_, len);
  }
  /// The boxes' centers at now in double (box index * d + axis), for the median build.
  [[nodiscard]] std::vector<double> centers_now(std::span<const std::uint32_t> alive) const;
  [[nodiscard]] bool leaf(std::uint32_t node) const;
  /// A node record on the free list (Node::left is kFreeNode).
  static constexpr std::uint32_t kFreeNode = kNoIndex - 1;
  [[nodiscard]] bool free_node(std::uint32_t node) const;
  [[nodiscard]] bool internal(std::uint32_t node) const;
  /// A node record (reused or appended, its slots sized), and its release (its tournament
  /// events removed; nothing may watch it).
  std::uint32_t new_node();
  void release_node(std::uint32_t node);
  /// The leaf an insertion of `box` goes beside: from the root, the child whose box at now
  /// grows least in surface measure (ties: left).
  [[nodiscard]] std::uint32_t insertion_leaf(std::uint32_t box) const;
  /// The node's box at now from its winners, in double.
  void node_box(std::uint32_t node, std::array<double, 3>& lo, std::array<double, 3>& hi) const;
  /// The pairs (not self) with a certificate on one of the node's sides: every pair with the
  /// node but its self pair. Sorted, unique.
  [[nodiscard]] std::vector<std::uint32_t> pairs_of(std::uint32_t node) const;
  /// A pair's descendants, contact and certificates removed (quietly), the pair kept.
  void clear_pair(std::uint32_t pair);
  /// clear_pair() on each, keeping those that are still pairs (not below another of them).
  void clear_pairs(std::vector<std::uint32_t>& pairs);
  /// The node's pairs after it changed in place (from `from` to `to`): re-pointed, reclassified.
  void move_pairs(const std::vector<std::uint32_t>& pairs, std::uint32_t from, std::uint32_t to);
  /// Puts the children of the self pair of `node` back in children_pairs() order, taking the
  /// records it has and `extra` (a new self pair), dropping none.
  void order_self_children(std::uint32_t node, std::uint32_t extra);
  /// The certificates on the sides of `leaf`'s ancestors (the leaf included) that were computed
  /// from `box` while it is not that side's winner: rescheduled (the box changed or leaves).
  void reschedule_computed_from(std::uint32_t leaf, std::uint32_t box);
  /// Whether `box`'s leaf lies in the subtree of `node`.
  [[nodiscard]] bool under(std::uint32_t box, std::uint32_t node) const;
  /// The ancestors of `node` re-decided on every axis and side (their winners may be new).
  void redecide_ancestors(std::uint32_t node);
  /// Certificates rescheduled by a timeline change that are due now: handled as the events they
  /// would have been, quietly.
  void settle_touched();
  void count_query() override { ++counters_.queries; }

  const Scheduler& scheduler_;
  int d_;
  OwnerRange owners_;                  // the tournaments', the separation list's certificates'
  std::vector<BoxEndpointKeys> keys_;  // per axis
  /// The node boxes' tournaments: per node, axis and side (a slot), the box whose side is the
  /// node's (the largest high side, the smallest low side), over the hierarchy's topology.
  TournamentTree<SideKeys, SideTopology> tree_;
  std::vector<Node> nodes_;
  std::uint32_t root_ = kNoIndex;
  std::vector<std::uint32_t> leaf_of_;  // box index -> leaf node
  std::vector<std::uint32_t> free_nodes_;
  std::vector<std::uint32_t> self_pair_;   // internal node -> its self pair
  std::vector<std::uint32_t> watch_head_;  // slot -> first watching link (cert * 2 + end)
  std::vector<PairRecord> pairs_;
  std::vector<std::uint32_t> free_pairs_;
  std::uint32_t root_pair_ = kNoIndex;  // (root, root)
  std::size_t live_pairs_ = 0;
  std::vector<Cert> certs_;
  std::vector<std::uint32_t> free_certs_;
  std::size_t live_certs_ = 0;
  std::uint64_t events_since_check_ = 0;
  std::uint64_t check_interval_ = 0;    // 0: max(1024, 4n)
  bool quiet_ = false;                  // a timeline change: contacts change without events
  bool building_ = false;               // build(): the pairs are classified, no change happens now
  bool collect_ = false;                // motion_changed: note the certificates rescheduled
  std::vector<std::uint32_t> touched_;  // those certificates
  /// insert, rebuild_subtree: nodes keep every box they had, so an overlap certificate kept at a
  /// winner change still implies its pair's inequality (as at an event), even while collecting
  bool keep_overlaps_ = false;
  bool journal_quiet_ = false;          // rebuild_subtree: note the contacts changed quietly
  std::vector<std::uint64_t> quiet_begun_, quiet_ended_;  // those contacts (PairSet keys)
  bool rebuild_policy_ = true;
  BvhCounters counters_;
};

static_assert(KineticStructure<KineticBvh>);

}  // namespace kinetic
