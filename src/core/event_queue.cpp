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
  heap_.push_back(slot);
  s.heap_index = static_cast<std::uint32_t>(heap_.size() - 1);
  sift_up(s.heap_index);
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
  const std::uint32_t last = static_cast<std::uint32_t>(heap_.size() - 1);
  if (i != last) {
    const std::uint32_t moved = heap_[last];
    place(i, moved);
    heap_.pop_back();
    sift_up(i);
    sift_down(slots_[moved].heap_index);
  } else {
    heap_.pop_back();
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
  sift_up(i);
  sift_down(slots_[h.slot].heap_index);
}

Event EventQueue::pop() {
  assert(!heap_.empty());
  const std::uint32_t slot = heap_.front();
  const Event e = slots_[slot].event;
  const std::uint32_t last = static_cast<std::uint32_t>(heap_.size() - 1);
  if (last != 0) {
    place(0, heap_[last]);
    heap_.pop_back();
    sift_down(0);
  } else {
    heap_.pop_back();
  }
  release(slot);
  return e;
}

void EventQueue::clear() {
  for (std::uint32_t slot : heap_) release(slot);
  heap_.clear();
}

void EventQueue::place(std::uint32_t heap_index, std::uint32_t slot) {
  heap_[heap_index] = slot;
  slots_[slot].heap_index = heap_index;
}

void EventQueue::release(std::uint32_t slot) {
  slots_[slot].heap_index = kNoIndex;
  ++slots_[slot].generation;
  free_.push_back(slot);
}

void EventQueue::sift_up(std::uint32_t i) {
  const std::uint32_t slot = heap_[i];
  const Event& e = slots_[slot].event;
  while (i > 0) {
    const std::uint32_t parent = (i - 1) / 2;
    if (!before(e, slots_[heap_[parent]].event)) break;
    place(i, heap_[parent]);
    i = parent;
  }
  place(i, slot);
}

void EventQueue::sift_down(std::uint32_t i) {
  const std::uint32_t n = static_cast<std::uint32_t>(heap_.size());
  const std::uint32_t slot = heap_[i];
  const Event& e = slots_[slot].event;
  for (;;) {
    std::uint32_t child = 2 * i + 1;
    if (child >= n) break;
    if (child + 1 < n && before(slots_[heap_[child + 1]].event, slots_[heap_[child]].event))
      ++child;
    if (!before(slots_[heap_[child]].event, e)) break;
    place(i, heap_[child]);
    i = child;
  }
  place(i, slot);
}

bool EventQueue::validate() const {
  for (std::uint32_t i = 0; i < heap_.size(); ++i) {
    if (slots_[heap_[i]].heap_index != i) return false;
    if (i > 0 && before(slots_[heap_[i]].event, slots_[heap_[(i - 1) / 2]].event)) return false;
  }
  std::size_t live = 0;
  for (const Slot& s : slots_) live += s.heap_index != kNoIndex;
  return live == heap_.size() && live + free_.size() == slots_.size();
}

}  // namespace kinetic
