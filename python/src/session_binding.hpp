#pragma once
// One Python class per structure over kinetic::Session<S>: the constructor from numpy arrays, the
// clock (advance with the GIL released and Ctrl-C stopping it), changes, positions, counters,
// and one method per query type the session offers for S (named as in the scenario contract),
// with a batch form where per-call overhead would dominate (range_many, stab_many,
// nearest_many). bind_common<S>() is instantiated once per structure in sessions.cpp.

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common.hpp"
#include "kinetic/run/runner.hpp"
#include "kinetic/session/session.hpp"

namespace kinetic::python {

/// What a class needs to know about its structure beyond S.
struct ClassInfo {
  const char* python_name;  ///< "KdTree"
  const char* cli_name;     ///< "kdtree": the registry entry (schedulers taken, description)
  bool boxes = false;       ///< objects are boxes: centre motions, then constant half extents
};

/// The scheduler a structure takes when none is named, for motions of degree at most
/// `max_degree` (run::default_scheduler: robust where the structure takes them under it, else
/// exact where it takes exact; the Delaunay triangulation of parabolas: exact).
SchedulerKind default_scheduler(const char* cli_name, int max_degree);

template <class S>
class PySession {
 public:
  template <class... Extra>
  PySession(const ClassInfo& info, py::handle motions, py::handle half_extents, py::handle ids,
            py::handle origins, const std::optional<std::string>& scheduler, double eps,
            double start, double horizon, Extra&&... extra)
      : info_(info) {
    const std::string where = info.python_name;
    const DoubleArray m = to_doubles(motions, where, "motions");
    if (m.ndim() != 3 && m.ndim() != 2) {
      refuse(where, "motions have shape " + shape_text(m) +
                        "; expected (n, d, k): n objects, d coordinates, k coefficients "
                        "(or (n, k) for d = 1)");
    }
    const py::ssize_t n = m.shape(0);
    if (m.ndim() == 3 && m.shape(1) > kMaxCoordinates) {
      refuse(where, "motions have shape " + shape_text(m) + ": " + std::to_string(m.shape(1)) +
                        " coordinates (at most " + std::to_string(kMaxCoordinates) + ")");
    }
    coords_ = m.ndim() == 3 ? static_cast<int>(m.shape(1)) : 1;
    const py::ssize_t k = m.ndim() == 3 ? m.shape(2) : m.shape(1);
    if (coords_ < 1 || k < 1) refuse(where, "motions have shape " + shape_text(m) + " (empty)");
    std::vector<ObjectId> id_list(static_cast<std::size_t>(n));
    if (ids.is_none()) {
      for (py::ssize_t i = 0; i < n; ++i) id_list[static_cast<std::size_t>(i)] = i;
    } else {
      id_list = ids_from(ids, n, where);
    }
    std::vector<double> origin_list(static_cast<std::size_t>(n), 0.0);
    if (!origins.is_none()) {
      const DoubleArray o = to_doubles(origins, where, "origins");
      if (o.ndim() == 0) {
        std::fill(origin_list.begin(), origin_list.end(), *o.data());
      } else if (o.ndim() == 1 && o.shape(0) == n) {
        std::copy(o.data(), o.data() + n, origin_list.begin());
      } else {
        refuse(where, "origins have shape " + shape_text(o) + "; expected a number or (" +
                          std::to_string(n) + ",)");
      }
    }
    DoubleArray halves;
    if (info.boxes) {
      halves = to_doubles(half_extents, where, "half_extents");
      if (halves.ndim() != 2 || halves.shape(0) != n || halves.shape(1) != coords_) {
        refuse(where, "half_extents have shape " + shape_text(halves) + "; expected (" +
                          std::to_string(n) + ", " + std::to_string(coords_) + ")");
      }
    }
    SessionOptions options;
    if (scheduler) {
      options.scheduler = scheduler_from(*scheduler, where);
    } else {
      int degree = 0;  // the highest non-zero coefficient of any motion
      for (py::ssize_t e = 0; e < n * coords_; ++e) {
        for (py::ssize_t j = k - 1; j > degree; --j) {
          if (m.data()[e * k + j] != 0.0) {
            degree = static_cast<int>(j);
            break;
          }
        }
      }
      options.scheduler = default_scheduler(info.cli_name, degree);
    }
    options.eps = eps;
    options.start = start;
    options.horizon = horizon;
    try {
      session_ =
          std::make_unique<Session<S>>(table_dimension(), options, std::forward<Extra>(extra)...);
    } catch (const PreconditionError& e) {
      refuse(where, e.what());
    }
    session_->set_interrupt(&interrupt_);
    for (py::ssize_t i = 0; i < n; ++i) {
      const ObjectId id = id_list[static_cast<std::size_t>(i)];
      const std::string at =
          where + ": object " + std::to_string(i) + " (id " + std::to_string(id) + ")";
      std::vector<MotionPolynomial> row = motion_of(m.data() + i * coords_ * k, coords_, k,
                                                    origin_list[static_cast<std::size_t>(i)], at);
      if (info.boxes) append_half_extents(row, halves.data() + i * coords_, at);
      try {
        session_->insert(id, row);
      } catch (const PreconditionError& e) {
        refuse(at, e.what());
      }
    }
  }

  /// Marks the session in use for one call: a second thread calling while an advance runs
  /// with the GIL released gets an error instead of a data race.
  class Use {
   public:
    Use(PySession& s, const char* what) : s_(s) {
      if (s_.busy_.exchange(true)) {
        throw std::runtime_error(std::string(s_.info_.python_name) + "." + what +
                                 ": the session is busy with another call (another thread's, "
                                 "or one that a signal handler interrupted)");
      }
    }
    ~Use() { s_.busy_.store(false); }
    Use(const Use&) = delete;
    Use& operator=(const Use&) = delete;

   private:
    PySession& s_;
  };

  Session<S>& session() { return *session_; }
  /// A call is running (for __repr__, which must not fail).
  [[nodiscard]] bool busy() const { return busy_.load(); }
  const ClassInfo& info() const { return info_; }
  [[nodiscard]] int coords() const { return coords_; }
  [[nodiscard]] std::string where(const char* method) const {
    return std::string(info_.python_name) + "." + method;
  }

  void advance(double t) {
    Use use(*this, "advance");
    InterruptScope scope(interrupt_);
    for (;;) {
      try {
        {
          py::gil_scoped_release release;
          session_->advance(t);
        }
        // A signal after the advance's last look at the flag is not lost: delivered now.
        if (scope.raised() && scope.deliver()) throw py::error_already_set();
        return;
      } catch (const SessionInterrupted&) {
        if (scope.deliver()) throw py::error_already_set();
      }
    }
  }

  /// The motion row of the table for a user's motion (boxes: with their half extents).
  std::vector<MotionPolynomial> row_from(py::handle motion, double origin, py::handle half_extent,
                                         const char* method) {
    const std::string at = where(method);
    std::vector<MotionPolynomial> row = motion_from(motion, coords_, origin, at);
    if (info_.boxes) {
      const DoubleArray h = to_doubles(half_extent, at, "half_extent");
      if (h.ndim() != 1 || h.shape(0) != coords_) {
        refuse(at, "half_extent has shape " + shape_text(h) + "; expected (" +
                       std::to_string(coords_) + ",)");
      }
      append_half_extents(row, h.data(), at);
    }
    return row;
  }

  /// Object `id`'s position at now() (boxes: the centre's), rounded to double.
  py::array_t<double> position(ObjectId id) {
    Use use(*this, "position");
    const std::vector<double> x = session_->position(id);
    py::array_t<double> out(coords_);
    std::copy(x.begin(), x.begin() + coords_, out.mutable_data());
    return out;
  }
  /// Every object's position at now(), one row per id of ids() (ascending).
  py::array_t<double> positions() {
    Use use(*this, "positions");
    const std::vector<ObjectId> ids = session_->ids();
    py::array_t<double> out(
        {static_cast<py::ssize_t>(ids.size()), static_cast<py::ssize_t>(coords_)});
    double* p = out.mutable_data();
    const MotionTable& table = session_->motions();
    for (const ObjectId id : ids) {
      const std::uint32_t index = table.find(id)->index;
      for (int a = 0; a < coords_; ++a) *p++ = table.motion(index, a).evaluate(session_->now());
    }
    return out;
  }

  py::object counters() {
    Use use(*this, "counters");
    Session<S>& s = *session_;
    const std::string text = run::counters_json(s.counters(), s.structure().named_counters(),
                                                s.scheduler().kind(), s.scheduler().eps());
    return py::module_::import("json").attr("loads")(text);
  }

 private:
  [[nodiscard]] int table_dimension() const { return info_.boxes ? 2 * coords_ : coords_; }
  void append_half_extents(std::vector<MotionPolynomial>& row, const double* h,
                           const std::string& at) const {
    for (int a = 0; a < coords_; ++a) {
      if (!std::isfinite(h[a]) || h[a] < 0.0) {
        refuse(at, "half extent " + std::to_string(a) + " is " + format_number(h[a]) +
                       " (a finite number >= 0)");
      }
      row.push_back(MotionPolynomial::from({h[a]}));
    }
  }

  /// Coordinates an object may have (the kd-tree's limit; the others take fewer).
  static constexpr py::ssize_t kMaxCoordinates = 64;

  ClassInfo info_;
  int coords_ = 0;
  std::unique_ptr<Session<S>> session_;
  std::atomic<bool> interrupt_{false};
  std::atomic<bool> busy_{false};
};

/// A query's eps (nearest): finite and >= 0.
inline void require_query_eps(double eps, const std::string& where) {
  if (!(eps >= 0.0) || !std::isfinite(eps)) {
    refuse(where, "eps = " + format_number(eps) + " (a finite eps >= 0)");
  }
}

/// Seconds per call of `query` over `repeats` calls, in C++ (the overhead benchmark's baseline).
template <class F>
double seconds_per_call(std::size_t repeats, F&& query) {
  const auto start = std::chrono::steady_clock::now();
  std::size_t sink = 0;
  for (std::size_t r = 0; r < repeats; ++r) sink += query();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (sink == std::numeric_limits<std::size_t>::max()) return 0.0;  // keeps the loop
  return seconds / static_cast<double>(std::max<std::size_t>(1, repeats));
}

/// The answers of a batch: a list of id arrays, or (flat) one array of every id and the offsets
/// where each answer starts (q + 1 of them).
inline py::object answers_of(const std::vector<std::vector<ObjectId>>& answers, bool flat) {
  if (!flat) {
    py::list out;
    for (const auto& ids : answers) out.append(id_array(ids));
    return out;
  }
  py::array_t<std::int64_t> offsets(static_cast<py::ssize_t>(answers.size() + 1));
  std::int64_t* o = offsets.mutable_data();
  std::int64_t total = 0;
  *o++ = 0;
  for (const auto& ids : answers) *o++ = total += static_cast<std::int64_t>(ids.size());
  py::array_t<std::int64_t> all(static_cast<py::ssize_t>(total));
  std::int64_t* a = all.mutable_data();
  for (const auto& ids : answers) a = std::copy(ids.begin(), ids.end(), a);
  return py::make_tuple(all, offsets);
}

template <class S>
using PyClass = py::class_<PySession<S>>;

/// The methods every class has, and the queries the session offers for S.
template <class S>
void bind_common(PyClass<S>& c) {
  using P = PySession<S>;
  using Q = Session<S>;
  constexpr double inf = std::numeric_limits<double>::infinity();
  (void)inf;
  c.def("advance", &P::advance, py::arg("t"),
        "Processes every event up to time t and moves the clock to t (the GIL is released; "
        "Ctrl-C stops it between two events, raising KeyboardInterrupt with the session usable "
        "at the time reached).");
  c.def(
      "at",
      [](py::object self, double t) {
        self.cast<P&>().advance(t);
        return self;
      },
      py::arg("t"), "advance(t), then the session: s.at(2.0).range(box).");
  c.def_property_readonly(
      "now",
      [](P& p) {
        typename P::Use use(p, "now");
        return p.session().now();
      },
      "The current time.");
  c.def_property_readonly("dimension", &P::coords,
                          "Coordinates per object (boxes: of the centre).");
  c.def_property_readonly(
      "scheduler", [](P& p) { return std::string(to_string(p.session().scheduler().kind())); });
  c.def_property_readonly("eps", [](P& p) { return p.session().scheduler().eps(); });
  c.def_property_readonly("horizon", [](P& p) { return p.session().simulator().horizon(); });
  c.def("__len__", [](P& p) {
    typename P::Use use(p, "__len__");
    return p.session().size();
  });
  c.def("__contains__", [](P& p, py::handle id) {
    if (!py::isinstance<py::int_>(id)) return false;
    ObjectId value = 0;
    try {
      value = id.cast<ObjectId>();
    } catch (const py::cast_error&) {
      return false;  // beyond the 64-bit ids
    }
    typename P::Use use(p, "__contains__");
    return p.session().contains(value);
  });
  c.def(
      "ids",
      [](P& p) {
        typename P::Use use(p, "ids");
        return id_array(p.session().ids());
      },
      "The ids of the objects present, ascending.");
  c.def("position", &P::position, py::arg("id"),
        "Object id's coordinates at now (boxes: its centre), rounded to double.");
  c.def("positions", &P::positions,
        "Every object's coordinates at now, one row per id of ids(), rounded to double.");
  c.def(
      "insert",
      [](P& p, ObjectId id, py::handle motion, double origin, py::handle half_extent) {
        typename P::Use use(p, "insert");
        p.session().insert(id, p.row_from(motion, origin, half_extent, "insert"));
      },
      py::arg("id"), py::arg("motion"), py::arg("origin") = 0.0,
      py::arg("half_extent") = py::none(),
      "Adds object id moving as motion ((d, k) coefficients in powers of t - origin) from now.");
  c.def(
      "update",
      [](P& p, ObjectId id, py::handle motion, double origin, py::handle half_extent) {
        typename P::Use use(p, "update");
        p.session().update(id, p.row_from(motion, origin, half_extent, "update"));
      },
      py::arg("id"), py::arg("motion"), py::arg("origin") = 0.0,
      py::arg("half_extent") = py::none(),
      "Replaces object id's motion from now on (a flight-plan update).");
  c.def(
      "remove",
      [](P& p, ObjectId id) {
        typename P::Use use(p, "remove");
        p.session().remove(id);
      },
      py::arg("id"), "Removes object id at now.");
  c.def("counters", &P::counters,
        "The run's counters as a dict: events, certificates, root isolations, predicates, the "
        "scheduler's figures and the structure's own counters.");
  c.def(
      "validate",
      [](P& p) {
        typename P::Use use(p, "validate");
        return p.session().validate();
      },
      "Checks the structure's invariants and its agreement with the motions (slow; for tests).");
  c.def("__repr__", [](P& p) {
    if (p.busy()) return std::string("kinetic.") + p.info().python_name + "(busy)";
    return std::string("kinetic.") + p.info().python_name +
           "(n=" + std::to_string(p.session().size()) +
           ", dimension=" + std::to_string(p.coords()) + ", scheduler=\"" +
           to_string(p.session().scheduler().kind()) +
           "\", now=" + format_number(p.session().now()) + ")";
  });

  if constexpr (requires(Q & q) { q.sorted(); }) {
    c.def(
        "sorted",
        [](P& p) {
          typename P::Use use(p, "sorted");
          return id_array(p.session().sorted());
        },
        "Every id, in order along the sort's axis at now.");
  }
  if constexpr (requires(Q & q) { q.top(); }) {
    c.def(
        "top",
        [](P& p) {
          typename P::Use use(p, "top");
          return p.session().top();
        },
        "The id with the extreme coordinate at now, None when empty.");
  }
  if constexpr (requires(Q & q) { q.extent(); }) {
    c.def(
        "extent",
        [](P& p) {
          typename P::Use use(p, "extent");
          return id_rows(p.session().extent());
        },
        "The bounding box at now: per axis the ids [argmin, argmax], shape (d, 2); (0, 2) when "
        "empty.");
    // The scenario contract's `max` and `min` queries: one axis's extreme.
    for (const int side : {0, 1}) {
      c.def(
          side == 0 ? "min" : "max",
          [side](P& p, int axis) -> std::optional<ObjectId> {
            const char* name = side == 0 ? "min" : "max";
            if (axis < 0 || axis >= p.coords()) {
              refuse(p.where(name), "axis " + std::to_string(axis) + " (the objects have " +
                                        std::to_string(p.coords()) + ")");
            }
            typename P::Use use(p, name);
            const auto box = p.session().extent();
            if (box.empty()) return std::nullopt;
            return box[static_cast<std::size_t>(axis)][static_cast<std::size_t>(side)];
          },
          py::arg("axis") = 0,
          side == 0 ? "The id with the smallest coordinate on the axis at now; None when empty."
                    : "The id with the largest coordinate on the axis at now; None when empty.");
    }
  }
  if constexpr (requires(Q & q, const Box& b) { q.range(b); }) {
    c.def(
        "range",
        [](P& p, py::handle box) {
          const Box b = box_from(box, p.coords(), p.where("range"));
          typename P::Use use(p, "range");
          return id_array(p.session().range(b));
        },
        py::arg("box"), "The ids in the closed box ((d, 2): [lo, hi] per axis) at now, ascending.");
    c.def(
        "range_many",
        [](P& p, py::handle boxes, bool flat) {
          const DoubleArray a = to_doubles(boxes, p.where("range_many"), "boxes");
          if (a.ndim() != 3 || a.shape(1) != p.coords() || a.shape(2) != 2) {
            refuse(p.where("range_many"), "boxes have shape " + shape_text(a) + "; expected (q, " +
                                              std::to_string(p.coords()) + ", 2)");
          }
          typename P::Use use(p, "range_many");
          std::vector<std::vector<ObjectId>> answers(static_cast<std::size_t>(a.shape(0)));
          {
            py::gil_scoped_release release;
            Box b(static_cast<std::size_t>(p.coords()));
            for (py::ssize_t q = 0; q < a.shape(0); ++q) {
              for (int k = 0; k < p.coords(); ++k)
                b[static_cast<std::size_t>(k)] = {a.at(q, k, 0), a.at(q, k, 1)};
              answers[static_cast<std::size_t>(q)] = p.session().range(b);
            }
          }
          return answers_of(answers, flat);
        },
        py::arg("boxes"), py::arg("flat") = false,
        "range() for each box of an array (q, d, 2): a list of q id arrays; with flat=True, "
        "(ids, offsets): the answers one after another in one array, answer i being "
        "ids[offsets[i]:offsets[i + 1]] (cheaper for many small answers).");
    c.def("_seconds_per_range", [](P& p, py::handle box, std::size_t repeats) {
      const Box b = box_from(box, p.coords(), p.where("range"));
      typename P::Use use(p, "range");
      return seconds_per_call(repeats, [&] { return p.session().range(b).size(); });
    });
  }
  if constexpr (requires(Q & q, Point2 x) { q.nearest(x, 0.0); }) {
    // The kd-tree's in any dimension, the plane's structures' with a Point2.
    const auto nearest = [](Q& s, const std::vector<double>& x, double eps) {
      if constexpr (requires { s.nearest(std::span<const double>(x), eps); }) {
        return s.nearest(std::span<const double>(x), eps);
      } else {
        return s.nearest(Point2{x[0], x[1]}, eps);
      }
    };
    c.def(
        "nearest",
        [nearest](P& p, py::handle point, double eps) {
          const std::vector<double> x = coordinates_from(point, p.coords(), p.where("nearest"));
          require_query_eps(eps, p.where("nearest"));
          typename P::Use use(p, "nearest");
          return nearest(p.session(), x, eps);
        },
        py::arg("point"), py::arg("eps") = 0.0,
        "A (1 + eps)-approximate nearest id to the point at now; None when empty.");
    c.def(
        "nearest_many",
        [nearest](P& p, py::handle points, double eps) {
          const DoubleArray a = to_doubles(points, p.where("nearest_many"), "points");
          if (a.ndim() != 2 || a.shape(1) != p.coords()) {
            refuse(p.where("nearest_many"), "points have shape " + shape_text(a) +
                                                "; expected (q, " + std::to_string(p.coords()) +
                                                ")");
          }
          require_query_eps(eps, p.where("nearest_many"));
          typename P::Use use(p, "nearest_many");
          if (p.session().size() == 0) refuse(p.where("nearest_many"), "no object to be nearest");
          py::array_t<std::int64_t> out(a.shape(0));
          std::int64_t* o = out.mutable_data();
          {
            py::gil_scoped_release release;
            std::vector<double> x(static_cast<std::size_t>(p.coords()));
            for (py::ssize_t q = 0; q < a.shape(0); ++q) {
              for (int k = 0; k < p.coords(); ++k) x[static_cast<std::size_t>(k)] = a.at(q, k);
              o[q] = *nearest(p.session(), x, eps);
            }
          }
          return out;
        },
        py::arg("points"), py::arg("eps") = 0.0,
        "nearest() for each point of an array (q, d): an array of q ids.");
    c.def("_seconds_per_nearest",
          [nearest](P& p, py::handle point, double eps, std::size_t repeats) {
            const std::vector<double> x = coordinates_from(point, p.coords(), p.where("nearest"));
            typename P::Use use(p, "nearest");
            if (p.session().size() == 0) refuse(p.where("nearest"), "no object to be nearest");
            return seconds_per_call(
                repeats, [&] { return static_cast<std::size_t>(*nearest(p.session(), x, eps)); });
          });
  }
  if constexpr (requires(Q & q, std::span<const double> x) { q.k_nearest(x, 1, 0.0); }) {
    c.def(
        "k_nearest",
        [](P& p, py::handle point, std::size_t k, double eps) {
          const std::vector<double> x = coordinates_from(point, p.coords(), p.where("k_nearest"));
          require_query_eps(eps, p.where("k_nearest"));
          typename P::Use use(p, "k_nearest");
          return id_array(p.session().k_nearest(x, k, eps));
        },
        py::arg("point"), py::arg("k"), py::arg("eps") = 0.0,
        "The k ids nearest to the point at now (all when fewer), by increasing distance, equal "
        "distances by id; with eps > 0 each distance within (1 + eps) of the true one of its "
        "rank.");
    c.def(
        "k_nearest_many",
        [](P& p, py::handle points, std::size_t k, double eps) {
          const DoubleArray a = to_doubles(points, p.where("k_nearest_many"), "points");
          if (a.ndim() != 2 || a.shape(1) != p.coords()) {
            refuse(p.where("k_nearest_many"), "points have shape " + shape_text(a) +
                                                  "; expected (q, " + std::to_string(p.coords()) +
                                                  ")");
          }
          require_query_eps(eps, p.where("k_nearest_many"));
          typename P::Use use(p, "k_nearest_many");
          const auto width = static_cast<py::ssize_t>(std::min(k, p.session().size()));
          py::array_t<std::int64_t> out({a.shape(0), width});
          std::int64_t* o = out.mutable_data();
          {
            py::gil_scoped_release release;
            std::vector<double> x(static_cast<std::size_t>(p.coords()));
            for (py::ssize_t q = 0; q < a.shape(0); ++q) {
              for (int j = 0; j < p.coords(); ++j) x[static_cast<std::size_t>(j)] = a.at(q, j);
              const std::vector<ObjectId> ids = p.session().k_nearest(x, k, eps);
              std::copy(ids.begin(), ids.end(), o + q * width);
            }
          }
          return out;
        },
        py::arg("points"), py::arg("k"), py::arg("eps") = 0.0,
        "k_nearest() for each point of an array (q, d): an array (q, min(k, n)) of ids, row i "
        "the answer for point i.");
    c.def("_seconds_per_k_nearest", [](P& p, py::handle point, std::size_t k, double eps,
                                       std::size_t repeats) {
      const std::vector<double> x = coordinates_from(point, p.coords(), p.where("k_nearest"));
      typename P::Use use(p, "k_nearest");
      return seconds_per_call(repeats, [&] { return p.session().k_nearest(x, k, eps).size(); });
    });
  }
  if constexpr (requires(Q & q, Point2 x) { q.farthest(x, 0.0); }) {
    c.def(
        "farthest",
        [](P& p, py::handle point, double eps) {
          const Point2 x = point_from(point, p.where("farthest"));
          typename P::Use use(p, "farthest");
          return p.session().farthest(x, eps);
        },
        py::arg("point"), py::arg("eps") = 0.0,
        "A (1 - eps)-approximate farthest id from the point at now; None when empty.");
  }
  if constexpr (requires(Q & q, const Shape& sh) { q.approx_range(sh, 0.0); }) {
    c.def(
        "approx_range",
        [](P& p, double eps, py::handle disk, py::handle polygon) {
          const std::string at = p.where("approx_range");
          Shape shape;
          if (disk.is_none() == polygon.is_none())
            refuse(at, "give one of disk=(center, radius) or polygon=vertices");
          if (!disk.is_none()) {
            if (!py::isinstance<py::sequence>(disk) || py::len(disk) != 2)
              refuse(at, "disk is (center, radius)");
            const py::sequence t = py::reinterpret_borrow<py::sequence>(disk);
            const Point2 c2 = point_from(t[0], at + " (disk centre)");
            const DoubleArray r = to_doubles(t[1], at, "the disk's radius");
            if (r.ndim() != 0) refuse(at, "the disk's radius is not a number");
            shape.kind = ShapeKind::Disk;
            shape.disk.center = {c2[0], c2[1]};
            shape.disk.radius = *r.data();
          } else {
            const DoubleArray v = to_doubles(polygon, at, "polygon");
            if (v.ndim() != 2 || v.shape(1) != 2)
              refuse(at, "polygon has shape " + shape_text(v) + "; expected (k, 2)");
            shape.kind = ShapeKind::Polygon;
            for (py::ssize_t i = 0; i < v.shape(0); ++i)
              shape.polygon.push_back({v.at(i, 0), v.at(i, 1)});
          }
          typename P::Use use(p, "approx_range");
          return id_array(p.session().approx_range(shape, eps));
        },
        py::arg("eps"), py::kw_only(), py::arg("disk") = py::none(),
        py::arg("polygon") = py::none(),
        "The ids in a disk (disk=(center, radius)) or simple polygon (polygon=(k, 2) vertices) "
        "at now, plus possibly ids within eps * diameter of it; ascending.");
  }
  if constexpr (requires(Q & q) { q.stab(0.0); }) {
    c.def(
        "stab",
        [](P& p, double x) {
          typename P::Use use(p, "stab");
          return id_array(p.session().stab(x));
        },
        py::arg("x"), "The ids of the intervals containing x at now, ascending.");
    c.def(
        "stab_many",
        [](P& p, py::handle xs, bool flat) {
          const DoubleArray a = to_doubles(xs, p.where("stab_many"), "xs");
          if (a.ndim() != 1)
            refuse(p.where("stab_many"), "xs have shape " + shape_text(a) + "; expected (q,)");
          typename P::Use use(p, "stab_many");
          std::vector<std::vector<ObjectId>> answers(static_cast<std::size_t>(a.shape(0)));
          {
            py::gil_scoped_release release;
            for (py::ssize_t q = 0; q < a.shape(0); ++q)
              answers[static_cast<std::size_t>(q)] = p.session().stab(a.at(q));
          }
          return answers_of(answers, flat);
        },
        py::arg("xs"), py::arg("flat") = false,
        "stab() for each x of an array (q,): a list of q id arrays; with flat=True, (ids, "
        "offsets) as for range_many.");
    c.def("_seconds_per_stab", [](P& p, double x, std::size_t repeats) {
      typename P::Use use(p, "stab");
      return seconds_per_call(repeats, [&] { return p.session().stab(x).size(); });
    });
  }
  if constexpr (requires(Q & q) { q.hull(); }) {
    c.def(
        "hull",
        [](P& p) {
          typename P::Use use(p, "hull");
          return id_array(p.session().hull());
        },
        "The convex hull's vertices at now: ids counter-clockwise from the lowest-then-leftmost.");
  }
  if constexpr (requires(Q & q) { q.delaunay(); }) {
    c.def(
        "delaunay",
        [](P& p) {
          typename P::Use use(p, "delaunay");
          return id_rows(p.session().delaunay());
        },
        "The Delaunay triangles at now: (m, 3) ids, each counter-clockwise from its smallest id, "
        "rows sorted.");
  }
  if constexpr (requires(Q & q) { q.closest_pair(); }) {
    c.def(
        "closest_pair",
        [](P& p) -> py::object {
          typename P::Use use(p, "closest_pair");
          const auto pair = p.session().closest_pair();
          if (!pair) return py::none();
          return py::make_tuple((*pair)[0], (*pair)[1]);
        },
        "The closest pair at now: (smaller id, larger id); None for fewer than two objects.");
  }
  if constexpr (requires(Q & q) { q.colliding_pairs(); }) {
    c.def(
        "colliding_pairs",
        [](P& p) {
          typename P::Use use(p, "colliding_pairs");
          return id_rows(p.session().colliding_pairs());
        },
        "The pairs of boxes in contact at now: (m, 2) ids (smaller, larger), rows sorted.");
  }
  if constexpr (requires(Q & q) { q.contact_changes(); }) {
    c.def(
        "contact_changes",
        [](P& p) {
          typename P::Use use(p, "contact_changes");
          const ContactChanges changes = p.session().contact_changes();
          py::dict out;
          const auto put = [&](const char* name, const std::vector<ContactChange>& list) {
            std::vector<std::array<ObjectId, 2>> ids;
            std::vector<double> times;
            for (const ContactChange& x : list) {
              ids.push_back({x.a, x.b});
              times.push_back(x.time);
            }
            out[name] = id_rows(ids);
            out[(std::string(name) + "_times").c_str()] =
                py::array_t<double>(static_cast<py::ssize_t>(times.size()), times.data());
          };
          put("begun", changes.begun);
          put("ended", changes.ended);
          put("touched", changes.touched);
          return out;
        },
        "What changed in colliding_pairs() since the previous call, at the cost of the changes: a "
        "dict of 'begun' (pairs in contact now, not at the previous call), 'ended' (the reverse) "
        "and 'touched' (in contact in between, at neither call: what a query per frame misses), "
        "each (m, 2) ids (smaller, larger) with rows sorted, and '<name>_times': when each began "
        "(begun: the last time; touched: the first) or ended. The first call reports every pair "
        "in contact as begun.");
  }
}

/// The constructor's common parameters, documented once.
inline constexpr const char* kConstructorDoc =
    "motions: (n, d, k) coefficients (or (n, k) for d = 1) in powers of t - origin; "
    "ids: n integers (default 0..n-1); origins: a number or n numbers (default 0); "
    "scheduler: 'robust', 'classic' or 'exact' (default: robust where the structure takes these "
    "motions under it, else exact); "
    "eps: the robust scheduler's precision; start: the time the motions are at first; "
    "horizon: no advance beyond it.";

}  // namespace kinetic::python
