#pragma once
// Test support for the runner's and the program's tests: scenario files written as JSON, the
// range answers of a scenario by brute force, runs in the runner's test mode and JSON-lines
// output read back. Header-only, tests only.

#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <ostream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "kinetic/core/polynomial.hpp"
#include "kinetic/core/predicates.hpp"
#include "kinetic/run/runner.hpp"
#include "kinetic/scenario/scenario.hpp"
#include "support/cli.hpp"

namespace kinetic::test {

/// A scenario's JSON without objects yet: its dimension, what the objects are (points when
/// `objects_are` is empty) and its time span [0, end_time].
inline nlohmann::json scenario_json(int dimension, double end_time,
                                    const std::string& objects_are = "") {
  nlohmann::json s;
  s["format"] = "kinetic-scenario/1";
  s["dimension"] = dimension;
  if (!objects_are.empty()) s["objects_are"] = objects_are;
  s["start_time"] = 0.0;
  s["end_time"] = end_time;
  s["objects"] = nlohmann::json::array();
  return s;
}

/// Adds points 0 .. n-1 of the plane to the scenario's objects: on a small integer grid
/// ([0, 4]^2), with integer velocities in [-speed, speed]^2 (drawn from rng).
inline void add_integer_grid_points(nlohmann::json& s, std::mt19937_64& rng, int n, int speed) {
  const auto small = [&](int m, int shift) {
    return static_cast<double>(static_cast<int>(rng() % static_cast<unsigned>(m)) - shift);
  };
  for (int i = 0; i < n; ++i) {
    const double x = small(5, 0), y = small(5, 0), vx = small(2 * speed + 1, speed),
                 vy = small(2 * speed + 1, speed);
    s["objects"].push_back({{"id", i},
                            {"motion", nlohmann::json::array({nlohmann::json::array({x, vx}),
                                                              nlohmann::json::array({y, vy})})}});
  }
}

/// The lines of a JSON-lines text, each parsed.
inline std::vector<nlohmann::json> json_lines(const std::string& text) {
  std::istringstream lines(text);
  std::string line;
  std::vector<nlohmann::json> out;
  while (std::getline(lines, line)) out.push_back(nlohmann::json::parse(line));
  return out;
}

/// Whether a point moving by `m` lies in the closed box at t (its first `dimension` axes),
/// comparing its coordinates with the box's ends exactly.
inline bool exactly_inside(const scenario::Motion& m, const Box& box, int dimension, Time t) {
  for (int a = 0; a < dimension; ++a) {
    const auto p = MotionPolynomial::from(m.coordinates[static_cast<std::size_t>(a)], m.origin);
    const auto& b = box[static_cast<std::size_t>(a)];
    if (compare_at(p, MotionPolynomial::constant(b[0]), t) < 0 ||
        compare_at(p, MotionPolynomial::constant(b[1]), t) > 0)
      return false;
  }
  return true;
}

/// One line of `kinetic run`'s answers: {"time": t, "type": type, "result": result}.
inline std::string answer_line(double time, const char* type, const nlohmann::json& result) {
  nlohmann::ordered_json line;
  line["time"] = time;
  line["type"] = type;
  line["result"] = result;
  return line.dump() + "\n";
}

/// What the program writes for a scenario's range queries, by brute force: its timeline
/// replayed, each alive object tested against the query's box (exactly_inside()).
inline std::string range_answers_by_brute_force(const scenario::Scenario& s) {
  using scenario::OpKind;
  std::map<scenario::ObjectId, scenario::Motion> alive;
  for (const auto& o : s.objects) alive[o.id] = o.motion;
  std::string expected;
  for (const auto& op : s.timeline) {
    if (op.op == OpKind::Remove) alive.erase(op.id);
    if (op.op == OpKind::Insert || op.op == OpKind::Update) alive[op.id] = op.motion;
    if (op.op != OpKind::Query) continue;
    nlohmann::json ids = nlohmann::json::array();
    for (const auto& [id, m] : alive) {
      if (exactly_inside(m, op.query.box, s.dimension, op.time)) ids.push_back(id);
    }
    expected += answer_line(op.time, "range", ids);
  }
  return expected;
}

/// Writes to `path` a scenario of n random points on lines in dimension d (`kinetic generate
/// random-linear`) with `queries` range queries and `changes` flight-plan updates, inserts and
/// removes each; `tag` names the program's output files.
inline void generate_range_scenario(const CliScratch& scratch, const std::string& path, int n,
                                    int d, int queries, int changes, int seed,
                                    const std::string& tag) {
  const std::string c = std::to_string(changes);
  std::string args = "generate random-linear --n " + std::to_string(n);
  args += " --dimension " + std::to_string(d);
  args += " --queries " + std::to_string(queries) + " --query-type range";
  args += " --updates " + c + " --inserts " + c + " --removes " + c;
  args += " --seed " + std::to_string(seed) + " --out " + path;
  const CliOutcome g = scratch.run(args, tag);
  ASSERT_EQ(g.status, 0) << g.err;
}

/// Runs the scenario on `structure` under `kind` in the runner's test mode (validate() after
/// every event), its answers written to `answers`; it must complete, after more than
/// `more_events_than` events. `where` names the run in a failure message.
inline run::RunResult run_validating(const scenario::Scenario& s, const std::string& structure,
                                     SchedulerKind kind, std::ostream& answers,
                                     std::uint64_t more_events_than,
                                     const std::string& where = "") {
  run::RunOptions options;
  options.structure = structure;
  options.scheduler = kind;
  options.validate_every_event = true;
  run::check_runnable(s, options, "generated.json");
  const run::RunResult r = run::run(s, options, answers);
  EXPECT_EQ(r.outcome, run::RunOutcome::Completed) << where << r.message;
  EXPECT_GT(r.stats.counters.events(), more_events_than) << where;
  return r;
}

}  // namespace kinetic::test
