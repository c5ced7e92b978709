#pragma once
// The Taylor shift of a polynomial: from the coefficients of p(u) to those of p(s + u), by
// repeated synthetic division (Horner's scheme applied degree times), in whatever arithmetic the
// coefficients are: exact in GMP rationals and dyadic numbers, an enclosure in interval
// arithmetic, an approximation in plain doubles (whose error bound is the caller's: CROP's
// frame states one). Written once for all of them: the order of operations is the same in each,
// so a double shift and an interval shift of the same data make the same rounding steps.

#include <array>
#include <cstddef>

namespace kinetic::numeric {

/// q[0..degree] := the coefficients of q(s + u) in powers of u; q[i] for i > degree untouched.
/// Each step is q[i] = q[i] + s * q[i + 1] (i from degree - 1 down to k, for k = 0 .. degree - 1).
template <class T, std::size_t M>
inline void taylor_shift(std::array<T, M>& q, int degree, const T& s) {
  for (int k = 0; k < degree; ++k) {
    for (int i = degree - 1; i >= k; --i) {
      const auto j = static_cast<std::size_t>(i);
      q[j] = q[j] + s * q[j + 1];
    }
  }
}

}  // namespace kinetic::numeric
