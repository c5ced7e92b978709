#pragma once
// The umbrella header: the session API, every structure, the core and the oracle. The scenario
// format and the paper experiments are not included (they need nlohmann-json; include
// kinetic/scenario/... or kinetic/experiment/... for them).

#include "kinetic/core/error.hpp"
#include "kinetic/core/geometry.hpp"
#include "kinetic/core/ids.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/polynomial.hpp"
#include "kinetic/core/preconditions.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/structure.hpp"
#include "kinetic/core/structure_group.hpp"
#include "kinetic/bvh/kinetic_bvh.hpp"
#include "kinetic/closest_pair/kinetic_closest_pair.hpp"
#include "kinetic/delaunay/kinetic_delaunay.hpp"
#include "kinetic/hull/kinetic_hull.hpp"
#include "kinetic/kdtree/kinetic_kdtree.hpp"
#include "kinetic/longest_side_kdtree/longest_side_kdtree.hpp"
#include "kinetic/oracle/oracle.hpp"
#include "kinetic/range_tree/kinetic_range_tree.hpp"
#include "kinetic/segment_tree/kinetic_segment_tree.hpp"
#include "kinetic/session/session.hpp"
#include "kinetic/sort/kinetic_sort.hpp"
#include "kinetic/sweep_and_prune/kinetic_sweep_and_prune.hpp"
#include "kinetic/tournament/kinetic_tournament.hpp"
#include "kinetic/tournament/kinetic_extent.hpp"
