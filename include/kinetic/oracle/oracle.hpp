#pragma once
// The brute-force oracle: the true answer at any time, computed from the motions alone with exact
// comparisons. Tests, audits and experiments hold the kinetic structures against it.

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "kinetic/core/motion_table.hpp"

namespace kinetic::oracle {

/// Live objects sorted by coordinate `axis` at time t; equal values ordered as just after t, then
/// by id. O(n log n) exact comparisons.
[[nodiscard]] std::vector<std::uint32_t> sorted_at(const MotionTable& motions, int axis, Time t);

/// True when `order` lists values that are non-decreasing at t (exactly): a correct sorted order,
/// whatever it does with ties.
[[nodiscard]] bool is_sorted_at(const MotionTable& motions, std::span<const std::uint32_t> order,
                                int axis, Time t);

/// An object with the largest / smallest coordinate `axis` at t (ties: the smallest id).
/// Precondition: motions.size() > 0.
[[nodiscard]] std::uint32_t max_at(const MotionTable& motions, int axis, Time t);
[[nodiscard]] std::uint32_t min_at(const MotionTable& motions, int axis, Time t);

/// The geometric error of a maintained order (Abam, Agarwal, de Berg, Yu, Section 6):
/// err(t) = max_i |y_i(t) - z_i(t)|, y the maintained order, z the true one; values are the exact
/// ones rounded to doubles.
[[nodiscard]] double sorting_error(const MotionTable& motions, std::span<const std::uint32_t> order,
                                   int axis, Time t);

/// Live objects inside the closed box (per axis [lo, hi]) at t, ascending, compared exactly; a
/// side may be -infinity or +infinity.
[[nodiscard]] std::vector<std::uint32_t> in_box_at(const MotionTable& motions,
                                                   std::span<const std::array<double, 2>> box,
                                                   Time t);

/// Live intervals (coordinate 0 the left end, 1 the right end) containing x at t (closed),
/// ascending by index, compared exactly.
[[nodiscard]] std::vector<std::uint32_t> stab_at(const MotionTable& intervals, double x, Time t);

/// The convex hull of the live points (coordinates 0 and 1) at t: the indices of its vertices,
/// counter-clockwise from the lowest-then-leftmost, computed by Andrew's monotone chain on the
/// exact positions (rational arithmetic). Points in the relative interior of a hull edge are not
/// vertices; of coincident points only the smallest id is. Empty for no points.
[[nodiscard]] std::vector<std::uint32_t> hull_at(const MotionTable& points, Time t);

/// The same for a subset of the points (a structure's candidates).
[[nodiscard]] std::vector<std::uint32_t> hull_of_at(const MotionTable& points,
                                                    std::span<const std::uint32_t> subset, Time t);

/// The Delaunay triangulation of the live points at t by brute force (O(n^4) exact predicates, for
/// small n): the triangles (a, b, c) that turn counter-clockwise just after t with every other
/// point outside their circle just after t, ties of points co-circular for ever broken by the
/// lifting perturbation by ids (core/incircle.hpp); of points with identical motions only the
/// smallest id takes part. Each triangle counter-clockwise from its smallest id, the list sorted
/// by ids. The rule the kinetic Delaunay triangulation follows (docs/delaunay.md).
[[nodiscard]] std::vector<std::array<std::uint32_t, 3>> delaunay_at(const MotionTable& points,
                                                                    Time t);

/// The closest pair of live points at t (exact squared distances, O(n^2)): indices by ascending
/// id, the smallest pair of ids among equally close pairs. Empty for fewer than two points.
[[nodiscard]] std::optional<std::array<std::uint32_t, 2>> closest_pair_at(const MotionTable& points,
                                                                          Time t);

/// A nearest live point to q at t, exactly (ties: the smallest id). Empty for no points.
[[nodiscard]] std::optional<std::uint32_t> exact_nearest_at(const MotionTable& points,
                                                            std::array<double, 2> q, Time t);

/// The k live points nearest to q at t (all of them when fewer), by increasing distance, equal
/// distances by id: every distance compared exactly (compare_distances_at). q has the table's
/// dimension.
[[nodiscard]] std::vector<std::uint32_t> k_nearest_at(const MotionTable& points,
                                                      std::span<const double> q, std::size_t k,
                                                      Time t);

/// Every pair of live boxes (a table of core/boxes.hpp's layout) that overlap at t, closed
/// (touching counts): index pairs {a, b} with id(a) < id(b), sorted by (id(a), id(b)). Brute
/// force on the exact centers at t (rational arithmetic): O(n^2 d).
[[nodiscard]] std::vector<std::array<std::uint32_t, 2>> colliding_pairs_at(const MotionTable& boxes,
                                                                           Time t);

/// A time known to lie in [lo, hi] (lo == hi: known exactly).
struct TimeBracket {
  Time lo = 0.0;
  Time hi = 0.0;
};

/// A maximal interval of positive length within [from, to] over which two boxes overlap
/// (closed). `begin` brackets the exact time the contact starts (the exact sign of a side
/// difference changes inside it), or is {from, from} when they overlap at from; `end` likewise,
/// or {to, to}.
struct ContactInterval {
  TimeBracket begin;
  TimeBracket end;
};

/// The contact intervals of boxes a and b over [from, to], ascending: the crossings of their
/// side differences (floating-point roots, each bracketed by exact signs and bisected with
/// exact signs to width <= tolerance), and between consecutive crossings the exact overlap test
/// at one time. A contact of zero length (sides that touch at an instant and part again) is not
/// an interval and not reported.
[[nodiscard]] std::vector<ContactInterval> contact_intervals(const MotionTable& boxes,
                                                             std::uint32_t a, std::uint32_t b,
                                                             Time from, Time to, double tolerance);

/// The position of an object at t: each coordinate's exact value rounded toward zero.
[[nodiscard]] std::vector<double> position_at(const MotionTable& motions, std::uint32_t index,
                                              Time t);

/// Euclidean distance from an object at t to the point q, from the exact squared distance
/// (point_distance_at(): relative error <= 2^-50, no underflow of the squares).
[[nodiscard]] double distance_at(const MotionTable& motions, std::uint32_t index,
                                 std::span<const double> q, Time t);

/// The smallest / largest distance from a live object to q at t (floating point, as
/// distance_at()). Precondition: motions.size() > 0.
[[nodiscard]] double nearest_distance_at(const MotionTable& motions, std::span<const double> q,
                                         Time t);
[[nodiscard]] double farthest_distance_at(const MotionTable& motions, std::span<const double> q,
                                          Time t);

/// Signed distance from x to a closed disk / a simple polygon (negative inside), in floating
/// point: the brute-force reference for approximate range queries.
[[nodiscard]] double signed_distance_to_disk(std::array<double, 2> x, std::array<double, 2> center,
                                             double radius);
[[nodiscard]] double signed_distance_to_polygon(std::array<double, 2> x,
                                                std::span<const std::array<double, 2>> polygon);

}  // namespace kinetic::oracle
