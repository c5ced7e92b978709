#include "kinetic/core/event_queue.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace kinetic {

EventHandle EventQueue::push(Time time, std::uint32_t owner, std::uint32_t payload) {
  assert(!std::isnan(time));
  std::uint32_t slot;
  if (!free_.empty()) {
    slot = free_.back();
    free_.pop_back();
  } else {
    slot = static_cast<std::uint32_t>(slots_.size());
    slots_.emplace_back();
  }
  Slot& s = slots_[slot];
  s.event = Event{time, next_sequence_++, owner, payload};
  heap_.emplace_back();
  sift_up(static_cast<std::uint32_t>(heap_.size() - 1), Entry{time, s.event.sequence, slot});
  max_size_ = std::max(max_size_, heap_.size());
  return EventHandle{slot, s.generation};
}

bool EventQueue::contains(EventHandle h) const {
  return h.slot < slots_.size() && slots_[h.slot].generation == h.generation &&
         slots_[h.slot].heap_index != kNoIndex;
}

const Event& EventQueue::get(EventHandle h) const {
  assert(contains(h));
  return slots_[h.slot].event;
}

void EventQueue::remove(EventHandle h) {
  assert(contains(h));
  const std::uint32_t i = slots_[h.slot].heap_index;
  const Entry last = heap_.back();
  heap_.pop_back();
  if (i < heap_.size()) {
    // The last entry fills the hole, then moves up or down.
    if (i > 0 && before(last, heap_[(i - 1) / kArity])) {
      sift_up(i, last);
    } else {
      sift_down(i, last);
    }
  }
  release(h.slot);
}

void EventQueue::update(EventHandle h, Time time) {
  assert(contains(h));
  assert(!std::isnan(time));
  Slot& s = slots_[h.slot];
  s.event.time = time;
  s.event.sequence = next_sequence_++;
  const std::uint32_t i = s.heap_index;
  const Entry e{time, s.event.sequence, h.slot};
  if (i > 0 && before(e, heap_[(i - 1) / kArity])) {
    sift_up(i, e);
  } else {
    sift_down(i, e);
  }
}

Event EventQueue::pop() {
  assert(!heap_.empty());
  const std::uint32_t slot = heap_.front().slot;
  const Event e = slots_[slot].event;
  const Entry last = heap_.back();
  heap_.pop_back();
  if (!heap_.empty()) sift_down(0, last);
  release(slot);
  return e;
}

void EventQueue::clear() {
  for (const Entry& e : heap_) release(e.slot);
  heap_.clear();
}

void EventQueue::place(std::uint32_t heap_index, const Entry& e) {
  heap_[heap_index] = e;
  slots_[e.slot].heap_index = heap_index;
}

void EventQueue::release(std::uint32_t slot) {
  slots_[slot].heap_index = kNoIndex;
  ++slots_[slot].generation;
  free_.push_back(slot);
}

void EventQueue::sift_up(std::uint32_t i, Entry e) {
  while (i > 0) {
    const std::uint32_t parent = (i - 1) / kArity;
    if (!before(e, heap_[parent])) break;
    place(i, heap_[parent]);
    i = parent;
  }
  place(i, e);
}

void EventQueue::sift_down(std::uint32_t i, Entry e) {
  const auto n = static_cast<std::uint32_t>(heap_.size());
  for (;;) {
    const std::uint32_t first = kArity * i + 1;
    if (first >= n) break;
    const std::uint32_t end = std::min(first + kArity, n);
    std::uint32_t child = first;
    for (std::uint32_t c = first + 1; c < end; ++c) {
      if (before(heap_[c], heap_[child])) child = c;
    }
    if (!before(heap_[child], e)) break;
    place(i, heap_[child]);
    i = child;
  }
  place(i, e);
}

bool EventQueue::validate() const {
  for (std::uint32_t i = 0; i < heap_.size(); ++i) {
    const Entry& e = heap_[i];
    if (e.slot >= slots_.size() || slots_[e.slot].heap_index != i) return false;
    const Event& ev = slots_[e.slot].event;
    if (ev.time != e.time && !(std::isnan(ev.time) && std::isnan(e.time))) return false;
    if (ev.sequence != e.sequence) return false;
    if (i > 0 && before(e, heap_[(i - 1) / kArity])) return false;
  }
  std::size_t live = 0;
  for (const Slot& s : slots_) live += s.heap_index != kNoIndex;
  return live == heap_.size() && live + free_.size() == slots_.size();
}

}  // namespace kinetic
