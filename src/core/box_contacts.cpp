#include "kinetic/core/box_contacts.hpp"

#include <string>

#include "kinetic/core/error.hpp"

namespace kinetic {

std::vector<IndexPair> BoxContacts::colliding_pairs(Time t) {
  sync_.require_current(query_where_);
  require_query_time(query_where_, t, sim_.now());
  count_query();
  return ended_.answer(boxes_, contacts_, sim_);
}

void BoxContacts::require_box_table(const MotionTable& boxes, const char* structure) {
  if (boxes.dimension() % 2 != 0) {
    precondition_failed(structure,
                        "the table does not hold boxes (an even dimension: centers, then half "
                        "extents), it has dimension " +
                            std::to_string(boxes.dimension()));
  }
  require_dimension(structure, box_dimension(boxes), 1, 3, "boxes in 1 to 3 dimensions");
}

}  // namespace kinetic
