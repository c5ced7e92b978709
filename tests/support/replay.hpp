#pragma once
// Test support: a scenario's timeline replayed without any structure, for oracles that answer
// each query from the objects alive at its time. Header-only, tests only.

#include <map>
#include <memory>
#include <vector>

#include "kinetic/core/motion_table.hpp"
#include "kinetic/scenario/scenario.hpp"

namespace kinetic::test {

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
