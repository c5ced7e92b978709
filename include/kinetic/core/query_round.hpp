#pragma once
// A per-query-time cache's clock: a round is one query time between changes to a structure.
// A structure counts its changes (events, inserts, removes, updates, rebuilds: anything that can
// make a cached value stale) and calls begin() at every query; entries stamped with `round` are
// current, any other stamp is stale (round 0 is never current: the first begin() starts round 1).
// Used by the longest-side kd-tree's region boxes and buckets and the kd-tree's kept runs.

#include <cstdint>
#include <limits>

#include "kinetic/core/time.hpp"

namespace kinetic {

struct QueryRound {
  std::uint64_t round = 0;
  Time time = std::numeric_limits<double>::quiet_NaN();
  std::uint64_t changes = 0;

  /// A query at t with the structure at `changes_now` changes: true when it starts a new round
  /// (another time, or a change since the last query).
  bool begin(Time t, std::uint64_t changes_now) {
    if (t == time && changes_now == changes) return false;
    ++round;
    time = t;
    changes = changes_now;
    return true;
  }
  /// The round of a query at t with `changes_now` changes is this one.
  [[nodiscard]] bool current(Time t, std::uint64_t changes_now) const {
    return t == time && changes_now == changes;
  }
};

}  // namespace kinetic
