// `kinetic run --structure sweep-and-prune` and `--events`: the contact events written as they
// are processed replay to exactly the colliding_pairs answers at every query time; the stats
// count them; `sort` writes its swaps; a scenario of points and a query the structure does not
// answer are refused with status 2 and one line. (Every other structure's events:
// test_cli_events.cpp.)

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "support/cli.hpp"
#include "support/scenario_runs.hpp"

namespace {

using kinetic::test::read_file;
using kinetic::test::write_file;
using nlohmann::json;

const kinetic::test::CliScratch scratch{"kinetic_cli_collision_"};

/// n random 2-D boxes with linear motion, queries at `queries` random times, some inserts,
/// removes and updates between them.
json boxes_scenario(std::uint64_t seed, int n, int queries) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0), p(0.0, 1.0);
  const auto box = [&] {
    return std::make_pair(
        json::array({json::array({6 * u(rng), u(rng)}), json::array({6 * u(rng), u(rng)})}),
        json::array({0.2 + p(rng), 0.2 + p(rng)}));
  };
  json s = kinetic::test::scenario_json(2, 8.0, "boxes");
  for (int i = 0; i < n; ++i) {
    const auto [motion, half] = box();
    s["objects"].push_back({{"id", i}, {"motion", motion}, {"half_extents", half}});
  }
  std::vector<double> times;
  for (int i = 0; i < queries; ++i) times.push_back(8.0 * std::generate_canonical<double, 53>(rng));
  std::sort(times.begin(), times.end());
  s["timeline"] = json::array();
  int next = n;
  for (std::size_t i = 0; i < times.size(); ++i) {
    s["timeline"].push_back(
        {{"time", times[i]}, {"op", "query"}, {"query", {{"type", "colliding_pairs"}}}});
    const auto [motion, half] = box();
    if (i % 5 == 1) {
      s["timeline"].push_back({{"time", times[i]},
                               {"op", "insert"},
                               {"id", next++},
                               {"motion", motion},
                               {"half_extents", half}});
    } else if (i % 5 == 3) {
      s["timeline"].push_back({{"time", times[i]},
                               {"op", "update"},
                               {"id", static_cast<int>(rng() % static_cast<unsigned>(n))},
                               {"motion", motion},
                               {"origin", times[i]}});
    }
  }
  return s;
}

TEST(CliCollision, ContactEventsReplayToTheAnswers) {
  for (const std::string structure : {"sweep-and-prune", "bvh"}) {
    for (const char* scheduler : {"robust", "classic"}) {
      const std::string in = scratch.path("boxes.json");
      write_file(in, boxes_scenario(11, 60, 40).dump());
      const std::string answers = scratch.path("answers.jsonl"),
                        events = scratch.path("events.jsonl"), stats = scratch.path("stats.json");
      const auto o = scratch.run("run " + in + " --structure " + structure + " --scheduler " +
                                     std::string(scheduler) + " --out " + answers + " --events " +
                                     events + " --stats " + stats,
                                 "replay");
      ASSERT_EQ(o.status, 0) << o.err;
      std::vector<json> lines;
      std::istringstream ev(read_file(events));
      for (std::string line; std::getline(ev, line);) lines.push_back(json::parse(line));
      // Query i is followed at its time by an insert (i % 5 == 1) or an update that may move a
      // box (i % 5 == 3): those contacts change without an event. After any other query, the
      // next answer is this answer plus the events between them, exactly.
      std::set<std::pair<long, long>> contacts;
      std::size_t next = 0, begins = 0, ends = 0, checked = 0, replayed = 0;
      bool exact_replay = false;
      std::istringstream an(read_file(answers));
      for (std::string line; std::getline(an, line);) {
        const json a = json::parse(line);
        const double t = a["time"].get<double>();
        for (; next < lines.size() && lines[next]["time"].get<double>() <= t; ++next) {
          const json& e = lines[next];
          const auto ids = e["ids"].get<std::vector<long>>();
          ASSERT_EQ(ids.size(), 2u);
          ASSERT_LT(ids[0], ids[1]);
          if (e["kind"] == "contact_begin") {
            if (exact_replay) {
              EXPECT_TRUE(contacts.insert({ids[0], ids[1]}).second);
            }
            ++begins;
          } else {
            ASSERT_EQ(e["kind"], "contact_end");
            if (exact_replay) {
              EXPECT_EQ(contacts.erase({ids[0], ids[1]}), 1u);
            }
            ++ends;
          }
        }
        std::set<std::pair<long, long>> answered;
        for (const auto& p : a["result"]) answered.insert({p[0].get<long>(), p[1].get<long>()});
        EXPECT_EQ(answered.size(), a["result"].size()) << "a pair answered twice";
        if (exact_replay) {
          EXPECT_EQ(answered, contacts) << "t = " << t;
          ++replayed;
        }
        contacts = answered;
        exact_replay = checked % 5 != 1 && checked % 5 != 3;
        ++checked;
      }
      EXPECT_GT(replayed, 20u);
      for (; next < lines.size(); ++next)
        ++(lines[next]["kind"] == "contact_begin" ? begins : ends);
      EXPECT_EQ(checked, 40u);
      EXPECT_GT(begins, 10u) << structure << " " << scheduler;
      EXPECT_GT(ends, 10u) << scheduler;
      const json st = json::parse(read_file(stats));
      EXPECT_EQ(st["structure_counters"]["contact_begins"].get<std::size_t>(), begins);
      EXPECT_EQ(st["structure_counters"]["contact_ends"].get<std::size_t>(), ends);
      EXPECT_EQ(st["events"]["external"].get<std::size_t>(), begins + ends);
    }
  }
}

TEST(CliCollision, EventsWithoutTimelineChangesReplayExactly) {
  // Only queries on the timeline: the contact set at each query is the replay of every event
  // before it, exactly.
  json s = boxes_scenario(12, 80, 30);
  json only_queries = json::array();
  for (const auto& op : s["timeline"]) {
    if (op["op"] == "query") only_queries.push_back(op);
  }
  s["timeline"] = only_queries;
  const std::string in = scratch.path("queries.json");
  write_file(in, s.dump());
  const std::string answers = scratch.path("q_answers.jsonl"),
                    events = scratch.path("q_events.jsonl");
  const auto o = scratch.run(
      "run " + in + " --structure sweep-and-prune --out " + answers + " --events " + events,
      "queries");
  ASSERT_EQ(o.status, 0) << o.err;
  std::vector<json> lines;
  std::istringstream ev(read_file(events));
  for (std::string line; std::getline(ev, line);) lines.push_back(json::parse(line));
  // The contacts at the start time, from a run that stops there.
  json s0 = s;
  s0["timeline"] =
      json::array({{{"time", 0.0}, {"op", "query"}, {"query", {{"type", "colliding_pairs"}}}}});
  s0["end_time"] = 0.0;
  const std::string in0 = scratch.path("start.json");
  write_file(in0, s0.dump());
  const auto o0 = scratch.run("run " + in0 + " --structure sweep-and-prune", "start");
  ASSERT_EQ(o0.status, 0) << o0.err;
  std::set<std::pair<long, long>> contacts;
  const json start = json::parse(o0.out);
  for (const auto& p : start["result"]) contacts.insert({p[0].get<long>(), p[1].get<long>()});
  std::size_t next = 0, compared = 0;
  std::istringstream an(read_file(answers));
  for (std::string line; std::getline(an, line);) {
    const json a = json::parse(line);
    const double t = a["time"].get<double>();
    for (; next < lines.size() && lines[next]["time"].get<double>() <= t; ++next) {
      const auto ids = lines[next]["ids"].get<std::vector<long>>();
      if (lines[next]["kind"] == "contact_begin") {
        EXPECT_TRUE(contacts.insert({ids[0], ids[1]}).second);
      } else {
        EXPECT_EQ(contacts.erase({ids[0], ids[1]}), 1u) << lines[next].dump();
      }
    }
    std::set<std::pair<long, long>> answered;
    for (const auto& p : a["result"]) answered.insert({p[0].get<long>(), p[1].get<long>()});
    EXPECT_EQ(answered, contacts) << "t = " << t;
    ++compared;
  }
  EXPECT_EQ(compared, 30u);
  EXPECT_GT(lines.size(), 20u);
}

TEST(CliCollision, SortWritesItsSwaps) {
  const std::string in = scratch.path("points.json");
  write_file(in, R"({"format": "kinetic-scenario/1", "dimension": 1, "start_time": 0, "end_time": 5,
    "objects": [{"id": 1, "motion": [[0, 1]]}, {"id": 2, "motion": [[2, -1]]}, {"id": 3, "motion": [[10]]}],
    "timeline": []})");
  const auto o =
      scratch.run("run " + in + " --structure sort --scheduler classic --events -", "swaps");
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_EQ(o.out, "{\"time\":1.0,\"kind\":\"swap\",\"ids\":[1,2],\"axis\":0}\n");
}

TEST(CliCollision, RefusalsNameWhatAndWhere) {
  const std::string points = scratch.path("refuse_points.json");
  write_file(points, R"({"format": "kinetic-scenario/1", "dimension": 2, "end_time": 1,
    "objects": [{"id": 1, "motion": [[0], [0]]}], "timeline": []})");
  auto o = scratch.run("run " + points + " --structure sweep-and-prune", "points");
  EXPECT_EQ(o.status, 2);
  EXPECT_NE(o.err.find("$.objects_are: structure sweep-and-prune expects \"boxes\""),
            std::string::npos)
      << o.err;
  const std::string boxes = scratch.path("refuse_boxes.json");
  write_file(boxes, R"({"format": "kinetic-scenario/1", "dimension": 2, "objects_are": "boxes",
    "end_time": 1, "objects": [{"id": 1, "motion": [[0], [0]], "half_extents": [1, 1]}],
    "timeline": [{"time": 0.5, "op": "query", "query": {"type": "sorted"}}]})");
  o = scratch.run("run " + boxes + " --structure sweep-and-prune", "query");
  EXPECT_EQ(o.status, 2);
  EXPECT_NE(o.err.find("$.timeline[0].query.type: structure sweep-and-prune answers "
                       "colliding_pairs"),
            std::string::npos)
      << o.err;
  o = scratch.run("run --help", "help");
  EXPECT_EQ(o.status, 0);
  EXPECT_NE(o.out.find("sweep-and-prune: colliding_pairs"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("bvh: colliding_pairs"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("--events kinds: contact_begin, contact_end"), std::string::npos);
}

}  // namespace
