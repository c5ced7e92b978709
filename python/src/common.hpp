#pragma once
// What the binding files share: the conversions between numpy arrays and the library's motions,
// boxes and ids, the interrupt scope that lets Ctrl-C stop a long call with the GIL released,
// and the registration functions of the module's parts.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <atomic>
#include <csignal>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "kinetic/core/error.hpp"
#include "kinetic/core/geometry.hpp"
#include "kinetic/core/ids.hpp"
#include "kinetic/core/polynomial.hpp"
#include "kinetic/core/scheduler.hpp"

namespace kinetic::python {

namespace py = pybind11;

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;
using IdArray = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>;

void register_sessions(py::module_& m);
void register_scenarios(py::module_& m);

/// Throws PreconditionError "where: what" (a kinetic.PreconditionError in Python).
[[noreturn]] inline void refuse(const std::string& where, const std::string& what) {
  throw PreconditionError(where + ": " + what);
}

/// A numpy array of doubles from anything numpy takes (list, tuple, array of any numeric type);
/// refuses what is not numbers with the place named.
DoubleArray to_doubles(py::handle value, const std::string& where, const char* what);

/// The shape of an array as "(2, 3)", for messages.
std::string shape_text(const py::array& a);

/// One object's motion: `coefficients` of shape (d, k) (or (k,) when d == 1), ascending
/// coefficients in powers of (t - origin), one row per coordinate.
std::vector<MotionPolynomial> motion_of(const double* coefficients, int d, py::ssize_t k,
                                        double origin, const std::string& where);
std::vector<MotionPolynomial> motion_from(py::handle motion, int d, double origin,
                                          const std::string& where);

/// n ids from anything numpy takes as integers (int or uint arrays, lists of ints); refuses
/// floats, values beyond int64 and the wrong count, naming `where`.
std::vector<ObjectId> ids_from(py::handle ids, py::ssize_t n, const std::string& where);

/// Ids as a numpy int64 array.
py::array_t<std::int64_t> id_array(std::span<const ObjectId> ids);
/// Pairs or triples of ids as an (m, K) int64 array.
template <std::size_t K>
py::array_t<std::int64_t> id_rows(const std::vector<std::array<ObjectId, K>>& rows) {
  py::array_t<std::int64_t> out(
      {static_cast<py::ssize_t>(rows.size()), static_cast<py::ssize_t>(K)});
  auto* p = out.mutable_data();
  for (const auto& r : rows) {
    for (std::size_t k = 0; k < K; ++k) *p++ = r[k];
  }
  return out;
}

/// A box of `d` axes from an array of shape (d, 2): one [lo, hi] per axis.
Box box_from(py::handle box, int d, const std::string& where);
/// A point of the plane from a sequence of two numbers.
Point2 point_from(py::handle point, const std::string& where);
/// A point of `d` coordinates from a sequence of d numbers.
std::vector<double> coordinates_from(py::handle point, int d, const std::string& where);

/// "robust", "classic", "exact" to the kind; refuses other names.
SchedulerKind scheduler_from(const std::string& name, const std::string& where);

/// Lets Ctrl-C stop a long call that runs with the GIL released. Made with the GIL held, in the
/// main thread (elsewhere it does nothing: Python delivers signals to the main thread only):
/// while it lives, SIGINT raises `flag` instead of Python's handler; deliver() then hands the
/// signal to Python (PyErr_SetInterruptEx) and runs its handler: true when that raised (usually
/// KeyboardInterrupt, now set as the Python error), false when the handler chose to go on.
class InterruptScope {
 public:
  explicit InterruptScope(std::atomic<bool>& flag);
  ~InterruptScope();
  InterruptScope(const InterruptScope&) = delete;
  InterruptScope& operator=(const InterruptScope&) = delete;
  /// Call with the GIL held, after the flag stopped the call (or raised() says a signal came
  /// after the call's last look at it).
  bool deliver();
  /// A SIGINT came while the scope lived and was not delivered yet.
  [[nodiscard]] bool raised() const { return flag_.load(); }

 private:
  std::atomic<bool>& flag_;
  std::atomic<bool>* previous_ = nullptr;
  bool installed_ = false;
  struct sigaction old_ {};
};

}  // namespace kinetic::python
