#include "kinetic/oracle/oracle.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "kinetic/core/predicates.hpp"

namespace kinetic::oracle {

std::vector<std::uint32_t> sorted_at(const MotionTable& motions, int axis, Time t) {
  std::vector<std::uint32_t> order = motions.alive_indices();
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    const int s = compare_after(motions.motion(a, axis), motions.motion(b, axis), t);
    if (s != 0) return s < 0;
    return motions.id(a) < motions.id(b);
  });
  return order;
}

bool is_sorted_at(const MotionTable& motions, std::span<const std::uint32_t> order, int axis,
                  Time t) {
  if (order.size() != motions.size()) return false;
  for (std::size_t j = 0; j + 1 < order.size(); ++j) {
    if (compare_at(motions.motion(order[j], axis), motions.motion(order[j + 1], axis), t) > 0) {
      return false;
    }
  }
  return true;
}

namespace {
std::uint32_t extreme_at(const MotionTable& motions, int axis, Time t, int want) {
  const std::vector<std::uint32_t> alive = motions.alive_indices();
  assert(!alive.empty());
  std::uint32_t best = alive.front();
  for (std::uint32_t i : alive) {
    const int s = compare_at(motions.motion(i, axis), motions.motion(best, axis), t);
    if (s == want || (s == 0 && motions.id(i) < motions.id(best))) best = i;
  }
  return best;
}
}  // namespace

std::uint32_t max_at(const MotionTable& motions, int axis, Time t) {
  return extreme_at(motions, axis, t, 1);
}
std::uint32_t min_at(const MotionTable& motions, int axis, Time t) {
  return extreme_at(motions, axis, t, -1);
}

double sorting_error(const MotionTable& motions, std::span<const std::uint32_t> order, int axis,
                     Time t) {
  const std::vector<std::uint32_t> truth = sorted_at(motions, axis, t);
  assert(truth.size() == order.size());
  double err = 0.0;
  for (std::size_t i = 0; i < order.size(); ++i) {
    if (order[i] == truth[i]) continue;
    const double d = std::fabs(value_at(motions.motion(order[i], axis), t) -
                               value_at(motions.motion(truth[i], axis), t));
    err = std::max(err, d);
  }
  return err;
}

}  // namespace kinetic::oracle
