// `delaunay`: the kinetic Delaunay triangulation of points in the plane (robust scheduler for
// points on lines, exact for degree <= 2); queries `delaunay`, `nearest` (exact),
// `closest_pair`.
#include <limits>

#include "../registry.hpp"
#include "kinetic/delaunay/kinetic_delaunay.hpp"

namespace kinetic::run::detail {
namespace {

LoopGuard guard(const KineticDelaunay&, const MotionTable&, const ScenarioBounds& b) {
  return triangulation_guard(b, 1, 1);
}

std::unique_ptr<StructureAdapter> make(const scenario::Scenario& s, SchedulerKind kind,
                                       double eps) {
  return make_structure(
      s, kind, eps,
      Binding<KineticDelaunay>(guard, nullptr,
                               {scenario::QueryType::Delaunay, scenario::QueryType::ClosestPair}));
}

}  // namespace

LoopGuard triangulation_guard(const ScenarioBounds& b, std::uint64_t per_instant,
                              std::uint64_t total) {
  // A flip at one instant makes an edge that the perturbed lifting says is lower, so flips at one
  // instant end after at most as many as there are pairs of points (each edge appears once), n^2.
  // Over a run, an edge's four points' certificate (degree <= 8 per motion piece) fails at most
  // 8 times per piece: at most 8 n^4 per piece of motions, loose but finite.
  const std::uint64_t n = b.max_objects + 3;
  const std::uint64_t degree = static_cast<std::uint64_t>(std::max(1, 4 * b.max_degree));
  LoopGuard g;
  g.max_events_per_instant = saturating_product({4, n, n, per_instant});
  const std::uint64_t pieces = b.motion_changes + 1;
  const std::uint64_t all = saturating_product({degree, pieces, n, n, n, n, total});
  constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();
  g.max_events_total = all >= kMax - 16 ? kMax : all + 16;
  return g;
}

template <>
StructureDescriptor descriptor<KineticDelaunay>() {
  return {KineticDelaunay::description(), make};
}

}  // namespace kinetic::run::detail
