#pragma once
// Test support: scenarios and their timelines made by hand, and a scenario's timeline replayed
// without any structure, for oracles that answer each query from the objects alive at its time.
// Header-only, tests only.

#include <map>
#include <memory>
#include <random>
#include <vector>

#include "kinetic/core/motion_table.hpp"
#include "kinetic/scenario/scenario.hpp"

namespace kinetic::test {

/// A scenario of points in `dimension` over [start, end], no objects, an empty timeline.
inline scenario::Scenario empty_scenario(int dimension, Time start, Time end) {
  scenario::Scenario s;
  s.dimension = dimension;
  s.start_time = start;
  s.end_time = end;
  return s;
}

/// Makes `op` a change of the objects alive (their ids in `alive`, kept up to date): the insert
/// of a new id (next_id, then advanced) when `what` is 0 or fewer than two are alive, the remove
/// of a random one (drawn from rng) when `what` is 1, else the update of a random one. The
/// caller gives an insert or an update its motion.
inline void choose_change(scenario::TimelineOp& op, int what,
                          std::vector<scenario::ObjectId>& alive, scenario::ObjectId& next_id,
                          std::mt19937_64& rng) {
  if (what == 0 || alive.size() < 2) {
    op.op = scenario::OpKind::Insert;
    op.id = next_id++;
    alive.push_back(op.id);
  } else if (what == 1) {
    const std::size_t k = rng() % alive.size();
    op.op = scenario::OpKind::Remove;
    op.id = alive[k];
    alive.erase(alive.begin() + static_cast<std::ptrdiff_t>(k));
  } else {
    op.op = scenario::OpKind::Update;
    op.id = alive[rng() % alive.size()];
  }
}

/// The objects alive at one query (ids ascending) in a table of the scenario's dimension, with
/// the query and its time.
struct QueryState {
  double time = 0.0;
  scenario::QuerySpec query;
  std::unique_ptr<MotionTable> table;
};

/// One QueryState per query of the timeline, in order (inserts, removes and updates applied).
inline std::vector<QueryState> query_states(const scenario::Scenario& s) {
  using scenario::OpKind;
  std::map<scenario::ObjectId, scenario::Motion> alive;
  for (const auto& o : s.objects) alive[o.id] = o.motion;
  std::vector<QueryState> out;
  for (const auto& op : s.timeline) {
    if (op.op == OpKind::Remove) alive.erase(op.id);
    if (op.op == OpKind::Insert || op.op == OpKind::Update) alive[op.id] = op.motion;
    if (op.op != OpKind::Query) continue;
    QueryState q{op.time, op.query, std::make_unique<MotionTable>(s.dimension)};
    for (const auto& [id, m] : alive) {
      std::vector<MotionPolynomial> p;
      for (const auto& c : m.coordinates) p.push_back(MotionPolynomial::from(c, m.origin));
      (void)q.table->insert(id, p);
    }
    out.push_back(std::move(q));
  }
  return out;
}

}  // namespace kinetic::test
