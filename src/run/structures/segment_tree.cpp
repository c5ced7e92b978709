// `segment-tree`: the kinetic segment tree over moving intervals; stabbing queries.
#include "../registry.hpp"
#include "kinetic/segment_tree/kinetic_segment_tree.hpp"

namespace kinetic::run::detail {
namespace {

/// The levels of the tree a trace's snapshot holds (255 nodes at most).
constexpr int kPictureLevels = 8;

/// The maintained order R of the 2n endpoints: {"endpoints": [[id, side], ...]}, side 0 the left
/// end, 1 the right end (the endpoint table's ids are 2 id + side).
Json snapshot(KineticSegmentTree& tree, const AnswerContext& c) {
  Json endpoints = Json::array();
  for (const std::uint32_t e : tree.endpoint_sort().order()) {
    if (e == kNoIndex) continue;  // an empty slot of R's gapped layout
    const ObjectId code = tree.endpoint_table().id(e);
    endpoints.push_back(Json::array({code >> 1, code & 1}));
  }
  // The canonical sets of the top levels: each node's leaves (elementary intervals
  // [R[j], R[j+1]] of the order above) and the ids of S(v).
  Json nodes = Json::array();
  for (const KineticSegmentTree::NodeSet& n : tree.canonical_sets(kPictureLevels)) {
    Json ids = Json::array();
    for (const std::uint32_t i : n.intervals) ids.push_back(c.motions.id(i));
    nodes.push_back({{"depth", n.depth},
                     {"leaves", Json::array({n.first_leaf, n.last_leaf})},
                     {"ids", std::move(ids)}});
  }
  return {{"endpoints", std::move(endpoints)}, {"nodes", std::move(nodes)}};
}

}  // namespace

void bind_segment_tree(OwnDescriptors& out) {
  out.push_back(with_picture<KineticSegmentTree, snapshot>());
}

}  // namespace kinetic::run::detail
