// `range-tree`: the kinetic range tree; closed-box range queries.
#include "../registry.hpp"
#include "kinetic/range_tree/kinetic_range_tree.hpp"

namespace kinetic::run::detail {

template <>
StructureDescriptor descriptor<KineticRangeTree>() {
  StructureInfo info;
  info.python_class = "RangeTree";
  info.python_doc =
      "The kinetic range tree, d = 1 to 8 (range(box), range_many(boxes); Delta-approximate"
      " near events).";
  info.name = "range-tree";
  info.description =
      "kinetic range tree (dimension <= 4; one kinetic sort per axis, Basch-Guibas-Zhang): "
      "orthogonal range queries";
  info.queries = {scenario::QueryType::Range};
  info.event_kinds = {"swap"};
  // Its space is U (log2 U + 1)^(d - 1) ids and positions, U the slots of A_0 (2n to 4n).
  info.max_dimension = 4;
  return {info, [](TimelineDriver& d) {
            // The snapshot carries the slots: the primary tree halves A_0's slots [0, U - 1].
            Binding<KineticRangeTree> binding = box_range_binding<KineticRangeTree>();
            binding.snapshot = slotted_orders_snapshot<KineticRangeTree>;
            return make_structure(d, binding);
          }};
}

}  // namespace kinetic::run::detail
