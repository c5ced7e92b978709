#pragma once
// A structure's description, written beside its class: its name, what its objects are, the
// queries it answers, the dimensions, degrees, magnitudes and schedulers it takes and why where
// it is restricted, the events it logs, and how many events a correct run can have (its loop
// guard's bounds, core/loop_guard.hpp). A structure declares
// `static StructureDescription description();` and defines it in its source; the run layer's
// registry (`kinetic run --help` and the request checks), run::default_scheduler and the Python
// classes read it, through the list of structures (structures.hpp).

#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "kinetic/core/loop_guard.hpp"
#include "kinetic/core/scheduler.hpp"

namespace kinetic {

/// What a structure's objects are (a scenario's "objects_are"): points (one polynomial per
/// coordinate), intervals (coordinate 0 the left end, 1 the right end) or boxes (the center's
/// motions, then one constant half extent per axis).
enum class ObjectsAre { Points, Intervals, Boxes };
/// The contract's spelling: "points", "intervals" or "boxes".
[[nodiscard]] const char* to_string(ObjectsAre objects_are);

/// The queries of the scenario contract (docs/scenario-format.md).
enum class QueryType {
  Sorted,
  Max,
  Min,
  Extent,
  Range,
  Nearest,
  KNearest,
  Farthest,
  ApproxRange,
  Stab,
  Hull,
  ClosestPair,
  CollidingPairs,
  Delaunay,
};
/// The contract's spelling of a query type ("sorted", "approx_range", ...).
[[nodiscard]] const char* to_string(QueryType type);
[[nodiscard]] std::optional<QueryType> query_type_from_string(const std::string& name);
/// Every query type's spelling, in the enum's order.
[[nodiscard]] std::vector<const char*> query_type_names();

/// Built as {name, python_class, objects, queries, event_kinds, python_doc, description}, then
/// its limits where it has any: StructureDescription{...}.limit_dimensions(2, 2, "why").
struct StructureDescription {
  StructureDescription() = default;
  StructureDescription(std::string name_, std::string python_class_, ObjectsAre objects_,
                       std::vector<QueryType> queries_, std::vector<std::string> event_kinds_,
                       std::string python_doc_, std::string description_)
      : name(std::move(name_)),
        python_class(std::move(python_class_)),
        objects(objects_),
        queries(std::move(queries_)),
        event_kinds(std::move(event_kinds_)),
        python_doc(std::move(python_doc_)),
        description(std::move(description_)) {}

  // A limit beyond the core's, each with its reason (shown in the error that refuses a request).
  /// Dimensions from `min` to `max`.
  StructureDescription& limit_dimensions(int min, int max, std::string why) {
    min_dimension = min;
    max_dimension = max;
    dimension_note = std::move(why);
    return *this;
  }
  /// Motions of degree <= `max`.
  StructureDescription& limit_degree(int max, std::string why) {
    max_degree = max;
    degree_note = std::move(why);
    return *this;
  }
  /// Under the robust scheduler, motions of degree <= `max`.
  StructureDescription& limit_robust_degree(int max, std::string why) {
    robust_max_degree = max;
    robust_degree_note = std::move(why);
    return *this;
  }
  /// Coefficients about t = 0 of magnitude in [2^-log2, 2^log2), or 0.
  StructureDescription& limit_magnitudes(int log2, std::string why) {
    magnitude_log2 = log2;
    magnitude_note = std::move(why);
    return *this;
  }
  /// Coefficients as given of magnitude < 2^log2.
  StructureDescription& limit_coefficients(int log2, std::string why) {
    coefficient_log2 = log2;
    coefficient_note = std::move(why);
    return *this;
  }
  /// The loop guard's bounds over a run (its worst-case number of events, at one instant and
  /// in all): required of every structure the run layer plays.
  StructureDescription& bound_events(EventBounds bounds) {
    event_bounds = bounds;
    return *this;
  }
  /// Only these schedulers.
  StructureDescription& limit_schedulers(std::vector<SchedulerKind> kinds, std::string why) {
    schedulers = std::move(kinds);
    scheduler_note = std::move(why);
    return *this;
  }

  /// Its name (`--structure`, the scenario tools, kinetic.CLASSES) and its Python class's name.
  std::string name;
  std::string python_class;
  ObjectsAre objects = ObjectsAre::Points;
  std::vector<QueryType> queries;
  /// The kinds of external events it writes to the event log (`kinetic run --events`,
  /// documented per structure); empty when it does not log its events.
  std::vector<std::string> event_kinds;
  /// Its Python class's docstring: what it keeps and its query methods.
  std::string python_doc;
  /// One line for `kinetic run --help`: what it keeps and answers.
  std::string description;
  /// The dimensions it supports, and why where it is restricted (shown in the error message).
  int min_dimension = 1;
  int max_dimension = std::numeric_limits<int>::max();
  std::string dimension_note;
  /// The highest motion degree it takes (6: the core's limit), and why where it is lower.
  int max_degree = 6;
  std::string degree_note;
  /// A lower limit under the robust scheduler (-1: max_degree), and why.
  int robust_max_degree = -1;
  std::string robust_degree_note;
  /// The magnitudes it takes: every motion's coefficients about t = 0 are 0 or of magnitude in
  /// [2^-magnitude_log2, 2^magnitude_log2) (0: any), and why where it is restricted.
  int magnitude_log2 = 0;
  std::string magnitude_note;
  /// The coefficients it takes as given (about the motion's own origin): |c| < 2^k (0: any),
  /// and why where it is restricted.
  int coefficient_log2 = 0;
  std::string coefficient_note;
  /// The schedulers it takes (empty: all three), and why where it is restricted.
  std::vector<SchedulerKind> schedulers;
  std::string scheduler_note;
  /// How many events a correct run can have (bound_events); null: not said.
  EventBounds event_bounds = nullptr;
};

}  // namespace kinetic
