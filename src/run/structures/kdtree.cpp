// `kdtree`: the kinetic rank-based kd-tree; closed-box range queries.
#include "../registry.hpp"
#include "kinetic/kdtree/kinetic_kdtree.hpp"

namespace kinetic::run::detail {
namespace {

Json answer(KineticKdTree& tree, const scenario::QuerySpec& q, const AnswerContext& c) {
  if (q.type != scenario::QueryType::Range) return Json(nullptr);  // excluded by check_runnable
  return c.sorted_ids(tree.range(q.box, c.now));
}

LoopGuard guard(const KineticKdTree&, const MotionTable& motions, const ScenarioBounds& b) {
  // The events are those of one kinetic sort per axis.
  return crossing_guard(static_cast<std::uint64_t>(motions.dimension()), b.max_objects,
                        b.motion_changes, b.max_degree);
}

std::unique_ptr<StructureAdapter> make(TimelineDriver& d) {
  return adapt(d, std::make_unique<KineticKdTree>(d.motions(), d.sim(), d.scheduler()),
               Binding<KineticKdTree>{answer, guard});
}

}  // namespace

StructureDescriptor kdtree_descriptor() {
  StructureInfo info;
  info.name = "kdtree";
  info.description = "kinetic rank-based kd-tree (any dimension <= 64): orthogonal range queries";
  info.queries = {scenario::QueryType::Range};
  info.max_dimension = 64;
  return {info, make};
}

}  // namespace kinetic::run::detail
