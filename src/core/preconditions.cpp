#include "kinetic/core/preconditions.hpp"

#include "kinetic/core/simulator.hpp"

#include <charconv>
#include <cmath>

namespace kinetic {

void precondition_failed(const char* where, const std::string& what) {
  throw PreconditionError(std::string(where) + ": " + what);
}

std::string format_number(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

void require_box(const char* where, const Box& box, int dimension) {
  if (box.size() != static_cast<std::size_t>(dimension)) {
    precondition_failed(where, "the box has " + std::to_string(box.size()) +
                                   (box.size() == 1 ? " axis" : " axes") + ", the structure " +
                                   std::to_string(dimension));
  }
  for (std::size_t a = 0; a < box.size(); ++a) {
    if (std::isnan(box[a][0]) || std::isnan(box[a][1])) {
      precondition_failed(where, "the box's interval on axis " + std::to_string(a) + " is NaN");
    }
    if (box[a][0] > box[a][1]) {
      precondition_failed(where, "the box's interval on axis " + std::to_string(a) + " is [" +
                                     format_number(box[a][0]) + ", " + format_number(box[a][1]) +
                                     "]: lo > hi (a box is one {lo, hi} per axis, lo <= hi)");
    }
  }
}

void require_query_point(const char* where, std::span<const double> q, int dimension, double eps) {
  if (q.size() != static_cast<std::size_t>(dimension)) {
    precondition_failed(where, "the query point has " + std::to_string(q.size()) +
                                   " coordinates, the structure " + std::to_string(dimension));
  }
  for (std::size_t a = 0; a < q.size(); ++a) {
    if (!std::isfinite(q[a])) {
      precondition_failed(where, "the query point's coordinate " + std::to_string(a) + " is " +
                                     format_number(q[a]) + " (a finite number)");
    }
  }
  if (!(eps >= 0.0) || !std::isfinite(eps)) {
    precondition_failed(where, "eps = " + format_number(eps) + " (a finite eps >= 0)");
  }
}

void require_dimension(const char* where, int dimension, int lo, int hi, const char* what) {
  if (dimension < lo || dimension > hi) {
    const std::string supported =
        lo == hi ? std::to_string(lo) : std::to_string(lo) + " to " + std::to_string(hi);
    precondition_failed(where, "the table has dimension " + std::to_string(dimension) +
                                   "; this structure takes " + what + " (dimension " +
                                   supported + ")");
  }
}

void require_axis(const char* where, int axis, int dimension) {
  if (axis < 0 || axis >= dimension) {
    precondition_failed(where, "axis " + std::to_string(axis) + " of a table of dimension " +
                                   std::to_string(dimension) + " (0 to " +
                                   std::to_string(dimension - 1) + ")");
  }
}

void Simulator::refuse_time(const char* where, Time t) const {
  if (std::isnan(t)) precondition_failed(where, "t is NaN");
  precondition_failed(where,
                      "t = " + format_number(t) + " is after the scheduler's horizon " +
                          format_number(horizon_) +
                          " (no event after it is scheduled, so the structure would be wrong "
                          "there; the horizon is the Scheduler's, or SessionOptions::horizon, and "
                          "for robust scheduling at most Scheduler::max_supported_time(eps), "
                          "about 2.6e5 * (eps / 1e-9): a larger eps reaches further)");
}

void TableSync::fail(const char* where) const {
  if (!initialized_) {
    precondition_failed(where, "the structure was not initialized (call initialize() once the "
                               "table holds the initial objects)");
  }
  precondition_failed(where,
                      "the motion table changed without the structure being told (after "
                      "MotionTable::insert, update or remove call the structure's insert, "
                      "motion_changed or remove)");
}

void TableSync::object_failed(const char* where, std::uint32_t index, const char* hint) const {
  if (!initialized_) fail(where);
  precondition_failed(where, "index " + std::to_string(index) +
                                 (table_.alive_index(index) ? " is still in the table"
                                                            : " is not in the table") +
                                 " (" + hint + ")");
}

}  // namespace kinetic
