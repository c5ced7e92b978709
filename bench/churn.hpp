#pragma once
// Inserts and removes alternating, n kept: the timing loop of the benches' insert / remove
// sections (bench_kdtree, bench_longest_side_kdtree, bench_segment_tree).

#include <cstddef>
#include <cstdint>
#include <vector>

#include "bench_config.hpp"
#include "kinetic/core/ids.hpp"
#include "kinetic/core/motion_table.hpp"

namespace kinetic::bench {

struct ChurnTimes {
  double insert_seconds = 0.0;  ///< CPU time in the structure's insert calls
  double remove_seconds = 0.0;  ///< CPU time in its remove calls
};

/// `changes` times: a new object with the motions make(k) (valid from t, id first_id + k) is
/// inserted, then a random live object is removed (the table first, then the structure). Only
/// the structure's calls are timed.
template <class Structure, class Make, class Rng>
ChurnTimes churn(Structure& structure, MotionTable& motions, std::size_t changes, ObjectId first_id,
                 Time t, Make&& make, Rng& rng) {
  std::vector<ObjectHandle> live;
  for (const std::uint32_t i : motions.alive_indices()) live.push_back(motions.handle(i));
  ChurnTimes out;
  for (std::size_t k = 0; k < changes; ++k) {
    const auto m = make(k);
    const ObjectHandle added = motions.insert(first_id + static_cast<ObjectId>(k), m, t);
    double c0 = cpu_now();
    structure.insert(added.index);
    out.insert_seconds += cpu_now() - c0;
    live.push_back(added);
    const std::size_t victim = rng() % live.size();
    const ObjectHandle gone = live[victim];
    live[victim] = live.back();
    live.pop_back();
    motions.remove(gone);
    c0 = cpu_now();
    structure.remove(gone.index);
    out.remove_seconds += cpu_now() - c0;
  }
  return out;
}

}  // namespace kinetic::bench
