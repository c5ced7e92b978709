#pragma once
// The global event queue: an indexed 4-ary heap of certificate failure times with stable
// handles (insert, remove, change key, pop min). The heap holds its keys (time, sequence) inline
// beside the slot in 16-byte entries, and a node's four children fill one 64-byte cache line
// (the array is aligned and offset so that they do), so sifting reads one line per level and
// never the slots it does not move. Under the double order the queue has three tiers, a ladder
// (after Tang, Goh and Thng's ladder queue): the heap holds only the earliest events; a calendar
// of buckets, each a slice of time, holds the next ones unordered by bucket; the latest wait
// unordered in a far tier. An insert, a remove or a change of key outside the heap costs O(1);
// when the heap runs empty the next non-empty bucket becomes the heap (a bottom-up build of a
// few dozen entries), and when the calendar runs empty the earliest share of the far tier is
// laid out in a new one (a selection and one pass). Rescheduled events mostly fall after the
// current bucket, so the heap stays a few dozen entries, in L1. The tiers split by time alone
// (equal times share a tier), so the order of events is that of one heap.
// Equal times are ordered by a sequence number assigned when an event is scheduled, so the order of
// simultaneous events -- the normal case on degenerate inputs -- is a deterministic function of the
// run: same input, same event order.

#include <bit>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "kinetic/core/exact_time.hpp"
#include "kinetic/core/huge_pages.hpp"
#include "kinetic/core/ids.hpp"
#include "kinetic/core/prefetch.hpp"
#include "kinetic/core/time.hpp"

namespace kinetic {

/// A scheduled certificate failure. `owner` tells the structure (or sub-structure) the event
/// belongs to, `payload` which of its certificates; the queue does not interpret either.
struct Event {
  Time time = 0.0;
  std::uint64_t sequence = 0;
  std::uint32_t owner = 0;
  std::uint32_t payload = 0;
};

/// Handle to a scheduled event. Default-constructed handles are null; a handle goes stale when its
/// event is popped or removed (detected by a generation count).
struct EventHandle {
  std::uint32_t slot = kNoIndex;
  std::uint32_t generation = 0;
  [[nodiscard]] bool is_null() const { return slot == kNoIndex; }
  friend bool operator==(const EventHandle&, const EventHandle&) = default;
};

class EventQueue {
 public:
  /// Schedules an event. O(log h) for a heap of h events, O(1) into the other tiers, amortized
  /// (a refill, a new calendar or a spill costs O(n) now and then). Precondition: time is not
  /// NaN; fewer than 2^30 events ever queued at once.
  EventHandle push(Time time, std::uint32_t owner, std::uint32_t payload);
  /// Removes a scheduled event. As push(). Precondition: contains(h).
  void remove(EventHandle h);
  /// Changes the time of a scheduled event (it gets a new sequence number). As push().
  /// Precondition: contains(h), time is not NaN.
  void update(EventHandle h, Time time);
  /// The same, and the event's payload replaced (a certificate that now watches another pair
  /// keeps its slot). As push().
  void update(EventHandle h, Time time, std::uint32_t payload) {
    slots_[h.slot].event.payload = payload;
    update(h, time);
  }
  /// True when h refers to an event still in the queue.
  [[nodiscard]] bool contains(EventHandle h) const;
  [[nodiscard]] const Event& get(EventHandle h) const;

  [[nodiscard]] bool empty() const { return heap_.size() == kOffset; }  // (the other tiers too)
  [[nodiscard]] std::size_t size() const {
    return heap_.size() - kOffset + calendar_size_ + far_.size();
  }
  [[nodiscard]] std::size_t max_size() const { return max_size_; }
  /// Events in the heap tier and in the calendar (diagnostics: the rest wait in the far tier).
  [[nodiscard]] std::size_t heap_size() const { return count(); }
  [[nodiscard]] std::size_t calendar_size() const { return calendar_size_; }
  /// Times the heap was spilled back and the calendar laid out again (a diagnostic).
  [[nodiscard]] std::uint64_t spills() const { return spills_; }
  /// The earliest event (smallest time, then smallest sequence). Precondition: !empty().
  [[nodiscard]] const Event& top() const { return slots_[at(0).slot].event; }
  /// A hint: brings the slot of the second earliest event (the earliest of the root's children,
  /// most often the event after the top) towards the cache. Changes nothing.
  void prefetch_second() const {
    const std::uint32_t n = count();
    if (n < 2) return;
    std::uint32_t best = 1;
    for (std::uint32_t c = 2; c <= kArity && c < n; ++c) {
      if (at(c).time < at(best).time) best = c;
    }
    prefetch_line(&slots_[at(best).slot]);
  }
  /// A hint: brings the slot of a scheduled event towards the cache (before an update() or
  /// remove() of it). Changes nothing.
  void prefetch_slot(EventHandle h) const {
    if (h.slot < slots_.size()) {
      prefetch_line(&slots_[h.slot]);
      prefetch_line(&heap_index_[h.slot]);
    }
  }
  /// Removes and returns the earliest event; under the exact order its exact time goes to
  /// `exact` when given. Precondition: !empty().
  Event pop(LazyTime* exact = nullptr);
  void clear();

  // The exact order (the exact scheduler, docs/exact-design.md). Once an event is pushed with
  // push_exact(), events come out by their exact times, then by scheduling order; a time pushed
  // as a double is the exact rational it is. Event::time is then a double at or below the exact
  // time, its key: the tiers (heap, calendar, far) split by keys as under the double order, and
  // only events of equal keys are compared by their exact times (brackets first, then without
  // GMP, then exactly, refining, equal roots found by their gcd).

  /// Schedules an event at an exact time.
  EventHandle push_exact(LazyTime time, std::uint32_t owner, std::uint32_t payload);
  EventHandle push_exact(ExactTime time, std::uint32_t owner, std::uint32_t payload) {
    return push_exact(LazyTime::of(std::move(time)), owner, payload);
  }
  [[nodiscard]] bool exact_order() const { return exact_; }
  /// Turns the exact order on (push_exact() does too); the events queued are the rationals
  /// their times are.
  void use_exact_order();
  /// The exact time of the earliest event (refinable). Precondition: exact(), !empty().
  [[nodiscard]] LazyTime& top_exact() { return exact_times_[at(0).slot]; }
  /// Under the exact order, whether the earliest event's exact time is <= t; otherwise whether
  /// its time is. Precondition: !empty().
  [[nodiscard]] bool top_at_or_before(Time t);
  /// Comparisons that needed exact arithmetic (the brackets overlapped).
  [[nodiscard]] std::uint64_t exact_comparisons() const { return exact_comparisons_; }
  /// Of those, the ones that reached GMP (core/gmp_work.hpp).
  [[nodiscard]] std::uint64_t exact_comparisons_gmp() const { return exact_comparisons_gmp_; }
  /// Halvings of exact times' intervals those comparisons made.
  [[nodiscard]] std::uint64_t exact_refinements() const { return exact_refinements_; }

  /// Numbers the queued events' order keys afresh, 0 .. size - 1, keeping their order (done by
  /// itself when 2^32 events have been scheduled since the last time). O(n log n).
  void renumber();

  /// Checks the heap order, every tier's bounds and the slot/tier cross references. O(n).
  [[nodiscard]] bool validate() const;

 private:
  struct Slot {
    Event event;
    std::uint32_t generation = 0;
  };
  /// A heap entry: the event's key and its slot. `order` is the event's sequence number among
  /// the queued events (32 bits: renumbered, keeping their order, when the count runs out).
  struct Entry {
    Time time = 0.0;
    std::uint32_t order = 0;
    std::uint32_t slot = kNoIndex;
  };
  static_assert(sizeof(Entry) == 16);
  static constexpr std::uint32_t kArity = 4;
  /// Heap index i lives at heap_[i + kOffset]: the children 4i + 1 .. 4i + 4 of i are then at
  /// 4(i + 1) + 3 .. 4(i + 1) + 6, one aligned group of four entries.
  static constexpr std::uint32_t kOffset = 3;
  [[nodiscard]] Entry& at(std::uint32_t i) { return heap_[i + kOffset]; }
  [[nodiscard]] const Entry& at(std::uint32_t i) const { return heap_[i + kOffset]; }
  [[nodiscard]] std::uint32_t count() const {
    return static_cast<std::uint32_t>(heap_.size() - kOffset);
  }
  static bool before(const Entry& a, const Entry& b) {
    return a.time < b.time || (a.time == b.time && a.order < b.order);
  }
  /// The exact order: exact times, then sequence (refines the two times when needed). An
  /// entry's key is its exact time's lower bracket when pushed, and that time is the key itself
  /// or lies strictly between the key and the next double (a time is a double, or strictly
  /// inside its bracket of adjacent doubles, and brackets only narrow; docs/exact-design.md, "The
  /// exact queue"): different keys decide without looking at the times, and so do the tiers,
  /// which split by keys.
  bool exact_before(const Entry& a, const Entry& b) const {
    if (a.time != b.time) return a.time < b.time;  // (keys are never NaN; -0 == +0 goes on)
    return exact_before_close(a, b);
  }
  bool exact_before_close(const Entry& a, const Entry& b) const;
  /// Doubles in order as integers, adjacent doubles one apart (-0 and +0 both 0); not for NaN.
  static std::int64_t ordinal(double x) {
    const auto bits = std::bit_cast<std::int64_t>(x);
    return bits >= 0 ? bits : -(bits & std::numeric_limits<std::int64_t>::max());
  }
  /// Moves `e` from heap position i towards the root / the leaves to where it belongs.
  template <bool Exact>
  void sift_up(std::uint32_t i, Entry e);
  template <bool Exact>
  void sift_down(std::uint32_t i, Entry e);
  /// sift_up or sift_down, whichever `e` needs at i (after a remove or an update).
  void sift(std::uint32_t i, Entry e);
  std::uint32_t take_slot();
  [[nodiscard]] bool less(const Entry& a, const Entry& b) const {
    return exact_ ? exact_before(a, b) : before(a, b);
  }
  /// Appends e to a tier's array (far_ or a bucket; `mark` kFar or kBucket) and records where.
  void append(HugeVector<Entry>& tier, std::uint32_t mark, const Entry& e) {
    heap_index_[e.slot] = mark | static_cast<std::uint32_t>(tier.size());
    tier.push_back(e);
  }
  void place(std::uint32_t heap_index, const Entry& e) {
    at(heap_index) = e;
    heap_index_[e.slot] = heap_index;
  }
  /// The tiers (the double order only). With `index(t)` the calendar's bucket of a time t
  /// (monotone in t, clamped to its buckets; below 0 for the times before its base):
  ///   heap     t <= cal_limit_ and index(t) < next_;
  ///   bucket b t <= cal_limit_ and index(t) == b, next_ <= b < buckets;
  ///   far      t > cal_limit_.
  /// Every time in a tier is before every time in the next, ties included, so the heap's top is
  /// the earliest event. heap_index_ of an event in bucket b is kBucket | its index there (b is
  /// index(its time)); in far_, kFar | its index there. The heap is empty only when the queue is.
  static constexpr std::uint32_t kFar = 0x80000000u;
  static constexpr std::uint32_t kBucket = 0x40000000u;
  static constexpr std::uint32_t kPlace = 0x3fffffffu;
  enum class Tier : std::uint8_t { Heap, Bucket, Far };
  struct Where {
    Tier tier;
    std::uint32_t bucket;
  };
  [[nodiscard]] Where tier_of(Time t) const {
    if (!(t <= cal_limit_)) return {Tier::Far, 0};
    if (next_ >= bucket_count_) return {Tier::Heap, 0};
    const double d = inv_width_ == 0.0 ? 0.0 : (t - base_) * inv_width_;
    // index(t) = clamp(floor(d), 0, buckets - 1): the heap when below next_ (the times before
    // the base go to bucket 0, which is the heap once next_ > 0).
    if (d < static_cast<double>(next_)) return {next_ > 0 ? Tier::Heap : Tier::Bucket, 0};
    const double last = static_cast<double>(bucket_count_ - 1);
    return {Tier::Bucket, d >= last ? bucket_count_ - 1 : static_cast<std::uint32_t>(d)};
  }
  /// Where the event in `slot`, whose entry has time t, is: its tier, and its bucket then.
  [[nodiscard]] Where where(std::uint32_t slot, Time t) const {
    const std::uint32_t i = heap_index_[slot];
    if ((i & kFar) != 0) return {Tier::Far, 0};
    if ((i & kBucket) != 0) return {Tier::Bucket, tier_of(t).bucket};
    return {Tier::Heap, 0};
  }
  /// Inserts e where its time belongs: the heap (sift up), its bucket or far_.
  void insert(const Entry& e);
  /// Takes the entry at `slot`'s place in tier w out (the last entry of its array fills it).
  void erase(std::uint32_t slot, Where w);
  /// Takes heap position i out (the last heap entry fills it, then moves).
  void heap_erase(std::uint32_t i);
  /// When the heap is empty and the queue is not: the next non-empty bucket becomes the heap; when
  /// the calendar is empty, about far_'s earliest max(kMinRefill, |far_| / kRefillShare) events
  /// (the limit from a sample; at least a quarter of that many, by an exact selection when the
  /// sample was unlucky) and the ties of the latest of them are laid out in a new calendar.
  void refill();
  void build_calendar();
  /// Every event back into far_ and a new calendar laid out: when inserts have grown the heap
  /// past both size / kRefillShare and spill_at_ (the first calendar, of the first event pushed,
  /// spans what it spans; or many events fall into the current bucket). spill_at_ is
  /// max(kMaxHeap, twice the bucket the heap started from), so a heap of equal times (one
  /// bucket, whatever the calendar) doubles between spills. O(size), amortized over the inserts
  /// that grew the heap.
  void spill();
  static constexpr std::size_t kMinRefill = 1024;
  static constexpr std::size_t kRefillShare = 4;
  /// The calendar's buckets hold this many events each on average when it is laid out.
  static constexpr std::size_t kPerBucket = 32;
  static constexpr std::size_t kMaxHeap = 4096;
  /// The calendar's limit is a quantile of this many of far_'s times.
  static constexpr std::size_t kSample = 1024;
  /// The next sequence number's `order`: renumbers the queued events 0 .. size - 1 in their
  /// order first when 32 bits run out.
  std::uint32_t next_order();
  void release(std::uint32_t slot);

  HugeVector<Slot> slots_;
  /// By slot: the event's heap position, kNoIndex when free. Apart from the slots, so that the
  /// writes of a sift (one per level moved) land in an array of 4 bytes per event.
  HugeVector<std::uint32_t> heap_index_;
  std::vector<std::uint32_t> free_;
  HugeVector<Entry> heap_ = HugeVector<Entry>(kOffset);  // (HugeVector: 64-byte aligned)
  HugeVector<Entry> far_;                                ///< the events after cal_limit_, unordered
  /// The calendar: buckets [0, bucket_count_) of width 1 / inv_width_ from base_ (inv_width_ 0:
  /// one bucket), the first next_ of them already moved into the heap. buckets_ may be longer
  /// (kept with their capacity from earlier calendars).
  std::vector<HugeVector<Entry>> buckets_;
  std::uint32_t bucket_count_ = 1;
  std::uint32_t next_ = 1;
  double base_ = 0.0;
  double inv_width_ = 0.0;
  Time cal_limit_ = -std::numeric_limits<double>::infinity();
  std::size_t calendar_size_ = 0;  ///< events in the buckets
  std::size_t spill_at_ = kMaxHeap;
  std::uint64_t spills_ = 0;
  std::vector<double> sample_;  ///< build_calendar()'s scratch
  bool exact_ = false;
  mutable std::vector<LazyTime> exact_times_;  // by slot, under the exact order
  /// Tie classes, under the exact order: tie_[slot] is the event's class (0: none yet), a node
  /// of the union-find forest tie_parent_ (tie_parent_[0] unused). Events of one class were
  /// found to have equal exact times (compare() returned 0 for two of them, and equality is
  /// transitive), so two of them are ordered by their sequence without arithmetic: a group of
  /// simultaneous events (GRIDS) is compared exactly about once per member instead of at every
  /// sift. tie_[slot] is 0 whenever the slot's time is set or released.
  mutable std::vector<std::uint32_t> tie_;
  mutable std::vector<std::uint32_t> tie_parent_{0};
  /// The class of the event in `slot` (its root, path halved), 0 for none.
  std::uint32_t tie_class(std::uint32_t slot) const;
  /// The events in slots a and b have equal exact times: one class.
  void join_ties(std::uint32_t a, std::uint32_t b) const;
  /// Renumbers the queued events' classes densely and forgets the others.
  void compact_ties() const;
  mutable std::uint64_t exact_comparisons_ = 0;
  mutable std::uint64_t exact_comparisons_gmp_ = 0;
  mutable std::uint64_t exact_refinements_ = 0;
  std::uint64_t next_sequence_ = 0;
  std::uint64_t next_order_ = 0;  // Entry::order of the next event (see next_order())
  std::size_t max_size_ = 0;
};

}  // namespace kinetic
