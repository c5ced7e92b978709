#pragma once
// The oracle check of a CROP result on a function built from several motions (a
// MotionCombination, a ProductCombination), shared by their tests.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "kinetic/core/crop.hpp"
#include "kinetic/core/scheduler.hpp"
#include "support/exact_poly.hpp"

namespace kinetic::test {

/// Uniform in [0, 1) with 53 random bits (raw mt19937_64 output: fixed by the standard).
inline double unit(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1p-53; }

/// +-m 2^e with a full random mantissa.
inline double full_mantissa(std::mt19937_64& rng, int e) {
  const double v = std::ldexp(1.0 + unit(rng), e);
  return (rng() & 1) != 0 ? -v : v;
}

/// A short dyadic in [-8, 8) with 6 fractional bits: sums and products of a few stay exact.
inline double short_value(std::mt19937_64& rng) {
  return std::ldexp(static_cast<double>(rng() % 1024) - 512.0, -6);
}

/// A motion of the given degree about `origin` with short coefficients (its top one not 0).
inline MotionPolynomial short_motion(std::mt19937_64& rng, int degree, double origin) {
  std::array<double, kMaxMotionDegree + 1> c{};
  for (int k = 0; k <= degree; ++k) c[static_cast<std::size_t>(k)] = short_value(rng);
  if (c[static_cast<std::size_t>(degree)] == 0.0) c[static_cast<std::size_t>(degree)] = 1.0;
  return MotionPolynomial::from(
      std::span<const double>(c.data(), static_cast<std::size_t>(degree) + 1), origin);
}

/// The motion of an exact polynomial about origin o: exact when its coefficients are doubles,
/// else rounded (a planted root then moves by a few ulps).
inline MotionPolynomial motion_of(const exact::QPoly& p, double o) {
  const std::vector<exact::Q> cc = exact::coefficients_about(p, exact::Q(o));
  if (auto m = exact::to_motion(cc, o)) return *m;
  std::array<double, kMaxMotionDegree + 1> d{};
  for (std::size_t i = 0; i < cc.size() && i <= kMaxMotionDegree; ++i) d[i] = cc[i].get_d();
  return MotionPolynomial::from(d, o);
}

/// A case's motions (origin and coefficients in hexadecimal) and CROP window, for a failure
/// message.
inline std::string describe_motions(const std::string& family, std::span<const MotionPolynomial> m,
                                    Time lo, Time hi, double eps) {
  std::ostringstream os;
  if (!family.empty()) os << "  family " << family << '\n';
  for (const MotionPolynomial& p : m) {
    os << "  origin " << exact::hex(p.origin) << " c";
    for (int k = 0; k <= p.degree; ++k) os << ' ' << exact::hex(p.c[static_cast<std::size_t>(k)]);
    os << '\n';
  }
  os << "  window [" << exact::hex(lo) << ", " << exact::hex(hi) << "] eps " << exact::hex(eps);
  return os.str();
}

/// The sign of p just after t from the exact polynomial: its first non-zero derivative at t.
inline int exact_sign_after(exact::QPoly p, double t) {
  while (!p.is_zero()) {
    const int s = exact::sign_at(p, exact::Q(t));
    if (s != 0) return s;
    p = exact::derivative(p);
  }
  return 0;
}

/// A motion of the given degree and origin with full-mantissa coefficients of magnitude
/// 2^-max_exponent .. 2^(max_exponent + 1).
inline MotionPolynomial random_motion(std::mt19937_64& rng, int degree, double origin,
                                      int max_exponent) {
  std::array<double, kMaxMotionDegree + 1> c{};
  for (int k = 0; k <= degree; ++k) {
    c[static_cast<std::size_t>(k)] = full_mantissa(
        rng, static_cast<int>(rng() % static_cast<unsigned>(2 * max_exponent + 1)) - max_exponent);
  }
  return MotionPolynomial::from(
      std::span<const double>(c.data(), static_cast<std::size_t>(degree) + 1), origin);
}

/// A grid point of CROP's grid for precision eps at a random place in [lo, hi].
inline double grid_point(double lo, double hi, double eps, std::mt19937_64& rng) {
  const double w = crop_grid_width(eps);
  const double j = std::floor((lo + (hi - lo) * unit(rng)) / w);
  return (j + 0.5) * w;
}

/// A time to plant a root at, CROP's hard cases: a grid point in [lo, hi], a window end, a few
/// ulps off a grid point, a window end a few ulps off outside, or a plain grid point.
inline double planted_root(std::mt19937_64& rng, double lo, double hi, double eps) {
  double r = grid_point(lo, hi, eps, rng);
  switch (rng() % 5) {
    case 0:
      return lo;
    case 1:
      return hi;
    case 2: {
      const int ulps = 1 + static_cast<int>(rng() % 3);
      for (int k = 0; k < ulps; ++k) r = std::nextafter(r, (rng() & 1) != 0 ? 1e300 : -1e300);
      return r;
    }
    case 3:
      return (rng() & 1) != 0 ? std::nextafter(hi, 1e300) : std::nextafter(lo, -1e300);
    default:
      return r;
  }
}

/// A case of the CROP tests: N motions, a window [lo, hi] and a precision eps, and the name of
/// the family that made it (none when empty), for failure messages.
template <std::size_t N>
struct MotionCase {
  std::array<MotionPolynomial, N> m;
  Time lo = 0.0, hi = 0.0;
  double eps = 0.0;
  std::string family;

  [[nodiscard]] std::string describe() const { return describe_motions(family, m, lo, hi, eps); }
};

/// The window the CROP generators draw: eps = 2^-4 .. 2^-(3 + eps_exponents), lo a
/// full-mantissa value of magnitude 1 .. 2 (either sign), hi 0.5 .. 4.5 after it.
template <class Case>
void draw_window(std::mt19937_64& rng, Case& cs, int eps_exponents = 12) {
  cs.eps = std::ldexp(1.0, -static_cast<int>(rng() % static_cast<unsigned>(eps_exponents)) - 4);
  cs.lo = full_mantissa(rng, 0);
  cs.hi = cs.lo + (0.5 + 4.0 * unit(rng));
}

/// Random motions of one random degree bound (1 .. 3), each of degree 1 .. that bound, with
/// random origins; returns the bound.
inline int draw_motions_up_to_cubic(std::mt19937_64& rng, std::span<MotionPolynomial> m) {
  const int degree = 1 + static_cast<int>(rng() % 3);
  for (MotionPolynomial& p : m) {
    p = random_motion(rng, 1 + static_cast<int>(rng() % degree), full_mantissa(rng, -1), 3);
  }
  return degree;
}

/// A short origin near t (a multiple of 1/16), for motions whose exact combinations must fit.
inline double short_origin_near(double t) { return std::ldexp(std::round(std::ldexp(t, 4)), -4); }

/// "seed <seed> case <i>" and the case's description, for a failure message.
template <class Case>
std::string case_context(std::uint64_t seed, int i, const Case& cs) {
  std::string s = "seed " + std::to_string(seed);
  s += " case " + std::to_string(i) + "\n";
  return s + cs.describe();
}

/// The same with the time t the case is decided at.
template <class Case>
std::string case_context(std::uint64_t seed, int i, double t, const Case& cs) {
  std::string s = "seed " + std::to_string(seed);
  s += " case " + std::to_string(i);
  s += " t " + exact::hex(t) + "\n";
  return s + cs.describe();
}

/// Checks crop(f, lo, hi, eps) against the exact polynomial of f: (A1)-(A4), the exact signs at
/// the intervals' ends and sign_at(f, .) there. Returns "" or a failure message. F is a
/// MotionCombination or a ProductCombination.
template <class F>
std::string check_crop(const F& f, Time lo, Time hi, double eps, const exact::QPoly& exact_f) {
  namespace ex = ::kinetic::test::exact;
  struct {
    Time lo, hi;
    double eps;
  } cs{lo, hi, eps};
  std::vector<CropInterval> all;
  CropStats stats;
  const CropResult r = crop(f, cs.lo, cs.hi, cs.eps, &stats, &all);
  const ex::QPoly& exact = exact_f;
  std::ostringstream err;
  // (A3): the same call gives the same result, bit for bit.
  const CropResult again = crop(f, cs.lo, cs.hi, cs.eps);
  bool same = again.count == r.count && again.sign_first == r.sign_first &&
              again.identically_zero == r.identically_zero && again.window_lo == r.window_lo &&
              again.window_hi == r.window_hi && again.turbulent_count == r.turbulent_count;
  for (int i = 0; same && i < r.count; ++i) {
    same = again.events[i].lambda == r.events[i].lambda && again.events[i].rho == r.events[i].rho &&
           again.events[i].sign_left == r.events[i].sign_left &&
           again.events[i].sign_right == r.events[i].sign_right;
  }
  if (!same) err << "(A3) not deterministic; ";
  if (exact.is_zero()) {
    if (!r.identically_zero) err << "f == 0 but not reported identically zero; ";
    return err.str();
  }
  if (r.identically_zero) return "reported identically zero, f != 0";
  const ex::RootOracle o(exact);
  if (!(r.window_lo <= cs.lo && r.window_hi >= cs.hi)) err << "window does not cover [lo, hi]; ";
  if (o.sign(r.window_lo) == 0 || o.sign(r.window_hi) == 0) err << "f = 0 at a window end; ";
  if (r.sign_first != o.sign(r.window_lo)) err << "sign_first wrong; ";
  // (A1), (A2): intervals ascending, disjoint, width <= eps, exact end signs, and together they
  // hold every root in the window (none between them).
  int covered = 0, events = 0;
  double previous = r.window_lo;
  for (const CropInterval& iv : all) {
    if (!(iv.lambda < iv.rho) || iv.lambda < previous || iv.rho > r.window_hi)
      err << "interval order/containment; ";
    if (!(iv.rho - iv.lambda <= cs.eps)) err << "interval wider than eps; ";
    if (iv.sign_left != o.sign(iv.lambda) || iv.sign_right != o.sign(iv.rho) || iv.sign_left == 0 ||
        iv.sign_right == 0)
      err << "end signs not exact; ";
    covered += o.count_open(iv.lambda, iv.rho);
    // (A4): an event iff an odd number of roots of odd multiplicity.
    const bool odd = o.count_odd_open(iv.lambda, iv.rho) % 2 == 1;
    if (odd != iv.is_event()) err << "event flag vs odd multiplicity; ";
    if (iv.is_event()) {
      if (events >= r.count || r.events[events].lambda != iv.lambda ||
          r.events[events].rho != iv.rho)
        err << "events differ from the event intervals of all; ";
      ++events;
    }
    previous = iv.rho;
  }
  if (covered != o.count_closed(r.window_lo, r.window_hi))
    err << "roots not covered: " << covered << " of " << o.count_closed(r.window_lo, r.window_hi)
        << "; ";
  if (events != r.count) err << "event count; ";
  if (r.turbulent_count != static_cast<int>(all.size()) - r.count) err << "turbulent count; ";
  // The exact signs at the interval ends and at a few other points.
  for (const CropInterval& iv : all) {
    for (const double t : {iv.lambda, iv.rho, std::nextafter(iv.lambda, iv.rho)}) {
      if (sign_at(f, t) != o.sign(t)) err << "sign_at wrong at " << ex::hex(t) << "; ";
    }
  }
  return err.str();
}

/// What an oracle run of CROP saw: its cases, those whose exact f has a root in the window, and
/// those where f == 0 (a generator must exercise what it claims).
struct OracleTally {
  int cases = 0, with_roots = 0, zero = 0;

  /// The generator exercised what it claims: roots in the window in more than a quarter of the
  /// cases, f == 0 in more than a twentieth.
  void expect_roots_and_zeros() const {
    EXPECT_GT(with_roots, cases / 4);
    EXPECT_GT(zero, cases / 20);
  }
};

/// CROP against the exact oracle on `cases` cases: case i is generate(rng, i % families), one of
/// the tests' Case types (lo, hi, eps, exact(), describe()) drawn from a generator seeded with
/// `seed`, certificate(case) the function CROP isolates. check_crop() on each; a failure is
/// reported with the seed, the case's number and its description (six at the most). Prints the
/// tally under `what` and returns it.
template <class Generate, class Certificate>
OracleTally crop_against_the_oracle(const char* what, std::uint64_t seed, int cases,
                                    Generate&& generate, int families, Certificate&& certificate) {
  namespace ex = ::kinetic::test::exact;
  std::mt19937_64 rng(seed);
  OracleTally tally;
  int failures = 0;
  for (int i = 0; i < cases; ++i) {
    const auto cs = generate(rng, i % families);
    const ex::QPoly exact = cs.exact();
    const std::string e = check_crop(certificate(cs), cs.lo, cs.hi, cs.eps, exact);
    ++tally.cases;
    if (!e.empty()) {
      ADD_FAILURE() << "seed " << seed << " case " << i << ": " << e << "\n" << cs.describe();
      if (++failures > 5) break;
    }
    if (exact.is_zero()) {
      ++tally.zero;
    } else if (ex::RootOracle(exact).count_closed(cs.lo, cs.hi) > 0) {
      ++tally.with_roots;
    }
  }
  std::printf("[ %s ] seed %llu: %d cases, %d with roots in the window, %d f == 0\n", what,
              static_cast<unsigned long long>(seed), tally.cases, tally.with_roots, tally.zero);
  return tally;
}

/// The schedulers whose decisions the CROP tests check, at one precision and horizon: robust,
/// classic (floating-point decisions) and classic with exact decisions (`careful`).
struct DecidingSchedulers {
  Scheduler robust, classic, careful;

  DecidingSchedulers(double eps, Time horizon)
      : robust(SchedulerKind::Robust, eps, horizon),
        classic(SchedulerKind::Classic, eps, horizon),
        careful(SchedulerKind::Classic, eps, horizon) {
    careful.set_classic_exact_decisions(true);
  }
};

/// The robust scheduler's decision on f at t (window_lo the start of CROP's window, up to the
/// scheduler's horizon) against CROP and the exact polynomial of f: 0 and no failure for f == 0;
/// else the pretended sign of CROP's result and EVENTTIME of the certificate it leaves, in the
/// future (Lemma 4), and the exact sign just after t unless a root lies within a grid cell of t.
/// `isolated` is the function CROP isolates for f (f itself, or its products). Returns whether
/// such a root lies that near t.
template <class F, class Isolated>
bool expect_robust_decision(const Scheduler& robust, const F& f, const Isolated& isolated, Time t,
                            Time window_lo, const exact::QPoly& exact_f, Counters& counters,
                            const std::string& where) {
  const Scheduler::SignDecision d = robust.decide(f, t, window_lo, counters);
  if (exact_f.is_zero()) {
    EXPECT_EQ(d.sign, 0) << where;
    EXPECT_EQ(d.failure, kTimeInfinity) << where;
    return false;
  }
  const CropResult r =
      crop(isolated, window_lo, robust.horizon(), Scheduler::crop_eps(robust.eps()));
  EXPECT_EQ(d.sign, pretended_sign(r, t)) << where;
  EXPECT_EQ(d.failure, event_time(d.sign > 0 ? r : negated(r), t)) << where;
  EXPECT_GT(d.failure, t) << where;
  const double w = crop_grid_width(Scheduler::crop_eps(robust.eps()));
  if (exact::RootOracle(exact_f).count_closed(t - w, t + w) > 0) return true;
  EXPECT_EQ(d.sign, exact_sign_after(exact_f, t)) << where;
  return false;
}

/// The classic scheduler with exact decisions (`careful`) on f at t: the exact sign just after t,
/// a failure not before t, and one within the horizon is a root of f (to 1e-6 relative).
/// Returns the decision.
template <class F>
Scheduler::SignDecision expect_careful_decision(const Scheduler& careful, const F& f, Time t,
                                                Time window_lo, const exact::QPoly& exact_f,
                                                Counters& counters, const std::string& where) {
  const Scheduler::SignDecision c = careful.decide(f, t, window_lo, counters);
  EXPECT_EQ(c.sign, exact_sign_after(exact_f, t)) << where;
  if (c.failure != kTimeInfinity) {
    EXPECT_GE(c.failure, t) << where;
  }
  if (c.failure <= careful.horizon()) {
    const double delta = 1e-6 * (1.0 + std::fabs(c.failure));
    EXPECT_GT(exact::RootOracle(exact_f).count_closed(c.failure - delta, c.failure + delta), 0)
        << "classic failure " << exact::hex(c.failure) << " is no root of f; " << where;
  }
  return c;
}

}  // namespace kinetic::test
