#include "kinetic/sort/kinetic_sort.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstddef>

#include "kinetic/core/predicates.hpp"

namespace kinetic {
namespace {}

KineticSort::KineticSort(const MotionTable& motions, Simulator& simulator,
                         const Scheduler& scheduler, int axis)
    : motions_(motions),
      sim_(simulator),
      scheduler_(scheduler),
      axis_(axis),
      owner_(simulator.reserve_owners(1).first) {
  require_axis("KineticSort", axis, motions.dimension());
  simulator.limit_horizon(scheduler.time_limit());
}

NamedCounters KineticSort::named_counters() const {
  return {{"swaps", counters_.swaps},
          {"inserts", counters_.inserts},
          {"removes", counters_.removes},
          {"updates", counters_.updates}};
}

bool KineticSort::before_after_now(std::uint32_t a, std::uint32_t b) const {
  const int s = compare_after(motions_.motion(a, axis_), motions_.motion(b, axis_), sim_.now(),
                              &sim_.counters().predicates);
  if (s != 0) return s < 0;
  return motions_.id(a) < motions_.id(b);  // identical motions: a fixed, deterministic order
}

void KineticSort::initialize() {
  sync_.note();
  for (std::size_t j = 0; j + 1 < order_.size(); ++j) cancel(order_[j]);
  order_ = motions_.alive_indices();
  std::sort(order_.begin(), order_.end(),
            [this](std::uint32_t a, std::uint32_t b) { return before_after_now(a, b); });
  position_.assign(motions_.capacity(), kNoIndex);
  certificate_.assign(motions_.capacity(), EventHandle{});
  for (std::size_t j = 0; j < order_.size(); ++j)
    position_[order_[j]] = static_cast<std::uint32_t>(j);
  for (std::size_t j = 0; j + 1 < order_.size(); ++j) schedule(j);
}

void KineticSort::cancel(std::uint32_t index) {
  EventHandle& h = certificate_[index];
  if (!h.is_null()) {
    if (sim_.queue().contains(h)) sim_.queue().remove(h);
    h = EventHandle{};
  }
}

void KineticSort::schedule(std::size_t position) {
  const std::uint32_t lower = order_[position];
  const std::uint32_t upper = order_[position + 1];
  cancel(lower);
  const Time window_lo = std::max(motions_.valid_from(lower), motions_.valid_from(upper));
  const Time t =
      scheduler_.failure_time(motions_.motion(lower, axis_), motions_.motion(upper, axis_),
                              sim_.now(), window_lo, sim_.counters());
  if (t != kTimeInfinity) certificate_[lower] = sim_.queue().push(t, owner_, lower);
}

KineticSort::Swap KineticSort::process_swap(const Event& event) {
  const std::uint32_t x = event.payload;
  assert(x < position_.size() && position_[x] != kNoIndex);
  certificate_[x] = EventHandle{};  // popped by the simulator
  const std::size_t j = position_[x];
  assert(j + 1 < order_.size());
  const std::uint32_t y = order_[j + 1];
  if (measure_delays_ && scheduler_.kind() == SchedulerKind::Robust) note_delay(x, y, event.time);
  // Swap x and y (Abam, Agarwal, de Berg, Yu, KINETICSORTING line 5), then replace the certificates
  // of the three adjacent pairs that changed (lines 6-11).
  order_[j] = y;
  order_[j + 1] = x;
  position_[y] = static_cast<std::uint32_t>(j);
  position_[x] = static_cast<std::uint32_t>(j + 1);
  ++counters_.swaps;
  if (j > 0) schedule(j - 1);
  schedule(j);
  if (j + 2 < order_.size()) {
    schedule(j + 1);
  } else {
    cancel(x);
  }
  return Swap{static_cast<std::uint32_t>(j), x, y};
}

void KineticSort::note_delay(std::uint32_t x, std::uint32_t y, Time t_cp) {
  // t_cp is the right end of an event interval of width <= eps containing t_ex (Abam, Agarwal, de
  // Berg, Yu, Section 3: t_ex < t_cp < t_ex + eps), unless it is the start of the window (rho_0).
  // CROP's own intervals are narrower (Scheduler::grid_width), a failure-time model's may be eps
  // wide.
  const double eps = scheduler_.eps();
  const Time t_ex = last_root_before(motions_.motion(y, axis_), motions_.motion(x, axis_), t_cp,
                                     eps, Scheduler::grid_width(eps) * 0x1p-24);
  if (t_ex < t_cp) sim_.counters().note_delay(sim_.now() - t_ex);
}

std::size_t KineticSort::locate(std::uint32_t index) const {
  // Binary search with exact comparisons as just after now. If the maintained order is
  // temporarily wrong (near an event), this still yields a valid position in the array.
  std::size_t lo = 0, hi = order_.size();
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (before_after_now(order_[mid], index)) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  return lo;
}

void KineticSort::place(std::uint32_t index, std::size_t p) {
  if (position_.size() < motions_.capacity()) {
    position_.resize(motions_.capacity(), kNoIndex);
    certificate_.resize(motions_.capacity(), EventHandle{});
  }
  order_.insert(order_.begin() + static_cast<std::ptrdiff_t>(p), index);
  for (std::size_t j = p; j < order_.size(); ++j)
    position_[order_[j]] = static_cast<std::uint32_t>(j);
  if (p > 0) schedule(p - 1);  // [A[p-1] < index] replaces [A[p-1] < old A[p]]
  if (p + 1 < order_.size()) schedule(p);
}

void KineticSort::insert(std::uint32_t index) {
  sync_.require_inserted("KineticSort::insert", index);
  ++counters_.inserts;
  place(index, locate(index));
}

void KineticSort::detach(std::uint32_t index) {
  assert(index < position_.size() && position_[index] != kNoIndex);
  const std::size_t p = position_[index];
  cancel(index);
  order_.erase(order_.begin() + static_cast<std::ptrdiff_t>(p));
  position_[index] = kNoIndex;
  for (std::size_t j = p; j < order_.size(); ++j)
    position_[order_[j]] = static_cast<std::uint32_t>(j);
  if (p > 0) {
    if (p < order_.size()) {
      schedule(p - 1);  // the neighbours of the removed point become adjacent
    } else {
      cancel(order_[p - 1]);  // the new last element has no certificate
    }
  }
}

void KineticSort::remove(std::uint32_t index) {
  sync_.require_removed("KineticSort::remove", index);
  ++counters_.removes;
  detach(index);
}

std::uint32_t KineticSort::rank_after_update(std::uint32_t index) const {
  // As locate() over the order without the object (the others keep their order).
  assert(index < position_.size() && position_[index] != kNoIndex);
  const std::size_t r = position_[index];
  std::size_t lo = 0, hi = order_.size() - 1;  // a place among the others
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (before_after_now(order_[mid < r ? mid : mid + 1], index)) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  return static_cast<std::uint32_t>(lo);
}

void KineticSort::motion_changed(std::uint32_t index) {
  sync_.require_updated("KineticSort::motion_changed", index);
  // A flight-plan update may move the point anywhere. Its new place is found as if it were taken
  // out (rank_after_update()), then only the entries between its old and new places move, and the
  // certificates of its old predecessor, its new predecessor and its own are replaced.
  ++counters_.updates;
  const std::size_t r = position_[index];
  const std::size_t n = order_.size();
  const std::size_t r2 = rank_after_update(index);
  const std::uint32_t old_before = r > 0 ? order_[r - 1] : kNoIndex;
  const auto at = [this](std::size_t j) { return order_.begin() + static_cast<std::ptrdiff_t>(j); };
  if (r2 > r) {
    std::rotate(at(r), at(r + 1), at(r2 + 1));
  } else if (r2 < r) {
    std::rotate(at(r2), at(r), at(r + 1));
  }
  for (std::size_t j = std::min(r, r2); j <= std::max(r, r2); ++j)
    position_[order_[j]] = static_cast<std::uint32_t>(j);
  if (old_before != kNoIndex) {
    const std::size_t q = position_[old_before];
    if (q + 1 < n) {
      schedule(q);
    } else {
      cancel(old_before);  // the new last element has no certificate
    }
  }
  if (r2 > 0) schedule(r2 - 1);
  if (r2 + 1 < n) {
    schedule(r2);
  } else {
    cancel(index);
  }
}

bool KineticSort::validate() const {
  if (!sync_.current()) return false;
  for (std::size_t j = 0; j < order_.size(); ++j) {
    const std::uint32_t x = order_[j];
    if (!motions_.alive_index(x) || x >= position_.size() || position_[x] != j) return false;
    const EventHandle h = certificate_[x];
    if (j + 1 == order_.size()) {
      if (!h.is_null()) return false;
      continue;
    }
    if (!h.is_null()) {
      if (!sim_.queue().contains(h)) return false;
      const Event& e = sim_.queue().get(h);
      if (e.owner != owner_ || e.payload != x) return false;
    }
  }
  std::size_t in_order = 0;
  for (std::size_t i = 0; i < position_.size(); ++i) {
    if (position_[i] == kNoIndex) {
      if (i < certificate_.size() && !certificate_[i].is_null()) return false;
    } else {
      ++in_order;
    }
  }
  return in_order == order_.size() && order_.size() == motions_.size();
}

SortAudit KineticSort::audit(Time t) const {
  for (std::size_t j = 0; j + 1 < order_.size(); ++j) {
    if (compare_at(motions_.motion(order_[j], axis_), motions_.motion(order_[j + 1], axis_), t) >
        0) {
      return SortAudit{false, j};
    }
  }
  return SortAudit{};
}

}  // namespace kinetic
