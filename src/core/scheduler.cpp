#include "kinetic/core/scheduler.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <vector>

#include "core/float_decision.hpp"
#include "core/incircle_lines.hpp"
#include "kinetic/core/error.hpp"
#include "kinetic/core/float_roots.hpp"
#include "kinetic/core/incircle.hpp"
#include "kinetic/core/predicates.hpp"
#include "kinetic/core/simulator.hpp"

namespace kinetic {

namespace {

/// True when floating-point arithmetic on these motions about t stays within the doubles: the
/// classic scheduler's Taylor shifts (to another origin or to t, |shift| < 2^H) of coefficients
/// below 2^C, and products of two such differences, are bounded by 2^(2 (C + 6H + 8)) < 2^1000.
/// Beyond it (extreme coefficients or origins) the rounded polynomial may overflow, and the
/// classic scheduler decides on the exact one instead (classic_exact_decision). A certificate that
/// multiplies four differences (the in-circle determinant) passes budget 240: half the exponents.
template <class Motions>
bool float_safe(const Motions& motions, Time t, int budget = 480) {
  double c = 0.0, h = 1.0;
  for (const MotionPolynomial* m : motions) {
    for (int k = 0; k <= m->degree; ++k)
      c = std::max(c, std::fabs(m->c[static_cast<std::size_t>(k)]));
    h = std::max(h, 2.0 * std::fabs(t - m->origin) + 1.0);
  }
  if (!std::isfinite(h)) return false;
  return (c == 0.0 ? 0 : std::ilogb(c)) + 6 * std::ilogb(h) <= budget;
}

bool float_safe(const MotionCombination& f, Time t) {
  return float_safe(
      std::array<const MotionPolynomial*, 4>{f.plus[0], f.plus[1], f.minus[0], f.minus[1]}, t);
}
bool float_safe(const ProductCombination& f, Time t) {
  std::array<const MotionPolynomial*, 8> all{};
  std::copy(f.plus.begin(), f.plus.end(), all.begin());
  std::copy(f.minus.begin(), f.minus.end(), all.begin() + 4);
  return float_safe(all, t);
}
bool float_safe(const ProductSum& f, Time t) {
  std::array<const MotionPolynomial*, 4 * ProductSum::kMaxProducts> all{};
  all.fill(f.factors[0][0]);  // (a repeated motion changes no bound)
  for (std::size_t k = 0; k < static_cast<std::size_t>(f.count); ++k)
    std::copy(f.factors[k].begin(), f.factors[k].end(), all.begin() + 4 * k);
  return float_safe(all, t);
}
/// An in-circle determinant multiplies four differences (not two): half the exponent budget.
bool float_safe(const InCircle& f, Time t) {
  std::array<const MotionPolynomial*, 8> all{};
  for (std::size_t k = 0; k < 8; ++k) all[k] = k % 2 == 0 ? f.p[k / 2].x : f.p[k / 2].y;
  return float_safe(all, t, 240);
}
bool float_safe(const MotionPolynomial& a, const MotionPolynomial& b, Time t) {
  return float_safe(std::array<const MotionPolynomial*, 2>{&a, &b}, t);
}

Scheduler::SignDecision classic_exact_decision(const ExactPolynomial& f, Time t_curr, Time horizon,
                                               Counters& counters);

}  // namespace

const char* to_string(SchedulerKind kind) {
  switch (kind) {
    case SchedulerKind::Classic:
      return "classic";
    case SchedulerKind::Robust:
      return "robust";
    case SchedulerKind::Exact:
      return "exact";
  }
  return "?";
}

std::optional<SchedulerKind> scheduler_from_string(const std::string& name) {
  if (name == "classic") return SchedulerKind::Classic;
  if (name == "robust") return SchedulerKind::Robust;
  if (name == "exact") return SchedulerKind::Exact;
  return std::nullopt;
}

bool scheduler_available(SchedulerKind /*kind*/) { return true; }

Scheduler::Scheduler(SchedulerKind kind, double eps, Time horizon)
    : kind_(kind),
      eps_(eps),
      horizon_(horizon),
      crop_limit_(eps_supported(eps) ? max_supported_time(eps) : 0.0) {
  if (kind == SchedulerKind::Robust && !eps_supported(eps)) {
    precondition_failed("Scheduler", "eps = " + format_number(eps) +
                                         " (robust scheduling takes 0 < eps <= 2^960, about "
                                         "9.7e288)");
  }
}

// 2^49 w, not 2^50 w: CROP needs |t| + 4w < 2^50 w on its window (crop_precision_supported).
Time Scheduler::max_supported_time(double eps) { return 0x1p49 * grid_width(eps); }

std::pair<Time, Time> Scheduler::crop_window(Time t_curr, Time window_lo) const {
  const Time limit = crop_limit_;
  const Time lo = std::max(std::isfinite(window_lo) ? window_lo : t_curr, -limit);
  return {lo, std::max(lo, std::min(horizon_, limit))};
}

CropResult Scheduler::crop_certificate(const MotionPolynomial& upper, const MotionPolynomial& lower,
                                       Time t_curr, Time window_lo, Counters& counters) const {
  ++counters.root_isolation_calls;
  const auto [lo, hi] = crop_window(t_curr, window_lo);
  return crop(upper, lower, lo, hi, crop_eps(eps_), &counters.crop);
}

Time Scheduler::crop_failure_time(const MotionPolynomial& upper, const MotionPolynomial& lower,
                                  Time t_curr, Time window_lo, Counters& counters) const {
  // event_time(crop_certificate(...), t_curr), without building the CropResult when it can.
  ++counters.root_isolation_calls;
  const auto [lo, hi] = crop_window(t_curr, window_lo);
  return crop_event_time(upper, lower, lo, hi, crop_eps(eps_), t_curr, &counters.crop);
}

Time Scheduler::failure_time(const MotionPolynomial& lower, const MotionPolynomial& upper,
                             Time t_curr, Time window_lo, Counters& counters,
                             ExactFailure* exact) const {
  assert(scheduler_available(kind_));
  if (kind_ == SchedulerKind::Exact) return exact_pair_failure(upper, lower, counters, exact);
  if (model_ != nullptr) {
    return model_(model_context_, *this, lower, upper, t_curr, window_lo, counters);
  }
  if (kind_ == SchedulerKind::Classic) {
    if (!float_safe(lower, upper, t_curr)) {
      const SignDecision d = classic_exact_decision(ExactPolynomial::difference(upper, lower),
                                                    t_curr, horizon_, counters);
      return d.sign > 0 ? d.failure : t_curr;
    }
    ++counters.root_isolation_calls;
    return classic_failure_time(lower, upper, t_curr);
  }
  return crop_failure_time(upper, lower, t_curr, window_lo, counters);
}

Time Scheduler::failure_time(const MotionCombination& f, Time t_curr, Time window_lo,
                             Counters& counters, ExactFailure* exact) const {
  assert(scheduler_available(kind_));
  if (kind_ == SchedulerKind::Exact) return exact_combination_failure(f, counters, exact);
  if (model_ == nullptr && kind_ == SchedulerKind::Classic && !float_safe(f, t_curr)) {
    const SignDecision d =
        classic_exact_decision(ExactPolynomial::of(f), t_curr, horizon_, counters);
    return d.sign > 0 ? d.failure : t_curr;
  }
  if (model_ != nullptr || kind_ == SchedulerKind::Classic) {
    const MotionPolynomial upper = motion_difference(*f.plus[0], *f.minus[0]).p;
    const MotionPolynomial lower = motion_difference(*f.minus[1], *f.plus[1]).p;
    return failure_time(lower, upper, t_curr, window_lo, counters);
  }
  if (const std::optional<int> s = constant_sign(f)) {
    // A constant certificate never changes sign: it holds for ever (> 0, or == 0: the same
    // function, ordered by the caller's tie rule), or it is invalid now (< 0).
    return *s < 0 ? t_curr : kTimeInfinity;
  }
  ++counters.root_isolation_calls;
  const auto [lo, hi] = crop_window(t_curr, window_lo);
  return crop_event_time(f, lo, hi, crop_eps(eps_), t_curr, &counters.crop);
}

Scheduler::MaxDecision Scheduler::compute_max(const MotionPolynomial& x, const MotionPolynomial& y,
                                              Time t_curr, Time window_lo,
                                              Counters& counters) const {
  assert(scheduler_available(kind_));
  MaxDecision d;
  if (kind_ == SchedulerKind::Exact) {
    SignDecision e = exact_pair_decision(x, y, counters);
    d.first_wins = e.sign > 0;  // identical motions: y wins, as COMPUTEMAX
    d.failure = e.failure;
    d.exact = std::move(e.exact);
    return d;
  }
  if (kind_ == SchedulerKind::Robust) {
    const CropResult r = crop_certificate(x, y, t_curr, window_lo, counters);
    d.first_wins = compute_max_is_first(r, t_curr);
    if (model_ == nullptr) {
      // [y < x] watches x - y (r); [x < y] watches y - x (negated r).
      d.failure = event_time(d.first_wins ? r : negated(r), t_curr);
      return d;
    }
  } else if (model_ == nullptr && !float_safe(x, y, t_curr)) {
    const SignDecision e =
        classic_exact_decision(ExactPolynomial::difference(x, y), t_curr, horizon_, counters);
    d.first_wins = e.sign > 0;  // identical motions: y wins, as COMPUTEMAX
    d.failure = e.failure;
    return d;
  } else if (classic_exact_decisions_) {
    d.first_wins = compare_after(x, y, t_curr, &counters.predicates) > 0;
  } else {
    d.first_wins = x.evaluate(t_curr) > y.evaluate(t_curr);  // a traditional KDS: floating point
  }
  d.failure = d.first_wins ? failure_time(y, x, t_curr, window_lo, counters)
                           : failure_time(x, y, t_curr, window_lo, counters);
  return d;
}

namespace {
/// The classic failure time of [sign * f > 0] at t_curr: f's Taylor coefficients at t_curr in
/// double, their floating-point roots.
template <class Products>
Time classic_product_failure(const Products& f, int sign, Time t_curr) {
  std::array<double, kMaxMotionDegree + 1> phi{};
  const int degree = approximate_taylor(f, t_curr, phi);
  if (sign < 0) {
    for (double& c : phi) c = -c;
  }
  return classic_failure_time(phi, degree, t_curr, t_curr);
}
}  // namespace

namespace {
/// A traditional KDS's decision on f, given in floating point (phi around origin, degree), at
/// t_curr: the floating-point sign just after t_curr (float_sign_after) and the first
/// floating-point root >= t_curr where sign * f falls (classic_failure_time). When that root is
/// t_curr itself, the root finder (the computation that scheduled the event being processed) sees
/// f change sign there: the decision follows it, the other sign with its own failure. When that
/// one rounds to t_curr too (two roots within rounding of t_curr), its first failure strictly
/// after t_curr is taken, so that a caller re-deciding at its events never meets the same event
/// again. Floating point only.
Scheduler::SignDecision float_decision(std::array<double, kMaxMotionDegree + 1> phi, int degree,
                                       Time origin, Time t_curr) {
  Scheduler::SignDecision d;
  d.sign = float_sign_after(phi, degree, origin, t_curr);
  if (d.sign == 0) return d;
  std::array<double, kMaxMotionDegree + 1> negated{};
  for (int k = 0; k <= degree; ++k) negated[k] = -phi[k];
  d.failure = classic_failure_time(d.sign > 0 ? phi : negated, degree, origin, t_curr);
  if (d.failure == t_curr) {
    d.sign = -d.sign;
    d.failure = classic_failure_time(d.sign > 0 ? phi : negated, degree, origin, t_curr, true);
  }
  return d;
}

/// The floating-point sign of upper - lower just after t_curr (float_difference, around
/// lower.origin), without a failure time.
int float_pair_sign(const MotionPolynomial& upper, const MotionPolynomial& lower, Time t_curr) {
  std::array<double, kMaxMotionDegree + 1> phi{};
  const int degree = float_difference(upper, lower, phi);
  return float_sign_after(phi, degree, lower.origin, t_curr);
}

/// f = upper - lower in floating point (float_difference, around lower.origin).
Scheduler::SignDecision float_pair_decision(const MotionPolynomial& upper,
                                            const MotionPolynomial& lower, Time t_curr) {
  std::array<double, kMaxMotionDegree + 1> phi{};
  const int degree = float_difference(upper, lower, phi);
  return float_decision(phi, degree, lower.origin, t_curr);
}
}  // namespace

namespace {
/// COMPUTEMAX on one CROP result: the pretended sign at t_curr and the failure of that sign, from
/// the same isolation, so the failure is > t_curr (Abam, Agarwal, de Berg, Yu, Lemma 4); sign 0
/// and no failure for the zero polynomial.
Scheduler::SignDecision robust_decision(const CropResult& r, Time t_curr) {
  Scheduler::SignDecision d;
  if (r.identically_zero) return d;
  d.sign = pretended_sign(r, t_curr) > 0 ? 1 : -1;
  d.failure = event_time(d.sign > 0 ? r : negated(r), t_curr);
  return d;
}
}  // namespace

template <class Products, class Exact>
Scheduler::SignDecision Scheduler::product_decision(const Products& f, const Exact& exact_f,
                                                    Time t_curr, Time window_lo,
                                                    Counters& counters) const {
  assert(kind_ != SchedulerKind::Exact);
  assert(f.degree_bound() <= kMaxMotionDegree);
  if (kind_ == SchedulerKind::Classic && model_ == nullptr && !float_safe(f, t_curr))
    return classic_exact_decision(ExactPolynomial::of(exact_f), t_curr, horizon_, counters);
  ++counters.root_isolation_calls;
  SignDecision d;
  if (kind_ == SchedulerKind::Robust) {
    const auto [lo, hi] = crop_window(t_curr, window_lo);
    const CropResult r = crop(f, lo, hi, crop_eps(eps_), &counters.crop);
    return robust_decision(r, t_curr);
  }
  if (floating_point_decisions()) {
    std::array<double, kMaxMotionDegree + 1> phi{};
    const int degree = approximate_taylor(f, t_curr, phi);
    return float_decision(phi, degree, t_curr, t_curr);
  }
  d.sign = sign_after(f, t_curr, &counters.predicates);
  if (d.sign != 0) d.failure = classic_product_failure(f, d.sign, t_curr);
  return d;
}

Scheduler::SignDecision Scheduler::decide(const ProductCombination& f, Time t_curr, Time window_lo,
                                          Counters& counters) const {
  assert(scheduler_available(kind_));
  if (kind_ == SchedulerKind::Exact) return exact_product_decision(f, counters);
  return product_decision(f, f, t_curr, window_lo, counters);
}

Scheduler::SignDecision Scheduler::decide(const ProductCombination& f, Time t_curr, Time window_lo,
                                          Counters& counters, Time* turbulent_end) const {
  *turbulent_end = kTimeInfinity;
  if (kind_ != SchedulerKind::Robust || model_ != nullptr)
    return decide(f, t_curr, window_lo, counters);
  ++counters.root_isolation_calls;
  const auto [lo, hi] = crop_window(t_curr, window_lo);
  thread_local std::vector<CropInterval> all;  // every interval, turbulent ones too
  all.clear();
  const CropResult r = crop(f, lo, hi, crop_eps(eps_), &counters.crop, &all);
  for (const CropInterval& iv : all) {
    if (!iv.is_event() && iv.rho > t_curr) {
      *turbulent_end = iv.rho;
      break;
    }
  }
  return robust_decision(r, t_curr);
}

Scheduler::SignDecision Scheduler::decide(const InCircle& f, Time t_curr, Time window_lo,
                                          Counters& counters) const {
  assert(scheduler_available(kind_));
  if (kind_ == SchedulerKind::Exact) return decide(f, counters);
  if (f.degree_bound() > kMaxMotionDegree) {
    precondition_failed("Scheduler::decide",
                        "an in-circle certificate of moving points of degree " +
                            std::to_string(f.degree_bound() / 4) + " is of degree " +
                            std::to_string(f.degree_bound()) + " in t; the " + to_string(kind_) +
                            " scheduler takes at most " + std::to_string(kMaxMotionDegree) +
                            " (points on lines)");
  }
  return product_decision(f, f, t_curr, window_lo, counters);
}

Scheduler::SignDecision Scheduler::decide_from_grid_point(const InCircle& f, int holding,
                                                          Time t_curr, Time window_lo,
                                                          Counters& counters) const {
  assert(holding == 1 || holding == -1);
  if (kind_ != SchedulerKind::Robust || f.degree_bound() > kMaxMotionDegree)
    return decide(f, t_curr, window_lo, counters);
  const Time g = grid_floor(eps_, t_curr);
  if (sign_at(f, g, &counters.predicates) != holding) return decide(f, t_curr, window_lo, counters);
  ++counters.root_isolation_calls;
  const auto [lo, hi] = crop_window(t_curr, window_lo);
  (void)lo;  // the window starts at g instead: the intervals after g are the same
  SignDecision d;
  d.sign = holding;
  d.failure =
      crop_first_failure(f, holding, g, std::max(g, hi), crop_eps(eps_), t_curr, &counters.crop);
  return d;
}

Scheduler::SignDecision Scheduler::decide_after_grid_point(const InCircle& f, int holding,
                                                           Time t_curr, Time window_lo,
                                                           Counters& counters,
                                                           int& sign_after_g) const {
  assert(kind_ == SchedulerKind::Robust);
  assert(holding == 1 || holding == -1);
  const Time g = grid_floor(eps_, t_curr);
  SignDecision d;
  detail::BoundedTaylor at_g;
  if (detail::incircle_of_lines_at(f, g, at_g)) {
    // Certain and not 0: f(g) != 0, so the sign just after g is the sign at g.
    sign_after_g = detail::certified_sign(at_g, 0.0);
    if (sign_after_g != 0) {
      ++counters.predicates.filtered;
      d.sign = sign_after_g;
      if (sign_after_g != holding) return d;
      ++counters.root_isolation_calls;
      const auto [lo, hi] = crop_window(t_curr, window_lo);
      (void)lo;  // the window starts at g instead: the intervals after g are the same
      d.failure = detail::crop_first_failure(f, &at_g, holding, g, std::max(g, hi), crop_eps(eps_),
                                             t_curr, &counters.crop);
      return d;
    }
  }
  sign_after_g = sign_after(f, g, &counters.predicates);
  if (sign_after_g != holding) {
    d.sign = sign_after_g;
    return d;
  }
  return decide_from_grid_point(f, holding, t_curr, window_lo, counters);
}

Scheduler::SignDecision Scheduler::decide(const LengthComparison& f, Time t_curr, Time window_lo,
                                          Counters& counters) const {
  assert(scheduler_available(kind_));
  if (kind_ == SchedulerKind::Exact) return decide(f, counters);
  if (f.degree_bound() > kMaxMotionDegree) {
    precondition_failed("Scheduler::decide",
                        "a length comparison of moving points of degree " +
                            std::to_string(f.degree_bound() / 2) + " is of degree " +
                            std::to_string(f.degree_bound()) + " in t; the " + to_string(kind_) +
                            " scheduler takes at most " + std::to_string(kMaxMotionDegree) +
                            " (motions of degree <= 3)");
  }
  return product_decision(f.products(), f, t_curr, window_lo, counters);
}

Time Scheduler::failure_time(const ProductCombination& f, int sign, Time t_curr, Time window_lo,
                             Counters& counters, ExactFailure* exact) const {
  assert(scheduler_available(kind_));
  assert(sign == 1 || sign == -1);
  if (kind_ == SchedulerKind::Exact) {
    return exact_failure_of(exact_product_decision(f, counters), sign, exact);
  }
  ++counters.root_isolation_calls;
  if (kind_ == SchedulerKind::Robust) {
    const auto [lo, hi] = crop_window(t_curr, window_lo);
    const CropResult r = crop(f, lo, hi, crop_eps(eps_), &counters.crop);
    if (r.identically_zero) return kTimeInfinity;
    return event_time(sign > 0 ? r : negated(r), t_curr);
  }
  if (model_ == nullptr && !float_safe(f, t_curr)) {
    const SignDecision d =
        classic_exact_decision(ExactPolynomial::of(f), t_curr, horizon_, counters);
    return d.sign == sign ? d.failure : t_curr;
  }
  return classic_product_failure(f, sign, t_curr);
}

Scheduler::SignDecision Scheduler::decide(const MotionCombination& f, Time t_curr, Time window_lo,
                                          Counters& counters) const {
  assert(scheduler_available(kind_));
  if (kind_ == SchedulerKind::Exact) return exact_combination_decision(f, counters);
  if (kind_ == SchedulerKind::Classic && model_ == nullptr && !float_safe(f, t_curr))
    return classic_exact_decision(ExactPolynomial::of(f), t_curr, horizon_, counters);
  if (floating_point_decisions()) {
    // f = (plus[0] - minus[0]) - (minus[1] - plus[1]), as the classic failure time reads it (a
    // constant f too: its sign in floating point). With a failure-time model, the floating-point
    // sign and the model's failure of it.
    const MotionPolynomial upper = motion_difference(*f.plus[0], *f.minus[0]).p;
    const MotionPolynomial lower = motion_difference(*f.minus[1], *f.plus[1]).p;
    if (model_ == nullptr) {
      ++counters.root_isolation_calls;
      return float_pair_decision(upper, lower, t_curr);
    }
    SignDecision d;
    d.sign = float_pair_sign(upper, lower, t_curr);
    if (d.sign != 0) {
      const MotionCombination g = d.sign > 0 ? f : MotionCombination{f.minus, f.plus};
      d.failure = failure_time(g, t_curr, window_lo, counters);
    }
    return d;
  }
  SignDecision d;
  if (const std::optional<int> s = constant_sign(f)) {
    d.sign = *s;  // never changes
    return d;
  }
  if (kind_ == SchedulerKind::Robust && model_ == nullptr) {
    ++counters.root_isolation_calls;
    const auto [lo, hi] = crop_window(t_curr, window_lo);
    const CropResult r = crop(f, lo, hi, crop_eps(eps_), &counters.crop);
    return robust_decision(r, t_curr);
  }
  d.sign = sign_after(f, t_curr, &counters.predicates);
  if (d.sign == 0) return d;
  const MotionCombination g = d.sign > 0 ? f : MotionCombination{f.minus, f.plus};  // sign * f
  d.failure = failure_time(g, t_curr, window_lo, counters);
  // A floating-point root at or before t_curr contradicts the exact decision just after t_curr
  // (the certificate holds there): the rounded root came early, and the exact one is just
  // ahead. It is found by exact signs at t_curr + delta, delta doubling from one ulp up to a
  // window of 2^-20 (1 + |t_curr|) (beyond it the rounded root was not this one: none), so that
  // a caller that re-decides at its events neither meets the same event again nor loses it.
  if (d.failure <= t_curr) {
    d.failure = kTimeInfinity;
    const double window = 0x1p-20 * (1.0 + std::abs(t_curr));
    for (double delta = std::nextafter(t_curr, kTimeInfinity) - t_curr; delta <= window;
         delta *= 2) {
      if (sign_at(g, t_curr + delta, &counters.predicates) <= 0) {
        d.failure = t_curr + delta;
        break;
      }
    }
  }
  return d;
}

Scheduler::SignDecision Scheduler::decide(const MotionPolynomial& upper,
                                          const MotionPolynomial& lower, Time t_curr,
                                          Time window_lo, Counters& counters) const {
  assert(scheduler_available(kind_));
  if (kind_ == SchedulerKind::Exact) return exact_pair_decision(upper, lower, counters);
  if (kind_ == SchedulerKind::Classic && model_ == nullptr && !float_safe(upper, lower, t_curr))
    return classic_exact_decision(ExactPolynomial::difference(upper, lower), t_curr, horizon_,
                                  counters);
  SignDecision d;
  if (kind_ == SchedulerKind::Robust) {
    const CropResult r = crop_certificate(upper, lower, t_curr, window_lo, counters);
    return robust_decision(r, t_curr);
  }
  if (floating_point_decisions() && model_ == nullptr) {
    ++counters.root_isolation_calls;
    return float_pair_decision(upper, lower, t_curr);
  }
  // The classic with exact decisions: the exact sign; the traditional classic with a failure-time
  // model: the floating-point sign. Their failures from failure_time() (the model's, if any).
  d.sign = floating_point_decisions() ? float_pair_sign(upper, lower, t_curr)
                                      : compare_after(upper, lower, t_curr, &counters.predicates);
  if (d.sign > 0) d.failure = failure_time(lower, upper, t_curr, window_lo, counters);
  if (d.sign < 0) d.failure = failure_time(upper, lower, t_curr, window_lo, counters);
  return d;
}

namespace {

/// The horizon, or when it is infinite a bound beyond every root of f: 1 + max |c_k / c_n|
/// (Cauchy), at least just past now.
mpq_class search_end(const ExactPolynomial& f, const ExactTime& now, Time horizon) {
  if (std::isfinite(horizon)) return rational(horizon);
  // Times are doubles: a certificate that fails only after the largest double never fails in
  // any time a run or a query can name, so the search ends there (a Cauchy bound of motions of
  // extreme magnitude may be 2^3000).
  static const mpq_class largest(std::numeric_limits<double>::max());
  if (now.hi() >= largest) return dyadic_at_or_above(now.hi() + 1);
  mpq_class bound = 0;
  const auto& c = f.coefficients();
  for (std::size_t k = 0; k + 1 < c.size(); ++k)
    bound = std::max(bound, mpq_class(abs(c[k] / c.back())));
  bound += 1;
  // A dyadic end: the isolation's bisection points are then dyadic (integer signs only).
  return std::min(dyadic_at_or_above(std::max(bound, mpq_class(now.hi() + 1))), largest);
}

ExactDecision decide_on(const ExactPolynomial& f, ExactTime& now, Time horizon,
                        Counters& counters) {
  ++counters.root_isolation_calls;
  if (f.is_zero()) return {};
  const std::size_t before = now.refinements();
  ExactDecision d = decide_exact(f, now, search_end(f, now, horizon));
  counters.exact_refinements += now.refinements() - before + d.failure.refinements();
  return d;
}

/// The classic scheduler's decision on a certificate whose floating-point form may overflow
/// (float_safe): the exact sign just after t_curr and the first exact failure after it, rounded
/// up to a double (+infinity beyond the doubles: never).
Scheduler::SignDecision classic_exact_decision(const ExactPolynomial& f, Time t_curr, Time horizon,
                                               Counters& counters) {
  ++counters.classic_exact_fallbacks;
  ExactTime now = ExactTime::point(rational(t_curr));
  ExactDecision e = decide_on(f, now, horizon, counters);
  Scheduler::SignDecision d;
  d.sign = e.sign;
  if (e.fails) {
    e.failure.tighten();  // its bracket between adjacent doubles (or beyond the largest)
    d.failure = e.failure.upper();
  }
  return d;
}

}  // namespace

LazyTime& Scheduler::clock() const {
  if (clock_ == nullptr) {
    precondition_failed("Scheduler",
                        "the exact scheduler has no clock: attach it to the "
                        "simulator first (Simulator::attach)");
  }
  return *clock_;
}

Time Scheduler::exact_failure_of(SignDecision d, int sign, ExactFailure* exact) const {
  if (exact == nullptr) {
    precondition_failed("Scheduler",
                        "the exact scheduler needs a place for the exact failure "
                        "time (failure_time's `exact` argument)");
  }
  exact->reset();
  if (d.sign == 0) return kTimeInfinity;  // the zero polynomial: never changes
  if (d.sign != sign) {
    exact->emplace(clock());  // invalid just after now: fails now
  } else if (d.exact) {
    *exact = std::move(d.exact);
  } else {
    return kTimeInfinity;
  }
  return (*exact)->lower();
}

namespace {
/// Counts one decision of the exact scheduler, and whether it reached GMP (gmp_work() moved
/// while it was alive).
class CountedDecision {
 public:
  explicit CountedDecision(Counters& c) : counters_(c), gmp_(gmp_work()) {
    ++counters_.exact_decisions;
  }
  ~CountedDecision() {
    if (gmp_work() != gmp_) ++counters_.exact_decisions_gmp;
  }
  CountedDecision(const CountedDecision&) = delete;
  CountedDecision& operator=(const CountedDecision&) = delete;

 private:
  Counters& counters_;
  std::uint64_t gmp_;
};
}  // namespace

Scheduler::SignDecision Scheduler::exact_decision(const ExactPolynomial& f,
                                                  Counters& counters) const {
  ExactDecision e = decide_on(f, clock().exact(), horizon_, counters);
  SignDecision d;
  d.sign = e.sign;
  if (e.fails) {
    d.exact.emplace(LazyTime::of(std::move(e.failure)));
    d.failure = d.exact->lower();
  }
  return d;
}

namespace {

/// A decision without GMP (decide_low_degree: motions of degree <= 2) as the scheduler's, with
/// the horizon; nullopt: the caller decides with GMP.
std::optional<Scheduler::SignDecision> low_degree_decision(std::optional<LowDegreeDecision> f,
                                                           Time horizon, Counters& counters) {
  if (!f) return std::nullopt;
  ++counters.root_isolation_calls;
  Scheduler::SignDecision d;
  d.sign = f->sign;
  if (!f->fails) return d;
  if (f->failure.upper() <= horizon) {
    d.exact.emplace(std::move(f->failure));
    d.failure = d.exact->lower();
  } else if (!(f->failure.lower() > horizon)) {
    return std::nullopt;  // straddles the horizon
  }
  return d;
}

/// A decision made in floating point (decide_in_floating_point) as the scheduler's; nullopt: the
/// caller decides with GMP.
std::optional<Scheduler::SignDecision> float_decision(std::optional<FloatDecision> fast,
                                                      Counters& counters) {
  if (!fast) return std::nullopt;
  ++counters.root_isolation_calls;
  Scheduler::SignDecision d;
  d.sign = fast->sign;
  if (fast->fails) {
    d.exact.emplace(std::move(fast->failure));
    d.failure = d.exact->lower();
  }
  return d;
}

}  // namespace

Time Scheduler::low_degree_failure(const std::optional<LowDegreeSign>& d, ExactFailure& exact,
                                   Counters& counters) const {
  // low_degree_decision() and exact_failure_of(.., sign 1, ..) on the root in place.
  if (!d) return std::numeric_limits<double>::quiet_NaN();
  ++counters.root_isolation_calls;
  if (d->sign == 0) return kTimeInfinity;  // the zero polynomial: never changes
  if (d->sign != 1) {                      // invalid just after now: fails now
    exact.emplace(clock());
    return exact->lower();
  }
  if (!d->fails) return kTimeInfinity;
  if (exact->upper() <= horizon_) return exact->lower();
  if (exact->lower() > horizon_) {  // beyond the horizon: never, for this run
    exact.reset();
    return kTimeInfinity;
  }
  exact.reset();  // straddles the horizon
  return std::numeric_limits<double>::quiet_NaN();
}

Time Scheduler::exact_pair_failure(const MotionPolynomial& upper, const MotionPolynomial& lower,
                                   Counters& counters, ExactFailure* exact) const {
  if (exact == nullptr) return exact_failure_of(SignDecision{}, 1, exact);  // refused there
  const CountedDecision counted(counters);
  const Time t =
      low_degree_failure(decide_low_degree_into(upper, lower, clock(), *exact), *exact, counters);
  if (!std::isnan(t)) return t;
  return exact_failure_of(exact_decision(ExactPolynomial::difference(upper, lower), counters), 1,
                          exact);
}

Time Scheduler::exact_combination_failure(const MotionCombination& f, Counters& counters,
                                          ExactFailure* exact) const {
  if (exact == nullptr) return exact_failure_of(SignDecision{}, 1, exact);  // refused there
  const CountedDecision counted(counters);
  const Time t = low_degree_failure(decide_low_degree_into(f, clock(), *exact), *exact, counters);
  if (!std::isnan(t)) return t;
  return exact_failure_of(exact_decision(ExactPolynomial::of(f), counters), 1, exact);
}

Scheduler::SignDecision Scheduler::exact_pair_decision(const MotionPolynomial& upper,
                                                       const MotionPolynomial& lower,
                                                       Counters& counters) const {
  const CountedDecision counted(counters);
  if (std::optional<SignDecision> d =
          low_degree_decision(decide_low_degree(upper, lower, clock()), horizon_, counters))
    return std::move(*d);
  return exact_decision(ExactPolynomial::difference(upper, lower), counters);
}

Scheduler::SignDecision Scheduler::exact_combination_decision(const MotionCombination& f,
                                                              Counters& counters) const {
  const CountedDecision counted(counters);
  if (std::optional<SignDecision> d =
          low_degree_decision(decide_low_degree(f, clock()), horizon_, counters))
    return std::move(*d);
  return exact_decision(ExactPolynomial::of(f), counters);
}

Scheduler::SignDecision Scheduler::exact_product_decision(const ProductCombination& f,
                                                          Counters& counters) const {
  const CountedDecision counted(counters);
  if (std::optional<SignDecision> d =
          low_degree_decision(decide_low_degree(f, clock()), horizon_, counters))
    return std::move(*d);
  // Motions of degree 2 (degree 4): in floating point when the filters decide.
  if (std::optional<SignDecision> d =
          float_decision(decide_in_floating_point(f, clock(), horizon_), counters))
    return std::move(*d);
  return exact_decision(ExactPolynomial::of(f), counters);
}

Scheduler::SignDecision Scheduler::decide(const InCircle& f, Counters& counters) const {
  if (kind_ != SchedulerKind::Exact) {
    precondition_failed("Scheduler::decide",
                        std::string("in-circle certificates are scheduled by the exact scheduler "
                                    "only (their degree is beyond CROP's), not by the ") +
                            to_string(kind_) + " scheduler");
  }
  const CountedDecision counted(counters);
  // In floating point when the filters decide (no GMP); else exactly.
  if (std::optional<SignDecision> d =
          float_decision(decide_in_floating_point(f, clock(), horizon_), counters))
    return std::move(*d);
  return exact_decision(ExactPolynomial::of(f), counters);
}

Scheduler::SignDecision Scheduler::decide(const LengthComparison& f, Counters& counters) const {
  if (kind_ != SchedulerKind::Exact) {
    precondition_failed("Scheduler::decide",
                        std::string("length comparisons of moving points are scheduled by the "
                                    "exact scheduler only, not by the ") +
                            to_string(kind_) + " scheduler");
  }
  const CountedDecision counted(counters);
  // Lines: degree 2, decided in floating-point expansions when they can.
  if (std::optional<SignDecision> d =
          low_degree_decision(decide_low_degree(f, clock()), horizon_, counters))
    return std::move(*d);
  return exact_decision(ExactPolynomial::of(f), counters);
}

ExactDecision Scheduler::decide_exact(const MotionPolynomial& upper, const MotionPolynomial& lower,
                                      ExactTime& now, Counters& counters) const {
  const CountedDecision counted(counters);
  return decide_on(ExactPolynomial::difference(upper, lower), now, horizon_, counters);
}

ExactDecision Scheduler::decide_exact(const MotionCombination& f, ExactTime& now,
                                      Counters& counters) const {
  const CountedDecision counted(counters);
  return decide_on(ExactPolynomial::of(f), now, horizon_, counters);
}

}  // namespace kinetic

namespace kinetic {

void Simulator::attach(const Scheduler& scheduler) {
  limit_horizon(scheduler.time_limit());
  if (scheduler.kind() == SchedulerKind::Exact) {
    queue_.use_exact_order();
    scheduler.use_clock(&exact_now_);
  }
}

}  // namespace kinetic
