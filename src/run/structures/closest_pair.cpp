// `closest-pair`: the kinetic closest pair of points in the plane, a kinetic tournament over the
// Delaunay triangulation's edge lengths (exact scheduler); queries `closest_pair`, and the
// triangulation's `delaunay` and `nearest`.
#include "../registry.hpp"
#include "kinetic/closest_pair/kinetic_closest_pair.hpp"

namespace kinetic::run::detail {
namespace {

Json answer(KineticClosestPair& cp, const scenario::QuerySpec& q, const AnswerContext& c) {
  if (q.type != scenario::QueryType::ClosestPair)
    return triangulation_answer(cp.triangulation(), q, c);
  const auto pair = cp.closest_pair();
  if (!pair) return Json(nullptr);
  return Json::array({c.motions.id((*pair)[0]), c.motions.id((*pair)[1])});
}

LoopGuard guard(const KineticClosestPair&, const MotionTable&, const ScenarioBounds& b) {
  // The triangulation's bounds, and the tournament's: at one instant a node is decided again
  // only when an edge below it changed or its own event came (a new decision fails strictly
  // later), so at most (flips + nodes) times the height (< 64) of events; over a run, a length
  // comparison of two edges (degree <= 4) fails at most 4 times per piece: within twice the
  // triangulation's bound.
  return triangulation_guard(b, 2 * 64, 2);
}

std::unique_ptr<StructureAdapter> make(TimelineDriver& d) {
  return make_structure(d, Binding<KineticClosestPair>{
                               answer, guard, [](KineticClosestPair& cp, const AnswerContext& c) {
                                 return answers_snapshot(cp, c, answer,
                                                         {scenario::QueryType::ClosestPair});
                               }});
}

}  // namespace

StructureDescriptor closest_pair_descriptor() {
  StructureInfo info;
  info.name = "closest-pair";
  info.description =
      "kinetic closest pair of points in the plane (a kinetic tournament over the Delaunay "
      "edges' lengths; exact scheduler only): the closest pair, and the triangulation's "
      "triangles and nearest point";
  info.queries = {scenario::QueryType::ClosestPair, scenario::QueryType::Delaunay,
                  scenario::QueryType::Nearest};
  info.event_kinds = {"pair_change", "flip", "inversion"};
  info.min_dimension = 2;
  info.max_dimension = 2;
  info.dimension_note = "points in the plane";
  info.max_degree = KineticClosestPair::kMaxDegree;
  info.degree_note =
      "its triangulation's in-circle certificates have four times the motions' degree";
  info.magnitude_log2 = KineticClosestPair::kMagnitudeLog2;
  info.magnitude_note = "its exact in-circle arithmetic takes seconds to minutes beyond";
  info.schedulers = {SchedulerKind::Exact};
  info.scheduler_note =
      "it is built on the Delaunay triangulation, whose flips need the exact order of the "
      "in-circle failures (degree 4 for lines, 8 for parabolas, beyond CROP's)";
  return {info, make};
}

}  // namespace kinetic::run::detail
