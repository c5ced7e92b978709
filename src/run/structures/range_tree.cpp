// `range-tree`: the kinetic range tree; closed-box range queries.
#include "../registry.hpp"
#include "kinetic/range_tree/kinetic_range_tree.hpp"

namespace kinetic::run::detail {

StructureDescriptor range_tree_descriptor() {
  StructureInfo info;
  info.name = "range-tree";
  info.description =
      "kinetic range tree (dimension <= 4; one kinetic sort per axis, Basch-Guibas-Zhang): "
      "orthogonal range queries";
  info.queries = {scenario::QueryType::Range};
  info.event_kinds = {"swap"};
  // Its space is n (ceil(log2 n) + 1)^(d - 1) ids and positions.
  info.max_dimension = 4;
  return {info, [](TimelineDriver& d) {
            return make_structure(d, box_range_binding<KineticRangeTree>());
          }};
}

}  // namespace kinetic::run::detail
