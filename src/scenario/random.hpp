#pragma once
// The datasets' random numbers (private to the scenario layer). Determinism (docs/datasets.md):
// mt19937_64 is fully specified by the standard, while the <random> distributions and libm's
// cos/sin/pow are not, so every number is derived from the raw 64-bit outputs with +, -, *, /
// and sqrt only (correctly rounded IEEE operations).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include "kinetic/scenario/scenario.hpp"

namespace kinetic::scenario::detail {

using Rng = std::mt19937_64;

inline double uniform01(Rng& rng) { return static_cast<double>(rng() >> 11) * 0x1p-53; }  // [0, 1)
inline double uniform(Rng& rng, double lo, double hi) { return lo + (hi - lo) * uniform01(rng); }

/// Uniform in [0, m), m >= 1, without modulo bias (reject the first 2^64 mod m outputs).
inline std::size_t uniform_index(Rng& rng, std::size_t m) {
  const std::uint64_t count = m;
  const std::uint64_t threshold = (0 - count) % count;
  for (;;) {
    const std::uint64_t x = rng();
    if (x >= threshold) return static_cast<std::size_t>(x % count);
  }
}

inline std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

/// Independent streams, so that e.g. the number of queries does not change the objects: stream 0
/// (the objects) is seeded with the seed itself.
inline Rng stream(std::uint64_t seed, std::uint64_t index) {
  return index == 0 ? Rng(seed) : Rng(splitmix64(seed + 0x9e3779b97f4a7c15ULL * index));
}

/// x^(1/d) by bisection (pow is not correctly rounded, so it could differ across platforms).
inline double root(double x, int d) {
  if (d == 1) return x;
  if (d == 2) return std::sqrt(x);
  double lo = 0.0, hi = std::max(1.0, x);
  for (int iteration = 0; iteration < 200; ++iteration) {
    const double mid = lo + (hi - lo) / 2;
    double power = 1.0;
    for (int i = 0; i < d; ++i) power *= mid;
    (power <= x ? lo : hi) = mid;
  }
  return lo;
}

inline double evaluate(const std::vector<double>& c, double origin, double t) {
  const double u = t - origin;
  double value = 0.0;
  for (auto it = c.rbegin(); it != c.rend(); ++it) value = value * u + *it;
  return value;
}

/// The times of a dataset's timeline changes: `updates`, `inserts` and `removes` times drawn
/// uniformly strictly inside (start, end), sorted (stable: updates, then inserts, then removes at
/// an equal time), to be replayed so that ids are chosen among the alive ones.
inline std::vector<std::pair<double, OpKind>> plan_changes(Rng& rng, double start, double end,
                                                           std::size_t updates, std::size_t inserts,
                                                           std::size_t removes) {
  std::vector<std::pair<double, OpKind>> planned;
  const auto plan = [&](std::size_t count, OpKind op) {
    for (std::size_t i = 0; i < count; ++i) {
      double t = start;
      while (!(start < t && t < end)) t = uniform(rng, start, end);
      planned.emplace_back(t, op);
    }
  };
  plan(updates, OpKind::Update);
  plan(inserts, OpKind::Insert);
  plan(removes, OpKind::Remove);
  std::stable_sort(planned.begin(), planned.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  return planned;
}

}  // namespace kinetic::scenario::detail
