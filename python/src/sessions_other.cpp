// The classes of the planar structures and the collision broad phases: Hull, Delaunay,
// ClosestPair (points in the plane), Bvh, SweepAndPrune (boxes: centre motions and constant
// half extents).

#include "kinetic/bvh/kinetic_bvh.hpp"
#include "kinetic/closest_pair/kinetic_cone_closest_pair.hpp"
#include "kinetic/delaunay/kinetic_delaunay.hpp"
#include "kinetic/hull/kinetic_hull.hpp"
#include "kinetic/sweep_and_prune/kinetic_sweep_and_prune.hpp"
#include "session_binding.hpp"

namespace kinetic::python {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

template <class S>
void bind_boxes(py::module_& m, const ClassInfo& info, const char* doc) {
  PyClass<S> c(m, info.python_name, doc);
  c.def(py::init([info](py::handle centers, py::handle half_extents, py::handle ids,
                        py::handle origins, std::optional<std::string> scheduler, double eps,
                        double start, double horizon) {
          return std::make_unique<PySession<S>>(info, centers, half_extents, ids, origins,
                                                scheduler, eps, start, horizon);
        }),
        py::arg("centers"), py::arg("half_extents"), py::kw_only(), py::arg("ids") = py::none(),
        py::arg("origins") = py::none(), py::arg("scheduler") = py::none(), py::arg("eps") = 1e-9,
        py::arg("start") = 0.0, py::arg("horizon") = kInf,
        "centers: (n, d, k) motions of the boxes' centres; half_extents: (n, d) constants >= 0; "
        "the rest as for every class. insert and update take half_extent=(d,).");
  bind_common(c);
}

}  // namespace

void register_sessions_other(py::module_& m) {
  bind_plain<KineticHull>(m, {"Hull", "hull"},
                          "The kinetic convex hull of points in the plane (hull()).");
  bind_plain<KineticDelaunay>(
      m, {"Delaunay", "delaunay"},
      "The kinetic Delaunay triangulation of points in the plane (delaunay(), nearest(), "
      "closest_pair()); robust by default for points on lines (exact just after the grid point "
      "at or before now, docs/delaunay.md), scheduler=\"exact\" for motions of degree <= 2.");
  bind_plain<KineticConeClosestPair>(
      m, {"ClosestPair", "closest-pair"},
      "The kinetic closest pair of points in the plane from cones (closest_pair()); every "
      "scheduler, robust by default (the answer within the bound of docs/closest-pair.md).");
  bind_boxes<KineticBvh>(m, {"Bvh", "bvh", true},
                         "The kinetic AABB tree with its separation list over moving boxes "
                         "(colliding_pairs()).");
  bind_boxes<KineticSweepAndPrune>(
      m, {"SweepAndPrune", "sweep-and-prune", true},
      "Kinetic sweep-and-prune over moving boxes (colliding_pairs()).");
}

}  // namespace kinetic::python
