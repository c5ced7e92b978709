// `range-tree`: the kinetic range tree; closed-box range queries.
#include "../registry.hpp"
#include "kinetic/range_tree/kinetic_range_tree.hpp"

namespace kinetic::run::detail {

template <>
StructureDescriptor descriptor<KineticRangeTree>() {
  return {KineticRangeTree::description(),
          [](const scenario::Scenario& s, SchedulerKind kind, double eps) {
            // The snapshot carries the slots: the primary tree halves A_0's slots [0, U - 1].
            Binding<KineticRangeTree> binding = box_range_binding<KineticRangeTree>();
            binding.snapshot = slotted_orders_snapshot<KineticRangeTree>;
            return make_structure(s, kind, eps, binding);
          }};
}

}  // namespace kinetic::run::detail
