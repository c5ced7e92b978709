// `hull`: the kinetic convex hull of points in the plane (Basch, Guibas, Hershberger); query
// `hull`. `extent` is not offered here: the contract's tie rule (the smallest id among points
// tied at an extreme) needs the points inside a vertical hull edge, which the hull does not keep;
// `--structure extent` answers it.
#include <limits>

#include "../registry.hpp"
#include "kinetic/hull/kinetic_hull.hpp"

namespace kinetic::run::detail {
namespace {

LoopGuard guard(const KineticHull&, const MotionTable&, const ScenarioBounds& b) {
  // A certificate is a test on at most 4 points (2 sides), a polynomial of degree <= 2 * 3 = 6
  // per piece of its motions: at one instant each test fails at most once, and over a run at most
  // 6 times per motion piece of each of its points. So at most 2 n^4 tests per instant and
  // 2 * 6 * 4 * changes * n^3 + 2 * 6 n^4 over a run: loose, but a scheduling loop at small n still
  // trips it (and at large n the bound saturates to none).
  const std::uint64_t n = b.max_objects;
  const std::uint64_t degree = static_cast<std::uint64_t>(std::max(1, 2 * b.max_degree));
  LoopGuard g;
  g.max_events_per_instant = saturating_product({2, n, n, n, n});
  const std::uint64_t per_instant = g.max_events_per_instant;
  const std::uint64_t changes = saturating_product({8, degree, b.motion_changes, n, n, n});
  const std::uint64_t all = saturating_product({degree, per_instant});
  constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();
  g.max_events_total = all >= kMax - 16 - changes ? kMax : all + changes + 16;
  return g;
}

std::unique_ptr<StructureAdapter> make(const scenario::Scenario& s, SchedulerKind kind,
                                       double eps) {
  return make_structure(s, kind, eps,
                        Binding<KineticHull>(guard, nullptr, {scenario::QueryType::Hull}));
}

}  // namespace

template <>
StructureDescriptor descriptor<KineticHull>() {
  return {KineticHull::description(), make};
}

}  // namespace kinetic::run::detail
