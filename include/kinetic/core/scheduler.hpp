#pragma once
// Event scheduling policies: how a certificate's failure time is computed and which times are
// scheduled. The structures ask the scheduler; they never compute failure times themselves, so
// the robust scheduling of Abam, Agarwal, de Berg, Yu (EVENTTIME over CROP) slots in here for every
// structure.

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <utility>

#include "kinetic/core/counters.hpp"
#include "kinetic/core/crop.hpp"
#include "kinetic/core/exact_time.hpp"
#include "kinetic/core/polynomial.hpp"

namespace kinetic {

enum class SchedulerKind {
  /// Traditional KDS scheduling: failure times computed in floating point, the first one not in
  /// the past is scheduled (Abam, Agarwal, de Berg, Yu, Sections 1 and 6, the baseline).
  Classic,
  /// Out-of-order-safe scheduling: EVENTTIME over CROP root isolation (Abam, Agarwal, de Berg, Yu,
  /// Sections 2-3).
  Robust,
  /// Exact event order: every failure time an exact algebraic number (core/exact_time.hpp),
  /// every decision the exact sign just after the exact current time (docs/scheduling.md).
  Exact,
};

[[nodiscard]] const char* to_string(SchedulerKind kind);
[[nodiscard]] std::optional<SchedulerKind> scheduler_from_string(const std::string& name);
/// True when this build implements the scheduler.
[[nodiscard]] bool scheduler_available(SchedulerKind kind);

class Scheduler {
 public:
  /// `horizon`: the end of the simulated time (no event after it is needed); +infinity for
  /// "until no event is left", in which case the robust scheduler searches up to
  /// max_supported_time(eps). Throws PreconditionError for a robust scheduler whose eps is not
  /// supported (eps_supported()).
  explicit Scheduler(SchedulerKind kind = SchedulerKind::Robust, double eps = 1e-9,
                     Time horizon = kTimeInfinity);

  [[nodiscard]] SchedulerKind kind() const { return kind_; }
  [[nodiscard]] double eps() const { return eps_; }
  [[nodiscard]] Time horizon() const { return horizon_; }
  /// The last time this scheduler finds events up to: the horizon, and for robust scheduling at
  /// most max_supported_time(eps). A simulator refuses to advance past it (limit_horizon), since
  /// a structure would be wrong there without an error.
  [[nodiscard]] Time time_limit() const {
    return kind_ == SchedulerKind::Robust ? std::min(horizon_, crop_limit_) : horizon_;
  }

  /// The robust scheduler asks CROP for intervals of width <= kCropWidthFraction * eps, i.e. a
  /// grid w = the largest power of two <= (sqrt(3) / 2) eps (docs/crop.md, "Grid width"). An
  /// event is processed at the right end of its interval, so its delay is at most w < eps, and a
  /// crossing time spread uniformly over a cell gives an RMS delay w / sqrt(3) <= eps / 2 for
  /// every eps (a grid w <= eps alone would give up to 0.577 eps).
  static constexpr double kCropWidthFraction = 0.8660254037844386;  // sqrt(3) / 2, rounded down
  /// The precision the robust scheduler passes to crop() for a user precision eps.
  [[nodiscard]] static double crop_eps(double eps) { return eps * kCropWidthFraction; }
  /// The width of the robust scheduler's CROP grid for a user precision eps.
  [[nodiscard]] static double grid_width(double eps) { return crop_grid_width(crop_eps(eps)); }
  /// The robust scheduler's grid point at or before t (its events fall on grid points, or just
  /// after one where a certificate vanishes exactly on it). Precondition: |t| <=
  /// max_supported_time(eps).
  [[nodiscard]] static Time grid_floor(double eps, Time t) {
    return crop_grid_floor(t, crop_eps(eps));
  }
  /// True when the robust scheduler can honour eps on [lo, hi]: crop_precision_supported for
  /// crop_eps(eps), and [lo, hi] within +-max_supported_time(eps), the last time it finds events
  /// up to (a window beyond it would be answered stale there, so it is refused before the run).
  [[nodiscard]] static bool precision_supported(double eps, Time lo, Time hi) {
    return eps_supported(eps) && crop_precision_supported(crop_eps(eps), lo, hi) &&
           std::max(std::fabs(lo), std::fabs(hi)) <= max_supported_time(eps);
  }

  /// The largest precision the robust scheduler takes: beyond it, 2^52 grid cells no longer fit
  /// in a double (the search limit max_supported_time() would overflow to infinity).
  static constexpr double kMaxEps = 0x1p960;
  /// True when the robust scheduler takes eps: 0 < eps <= kMaxEps (then max_supported_time(eps)
  /// is finite; whether eps resolves a given window is precision_supported()).
  [[nodiscard]] static bool eps_supported(double eps) { return eps > 0.0 && eps <= kMaxEps; }

  /// The largest time at which CROP's grid for eps is representable (|t| < 2^49 w, w the grid
  /// width): the robust scheduler finds no event beyond it.
  [[nodiscard]] static Time max_supported_time(double eps);

  /// The time at which to schedule the failure of certificate c = [lower < upper] (valid while
  /// upper - lower > 0), computed at t_curr, or +infinity when it is not to be scheduled.
  ///  - Classic: the first floating-point root where upper - lower falls, not in the past (it may
  ///    equal t_curr, as in a traditional KDS).
  ///  - Robust: EVENTTIME(c) over CROP(upper - lower) on [window_lo, horizon], where window_lo is
  ///    when the two motions started to hold (roots before it belong to old motions). The result
  ///    may lie in the past (<= t_curr): c is then invalid now and must be processed at once.
  ///  - Exact: the first time after the exact current time (the clock of the simulator the
  ///    scheduler is attached to, Simulator::attach) at which upper - lower changes sign, a root
  ///    of odd multiplicity (a touching root is no failure), written to *exact; the result is a
  ///    double at or below it. When the certificate is invalid just after now, now itself.
  /// Precondition: scheduler_available(kind()); under the exact scheduler, exact != nullptr.
  [[nodiscard]] Time failure_time(const MotionPolynomial& lower, const MotionPolynomial& upper,
                                  Time t_curr, Time window_lo, Counters& counters,
                                  ExactFailure* exact = nullptr) const;

  /// The failure time of a certificate whose function is the combination f (valid while f > 0),
  /// e.g. [L1 < L2] for two side lengths, f = L2 - L1.
  ///  - Robust: EVENTTIME over CROP(f) (crop() on the MotionCombination, exact f) on the same
  ///    window as failure_time() above.
  ///  - Classic (and a failure-time model): failure_time() on the floating-point differences
  ///    plus[0] - minus[0] and minus[1] - plus[1] (motion_difference(), possibly rounded: the
  ///    classic scheduler's roots are floating-point guesses anyway).
  ///  - Exact: as for two motions, on the exact f.
  [[nodiscard]] Time failure_time(const MotionCombination& f, Time t_curr, Time window_lo,
                                  Counters& counters, ExactFailure* exact = nullptr) const;

  /// A model of root-finding errors for experiments and tests: when set, failure_time() returns
  /// what this function returns instead (it may call event_time(), crop_certificate() or
  /// classic_failure_time() itself). For example the paper's Figure 1 (computed failure times
  /// t0 + eps, t0 + 3 eps / 2, t0) or its Theorem 3 construction, where CROP's intervals are
  /// given. `context` is passed through. Costs one branch per call when unset.
  using FailureTimeModel = Time (*)(void* context, const Scheduler& scheduler,
                                    const MotionPolynomial& lower, const MotionPolynomial& upper,
                                    Time t_curr, Time window_lo, Counters& counters);
  void set_failure_time_model(FailureTimeModel model, void* context) {
    model_ = model;
    model_context_ = context;
  }
  [[nodiscard]] bool has_failure_time_model() const { return model_ != nullptr; }
  /// The start of the robust scheduler's CROP window for motions valid since a finite
  /// window_lo (crop_window() below): EVENTTIME returns a time at or before it only for a
  /// certificate that fails from the window's start.
  [[nodiscard]] Time crop_window_start(Time window_lo) const {
    return std::max(window_lo, -crop_limit_);
  }

  /// COMPUTEMAX(x, y) (Abam, Agarwal, de Berg, Yu, Section 4) and the failure time of the
  /// certificate it leaves, [loser < winner], from one root isolation:
  ///  - Robust: CROP(x - y) once; x wins when its pretended sign at t_curr is +1 (COMPUTEMAX,
  ///    so identical motions: y wins), and the failure time is EVENTTIME of [loser < winner] on
  ///    the same CROP result, hence always > t_curr (Lemma 4).
  ///  - Classic: x wins when its floating-point value at t_curr is larger, x.evaluate(t_curr) >
  ///    y.evaluate(t_curr) (a tie: y wins), as a traditional KDS decides (Abam, Agarwal, de Berg,
  ///    Yu, Section 6: the baseline keeps "a rather inaccurate maximum"); with
  ///    set_classic_exact_decisions(true), when x > y just after t_curr, exactly. The failure
  ///    time is failure_time() (floating-point roots, or the failure-time model).
  ///  - Exact: x wins when x > y just after the exact now (identical motions: y wins); the
  ///    failure is exact (the exact scheduler's decisions below are all of this kind).
  struct MaxDecision {
    bool first_wins = false;
    Time failure = kTimeInfinity;
    ExactFailure exact;  ///< the exact failure, under the exact scheduler
  };
  [[nodiscard]] MaxDecision compute_max(const MotionPolynomial& x, const MotionPolynomial& y,
                                        Time t_curr, Time window_lo, Counters& counters) const;

  /// The classic scheduler's COMPUTEMAX decisions taken exactly (sign just after t_curr) instead
  /// of in floating point: a variant of the baseline, more careful than a traditional KDS, kept
  /// for the experiments ("classic, exact decisions"). No effect on the other schedulers.
  void set_classic_exact_decisions(bool exact) { classic_exact_decisions_ = exact; }
  [[nodiscard]] bool classic_exact_decisions() const { return classic_exact_decisions_; }
  /// True when the decisions are taken in floating point as a traditional KDS takes them: the
  /// classic scheduler unless set_classic_exact_decisions(true). The decide() calls below then
  /// read floating-point signs, and a structure that orders or compares motions itself (the
  /// kinetic sort's build, inserts and updates; the longest-side kd-tree's split axes) compares
  /// their floating-point values at now.
  [[nodiscard]] bool floating_point_decisions() const {
    return kind_ == SchedulerKind::Classic && !classic_exact_decisions_;
  }

  /// The sign decision of a certificate built from several motions (an orientation, a slope
  /// comparison), f a ProductCombination, and the failure time of the certificate it leaves,
  /// [sign * f > 0], from one root isolation: COMPUTEMAX generalised to one polynomial.
  ///  - Robust: CROP(f) once; sign is f's pretended sign at t_curr (chi of the last event
  ///    interval before t_curr, Abam, Agarwal, de Berg, Yu, Section 2), and failure is EVENTTIME
  ///    of [sign * f > 0] on the same result, hence always > t_curr (their Lemma 4).
  ///  - Classic, as a traditional KDS: f's Taylor coefficients at t_curr approximated in double;
  ///    sign is their floating-point sign just after t_curr (float_sign_after: the value's sign,
  ///    the first non-zero derivative's where the value is 0), failure the earliest
  ///    floating-point root of sign * f where it falls, not before t_curr. When that root is
  ///    t_curr itself the root finder sees f change sign there, and the decision follows it (the
  ///    other sign): re-deciding at an event cannot meet the same event again.
  ///  - Classic with set_classic_exact_decisions(true): sign is f's exact sign just after t_curr
  ///    (sign_after), failure as above.
  /// sign is 0 (and failure +infinity) only when f is the zero polynomial (classic: when its
  /// floating-point coefficients are all 0): the three points stay collinear, or the two slopes
  /// equal, for ever; the caller breaks that tie.
  /// Precondition: f.degree_bound() <= kMaxMotionDegree.
  struct SignDecision {
    int sign = 0;
    Time failure = kTimeInfinity;
    ExactFailure exact;  ///< the exact failure, under the exact scheduler
  };
  [[nodiscard]] SignDecision decide(const ProductCombination& f, Time t_curr, Time window_lo,
                                    Counters& counters) const;
  /// The same, and under the robust scheduler the end of the first turbulent interval of the same
  /// CROP(f) ending after t_curr in *turbulent_end (+infinity: none, and under the others): a
  /// cell where f may change sign twice, which EVENTTIME does not report (A4). A structure whose
  /// validity, not only its answers, rests on f's sign (a triangulation's orientations) looks
  /// again there.
  [[nodiscard]] SignDecision decide(const ProductCombination& f, Time t_curr, Time window_lo,
                                    Counters& counters, Time* turbulent_end) const;

  /// The same decision for a combination f (e.g. the difference of two box sides,
  /// core/boxes.hpp): robust from one CROP(f), so the decision and its failure agree (the
  /// failure is > t_curr); classic in floating point as above, on the floating-point difference
  /// (plus[0] - minus[0]) - (minus[1] - plus[1]) that its failure times read (a constant f too);
  /// classic with exact decisions: the exact sign just after t_curr and the first floating-point
  /// failure of [sign * f > 0] after t_curr (a root at t_curr itself contradicts the exact sign
  /// and is skipped, so a caller that re-decides at its events cannot loop), a constant f decided
  /// exactly with failure +infinity. Sign 0 only when f is the zero polynomial (classic: zero in
  /// floating point).
  [[nodiscard]] SignDecision decide(const MotionCombination& f, Time t_curr, Time window_lo,
                                    Counters& counters) const;

  /// The same decision for an in-circle determinant (core/incircle.hpp, degree 4k for motions of
  /// degree k), under the exact scheduler only: the sign of f just after the exact now and the
  /// exact time it next changes sign (GMP: the polynomial is beyond CROP's degree). The robust
  /// and classic schedulers refuse it (PreconditionError naming `where`): a structure built on
  /// in-circle certificates checks kind() in its constructor.
  [[nodiscard]] SignDecision decide(const InCircle& f, Counters& counters) const;
  /// The same for the difference of two squared lengths (core/incircle.hpp; the kinetic closest
  /// pair, built on the Delaunay triangulation), under the exact scheduler only.
  [[nodiscard]] SignDecision decide(const LengthComparison& f, Counters& counters) const;
  /// The same for an in-circle determinant under any scheduler: exact as decide(f, counters)
  /// above; robust from one CROP of f (core/crop.hpp), classic in floating point, as for a
  /// ProductCombination. The robust and classic schedulers take points on lines (f of degree
  /// <= 4) and refuse others (PreconditionError).
  [[nodiscard]] SignDecision decide(const InCircle& f, Time t_curr, Time window_lo,
                                    Counters& counters) const;
  /// Robust scheduling of the in-circle certificate [holding * f > 0] whose exact sign at the
  /// grid point g at or before t_curr the caller knows: when f's exact sign at g is `holding`
  /// (+1 or -1), {holding, EVENTTIME} from crop_first_failure() over [g, horizon], the decision
  /// decide() gives when its pretended sign is `holding`, without isolating the roots before g
  /// or after the failure; otherwise (f vanishes at g, or has the other sign) decide(), and
  /// under the other schedulers decide().
  [[nodiscard]] SignDecision decide_from_grid_point(const InCircle& f, int holding, Time t_curr,
                                                    Time window_lo, Counters& counters) const;
  /// Robust scheduling of the in-circle certificate [holding * f > 0] from the grid point g at
  /// or before t_curr, for a caller that does not know f's sign there yet: `sign_after_g` gets
  /// f's exact sign just after g (0 only for the zero polynomial). When it is `holding` the
  /// result is decide_from_grid_point()'s (whose sign may be CROP's pretended one, different
  /// from it, when f vanishes at g); otherwise {sign_after_g, kTimeInfinity} (nothing searched).
  /// For points on lines the sign and the search share one evaluation of f at g in floating
  /// point with error bounds. Robust only (precondition).
  [[nodiscard]] SignDecision decide_after_grid_point(const InCircle& f, int holding, Time t_curr,
                                                     Time window_lo, Counters& counters,
                                                     int& sign_after_g) const;
  /// The same for the difference of two squared lengths f = |a - b|^2 - |c - d|^2 under any
  /// scheduler: exact as decide(f, counters) above; robust from one CROP of f (its four
  /// products, LengthComparison::products()), classic in floating point, as for a
  /// ProductCombination. The robust and classic schedulers take motions of degree <= 3 (f of
  /// degree <= kMaxMotionDegree) and refuse others (PreconditionError).
  [[nodiscard]] SignDecision decide(const LengthComparison& f, Time t_curr, Time window_lo,
                                    Counters& counters) const;

  /// The same decision for f = upper - lower (two motions): COMPUTEMAX(upper, lower) with the
  /// sign made explicit, 0 (failure +infinity) only when the two are the same function of t.
  /// Classic: in floating point, as for a ProductCombination, on float_difference(upper, lower).
  [[nodiscard]] SignDecision decide(const MotionPolynomial& upper, const MotionPolynomial& lower,
                                    Time t_curr, Time window_lo, Counters& counters) const;

  /// The exact scheduler's decision on f = upper - lower at the exact time `now` (any scheduler
  /// kind may ask): the sign of f just after now and, when f changes sign later (a root of odd
  /// multiplicity: a tangency is not a failure) before the horizon, that exact time. With an
  /// infinite horizon the search ends at a bound on f's roots (Cauchy's). Counted as a root
  /// isolation.
  [[nodiscard]] ExactDecision decide_exact(const MotionPolynomial& upper,
                                           const MotionPolynomial& lower, ExactTime& now,
                                           Counters& counters) const;
  /// The same for a combination f.
  [[nodiscard]] ExactDecision decide_exact(const MotionCombination& f, ExactTime& now,
                                           Counters& counters) const;

  /// The failure time of the certificate [sign * f > 0] (sign = +1 or -1) without a decision: for
  /// a traditional KDS that trusts an event (the certificate that failed holds the other way
  /// now). Robust: EVENTTIME over CROP(f); classic: floating-point roots as in decide().
  [[nodiscard]] Time failure_time(const ProductCombination& f, int sign, Time t_curr,
                                  Time window_lo, Counters& counters,
                                  ExactFailure* exact = nullptr) const;

  /// The exact scheduler reads the current time from this clock (Simulator::attach binds it to
  /// the simulator's exact_now()). Other schedulers ignore it.
  void use_clock(LazyTime* now) const { clock_ = now; }

  /// CROP(upper - lower) on the robust scheduler's window for a certificate whose motions hold
  /// since window_lo, at t_curr (shared by EVENTTIME and COMPUTEMAX).
  [[nodiscard]] CropResult crop_certificate(const MotionPolynomial& upper,
                                            const MotionPolynomial& lower, Time t_curr,
                                            Time window_lo, Counters& counters) const;

  /// event_time(crop_certificate(upper, lower, t_curr, window_lo, counters), t_curr), the same
  /// value and counts (crop_event_time): the robust failure time of [lower < upper].
  [[nodiscard]] Time crop_failure_time(const MotionPolynomial& upper, const MotionPolynomial& lower,
                                       Time t_curr, Time window_lo, Counters& counters) const;

 private:
  /// The robust scheduler's CROP window [lo, hi] for a certificate whose motions hold since
  /// window_lo (t_curr when that is not finite), within +-max_supported_time(eps) and the horizon.
  [[nodiscard]] std::pair<Time, Time> crop_window(Time t_curr, Time window_lo) const;

  /// The exact current time. Throws PreconditionError when no simulator attached the scheduler.
  [[nodiscard]] LazyTime& clock() const;
  /// The exact scheduler's decision on f (see decide()).
  [[nodiscard]] SignDecision exact_decision(const ExactPolynomial& f, Counters& counters) const;
  /// The same on f = upper - lower: without GMP when the motions are of degree <= 2 and
  /// decide_low_degree() decides, otherwise exact_decision().
  [[nodiscard]] SignDecision exact_pair_decision(const MotionPolynomial& upper,
                                                 const MotionPolynomial& lower,
                                                 Counters& counters) const;
  /// The same on a combination of four motions (decide_low_degree(), then exact_decision()).
  [[nodiscard]] SignDecision exact_combination_decision(const MotionCombination& f,
                                                        Counters& counters) const;
  /// The same on a product combination (decide_low_degree(), then exact_decision()).
  [[nodiscard]] SignDecision exact_product_decision(const ProductCombination& f,
                                                    Counters& counters) const;
  /// The failure time of [sign * f > 0] from the exact decision d on f.
  Time exact_failure_of(SignDecision d, int sign, ExactFailure* exact) const;
  /// failure_time() of [upper > lower] (of [f > 0]) under the exact scheduler, the
  /// low-degree root built in place in *exact (decide_low_degree_into()), GMP otherwise.
  Time exact_pair_failure(const MotionPolynomial& upper, const MotionPolynomial& lower,
                          Counters& counters, ExactFailure* exact) const;
  Time exact_combination_failure(const MotionCombination& f, Counters& counters,
                                 ExactFailure* exact) const;
  /// The failure time from a low-degree decision whose root is in *exact; NaN when GMP must
  /// decide (no decision, or a root straddling the horizon).
  Time low_degree_failure(const std::optional<LowDegreeSign>& d, ExactFailure& exact,
                          Counters& counters) const;

  /// The robust and classic decisions on a sum of products f (a ProductCombination or a
  /// ProductSum; exact_f: the same function as ExactPolynomial::of takes it).
  template <class Products, class Exact>
  [[nodiscard]] SignDecision product_decision(const Products& f, const Exact& exact_f, Time t_curr,
                                              Time window_lo, Counters& counters) const;

  SchedulerKind kind_;
  double eps_;
  Time horizon_;
  Time crop_limit_ = 0.0;  ///< max_supported_time(eps_), computed once (robust scheduler)
  FailureTimeModel model_ = nullptr;
  void* model_context_ = nullptr;
  bool classic_exact_decisions_ = false;
  mutable LazyTime* clock_ = nullptr;  ///< the exact scheduler's current time
};

}  // namespace kinetic
