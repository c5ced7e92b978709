// `kinetic run --structure segment-tree`: stab answers equal a brute-force replay of the same
// timeline (exact comparisons of the endpoints with x), under both schedulers, with inserts,
// removes and flight-plan updates; the runner's test mode validates after every event; point
// scenarios and other query types are refused with status 2.

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "kinetic/core/predicates.hpp"
#include "kinetic/run/runner.hpp"
#include "kinetic/scenario/scenario_json.hpp"
#include "support/cli.hpp"
#include "support/scenario_runs.hpp"

namespace {

using nlohmann::json;

using Outcome = kinetic::test::CliOutcome;
using kinetic::test::read_file;
using kinetic::test::write_file;

const kinetic::test::CliScratch scratch{"kinetic_cli_st_"};

/// A random interval valid for t >= 0: left end linear or quadratic, width a sum of non-negative
/// terms; with `shared`, small integers (many equal endpoint values).
json random_interval(std::mt19937_64& rng, bool shared) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), p(0.0, 1.0);
  if (shared) {
    const double a = static_cast<double>(rng() % 5), v = static_cast<double>(rng() % 3) - 1.0;
    const double w = static_cast<double>(rng() % 3);
    return json::array({json::array({a, v}), json::array({a + w, v})});
  }
  const double a0 = 10 * u(rng), a1 = u(rng), a2 = rng() % 2 == 0 ? 0.0 : 0.05 * u(rng);
  const double w0 = 3 * p(rng), w1 = 0.2 * p(rng), w2 = a2 == 0.0 ? 0.0 : 0.02 * p(rng);
  return json::array({json::array({a0, a1, a2}), json::array({a0 + w0, a1 + w1, a2 + w2})});
}

json make_scenario(std::uint64_t seed, bool shared, int queries) {
  std::mt19937_64 rng(seed);
  json s = kinetic::test::scenario_json(2, 10.0, "intervals");
  int next = 0;
  std::vector<int> alive;
  for (; next < 40; ++next) {
    s["objects"].push_back({{"id", next}, {"motion", random_interval(rng, shared)}});
    alive.push_back(next);
  }
  std::vector<double> times;
  for (int i = 0; i < queries; ++i)
    times.push_back(shared && i % 2 == 0 ? static_cast<double>(1 + i % 9)
                                         : 10.0 * std::generate_canonical<double, 53>(rng));
  std::sort(times.begin(), times.end());
  s["timeline"] = json::array();
  for (std::size_t i = 0; i < times.size(); ++i) {
    const double t = times[i];
    double x = 24.0 * std::generate_canonical<double, 53>(rng) - 12.0;
    if (shared && i % 3 != 0) x = static_cast<double>(static_cast<int>(rng() % 10) - 3);
    s["timeline"].push_back(
        {{"time", t}, {"op", "query"}, {"query", {{"type", "stab"}, {"x", x}}}});
    const int op = static_cast<int>(i % 4);
    if (op == 1) {
      s["timeline"].push_back(
          {{"time", t}, {"op", "insert"}, {"id", next}, {"motion", random_interval(rng, shared)}});
      alive.push_back(next++);
    } else if (op == 2 && alive.size() > 2) {
      const std::size_t k = rng() % alive.size();
      s["timeline"].push_back({{"time", t}, {"op", "remove"}, {"id", alive[k]}});
      alive.erase(alive.begin() + static_cast<std::ptrdiff_t>(k));
    } else if (op == 3) {
      s["timeline"].push_back({{"time", t},
                               {"op", "update"},
                               {"id", alive[rng() % alive.size()]},
                               {"motion", random_interval(rng, shared)}});
    }
  }
  return s;
}

/// The answers by brute force: replay the timeline, exact comparisons at the query time.
std::vector<std::vector<kinetic::scenario::ObjectId>> brute_force(
    const kinetic::scenario::Scenario& s) {
  using kinetic::scenario::OpKind;
  std::map<kinetic::scenario::ObjectId, kinetic::scenario::Motion> alive;
  for (const auto& o : s.objects) alive[o.id] = o.motion;
  std::vector<std::vector<kinetic::scenario::ObjectId>> out;
  for (const auto& op : s.timeline) {
    if (op.op == OpKind::Remove) alive.erase(op.id);
    if (op.op == OpKind::Insert || op.op == OpKind::Update) alive[op.id] = op.motion;
    if (op.op != OpKind::Query) continue;
    const auto q = kinetic::MotionPolynomial::constant(op.query.x);
    std::vector<kinetic::scenario::ObjectId> ids;
    for (const auto& [id, m] : alive) {
      const auto l = kinetic::MotionPolynomial::from(m.coordinates[0], m.origin);
      const auto r = kinetic::MotionPolynomial::from(m.coordinates[1], m.origin);
      if (kinetic::compare_at(l, q, op.time) <= 0 && kinetic::compare_at(r, q, op.time) >= 0)
        ids.push_back(id);
    }
    out.push_back(ids);
  }
  return out;
}

TEST(CliSegmentTree, StabAnswersEqualBruteForce) {
  const std::string help = scratch.run("run --help", "st_help").out;
  EXPECT_NE(help.find("segment-tree"), std::string::npos);
  for (const bool shared : {false, true}) {
    const std::string path = scratch.path(shared ? "shared.json" : "random.json");
    write_file(path, make_scenario(shared ? 12 : 11, shared, 24).dump());
    const kinetic::scenario::Scenario s = kinetic::scenario::load_scenario(path);
    const auto expected = brute_force(s);
    std::size_t nonempty = 0;
    for (const auto& e : expected) nonempty += e.empty() ? 0 : 1;
    EXPECT_GE(nonempty, 6u);
    for (const char* sched : {"robust", "classic"}) {
      const std::string stats = scratch.path("stats.json");
      const Outcome o = scratch.run(
          "run " + path + " --structure segment-tree --scheduler " + sched + " --stats " + stats,
          "st_run");
      ASSERT_EQ(o.status, 0) << o.err;
      const std::vector<json> answers = kinetic::test::json_lines(o.out);
      ASSERT_EQ(answers.size(), expected.size()) << sched;
      for (std::size_t k = 0; k < answers.size(); ++k) {
        const json& a = answers[k];
        EXPECT_EQ(a["type"], "stab");
        EXPECT_EQ(a["result"].get<std::vector<kinetic::scenario::ObjectId>>(), expected[k])
            << sched << " " << a.dump();
      }
      const json st = json::parse(read_file(stats));
      const json& sc = st["structure_counters"];
      ASSERT_TRUE(sc.is_object());
      EXPECT_EQ(sc["swaps"].get<std::uint64_t>(), st["events"]["external"].get<std::uint64_t>());
      EXPECT_EQ(sc["queries"].get<std::uint64_t>(), expected.size());
    }
  }
}

TEST(CliSegmentTree, RunnerTestModeValidatesEveryEvent) {
  for (const bool shared : {false, true}) {
    const std::string path = scratch.path("testmode.json");
    write_file(path, make_scenario(shared ? 22 : 21, shared, 12).dump());
    const kinetic::scenario::Scenario s = kinetic::scenario::load_scenario(path);
    for (const auto kind : {kinetic::SchedulerKind::Robust, kinetic::SchedulerKind::Classic}) {
      std::ostringstream answers;
      const kinetic::run::RunResult r =
          kinetic::test::run_validating(s, "segment-tree", kind, answers, 20);
      EXPECT_EQ(r.stats.queries, 12u);
    }
  }
}

// A scenario's interval needs to keep left <= right only until its next change: one that would
// turn inside out after its update or its removal runs (the session a run plays on does not ask
// more of it than the scenario's reader).
TEST(CliSegmentTree, AnIntervalHoldsOnlyUntilItsNextChange) {
  json s = kinetic::test::scenario_json(2, 3.0, "intervals");
  s["objects"].push_back({{"id", 0}, {"motion", {{0.0, 1.0}, {2.0}}}});   // [t, 2]: out at 2
  s["objects"].push_back({{"id", 1}, {"motion", {{0.0}, {3.0}}}});        // [0, 3]
  s["objects"].push_back({{"id", 2}, {"motion", {{0.0}, {1.0, -1.0}}}});  // [0, 1 - t]: out at 1
  s["timeline"] = json::array(
      {{{"time", 0.25}, {"op", "remove"}, {"id", 2}},
       {{"time", 1.0}, {"op", "query"}, {"query", {{"type", "stab"}, {"x", 1.0}}}},
       {{"time", 1.5}, {"op", "update"}, {"id", 0}, {"motion", {{1.5}, {2.0}}}, {"origin", 1.5}},
       {{"time", 2.5}, {"op", "query"}, {"query", {{"type", "stab"}, {"x", 1.0}}}}});
  const std::string path = scratch.path("until_change.json");
  write_file(path, s.dump());
  const Outcome o = scratch.run("run " + path + " --structure segment-tree", "st_until_change");
  ASSERT_EQ(o.status, 0) << o.err;
  std::istringstream lines(o.out);
  std::string line;
  std::vector<json> results;
  while (std::getline(lines, line)) results.push_back(json::parse(line)["result"]);
  EXPECT_EQ(results, (std::vector<json>{json::array({0, 1}), json::array({1})})) << o.out;
}

TEST(CliSegmentTree, PointsAndOtherQueriesAreRefused) {
  const std::string points = scratch.path("points.json");
  ASSERT_EQ(
      scratch.run("generate random-linear --n 10 --dimension 2 --out " + points, "st_gen").status,
      0);
  const Outcome o = scratch.run("run " + points + " --structure segment-tree", "st_points");
  EXPECT_EQ(o.status, 2);
  EXPECT_NE(o.err.find("intervals"), std::string::npos) << o.err;
  json s = make_scenario(5, false, 2);
  s["timeline"] = json::array({{{"time", 1.0}, {"op", "query"}, {"query", {{"type", "sorted"}}}}});
  const std::string path = scratch.path("sorted.json");
  write_file(path, s.dump());
  const Outcome q = scratch.run("run " + path + " --structure segment-tree", "st_sorted");
  EXPECT_EQ(q.status, 2);
  EXPECT_NE(q.err.find("stab"), std::string::npos) << q.err;
  // And the point structures refuse interval scenarios.
  const Outcome k = scratch.run("run " + path + " --structure kdtree", "st_kd");
  EXPECT_EQ(k.status, 2);
}

}  // namespace
