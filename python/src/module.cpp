// The extension module kinetic._kinetic: the exceptions, the shared conversions, and the parts
// registered by the other files (sessions.cpp: one class per structure; scenarios.cpp: the
// scenario format, the runner, the experiments). The package kinetic (python/kinetic) re-exports
// it; docs/python.md.

#include <pybind11/pybind11.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "common.hpp"
#include "kinetic/run/runner.hpp"
#include "kinetic/scenario/scenario.hpp"
#include "kinetic/session/session.hpp"
#include "kinetic/version.hpp"

namespace kinetic::python {

namespace {

/// The flag of the call that a SIGINT stops now (at most one: the main thread's).
std::atomic<std::atomic<bool>*> g_sigint_target{nullptr};

extern "C" void raise_interrupt_flag(int) {
  if (std::atomic<bool>* f = g_sigint_target.load()) f->store(true);
}

bool in_main_thread() {
  const py::module_ threading = py::module_::import("threading");
  return threading.attr("current_thread")().is(threading.attr("main_thread")());
}

}  // namespace

InterruptScope::InterruptScope(std::atomic<bool>& flag) : flag_(flag) {
  flag_.store(false);
  if (!in_main_thread()) return;
  struct sigaction current {};
  // Ignored, or the default (the process dies at Ctrl-C): left as they are.
  if (sigaction(SIGINT, nullptr, &current) != 0 || current.sa_handler == SIG_IGN ||
      current.sa_handler == SIG_DFL) {
    return;
  }
  struct sigaction ours {};
  ours.sa_handler = raise_interrupt_flag;
  sigemptyset(&ours.sa_mask);
  previous_ = g_sigint_target.exchange(&flag_);
  if (sigaction(SIGINT, &ours, &old_) != 0) {
    g_sigint_target.store(previous_);
    return;
  }
  installed_ = true;
}

InterruptScope::~InterruptScope() {
  if (!installed_) return;
  sigaction(SIGINT, &old_, nullptr);
  g_sigint_target.store(previous_);
}

bool InterruptScope::deliver() {
  flag_.store(false);
  PyErr_SetInterruptEx(SIGINT);
  return PyErr_CheckSignals() != 0;
}

DoubleArray to_doubles(py::handle value, const std::string& where, const char* what) {
  DoubleArray a = DoubleArray::ensure(value);
  if (!a) refuse(where, std::string(what) + " is not an array of numbers");
  return a;
}

std::string shape_text(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t k = 0; k < a.ndim(); ++k) {
    if (k > 0) s += ", ";
    s += std::to_string(a.shape(k));
  }
  return s + (a.ndim() == 1 ? ",)" : ")");
}

std::vector<MotionPolynomial> motion_of(const double* coefficients, int d, py::ssize_t k,
                                        double origin, const std::string& where) {
  std::vector<MotionPolynomial> motion;
  motion.reserve(static_cast<std::size_t>(d));
  for (int a = 0; a < d; ++a) {
    try {
      motion.push_back(MotionPolynomial::from(
          std::span<const double>(coefficients + a * k, static_cast<std::size_t>(k)), origin));
    } catch (const PreconditionError& e) {
      refuse(where + " coordinate " + std::to_string(a), e.what());
    }
  }
  return motion;
}

std::vector<MotionPolynomial> motion_from(py::handle motion, int d, double origin,
                                          const std::string& where) {
  const DoubleArray a = to_doubles(motion, where, "the motion");
  if (a.ndim() == 1 && d == 1) return motion_of(a.data(), 1, a.shape(0), origin, where);
  if (a.ndim() != 2 || a.shape(0) != d) {
    refuse(where, "the motion has shape " + shape_text(a) + "; expected (" + std::to_string(d) +
                      ", k): one row of k coefficients per coordinate" +
                      (d == 1 ? " (or (k,))" : ""));
  }
  return motion_of(a.data(), d, a.shape(1), origin, where);
}

std::vector<ObjectId> ids_from(py::handle ids, py::ssize_t n, const std::string& where) {
  const py::array a = py::array::ensure(ids);
  const std::string count = "ids must be n = " + std::to_string(n) + " integers";
  if (!a || a.ndim() != 1 || a.shape(0) != n) refuse(where, count);
  if (n == 0) return {};
  const char kind = a.dtype().kind();
  if (kind != 'i' && kind != 'u') {
    refuse(where, count + " (got an array of dtype " + std::string(py::str(a.dtype())) + ")");
  }
  std::vector<ObjectId> out(static_cast<std::size_t>(n));
  if (kind == 'u' && a.itemsize() == 8) {
    const auto u = py::array_t<std::uint64_t, py::array::c_style | py::array::forcecast>::ensure(a);
    for (py::ssize_t i = 0; i < n; ++i) {
      if (u.at(i) > static_cast<std::uint64_t>(std::numeric_limits<ObjectId>::max())) {
        refuse(where, "ids[" + std::to_string(i) + "] = " + std::to_string(u.at(i)) +
                          " is beyond the 64-bit signed ids");
      }
      out[static_cast<std::size_t>(i)] = static_cast<ObjectId>(u.at(i));
    }
    return out;
  }
  const IdArray s = IdArray::ensure(a);
  std::copy(s.data(), s.data() + n, out.begin());
  return out;
}

py::array_t<std::int64_t> id_array(std::span<const ObjectId> ids) {
  py::array_t<std::int64_t> out(static_cast<py::ssize_t>(ids.size()));
  std::copy(ids.begin(), ids.end(), out.mutable_data());
  return out;
}

Box box_from(py::handle box, int d, const std::string& where) {
  const DoubleArray a = to_doubles(box, where, "the box");
  if (a.ndim() != 2 || a.shape(0) != d || a.shape(1) != 2) {
    refuse(where, "the box has shape " + shape_text(a) + "; expected (" + std::to_string(d) +
                      ", 2): one [lo, hi] per axis");
  }
  Box b(static_cast<std::size_t>(d));
  for (int k = 0; k < d; ++k) b[static_cast<std::size_t>(k)] = {a.at(k, 0), a.at(k, 1)};
  return b;
}

std::vector<double> coordinates_from(py::handle point, int d, const std::string& where) {
  const DoubleArray a = to_doubles(point, where, "the point");
  if (a.ndim() != 1 || a.shape(0) != d) {
    refuse(where,
           "the point has shape " + shape_text(a) + "; expected (" + std::to_string(d) + ",)");
  }
  std::vector<double> x(static_cast<std::size_t>(d));
  for (int k = 0; k < d; ++k) x[static_cast<std::size_t>(k)] = a.at(k);
  return x;
}

Point2 point_from(py::handle point, const std::string& where) {
  const std::vector<double> x = coordinates_from(point, 2, where);
  return {x[0], x[1]};
}

SchedulerKind scheduler_from(const std::string& name, const std::string& where) {
  const std::optional<SchedulerKind> k = scheduler_from_string(name);
  if (!k) refuse(where, "scheduler \"" + name + "\" (robust, classic or exact)");
  return *k;
}

}  // namespace kinetic::python

PYBIND11_MODULE(_kinetic, m) {
  namespace kp = kinetic::python;
  namespace py = pybind11;
  m.doc() = "kinetic data structures (the C++ library kinetic); see the package kinetic";
  m.attr("__version__") = KINETIC_VERSION_STRING;

  // Bad input: a ValueError naming the call and the fault, raised before anything changed.
  static py::exception<kinetic::PreconditionError> precondition(m, "PreconditionError",
                                                                PyExc_ValueError);
  static py::exception<kinetic::scenario::ScenarioError> scenario_error(m, "ScenarioError",
                                                                        PyExc_ValueError);
  static py::exception<kinetic::run::UsageError> usage(m, "UsageError", PyExc_ValueError);
  // The scheduler failed to finish an advance (a loop guard tripped): the session is unusable.
  static py::exception<kinetic::SessionError> session_error(m, "SessionError", PyExc_RuntimeError);
  for (py::handle e :
       std::initializer_list<py::handle>{precondition, scenario_error, usage, session_error})
    e.attr("__module__") = "kinetic";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const kinetic::PreconditionError& e) {
      precondition(e.what());
    } catch (const kinetic::scenario::ScenarioError& e) {
      scenario_error(e.what());
    } catch (const kinetic::run::UsageError& e) {
      usage(e.what());
    } catch (const kinetic::SessionError& e) {
      session_error(e.what());
    }
  });

  kp::register_sessions(m);
  kp::register_scenarios(m);
}
