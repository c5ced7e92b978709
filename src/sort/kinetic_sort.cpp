#include "kinetic/sort/kinetic_sort.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstddef>
#include <tuple>
#include <type_traits>

#include "kinetic/core/predicates.hpp"

namespace kinetic {

template <SortKeys Keys>
BasicKineticSort<Keys>::BasicKineticSort(const MotionTable& motions, Simulator& simulator,
                                         const Scheduler& scheduler, int axis, SortLayout layout)
    : keys_(motions, axis),
      motions_(motions),
      sim_(simulator),
      scheduler_(scheduler),
      owner_(simulator.reserve_owners(1).first),
      gapped_(layout == SortLayout::Gapped) {
  simulator.attach(scheduler);
}

template <SortKeys Keys>
NamedCounters BasicKineticSort<Keys>::named_counters() const {
  return {{"swaps", counters_.swaps},
          {"inserts", counters_.inserts},
          {"removes", counters_.removes},
          {"updates", counters_.updates},
          {"swapped_pairs_settled", counters_.swapped_pairs_settled}};
}

template <SortKeys Keys>
bool BasicKineticSort<Keys>::before_after_now(std::uint32_t a, std::uint32_t b) const {
  if (scheduler_.floating_point_decisions()) {
    // A traditional KDS orders by the keys' floating-point values at now. An order that is wrong
    // just after now is swapped back when the floating-point root of its certificate falls at
    // now or later, and kept wrong otherwise (the traditional KDS's weakness).
    const double va = keys_.value_at(a, sim_.now()), vb = keys_.value_at(b, sim_.now());
    if (va != vb) return va < vb;
    return keys_.tie_before(a, b);
  }
  const int s = keys_.compare_after(a, b, sim_.now(), &sim_.counters().predicates);
  if (s != 0) return s < 0;
  return keys_.tie_before(a, b);  // identical functions: a fixed, deterministic order
}

template <SortKeys Keys>
bool BasicKineticSort<Keys>::slot_before_after_now(std::size_t j, std::uint32_t key) const {
  if constexpr (kMotionsInOrder) {
    // The same decision as before_after_now(A[j], key), reading A[j]'s motion from its entry in
    // sort order (one cache line) instead of the table.
    if (!scheduler_.floating_point_decisions()) {
      const int s =
          compare_after(motion_at(j), keys_.motion(key), sim_.now(), &sim_.counters().predicates);
      if (s != 0) return s < 0;
      return keys_.tie_before(order_[j], key);
    }
  }
  return before_after_now(order_[j], key);
}

template <SortKeys Keys>
void BasicKineticSort<Keys>::initialize() {
  sync_.note();
  for (std::size_t j = 0; j < cert_.size(); ++j) cancel_at(j);
  order_.clear();
  for (const std::uint32_t object : motions_.alive_indices()) {
    keys_.refresh(object);
    for (std::uint32_t k = 0; k < kKeysPerObject; ++k) order_.push_back(first_key(object) + k);
  }
  std::sort(order_.begin(), order_.end(),
            [this](std::uint32_t a, std::uint32_t b) { return before_after_now(a, b); });
  size_ = order_.size();
  position_.assign(kKeysPerObject * motions_.capacity(), kNoIndex);
  cap_ = -1;
  if constexpr (kMotionsInOrder) cap_ = std::max(1, motions_.max_degree());
  if (gapped_) {
    // The sorted keys spread evenly over the segments (density <= 1/2), then read as above.
    gather_keys_.assign(order_.begin(), order_.end());
    gather_cert_.clear();
    gather_local_.clear();
    relabel_entry_.assign(position_.size(), kNoIndex);
    relabeled_.clear();
    relabeled_from_.clear();
    seg_count_.clear();
    relayout(size_);
    for (std::size_t j = 0; j < order_.size(); ++j) {
      if (order_[j] != kNoIndex) refresh_in_order(j, j);
    }
    for (std::size_t j = 0; j < order_.size(); ++j) {
      if (order_[j] != kNoIndex && next_slot(j) != kNoSlot) schedule(j);
    }
    return;
  }
  cert_.assign(order_.size(), EventHandle{});
  for (std::size_t j = 0; j < order_.size(); ++j)
    position_[order_[j]] = static_cast<std::uint32_t>(j);
  local_.assign(order_.size() * stride(), 0.0);
  if (!order_.empty()) refresh_in_order(0, order_.size() - 1);
  for (std::size_t j = 0; j + 1 < order_.size(); ++j) schedule(j);
}

template <SortKeys Keys>
void BasicKineticSort<Keys>::refresh_in_order(std::size_t lo, std::size_t hi) {
  for (std::size_t j = lo; j <= hi; ++j) {
    double* entry = &local_[j * stride()];
    entry[0] = motions_.valid_from(object_of(order_[j]));
    if constexpr (kMotionsInOrder) {
      const MotionPolynomial& m = keys_.motion(order_[j]);
      if (m.degree > cap_) {
        widen(m.degree);
        entry = &local_[j * stride()];
      }
      entry[1] = m.origin;
      for (int k = 0; k <= cap_; ++k) entry[2 + k] = m.c[static_cast<std::size_t>(k)];
    }
  }
}

template <SortKeys Keys>
void BasicKineticSort<Keys>::widen(int degree) {
  // A motion of a higher degree than the entries hold: every entry gets room for it.
  const std::size_t old_stride = stride(), n = local_.size() / old_stride;
  cap_ = degree;
  HugeVector<double> wider(n * stride(), 0.0);
  for (std::size_t j = 0; j < n; ++j)
    std::copy_n(&local_[j * old_stride], old_stride, &wider[j * stride()]);
  local_ = std::move(wider);
}

template <SortKeys Keys>
MotionPolynomial BasicKineticSort<Keys>::motion_at(std::size_t position) const {
  const double* entry = &local_[position * stride()];
  MotionPolynomial m;
  m.origin = entry[1];
  for (int k = 0; k <= cap_; ++k) {
    m.c[static_cast<std::size_t>(k)] = entry[2 + k];
    if (entry[2 + k] != 0.0) m.degree = k;
  }
  return m;
}

template <SortKeys Keys>
void BasicKineticSort<Keys>::cancel_at(std::size_t position) {
  sim_.cancel(cert_[position]);
}

template <SortKeys Keys>
void BasicKineticSort<Keys>::schedule(std::size_t position) {
  const std::uint32_t lower = order_[position];
  const std::size_t upper = next_slot(position);
  const Time window_lo = std::max(local_[position * stride()], local_[upper * stride()]);
  ExactFailure exact;
  Time t;
  if constexpr (kMotionsInOrder) {
    t = scheduler_.failure_time(motion_at(position), motion_at(upper), sim_.now(), window_lo,
                                sim_.counters(), &exact);
  } else {
    t = keys_.failure_time(scheduler_, lower, order_[upper], sim_.now(), window_lo, sim_.counters(),
                           &exact);
  }
  // Two keys that are the same function of t never fail by a root; their order is the tie order
  // for ever. A robust or classic change made while an event within eps is pending may place a
  // key beside its identical twin's neighbour, on the wrong side of the twin (the order is
  // sorted just after now only once those events are processed): that pair fails now, and its
  // swap restores the tie order (found by fuzzing: identical point boxes lost their contact).
  if (t == kTimeInfinity && scheduler_.kind() != SchedulerKind::Exact &&
      keys_.tie_before(order_[upper], lower) &&
      keys_.compare_after(lower, order_[upper], sim_.now(), nullptr) == 0)
    t = sim_.now();
  sim_.reschedule(cert_[position], t, std::move(exact), owner_, lower);
}

template <SortKeys Keys>
typename BasicKineticSort<Keys>::Swap BasicKineticSort<Keys>::process_swap(const Event& event) {
  const std::uint32_t x = event.payload;
  assert(x < position_.size() && position_[x] != kNoIndex);
  const std::size_t j = position_[x];
  // The next key: at j + 1 (dense), at the next occupied slot (gapped).
  const std::size_t k = next_slot(j);
  assert(k < order_.size());
  cert_[j] = EventHandle{};  // popped by the simulator
  const std::size_t before = prev_slot(j);
  // The events of the neighbouring certificates are moved below, after their failure times
  // are computed: their slots are asked for now (a hint).
  if (before != kNoSlot) sim_.queue().prefetch_slot(cert_[before]);
  sim_.queue().prefetch_slot(cert_[k]);
  const std::uint32_t y = order_[k];
  if (measure_delays_ && scheduler_.kind() == SchedulerKind::Robust) note_delay(x, y, event.time);
  // Swap x and y (Abam, Agarwal, de Berg, Yu, KINETICSORTING line 5), then replace the certificates
  // of the three adjacent pairs that changed (lines 6-11).
  order_[j] = y;
  order_[k] = x;
  position_[y] = static_cast<std::uint32_t>(j);
  position_[x] = static_cast<std::uint32_t>(k);
  std::swap_ranges(&local_[j * stride()], &local_[(j + 1) * stride()], &local_[k * stride()]);
  ++counters_.swaps;
  if (log_swaps_ && sim_.logging_events()) {
    const std::array<ObjectId, 2> ids{motions_.id(object_of(x)), motions_.id(object_of(y))};
    sim_.log_event("swap", ids, axis());
  }
  if (before != kNoSlot) schedule(before);
  if (swapped_pair_holds(j, k, event.time)) {
    ++counters_.swapped_pairs_settled;  // [y < x] never fails again: its cert_ entry stays null
  } else {
    schedule(j);
  }
  // (x last: its cert_ entry stays null)
  if (next_slot(k) != kNoSlot) schedule(k);
  return Swap{static_cast<std::uint32_t>(j), x, y, static_cast<std::uint32_t>(k)};
}

template <SortKeys Keys>
void BasicKineticSort<Keys>::note_delay(std::uint32_t x, std::uint32_t y, Time t_cp) {
  if constexpr (std::is_same_v<Keys, AxisKeys>) {
    // t_cp is the right end of an event interval of width <= eps containing t_ex (Abam, Agarwal, de
    // Berg, Yu, Section 3: t_ex < t_cp < t_ex + eps), unless it is the start of the window (rho_0).
    // CROP's own intervals are narrower (Scheduler::grid_width), a failure-time model's may be eps
    // wide.
    const double eps = scheduler_.eps();
    const Time t_ex = last_root_before(keys_.motion(y), keys_.motion(x), t_cp, eps,
                                       Scheduler::grid_width(eps) * 0x1p-24);
    if (t_ex < t_cp) sim_.counters().note_delay(sim_.now() - t_ex);
  }
}

template <SortKeys Keys>
std::size_t BasicKineticSort<Keys>::locate(std::uint32_t key) const {
  // Binary search with the order of before_after_now() (exact as just after now; the traditional
  // classic's floating-point values). If the maintained order is temporarily wrong (near an
  // event), this still yields a valid position in the array.
  std::size_t lo = 0, hi = order_.size();
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (slot_before_after_now(mid, key)) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  return lo;
}

template <SortKeys Keys>
void BasicKineticSort<Keys>::grow() {
  const std::size_t keys = kKeysPerObject * motions_.capacity();
  if (position_.size() < keys) position_.resize(keys, kNoIndex);
  if (gapped_ && relabel_entry_.size() < keys) relabel_entry_.resize(keys, kNoIndex);
}

template <SortKeys Keys>
void BasicKineticSort<Keys>::place(std::uint32_t key, std::size_t p) {
  const auto at = static_cast<std::ptrdiff_t>(p);
  order_.insert(order_.begin() + at, key);
  cert_.insert(cert_.begin() + at, EventHandle{});
  local_.insert(local_.begin() + at * static_cast<std::ptrdiff_t>(stride()), stride(), 0.0);
  refresh_in_order(p, p);
  ++size_;
  for (std::size_t j = p; j < order_.size(); ++j)
    position_[order_[j]] = static_cast<std::uint32_t>(j);
  if (p > 0) schedule(p - 1);  // [A[p-1] < key] replaces [A[p-1] < old A[p]]
  if (p + 1 < order_.size()) schedule(p);
}

template <SortKeys Keys>
void BasicKineticSort<Keys>::insert(std::uint32_t index) {
  sync_.require_inserted("KineticSort::insert", index);
  ++counters_.inserts;
  grow();
  keys_.refresh(index);
  if (gapped_) {
    begin_change();
    for (std::uint32_t k = 0; k < kKeysPerObject; ++k) place_gapped(first_key(index) + k);
    forget_own_relabels(index);
    return;
  }
  // Each key at its place among those already placed (the object's earlier keys included),
  // after the object's earlier keys: a box's high side after its low side even where the robust
  // order is briefly inverted around them and the binary search would end before it.
  for (std::uint32_t k = 0; k < kKeysPerObject; ++k) {
    std::size_t p = locate(first_key(index) + k);
    if (k > 0) p = std::max<std::size_t>(p, position_[first_key(index) + k - 1] + std::size_t{1});
    place(first_key(index) + k, p);
  }
}

template <SortKeys Keys>
void BasicKineticSort<Keys>::erase_at(std::size_t p) {
  const auto at = static_cast<std::ptrdiff_t>(p);
  order_.erase(order_.begin() + at);
  cert_.erase(cert_.begin() + at);
  const auto width = static_cast<std::ptrdiff_t>(stride());
  local_.erase(local_.begin() + at * width, local_.begin() + (at + 1) * width);
}

template <SortKeys Keys>
void BasicKineticSort<Keys>::detach(std::uint32_t key) {
  assert(key < position_.size() && position_[key] != kNoIndex);
  const std::size_t p = position_[key];
  cancel_at(p);
  erase_at(p);
  --size_;
  position_[key] = kNoIndex;
  for (std::size_t j = p; j < order_.size(); ++j)
    position_[order_[j]] = static_cast<std::uint32_t>(j);
  if (p > 0) {
    if (p < order_.size()) {
      schedule(p - 1);  // the neighbours of the removed point become adjacent
    } else {
      cancel_at(p - 1);  // the new last element has no certificate
    }
  }
}

template <SortKeys Keys>
void BasicKineticSort<Keys>::remove(std::uint32_t index) {
  sync_.require_removed("KineticSort::remove", index);
  ++counters_.removes;
  if (gapped_) {
    begin_change();
    detach_object_gapped(index);
    return;
  }
  if constexpr (kKeysPerObject == 1) {
    detach(index);
  } else {
    // All the object's keys leave first (a certificate between one of them and another would
    // read the removed object's motion), then the seams get their certificates.
    std::array<std::uint32_t, kKeysPerObject> at{};
    for (std::uint32_t k = 0; k < kKeysPerObject; ++k) {
      const std::uint32_t key = first_key(index) + k;
      at[k] = position_[key];
      cancel_at(at[k]);
      position_[key] = kNoIndex;
    }
    std::sort(at.begin(), at.end());
    for (std::uint32_t k = kKeysPerObject; k-- > 0;) erase_at(at[k]);
    size_ -= kKeysPerObject;
    for (std::size_t j = at[0]; j < order_.size(); ++j)
      position_[order_[j]] = static_cast<std::uint32_t>(j);
    for (std::uint32_t k = 0; k < kKeysPerObject; ++k) {
      const std::size_t q = at[k] - k;  // where the entry after the k-th removed key is now
      if (q == 0) continue;
      if (q < order_.size()) {
        schedule(q - 1);
      } else {
        cancel_at(q - 1);  // the new last entry has no certificate
      }
    }
  }
}

template <SortKeys Keys>
std::size_t BasicKineticSort<Keys>::rank_among_others(
    std::uint32_t key, const std::array<std::uint32_t, kKeysPerObject>& own_positions) const {
  // Binary search as locate(), over the order without the object's own keys (ascending
  // own_positions): the m-th other entry sits at m plus the own positions at or before it.
  const auto other = [&](std::size_t m) {
    for (const std::uint32_t p : own_positions) m += (m >= p) ? 1 : 0;
    return order_[m];
  };
  std::size_t lo = 0, hi = order_.size() - kKeysPerObject;
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (before_after_now(other(mid), key)) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  return lo;
}

template <SortKeys Keys>
std::uint32_t BasicKineticSort<Keys>::rank_after_update(std::uint32_t index) const
    requires(Keys::kKeysPerObject == 1) {
  assert(index < position_.size() && position_[index] != kNoIndex);
  if (gapped_) precondition_failed("KineticSort::rank_after_update", "a dense layout only");
  return static_cast<std::uint32_t>(rank_among_others(index, {position_[index]}));
}

template <SortKeys Keys>
void BasicKineticSort<Keys>::motion_changed(std::uint32_t index) {
  sync_.require_updated("KineticSort::motion_changed", index);
  // A flight-plan update may move the object's keys anywhere. Their new places are found as if
  // they were taken out (rank_among_others), then only the entries between the old and new
  // places move, and only the certificates whose pair changed or that involve the object are
  // replaced: O(log n) comparisons and O(distance moved) array work.
  ++counters_.updates;
  keys_.refresh(index);
  if (gapped_) {
    begin_change();
    detach_object_gapped(index);
    for (std::uint32_t k = 0; k < kKeysPerObject; ++k) place_gapped(first_key(index) + k);
    forget_own_relabels(index);
    return;
  }
  constexpr std::uint32_t K = kKeysPerObject;
  const std::size_t n = order_.size();
  std::array<std::uint32_t, K> own{}, old_positions{};
  for (std::uint32_t k = 0; k < K; ++k) {
    own[k] = first_key(index) + k;
    old_positions[k] = position_[own[k]];
  }
  std::sort(old_positions.begin(), old_positions.end());
  std::sort(own.begin(), own.end(),
            [this](std::uint32_t a, std::uint32_t b) { return before_after_now(a, b); });
  std::array<std::size_t, K> final_positions{};
  for (std::uint32_t k = 0; k < K; ++k) {
    final_positions[k] = rank_among_others(own[k], old_positions) + k;
    if (k > 0) final_positions[k] = std::max(final_positions[k], final_positions[k - 1] + 1);
  }
  const std::size_t lo = std::min<std::size_t>(old_positions[0], final_positions[0]);
  const std::size_t hi = std::max<std::size_t>(old_positions[K - 1], final_positions[K - 1]);
  scratch_.assign(order_.begin() + static_cast<std::ptrdiff_t>(lo),
                  order_.begin() + static_cast<std::ptrdiff_t>(hi + 1));
  scratch_cert_.assign(cert_.begin() + static_cast<std::ptrdiff_t>(lo),
                       cert_.begin() + static_cast<std::ptrdiff_t>(hi + 1));
  std::size_t w = lo, k = 0;
  for (const std::uint32_t x : scratch_) {
    if (object_of(x) == index) continue;
    while (k < K && final_positions[k] == w) order_[w++] = own[k++];
    order_[w++] = x;
  }
  while (k < K) order_[w++] = own[k++];
  assert(w == hi + 1);
  // The pairs [A[j] < A[j+1]] to replace, j in [lo - 1, hi]: the object's own, and those whose
  // lower entry has another successor than before (position_ still holds the old places).
  const auto old_successor = [&](std::uint32_t x) -> std::uint32_t {
    const std::size_t p = position_[x] + std::size_t{1};
    if (p >= n) return kNoIndex;
    return (p >= lo && p <= hi) ? scratch_[p - lo] : order_[p];
  };
  renew_.clear();
  for (std::size_t j = lo > 0 ? lo - 1 : 0; j <= hi; ++j) {
    const std::uint32_t x = order_[j];
    const std::uint32_t next = j + 1 < n ? order_[j + 1] : kNoIndex;
    if (object_of(x) == index || (next != kNoIndex && object_of(next) == index) ||
        old_successor(x) != next) {
      renew_.push_back(j);
    }
  }
  // Each event moves with its lower key (position_ still holds the old places); then the
  // range's motions and valid-from times are read again (the object's changed).
  for (std::size_t j = lo; j <= hi; ++j) cert_[j] = scratch_cert_[position_[order_[j]] - lo];
  for (std::size_t j = lo; j <= hi; ++j) position_[order_[j]] = static_cast<std::uint32_t>(j);
  refresh_in_order(lo, hi);
  for (const std::size_t j : renew_) {
    if (j + 1 < n) {
      schedule(j);
    } else {
      cancel_at(j);  // the last entry has no certificate
    }
  }
}

template <SortKeys Keys>
bool BasicKineticSort<Keys>::validate() const {
  if (!sync_.current()) return false;
  if (gapped_) {
    // U a power of two in whole segments; every segment packed to the left, and (U > one
    // segment) holding at least kGapSegment / 8 keys; the empty slots hold nothing.
    const std::size_t segments = seg_count_.size();
    if (segments == 0 || (segments & (segments - 1)) != 0) return false;
    if (order_.size() != segments * kGapSegment) return false;
    std::size_t keys = 0;
    for (std::size_t g = 0; g < segments; ++g) {
      if (seg_count_[g] > kGapSegment) return false;
      if (segments > 1 && seg_count_[g] < kGapSegment / 8) return false;
      keys += seg_count_[g];
      for (std::size_t o = 0; o < kGapSegment; ++o) {
        const std::size_t j = g * kGapSegment + o;
        if ((order_[j] != kNoIndex) != (o < seg_count_[g])) return false;
        if (order_[j] == kNoIndex && !cert_[j].is_null()) return false;
      }
    }
    if (keys != size_) return false;
  } else if (size_ != order_.size()) {
    return false;
  }
  for (std::size_t j = 0; j < order_.size(); ++j) {
    const std::uint32_t x = order_[j];
    if (x == kNoIndex) continue;  // an empty slot (gapped)
    if (!motions_.alive_index(object_of(x)) || x >= position_.size() || position_[x] != j)
      return false;
    if constexpr (kMotionsInOrder) {
      const MotionPolynomial& m = keys_.motion(x);
      const MotionPolynomial mine = motion_at(j);
      if (m.origin != mine.origin || m.degree != mine.degree || m.c != mine.c) return false;
    }
    if (local_[j * stride()] != motions_.valid_from(object_of(x))) return false;
    const EventHandle h = cert_[j];
    if (next_slot(j) == kNoSlot) {
      if (!h.is_null()) return false;
      continue;
    }
    if (!h.is_null()) {
      if (!sim_.queue().contains(h)) return false;
      const Event& e = sim_.queue().get(h);
      if (e.owner != owner_ || e.payload != x) return false;
    }
  }
  if (cert_.size() != order_.size() || local_.size() != order_.size() * stride()) return false;
  std::size_t in_order = 0;
  for (std::size_t i = 0; i < position_.size(); ++i) in_order += position_[i] != kNoIndex;
  return in_order == size_ && size_ == kKeysPerObject * motions_.size();
}

template <SortKeys Keys>
SortAudit BasicKineticSort<Keys>::audit(Time t) const {
  std::size_t j = 0;
  while (j < order_.size() && order_[j] == kNoIndex) ++j;
  for (std::size_t k = j < order_.size() ? next_slot(j) : kNoSlot; k != kNoSlot;
       j = k, k = next_slot(k)) {
    if (keys_.compare_at(order_[j], order_[k], t) > 0) return SortAudit{false, j};
  }
  return SortAudit{};
}

// --- The gapped layout (SortLayout::Gapped). ------------------------------------------------
// A packed-memory array: U = segments * kGapSegment slots, every segment packed to the left.
// Density bounds per window of 2^l segments (l = 0 a segment, l = h the whole array, h =
// log2(segments)): a segment may be full and must keep kGapSegment / 8 keys (when there are
// two segments or more); a window of level l >= 1 has the bounds [(h + l) / 8h, (7h - l) / 8h]
// of its slots, from [1/8, 7/8] at the first level to [1/4, 3/4] for the whole array, checked
// when a segment is out of its own (so only the segments' bounds are invariants: n <= U <= 8n). A
// segment out of its bounds spreads the smallest enclosing window within its own; no such
// window: the array is laid out again at density <= 1/2 (U doubles or halves). A spread window
// ends with every segment within [kGapSegment / 8, 7 kGapSegment / 8], so each segment takes
// Omega(kGapSegment) inserts or removes before it is out of bounds again.

template <SortKeys Keys>
std::pair<std::size_t, std::size_t> BasicKineticSort<Keys>::locate_gapped(std::uint32_t key) const {
  // The last segment whose first key is before `key` (segments are never empty when there are
  // two or more), then the first key in it that is not.
  std::size_t lo = 0, hi = seg_count_.size();
  while (hi - lo > 1) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (slot_before_after_now(mid * kGapSegment, key)) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  const std::size_t g = lo;
  std::size_t a = 0, b = seg_count_[g];
  while (a < b) {
    const std::size_t mid = a + (b - a) / 2;
    if (slot_before_after_now(g * kGapSegment + mid, key)) {
      a = mid + 1;
    } else {
      b = mid;
    }
  }
  return {g, a};
}

template <SortKeys Keys>
void BasicKineticSort<Keys>::move_entries(std::size_t from, std::size_t count, std::size_t to) {
  if (count == 0 || from == to) return;
  const auto f = static_cast<std::ptrdiff_t>(from), t = static_cast<std::ptrdiff_t>(to),
             c = static_cast<std::ptrdiff_t>(count), w = static_cast<std::ptrdiff_t>(stride());
  if (to < from) {
    std::move(order_.begin() + f, order_.begin() + f + c, order_.begin() + t);
    std::move(cert_.begin() + f, cert_.begin() + f + c, cert_.begin() + t);
    std::move(local_.begin() + f * w, local_.begin() + (f + c) * w, local_.begin() + t * w);
  } else {
    std::move_backward(order_.begin() + f, order_.begin() + f + c, order_.begin() + t + c);
    std::move_backward(cert_.begin() + f, cert_.begin() + f + c, cert_.begin() + t + c);
    std::move_backward(local_.begin() + f * w, local_.begin() + (f + c) * w,
                       local_.begin() + (t + c) * w);
  }
  touch(std::min(from, to), std::max(from, to) + count - 1);
  for (std::size_t j = to; j < to + count; ++j) {
    note_relabel(order_[j]);
    position_[order_[j]] = static_cast<std::uint32_t>(j);
  }
}

template <SortKeys Keys>
void BasicKineticSort<Keys>::place_gapped(std::uint32_t key) {
  // The last segment whose first key is before `key` (so o >= 1 unless g = 0).
  // (Named, not a structured binding: the lambda below captures them.)
  // After the object's earlier keys (see insert()).
  const auto locate_after_own = [&] {
    std::pair<std::size_t, std::size_t> where = locate_gapped(key);
    if (key % kKeysPerObject != 0) {
      const std::size_t q = position_[key - 1];
      if (where.first * kGapSegment + where.second <= q)
        where = {q / kGapSegment, q % kGapSegment + 1};
    }
    return where;
  };
  const std::pair<std::size_t, std::size_t> at = locate_after_own();
  std::size_t g = at.first, o = at.second;
  // After the last key of a full segment: the front of the next one, if it has room.
  const auto prefer_next = [&] {
    if (o == kGapSegment && g + 1 < seg_count_.size() && seg_count_[g + 1] < kGapSegment) {
      ++g;
      o = 0;
    }
  };
  prefer_next();
  if (seg_count_[g] == kGapSegment) {
    rebalance(g, true);
    std::tie(g, o) = locate_after_own();
  }
  assert(seg_count_[g] < kGapSegment);
  const std::size_t p = g * kGapSegment + o;
  move_entries(p, seg_count_[g] - o, p + 1);
  order_[p] = key;
  cert_[p] = EventHandle{};
  position_[key] = static_cast<std::uint32_t>(p);
  touch(p, p);
  ++seg_count_[g];
  ++size_;
  refresh_in_order(p, p);
  const std::size_t before = prev_slot(p);
  if (before != kNoSlot) schedule(before);  // [A[before] < key] replaces its old pair
  if (next_slot(p) != kNoSlot) schedule(p);
}

template <SortKeys Keys>
void BasicKineticSort<Keys>::detach_gapped(std::uint32_t key, bool reschedule) {
  assert(key < position_.size() && position_[key] != kNoIndex);
  const std::size_t p = position_[key];
  const std::size_t g = p / kGapSegment, end = g * kGapSegment + seg_count_[g];
  const std::size_t before = prev_slot(p);  // not moved below: before p, or in segment g - 1
  cancel_at(p);
  move_entries(p + 1, end - p - 1, p);
  touch(p, end - 1);
  order_[end - 1] = kNoIndex;
  cert_[end - 1] = EventHandle{};
  std::fill_n(&local_[(end - 1) * stride()], stride(), 0.0);
  position_[key] = kNoIndex;
  --seg_count_[g];
  --size_;
  if (reschedule && before != kNoSlot) {
    if (next_slot(before) != kNoSlot) {
      schedule(before);  // the neighbours of the removed key become adjacent
    } else {
      cancel_at(before);  // the new last key has no certificate
    }
  }
  if (seg_count_.size() > 1 && seg_count_[g] < kGapSegment / 8) rebalance(g, false);
}

template <SortKeys Keys>
void BasicKineticSort<Keys>::detach_object_gapped(std::uint32_t index) {
  if constexpr (kKeysPerObject == 1) {
    detach_gapped(index);
  } else {
    // Every certificate that reads one of the object's keys is cancelled first (a seam between
    // two of its keys would otherwise be scheduled on a key about to leave, whose motion may be
    // gone from the table); the keys leave; then the key before each removed run gets its
    // certificate with its new neighbour.
    std::array<std::uint32_t, kKeysPerObject> before{};
    for (std::uint32_t k = 0; k < kKeysPerObject; ++k) {
      const std::size_t p = position_[first_key(index) + k];
      cancel_at(p);
      const std::size_t b = prev_slot(p);
      before[k] = kNoIndex;
      if (b != kNoSlot && object_of(order_[b]) != index) {
        cancel_at(b);
        before[k] = order_[b];
      }
    }
    for (std::uint32_t k = 0; k < kKeysPerObject; ++k)
      detach_gapped(first_key(index) + k, /*reschedule=*/false);
    for (const std::uint32_t x : before) {
      if (x == kNoIndex) continue;
      const std::size_t b = position_[x];
      if (next_slot(b) != kNoSlot) {
        schedule(b);
      } else {
        cancel_at(b);
      }
    }
    forget_own_relabels(index);
  }
}

template <SortKeys Keys>
void BasicKineticSort<Keys>::forget_own_relabels(std::uint32_t index) {
  // Placing or removing one key of an object may move another of its keys: relabeled() tells
  // the other objects' keys only.
  if constexpr (kKeysPerObject > 1) {
    std::size_t w = 0;
    for (std::size_t r = 0; r < relabeled_.size(); ++r) {
      const std::uint32_t x = relabeled_[r];
      if (object_of(x) == index) {
        relabel_entry_[x] = kNoIndex;
        continue;
      }
      relabel_entry_[x] = static_cast<std::uint32_t>(w);
      relabeled_[w] = x;
      relabeled_from_[w] = relabeled_from_[r];
      ++w;
    }
    relabeled_.resize(w);
    relabeled_from_.resize(w);
  } else {
    (void)index;
  }
}

template <SortKeys Keys>
void BasicKineticSort<Keys>::rebalance(std::size_t g, bool inserting) {
  std::size_t h = 0;
  while ((std::size_t{1} << h) < seg_count_.size()) ++h;
  std::size_t keys = seg_count_[g], lo = g, width = 1;
  for (std::size_t l = 1; l <= h; ++l) {
    // The level-l window holding g: add the sibling window's keys.
    const std::size_t half = width, start = (g >> l) << l;
    const std::size_t sibling = lo == start ? start + half : start;
    for (std::size_t s = sibling; s < sibling + half; ++s) keys += seg_count_[s];
    lo = start;
    width *= 2;
    const std::size_t room = width * kGapSegment;
    const bool within =
        inserting ? (keys + 1) * 8 * h <= room * (7 * h - l) : keys * 8 * h >= room * (h + l);
    if (within) {
      spread(lo, width);
      return;
    }
  }
  relayout(inserting ? size_ + 1 : size_);
}

template <SortKeys Keys>
void BasicKineticSort<Keys>::gather(std::size_t g0, std::size_t k) {
  const std::size_t w = stride();
  gather_keys_.clear();
  gather_cert_.clear();
  gather_local_.clear();
  for (std::size_t g = g0; g < g0 + k; ++g) {
    const std::size_t first = g * kGapSegment;
    for (std::size_t j = first; j < first + seg_count_[g]; ++j) {
      gather_keys_.push_back(order_[j]);
      gather_cert_.push_back(cert_[j]);
      gather_local_.insert(gather_local_.end(), &local_[j * w], &local_[(j + 1) * w]);
    }
  }
}

template <SortKeys Keys>
void BasicKineticSort<Keys>::scatter(std::size_t g0, std::size_t k) {
  // m / k keys per segment, the first m mod k segments one more, each packed to the left.
  const std::size_t w = stride();
  const std::size_t m = gather_keys_.size();
  const bool entries = gather_cert_.size() == m;  // initialize() passes the keys alone
  const std::size_t first = g0 * kGapSegment, end = (g0 + k) * kGapSegment;
  std::fill(order_.begin() + static_cast<std::ptrdiff_t>(first),
            order_.begin() + static_cast<std::ptrdiff_t>(end), kNoIndex);
  std::fill(cert_.begin() + static_cast<std::ptrdiff_t>(first),
            cert_.begin() + static_cast<std::ptrdiff_t>(end), EventHandle{});
  std::fill(local_.begin() + static_cast<std::ptrdiff_t>(first * w),
            local_.begin() + static_cast<std::ptrdiff_t>(end * w), 0.0);
  std::size_t i = 0;
  for (std::size_t g = g0; g < g0 + k; ++g) {
    const std::size_t count = m / k + (g - g0 < m % k ? 1 : 0);
    seg_count_[g] = static_cast<std::uint32_t>(count);
    for (std::size_t o = 0; o < count; ++o, ++i) {
      const std::size_t j = g * kGapSegment + o;
      const std::uint32_t x = gather_keys_[i];
      order_[j] = x;
      if (entries) {
        cert_[j] = gather_cert_[i];
        std::copy_n(&gather_local_[i * w], w, &local_[j * w]);
      }
      if (position_[x] != j) {
        note_relabel(x);
        position_[x] = static_cast<std::uint32_t>(j);
      }
    }
  }
}

template <SortKeys Keys>
void BasicKineticSort<Keys>::spread(std::size_t g0, std::size_t k) {
  // The window's entries in order, written back evenly. Their certificates (pairs of adjacent
  // keys) do not change.
  gather(g0, k);
  touch(g0 * kGapSegment, (g0 + k) * kGapSegment - 1);
  scatter(g0, k);
}

template <SortKeys Keys>
void BasicKineticSort<Keys>::relayout(std::size_t n) {
  // Every key in order (initialize() passes them in gather_keys_ with no entries yet), then the
  // fewest segments (a power of two) that hold n keys at density <= 1/2.
  if (!seg_count_.empty()) gather(0, seg_count_.size());
  std::size_t segments = 1;
  while (segments * kGapSegment < 2 * n) segments *= 2;
  order_.assign(segments * kGapSegment, kNoIndex);
  cert_.assign(order_.size(), EventHandle{});
  local_.assign(order_.size() * stride(), 0.0);
  seg_count_.assign(segments, 0);
  scatter(0, segments);
  ++layout_generation_;  // every slot may have changed: nothing is told key by key
  clear_relabels();
  touched_.clear();
  if (!order_.empty()) touched_.emplace_back(0, order_.size() - 1);
}

template <SortKeys Keys>
void BasicKineticSort<Keys>::clear_relabels() {
  for (const std::uint32_t x : relabeled_) relabel_entry_[x] = kNoIndex;
  relabeled_.clear();
  relabeled_from_.clear();
}

template <SortKeys Keys>
void BasicKineticSort<Keys>::begin_change() {
  clear_relabels();
  touched_.clear();
}

template <SortKeys Keys>
void BasicKineticSort<Keys>::note_relabel(std::uint32_t x) {
  // Called before position_[x] changes. A key moved twice in one change (a spread, then a
  // shift) is told once, with the slot it held before the change.
  if (relabel_entry_[x] != kNoIndex) return;
  relabel_entry_[x] = static_cast<std::uint32_t>(relabeled_.size());
  relabeled_.push_back(x);
  relabeled_from_.push_back(position_[x]);
}

namespace {

/// The loop guard's bounds: the crossings of one kinetic sort.
LoopGuard sort_event_bounds(const RunBounds& b) {
  return crossing_guard(1, b.max_objects, b.motion_changes, b.max_degree);
}

}  // namespace

template <>
StructureDescription KineticSort::description() {
  return StructureDescription{
      "sort",
      "Sort",
      ObjectsAre::Points,
      {QueryType::Sorted, QueryType::Max, QueryType::Min},
      {"swap"},
      "Kinetic sorting: the objects in order along one axis (sorted()).",
      "kinetic sorting of points along each axis (one sorted array per axis)"}
      .bound_events(sort_event_bounds);
}

template class BasicKineticSort<AxisKeys>;
template class BasicKineticSort<BoxEndpointKeys>;
template class BasicKineticSort<DirectionKeys>;

}  // namespace kinetic
