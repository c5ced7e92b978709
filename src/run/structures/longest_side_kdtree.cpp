// `longest-side-kdtree`: the kinetic rank-based longest-side kd-tree in the plane.
#include <algorithm>

#include "../registry.hpp"
#include "kinetic/longest_side_kdtree/longest_side_kdtree.hpp"

namespace kinetic::run::detail {
namespace {

/// The levels of active nodes a trace's snapshot lists (1023 cells at most).
constexpr int kSketchLevels = 10;

LoopGuard guard(const LongestSideKdTree&, const MotionTable&, const ScenarioBounds& b) {
  // Ordering events are crossings in the two sorts. The side-length list has m < 2n
  // elements; a pair of elements crosses at most s times while both keep their length
  // polynomials, and an ordering event gives new polynomials to at most 12 ceil(log2 n) + 12
  // elements (a rank ends at most 3 ranges per level on each axis), each of which may then
  // cross every other element once more. Saturating arithmetic: the bounds are huge for large n.
  const std::uint64_t n = b.max_objects, changes = b.motion_changes;
  const LoopGuard sorts = crossing_guard(2, n, changes, b.max_degree);
  const std::uint64_t s = static_cast<std::uint64_t>(std::max(1, b.max_degree));
  std::uint64_t log = 0;
  while ((std::uint64_t{1} << log) < n) ++log;
  const std::uint64_t m = 2 * n;
  const std::uint64_t pairs_m = m * (m > 0 ? m - 1 : 0) / 2;
  const std::uint64_t per_ordering = (12 * log + 12) * m;
  auto mul = [](std::uint64_t x, std::uint64_t y) {
    return (x != 0 && y > UINT64_MAX / x) ? UINT64_MAX : x * y;
  };
  auto add = [](std::uint64_t x, std::uint64_t y) {
    return x > UINT64_MAX - y ? UINT64_MAX : x + y;
  };
  LoopGuard g;
  g.max_events_per_instant = add(sorts.max_events_per_instant,
                                 add(pairs_m, mul(sorts.max_events_per_instant, per_ordering)));
  g.max_events_total = add(
      sorts.max_events_total,
      add(mul(s, mul(changes + 1, pairs_m)), mul(s, mul(sorts.max_events_total, per_ordering))));
  return g;
}

std::unique_ptr<StructureAdapter> make(const scenario::Scenario& s, SchedulerKind kind,
                                       double eps) {
  const Binding<LongestSideKdTree> binding(
      guard, [](LongestSideKdTree& tree, const AnswerContext& c) {
        // The orders, and the tree's own cells (its splits depend on the side-length list too).
        Json j = sort_orders_snapshot(tree, c);
        Json cells = Json::array();
        for (const LongestSideKdTree::CellSketch& v : tree.sketch(kSketchLevels)) {
          cells.push_back({{"depth", v.depth},
                           {"lo", Json::array({c.motions.id(v.lo[0]), c.motions.id(v.lo[1])})},
                           {"top", Json::array({c.motions.id(v.top[0]), c.motions.id(v.top[1])})},
                           {"axis", v.axis},
                           {"split", c.motions.id(v.split)}});
        }
        j["cells"] = std::move(cells);
        return j;
      });
  return make_structure(s, kind, eps, binding);
}

}  // namespace

template <>
StructureDescriptor descriptor<LongestSideKdTree>() {
  return {LongestSideKdTree::description(), make};
}

}  // namespace kinetic::run::detail
