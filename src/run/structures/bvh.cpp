// `bvh`: the kinetic AABB tree over moving boxes (node boxes by kinetic tournaments) with its
// kinetic separation list (the self-traversal's front); query `colliding_pairs`.
#include "../registry.hpp"
#include "kinetic/bvh/kinetic_bvh.hpp"

namespace kinetic::run::detail {
namespace {

/// The levels of the tree a trace's snapshot draws (63 nodes at most).
constexpr int kSketchLevels = 6;

/// After the contacts (the snapshot's answers), the hierarchy's top levels: per node and axis
/// the boxes bounding it, and the separation list's pairs between those nodes.
Json snapshot(KineticBvh& bvh, const AnswerContext& c) {
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
}

}  // namespace

void bind_bvh(OwnDescriptors& out) { out.push_back(with_picture<KineticBvh, snapshot>()); }

}  // namespace kinetic::run::detail
