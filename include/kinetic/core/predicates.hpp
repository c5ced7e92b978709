#pragma once
// Exact sign decisions on polynomial motions. The scenario's numbers are the exact truth, so
// "is a(t) < b(t)?" has one right answer. Every sign decision here goes through three stages:
//  1. plain Horner in floating point with a rigorous a-priori error bound (evaluate_filtered,
//     evaluate_difference_filtered);
//  2. when that bound cannot separate the value from zero, compensated Horner (error-free
//     transformations, twice the working precision) with its own rigorous bound
//     (evaluate_compensated, evaluate_difference_compensated);
//  3. when that cannot either, exact dyadic arithmetic (GMP integers scaled by powers of two).
// Every stage answers only when it is certain, so the sign returned is the exact one whichever
// stage decides it.

#include <cstdint>
#include <optional>
#include <span>

#include "kinetic/core/polynomial.hpp"

namespace kinetic {

/// How often the filter decided and how often the exact fallback was needed.
struct PredicateStats {
  std::uint64_t filtered = 0;     ///< decisions taken by the floating-point filters (stages 1, 2)
  std::uint64_t compensated = 0;  ///< of those, decisions taken by the compensated stage 2
  std::uint64_t exact = 0;        ///< decisions that needed exact (GMP) arithmetic
};

/// sign(p(t)) in {-1, 0, +1}, exactly.
[[nodiscard]] int sign_at(const MotionPolynomial& p, Time t, PredicateStats* stats = nullptr);

/// sign(a(t) - b(t)) in {-1, 0, +1}, exactly.
[[nodiscard]] int compare_at(const MotionPolynomial& a, const MotionPolynomial& b, Time t,
                             PredicateStats* stats = nullptr);

/// sign(p(t) - x) in {-1, 0, +1}, exactly, for a constant x (a box side, a query point): p(t) in
/// double with the rigorous bound of evaluate_filtered() first (|value - p(t)| <= error, and
/// x - value is rounded with a relative error <= 2^-53, so (x - value)(1 - 2^-52) > error proves
/// x > p(t)); compare_at() decides only what this cannot. The first stage is not counted in
/// `stats`.
[[nodiscard]] int compare_at_value(const MotionPolynomial& p, double x, Time t,
                                   PredicateStats* stats = nullptr);

/// A point's coordinates at one time in double, each with the rigorous bound of
/// evaluate_filtered(): for a query that compares many points at one t, each evaluated once.
struct FilteredPoint {
  FilteredValue x, y;
};
[[nodiscard]] FilteredPoint filtered_point(const MotionPolynomial& x, const MotionPolynomial& y,
                                           Time t);
/// sign(a - b) when the bounds decide it, else 0 (then compare_at() decides).
[[nodiscard]] int filtered_compare(const FilteredValue& a, const FilteredValue& b);
/// sign(orient(a, b, c)) = sign((b.x - a.x)(c.y - a.y) - (b.y - a.y)(c.x - a.x)) when the bounds
/// decide it (interval arithmetic, outward rounding), else 0 (then an exact orientation of the
/// motions decides: sign_at(orientation(...), t) in crop.hpp).
[[nodiscard]] int filtered_orientation(const FilteredPoint& a, const FilteredPoint& b,
                                       const FilteredPoint& c);

/// The order of a and b just after t: sign(a - b) on (t, t + delta) for every small enough
/// delta > 0, exactly. 0 only when a and b are the same polynomial function.
[[nodiscard]] int compare_after(const MotionPolynomial& a, const MotionPolynomial& b, Time t,
                                PredicateStats* stats = nullptr);

/// Searches [lo, hi] (hi may be +infinity) for a time where a(t) < b(t) and returns one, with
/// a(t) < b(t) certified exactly at the returned time; nullopt when none was found. The search
/// probes the ends, the behaviour at infinity and every floating-point critical point of a - b,
/// so a dip below zero narrower than the rounding of those critical points can be missed.
[[nodiscard]] std::optional<Time> find_time_below(const MotionPolynomial& a,
                                                  const MotionPolynomial& b, Time lo, Time hi);

/// The exact value of p(t), rounded toward zero to a double (for reports and oracles that need a
/// value, e.g. geometric errors; decisions use the predicates above).
[[nodiscard]] double value_at(const MotionPolynomial& p, Time t);

/// The Euclidean distance from the point with coordinates point[k](t) to q (point.size() ==
/// q.size()), computed from the exact squared distance: no cancellation inside the motions, no
/// underflow or overflow of the squares. Relative error at most 2^-50 when the distance is at
/// least DBL_MIN (2.2e-308); below that an absolute error of at most DBL_MIN * 2^-50. For
/// decisions where a filtered distance is too coarse (coefficients far larger than the
/// coordinates), and for oracles. Costs rational arithmetic: not for hot paths.
[[nodiscard]] double point_distance_at(std::span<const MotionPolynomial* const> point,
                                       std::span<const double> q, Time t);

/// sign(|a(t) - q| - |b(t) - q|) for the points with coordinates a[k](t) and b[k](t) (a, b and q
/// of one size), exactly: interval arithmetic on the filtered coordinates first, rational
/// arithmetic when that cannot decide.
[[nodiscard]] int compare_distances_at(std::span<const MotionPolynomial* const> a,
                                       std::span<const MotionPolynomial* const> b,
                                       std::span<const double> q, Time t);

}  // namespace kinetic
