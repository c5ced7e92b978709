#pragma once
// The in-circle certificate of four points moving on lines, in floating point with rigorous error
// bounds: the robust Delaunay triangulation's hot path (CROP's EVENTTIME of an in-circle that
// holds at a grid point). Private to the core (crop.cpp, scheduler.cpp).
//
// The determinant of points on lines is a polynomial of degree 4 in t. At a grid point g its
// Taylor coefficients are computed once, in double, as a straight-line program (no interval
// arithmetic, no truncated-polynomial products: determinants.hpp's program), with an a-priori
// bound of every coefficient's error from the same program run on magnitudes. The search needs:
//  - signs at grid points: Horner on the coefficients, certain when |value| exceeds the bound;
//  - "positive on a span of cells": the Bernstein coefficients on the span (a Taylor shift,
//    a scaling and a binomial transform in double) all above their bound;
//  - a floating-point guess of the first root, which is only where to look.
// What it returns is CROP's own answer (the first grid point after g where the exact sign is the
// failing one: event intervals are the grid cells whose ends' exact signs differ, docs/crop.md),
// certified; when a bound cannot decide (a grid point within rounding of a root, two roots in one
// cell, a span that will not certify), it says so and CROP's general path answers.

#include <array>
#include <cstdint>
#include <optional>

#include "kinetic/core/crop.hpp"
#include "kinetic/core/incircle.hpp"

namespace kinetic::detail {

/// A polynomial p(s) = sum_k P_k s^k known through doubles: c[k] approximates the exact P_k with
/// |c[k] - P_k| <= e[k].
struct BoundedTaylor {
  std::array<double, 5> c{}, e{};
};

/// The in-circle determinant of f at t = g + s (s >= 0) as a BoundedTaylor in s. False (out
/// unspecified) when a motion is not of degree <= 1, or a magnitude is beyond 2^100 or not
/// finite (the bounds would not hold); the caller then uses the general path.
[[nodiscard]] bool incircle_of_lines_at(const InCircle& f, double g, BoundedTaylor& out);

/// The sign of the in-circle determinant of f at t when the positions' values with their error
/// bounds (any degree) certify it, else 0: the filter of sign_at(const InCircle&, ...).
[[nodiscard]] int filtered_incircle_sign(const InCircle& f, Time t);

/// The sign of p(s) at s >= 0 when the bounds certify it, else 0.
[[nodiscard]] int certified_sign(const BoundedTaylor& p, double s);

/// EVENTTIME of the certificate [holding * p > 0] searched from the grid point g on, where p's
/// exact sign at g is `holding`: g + j w for the smallest j in [1, cells] where p's exact sign at
/// g + j w is -holding, or kTimeInfinity when there is none (w: the grid's width, a power of two;
/// g + cells w: the grid point ending the window). std::nullopt when the bounds cannot certify the
/// answer. `boxes` counts the Bernstein spans examined.
[[nodiscard]] std::optional<Time> first_failure_on_grid(const BoundedTaylor& p, int holding,
                                                        double g, double w, std::int64_t cells,
                                                        std::uint64_t* boxes = nullptr);

/// crop_first_failure() (crop.hpp) given the bounded Taylor coefficients of f at lo, or nullptr:
/// the search above when it certifies, CROP's general path otherwise (and always for nullptr:
/// what the tests compare the search with).
[[nodiscard]] Time crop_first_failure(const InCircle& f, const BoundedTaylor* at_lo, int holding,
                                      Time lo, Time hi, double eps, Time t_curr, CropStats* stats);

}  // namespace kinetic::detail
