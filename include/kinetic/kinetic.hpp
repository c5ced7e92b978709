#pragma once
// The umbrella header: the session API, every structure (structures.hpp, and the classic
// closest pair and its pair tournament), the core and the oracle. The scenario format and the
// paper experiments are not included (they need nlohmann-json; include kinetic/scenario/... or
// kinetic/experiment/... for them).

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
#include "kinetic/closest_pair/kinetic_closest_pair.hpp"
#include "kinetic/closest_pair/pair_tournament.hpp"
#include "kinetic/oracle/oracle.hpp"
#include "kinetic/session/session.hpp"
#include "kinetic/structures.hpp"
