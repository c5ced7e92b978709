// `sweep-and-prune`: kinetic sweep-and-prune over moving boxes (one kinetic sort of the box
// sides per axis, the contact set kept at the swaps); query `colliding_pairs`.
#include "../registry.hpp"
#include "kinetic/sweep_and_prune/kinetic_sweep_and_prune.hpp"

namespace kinetic::run::detail {
namespace {

// The events are those of one kinetic sort of the 2n sides per axis (an insert or update changes
// two keys).
std::unique_ptr<StructureAdapter> make(const scenario::Scenario& s, SchedulerKind kind,
                                       double eps) {
  return make_structure(s, kind, eps, colliding_pairs_binding<KineticSweepAndPrune, 1>());
}

}  // namespace

template <>
StructureDescriptor descriptor<KineticSweepAndPrune>() {
  return {KineticSweepAndPrune::description(), make};
}

}  // namespace kinetic::run::detail
