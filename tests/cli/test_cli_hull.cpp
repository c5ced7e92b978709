// `kinetic run --structure hull`: hull answers equal the exact oracle (Andrew's monotone chain on
// exactly evaluated positions) replayed over the same timeline, under both schedulers, on the
// circle dataset with inserts, removes and flight-plan updates and on an integer grid queried at
// the integer times where many points are collinear or coincide; the runner's test mode validates
// after every event; other dimensions, motions above degree 3 and other query types are refused
// with status 2 and a message naming where.

#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/predicates.hpp"
#include "kinetic/oracle/oracle.hpp"
#include "kinetic/run/runner.hpp"
#include "kinetic/scenario/scenario_json.hpp"
#include "support/cli.hpp"
#include "support/replay.hpp"
#include "support/scenario_runs.hpp"

namespace {

using kinetic::scenario::ObjectId;
using nlohmann::json;
using Outcome = kinetic::test::CliOutcome;
using kinetic::test::read_file;
using kinetic::test::write_file;

const kinetic::test::CliScratch scratch{"kinetic_cli_hull_"};

using kinetic::test::query_states;
using kinetic::test::QueryState;

/// The oracle's hull at a query (hull_at() at its time), in ids.
std::vector<ObjectId> oracle_hull(const QueryState& q) {
  std::vector<ObjectId> ids;
  for (const std::uint32_t i : kinetic::oracle::hull_at(*q.table, q.time))
    ids.push_back(q.table->id(i));
  return ids;
}

/// n points on a small integer grid with integer velocities, hull queries at every integer time
/// in [1, 6] (where points meet and line up) and halfway between.
json integer_grid(std::uint64_t seed, int n) {
  std::mt19937_64 rng(seed);
  json s = kinetic::test::scenario_json(2, 6.0);
  kinetic::test::add_integer_grid_points(s, rng, n, 2);
  s["timeline"] = json::array();
  for (int k = 1; k <= 12; ++k) {
    s["timeline"].push_back({{"time", 0.5 * k}, {"op", "query"}, {"query", {{"type", "hull"}}}});
  }
  return s;
}

/// Runs the scenario at `path` through the CLI under both schedulers; every answer must equal
/// the oracle's (of points at one position at a vertex, the smallest id).
void expect_oracle_answers(const std::string& path, std::size_t min_queries) {
  const std::vector<QueryState> states = query_states(kinetic::scenario::load_scenario(path));
  std::vector<std::vector<ObjectId>> expected;
  for (const QueryState& q : states) expected.push_back(oracle_hull(q));
  ASSERT_GE(expected.size(), min_queries);
  for (const char* sched : {"robust", "classic"}) {
    const std::string stats = scratch.path("stats.json");
    const Outcome o = scratch.run(
        "run " + path + " --structure hull --scheduler " + sched + " --stats " + stats, "run");
    ASSERT_EQ(o.status, 0) << o.err;
    const std::vector<json> answers = kinetic::test::json_lines(o.out);
    ASSERT_EQ(answers.size(), expected.size()) << path << " " << sched;
    for (std::size_t k = 0; k < answers.size(); ++k) {
      const json& a = answers[k];
      EXPECT_EQ(a["type"], "hull");
      const auto got = a["result"].get<std::vector<ObjectId>>();
      ASSERT_EQ(got.size(), expected[k].size()) << path << " " << sched << " at t = " << a["time"];
      for (std::size_t j = 0; j < got.size(); ++j) {
        if (got[j] == expected[k][j]) continue;
        ADD_FAILURE() << path << " " << sched << " at t = " << a["time"] << ": vertex " << j
                      << " is " << got[j] << ", the oracle says " << expected[k][j];
      }
    }
    const json st = json::parse(read_file(stats));
    EXPECT_EQ(st["structure"], "hull");
    EXPECT_GT(st["events"]["external"].get<std::uint64_t>(), 0u) << path << " " << sched;
    EXPECT_EQ(st["structure_counters"]["queries"].get<std::uint64_t>(), expected.size());
  }
}

TEST(CliHull, HullAnswersEqualTheOracle) {
  const std::string help = scratch.run("run --help", "help").out;
  EXPECT_NE(help.find("hull: hull"), std::string::npos) << help;
  const std::string circle = scratch.path("circle.json");
  const Outcome g = scratch.run(
      "generate circle --n 80 --seed 3 --queries 15 --query-type hull "
      "--updates 6 --inserts 6 --removes 6 --out " +
          circle,
      "gen");
  ASSERT_EQ(g.status, 0) << g.err;
  expect_oracle_answers(circle, 15);
  const std::string grid = scratch.path("grid.json");
  write_file(grid, integer_grid(5, 30).dump());
  expect_oracle_answers(grid, 12);
}

TEST(CliHull, RunnerTestModeValidatesEveryEvent) {
  const std::string circle = scratch.path("circle_testmode.json");
  ASSERT_EQ(scratch
                .run("generate circle --n 60 --seed 8 --queries 4 --query-type hull --updates 4 "
                     "--inserts 4 --removes 4 --out " +
                         circle,
                     "gen2")
                .status,
            0);
  const std::string grid = scratch.path("grid_testmode.json");
  write_file(grid, integer_grid(9, 25).dump());
  for (const std::string& path : {circle, grid}) {
    const kinetic::scenario::Scenario s = kinetic::scenario::load_scenario(path);
    for (const auto kind : {kinetic::SchedulerKind::Robust, kinetic::SchedulerKind::Classic}) {
      std::ostringstream answers;
      (void)kinetic::test::run_validating(s, "hull", kind, answers, 20, path + ": ");
    }
  }
}

TEST(CliHull, OtherDimensionsDegreesAndQueriesAreRefused) {
  const std::string line = scratch.path("line.json");
  ASSERT_EQ(scratch.run("generate random-linear --n 10 --out " + line, "gen_1d").status, 0);
  const Outcome d = scratch.run("run " + line + " --structure hull", "1d");
  EXPECT_EQ(d.status, 2);
  EXPECT_NE(d.err.find("$.dimension: structure hull supports dimension 2 only"), std::string::npos)
      << d.err;

  json s = integer_grid(1, 6);
  s["objects"][3]["motion"][1] = json::array({0.0, 0.0, 0.0, 0.0, 1.0});
  const std::string quartic = scratch.path("quartic.json");
  write_file(quartic, s.dump());
  const Outcome q = scratch.run("run " + quartic + " --structure hull", "quartic");
  EXPECT_EQ(q.status, 2);
  EXPECT_NE(q.err.find("$.objects[3].motion: structure hull takes motions of degree <= 3"),
            std::string::npos)
      << q.err;

  s = integer_grid(1, 6);
  s["timeline"].push_back(
      {{"time", 6.0},
       {"op", "update"},
       {"id", 2},
       {"motion", json::array({json::array({0.0, 0.0, 0.0, 0.0, 1.0}), json::array({1.0})})}});
  const std::string update = scratch.path("update.json");
  write_file(update, s.dump());
  const Outcome u = scratch.run("run " + update + " --structure hull", "update");
  EXPECT_EQ(u.status, 2);
  EXPECT_NE(u.err.find("$.timeline[12].motion: structure hull takes motions of degree <= 3"),
            std::string::npos)
      << u.err;

  s = integer_grid(1, 6);
  s["timeline"] = json::array({{{"time", 1.0}, {"op", "query"}, {"query", {{"type", "sorted"}}}}});
  const std::string sorted = scratch.path("sorted.json");
  write_file(sorted, s.dump());
  const Outcome o = scratch.run("run " + sorted + " --structure hull", "sorted");
  EXPECT_EQ(o.status, 2);
  EXPECT_NE(o.err.find("structure hull answers hull"), std::string::npos) << o.err;
}

}  // namespace
