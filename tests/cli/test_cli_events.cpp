// `kinetic run --events` for every structure that is not a collision structure (those:
// test_cli_collision.cpp): one JSON line per external event, in processing order, of the kinds the
// structure documents, naming scenario ids (and the axis where the structure has one), as many
// lines as the stats count external events, under both schedulers.

#include <gtest/gtest.h>

#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "support/cli.hpp"

namespace {

using kinetic::test::read_file;
using kinetic::test::write_file;
using nlohmann::json;

const kinetic::test::CliScratch scratch{"kinetic_cli_events_"};

/// Intervals whose ends cross each other's (the segment tree's input): interval i is
/// [i + v t, i + 3 + v t] with velocities of both signs.
std::string intervals_scenario() {
  json objects = json::array();
  for (int i = 0; i < 12; ++i) {
    const double v = (i % 3 == 0 ? 1.0 : -0.5) * (1.0 + 0.1 * i);
    objects.push_back({{"id", 100 + i}, {"motion", {{i, v}, {i + 3, v}}}});
  }
  return json{{"format", "kinetic-scenario/1"},
              {"dimension", 2},
              {"objects_are", "intervals"},
              {"end_time", 10},
              {"objects", objects},
              {"timeline", json::array()}}
      .dump();
}

TEST(CliEvents, EveryStructureWritesItsExternalEvents) {
  const std::string points = scratch.path("points.json");
  const auto g = scratch.run("generate random-linear --n 40 --dimension 2 --out " + points, "gen");
  ASSERT_EQ(g.status, 0) << g.err;
  const std::string intervals = scratch.path("intervals.json");
  write_file(intervals, intervals_scenario());
  const std::map<std::string, std::set<std::string>> kinds{
      {"sort", {"swap"}},
      {"tournament", {"max_change", "min_change"}},
      {"extent", {"max_change", "min_change"}},
      {"kdtree", {"swap"}},
      {"range-tree", {"swap"}},
      {"longest-side-kdtree", {"swap", "longest_side"}},
      {"segment-tree", {"endpoint_swap"}},
      {"hull", {"hull_change"}}};
  for (const auto& [structure, allowed] : kinds) {
    const std::string& in = structure == "segment-tree" ? intervals : points;
    const json scenario = json::parse(read_file(in));
    std::set<long long> ids;
    for (const json& o : scenario["objects"]) ids.insert(o["id"].get<long long>());
    for (const char* sched : {"robust", "classic"}) {
      SCOPED_TRACE(structure + ", " + sched);
      const std::string events = scratch.path("events.jsonl");
      const std::string stats = scratch.path("stats.json");
      const auto o =
          scratch.run("run " + in + " --structure " + structure + " --scheduler " + sched +
                          " --events " + events + " --stats " + stats + " --out /dev/null",
                      "run");
      ASSERT_EQ(o.status, 0) << o.err;
      std::istringstream lines(read_file(events));
      std::string line;
      std::size_t count = 0;
      std::map<std::string, std::size_t> by_kind;
      double last = 0.0;
      while (std::getline(lines, line)) {
        const json e = json::parse(line);
        ++count;
        const std::string kind = e["kind"].get<std::string>();
        EXPECT_TRUE(allowed.contains(kind)) << line;
        ++by_kind[kind];
        const double t = e["time"].get<double>();
        EXPECT_GE(t, last) << line;  // processing order
        EXPECT_LE(t, 10.0) << line;
        last = t;
        EXPECT_FALSE(e["ids"].empty()) << line;
        for (const json& id : e["ids"]) EXPECT_TRUE(ids.contains(id.get<long long>())) << line;
        const bool has_axis = kind == "swap" || kind == "max_change" || kind == "min_change";
        EXPECT_EQ(e.contains("axis"), has_axis) << line;
        if (has_axis) {
          EXPECT_GE(e["axis"].get<int>(), 0);
          EXPECT_LT(e["axis"].get<int>(), scenario["dimension"].get<int>());
        }
      }
      const json st = json::parse(read_file(stats));
      EXPECT_EQ(count, st["events"]["external"].get<std::size_t>());
      EXPECT_GT(count, 0u);
      if (structure == "longest-side-kdtree") {
        EXPECT_GT(by_kind["longest_side"], 0u);
      }
    }
  }
}

}  // namespace
