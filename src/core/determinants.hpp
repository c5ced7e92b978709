#pragma once
// The determinants of the proximity certificates, written once for every arithmetic closed under
// +, -, * (intervals, rationals, exact polynomials, truncated Taylor polynomials): the in-circle
// determinant of four points (also of four points on lines, expanded in time) and the difference of
// two squared lengths. Private to the core (incircle.cpp: exact and filtered signs; crop.cpp: CROP
// on an in-circle certificate; incircle_lines.cpp: the same in floating point with error bounds).

#include <array>
#include <cstddef>

namespace kinetic::detail {

/// The in-circle determinant from the rows of a, b and c relative to d (x[0] = a_x - d_x,
/// y[0] = a_y - d_y, x[1] = b_x - d_x, ...): each row's lift times the minor of the other two.
template <class N>
N incircle_of_rows(const std::array<N, 3>& x, const std::array<N, 3>& y) {
  const N alift = x[0] * x[0] + y[0] * y[0];
  const N blift = x[1] * x[1] + y[1] * y[1];
  const N clift = x[2] * x[2] + y[2] * y[2];
  return N(alift * (x[1] * y[2] - y[1] * x[2]) - blift * (x[0] * y[2] - y[0] * x[2]) +
           clift * (x[0] * y[1] - y[0] * x[1]));
}

/// The in-circle determinant of a, b, c, d from their coordinates a_x, a_y, ..., d_y: > 0 when d
/// lies inside the circle through a, b, c (counter-clockwise).
template <class N>
N incircle_determinant(const std::array<N, 8>& v) {
  return incircle_of_rows<N>({N(v[0] - v[6]), N(v[2] - v[6]), N(v[4] - v[6])},
                             {N(v[1] - v[7]), N(v[3] - v[7]), N(v[5] - v[7])});
}

/// The rows of a, b and c relative to d when the four points move on lines: x_i = x0_i + x1_i s,
/// y_i = y0_i + y1_i s.
template <class N>
struct LineRows {
  std::array<N, 3> x0, y0, x1, y1;
};

/// The in-circle determinant of points on lines, a polynomial of degree 4 in s: its coefficients,
/// lowest first, written out (incircle_of_rows() on the rows above, with each lift and minor a
/// quadratic in s and their products expanded). N provides twice(), 2 x without rounding.
/// Depth, counted as MagnitudeDoubleDouble counts it (a sum's is its operands' largest plus one,
/// a product's their sum plus one), from rows of depth r: a lift 2r + 2, a minor 2r + 3, a term
/// (lift times minor) 4r + 6, a coefficient (three terms' products summed, then the terms
/// combined) 4r + 10.
template <class N>
std::array<N, 5> incircle_of_line_rows(const LineRows<N>& r) {
  using Quadratic = std::array<N, 3>;
  const auto lift = [&](std::size_t i) {
    return Quadratic{r.x0[i] * r.x0[i] + r.y0[i] * r.y0[i],
                     (r.x0[i] * r.x1[i] + r.y0[i] * r.y1[i]).twice(),
                     r.x1[i] * r.x1[i] + r.y1[i] * r.y1[i]};
  };
  const auto minor = [&](std::size_t i, std::size_t j) {  // x_i y_j - x_j y_i
    return Quadratic{
        r.x0[i] * r.y0[j] - r.x0[j] * r.y0[i],
        (r.x0[i] * r.y1[j] - r.x0[j] * r.y1[i]) + (r.x1[i] * r.y0[j] - r.x1[j] * r.y0[i]),
        r.x1[i] * r.y1[j] - r.x1[j] * r.y1[i]};
  };
  const auto product = [](const Quadratic& p, const Quadratic& q) {
    return std::array<N, 5>{p[0] * q[0], p[0] * q[1] + p[1] * q[0],
                            (p[0] * q[2] + p[1] * q[1]) + p[2] * q[0], p[1] * q[2] + p[2] * q[1],
                            p[2] * q[2]};
  };
  const std::array<N, 5> ta = product(lift(0), minor(1, 2));
  const std::array<N, 5> tb = product(lift(1), minor(0, 2));
  const std::array<N, 5> tc = product(lift(2), minor(0, 1));
  std::array<N, 5> d;
  for (std::size_t k = 0; k < 5; ++k) d[k] = (ta[k] - tb[k]) + tc[k];
  return d;
}

/// |a - b|^2 - |c - d|^2 from the coordinates a_x, a_y, b_x, ..., d_y.
template <class N>
N squared_length_difference(const std::array<N, 8>& v) {
  const N abx = v[0] - v[2], aby = v[1] - v[3], cdx = v[4] - v[6], cdy = v[5] - v[7];
  return N((abx * abx + aby * aby) - (cdx * cdx + cdy * cdy));
}

}  // namespace kinetic::detail
