#include "kinetic/core/event_queue.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>

#include "kinetic/core/error.hpp"
#include "kinetic/core/gmp_work.hpp"

namespace kinetic {

std::uint32_t EventQueue::take_slot() {
  std::uint32_t slot;
  if (!free_.empty()) {
    slot = free_.back();
    free_.pop_back();
  } else {
    // Tier positions are 30 bits (heap_index_ keeps two tier bits beside them).
    if (slots_.size() >= kPlace) {
      precondition_failed("EventQueue::push",
                          "more than 2^30 - 1 events queued at once (the queue's capacity)");
    }
    slot = static_cast<std::uint32_t>(slots_.size());
    slots_.emplace_back();
    heap_index_.push_back(kNoIndex);
    if (exact_) {
      exact_times_.emplace_back();
      tie_.push_back(0);
    }
  }
  return slot;
}

EventHandle EventQueue::push(Time time, std::uint32_t owner, std::uint32_t payload) {
  assert(!std::isnan(time));
  if (exact_) return push_exact(LazyTime::point(time), owner, payload);
  const std::uint32_t slot = take_slot();
  Slot& s = slots_[slot];
  s.event = Event{time, next_sequence_++, owner, payload};
  const std::uint32_t order = next_order();
  insert(Entry{time, order, slot});
  if (empty()) refill();
  max_size_ = std::max(max_size_, size());
  return EventHandle{slot, s.generation};
}

void EventQueue::insert(const Entry& e) {
  const Where w = tier_of(e.time);
  if (w.tier == Tier::Heap) {
    heap_.emplace_back();
    if (exact_) {
      sift_up<true>(count() - 1, e);
    } else {
      sift_up<false>(count() - 1, e);
    }
    if (count() > spill_at_ && count() > size() / kRefillShare) spill();
  } else if (w.tier == Tier::Bucket) {
    append(buckets_[w.bucket], kBucket, e);
    ++calendar_size_;
  } else {
    append(far_, kFar, e);
  }
}

void EventQueue::erase(std::uint32_t slot, Where w) {
  const std::uint32_t i = heap_index_[slot] & kPlace;
  if (w.tier == Tier::Heap) {
    heap_erase(i);
    return;
  }
  HugeVector<Entry>& v = w.tier == Tier::Far ? far_ : buckets_[w.bucket];
  const std::uint32_t mark = w.tier == Tier::Far ? kFar : kBucket;
  const Entry last = v.back();
  v.pop_back();
  if (i < v.size()) {
    v[i] = last;
    heap_index_[last.slot] = mark | i;
  }
  if (w.tier == Tier::Bucket) --calendar_size_;
}

void EventQueue::heap_erase(std::uint32_t i) {
  const Entry last = heap_.back();
  heap_.pop_back();
  if (i < count()) sift(i, last);  // the last entry fills the hole, then moves
}

void EventQueue::refill() {
  assert(empty());
  for (;;) {
    while (next_ < bucket_count_) {
      HugeVector<Entry>& b = buckets_[next_++];
      if (b.empty()) continue;
      // The bucket becomes the heap: built bottom up (Floyd), then every position written once.
      const std::size_t k = b.size();
      heap_.resize(kOffset + k);
      std::copy(b.begin(), b.end(), heap_.begin() + kOffset);
      b.clear();
      calendar_size_ -= k;
      for (std::uint32_t i = k > 1 ? static_cast<std::uint32_t>((k - 2) / kArity) + 1 : 0; i-- > 0;) {
        if (exact_) {
          sift_down<true>(i, at(i));
        } else {
          sift_down<false>(i, at(i));
        }
      }
      for (std::uint32_t i = 0; i < count(); ++i) heap_index_[at(i).slot] = i;
      // A heap that starts large (a bucket of equal times) must double before it spills.
      spill_at_ = std::max<std::size_t>(kMaxHeap, 2 * k);
      return;
    }
    if (far_.empty()) return;
    build_calendar();
  }
}

void EventQueue::spill() {
  ++spills_;
  for (std::uint32_t i = 0; i < count(); ++i) append(far_, kFar, at(i));
  for (std::uint32_t b = next_; b < bucket_count_; ++b) {
    for (const Entry& e : buckets_[b]) append(far_, kFar, e);
    buckets_[b].clear();
  }
  heap_.resize(kOffset);
  calendar_size_ = 0;
  bucket_count_ = 1;
  next_ = 1;
  cal_limit_ = -std::numeric_limits<double>::infinity();
  refill();  // (a new calendar over every event)
}

void EventQueue::build_calendar() {
  assert(empty() && calendar_size_ == 0 && !far_.empty());
  const std::size_t m = far_.size();
  const std::size_t k = std::min(m, std::max(kMinRefill, m / kRefillShare));
  // The calendar takes about the k earliest times, and every tie of the latest of them: the limit
  // is that quantile of a sample of far_ (every (m / kSample)-th entry: deterministic), or the
  // latest time when all go.
  Time limit = -std::numeric_limits<double>::infinity();
  if (k < m) {
    const std::size_t stride = std::max<std::size_t>(1, m / kSample);
    sample_.clear();
    for (std::size_t i = 0; i < m; i += stride) sample_.push_back(far_[i].time);
    const std::size_t q = std::min(sample_.size() - 1, sample_.size() * k / m);
    std::nth_element(sample_.begin(), sample_.begin() + static_cast<std::ptrdiff_t>(q),
                     sample_.end());
    limit = sample_[q];  // (a time of far_: at least one event moves)
  } else {
    for (const Entry& e : far_) limit = std::max(limit, e.time);
  }
  // far_ partitioned: the times after the limit stay at the front, the others go to the tail
  // [m - moved, m). Only an entry that stays and changes place needs its position written.
  std::size_t front = 0, back = m;
  for (;;) {
    while (front < back && far_[front].time > limit) ++front;
    while (front < back && !(far_[back - 1].time > limit)) --back;
    if (front + 1 >= back) break;
    std::swap(far_[front], far_[back - 1]);
    heap_index_[far_[front].slot] = kFar | static_cast<std::uint32_t>(front);
    ++front;
    --back;
  }
  if (k < m && m - back < k / 4) {
    // An unlucky sample (its quantile fell among the earliest times): the exact quantile of the
    // rest, and a second partition of it. Every position in front is written again.
    const std::size_t want = k - (m - back);
    const auto front_end = far_.begin() + static_cast<std::ptrdiff_t>(back);
    std::nth_element(far_.begin(), front_end - static_cast<std::ptrdiff_t>(want), front_end,
                     [](const Entry& a, const Entry& b) { return a.time > b.time; });
    limit = (front_end - static_cast<std::ptrdiff_t>(want))->time;
    back = static_cast<std::size_t>(
        std::partition(far_.begin(), front_end,
                       [limit](const Entry& e) { return e.time > limit; }) -
        far_.begin());
    for (std::size_t i = 0; i < back; ++i)
      heap_index_[far_[i].slot] = kFar | static_cast<std::uint32_t>(i);
  }
  const auto split = far_.begin() + static_cast<std::ptrdiff_t>(back);
  const std::size_t moved = m - back;
  // The buckets span the finite times moved (-inf falls into the first, +inf into the last).
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  for (auto it = split; it != far_.end(); ++it) {
    if (std::isfinite(it->time)) {
      lo = std::min(lo, it->time);
      hi = std::max(hi, it->time);
    }
  }
  const std::size_t count =
      std::max<std::size_t>(1, std::min<std::size_t>(moved / kPerBucket, kPlace));
  bucket_count_ = static_cast<std::uint32_t>(count);
  base_ = lo <= hi ? lo : 0.0;
  inv_width_ = lo < hi ? static_cast<double>(count) / (hi - lo) : 0.0;
  if (!std::isfinite(inv_width_)) inv_width_ = 0.0;  // (a span that overflows, or vanishes)
  if (inv_width_ == 0.0) bucket_count_ = 1;
  if (buckets_.size() < bucket_count_) buckets_.resize(bucket_count_);
  cal_limit_ = limit;
  next_ = 0;
  for (auto it = split; it != far_.end(); ++it) {
    const Where w = tier_of(it->time);
    assert(w.tier == Tier::Bucket);
    append(buckets_[w.bucket], kBucket, *it);
  }
  calendar_size_ = moved;
  far_.erase(split, far_.end());
}

void EventQueue::use_exact_order() {
  if (exact_) return;
  // The exact order from now on: the events already queued are the rationals they are (their
  // keys), so the heap, the calendar and far_ keep their places (on points the exact order is
  // the double order).
  exact_ = true;
  exact_times_.resize(slots_.size());
  tie_.assign(slots_.size(), 0);
  for (std::uint32_t i = 0; i < count(); ++i)
    exact_times_[at(i).slot] = LazyTime::point(at(i).time);
  for (std::uint32_t b = next_; b < bucket_count_; ++b)
    for (const Entry& e : buckets_[b]) exact_times_[e.slot] = LazyTime::point(e.time);
  for (const Entry& e : far_) exact_times_[e.slot] = LazyTime::point(e.time);
}

EventHandle EventQueue::push_exact(LazyTime time, std::uint32_t owner, std::uint32_t payload) {
  // (LazyTime brackets are one double wide: comparisons rarely need exact arithmetic.)
  use_exact_order();
  const std::uint32_t slot = take_slot();
  Slot& s = slots_[slot];
  const double lo = time.lower();
  exact_times_[slot] = std::move(time);
  tie_[slot] = 0;
  s.event = Event{lo, next_sequence_++, owner, payload};
  const std::uint32_t order = next_order();
  insert(Entry{lo, order, slot});
  if (empty()) refill();
  max_size_ = std::max(max_size_, size());
  return EventHandle{slot, s.generation};
}

std::uint32_t EventQueue::tie_class(std::uint32_t slot) const {
  std::uint32_t c = tie_[slot];
  if (c == 0) return 0;
  while (tie_parent_[c] != c) {  // (path halving)
    tie_parent_[c] = tie_parent_[tie_parent_[c]];
    c = tie_parent_[c];
  }
  return tie_[slot] = c;
}

void EventQueue::join_ties(std::uint32_t a, std::uint32_t b) const {
  const std::uint32_t ca = tie_class(a), cb = tie_class(b);
  if (ca != 0 && cb != 0) {
    tie_parent_[cb] = ca;
    return;
  }
  if (ca != 0 || cb != 0) {
    tie_[a] = tie_[b] = ca != 0 ? ca : cb;
    return;
  }
  if (tie_parent_.size() >= kNoIndex) compact_ties();
  const auto c = static_cast<std::uint32_t>(tie_parent_.size());
  tie_parent_.push_back(c);
  tie_[a] = tie_[b] = c;
}

void EventQueue::compact_ties() const {
  // The classes of the queued events renumbered densely (their roots), the rest forgotten.
  std::vector<std::uint32_t> renumbered(tie_parent_.size(), 0);
  std::vector<std::uint32_t> parent{0};
  for (std::uint32_t slot = 0; slot < tie_.size(); ++slot) {
    if (heap_index_[slot] == kNoIndex) {
      tie_[slot] = 0;
      continue;
    }
    const std::uint32_t c = tie_class(slot);
    if (c == 0) continue;
    if (renumbered[c] == 0) {
      renumbered[c] = static_cast<std::uint32_t>(parent.size());
      parent.push_back(renumbered[c]);
    }
    tie_[slot] = renumbered[c];
  }
  tie_parent_ = std::move(parent);
}

bool EventQueue::exact_before_close(const Entry& a, const Entry& b) const {
  const std::uint32_t tie_a = tie_class(a.slot);
  if (tie_a != 0 && tie_a == tie_class(b.slot)) return a.order < b.order;  // found equal before
  LazyTime& x = exact_times_[a.slot];
  LazyTime& y = exact_times_[b.slot];
  if (const int c = order_by_brackets(x, y)) return c < 0;
  ++exact_comparisons_;
  const std::size_t before = x.refinements() + y.refinements();
  const std::uint64_t gmp = gmp_work();
  const int c = compare(x, y);
  if (gmp_work() != gmp) ++exact_comparisons_gmp_;
  exact_refinements_ += x.refinements() + y.refinements() - before;
  if (c != 0) return c < 0;
  join_ties(a.slot, b.slot);  // the next comparison of any two of their classes is free
  return a.order < b.order;
}

bool EventQueue::top_at_or_before(Time t) {
  assert(!empty());
  if (!exact_) return at(0).time <= t;
  // The key is at or below the exact time, which is within one double above it.
  const Entry& top_entry = at(0);
  if (!(top_entry.time <= t)) return false;  // (a NaN t too)
  if (ordinal(top_entry.time) + 1 <= ordinal(t)) return true;
  LazyTime& x = exact_times_[top_entry.slot];
  if (x.upper() <= t) return true;
  if (x.lower() > t) return false;
  LazyTime point = LazyTime::point(t);
  ++exact_comparisons_;
  const std::size_t before = x.refinements();
  const std::uint64_t gmp = gmp_work();
  const bool due = compare(x, point) <= 0;
  if (gmp_work() != gmp) ++exact_comparisons_gmp_;
  exact_refinements_ += x.refinements() - before;
  return due;
}

bool EventQueue::contains(EventHandle h) const {
  return h.slot < slots_.size() && slots_[h.slot].generation == h.generation &&
         heap_index_[h.slot] != kNoIndex;
}

const Event& EventQueue::get(EventHandle h) const {
  assert(contains(h));
  return slots_[h.slot].event;
}

void EventQueue::sift(std::uint32_t i, Entry e) {
  if (exact_) {
    if (i > 0 && exact_before(e, at((i - 1) / kArity))) {
      sift_up<true>(i, e);
    } else {
      sift_down<true>(i, e);
    }
  } else if (i > 0 && before(e, at((i - 1) / kArity))) {
    sift_up<false>(i, e);
  } else {
    sift_down<false>(i, e);
  }
}

void EventQueue::remove(EventHandle h) {
  assert(contains(h));
  erase(h.slot, where(h.slot, slots_[h.slot].event.time));
  release(h.slot);
  if (empty()) refill();
}

void EventQueue::update(EventHandle h, Time time) {
  assert(contains(h));
  assert(!std::isnan(time));
  Slot& s = slots_[h.slot];
  const Where from = where(h.slot, s.event.time);
  s.event.time = time;
  s.event.sequence = next_sequence_++;
  if (exact_) {
    exact_times_[h.slot] = LazyTime::point(time);
    tie_[h.slot] = 0;
  }
  const std::uint32_t order = next_order();
  const Entry e{time, order, h.slot};
  const Where to = tier_of(time);
  const std::uint32_t i = heap_index_[h.slot] & kPlace;
  if (from.tier == Tier::Heap && to.tier == Tier::Heap) {
    sift(i, e);
  } else if (from.tier == to.tier && from.bucket == to.bucket) {
    (to.tier == Tier::Far ? far_ : buckets_[to.bucket])[i] = e;
  } else {
    erase(h.slot, from);
    insert(e);
    if (empty()) refill();
  }
}

Event EventQueue::pop(LazyTime* exact_time) {
  assert(!empty());
  const std::uint32_t slot = at(0).slot;
  const Event e = slots_[slot].event;
  if (exact_ && exact_time != nullptr) *exact_time = std::move(exact_times_[slot]);
  const Entry last = heap_.back();
  heap_.pop_back();
  if (!empty()) {
    if (exact_) {
      sift_down<true>(0, last);
    } else {
      sift_down<false>(0, last);
    }
  } else {
    refill();
  }
  release(slot);
  return e;
}

void EventQueue::clear() {
  for (std::uint32_t i = 0; i < count(); ++i) release(at(i).slot);
  for (std::uint32_t b = next_; b < bucket_count_; ++b) {
    for (const Entry& e : buckets_[b]) release(e.slot);
    buckets_[b].clear();
  }
  for (const Entry& f : far_) release(f.slot);
  heap_.resize(kOffset);
  far_.clear();
  calendar_size_ = 0;
  bucket_count_ = 1;
  next_ = 1;
  cal_limit_ = -std::numeric_limits<double>::infinity();
  spill_at_ = kMaxHeap;
}

void EventQueue::renumber() {
  // The queued events numbered 0 .. size - 1 in their order: the heap stays a heap (every
  // comparison between them comes out as before), and later events number on from there. The
  // other tiers' events are numbered with them (pointers to every queued entry); the tiers split
  // by time, which does not change.
  std::vector<Entry*> by_order;
  by_order.reserve(size());
  for (std::uint32_t i = 0; i < count(); ++i) by_order.push_back(&at(i));
  for (std::uint32_t b = next_; b < bucket_count_; ++b)
    for (Entry& e : buckets_[b]) by_order.push_back(&e);
  for (Entry& f : far_) by_order.push_back(&f);
  std::sort(by_order.begin(), by_order.end(),
            [](const Entry* x, const Entry* y) { return x->order < y->order; });
  for (std::uint32_t k = 0; k < by_order.size(); ++k) by_order[k]->order = k;
  next_order_ = by_order.size();
}

std::uint32_t EventQueue::next_order() {
  if (next_order_ > std::numeric_limits<std::uint32_t>::max()) renumber();
  return static_cast<std::uint32_t>(next_order_++);
}

void EventQueue::release(std::uint32_t slot) {
  heap_index_[slot] = kNoIndex;
  if (exact_) {
    tie_[slot] = 0;
    // Classes outlive their events: renumbered when they outnumber the queued events by far.
    if (tie_parent_.size() > std::max<std::size_t>(4096, 4 * size())) compact_ties();
  }
  ++slots_[slot].generation;
  free_.push_back(slot);
}

template <bool Exact>
void EventQueue::sift_up(std::uint32_t i, Entry e) {
  while (i > 0) {
    const std::uint32_t parent = (i - 1) / kArity;
    if (!(Exact ? exact_before(e, at(parent)) : before(e, at(parent)))) break;
    place(i, at(parent));
    i = parent;
  }
  place(i, e);
}

template <bool Exact>
void EventQueue::sift_down(std::uint32_t i, Entry e) {
  const std::uint32_t n = count();
  for (;;) {
    const std::uint32_t first = kArity * i + 1;
    if (first >= n) break;
    const std::uint32_t end = std::min(first + kArity, n);
    std::uint32_t child = first;
    for (std::uint32_t c = first + 1; c < end; ++c) {
      if (Exact ? exact_before(at(c), at(child)) : before(at(c), at(child))) child = c;
    }
    if (!(Exact ? exact_before(at(child), e) : before(at(child), e))) break;
    place(i, at(child));
    i = child;
  }
  place(i, e);
}

bool EventQueue::validate() const {
  if (heap_.size() < kOffset || reinterpret_cast<std::uintptr_t>(heap_.data()) % 64 != 0)
    return false;
  for (std::uint32_t i = 0; i < count(); ++i) {
    const Entry& e = at(i);
    if (e.slot >= slots_.size() || heap_index_[e.slot] != i) return false;
    const Event& ev = slots_[e.slot].event;
    if (ev.time != e.time && !(std::isnan(ev.time) && std::isnan(e.time))) return false;
    if (e.order >= next_order_) return false;
    if (i > 0 && less(e, at((i - 1) / kArity))) return false;
    // Under the exact order the key is a double at or below the exact time,
    // and the exact time lies within one double of the key (exact_before() relies on it).
    if (exact_ && !(e.time <= exact_times_[e.slot].lower() &&
                    exact_times_[e.slot].upper() <= std::nextafter(e.time, kTimeInfinity)))
      return false;
  }
  // The tiers: every heap entry's time (key) in the heap tier, every bucket's and far_'s in
  // theirs, and the heap empty only when the others are.
  for (std::uint32_t i = 0; i < count(); ++i)
    if (tier_of(at(i).time).tier != Tier::Heap) return false;
  if (empty() && (calendar_size_ != 0 || !far_.empty())) return false;
  if (next_ > bucket_count_ || (next_ < bucket_count_ && bucket_count_ > buckets_.size()))
    return false;
  if (slots_.size() > kPlace) return false;
  std::size_t in_calendar = 0;
  for (std::uint32_t b = next_; b < bucket_count_; ++b) {
    const HugeVector<Entry>& v = buckets_[b];
    for (std::uint32_t i = 0; i < v.size(); ++i) {
      const Entry& e = v[i];
      if (e.slot >= slots_.size() || heap_index_[e.slot] != (kBucket | i)) return false;
      const Where w = tier_of(e.time);
      if (w.tier != Tier::Bucket || w.bucket != b) return false;
      if (e.order >= next_order_ || slots_[e.slot].event.time != e.time) return false;
    }
    in_calendar += v.size();
  }
  for (std::uint32_t b = 0; b < buckets_.size(); ++b)
    if ((b < next_ || b >= bucket_count_) && !buckets_[b].empty()) return false;
  if (in_calendar != calendar_size_) return false;
  for (std::uint32_t i = 0; i < far_.size(); ++i) {
    const Entry& e = far_[i];
    if (e.slot >= slots_.size() || heap_index_[e.slot] != (kFar | i)) return false;
    if (tier_of(e.time).tier != Tier::Far || e.order >= next_order_ ||
        slots_[e.slot].event.time != e.time)
      return false;
  }
  std::size_t live = 0;
  for (const std::uint32_t h : heap_index_) live += h != kNoIndex;
  return live == size() && live + free_.size() == slots_.size() &&
         heap_index_.size() == slots_.size();
}

}  // namespace kinetic
