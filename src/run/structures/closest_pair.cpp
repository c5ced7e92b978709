// `closest-pair`: the kinetic closest pair of points in the plane from cones (after Basch, Guibas
// and Zhang: each point's candidate in eight cones kept with kinetic sorted orders, a kinetic
// tournament over the candidates' lengths), under every scheduler (robust by default); query
// `closest_pair`. The Delaunay-based closest pair (KineticClosestPair, exact only) is the
// library's alternative, and `delaunay` answers `closest_pair` too.
#include "../registry.hpp"
#include "kinetic/closest_pair/kinetic_cone_closest_pair.hpp"

namespace kinetic::run::detail {
namespace {

LoopGuard guard(const KineticConeClosestPair&, const MotionTable& motions,
                const ScenarioBounds& b) {
  // The eight orders' swaps are crossings of pairs along eight directions. A swap changes at
  // most n + 2 candidates (the reverse list of the point passed, and the two swapped), and each
  // changed candidate and each length event re-decides at most the height of the tournament
  // (< 64) of nodes, each of which fails at most once per instant (a new decision fails
  // strictly later) and, over a run, at most 6 times per piece of motion (a length comparison
  // has degree <= 6).
  const LoopGuard swaps = crossing_guard(8, b.max_objects, b.motion_changes, b.max_degree);
  const std::uint64_t n = std::max<std::uint64_t>(1, b.max_objects);
  const std::uint64_t nodes = 8 * n;
  (void)motions;
  LoopGuard g;
  g.max_events_per_instant =
      saturating_product({swaps.max_events_per_instant, (n + 2) * 64 + 1}) + nodes * 64;
  g.max_events_total = saturating_product({swaps.max_events_total, (n + 2) * 64 * 6 + 1}) +
                       saturating_product({nodes, 64, 6, b.motion_changes + 1});
  return g;
}

std::unique_ptr<StructureAdapter> make(const scenario::Scenario& s, SchedulerKind kind,
                                       double eps) {
  return make_structure(
      s, kind, eps,
      Binding<KineticConeClosestPair>(guard, nullptr, {scenario::QueryType::ClosestPair}));
}

}  // namespace

template <>
StructureDescriptor descriptor<KineticConeClosestPair>() {
  return {KineticConeClosestPair::description(), make};
}

}  // namespace kinetic::run::detail
