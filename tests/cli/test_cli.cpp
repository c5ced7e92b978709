// The command line as users and scripts see it: exit statuses, one-line errors naming the file and
// the JSON path, answers as JSON lines, byte-identical reruns.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "kinetic/core/predicates.hpp"
#include "kinetic/scenario/scenario_json.hpp"
#include "support/cli.hpp"
#include "support/scenario_runs.hpp"

namespace {

using Outcome = kinetic::test::CliOutcome;
using kinetic::test::read_file;
using kinetic::test::write_file;

const kinetic::test::CliScratch scratch{"kinetic_cli_"};

const char* kGood = R"({
  "format": "kinetic-scenario/1", "dimension": 1, "start_time": 0.0, "end_time": 4.0,
  "objects": [
    {"id": 7, "motion": [[0.0, 1.0]]},
    {"id": 8, "motion": [[2.0, -1.0]]},
    {"id": 9, "motion": [[1.0, 0.0, 0.25]], "origin": 1.0}
  ],
  "timeline": [
    {"time": 0.5, "op": "query", "query": {"type": "sorted"}},
    {"time": 2.0, "op": "query", "query": {"type": "max"}},
    {"time": 2.0, "op": "update", "id": 7, "motion": [[5.0, 0.0]], "origin": 2.0},
    {"time": 2.5, "op": "insert", "id": 3, "motion": [[-1.0]]},
    {"time": 3.0, "op": "remove", "id": 8},
    {"time": 3.5, "op": "query", "query": {"type": "sorted", "axis": 0}},
    {"time": 4.0, "op": "query", "query": {"type": "min"}}
  ]
})";

TEST(Cli, RunAnswersJsonLinesInTimelineOrder) {
  const std::string path = scratch.path("good.json");
  write_file(path, kGood);
  const Outcome o = scratch.run(path + " --structure sort --scheduler classic", "good");
  // The subcommand is required: without `run` this is a usage error.
  EXPECT_EQ(o.status, 2);
  const Outcome r =
      scratch.run("run " + path + " --structure sort --scheduler classic", "good_run");
  ASSERT_EQ(r.status, 0) << r.err;
  std::istringstream lines(r.out);
  std::string line;
  std::vector<std::string> answers;
  while (std::getline(lines, line)) {
    EXPECT_TRUE(nlohmann::json::accept(line)) << line;
    answers.push_back(line);
  }
  ASSERT_EQ(answers.size(), 4u);
  // At 0.5: 7 at 0.5, 8 at 1.5, 9 at 1 + 0.0625 -> 7, 9, 8.
  EXPECT_EQ(answers[0], R"({"time":0.5,"type":"sorted","result":[7,9,8]})");
  // At 2.0 (before the update): 7 at 2, 8 at 0, 9 at 1.25 -> max 7.
  EXPECT_EQ(answers[1], R"({"time":2.0,"type":"max","result":7})");
  // At 3.5: 7 at 5, 9 at 2.5625, 3 at -1 -> 3, 9, 7.
  EXPECT_EQ(answers[2], R"({"time":3.5,"type":"sorted","result":[3,9,7]})");
  EXPECT_EQ(answers[3], R"({"time":4.0,"type":"min","result":3})");
}

TEST(Cli, StatsFileHasTheKdsMeasures) {
  const std::string path = scratch.path("stats_in.json"), stats = scratch.path("stats.json");
  write_file(path, kGood);
  const Outcome r = scratch.run("run " + path + " --structure sort --scheduler classic --stats " +
                                    stats + " --out " + scratch.path("stats_answers.jsonl"),
                                "stats");
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(read_file(stats));
  for (const char* key :
       {"events", "certificates", "root_isolation_calls", "wall_time_s", "events_per_second"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_TRUE(j["events"].contains("internal"));
  EXPECT_TRUE(j["events"].contains("external"));
  EXPECT_TRUE(j["certificates"].contains("alive_max"));
  EXPECT_TRUE(j["certificates"].contains("alive_end"));
  EXPECT_TRUE(j["certificates"].contains("per_object_max"));
  EXPECT_EQ(j["outcome"], "completed");
  // 7 and 9 cross once before the update, 9 and 8 once: both before t = 2.
  EXPECT_GE(j["events"]["processed"].get<int>(), 2);
  EXPECT_EQ(read_file(scratch.path("stats_answers.jsonl")).empty(), false);
}

TEST(Cli, TwoRunsAreByteIdentical) {
  const std::string scenario = scratch.path("det.json");
  const Outcome g = scratch.run(
      "generate parabola --n 400 --seed 5 --queries 20 --updates 30 --out " + scenario, "det_gen");
  ASSERT_EQ(g.status, 0) << g.err;
  for (const std::string scheduler : {"classic", "robust"}) {
    SCOPED_TRACE(scheduler);
    std::string first_answers, first_stats;
    for (int run = 0; run < 2; ++run) {
      const std::string stats = scratch.path("det_stats" + std::to_string(run));
      const Outcome r = scratch.run(
          "run " + scenario + " --structure sort --scheduler " + scheduler + " --stats " + stats,
          "det_run");
      ASSERT_EQ(r.status, 0) << r.err;
      nlohmann::json j = nlohmann::json::parse(read_file(stats));
      j.erase("wall_time_s");
      j.erase("events_per_second");
      j.erase("time_per_event_us");
      if (run == 0) {
        first_answers = r.out;
        first_stats = j.dump();
      } else {
        EXPECT_EQ(r.out, first_answers);
        EXPECT_EQ(j.dump(), first_stats);
      }
    }
    EXPECT_FALSE(first_answers.empty());
  }
}

TEST(Cli, RobustIsTheDefaultAndEpsIsChecked) {
  const std::string path = scratch.path("eps.json");
  write_file(path, kGood);
  const Outcome r = scratch.run("run " + path + " --structure sort --stats -", "default_sched");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("\"scheduler\": \"robust\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"eps\": 1e-09"), std::string::npos) << r.out;
  // Same answers as the classic scheduler on this simple scenario.
  const Outcome c =
      scratch.run("run " + path + " --structure sort --scheduler classic", "classic_sched");
  const Outcome rr = scratch.run("run " + path + " --structure sort --scheduler robust --eps 1e-6",
                                 "robust_sched");
  EXPECT_EQ(c.out, rr.out);
  const Outcome tiny = scratch.run("run " + path + " --structure sort --eps 1e-300", "tiny_eps");
  EXPECT_EQ(tiny.status, 2);
  EXPECT_NE(tiny.err.find("--eps"), std::string::npos) << tiny.err;
  EXPECT_EQ(scratch.run("run " + path + " --structure sort --eps -1", "neg_eps").status, 2);
  // The exact scheduler gives the same answers here too, and refuses an eps it does not use.
  const Outcome ex = scratch.run("run " + path + " --structure sort --scheduler exact", "exact");
  EXPECT_EQ(ex.status, 0) << ex.err;
  EXPECT_EQ(ex.out, c.out);
  EXPECT_EQ(scratch.run("run " + path + " --structure sort --scheduler exact --eps 1e-6", "ex_eps")
                .status,
            2);
  // Delays are measured on request; here every crossing is a simple one, so each delay is
  // below one grid cell: w = 2^-21 <= (sqrt(3) / 2) eps for eps = 1e-6.
  const std::string stats_path = scratch.path("delays_stats.json");
  const Outcome d = scratch.run(
      "run " + path + " --structure sort --eps 1e-6 --measure-delays --stats " + stats_path,
      "delays");
  ASSERT_EQ(d.status, 0) << d.err;
  const nlohmann::json stats = nlohmann::json::parse(read_file(stats_path));
  ASSERT_TRUE(stats.contains("delays")) << stats.dump();
  EXPECT_GE(stats["delays"]["measured"].get<int>(), 2);
  EXPECT_GT(stats["delays"]["max_in_eps"].get<double>(), 0.0);
  EXPECT_LE(stats["delays"]["max"].get<double>(), 0x1p-21);
}

TEST(Cli, GenerateIsDeterministicAndReadable) {
  const Outcome a = scratch.run("generate randdc --n 50 --seed 9", "gen_a");
  const Outcome b = scratch.run("generate randdc --n 50 --seed 9", "gen_b");
  const Outcome c = scratch.run("generate randdc --n 50 --seed 10", "gen_c");
  ASSERT_EQ(a.status, 0) << a.err;
  EXPECT_EQ(a.out, b.out);
  EXPECT_NE(a.out, c.out);
  EXPECT_EQ(nlohmann::json::parse(a.out)["format"], "kinetic-scenario/1");
  EXPECT_EQ(scratch.run("generate no-such-dataset --n 5", "gen_bad").status, 2);
}

TEST(Cli, HelpVersionAndUsageErrors) {
  const Outcome help = scratch.run("run --help", "help");
  EXPECT_EQ(help.status, 0);
  EXPECT_NE(help.out.find("sort: sorted, max, min"), std::string::npos) << help.out;
  const Outcome version = scratch.run("--version", "version");
  EXPECT_EQ(version.status, 0);
  EXPECT_NE(version.out.find("kinetic "), std::string::npos);
  EXPECT_EQ(scratch.run("", "none").status, 2);
  EXPECT_EQ(scratch.run("frobnicate", "unknown_cmd").status, 2);
  const std::string path = scratch.path("usage.json");
  write_file(path, kGood);
  const Outcome unknown = scratch.run("run " + path + " --structure heap", "unknown_structure");
  EXPECT_EQ(unknown.status, 2);
  EXPECT_NE(unknown.err.find("unknown structure 'heap'"), std::string::npos) << unknown.err;
  EXPECT_EQ(scratch.run("run " + path + " --structure sort --scheduler sloppy", "bad_sched").status,
            2);
  EXPECT_EQ(
      scratch.run("run " + scratch.path("missing.json") + " --structure sort", "missing").status,
      2);
  EXPECT_EQ(scratch.run("experiment nothing", "experiment").status, 2);
}

TEST(Cli, UnsupportedQueryTypeIsRefusedBeforeRunning) {
  const std::string path = scratch.path("range.json");
  write_file(path,
             R"({"format": "kinetic-scenario/1", "dimension": 1, "start_time": 0, "end_time": 1,
    "objects": [{"id": 1, "motion": [[0.0]]}],
    "timeline": [{"time": 0.5, "op": "query", "query": {"type": "sorted"}},
                 {"time": 0.75, "op": "query", "query": {"type": "range", "box": [[0, 1]]}}]})");
  const Outcome o = scratch.run("run " + path + " --structure sort --scheduler classic", "range");
  EXPECT_EQ(o.status, 2);
  EXPECT_TRUE(o.out.empty()) << "nothing is half-run: " << o.out;
  EXPECT_NE(o.err.find(path + ": $.timeline[1].query.type:"), std::string::npos) << o.err;
}

/// Malformed scenarios: one line on standard error naming the file and the JSON path; status 2;
/// nothing on standard output.
struct BadInput {
  const char* name;
  const char* text;
  const char* path;  // the JSON path the message must name
};

const BadInput kBadInputs[] = {
    {"not_json", "{ this is not json", "$"},
    {"root_array", "[1, 2]", "$"},
    {"wrong_format", R"({"format": "kinetic-scenario/2", "dimension": 1, "objects": []})",
     "$.format"},
    {"no_dimension", R"({"format": "kinetic-scenario/1", "objects": []})", "$"},
    {"dimension_zero", R"({"format": "kinetic-scenario/1", "dimension": 0, "objects": []})",
     "$.dimension"},
    {"dimension_real", R"({"format": "kinetic-scenario/1", "dimension": 1.5, "objects": []})",
     "$.dimension"},
    {"objects_are",
     R"({"format": "kinetic-scenario/1", "dimension": 1, "objects_are": "blobs", "objects": []})",
     "$.objects_are"},
    {"start_string",
     R"({"format": "kinetic-scenario/1", "dimension": 1, "start_time": "0", "objects": []})",
     "$.start_time"},
    {"end_before_start",
     R"({"format": "kinetic-scenario/1", "dimension": 1, "start_time": 5, "end_time": 1, "objects": []})",
     "$.end_time"},
    {"objects_missing", R"({"format": "kinetic-scenario/1", "dimension": 1})", "$"},
    {"id_missing",
     R"({"format": "kinetic-scenario/1", "dimension": 1, "objects": [{"motion": [[0]]}]})",
     "$.objects[0]"},
    {"id_real",
     R"({"format": "kinetic-scenario/1", "dimension": 1, "objects": [{"id": 1.5, "motion": [[0]]}]})",
     "$.objects[0].id"},
    {"duplicate_id",
     R"({"format": "kinetic-scenario/1", "dimension": 1, "objects": [{"id": 1, "motion": [[0]]}, {"id": 1, "motion": [[1]]}]})",
     "$.objects[1].id"},
    {"coordinate_count",
     R"({"format": "kinetic-scenario/1", "dimension": 2, "objects": [{"id": 1, "motion": [[0]]}]})",
     "$.objects[0].motion"},
    {"empty_coefficients",
     R"({"format": "kinetic-scenario/1", "dimension": 1, "objects": [{"id": 1, "motion": [[]]}]})",
     "$.objects[0].motion[0]"},
    {"degree_seven",
     R"({"format": "kinetic-scenario/1", "dimension": 1, "objects": [{"id": 1, "motion": [[0, 1, 2, 3, 4, 5, 6, 7]]}]})",
     "$.objects[0].motion[0]"},
    {"infinite_number",
     R"({"format": "kinetic-scenario/1", "dimension": 1, "objects": [{"id": 1, "motion": [[1e999]]}]})",
     "$.objects[0].motion[0][0]"},
    {"nan_literal",
     R"({"format": "kinetic-scenario/1", "dimension": 1, "objects": [{"id": 1, "motion": [[NaN]]}]})",
     "$"},
    {"unknown_key",
     R"({"format": "kinetic-scenario/1", "dimension": 1, "objects": [{"id": 1, "motion": [[0]], "orgin": 2}]})",
     "$.objects[0]"},
    {"unknown_op",
     R"({"format": "kinetic-scenario/1", "dimension": 1, "objects": [], "timeline": [{"time": 0, "op": "teleport"}]})",
     "$.timeline[0].op"},
    {"unknown_query",
     R"({"format": "kinetic-scenario/1", "dimension": 1, "objects": [], "timeline": [{"time": 0, "op": "query", "query": {"type": "median"}}]})",
     "$.timeline[0].query.type"},
    {"time_outside_window",
     R"({"format": "kinetic-scenario/1", "dimension": 1, "start_time": 0, "end_time": 1, "objects": [], "timeline": [{"time": 2, "op": "query", "query": {"type": "sorted"}}]})",
     "$.timeline[0].time"},
    {"update_unknown_id",
     R"({"format": "kinetic-scenario/1", "dimension": 1, "objects": [], "timeline": [{"time": 0, "op": "update", "id": 4, "motion": [[0]]}]})",
     "$.timeline[0].id"},
    {"insert_live_id",
     R"({"format": "kinetic-scenario/1", "dimension": 1, "objects": [{"id": 4, "motion": [[0]]}], "timeline": [{"time": 0, "op": "insert", "id": 4, "motion": [[0]]}]})",
     "$.timeline[0].id"},
    {"axis_out_of_range",
     R"({"format": "kinetic-scenario/1", "dimension": 1, "objects": [], "timeline": [{"time": 0, "op": "query", "query": {"type": "sorted", "axis": 1}}]})",
     "$.timeline[0].query.axis"},
};

TEST(Cli, MalformedScenariosAreRefusedWithPathAndStatus2) {
  for (const BadInput& bad : kBadInputs) {
    SCOPED_TRACE(bad.name);
    const std::string path = scratch.path(std::string("bad_") + bad.name + ".json");
    write_file(path, bad.text);
    const Outcome o =
        scratch.run("run " + path + " --structure sort --scheduler classic", bad.name);
    EXPECT_EQ(o.status, 2);
    EXPECT_TRUE(o.out.empty()) << o.out;
    EXPECT_EQ(o.err.find("kinetic: " + path + ": " + bad.path + ":"), 0u) << o.err;
    EXPECT_EQ(o.err.find('\n'), o.err.size() - 1) << "one line: " << o.err;
  }
}

}  // namespace

// `kinetic experiment sorting --quick`, the README's main job: the report's format, the robust
// bounds of Theorems 1 and 2 on every robust run, the classic scheduler's failure on the
// degenerate inputs, the CSV files, and docs/experiments.md quoting exactly this report.
TEST(Cli, ExperimentSortingQuick) {
  const std::string dir = scratch.path("experiment_sorting");
  const Outcome o =
      scratch.run("experiment sorting --quick --no-plots --out " + dir, "exp_sorting");
  ASSERT_EQ(o.status, 0) << o.err;
  const std::size_t begin = o.out.find("Table 1.");
  const std::size_t end = o.out.find("\nCSV files in ");
  ASSERT_NE(begin, std::string::npos) << o.out;
  ASSERT_NE(end, std::string::npos) << o.out;
  const std::string report = o.out.substr(begin, end - begin);

  std::istringstream lines(report);
  std::string line;
  int table_rows = 0, robust_rows = 0, classic_rows = 0, exact_rows = 0;
  enum { kTable, kRobust, kClassic, kSide } part = kTable;
  while (std::getline(lines, line)) {
    if (line.rfind("Robust runs", 0) == 0) part = kRobust;
    if (line.rfind("Classic scheduler", 0) == 0) part = kClassic;
    if (line.rfind("The three schedulers", 0) == 0) part = kSide;
    std::istringstream words(line);
    std::vector<std::string> w;
    for (std::string x; words >> x;) w.push_back(x);
    if (w.empty()) continue;
    if (part == kTable && (w[0] == "1e-06" || w[0] == "1e-07" || w[0] == "1e-08")) {
      ++table_rows;
      // eps | RMS [paper] Max [paper] for GRIDS, PARABOLA, RANDDC
      ASSERT_EQ(w.size(), 1u + 3u * 5u) << line;
      for (int d = 0; d < 3; ++d) {
        const double rms = std::stod(w[2 + 5 * d]), max = std::stod(w[4 + 5 * d]);
        EXPECT_GT(rms, 0.0) << line;
        EXPECT_LT(rms, 0.5) << "RMS delay below eps / 2: " << line;
        EXPECT_LE(rms, max) << line;
        EXPECT_LE(max, 2.0) << "max delay at most 2 eps: " << line;
        EXPECT_EQ(w[3 + 5 * d].front(), '[') << line;
      }
    }
    if (part == kRobust && (w[0] == "grids" || w[0] == "parabola" || w[0] == "randdc")) {
      ++robust_rows;
      EXPECT_EQ(w[3], "0") << "no event in the past: " << line;
      EXPECT_EQ(w[6].rfind("0/", 0), 0u) << "Theorem 1 violated: " << line;
      EXPECT_EQ(w.back(), "ok") << "Theorem 2 violated: " << line;
    }
    if (part == kClassic && (w[0] == "grids" || w[0] == "parabola")) {
      ++classic_rows;
      EXPECT_GT(std::stoull(w[3]), 0u) << "the classic scheduler misses events: " << line;
      EXPECT_GT(std::stoull(w[7]), 0u) << "and ends in a wrong order: " << line;
    }
    if (part == kSide && w.size() == 7 && w[1] == "exact") {
      // dataset exact events in-past groups max-err final-inversions: zero error, every crossing.
      ++exact_rows;
      EXPECT_EQ(w[3], "0") << "no event in the past: " << line;
      if (w[0] != "randdc") {
        EXPECT_GT(std::stoull(w[4]), 0u) << "simultaneous events: " << line;
      }
      EXPECT_EQ(w[5], "0") << "zero error: " << line;
      EXPECT_EQ(w[6], "0") << line;
    }
  }
  EXPECT_EQ(table_rows, 3);
  EXPECT_EQ(robust_rows, 9);
  EXPECT_EQ(classic_rows, 2);
  EXPECT_EQ(exact_rows, 3);
  EXPECT_NE(o.out.find("Run times on this machine"), std::string::npos) << o.out;
  for (const char* f :
       {"table1.csv", "runs.csv", "err_grids.csv", "err_parabola.csv", "err_randdc.csv"}) {
    EXPECT_FALSE(read_file(dir + "/" + f).empty()) << f;
  }
  // The plots of the main job draw every run's column (classic, robust, exact) from these CSV
  // files (with the Python the project's packages install).
  const std::string script = std::string(KINETIC_DOCS_DIR) + "/../scripts/plot_experiments.py";
  const int plotted =
      std::system(("/usr/bin/python3 '" + script + "' '" + dir + "' >/dev/null 2>&1").c_str());
  EXPECT_EQ(plotted, 0) << "scripts/plot_experiments.py failed on " << dir;
  for (const char* f : {"fig6_grids.png", "fig7_parabola.png", "fig8_randdc.png"}) {
    EXPECT_FALSE(read_file(dir + "/" + f).empty()) << f;
  }
  // The documentation shows this very report.
  const std::string doc = read_file(std::string(KINETIC_DOCS_DIR) + "/experiments.md");
  EXPECT_NE(doc.find(report), std::string::npos)
      << "docs/experiments.md does not quote the report of `kinetic experiment sorting --quick`:\n"
      << report;
}

TEST(Cli, GenerateScaleAndExperimentUsageErrors) {
  const Outcome unit = scratch.run("generate grids --n 9 --scale unit", "gen_unit");
  ASSERT_EQ(unit.status, 0) << unit.err;
  const nlohmann::json s = nlohmann::json::parse(unit.out);
  EXPECT_EQ(s["objects"][0]["motion"][0][0].get<double>(), -1.0);  // (-(k-1)) / (k-1), k = 3
  EXPECT_EQ(s["objects"][1]["motion"][0][0].get<double>(), 0.0);
  const Outcome half = scratch.run("generate grids --n 9 --scale 0.5", "gen_half");
  ASSERT_EQ(half.status, 0) << half.err;
  EXPECT_EQ(nlohmann::json::parse(half.out)["objects"][0]["motion"][0][0].get<double>(), -1.0);
  for (const char* bad : {"abc", "0", "-2", "1e999", "0.5x"}) {
    const Outcome o =
        scratch.run(std::string("generate grids --n 9 --scale ") + bad, "gen_bad_scale");
    EXPECT_EQ(o.status, 2) << bad;
    EXPECT_NE(o.err.find("scale"), std::string::npos) << o.err;
  }
  const Outcome unknown = scratch.run("experiment nope --no-plots", "exp_unknown");
  EXPECT_EQ(unknown.status, 2);
  EXPECT_NE(unknown.err.find("sorting"), std::string::npos) << unknown.err;
  EXPECT_EQ(scratch.run("experiment sorting --eps -1 --no-plots", "exp_bad_eps").status, 2);
  EXPECT_EQ(scratch.run("experiment sorting --n 1 --no-plots", "exp_bad_n").status, 2);
}

// `tournament` and `extent` answer max / min / extent like the sorted order does (the queries of a
// generated scenario are at generic times, away from every crossing), with both schedulers.
TEST(Cli, TournamentAndExtentAgreeWithSorting) {
  const std::string ext = scratch.path("extent.json");
  ASSERT_EQ(scratch
                .run("generate random-linear --n 300 --dimension 2 --queries 9 --query-type extent "
                     "--updates 20 --inserts 20 --removes 20 --out " +
                         ext,
                     "gen_extent")
                .status,
            0);
  // The same times with max / min queries on both axes, for `sort` and `tournament`.
  nlohmann::json s = nlohmann::json::parse(read_file(ext));
  nlohmann::json timeline = nlohmann::json::array();
  for (const auto& op : s["timeline"]) {
    if (op["op"] != "query") {
      timeline.push_back(op);
      continue;
    }
    for (int axis = 0; axis < 2; ++axis) {
      for (const char* type : {"min", "max"}) {
        timeline.push_back(
            {{"time", op["time"]}, {"op", "query"}, {"query", {{"type", type}, {"axis", axis}}}});
      }
    }
  }
  s["timeline"] = timeline;
  const std::string minmax = scratch.path("minmax.json");
  write_file(minmax, s.dump());
  const Outcome sorted = scratch.run("run " + minmax + " --structure sort", "mm_sort");
  ASSERT_EQ(sorted.status, 0) << sorted.err;
  for (const char* sched : {"robust", "classic"}) {
    const Outcome t =
        scratch.run("run " + minmax + " --structure tournament --scheduler " + sched, "mm_tour");
    ASSERT_EQ(t.status, 0) << t.err;
    EXPECT_EQ(t.out, sorted.out) << sched;
    const Outcome e =
        scratch.run("run " + ext + " --structure extent --scheduler " + sched, "mm_ext");
    ASSERT_EQ(e.status, 0) << e.err;
    // Each extent answer is [[min0, max0], [min1, max1]]: the four sorted answers at its time.
    std::istringstream ext_lines(e.out), sort_lines(sorted.out);
    std::string el;
    int answers = 0;
    while (std::getline(ext_lines, el)) {
      const nlohmann::json box = nlohmann::json::parse(el)["result"];
      ASSERT_EQ(box.size(), 2u);
      for (int axis = 0; axis < 2; ++axis) {
        for (int k = 0; k < 2; ++k) {
          std::string sl;
          ASSERT_TRUE(static_cast<bool>(std::getline(sort_lines, sl)));
          EXPECT_EQ(box[axis][k], nlohmann::json::parse(sl)["result"]) << el << " vs " << sl;
        }
      }
      ++answers;
    }
    EXPECT_EQ(answers, 9);
  }
  // The structures refuse queries they do not answer.
  EXPECT_EQ(scratch.run("run " + ext + " --structure tournament", "tour_extent").status, 2);
}

// `kdtree` answers range queries exactly like a brute-force scan replaying the same timeline
// (queries at generic times, away from every swap), with both schedulers, in 1 to 3 dimensions.
TEST(Cli, KdTreeRangeAnswersEqualBruteForce) {
  for (int d = 1; d <= 3; ++d) {
    const std::string path = scratch.path("kd" + std::to_string(d) + ".json");
    ASSERT_NO_FATAL_FAILURE(
        kinetic::test::generate_range_scenario(scratch, path, 400, d, 12, 15, d, "gen_kd"));
    const std::string expected =
        kinetic::test::range_answers_by_brute_force(kinetic::scenario::load_scenario(path));
    for (const char* sched : {"robust", "classic"}) {
      const std::string stats = scratch.path("kd_stats.json");
      const Outcome o = scratch.run(
          "run " + path + " --structure kdtree --scheduler " + sched + " --stats " + stats,
          "kd_run");
      ASSERT_EQ(o.status, 0) << o.err;
      EXPECT_EQ(o.out, expected) << "d " << d << " " << sched;
      // The tree's own counters: every external event is a swap of one of the sorts.
      const auto st = nlohmann::json::parse(read_file(stats));
      const auto& sc = st["structure_counters"];
      ASSERT_TRUE(sc.is_object()) << read_file(stats);
      EXPECT_EQ(sc["swaps"].get<std::uint64_t>(), st["events"]["external"].get<std::uint64_t>());
      EXPECT_LE(sc["unchanged_events"].get<std::uint64_t>(), sc["swaps"].get<std::uint64_t>());
      EXPECT_EQ(sc["queries"].get<std::uint64_t>(), 12u);
      EXPECT_GT(sc["tree_nodes"].get<std::uint64_t>(), 0u);
    }
  }
}

// `longest-side-kdtree` answers every query type it offers within its guarantee, against a
// brute-force scan replaying the same timeline: (1+eps)-nearest, (1-eps)-farthest, approx_range
// (all points inside the disk, none farther than eps * diameter outside) and exact range.
TEST(Cli, LongestSideKdTreeAnswersKeepTheirGuarantees) {
  const std::string help = scratch.run("run --help", "ls_help").out;
  EXPECT_NE(help.find("longest-side-kdtree"), std::string::npos);
  for (const char* type : {"nearest", "farthest", "approx_range", "range"}) {
    const std::string path = scratch.path(std::string("ls_") + type + ".json");
    ASSERT_EQ(scratch
                  .run(std::string("generate random-linear --n 300 --dimension 2 --queries 12 "
                                   "--query-type ") +
                           type + " --updates 5 --inserts 5 --removes 5 --seed 4 --out " + path,
                       "gen_ls")
                  .status,
              0);
    const kinetic::scenario::Scenario s = kinetic::scenario::load_scenario(path);
    for (const char* sched : {"robust", "classic"}) {
      const Outcome o = scratch.run(
          "run " + path + " --structure longest-side-kdtree --scheduler " + sched, "ls_run");
      ASSERT_EQ(o.status, 0) << o.err;
      std::istringstream lines(o.out);
      std::map<kinetic::scenario::ObjectId, kinetic::scenario::Motion> alive;
      for (const auto& obj : s.objects) alive[obj.id] = obj.motion;
      int answered = 0;
      for (const auto& op : s.timeline) {
        if (op.op == kinetic::scenario::OpKind::Remove) alive.erase(op.id);
        if (op.op == kinetic::scenario::OpKind::Insert ||
            op.op == kinetic::scenario::OpKind::Update)
          alive[op.id] = op.motion;
        if (op.op != kinetic::scenario::OpKind::Query) continue;
        std::string line;
        ASSERT_TRUE(std::getline(lines, line));
        const auto answer = nlohmann::json::parse(line);
        ASSERT_EQ(answer["type"], type);
        auto position = [&](const kinetic::scenario::Motion& m, int a) {
          return kinetic::value_at(
              kinetic::MotionPolynomial::from(m.coordinates[static_cast<std::size_t>(a)], m.origin),
              op.time);
        };
        const auto& q = op.query;
        if (q.type == kinetic::scenario::QueryType::Nearest ||
            q.type == kinetic::scenario::QueryType::Farthest) {
          double best = q.type == kinetic::scenario::QueryType::Nearest ? HUGE_VAL : 0.0;
          double got = -1.0;
          for (const auto& [id, m] : alive) {
            const double d = std::hypot(position(m, 0) - q.point[0], position(m, 1) - q.point[1]);
            best = q.type == kinetic::scenario::QueryType::Nearest ? std::min(best, d)
                                                                   : std::max(best, d);
            if (answer["result"] == id) got = d;
          }
          ASSERT_GE(got, 0.0) << line;
          if (q.type == kinetic::scenario::QueryType::Nearest) {
            EXPECT_LE(got, (1.0 + q.eps) * best + 1e-9) << line;
          } else {
            EXPECT_GE(got, (1.0 - q.eps) * best - 1e-9) << line;
          }
        } else {
          std::vector<kinetic::scenario::ObjectId> ids = answer["result"];
          EXPECT_TRUE(std::is_sorted(ids.begin(), ids.end()));
          for (const auto& [id, m] : alive) {
            const bool reported = std::find(ids.begin(), ids.end(), id) != ids.end();
            if (q.type == kinetic::scenario::QueryType::Range) {
              EXPECT_EQ(reported, kinetic::test::exactly_inside(m, q.box, 2, op.time))
                  << "id " << id << " " << line;
            } else {
              const auto& disk = q.shape.disk;
              const double sd =
                  std::hypot(position(m, 0) - disk.center[0], position(m, 1) - disk.center[1]) -
                  disk.radius;
              if (sd < -1e-9) {
                EXPECT_TRUE(reported) << "id " << id << " " << line;
              }
              if (reported) {
                EXPECT_LE(sd, q.eps * 2.0 * disk.radius + 1e-9) << "id " << id;
              }
            }
          }
        }
        ++answered;
      }
      EXPECT_EQ(answered, 12);
    }
  }
  // Deterministic; dimension 2 only; query types it does not answer are refused.
  const std::string path = scratch.path("ls_nearest.json");
  const std::string stats = scratch.path("ls_stats.json");
  const Outcome a =
      scratch.run("run " + path + " --structure longest-side-kdtree --stats " + stats, "ls_det_a");
  const Outcome b = scratch.run("run " + path + " --structure longest-side-kdtree", "ls_det_b");
  ASSERT_EQ(a.status, 0) << a.err;
  EXPECT_EQ(a.out, b.out);
  const auto st = nlohmann::json::parse(read_file(stats));
  const auto& sc = st["structure_counters"];
  ASSERT_TRUE(sc.is_object()) << read_file(stats);
  EXPECT_EQ(
      sc["ordering_events"].get<std::uint64_t>() + sc["longest_side_events"].get<std::uint64_t>(),
      st["events"]["external"].get<std::uint64_t>());
  EXPECT_EQ(st["events"]["internal"].get<std::uint64_t>(), 0u);  // every event changes the tree
  EXPECT_EQ(sc["queries"].get<std::uint64_t>(), 12u);
  EXPECT_GT(sc["node_visits"].get<std::uint64_t>(), 0u);
  const std::string three = scratch.path("ls_3d.json");
  ASSERT_EQ(
      scratch.run("generate random-linear --n 20 --dimension 3 --out " + three, "gen_ls3").status,
      0);
  const Outcome d3 = scratch.run("run " + three + " --structure longest-side-kdtree", "ls_3d");
  EXPECT_EQ(d3.status, 2);
  EXPECT_NE(d3.err.find("dimension 2"), std::string::npos) << d3.err;
  const std::string sorted = scratch.path("ls_sorted.json");
  ASSERT_EQ(scratch
                .run("generate random-linear --n 20 --dimension 2 --queries 2 --query-type sorted "
                     "--out " +
                         sorted,
                     "gen_ls_sorted")
                .status,
            0);
  EXPECT_EQ(scratch.run("run " + sorted + " --structure longest-side-kdtree", "ls_sorted").status,
            2);
}
