#pragma once
// The scenario model: the in-memory form of a `kinetic-scenario/1` file (see the contract in
// docs/scenario-format.md). Parsing and validation live in scenario_json.hpp; dataset generators
// in generators.hpp. Everything here is plain data.

#include <array>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "kinetic/core/description.hpp"
#include "kinetic/core/geometry.hpp"
#include "kinetic/core/ids.hpp"

namespace kinetic::scenario {

using kinetic::Box;
using kinetic::Disk;
using kinetic::ObjectId;
using kinetic::Polygon;
using kinetic::Shape;

// The object kinds and query types are the core's vocabulary (core/description.hpp): a
// structure's description names them.
using kinetic::ObjectsAre;
using kinetic::query_type_from_string;
using kinetic::query_type_names;
using kinetic::QueryType;
using kinetic::to_string;

/// Motion of one object: motion[k] holds coordinate k's coefficients in ascending powers of
/// (t - origin), as written in the file (trailing zeros kept as written).
struct Motion {
  std::vector<std::vector<double>> coordinates;
  double origin = 0.0;

  friend bool operator==(const Motion&, const Motion&) = default;
};

struct ObjectSpec {
  ObjectSpec() = default;
  ObjectSpec(ObjectId id_, Motion motion_, std::vector<double> half_extents_ = {})
      : id(id_), motion(std::move(motion_)), half_extents(std::move(half_extents_)) {}

  ObjectId id = 0;
  Motion motion;  ///< boxes: the center's motion
  /// Boxes: one constant half extent >= 0 per axis (the box is [center - h, center + h] on each
  /// axis, closed); empty for points and intervals.
  std::vector<double> half_extents;

  friend bool operator==(const ObjectSpec&, const ObjectSpec&) = default;
};

/// One query. Only the fields of its type are meaningful; the parser fills defaults.
struct QuerySpec {
  QueryType type = QueryType::Sorted;
  int axis = 0;                  ///< sorted, max, min
  Box box;                       ///< range (closed [lo, hi] per axis)
  std::vector<double> point;     ///< nearest, k_nearest, farthest
  std::size_t k = 1;             ///< k_nearest
  double eps = 0.0;              ///< nearest, k_nearest, farthest, approx_range
  Shape shape;                   ///< approx_range
  double x = 0.0;                ///< stab

  friend bool operator==(const QuerySpec&, const QuerySpec&) = default;
};

enum class OpKind { Query, Update, Insert, Remove };
[[nodiscard]] const char* to_string(OpKind op);

struct TimelineOp {
  double time = 0.0;
  OpKind op = OpKind::Query;
  QuerySpec query;             ///< op == Query
  ObjectId id = 0;             ///< update, insert, remove
  Motion motion;               ///< update, insert
  /// Boxes: insert (required), update (optional: empty keeps the box's half extents).
  std::vector<double> half_extents;
  std::size_t file_index = 0;  ///< position in the file's timeline array (for messages)

  friend bool operator==(const TimelineOp&, const TimelineOp&) = default;
};

struct Scenario {
  int dimension = 1;
  ObjectsAre objects_are = ObjectsAre::Points;
  double start_time = 0.0;
  std::optional<double> end_time;  ///< absent: "until no event is left"
  std::vector<ObjectSpec> objects;
  /// In processing order: sorted by time, stable for equal times (file order).
  std::vector<TimelineOp> timeline;

  /// Field by field; doubles compare with ==, so 0.0 == -0.0 here.
  friend bool operator==(const Scenario&, const Scenario&) = default;
};

/// A malformed scenario. what() is one line: "FILE: JSON-PATH: what was expected".
class ScenarioError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace kinetic::scenario
