#pragma once
// Kinetic sorting of keys moving on a line: the sorted array A and the certificates
// [A[j] < A[j+1]], one per adjacent pair (Abam, Agarwal, de Berg, Yu, Introduction and Section 3).
// A swap replaces at most three certificates. All events are external: the maintained attribute
// is the order itself.
//
// What is sorted is a SortKeys type (core/sort_keys.hpp): KineticSort sorts points by one axis
// of their motions (AxisKeys, one key per object); KineticEndpointSort sorts the low and high
// sides of moving boxes on one axis (BoxEndpointKeys, two keys per box: the sweep-and-prune of
// collision detection). Both are instantiated in kinetic_sort.cpp.

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "kinetic/core/boxes.hpp"
#include "kinetic/core/description.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/preconditions.hpp"
#include "kinetic/core/prefetch.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/sort_keys.hpp"
#include "kinetic/core/structure.hpp"

namespace kinetic {

/// Counters specific to kinetic sorting (the KDS measures are in the simulator's Counters).
struct SortCounters : ChangeCounters {
  std::uint64_t swaps = 0;
  /// Swaps whose pair's new certificate was settled without a root isolation (see
  /// swapped_pair_holds()).
  std::uint64_t swapped_pairs_settled = 0;
};

/// How the sorted array A is stored.
///  * Dense: A[0 .. n-1], a key's position is its rank. An insert or remove shifts the array
///    (O(n)); the layout of the sweep-and-prune.
///  * Gapped: a packed-memory array (Bender, Demaine, Farach-Colton, "Cache-oblivious B-trees";
///    Itai, Konheim, Rodeh's sparse table): slots [0, U), U a power of two, in segments of
///    kGapSegment slots, each packed to the left and never empty (for U > kGapSegment); a
///    key's position is its slot, a label that keeps the order but not consecutive. Neighbours
///    are consecutive occupied slots (next_slot / prev_slot). An insert or remove shifts at most
///    one segment, and when a segment overflows or runs low the smallest enclosing window of
///    segments within its density bounds is spread evenly (O(log^2 n) keys moved, amortized),
///    or, at the whole array's bounds, U doubles or halves. The keys that moved are reported
///    (relabeled(), layout_generation()). Any keys (the sweep-and-prune's two per box too).
enum class SortLayout : std::uint8_t { Dense, Gapped };

/// The result of an audit against the brute-force oracle at one time.
struct SortAudit {
  bool ok = true;
  std::size_t first_inversion = 0;  ///< position j with A[j] > A[j+1] at the audited time
};

template <SortKeys Keys>
class BasicKineticSort {
 public:
  /// What the structure is and takes (core/description.hpp), for KineticSort (the registry
  /// and the CLI's `sort`, the Python class Sort): defined for it only.
  [[nodiscard]] static StructureDescription description();

  static constexpr std::uint32_t kKeysPerObject = Keys::kKeysPerObject;

  /// Reserves one owner tag from the simulator for this structure's events. Throws
  /// PreconditionError when the keys refuse the table or the axis.
  BasicKineticSort(const MotionTable& motions, Simulator& simulator, const Scheduler& scheduler,
                   int axis, SortLayout layout = SortLayout::Dense);

  /// Slots per segment of the gapped layout (a power of two).
  static constexpr std::uint32_t kGapSegment = 16;
  /// "No such slot" (next_slot after the last key, prev_slot before the first).
  static constexpr std::size_t kNoSlot = ~std::size_t{0};

  /// Builds A from every key of every live object of the table, ordered as just after sim.now()
  /// (exact comparisons; identical key functions by the keys' tie order; under the traditional
  /// classic scheduler by floating-point values at now, equal ones by the tie order), and
  /// schedules all certificates. O(n log n).
  void initialize();

  /// What a swap event does to A: key `up` moves from `position` to `next` (position + 1 in
  /// the dense layout, the next occupied slot in the gapped one), past `down`, which takes
  /// `position`.
  struct Swap {
    std::uint32_t position = 0;
    std::uint32_t up = kNoIndex;
    std::uint32_t down = kNoIndex;
    std::uint32_t next = 0;
  };
  /// The swap an event of this sort will make (before processing it).
  [[nodiscard]] Swap pending_swap(const Event& event) const {
    const std::uint32_t j = position_[event.payload];
    const auto k = static_cast<std::uint32_t>(next_slot(j));
    return Swap{j, event.payload, order_[k], k};
  }
  /// The KDS event handler for structures built on the sort: swaps the certificate's pair,
  /// reschedules the (at most three) certificates that changed and returns the swap, so that the
  /// structure above repairs itself without reading the ranks again. O(log n).
  Swap process_swap(const Event& event);
  /// The KDS event handler: process_swap(). Every swap is external (the order changed).
  EventKind process(const Event& event) {
    process_swap(event);
    return EventKind::External;
  }

  /// The simulator's memory hint (PrefetchingHandler) for the next event, when it is this
  /// sort's: the key's position first, then the entries around it that a swap there reads.
  void prefetch(const Event& next, bool located) const {
    if (next.owner != owner_ || next.payload >= position_.size()) return;
    if (!located) {
      prefetch_line(&position_[next.payload]);
      return;
    }
    const std::size_t j = position_[next.payload];
    if (j + 1 >= order_.size()) return;
    const std::size_t from = j > 0 ? j - 1 : 0;
    prefetch_line(&order_[from]);
    prefetch_line(&cert_[from]);
    const std::size_t to = std::min(j + 2, order_.size() - 1);
    prefetch_range(&local_[from * stride()], &local_[to * stride()] + stride());
  }

  /// Adds the keys of a live object of the table at their places as just after sim.now().
  /// Dense: O(n) (array shift). Gapped: O(log n) comparisons and O(log^2 n) moved keys
  /// (amortized; see SortLayout).
  void insert(std::uint32_t index);
  /// Removes the keys of an object that left the table (call after removing it there). Dense:
  /// O(n). Gapped: as insert.
  void remove(std::uint32_t index);
  /// The object's motion was replaced in the table: repositions its keys (they may have
  /// jumped). Dense: moving only the entries between their old and new places, O(log n + the
  /// distance moved). Gapped: a remove and an insert of its keys.
  void motion_changed(std::uint32_t index);

  [[nodiscard]] SortLayout layout() const {
    return gapped_ ? SortLayout::Gapped : SortLayout::Dense;
  }
  /// Keys in A.
  [[nodiscard]] std::size_t size() const { return size_; }
  /// Slots of A: size() when dense, U when gapped.
  [[nodiscard]] std::size_t slots() const { return order_.size(); }
  /// The occupied slot after / before slot p (p occupied, or for prev_slot any slot whose
  /// earlier slots in its segment are occupied), or kNoSlot.
  [[nodiscard]] std::size_t next_slot(std::size_t p) const {
    const std::size_t q = p + 1;
    if (!gapped_) return q < order_.size() ? q : kNoSlot;
    if (q < order_.size() && order_[q] != kNoIndex) return q;
    const std::size_t g = p / kGapSegment + 1;  // p was the last key of its segment
    return g < seg_count_.size() && seg_count_[g] > 0 ? g * kGapSegment : kNoSlot;
  }
  [[nodiscard]] std::size_t prev_slot(std::size_t p) const {
    if (p == 0) return kNoSlot;
    if (!gapped_ || p % kGapSegment != 0) return p - 1;
    const std::size_t g = p / kGapSegment - 1;
    return seg_count_[g] > 0 ? g * kGapSegment + seg_count_[g] - 1 : kNoSlot;
  }
  /// The first occupied slot at or after slot r, or kNoSlot.
  [[nodiscard]] std::size_t slot_at_or_after(std::size_t r) const {
    if (r >= order_.size()) return kNoSlot;
    if (order_[r] != kNoIndex) return r;
    // An empty slot ends its segment (packed to the left); the next segment starts with a key.
    const std::size_t next = (r / kGapSegment + 1) * kGapSegment;
    return next < order_.size() && order_[next] != kNoIndex ? next : kNoSlot;
  }
  /// Gapped layout: the keys whose slot the last insert, remove or motion_changed changed,
  /// other than the object's own, each once (a key moved twice, e.g. by a spread and then a
  /// shift, is told once; it may then be back in its slot). A structure above re-reads their
  /// labels. Empty for the dense layout (every later rank moves by one there).
  [[nodiscard]] std::span<const std::uint32_t> relabeled() const { return relabeled_; }
  /// The slot each key of relabeled() held before the change (entry k for relabeled()[k]).
  [[nodiscard]] std::span<const std::uint32_t> relabeled_from() const { return relabeled_from_; }
  /// Gapped layout: ranges of slots [first, second] whose content the last insert, remove or
  /// motion_changed may have changed (an update's two places are two ranges); every other slot
  /// holds what it held.
  [[nodiscard]] std::span<const std::pair<std::size_t, std::size_t>> touched_slots() const {
    return touched_;
  }
  /// Gapped layout: changes when every key may have a new slot (initialize, U doubled or
  /// halved); relabeled() is then not filled.
  [[nodiscard]] std::uint64_t layout_generation() const { return layout_generation_; }
  /// The rank motion_changed(index) would give the object (its motion in the table already
  /// replaced), without changing anything. O(log n) comparisons. One key per object only.
  [[nodiscard]] std::uint32_t rank_after_update(std::uint32_t index) const
      requires(Keys::kKeysPerObject == 1);

  /// Robust scheduling only: measure every event's delay t_pr - t_ex (the exact crossing found
  /// by exact-sign bisection below eps) into the simulator's counters. Costs about 30 exact
  /// sign evaluations per event; for experiments and tests. Axis keys only (ignored otherwise).
  void set_measure_delays(bool on) { measure_delays_ = on; }
  /// Turns swapped_pair_holds() off (on by default): every swapped pair's certificate then gets
  /// its root isolation (tests compare the two).
  void set_settle_swapped_pairs(bool on) { settle_swapped_pairs_ = on; }
  /// Tell the simulator's event log (Simulator::set_event_log) every swap: kind "swap", ids
  /// [the object that moved up, the one it passed]. Off by default: for a structure built on
  /// sorts a swap may be internal.
  void set_log_swaps(bool on) { log_swaps_ = on; }

  /// The maintained order, as keys (for AxisKeys: object indices of the table); by slot in the
  /// gapped layout, kNoIndex in the empty slots.
  [[nodiscard]] std::span<const std::uint32_t> order() const { return order_; }
  /// The position of a key in the maintained order (dense: its rank, from 0; gapped: its slot).
  /// Precondition: in it.
  [[nodiscard]] std::uint32_t rank(std::uint32_t key) const {
    assert(key < position_.size() && position_[key] != kNoIndex);  // debug builds only
    return position_[key];
  }
  [[nodiscard]] int axis() const { return keys_.axis(); }
  [[nodiscard]] const Keys& keys() const { return keys_; }
  [[nodiscard]] const SortCounters& counters() const { return counters_; }
  [[nodiscard]] NamedCounters named_counters() const;
  /// The owner tag of this structure's events.
  [[nodiscard]] OwnerRange owners() const { return OwnerRange{owner_, 1}; }
  /// Certificates alive: one per adjacent pair.
  [[nodiscard]] std::size_t certificates() const { return size_ == 0 ? 0 : size_ - 1; }
  /// Certificates an object takes part in, at most: one per neighbour of each of its keys.
  [[nodiscard]] std::size_t certificates_per_object_max() const {
    return size_ == 0 ? 0 : std::min<std::size_t>(2 * kKeysPerObject, size_ - 1);
  }

  /// initialize() was called.
  [[nodiscard]] bool initialized() const { return sync_.initialized(); }
  /// Invariants: positions and order agree; every scheduled event belongs to the certificate of
  /// its adjacent pair; no other events of this structure exist. O(n).
  [[nodiscard]] bool validate() const;
  /// Oracle audit at time t: the maintained order is sorted at t (exact comparisons). O(n).
  [[nodiscard]] SortAudit audit(Time t) const;

 private:
  /// The keys are one motion each (AxisKeys): their motions are kept in sort order.
  static constexpr bool kMotionsInOrder = requires(const Keys& k, std::uint32_t a) {
    { k.motion(a) } -> std::same_as<const MotionPolynomial&>;
  };
  void schedule(std::size_t position);  // certificate [A[position] < A[position+1]]
  void cancel_at(std::size_t position);
  /// The entries of local_ at positions [lo, hi] read again from the table.
  void refresh_in_order(std::size_t lo, std::size_t hi);
  /// Doubles per entry of local_: valid-from, then (AxisKeys) origin and cap_ + 1 coefficients.
  [[nodiscard]] std::size_t stride() const {
    return cap_ < 0 ? 1 : static_cast<std::size_t>(cap_) + 3;
  }
  /// Whether the certificate of the pair a swap at `position` just exchanged, [y < x], is known
  /// to hold for the rest of the window without a root isolation, given the time of the event
  /// of [x < y] just processed. Under the robust scheduler (no failure-time model), with every
  /// motion of degree <= 1 and the event after the start of the pair's CROP window: CROP of
  /// x - y over that window finds the same single event interval as CROP of y - x did (its
  /// signs at grid points are exact, so the one cell holding the only root is found however the
  /// root is guessed). An event after the window's start was that interval's right end (EVENTTIME
  /// returns the window's start only for a certificate failing from it, whose interval may end
  /// after now), so the interval ends at or before now and x - y > 0 beyond it: EVENTTIME is
  /// +infinity, the event CROP would leave (none). Skipping the call changes no event; a test
  /// runs the same inputs with and without it.
  ///
  /// Under the exact scheduler, with every motion of degree <= 2: the event of [x < y] is its
  /// exact failure, so g = x - y > 0 just after now (motions unchanged since it was scheduled:
  /// a change reschedules). When g' >= 0 at the event's key (a double at or below now) and g is
  /// not concave (the leading coefficients compare exactly), g' >= 0 from then on, so g stays
  /// > 0 for ever and [y < x] never fails; otherwise it gets its decision. Lines: g' is the
  /// difference of the slopes, compared exactly; parabolas: g'(key) by the exact predicate on the
  /// derivatives. (`position` holds y, `next` x.)
  [[nodiscard]] bool swapped_pair_holds(std::size_t position, std::size_t next,
                                        Time event_time) const {
    if constexpr (kMotionsInOrder) {
      if (!settle_swapped_pairs_ || cap_ > 2) return false;
      if (scheduler_.kind() == SchedulerKind::Exact) {
        if (cap_ < 1) return true;  // constants: x - y > 0 for ever
        const double* x = &local_[next * stride()];
        const double* y = &local_[position * stride()];
        if (cap_ == 1) return x[3] >= y[3];
        if (x[4] < y[4]) return false;  // concave: g' falls, g may fail
        if (!std::isfinite(2.0 * x[4]) || !std::isfinite(2.0 * y[4])) return false;  // (huge)
        const MotionPolynomial dx = MotionPolynomial::from({x[3], 2.0 * x[4]}, x[1]);
        const MotionPolynomial dy = MotionPolynomial::from({y[3], 2.0 * y[4]}, y[1]);
        return compare_at(dx, dy, event_time) >= 0;
      }
      if (cap_ > 1) return false;
      if (scheduler_.kind() != SchedulerKind::Robust || scheduler_.has_failure_time_model())
        return false;
      const Time window_lo = std::max(local_[position * stride()], local_[next * stride()]);
      return std::isfinite(window_lo) && event_time > scheduler_.crop_window_start(window_lo);
    } else {
      return false;
    }
  }
  /// The motion of A[position] from its entry.
  [[nodiscard]] MotionPolynomial motion_at(std::size_t position) const;
  /// Entries with room for coefficients up to `degree`.
  void widen(int degree);
  void place(std::uint32_t key, std::size_t position);
  /// Takes position p out of A and of the arrays kept beside it (its event already cancelled).
  void erase_at(std::size_t p);
  void detach(std::uint32_t key);
  void grow();
  std::size_t locate(std::uint32_t key) const;
  // The gapped layout (SortLayout::Gapped).
  /// The segment and the offset in it where `key` goes (before the first key not before it).
  [[nodiscard]] std::pair<std::size_t, std::size_t> locate_gapped(std::uint32_t key) const;
  void place_gapped(std::uint32_t key);
  /// Takes `key` out; with `reschedule`, the key before it gets its certificate with the key
  /// after it.
  void detach_gapped(std::uint32_t key, bool reschedule = true);
  /// Takes every key of the object out (its certificates and those of the keys before its keys
  /// replaced once all are out).
  void detach_object_gapped(std::uint32_t index);
  /// Drops the object's own keys from relabeled_ (its other keys may move as one is placed).
  void forget_own_relabels(std::uint32_t index);
  /// Moves entries [from, from + count) of A to start at `to` (overlap allowed), positions
  /// updated and the moved keys noted in relabeled_.
  void move_entries(std::size_t from, std::size_t count, std::size_t to);
  /// Spreads the keys of segments [g0, g0 + k) evenly over them.
  void spread(std::size_t g0, std::size_t k);
  /// The entries of segments [g0, g0 + k) in order, into gather_keys_, gather_cert_ and
  /// gather_local_.
  void gather(std::size_t g0, std::size_t k);
  /// Writes gather_keys_ (with their entries, when gathered) evenly over segments [g0, g0 + k),
  /// each packed to the left; positions updated, the moved keys noted.
  void scatter(std::size_t g0, std::size_t k);
  /// An insert, remove or update of the gapped layout starts: nothing relabeled or touched yet.
  void begin_change();
  void clear_relabels();
  /// Key x is about to leave its slot: told in relabeled_ unless already told in this change.
  void note_relabel(std::uint32_t x);
  /// Lays the keys out again over the number of segments that keeps n keys at density <= 1/2.
  void relayout(std::size_t n);
  /// Segment g overflowed (insert) or ran low (remove): the smallest window within its bounds
  /// is spread, or the whole array relaid.
  void rebalance(std::size_t g, bool inserting);
  void note_delay(std::uint32_t x, std::uint32_t y, Time t_cp);
  bool before_after_now(std::uint32_t a, std::uint32_t b) const;
  /// before_after_now(A[j], key), with A[j]'s motion read from its entry in sort order.
  bool slot_before_after_now(std::size_t j, std::uint32_t key) const;
  /// The rank of `key` among the keys not of its object (their order kept), as just after now.
  std::size_t rank_among_others(
      std::uint32_t key, const std::array<std::uint32_t, kKeysPerObject>& own_positions) const;
  [[nodiscard]] static std::uint32_t object_of(std::uint32_t key) { return key / kKeysPerObject; }
  [[nodiscard]] static std::uint32_t first_key(std::uint32_t object) {
    return object * kKeysPerObject;
  }

  Keys keys_;
  const MotionTable& motions_;
  TableSync sync_{motions_};  // told of every change to the table
  Simulator& sim_;
  const Scheduler& scheduler_;
  std::uint32_t owner_;
  // Everything an event reads is kept in sort order, by position j in A, so that the three
  // certificates a swap replaces read neighbouring memory: the key, the event of [A[j] <
  // A[j+1]] (its payload is the key A[j]), the key's motion (AxisKeys) and its object's
  // valid-from time. Only the key -> position map is indexed by key.
  HugeVector<std::uint32_t> order_;  // A, as keys
  HugeVector<EventHandle> cert_;     // position j -> event of [A[j] < A[j+1]]
  // position j -> [valid_from of A[j]'s object, (AxisKeys:) its motion's origin and
  // coefficients up to degree cap_]: a linear motion's entry is 4 doubles, two to a cache line.
  HugeVector<double> local_;
  bool settle_swapped_pairs_ = true;  // swapped_pair_holds() on (tests turn it off)
  int cap_ = -1;                      // the highest degree an entry holds (-1: no motions kept)
  bool gapped_ = false;
  std::size_t size_ = 0;                       // keys in A
  std::vector<std::uint32_t> seg_count_;       // gapped: keys in each segment (packed to the left)
  std::vector<std::uint32_t> relabeled_;       // gapped: keys moved by the last insert / remove
  std::vector<std::uint32_t> relabeled_from_;  // the slots they held before it
  std::vector<std::uint32_t> relabel_entry_;  // gapped: key -> its entry in relabeled_, or kNoIndex
  std::vector<std::pair<std::size_t, std::size_t>> touched_;  // gapped: slots changed by it
  void touch(std::size_t lo, std::size_t hi) {
    for (auto& r : touched_) {  // a few ranges: merged when they overlap or meet
      if (lo <= r.second + 1 && r.first <= hi + 1) {
        r = {std::min(r.first, lo), std::max(r.second, hi)};
        return;
      }
    }
    touched_.emplace_back(lo, hi);
  }
  std::uint64_t layout_generation_ = 0;     // gapped: bumped when every slot may have changed
  std::vector<std::uint32_t> gather_keys_;  // spread / relayout: the window's keys in order
  std::vector<EventHandle> gather_cert_;    // their events
  std::vector<double> gather_local_;        // their entries of local_
  HugeVector<std::uint32_t> position_;      // key -> position in A (kNoIndex if not in A)
  std::vector<std::uint32_t> scratch_;     // motion_changed: the entries between old and new places
  std::vector<EventHandle> scratch_cert_;  // motion_changed: their events
  std::vector<std::size_t> renew_;         // motion_changed: the certificates to replace
  SortCounters counters_;
  bool measure_delays_ = false;
  bool log_swaps_ = false;
};

/// Points sorted by one axis of their motions.
using KineticSort = BasicKineticSort<AxisKeys>;
template <>
StructureDescription KineticSort::description();
/// The sides of moving boxes sorted on one axis (sweep-and-prune's endpoint lists).
using KineticEndpointSort = BasicKineticSort<BoxEndpointKeys>;
/// Points of the plane sorted along an integer direction a x + b y (the "axis" is the index of
/// the direction in DirectionKeys::kDirections; the cones of the kinetic closest pair).
using KineticDirectionSort = BasicKineticSort<DirectionKeys>;

extern template class BasicKineticSort<AxisKeys>;
extern template class BasicKineticSort<BoxEndpointKeys>;
extern template class BasicKineticSort<DirectionKeys>;

static_assert(KineticStructure<KineticSort>);
static_assert(KineticStructure<KineticEndpointSort>);
static_assert(KineticStructure<KineticDirectionSort>);

}  // namespace kinetic
