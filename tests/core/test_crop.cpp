// CROP (certified root isolation, Abam, Agarwal, de Berg, Yu Section 2: (A1)-(A4)) against the
// exact oracle of tests/support/exact_poly.hpp (rational arithmetic, Sturm sequences, Yun's
// square-free decomposition; nothing shared with the library's code).
//
// Every generated case (upper, lower, lo, hi, eps) goes through check_case(), which checks:
//  (A1) every distinct real root of f = upper - lower in the searched window lies strictly inside
//       an interval of `all`; widths <= eps (exactly); intervals ascending and disjoint;
//  (A2) the end signs are the exact signs of f (never 0); no root between consecutive intervals
//       or between the window's ends and the first / last interval; sign_first;
//  (A4) events == the intervals of `all` whose end signs differ, in order; count <= deg f;
//       turbulent_count == |all| - count; an interval is an event iff it holds an odd number of
//       roots of odd multiplicity (so a lone sign-changing root is an event, a double root or two
//       simple roots make a turbulent interval);
//  (A3) the same call twice gives bit-identical results; crop(lower, upper) ==
//       negated(crop(upper, lower));
//  and the header's contract: grid width, window = [lo, hi] widened to the grid, endpoints on the
//  grid unless next to an exact zero of f at a grid point.
// Generators use fixed seeds; a failure prints the case (hex floats, ready to paste) and its seed.

#include "kinetic/core/crop.hpp"

#include <gmpxx.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "support/exact_poly.hpp"

namespace kinetic {
namespace {

namespace ex = ::kinetic::test::exact;
using ex::Q;
using ex::QPoly;
using ex::Z;

// ---------------------------------------------------------------------------------------------
// Small helpers.

/// Deterministic random numbers from the raw mt19937_64 stream (its output is fixed by the
/// standard; the <random> distributions are not).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : engine_(seed) {}
  std::uint64_t bits() { return engine_(); }
  /// Uniform integer in [lo, hi].
  int uniform(int lo, int hi) {
    return lo + static_cast<int>(engine_() % static_cast<std::uint64_t>(hi - lo + 1));
  }
  bool chance(int num, int den) { return uniform(0, den - 1) < num; }
  /// Uniform in [0, 1), 53 random bits.
  double unit() { return static_cast<double>(engine_() >> 11) * 0x1p-53; }
  /// +-m 2^e, m in [1, 2) with a full (or, one time in four, short) random mantissa.
  double mantissa_double(int e) {
    std::uint64_t mant = engine_() & ((std::uint64_t{1} << 52) - 1);
    if (chance(1, 4)) mant &= ~((std::uint64_t{1} << 44) - 1);
    const double m = 1.0 + static_cast<double>(mant) * 0x1p-52;
    const double v = std::ldexp(m, e);
    return chance(1, 2) ? -v : v;
  }
  template <class T>
  const T& pick(const std::vector<T>& v) {
    return v[static_cast<std::size_t>(uniform(0, static_cast<int>(v.size()) - 1))];
  }

 private:
  std::mt19937_64 engine_;
};

std::string hex(double x) { return ex::hex(x); }

std::string num(double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

bool same_bits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

Z floor_q(const Q& q) {
  Z r;
  mpz_fdiv_q(r.get_mpz_t(), q.get_num_mpz_t(), q.get_den_mpz_t());
  return r;
}

Z ceil_q(const Q& q) {
  Z r;
  mpz_cdiv_q(r.get_mpz_t(), q.get_num_mpz_t(), q.get_den_mpz_t());
  return r;
}

Q pow2(int e) {
  Q r = 1;
  if (e >= 0) {
    mpq_mul_2exp(r.get_mpq_t(), r.get_mpq_t(), static_cast<mp_bitcnt_t>(e));
  } else {
    mpq_div_2exp(r.get_mpq_t(), r.get_mpq_t(), static_cast<mp_bitcnt_t>(-e));
  }
  return r;
}

/// The grid width, computed here independently: the largest power of two <= eps.
double expected_grid_width(double eps) {
  int e = 0;
  (void)std::frexp(eps, &e);  // eps = m 2^e, m in [1/2, 1)
  return std::ldexp(1.0, e - 1);
}

/// The grid point (j + 1/2) w as a rational.
Q grid_point(const Z& j, double w) { return (Q(j) + Q(1, 2)) * Q(w); }

bool on_grid(double x, double w) {
  const Q t = Q(x) / Q(w) - Q(1, 2);
  return t.get_den() == 1;
}

/// Largest grid point <= x and smallest grid point >= x (as rationals).
Q grid_floor(double x, double w) { return grid_point(floor_q(Q(x) / Q(w) - Q(1, 2)), w); }
Q grid_ceil(double x, double w) { return grid_point(ceil_q(Q(x) / Q(w) - Q(1, 2)), w); }

std::string describe_motion(const MotionPolynomial& p) {
  std::ostringstream os;
  os << "MotionPolynomial::from(std::vector<double>{";
  for (int i = 0; i <= kMaxMotionDegree; ++i) {
    if (i > p.degree && p.c[i] == 0.0) break;
    os << (i ? ", " : "") << hex(p.c[i]);
  }
  os << "}, " << hex(p.origin) << ")";
  return os.str();
}

std::string describe_interval(const CropInterval& iv) {
  std::ostringstream os;
  os << "(" << hex(iv.lambda) << " [" << num(iv.lambda) << "], " << hex(iv.rho) << " ["
     << num(iv.rho) << "]) signs " << int(iv.sign_left) << "/" << int(iv.sign_right);
  return os.str();
}

// ---------------------------------------------------------------------------------------------
// Cases and the checker.

struct CropCase {
  MotionPolynomial upper, lower;
  double lo = 0.0, hi = 100.0, eps = 1e-9;
  std::string label;
  /// The f the generator meant (powers of t), when it built one exactly: checked against the
  /// oracle's expansion of upper - lower (a self-check of generator and oracle).
  std::optional<QPoly> planted;
};

std::string describe_case(const CropCase& cs) {
  std::ostringstream os;
  os << "case " << cs.label << "\n  upper = " << describe_motion(cs.upper)
     << "\n  lower = " << describe_motion(cs.lower) << "\n  lo = " << hex(cs.lo) << " ["
     << num(cs.lo) << "], hi = " << hex(cs.hi) << " [" << num(cs.hi) << "], eps = " << hex(cs.eps)
     << " [" << num(cs.eps) << "]";
  return os.str();
}

struct Tally {
  std::uint64_t cases = 0, zero = 0, intervals = 0, events = 0, turbulent = 0;
  std::uint64_t empty_intervals = 0;  ///< intervals holding no real root (allowed)
  std::uint64_t multi_root_intervals = 0;
  std::uint64_t grid_zero_intervals = 0;  ///< intervals around an exact zero at a grid point
  std::uint64_t roots_in_window = 0;
  std::uint64_t fast_path = 0, boxes = 0, exact_boxes = 0, filtered = 0, exact = 0;
  std::uint64_t failures = 0;
  double crop_seconds = 0;  ///< time spent inside crop() (1 call per case, 3 with (A3))
  std::string summary() const {
    std::ostringstream os;
    os << cases << " cases (" << zero << " identically zero), " << roots_in_window
       << " distinct roots in windows, " << intervals << " intervals: " << events << " events, "
       << turbulent << " turbulent (" << empty_intervals << " hold no root, "
       << multi_root_intervals << " hold >= 2 roots, " << grid_zero_intervals
       << " around a zero at a grid point); crop stats: fast_path " << fast_path
       << ", bernstein_boxes " << boxes << " (exact " << exact_boxes
       << "), predicates filtered/exact " << filtered << "/" << exact << "; " << crop_seconds
       << " s inside crop()";
    return os.str();
  }
};

struct Violations {
  std::vector<std::string> list;
  void add(const std::string& s) { list.push_back(s); }
  explicit operator bool() const { return !list.empty(); }
};

bool same_interval(const CropInterval& a, const CropInterval& b, bool flip) {
  const int s = flip ? -1 : 1;
  return same_bits(a.lambda, b.lambda) && same_bits(a.rho, b.rho) &&
         a.sign_left == s * b.sign_left && a.sign_right == s * b.sign_right;
}

/// Field-by-field, bitwise. `all_slots`: also the unused entries of `events`.
std::string result_difference(const CropResult& a, const CropResult& b, bool all_slots) {
  std::ostringstream os;
  if (a.count != b.count) os << " count " << a.count << " vs " << b.count << ";";
  if (a.turbulent_count != b.turbulent_count)
    os << " turbulent_count " << a.turbulent_count << " vs " << b.turbulent_count << ";";
  if (a.sign_first != b.sign_first)
    os << " sign_first " << a.sign_first << " vs " << b.sign_first << ";";
  if (a.identically_zero != b.identically_zero) os << " identically_zero differs;";
  if (!same_bits(a.window_lo, b.window_lo) || !same_bits(a.window_hi, b.window_hi))
    os << " window [" << hex(a.window_lo) << ", " << hex(a.window_hi) << "] vs ["
       << hex(b.window_lo) << ", " << hex(b.window_hi) << "];";
  const int n = all_slots ? kMaxMotionDegree : std::min(a.count, b.count);
  for (int i = 0; i < n && i >= 0; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (!same_interval(a.events[k], b.events[k], false))
      os << " events[" << i << "] " << describe_interval(a.events[k]) << " vs "
         << describe_interval(b.events[k]) << ";";
  }
  return os.str();
}

std::string describe_result(const CropResult& r, const std::vector<CropInterval>& all) {
  std::ostringstream os;
  os << "  crop: count=" << r.count << " turbulent_count=" << r.turbulent_count
     << " sign_first=" << r.sign_first << " identically_zero=" << r.identically_zero << " window=["
     << hex(r.window_lo) << ", " << hex(r.window_hi) << "]";
  for (std::size_t i = 0; i < all.size(); ++i)
    os << "\n    all[" << i << "] " << describe_interval(all[i])
       << (all[i].is_event() ? " event" : " turbulent");
  return os.str();
}

std::string describe_roots(const ex::RootOracle& o, double a, double b) {
  std::ostringstream os;
  os << "  oracle: deg f = " << o.f().degree() << ", distinct real roots " << o.count_all()
     << ", in [" << num(a) << ", " << num(b) << "]:";
  const auto roots = o.approximate_roots(a, b);
  if (roots.empty()) os << " none";
  for (const auto& [x, m] : roots) os << " " << hex(x) << " [" << num(x) << "] (mult " << m << ")";
  return os.str();
}

/// The exactly-zero grid point within a few doubles of x, if any.
std::optional<double> zero_grid_point_near(const ex::RootOracle& o, double x, double w) {
  // Widening over roots can put the end a few doubles past the nearest grid point (w can be as
  // small as 4 ulps): try the grid points within 2 w.
  const Z j = floor_q(Q(x) / Q(w));
  for (const Z& k : {Z(j - 3), Z(j - 2), Z(j - 1), j, Z(j + 1), Z(j + 2)}) {
    const Q g = grid_point(k, w);
    if (!ex::representable(g)) continue;
    const double gd = g.get_d();
    if (o.sign(gd) != 0) continue;
    double y = x;
    for (int step = 0; step <= 8; ++step) {
      if (y == gd) return gd;
      y = std::nextafter(y, gd);
    }
  }
  return std::nullopt;
}

/// crop(), timed into the tally.
CropResult timed_crop(Tally& tally, const MotionPolynomial& upper, const MotionPolynomial& lower,
                      Time lo, Time hi, double eps, CropStats* stats = nullptr,
                      std::vector<CropInterval>* all = nullptr) {
  const auto start = std::chrono::steady_clock::now();
  CropResult r = crop(upper, lower, lo, hi, eps, stats, all);
  tally.crop_seconds +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

/// Runs crop on the case and checks everything; returns the violations (empty when fine).
/// `check_a3`: also call crop again, and on (lower, upper), for (A3).
Violations check_case(const CropCase& cs, Tally& tally, std::string* details = nullptr,
                      CropResult* result_out = nullptr,
                      std::vector<CropInterval>* all_out = nullptr, bool check_a3 = true) {
  Violations v;
  ++tally.cases;
  const QPoly f = ex::sub(ex::from_motion(cs.upper), ex::from_motion(cs.lower));
  if (cs.planted && !(f == *cs.planted))
    v.add("harness: upper - lower differs from the planted polynomial (generator/oracle bug)");
  if (!crop_precision_supported(cs.eps, cs.lo, cs.hi))
    v.add("harness: crop_precision_supported is false for a generated case");
  if (v) return v;

  CropStats stats;
  std::vector<CropInterval> all;
  const CropResult r = timed_crop(tally, cs.upper, cs.lower, cs.lo, cs.hi, cs.eps, &stats, &all);
  if (result_out) *result_out = r;
  if (all_out) *all_out = all;
  tally.fast_path += stats.fast_path;
  tally.boxes += stats.bernstein_boxes;
  tally.exact_boxes += stats.exact_boxes;
  tally.filtered += stats.predicates.filtered;
  tally.exact += stats.predicates.exact;
  if (stats.calls != 1) v.add("stats.calls is " + std::to_string(stats.calls) + " after one call");

  // (A3) determinism: the same call again, with and without the optional outputs.
  {
    if (check_a3) {
      const CropResult r2 = timed_crop(tally, cs.upper, cs.lower, cs.lo, cs.hi, cs.eps);
      const std::string d = result_difference(r, r2, true);
      if (!d.empty()) v.add("(A3) a second call (no stats / no list) differs:" + d);
    }
  }
  // (A3) orientation: crop(lower, upper) == negated(crop(upper, lower)).
  if (check_a3) {
    std::vector<CropInterval> alln;
    const CropResult rn =
        timed_crop(tally, cs.lower, cs.upper, cs.lo, cs.hi, cs.eps, nullptr, &alln);
    const CropResult neg = negated(r);
    const std::string d = result_difference(rn, neg, false);
    if (!d.empty()) v.add("(A3) crop(lower, upper) != negated(crop(upper, lower)):" + d);
    bool same_all = all.size() == alln.size();
    for (std::size_t i = 0; same_all && i < all.size(); ++i)
      same_all = same_interval(all[i], alln[i], true);
    if (!same_all)
      v.add(
          "(A3) the interval list of crop(lower, upper) is not that of crop(upper, lower) with "
          "signs flipped (" +
          std::to_string(alln.size()) + " vs " + std::to_string(all.size()) + " intervals)");
    // negated() itself.
    bool neg_ok = neg.count == r.count && neg.turbulent_count == r.turbulent_count &&
                  neg.sign_first == -r.sign_first && neg.identically_zero == r.identically_zero &&
                  same_bits(neg.window_lo, r.window_lo) && same_bits(neg.window_hi, r.window_hi);
    for (int i = 0; neg_ok && i < r.count; ++i)
      neg_ok = same_interval(neg.events[static_cast<std::size_t>(i)],
                             r.events[static_cast<std::size_t>(i)], true);
    if (!neg_ok) v.add("negated(r) is not r with every sign flipped");
  }

  // crop_event_time() is event_time(crop()), in both orientations, with the same counts.
  // event_time() depends on t only through the comparisons rho <= t of the event intervals, so
  // the window's ends and, per event interval, rho and the double before it cover every case.
  {
    std::vector<double> times{cs.lo, r.window_lo, cs.hi};
    for (int i = 0; i < r.count; ++i) {
      const double rho = r.events[static_cast<std::size_t>(i)].rho;
      times.push_back(rho);
      times.push_back(std::nextafter(rho, -kTimeInfinity));
    }
    const CropResult neg = negated(r);
    for (std::size_t k = 0; k < times.size(); ++k) {
      const double t = times[k];
      if (!std::isfinite(t)) continue;
      CropStats st;
      const Time got =
          crop_event_time(cs.upper, cs.lower, cs.lo, cs.hi, cs.eps, t, k == 0 ? &st : nullptr);
      if (!same_bits(got, event_time(r, t)))
        v.add("crop_event_time(upper, lower) at " + hex(t) + " is " + hex(got) +
              ", event_time(crop()) is " + hex(event_time(r, t)));
      if (k < 2 || k + 1 == times.size()) {
        const Time got_n = crop_event_time(cs.lower, cs.upper, cs.lo, cs.hi, cs.eps, t);
        if (!same_bits(got_n, event_time(neg, t)))
          v.add("crop_event_time(lower, upper) at " + hex(t) + " is " + hex(got_n) +
                ", event_time(negated(crop())) is " + hex(event_time(neg, t)));
      }
      if (k == 0 && (st.calls != stats.calls || st.bernstein_boxes != stats.bernstein_boxes ||
                     st.exact_boxes != stats.exact_boxes || st.fast_path != stats.fast_path ||
                     st.predicates.filtered != stats.predicates.filtered ||
                     st.predicates.compensated != stats.predicates.compensated ||
                     st.predicates.exact != stats.predicates.exact))
        v.add("crop_event_time() counts differ from crop()'s");
    }
  }

  // The header's grid and window.
  const double w = expected_grid_width(cs.eps);
  if (!same_bits(crop_grid_width(cs.eps), w))
    v.add("crop_grid_width(eps) = " + hex(crop_grid_width(cs.eps)) + ", expected " + hex(w));

  if (f.is_zero()) {
    ++tally.zero;
    if (!r.identically_zero) v.add("f is identically zero but identically_zero is false");
    if (r.count != 0 || r.turbulent_count != 0 || !all.empty())
      v.add("f is identically zero but intervals were reported");
    if (r.sign_first != 0) v.add("f is identically zero but sign_first != 0");
    if (v && details) *details = describe_result(r, all);
    return v;
  }
  if (r.identically_zero) v.add("identically_zero is true for a non-zero f");
  if (r.sign_first != 1 && r.sign_first != -1)
    v.add("sign_first = " + std::to_string(r.sign_first) + " for a non-zero f");

  const ex::RootOracle o(f);
  // Each point is evaluated once (sign of f, Sturm values).
  std::vector<ex::RootOracle::Point> cache;
  auto pt = [&](double x) -> ex::RootOracle::Point {
    for (const auto& p : cache)
      if (same_bits(p.x, x)) return p;
    cache.push_back(o.point(x));
    return cache.back();
  };
  const double wlo = r.window_lo, whi = r.window_hi;
  if (!std::isfinite(wlo) || !std::isfinite(whi) || !(wlo <= cs.lo) || !(whi >= cs.hi)) {
    v.add("window [" + hex(wlo) + ", " + hex(whi) + "] does not contain [lo, hi]");
  } else {
    // The header: [lo, hi] widened outward to the nearest grid points, then by whole cells
    // while f vanishes at an end. When lo == hi is a grid point, one cell [lo, lo + w] is
    // accepted too (crop.cpp searches at least one cell).
    Q elo = grid_floor(cs.lo, w), ehi = grid_ceil(cs.hi, w);
    if (elo == ehi && Q(whi) > ehi) ehi += w;
    for (int k = 0; k < 8 && ex::representable(elo) && o.sign(elo.get_d()) == 0; ++k) elo -= w;
    for (int k = 0; k < 8 && ex::representable(ehi) && o.sign(ehi.get_d()) == 0; ++k) ehi += w;
    if (!(Q(wlo) == elo) || !(Q(whi) == ehi))
      v.add("header contract: window [" + hex(wlo) + ", " + hex(whi) +
            "] is not [lo, hi] widened to the nearest grid points where f != 0 [" +
            hex(elo.get_d()) + ", " + hex(ehi.get_d()) + "]");
  }
  tally.roots_in_window += static_cast<std::uint64_t>(o.closed(pt(cs.lo), pt(cs.hi)));

  // The intervals one by one.
  const Q qeps(cs.eps);
  int n_events = 0;
  for (std::size_t i = 0; i < all.size(); ++i) {
    const CropInterval& iv = all[i];
    const std::string name = "all[" + std::to_string(i) + "] " + describe_interval(iv);
    ++tally.intervals;
    if (!std::isfinite(iv.lambda) || !std::isfinite(iv.rho) || !(iv.lambda < iv.rho)) {
      v.add("(A1) " + name + " is not a non-empty finite interval");
      continue;
    }
    if (Q(iv.rho) - Q(iv.lambda) > qeps) v.add("(A1) " + name + " is wider than eps");
    if (i > 0 && !(all[i - 1].rho <= iv.lambda))
      v.add("(A1) " + name + " overlaps or precedes the previous interval");
    const auto pl = pt(iv.lambda), pr = pt(iv.rho);
    const int sl = pl.sign_f, sr = pr.sign_f;
    if (iv.sign_left != sl)
      v.add("(A2) " + name + ": exact sign at lambda is " + std::to_string(sl));
    if (iv.sign_right != sr) v.add("(A2) " + name + ": exact sign at rho is " + std::to_string(sr));
    if (sl == 0 || sr == 0) v.add("(A1) " + name + ": an endpoint is a root (intervals are open)");
    // Root structure inside: an event iff an odd number of odd-multiplicity roots.
    const int distinct = o.open(pl, pr);
    const int odd = o.odd_open(pl, pr);
    if (distinct == 0) ++tally.empty_intervals;
    if (distinct >= 2) ++tally.multi_root_intervals;
    if (iv.is_event()) {
      ++n_events;
      ++tally.events;
    } else {
      ++tally.turbulent;
    }
    if (iv.is_event() != (odd % 2 == 1)) {
      std::string what = std::to_string(distinct) + " distinct roots, " + std::to_string(odd) +
                         " of odd multiplicity";
      if (distinct == 1 && odd == 1) what = "a lone sign-changing root";
      if (distinct == 1 && o.count_multiplicity_open(2, iv.lambda, iv.rho) == 1)
        what = "one double root";
      if (distinct == 2 && odd == 2) what = "two roots of odd multiplicity";
      v.add("(A4) " + name + " holds " + what + " but is " +
            (iv.is_event() ? "an event" : "turbulent"));
    }
    // Header contract: endpoints on the grid, unless next to an exact zero at a grid point.
    for (double e : {iv.lambda, iv.rho}) {
      if (!on_grid(e, w) && !zero_grid_point_near(o, e, w))
        v.add("header contract: " + name + ": endpoint " + hex(e) +
              " is neither a grid point nor next to a zero of f at a grid point");
    }
    // An interval around a zero of f at a grid point g is (pred(g), succ(g)) widened to the
    // nearest doubles where f != 0.
    const Z j0 = ceil_q(Q(iv.lambda) / Q(w) - Q(1, 2));
    for (Z j = j0; j < j0 + 4 && grid_point(j, w) < Q(iv.rho); ++j) {
      const Q gq = grid_point(j, w);
      if (!(Q(iv.lambda) < gq) || !ex::representable(gq)) continue;
      const double g = gq.get_d();
      if (o.sign(g) != 0) continue;
      ++tally.grid_zero_intervals;
      double a = std::nextafter(g, -1e300), b = std::nextafter(g, 1e300);
      for (int k = 0; k < 8 && o.sign(a) == 0; ++k) a = std::nextafter(a, -1e300);
      for (int k = 0; k < 8 && o.sign(b) == 0; ++k) b = std::nextafter(b, 1e300);
      if (!same_bits(iv.lambda, a) || !same_bits(iv.rho, b))
        v.add("header contract: " + name + " holds the zero grid point " + hex(g) +
              " but is not (" + hex(a) + ", " + hex(b) + ")");
    }
  }

  // (A1)/(A2): no root of f in the searched window outside the intervals.
  {
    auto gap = [&](double a, double b, const std::string& where) {
      if (!(a <= b)) return;
      const int n = o.closed(pt(a), pt(b));
      if (n == 0) return;
      const double ia = std::max(a, cs.lo), ib = std::min(b, cs.hi);
      const int in_lohi = ia <= ib ? o.count_closed(ia, ib) : 0;
      v.add((in_lohi > 0 ? "(A1) " : "(A2) ") + std::to_string(n) + " root(s) of f in [" + hex(a) +
            ", " + hex(b) + "] " + where + " are in no interval" +
            (in_lohi > 0 ? " (" + std::to_string(in_lohi) + " of them in [lo, hi])"
                         : " (in the grid-widened part of the window)"));
    };
    double a = wlo;
    for (std::size_t i = 0; i < all.size(); ++i) {
      if (all[i].lambda > a)
        gap(a, all[i].lambda,
            i == 0
                ? "before the first interval"
                : "between all[" + std::to_string(i - 1) + "] and all[" + std::to_string(i) + "]");
      a = std::max(a, all[i].rho);
    }
    if (whi > a) gap(a, whi, all.empty() ? "(no intervals)" : "after the last interval");
    for (std::size_t i = 1; i < all.size(); ++i)
      if (all[i - 1].sign_right != all[i].sign_left)
        v.add("(A2) sign changes between all[" + std::to_string(i - 1) + "] and all[" +
              std::to_string(i) + "] with no interval there");
  }
  // sign_first: the sign before the first interval, as seen from the window.
  {
    const int s_lo = pt(wlo).sign_f;
    if (s_lo != 0 && r.sign_first != s_lo)
      v.add("(A2) sign_first = " + std::to_string(r.sign_first) + " but f(window_lo) has sign " +
            std::to_string(s_lo));
    if (s_lo == 0 || pt(whi).sign_f == 0)
      v.add("header contract: f vanishes at an end of the window [" + hex(wlo) + ", " + hex(whi) +
            "]");
    if (!all.empty() && r.sign_first != all.front().sign_left)
      v.add("(A2) sign_first = " + std::to_string(r.sign_first) +
            " but the first interval starts with sign " + std::to_string(all.front().sign_left));
    const int s_hi = pt(whi).sign_f;
    const int last = all.empty() ? r.sign_first : all.back().sign_right;
    if (s_hi != 0 && last != s_hi)
      v.add("(A2) the sign after the last interval is " + std::to_string(last) +
            " but f(window_hi) has sign " + std::to_string(s_hi));
  }
  // (A4) the events.
  {
    std::vector<CropInterval> events;
    for (const auto& iv : all)
      if (iv.is_event()) events.push_back(iv);
    if (r.count < 0 || r.count > kMaxMotionDegree ||
        static_cast<std::size_t>(r.count) != events.size()) {
      v.add("(A4) count = " + std::to_string(r.count) + " but `all` holds " +
            std::to_string(events.size()) + " event intervals");
    } else {
      for (std::size_t i = 0; i < events.size(); ++i)
        if (!same_interval(r.events[i], events[i], false))
          v.add("(A4) events[" + std::to_string(i) + "] " + describe_interval(r.events[i]) +
                " is not the " + std::to_string(i) + "-th event interval of `all` " +
                describe_interval(events[i]));
    }
    if (r.count > std::max(0, f.degree()))
      v.add("(A4) count = " + std::to_string(r.count) + " > deg f = " + std::to_string(f.degree()));
    if (static_cast<std::size_t>(r.turbulent_count) + static_cast<std::size_t>(n_events) !=
        all.size())
      v.add("(A4) turbulent_count = " + std::to_string(r.turbulent_count) + " but `all` holds " +
            std::to_string(all.size() - static_cast<std::size_t>(n_events)) +
            " turbulent intervals");
  }
  if (v && details) {
    const double a = std::isfinite(wlo) ? std::min(wlo, cs.lo) : cs.lo;
    const double b = std::isfinite(whi) ? std::max(whi, cs.hi) : cs.hi;
    *details = describe_result(r, all) + "\n" + describe_roots(o, a, b);
  }
  return v;
}

/// FNV-1a over the bits of a result and its interval list (to compare builds: A3 asks for the
/// same result bit for bit; a build that differs is worth knowing about).
std::uint64_t digest(const CropResult& r, const std::vector<CropInterval>& all) {
  std::uint64_t h = 1469598103934665603ull;
  auto mix = [&](std::uint64_t x) {
    for (int k = 0; k < 8; ++k) h = (h ^ ((x >> (8 * k)) & 0xff)) * 1099511628211ull;
  };
  mix(static_cast<std::uint64_t>(r.count));
  mix(static_cast<std::uint64_t>(r.turbulent_count));
  mix(static_cast<std::uint64_t>(r.sign_first + 2));
  mix(r.identically_zero ? 1 : 0);
  mix(std::bit_cast<std::uint64_t>(r.window_lo));
  mix(std::bit_cast<std::uint64_t>(r.window_hi));
  for (const auto& iv : all) {
    mix(std::bit_cast<std::uint64_t>(iv.lambda));
    mix(std::bit_cast<std::uint64_t>(iv.rho));
    mix(static_cast<std::uint64_t>(iv.sign_left + 2) * 4 +
        static_cast<std::uint64_t>(iv.sign_right + 2));
  }
  return h;
}

/// Optional per-case digests (KINETIC_CROP_DUMP=<file>): diff two builds' files to find a case
/// whose result depends on the build.
std::FILE* dump_file() {
  static std::FILE* f = [] {
    const char* path = std::getenv("KINETIC_CROP_DUMP");
    return path ? std::fopen(path, "w") : nullptr;
  }();
  return f;
}

/// A case's violations as one failure message: the case, the checker's details, the list.
std::string violation_report(const CropCase& cs, const std::string& details, const Violations& v) {
  std::ostringstream os;
  os << describe_case(cs) << "\n" << details << "\n  violations:";
  for (const auto& s : v.list) os << "\n    - " << s;
  return os.str();
}

/// Checks one case and reports its violations as a gtest failure (the first `max_reports`
/// failing cases of a suite in full).
bool report_case(const CropCase& cs, Tally& tally, bool check_a3 = true, int max_reports = 8) {
  std::string details;
  CropResult r;
  std::vector<CropInterval> all;
  const Violations v = check_case(cs, tally, &details, &r, &all, check_a3);
  if (std::FILE* f = dump_file()) {
    std::fprintf(f, "%s %016llx\n", cs.label.c_str(),
                 static_cast<unsigned long long>(digest(r, all)));
  }
  if (!v) return true;
  ++tally.failures;
  if (tally.failures <= static_cast<std::uint64_t>(max_reports)) {
    ADD_FAILURE() << violation_report(cs, details, v);
  }
  return false;
}

/// A checked case's result from crop(): the result, every interval, and whether the case held.
struct Ran {
  CropResult r;
  std::vector<CropInterval> all;
  bool ok = false;
};

/// Checks one case into `tally` and keeps crop's result for extra expectations; a case with
/// violations is a test failure that lists them.
Ran checked_case(const CropCase& cs, Tally& tally) {
  Ran out;
  std::string details;
  const Violations v = check_case(cs, tally, &details, &out.r, &out.all);
  out.ok = !v;
  if (v) ADD_FAILURE() << violation_report(cs, details, v);
  return out;
}

// Sizes. The full suites (over 10^5 cases) run in optimised builds. Unoptimised and sanitizer
// builds (the Debug + ASan/UBSan build is -O0) run a fixed fraction of every suite, the first
// cases of the same sequences, and check (A3) on every 4th case only, to stay near a minute.
// KINETIC_CROP_SCALE=<factor> overrides the fraction (1 = the full suites in any build);
// KINETIC_CROP_SEED=<k> runs other fixed sequences.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__) || !defined(NDEBUG) || \
    !defined(__OPTIMIZE__)
constexpr bool kSlowBuild = true;
#else
constexpr bool kSlowBuild = false;
#endif
constexpr double kSlowBuildScale = 0.25;

double suite_scale() {
  if (const char* e = std::getenv("KINETIC_CROP_SCALE")) {
    const double x = std::atof(e);
    if (x > 0) return x;
  }
  return kSlowBuild ? kSlowBuildScale : 1.0;
}

/// Runs the first scale * `n` generated cases of a suite with a fixed seed.
void run_suite(const char* name, std::uint64_t seed, int n_full,
               const std::function<CropCase(Rng&, int)>& generate) {
  const int n = std::max(1, static_cast<int>(std::lround(n_full * suite_scale())));
  // KINETIC_CROP_SEED=<k> explores other sequences (the seed used is printed either way).
  if (const char* e = std::getenv("KINETIC_CROP_SEED")) seed += std::strtoull(e, nullptr, 0) << 32;
  const int a3_every = kSlowBuild ? 4 : 1;
  const auto start = std::chrono::steady_clock::now();
  Rng rng(seed);
  Tally tally;
  std::map<std::string, int> labels;
  for (int i = 0; i < n; ++i) {
    CropCase cs = generate(rng, i);
    ++labels[cs.label];
    cs.label = std::string(name) + " seed=" + std::to_string(seed) + " i=" + std::to_string(i) +
               (cs.label.empty() ? "" : " (" + cs.label + ")");
    report_case(cs, tally, i % a3_every == 0);
  }
  const double secs =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("[ %s ] seed %llu, %d of %d cases ((A3) on 1 in %d): %s; %.2f s\n", name,
              static_cast<unsigned long long>(seed), n, n_full, a3_every, tally.summary().c_str(),
              secs);
  std::string mix;
  for (const auto& [label, k] : labels) mix += " " + label + ":" + std::to_string(k);
  std::printf("[ %s ] kinds:%s\n", name, mix.c_str());
  EXPECT_EQ(tally.failures, 0u) << name << ": " << tally.failures << " of " << n
                                << " cases failed (seed " << seed << ")";
}

// ---------------------------------------------------------------------------------------------
// Generators.

struct Setting {
  double lo, hi, eps;
};

/// The main setting ([0, 100], eps = 1e-9) most of the time, then coarser eps, a window far from
/// 0, random windows and odd ones (eps at the 4-ulp limit, eps > the window, tiny and subnormal
/// windows and grids, empty windows lo == hi).
Setting pick_setting(Rng& rng) {
  const int k = rng.uniform(0, 39);
  if (k < 22) return {0.0, 100.0, 1e-9};
  if (k < 26) return {0.0, 100.0, 1e-6};
  if (k < 30) return {0.0, 100.0, 1e-3};
  if (k < 34) return {1e5, 1e5 + 10.0, rng.chance(1, 2) ? 1e-9 : 1e-6};
  if (k == 34) {
    static const std::vector<Setting> odd = {
        {0.0, 1.0, 0x1p-49},                 // w = 8 ulp(1): the limit of crop_precision_supported
        {-0.75, -0.5, 0x1p-50},              // the same, negative
        {0x1p21 - 2.0, 0x1p21 - 1.0, 2e-9},  // w = 8 ulp at the top of the window
        {-1e6 - 1.0, -1e6, 1e-9},
        {0.0, 100.0, 1000.0},  // eps wider than the window
        {0.0, 100.0, 4.0},
        {-3.0, 3.0, 0.75},
        {1e-300, 3e-300, 1e-305},  // tiny window and grid
        {0.0, 1e-310, 1e-315},     // subnormal grid
        {50.0, 50.0, 1e-9},        // lo == hi
        {0.1, 0.1, 1e-6},
        {0.0, 0.0, 1e-3},
    };
    return rng.pick(odd);
  }
  // A random window: lo in [-1000, 1000], length 2^[-6, 7].
  const double lo = std::ldexp(std::round(std::ldexp(rng.unit() * 2000.0 - 1000.0, 20)), -20);
  const double len = std::ldexp(1.0 + rng.unit(), rng.uniform(-6, 6));
  const double eps = rng.pick(std::vector<double>{1e-9, 1e-6, 1e-3});
  return {lo, lo + len, eps};
}

/// A random double in [lo, hi] (full mantissa).
double random_in(Rng& rng, double lo, double hi) {
  const double x = lo + rng.unit() * (hi - lo);
  return std::min(std::max(x, lo), hi);
}

MotionPolynomial motion(const std::vector<double>& c, double origin) {
  return MotionPolynomial::from(c, origin);
}

/// A random motion of the given degree about `origin`: coefficient i about 2^(e0 - i b), so the
/// roots are at distance about 2^b from the origin.
MotionPolynomial random_motion(Rng& rng, int degree, double origin, int e0, int b) {
  std::vector<double> c(static_cast<std::size_t>(degree) + 1, 0.0);
  for (int i = 0; i <= degree; ++i) {
    if (i < degree && rng.chance(1, 8)) continue;
    c[static_cast<std::size_t>(i)] = rng.mantissa_double(e0 - i * b + rng.uniform(-2, 2));
  }
  return motion(c, origin);
}

MotionPolynomial scaled(MotionPolynomial p, int e) {
  for (auto& x : p.c) x = std::ldexp(x, e);
  return p;
}

/// Every coefficient of p about `origin`, rounded (toward zero) to doubles: the same motion up to
/// rounding, so upper - lower is tiny and only exact as a difference.
MotionPolynomial rounded_reexpansion(const MotionPolynomial& p, double origin) {
  const std::vector<Q> c = ex::coefficients_about(ex::from_motion(p), Q(origin));
  std::vector<double> d(static_cast<std::size_t>(kMaxMotionDegree) + 1, 0.0);
  for (std::size_t i = 0; i < c.size(); ++i) d[i] = c[i].get_d();
  return motion(d, origin);
}

/// Generic random pairs; different origins; rounding traps.
CropCase generate_generic(Rng& rng, int /*i*/) {
  CropCase cs;
  const Setting s = pick_setting(rng);
  cs.lo = s.lo, cs.hi = s.hi, cs.eps = s.eps;
  const double len = s.hi - s.lo;
  const double pad = len > 0 ? std::min(1.0, len) : 1.0;
  auto origin = [&]() {
    const int k = rng.uniform(0, 9);
    if (k == 0) return 0.0;
    if (k == 1) return std::ldexp(std::round(std::ldexp(random_in(rng, s.lo, s.hi), 4)), -4);
    return random_in(rng, s.lo - pad, s.hi + pad);
  };
  const int du = rng.uniform(1, kMaxMotionDegree);
  // Roots at distance about 2^b from the origin: up to the window's length.
  const int b = std::clamp((len > 0 ? std::ilogb(len) : -20) - 6 + rng.uniform(-1, 6), -120, 7);
  const double ou = origin();
  cs.upper = random_motion(rng, du, ou, rng.uniform(-4, 4), b);
  const int mode = rng.uniform(0, 9);
  double ol = origin();
  if (ol == ou) ol = std::nextafter(ou, 1e300);
  if (mode < 5) {
    cs.label = "independent";
    cs.lower = random_motion(rng, rng.uniform(0, kMaxMotionDegree), ol, rng.uniform(-4, 4), b);
  } else if (mode < 7) {
    cs.label = "rounded re-expansion";
    cs.lower = rounded_reexpansion(cs.upper, ol);
    if (rng.chance(1, 2)) {
      const auto k = static_cast<std::size_t>(rng.uniform(0, cs.lower.degree));
      cs.lower.c[k] = std::nextafter(cs.lower.c[k], rng.chance(1, 2) ? 1e300 : -1e300);
    }
  } else if (mode < 8) {
    cs.label = "ulp-perturbed coefficients";
    cs.lower = cs.upper;
    for (int r = rng.uniform(1, 2); r > 0; --r) {
      const auto k = static_cast<std::size_t>(rng.uniform(0, cs.lower.degree));
      double& x = cs.lower.c[k];
      for (int u = rng.uniform(1, 3); u > 0; --u)
        x = std::nextafter(x, rng.chance(1, 2) ? 1e300 : -1e300);
    }
  } else {
    cs.label = "origin shifted by ulps";
    cs.lower = cs.upper;
    double o = cs.upper.origin;
    for (int u = rng.uniform(1, 4); u > 0; --u) o = std::nextafter(o, 1e300);
    cs.lower.origin = o;
  }
  // Huge and tiny coefficients: both motions scaled by one power of two.
  const int sk = rng.uniform(0, 9);
  if (sk == 0) cs.upper = scaled(cs.upper, 200), cs.lower = scaled(cs.lower, 200);
  if (sk == 1) cs.upper = scaled(cs.upper, -200), cs.lower = scaled(cs.lower, -200);
  if (sk == 2) cs.upper = scaled(cs.upper, -60), cs.lower = scaled(cs.lower, -60);
  return cs;
}

/// A planted polynomial in x = t - c: s * prod (x - a_i)^{m_i} * prod ((x - b_j)^2 + d_j).
struct Plant {
  std::vector<std::pair<Q, int>> roots;  ///< (a_i, multiplicity), offsets from the centre
  std::vector<std::pair<Q, Q>> complex;  ///< (b_j, d_j), d_j > 0
  Q scale = 1;
  [[nodiscard]] int degree() const {
    int d = 2 * static_cast<int>(complex.size());
    for (const auto& [a, m] : roots) d += m;
    return d;
  }
  [[nodiscard]] QPoly in_x() const {
    QPoly p = ex::constant(scale);
    for (const auto& [a, m] : roots) p = ex::mul(p, ex::power(ex::linear_root(a), m));
    for (const auto& [b, d] : complex)
      p = ex::mul(p, ex::add(ex::power(ex::linear_root(b), 2), ex::constant(d)));
    return p;
  }
};

/// Splits the exact f = P(t - c) into (upper, lower): plain, negated, or with a common
/// polynomial L about another origin added to both (exact; f is then only exact as a difference).
bool split_plant(Rng& rng, const QPoly& p_in_x, double c, CropCase& cs) {
  const int mode = rng.uniform(0, 5);
  const auto plain = ex::to_motion(p_in_x.c, c);
  if (!plain) return false;
  cs.planted = ex::about(p_in_x.c, Q(c));
  if (mode <= 1) {
    cs.upper = *plain;
    cs.lower = MotionPolynomial::constant(0.0);
    if (rng.chance(1, 2)) cs.lower.origin = random_in(rng, -10.0, 10.0);
    return true;
  }
  if (mode == 2) {
    // upper = 0, lower = -P: f = P.
    cs.upper = MotionPolynomial::constant(0.0);
    cs.upper.origin = random_in(rng, -10.0, 10.0);
    cs.lower = *ex::to_motion(ex::neg(p_in_x).c, c);
    return true;
  }
  // L: small dyadic coefficients about o2 = c + d; upper = P + L (about c), lower = L (about o2).
  for (int attempt = 0; attempt < 8; ++attempt) {
    const int dl = rng.uniform(0, kMaxMotionDegree);
    std::vector<Q> l;
    for (int i = 0; i <= dl; ++i) {
      Q q(rng.uniform(-1023, 1023));
      q *= pow2(rng.uniform(-12, 4) - 2 * i);
      l.push_back(q);
    }
    Q d(rng.uniform(-63, 63));
    d *= pow2(-rng.uniform(0, 6));
    const Q o2 = Q(c) + d;
    if (!ex::representable(o2)) continue;
    const QPoly l_t = ex::about(l, o2);
    const auto lower = ex::to_motion(l, o2.get_d());
    const auto upper = ex::to_motion(ex::coefficients_about(ex::add(*cs.planted, l_t), Q(c)), c);
    if (!lower || !upper) continue;
    cs.upper = *upper;
    cs.lower = *lower;
    return true;
  }
  cs.upper = *plain;
  cs.lower = MotionPolynomial::constant(0.0);
  return true;
}

/// Random offsets k 2^-m.
Q offset(Rng& rng, int k_range, int m) { return Q(rng.uniform(-k_range, k_range)) * pow2(-m); }

/// Planted-root polynomials: spread roots, clusters, multiple roots, pairs closer / wider than
/// eps, near-double roots, complex pairs just off the axis.
CropCase generate_planted(Rng& rng, int /*i*/) {
  for (int attempt = 0;; ++attempt) {
    CropCase cs;
    const Setting s = pick_setting(rng);
    cs.lo = s.lo, cs.hi = s.hi, cs.eps = s.eps;
    const double w = expected_grid_width(s.eps);
    const int wexp = std::ilogb(w);
    // The centre: random, a grid point, a bisection midpoint j w, or a simple dyadic.
    double c = random_in(rng, s.lo, s.hi);
    const int ck = rng.uniform(0, 5);
    if (ck == 0) c = grid_floor(c, w).get_d();
    if (ck == 1) c = std::ldexp(std::round(std::ldexp(c, -wexp)), wexp);
    if (ck == 2) c = std::ldexp(std::round(std::ldexp(c, 6)), -6);
    Plant p;
    const int kind = attempt > 20 ? 0 : rng.uniform(0, 7);
    const int budget = attempt > 40 ? 1 : rng.uniform(1, kMaxMotionDegree);
    // Offsets k 2^-spread_m, |k| <= 96, reach about half the window (or less).
    const double len = s.hi > s.lo ? s.hi - s.lo : std::max(std::abs(s.lo) * 0x1p-20, 64 * w);
    const int spread_m = std::min(1060, 7 - std::ilogb(len) + rng.uniform(0, 4));
    auto add_spread = [&](int upto) {
      while (p.degree() < upto) p.roots.push_back({offset(rng, 96, spread_m), 1});
    };
    switch (kind) {
      case 0:  // spread over the window
        cs.label = "spread";
        add_spread(budget);
        break;
      case 1: {  // a cluster of 2-4 roots spread 1e-10 .. 1e-3
        cs.label = "cluster";
        const int m = rng.uniform(10, 33) + 4;
        for (int k = rng.uniform(2, 4); k > 0; --k) p.roots.push_back({offset(rng, 16, m), 1});
        add_spread(std::max(budget, p.degree()));
        break;
      }
      case 2: {  // exact double and triple roots
        cs.label = "multiple";
        const int mult = rng.uniform(2, 3);
        p.roots.push_back({offset(rng, 64, rng.uniform(0, 40)), mult});
        if (rng.chance(1, 2)) p.roots.push_back({offset(rng, 64, rng.uniform(0, 40)), 2});
        add_spread(std::max(budget, p.degree()));
        break;
      }
      case 3: {  // a pair closer than eps (w/8) or just wider (w + w/8, 2 w)
        cs.label = "pair vs eps";
        const Q a = offset(rng, 64, spread_m);
        const Q gap =
            rng.pick(std::vector<Q>{Q(w) / 8, Q(w) * Q(9, 8), Q(w) * 2, Q(w) / 2, pow2(wexp - 4)});
        p.roots.push_back({a, 1});
        p.roots.push_back({a + gap, 1});
        add_spread(std::max(budget, p.degree()));
        break;
      }
      case 4: {  // near-double roots: gaps 1e-13 .. 1e-4
        cs.label = "near-double";
        const Q a = offset(rng, 64, rng.uniform(0, 8));
        p.roots.push_back({a, 1});
        p.roots.push_back({a + Q(rng.uniform(1, 7)) * pow2(-rng.uniform(14, 43)), 1});
        add_spread(std::max(budget, p.degree()));
        break;
      }
      case 5: {  // complex pairs just off the axis
        cs.label = "complex pair";
        p.complex.push_back({offset(rng, 64, rng.uniform(0, 8)), pow2(-rng.uniform(10, 100))});
        if (rng.chance(1, 3))
          p.complex.push_back({offset(rng, 64, rng.uniform(0, 8)), pow2(-rng.uniform(10, 100))});
        add_spread(std::max(budget, p.degree()));
        break;
      }
      case 6: {  // a complex pair next to a real root
        cs.label = "complex pair + root";
        const Q b = offset(rng, 64, rng.uniform(0, 8));
        p.complex.push_back({b, pow2(-rng.uniform(20, 90))});
        p.roots.push_back({b + Q(rng.uniform(-3, 3)) * pow2(-rng.uniform(10, 40)), 1});
        add_spread(std::max(budget, p.degree()));
        break;
      }
      default: {  // a double root next to a simple root
        cs.label = "double + near simple";
        const Q a = offset(rng, 64, rng.uniform(0, 8));
        p.roots.push_back({a, 2});
        p.roots.push_back({a + Q(rng.uniform(-7, 7)) * pow2(-rng.uniform(8, 40)), 1});
        add_spread(std::max(budget, p.degree()));
        break;
      }
    }
    if (p.degree() > kMaxMotionDegree) continue;
    p.scale = pow2(rng.uniform(-8, 8));
    const int sk = rng.uniform(0, 9);
    if (sk == 0) p.scale *= pow2(200);
    if (sk == 1) p.scale *= pow2(-200);
    if (rng.chance(1, 2)) p.scale = -p.scale;
    if (!split_plant(rng, p.in_x(), c, cs)) continue;
    return cs;
  }
}

/// Roots at the window's ends, a few ulps inside / outside, at grid points (j + 1/2) w and at
/// bisection midpoints j w.
CropCase generate_special(Rng& rng, int /*i*/) {
  for (int attempt = 0;; ++attempt) {
    CropCase cs;
    Setting s = pick_setting(rng);
    const double w = expected_grid_width(s.eps);
    const int wexp = std::ilogb(w);
    // Sometimes the window's ends are themselves grid points.
    if (rng.chance(1, 4)) s.lo = grid_floor(s.lo, w).get_d();
    if (rng.chance(1, 4)) s.hi = grid_ceil(s.hi, w).get_d();
    cs.lo = s.lo, cs.hi = s.hi, cs.eps = s.eps;
    double c = 0;
    const int where = rng.uniform(0, 7);
    const double mid = random_in(rng, s.lo, s.hi);
    switch (where) {
      case 0:
        c = s.lo;
        cs.label = "root at lo";
        break;
      case 1:
        c = s.hi;
        cs.label = "root at hi";
        break;
      case 2:
      case 3: {
        const bool at_lo = where == 2;
        c = at_lo ? s.lo : s.hi;
        const int k = rng.uniform(1, 4);
        const bool outward = rng.chance(1, 2);
        const double dir = (at_lo == outward) ? -1e300 : 1e300;
        for (int u = 0; u < k; ++u) c = std::nextafter(c, dir);
        cs.label = std::string("root ") + std::to_string(k) + " ulps " +
                   (outward ? "outside " : "inside ") + (at_lo ? "lo" : "hi");
        break;
      }
      case 4:
        c = grid_floor(mid, w).get_d();
        cs.label = "root at a grid point";
        break;
      case 5:
        c = std::ldexp(std::round(std::ldexp(mid, -wexp)), wexp);
        cs.label = "root at a bisection midpoint j w";
        break;
      case 6: {
        c = grid_floor(mid, w).get_d();
        const int k = rng.uniform(1, 3);
        const double dir = rng.chance(1, 2) ? -1e300 : 1e300;
        for (int u = 0; u < k; ++u) c = std::nextafter(c, dir);
        cs.label = "root " + std::to_string(k) + " ulps from a grid point";
        break;
      }
      default: {
        // A grid point of the far window / window ends on the grid with the root there.
        c = grid_ceil(s.hi, w).get_d();
        cs.label = "root at window_hi";
        break;
      }
    }
    Plant p;
    p.roots.push_back({Q(0), rng.pick(std::vector<int>{1, 1, 1, 2, 3})});
    const int extra = attempt > 40 ? 0 : rng.uniform(0, kMaxMotionDegree - p.degree());
    for (int k = 0; k < extra; ++k) {
      const int t = rng.uniform(0, 3);
      if (t == 0) p.roots.push_back({Q(rng.uniform(-4, 4)) * Q(w) / 2, 1});  // grid neighbours
      if (t == 1) p.roots.push_back({offset(rng, 64, rng.uniform(-4, 40)), 1});
      if (t == 2)
        p.roots.push_back({Q(rng.uniform(-3, 3)) * pow2(std::ilogb(c == 0 ? 1.0 : c) - 52), 1});
      if (t == 3) p.roots.push_back({offset(rng, 100, 0), 1});
    }
    if (p.degree() > kMaxMotionDegree) continue;
    p.scale = pow2(rng.uniform(-4, 4));
    if (rng.chance(1, 10)) p.scale *= pow2(rng.chance(1, 2) ? 200 : -200);
    if (rng.chance(1, 2)) p.scale = -p.scale;
    if (!split_plant(rng, p.in_x(), c, cs)) continue;
    return cs;
  }
}

// ---------------------------------------------------------------------------------------------
// The oracle itself (so that a wrong oracle cannot pass silently).

TEST(CropOracle, CountsPlantedRootsAndSigns) {
  Rng rng(0xC0FFEE01);
  for (int it = 0; it < 400; ++it) {
    // Distinct roots r_1 < ... < r_k with multiplicities, in powers of t.
    std::vector<std::pair<Q, int>> roots;
    int deg = 0;
    while (deg < rng.uniform(1, kMaxMotionDegree)) {
      const Q r = Q(rng.uniform(-200, 200)) * pow2(-rng.uniform(0, 40));
      if (std::any_of(roots.begin(), roots.end(), [&](const auto& x) { return x.first == r; }))
        continue;
      const int m = std::min(rng.uniform(1, 3), kMaxMotionDegree - deg);
      roots.push_back({r, m});
      deg += m;
    }
    QPoly f = ex::constant(Q(rng.uniform(1, 9)) * (rng.chance(1, 2) ? 1 : -1));
    for (const auto& [r, m] : roots) f = ex::mul(f, ex::power(ex::linear_root(r), m));
    if (rng.chance(1, 3)) f = ex::mul(f, QPoly({Q(1), Q(0), Q(1)}));  // t^2 + 1: no real root
    const ex::RootOracle o(f);
    ASSERT_EQ(o.count_all(), static_cast<int>(roots.size())) << "it=" << it;
    for (int q = 0; q < 20; ++q) {
      double a = rng.uniform(-250, 250) * std::ldexp(1.0, -rng.uniform(0, 40));
      double b = rng.uniform(-250, 250) * std::ldexp(1.0, -rng.uniform(0, 40));
      if (rng.chance(1, 4)) a = roots[0].first.get_d();  // an end at a root
      if (rng.chance(1, 4)) b = roots.back().first.get_d();
      if (a > b) std::swap(a, b);
      int open = 0, closed = 0, half = 0, odd = 0, doubles = 0;
      for (const auto& [r, m] : roots) {
        const Q A(a), B(b);
        if (A < r && r < B) ++open, odd += m % 2, doubles += m == 2;
        if (A <= r && r <= B) ++closed;
        if (A < r && r <= B) ++half;
      }
      EXPECT_EQ(o.count_open(a, b), open) << "it=" << it << " a=" << hex(a) << " b=" << hex(b);
      EXPECT_EQ(o.count_closed(a, b), closed) << "it=" << it;
      EXPECT_EQ(o.count_half_open(a, b), half) << "it=" << it;
      EXPECT_EQ(o.count_odd_open(a, b), odd) << "it=" << it;
      EXPECT_EQ(o.count_multiplicity_open(2, a, b), doubles) << "it=" << it;
      const double x =
          rng.chance(1, 3) ? a : rng.uniform(-250, 250) * std::ldexp(1.0, -rng.uniform(0, 45));
      EXPECT_EQ(o.sign(x), sgn(ex::eval(f, Q(x)))) << "it=" << it;
    }
  }
}

TEST(CropOracle, ExpandsMotionsExactly) {
  // (t - 1)^2 + 2 (t - 1) + 1 about 1 is t^2; 3 (t + 2) about -2 is 3 t + 6.
  EXPECT_TRUE(ex::from_motion(motion({1.0, 2.0, 1.0}, 1.0)) == QPoly({Q(0), Q(0), Q(1)}));
  EXPECT_TRUE(ex::from_motion(motion({0.0, 3.0}, -2.0)) == QPoly({Q(6), Q(3)}));
  // A difference that no double expansion would get right: 2^-60 (t - 0.1)^2 vs about 0.
  // 1 + 2^-60 (t - 0.1): root at 0.1 - 2^60 (0.1 the double), which no double equals.
  const QPoly fa = ex::from_motion(motion({1.0, 0x1p-60}, 0.1));
  EXPECT_EQ(sgn(ex::eval(fa, Q(0.1) - pow2(60))), 0);
  EXPECT_EQ(ex::sign_at(fa, 0.1), 1);
  EXPECT_EQ(ex::sign_at(fa, -0x1p60), -1);            // -2^60 < 0.1 - 2^60
  const double above = std::nextafter(-0x1p60, 0.0);  // -2^60 + 128
  EXPECT_EQ(ex::sign_at(fa, above), 1);
  const ex::RootOracle o(fa);
  EXPECT_EQ(o.count_open(-0x1p60, above), 1);
  EXPECT_EQ(o.count_closed(above, 0.1), 0);
  EXPECT_EQ(o.count_closed(-0x1p61, -0x1p60), 0);
}

// ---------------------------------------------------------------------------------------------
// crop_grid_width and crop_precision_supported.

TEST(CropGridWidth, PowersOfTwoAreTheirOwnWidth) {
  for (int e = -1074; e <= 1023; ++e) {
    const double p = std::ldexp(1.0, e);
    EXPECT_EQ(crop_grid_width(p), p) << "eps = 2^" << e;
  }
}

TEST(CropGridWidth, LargestPowerOfTwoNotAboveEps) {
  EXPECT_EQ(crop_grid_width(1e-9), 0x1p-30);
  EXPECT_EQ(crop_grid_width(1e-6), 0x1p-20);
  EXPECT_EQ(crop_grid_width(1e-3), 0x1p-10);
  EXPECT_EQ(crop_grid_width(0.75), 0.5);
  EXPECT_EQ(crop_grid_width(std::nextafter(1.0, 0.0)), 0.5);
  EXPECT_EQ(crop_grid_width(std::nextafter(1.0, 2.0)), 1.0);
  EXPECT_EQ(crop_grid_width(std::numeric_limits<double>::max()), 0x1p1023);
  EXPECT_EQ(crop_grid_width(std::numeric_limits<double>::denorm_min()), 0x1p-1074);
  EXPECT_EQ(crop_grid_width(3 * std::numeric_limits<double>::denorm_min()), 0x1p-1073);
  EXPECT_EQ(crop_grid_width(std::numeric_limits<double>::min() * 1.5), 0x1p-1022);
  Rng rng(0xC0FFEE02);
  for (int it = 0; it < 20000; ++it) {
    const double eps = std::abs(rng.mantissa_double(rng.uniform(-1074, 1023)));
    if (eps == 0.0 || !std::isfinite(eps)) continue;
    const double w = crop_grid_width(eps);
    int e = 0;
    const double m = std::frexp(w, &e);
    EXPECT_EQ(m, 0.5) << "not a power of two: eps=" << hex(eps) << " w=" << hex(w);
    EXPECT_LE(w, eps) << hex(eps);
    EXPECT_GT(2 * w, eps) << hex(eps);  // 2 w is exact (or +inf); eps / 2 may round
  }
}

TEST(CropPrecisionSupported, MainSettings) {
  EXPECT_TRUE(crop_precision_supported(1e-9, 0.0, 100.0));
  EXPECT_TRUE(crop_precision_supported(1e-3, 0.0, 100.0));
  EXPECT_TRUE(crop_precision_supported(1e-9, 1e5, 1e5 + 10));
  EXPECT_TRUE(crop_precision_supported(1e-9, -1e5 - 10, -1e5));
  EXPECT_TRUE(crop_precision_supported(1e-9, 0.0, 0.0));
  EXPECT_TRUE(crop_precision_supported(1e-300, 0.0, 0.0));
  EXPECT_TRUE(crop_precision_supported(1e-300, -1e-290, 1e-290));
  EXPECT_FALSE(crop_precision_supported(1e-9, 0.0, 1e300));
  EXPECT_FALSE(crop_precision_supported(1e-9, -1e300, 0.0));
  EXPECT_FALSE(crop_precision_supported(1e-9, 1e9, 1e9 + 1));  // ulp(1e9) = 2^-23
  EXPECT_TRUE(crop_precision_supported(1e-3, 1e9, 1e9 + 1));
}

TEST(CropPrecisionSupported, BoundaryIsEightUlps) {
  // For |x| in (2^k, 2^(k+1)) (not a power of two, to stay clear of the two conventions for the
  // ulp of a power of two) ulp(x) = 2^(k-52): supported iff w >= 8 ulp = 2^(k-49) (the interval
  // around a root on a grid point may span kMaxMotionDegree + 1 = 7 ulps).
  for (int k = -900; k <= 900; k += 7) {
    const double x = 1.5 * std::ldexp(1.0, k);
    const double eight_ulp = std::ldexp(1.0, k - 49);
    for (double lo_sign : {1.0, -1.0}) {
      const double lo = lo_sign > 0 ? 0.0 : -x, hi = lo_sign > 0 ? x : 0.0;
      EXPECT_TRUE(crop_precision_supported(eight_ulp, lo, hi)) << "k=" << k;
      EXPECT_TRUE(crop_precision_supported(eight_ulp * 1.9, lo, hi)) << "k=" << k;
      EXPECT_FALSE(crop_precision_supported(eight_ulp / 2, lo, hi)) << "k=" << k;
      EXPECT_FALSE(crop_precision_supported(std::nextafter(eight_ulp, 0.0), lo, hi)) << "k=" << k;
    }
    // The larger end decides.
    EXPECT_FALSE(crop_precision_supported(eight_ulp, -4 * x, x)) << "k=" << k;
    EXPECT_TRUE(crop_precision_supported(eight_ulp, -x / 4, x)) << "k=" << k;
  }
  // At a power of two both conventions agree on these.
  EXPECT_TRUE(crop_precision_supported(0x1p-43, 0.0, 0x1p6 * 1.0));  // 100 < 128: ulp 2^-46
  EXPECT_FALSE(crop_precision_supported(0x1p-44, 0.0, 0x1p6 * 1.0));
  EXPECT_FALSE(crop_precision_supported(0x1p-54, 0.0, 0x1p0));
  EXPECT_TRUE(crop_precision_supported(0x1p-48, 0.0, 0x1p0));
}

// ---------------------------------------------------------------------------------------------
// Identically zero and constant differences.

TEST(CropIdenticallyZero, SamePolynomialWithTwoOrigins) {
  Tally tally;
  // t^2 about 0 vs (t - 1)^2 + 2 (t - 1) + 1 about 1.
  for (double eps : {1e-9, 1e-6, 1e-3}) {
    CropCase cs{motion({0.0, 0.0, 1.0}, 0.0),
                motion({1.0, 2.0, 1.0}, 1.0),
                0.0,
                100.0,
                eps,
                "t^2 two origins",
                QPoly()};
    const Ran ran = checked_case(cs, tally);
    EXPECT_TRUE(ran.r.identically_zero);
    EXPECT_EQ(ran.r.count, 0);
    EXPECT_EQ(ran.r.turbulent_count, 0);
    EXPECT_TRUE(ran.all.empty());
    EXPECT_EQ(ran.r.sign_first, 0);
  }
  // Zero written in different ways; the same motion twice; -0.0.
  const std::vector<std::pair<MotionPolynomial, MotionPolynomial>> pairs = {
      {MotionPolynomial::constant(0.0), MotionPolynomial::constant(-0.0)},
      {motion({0.0}, 5.0), motion({0.0}, -3.0)},
      {motion({2.0, -1.0, 0.5, 3.0}, 7.25), motion({2.0, -1.0, 0.5, 3.0}, 7.25)},
      {motion({1.0, 1.0}, 0.0), motion({3.0, 1.0}, 2.0)},  // t + 1 = (t - 2) + 3
      {motion({0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0}, 0.5),
       motion({0x1p-6, -0x1.8p-3, 0x1.ep-1, -2.5, 3.75, -3.0, 1.0}, 0.0)},  // (t - 1/2)^6
  };
  for (const auto& [a, b] : pairs) {
    CropCase cs{a, b, -5.0, 20.0, 1e-9, "zero pair", QPoly()};
    report_case(cs, tally);
    CropCase far{a, b, 1e5, 1e5 + 10, 1e-9, "zero pair, far window", QPoly()};
    report_case(far, tally);
  }
  // Random motions re-expanded exactly about another dyadic origin.
  Rng rng(0xC0FFEE03);
  int made = 0;
  for (int it = 0; it < 3000 && made < 300; ++it) {
    std::vector<Q> c;
    const int deg = rng.uniform(0, kMaxMotionDegree);
    for (int i = 0; i <= deg; ++i)
      c.push_back(Q(rng.uniform(-2000, 2000)) * pow2(rng.uniform(-20, 5)));
    const double o1 = rng.uniform(-400, 400) / 4.0, o2 = rng.uniform(-400, 400) / 8.0;
    const auto a = ex::to_motion(c, o1);
    const auto b = ex::to_motion(ex::coefficients_about(ex::about(c, Q(o1)), Q(o2)), o2);
    if (!a || !b) continue;
    ++made;
    CropCase cs{*a,
                *b,
                0.0,
                100.0,
                rng.pick(std::vector<double>{1e-9, 1e-6, 1e-3}),
                "exact re-expansion",
                QPoly()};
    report_case(cs, tally);
  }
  EXPECT_GE(made, 100);
  EXPECT_EQ(tally.zero, tally.cases);
  EXPECT_EQ(tally.failures, 0u);
}

TEST(CropConstant, NonZeroConstantDifferenceHasNoIntervals) {
  Tally tally;
  for (double k : {1.0, -1.0, 0x1p-1074, -0x1p-1074, 0x1p1000}) {
    CropCase cs{motion({k + 0.0, 3.0}, 1.0),
                motion({0.0, 3.0}, 1.0),
                0.0,
                100.0,
                1e-9,
                "constant " + hex(k),
                std::nullopt};
    const Ran ran = checked_case(cs, tally);
    EXPECT_FALSE(ran.r.identically_zero);
    EXPECT_EQ(ran.r.count, 0);
    EXPECT_TRUE(ran.all.empty());
    EXPECT_EQ(ran.r.sign_first, k > 0 ? 1 : -1);
  }
}

// ---------------------------------------------------------------------------------------------
// The known traps, one named test each.

/// Runs a hand-made case through the checker and returns crop's result for extra expectations.
Ran run_named(const CropCase& cs) {
  Tally tally;
  return checked_case(cs, tally);
}

/// The interval of `all` holding t, if any.
const CropInterval* holding(const Ran& ran, double t) {
  for (const auto& iv : ran.all)
    if (iv.lambda < t && t < iv.rho) return &iv;
  return nullptr;
}

TEST(CropTrap, DoubleRootAt50NaiveIntervalHornerOverestimates) {
  // (t - 50)^2 over [49.9, 50.1]: naive interval Horner on t^2 - 100 t + 2500 encloses 0 on every
  // subinterval; one turbulent interval around 50 and sign_first = +1 are expected.
  const std::vector<std::pair<MotionPolynomial, MotionPolynomial>> forms = {
      {motion({2500.0, -100.0, 1.0}, 0.0), MotionPolynomial::constant(0.0)},
      {motion({0.0, 0.0, 1.0}, 50.0), MotionPolynomial::constant(0.0)},
      {motion({0.0, 0.0, 1.0}, 0.0), motion({-2500.0, 100.0}, 0.0)},
      {motion({0.0, 0.0, 1.0}, 0.0), motion({2500.0, 100.0}, 50.0)},  // 100 (t - 50) + 2500
  };
  for (double eps : {1e-9, 1e-6, 1e-3}) {
    for (const auto& [u, l] : forms) {
      const Ran ran = run_named({u, l, 49.9, 50.1, eps, "(t-50)^2", std::nullopt});
      EXPECT_EQ(ran.r.count, 0) << "eps=" << eps;
      EXPECT_EQ(ran.r.sign_first, 1) << "eps=" << eps;
      ASSERT_EQ(ran.all.size(), 1u) << "eps=" << eps;
      EXPECT_NE(holding(ran, 50.0), nullptr);
      EXPECT_FALSE(ran.all[0].is_event());
    }
  }
  // (t - 50)^2 - 2^-80: roots 50 +- 2^-40, one grid cell: one turbulent interval.
  {
    const Ran ran = run_named({motion({-0x1p-80, 0.0, 1.0}, 50.0), MotionPolynomial::constant(0.0),
                               49.9, 50.1, 1e-9, "(t-50)^2 - 2^-80", std::nullopt});
    EXPECT_EQ(ran.r.count, 0);
    EXPECT_EQ(ran.all.size(), 1u);
  }
  // (t - 50)^2 - 2^-56: roots 50 +- 2^-28, 2^-27 apart > eps = 1e-9: two events.
  {
    const Ran ran = run_named({motion({-0x1p-56, 0.0, 1.0}, 50.0), MotionPolynomial::constant(0.0),
                               49.9, 50.1, 1e-9, "(t-50)^2 - 2^-56", std::nullopt});
    EXPECT_EQ(ran.r.count, 2);
    EXPECT_NE(holding(ran, 50.0 - 0x1p-28), nullptr);
    EXPECT_NE(holding(ran, 50.0 + 0x1p-28), nullptr);
  }
  // (t - 50)^2 + 2^-80: no real root; no event, sign +.
  {
    const Ran ran = run_named({motion({0x1p-80, 0.0, 1.0}, 50.0), MotionPolynomial::constant(0.0),
                               49.9, 50.1, 1e-9, "(t-50)^2 + 2^-80", std::nullopt});
    EXPECT_EQ(ran.r.count, 0);
    EXPECT_EQ(ran.r.sign_first, 1);
  }
}

TEST(CropTrap, RootExactlyAtBisectionMidpoint) {
  // Roots at j w (midpoints of grid cells), including the window's centre and its halvings.
  for (double eps : {1e-9, 1e-6, 1e-3}) {
    const double w = expected_grid_width(eps);
    for (double r : {50.0, 25.0, 75.0, 12.5, 37.5, 0.0 + w, 100.0 - w, 64.0, 33.0 * w}) {
      for (int mult : {1, 2, 3}) {
        std::vector<double> c(static_cast<std::size_t>(mult) + 1, 0.0);
        c.back() = 1.0;
        const Ran ran = run_named({motion(c, r), MotionPolynomial::constant(0.0), 0.0, 100.0, eps,
                                   "(t - " + num(r) + ")^" + std::to_string(mult), std::nullopt});
        const CropInterval* iv = holding(ran, r);
        ASSERT_NE(iv, nullptr) << "r=" << r << " mult=" << mult << " eps=" << eps;
        EXPECT_EQ(iv->is_event(), mult % 2 == 1) << "r=" << r << " mult=" << mult;
        EXPECT_EQ(ran.r.count, mult % 2);
      }
      // A pair around the midpoint, inside one cell.
      const Ran pair =
          run_named({motion({-w * w / 64, 0.0, 1.0}, r), MotionPolynomial::constant(0.0), 0.0,
                     100.0, eps, "pair around " + num(r), std::nullopt});
      EXPECT_EQ(pair.r.count, 0) << "r=" << r;
    }
    // The grid points where a subdivision of the window's grid indices splits first (either
    // rounding of the middle index), with simple, double and triple roots there.
    std::vector<std::pair<Z, Z>> boxes = {
        {floor_q(Q(0.0) / Q(w) - Q(1, 2)), ceil_q(Q(100.0) / Q(w) - Q(1, 2))}};
    for (int level = 0; level < 4; ++level) {
      std::vector<std::pair<Z, Z>> next;
      for (const auto& [a, b] : boxes) {
        if (b - a < 2) continue;
        const Z sum = a + b;
        for (const Z& m : {floor_q(Q(sum) / 2), ceil_q(Q(sum) / 2)}) {
          const double g = grid_point(m, w).get_d();
          for (int mult : {1, 2, 3}) {
            std::vector<double> c(static_cast<std::size_t>(mult) + 1, 0.0);
            c.back() = -1.0;
            const Ran ran =
                run_named({motion(c, g), MotionPolynomial::constant(0.0), 0.0, 100.0, eps,
                           "split grid point, mult " + std::to_string(mult), std::nullopt});
            const CropInterval* iv = holding(ran, g);
            ASSERT_NE(iv, nullptr) << "g=" << hex(g);
            EXPECT_EQ(iv->is_event(), mult % 2 == 1);
          }
        }
        const Z m = floor_q(Q(sum) / 2);
        next.push_back({a, m});
        next.push_back({m, b});
      }
      boxes = std::move(next);
    }
  }
}

TEST(CropTrap, OddWindows) {
  // eps wider than the window: w = 512, window [-256, 256]; a root outside [lo, hi] but inside
  // the searched window must be covered too (A2 is stated for the searched window).
  {
    const Ran both =
        run_named({motion({30.0 * 70.0, -100.0, 1.0}, 0.0), MotionPolynomial::constant(0.0), 0.0,
                   100.0, 1000.0, "(t-30)(t-70), eps 1000", std::nullopt});
    EXPECT_EQ(both.r.count, 0);
    EXPECT_EQ(both.r.window_lo, -256.0);
    EXPECT_EQ(both.r.window_hi, 256.0);
    const Ran outside = run_named({motion({-200.0, 1.0}, 0.0), MotionPolynomial::constant(0.0), 0.0,
                                   100.0, 1000.0, "t - 200, eps 1000", std::nullopt});
    EXPECT_EQ(outside.r.count, 1);
  }
  // Empty windows lo == hi: at a root, next to one, at a grid point that is a root.
  for (double eps : {1e-9, 1e-3}) {
    const double w = expected_grid_width(eps);
    const double g = grid_floor(50.0, w).get_d();
    for (double x : {50.0, std::nextafter(50.0, 0.0), g, std::nextafter(g, 100.0)}) {
      for (int mult : {1, 2, 3}) {
        std::vector<double> c(static_cast<std::size_t>(mult) + 1, 0.0);
        c.back() = 1.0;
        const Ran ran = run_named({motion(c, 50.0), MotionPolynomial::constant(0.0), x, x, eps,
                                   "empty window at " + hex(x), std::nullopt});
        if (x == 50.0) {
          EXPECT_NE(holding(ran, 50.0), nullptr);
        }
      }
    }
  }
  // Tiny and subnormal windows and grids.
  const std::vector<std::pair<std::vector<double>, double>> tiny = {
      {{-1e-310, 1.0}, 0.0},          // root at 1e-310 (subnormal)
      {{0.0, 1.0}, 0.0},              // root at 0
      {{0.0, -1e-300, 1.0}, 1e-300},  // roots 1e-300 and 2e-300
      {{0.0, 0.0, 1.0}, 0x1p-1060},   // double root at a subnormal-grid point
      {{0x1p-1074, 1.0}, 0.0},        // root at -denorm_min
  };
  const std::vector<Setting> windows = {{0.0, 1e-310, 1e-315},
                                        {-1e-310, 1e-310, 1e-318},
                                        {1e-300, 3e-300, 1e-305},
                                        {0.0, 0.0, 1e-320},
                                        {-1e-300, 1e-300, 1e-310}};
  for (const auto& [c, o] : tiny) {
    for (const auto& s : windows) {
      if (!crop_precision_supported(s.eps, s.lo, s.hi)) continue;
      run_named({motion(c, o), MotionPolynomial::constant(0.0), s.lo, s.hi, s.eps, "tiny window",
                 std::nullopt});
    }
  }
}

TEST(CropTrap, RootAFewUlpsPastTheWindowEnd) {
  for (double eps : {1e-9, 1e-3}) {
    for (const auto& [lo, hi] :
         {std::pair{0.0, 100.0}, std::pair{49.9, 50.1}, std::pair{1e5, 1e5 + 10}}) {
      for (int k = -4; k <= 4; ++k) {
        for (bool at_hi : {true, false}) {
          double r = at_hi ? hi : lo;
          const double dir = (k > 0) == at_hi ? 1e300 : -1e300;  // k > 0: outside the window
          for (int u = 0; u < std::abs(k); ++u) r = std::nextafter(r, dir);
          for (int mult : {1, 2}) {
            std::vector<double> c(static_cast<std::size_t>(mult) + 1, 0.0);
            c.back() = -1.0;
            const Ran ran =
                run_named({motion(c, r), MotionPolynomial::constant(0.0), lo, hi, eps,
                           "root " + std::to_string(k) + " ulps past " + (at_hi ? "hi" : "lo"),
                           std::nullopt});
            if (k <= 0) {  // inside [lo, hi] (or on its end): must be covered
              const CropInterval* iv = holding(ran, r);
              ASSERT_NE(iv, nullptr) << "k=" << k << " lo=" << lo << " hi=" << hi;
              EXPECT_EQ(iv->is_event(), mult == 1);
            }
          }
        }
      }
    }
  }
}

TEST(CropTrap, ClosePairsAndNearDoubleRoots) {
  // (t - r)(t - r - g) expanded about 0 where exact: the textbook quadratic formula loses the
  // discriminant to cancellation (misses close pairs, invents double roots).
  int run = 0;
  for (double eps : {1e-9, 1e-6, 1e-3}) {
    const double w = expected_grid_width(eps);
    for (double r : {50.0, 1.0, 0.75, 99.5}) {
      for (int gexp = -46; gexp <= -2; ++gexp) {
        const double g = std::ldexp(1.0, gexp);
        const Q R(r), G(g);
        const QPoly p = ex::mul(ex::linear_root(R), ex::linear_root(R + G));
        auto m = ex::to_motion(p.c, 0.0);
        if (!m) m = ex::to_motion(ex::coefficients_about(p, R), r);
        ASSERT_TRUE(m.has_value());
        for (double sign : {1.0, -1.0}) {
          MotionPolynomial u = *m;
          for (auto& x : u.c) x *= sign;
          const Ran ran = run_named({u, MotionPolynomial::constant(0.0), 0.0, 100.0, eps,
                                     "pair gap 2^" + std::to_string(gexp), std::nullopt});
          ++run;
          if (g > eps) {
            EXPECT_EQ(ran.r.count, 2) << "r=" << r << " g=2^" << gexp << " eps=" << eps;
          }
          if (g < w / 2) {
            // Both roots in one interval or in two: either way no root may be lost.
            EXPECT_NE(holding(ran, r), nullptr);
          }
        }
      }
      // Near-double roots (t - r)^2 -+ d and a double root next to a simple one.
      for (int dexp = -100; dexp <= -8; dexp += 4) {
        const double d = std::ldexp(1.0, dexp);
        for (double s : {1.0, -1.0}) {
          const Ran ran =
              run_named({motion({s * d, 0.0, 1.0}, r), MotionPolynomial::constant(0.0), 0.0, 100.0,
                         eps, "(t - r)^2 + s 2^" + std::to_string(dexp), std::nullopt});
          if (s > 0) {
            EXPECT_EQ(ran.r.count, 0) << "no real root: no event";
          }
          ++run;
        }
      }
      for (int gexp = -44; gexp <= -4; gexp += 5) {
        const double g = std::ldexp(1.0, gexp);
        const QPoly p = ex::mul(ex::power(ex::linear_root(Q(0)), 2), ex::linear_root(Q(g)));
        const auto m = ex::to_motion(p.c, r);
        ASSERT_TRUE(m.has_value());
        const Ran ran =
            run_named({*m, MotionPolynomial::constant(0.0), 0.0, 100.0, eps,
                       "double root + simple at 2^" + std::to_string(gexp), std::nullopt});
        EXPECT_EQ(ran.r.count, 1);
        ++run;
      }
    }
  }
  EXPECT_GT(run, 500);
}

TEST(CropTrap, RootExactlyAtGridEndpoint) {
  for (double eps : {1e-9, 1e-6, 1e-3}) {
    const double w = expected_grid_width(eps);
    for (double approx : {50.0, 0.0, 100.0, 3.3, 99.99}) {
      const double g = grid_floor(approx, w).get_d();
      ASSERT_TRUE(on_grid(g, w));
      for (int mult : {1, 2, 3}) {
        std::vector<double> c(static_cast<std::size_t>(mult) + 1, 0.0);
        c.back() = 1.0;
        const Ran ran = run_named({motion(c, g), MotionPolynomial::constant(0.0), 0.0, 100.0, eps,
                                   "(t - g)^" + std::to_string(mult), std::nullopt});
        const CropInterval* iv = holding(ran, g);
        ASSERT_NE(iv, nullptr) << "g=" << hex(g) << " mult=" << mult;
        EXPECT_EQ(iv->is_event(), mult % 2 == 1);
        // The header: (pred(g), succ(g)) (f has no other zero nearby).
        EXPECT_EQ(iv->lambda, std::nextafter(g, -1e300)) << "g=" << hex(g);
        EXPECT_EQ(iv->rho, std::nextafter(g, 1e300)) << "g=" << hex(g);
      }
      // Roots at two neighbouring grid points; at a grid point and the next midpoint; at a grid
      // point and a few ulps away.
      const std::vector<std::vector<Q>> others = {{Q(w)},
                                                  {Q(w) / 2},
                                                  {-Q(w) / 2},
                                                  {Q(w) / 4, -Q(w) / 4},
                                                  {pow2(std::ilogb(g == 0 ? 1.0 : g) - 50)}};
      for (const auto& extra : others) {
        QPoly p = ex::linear_root(Q(0));
        for (const auto& a : extra) p = ex::mul(p, ex::linear_root(a));
        const auto m = ex::to_motion(p.c, g);
        ASSERT_TRUE(m.has_value());
        const Ran ran = run_named({*m, MotionPolynomial::constant(0.0), 0.0, 100.0, eps,
                                   "root at grid point + neighbours", std::nullopt});
        EXPECT_NE(holding(ran, g), nullptr);
      }
    }
  }
}

TEST(CropTrap, RootsOnConsecutiveDoublesAroundAGridPointAtThePrecisionLimit) {
  // A root at a grid point g with more roots on the doubles next to it: "(pred(g), succ(g))
  // widened to the nearest doubles where f != 0" spans up to 7 ulps. A grid of 4 ulps would
  // break (A1) (found by this test); crop_precision_supported therefore asks for 8 ulps, and at
  // that limit every interval stays within eps.
  struct Setup {
    double lo, hi, eps;
  };
  for (const Setup& st : {Setup{1.0, 1.5, 0x1p-49}, Setup{0x1p21 - 2.0, 0x1p21 - 1.0, 2e-9},
                          Setup{-1.5, -1.0, 0x1p-49}}) {
    const double w = expected_grid_width(st.eps);
    const double g = grid_floor(st.lo / 2 + st.hi / 2, w).get_d();
    const double u = std::nextafter(std::abs(g), 1e300) - std::abs(g);  // ulp(g)
    ASSERT_EQ(w, 8 * u);
    ASSERT_TRUE(crop_precision_supported(st.eps, st.lo, st.hi));
    ASSERT_FALSE(crop_precision_supported(st.eps / 2, st.lo, st.hi));
    // Roots at g - u, g, g + u, g + 2u (and one more at g - 2u): about origin g.
    for (const std::vector<int>& ks : {std::vector<int>{-1, 0, 1, 2}, {-2, -1, 0, 1, 2}}) {
      QPoly p = ex::constant(1);
      for (int k : ks) p = ex::mul(p, ex::linear_root(Q(k) * Q(u)));
      const auto m = ex::to_motion(p.c, g);
      ASSERT_TRUE(m.has_value());
      const Ran ran = run_named(
          {*m, MotionPolynomial::constant(0.0), st.lo, st.hi, st.eps,
           std::to_string(ks.size()) + " roots on consecutive doubles at " + hex(g), std::nullopt});
      for (const auto& iv : ran.all)
        EXPECT_LE(Q(iv.rho) - Q(iv.lambda), Q(st.eps))
            << "interval " << describe_interval(iv) << " is wider than eps = " << hex(st.eps);
    }
  }
}

TEST(CropTrap, ExtremeScales) {
  // Planted roots in [0, 100] scaled by 2^e up to the ends of the double range, where the
  // floating-point filters and interval enclosures overflow or underflow: exact signs must take
  // over. Roots r_k = 50 + k/4 (k = -3..2), about origin 50.
  for (int e : {900, 1000, -900, -1000, -1070}) {
    for (int deg = 1; deg <= kMaxMotionDegree; ++deg) {
      QPoly p = ex::constant(pow2(e));
      for (int k = 0; k < deg; ++k) p = ex::mul(p, ex::linear_root(Q(k - 3, 4)));
      const auto m = ex::to_motion(p.c, 50.0);
      if (!m) continue;  // a coefficient overflowed or underflowed
      for (double eps : {1e-9, 1e-3}) {
        const Ran ran = run_named(
            {*m, MotionPolynomial::constant(0.0), 0.0, 100.0, eps,
             "scale 2^" + std::to_string(e) + ", degree " + std::to_string(deg), std::nullopt});
        EXPECT_EQ(ran.r.count, deg) << "e=" << e << " deg=" << deg;
      }
    }
  }
}

TEST(CropTrap, FarWindowAndHugeTinyScales) {
  // Roots near 1e5 written about origin 0 (huge cancellation) and about 1e5; scales 2^+-200.
  for (int scale : {0, 200, -200}) {
    for (double eps : {1e-9, 1e-6}) {
      const double r1 = 1e5 + 3.25, r2 = 1e5 + 3.25 + 0x1p-14;  // r1 r2 fits 53 bits
      const QPoly p =
          ex::scale(ex::mul(ex::linear_root(Q(r1)), ex::linear_root(Q(r2))), pow2(scale));
      for (double origin : {0.0, 1e5, r1}) {
        const auto m = ex::to_motion(ex::coefficients_about(p, Q(origin)), origin);
        if (!m) continue;
        const Ran ran = run_named({*m, MotionPolynomial::constant(0.0), 1e5, 1e5 + 10, eps,
                                   "far pair about " + num(origin), std::nullopt});
        EXPECT_EQ(ran.r.count, 2);
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// The quadratic path (derivative split, docs/crop.md): certificates of degree exactly 2 are
// split at the grid point next to the vertex, where f' changes sign. Each case is checked
// against the oracle; the cases expected to stay on that path also check that no Bernstein box
// was needed (the path finished the call).

/// Runs a case; returns the tally (boxes, fast_path) of the checked call and its result.
struct QuadRun {
  Ran ran;
  Tally tally;
};

QuadRun run_quadratic(const CropCase& cs) {
  QuadRun out;
  out.ran = checked_case(cs, out.tally);
  return out;
}

/// a (t - v)^2 + e about origin v, exactly (nullopt when a coefficient is not a double).
std::optional<MotionPolynomial> vertex_form(const Q& a, const Q& v, const Q& e, double origin) {
  const QPoly p = ex::add(ex::scale(ex::power(ex::linear_root(v), 2), a), ex::constant(e));
  return ex::to_motion(ex::coefficients_about(p, Q(origin)), origin);
}

TEST(CropQuadraticPath, TwoRootsAroundTheVertex) {
  // (t - v + h)(t - v - h) sigma, about v and written as the difference of two motions with
  // other origins; h from far apart down to one cell.
  for (double eps : {1e-9, 1e-6}) {
    const double w = expected_grid_width(eps);
    for (double v : {50.25, 3.0 + 0x1p-20, 99.0}) {
      for (int hexp = -20; hexp <= 4; hexp += 2) {
        const double h = std::ldexp(1.0, hexp);
        for (int sigma : {1, -1}) {
          const Q a(sigma);
          const auto f = vertex_form(a, Q(v), -a * Q(h) * Q(h), v);
          ASSERT_TRUE(f.has_value());
          const QuadRun q = run_quadratic({*f, MotionPolynomial::constant(0.0), 0.0, 100.0, eps,
                                           "roots v +- 2^" + std::to_string(hexp), std::nullopt});
          const int inside = (v - h >= 0.0 ? 1 : 0) + (v + h <= 100.0 ? 1 : 0);
          if (2.0 * h > 2.0 * w) {
            EXPECT_EQ(q.ran.r.count, inside) << "v=" << v << " h=2^" << hexp;
          }
          EXPECT_EQ(q.tally.boxes, 0u) << "v=" << v << " h=2^" << hexp;
          EXPECT_GE(q.tally.fast_path, 1u);
          // The same f as upper - lower with different origins (a linear lower motion).
          const Q o2(7.5);
          const QPoly lower_t = QPoly({Q(3), Q(1, 4)});  // 3 + t/4
          const QPoly upper_t = ex::add(ex::from_motion(*f), lower_t);
          const auto up = ex::to_motion(ex::coefficients_about(upper_t, Q(0)), 0.0);
          const auto lo = ex::to_motion(ex::coefficients_about(lower_t, o2), o2.get_d());
          if (!up || !lo) continue;
          const QuadRun q2 =
              run_quadratic({*up, *lo, 0.0, 100.0, eps,
                             "two origins, roots v +- 2^" + std::to_string(hexp), std::nullopt});
          EXPECT_EQ(q2.ran.r.count, q.ran.r.count) << "v=" << v << " h=2^" << hexp;
        }
      }
    }
  }
}

TEST(CropQuadraticPath, VertexOnAGridPoint) {
  // f'(g) == 0 exactly at a grid point g: the split cell starts at g. Roots at g +- h, none, or a
  // double root at g itself (f(g) == 0: the general path takes over).
  for (double eps : {1e-9, 1e-6, 1e-3}) {
    const double w = expected_grid_width(eps);
    for (double approx : {50.0, 0.3, 99.9}) {
      const double g = grid_floor(approx, w).get_d();
      // Roots at g +- h for h = 2^-40 (below every cell), 3w/4 and 11w/4 (never on the grid).
      const Q cell(w);
      const std::vector<Q> offsets{
          Q(0),      Q(-pow2(-80)), Q(-cell * cell * 9 / 16), Q(-cell * cell * 121 / 16),
          pow2(-80), Q(1, 1024)};
      for (const Q& e : offsets) {
        for (int sigma : {1, -1}) {
          const auto f = vertex_form(Q(sigma), Q(g), Q(sigma) * e, g);
          ASSERT_TRUE(f.has_value());
          const QuadRun q = run_quadratic(
              {*f, MotionPolynomial::constant(0.0), 0.0, 100.0, eps, "vertex at g", std::nullopt});
          if (sgn(e) > 0) {
            EXPECT_EQ(q.ran.r.count, 0);
          }
          if (sgn(e) != 0) {
            EXPECT_EQ(q.tally.boxes, 0u) << "g=" << hex(g) << " e=" << e.get_d();
          } else {
            const CropInterval* iv = holding(q.ran, g);
            ASSERT_NE(iv, nullptr);
            EXPECT_FALSE(iv->is_event());
          }
        }
      }
    }
  }
}

TEST(CropQuadraticPath, DoubleRootsOnAndNearGridPoints) {
  // (t - r)^2 for r a grid point, a few ulps from one, a cell's midpoint, and w/4 from a grid
  // point; with + and - 2^-k offsets (near-double roots and complex pairs just off the axis).
  for (double eps : {1e-9, 1e-6}) {
    const double w = expected_grid_width(eps);
    for (double approx : {50.0, 12.3}) {
      const double g = grid_floor(approx, w).get_d();
      std::vector<double> places{g, g + w / 2, g + w / 4, g - w / 4};
      for (int k = 1; k <= 3; ++k) {
        double above = g, below = g;
        for (int i = 0; i < k; ++i) {
          above = std::nextafter(above, 1e300);
          below = std::nextafter(below, -1e300);
        }
        places.push_back(above);
        places.push_back(below);
      }
      for (double r : places) {
        for (int dexp : {0, -100, -70, -62, -58}) {
          for (int s : {1, -1}) {
            const Q e = dexp == 0 ? Q(0) : Q(s) * pow2(dexp);
            const auto f = vertex_form(Q(1), Q(r), e, r);
            ASSERT_TRUE(f.has_value());
            const QuadRun q = run_quadratic({*f, MotionPolynomial::constant(0.0), 0.0, 100.0, eps,
                                             "double root near a grid point", std::nullopt});
            if (dexp == 0 || s > 0) {
              EXPECT_EQ(q.ran.r.count, 0);
            }
            if (dexp == 0 && r != g) {
              // An exact double root inside a cell: one turbulent interval, found by the split.
              EXPECT_EQ(q.ran.all.size(), 1u) << "r=" << hex(r);
              EXPECT_NE(holding(q.ran, r), nullptr) << "r=" << hex(r);
              EXPECT_EQ(q.tally.boxes, 0u) << "r=" << hex(r);
            }
          }
        }
      }
    }
  }
}

TEST(CropQuadraticPath, DoubleRootWithDifferentOriginsNeedsTheExactDiscriminant) {
  // (t - v)^2 = t^2 - (2 v t - v^2), the linear part written about another origin: the frame is
  // an interval Taylor shift, the discriminant is exactly 0 (GMP decides it).
  for (double v : {50.5, 0x1.9p5 + 0x1p-20}) {
    const Q V(v), o2(3);
    const QPoly lower_t = QPoly({-V * V, 2 * V});
    const auto lo = ex::to_motion(ex::coefficients_about(lower_t, o2), o2.get_d());
    ASSERT_TRUE(lo.has_value());
    const MotionPolynomial up = motion({0.0, 0.0, 1.0}, 0.0);
    for (double eps : {1e-9, 1e-6}) {
      const QuadRun q =
          run_quadratic({up, *lo, 0.0, 100.0, eps, "(t - v)^2, two origins", std::nullopt});
      EXPECT_EQ(q.ran.r.count, 0);
      ASSERT_EQ(q.ran.all.size(), 1u);
      EXPECT_NE(holding(q.ran, v), nullptr);
      EXPECT_EQ(q.tally.boxes, 0u);
      EXPECT_GE(q.tally.exact, 1u);
    }
  }
}

TEST(CropQuadraticPath, VertexOutsideAndRootsAtTheWindowEnds) {
  // Monotone on the window (vertex before or after it), roots exactly at, 1-3 ulps around, and
  // just inside or outside the window's ends.
  for (double eps : {1e-9, 1e-6}) {
    for (double lo_hi_root : {0.0, 100.0, 0x1p-40, 100.0 - 0x1p-40}) {
      for (int du : {-3, -1, 0, 1, 3}) {
        double r = lo_hi_root;
        for (int i = 0; i < std::abs(du); ++i) r = std::nextafter(r, du > 0 ? 1e300 : -1e300);
        for (double other : {-50.0, -1.0, 101.0, 250.0}) {
          for (int sigma : {1, -1}) {
            // sigma (t - r)(t - other), about r.
            const QPoly p =
                ex::scale(ex::mul(ex::linear_root(Q(r)), ex::linear_root(Q(other))), Q(sigma));
            const auto f = ex::to_motion(ex::coefficients_about(p, Q(r)), r);
            if (!f) continue;
            const QuadRun q = run_quadratic({*f, MotionPolynomial::constant(0.0), 0.0, 100.0, eps,
                                             "root at a window end", std::nullopt});
            const bool inside = r > 0.0 && r < 100.0;
            if (inside) {
              EXPECT_EQ(q.ran.r.count, 1) << "r=" << hex(r) << " other=" << other;
            }
          }
        }
      }
    }
  }
}

TEST(CropQuadraticPath, RandomFeaturesNearTheVertex) {
  // Random quadratics sigma a ((t - v)^2 - e) with the vertex in, near or outside the window,
  // e log-uniform of both signs (root pairs from far apart to far below a cell, complex pairs),
  // written as upper - lower with random origins; against the oracle, both orientations.
  Tally tally;
  Rng rng(0x5EED00A2);
  int made = 0;
  for (int it = 0; it < 200000 && made < 20000; ++it) {
    const double eps = rng.pick(std::vector<double>{1e-9, 1e-6, 1e-3});
    const double w = expected_grid_width(eps);
    const double lo = rng.pick(std::vector<double>{0.0, -7.25, 40.0});
    const double hi = lo + rng.pick(std::vector<double>{100.0, 1.0, 0.0});
    // The vertex: a short dyadic in or near the window, or a grid point, or next to one.
    double v =
        std::ldexp(std::round(std::ldexp(lo - 10.0 + (hi - lo + 20.0) * rng.unit(), 16)), -16);
    if (rng.chance(1, 4)) v = grid_floor(v, w).get_d();
    if (rng.chance(1, 8)) v = std::nextafter(v, rng.chance(1, 2) ? 1e300 : -1e300);
    const Q a = Q(rng.pick(std::vector<int>{1, -1, 3, -3, 5, -7})) * pow2(rng.uniform(-6, 3));
    // e = h^2 (roots v +- h) or -h^2 (a complex pair), h from far apart down to far below a cell.
    const Q h = Q(rng.uniform(1, 15)) * pow2(rng.uniform(-60, 2));
    Q e = h * h;
    if (rng.chance(1, 2)) e = -e;
    if (rng.chance(1, 10)) e = 0;
    const QPoly f = ex::scale(ex::sub(ex::power(ex::linear_root(Q(v)), 2), ex::constant(e)), a);
    // lower: zero, or a linear or quadratic motion about its own origin; upper = f + lower.
    const double ol = rng.chance(1, 3) ? v : std::ldexp(std::round(rng.unit() * 1024.0), -3);
    const double ou = rng.chance(1, 2) ? v : ol;
    std::vector<Q> lc{Q(rng.uniform(-4000, 4000)) / 64, Q(rng.uniform(-256, 256)) / 64};
    if (rng.chance(1, 2)) lc.push_back(Q(rng.uniform(-64, 64)) / 64);
    if (rng.chance(1, 4)) lc = {Q(0)};
    const QPoly lower_t = ex::about(lc, Q(ol));
    const auto lower = ex::to_motion(ex::coefficients_about(lower_t, Q(ol)), ol);
    const auto upper = ex::to_motion(ex::coefficients_about(ex::add(f, lower_t), Q(ou)), ou);
    if (!lower || !upper) continue;
    ++made;
    CropCase cs{*upper, *lower, lo, hi, eps, "random vertex feature", f};
    report_case(cs, tally);
  }
  std::printf("[ quadratic path ] %d cases made: %s\n", made, tally.summary().c_str());
  EXPECT_GE(made, 15000);
  EXPECT_EQ(tally.failures, 0u);
}

TEST(CropLinearPath, LinearPairsAndCongruentParabolas) {
  // The lean path for a linear f: two motions of degree <= 1, or two parabolas with the same
  // leading coefficient (PARABOLA's certificates), with equal or different origins, roots inside,
  // outside, at a window end and exactly on a grid point, and constant differences.
  Tally tally;
  Rng rng(0x5EED00A3);
  int made = 0;
  for (int it = 0; it < 20000; ++it) {
    const double eps = rng.pick(std::vector<double>{1e-9, 1e-6, 1e-3});
    const double w = expected_grid_width(eps);
    const double lo = rng.pick(std::vector<double>{0.0, -45.0, 10.0});
    const double hi = lo + rng.pick(std::vector<double>{90.0, 1.0, 0.0});
    const bool parabola = rng.chance(1, 2);
    const double A = parabola ? rng.uniform(-64, 64) / 16.0 : 0.0;
    auto motion_about = [&](double origin) {
      std::vector<double> c{rng.uniform(-4000, 4000) / 64.0, rng.uniform(-256, 256) / 64.0};
      if (rng.chance(1, 8)) c[1] = 0.0;
      if (parabola) c.push_back(A);
      return MotionPolynomial::from(c, origin);
    };
    const double ou = rng.uniform(-400, 400) / 8.0;
    const double ol = rng.chance(1, 3) ? ou : rng.uniform(-400, 400) / 8.0;
    MotionPolynomial u = motion_about(ou), l = motion_about(ol);
    if (rng.chance(1, 8)) {  // parallel, or congruent with the same apex
      l.c[1] = u.c[1];
      l = MotionPolynomial::from(std::vector<double>(l.c.begin(), l.c.end()), l.origin);
    }
    // Now and then move u so that f vanishes exactly at a grid point g (f(g) = 0 needs
    // u(g) = l(g); kept only when exact).
    if (rng.chance(1, 6)) {
      const double g = grid_floor(lo + (hi - lo) * rng.unit(), w).get_d();
      const Q shift = ex::eval(ex::sub(ex::from_motion(l), ex::from_motion(u)), Q(g));
      const Q c0 = Q(u.c[0]) + shift;
      if (!ex::representable(c0)) continue;
      u.c[0] = c0.get_d();
    }
    ++made;
    report_case({u, l, lo, hi, eps, parabola ? "congruent parabolas" : "linear pair", std::nullopt},
                tally);
  }
  std::printf("[ linear path ] %d cases made: %s\n", made, tally.summary().c_str());
  EXPECT_GE(made, 15000);
  EXPECT_GT(tally.grid_zero_intervals, 100u);
  EXPECT_EQ(tally.failures, 0u);
}

TEST(CropLinearPath, HardCasesAgainstTheOracle) {
  // The lean linear path (two motions of degree <= 1, congruent parabolas) at its edges: origins
  // equal, far apart or full-mantissa doubles (so that o_l - o_u rounds), huge, tiny and
  // near-underflow coefficients, roots exactly on grid points, at the window's ends and a few
  // ulps past them, parallel and identical motions, and constant differences written about
  // different origins (upper != lower, f identically zero). Against the oracle, both orientations,
  // and crop_event_time() against event_time(crop()) (check_case).
  constexpr std::uint64_t kSeed = 0x5EED00A4;
  Tally tally;
  Rng rng(kSeed);
  int made = 0;
  for (int it = 0; it < 20000; ++it) {
    const Setting st = pick_setting(rng);
    const double w = expected_grid_width(st.eps);
    const bool parabola = rng.chance(1, 3);
    auto pick_origin = [&]() -> double {
      switch (rng.uniform(0, 4)) {
        case 0:
          return 0.0;
        case 1:
          return st.lo;
        case 2:
          return random_in(rng, st.lo - 10.0, st.hi + 10.0);  // a full mantissa
        case 3:
          return rng.mantissa_double(rng.uniform(-20, 20));
        default:
          return std::round(random_in(rng, -50.0, 50.0));
      }
    };
    const double ou = pick_origin();
    const double ol = rng.chance(1, 3) ? ou : pick_origin();
    const double A = parabola ? rng.mantissa_double(rng.uniform(-4, 4)) : 0.0;
    auto slope = [&]() { return rng.chance(1, 8) ? 0.0 : rng.mantissa_double(rng.uniform(-6, 6)); };
    const double su = slope();
    const double sl = rng.chance(1, 6) ? su : slope();
    auto make = [&](double c0, double c1, double origin) {
      std::vector<double> c{c0, c1};
      if (parabola) c.push_back(A);
      return MotionPolynomial::from(c, origin);
    };
    MotionPolynomial l = make(rng.mantissa_double(rng.uniform(-4, 8)), sl, ol);
    MotionPolynomial u = make(0.0, su, ou);
    // Where f should vanish: a grid point, a window end or a few ulps past it, the grid-widened
    // window end, a random time; u's constant term then makes u - l vanish there (exactly when
    // the constant is representable, else about there).
    double target = 0.0;
    const int kind = rng.uniform(0, 6);
    const double lo = st.lo, hi = st.hi;
    switch (kind) {
      case 0:
        target = grid_floor(random_in(rng, lo, hi), w).get_d();
        break;
      case 1:
        target = rng.chance(1, 2) ? lo : hi;
        break;
      case 2: {
        double x = rng.chance(1, 2) ? lo : hi;
        const double dir = rng.chance(1, 2) ? kTimeInfinity : -kTimeInfinity;
        for (int k = rng.uniform(1, 4); k > 0; --k) x = std::nextafter(x, dir);
        target = x;
        break;
      }
      case 3: {
        double x = rng.chance(1, 2) ? grid_floor(lo, w).get_d() : grid_ceil(hi, w).get_d();
        const double dir = rng.chance(1, 2) ? kTimeInfinity : -kTimeInfinity;
        for (int k = rng.uniform(0, 3); k > 0; --k) x = std::nextafter(x, dir);
        target = x;
        break;
      }
      case 4:
        target = random_in(rng, lo - 2.0 * (hi - lo) - 1.0, hi + 2.0 * (hi - lo) + 1.0);
        break;
      default:
        target = random_in(rng, lo, hi);
        break;
    }
    const Q shift = ex::eval(ex::sub(ex::from_motion(l), ex::from_motion(u)), Q(target));
    u.c[0] = shift.get_d();  // exact when representable
    u = MotionPolynomial::from(std::vector<double>(u.c.begin(), u.c.end()), u.origin);
    // Special pairs now and then.
    const int special = rng.uniform(0, 15);
    if (special == 0) {
      u = l;  // identical motions
    } else if (special == 1 && !parabola) {
      // One constant written about two origins: f identically zero, upper != lower.
      u = MotionPolynomial::from(std::vector<double>{l.c[0]}, ou);
      l = MotionPolynomial::from(std::vector<double>{l.c[0]}, ol);
    } else if (special == 2) {
      u = rounded_reexpansion(l, ou);  // the same motion up to rounding, about another origin
    }
    // Scale both (exactly, unless the scaling underflows: the oracle checks what is given).
    const int scale = rng.pick(std::vector<int>{0, 0, 0, 0, -40, 40, -300, 300, 900, -900, -1015});
    if (scale != 0) {
      u = scaled(u, scale);
      l = scaled(l, scale);
      u = MotionPolynomial::from(std::vector<double>(u.c.begin(), u.c.end()), u.origin);
      l = MotionPolynomial::from(std::vector<double>(l.c.begin(), l.c.end()), l.origin);
    }
    if (u.degree > 2 || l.degree > 2) continue;
    ++made;
    report_case({u, l, st.lo, st.hi, st.eps,
                 std::string(parabola ? "congruent parabolas" : "linear pair") +
                     " seed=" + std::to_string(kSeed) + " it=" + std::to_string(it) +
                     " kind=" + std::to_string(kind) + " special=" + std::to_string(special) +
                     " scale=" + std::to_string(scale),
                 std::nullopt},
                tally);
  }
  std::printf("[ linear path, hard cases ] seed %llu, %d cases made: %s\n",
              static_cast<unsigned long long>(kSeed), made, tally.summary().c_str());
  EXPECT_GE(made, 19000);
  EXPECT_GT(tally.grid_zero_intervals, 50u);
  EXPECT_EQ(tally.failures, 0u) << "seed " << kSeed;
}

// ---------------------------------------------------------------------------------------------
// The generated suites.

constexpr int kGenericCases = 40000;
constexpr int kPlantedCases = 40000;
constexpr int kSpecialCases = 24000;

TEST(CropGenerated, GenericRandomPairs) {
  run_suite("generic", 0x5EED0001, kGenericCases, generate_generic);
}

TEST(CropGenerated, PlantedRoots) {
  run_suite("planted", 0x5EED0002, kPlantedCases, generate_planted);
}

TEST(CropGenerated, RootsAtWindowEndsAndGridPoints) {
  run_suite("special", 0x5EED0003, kSpecialCases, generate_special);
}

}  // namespace
}  // namespace kinetic
