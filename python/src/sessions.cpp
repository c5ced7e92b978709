// One Python class per structure of kinetic::Structures (structures.hpp), named and documented by
// its registry descriptor (python_class, python_doc) (run::structures(), in the same order): the
// constructor from motions (points and intervals) or from centres and half extents (boxes), and the
// query methods its session offers (session_binding.hpp). Sort and Tournament take more constructor
// arguments (an axis; an extreme): Constructor<S> below.

#include <stdexcept>

#include "kinetic/structures.hpp"
#include "session_binding.hpp"

namespace kinetic::python {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// The constructor of a structure's class: from motions, or from centres and half extents when
/// its objects are boxes.
template <class S>
struct Constructor {
  static void bind(PyClass<S>& c, const ClassInfo& info) {
    if (info.boxes) {
      c.def(py::init([info](py::handle centers, py::handle half_extents, py::handle ids,
                            py::handle origins, std::optional<std::string> scheduler, double eps,
                            double start, double horizon) {
              return std::make_unique<PySession<S>>(info, centers, half_extents, ids, origins,
                                                    scheduler, eps, start, horizon);
            }),
            py::arg("centers"), py::arg("half_extents"), py::kw_only(), py::arg("ids") = py::none(),
            py::arg("origins") = py::none(), py::arg("scheduler") = py::none(),
            py::arg("eps") = 1e-9, py::arg("start") = 0.0, py::arg("horizon") = kInf,
            "centers: (n, d, k) motions of the boxes' centres; half_extents: (n, d) constants "
            ">= 0; the rest as for every class. insert and update take half_extent=(d,).");
      return;
    }
    c.def(py::init([info](py::handle motions, py::handle ids, py::handle origins,
                          std::optional<std::string> scheduler, double eps, double start,
                          double horizon) {
            return std::make_unique<PySession<S>>(info, motions, py::none(), ids, origins,
                                                  scheduler, eps, start, horizon);
          }),
          py::arg("motions"), py::kw_only(), py::arg("ids") = py::none(),
          py::arg("origins") = py::none(), py::arg("scheduler") = py::none(), py::arg("eps") = 1e-9,
          py::arg("start") = 0.0, py::arg("horizon") = kInf, kConstructorDoc);
  }
};

template <>
struct Constructor<KineticSort> {
  static void bind(PyClass<KineticSort>& c, const ClassInfo& info) {
    c.def(py::init([info](py::handle motions, int axis, py::handle ids, py::handle origins,
                          std::optional<std::string> scheduler, double eps, double start,
                          double horizon) {
            return std::make_unique<PySession<KineticSort>>(info, motions, py::none(), ids, origins,
                                                            scheduler, eps, start, horizon, axis);
          }),
          py::arg("motions"), py::arg("axis") = 0, py::kw_only(), py::arg("ids") = py::none(),
          py::arg("origins") = py::none(), py::arg("scheduler") = py::none(), py::arg("eps") = 1e-9,
          py::arg("start") = 0.0, py::arg("horizon") = kInf, kConstructorDoc);
  }
};

Extreme extreme_from(const std::string& name) {
  if (name == "max") return Extreme::Max;
  if (name == "min") return Extreme::Min;
  refuse("Tournament", "extreme \"" + name + "\" (max or min)");
}

template <>
struct Constructor<KineticTournament> {
  static void bind(PyClass<KineticTournament>& c, const ClassInfo& info) {
    c.def(py::init([info](py::handle motions, int axis, const std::string& extreme, py::handle ids,
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
  }
};

}  // namespace

void register_sessions(py::module_& m) {
  const std::vector<run::StructureInfo>& infos = run::structures();
  if (infos.size() != Structures::size)
    throw std::logic_error("kinetic: the registry does not list every structure of the type list");
  std::size_t k = 0;
  Structures::for_each([&]<class S>() {
    const run::StructureInfo& s = infos[k++];
    // (The names point into the registry, which lives as long as the program.)
    const ClassInfo info{s.python_class.c_str(), s.name.c_str(),
                         s.objects == scenario::ObjectsAre::Boxes};
    PyClass<S> c(m, info.python_name, s.python_doc.c_str());
    Constructor<S>::bind(c, info);
    bind_common(c);
  });
}

}  // namespace kinetic::python
