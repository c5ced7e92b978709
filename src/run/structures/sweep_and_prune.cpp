// `sweep-and-prune`: kinetic sweep-and-prune over moving boxes (one kinetic sort of the box
// sides per axis, the contact set kept at the swaps); query `colliding_pairs`.
#include "../registry.hpp"
#include "kinetic/sweep_and_prune/kinetic_sweep_and_prune.hpp"

namespace kinetic::run::detail {
namespace {

// The events are those of one kinetic sort of the 2n sides per axis (an insert or update changes
// two keys).
std::unique_ptr<StructureAdapter> make(TimelineDriver& d) {
  return make_structure(d, colliding_pairs_binding<KineticSweepAndPrune, 1>());
}

}  // namespace

template <>
StructureDescriptor descriptor<KineticSweepAndPrune>() {
  StructureInfo info;
  info.python_class = "SweepAndPrune";
  info.python_doc =
      "Kinetic sweep-and-prune over moving boxes (colliding_pairs()); centers (n, d, k) and"
      " half_extents (n, d).";
  info.name = "sweep-and-prune";
  info.description =
      "kinetic sweep-and-prune over moving boxes (the box sides kinetically sorted per axis, "
      "contacts begun and ended at the swaps): all pairs of boxes in contact";
  info.queries = {scenario::QueryType::CollidingPairs};
  info.objects = scenario::ObjectsAre::Boxes;
  info.min_dimension = 1;
  info.max_dimension = 3;
  info.dimension_note = "boxes in 1 to 3 dimensions";
  info.event_kinds = {"contact_begin", "contact_end"};
  return {info, make};
}

}  // namespace kinetic::run::detail
