#pragma once
// Decisions of the exact scheduler made in floating point for certificates of any degree (the
// in-circle certificate of moving points, degree 4 for lines and 8 for parabolas): the same
// answer as decide_exact, without GMP, when the filters decide; otherwise the caller decides
// with GMP. Private to the core (docs/exact-design.md, "In-circle decisions in floating point").

#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "core/function_ref.hpp"
#include "core/numeric/interval.hpp"
#include "kinetic/core/exact_time.hpp"
#include "kinetic/core/incircle.hpp"

namespace kinetic {

/// The sign of a certificate f just after now (never 0 here), and its first failure after now
/// up to the horizon when it has one: a double, or the only root of f, simple, strictly between
/// two adjacent doubles (a deferred root: its exact time is built from f's expansions only when
/// a comparison needs it).
struct FloatDecision {
  int sign = 0;
  bool fails = false;
  LazyTime failure;
};

/// The decision on f, given by the enclosures `c` of its coefficients in powers of t and by
/// `exact_sign(x)`, f's exact sign at the double x (nullopt when it cannot be had without GMP);
/// `root(lo, hi, sign_lo)` makes the lazy time of f's only root in (lo, hi), adjacent doubles,
/// where f goes from sign_lo to -sign_lo. Nullopt when the filters cannot decide: now or the
/// search's end far from 1 (beyond 2^+-64), f's sign over now's bracket unknown, roots closer
/// than the subdivision resolves, a root within one double of the horizon. `sign_after_now`,
/// when not 0, is f's sign just after now, known to the caller (f vanishes at now: the
/// certificate whose failure now is, seen from the other side of a flip). `accurate_value(x)`,
/// when given, is f(x) to about double-double accuracy (not a proof of anything: it only steers
/// the estimate from which the exact signs narrow a root's bracket).
[[nodiscard]] std::optional<FloatDecision> decide_in_floating_point(
    std::span<const numeric::Interval> c, FunctionRef<std::optional<int>(double)> exact_sign,
    const LazyTime& now, Time horizon, FunctionRef<LazyTime(double, double, int)> root,
    int sign_after_now = 0, const FunctionRef<double(double)>* accurate_value = nullptr);

/// The in-circle certificate decided so (points on lines and parabolas, whose in-circle
/// polynomial is computed in floating-point expansions); nullopt: decide with GMP.
[[nodiscard]] std::optional<FloatDecision> decide_in_floating_point(const InCircle& f,
                                                                    const LazyTime& now,
                                                                    Time horizon);

/// The same for a product combination (the orientation of points on lines and parabolas, degree
/// <= 4), computed in floating-point expansions; nullopt: decide with GMP.
[[nodiscard]] std::optional<FloatDecision> decide_in_floating_point(const ProductCombination& f,
                                                                    const LazyTime& now,
                                                                    Time horizon);

}  // namespace kinetic
