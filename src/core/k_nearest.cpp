#include "kinetic/core/k_nearest.hpp"

#include <array>
#include <cassert>

#include "kinetic/core/predicates.hpp"

namespace kinetic {

int NearestCandidates::compare_object_distances(const MotionTable& table, std::uint32_t a,
                                                std::uint32_t b, std::span<const double> q,
                                                Time t) {
  const auto d = static_cast<std::size_t>(table.dimension());
  assert(q.size() == d && d <= 64);
  std::array<const MotionPolynomial*, 64> ma{}, mb{};
  for (std::size_t axis = 0; axis < d; ++axis) {
    ma[axis] = &table.motion(a, static_cast<int>(axis));
    mb[axis] = &table.motion(b, static_cast<int>(axis));
  }
  return compare_distances_at(std::span(ma.data(), d), std::span(mb.data(), d), q, t);
}

}  // namespace kinetic
