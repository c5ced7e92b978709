#pragma once
// Points kept in one gapped kinetic sort per axis, answering orthogonal range queries: what the
// kinetic kd-tree and the kinetic range tree share, written once. The base holds the table and
// its sync, the simulator, the sorts (each reserves its owner from the simulator; every rank
// swap is an external event, kind "swap") and the points' count; it answers the measures read
// off the sorts, checks a range query's preconditions and sorts the answer by id. A structure
// builds its own tree over the sorts' labels and writes a query's answer, in any order, in
// query().

#include <cstddef>
#include <cstdint>
#include <vector>

#include "kinetic/core/geometry.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/preconditions.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/structure_group.hpp"
#include "kinetic/sort/kinetic_sort.hpp"

namespace kinetic {

class AxisSortedPoints {
 public:
  AxisSortedPoints(const AxisSortedPoints&) = delete;
  AxisSortedPoints& operator=(const AxisSortedPoints&) = delete;

  /// Object indices inside the closed box at time t (= sim.now() for a kinetic answer),
  /// ascending. Positions are compared exactly.
  [[nodiscard]] std::vector<std::uint32_t> range(const Box& box, Time t);

  [[nodiscard]] int dimension() const { return d_; }
  [[nodiscard]] std::size_t size() const { return n_; }
  /// Certificates alive (one per adjacent pair per axis) and per point at most (2 per axis).
  [[nodiscard]] std::size_t certificates() const { return sorts_.certificates(); }
  [[nodiscard]] std::size_t certificates_per_object_max() const {
    return sorts_.certificates_per_object_max();
  }
  [[nodiscard]] const KineticSort& sort(int axis) const {
    return sorts_[static_cast<std::size_t>(axis)];
  }
  /// initialize() was called.
  [[nodiscard]] bool initialized() const { return sync_.initialized(); }

 protected:
  /// One gapped kinetic sort per axis of the table. `structure` names the structure in a
  /// refusal: PreconditionError unless 1 <= d <= max_dimension (`takes`: what it takes, in
  /// words).
  AxisSortedPoints(const MotionTable& motions, Simulator& simulator, const Scheduler& scheduler,
                   const char* structure, int max_dimension, const char* takes);
  ~AxisSortedPoints() = default;

  /// The indices inside the box at t, in any order, written to `out` (empty when range() calls).
  virtual void query(const Box& box, Time t, std::vector<std::uint32_t>& out) = 0;
  /// A range query's preconditions (`where` names the call): the structure follows the table,
  /// t is the simulator's now, the box has the points' dimension.
  void require_range(const char* where, const Box& box, Time t) const;
  /// Sorts an answer by index (distinct indices of the table), ascending.
  void sort_ids(std::vector<std::uint32_t>& out);

  const MotionTable& motions_;
  TableSync sync_{motions_};  // told of every change to the table
  Simulator& sim_;
  int d_;
  StructureGroup<KineticSort> sorts_;  // one per axis
  std::size_t n_ = 0;

 private:
  std::vector<std::uint64_t> seen_;        // scratch of sort_ids(): a bit per index
  std::vector<std::uint64_t> seen_words_;  // and a bit per word of seen_
};

}  // namespace kinetic
