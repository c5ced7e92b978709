#pragma once
// CROP: certified root isolation in the model of Abam, Agarwal, de Berg, Yu, Section 2.
//
// For f(t) = upper(t) - lower(t), the exact difference of two motions (different origins are
// handled exactly: nothing is rounded into a copy of f), over a window [lo, hi], CROP returns
//  (A1) disjoint open intervals (lambda, rho) of width <= eps covering every real root of f in
//       the window;
//  (A2) the sign of f between consecutive intervals (the exact signs at every endpoint);
//  (A3) the same result for the same f, window and eps, bit for bit;
//  (A4) only the event intervals (sign(f(lambda)) != sign(f(rho))); turbulent intervals, where f
//       may have roots but ends with the sign it started with, are dropped.
// Interval endpoints are doubles, so "is t_curr inside this interval?" is an exact comparison.
//
// How (docs/crop.md has the details):
//  - Every interval endpoint lies on the grid G = {(j + 1/2) w : j integer}, w the largest power
//    of two <= eps (so widths are w, or less near a root exactly on a grid point), unless f
//    vanishes exactly at a grid point g, where the interval is (pred(g), succ(g)) widened to the
//    nearest doubles where f != 0.
//  - Isolation: Descartes' rule of signs on Bernstein coefficients computed in interval
//    arithmetic with outward rounding (a rigorous enclosure of the exact coefficients), with
//    subdivision on grid points; a certified single sign change is located by a floating-point
//    root guess verified by exact signs, or by bisection over grid indices.
//  - Every sign that is reported is exact: the floating-point filter of predicates.hpp first,
//    GMP only when the filter cannot decide.
// Supported degree: up to kMaxMotionDegree (6) for each motion.

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "kinetic/core/polynomial.hpp"
#include "kinetic/core/predicates.hpp"

namespace kinetic {

/// One interval of a CROP result with the exact signs of f at its ends (never 0).
struct CropInterval {
  Time lambda = 0.0;
  Time rho = 0.0;
  std::int8_t sign_left = 0;   ///< sign of f at lambda
  std::int8_t sign_right = 0;  ///< sign of f at rho
  [[nodiscard]] bool is_event() const { return sign_left != sign_right; }
};

struct CropResult {
  /// The event intervals (A4), ascending and disjoint. Each contains a root where f changes
  /// sign, so there are at most kMaxMotionDegree of them.
  std::array<CropInterval, kMaxMotionDegree> events{};
  int count = 0;
  /// Turbulent intervals found (dropped, A4); crop() can list them for tests.
  int turbulent_count = 0;
  /// Sign of f at window_lo, i.e. before the first interval: the sign the paper calls
  /// chi(rho_0), rho_0 = -infinity, as seen from the window. 0 only when f is identically zero.
  int sign_first = 0;
  /// True when upper - lower is the zero polynomial (no roots, no sign).
  bool identically_zero = false;
  /// The window actually searched: [lo, hi] widened outward to the nearest grid points (at least
  /// one cell when lo == hi), and
  /// then by whole grid cells while f vanishes exactly at an end (so that f != 0 at both ends;
  /// at most kMaxMotionDegree + 1 cells each side).
  Time window_lo = 0.0, window_hi = 0.0;

  [[nodiscard]] const CropInterval* begin() const { return events.data(); }
  [[nodiscard]] const CropInterval* end() const { return events.data() + count; }
};

/// Work counters of CROP (added to, never reset).
struct CropStats {
  std::uint64_t calls = 0;
  std::uint64_t bernstein_boxes = 0;  ///< subdivision intervals examined
  std::uint64_t exact_boxes = 0;      ///< boxes whose Bernstein signs needed GMP
  std::uint64_t fast_path = 0;        ///< calls finished by the closed-form / guess fast path
  /// In-circle searches from a grid point finished in floating point with error bounds (points
  /// on lines), without the general path.
  std::uint64_t bounded_float = 0;
  PredicateStats predicates;  ///< exact sign decisions (filter vs GMP fallback)
};

/// The grid spacing used for precision eps: the largest power of two <= eps.
/// Precondition: eps > 0 and finite.
[[nodiscard]] double crop_grid_width(double eps);
/// The grid point of precision eps at or before t: the largest (j + 1/2) w <= t, w =
/// crop_grid_width(eps), exactly. Precondition: |t| < 2^52 w (crop_precision_supported).
[[nodiscard]] Time crop_grid_floor(Time t, double eps);

/// Checks that eps can be honoured on [lo, hi]: the grid points there must be representable and
/// a cell must hold the interval around a root on a grid point, i.e.
/// w >= (kMaxMotionDegree + 2) ulp(max(|lo|, |hi|)). Returns false otherwise (the caller reports
/// the error).
[[nodiscard]] bool crop_precision_supported(double eps, Time lo, Time hi);

/// CROP(upper - lower) over [lo, hi] with precision eps. Preconditions: lo <= hi, both finite,
/// crop_precision_supported(eps, lo, hi). When `all_intervals` is given (tests), every interval
/// found, event and turbulent, is appended to it in ascending order: together they cover every
/// root of f in [lo, hi] (A1).
[[nodiscard]] CropResult crop(const MotionPolynomial& upper, const MotionPolynomial& lower, Time lo,
                              Time hi, double eps, CropStats* stats = nullptr,
                              std::vector<CropInterval>* all_intervals = nullptr);

/// event_time(crop(upper, lower, lo, hi, eps, stats), t_curr): the robust scheduler's failure
/// time of the certificate watching upper - lower, with the same value and the same counts in
/// `stats`. The lean paths of crop() (linear certificates) keep their result in a smaller object
/// here instead of a CropResult. Preconditions as for crop().
[[nodiscard]] Time crop_event_time(const MotionPolynomial& upper, const MotionPolynomial& lower,
                                   Time lo, Time hi, double eps, Time t_curr,
                                   CropStats* stats = nullptr);

/// f = plus[0] + plus[1] - minus[0] - minus[1], the exact signed sum of four motions with any
/// origins (e.g. the difference of two side lengths x_j - x_i and y_l - y_k: plus = {x_j, y_k},
/// minus = {x_i, y_l}). Nothing is rounded into a copy of f: every sign below is the exact sign
/// of this sum. The pointers must be non-null and outlive the calls.
struct MotionCombination {
  std::array<const MotionPolynomial*, 2> plus{};
  std::array<const MotionPolynomial*, 2> minus{};
};

/// CROP(f) for a combination: (A1)-(A4) as for crop(upper, lower, ...), on the exact f. Only the
/// general path (interval Bernstein/Descartes on an enclosure of f's Taylor coefficients, exact
/// signs by a floating-point filter on that enclosure, then GMP on the exact sum).
[[nodiscard]] CropResult crop(const MotionCombination& f, Time lo, Time hi, double eps,
                              CropStats* stats = nullptr,
                              std::vector<CropInterval>* all_intervals = nullptr);

/// event_time(crop(f, lo, hi, eps, stats), t_curr).
[[nodiscard]] Time crop_event_time(const MotionCombination& f, Time lo, Time hi, double eps,
                                   Time t_curr, CropStats* stats = nullptr);

/// The exact sign of f when every term is a constant (degree 0, e.g. a resting box's side
/// against another's): error-free sums, no GMP; nullopt otherwise (or beyond 2^1020).
[[nodiscard]] std::optional<int> constant_sign(const MotionCombination& f);

/// sign(f(t)), exactly.
[[nodiscard]] int sign_at(const MotionCombination& f, Time t, PredicateStats* stats = nullptr);

/// The sign of f on (t, t + delta) for every small enough delta > 0, exactly; 0 only when f is
/// the zero polynomial.
[[nodiscard]] int sign_after(const MotionCombination& f, Time t, PredicateStats* stats = nullptr);

/// f = (plus[0] - plus[1]) (plus[2] - plus[3]) - (minus[0] - minus[1]) (minus[2] - minus[3]), the
/// exact difference of two products of motion differences: the orientation determinant of three
/// moving points (orientation()), a comparison of two slopes, ... Nothing is rounded into a copy
/// of f: every sign below is the exact sign of this polynomial in t. The pointers must be non-null
/// and outlive the calls; a pointer may repeat (orientation() uses a_x and a_y twice).
struct ProductCombination {
  std::array<const MotionPolynomial*, 4> plus{};
  std::array<const MotionPolynomial*, 4> minus{};
  /// An upper bound of f's degree: the larger of the two products' degree bounds. CROP and the
  /// signs below take f only when it is at most kMaxMotionDegree (so motions of degree <= 3 for
  /// an orientation); callers check it before.
  [[nodiscard]] int degree_bound() const;
};

/// orient(a, b, c)(t) = (x_b - x_a)(y_c - y_a) - (y_b - y_a)(x_c - x_a): > 0 when a, b, c turn
/// counter-clockwise at t, 0 when collinear. References must outlive the result.
[[nodiscard]] ProductCombination orientation(const MotionPolynomial& ax, const MotionPolynomial& ay,
                                             const MotionPolynomial& bx, const MotionPolynomial& by,
                                             const MotionPolynomial& cx,
                                             const MotionPolynomial& cy);

/// CROP(f) for a product combination: (A1)-(A4) on the exact f, by the general path (Bernstein
/// coefficients enclosed from the products of the factors' enclosed Taylor coefficients; exact
/// signs by the frame's filter, then GMP on the exact products). Precondition: f.degree_bound()
/// <= kMaxMotionDegree.
[[nodiscard]] CropResult crop(const ProductCombination& f, Time lo, Time hi, double eps,
                              CropStats* stats = nullptr,
                              std::vector<CropInterval>* all_intervals = nullptr);

/// event_time(crop(f, lo, hi, eps, stats), t_curr).
[[nodiscard]] Time crop_event_time(const ProductCombination& f, Time lo, Time hi, double eps,
                                   Time t_curr, CropStats* stats = nullptr);

/// sign(f(t)), exactly (filter first, GMP when it cannot decide).
[[nodiscard]] int sign_at(const ProductCombination& f, Time t, PredicateStats* stats = nullptr);

/// The sign of f on (t, t + delta) for every small enough delta > 0, exactly; 0 only when f is
/// the zero polynomial.
[[nodiscard]] int sign_after(const ProductCombination& f, Time t, PredicateStats* stats = nullptr);

/// f's Taylor coefficients at t in plain floating point (a guess: the classic scheduler's roots
/// and decisions). Returns their degree: the largest k with out[k] != 0 (0 when none).
int approximate_taylor(const ProductCombination& f, Time t,
                       std::array<double, kMaxMotionDegree + 1>& out);

/// f = sum over k < count of (-1)^k (a_k - b_k)(c_k - d_k), factors[k] = {a_k, b_k, c_k, d_k}: a
/// signed sum of up to four products of motion differences (a ProductCombination is the case
/// count = 2; the difference of two squared lengths |a - b|^2 - |c - d|^2 of moving points is
/// count = 4, LengthComparison::products() in core/incircle.hpp). Exact as a ProductCombination:
/// nothing is rounded into a copy of f. The pointers must be non-null and outlive the calls.
struct ProductSum {
  static constexpr int kMaxProducts = 4;
  std::array<std::array<const MotionPolynomial*, 4>, kMaxProducts> factors{};
  int count = 0;  ///< 1 to kMaxProducts
  /// An upper bound of f's degree: the largest product's. The functions below take f only when
  /// it is at most kMaxMotionDegree; callers check it before.
  [[nodiscard]] int degree_bound() const;
};

/// CROP(f) for a sum of products, as for a ProductCombination. Precondition: f.degree_bound() <=
/// kMaxMotionDegree.
[[nodiscard]] CropResult crop(const ProductSum& f, Time lo, Time hi, double eps,
                              CropStats* stats = nullptr,
                              std::vector<CropInterval>* all_intervals = nullptr);
/// sign(f(t)), exactly (filter first, GMP when it cannot decide).
[[nodiscard]] int sign_at(const ProductSum& f, Time t, PredicateStats* stats = nullptr);
/// The sign of f just after t, exactly; 0 only when f is the zero polynomial.
[[nodiscard]] int sign_after(const ProductSum& f, Time t, PredicateStats* stats = nullptr);
/// f's Taylor coefficients at t in plain floating point (a guess: the classic scheduler's), and
/// their degree.
int approximate_taylor(const ProductSum& f, Time t, std::array<double, kMaxMotionDegree + 1>& out);

struct InCircle;  // core/incircle.hpp
/// CROP(f) for the in-circle determinant of four moving points (core/incircle.hpp): its Taylor
/// coefficients computed by the determinant in truncated polynomial arithmetic (intervals for the
/// enclosures, dyadics for the exact signs), the general path. Precondition: f.degree_bound() <=
/// kMaxMotionDegree (points on lines: degree 4). Its exact signs at and just after t are
/// incircle.hpp's sign_at and sign_after.
[[nodiscard]] CropResult crop(const InCircle& f, Time lo, Time hi, double eps,
                              CropStats* stats = nullptr,
                              std::vector<CropInterval>* all_intervals = nullptr);
/// EVENTTIME of the certificate [holding * f > 0] at t_curr over CROP(f) on [lo, hi], where lo
/// is a grid point at which f's exact sign is `holding` (+1 or -1): the search stops at the first
/// event interval after t_curr where f takes the other sign, so the roots after it are not
/// isolated. The same time as event_time() over the whole crop(f, lo, hi, eps) (and over any
/// window starting before lo: CROP's intervals after lo are the grid cells where f's exact signs
/// differ, the same whatever the window).
[[nodiscard]] Time crop_first_failure(const InCircle& f, int holding, Time lo, Time hi, double eps,
                                      Time t_curr, CropStats* stats = nullptr);
/// Its Taylor coefficients at t in plain floating point (the classic scheduler's guess).
int approximate_taylor(const InCircle& f, Time t, std::array<double, kMaxMotionDegree + 1>& out);

/// CROP of lower - upper from CROP of upper - lower (same intervals, signs flipped): the two
/// orientations of one pair share one result, as (A3) requires of a deterministic CROP.
[[nodiscard]] CropResult negated(const CropResult& r);

}  // namespace kinetic

namespace kinetic {

/// EVENTTIME (Abam, Agarwal, de Berg, Yu, Section 2) for a certificate c whose function is phi_c =
/// upper - lower (c is valid while phi_c > 0), given CROP(phi_c):
///   last <- number of event intervals to the left of t_curr (rho <= t_curr);
///   if chi_c(rho_last) = -1 return rho_last else return rho_{last+1}
/// with rho_0 = -infinity (here: the start of the searched window, a time in the past) and
/// rho_{k+1} = +infinity. A returned time <= t_curr is an event in the past: c is invalid now.
[[nodiscard]] Time event_time(const CropResult& crop_of_phi, Time t_curr);

/// chi_c(rho_last): the sign of phi_c that the KDS pretends at t_curr (the sign at the right end
/// of the last event interval to the left of t_curr, or before the first interval).
[[nodiscard]] int pretended_sign(const CropResult& crop_of_phi, Time t_curr);

/// COMPUTEMAX(x, y) (Abam, Agarwal, de Berg, Yu, Section 4) given CROP(x - y): true when x is the
/// maximum, i.e. sign(x - y) at rho_last is +1. Consistent with event_time() on the same CROP
/// result.
[[nodiscard]] inline bool compute_max_is_first(const CropResult& crop_of_x_minus_y, Time t_curr) {
  return pretended_sign(crop_of_x_minus_y, t_curr) > 0;
}

/// An approximation of t_ex (Abam, Agarwal, de Berg, Yu, eq. (1)): the last root of upper - lower
/// before rho, searched in [rho - span, rho] by exact-sign bisection down to `tolerance`. Used to
/// measure event delays t_pr - t_ex; returns rho when no sign change is found in that span.
[[nodiscard]] Time last_root_before(const MotionPolynomial& upper, const MotionPolynomial& lower,
                                    Time rho, double span, double tolerance);

}  // namespace kinetic
