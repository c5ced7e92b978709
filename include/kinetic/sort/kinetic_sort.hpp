#pragma once
// Kinetic sorting of points moving on a line (one axis of the motions): the sorted array A and
// the certificates [A[j] < A[j+1]], one per adjacent pair (Abam, Agarwal, de Berg, Yu, Introduction
// and Section 3). A swap replaces at most three certificates. All events are external: the
// maintained attribute is the order itself.

#include <cassert>
#include <cstdint>
#include <span>
#include <vector>

#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/preconditions.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/structure.hpp"

namespace kinetic {

/// Counters specific to kinetic sorting (the KDS measures are in the simulator's Counters).
struct SortCounters {
  std::uint64_t swaps = 0;
  std::uint64_t inserts = 0;
  std::uint64_t removes = 0;
  std::uint64_t updates = 0;
};

/// The result of an audit against the brute-force oracle at one time.
struct SortAudit {
  bool ok = true;
  std::size_t first_inversion = 0;  ///< position j with A[j] > A[j+1] at the audited time
};

class KineticSort {
 public:
  /// Reserves one owner tag from the simulator for this structure's events.
  KineticSort(const MotionTable& motions, Simulator& simulator, const Scheduler& scheduler,
              int axis);

  /// Builds A from every live object of the table, ordered as just after sim.now() (exact
  /// comparisons; identical motions by id), and schedules all certificates. O(n log n).
  void initialize();

  /// What a swap event does to A: `up` moves from `position` to position + 1, past `down`.
  struct Swap {
    std::uint32_t position = 0;
    std::uint32_t up = kNoIndex;
    std::uint32_t down = kNoIndex;
  };
  /// The swap an event of this sort will make (before processing it).
  [[nodiscard]] Swap pending_swap(const Event& event) const {
    const std::uint32_t j = position_[event.payload];
    return Swap{j, event.payload, order_[j + 1]};
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

  /// Adds a live object of the table at its place as just after sim.now(). O(n) (array shift).
  void insert(std::uint32_t index);
  /// Removes an object that left the table (call after removing it there). O(n).
  void remove(std::uint32_t index);
  /// The object's motion was replaced in the table: repositions it (it may have jumped), moving
  /// only the entries between its old and new places. O(log n + |new rank - old rank|).
  void motion_changed(std::uint32_t index);
  /// The rank motion_changed(index) would give the object (its motion in the table already
  /// replaced), without changing anything. O(log n) comparisons.
  [[nodiscard]] std::uint32_t rank_after_update(std::uint32_t index) const;

  /// Robust scheduling only: measure every event's delay t_pr - t_ex (the exact crossing found
  /// by exact-sign bisection below eps) into the simulator's counters. Costs about 30 exact
  /// sign evaluations per event; for experiments and tests.
  void set_measure_delays(bool on) { measure_delays_ = on; }

  /// The maintained order, as object indices of the table.
  [[nodiscard]] std::span<const std::uint32_t> order() const { return order_; }
  /// The position (rank, from 0) of an object in the maintained order. Precondition: in it.
  [[nodiscard]] std::uint32_t rank(std::uint32_t index) const {
    assert(index < position_.size() && position_[index] != kNoIndex);  // debug builds only
    return position_[index];
  }
  [[nodiscard]] int axis() const { return axis_; }
  [[nodiscard]] const SortCounters& counters() const { return counters_; }
  [[nodiscard]] NamedCounters named_counters() const;
  /// The owner tag of this structure's events.
  [[nodiscard]] OwnerRange owners() const { return OwnerRange{owner_, 1}; }
  /// Certificates alive: one per adjacent pair.
  [[nodiscard]] std::size_t certificates() const { return order_.empty() ? 0 : order_.size() - 1; }
  /// Certificates an object takes part in, at most: one per neighbour.
  [[nodiscard]] std::size_t certificates_per_object_max() const {
    return order_.size() >= 3 ? 2 : order_.size() == 2 ? 1 : 0;
  }

  /// Invariants: positions and order agree; every scheduled event belongs to the certificate of
  /// its adjacent pair; no other events of this structure exist. O(n).
  /// initialize() was called.
  [[nodiscard]] bool initialized() const { return sync_.initialized(); }
  [[nodiscard]] bool validate() const;
  /// Oracle audit at time t: the maintained order is sorted at t (exact comparisons). O(n).
  [[nodiscard]] SortAudit audit(Time t) const;

 private:
  void schedule(std::size_t position);  // certificate [A[position] < A[position+1]]
  void cancel(std::uint32_t index);
  void place(std::uint32_t index, std::size_t position);
  void detach(std::uint32_t index);
  std::size_t locate(std::uint32_t index) const;
  void note_delay(std::uint32_t x, std::uint32_t y, Time t_cp);
  bool before_after_now(std::uint32_t a, std::uint32_t b) const;

  const MotionTable& motions_;
  TableSync sync_{motions_};  // told of every change to the table
  Simulator& sim_;
  const Scheduler& scheduler_;
  int axis_;
  std::uint32_t owner_;
  std::vector<std::uint32_t> order_;      // A
  std::vector<std::uint32_t> position_;   // object index -> position in A (kNoIndex if not in A)
  std::vector<EventHandle> certificate_;  // object index -> event of [it < its successor]
  SortCounters counters_;
  bool measure_delays_ = false;
};

static_assert(KineticStructure<KineticSort>);

}  // namespace kinetic
