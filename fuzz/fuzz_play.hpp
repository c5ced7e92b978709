#pragma once
// Fuzz support: plays the bytes as a timeline on a session (fuzz_structures, fuzz_delaunay): a
// few objects on degenerate motions (small integers, halves and quarters: equal trajectories,
// many crossings at one instant, tangencies), then advances, inserts, flight-plan updates,
// removes and queries. After every step the structure must validate(); a query is checked when
// its answer must be exact: always under the exact scheduler, under the robust one at safe
// times (no two sorted coordinates meet within 2 eps before it), never under the classic one.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz_input.hpp"
#include "kinetic/kinetic.hpp"
#include "support/crossing.hpp"

namespace kinetic::fuzz {

constexpr double kEps = 1e-9;

/// Counts of what the inputs exercised.
struct PlayTally {
  std::uint64_t steps = 0, queries_checked = 0, queries_unsafe = 0;
};

/// A motion of degree <= 2 with small coefficients, valid from `now` (its origin).
inline MotionPolynomial motion(Input& in, Time now) {
  std::array<double, 3> c{static_cast<double>(in.small(4)), static_cast<double>(in.small(3)) / 2.0,
                          in.below(3) == 0 ? static_cast<double>(in.small(2)) / 4.0 : 0.0};
  return MotionPolynomial::from(c, in.below(2) == 0 ? now : 0.0);
}

/// Safe: no two of the coordinates the structure sorts meet within [t - 2 eps, t] (`cross_axes`:
/// the segment tree sorts both ends of all intervals together).
inline bool safe(const MotionTable& m, Time t, bool cross_axes) {
  const std::vector<std::uint32_t> alive = m.alive_indices();
  const int d = m.dimension();
  for (std::size_t i = 0; i < alive.size(); ++i) {
    for (std::size_t j = 0; j < alive.size(); ++j) {
      for (int a = 0; a < d; ++a) {
        for (int b = 0; b < d; ++b) {
          if (a != b && !cross_axes) continue;
          if (i == j && a == b) continue;
          if (test::cross_within(m.motion(alive[i], a), m.motion(alive[j], b), t - 2 * kEps, t))
            return false;
        }
      }
    }
  }
  return true;
}

/// Plays the bytes on a session of S; `query` checks one query at a safe time.
template <class S, class MakeMotion, class Query>
void play(Input& in, Session<S>& s, MakeMotion&& make, Query&& query, bool cross_axes,
          PlayTally& tally) {
  const SchedulerKind kind = s.scheduler().kind();
  const bool exact_answers = kind != SchedulerKind::Classic;
  const int n = 1 + static_cast<int>(in.below(7));
  ObjectId next = 0;
  for (; next < n; ++next) s.insert(next, make(s.now()));
  for (int step = 0; step < 24 && !in.done(); ++step) {
    s.advance(s.now() + static_cast<double>(in.below(9)) / 4.0);
    const std::vector<ObjectId> ids = s.ids();
    switch (in.below(5)) {
      case 0:
        s.insert(next++, make(s.now()));
        break;
      case 1:
        if (!ids.empty())
          s.update(ids[in.below(static_cast<std::uint32_t>(ids.size()))], make(s.now()));
        break;
      case 2:
        if (ids.size() > 1) s.remove(ids[in.below(static_cast<std::uint32_t>(ids.size()))]);
        break;
      default:
        if (!exact_answers) break;
        if (kind == SchedulerKind::Exact || safe(s.motions(), s.now(), cross_axes)) {
          query();
          ++tally.queries_checked;
        } else {
          ++tally.queries_unsafe;
        }
        break;
    }
    ++tally.steps;
    if (!s.validate()) fail("validate() failed at t = " + std::to_string(s.now()));
  }
}

template <class S>
void points(Input& in, Session<S>& s, int d, auto&& query, PlayTally& tally) {
  play(
      in, s,
      [&](Time now) {
        std::vector<MotionPolynomial> m;
        for (int a = 0; a < d; ++a) m.push_back(motion(in, now));
        return m;
      },
      query, false, tally);
}

}  // namespace kinetic::fuzz
