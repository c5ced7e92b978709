// Reading and writing kinetic-scenario/1 files: every refusal names the file, the JSON path and
// what was expected (docs/scenario-format.md); good files come back with defaults applied and
// survive a write/parse round trip bit for bit.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <ostream>
#include <string>
#include <vector>

#include "kinetic/scenario/scenario_json.hpp"

namespace kinetic::scenario {
namespace {

/// A document with the right format line; `body` holds the other root members.
std::string doc(const std::string& body) {
  return R"({"format": "kinetic-scenario/1", )" + body + "}";
}

/// Two points in the plane, ids 7 and 8, plus `timeline` (a JSON array).
std::string plane(const std::string& timeline) {
  return doc(R"("dimension": 2, "end_time": 10, "objects": [
      {"id": 7, "motion": [[0, 1], [0]]}, {"id": 8, "motion": [[1], [1]]}], "timeline": )" +
             timeline);
}

/// A plane scenario with one query at t=1.
std::string query(const std::string& q) {
  return plane(R"([{"time": 1, "op": "query", "query": )" + q + "}]");
}

std::string message_of(const std::string& text) {
  try {
    (void)parse_scenario(text, "bad.json");
  } catch (const ScenarioError& error) {
    return error.what();
  }
  return "(accepted)";
}

struct Malformed {
  const char* name;
  std::string text;
  std::string expected;  ///< the whole message; a trailing "..." means "starts with"
};

const std::vector<Malformed>& malformed_cases() {
  static const std::vector<Malformed> cases = {
      // --- The document itself.
      {"not_json", R"({"format": )",
       "bad.json: $: not valid JSON: parse error at line 1, column 12: syntax error while parsing "
       "value..."},
      {"not_json_nan", doc(R"("dimension": NaN, "objects": [])"),
       "bad.json: $: not valid JSON: parse error at line 1, column 47: syntax error while parsing "
       "value..."},
      {"trailing_garbage", doc(R"("dimension": 1, "objects": []} x)"),
       "bad.json: $: not valid JSON: parse error..."},
      {"root_not_object", "[1, 2]", "bad.json: $: expected an object, got an array of 2 elements"},
      {"duplicate_key", doc(R"("dimension": 1, "objects": [{"id": 1, "id": 2, "motion": [[0]]}])"),
       R"(bad.json: $.objects[0]: expected each key once, got key "id" twice)"},
      {"missing_format", R"({"dimension": 1, "objects": []})",
       R"(bad.json: $: expected key "format" ("kinetic-scenario/1"))"},
      {"wrong_format", R"({"format": "kinetic-scenario/2", "dimension": 1, "objects": []})",
       R"(bad.json: $.format: expected "kinetic-scenario/1", got "kinetic-scenario/2")"},
      {"unknown_root_key", doc(R"("dimension": 1, "objects": [], "end": 3)"),
       R"(bad.json: $: expected one of "format", "dimension", "objects_are", "start_time", "end_time", )"
       R"("objects", "timeline", got key "end")"},
      {"missing_dimension", doc(R"("objects": [])"),
       R"(bad.json: $: expected key "dimension" (an integer in [1, 64]))"},
      {"dimension_zero", doc(R"("dimension": 0, "objects": [])"),
       "bad.json: $.dimension: expected an integer in [1, 64], got 0"},
      {"dimension_fraction", doc(R"("dimension": 2.5, "objects": [])"),
       "bad.json: $.dimension: expected an integer in [1, 64], got 2.5"},
      {"dimension_float_literal", doc(R"("dimension": 2.0, "objects": [])"),
       "bad.json: $.dimension: expected an integer in [1, 64], got 2.0"},
      {"dimension_too_large", doc(R"("dimension": 65, "objects": [])"),
       "bad.json: $.dimension: expected an integer in [1, 64], got 65"},
      {"unknown_objects_are", doc(R"("dimension": 2, "objects_are": "segments", "objects": [])"),
       R"(bad.json: $.objects_are: expected one of "points", "intervals", "boxes", got "segments")"},
      // --- Boxes: a center motion and constant half extents >= 0 per axis.
      {"boxes_in_dimension_4", doc(R"("dimension": 4, "objects_are": "boxes", "objects": [])"),
       R"(bad.json: $.dimension: expected 1, 2 or 3 for "objects_are": "boxes" (one center coordinate and one half extent per axis), got 4)"},
      {"box_without_half_extents",
       doc(R"("dimension": 2, "objects_are": "boxes", "objects": [{"id": 1, "motion": [[0], [0]]}])"),
       R"(bad.json: $.objects[0]: expected key "half_extents" (an array of 2 numbers >= 0, one per axis: the objects are boxes))"},
      {"box_negative_half_extent",
       doc(R"("dimension": 2, "objects_are": "boxes", "objects": [
             {"id": 1, "motion": [[0], [0]], "half_extents": [1, -0.5]}])"),
       R"(bad.json: $.objects[0].half_extents[1]: expected a half extent >= 0, got -0.5)"},
      {"box_half_extent_too_large",
       doc(R"("dimension": 1, "objects_are": "boxes", "objects": [
             {"id": 1, "motion": [[0]], "half_extents": [1e999]}])"),
       "bad.json: $.objects[0].half_extents[0]: expected a finite number, got 1e999 (beyond the "
       "range of a double)"},
      {"box_half_extents_wrong_count",
       doc(R"("dimension": 3, "objects_are": "boxes", "objects": [
             {"id": 1, "motion": [[0], [0], [0]], "half_extents": [1, 1]}])"),
       R"(bad.json: $.objects[0].half_extents: expected an array of 3 numbers, got an array of 2 elements)"},
      {"box_half_extent_string",
       doc(R"("dimension": 1, "objects_are": "boxes", "objects": [
             {"id": 1, "motion": [[0]], "half_extents": ["1"]}])"),
       R"(bad.json: $.objects[0].half_extents[0]: expected a finite number, got "1")"},
      {"inserted_box_without_half_extents",
       doc(R"("dimension": 1, "objects_are": "boxes", "objects": [],
             "timeline": [{"time": 0, "op": "insert", "id": 2, "motion": [[0]]}])"),
       R"(bad.json: $.timeline[0]: expected key "half_extents" (an array of 1 numbers >= 0, one per axis: the objects are boxes))"},
      {"updated_box_negative_half_extent",
       doc(R"("dimension": 1, "objects_are": "boxes", "objects": [{"id": 2, "motion": [[0]], "half_extents": [1]}],
             "timeline": [{"time": 0, "op": "update", "id": 2, "motion": [[0]], "half_extents": [-1]}])"),
       R"(bad.json: $.timeline[0].half_extents[0]: expected a half extent >= 0, got -1)"},
      {"point_with_half_extents",
       doc(R"("dimension": 1, "objects": [{"id": 1, "motion": [[0]], "half_extents": [1]}])"),
       R"(bad.json: $.objects[0].half_extents: expected no "half_extents": they belong to "objects_are": "boxes", and these objects are "points")"},
      {"inserted_interval_with_half_extents",
       doc(R"("dimension": 2, "objects_are": "intervals", "objects": [],
             "timeline": [{"time": 0, "op": "insert", "id": 2, "motion": [[0], [1]], "half_extents": [1, 1]}])"),
       R"(bad.json: $.timeline[0].half_extents: expected no "half_extents": they belong to "objects_are": "boxes", and these objects are "intervals")"},
      {"intervals_in_dimension_3",
       doc(R"("dimension": 3, "objects_are": "intervals", "objects": [])"),
       R"(bad.json: $.dimension: expected 2 for "objects_are": "intervals" (left end, right end), got 3)"},
      {"start_time_string", doc(R"("dimension": 1, "start_time": "0", "objects": [])"),
       R"(bad.json: $.start_time: expected a finite number, got "0")"},
      {"end_time_before_start",
       doc(R"("dimension": 1, "start_time": 5, "end_time": 4, "objects": [])"),
       "bad.json: $.end_time: expected a finite number >= start_time (5.0), got 4"},
      {"end_time_null", doc(R"("dimension": 1, "end_time": null, "objects": [])"),
       "bad.json: $.end_time: expected a finite number, got null"},

      // --- Objects.
      {"missing_objects", doc(R"("dimension": 1)"),
       R"(bad.json: $: expected key "objects" (an array))"},
      {"objects_not_array", doc(R"("dimension": 1, "objects": {"id": 1})"),
       "bad.json: $.objects: expected an array, got an object"},
      {"object_not_object", doc(R"("dimension": 1, "objects": [3])"),
       R"(bad.json: $.objects[0]: expected an object {"id", "motion"}, got 3)"},
      {"object_without_id", doc(R"("dimension": 1, "objects": [{"motion": [[0]]}])"),
       R"(bad.json: $.objects[0]: expected key "id" (an integer id))"},
      {"id_fraction", doc(R"("dimension": 1, "objects": [{"id": 7.5, "motion": [[0]]}])"),
       "bad.json: $.objects[0].id: expected an integer id (64-bit signed), got 7.5"},
      {"id_string", doc(R"("dimension": 1, "objects": [{"id": "7", "motion": [[0]]}])"),
       R"(bad.json: $.objects[0].id: expected an integer id (64-bit signed), got "7")"},
      {"id_beyond_int64",
       doc(R"("dimension": 1, "objects": [{"id": 9223372036854775808, "motion": [[0]]}])"),
       "bad.json: $.objects[0].id: expected an integer id (64-bit signed), got "
       "9223372036854775808"},
      {"duplicate_id",
       doc(R"("dimension": 1, "objects": [{"id": 7, "motion": [[0]]}, {"id": 1, "motion": [[0]]},
                                          {"id": 7, "motion": [[2]]}])"),
       "bad.json: $.objects[2].id: duplicate id 7 (also $.objects[0].id)"},
      {"missing_motion", doc(R"("dimension": 1, "objects": [{"id": 1}])"),
       R"(bad.json: $.objects[0]: expected key "motion" (an array of 1 coefficient arrays))"},
      {"motion_wrong_coordinate_count",
       doc(R"("dimension": 2, "objects": [{"id": 1, "motion": [[0, 1]]}])"),
       "bad.json: $.objects[0].motion: expected an array of 2 coefficient arrays (one per "
       "coordinate), "
       "got an array of 1 element"},
      {"empty_coefficients", doc(R"("dimension": 2, "objects": [{"id": 1, "motion": [[0], []]}])"),
       "bad.json: $.objects[0].motion[1]: expected an array of 1 to 7 coefficients, got an empty "
       "array"},
      {"coefficients_not_array", doc(R"("dimension": 1, "objects": [{"id": 1, "motion": [2.5]}])"),
       "bad.json: $.objects[0].motion[0]: expected an array of 1 to 7 coefficients, got 2.5"},
      {"degree_7",
       doc(R"("dimension": 1, "objects": [{"id": 1, "motion": [[0, 0, 0, 0, 0, 0, 0, 1, 0]]}])"),
       "bad.json: $.objects[0].motion[0]: expected a polynomial of degree <= 6 (at most 7 "
       "coefficients "
       "once trailing zeros are dropped), got degree 7"},
      {"huge_number", doc(R"("dimension": 2, "objects": [{"id": 1, "motion": [[0], [0, 1e999]]}])"),
       "bad.json: $.objects[0].motion[1][1]: expected a finite number, got 1e999 (beyond the range "
       "of a double)"},
      {"huge_start_time", doc(R"("dimension": 1, "start_time": 1e999, "objects": [])"),
       "bad.json: $.start_time: expected a finite number, got 1e999 (beyond the range of a "
       "double)"},
      {"coefficient_string", doc(R"("dimension": 1, "objects": [{"id": 1, "motion": [[0, "1"]]}])"),
       R"(bad.json: $.objects[0].motion[0][1]: expected a finite number, got "1")"},
      {"unknown_object_key",
       doc(R"("dimension": 1, "objects": [{"id": 1, "motion": [[0]], "orgin": 2}])"),
       R"(bad.json: $.objects[0]: expected one of "id", "motion", "origin", got key "orgin")"},
      {"origin_bool",
       doc(R"("dimension": 1, "objects": [{"id": 1, "motion": [[0]], "origin": true}])"),
       "bad.json: $.objects[0].origin: expected a finite number, got true"},

      // --- Timeline entries.
      {"timeline_not_array", doc(R"("dimension": 1, "objects": [], "timeline": {})"),
       "bad.json: $.timeline: expected an array, got an object"},
      {"entry_without_time", plane(R"([{"op": "remove", "id": 7}])"),
       R"(bad.json: $.timeline[0]: expected key "time" (a finite number))"},
      {"unknown_op", plane(R"([{"time": 1, "op": "move", "id": 7}])"),
       R"(bad.json: $.timeline[0].op: expected one of "query", "update", "insert", "remove", got "move")"},
      {"time_after_end",
       plane(R"([{"time": 1, "op": "remove", "id": 8}, {"time": 12.5, "op": "remove", "id": 7}])"),
       "bad.json: $.timeline[1].time: expected a time in [0.0, 10.0] (start_time, end_time), got "
       "12.5"},
      {"time_before_start_without_end",
       doc(R"("dimension": 1, "start_time": 1, "objects": [], "timeline": [{"time": 0.5, "op": "query",
               "query": {"type": "sorted"}}])"),
       "bad.json: $.timeline[0].time: expected a time >= start_time (1.0), got 0.5"},
      {"remove_with_motion",
       plane(R"([{"time": 1, "op": "remove", "id": 7, "motion": [[0], [0]]}])"),
       R"(bad.json: $.timeline[0]: expected one of "time", "op", "id" (fields of a "remove" entry), )"
       R"(got key "motion")"},
      {"update_motion_wrong_dimension",
       plane(R"([{"time": 1, "op": "update", "id": 7, "motion": [[0]]}])"),
       "bad.json: $.timeline[0].motion: expected an array of 2 coefficient arrays (one per "
       "coordinate), "
       "got an array of 1 element"},
      {"update_of_unknown_id",
       plane(R"([{"time": 1, "op": "update", "id": 5, "motion": [[0], [0]]}])"),
       "bad.json: $.timeline[0].id: unknown id 5: no object with this id is alive at t=1.0"},
      {"insert_of_live_id",
       plane(R"([{"time": 1, "op": "insert", "id": 8, "motion": [[0], [0]]}])"),
       "bad.json: $.timeline[0].id: duplicate id 8: an object with this id is alive at t=1.0"},
      // Out of order in the file: the walk follows time, the message the file's positions.
      {"remove_twice",
       plane(R"([{"time": 2, "op": "remove", "id": 7}, {"time": 1, "op": "remove", "id": 7}])"),
       "bad.json: $.timeline[0].id: unknown id 7: no object with this id is alive at t=2.0 "
       "(removed at t=1.0 by $.timeline[1])"},
      {"insert_twice_same_time",
       plane(R"([{"time": 3, "op": "insert", "id": 1, "motion": [[0], [0]]},
                 {"time": 3, "op": "insert", "id": 1, "motion": [[0], [0]]}])"),
       "bad.json: $.timeline[1].id: duplicate id 1: an object with this id is alive at t=3.0"},

      // --- Queries.
      {"missing_query", plane(R"([{"time": 1, "op": "query"}])"),
       R"(bad.json: $.timeline[0]: expected key "query" (an object with a "type"))"},
      {"unknown_query_type", query(R"({"type": "median"})"),
       R"(bad.json: $.timeline[0].query.type: expected one of "sorted", "max", "min", "extent", "range", )"
       R"("nearest", "k_nearest", "farthest", "approx_range", "stab", "hull", "closest_pair", "colliding_pairs", )"
       R"("delaunay", got "median")"},
      {"unknown_field_for_type", query(R"({"type": "hull", "axis": 0})"),
       R"(bad.json: $.timeline[0].query: expected only "type" (fields of a "hull" query), got key "axis")"},
      {"box_lo_above_hi", query(R"({"type": "range", "box": [[0, 1], [3, 1]]})"),
       "bad.json: $.timeline[0].query.box[1]: expected [lo, hi] with lo <= hi, got [3.0, 1.0]"},
      {"box_wrong_dimension", query(R"({"type": "range", "box": [[0, 1]]})"),
       "bad.json: $.timeline[0].query.box: expected an array of 2 [lo, hi] pairs (one per axis), "
       "got an array of 1 element"},
      {"box_side_of_three", query(R"({"type": "range", "box": [[0, 1], [0, 1, 2]]})"),
       "bad.json: $.timeline[0].query.box[1]: expected an array of 2 numbers, got an array of 3 "
       "elements"},
      {"axis_out_of_range", query(R"({"type": "sorted", "axis": 2})"),
       "bad.json: $.timeline[0].query.axis: expected an integer in [0, 1], got 2"},
      {"axis_negative", query(R"({"type": "max", "axis": -1})"),
       "bad.json: $.timeline[0].query.axis: expected an integer in [0, 1], got -1"},
      {"eps_negative", query(R"({"type": "nearest", "point": [0, 0], "eps": -0.5})"),
       "bad.json: $.timeline[0].query.eps: expected a finite number >= 0, got -0.5"},
      {"point_wrong_dimension", query(R"({"type": "farthest", "point": [0, 0, 0]})"),
       "bad.json: $.timeline[0].query.point: expected an array of 2 numbers, got an array of 3 "
       "elements"},
      {"polygon_two_vertices",
       query(R"({"type": "approx_range", "shape": {"polygon": [[0, 0], [1, 0]]}})"),
       "bad.json: $.timeline[0].query.shape.polygon: expected an array of at least 3 vertices [x, "
       "y], "
       "got an array of 2 elements"},
      {"polygon_in_dimension_3",
       doc(R"("dimension": 3, "objects": [], "timeline": [{"time": 0, "op": "query", "query":
               {"type": "approx_range", "shape": {"polygon": [[0, 0], [1, 0], [0, 1]]}}}])"),
       R"(bad.json: $.timeline[0].query.shape.polygon: expected "disk" (a polygon needs dimension 2, )"
       "the scenario has dimension 3)"},
      {"shape_two_kinds",
       query(
           R"({"type": "approx_range", "shape": {"disk": {"center": [0, 0], "radius": 1}, "polygon": []}})"),
       R"(bad.json: $.timeline[0].query.shape: expected an object with one key, "disk" or "polygon", )"
       "got an object"},
      {"disk_negative_radius",
       query(R"({"type": "approx_range", "shape": {"disk": {"center": [0, 0], "radius": -1}}})"),
       "bad.json: $.timeline[0].query.shape.disk.radius: expected a finite number >= 0, got -1"},
      {"stab_without_x", query(R"({"type": "stab"})"),
       R"(bad.json: $.timeline[0].query: expected key "x" (a finite number))"},
      {"colliding_pairs_takes_no_radius", query(R"({"type": "colliding_pairs", "radius": 2})"),
       "bad.json: $.timeline[0].query: expected only \"type\" (fields of a \"colliding_pairs\" "
       "query), got key \"radius\""},

      // --- Intervals: the left end must never pass the right end.
      {"interval_turns_inside_out",
       doc(R"("dimension": 2, "objects_are": "intervals", "end_time": 10, "objects": [
               {"id": 1, "motion": [[0], [1]]}, {"id": 5, "motion": [[0], [1]]},
               {"id": 17, "motion": [[0, 1], [3.25]]}])"),
       "bad.json: $.objects[2]: interval 17 turns inside out at t=3.25 (left end passes right "
       "end)"},
      {"interval_inside_out_from_the_start",
       doc(R"("dimension": 2, "objects_are": "intervals", "start_time": 1, "objects": [
               {"id": 4, "motion": [[2], [1]]}])"),
       "bad.json: $.objects[0]: interval 4 is inside out at t=1.0 (left end passes right end)"},
      {"interval_inside_out_at_start",  // right end t^2 - 4 starts below the left end 10 - 3t
       doc(R"("dimension": 2, "objects_are": "intervals", "objects": [
               {"id": 4, "motion": [[10, -3], [-4, 0, 1]]}])"),
       "bad.json: $.objects[0]: interval 4 is inside out at t=0.0 (left end passes right end)"},
      {"interval_quadratic_crossing",  // right end 4 - t^2 passes the left end 0 at t=2, no
                                       // end_time
       doc(R"("dimension": 2, "objects_are": "intervals", "objects": [
               {"id": 4, "motion": [[0], [4, 0, -1]]}])"),
       "bad.json: $.objects[0]: interval 4 turns inside out at t=2.0 (left end passes right end)"},
      {"interval_inside_out_after_update",
       doc(R"("dimension": 2, "objects_are": "intervals", "end_time": 10, "objects": [
               {"id": 3, "motion": [[0], [1]]}],
             "timeline": [{"time": 2, "op": "update", "id": 3, "motion": [[0, 1], [5]], "origin": 2}])"),
       "bad.json: $.timeline[0]: interval 3 turns inside out at t=7.0 (left end passes right end)"},
      {"interval_touching_then_crossing",  // the ends meet at t=1 and part the wrong way at once
       doc(R"("dimension": 2, "objects_are": "intervals", "start_time": 1, "objects": [
               {"id": 2, "motion": [[0], [0, -1]], "origin": 1}])"),
       "bad.json: $.objects[0]: interval 2 turns inside out just after t=1.0 (left end passes "
       "right end)"},
      {"inserted_interval_inside_out",
       doc(R"("dimension": 2, "objects_are": "intervals", "end_time": 10, "objects": [],
             "timeline": [{"time": 1, "op": "insert", "id": 9, "motion": [[0, 0, 1], [4]]}])"),
       "bad.json: $.timeline[0]: interval 9 turns inside out at t=2.0 (left end passes right end)"},
  };
  return cases;
}

void PrintTo(const Malformed& c, std::ostream* out) { *out << c.name; }

class ScenarioMalformed : public testing::TestWithParam<Malformed> {};

TEST_P(ScenarioMalformed, IsRefusedWithItsPath) {
  const Malformed& c = GetParam();
  const std::string message = message_of(c.text);
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  const std::string ellipsis = "...";
  if (c.expected.size() >= ellipsis.size() &&
      c.expected.compare(c.expected.size() - ellipsis.size(), ellipsis.size(), ellipsis) == 0) {
    const std::string prefix = c.expected.substr(0, c.expected.size() - ellipsis.size());
    EXPECT_EQ(message.substr(0, prefix.size()), prefix) << message;
  } else {
    EXPECT_EQ(message, c.expected);
  }
}

INSTANTIATE_TEST_SUITE_P(Scenario, ScenarioMalformed, testing::ValuesIn(malformed_cases()),
                         [](const testing::TestParamInfo<Malformed>& param) {
                           return std::string(param.param.name);
                         });

// ---------------------------------------------------------------------------------------------
// Good inputs

std::string contract_example_path() {
  return std::string(KINETIC_TEST_DATA_DIR) + "/scenario_contract_example.json";
}

TEST(ScenarioJson, ContractExampleParses) {
  const Scenario s = load_scenario(contract_example_path());
  EXPECT_EQ(s.dimension, 2);
  EXPECT_EQ(s.objects_are, ObjectsAre::Points);
  EXPECT_EQ(s.start_time, 0.0);
  ASSERT_TRUE(s.end_time.has_value());
  EXPECT_EQ(*s.end_time, 10.0);

  ASSERT_EQ(s.objects.size(), 2u);
  EXPECT_EQ(s.objects[0].id, 7);
  EXPECT_EQ(s.objects[0].motion.coordinates,
            (std::vector<std::vector<double>>{{1.0, 0.5}, {2.0, -1.0, 0.25}}));
  EXPECT_EQ(s.objects[0].motion.origin, 0.0);
  EXPECT_EQ(s.objects[1].id, 8);
  EXPECT_EQ(s.objects[1].motion.coordinates, (std::vector<std::vector<double>>{{0.0, 1.0}, {3.0}}));
  EXPECT_EQ(s.objects[1].motion.origin, 2.0);

  ASSERT_EQ(s.timeline.size(), 4u);
  const TimelineOp& q = s.timeline[0];
  EXPECT_EQ(q.time, 1.25);
  EXPECT_EQ(q.op, OpKind::Query);
  EXPECT_EQ(q.query.type, QueryType::Range);
  EXPECT_EQ(q.query.box, (std::vector<std::array<double, 2>>{{0.0, 1.0}, {0.0, 2.0}}));
  const TimelineOp& update = s.timeline[1];
  EXPECT_EQ(update.op, OpKind::Update);
  EXPECT_EQ(update.id, 7);
  EXPECT_EQ(update.motion.coordinates, (std::vector<std::vector<double>>{{1.5, -0.5}, {0.0, 1.0}}));
  EXPECT_EQ(update.motion.origin, 2.0);
  EXPECT_EQ(s.timeline[2].op, OpKind::Insert);
  EXPECT_EQ(s.timeline[2].id, 99);
  EXPECT_EQ(s.timeline[2].motion.origin, 0.0);
  EXPECT_EQ(s.timeline[3].op, OpKind::Remove);
  EXPECT_EQ(s.timeline[3].id, 8);
  for (std::size_t i = 0; i < s.timeline.size(); ++i) EXPECT_EQ(s.timeline[i].file_index, i);
}

TEST(ScenarioJson, DefaultsApplied) {
  const Scenario s = parse_scenario(
      doc(R"("dimension": 3, "objects": [{"id": -4, "motion": [[1], [2], [3]]}], "timeline": [
            {"time": 0, "op": "query", "query": {"type": "max"}},
            {"time": 0, "op": "query", "query": {"type": "nearest", "point": [0, 0, 0]}},
            {"time": 0, "op": "query", "query": {"type": "colliding_pairs"}}])"),
      "good.json");
  EXPECT_EQ(s.objects_are, ObjectsAre::Points);
  EXPECT_EQ(s.start_time, 0.0);
  EXPECT_FALSE(s.end_time.has_value());
  EXPECT_EQ(s.objects[0].id, -4);
  EXPECT_EQ(s.objects[0].motion.origin, 0.0);
  EXPECT_EQ(s.timeline[0].query.axis, 0);
  EXPECT_EQ(s.timeline[1].query.eps, 0.0);

  const Scenario empty = parse_scenario(doc(R"("dimension": 1, "objects": [])"), "empty.json");
  EXPECT_TRUE(empty.objects.empty());
  EXPECT_TRUE(empty.timeline.empty());
}

TEST(ScenarioJson, TimelineSortedStably) {
  const Scenario s = parse_scenario(plane(R"([
      {"time": 3, "op": "query", "query": {"type": "sorted"}},
      {"time": 1, "op": "query", "query": {"type": "min"}},
      {"time": 3, "op": "query", "query": {"type": "max"}},
      {"time": 1, "op": "query", "query": {"type": "extent"}},
      {"time": 2, "op": "query", "query": {"type": "hull"}},
      {"time": 1, "op": "query", "query": {"type": "closest_pair"}}])"),
                                    "good.json");
  std::vector<std::size_t> order;
  for (const TimelineOp& op : s.timeline) order.push_back(op.file_index);
  EXPECT_EQ(order, (std::vector<std::size_t>{1, 3, 5, 4, 0, 2}));
  EXPECT_EQ(s.timeline[0].query.type, QueryType::Min);
  EXPECT_EQ(s.timeline[5].query.type, QueryType::Max);
}

TEST(ScenarioJson, IdsFollowTheTimeline) {
  // Remove then re-insert is fine, also at the same time; an id freed by a remove may be reused.
  EXPECT_NO_THROW((void)parse_scenario(plane(R"([
      {"time": 1, "op": "remove", "id": 7},
      {"time": 1, "op": "insert", "id": 7, "motion": [[0], [0]]},
      {"time": 2, "op": "update", "id": 7, "motion": [[1], [1]]},
      {"time": 4, "op": "insert", "id": -9223372036854775808, "motion": [[0], [0]]},
      {"time": 5, "op": "remove", "id": -9223372036854775808},
      {"time": 6, "op": "insert", "id": 9223372036854775807, "motion": [[0], [0]]}])"),
                                       "good.json"));
}

TEST(ScenarioJson, DegreeCountsAfterTrailingZeros) {
  const Scenario s = parse_scenario(
      doc(R"("dimension": 1, "objects": [{"id": 1, "motion": [[1, 2, 3, 4, 5, 6, 7, 0, 0, 0]]}])"),
      "good.json");
  // Stored as written, trailing zeros included.
  EXPECT_EQ(s.objects[0].motion.coordinates[0].size(), 10u);
}

TEST(ScenarioJson, IntervalsMayTouchButNotCross) {
  // Right end (t - 1.5)^2 touches the left end 0 at t = 1.5: fine.
  EXPECT_NO_THROW(
      (void)parse_scenario(doc(R"("dimension": 2, "objects_are": "intervals", "objects": [
      {"id": 1, "motion": [[0], [2.25, -3, 1]]}])"),
                           "good.json"));
  // Crossing after end_time is outside the run: fine.
  EXPECT_NO_THROW(
      (void)parse_scenario(doc(R"("dimension": 2, "objects_are": "intervals", "end_time": 3,
      "objects": [{"id": 1, "motion": [[0, 1], [3.25]]}])"),
                           "good.json"));
  // Crossing after the update that replaces the motion never happens: fine.
  EXPECT_NO_THROW(
      (void)parse_scenario(doc(R"("dimension": 2, "objects_are": "intervals", "objects": [
      {"id": 1, "motion": [[0, 1], [3.25]]}],
      "timeline": [{"time": 3, "op": "update", "id": 1, "motion": [[3], [3.25, 1]], "origin": 3},
                   {"time": 8, "op": "remove", "id": 1}])"),
                           "good.json"));
}

TEST(ScenarioJson, InsideOutIntervalWithoutEndTime) {
  // Right end -t + 100 meets the left end 0 at t = 100; no end_time, so the crossing counts.
  EXPECT_EQ(
      message_of(doc(R"("dimension": 2, "objects_are": "intervals", "objects": [
                {"id": 6, "motion": [[0], [100, -1]]}])")),
      "bad.json: $.objects[0]: interval 6 turns inside out at t=100.0 (left end passes right end)");
  // A gap 1e6 - t + 2.4e-7 t^2 that is negative only between its roots 1.666...e6 and 2.5e6.
  const std::string message =
      message_of(doc(R"("dimension": 2, "objects_are": "intervals", "objects": [
                {"id": 6, "motion": [[0], [1000000, -1, 2.4e-7]]}])"));
  EXPECT_EQ(message.substr(0, 47), "bad.json: $.objects[0]: interval 6 turns inside") << message;
}

void expect_identical(const Scenario& a, const Scenario& b) {
  EXPECT_EQ(a, b);
  // operator== cannot see the sign of zero: compare the texts, which keep it.
  EXPECT_EQ(write_scenario(a), write_scenario(b));
}

TEST(ScenarioJson, RoundTrip) {
  const std::vector<std::string> texts = {
      std::string(
          R"({"format": "kinetic-scenario/1", "dimension": 2, "start_time": 0.0, "end_time": 10.0,
        "objects": [{"id": 7, "motion": [[1.0, 0.5], [2.0, -1.0, 0.25]]},
                    {"id": 8, "motion": [[0.0, 1.0], [3.0]], "origin": 2.0}],
        "timeline": [
          {"time": 1.25, "op": "query", "query": {"type": "range", "box": [[0, 1], [0, 2]]}},
          {"time": 2.0, "op": "update", "id": 7, "motion": [[1.5, -0.5], [0.0, 1.0]], "origin": 2.0},
          {"time": 3.0, "op": "insert", "id": 99, "motion": [[0.0], [0.0, 2.0]]},
          {"time": 4.0, "op": "remove", "id": 8}]})"),
      doc(R"("dimension": 2, "start_time": -0.0, "objects": [
          {"id": 1, "motion": [[0.1, 1e-300, -0.0, 5e-324], [1.7976931348623157e308, -2.2250738585072014e-308]],
           "origin": -0.0},
          {"id": 2, "motion": [[0.30000000000000004], [123456789012345680000, 1e21, 0.3]], "origin": 1e-7}],
        "timeline": [
          {"time": 0.1, "op": "query", "query": {"type": "sorted", "axis": 1}},
          {"time": 0.1, "op": "query", "query": {"type": "max"}},
          {"time": 0.2, "op": "query", "query": {"type": "min", "axis": 1}},
          {"time": 0.3, "op": "query", "query": {"type": "extent"}},
          {"time": 0.4, "op": "query", "query": {"type": "nearest", "point": [0.1, -0.0], "eps": 0.01}},
          {"time": 0.5, "op": "query", "query": {"type": "farthest", "point": [1, 2]}},
          {"time": 0.6, "op": "query", "query": {"type": "approx_range",
                                                   "shape": {"disk": {"center": [0.5, 0.5], "radius": 0.1}}}},
          {"time": 0.7, "op": "query", "query": {"type": "approx_range", "eps": 0.25,
                                                   "shape": {"polygon": [[0, 0], [1, 0], [0.5, 0.7]]}}},
          {"time": 0.8, "op": "query", "query": {"type": "hull"}},
          {"time": 0.9, "op": "query", "query": {"type": "closest_pair"}},
          {"time": 1.0, "op": "query", "query": {"type": "colliding_pairs"}},
          {"time": 1.1, "op": "query", "query": {"type": "colliding_pairs"}}])"),
      doc(R"("dimension": 2, "objects_are": "intervals", "start_time": 1.5, "end_time": 1e300, "objects": [
          {"id": 3, "motion": [[0, 1], [1, 1]], "origin": 1.5}],
        "timeline": [{"time": 2.5, "op": "query", "query": {"type": "stab", "x": -0.0}},
                     {"time": 1e299, "op": "remove", "id": 3}])"),
      doc(R"("dimension": 1, "objects": [])"),
      doc(R"("dimension": 3, "objects_are": "boxes", "end_time": 5, "objects": [
          {"id": 4, "motion": [[0, 1], [0], [2, 0, -4.9]], "half_extents": [0.5, 0, 1e-300]},
          {"id": 5, "motion": [[1], [1], [1]], "origin": 1, "half_extents": [-0.0, 2, 3]}],
        "timeline": [{"time": 1, "op": "query", "query": {"type": "colliding_pairs"}},
                     {"time": 2, "op": "update", "id": 4, "motion": [[2, -1], [0], [0]], "origin": 2},
                     {"time": 2, "op": "update", "id": 5, "motion": [[1], [1], [1]], "half_extents": [1, 1, 1]},
                     {"time": 3, "op": "insert", "id": 6, "motion": [[0], [0], [0]], "half_extents": [0.25, 0.25, 0.25]}])"),
  };
  for (const std::string& text : texts) {
    SCOPED_TRACE(text);
    const Scenario original = parse_scenario(text, "original.json");
    const std::string written = write_scenario(original);
    const Scenario again = parse_scenario(written, "written.json");
    expect_identical(original, again);
    EXPECT_EQ(write_scenario(again), written);
  }
}

TEST(ScenarioJson, RoundTripKeepsAwkwardDoublesBitForBit) {
  Scenario s;
  s.dimension = 2;
  s.start_time = -0.0;
  const std::vector<std::vector<double>> awkward = {
      {0.1, 1e-300, -0.0, 5e-324, 1.0 / 3.0},
      {-1.7976931348623157e308, 2.5e15, 9007199254740993.0, 1e22, 0.0}};
  s.objects.push_back({1, Motion{awkward, -0.0}});
  const Scenario again = parse_scenario(write_scenario(s), "written.json");
  ASSERT_EQ(again.objects.size(), 1u);
  ASSERT_EQ(again.objects[0].motion.coordinates, awkward);
  for (std::size_t k = 0; k < awkward.size(); ++k) {
    for (std::size_t i = 0; i < awkward[k].size(); ++i) {
      const double back = again.objects[0].motion.coordinates[k][i];
      EXPECT_EQ(std::memcmp(&back, &awkward[k][i], sizeof(double)), 0)
          << "motion[" << k << "][" << i << "]";
    }
  }
  EXPECT_TRUE(std::signbit(again.start_time));
  EXPECT_TRUE(std::signbit(again.objects[0].motion.origin));
}

TEST(ScenarioJson, WriteIsReadableAndDeterministic) {
  const Scenario s = load_scenario(contract_example_path());
  const std::string text = write_scenario(s);
  EXPECT_EQ(text, write_scenario(s));
  // One object or timeline entry per line.
  EXPECT_NE(text.find("\n    {\"id\": 7, \"motion\": [[1.0, 0.5], [2.0, -1.0, 0.25]]},\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("\n    {\"time\": 4.0, \"op\": \"remove\", \"id\": 8}\n"), std::string::npos)
      << text;
}

TEST(ScenarioJson, WriteRefusesNonFiniteNumbers) {
  Scenario s;
  s.start_time = std::numeric_limits<double>::infinity();
  EXPECT_THROW((void)write_scenario(s), std::invalid_argument);
}

TEST(ScenarioJson, UnreadableFile) {
  try {
    (void)load_scenario("/nonexistent/dir/none.json");
    FAIL() << "accepted a missing file";
  } catch (const ScenarioError& error) {
    EXPECT_EQ(std::string(error.what()),
              "/nonexistent/dir/none.json: cannot read: No such file or directory");
  }
  try {
    (void)load_scenario(KINETIC_TEST_DATA_DIR);
    FAIL() << "accepted a directory";
  } catch (const ScenarioError& error) {
    EXPECT_EQ(std::string(error.what()),
              std::string(KINETIC_TEST_DATA_DIR) + ": cannot read: Is a directory");
  }
}

TEST(ScenarioJson, LoadNamesTheFile) {
  const std::string path = testing::TempDir() + "scenario_json_load_names_the_file.json";
  std::FILE* file = std::fopen(path.c_str(), "wb");
  ASSERT_NE(file, nullptr);
  const std::string text = doc(R"("dimension": 1, "objects": [{"id": 1, "motion": [[-1e999]]}])");
  std::fwrite(text.data(), 1, text.size(), file);
  std::fclose(file);
  try {
    (void)load_scenario(path);
    FAIL() << "accepted an infinite coefficient";
  } catch (const ScenarioError& error) {
    EXPECT_EQ(std::string(error.what()),
              path +
                  ": $.objects[0].motion[0][0]: expected a finite number, got -1e999 (beyond the "
                  "range of a double)");
  }
  std::remove(path.c_str());
}

TEST(ScenarioJson, EnumSpellings) {
  for (const char* name : {"sorted", "max", "min", "extent", "range", "nearest", "farthest",
                           "approx_range", "stab", "hull", "closest_pair", "colliding_pairs"}) {
    const std::optional<QueryType> type = query_type_from_string(name);
    ASSERT_TRUE(type.has_value()) << name;
    EXPECT_STREQ(to_string(*type), name);
  }
  EXPECT_FALSE(query_type_from_string("Sorted").has_value());
  EXPECT_STREQ(to_string(OpKind::Insert), "insert");
  EXPECT_STREQ(to_string(ObjectsAre::Intervals), "intervals");
  EXPECT_STREQ(to_string(ObjectsAre::Boxes), "boxes");
  EXPECT_STREQ(to_string(ObjectsAre::Points), "points");
}

TEST(ScenarioJson, BoxesKeepTheirHalfExtents) {
  const Scenario s = parse_scenario(
      doc(R"("dimension": 2, "objects_are": "boxes", "objects": [
          {"id": 1, "motion": [[0, 1], [2]], "half_extents": [0.5, 0.25]}],
        "timeline": [{"time": 1, "op": "update", "id": 1, "motion": [[1], [2]]},
                     {"time": 2, "op": "update", "id": 1, "motion": [[1], [2]], "half_extents": [0, 3]},
                     {"time": 3, "op": "insert", "id": 2, "motion": [[0], [0]], "half_extents": [1, 1]}])"),
      "boxes.json");
  EXPECT_EQ(s.objects_are, ObjectsAre::Boxes);
  ASSERT_EQ(s.objects.size(), 1u);
  EXPECT_EQ(s.objects[0].half_extents, (std::vector<double>{0.5, 0.25}));
  ASSERT_EQ(s.timeline.size(), 3u);
  EXPECT_TRUE(s.timeline[0].half_extents.empty());  // an update keeping the box's extents
  EXPECT_EQ(s.timeline[1].half_extents, (std::vector<double>{0.0, 3.0}));
  EXPECT_EQ(s.timeline[2].half_extents, (std::vector<double>{1.0, 1.0}));
}

}  // namespace
}  // namespace kinetic::scenario
