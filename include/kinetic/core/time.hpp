#pragma once
// Time in kinetic. A time is a double, i.e. a dyadic rational, and times are compared exactly:
// never with a tolerance. Event-interval endpoints, t_curr and query times are all such values,
// so "is t_curr inside this interval?" is an exact test (Abam, Agarwal, de Berg, Yu, Section 2).

#include <limits>

namespace kinetic {

using Time = double;

inline constexpr Time kTimeInfinity = std::numeric_limits<double>::infinity();
inline constexpr Time kTimeMinusInfinity = -std::numeric_limits<double>::infinity();

}  // namespace kinetic
