#pragma once
// Fuzz support: plays the bytes as a timeline on a session (fuzz_structures, fuzz_delaunay): a
// few objects on degenerate motions (small integers, halves and quarters: equal trajectories,
// many crossings at one instant, tangencies), then advances, inserts, flight-plan updates,
// removes and queries. After every step the structure must validate(); a query is checked when
// its answer must be exact: always under the exact scheduler, under the robust one at safe
// times (no two sorted coordinates meet within 2 eps before it), never under the classic one.

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
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

/// A coefficient near the limits of double: a small integer times a power of two within 64 of
/// the largest or the smallest exponent, the largest double, or the smallest subnormal. For a
/// structure that bounds magnitudes to 2^-top <= |c| < 2^top (top > 0), one near those bounds
/// instead: +-(1 to 9) times 2^+-(top - 8 - k), k < 16.
inline double extreme(Input& in, int top = 0) {
  if (top > 0) {
    const int e = top - 8 - static_cast<int>(in.below(16));
    const double x = std::ldexp(static_cast<double>(in.below(9) + 1), in.below(2) == 0 ? e : -e);
    return in.below(2) == 0 ? x : -x;
  }
  switch (in.below(4)) {
    case 0:
      return in.below(2) == 0 ? std::numeric_limits<double>::max()
                              : -std::numeric_limits<double>::max();
    case 1:
      return std::numeric_limits<double>::denorm_min() * static_cast<double>(in.small(3));
    case 2:
      return std::ldexp(static_cast<double>(in.small(8)), 960 + static_cast<int>(in.below(60)));
    default:
      return std::ldexp(static_cast<double>(in.small(8)), -1074 + static_cast<int>(in.below(64)));
  }
}

/// A motion of degree <= 2 (<= max_degree) with small coefficients, valid from `now` (its
/// origin); when `extremes` is set, now and then a coefficient near the limits of double (near
/// 2^+-top when top > 0, with origin 0 then, so that its expansion about 0 stays within them).
inline MotionPolynomial motion(Input& in, Time now, bool extremes = false, int top = 0,
                               int max_degree = 2) {
  std::array<double, 3> c{static_cast<double>(in.small(4)), static_cast<double>(in.small(3)) / 2.0,
                          in.below(3) == 0 ? static_cast<double>(in.small(2)) / 4.0 : 0.0};
  if (max_degree < 2) c[2] = 0.0;
  bool far = false;
  if (extremes) {
    for (double& x : c) {
      if (in.below(4) == 0) {
        x = extreme(in, top);
        far = true;
      }
    }
  }
  const Time origin = in.below(2) == 0 ? now : 0.0;
  return MotionPolynomial::from(c, far && top > 0 ? 0.0 : origin);
}

/// Object `id`'s motion as the session holds it (to give another object the same motion: groups
/// of identical motions).
template <class S>
std::vector<MotionPolynomial> motion_of(const Session<S>& s, ObjectId id) {
  const MotionTable& m = s.motions();
  const std::uint32_t i = m.find(id)->index;
  std::vector<MotionPolynomial> out;
  for (int a = 0; a < m.dimension(); ++a) out.push_back(m.motion(i, a));
  return out;
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
          // Identical motions (copies) never cross: their order is the tie order for ever.
          if (m.motion(alive[i], a) == m.motion(alive[j], b)) continue;
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
  // Now and then a copy of a live object's motion (groups of identical motions: one vertex,
  // equal keys for ever), at the start, at an insert, or by an update onto a group's motion.
  const auto made = [&](const std::vector<ObjectId>& ids) {
    if (!ids.empty() && in.below(4) == 0)
      return motion_of(s, ids[in.below(static_cast<std::uint32_t>(ids.size()))]);
    return make(s.now());
  };
  const bool verbose = std::getenv("KINETIC_FUZZ_VERBOSE") != nullptr;
  const auto show = [&](const char* op, ObjectId id) {
    if (!verbose) return;
    std::fprintf(stderr, "t=%.17g %s %lld:", s.now(), op, static_cast<long long>(id));
    if (s.contains(id)) {
      for (const MotionPolynomial& p : motion_of(s, id)) {
        std::fprintf(stderr, " [o=%.17g", p.origin);
        for (int k = 0; k <= p.degree; ++k)
          std::fprintf(stderr, " %.17g", p.c[static_cast<std::size_t>(k)]);
        std::fprintf(stderr, "]");
      }
    }
    std::fprintf(stderr, "\n");
  };
  for (; next < n; ++next) {
    s.insert(next, made(s.ids()));
    show("insert", next);
  }
  for (int step = 0; step < 24 && !in.done(); ++step) {
    s.advance(s.now() + static_cast<double>(in.below(9)) / 4.0);
    const std::vector<ObjectId> ids = s.ids();
    switch (in.below(5)) {
      case 0:
        s.insert(next, made(ids));
        show("insert", next++);
        break;
      case 1:
        if (!ids.empty()) {
          const ObjectId id = ids[in.below(static_cast<std::uint32_t>(ids.size()))];
          s.update(id, made(ids));
          show("update", id);
        }
        break;
      case 2:
        if (ids.size() > 1) {
          const ObjectId id = ids[in.below(static_cast<std::uint32_t>(ids.size()))];
          s.remove(id);
          show("remove", id);
        }
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
void points(Input& in, Session<S>& s, int d, auto&& query, PlayTally& tally, bool extremes = false,
            int top = 0, int max_degree = 2) {
  play(
      in, s,
      [&](Time now) {
        std::vector<MotionPolynomial> m;
        for (int a = 0; a < d; ++a) m.push_back(motion(in, now, extremes, top, max_degree));
        return m;
      },
      query, false, tally);
}

}  // namespace kinetic::fuzz
