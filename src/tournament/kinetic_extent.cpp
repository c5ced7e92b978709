#include "kinetic/tournament/kinetic_extent.hpp"

namespace kinetic {

StructureDescription KineticExtent::description() {
  return {"extent",
          "Extent",
          ObjectsAre::Points,
          {QueryType::Extent, QueryType::Max, QueryType::Min},
          {"max_change", "min_change"},
          "The kinetic bounding box: a min and a max tournament per axis (extent(), min(axis), "
          "max(axis)).",
          "kinetic bounding box: a max and a min tournament per axis"};
}

}  // namespace kinetic
