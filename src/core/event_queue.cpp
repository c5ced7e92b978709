#include "kinetic/core/event_queue.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>

namespace kinetic {

std::uint32_t EventQueue::take_slot() {
  std::uint32_t slot;
  if (!free_.empty()) {
    slot = free_.back();
    free_.pop_back();
  } else {
    slot = static_cast<std::uint32_t>(slots_.size());
    slots_.emplace_back();
    heap_index_.push_back(kNoIndex);
    if (exact_) exact_times_.emplace_back();
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
  if (empty() && !far_.empty()) refill();
  max_size_ = std::max(max_size_, size());
  return EventHandle{slot, s.generation};
}

void EventQueue::insert(const Entry& e) {
  if (in_heap_tier(e)) {
    heap_.emplace_back();
    sift_up<false>(count() - 1, e);
  } else {
    far_append(e);
  }
}

void EventQueue::far_append(const Entry& e) {
  heap_index_[e.slot] = kFar | static_cast<std::uint32_t>(far_.size());
  far_.push_back(e);
}

void EventQueue::far_erase(std::uint32_t i) {
  const Entry last = far_.back();
  far_.pop_back();
  if (i < far_.size()) {
    far_[i] = last;
    heap_index_[last.slot] = kFar | i;
  }
}

void EventQueue::heap_erase(std::uint32_t i) {
  const Entry last = heap_.back();
  heap_.pop_back();
  if (i < count()) sift(i, last);  // the last entry fills the hole, then moves
}

void EventQueue::refill() {
  assert(empty() && !far_.empty() && tiered_);
  const std::size_t m = far_.size();
  const std::size_t k = std::min(m, std::max(kMinRefill, m / kRefillShare));
  // far_[m - k, m) gets the k earliest events (in any order), the latest of them at m - k.
  std::nth_element(far_.begin(), far_.begin() + static_cast<std::ptrdiff_t>(m - k), far_.end(),
                   [](const Entry& a, const Entry& b) { return before(b, a); });
  split_ = far_[m - k];
  heap_.resize(kOffset + k);
  for (std::size_t i = 0; i < k; ++i) at(static_cast<std::uint32_t>(i)) = far_[m - k + i];
  far_.resize(m - k);
  // The heap built bottom up (Floyd), then every position written once.
  for (std::uint32_t i = k > 1 ? static_cast<std::uint32_t>((k - 2) / kArity) + 1 : 0; i-- > 0;)
    sift_down<false>(i, at(i));
  for (std::uint32_t i = 0; i < count(); ++i) heap_index_[at(i).slot] = i;
  for (std::uint32_t i = 0; i < far_.size(); ++i) heap_index_[far_[i].slot] = kFar | i;
}

void EventQueue::flatten() {
  tiered_ = false;
  for (const Entry& e : far_) {
    heap_.emplace_back();
    if (exact_) {
      sift_up<true>(count() - 1, e);
    } else {
      sift_up<false>(count() - 1, e);
    }
  }
  far_.clear();
}

void EventQueue::use_exact_order() {
  if (exact_) return;
  // The exact order from now on: the events already queued are the rationals they are, and all
  // in the heap.
  exact_ = true;
  exact_times_.resize(slots_.size());
  for (std::uint32_t i = 0; i < count(); ++i)
    exact_times_[at(i).slot] = LazyTime::point(at(i).time);
  for (const Entry& e : far_) exact_times_[e.slot] = LazyTime::point(e.time);
  flatten();
}

EventHandle EventQueue::push_exact(LazyTime time, std::uint32_t owner, std::uint32_t payload) {
  // (LazyTime brackets are one double wide: comparisons rarely need exact arithmetic.)
  use_exact_order();
  const std::uint32_t slot = take_slot();
  Slot& s = slots_[slot];
  const double lo = time.lower();
  exact_times_[slot] = std::move(time);
  s.event = Event{lo, next_sequence_++, owner, payload};
  const std::uint32_t order = next_order();
  heap_.emplace_back();
  sift_up<true>(count() - 1, Entry{lo, order, slot});
  max_size_ = std::max(max_size_, size());
  return EventHandle{slot, s.generation};
}

bool EventQueue::exact_before_close(const Entry& a, const Entry& b) const {
  LazyTime& x = exact_times_[a.slot];
  LazyTime& y = exact_times_[b.slot];
  if (x.upper() < y.lower()) return true;
  if (y.upper() < x.lower()) return false;
  ++exact_comparisons_;
  const std::size_t before = x.refinements() + y.refinements();
  const int c = compare(x, y);
  exact_refinements_ += x.refinements() + y.refinements() - before;
  return c != 0 ? c < 0 : a.order < b.order;
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
  const bool due = compare(x, point) <= 0;
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
  const std::uint32_t i = heap_index_[h.slot];
  if ((i & kFar) != 0) {
    far_erase(i & ~kFar);
  } else {
    heap_erase(i);
  }
  release(h.slot);
  if (empty() && !far_.empty()) refill();
}

void EventQueue::update(EventHandle h, Time time) {
  assert(contains(h));
  assert(!std::isnan(time));
  Slot& s = slots_[h.slot];
  s.event.time = time;
  s.event.sequence = next_sequence_++;
  if (exact_) exact_times_[h.slot] = LazyTime::point(time);
  const std::uint32_t order = next_order();
  const Entry e{time, order, h.slot};
  const std::uint32_t i = heap_index_[h.slot];
  const bool to_heap = in_heap_tier(e);
  if ((i & kFar) == 0) {
    if (to_heap) {
      sift(i, e);
    } else {
      heap_erase(i);
      far_append(e);
      if (empty()) refill();
    }
  } else if (to_heap) {
    far_erase(i & ~kFar);
    heap_.emplace_back();
    sift_up<false>(count() - 1, e);
  } else {
    far_[i & ~kFar] = e;
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
  } else if (!far_.empty()) {
    refill();
  }
  release(slot);
  return e;
}

void EventQueue::clear() {
  for (std::uint32_t i = 0; i < count(); ++i) release(at(i).slot);
  for (const Entry& f : far_) release(f.slot);
  heap_.resize(kOffset);
  far_.clear();
}

void EventQueue::renumber() {
  // The queued events numbered 0 .. size - 1 in their order: the heap stays a heap (every
  // comparison between them comes out as before), and later events number on from there.
  // The far tier's events are numbered with them (pointers to every queued entry), and split_
  // becomes the heap's largest key afterwards: it still lies between the two tiers.
  std::vector<Entry*> by_order;
  by_order.reserve(size());
  for (std::uint32_t i = 0; i < count(); ++i) by_order.push_back(&at(i));
  for (Entry& f : far_) by_order.push_back(&f);
  std::sort(by_order.begin(), by_order.end(),
            [](const Entry* x, const Entry* y) { return x->order < y->order; });
  for (std::uint32_t k = 0; k < by_order.size(); ++k) by_order[k]->order = k;
  next_order_ = by_order.size();
  if (tiered_ && !empty()) {
    split_ = at(0);
    for (std::uint32_t i = 1; i < count(); ++i)
      if (before(split_, at(i))) split_ = at(i);
  }
}

std::uint32_t EventQueue::next_order() {
  if (next_order_ > std::numeric_limits<std::uint32_t>::max()) renumber();
  return static_cast<std::uint32_t>(next_order_++);
}

void EventQueue::release(std::uint32_t slot) {
  heap_index_[slot] = kNoIndex;
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
  // The far tier: only with tiers (the double order), its events after split_, every heap key at
  // or before it, and the heap empty only when far_ is.
  if (!far_.empty() && (!tiered_ || exact_ || empty())) return false;
  for (std::uint32_t i = 0; i < far_.size(); ++i) {
    const Entry& e = far_[i];
    if (e.slot >= slots_.size() || heap_index_[e.slot] != (kFar | i)) return false;
    if (!before(split_, e) || e.order >= next_order_ || slots_[e.slot].event.time != e.time)
      return false;
  }
  if (tiered_ && !far_.empty()) {
    for (std::uint32_t i = 0; i < count(); ++i)
      if (before(split_, at(i))) return false;
  }
  std::size_t live = 0;
  for (const std::uint32_t h : heap_index_) live += h != kNoIndex;
  return live == size() && live + free_.size() == slots_.size() &&
         heap_index_.size() == slots_.size();
}

}  // namespace kinetic
