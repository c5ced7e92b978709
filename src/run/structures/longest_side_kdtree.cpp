// `longest-side-kdtree`: the kinetic rank-based longest-side kd-tree in the plane.
#include "kinetic/longest_side_kdtree/longest_side_kdtree.hpp"
#include "../registry.hpp"

namespace kinetic::run::detail {
namespace {

/// The levels of active nodes a trace's snapshot lists (1023 cells at most).
constexpr int kSketchLevels = 10;

/// The orders, and the tree's own cells (its splits depend on the side-length list too).
Json snapshot(LongestSideKdTree& tree, const AnswerContext& c) {
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
}

}  // namespace

void bind_longest_side_kdtree(OwnDescriptors& out) {
  out.push_back(with_picture<LongestSideKdTree, snapshot>());
}

}  // namespace kinetic::run::detail
