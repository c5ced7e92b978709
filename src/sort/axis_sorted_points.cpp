#include "kinetic/sort/axis_sorted_points.hpp"

#include <memory>

#include "core/numeric/id_bitmap_sort.hpp"

namespace kinetic {

AxisSortedPoints::AxisSortedPoints(const MotionTable& motions, Simulator& simulator,
                                   const Scheduler& scheduler, const char* structure,
                                   int max_dimension, const char* takes)
    : motions_(motions), sim_(simulator), d_(motions.dimension()) {
  require_dimension(structure, d_, 1, max_dimension, takes);
  for (int axis = 0; axis < d_; ++axis) {
    sorts_
        .add(std::make_unique<KineticSort>(motions, simulator, scheduler, axis,
                                           SortLayout::Gapped))
        .set_log_swaps(true);  // every rank swap is an external event (kind "swap")
  }
}

std::vector<std::uint32_t> AxisSortedPoints::range(const Box& box, Time t) {
  std::vector<std::uint32_t> out;
  query(box, t, out);
  sort_ids(out);
  return out;
}

void AxisSortedPoints::require_range(const char* where, const Box& box, Time t) const {
  sync_.require_current(where);
  require_query_time(where, t, sim_.now());
  require_box(where, box, d_);
}

void AxisSortedPoints::sort_ids(std::vector<std::uint32_t>& out) {
  numeric::sort_ids_ascending(out, motions_.capacity(), seen_, seen_words_);
}

}  // namespace kinetic
