// `kinetic run --trace` and `kinetic view`: the trace (kinetic-trace/2, docs/trace-format.md;
// read here in kinetic-trace/1's form, which the reader reads too) of every structure holds the
// header with the scenario, every event processed (as many as the stats count, external ones with
// the --events kinds and ids), every op and query answer (the same answers as --out), snapshots
// of the structure's documented kind; the limits leave events and snapshots out and say so;
// `kinetic view` makes one page with the trace inside and refuses what is not a whole, valid
// trace (cut off, damaged: docs/trace-format.md, "What the reader checks"), naming the file and
// the line, with no page.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "kinetic/run/trace_check.hpp"
#include "kinetic/scenario/scenario_json.hpp"
#include "support/cli.hpp"

namespace {

using kinetic::test::read_file;
using kinetic::test::write_file;
using nlohmann::json;

const kinetic::test::CliScratch scratch{"kinetic_cli_trace_"};

/// Applies a snapshot patch ([path, value] pairs, docs/trace-format.md) to `target`, the swap
/// events since the snapshot before (kinetic-trace/2: [axis, a, b] each) first, written here from
/// the format's definition (not the library's code), so that the tests read a trace as any reader
/// of the format would.
void apply_patch(json& target, const json& swaps, const json& patch) {
  for (const json& s : swaps) {
    json& ids = target["orders"][s[0].get<std::size_t>()]["ids"];
    const auto a = std::find(ids.begin(), ids.end(), s[1]);
    const auto b = std::find(ids.begin(), ids.end(), s[2]);
    ASSERT_TRUE(a != ids.end() && b != ids.end()) << s.dump();
    std::iter_swap(a, b);
  }
  for (const json& entry : patch) {
    json* at = &target;
    for (const json& step : entry[0])
      at = step.is_string() ? &at->at(step.get<std::string>()) : &at->at(step.get<std::size_t>());
    *at = entry[1];
  }
}

/// The lines of a file as they are.
std::vector<json> raw_lines_of(const std::string& path) {
  std::vector<json> out;
  std::istringstream in(read_file(path));
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) out.push_back(json::parse(line));
  }
  return out;
}

/// The lines of a kinetic-trace/2 file in kinetic-trace/1's form, which the reader reads too: an
/// events line made one line per event (its time the one before plus dt * 2^q, its kind and
/// axis the header's kinds' entry), a snapshot line given its time and event count, and each
/// snapshot made whole (a patch applied to the snapshot before, the swaps since first). The
/// result is a valid kinetic-trace/1 trace of the same run. Other files' lines as they are.
std::vector<json> lines_of(const std::string& path) {
  const std::vector<json> raw = raw_lines_of(path);
  if (raw.empty() || !raw[0].contains("scenario")) return raw;  // not a trace (--events, --out)
  std::vector<json> out;
  json header = raw[0];
  const json kinds = header.value("kinds", json::array());
  if (header["format"] == "kinetic-trace/2") {
    header["format"] = "kinetic-trace/1";
    header.erase("kinds");
  }
  out.push_back(header);
  json previous, swaps = json::array();
  double t = header["scenario"].value("start_time", 0.0);
  std::uint64_t events = 0;
  for (std::size_t k = 1; k < raw.size(); ++k) {
    json l = raw[k];
    if (l.value("k", "") == "events") {
      const int q = l["q"];
      if (l.contains("t")) t = l["t"];
      for (std::size_t i = 0; i < l["dt"].size(); ++i) {
        t = t + std::ldexp(static_cast<double>(l["dt"][i].get<std::int64_t>()), q);
        const json& type = kinds.at(l["kind"][i].get<std::size_t>());
        ++events;
        if (type[0] == "internal") {
          out.push_back({{"t", t}, {"k", "internal"}});
          continue;
        }
        json e = {{"t", t}, {"k", "event"}, {"kind", type[0]}, {"ids", l["ids"][i]}};
        if (type.size() > 1) e["axis"] = type[1];
        if (type[0] == "swap") swaps.push_back({type[1], l["ids"][i][0], l["ids"][i][1]});
        out.push_back(e);
      }
      continue;
    }
    if (!l.contains("t")) l["t"] = t;
    t = l["t"];
    if (l.value("k", "") == "snapshot") {
      if (!l.contains("event")) l["event"] = events;
      if (l.contains("patch")) {
        apply_patch(previous, swaps, l["patch"]);
        l.erase("patch");
        l["snapshot"] = previous;
      } else {
        previous = l["snapshot"];
      }
      swaps = json::array();
    }
    out.push_back(l);
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
    EXPECT_EQ(raw_lines_of(trace)[0]["format"], "kinetic-trace/2");
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
    EXPECT_NE(html.find("\"format\":\"kinetic-trace/2\""), std::string::npos);
    EXPECT_EQ(html.find("/*KINETIC_TRACE*/"), std::string::npos);
    // The same trace with its second snapshot damaged (an object gone from it, or one that is
    // not alive added) is refused, naming that line.
    std::string damaged;
    std::size_t damaged_line = 0, snapshots_seen = 0;
    for (std::size_t k = 0; k < t.size(); ++k) {
      json l = t[k];
      if (l.value("k", "") == "snapshot" && ++snapshots_seen == 2) {
        damaged_line = k + 1;
        json& sn = l["snapshot"];
        const json stranger = json::array({999999, 999998});
        if (sn.contains("orders")) sn["orders"][0]["ids"].erase(0);
        if (sn.contains("tops")) sn["tops"][0]["id"] = 999999;
        if (sn.contains("endpoints")) sn["endpoints"].erase(0);
        if (sn.contains("hull")) sn["hull"].push_back(999999);
        if (sn.contains("closest_pair")) sn["closest_pair"] = stranger;
        if (sn.contains("colliding_pairs")) sn["colliding_pairs"].push_back(stranger);
      }
      damaged += l.dump() + "\n";
    }
    ASSERT_GT(damaged_line, 0u);
    write_file(trace, damaged);
    const auto d = scratch.run("view " + trace + " --out " + page, "view");
    EXPECT_EQ(d.status, 2) << d.err;
    EXPECT_EQ(
        d.err.rfind("kinetic: " + trace + ":" + std::to_string(damaged_line) + ": $.snapshot.", 0),
        0u)
        << d.err;
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

std::string small_trace_of();

/// A small trace with a line of every kind but "internal" (sort, robust): two points that swap,
/// an insert, a third point swapping with one of them, a query, and the end. The ids 11, 22, 33
/// differ in two digits each, so that no changed byte makes one id another. As written
/// (kinetic-trace/2): 1 header, 2 snapshot, 3 events (swap 11 22 at 1), 4 snapshot, 5 op (insert
/// 33 at 2), 6 snapshot, 7 events (swap 11 33 at 2.75), 8 snapshot, 9 query (at 3), 10
/// snapshot, 11 end.
std::string small_trace_v2() {
  (void)small_trace_of();
  return read_file(scratch.path("small.trace"));
}

/// The small trace in kinetic-trace/1's form (lines_of): the same 11 lines, an event line for
/// each events line.
std::string small_trace() { return small_trace_of(); }

std::string small_trace_of() {
  static const std::string text = [] {
    const std::string in = scratch.path("small.json");
    write_file(in, R"({"format": "kinetic-scenario/1", "dimension": 1, "end_time": 4.0,
      "objects": [{"id": 11, "motion": [[0.0, 1.0]]}, {"id": 22, "motion": [[1.0]]}],
      "timeline": [{"time": 2.0, "op": "insert", "id": 33, "motion": [[5.5, -1.0]]},
                   {"time": 3.0, "op": "query", "query": {"type": "sorted"}}]})");
    const std::string trace = scratch.path("small.trace");
    const auto r = scratch.run("run " + in + " --structure sort --out - --trace " + trace, "small");
    EXPECT_EQ(r.status, 0) << r.err;
    std::string whole;  // every snapshot whole (the rules below edit snapshots' contents)
    for (const json& l : lines_of(trace)) whole += l.dump() + "\n";
    return whole;
  }();
  return text;
}

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::size_t begin = 0;
  for (std::size_t end; (end = text.find('\n', begin)) != std::string::npos; begin = end + 1)
    lines.push_back(text.substr(begin, end - begin));
  if (begin < text.size()) lines.push_back(text.substr(begin));
  return lines;
}

/// The JSON of every line of `text`, or nothing when a line is not JSON or the last line has no
/// newline (a trace cut off).
std::optional<std::vector<json>> json_lines(const std::string& text) {
  if (text.empty() || text.back() != '\n') return std::nullopt;
  std::vector<json> out;
  for (const std::string& line : split_lines(text)) {
    try {
      out.push_back(json::parse(line));
    } catch (const json::exception&) {
      return std::nullopt;
    }
  }
  return out;
}

/// Whether `b` differs from `a` only where kinetic-trace/1 leaves a trace free: a number that was
/// a float (a time, eps, a coordinate; whether a time still fits its place is the reader's to
/// check), an integer of the header's limits (all far above the small trace's counts).
bool free_change(const json& a, const json& b, bool in_limits = false, bool in_steps = false) {
  if (a.is_number_float() && b.is_number()) return true;
  if (in_limits && a.is_number_unsigned() && b.is_number_unsigned()) return true;
  // kinetic-trace/2: an events line's time steps and unit (whether the times still fit their
  // places is the reader's to check).
  if (in_steps && a.is_number_integer() && b.is_number_integer()) return true;
  if (a.type() != b.type()) return false;
  if (a.is_object()) {
    if (a.size() != b.size()) return false;
    for (auto it = a.begin(); it != a.end(); ++it) {
      if (!b.contains(it.key())) return false;
      if (!free_change(it.value(), b[it.key()], in_limits || it.key() == "limits",
                       it.key() == "dt" || it.key() == "q"))
        return false;
    }
    return true;
  }
  if (a.is_array()) {
    if (a.size() != b.size()) return false;
    for (std::size_t k = 0; k < a.size(); ++k)
      if (!free_change(a[k], b[k], in_limits, in_steps)) return false;
    return true;
  }
  return a == b;
}

/// Whether the damaged trace `bad` may still be a valid trace by its format, judged apart from
/// the reader: every line JSON, as many lines as `good`, and each line the same but for free
/// changes (free_change), or a header whose scenario changed into another valid scenario (a
/// number split in two makes a motion of a higher degree: the reader checks the lines against
/// the scenario, not the motions against the events).
bool may_be_valid(const std::string& good, const std::string& bad) {
  const auto a = json_lines(good);
  const auto b = json_lines(bad);
  if (!a || !b || a->size() != b->size()) return false;
  for (std::size_t k = 0; k < a->size(); ++k) {
    if (free_change((*a)[k], (*b)[k])) continue;
    if (k != 0 || !(*b)[0].is_object() || !(*b)[0].contains("scenario")) return false;
    json a0 = (*a)[0], b0 = (*b)[0];
    const std::string scenario = b0["scenario"].dump();
    a0.erase("scenario");
    b0.erase("scenario");
    if (!free_change(a0, b0)) return false;
    try {
      (void)kinetic::scenario::parse_scenario(scenario, "scenario");
    } catch (const kinetic::scenario::ScenarioError&) {
      return false;
    }
  }
  return true;
}

/// `kinetic view` on each of `traces` (one program run each, all from one shell): the outcome of
/// each, and whether its page exists afterwards. Files under `tag`.
struct ViewOutcome {
  int status = -1;
  std::string out, err;
  bool page = false;
};
/// `kinetic view` on the traces whose positions are in `which` (all when empty), each from its own
/// file TAG_K.trace, in one shell loop; the outcomes by position (the others left at -1).
std::vector<ViewOutcome> view_all(const std::vector<std::string>& traces, const std::string& tag,
                                  std::vector<std::size_t> which = {}) {
  const std::string dir = scratch.path(tag + "_");
  if (which.empty()) {
    for (std::size_t k = 0; k < traces.size(); ++k) which.push_back(k);
  }
  std::string list;
  for (const std::size_t k : which) {
    write_file(dir + std::to_string(k) + ".trace", traces[k]);
    std::remove((dir + std::to_string(k) + ".html").c_str());
    list.append(" ").append(std::to_string(k));
  }
  const std::string script = dir + "run.sh";
  write_file(script, "for k in" + list + "; do\n  \"" + std::string(KINETIC_CLI_PATH) +
                         "\" view \"" + dir + "$k.trace\" --out \"" + dir + "$k.html\" >\"" + dir +
                         "$k.out\" 2>\"" + dir + "$k.err\" </dev/null\n  echo $? >\"" + dir +
                         "$k.rc\"\ndone\n");
  EXPECT_EQ(std::system(("sh \"" + script + "\"").c_str()), 0);
  std::vector<ViewOutcome> out(traces.size());
  for (const std::size_t k : which) {
    const std::string base = dir + std::to_string(k);
    out[k].status = std::atoi(read_file(base + ".rc").c_str());
    out[k].out = read_file(base + ".out");
    out[k].err = read_file(base + ".err");
    out[k].page = std::ifstream(base + ".html").good();
    for (const char* end : {".rc", ".out", ".err", ".html"}) std::remove((base + end).c_str());
  }
  return out;
}

/// What `kinetic view` does with a trace, decided in this process by the same check
/// (kinetic::run::check_trace): exit 2 with "kinetic: " and the check's message, or 0 and a page.
ViewOutcome view_in_process(const std::string& trace, const std::string& file) {
  ViewOutcome o;
  try {
    kinetic::run::check_trace(trace, file);
    o.status = 0;
    o.page = true;
  } catch (const kinetic::run::TraceError& e) {
    o.status = 2;
    o.err = "kinetic: ";
    o.err.append(e.what()).append("\n");
    const std::string line = file + ":" + std::to_string(e.line()) + ": ";
    EXPECT_EQ(o.err.compare(9, line.size(), line), 0) << "line() is the message's line: " << o.err;
  }
  return o;
}

/// A refusal as every refusal of the CLI: exit 2, one line "kinetic: FILE:LINE: ..." (LINE a line
/// of the file), of bounded length, nothing on standard output, and no page.
::testing::AssertionResult refused_with_the_line(const ViewOutcome& o, const std::string& file,
                                                 const std::string& text) {
  if (o.status != 2) return ::testing::AssertionFailure() << "exit " << o.status << ": " << o.err;
  if (o.page) return ::testing::AssertionFailure() << "a page was written: " << o.err;
  if (!o.out.empty()) return ::testing::AssertionFailure() << "standard output: " << o.out;
  if (o.err.empty() || o.err.back() != '\n' || o.err.find('\n') + 1 != o.err.size())
    return ::testing::AssertionFailure() << "not one line: " << o.err;
  if (o.err.size() > 600) return ::testing::AssertionFailure() << "too long: " << o.err;
  const std::string prefix = "kinetic: " + file + ":";
  if (o.err.rfind(prefix, 0) != 0)
    return ::testing::AssertionFailure() << "not " << prefix << "LINE: " << o.err;
  std::size_t digits = 0, line = 0;
  while (prefix.size() + digits < o.err.size() && o.err[prefix.size() + digits] >= '0' &&
         o.err[prefix.size() + digits] <= '9' && digits < 9)
    line = 10 * line + static_cast<std::size_t>(o.err[prefix.size() + digits++] - '0');
  const std::size_t lines = std::max<std::size_t>(1, split_lines(text).size());
  if (digits == 0 || line < 1 || line > lines ||
      o.err.compare(prefix.size() + digits, 2, ": ") != 0)
    return ::testing::AssertionFailure() << "no line of the file (1 to " << lines << "): " << o.err;
  return ::testing::AssertionSuccess();
}

void refuses_every_cut_or_damage_of(const std::string& good);

// Issue 47, item 8: damaged traces were made pages. Every cut of a small trace (at every byte)
// and bytes changed at fixed positions (a fixed seed) to fixed values: each is refused with the
// file and the line, exit 2 and no page, or accepted only when it is still a valid trace by the
// format (judged apart from the reader: may_be_valid).
/// A trace broken on purpose: the line `kinetic view` must name and what its message must say.
struct Broken {
  std::string trace;
  std::size_t line;
  std::string says;  // the rule, as the message says it
};

/// `kinetic view` refuses each broken trace with its line and the rule's words, leaving the page
/// as it was; the good trace it reads, writing the page.
void expect_each_refused(const std::vector<Broken>& cases, const std::string& good,
                         const std::string& name) {
  const std::string page = scratch.path(name + ".html");
  write_file(page, "an older page");
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const Broken& c = cases[k];
    SCOPED_TRACE(c.says);
    const std::string file = scratch.path(name + "_" + std::to_string(k) + ".trace");
    write_file(file, c.trace);
    const auto r = scratch.run("view " + file + " --out " + page, name);
    ViewOutcome o{r.status, r.out, r.err, false};
    EXPECT_TRUE(refused_with_the_line(o, file, c.trace));
    EXPECT_EQ(r.err.rfind("kinetic: " + file + ":" + std::to_string(c.line) + ": ", 0), 0u)
        << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << r.err;
    EXPECT_EQ(read_file(page), "an older page") << "the page was touched";
  }
  const std::string file = scratch.path(name + "_good.trace");
  write_file(file, good);
  EXPECT_EQ(scratch.run("view " + file + " --out " + page, name).status, 0);
  EXPECT_NE(read_file(page).find("window.kineticViewer"), std::string::npos);
}

TEST(CliTrace, ViewRefusesEveryCutOrDamagedTraceWithItsLine) {
  for (const std::string& good : {small_trace_v2(), small_trace()}) {
    SCOPED_TRACE(good.substr(0, 30));
    refuses_every_cut_or_damage_of(good);
  }
}

void refuses_every_cut_or_damage_of(const std::string& good) {
  ASSERT_GT(good.size(), 500u);
  ASSERT_EQ(split_lines(good).size(), 11u) << good;
  std::vector<std::string> traces;
  std::vector<std::string> what;
  // Cuts: at every byte after the header, and in the header (where every cut leaves a line
  // without its newline) at 9 points from the empty file to the whole header.
  const std::size_t header = good.find('\n') + 1;
  for (std::size_t n = 0; n < good.size(); ++n) {
    if (n < header && n % (header / 8) != 0 && n != header - 1) continue;
    traces.push_back(good.substr(0, n));
    what.push_back("cut to " + std::to_string(n) + " bytes");
  }
  const std::size_t cuts = traces.size();
  // Changed bytes: the positions and values of a fixed generator (std::mt19937's numbers are
  // the same everywhere); the values those that make other JSON or other numbers, and the
  // neighbour of the byte.
  const std::string values = std::string("0123456789\"{}[],:.-+eE tk\n\x7f") + '\0' + '\xff';
  std::mt19937 random(47);
  for (int k = 0; k < 320; ++k) {
    const std::size_t at = random() % good.size();
    std::string bad = good;
    bad[at] = k % 4 == 0 ? static_cast<char>(bad[at] ^ 1) : values[random() % values.size()];
    if (bad == good) continue;
    traces.push_back(bad);
    what.push_back("byte " + std::to_string(at) + " made " +
                   std::to_string(unsigned(bad[at] & 0xff)));
  }
  // Every trace checked in this process by the reader `kinetic view` runs; the command itself on
  // every eighth and on every one the reader accepts, which must come out the same.
  std::vector<ViewOutcome> outcomes(traces.size());
  std::vector<std::size_t> sample;
  for (std::size_t k = 0; k < traces.size(); ++k) {
    outcomes[k] =
        view_in_process(traces[k], scratch.path("damaged_") + std::to_string(k) + ".trace");
    if (k % 8 == 0 || outcomes[k].status == 0) sample.push_back(k);
  }
  const std::vector<ViewOutcome> cli = view_all(traces, "damaged", sample);
  std::size_t cli_refused = 0;
  for (const std::size_t k : sample) {
    SCOPED_TRACE(what[k]);
    EXPECT_EQ(cli[k].status, outcomes[k].status) << cli[k].err;
    EXPECT_EQ(cli[k].err, outcomes[k].err);
    EXPECT_EQ(cli[k].out, "");
    EXPECT_EQ(cli[k].page, outcomes[k].page);
    cli_refused += cli[k].status == 2 ? 1 : 0;
  }
  EXPECT_GT(cli_refused, 50u);  // the command's refusals, not only its acceptances
  std::size_t refused = 0, accepted = 0;
  std::string accepted_what;
  for (std::size_t k = 0; k < traces.size(); ++k) {
    SCOPED_TRACE(what[k]);
    const std::string file = scratch.path("damaged_") + std::to_string(k) + ".trace";
    if (outcomes[k].status == 0) {
      ++accepted;
      accepted_what += (accepted_what.empty() ? "" : "; ") + what[k];
      EXPECT_GE(k, cuts) << "a cut trace was made a page";
      EXPECT_TRUE(may_be_valid(good, traces[k])) << "a damaged trace was made a page";
      EXPECT_TRUE(outcomes[k].page);
    } else {
      ++refused;
      EXPECT_TRUE(refused_with_the_line(outcomes[k], file, traces[k]));
    }
  }
  std::cout << "[          ] " << good.substr(0, good.find(',')) << ": " << traces.size()
            << " damaged traces (" << cuts << " cuts; " << sample.size()
            << " also through the command): refused " << refused << ", accepted as still valid "
            << accepted << " (" << accepted_what << ")\n";
}

TEST(CliTrace, ViewNamesTheRuleABrokenTraceBreaks) {
  const std::string good = small_trace();
  const std::vector<std::string> lines = split_lines(good);
  ASSERT_EQ(lines.size(), 11u) << good;
  // The small trace, line by line: 1 header, 2 snapshot, 3 event (swap 11 22 at 1), 4 snapshot,
  // 5 op (insert 33 at 2), 6 snapshot, 7 event (swap at 2.75), 8 snapshot, 9 query (at 3),
  // 10 snapshot, 11 end.
  ASSERT_EQ(json::parse(lines[2])["k"], "event");
  ASSERT_EQ(json::parse(lines[4])["k"], "op");
  ASSERT_EQ(json::parse(lines[8])["k"], "query");
  ASSERT_EQ(json::parse(lines[10])["k"], "end");
  const auto join = [](const std::vector<std::string>& ls) {
    std::string text;
    for (const std::string& l : ls) text += l + "\n";
    return text;
  };
  // The trace with line `n` (1-based) changed by `edit` on its JSON.
  const auto with = [&](std::size_t n, const std::function<void(json&)>& edit) {
    std::vector<std::string> ls = lines;
    json j = json::parse(ls[n - 1]);
    edit(j);
    ls[n - 1] = j.dump();
    return join(ls);
  };
  const auto without = [&](std::size_t from, std::size_t to) {  // lines [from, to] removed
    std::vector<std::string> ls = lines;
    ls.erase(ls.begin() + static_cast<std::ptrdiff_t>(from - 1),
             ls.begin() + static_cast<std::ptrdiff_t>(to));
    return join(ls);
  };
  const std::vector<Broken> cases{
      {"", 1, "expected a kinetic-trace header, got an empty file"},
      {good.substr(0, good.size() - 1), 11, "expected a line ending in a newline"},
      {without(11, 11), 10,
       "expected the end line ({\"k\": \"end\", ...}) last, got a \"snapshot\""},
      {without(6, 11), 5, "the trace was cut off"},
      {good + lines[10] + "\n", 12, "expected nothing after the end line"},
      {join({lines[0], "{oops"}), 2, "not a JSON line"},
      {join({lines[0], lines[1], ""}), 3, "not a JSON line"},
      {with(3, [](json& j) { j["t"] = 1e300; }), 3,
       "$.t: expected a time <= 4.0 (the scenario's end_time)"},
      {join({lines[0], lines[1], R"({"t":1e999,"k":"internal"})"}), 3, "not a JSON line"},
      {join({lines[0], lines[1], lines[2].substr(0, lines[2].size() - 1) + ",\"k\":\"event\"}"}), 3,
       "expected each key once, got key \"k\" twice"},
      {join({lines[0], std::string(100, '[') + std::string(100, ']')}), 2, "nested deeper than 64"},
      {join({lines[0], lines[1].substr(0, 3) + '\0' + lines[1].substr(4)}), 2, "a NUL byte"},
      {with(1, [](json& j) { j["format"] = "kinetic-trace/3"; }), 1,
       "not a kinetic-trace header: $.format: expected \"kinetic-trace/2\" (or the older "
       "\"kinetic-trace/1\"), got \"kinetic-trace/3\""},
      {with(1, [](json& j) { j["format"] = "kinetic-trace/2"; }), 1,
       "$.kinds: expected the event types, got no such key"},
      {with(1, [](json& j) { j["structure"] = "sorted"; }), 1,
       "$.structure: expected a structure this build offers"},
      {with(1, [](json& j) { j["scheduler"] = "fast"; }), 1, "$.scheduler: expected \"robust\""},
      {with(1, [](json& j) { j.erase("eps"); }), 1,
       "$.eps: expected the robust scheduler's precision"},
      {with(1, [](json& j) { j["eps"] = -1e-9; }), 1,
       "$.eps: expected the robust scheduler's precision"},
      {with(1, [](json& j) { j.erase("limits"); }), 1,
       "$.limits: expected an object, got no such key"},
      {with(1, [](json& j) { j["limits"]["max_events"] = -1; }), 1,
       "$.limits.max_events: expected an integer >= 0, got -1"},
      {with(1, [](json& j) { j["scenario"]["objects"][1]["id"] = 11; }), 1,
       "$.scenario.objects[1].id: duplicate id 11"},
      {with(1, [](json& j) { j["structure"] = "hull"; }), 1,
       "(the header's structure cannot run its scenario)"},
      {with(2, [](json& j) { j["k"] = "snap"; }), 2,
       "$.k: expected one of \"event\", \"internal\""},
      {with(2, [](json& j) { j["t"] = -1.0; }), 2,
       "$.t: expected a time >= 0.0 (the scenario's start_time)"},
      {with(7, [](json& j) { j["t"] = 1.5; }), 7, "$.t: expected a time >= 2.0 (the line before's"},
      {with(2, [](json& j) { j.erase("t"); }), 2,
       "$.t: expected the time (a number), got no such key"},
      {with(3, [](json& j) { j["kind"] = "flip"; }), 3, "$.kind: expected an event kind of sort"},
      {with(3, [](json& j) { j["ids"][1] = 33; }), 3,
       "$.ids[1]: expected the id of an object alive at t="},
      {with(3, [](json& j) { j["ids"] = json::array({11}); }), 3,
       "$.ids: expected two ids (a \"swap\" event)"},
      {with(3, [](json& j) { j.erase("axis"); }), 3,
       "$.axis: expected the axis of the \"swap\" event"},
      {with(3, [](json& j) { j["axis"] = 1; }), 3,
       "$.axis: expected an axis, an integer in [0, 0]"},
      {with(3,
            [](json& j) {
              j["t"] = 0.5;
              j["k"] = "external";
            }),
       3, "$.k: expected one of"},
      {with(3, [](json& j) { j["kind"] = "external"; }), 3, "$.ids: expected no ids"},
      {with(4, [](json& j) { j["event"] = 0; }), 4,
       "$.event: expected 1, the number of event lines"},
      {with(4, [](json& j) { j["t"] = 1.5; }), 4, ", the time of the line before (a snapshot is"},
      {with(4, [](json& j) { j["snapshot"]["orders"][0]["ids"] = json::array({22}); }), 4,
       "$.snapshot.orders[0].ids: expected the 2 ids of the objects alive at t="},
      {with(4,
            [](json& j) {
              j["snapshot"]["orders"][0]["ids"] = json::array({22, 22});
            }),
       4, "$.snapshot.orders[0].ids[1]: expected each id once, got id 22 again"},
      {with(4, [](json& j) { j["snapshot"].erase("orders"); }), 4,
       "$.snapshot.orders: expected an array, got no such key"},
      {with(5, [](json& j) { j["index"] = 1; }), 5,
       "$.index: expected 0: the next is timeline entry 0"},
      {with(5, [](json& j) { j["id"] = 44; }), 5, "$.id: expected 33 (timeline entry 0"},
      {with(5, [](json& j) { j["op"] = "update"; }), 5, "$.op: expected \"insert\""},
      {with(5, [](json& j) { j["k"] = "query"; }), 5,
       "$.k: expected \"op\": the next is timeline entry 0"},
      {with(5, [](json& j) { j["t"] = 2.5; }), 5,
       "$.t: expected 2.0: the time of timeline entry 0"},
      {without(6, 6), 6, "$.k: expected \"snapshot\" (one follows the op on line 5"},
      {with(9, [](json& j) { j["type"] = "max"; }), 9, "$.type: expected \"sorted\""},
      {with(9,
            [](json& j) {
              j["result"] = json::array({11, 22});
            }),
       9, "$.result: expected the 3 ids"},
      {with(9, [](json& j) { j["result"][0] = 44; }), 9,
       "$.result[0]: expected the id of an object alive"},
      {with(11, [](json& j) { j["outcome"] = "done"; }), 11, "$.outcome: expected \"completed\""},
      {with(11, [](json& j) { j["events"]["written"] = 3; }), 11,
       "$.events.written: expected 2, the event lines of the trace, got 3"},
      {with(11, [](json& j) { j["events"]["processed"] = 3; }), 11,
       "$.events.processed: expected written + left_out, 2 + 0, got 3"},
      {with(11,
            [](json& j) {
              j["events"]["left_out"] = 1;
              j["events"]["processed"] = 3;
            }),
       11, "$.events.left_out: expected 0: events are left out only beyond limits.max_events"},
      {with(11, [](json& j) { j["snapshots"]["written"] = 4; }), 11,
       "$.snapshots.written: expected 5, the snapshot lines of the trace, got 4"},
      {with(11, [](json& j) { j["snapshots"]["left_out"] = 1; }), 11,
       "$.snapshots.left_out: expected 0: snapshots are left out only once"},
      {with(11, [](json& j) { j["t"] = 3.5; }), 11,
       "$.t: expected 4.0, the scenario's end_time (a completed run's end)"},
      {without(9, 10), 9,
       "a line for timeline entry 1 (query at t=3.0) before a completed run's end"},
      {with(1, [](json& j) { j["limits"]["max_events"] = 1; }), 7,
       "$.k: expected no more event lines than limits.max_events (1)"},
      {with(1, [](json& j) { j["limits"]["max_snapshots"] = 3; }), 8,
       "$.k: expected no more snapshots: limits.max_snapshots (3)"},
  };
  expect_each_refused(cases, good, "rule");
}

// Snapshots are written as patches against the snapshot before while the patches since the last
// whole one stay below four times its size: the small run's trace has both; every patch is a list
// of [path, value] pairs whose application gives a snapshot the reader accepts (the page is made
// from the raw trace); a patch that names nothing, a patch before any whole snapshot and a line
// with both are refused, naming the line and the rule.
TEST(CliTrace, SnapshotsArePatchesAgainstTheOneBefore) {
  small_trace();  // writes small.trace
  const std::string raw = scratch.path("small.trace");
  const std::vector<json> t = raw_lines_of(raw);
  std::size_t whole = 0, patches = 0, first = 0, patched = 0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    if (t[k].value("k", "") != "snapshot") continue;
    EXPECT_NE(t[k].contains("snapshot"), t[k].contains("patch")) << t[k].dump();
    if (t[k].contains("snapshot")) {
      if (whole++ == 0) first = k;
      continue;
    }
    if (patches++ == 0 || (t[patched]["patch"].empty() && !t[k]["patch"].empty())) patched = k;
    for (const json& entry : t[k]["patch"]) {
      ASSERT_TRUE(entry.is_array() && entry.size() == 2 && entry[0].is_array()) << entry.dump();
    }
  }
  EXPECT_EQ(first, 1u) << "the first snapshot is whole";
  ASSERT_GE(whole, 1u);
  ASSERT_GE(patches, 1u) << "a swap's snapshot is a patch (the swap event makes it)";
  ASSERT_FALSE(t[patched]["patch"].empty()) << "the insert's snapshot changes its order";
  const std::string page = scratch.path("patch.html");
  EXPECT_EQ(scratch.run("view " + raw + " --out " + page, "patch").status, 0);
  // Broken patches.
  const auto broken = [&](std::size_t line, const std::function<void(json&)>& edit) {
    std::string text;
    for (std::size_t k = 0; k < t.size(); ++k) {
      json l = t[k];
      if (k == line) edit(l);
      text += l.dump() + "\n";
    }
    const std::string file = scratch.path("patch_broken.trace");
    write_file(file, text);
    return scratch.run("view " + file + " --out " + page, "patch_broken");
  };
  const auto says = [](const kinetic::test::CliOutcome& o, std::size_t line,
                       const std::string& what) {
    EXPECT_EQ(o.status, 2) << o.err;
    std::string at(1, ':');  // (GCC 12 warns wrongly on ":" + std::to_string(n) + ": ")
    at.append(std::to_string(line + 1)).append(": ");
    EXPECT_NE(o.err.find(at), std::string::npos) << o.err;
    EXPECT_NE(o.err.find(what), std::string::npos) << o.err;
  };
  says(broken(patched, [](json& l) { l["patch"][0][0][0] = "nope"; }), patched,
       "$.patch[0]: expected a [path, value] pair that applies: the path names no key \"nope\"");
  says(broken(patched,
              [](json& l) {
                l["patch"][0][0] = json::array({"orders", 0, "ids", 99});
              }),
       patched, "the path's index 99 is past the array's");
  says(broken(patched, [](json& l) { l["snapshot"] = json::object(); }), patched,
       "expected one of \"snapshot\" (the whole structure) and \"patch\" (its changes), got both");
  says(broken(first,
              [](json& l) {
                l["patch"] = json::array();
                l.erase("snapshot");
              }),
       first, "$.patch: expected no patch before a whole snapshot");
  says(broken(patched,
              [](json& l) {
                json& v = l["patch"][0][1];
                (v.is_array() ? v[0] : v) = 999999;
              }),
       patched, "expected the id of an object alive");
}

// `index` is the entry's place in the header's timeline, which is in processing order: for a
// scenario whose timeline is not in time order it differs from the file's (the writer wrote the
// file's, and the replay looked up another entry).
TEST(CliTrace, OpsAndQueriesIndexTheHeadersTimeline) {
  const std::string in = scratch.path("unsorted.json");
  write_file(in, R"({"format": "kinetic-scenario/1", "dimension": 1, "end_time": 10.0,
    "objects": [{"id": 11, "motion": [[0.0, 1.0]]}, {"id": 22, "motion": [[5.0, -1.0]]}],
    "timeline": [{"time": 6.0, "op": "query", "query": {"type": "sorted"}},
                 {"time": 2.0, "op": "insert", "id": 44, "motion": [[1.0, 0.5]]},
                 {"time": 2.0, "op": "query", "query": {"type": "max"}},
                 {"time": 4.0, "op": "remove", "id": 11}]})");
  const std::string trace = scratch.path("unsorted.trace");
  ASSERT_EQ(scratch.run("run " + in + " --structure sort --trace " + trace, "unsorted").status, 0);
  const std::vector<json> t = lines_of(trace);
  const json& timeline = t[0]["scenario"]["timeline"];
  std::size_t seen = 0;
  for (const json& l : t) {
    if (l.value("k", "") != "op" && l.value("k", "") != "query") continue;
    const json& entry = timeline[l["index"].get<std::size_t>()];
    EXPECT_EQ(l["index"], seen++) << "in processing order";
    EXPECT_EQ(entry["time"], l["t"]);
    if (l["k"] == "op") {
      EXPECT_EQ(entry["op"], l["op"]);
      EXPECT_EQ(entry["id"], l["id"]);
    } else {
      EXPECT_EQ(entry["query"]["type"], l["type"]);
    }
  }
  EXPECT_EQ(seen, 4u);
  EXPECT_EQ(scratch.run("view " + trace + " --out " + scratch.path("unsorted.html"), "v").status,
            0);
}

TEST(CliTrace, ViewRefusesWhatIsNotATrace) {
  const std::string page = scratch.path("bad.html");
  std::remove(page.c_str());
  const auto missing = scratch.run("view " + scratch.path("missing.trace") + " --out " + page, "m");
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.err.find("cannot read"), std::string::npos) << missing.err;
  const std::string empty = scratch.path("empty.trace");
  write_file(empty, "");
  const auto e = scratch.run("view " + empty + " --out " + page, "e");
  EXPECT_EQ(e.status, 2);
  EXPECT_NE(e.err.find("empty.trace:1: expected a kinetic-trace header, got an empty file"),
            std::string::npos)
      << e.err;
  const std::string scenario = scratch.path("scenario.trace");
  write_file(scenario, "{\"format\": \"kinetic-scenario/1\"}\n");
  const auto s = scratch.run("view " + scenario + " --out " + page, "s");
  EXPECT_EQ(s.status, 2);
  EXPECT_NE(s.err.find(":1: not a kinetic-trace header"), std::string::npos) << s.err;
  const std::vector<std::string> lines = split_lines(small_trace());
  const std::string broken = scratch.path("broken.trace");
  write_file(broken, lines[0] + "\n" + lines[1] + "\n{oops\n");
  const auto b = scratch.run("view " + broken + " --out " + page, "b");
  EXPECT_EQ(b.status, 2);
  EXPECT_NE(b.err.find("broken.trace:3: not a JSON line"), std::string::npos) << b.err;
  EXPECT_FALSE(std::ifstream(page).good()) << "no page for a refused trace";
  // A script end inside a string cannot end the page's script: "</" is written "<\/".
  json header = json::parse(lines[0]);
  header["note"] = "</script><b>";  // a field the format does not know: kept, not read
  std::string sneaky_text = header.dump() + "\n";
  for (std::size_t k = 1; k < lines.size(); ++k) sneaky_text += lines[k] + "\n";
  const std::string sneaky = scratch.path("sneaky.trace");
  write_file(sneaky, sneaky_text);
  const auto x = scratch.run("view " + sneaky + " --out " + page, "x");
  ASSERT_EQ(x.status, 0) << x.err;
  EXPECT_EQ(read_file(page).find("</script><b>"), std::string::npos);
  EXPECT_NE(read_file(page).find("<\\/script><b>"), std::string::npos);
}

// kinetic-trace/2's own rules (docs/trace-format.md): the header's kinds, an events line's unit,
// time steps, types and ids, and the keys of its events and snapshot lines; each refused with its
// line and the rule, on the small trace as written.
TEST(CliTrace, ViewNamesTheCompactRuleABrokenTraceBreaks) {
  const std::string good = small_trace_v2();
  const std::vector<std::string> lines = split_lines(good);
  ASSERT_EQ(lines.size(), 11u) << good;
  ASSERT_EQ(json::parse(lines[2])["k"], "events");
  ASSERT_TRUE(json::parse(lines[2]).contains("t")) << "the first batch's time is its own";
  ASSERT_EQ(json::parse(lines[6])["k"], "events");
  ASSERT_FALSE(json::parse(lines[6]).contains("t")) << "a step from the line before's time";
  ASSERT_EQ(json::parse(lines[7]), json::parse(R"({"k": "snapshot", "patch": []})"))
      << "the swap alone makes the snapshot";
  const auto with = [&](std::size_t n, const std::function<void(json&)>& edit) {
    std::string text;
    for (std::size_t k = 0; k < lines.size(); ++k) {
      json j = json::parse(lines[k]);
      if (k + 1 == n) edit(j);
      text += (k + 1 == n ? j.dump() : lines[k]) + "\n";
    }
    return text;
  };
  const std::vector<Broken> cases{
      {with(1, [](json& j) { j.erase("kinds"); }), 1,
       "$.kinds: expected the event types, got no such key"},
      {with(1, [](json& j) { j["kinds"][0] = json::array({"swap"}); }), 1,
       "$.kinds: expected the event types of sort in 1-D, \"[[\\\"swap\\\",0],"},
      {with(1, [](json& j) { j["format"] = "kinetic-trace/1"; }), 2,
       "$.t: expected the time (a number), got no such key"},
      {with(3, [](json& j) { j["q"] = 2000; }), 3,
       "$.q: expected the exponent of the time unit 2^q, an integer in [-1074, 1023]"},
      {with(3, [](json& j) { j["dt"] = json::array(); }), 3, "$.dt: expected the time steps"},
      {with(3, [](json& j) { j["dt"][0] = 0.5; }), 3,
       "$.dt[0]: expected a time step, an integer of magnitude at most 2^53"},
      {with(3, [](json& j) { j["dt"][0] = std::int64_t{1} << 60; }), 3,
       "$.dt[0]: expected a time step, an integer of magnitude at most 2^53"},
      {with(3,
            [](json& j) {
              j["q"] = 0;
              j["dt"][0] = 5;
            }),
       3, "$.dt[0]: expected a time <= 4.0 (the scenario's end_time)"},
      {with(7, [](json& j) { j["dt"][0] = -1; }), 7,
       "$.dt[0]: expected a time >= 2.0 (the line before's"},
      {with(3, [](json& j) { j["t"] = -1.0; }), 3,
       "$.t: expected a time >= 0.0 (the line before's: lines are in time order)"},
      {with(3,
            [](json& j) {
              j["kind"] = json::array({0, 0});
            }),
       3, "$.kind: expected one type per event, 1 (as dt)"},
      {with(3, [](json& j) { j["ids"] = json::array(); }), 3,
       "$.ids: expected one array of ids per event, 1 (as dt)"},
      {with(3, [](json& j) { j["kind"][0] = 3; }), 3,
       "$.kind[0]: expected an event type, a place in the header's kinds (below 3)"},
      {with(3, [](json& j) { j["kind"][0] = 1; }), 3,
       "$.ids[0]: expected no ids (an event the structure did not log: \"external\")"},
      {with(3, [](json& j) { j["ids"][0][1] = 33; }), 3,
       "$.ids[0][1]: expected the id of an object alive at t="},
      {with(3, [](json& j) { j["ids"][0] = json::array({11}); }), 3,
       "$.ids[0]: expected two ids (a \"swap\" event)"},
      {with(3, [](json& j) { j["axis"] = json::array({0}); }), 3,
       "$: expected only the keys of an events line (k, t, q, dt, kind, ids), got key \"axis\""},
      {with(4, [](json& j) { j["note"] = 1; }), 4,
       "$: expected only the keys of a snapshot line (k, t, event, snapshot, patch), got key"},
      {with(4, [](json& j) { j["event"] = 0; }), 4,
       "$.event: expected 1, the number of event lines"},
      {with(4, [](json& j) { j["t"] = 1.5; }), 4, ", the time of the line before (a snapshot is"},
      {with(5, [](json& j) { j.erase("t"); }), 5,
       "$.t: expected the time (a number), got no such key"},
      {with(8, [](json& j) { j["t"] = 2.5; }), 8,
       "$.t: expected a time >= 2.7500000002328306 (the line before's"},
      {with(1, [](json& j) { j["limits"]["max_events"] = 1; }), 7,
       "$.kind[0]: expected no more events than limits.max_events (1)"},
  };
  expect_each_refused(cases, good, "rule2");
}

// The compact trace tells the same run: its times are the events' times bit for bit (as
// --events writes them), the snapshots its patches and swaps make are those a trace without
// events (--trace-max-events 0: every patch a diff) writes, a sorted answer is the order of the
// snapshot after it, and the same run writes the same bytes.
TEST(CliTrace, TheCompactTraceTellsTheSameRun) {
  struct Run {
    std::string structure, generate;
  };
  const std::vector<Run> cases{
      {"sort", "random-linear --n 40 --queries 5 --updates 2 --inserts 2 --removes 2"},
      {"kdtree",
       "random-linear --n 60 --dimension 2 --queries 4 --query-type range --updates 2 "
       "--inserts 2 --removes 2"},
      {"range-tree", "random-linear --n 40 --dimension 2 --queries 3 --query-type range"},
      {"longest-side-kdtree",
       "random-linear --n 30 --dimension 2 --end 0.5 --queries 2 --query-type nearest"},
      {"tournament", "random-linear --n 30 --queries 3 --query-type max"},
  };
  for (const Run& c : cases) {
    SCOPED_TRACE(c.structure);
    const std::string in = scratch.path("same_" + c.structure + ".json");
    ASSERT_EQ(scratch.run("generate " + c.generate + " --seed 11 --out " + in, "gen").status, 0);
    const std::string base = scratch.path("same_" + c.structure);
    const std::string run = "run " + in + " --structure " + c.structure;
    ASSERT_EQ(scratch
                  .run(run + " --events " + base + ".events --out " + base + ".answers" +
                           " --trace " + base + ".trace",
                       "run")
                  .status,
              0);
    ASSERT_EQ(scratch.run(run + " --trace " + base + ".again", "again").status, 0);
    ASSERT_EQ(scratch.run(run + " --trace-max-events 0 --trace " + base + ".plain", "plain").status,
              0);
    EXPECT_EQ(read_file(base + ".trace"), read_file(base + ".again")) << "deterministic";
    const std::vector<json> t = lines_of(base + ".trace");
    const std::vector<json> plain = lines_of(base + ".plain");
    std::vector<json> a, b;
    for (const json& l : t)
      if (l.value("k", "") == "snapshot") a.push_back(l["snapshot"]);
    for (const json& l : plain)
      if (l.value("k", "") == "snapshot") b.push_back(l["snapshot"]);
    ASSERT_FALSE(a.empty());
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t k = 0; k < a.size(); ++k) EXPECT_EQ(a[k], b[k]) << "snapshot " << k;
    // The times: the --events lines' times, bit for bit (their text is the shortest that reads
    // back as the double).
    std::vector<double> times;
    for (const json& l : t)
      if (l.value("k", "") == "event" && l["kind"] != "external") times.push_back(l["t"]);
    const std::vector<json> logged = lines_of(base + ".events");
    ASSERT_EQ(times.size(), logged.size());
    for (std::size_t k = 0; k < times.size(); ++k) {
      EXPECT_EQ(std::bit_cast<std::uint64_t>(times[k]),
                std::bit_cast<std::uint64_t>(logged[k]["time"].get<double>()))
          << k;
    }
    std::size_t sorted = 0;
    for (std::size_t k = 0; k + 1 < t.size(); ++k) {
      if (t[k].value("k", "") != "query" || t[k]["type"] != "sorted") continue;
      ASSERT_EQ(t[k + 1]["k"], "snapshot");
      EXPECT_EQ(t[k + 1]["snapshot"]["orders"][0]["ids"], t[k]["result"]) << "line " << k + 1;
      ++sorted;
    }
    if (c.structure == "sort") {
      EXPECT_GT(sorted, 0u);
    }
  }
}

}  // namespace
