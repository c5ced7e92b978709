// `tournament` and `extent`: kinetic tournaments (a StructureGroup) sharing the simulator's
// queue. `extent` keeps a max and a min tournament per axis (the kinetic bounding box);
// `tournament` keeps those the scenario's queries ask for (max on axis 0 when there are none).
#include <algorithm>

#include "../registry.hpp"
#include "kinetic/core/structure_group.hpp"
#include "kinetic/tournament/kinetic_extent.hpp"
#include "kinetic/tournament/kinetic_tournament.hpp"

namespace kinetic::run::detail {
namespace {

using Tournaments = StructureGroup<KineticTournament>;

Json top(const Tournaments& group, int axis, Extreme extreme, const AnswerContext& c) {
  for (std::size_t k = 0; k < group.size(); ++k) {
    if (group[k].axis() == axis && group[k].extreme() == extreme) return c.id(group[k].top());
  }
  return Json(nullptr);  // excluded by check_runnable and the choice of tournaments
}

Json answer(Tournaments& group, const scenario::QuerySpec& q, const AnswerContext& c) {
  switch (q.type) {
    case scenario::QueryType::Max:
    case scenario::QueryType::Min:
      return top(group, q.axis, q.type == scenario::QueryType::Max ? Extreme::Max : Extreme::Min,
                 c);
    case scenario::QueryType::Extent: {
      Json box = Json::array();
      for (int axis = 0; axis < c.motions.dimension(); ++axis)
        box.push_back(
            Json::array({top(group, axis, Extreme::Min, c), top(group, axis, Extreme::Max, c)}));
      return box;
    }
    default:
      return Json(nullptr);  // excluded by check_runnable
  }
}

/// The levels of a tournament tree a trace's snapshot holds (63 nodes at most).
constexpr int kPictureLevels = 6;

/// Every tournament's winner and its tree's top levels' winners: {"tops": [{"axis", "extreme",
/// "id", "levels": [[root], [two], [four], ...]}, ...]} (null: an empty subtree).
Json snapshot(Tournaments& group, const AnswerContext& c) {
  Json tops = Json::array();
  for (std::size_t k = 0; k < group.size(); ++k) {
    Json levels = Json::array();
    for (const auto& level : group[k].winner_levels(kPictureLevels)) {
      Json ids = Json::array();
      for (const auto& w : level) ids.push_back(c.id(w));
      levels.push_back(std::move(ids));
    }
    tops.push_back({{"axis", group[k].axis()},
                    {"extreme", group[k].extreme() == Extreme::Max ? "max" : "min"},
                    {"id", c.id(group[k].top())},
                    {"levels", std::move(levels)}});
  }
  return {{"tops", std::move(tops)}};
}

LoopGuard guard(const Tournaments& group, const ScenarioBounds& b) {
  // A certificate at a node fails only when its two points cross (at their lowest common
  // ancestor): each tournament is bounded like one sort.
  return crossing_guard(group.size(), b.max_objects, b.motion_changes, b.max_degree);
}

std::unique_ptr<StructureAdapter> make_with(const scenario::Scenario& s, SchedulerKind kind,
                                            double eps,
                                            std::vector<std::pair<int, Extreme>> which) {
  return make_structure<Tournaments>(
      s, kind, eps, Binding<Tournaments>(guard, snapshot, answer),
      build_with([which = std::move(which)](MotionTable& motions, Simulator& sim,
                                            Scheduler& scheduler) {
        auto group = std::make_unique<Tournaments>();
        for (const auto& [axis, extreme] : which)
          group->add(std::make_unique<KineticTournament>(motions, sim, scheduler, axis, extreme));
        return group;
      }));
}

std::unique_ptr<StructureAdapter> make_extent(const scenario::Scenario& s, SchedulerKind kind,
                                              double eps) {
  std::vector<std::pair<int, Extreme>> which;
  for (int axis = 0; axis < s.dimension; ++axis) {
    which.emplace_back(axis, Extreme::Min);
    which.emplace_back(axis, Extreme::Max);
  }
  return make_with(s, kind, eps, std::move(which));
}

std::unique_ptr<StructureAdapter> make_tournament(const scenario::Scenario& s, SchedulerKind kind,
                                                  double eps) {
  std::vector<std::pair<int, Extreme>> which;
  for (const scenario::TimelineOp& op : s.timeline) {
    if (op.op != scenario::OpKind::Query) continue;
    const std::pair<int, Extreme> w{
        op.query.axis, op.query.type == scenario::QueryType::Min ? Extreme::Min : Extreme::Max};
    if (std::find(which.begin(), which.end(), w) == which.end()) which.push_back(w);
  }
  std::sort(which.begin(), which.end());
  if (which.empty()) which.emplace_back(0, Extreme::Max);
  return make_with(s, kind, eps, std::move(which));
}

}  // namespace

void bind_tournament(OwnDescriptors& out) {
  out.push_back({KineticTournament::description(), make_tournament});
  out.push_back({KineticExtent::description(), make_extent});
}

}  // namespace kinetic::run::detail
