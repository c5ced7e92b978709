#pragma once
// The doubles in order: each double's rank among the doubles as an integer, the next double up or
// down, adjacency and the midpoint by rank, without the library's nextafter call. Private to the
// core: the brackets of exact times (exact_time.cpp, lazy_time.cpp) and the floating-point root
// narrowing, whose steps are one double, then doubling.

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

namespace kinetic::numeric {

/// The doubles in order as integers: -inf, ..., -0 and +0 (both 0), ..., +inf (x not NaN).
inline std::int64_t ordinal(double x) {
  const auto bits = std::bit_cast<std::int64_t>(x);
  return bits >= 0 ? bits : -(bits & std::numeric_limits<std::int64_t>::max());
}

/// The double of rank k (the inverse of ordinal(), +0 for 0).
inline double from_ordinal(std::int64_t k) {
  const std::int64_t bits = k >= 0 ? k : (-k | std::numeric_limits<std::int64_t>::min());
  return std::bit_cast<double>(bits);
}

/// The double next to x towards +infinity (up) or -infinity (!up); x finite or infinite, not
/// NaN; an infinity towards itself stays (std::nextafter(x, +-inf), without the library call).
inline double next_double(double x, bool up) {
  if (x == 0.0) {
    return up ? std::numeric_limits<double>::denorm_min()
              : -std::numeric_limits<double>::denorm_min();
  }
  if (std::isinf(x)) {
    return (x > 0.0) == up ? x : std::copysign(std::numeric_limits<double>::max(), x);
  }
  auto bits = std::bit_cast<std::uint64_t>(x);
  bits += ((x > 0.0) == up) ? 1 : static_cast<std::uint64_t>(-1);
  return std::bit_cast<double>(bits);
}

/// True when b is at most one double above a.
inline bool adjacent(double a, double b) { return !(b > next_double(a, true)); }

/// The double halfway between a and b (a < b, both finite) in the order of the doubles: halving
/// the doubles between them, so that at most 64 halvings reach adjacent doubles whatever their
/// magnitudes (an arithmetic midpoint takes one halving per binade: about 2,000 from 1e-300 to
/// 1e300).
inline double ordinal_midpoint(double a, double b) {
  const std::int64_t i = ordinal(a), j = ordinal(b);
  // Halves first: j - i overflows when a and b are huge and of opposite signs.
  return from_ordinal(i / 2 + j / 2 + (i % 2 + j % 2) / 2);
}

}  // namespace kinetic::numeric
