// `sort`: one kinetic sort per axis (a StructureGroup), all sharing the simulator's queue.
#include "../registry.hpp"
#include "kinetic/core/structure_group.hpp"
#include "kinetic/sort/kinetic_sort.hpp"

namespace kinetic::run::detail {
namespace {

using Sorts = StructureGroup<KineticSort>;

Json answer(Sorts& sorts, const scenario::QuerySpec& q, const AnswerContext& c) {
  const auto order = sorts[static_cast<std::size_t>(q.axis)].order();
  switch (q.type) {
    case scenario::QueryType::Sorted: {
      Json ids = Json::array();
      for (std::uint32_t i : order) ids.push_back(c.motions.id(i));
      return ids;
    }
    case scenario::QueryType::Max:
      return order.empty() ? Json(nullptr) : c.id(order.back());
    case scenario::QueryType::Min:
      return order.empty() ? Json(nullptr) : c.id(order.front());
    default:
      return Json(nullptr);  // excluded by check_runnable
  }
}

LoopGuard guard(const Sorts& sorts, const MotionTable&, const ScenarioBounds& b) {
  return crossing_guard(sorts.size(), b.max_objects, b.motion_changes, b.max_degree);
}

std::unique_ptr<StructureAdapter> make(TimelineDriver& d) {
  auto sorts = std::make_unique<Sorts>();
  for (int axis = 0; axis < d.motions().dimension(); ++axis) {
    sorts->add(std::make_unique<KineticSort>(d.motions(), d.sim(), d.scheduler(), axis))
        .set_log_swaps(true);
  }
  return adapt<Sorts>(d, std::move(sorts), {answer, guard});
}

}  // namespace

StructureDescriptor sort_descriptor() {
  StructureInfo info;
  info.name = "sort";
  info.description = "kinetic sorting of points along each axis (one sorted array per axis)";
  info.queries = {scenario::QueryType::Sorted, scenario::QueryType::Max, scenario::QueryType::Min};
  info.event_kinds = {"swap"};
  return {info, make};
}

}  // namespace kinetic::run::detail
