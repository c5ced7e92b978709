// `kinetic run --structure delaunay` and `--structure closest-pair` (the closest pair from
// cones): the `delaunay`, `closest_pair` and `nearest` answers equal the brute-force oracle
// replayed over the same timeline under the exact scheduler, and for `delaunay` under the robust
// one the oracle's at the grid point at or before each query (random lines with inserts, removes
// and flight-plan updates; an integer grid queried at the integer times where points are
// co-circular, collinear and coincide); the runner's test mode validates after every event;
// `--events` lists the flips and the changes of the pair; for `delaunay` the classic scheduler,
// motions above degree 2 (above 1 under the robust scheduler, the default), other dimensions
// and other query types are refused with status 2 and a message naming why; `closest-pair` runs
// under all three schedulers.

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "kinetic/core/motion_table.hpp"
#include "kinetic/oracle/oracle.hpp"
#include "kinetic/run/runner.hpp"
#include "kinetic/scenario/scenario_json.hpp"
#include "support/cli.hpp"
#include "support/grid.hpp"
#include "support/replay.hpp"
#include "support/scenario_runs.hpp"

namespace {

using nlohmann::json;
using Outcome = kinetic::test::CliOutcome;
using kinetic::test::read_file;
using kinetic::test::write_file;

const kinetic::test::CliScratch scratch{"kinetic_cli_delaunay_"};

using kinetic::test::query_states;
using kinetic::test::QueryState;

/// The oracle's answer to a query at `time`, as the runner writes it.
json oracle_answer(const QueryState& q, kinetic::Time time) {
  const kinetic::MotionTable& t = *q.table;
  switch (q.query.type) {
    case kinetic::scenario::QueryType::Delaunay: {
      json out = json::array();
      for (const auto& tri : kinetic::oracle::delaunay_at(t, time))
        out.push_back(json::array({t.id(tri[0]), t.id(tri[1]), t.id(tri[2])}));
      return out;
    }
    case kinetic::scenario::QueryType::ClosestPair: {
      const auto p = kinetic::oracle::closest_pair_at(t, time);
      return p ? json::array({t.id((*p)[0]), t.id((*p)[1])}) : json(nullptr);
    }
    default: {
      const auto i =
          kinetic::oracle::exact_nearest_at(t, {q.query.point[0], q.query.point[1]}, time);
      return i ? json(t.id(*i)) : json(nullptr);
    }
  }
}

/// n points on a small integer grid with integer velocities; the three query types at every
/// half-integer time in (0, 5].
json integer_grid(std::uint64_t seed, int n, bool closest_pair_only = false) {
  std::mt19937_64 rng(seed);
  json s = kinetic::test::scenario_json(2, 5.0);
  kinetic::test::add_integer_grid_points(s, rng, n, 1);
  s["timeline"] = json::array();
  for (int k = 1; k <= 10; ++k) {
    if (!closest_pair_only) {
      s["timeline"].push_back(
          {{"time", 0.5 * k}, {"op", "query"}, {"query", {{"type", "delaunay"}}}});
    }
    s["timeline"].push_back(
        {{"time", 0.5 * k}, {"op", "query"}, {"query", {{"type", "closest_pair"}}}});
    if (!closest_pair_only) {
      s["timeline"].push_back({{"time", 0.5 * k},
                               {"op", "query"},
                               {"query", {{"type", "nearest"}, {"point", {1.0 * k, 2.0}}}}});
    }
  }
  return s;
}

/// The run's answers equal the oracle's: at the query's time (exact scheduler), or at the grid
/// point at or before it (`robust_eps` > 0: the robust scheduler at that precision, whose
/// triangulation is exact there).
void expect_oracle_answers(const std::string& path, std::size_t min_queries,
                           const std::string& structure = "delaunay", double robust_eps = 0.0) {
  const std::vector<QueryState> states = query_states(kinetic::scenario::load_scenario(path));
  ASSERT_GE(states.size(), min_queries);
  const std::string stats = scratch.path("stats.json");
  std::ostringstream scheduler;
  scheduler.precision(17);
  if (robust_eps > 0.0) {
    scheduler << "robust --eps " << robust_eps;
  } else {
    scheduler << "exact";
  }
  const Outcome o = scratch.run("run " + path + " --structure " + structure + " --scheduler " +
                                    scheduler.str() + " --stats " + stats,
                                "run");
  ASSERT_EQ(o.status, 0) << o.err;
  const std::vector<json> answers = kinetic::test::json_lines(o.out);
  ASSERT_EQ(answers.size(), states.size()) << path;
  for (std::size_t k = 0; k < answers.size(); ++k) {
    const json& a = answers[k];
    const kinetic::Time at = robust_eps > 0.0
                                 ? kinetic::test::grid_point_before(states[k].time, robust_eps)
                                 : states[k].time;
    EXPECT_EQ(a["result"], oracle_answer(states[k], at))
        << path << " (--scheduler " << scheduler.str() << "): " << a["type"]
        << " at t = " << a["time"];
  }
  const json st = json::parse(read_file(stats));
  EXPECT_EQ(st["structure"], structure);
  EXPECT_GT(st["events"]["external"].get<std::uint64_t>(), 0u) << path;
}

/// Runs the grid scenario on `structure` in the runner's test mode (validate() after every
/// event), then through the CLI with --events; returns the events' lines.
std::vector<json> test_mode_events(const std::string& name, const json& grid_json,
                                   const std::string& structure,
                                   const std::string& scheduler = "exact") {
  const std::string grid = scratch.path(name + ".json");
  write_file(grid, grid_json.dump());
  const kinetic::scenario::Scenario s = kinetic::scenario::load_scenario(grid);
  const kinetic::SchedulerKind kind = scheduler == "robust"    ? kinetic::SchedulerKind::Robust
                                      : scheduler == "classic" ? kinetic::SchedulerKind::Classic
                                                               : kinetic::SchedulerKind::Exact;
  std::ostringstream answers;
  (void)kinetic::test::run_validating(s, structure, kind, answers, 10);
  const std::string events = scratch.path(name + "_events.jsonl");
  const Outcome o = scratch.run("run " + grid + " --structure " + structure + " --scheduler " +
                                    scheduler + " --events " + events,
                                "events");
  EXPECT_EQ(o.status, 0) << o.err;
  return kinetic::test::json_lines(read_file(events));
}

TEST(CliDelaunay, AnswersEqualTheOracle) {
  const std::string help = scratch.run("run --help", "help").out;
  EXPECT_NE(help.find("delaunay: delaunay, nearest, k_nearest, closest_pair"), std::string::npos)
      << help;
  for (const char* type : {"delaunay", "closest_pair", "nearest"}) {
    const std::string random = scratch.path(std::string("random_") + type + ".json");
    const Outcome g = scratch.run(
        "generate random-linear --dimension 2 --n 25 --seed 4 --queries 8 --query-type " +
            std::string(type) + " --updates 4 --inserts 4 --removes 4 --out " + random,
        "gen");
    ASSERT_EQ(g.status, 0) << g.err;
    expect_oracle_answers(random, 8);
    for (const double eps : {1e-9, 0.3}) expect_oracle_answers(random, 8, "delaunay", eps);
  }
  const std::string grid = scratch.path("grid.json");
  write_file(grid, integer_grid(5, 14).dump());
  expect_oracle_answers(grid, 30);
  for (const double eps : {1e-9, 0.3}) expect_oracle_answers(grid, 30, "delaunay", eps);
}

TEST(CliClosestPair, AnswersEqualTheOracle) {
  const std::string help = scratch.run("run --help", "help").out;
  EXPECT_NE(help.find("closest-pair: closest_pair\n"), std::string::npos) << help;
  const std::string random = scratch.path("cp_random.json");
  const Outcome g = scratch.run(
      "generate random-linear --dimension 2 --n 30 --seed 6 --queries 10 --query-type "
      "closest_pair --updates 5 --inserts 5 --removes 5 --out " +
          random,
      "gen");
  ASSERT_EQ(g.status, 0) << g.err;
  expect_oracle_answers(random, 10, "closest-pair");
  const std::string grid = scratch.path("cp_grid.json");
  write_file(grid, integer_grid(7, 14, true).dump());
  expect_oracle_answers(grid, 10, "closest-pair");
}

TEST(CliClosestPair, EverySchedulerValidatesEveryEventAndLogsPairChanges) {
  // Exact, robust (the default) and classic: the runner's test mode validates every event (each
  // candidate the first of its cone, by brute force); --events lists the changes of the pair.
  for (const char* scheduler : {"exact", "robust", "classic"}) {
    SCOPED_TRACE(scheduler);
    std::size_t changes = 0;
    for (const json& e : test_mode_events(std::string("cp_grid_testmode_") + scheduler,
                                          integer_grid(11, 12, true), "closest-pair", scheduler)) {
      EXPECT_EQ(e["kind"], "pair_change") << e;
      ++changes;
      ASSERT_EQ(e["ids"].size(), 2u) << e;
      EXPECT_LT(e["ids"][0].get<int>(), e["ids"][1].get<int>()) << e;
    }
    EXPECT_GT(changes, 0u);
  }
  // Without --scheduler: robust, and the answers of a run away from events are the oracle's.
  const std::string grid = scratch.path("cp_grid_testmode_exact.json");
  const Outcome robust = scratch.run("run " + grid + " --structure closest-pair", "default");
  EXPECT_EQ(robust.status, 0) << robust.err;
  EXPECT_EQ(std::count(robust.out.begin(), robust.out.end(), '\n'), 10) << robust.out;
  // Triangulation queries are the `delaunay` structure's.
  const std::string mixed = scratch.path("cp_mixed.json");
  write_file(mixed, integer_grid(3, 6).dump());
  const Outcome refused = scratch.run("run " + mixed + " --structure closest-pair", "mixed");
  EXPECT_EQ(refused.status, 2);
  EXPECT_NE(refused.err.find("delaunay"), std::string::npos) << refused.err;
}

TEST(CliDelaunay, RunnerTestModeValidatesEveryEventAndLogsFlips) {
  for (const char* scheduler : {"exact", "robust"}) {
    SCOPED_TRACE(scheduler);
    std::size_t flips = 0;
    for (const json& e : test_mode_events(std::string("grid_testmode_") + scheduler,
                                          integer_grid(9, 12), "delaunay", scheduler)) {
      const std::string kind = e["kind"];
      EXPECT_TRUE(kind == "flip" || kind == "inversion") << e;
      flips += kind == "flip";
      for (const auto& id : e["ids"]) EXPECT_LT(id.get<int>(), 12) << e;
    }
    EXPECT_GT(flips, 0u);
  }
}

TEST(CliDelaunay, SchedulersDegreesDimensionsAndQueriesAreRefused) {
  const std::string plane = scratch.path("plane.json");
  ASSERT_EQ(scratch
                .run("generate random-linear --dimension 2 --n 10 --queries 2 --query-type "
                     "delaunay --out " +
                         plane,
                     "gen2")
                .status,
            0);
  const Outcome classic =
      scratch.run("run " + plane + " --structure delaunay --scheduler classic", "classic");
  EXPECT_EQ(classic.status, 2);
  EXPECT_NE(classic.err.find("takes --scheduler robust, exact"), std::string::npos) << classic.err;
  const Outcome def = scratch.run(
      "run " + plane + " --structure delaunay --stats " + scratch.path("default_stats.json"),
      "default");
  EXPECT_EQ(def.status, 0) << "the default scheduler is robust: " << def.err;
  EXPECT_EQ(json::parse(read_file(scratch.path("default_stats.json")))["scheduler"], "robust");
  json parabola = json::parse(read_file(plane));
  parabola["objects"][2]["motion"][1] = json::array({0.0, 1.0, 0.5});
  const std::string parabola_path = scratch.path("parabola.json");
  write_file(parabola_path, parabola.dump());
  // Robust takes points on lines only: asked for, parabolas are refused naming the motion; not
  // asked for, the structure runs them on the scheduler it takes for them (exact), never a
  // refusal for a missing option, with the same answers as --scheduler exact.
  const Outcome p =
      scratch.run("run " + parabola_path + " --structure delaunay --scheduler robust", "parabola");
  EXPECT_EQ(p.status, 2);
  EXPECT_NE(p.err.find("degree <= 1 under --scheduler robust"), std::string::npos) << p.err;
  EXPECT_NE(p.err.find("$.objects[2]"), std::string::npos) << p.err;
  const Outcome p_default = scratch.run("run " + parabola_path + " --structure delaunay --stats " +
                                            scratch.path("p_default_stats.json"),
                                        "p_default");
  EXPECT_EQ(p_default.status, 0) << p_default.err;
  EXPECT_EQ(json::parse(read_file(scratch.path("p_default_stats.json")))["scheduler"], "exact");
  const Outcome p_exact =
      scratch.run("run " + parabola_path + " --structure delaunay --scheduler exact", "p_exact");
  EXPECT_EQ(p_exact.status, 0);
  EXPECT_EQ(p_default.out, p_exact.out);
  EXPECT_FALSE(p_exact.out.empty());
  const Outcome p_eps =
      scratch.run("run " + parabola_path + " --structure delaunay --eps 1e-6", "p_eps");
  EXPECT_EQ(p_eps.status, 2);
  EXPECT_NE(p_eps.err.find("runs this scenario under exact"), std::string::npos) << p_eps.err;
  const std::string line = scratch.path("line.json");
  ASSERT_EQ(scratch.run("generate random-linear --n 10 --out " + line, "gen1").status, 0);
  const Outcome d = scratch.run("run " + line + " --structure delaunay --scheduler exact", "1d");
  EXPECT_EQ(d.status, 2);
  EXPECT_NE(d.err.find("$.dimension"), std::string::npos) << d.err;
  json cubic = json::parse(read_file(plane));
  cubic["objects"][3]["motion"][0] = json::array({0.0, 1.0, 0.0, 1.0});
  const std::string cubic_path = scratch.path("cubic.json");
  write_file(cubic_path, cubic.dump());
  const Outcome c =
      scratch.run("run " + cubic_path + " --structure delaunay --scheduler exact", "cubic");
  EXPECT_EQ(c.status, 2);
  EXPECT_NE(c.err.find("degree <= 2"), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("$.objects[3]"), std::string::npos) << c.err;
  json hull = json::parse(read_file(plane));
  hull["timeline"] = json::array({{{"time", 0.5}, {"op", "query"}, {"query", {{"type", "hull"}}}}});
  const std::string hull_path = scratch.path("hullq.json");
  write_file(hull_path, hull.dump());
  const Outcome h =
      scratch.run("run " + hull_path + " --structure delaunay --scheduler exact", "hullq");
  EXPECT_EQ(h.status, 2);
  EXPECT_NE(h.err.find("hull"), std::string::npos) << h.err;
}

}  // namespace

namespace {

/// Splits a CSV line at commas.
std::vector<std::string> cells(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, ',')) out.push_back(cell);
  return out;
}

// `kinetic experiment delaunay`: the exact run and a robust one per eps, its table and CSV; the
// robust flips' RMS delay about w / sqrt(3), the exact run Delaunay at every sample, the error
// growing from none at a fine grid; bad options refused.
TEST(CliDelaunay, ExperimentReportsDelaysAndErrorAgainstEps) {
  const std::string dir = scratch.path("experiment_delaunay");
  const Outcome o = scratch.run("experiment delaunay --n 80 --eps 0.2,1e-9 --no-plots --out " + dir,
                                "exp_delaunay");
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_NE(o.out.find("Kinetic Delaunay triangulation on random-linear 2-D, n = 80"),
            std::string::npos)
      << o.out;
  for (const char* run : {"\nexact ", "\nrobust eps=2e-01 ", "\nrobust eps=1e-09 "})
    EXPECT_NE(o.out.find(run), std::string::npos) << run << "\n" << o.out;
  std::istringstream csv(read_file(dir + "/delaunay_runs.csv"));
  std::string line;
  ASSERT_TRUE(std::getline(csv, line));
  const std::vector<std::string> header = cells(line);
  const auto column = [&](const char* name) {
    return static_cast<std::size_t>(std::find(header.begin(), header.end(), name) - header.begin());
  };
  std::vector<std::vector<std::string>> rows;
  while (std::getline(csv, line)) rows.push_back(cells(line));
  ASSERT_EQ(rows.size(), 3u);
  const std::size_t wrong = column("wrong_fraction"), delay = column("delay_max"),
                    grid = column("grid"), delayed = column("delayed"), flips = column("flips");
  ASSERT_LT(flips, header.size());
  EXPECT_EQ(rows[0][column("scheduler")], "exact");
  EXPECT_EQ(std::stod(rows[0][wrong]), 0.0);  // the exact triangulation is Delaunay at every sample
  for (std::size_t k = 1; k < 3; ++k) {
    EXPECT_EQ(rows[k][column("scheduler")], "robust");
    EXPECT_GT(std::stoull(rows[k][delayed]), 100u);
    EXPECT_GT(std::stod(rows[k][delay]), 0.0);
  }
  // Roots spread over their cells: the RMS delay is about w / sqrt(3) = 0.577 w.
  const double rms = std::stod(rows[2][column("delay_rms")]), w = std::stod(rows[2][grid]);
  EXPECT_GT(rms, 0.45 * w);
  EXPECT_LT(rms, 0.70 * w);
  EXPECT_GT(std::stod(rows[1][wrong]), 0.0) << "eps 0.2: wrong at some samples";
  EXPECT_EQ(std::stod(rows[2][wrong]), 0.0) << "eps 1e-9: Delaunay at every sample";
  EXPECT_EQ(rows[2][flips], rows[0][flips]) << "eps 1e-9 flips as the exact scheduler does";
  EXPECT_EQ(scratch.run("experiment delaunay --n 2 --no-plots", "exp_dt_n").status, 2);
  EXPECT_EQ(scratch.run("experiment delaunay --eps 0 --no-plots", "exp_dt_eps").status, 2);
}

}  // namespace
