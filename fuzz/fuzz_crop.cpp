// Fuzz harness (b): CROP and the exact sign predicates on arbitrary coefficients. For two
// motions of degree <= 6 (small integers, quarters, far powers of two, raw doubles; origins
// that differ) over a window and a precision the scheduler supports, the CROP result is checked
// against the exact predicates:
//  - every event interval has width <= w (w the grid width) or is the tiny interval around a
//    root on a grid point, lies in the searched window, and the signs it reports at its ends
//    are the exact signs of upper - lower there, different from each other and nonzero;
//  - the signs chain: sign_first at window_lo, then each interval starts with the sign the
//    previous one ended with (between them f keeps its sign);
//  - f keeps that sign at every floating-point root and critical point of f found in a gap
//    (an isolation that missed a sign change would show here), checked exactly;
//  - the same call twice gives the same result bit for bit (A3), and crop_event_time() agrees
//    with the event time computed from the result.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "fuzz_input.hpp"
#include "kinetic/core/crop.hpp"
#include "kinetic/core/float_roots.hpp"
#include "kinetic/core/predicates.hpp"
#include "kinetic/core/scheduler.hpp"

namespace {

using namespace kinetic;

MotionPolynomial motion(fuzz::Input& in, Time origin) {
  const int degree = static_cast<int>(in.below(kMaxMotionDegree + 1));
  std::vector<double> c(static_cast<std::size_t>(degree) + 1);
  for (double& x : c) x = in.number();
  if (c.back() == 0.0) c.back() = 1.0;
  return MotionPolynomial::from(c, origin);
}

bool same(const CropResult& a, const CropResult& b) {
  if (a.count != b.count || a.sign_first != b.sign_first ||
      a.identically_zero != b.identically_zero ||
      std::memcmp(&a.window_lo, &b.window_lo, sizeof(Time)) != 0 ||
      std::memcmp(&a.window_hi, &b.window_hi, sizeof(Time)) != 0) {
    return false;
  }
  for (int i = 0; i < a.count; ++i) {
    const CropInterval& x = a.events[static_cast<std::size_t>(i)];
    const CropInterval& y = b.events[static_cast<std::size_t>(i)];
    if (std::memcmp(&x.lambda, &y.lambda, sizeof(Time)) != 0 ||
        std::memcmp(&x.rho, &y.rho, sizeof(Time)) != 0 || x.sign_left != y.sign_left ||
        x.sign_right != y.sign_right) {
      return false;
    }
  }
  return true;
}

/// The exact sign of f at t must be `want` (t inside a gap where f keeps its sign).
void expect_sign(const MotionPolynomial& upper, const MotionPolynomial& lower, Time t, int want,
                 const char* where) {
  const int got = compare_at(upper, lower, t);
  if (got != want) {
    fuzz::fail(std::string("sign of f at a ") + where + " is " + std::to_string(got) +
               ", the gap's sign is " + std::to_string(want));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::Input in(data, size);
  const Time origin_a = static_cast<double>(in.small(4)) / 2.0;
  const Time origin_b = in.below(4) == 0 ? static_cast<double>(in.small(4)) : origin_a;
  const MotionPolynomial upper = motion(in, origin_a);
  const MotionPolynomial lower = motion(in, origin_b);
  const double eps = std::ldexp(1.0, -static_cast<int>(in.below(40)));
  Time lo = static_cast<double>(in.small(1000)) / 8.0;
  Time hi = lo + static_cast<double>(in.below(2000)) / 8.0;
  if (!crop_precision_supported(eps, lo, hi)) return 0;

  CropStats stats;
  std::vector<CropInterval> all;
  const CropResult r = crop(upper, lower, lo, hi, eps, &stats, &all);
  const CropResult again = crop(upper, lower, lo, hi, eps);
  if (!same(r, again)) fuzz::fail("two calls differ (A3)");
  if (r.identically_zero) {
    if (compare_at(upper, lower, lo) != 0 || r.count != 0) fuzz::fail("not identically zero");
    return 0;
  }
  const double w = crop_grid_width(eps);
  if (!(r.window_lo <= lo && r.window_hi >= hi)) fuzz::fail("the window does not cover [lo, hi]");
  if (compare_at(upper, lower, r.window_lo) != r.sign_first || r.sign_first == 0) {
    fuzz::fail("sign_first is not the exact sign at window_lo");
  }
  int sign = r.sign_first;
  Time gap_lo = r.window_lo;
  std::vector<std::pair<Time, Time>> gaps;
  for (const CropInterval& e : r) {
    if (!(e.lambda < e.rho) || e.lambda < r.window_lo || e.rho > r.window_hi) {
      fuzz::fail("an interval out of order or outside the window");
    }
    if (e.rho - e.lambda > w && e.rho - e.lambda > 1e-6 * w) fuzz::fail("an interval wider than w");
    if (e.sign_left == 0 || e.sign_right == 0 || e.sign_left == e.sign_right) {
      fuzz::fail("an event interval without a sign change");
    }
    if (compare_at(upper, lower, e.lambda) != e.sign_left ||
        compare_at(upper, lower, e.rho) != e.sign_right) {
      fuzz::fail("an interval's signs are not the exact signs at its ends");
    }
    if (e.sign_left != sign) fuzz::fail("the signs do not chain");
    if (gap_lo > e.lambda) fuzz::fail("intervals overlap");
    gaps.emplace_back(gap_lo, e.lambda);
    sign = e.sign_right;
    gap_lo = e.rho;
  }
  gaps.emplace_back(gap_lo, r.window_hi);
  if (compare_at(upper, lower, r.window_hi) != sign) fuzz::fail("the last sign is not f's at hi");

  // No sign change inside a gap: probe f's floating-point roots and critical points there,
  // outside every interval CROP found (turbulent ones included: f may touch zero there).
  std::array<double, kMaxMotionDegree + 1> d{};
  const int degree = float_difference(upper, lower, d);
  std::vector<Time> probes;
  if (degree >= 1) {
    std::array<FloatRoot, kMaxMotionDegree> roots{};
    const int m = float_sign_change_roots(d, degree, r.window_lo - lower.origin,
                                          r.window_hi - lower.origin, roots);
    for (int i = 0; i < m; ++i)
      probes.push_back(lower.origin + roots[static_cast<std::size_t>(i)].at);
  }
  for (int k = 0; k < 8; ++k) {
    probes.push_back(r.window_lo + (r.window_hi - r.window_lo) * in.below(1025) / 1024.0);
  }
  int gap_sign = r.sign_first;
  for (std::size_t g = 0; g < gaps.size(); ++g) {
    if (g > 0) gap_sign = r.events[g - 1].sign_right;
    for (const Time t : probes) {
      if (!(t > gaps[g].first && t < gaps[g].second)) continue;
      bool in_turbulent = false;
      for (const CropInterval& x : all) in_turbulent |= t >= x.lambda && t <= x.rho;
      if (!in_turbulent) expect_sign(upper, lower, t, gap_sign, "point of a gap");
    }
  }

  // The scheduler's lean path agrees with the full result.
  const Time t_curr = lo + (hi - lo) * in.below(9) / 8.0;
  if (t_curr >= lo && t_curr <= hi) {
    const Time a = crop_event_time(upper, lower, lo, hi, eps, t_curr);
    const Time b = event_time(r, t_curr);
    if (std::memcmp(&a, &b, sizeof(Time)) != 0) {
      fuzz::fail("crop_event_time and event_time(crop) differ");
    }
  }
  return 0;
}
