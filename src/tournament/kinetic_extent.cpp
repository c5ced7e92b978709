#include "kinetic/tournament/kinetic_extent.hpp"

namespace kinetic {

namespace {

/// The loop guard's bounds: a min and a max tournament per axis, each bounded like one sort.
LoopGuard extent_event_bounds(const RunBounds& b) {
  return crossing_guard(2 * static_cast<std::uint64_t>(b.dimension), b.max_objects,
                        b.motion_changes, b.max_degree);
}

}  // namespace

StructureDescription KineticExtent::description() {
  return StructureDescription{
      "extent",
      "Extent",
      ObjectsAre::Points,
      {QueryType::Extent, QueryType::Max, QueryType::Min},
      {"max_change", "min_change"},
      "The kinetic bounding box: a min and a max tournament per axis (extent(), min(axis), "
      "max(axis)).",
      "kinetic bounding box: a max and a min tournament per axis"}
      .bound_events(extent_event_bounds);
}

}  // namespace kinetic
