#pragma once
// The structure contract: what every kinetic structure offers the framework, written once as a
// C++20 concept and static_assert'ed by every structure (lecture notes on KDS: a structure keeps
// certificates, the simulator hands it the failed one, it repairs itself and reschedules).
//
// A structure
//  - is built on a MotionTable (read through `motion(index, axis)` only), a Simulator and a
//    Scheduler, and reserves its owner tags from the simulator (Simulator::reserve_owners);
//  - initialize(): builds itself from every live object of the table at sim.now() and schedules
//    its certificates;
//  - process(event): repairs itself at a failed certificate of its own (the simulator calls it
//    statically, never through a virtual call) and says whether the maintained attribute
//    changed (EventKind::External) or not (Internal);
//  - insert(index) after the object joined the table; remove(index) after it left the table
//    (its index is not reused before the structure is told); motion_changed(index) after its
//    motion was replaced in the table (a flight-plan update); all at sim.now(). The table changes
//    first, then the structure is told, for all three;
//  - initialized(): initialize() was called (the simulator refuses to advance before);
//  - its queries throw PreconditionError when asked at a time other than sim.now(), before
//    initialize(), or after a change of the table it was not told of (TableSync), and
//    validate() is false in the last two cases;
//  - validate(): its invariants, checked against a recomputation (tests and --validate);
//  - certificates() alive now, and certificates_per_object_max(): the KDS measures "compact"
//    and "local" (lecture notes);
//  - named_counters(): its own counters by their one spelling (snake_case; the same quantity has
//    the same name in every structure, e.g. `swaps`, `node_visits`, `queries`, `rebuilds`), so
//    that reports need no per-structure code.
// Queries are not part of the contract: each structure answers its own (range, nearest, ...).

#include <concepts>
#include <cstdint>
#include <string>
#include <vector>

#include "kinetic/core/event_queue.hpp"
#include "kinetic/core/simulator.hpp"

namespace kinetic {

/// One of a structure's counters, by name.
struct NamedCounter {
  std::string name;
  std::uint64_t value = 0;
  friend bool operator==(const NamedCounter&, const NamedCounter&) = default;
};
using NamedCounters = std::vector<NamedCounter>;

template <class S>
concept KineticStructure = requires(S& s, const S& cs, const Event& event, std::uint32_t index) {
  { s.initialize() } -> std::same_as<void>;
  { s.process(event) } -> std::same_as<EventKind>;
  { s.insert(index) } -> std::same_as<void>;
  { s.remove(index) } -> std::same_as<void>;
  { s.motion_changed(index) } -> std::same_as<void>;
  { cs.initialized() } -> std::same_as<bool>;
  { cs.validate() } -> std::same_as<bool>;
  { cs.certificates() } -> std::convertible_to<std::uint64_t>;
  { cs.certificates_per_object_max() } -> std::convertible_to<std::uint64_t>;
  { cs.named_counters() } -> std::same_as<NamedCounters>;
};

/// Adds `more` to `into`, summing counters of the same name (in the order they first appear):
/// the counters of a group of sub-structures.
inline void accumulate(NamedCounters& into, const NamedCounters& more) {
  for (const NamedCounter& c : more) {
    bool found = false;
    for (NamedCounter& d : into) {
      if (d.name == c.name) {
        d.value += c.value;
        found = true;
        break;
      }
    }
    if (!found) into.push_back(c);
  }
}

}  // namespace kinetic
