#pragma once
// The determinants of the proximity certificates, written once for every arithmetic closed under
// +, -, * (intervals, rationals, exact polynomials, truncated Taylor polynomials): the in-circle
// determinant of four points and the difference of two squared lengths. Private to the core
// (incircle.cpp: exact and filtered signs; crop.cpp: CROP on an in-circle certificate).

#include <array>

namespace kinetic::detail {

/// The in-circle determinant of a, b, c, d from their coordinates a_x, a_y, ..., d_y: > 0 when d
/// lies inside the circle through a, b, c (counter-clockwise).
template <class N>
N incircle_determinant(const std::array<N, 8>& v) {
  const N adx = v[0] - v[6], ady = v[1] - v[7];
  const N bdx = v[2] - v[6], bdy = v[3] - v[7];
  const N cdx = v[4] - v[6], cdy = v[5] - v[7];
  const N alift = adx * adx + ady * ady;
  const N blift = bdx * bdx + bdy * bdy;
  const N clift = cdx * cdx + cdy * cdy;
  return N(alift * (bdx * cdy - bdy * cdx) - blift * (adx * cdy - ady * cdx) +
           clift * (adx * bdy - ady * bdx));
}

/// |a - b|^2 - |c - d|^2 from the coordinates a_x, a_y, b_x, ..., d_y.
template <class N>
N squared_length_difference(const std::array<N, 8>& v) {
  const N abx = v[0] - v[2], aby = v[1] - v[3], cdx = v[4] - v[6], cdy = v[5] - v[7];
  return N((abx * abx + aby * aby) - (cdx * cdx + cdy * cdy));
}

}  // namespace kinetic::detail
