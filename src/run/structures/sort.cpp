// `sort`: one kinetic sort per axis (a StructureGroup), all sharing the simulator's queue.
#include "../registry.hpp"
#include "kinetic/core/predicates.hpp"
#include "kinetic/core/structure_group.hpp"
#include "kinetic/sort/kinetic_sort.hpp"

namespace kinetic::run::detail {
namespace {

using Sorts = StructureGroup<KineticSort>;

/// The last (max) or first (min) object of a sorted order, ties at now broken by the smallest id
/// (the oracle's rule: at a crossing time the order is the one just after now).
Json extreme(std::span<const std::uint32_t> order, int axis, bool max, const AnswerContext& c) {
  if (order.empty()) return Json(nullptr);
  const std::size_t n = order.size();
  const std::uint32_t end = max ? order[n - 1] : order[0];
  std::uint32_t best = end;
  for (std::size_t k = 1; k < n; ++k) {
    const std::uint32_t x = max ? order[n - 1 - k] : order[k];
    if (compare_at(c.motions.motion(x, axis), c.motions.motion(end, axis), c.now) != 0) break;
    if (c.motions.id(x) < c.motions.id(best)) best = x;
  }
  return c.id(best);
}

Json answer(Sorts& sorts, const scenario::QuerySpec& q, const AnswerContext& c) {
  const auto order = sorts[static_cast<std::size_t>(q.axis)].order();
  switch (q.type) {
    case scenario::QueryType::Sorted: {
      Json ids = Json::array();
      for (std::uint32_t i : order) ids.push_back(c.motions.id(i));
      return ids;
    }
    case scenario::QueryType::Max:
      return extreme(order, q.axis, true, c);
    case scenario::QueryType::Min:
      return extreme(order, q.axis, false, c);
    default:
      return Json(nullptr);  // excluded by check_runnable
  }
}

/// The maintained order of every axis.
Json snapshot(Sorts& sorts, const AnswerContext& c) {
  Json orders = Json::array();
  for (std::size_t k = 0; k < sorts.size(); ++k)
    orders.push_back({{"axis", sorts[k].axis()}, {"ids", c.ids_in_order(sorts[k].order())}});
  return {{"orders", std::move(orders)}};
}

LoopGuard guard(const Sorts& sorts, const ScenarioBounds& b) {
  return crossing_guard(sorts.size(), b.max_objects, b.motion_changes, b.max_degree);
}

std::unique_ptr<StructureAdapter> make(const scenario::Scenario& s, SchedulerKind kind,
                                       double eps) {
  return make_structure<Sorts>(
      s, kind, eps, Binding<Sorts>(guard, snapshot, answer),
      build_with([](MotionTable& motions, Simulator& sim, Scheduler& scheduler) {
        auto sorts = std::make_unique<Sorts>();
        for (int axis = 0; axis < motions.dimension(); ++axis) {
          sorts->add(std::make_unique<KineticSort>(motions, sim, scheduler, axis))
              .set_log_swaps(true);
        }
        return sorts;
      }));
}

}  // namespace

void bind_sort(OwnDescriptors& out) { out.push_back({KineticSort::description(), make}); }

}  // namespace kinetic::run::detail
