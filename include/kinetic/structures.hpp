#pragma once
// The structures the library builds, listed once. The run layer's registry (`kinetic run
// --structure`, its help and its checks), the Python classes, the umbrella header and the test
// that the docs name every structure all read this list; a structure's description for them
// (its name, Python class, objects, dimensions, degrees, queries, schedulers) is its class's
// description() (core/description.hpp). Adding a structure: its folders, one entry here, its
// tests, bench and docs page (docs/architecture.md, "Where a new structure goes").

#include <cstddef>

#include "kinetic/bvh/kinetic_bvh.hpp"
#include "kinetic/closest_pair/kinetic_cone_closest_pair.hpp"
#include "kinetic/delaunay/kinetic_delaunay.hpp"
#include "kinetic/fat_bvh/kinetic_fat_bvh.hpp"
#include "kinetic/hull/kinetic_hull.hpp"
#include "kinetic/kdtree/kinetic_kdtree.hpp"
#include "kinetic/longest_side_kdtree/longest_side_kdtree.hpp"
#include "kinetic/range_tree/kinetic_range_tree.hpp"
#include "kinetic/segment_tree/kinetic_segment_tree.hpp"
#include "kinetic/sort/kinetic_sort.hpp"
#include "kinetic/sweep_and_prune/kinetic_sweep_and_prune.hpp"
#include "kinetic/tournament/kinetic_extent.hpp"
#include "kinetic/tournament/kinetic_tournament.hpp"

namespace kinetic {

/// A list of structure types: for_each calls f.template operator()<S>() for each S in order.
template <class... S>
struct StructureList {
  static constexpr std::size_t size = sizeof...(S);
  template <class F>
  static void for_each(F&& f) {
    (f.template operator()<S>(), ...);
  }
};

/// Every structure built, in the order `kinetic run --help` and the docs list them: the one list.
using Structures =
    StructureList<KineticSort, KineticTournament, KineticExtent, KineticKdTree, KineticRangeTree,
                  LongestSideKdTree, KineticSegmentTree, KineticHull, KineticBvh,
                  KineticFatBvh, KineticSweepAndPrune, KineticDelaunay, KineticConeClosestPair>;

}  // namespace kinetic
