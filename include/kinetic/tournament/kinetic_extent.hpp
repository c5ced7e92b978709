#pragma once
// The kinetic bounding box (the lecture notes' "kinetic bounding box from tournaments"): a min and
// a max KineticTournament per axis sharing one simulator, as one structure. What the session and
// the Python module offer as `extent`; the command line's `extent` is the same group.

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "kinetic/core/description.hpp"
#include "kinetic/core/structure_group.hpp"
#include "kinetic/tournament/kinetic_tournament.hpp"

namespace kinetic {

class KineticExtent : public StructureGroup<KineticTournament> {
 public:
  /// What the structure is and takes (core/description.hpp): the registry, the CLI and the
  /// Python class read it.
  [[nodiscard]] static StructureDescription description();

  KineticExtent(const MotionTable& motions, Simulator& simulator, const Scheduler& scheduler) {
    for (int axis = 0; axis < motions.dimension(); ++axis) {
      add(std::make_unique<KineticTournament>(motions, simulator, scheduler, axis, Extreme::Min));
      add(std::make_unique<KineticTournament>(motions, simulator, scheduler, axis, Extreme::Max));
    }
  }

  /// The maintained extreme on `axis` (object index), nullopt when empty.
  [[nodiscard]] std::optional<std::uint32_t> extreme(int axis, Extreme which) const {
    return (*this)[2 * static_cast<std::size_t>(axis) + (which == Extreme::Max ? 1 : 0)].top();
  }
  /// Per axis, the objects with the smallest and the largest coordinate (object indices); empty
  /// when the table is.
  [[nodiscard]] std::vector<std::array<std::uint32_t, 2>> extent() const {
    std::vector<std::array<std::uint32_t, 2>> box;
    for (std::size_t k = 0; k + 1 < size(); k += 2) {
      const auto lo = (*this)[k].top();
      const auto hi = (*this)[k + 1].top();
      if (!lo || !hi) return {};
      box.push_back({*lo, *hi});
    }
    return box;
  }
};

}  // namespace kinetic
