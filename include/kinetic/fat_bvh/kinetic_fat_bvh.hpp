#pragma once
// The kinetic BVH over fat boxes: the per-frame broad phases' fattened AABB tree (Box2D's
// b2DynamicTree, Bullet's btDbvt) made kinetic, with every contact still begun and ended at its
// exact time.
//
// Every box gets a *fat box*: a constant box that holds the moving box over a lookahead (the
// box's path over a time in which it travels about its own extent, and a small margin). The fat
// boxes sit in a dynamic AABB tree (FatBoxTree) that does not move between refits, so no event
// keeps it: node boxes are numbers. Certificates:
//  - containment: the box stays inside its fat box (2d comparisons of a side with a constant,
//    one event: the first to fail). When it fails the box is *refitted*: a new fat box around
//    its path from now, the leaf moved in the tree (remove, insert), and the pairs of fat boxes
//    found again by one tree query;
//  - pairs: every two boxes whose fat boxes meet form a pair, either separated (one certificate:
//    a side of one below the opposite side of the other, on the axis where that lasts longest)
//    or in contact (the 2d inequalities low <= high, one event at the first to fail). Entering
//    and leaving contact are the external events contact_begin / contact_end, at their times.
// Two boxes in contact have meeting fat boxes (each box lies in its own), so the pairs hold
// every contact; a contact pair whose fat boxes part stays a pair until it separates.
//
// Events: a refit per box per lookahead, and the separations and contacts of pairs whose fat
// boxes meet, not the node-side and node-pair events of the exact-box tree (bvh/): a box at rest
// never refits, and two boxes at rest make no event. The guarantee is the exact-box BVH's (every
// contact at its time, within the scheduler's delay); what the fat boxes change is the work,
// not the answers. colliding_pairs() reads the contact pairs.

#include <array>
#include <cstdint>
#include <vector>

#include "kinetic/core/box_contacts.hpp"
#include "kinetic/core/boxes.hpp"
#include "kinetic/core/description.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/structure.hpp"
#include "kinetic/fat_bvh/fat_box_tree.hpp"

namespace kinetic {

struct FatBvhCounters : ChangeCounters {
  std::uint64_t refits = 0;              ///< a box left its fat box: new fat box, leaf moved
  std::uint64_t containment_checks = 0;  ///< containment events that found the box still inside
  std::uint64_t pair_events = 0;         ///< a pair's certificate failed
  std::uint64_t pairs_made = 0;          ///< pairs whose fat boxes began to meet
  std::uint64_t pairs_dropped = 0;       ///< pairs whose fat boxes parted
  /// pair classifications settled without root isolation: apart now on a side that never closes
  std::uint64_t pairs_apart_for_ever = 0;
  std::uint64_t contact_begins = 0;
  std::uint64_t contact_ends = 0;
  /// pairs apart just after a change whose closed boxes touch at its time (reported by a query
  /// then, a contact of zero duration)
  std::uint64_t instant_contacts = 0;
  std::uint64_t queries = 0;
};

/// The contact set, colliding_pairs() and the table's checks are the base's
/// (core/box_contacts.hpp).
class KineticFatBvh final : public BoxContacts {
 public:
  [[nodiscard]] static StructureDescription description();

  /// `boxes`: a table of boxes (core/boxes.hpp: 2d coordinates, d = 1..3).
  KineticFatBvh(const MotionTable& boxes, Simulator& simulator, const Scheduler& scheduler);

  void initialize();
  EventKind process(const Event& event);
  /// A fat box and a leaf for the box, its pairs found by one tree query. Contacts the box has
  /// at insertion are not events.
  void insert(std::uint32_t index);
  /// The box's pairs and leaf leave. Its contacts end without events.
  void remove(std::uint32_t index);
  /// The box is refitted (a fat box for its new path) and its pairs decided again; contacts the
  /// change makes or ends are not events.
  void motion_changed(std::uint32_t index);

  /// How fat a fat box is: it holds the box's path over the time the box takes to travel
  /// `lookahead` times its extent (at its speed at the refit), and `margin` times its extent
  /// more on every side. Takes effect at the next refit. Defaults: 2 and 0.05.
  void set_fattening(double lookahead, double margin);
  [[nodiscard]] double lookahead() const { return lookahead_; }
  [[nodiscard]] double margin() const { return margin_; }
  /// Refits of one motion at the lookahead above; each later refit of the same motion looks
  /// twice as far as the one before (a box far faster than its size, or than the others, stops
  /// costing a refit per step: its fat box becomes its path), so a motion costs at most this
  /// plus about 2,100 refits (a double's exponent range).
  static constexpr std::uint32_t kSteadyRefits = 64;
  /// A refit looks at least this far ahead (2^-20 time units): a box faster than about a million
  /// extents per unit time gets a fat box longer than itself rather than a refit per instant.
  static constexpr double kMinLookahead = 0x1p-20;

  /// Oracle audit at t: every certificate holds at t, exactly (each box inside its fat box, each
  /// separated pair apart on its axis, each contact pair overlapping), so the answer at t is
  /// exact. O(n + pairs).
  [[nodiscard]] bool audit(Time t) const;
  /// The tree (links, node boxes the bounding boxes of their children, one leaf per box holding
  /// its fat box), every containment certificate scheduled, the pairs exactly the pairs of
  /// boxes whose fat boxes meet plus contact pairs, the contact set the contact pairs.
  /// O(n log n + pairs).
  [[nodiscard]] bool validate() const;
  [[nodiscard]] std::size_t certificates() const;
  [[nodiscard]] std::size_t certificates_per_object_max() const;
  [[nodiscard]] const FatBvhCounters& counters() const { return counters_; }
  [[nodiscard]] NamedCounters named_counters() const;
  [[nodiscard]] int dimension() const { return d_; }
  /// The fat box of a live box.
  [[nodiscard]] const ConstantBox& fat_box(std::uint32_t index) const { return fat_[index]; }
  /// Pairs of boxes kept (fat boxes meeting, or in contact).
  [[nodiscard]] std::size_t pairs() const { return live_pairs_; }
  [[nodiscard]] const FatBoxTree& tree() const { return tree_; }
  /// Bytes held by the tree, the fat boxes, the pairs and the contact set.
  [[nodiscard]] std::size_t bytes() const;

 private:
  enum class State : std::uint8_t { Free, Separated, Contact };
  struct Pair {
    std::array<std::uint32_t, 2> box{kNoIndex, kNoIndex};
    std::array<std::uint32_t, 2> at{};  // positions in pairs_of_[box[e]]
    EventHandle handle;
    State state = State::Free;
    std::int8_t certified = -1;  // separated: the decision scheduled (axis * 2 + which)
  };

  /// The decision k = axis * 2 + which of a pair: sign(low(y) - high(x)) with (x, y) = (a, b) for
  /// which 0 and (b, a) for which 1; > 0 is apart on that axis.
  [[nodiscard]] Scheduler::SignDecision decide_pair(std::uint32_t a, std::uint32_t b, int k) const;
  /// The containment decision k = axis * 2 + side: sign(fat side - box side) (high) or
  /// sign(box side - fat side) (low); > 0 is inside.
  [[nodiscard]] Scheduler::SignDecision decide_inside(std::uint32_t box, int k) const;
  /// A decision k of the pair that holds now and for ever, found without root isolation: both
  /// centers of degree <= 1 and both half extents constant on its axis, low(y) - high(x) > 0 now
  /// (exactly) and y no slower than x. -1 when no side is such.
  [[nodiscard]] int apart_for_ever(std::uint32_t a, std::uint32_t b) const;
  /// Decides the pair's state just after now and schedules its certificate; returns whether the
  /// contact set changed. Logged as events unless `quiet`. `axis`: the axis whose certificate
  /// failed (-1: none), checked last when the boxes may touch now.
  bool classify(std::uint32_t pair, bool quiet, int axis);
  /// The box's fat box around its path from now, its leaf moved, its containment scheduled.
  void fatten(std::uint32_t box);
  /// Schedules the box's containment certificate; false when the box is not inside just after now.
  bool schedule_inside(std::uint32_t box);
  /// The pairs of the box after its fat box changed: new pairs made and decided, pairs whose fat
  /// boxes parted dropped (not contacts). Returns whether the contact set changed.
  bool find_pairs(std::uint32_t box, bool quiet);
  std::uint32_t add_pair(std::uint32_t a, std::uint32_t b);
  void drop_pair(std::uint32_t pair);
  void set_contact(std::uint32_t pair, bool contact, bool quiet);
  void note_if_touching(std::uint32_t a, std::uint32_t b, int axis);
  [[nodiscard]] std::uint32_t other(std::uint32_t pair, std::uint32_t box) const {
    return pairs_[pair].box[0] == box ? pairs_[pair].box[1] : pairs_[pair].box[0];
  }
  void grow(std::size_t capacity);
  void count_query() override { ++counters_.queries; }

  const Scheduler& scheduler_;
  int d_;
  OwnerRange owners_;                  // [0]: containment, [1]: pairs
  std::vector<BoxEndpointKeys> keys_;  // per axis
  FatBoxTree tree_;
  std::vector<ConstantBox> fat_;                      // box index -> its fat box
  std::vector<Time> fat_since_;                       // box index -> when it was made
  std::vector<std::uint32_t> leaf_;                   // box index -> its leaf (kNoIndex: none)
  std::vector<EventHandle> inside_;                   // box index -> its containment event
  std::vector<std::vector<std::uint32_t>> pairs_of_;  // box index -> its pairs
  std::vector<Pair> pairs_;
  std::vector<std::uint32_t> free_pairs_;
  std::size_t live_pairs_ = 0;
  std::vector<std::uint32_t> mark_;     // scratch: box index -> pair with the box being refitted
  std::vector<std::uint32_t> scratch_;  // scratch: boxes found by a query
  std::vector<std::uint32_t> had_;      // scratch: an updated box's pairs
  double lookahead_ = 2.0;
  double margin_ = 0.05;
  double unit_extent_ = 1.0;  // the extent of a box of zero extent (the mean at initialize)
  std::vector<std::uint32_t> piece_refits_;  // box index -> refits since its motion was given
  bool building_ = false;                    // initialize(): the tree is built after the fat boxes
  FatBvhCounters counters_;
};

static_assert(KineticStructure<KineticFatBvh>);

}  // namespace kinetic
