#pragma once
// The loop guard's bounds: how many events a correct run can have, at one instant and in all
// (the simulator stops a run that exceeds them: a scheduling loop). A structure states its own
// worst case (its efficiency, a KDS measure) in its description (core/description.hpp), as a
// function of what the run holds at most (RunBounds); the helpers below serve those functions.

#include <algorithm>
#include <cstdint>
#include <initializer_list>
#include <limits>

namespace kinetic {

struct LoopGuard {
  std::uint64_t max_events_per_instant = std::numeric_limits<std::uint64_t>::max();
  std::uint64_t max_events_total = std::numeric_limits<std::uint64_t>::max();
};

/// What a run holds at most, for its loop guard: objects alive at once (the initial ones plus
/// every insert), motions given (objects plus inserts and updates), the highest degree of any
/// coordinate, and the objects' dimension (a box's, not its table's).
struct RunBounds {
  std::uint64_t max_objects = 0;
  std::uint64_t motion_changes = 0;
  int max_degree = 0;
  int dimension = 0;
};

/// A structure's loop guard over a run with those bounds (StructureDescription::bound_events).
using EventBounds = LoopGuard (*)(const RunBounds& bounds);

/// The product of the factors, or the largest uint64_t when it overflows.
[[nodiscard]] inline std::uint64_t saturating_product(
    std::initializer_list<std::uint64_t> factors) {
  constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();
  std::uint64_t p = 1;
  for (const std::uint64_t f : factors) {
    if (f != 0 && p > kMax / f) return kMax;
    p *= f;
  }
  return p;
}

/// Loop-guard bounds for `copies` structures whose events are crossings of pairs among n
/// motions of degree <= max_degree, with `changes` motions given over the run (objects,
/// inserts, updates): at one instant each pair crosses at most once per structure; over a run,
/// two degree-s motions cross at most s times per pair of motion pieces.
[[nodiscard]] inline LoopGuard crossing_guard(std::uint64_t copies, std::uint64_t n,
                                              std::uint64_t changes, int max_degree) {
  const std::uint64_t s = static_cast<std::uint64_t>(std::max(1, max_degree));
  const std::uint64_t pairs = n * (n > 0 ? n - 1 : 0) / 2;
  LoopGuard g;
  g.max_events_per_instant = copies * pairs + 16;
  g.max_events_total = copies * s * (pairs + changes * n) + 16;
  return g;
}

/// The bounds of a structure whose events are those of one kinetic sort per axis (the kd-tree,
/// the range tree).
[[nodiscard]] inline LoopGuard per_axis_sort_bounds(const RunBounds& b) {
  return crossing_guard(static_cast<std::uint64_t>(b.dimension), b.max_objects, b.motion_changes,
                        b.max_degree);
}

}  // namespace kinetic
