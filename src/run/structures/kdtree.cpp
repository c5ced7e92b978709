// `kdtree`: the kinetic rank-based kd-tree; closed-box range queries.
#include "../registry.hpp"
#include "kinetic/kdtree/kinetic_kdtree.hpp"

namespace kinetic::run::detail {

template <>
StructureDescriptor descriptor<KineticKdTree>() {
  StructureInfo info;
  info.python_class = "KdTree";
  info.python_doc =
      "The kinetic rank-based kd-tree in d dimensions (range(box), range_many(boxes)).";
  info.name = "kdtree";
  info.description = "kinetic rank-based kd-tree (any dimension <= 64): orthogonal range queries";
  info.queries = {scenario::QueryType::Range};
  info.event_kinds = {"swap"};
  info.max_dimension = 64;
  return {info, [](TimelineDriver& d) {
            // The snapshot carries the slots: the tree halves the gapped orders' label ranges.
            Binding<KineticKdTree> binding = box_range_binding<KineticKdTree>();
            binding.snapshot = slotted_orders_snapshot<KineticKdTree>;
            return make_structure(d, binding);
          }};
}

}  // namespace kinetic::run::detail
