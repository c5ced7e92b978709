// `kdtree` and `range-tree`: structures over one gapped kinetic sort per axis whose shape is a
// function of the keys' slots (the kd-tree halves the orders' label ranges, the range tree's
// primary tree A_0's slots [0, U - 1]): a trace's snapshot carries the orders with their slots.
#include "../registry.hpp"
#include "kinetic/kdtree/kinetic_kdtree.hpp"
#include "kinetic/range_tree/kinetic_range_tree.hpp"

namespace kinetic::run::detail {

void bind_gapped_orders(OwnDescriptors& out) {
  out.push_back(with_picture<KineticKdTree, slotted_orders_snapshot<KineticKdTree>>());
  out.push_back(with_picture<KineticRangeTree, slotted_orders_snapshot<KineticRangeTree>>());
}

}  // namespace kinetic::run::detail
