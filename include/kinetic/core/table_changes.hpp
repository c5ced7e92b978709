#pragma once
// The one order of a change between the motion table and a structure over it (the structure
// contract, docs/architecture.md): the table changes first, then the structure is told (insert,
// remove, motion_changed), then the simulator notes the external change. A structure not built
// yet is told nothing: its initialize() loads the table as it is. The session and the timeline
// driver change objects only through these three.

#include <span>

#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/polynomial.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/structure.hpp"
#include "kinetic/core/time.hpp"

namespace kinetic {

/// Object `id` joins the table, moving as `motion` from t on; `built`: the structure is told.
template <KineticStructure S>
ObjectHandle insert_object(MotionTable& table, Simulator& sim, S& structure, bool built,
                           ObjectId id, std::span<const MotionPolynomial> motion, Time t,
                           const char* where = "MotionTable::insert") {
  const ObjectHandle h = table.insert(id, motion, t, where);
  if (built) {
    structure.insert(h.index);
    sim.note_external_change();
  }
  return h;
}

/// Object h moves as `motion` from t on (a flight-plan update).
template <KineticStructure S>
void update_object(MotionTable& table, Simulator& sim, S& structure, bool built, ObjectHandle h,
                   std::span<const MotionPolynomial> motion, Time t,
                   const char* where = "MotionTable::update") {
  table.update(h, motion, t, where);
  if (built) {
    structure.motion_changed(h.index);
    sim.note_external_change();
  }
}

/// Object h leaves the table.
template <KineticStructure S>
void remove_object(MotionTable& table, Simulator& sim, S& structure, bool built, ObjectHandle h) {
  table.remove(h);
  if (built) {
    structure.remove(h.index);
    sim.note_external_change();
  }
}

}  // namespace kinetic
