#pragma once
// The in-circle certificate of four moving points in the plane (Delaunay triangulations: Guibas,
// Mitchell, Roos; CGAL's kinetic Delaunay triangulation, Russel):
//
//   incircle(a, b, c, d)(t) = det | a_x - d_x   a_y - d_y   (a_x - d_x)^2 + (a_y - d_y)^2 |
//                                 | b_x - d_x   b_y - d_y   (b_x - d_x)^2 + (b_y - d_y)^2 |
//                                 | c_x - d_x   c_y - d_y   (c_x - d_x)^2 + (c_y - d_y)^2 |
//
// > 0 when d lies strictly inside the circle through a, b, c (counter-clockwise), 0 when the four
// are co-circular (or a, b, c collinear and d on their line). For motions of degree k it is a
// polynomial of degree 4k in t (4 for lines, 8 for parabolas): beyond CROP's degree (6), so it is
// kept as its exact polynomial (ExactPolynomial::of, GMP) and scheduled by the exact scheduler
// only (Scheduler::decide). Signs at one time have a floating-point filter first.

#include <array>

#include "kinetic/core/crop.hpp"
#include "kinetic/core/ids.hpp"
#include "kinetic/core/polynomial.hpp"
#include "kinetic/core/predicates.hpp"

namespace kinetic {

class LazyTime;

/// A moving point of the plane: its two coordinates' motions (non-null, outliving the user).
struct MovingPoint2 {
  const MotionPolynomial* x = nullptr;
  const MotionPolynomial* y = nullptr;
};

class MotionTable;
/// Object `index` of a table of dimension 2, as a moving point.
[[nodiscard]] MovingPoint2 moving_point(const MotionTable& points, std::uint32_t index);
/// orient(a, b, c) of three objects of a table of dimension 2 (crop.hpp's orientation()).
[[nodiscard]] ProductCombination orientation(const MotionTable& points, std::uint32_t a,
                                             std::uint32_t b, std::uint32_t c);

/// The in-circle determinant of p[0], p[1], p[2], p[3] (a, b, c, d above).
struct InCircle {
  std::array<MovingPoint2, 4> p{};
  /// An upper bound of its degree in t: 4 times the largest degree of the motions.
  [[nodiscard]] int degree_bound() const;
};

/// sign(incircle(t)), exactly: the positions at t enclosed from their filtered values, the
/// determinant in interval arithmetic; rational arithmetic when that cannot decide.
[[nodiscard]] int sign_at(const InCircle& f, Time t, PredicateStats* stats = nullptr);

/// The sign of incircle on (t, t + delta) for every small enough delta > 0, exactly; 0 only when
/// it is the zero polynomial (four points co-circular, or collinear, for ever).
[[nodiscard]] int sign_after(const InCircle& f, Time t, PredicateStats* stats = nullptr);

/// |p[0] - p[1]|^2 - |p[2] - p[3]|^2: which of two moving segments is longer (the certificates of
/// the kinetic closest pair, a tournament over edge lengths). A polynomial of degree 2k for
/// motions of degree k, kept exactly (ExactPolynomial::of) and scheduled by the exact scheduler
/// (Scheduler::decide).
struct LengthComparison {
  std::array<MovingPoint2, 4> p{};
  /// An upper bound of its degree in t: twice the largest degree of the motions.
  [[nodiscard]] int degree_bound() const;
  /// The same polynomial as a sum of four products (crop.hpp), (x_a - x_b)^2 - (x_c - x_d)^2 +
  /// (y_a - y_b)^2 - (y_c - y_d)^2: what CROP and the classic scheduler read (motions of degree
  /// <= 3, so that the degree is at most kMaxMotionDegree).
  [[nodiscard]] ProductSum products() const {
    const auto& [a, b, c, d] = p;
    return ProductSum{{{{a.x, b.x, a.x, b.x}, {c.x, d.x, c.x, d.x}, {a.y, b.y, a.y, b.y},
                        {c.y, d.y, c.y, d.y}}},
                      4};
  }
};

/// sign(|a - b|^2 - |c - d|^2) at t, exactly (closest pairs, nearest neighbours; a fixed point is
/// a motion of degree 0): filtered positions first, rational arithmetic when they cannot decide.
[[nodiscard]] int compare_squared_distances_at(const MovingPoint2& a, const MovingPoint2& b,
                                               const MovingPoint2& c, const MovingPoint2& d,
                                               Time t);

/// True when a and b are at the same place at the exact time `now` (core/exact_time.hpp): the
/// positions enclosed over now's double bracket first, exact signs only when they overlap.
[[nodiscard]] bool coincide_at(const MovingPoint2& a, const MovingPoint2& b, LazyTime& now);

/// The symbolic perturbation that breaks co-circular ties for ever (four points whose in-circle
/// determinant is the zero polynomial, e.g. a translating integer grid): every point's lifted
/// height x^2 + y^2 is raised by an infinitesimal delta^r, r = 1 for the largest id of the four,
/// 2 for the next, ... (a lifting perturbation in the manner of Devillers and Teillaud, with the
/// ids as the order, since positions change with time). The perturbed determinant is then
/// incircle + sum_k delta^r(k) C_k, where C_k, the derivative of the determinant by p[k]'s lifted
/// height, is an orientation (a cofactor):
///   C_0 = orient(b, c, d),  C_1 = orient(c, a, d),  C_2 = orient(a, b, d),  C_3 = -orient(a, b,
///   c).
/// Its sign is incircle's when that is not the zero polynomial, else the sign of the first
/// cofactor, by decreasing id, that is not.
struct LiftingCofactor {
  ProductCombination orientation;
  int sign = 1;  ///< C_k = sign * orientation
};
[[nodiscard]] LiftingCofactor lifting_cofactor(const InCircle& f, int k);
/// The indices 0..3 of the four points by decreasing id: the order their cofactors decide in.
[[nodiscard]] std::array<int, 4> lifting_order(const std::array<ObjectId, 4>& ids);

/// The perturbed in-circle sign just after t (ids: the four points' ids); 0 only when every
/// cofactor is the zero polynomial too (the four points collinear for ever).
[[nodiscard]] int perturbed_sign_after(const InCircle& f, const std::array<ObjectId, 4>& ids,
                                       Time t, PredicateStats* stats = nullptr);
/// The same just after an exact time (core/exact_time.hpp: sign_after at a LazyTime).
[[nodiscard]] int perturbed_sign_after(const InCircle& f, const std::array<ObjectId, 4>& ids,
                                       LazyTime& now);

}  // namespace kinetic
