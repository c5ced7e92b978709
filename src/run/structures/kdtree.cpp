// `kdtree`: the kinetic rank-based kd-tree; closed-box range queries.
#include "../registry.hpp"
#include "kinetic/kdtree/kinetic_kdtree.hpp"

namespace kinetic::run::detail {

template <>
StructureDescriptor descriptor<KineticKdTree>() {
  return {KineticKdTree::description(),
          [](const scenario::Scenario& s, SchedulerKind kind, double eps) {
            // The snapshot carries the slots: the tree halves the gapped orders' label ranges.
            Binding<KineticKdTree> binding = box_range_binding<KineticKdTree>();
            binding.snapshot = slotted_orders_snapshot<KineticKdTree>;
            return make_structure(s, kind, eps, binding);
          }};
}

}  // namespace kinetic::run::detail
