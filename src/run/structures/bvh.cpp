// `bvh`: the kinetic AABB tree over moving boxes (node boxes by kinetic tournaments) with its
// kinetic separation list (the self-traversal's front); query `colliding_pairs`.
#include "../registry.hpp"
#include "kinetic/bvh/kinetic_bvh.hpp"

namespace kinetic::run::detail {
namespace {

Json answer(KineticBvh& bvh, const scenario::QuerySpec& q, const AnswerContext& c) {
  if (q.type != scenario::QueryType::CollidingPairs) return Json(nullptr);  // check_runnable
  Json pairs = Json::array();
  for (const auto& [a, b] : bvh.colliding_pairs(c.now)) {
    pairs.push_back(Json::array({c.motions.id(a), c.motions.id(b)}));
  }
  return pairs;
}

LoopGuard guard(const KineticBvh& bvh, const MotionTable&, const ScenarioBounds& b) {
  // Every certificate compares two of the 2dn box sides; at one instant a pair of sides crosses
  // at most once, and each crossing fails at most the certificates comparing those two sides
  // (a node side's tournament certificate and the pair certificates watching it): loose, by a
  // constant factor per axis.
  return crossing_guard(16 * static_cast<std::uint64_t>(bvh.dimension()), 2 * b.max_objects,
                        2 * b.motion_changes, b.max_degree);
}

std::unique_ptr<StructureAdapter> make(TimelineDriver& d) {
  return make_structure(d, Binding<KineticBvh>{answer, guard});
}

}  // namespace

StructureDescriptor bvh_descriptor() {
  StructureInfo info;
  info.name = "bvh";
  info.description =
      "kinetic AABB tree over moving boxes (node boxes kept by kinetic tournaments) with its "
      "kinetic separation list (node pairs expanded and collapsed at their overlap events): all "
      "pairs of boxes in contact";
  info.queries = {scenario::QueryType::CollidingPairs};
  info.objects = scenario::ObjectsAre::Boxes;
  info.min_dimension = 1;
  info.max_dimension = 3;
  info.dimension_note = "boxes in 1 to 3 dimensions";
  info.event_kinds = {"contact_begin", "contact_end"};
  return {info, make};
}

}  // namespace kinetic::run::detail
