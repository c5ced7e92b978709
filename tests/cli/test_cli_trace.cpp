// `kinetic run --trace` and `kinetic view`: the trace (kinetic-trace/1, docs/trace-format.md) of
// every structure holds the header with the scenario, every event processed (as many as the
// stats count, external ones with the --events kinds and ids), every op and query answer (the
// same answers as --out), snapshots of the structure's documented kind; the limits leave events
// and snapshots out and say so; `kinetic view` makes one page with the trace inside and refuses
// what is not a trace, naming the file and the line.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
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

const kinetic::test::CliScratch scratch{"kinetic_cli_trace_"};

std::vector<json> lines_of(const std::string& path) {
  std::vector<json> out;
  std::istringstream in(read_file(path));
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) out.push_back(json::parse(line));
  }
  return out;
}

std::string intervals_scenario() {
  json objects = json::array();
  for (int i = 0; i < 10; ++i) {
    const double v = (i % 3 == 0 ? 1.0 : -0.5) * (1.0 + 0.1 * i);
    objects.push_back({{"id", 100 + i}, {"motion", {{i, v}, {i + 3, v}}}});
  }
  json timeline = json::array();
  for (int k = 1; k <= 3; ++k)
    timeline.push_back(
        {{"time", 2.5 * k}, {"op", "query"}, {"query", {{"type", "stab"}, {"x", 4.0}}}});
  return json{{"format", "kinetic-scenario/1"},
              {"dimension", 2},
              {"objects_are", "intervals"},
              {"end_time", 10},
              {"objects", objects},
              {"timeline", timeline}}
      .dump();
}

/// x_axis(t) of a scenario object (no timeline changes in these scenarios).
double position(const json& object, int axis, double t) {
  const json& c = object["motion"][axis];
  const double dt = t - object.value("origin", 0.0);
  double v = 0.0;
  for (std::size_t j = c.size(); j-- > 0;) v = v * dt + c[j].get<double>();
  return v;
}

/// What the snapshot's pictures say holds: a tournament tree's root is its top, and its
/// levels halve; the BVH's root box is bounded by the boxes with the extreme sides at t.
void check_snapshot(const std::string& structure, const json& line, const json& scenario) {
  const json& s = line["snapshot"];
  const double t = line["t"];
  std::map<long long, const json*> by_id;
  for (const json& o : scenario["objects"]) by_id[o["id"].get<long long>()] = &o;
  if (structure == "tournament" || structure == "extent") {
    for (const json& top : s["tops"]) {
      ASSERT_FALSE(top["levels"].empty());
      EXPECT_EQ(top["levels"][0][0], top["id"]);
      for (std::size_t k = 1; k < top["levels"].size(); ++k)
        EXPECT_EQ(top["levels"][k].size(), 2 * top["levels"][k - 1].size());
    }
  }
  if (structure == "kdtree" || structure == "range-tree") {
    // Every order with the slot of each key in the sort's gapped layout (strictly increasing,
    // below U) and U, a power of two; the same objects on every axis. (tests/run/
    // test_trace_snapshot.cpp checks the kd-tree's against its sorts and its tree; the range
    // tree's primary tree halves A_0's slots.)
    ASSERT_EQ(s["orders"].size(), scenario["dimension"].get<std::size_t>());
    std::set<long long> ids_of_first;
    for (const json& o : s["orders"]) {
      const auto u = o["slot_count"].get<std::uint64_t>();
      EXPECT_TRUE(std::has_single_bit(u)) << "U = " << u;
      const json& ids = o["ids"];
      const json& slots = o["slots"];
      ASSERT_EQ(slots.size(), ids.size());
      EXPECT_LE(ids.size(), u);
      for (std::size_t k = 0; k < slots.size(); ++k) {
        EXPECT_LT(slots[k].get<std::uint64_t>(), u);
        if (k > 0) {
          EXPECT_LT(slots[k - 1].get<std::uint64_t>(), slots[k].get<std::uint64_t>());
        }
      }
      std::set<long long> these;
      for (const json& id : ids) these.insert(id.get<long long>());
      EXPECT_EQ(these.size(), ids.size());
      if (ids_of_first.empty()) ids_of_first = these;
      EXPECT_EQ(these, ids_of_first);
    }
  }
  if (structure == "segment-tree") {
    // S(v) holds intervals that cover v's span [R[first], R[last + 1]] (and not its parent's).
    const json& r = s["endpoints"];
    const auto end_at = [&](std::size_t rank) {
      return position(*by_id.at(r[rank][0].get<long long>()), r[rank][1].get<int>(), t);
    };
    ASSERT_FALSE(s["nodes"].empty());
    for (const json& node : s["nodes"]) {
      const std::size_t first = node["leaves"][0], last = node["leaves"][1];
      if (last + 1 >= r.size()) continue;  // padding leaves beyond the 2n - 1 elementary ones
      for (const json& id : node["ids"]) {
        const json& o = *by_id.at(id.get<long long>());
        EXPECT_LE(position(o, 0, t), end_at(first) + 1e-9) << node.dump();
        EXPECT_GE(position(o, 1, t), end_at(last + 1) - 1e-9) << node.dump();
      }
    }
  }
  if (structure == "longest-side-kdtree") {
    // Each cell's region at t from its bounding points; the root's is the bounding box, every
    // other lies inside a cell one level up, and the split is orthogonal to the longest side
    // through a point of the region.
    const auto at = [&](const json& id, int axis) {
      return position(*by_id.at(id.get<long long>()), axis, t);
    };
    using Region = std::array<std::array<double, 2>, 2>;
    std::vector<std::pair<int, Region>> regions;
    ASSERT_FALSE(s["cells"].empty());
    for (const json& cell : s["cells"]) {
      Region r{};
      for (int a = 0; a < 2; ++a) r[a] = {at(cell["lo"][a], a), at(cell["top"][a], a)};
      const int axis = cell["axis"], depth = cell["depth"];
      EXPECT_GE(r[axis][1] - r[axis][0], r[1 - axis][1] - r[1 - axis][0] - 1e-9) << cell.dump();
      const double split = at(cell["split"], axis);
      EXPECT_TRUE(r[axis][0] - 1e-9 <= split && split <= r[axis][1] + 1e-9) << cell.dump();
      if (depth == 0) {
        for (int a = 0; a < 2; ++a) {
          double lo = 1e300, hi = -1e300;
          for (const json& o : scenario["objects"]) {
            lo = std::min(lo, position(o, a, t));
            hi = std::max(hi, position(o, a, t));
          }
          EXPECT_NEAR(r[a][0], lo, 1e-9);
          EXPECT_NEAR(r[a][1], hi, 1e-9);
        }
      } else {
        const bool inside = std::any_of(regions.begin(), regions.end(), [&](const auto& up) {
          if (up.first != depth - 1) return false;
          for (int a = 0; a < 2; ++a)
            if (r[a][0] < up.second[a][0] - 1e-9 || r[a][1] > up.second[a][1] + 1e-9) return false;
          return true;
        });
        EXPECT_TRUE(inside) << cell.dump();
      }
      regions.emplace_back(depth, r);
    }
  }
  if (structure == "bvh") {
    // The separation list's pairs between listed nodes: a separated pair's boxes are apart on
    // some axis, an expanded or contact pair's overlap on every axis, a self pair is one node.
    const int d = scenario["dimension"];
    const auto box_side = [&](const json& id, int a, int sign) {
      const json& o = *by_id.at(id.get<long long>());
      return position(o, a, t) + sign * o["half_extents"][a].get<double>();
    };
    const json& nodes = s["nodes"];
    for (const json& p : s["pairs"]) {
      const std::size_t a = p[0], b = p[1];
      ASSERT_LT(a, nodes.size());
      ASSERT_LT(b, nodes.size());
      const std::string state = p[2];
      if (state == "self") {
        EXPECT_EQ(a, b);
        continue;
      }
      bool apart = false;  // on some axis (or touching, at a certificate's failure time)
      for (int k = 0; k < d; ++k) {
        const double alo = box_side(nodes[a]["sides"][k][0], k, -1);
        const double ahi = box_side(nodes[a]["sides"][k][1], k, 1);
        const double blo = box_side(nodes[b]["sides"][k][0], k, -1);
        const double bhi = box_side(nodes[b]["sides"][k][1], k, 1);
        apart = apart || ahi <= blo + 1e-9 || bhi <= alo + 1e-9;
        if (state != "separated") {
          EXPECT_LE(std::max(alo, blo), std::min(ahi, bhi) + 1e-9) << p.dump();
        }
      }
      if (state == "separated") {
        EXPECT_TRUE(apart) << p.dump();
      }
    }
  }
  if (structure == "bvh" && !s["nodes"].empty()) {
    const json& root = s["nodes"][0];
    EXPECT_EQ(root["depth"], 0);
    const int d = scenario["dimension"];
    ASSERT_EQ(root["sides"].size(), static_cast<std::size_t>(d));
    for (int a = 0; a < d; ++a) {
      double lo = 1e300, hi = -1e300;
      for (const json& o : scenario["objects"]) {
        const double h = o["half_extents"][a];
        lo = std::min(lo, position(o, a, t) - h);
        hi = std::max(hi, position(o, a, t) + h);
      }
      const json& lo_box = *by_id.at(root["sides"][a][0].get<long long>());
      const json& hi_box = *by_id.at(root["sides"][a][1].get<long long>());
      EXPECT_NEAR(position(lo_box, a, t) - lo_box["half_extents"][a].get<double>(), lo, 1e-9);
      EXPECT_NEAR(position(hi_box, a, t) + hi_box["half_extents"][a].get<double>(), hi, 1e-9);
    }
  }
}

struct Case {
  std::string structure, generate, scheduler, snapshot_key;
};

TEST(CliTrace, EveryStructureTracesEventsOpsAnswersAndSnapshots) {
  const std::string intervals = scratch.path("intervals.json");
  write_file(intervals, intervals_scenario());
  const std::vector<Case> cases{
      {"sort", "random-linear --n 20 --queries 3 --updates 2 --inserts 2 --removes 1", "robust",
       "orders"},
      {"tournament", "random-linear --n 20 --queries 3 --query-type max", "robust", "tops"},
      {"extent", "random-linear --n 20 --dimension 2 --queries 3 --query-type extent", "classic",
       "tops"},
      {"kdtree", "random-linear --n 30 --dimension 2 --queries 3 --query-type range --updates 3",
       "robust", "orders"},
      {"range-tree", "random-linear --n 30 --dimension 2 --queries 3 --query-type range", "exact",
       "orders"},
      {"longest-side-kdtree",
       "random-linear --n 24 --dimension 2 --end 0.5 --queries 2 --query-type nearest", "robust",
       "cells"},
      {"segment-tree", "", "robust", "endpoints"},
      {"hull", "circle --n 16 --queries 3 --query-type hull", "robust", "hull"},
      {"delaunay", "random-linear --n 10 --dimension 2 --end 2 --queries 2 --query-type delaunay",
       "exact", "delaunay"},
      {"closest-pair",
       "random-linear --n 10 --dimension 2 --end 2 --queries 2 --query-type closest_pair", "exact",
       "closest_pair"},
      {"bvh", "boxes-linear --n 16 --dimension 2 --queries 2 --query-type colliding_pairs",
       "robust", "colliding_pairs"},
      {"sweep-and-prune",
       "boxes-linear --n 16 --dimension 2 --queries 2 --query-type colliding_pairs", "robust",
       "colliding_pairs"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.structure);
    std::string in = intervals;
    if (!c.generate.empty()) {
      in = scratch.path(c.structure + ".json");
      const auto g = scratch.run("generate " + c.generate + " --seed 7 --out " + in, "gen");
      ASSERT_EQ(g.status, 0) << g.err;
    }
    const std::string trace = scratch.path(c.structure + ".trace");
    const std::string answers = scratch.path(c.structure + ".answers");
    const std::string stats = scratch.path(c.structure + ".stats");
    const std::string events = scratch.path(c.structure + ".events");
    const auto r = scratch.run("run " + in + " --structure " + c.structure + " --scheduler " +
                                   c.scheduler + " --out " + answers + " --stats " + stats +
                                   " --events " + events + " --trace " + trace,
                               "run");
    ASSERT_EQ(r.status, 0) << r.err;
    const std::vector<json> t = lines_of(trace);
    ASSERT_GE(t.size(), 3u);
    // The header: the format, the run's settings and the scenario as read.
    EXPECT_EQ(t[0]["format"], "kinetic-trace/1");
    EXPECT_EQ(t[0]["structure"], c.structure);
    EXPECT_EQ(t[0]["scheduler"], c.scheduler);
    ASSERT_TRUE(t[0]["scenario"].is_object() && t[0]["scenario"].contains("objects"));
    EXPECT_EQ(t[0]["scenario"]["objects"].size(), json::parse(read_file(in))["objects"].size());
    const json st = json::parse(read_file(stats));
    // Events: one line each, external ones as --events writes them.
    std::vector<json> external;
    std::size_t internal = 0, queries = 0, ops = 0, snapshots = 0;
    double last_time = -1e300;
    std::vector<json> answer_lines;
    for (std::size_t k = 1; k + 1 < t.size(); ++k) {
      const json& l = t[k];
      ASSERT_TRUE(l.contains("t") && l.contains("k")) << l.dump();
      EXPECT_GE(l["t"].get<double>(), last_time) << "times never go back: " << l.dump();
      last_time = l["t"].get<double>();
      const std::string kind = l["k"];
      if (kind == "event") external.push_back(l);
      if (kind == "internal") ++internal;
      if (kind == "query") {
        ++queries;
        answer_lines.push_back(l);
      }
      if (kind == "op") ++ops;
      if (kind == "snapshot") {
        ++snapshots;
        EXPECT_TRUE(l["snapshot"].contains(c.snapshot_key)) << l.dump().substr(0, 200);
        check_snapshot(c.structure, l, t[0]["scenario"]);
      }
    }
    // Every event has a line: the structure's log lines (as --events), or one of its own.
    EXPECT_GE(external.size() + internal, st["events"]["processed"].get<std::size_t>());
    EXPECT_LE(internal, st["events"]["internal"].get<std::size_t>());
    const std::vector<json> logged = lines_of(events);
    std::erase_if(external, [](const json& l) { return l["kind"] == "external"; });  // unlogged
    ASSERT_EQ(logged.size(), external.size());
    for (std::size_t k = 0; k < logged.size(); ++k) {
      EXPECT_EQ(external[k]["kind"], logged[k]["kind"]);
      EXPECT_EQ(external[k]["ids"], logged[k]["ids"]);
      EXPECT_EQ(external[k]["t"], logged[k]["time"]);
    }
    // Ops and answers: each op of the timeline, each answer as --out wrote it.
    const json scenario = json::parse(read_file(in));
    std::size_t timeline_queries = 0;
    for (const json& op : scenario["timeline"]) timeline_queries += op["op"] == "query";
    EXPECT_EQ(queries, timeline_queries);
    EXPECT_EQ(ops, scenario["timeline"].size() - timeline_queries);
    const std::vector<json> out = lines_of(answers);
    ASSERT_EQ(out.size(), answer_lines.size());
    for (std::size_t k = 0; k < out.size(); ++k) {
      EXPECT_EQ(answer_lines[k]["result"], out[k]["result"]);
      EXPECT_EQ(answer_lines[k]["t"], out[k]["time"]);
    }
    // Snapshots: at the start, after every op and query, and after events (all of them here:
    // the runs are far below the sampling limit).
    EXPECT_GE(snapshots, 1 + ops + queries);
    EXPECT_EQ(t.back()["k"], "end");
    EXPECT_EQ(t.back()["outcome"], "completed");
    EXPECT_EQ(t.back()["events"]["left_out"], 0);
    EXPECT_EQ(t.back()["snapshots"]["left_out"], 0);
    // The replay page holds the viewer and the trace.
    const std::string page = scratch.path(c.structure + ".html");
    const auto v = scratch.run("view " + trace + " --out " + page, "view");
    ASSERT_EQ(v.status, 0) << v.err;
    const std::string html = read_file(page);
    EXPECT_NE(html.find("window.kineticViewer"), std::string::npos);
    EXPECT_NE(html.find("\"format\":\"kinetic-trace/1\""), std::string::npos);
    EXPECT_EQ(html.find("/*KINETIC_TRACE*/"), std::string::npos);
  }
}

TEST(CliTrace, TheLimitsLeaveEventsAndSnapshotsOutAndSaySo) {
  const std::string in = scratch.path("limits.json");
  ASSERT_EQ(
      scratch.run("generate random-linear --n 60 --seed 3 --queries 10 --out " + in, "gen").status,
      0);
  const std::string trace = scratch.path("limits.trace");
  const std::string stats = scratch.path("limits.stats");
  const auto r = scratch.run("run " + in + " --structure sort --stats " + stats + " --trace " +
                                 trace + " --trace-max-events 25 --trace-max-snapshots 6",
                             "run");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::vector<json> t = lines_of(trace);
  std::size_t events = 0, snapshots = 0;
  for (const json& l : t) {
    events += l.value("k", "") == "event" || l.value("k", "") == "internal";
    snapshots += l.value("k", "") == "snapshot";
  }
  const std::size_t processed = json::parse(read_file(stats))["events"]["processed"];
  ASSERT_GT(processed, 25u);
  EXPECT_EQ(events, 25u);
  EXPECT_EQ(snapshots, 6u);
  const json& end = t.back();
  EXPECT_EQ(end["events"]["processed"], processed);
  EXPECT_EQ(end["events"]["written"], 25);
  EXPECT_EQ(end["events"]["left_out"], processed - 25);
  EXPECT_GT(end["snapshots"]["left_out"].get<std::size_t>(), 0u);
}

TEST(CliTrace, ViewRefusesWhatIsNotATrace) {
  const std::string page = scratch.path("bad.html");
  const auto missing = scratch.run("view " + scratch.path("missing.trace") + " --out " + page, "m");
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.err.find("cannot read"), std::string::npos) << missing.err;
  const std::string empty = scratch.path("empty.trace");
  write_file(empty, "");
  const auto e = scratch.run("view " + empty + " --out " + page, "e");
  EXPECT_EQ(e.status, 2);
  EXPECT_NE(e.err.find("is empty"), std::string::npos) << e.err;
  const std::string scenario = scratch.path("scenario.trace");
  write_file(scenario, "{\"format\": \"kinetic-scenario/1\"}\n");
  const auto s = scratch.run("view " + scenario + " --out " + page, "s");
  EXPECT_EQ(s.status, 2);
  EXPECT_NE(s.err.find(":1: not a kinetic-trace/1 header"), std::string::npos) << s.err;
  const std::string broken = scratch.path("broken.trace");
  write_file(
      broken,
      "{\"format\":\"kinetic-trace/1\",\"scenario\":{}}\n{\"t\":0,\"k\":\"event\"}\n{oops\n");
  const auto b = scratch.run("view " + broken + " --out " + page, "b");
  EXPECT_EQ(b.status, 2);
  EXPECT_NE(b.err.find("broken.trace:3: not a JSON line"), std::string::npos) << b.err;
  // A script end inside a string cannot end the page's script: "</" is written "<\/".
  const std::string sneaky = scratch.path("sneaky.trace");
  write_file(sneaky,
             "{\"format\":\"kinetic-trace/1\",\"scenario\":{},\"note\":\"</script><b>\"}\n");
  ASSERT_EQ(scratch.run("view " + sneaky + " --out " + page, "x").status, 0);
  EXPECT_EQ(read_file(page).find("</script><b>"), std::string::npos);
}

}  // namespace
