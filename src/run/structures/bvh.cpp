// `bvh`: the kinetic AABB tree over moving boxes (node boxes by kinetic tournaments) with its
// kinetic separation list (the self-traversal's front); query `colliding_pairs`.
#include "../registry.hpp"
#include "kinetic/bvh/kinetic_bvh.hpp"

namespace kinetic::run::detail {
namespace {

/// The levels of the tree a trace's snapshot draws (63 nodes at most).
constexpr int kSketchLevels = 6;

// Every certificate compares two of the 2dn box sides; at one instant a pair of sides crosses at
// most once, and each crossing fails at most the certificates comparing those two sides (a node
// side's tournament certificate and the pair certificates watching it): loose, by a constant
// factor per axis.
std::unique_ptr<StructureAdapter> make(const scenario::Scenario& s, SchedulerKind kind,
                                       double eps) {
  Binding<KineticBvh> binding = colliding_pairs_binding<KineticBvh, 16>();
  binding.snapshot = [](KineticBvh& bvh, const AnswerContext& c) {
    // After the contacts (colliding_pairs_binding's snapshot answers), the hierarchy's top
    // levels: per node and axis the boxes bounding it.
    Json j = Json::object();
    Json nodes = Json::array();
    for (const KineticBvh::NodeSketch& n : bvh.sketch(kSketchLevels)) {
      Json sides = Json::array();
      for (const auto& [lo, hi] : n.sides)
        sides.push_back(Json::array({c.motions.id(lo), c.motions.id(hi)}));
      nodes.push_back({{"depth", n.depth}, {"sides", std::move(sides)}});
    }
    j["nodes"] = std::move(nodes);
    Json pairs = Json::array();
    for (const KineticBvh::PairSketch& p : bvh.sketch_pairs(kSketchLevels))
      pairs.push_back(Json::array({p.a, p.b, p.state}));
    j["pairs"] = std::move(pairs);
    return j;
  };
  return make_structure(s, kind, eps, binding);
}

}  // namespace

template <>
StructureDescriptor descriptor<KineticBvh>() {
  return {KineticBvh::description(), make};
}

}  // namespace kinetic::run::detail
