// `range-tree`: the kinetic range tree; closed-box range queries.
#include "../registry.hpp"
#include "kinetic/range_tree/kinetic_range_tree.hpp"

namespace kinetic::run::detail {
namespace {

Json answer(KineticRangeTree& tree, const scenario::QuerySpec& q, const AnswerContext& c) {
  if (q.type != scenario::QueryType::Range) return Json(nullptr);  // excluded by check_runnable
  return c.sorted_ids(tree.range(q.box, c.now));
}

LoopGuard guard(const KineticRangeTree&, const MotionTable& motions, const ScenarioBounds& b) {
  // The events are those of one kinetic sort per axis.
  return crossing_guard(static_cast<std::uint64_t>(motions.dimension()), b.max_objects,
                        b.motion_changes, b.max_degree);
}

std::unique_ptr<StructureAdapter> make(TimelineDriver& d) {
  return adapt(d, std::make_unique<KineticRangeTree>(d.motions(), d.sim(), d.scheduler()),
               Binding<KineticRangeTree>{answer, guard});
}

}  // namespace

StructureDescriptor range_tree_descriptor() {
  StructureInfo info;
  info.name = "range-tree";
  info.description =
      "kinetic range tree (dimension <= 4; one kinetic sort per axis, Basch-Guibas-Zhang): "
      "orthogonal range queries";
  info.queries = {scenario::QueryType::Range};
  // Its space is n (ceil(log2 n) + 1)^(d - 1) ids and positions.
  info.max_dimension = 4;
  return {info, make};
}

}  // namespace kinetic::run::detail
