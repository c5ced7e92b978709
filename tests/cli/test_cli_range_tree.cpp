// `kinetic run --structure range-tree`: range answers equal a brute-force replay of the same
// timeline (exact comparisons of the coordinates with the box), under both schedulers, in 1 to 3
// dimensions, with inserts, removes and flight-plan updates; the runner's test mode validates
// after every event; other query types are refused with status 2.

#include <gtest/gtest.h>

#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "kinetic/run/runner.hpp"
#include "kinetic/scenario/scenario_json.hpp"
#include "support/cli.hpp"
#include "support/scenario_runs.hpp"

namespace {

using Outcome = kinetic::test::CliOutcome;
using kinetic::test::read_file;

const kinetic::test::CliScratch scratch{"kinetic_cli_rt_"};

TEST(CliRangeTree, RangeAnswersEqualBruteForce) {
  const Outcome help = scratch.run("run --help", "rt_help");
  EXPECT_NE(help.out.find("range-tree"), std::string::npos);
  for (int d = 1; d <= 3; ++d) {
    const std::string path = scratch.path("rt" + std::to_string(d) + ".json");
    ASSERT_NO_FATAL_FAILURE(kinetic::test::generate_range_scenario(
        scratch, path, d == 3 ? 150 : 300, d, 12, 10, 30 + d, "gen_rt"));
    const kinetic::scenario::Scenario s = kinetic::scenario::load_scenario(path);
    const std::string expected = kinetic::test::range_answers_by_brute_force(s);
    for (const char* sched : {"robust", "classic"}) {
      const Outcome o =
          scratch.run("run " + path + " --structure range-tree --scheduler " + sched, "rt_run");
      ASSERT_EQ(o.status, 0) << o.err;
      EXPECT_EQ(o.out, expected) << "d " << d << " " << sched;
    }
  }
}

TEST(CliRangeTree, RunnerTestModeValidatesEveryEvent) {
  for (int d = 1; d <= 3; ++d) {
    const std::string path = scratch.path("rt_testmode" + std::to_string(d) + ".json");
    ASSERT_NO_FATAL_FAILURE(
        kinetic::test::generate_range_scenario(scratch, path, 40, d, 8, 4, 50 + d, "gen_rt_tm"));
    const kinetic::scenario::Scenario s = kinetic::scenario::load_scenario(path);
    for (const auto kind : {kinetic::SchedulerKind::Robust, kinetic::SchedulerKind::Classic}) {
      std::ostringstream answers;
      const kinetic::run::RunResult r =
          kinetic::test::run_validating(s, "range-tree", kind, answers, 20);
      EXPECT_EQ(r.stats.queries, 8u);
      EXPECT_EQ(answers.str(), kinetic::test::range_answers_by_brute_force(s)) << "d " << d;
      // The structure's counters: every external event is a swap of one axis; the queries.
      std::map<std::string, std::uint64_t> sc;
      for (const kinetic::NamedCounter& c : r.stats.structure_counters) sc[c.name] = c.value;
      std::uint64_t by_axis = 0;
      for (int a = 0; a < d; ++a) by_axis += sc.at("swaps_axis_" + std::to_string(a));
      EXPECT_EQ(by_axis, sc.at("swaps"));
      EXPECT_EQ(sc.at("swaps"), r.stats.counters.events_external);
      EXPECT_EQ(sc.at("queries"), 8u);
      // 4 inserts, 4 removes and 4 updates, each local unless A_0 was laid out again.
      EXPECT_EQ(sc.at("local_changes") + sc.at("rebuilds"), 12u);
      EXPECT_GT(sc.at("local_changes"), 0u);
      EXPECT_GT(sc.at("stored_entries"), 0u);
    }
  }
}

TEST(CliRangeTree, OtherQueriesAreRefused) {
  const std::string path = scratch.path("rt_sorted.json");
  ASSERT_EQ(scratch
                .run("generate random-linear --n 10 --dimension 2 --queries 2 --query-type sorted "
                     "--out " +
                         path,
                     "rt_gen_sorted")
                .status,
            0);
  EXPECT_EQ(scratch.run("run " + path + " --structure range-tree", "rt_sorted").status, 2);
  // Dimensions above 4 are refused (the space grows as n log^(d-1) n).
  const std::string five = scratch.path("rt_5d.json");
  ASSERT_EQ(scratch
                .run("generate random-linear --n 10 --dimension 5 --queries 2 --query-type range "
                     "--out " +
                         five,
                     "rt_gen_5d")
                .status,
            0);
  const Outcome o = scratch.run("run " + five + " --structure range-tree", "rt_5d");
  EXPECT_EQ(o.status, 2);
  EXPECT_NE(o.err.find("dimensions up to 4"), std::string::npos) << o.err;
}

}  // namespace
