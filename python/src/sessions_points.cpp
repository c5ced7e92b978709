// The classes of the structures over points and intervals in d dimensions: Sort, Tournament,
// Extent, KdTree, RangeTree, LongestSideKdTree, SegmentTree.

#include "kinetic/kdtree/kinetic_kdtree.hpp"
#include "kinetic/longest_side_kdtree/longest_side_kdtree.hpp"
#include "kinetic/range_tree/kinetic_range_tree.hpp"
#include "kinetic/segment_tree/kinetic_segment_tree.hpp"
#include "kinetic/sort/kinetic_sort.hpp"
#include "kinetic/tournament/kinetic_extent.hpp"
#include "kinetic/tournament/kinetic_tournament.hpp"
#include "session_binding.hpp"

namespace kinetic::python {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

Extreme extreme_from(const std::string& name) {
  if (name == "max") return Extreme::Max;
  if (name == "min") return Extreme::Min;
  refuse("Tournament", "extreme \"" + name + "\" (max or min)");
}

}  // namespace

void register_sessions_points(py::module_& m) {
  {
    static const ClassInfo info{"Sort", "sort"};
    PyClass<KineticSort> c(m, info.python_name,
                           "Kinetic sorting: the objects in order along one axis (sorted()).");
    c.def(py::init([](py::handle motions, int axis, py::handle ids, py::handle origins,
                      std::optional<std::string> scheduler, double eps, double start,
                      double horizon) {
            return std::make_unique<PySession<KineticSort>>(info, motions, py::none(), ids, origins,
                                                            scheduler, eps, start, horizon, axis);
          }),
          py::arg("motions"), py::arg("axis") = 0, py::kw_only(), py::arg("ids") = py::none(),
          py::arg("origins") = py::none(), py::arg("scheduler") = py::none(), py::arg("eps") = 1e-9,
          py::arg("start") = 0.0, py::arg("horizon") = kInf, kConstructorDoc);
    bind_common(c);
  }
  {
    static const ClassInfo info{"Tournament", "tournament"};
    PyClass<KineticTournament> c(
        m, info.python_name,
        "A kinetic tournament: the object with the largest (extreme='max') or smallest "
        "coordinate on one axis (top()).");
    c.def(py::init([](py::handle motions, int axis, const std::string& extreme, py::handle ids,
                      py::handle origins, std::optional<std::string> scheduler, double eps,
                      double start, double horizon) {
            return std::make_unique<PySession<KineticTournament>>(
                info, motions, py::none(), ids, origins, scheduler, eps, start, horizon, axis,
                extreme_from(extreme));
          }),
          py::arg("motions"), py::arg("axis") = 0, py::arg("extreme") = "max", py::kw_only(),
          py::arg("ids") = py::none(), py::arg("origins") = py::none(),
          py::arg("scheduler") = py::none(), py::arg("eps") = 1e-9, py::arg("start") = 0.0,
          py::arg("horizon") = kInf, kConstructorDoc);
    bind_common(c);
  }
  bind_plain<KineticExtent>(m, {"Extent", "extent"},
                            "The kinetic bounding box: a min and a max tournament per axis "
                            "(extent()).");
  bind_plain<KineticKdTree>(m, {"KdTree", "kdtree"},
                            "The kinetic rank-based kd-tree in d dimensions (range(box)).");
  bind_plain<KineticRangeTree>(
      m, {"RangeTree", "range-tree"},
      "The kinetic range tree, d = 1 to 8 (range(box), Delta-approximate near events).");
  bind_plain<LongestSideKdTree>(
      m, {"LongestSideKdTree", "longest-side-kdtree"},
      "The kinetic rank-based longest-side kd-tree in the plane (range, nearest, farthest, "
      "approx_range).");
  bind_plain<KineticSegmentTree>(
      m, {"SegmentTree", "segment-tree"},
      "The kinetic segment tree over moving intervals (stab(x)); motions (n, 2, k): the left "
      "end, then the right end.");
}

}  // namespace kinetic::python
