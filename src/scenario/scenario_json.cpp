#include "kinetic/scenario/scenario_json.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "kinetic/core/polynomial.hpp"
#include "kinetic/core/predicates.hpp"
#include "json_text.hpp"

namespace kinetic::scenario {
namespace {

// ordered_json keeps the keys in file order, so "the first fault found" is the first in the file.
using json_text::Json;
using json_text::describe;
using json_text::excerpt;
using json_text::excerpt_raw;
using json_text::format_double;
using json_text::index_path;
using json_text::member_path;
using json_text::Path;
using json_text::quote;
using json_text::short_path;

constexpr const char* kFormat = "kinetic-scenario/1";
constexpr int kMaxDimension = 64;
constexpr std::size_t kMaxCoefficients = static_cast<std::size_t>(kMaxMotionDegree) + 1;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// ---------------------------------------------------------------------------------------------
// Text helpers

/// `v` to 15 significant digits, for times that are found numerically: the first double past a
/// crossing at 3.25 is 3.2500000000000004, which would only distract in a message.
std::string format_rounded(double v) {
  std::array<char, 64> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), v,
                                    std::chars_format::general, 15);
  double rounded = v;
  std::from_chars(buffer.data(), result.ptr, rounded);
  return format_double(rounded);
}

std::string list_of(std::initializer_list<const char*> names) {
  std::string out;
  for (const char* name : names) out += (out.empty() ? "" : ", ") + quote(name);
  return out;
}

// ---------------------------------------------------------------------------------------------
// Intervals turning inside out

/// Maps doubles to integers in the same order, so that a bisection over times ends in 64 steps.
std::int64_t time_key(double t) {
  const auto bits = std::bit_cast<std::int64_t>(t);
  return bits >= 0 ? bits : std::numeric_limits<std::int64_t>::min() - bits;
}
double time_of_key(std::int64_t key) {
  return std::bit_cast<double>(key >= 0 ? key : std::numeric_limits<std::int64_t>::min() - key);
}

/// The earliest time in [lo, hi] (hi may be +infinity) at which `right` is below `left`, to double
/// precision, certified exactly; nullopt when there is none.
std::optional<double> inside_out_time(const MotionPolynomial& left, const MotionPolynomial& right,
                                      double lo, double hi) {
  const std::optional<Time> witness = find_time_below(right, left, lo, hi);
  if (!witness || *witness == lo) return witness;
  // The witness may be any such time (often the end of the piece); the message should name the
  // crossing, so bisect for the smallest end at which the exact search still finds one. This
  // runs only on the way to an error, so its cost does not matter.
  std::int64_t good = time_key(lo);
  std::int64_t bad = time_key(*witness);
  while (true) {
    const std::int64_t mid = std::midpoint(good, bad);
    if (mid == good) break;
    (find_time_below(right, left, lo, time_of_key(mid)) ? bad : good) = mid;
  }
  return time_of_key(bad);
}

[[noreturn]] void refuse_size(const std::string& file_name) {
  throw ScenarioError(file_name + ": larger than " + std::to_string(kMaxScenarioBytes >> 20) +
                      " MiB, the most a scenario may hold");
}

Json read_json(const std::string& text, const std::string& file_name) {
  if (text.size() > kMaxScenarioBytes) refuse_size(file_name);
  return json_text::read_strict(text, kMaxScenarioDepth, [&](const json_text::ReadFault& f) {
    using Kind = json_text::ReadFault::Kind;
    switch (f.kind) {
      case Kind::NulByte:
        throw ScenarioError(file_name + ": $: not valid JSON: a NUL byte at offset " +
                            std::to_string(f.offset) + " (JSON text has none)");
      case Kind::DuplicateKey:
        throw ScenarioError(file_name + ": " + short_path(f.path) +
                            ": expected each key once, got key " + excerpt(f.key) + " twice");
      case Kind::TooDeep:
        throw ScenarioError(file_name + ": " + short_path(f.path) + ": nested deeper than " +
                            std::to_string(kMaxScenarioDepth) +
                            " levels (a scenario needs at most 6)");
      case Kind::Syntax:
        break;
    }
    // 406: a number literal beyond the double range ("number overflow parsing '1e999'").
    const std::string& message = f.message;
    const auto open_quote = message.find('\'');
    const auto close_quote = message.rfind('\'');
    if (f.id == 406 && open_quote != std::string::npos && close_quote > open_quote) {
      // What the value had to be, where the reader knows it from the key alone (the integer
      // fields); any other number must be a finite double.
      const char* expected = f.key == "id"          ? "an integer id (64-bit signed)"
                             : f.key == "dimension" ? "an integer dimension"
                             : f.key == "axis"      ? "an integer axis"
                                                    : "a finite number";
      throw ScenarioError(
          file_name + ": " + short_path(f.path) + ": expected " + expected + ", got " +
          excerpt_raw(message.substr(open_quote + 1, close_quote - open_quote - 1)) +
          " (beyond the range of a double)");
    }
    throw ScenarioError(file_name + ": $: not valid JSON: " + message);
  });
}

// ---------------------------------------------------------------------------------------------
// Validation

std::string object_path(std::size_t index) { return index_path("$.objects", index); }
std::string timeline_path(const TimelineOp& op) { return index_path("$.timeline", op.file_index); }

class ScenarioParser {
 public:
  explicit ScenarioParser(std::string file_name) : file_(std::move(file_name)) {}

  Scenario parse(const Json& root) {
    const Path at;
    if (!root.is_object()) fail(at, "expected an object, got " + describe(root));
    const Json& format = require(root, at, "format", "\"kinetic-scenario/1\"");
    if (format != kFormat)
      fail(at / "format", "expected " + quote(kFormat) + ", got " + describe(format));
    check_keys(
        root, at,
        {"format", "dimension", "objects_are", "start_time", "end_time", "objects", "timeline"});

    const Json& dimension = require(root, at, "dimension", "an integer in [1, 64]");
    s_.dimension = static_cast<int>(integer(dimension, at / "dimension", 1, kMaxDimension));

    if (const Json* objects_are = find(root, "objects_are")) {
      if (*objects_are == "points") {
        s_.objects_are = ObjectsAre::Points;
      } else if (*objects_are == "intervals") {
        s_.objects_are = ObjectsAre::Intervals;
      } else if (*objects_are == "boxes") {
        s_.objects_are = ObjectsAre::Boxes;
      } else {
        fail(at / "objects_are",
             "expected one of \"points\", \"intervals\", \"boxes\", got " + describe(*objects_are));
      }
    }
    if (s_.objects_are == ObjectsAre::Boxes && s_.dimension > 3) {
      fail(at / "dimension",
           "expected 1, 2 or 3 for \"objects_are\": \"boxes\" (one center coordinate and one "
           "half extent per axis), got " +
               std::to_string(s_.dimension));
    }
    if (s_.objects_are == ObjectsAre::Intervals && s_.dimension != 2) {
      fail(at / "dimension",
           "expected 2 for \"objects_are\": \"intervals\" (left end, right end), got " +
               std::to_string(s_.dimension));
    }

    if (const Json* start = find(root, "start_time"))
      s_.start_time = number(*start, at / "start_time");
    if (const Json* end = find(root, "end_time")) {
      const double end_time = number(*end, at / "end_time");
      if (end_time < s_.start_time) {
        fail(at / "end_time", "expected a finite number >= start_time (" +
                                  format_double(s_.start_time) + "), got " + describe(*end));
      }
      s_.end_time = end_time;
    }

    const Path objects_at = at / "objects";
    const Json& objects = require(root, at, "objects", "an array");
    if (!objects.is_array()) fail(objects_at, "expected an array, got " + describe(objects));
    s_.objects.reserve(objects.size());
    std::map<ObjectId, std::size_t> first_seen;
    for (std::size_t i = 0; i < objects.size(); ++i) {
      s_.objects.push_back(object(objects[i], objects_at[i]));
      const ObjectId id = s_.objects.back().id;
      const auto [seen, inserted] = first_seen.emplace(id, i);
      if (!inserted) {
        fail(objects_at[i] / "id",
             "duplicate id " + std::to_string(id) + " (also " + object_path(seen->second) + ".id)");
      }
    }

    if (const Json* timeline = find(root, "timeline")) {
      const Path timeline_at = at / "timeline";
      if (!timeline->is_array()) fail(timeline_at, "expected an array, got " + describe(*timeline));
      s_.timeline.reserve(timeline->size());
      for (std::size_t i = 0; i < timeline->size(); ++i) {
        s_.timeline.push_back(timeline_op((*timeline)[i], timeline_at[i]));
        s_.timeline.back().file_index = i;
      }
      std::stable_sort(s_.timeline.begin(), s_.timeline.end(),
                       [](const TimelineOp& x, const TimelineOp& y) { return x.time < y.time; });
    }

    check_ids_along_timeline();
    if (s_.objects_are == ObjectsAre::Intervals) check_intervals();
    return std::move(s_);
  }

 private:
  [[noreturn]] void fail(const std::string& path, const std::string& message) const {
    throw ScenarioError(file_ + ": " + short_path(path) + ": " + message);
  }
  [[noreturn]] void fail(const Path& path, const std::string& message) const {
    fail(path.str(), message);
  }

  static const Json* find(const Json& object, const char* key) {
    const auto it = object.find(key);
    return it == object.end() ? nullptr : &*it;
  }

  const Json& require(const Json& object, const Path& path, const char* key,
                      const char* what) const {
    const Json* value = find(object, key);
    if (value == nullptr) fail(path, "expected key " + quote(key) + " (" + what + ")");
    return *value;
  }

  /// Unknown keys are errors: a typo such as "orgin" must not silently fall back to a default.
  /// `context` (may be empty) says whose fields these are.
  void check_keys(const Json& object, const Path& path, std::initializer_list<const char*> allowed,
                  const std::string& context = "") const {
    for (const auto& item : object.items()) {
      const bool known = std::any_of(allowed.begin(), allowed.end(),
                                     [&](const char* name) { return item.key() == name; });
      if (!known) {
        fail(path, "expected " + std::string(allowed.size() == 1 ? "only " : "one of ") +
                       list_of(allowed) + context + ", got key " + excerpt(item.key()));
      }
    }
  }

  double number(const Json& v, const Path& path) const {
    if (!v.is_number() || !std::isfinite(v.get<double>())) {
      fail(path, "expected a finite number, got " + describe(v));
    }
    return v.get<double>();
  }

  double non_negative(const Json& v, const Path& path) const {
    const double x = number(v, path);
    if (x < 0.0) fail(path, "expected a finite number >= 0, got " + describe(v));
    return x;
  }

  /// A JSON integer literal (not 7.0, not "7") within [lo, hi]; `what` names it in messages
  /// (default "an integer in [lo, hi]").
  std::int64_t integer(const Json& v, const Path& path, std::int64_t lo, std::int64_t hi,
                       const char* what = nullptr) const {
    // The reader keeps non-negative literals as unsigned: compare without converting first.
    bool fits = false;
    if (v.is_number_unsigned()) {
      const std::uint64_t u = v.get<std::uint64_t>();
      fits = hi >= 0 && u <= static_cast<std::uint64_t>(hi) &&
             (lo <= 0 || u >= static_cast<std::uint64_t>(lo));
    } else if (v.is_number_integer()) {
      const std::int64_t i = v.get<std::int64_t>();
      fits = i >= lo && i <= hi;
    }
    if (!fits) {
      const std::string expected = what != nullptr ? std::string(what)
                                                   : "an integer in [" + std::to_string(lo) + ", " +
                                                         std::to_string(hi) + "]";
      fail(path, "expected " + expected + ", got " + describe(v));
    }
    return v.get<std::int64_t>();
  }

  ObjectId id(const Json& owner, const Path& owner_path) const {
    return integer(require(owner, owner_path, "id", "an integer id"), owner_path / "id",
                   std::numeric_limits<std::int64_t>::min(),
                   std::numeric_limits<std::int64_t>::max(), "an integer id (64-bit signed)");
  }

  /// Exactly `count` finite numbers.
  std::vector<double> numbers(const Json& v, const Path& path, std::size_t count) const {
    if (!v.is_array() || v.size() != count) {
      fail(path, "expected an array of " + std::to_string(count) + " numbers, got " + describe(v));
    }
    std::vector<double> out;
    out.reserve(count);
    for (std::size_t i = 0; i < count; ++i) out.push_back(number(v[i], path[i]));
    return out;
  }

  /// `owner`'s key `key`: an array of `dimension` numbers.
  std::vector<double> point(const Json& owner, const Path& owner_path, const char* key) const {
    const Json* v = find(owner, key);
    if (v == nullptr) {
      fail(owner_path, "expected key " + quote(key) + " (an array of " +
                           std::to_string(s_.dimension) + " numbers)");
    }
    return numbers(*v, owner_path / key, static_cast<std::size_t>(s_.dimension));
  }

  /// Reads "motion" (required) and "origin" (optional) of `owner`.
  Motion motion(const Json& owner, const Path& owner_path) const {
    const std::size_t dimension = static_cast<std::size_t>(s_.dimension);
    const Json* coordinates = find(owner, "motion");
    if (coordinates == nullptr) {
      fail(owner_path, "expected key \"motion\" (an array of " + std::to_string(dimension) +
                           " coefficient arrays)");
    }
    const Path path = owner_path / "motion";
    if (!coordinates->is_array() || coordinates->size() != dimension) {
      fail(path, "expected an array of " + std::to_string(dimension) +
                     " coefficient arrays (one per coordinate), got " + describe(*coordinates));
    }
    Motion m;
    m.coordinates.reserve(dimension);
    for (std::size_t k = 0; k < dimension; ++k) {
      const Json& c = (*coordinates)[k];
      const Path coordinate_path = path[k];
      if (!c.is_array() || c.empty()) {
        fail(coordinate_path, "expected an array of 1 to " + std::to_string(kMaxCoefficients) +
                                  " coefficients, got " + describe(c));
      }
      std::vector<double> coefficients;
      coefficients.reserve(c.size());
      for (std::size_t i = 0; i < c.size(); ++i)
        coefficients.push_back(number(c[i], coordinate_path[i]));
      // Trailing zeros do not raise the degree; they are kept as written.
      std::size_t significant = coefficients.size();
      while (significant > 1 && coefficients[significant - 1] == 0.0) --significant;
      if (significant > kMaxCoefficients) {
        fail(coordinate_path,
             "expected a polynomial of degree <= " + std::to_string(kMaxMotionDegree) +
                 " (at most " + std::to_string(kMaxCoefficients) +
                 " coefficients once trailing zeros are dropped), got degree " +
                 std::to_string(significant - 1));
      }
      m.coordinates.push_back(std::move(coefficients));
    }
    if (const Json* origin = find(owner, "origin"))
      m.origin = number(*origin, owner_path / "origin");
    return m;
  }

  /// Boxes: `owner`'s "half_extents", one finite number >= 0 per axis (required unless
  /// `optional`; absent: empty). Other objects: the key is refused with what it is for.
  std::vector<double> half_extents(const Json& owner, const Path& owner_path, bool optional) const {
    const Json* v = find(owner, "half_extents");
    if (s_.objects_are != ObjectsAre::Boxes) {
      if (v != nullptr) {
        fail(owner_path / "half_extents",
             std::string("expected no \"half_extents\": they belong to \"objects_are\": "
                         "\"boxes\", and these objects are ") +
                 quote(to_string(s_.objects_are)));
      }
      return {};
    }
    if (v == nullptr) {
      if (optional) return {};
      fail(owner_path, "expected key \"half_extents\" (an array of " +
                           std::to_string(s_.dimension) +
                           " numbers >= 0, one per axis: the objects are boxes)");
    }
    const Path path = owner_path / "half_extents";
    std::vector<double> h = numbers(*v, path, static_cast<std::size_t>(s_.dimension));
    for (std::size_t k = 0; k < h.size(); ++k) {
      if (h[k] < 0.0) fail(path[k], "expected a half extent >= 0, got " + describe((*v)[k]));
    }
    return h;
  }

  ObjectSpec object(const Json& v, const Path& path) const {
    const bool boxes = s_.objects_are == ObjectsAre::Boxes;
    if (!v.is_object()) {
      fail(path, std::string("expected an object {\"id\", \"motion\"") +
                     (boxes ? ", \"half_extents\"" : "") + "}, got " + describe(v));
    }
    if (boxes) {
      check_keys(v, path, {"id", "motion", "origin", "half_extents"});
    } else if (find(v, "half_extents") == nullptr) {
      check_keys(v, path, {"id", "motion", "origin"});
    }
    ObjectSpec spec;
    spec.id = id(v, path);
    spec.motion = motion(v, path);
    spec.half_extents = half_extents(v, path, false);
    return spec;
  }

  TimelineOp timeline_op(const Json& v, const Path& path) const {
    if (!v.is_object())
      fail(path, "expected an object {\"time\", \"op\", ...}, got " + describe(v));
    TimelineOp op;
    const Json& time = require(v, path, "time", "a finite number");
    op.time = number(time, path / "time");
    const bool inside = op.time >= s_.start_time && (!s_.end_time || op.time <= *s_.end_time);
    if (!inside) {
      const std::string window = s_.end_time
                                     ? "in [" + format_double(s_.start_time) + ", " +
                                           format_double(*s_.end_time) + "] (start_time, end_time)"
                                     : ">= start_time (" + format_double(s_.start_time) + ")";
      fail(path / "time", "expected a time " + window + ", got " + describe(time));
    }
    const Json& kind =
        require(v, path, "op", "one of \"query\", \"update\", \"insert\", \"remove\"");
    if (kind == "query") {
      op.op = OpKind::Query;
      check_keys(v, path, {"time", "op", "query"}, " (fields of a \"query\" entry)");
      op.query = query(require(v, path, "query", "an object with a \"type\""), path / "query");
    } else if (kind == "update" || kind == "insert") {
      op.op = kind == "update" ? OpKind::Update : OpKind::Insert;
      if (s_.objects_are == ObjectsAre::Boxes || find(v, "half_extents") != nullptr) {
        check_keys(v, path, {"time", "op", "id", "motion", "origin", "half_extents"},
                   op.op == OpKind::Update ? " (fields of an \"update\" entry)"
                                           : " (fields of an \"insert\" entry)");
      } else {
        check_keys(v, path, {"time", "op", "id", "motion", "origin"},
                   op.op == OpKind::Update ? " (fields of an \"update\" entry)"
                                           : " (fields of an \"insert\" entry)");
      }
      op.id = id(v, path);
      op.motion = motion(v, path);
      op.half_extents = half_extents(v, path, op.op == OpKind::Update);
    } else if (kind == "remove") {
      op.op = OpKind::Remove;
      check_keys(v, path, {"time", "op", "id"}, " (fields of a \"remove\" entry)");
      op.id = id(v, path);
    } else {
      fail(path / "op",
           "expected one of \"query\", \"update\", \"insert\", \"remove\", got " + describe(kind));
    }
    return op;
  }

  QuerySpec query(const Json& v, const Path& path) const {
    if (!v.is_object()) fail(path, "expected an object with a \"type\", got " + describe(v));
    const Json& type = require(v, path, "type", "a query type");
    const std::optional<QueryType> parsed =
        type.is_string() ? query_type_from_string(type.get<std::string>()) : std::nullopt;
    if (!parsed) {
      fail(path / "type",
           "expected one of \"sorted\", \"max\", \"min\", \"extent\", \"range\", \"nearest\", "
           "\"k_nearest\", \"farthest\", "
           "\"approx_range\", \"stab\", \"hull\", \"closest_pair\", \"colliding_pairs\", "
           "\"delaunay\", got " +
               describe(type));
    }
    QuerySpec q;
    q.type = *parsed;
    const std::string context = std::string(" (fields of a \"") + to_string(q.type) + "\" query)";
    switch (q.type) {
      case QueryType::Sorted:
      case QueryType::Max:
      case QueryType::Min:
        check_keys(v, path, {"type", "axis"}, context);
        if (const Json* axis = find(v, "axis")) {
          q.axis = static_cast<int>(integer(*axis, path / "axis", 0, s_.dimension - 1));
        }
        break;
      case QueryType::Extent:
      case QueryType::Hull:
      case QueryType::ClosestPair:
      case QueryType::Delaunay:
        check_keys(v, path, {"type"}, context);
        break;
      case QueryType::Range:
        q.box = box(v, path, context);
        break;
      case QueryType::Nearest:
      case QueryType::Farthest:
        check_keys(v, path, {"type", "point", "eps"}, context);
        q.point = point(v, path, "point");
        if (const Json* eps = find(v, "eps")) q.eps = non_negative(*eps, path / "eps");
        break;
      case QueryType::KNearest:
        check_keys(v, path, {"type", "point", "k", "eps"}, context);
        q.point = point(v, path, "point");
        q.k = static_cast<std::size_t>(integer(require(v, path, "k", "an integer k >= 0"),
                                               path / "k", 0, (std::int64_t{1} << 32) - 1));
        if (const Json* eps = find(v, "eps")) q.eps = non_negative(*eps, path / "eps");
        break;
      case QueryType::ApproxRange:
        check_keys(v, path, {"type", "shape", "eps"}, context);
        q.shape = shape(require(v, path, "shape", "{\"disk\": ...} or {\"polygon\": ...}"),
                        path / "shape");
        if (const Json* eps = find(v, "eps")) q.eps = non_negative(*eps, path / "eps");
        break;
      case QueryType::Stab:
        check_keys(v, path, {"type", "x"}, context);
        q.x = number(require(v, path, "x", "a finite number"), path / "x");
        break;
      case QueryType::CollidingPairs:
        check_keys(v, path, {"type"}, context);  // the boxes carry their extents
        break;
    }
    return q;
  }

  std::vector<std::array<double, 2>> box(const Json& query, const Path& query_path,
                                         const std::string& context) const {
    check_keys(query, query_path, {"type", "box"}, context);
    const std::string pairs = std::to_string(s_.dimension) + " [lo, hi] pairs";
    const Json* v = find(query, "box");
    if (v == nullptr) fail(query_path, "expected key \"box\" (an array of " + pairs + ")");
    const Path path = query_path / "box";
    if (!v->is_array() || v->size() != static_cast<std::size_t>(s_.dimension)) {
      fail(path, "expected an array of " + pairs + " (one per axis), got " + describe(*v));
    }
    std::vector<std::array<double, 2>> out;
    for (std::size_t k = 0; k < v->size(); ++k) {
      const std::vector<double> side = numbers((*v)[k], path[k], 2);
      if (side[0] > side[1]) {
        fail(path[k], "expected [lo, hi] with lo <= hi, got [" + format_double(side[0]) + ", " +
                          format_double(side[1]) + "]");
      }
      out.push_back({side[0], side[1]});
    }
    return out;
  }

  Shape shape(const Json& v, const Path& path) const {
    if (!v.is_object() || v.size() != 1) {
      fail(path, "expected an object with one key, \"disk\" or \"polygon\", got " + describe(v));
    }
    check_keys(v, path, {"disk", "polygon"});
    Shape out;
    if (const Json* disk = find(v, "disk")) {
      const Path disk_path = path / "disk";
      if (!disk->is_object())
        fail(disk_path, "expected an object {\"center\", \"radius\"}, got " + describe(*disk));
      check_keys(*disk, disk_path, {"center", "radius"});
      out.kind = Shape::Kind::Disk;
      out.disk.center = point(*disk, disk_path, "center");
      out.disk.radius = non_negative(require(*disk, disk_path, "radius", "a finite number >= 0"),
                                     disk_path / "radius");
      return out;
    }
    const Json& polygon = *find(v, "polygon");
    const Path polygon_path = path / "polygon";
    if (s_.dimension != 2) {
      fail(polygon_path,
           "expected \"disk\" (a polygon needs dimension 2, the scenario has dimension " +
               std::to_string(s_.dimension) + ")");
    }
    if (!polygon.is_array() || polygon.size() < 3) {
      fail(polygon_path,
           "expected an array of at least 3 vertices [x, y], got " + describe(polygon));
    }
    out.kind = Shape::Kind::Polygon;
    for (std::size_t i = 0; i < polygon.size(); ++i) {
      const std::vector<double> vertex = numbers(polygon[i], polygon_path[i], 2);
      out.polygon.push_back({vertex[0], vertex[1]});
    }
    return out;
  }

  /// Walks the time-sorted timeline: an insert needs a free id, an update or remove a live one.
  void check_ids_along_timeline() const {
    struct State {
      bool alive = false;
      const TimelineOp* removed_by = nullptr;
    };
    std::map<ObjectId, State> ids;
    for (const ObjectSpec& object : s_.objects) ids[object.id].alive = true;
    for (const TimelineOp& op : s_.timeline) {
      if (op.op == OpKind::Query) continue;
      State& state = ids[op.id];
      if (op.op == OpKind::Insert) {
        if (state.alive) {
          fail(timeline_path(op) + ".id",
               "duplicate id " + std::to_string(op.id) +
                   ": an object with this id is alive at t=" + format_double(op.time));
        }
        state = State{true, nullptr};
        continue;
      }
      if (!state.alive) {
        const std::string why = state.removed_by != nullptr
                                    ? " (removed at t=" + format_double(state.removed_by->time) +
                                          " by " + timeline_path(*state.removed_by) + ")"
                                    : "";
        fail(timeline_path(op) + ".id",
             "unknown id " + std::to_string(op.id) +
                 ": no object with this id is alive at t=" + format_double(op.time) + why);
      }
      if (op.op == OpKind::Remove) state = State{false, &op};
    }
  }

  /// Each piece of an interval's motion, from its start (start_time, or the insert/update) to
  /// the next update/remove of that id or the end, must keep left end <= right end.
  void check_intervals() const {
    struct Piece {
      ObjectId id;
      const Motion* motion;
      double from;
      double to;
      const TimelineOp* op;  // the insert/update that starts the piece; null for an object
      std::size_t object_index;
    };
    const double end = s_.end_time.value_or(kInfinity);
    std::vector<Piece> pieces;
    std::map<ObjectId, std::size_t> open;  // id -> its piece under way
    for (std::size_t i = 0; i < s_.objects.size(); ++i) {
      open[s_.objects[i].id] = pieces.size();
      pieces.push_back({s_.objects[i].id, &s_.objects[i].motion, s_.start_time, end, nullptr, i});
    }
    for (const TimelineOp& op : s_.timeline) {
      if (op.op == OpKind::Query) continue;
      if (op.op != OpKind::Insert) {
        pieces[open.at(op.id)].to = op.time;
        open.erase(op.id);
      }
      if (op.op != OpKind::Remove) {
        open[op.id] = pieces.size();
        pieces.push_back({op.id, &op.motion, op.time, end, &op, 0});
      }
    }
    for (const Piece& piece : pieces) {
      const Motion& m = *piece.motion;
      const std::optional<double> t =
          inside_out_time(MotionPolynomial::from(m.coordinates[0], m.origin),
                          MotionPolynomial::from(m.coordinates[1], m.origin), piece.from, piece.to);
      if (!t) continue;
      // Ends that touch at the start and part the wrong way are inside out from the next double on.
      const std::string when = *t == piece.from ? "is inside out at t=" + format_double(*t)
                               : std::nextafter(piece.from, kInfinity) == *t
                                   ? "turns inside out just after t=" + format_double(piece.from)
                                   : "turns inside out at t=" + format_rounded(*t);
      fail(piece.op != nullptr ? timeline_path(*piece.op) : object_path(piece.object_index),
           "interval " + std::to_string(piece.id) + " " + when + " (left end passes right end)");
    }
  }

  std::string file_;
  Scenario s_;
};

// ---------------------------------------------------------------------------------------------
// Writing

std::string number_text(double v) {
  if (!std::isfinite(v)) throw std::invalid_argument("write_scenario: a number is not finite");
  return format_double(v);
}

std::string numbers_text(const std::vector<double>& values) {
  std::string out = "[";
  for (std::size_t i = 0; i < values.size(); ++i) out += (i ? ", " : "") + number_text(values[i]);
  return out + "]";
}

std::string pairs_text(const std::vector<std::array<double, 2>>& pairs) {
  std::string out = "[";
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    out += (i ? ", [" : "[") + number_text(pairs[i][0]) + ", " + number_text(pairs[i][1]) + "]";
  }
  return out + "]";
}

/// `"motion": [...]` plus `"origin"` unless it is +0.0 (the default; -0.0 is written).
std::string motion_text(const Motion& m) {
  std::string out = "\"motion\": [";
  for (std::size_t k = 0; k < m.coordinates.size(); ++k)
    out += (k ? ", " : "") + numbers_text(m.coordinates[k]);
  out += "]";
  if (m.origin != 0.0 || std::signbit(m.origin)) out += ", \"origin\": " + number_text(m.origin);
  return out;
}

std::string query_text(const QuerySpec& q) {
  std::string out = "{\"type\": " + quote(to_string(q.type));
  switch (q.type) {
    case QueryType::Sorted:
    case QueryType::Max:
    case QueryType::Min:
      out += ", \"axis\": " + std::to_string(q.axis);
      break;
    case QueryType::Extent:
    case QueryType::Hull:
    case QueryType::ClosestPair:
    case QueryType::Delaunay:
      break;
    case QueryType::Range:
      out += ", \"box\": " + pairs_text(q.box);
      break;
    case QueryType::Nearest:
    case QueryType::Farthest:
      out += ", \"point\": " + numbers_text(q.point) + ", \"eps\": " + number_text(q.eps);
      break;
    case QueryType::KNearest:
      out += ", \"point\": " + numbers_text(q.point) + ", \"k\": " + std::to_string(q.k) +
             ", \"eps\": " + number_text(q.eps);
      break;
    case QueryType::ApproxRange:
      if (q.shape.kind == Shape::Kind::Polygon) {
        out += ", \"shape\": {\"polygon\": " + pairs_text(q.shape.polygon) + "}";
      } else {
        out += ", \"shape\": {\"disk\": {\"center\": " + numbers_text(q.shape.disk.center) +
               ", \"radius\": " + number_text(q.shape.disk.radius) + "}}";
      }
      out += ", \"eps\": " + number_text(q.eps);
      break;
    case QueryType::Stab:
      out += ", \"x\": " + number_text(q.x);
      break;
    case QueryType::CollidingPairs:
      break;
  }
  return out + "}";
}

}  // namespace

Scenario parse_scenario(const std::string& text, const std::string& file_name) {
  return ScenarioParser(file_name).parse(read_json(text, file_name));
}

Scenario load_scenario(const std::string& path) {
  const bool from_stdin = path == "-";
  const std::string name = from_stdin ? "<stdin>" : path;
  std::FILE* file = from_stdin ? stdin : std::fopen(path.c_str(), "rb");
  if (file == nullptr) throw ScenarioError(name + ": cannot read: " + std::strerror(errno));
  std::string text;
  std::array<char, 1 << 16> buffer{};
  std::size_t got = 0;
  while ((got = std::fread(buffer.data(), 1, buffer.size(), file)) > 0) {
    text.append(buffer.data(), got);
    if (text.size() > kMaxScenarioBytes) {  // stop reading: it would be refused anyway
      if (!from_stdin) std::fclose(file);
      refuse_size(name);
    }
  }
  const int error = std::ferror(file) ? errno : 0;
  if (!from_stdin) std::fclose(file);
  if (error != 0) throw ScenarioError(name + ": cannot read: " + std::strerror(error));
  return parse_scenario(text, name);
}

namespace {
/// `, "half_extents": [...]`, or nothing when empty.
std::string half_extents_text(const std::vector<double>& h) {
  if (h.empty()) return "";
  std::string out = ", \"half_extents\": [";
  for (std::size_t k = 0; k < h.size(); ++k) out += (k ? ", " : "") + number_text(h[k]);
  return out + "]";
}
}  // namespace

std::string write_scenario(const Scenario& s) {
  std::string out = "{\n";
  out += "  \"format\": " + quote(kFormat) + ",\n";
  out += "  \"dimension\": " + std::to_string(s.dimension) + ",\n";
  out += "  \"objects_are\": " + quote(to_string(s.objects_are)) + ",\n";
  out += "  \"start_time\": " + number_text(s.start_time) + ",\n";
  if (s.end_time) out += "  \"end_time\": " + number_text(*s.end_time) + ",\n";
  out += "  \"objects\": [";
  for (std::size_t i = 0; i < s.objects.size(); ++i) {
    out += (i ? ",\n    " : "\n    ") + std::string("{\"id\": ") + std::to_string(s.objects[i].id) +
           ", " + motion_text(s.objects[i].motion) + half_extents_text(s.objects[i].half_extents) +
           "}";
  }
  out += s.objects.empty() ? "],\n" : "\n  ],\n";
  out += "  \"timeline\": [";
  for (std::size_t i = 0; i < s.timeline.size(); ++i) {
    const TimelineOp& op = s.timeline[i];
    out += (i ? ",\n    " : "\n    ") + std::string("{\"time\": ") + number_text(op.time) +
           ", \"op\": " + quote(to_string(op.op));
    switch (op.op) {
      case OpKind::Query:
        out += ", \"query\": " + query_text(op.query);
        break;
      case OpKind::Update:
      case OpKind::Insert:
        out += ", \"id\": " + std::to_string(op.id) + ", " + motion_text(op.motion) +
               half_extents_text(op.half_extents);
        break;
      case OpKind::Remove:
        out += ", \"id\": " + std::to_string(op.id);
        break;
    }
    out += "}";
  }
  out += s.timeline.empty() ? "]\n" : "\n  ]\n";
  return out + "}\n";
}

}  // namespace kinetic::scenario
