// Root isolation (CROP) beside two anchors on the same polynomials (docs/performance/crop.md).
//
// One run, three tools, the same exact polynomials:
//  - kinetic: crop(upper, lower, 0, 100, 1e-9) (include/kinetic/core/crop.hpp);
//  - FLINT/Arb: squarefree part f / gcd(f, f') (fmpz_poly_gcd) + arb_fmpz_poly_complex_roots,
//    at increasing target precision until every real root that meets [0, 100] is enclosed in an
//    interval of width <= 1e-9 (real roots are the ones Arb returns with an imaginary part that
//    is exactly zero);
//  - CGAL: Algebraic_kernel_d_1<Gmpz>: Solve_1 (roots with multiplicities) on [0, 100], then
//    Approximate_absolute_1 to 2^-30 < 1e-9 for each root found.
// The anchors are optional: when one was not found at configure time, its columns say "n/a" and
// the program prints "anchor X: not available".
//
// Inputs (deterministic: mt19937_64 with a fixed seed). Every polynomial is a MotionPolynomial
// f(t) = sum c_i (t - o)^i with double coefficients and a double origin o, i.e. exact dyadic
// rationals. kinetic gets it as `upper` with `lower` = the zero polynomial; the anchors get the
// same polynomial expanded exactly in powers of t and scaled by a positive integer (a power of
// two, then divided by the content) to an integer polynomial with the same roots. The
// polynomials are built from prescribed roots in exact rational arithmetic, in powers of
// s = t - o, and each coefficient is then truncated to a double: the truncated polynomial is the
// exact input for all three tools. Putting the origin at the interesting spot (a near-double
// root, a cluster, a multiple root, a window end) keeps those features intact through the
// truncation, which perturbs every coefficient by a relative 2^-52 at most.
//  - generic: a random leading coefficient in +-[0.5, 2] and d roots: real, uniform in
//    [-10, 110], or (probability 0.3 per pair of remaining slots) a complex pair with real part
//    uniform in [-10, 110] and imaginary part uniform in [0.05, 20]; origin 0.
//  - the hard mix (eps = 1e-9, window [0, 100]), per polynomial:
//      40 % generic;
//      20 % near-double roots: origin o on the 2^-10 grid in [0, 100], a pair at o + a and
//           o + a + g with g log-uniform in [1e-13, 1e-4] (half of them), or a complex pair
//           o + a +- i g/2 just off the axis (the other half); a within +-g/8 of -g/2 resp. 0;
//      20 % clusters: 2-4 real roots (at most d) at o + sigma (u - 1/2), u uniform in [0, 1],
//           spread sigma log-uniform in [1e-10, 1e-3];
//      10 % exact multiple roots: (t - o)^m, m uniform in 2..min(d, 4);
//      10 % window ends: o = 0 or 100 and a root at o exactly (40 %), just past the end by a
//           log-uniform 1e-15..1e-9 (40 %) or just inside it by as much (20 %);
//    the remaining roots of each polynomial are generic. At degree 1 the categories that need
//    two roots fall back to generic (degree 1 mix = 90 % generic, 10 % window ends).
//  - certificates: two motions of a kinetic sort, x(t) = x0 + v (t - o) [+ a (t - o)^2], x0
//    uniform in [0, 100], v in [-1, 1], a in [-0.01, 0.01], each with its own origin o uniform in
//    [0, 100] (full double precision): crop(a, b, 0, 100, 1e-9) on the exact difference.
//
// Timing: each tool runs over the whole set of a row, in passes (after one warm-up pass; a pass
// repeats the set until it lasts >= 20 ms); the figure is the fastest pass time divided by the
// number of polynomials, in process CPU time (the same as wall time on a quiet machine; the
// cpu/wall ratio of every measurement is printed, and a warning when another process competed
// for the core). Single-threaded. Inputs are converted to each tool's types before the clock
// starts.
//
// Checks (not timed), all exact: for each kinetic result with all intervals (event and
// turbulent) listed,
//  - self: signs at the interval ends against an exact GMP evaluation of the integer polynomial,
//    widths <= eps, ascending disjoint intervals, events = the event intervals of the list, the
//    same events as the timed call, sign_first;
//  - per anchor: every real root of the anchor in [0, 100] lies strictly inside a kinetic
//    interval, and the multiplicities of the anchor's roots inside each kinetic interval add up
//    to an odd number for an event interval and an even one (possibly 0) for a turbulent one.
//    CGAL roots are compared exactly with the interval ends; Arb roots are refined to 160 bits
//    first (with multiplicities from fmpz_poly_factor_squarefree), and an Arb enclosure that
//    still contains an interval end is counted as undecided, not as a disagreement.
//
// Options: --n=N polynomials per row (default 2000), --cert-n=N certificates (default 4096),
// --seed=S (default 20240917), --degrees=1,2,4,6, --kinetic-passes=P (default 9),
// --anchor-passes=P (default 5).

#include <gmpxx.h>
#include <time.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "harness.hpp"
#include "kinetic/core/crop.hpp"
#include "kinetic/core/polynomial.hpp"

#if KINETIC_BENCH_HAVE_ARB
#include <acb.h>
#include <arb.h>
#include <arb_fmpz_poly.h>
#include <arf.h>
#include <flint/flint.h>
#include <flint/fmpz.h>
#include <flint/fmpz_poly.h>
#include <flint/fmpz_poly_factor.h>
#endif

#if KINETIC_BENCH_HAVE_CGAL
#include <CGAL/Algebraic_kernel_d_1.h>
#include <CGAL/Gmpq.h>
#include <CGAL/Gmpz.h>
#include <CGAL/Polynomial_traits_d.h>
#include <CGAL/version.h>
#endif

using kinetic::bench::out;

namespace {

using kinetic::CropInterval;
using kinetic::CropResult;
using kinetic::CropStats;
using kinetic::MotionPolynomial;
using Clock = std::chrono::steady_clock;

constexpr double kLo = 0.0;
constexpr double kHi = 100.0;
constexpr double kEps = 1e-9;
constexpr int kAnchorBits = 30;    // 2^-30 < 1e-9: CGAL's Approximate_absolute_1 precision
constexpr long kVerifyBits = 160;  // Arb precision of the check pass

// ---------------------------------------------------------------------------------------------
// Inputs.

class Rng {
 public:
  explicit Rng(std::uint64_t seed) : engine_(seed) {}
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1p-53; }
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  double log_uniform(double lo_exp10, double hi_exp10) {
    return std::pow(10.0, uniform(lo_exp10, hi_exp10));
  }
  int below(int n) { return static_cast<int>(engine_() % static_cast<std::uint64_t>(n)); }
  bool coin() { return (engine_() & 1U) != 0; }

 private:
  std::mt19937_64 engine_;
};

enum class Category {
  generic,
  near_pair,
  complex_pair,
  cluster,
  multiple,
  window_end,
  certificate
};
constexpr int kCategoryCount = 7;
const char* category_name(Category c) {
  switch (c) {
    case Category::generic:
      return "generic";
    case Category::near_pair:
      return "near-double (real pair)";
    case Category::complex_pair:
      return "near-double (complex pair)";
    case Category::cluster:
      return "cluster";
    case Category::multiple:
      return "exact multiple root";
    case Category::window_end:
      return "window end";
    case Category::certificate:
      return "certificate";
  }
  return "?";
}

using QPoly = std::vector<mpq_class>;  // ascending coefficients

QPoly multiply(const QPoly& a, const QPoly& b) {
  QPoly r(a.size() + b.size() - 1, mpq_class(0));
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t j = 0; j < b.size(); ++j) r[i + j] += a[i] * b[j];
  return r;
}

/// Roots in s = t - o, exact.
struct RootSpec {
  double origin = 0.0;
  double lead = 1.0;
  std::vector<mpq_class> real;                           // s-roots
  std::vector<std::pair<mpq_class, mpq_class>> complex;  // re +- i im, in s
  Category category = Category::generic;
};

void add_generic_roots(Rng& rng, RootSpec& spec, int count) {
  const mpq_class origin(spec.origin);
  while (count > 0) {
    if (count >= 2 && rng.uniform() < 0.3) {
      const double re = rng.uniform(-10.0, 110.0);
      const double im = rng.uniform(0.05, 20.0);
      spec.complex.emplace_back(mpq_class(re) - origin, mpq_class(im));
      count -= 2;
    } else {
      spec.real.push_back(mpq_class(rng.uniform(-10.0, 110.0)) - origin);
      count -= 1;
    }
  }
}

double grid_origin(Rng& rng) { return std::floor(rng.uniform(0.0, 100.0) * 1024.0) / 1024.0; }

RootSpec make_spec(Rng& rng, int degree, bool mix) {
  RootSpec spec;
  spec.lead = (rng.coin() ? 1.0 : -1.0) * rng.uniform(0.5, 2.0);
  const double u = mix ? rng.uniform() : 0.0;
  int placed = 0;
  if (u < 0.4 || (u < 0.9 && degree < 2)) {
    spec.category = Category::generic;
  } else if (u < 0.6) {
    spec.origin = grid_origin(rng);
    const double g = rng.log_uniform(-13.0, -4.0);
    if (rng.coin()) {
      spec.category = Category::near_pair;
      const double a = g * (-0.5 + 0.25 * (rng.uniform() - 0.5));
      spec.real.push_back(mpq_class(a));
      spec.real.push_back(mpq_class(a) + mpq_class(g));
    } else {
      spec.category = Category::complex_pair;
      const double re = g * 0.25 * (rng.uniform() - 0.5);
      spec.complex.emplace_back(mpq_class(re), mpq_class(g / 2.0));
    }
    placed = 2;
  } else if (u < 0.8) {
    spec.category = Category::cluster;
    spec.origin = grid_origin(rng);
    const int k = std::min(degree, 2 + rng.below(3));
    const double sigma = rng.log_uniform(-10.0, -3.0);
    for (int j = 0; j < k; ++j) spec.real.push_back(mpq_class(sigma * (rng.uniform() - 0.5)));
    placed = k;
  } else if (u < 0.9) {
    spec.category = Category::multiple;
    spec.origin = grid_origin(rng);
    const int m = 2 + rng.below(std::min(degree, 4) - 1);
    for (int j = 0; j < m; ++j) spec.real.push_back(mpq_class(0));
    placed = m;
  } else {
    spec.category = Category::window_end;
    const bool at_hi = rng.coin();
    spec.origin = at_hi ? kHi : kLo;
    const double outward = at_hi ? 1.0 : -1.0;
    const double kind = rng.uniform();
    const double delta = rng.log_uniform(-15.0, -9.0);
    if (kind < 0.4) {
      spec.real.push_back(mpq_class(0));
    } else if (kind < 0.8) {
      spec.real.push_back(mpq_class(outward * delta));
    } else {
      spec.real.push_back(mpq_class(-outward * delta));
    }
    placed = 1;
  }
  add_generic_roots(rng, spec, degree - placed);
  return spec;
}

/// The motion with the roots of `spec`, coefficients truncated to doubles.
MotionPolynomial motion_from_spec(const RootSpec& spec) {
  QPoly p{mpq_class(spec.lead)};
  for (const mpq_class& r : spec.real) p = multiply(p, QPoly{-r, mpq_class(1)});
  for (const auto& [re, im] : spec.complex)
    p = multiply(p, QPoly{re * re + im * im, -2 * re, mpq_class(1)});
  std::vector<double> c(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) c[i] = p[i].get_d();  // truncation
  return MotionPolynomial::from(c, spec.origin);
}

/// p(t) in powers of t, exactly.
QPoly expand(const MotionPolynomial& p) {
  QPoly out(static_cast<std::size_t>(p.degree) + 1, mpq_class(0));
  QPoly power{mpq_class(1)};  // (t - o)^i
  const QPoly linear{-mpq_class(p.origin), mpq_class(1)};
  for (int i = 0; i <= p.degree; ++i) {
    for (std::size_t j = 0; j < power.size(); ++j) out[j] += mpq_class(p.c[i]) * power[j];
    power = multiply(power, linear);
  }
  return out;
}

struct TestPoly {
  MotionPolynomial upper;
  MotionPolynomial lower;          // the zero polynomial except for certificates
  std::vector<mpz_class> integer;  // a positive multiple of upper - lower, in powers of t
  Category category = Category::generic;
};

std::vector<mpz_class> to_integer(const MotionPolynomial& upper, const MotionPolynomial& lower) {
  QPoly a = expand(upper);
  const QPoly b = expand(lower);
  if (a.size() < b.size()) a.resize(b.size(), mpq_class(0));
  for (std::size_t i = 0; i < b.size(); ++i) a[i] -= b[i];
  while (a.size() > 1 && a.back() == 0) a.pop_back();
  mpz_class denominator = 1;
  for (const mpq_class& q : a)
    mpz_lcm(denominator.get_mpz_t(), denominator.get_mpz_t(), q.get_den_mpz_t());
  std::vector<mpz_class> z(a.size());
  mpz_class content = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const mpq_class scaled = a[i] * denominator;
    z[i] = scaled.get_num();
    mpz_gcd(content.get_mpz_t(), content.get_mpz_t(), z[i].get_mpz_t());
  }
  if (content > 1)
    for (mpz_class& v : z) mpz_divexact(v.get_mpz_t(), v.get_mpz_t(), content.get_mpz_t());
  return z;
}

TestPoly make_poly(Rng& rng, int degree, bool mix) {
  const RootSpec spec = make_spec(rng, degree, mix);
  TestPoly t;
  t.upper = motion_from_spec(spec);
  t.integer = to_integer(t.upper, t.lower);
  t.category = spec.category;
  return t;
}

TestPoly make_certificate(Rng& rng, int degree) {
  auto motion = [&] {
    std::vector<double> c{rng.uniform(0.0, 100.0), rng.uniform(-1.0, 1.0)};
    if (degree == 2) c.push_back(rng.uniform(-0.01, 0.01));
    return MotionPolynomial::from(c, rng.uniform(0.0, 100.0));
  };
  TestPoly t;
  t.upper = motion();
  t.lower = motion();
  t.integer = to_integer(t.upper, t.lower);
  t.category = Category::certificate;
  return t;
}

void print_poly(const char* tag, const TestPoly& p) {
  auto one = [](const char* name, const MotionPolynomial& m) {
    out("      %s: origin %a, coefficients in (t - origin)^i:", name, m.origin);
    for (int i = 0; i <= m.degree; ++i) out(" %a", m.c[i]);
    out("\n");
  };
  out("    %s (%s)\n", tag, category_name(p.category));
  one("upper", p.upper);
  one("lower", p.lower);
}

// ---------------------------------------------------------------------------------------------
// Timing helpers.

double g_min_cpu_over_wall = 1e300;  // over every measurement of the run

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

struct Timing {
  double us_per_poly = 0.0;  // fastest pass / n, process CPU time
  double cpu_over_wall = 0.0;
};

/// Runs `pass` (one pass over n items) once to warm up, then `passes` times, each time repeated
/// enough to last >= 20 ms (short passes are at the mercy of a single interrupt); the fastest
/// pass's CPU time per item in us (the least disturbed one: on a shared machine, a process on the
/// other core slows a pass down through the shared caches and memory, never speeds it up). The
/// process CPU time equals the wall time on a quiet machine; it is used because it stays nearly
/// right when another process shares the core (cpu/wall then drops below 1, and main() says so).
Timing time_passes(int passes, std::size_t n, const std::function<void()>& pass) {
  const double warm0 = cpu_seconds();
  pass();
  const double warm = std::max(cpu_seconds() - warm0, 1e-6);
  const int repeat = std::clamp(static_cast<int>(std::ceil(0.02 / warm)), 1, 1000);
  std::vector<double> per_pass;
  double wall_total = 0.0, cpu_total = 0.0;
  for (int k = 0; k < passes; ++k) {
    const double cpu0 = cpu_seconds();
    const auto t0 = Clock::now();
    for (int r = 0; r < repeat; ++r) pass();
    const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
    const double cpu = cpu_seconds() - cpu0;
    cpu_total += cpu;
    wall_total += wall;
    per_pass.push_back(cpu);
  }
  std::sort(per_pass.begin(), per_pass.end());
  Timing t;
  t.us_per_poly = per_pass.front() * 1e6 / (static_cast<double>(n) * repeat);
  t.cpu_over_wall = wall_total > 0.0 ? cpu_total / wall_total : 0.0;
  if (t.cpu_over_wall < g_min_cpu_over_wall) g_min_cpu_over_wall = t.cpu_over_wall;
  return t;
}

volatile std::int64_t g_sink = 0;  // keeps results alive

/// A fixed floating-point and integer workload, in CPU ms (fastest of 5): the machine's speed
/// at the time of a row. On a virtual machine the host can slow every tool down for seconds
/// without that showing in cpu/wall; a calibration time above the run's lowest flags it.
double calibration_ms() {
  double best = 1e300;
  for (int rep = 0; rep < 5; ++rep) {
    const double t0 = cpu_seconds();
    std::uint64_t x = 88172645463325252ULL;
    double acc = 0.0;
    for (int i = 0; i < 2000000; ++i) {
      x ^= x << 13;
      x ^= x >> 7;
      x ^= x << 17;
      acc = acc * 0.999 + static_cast<double>(x >> 40);
    }
    g_sink = g_sink + static_cast<std::int64_t>(acc);
    best = std::min(best, cpu_seconds() - t0);
  }
  return best * 1e3;
}

// ---------------------------------------------------------------------------------------------
// Exact checks shared by the anchors: position of a root relative to a double.

/// Sign of p(x) for the integer polynomial p, exactly.
int exact_sign(const std::vector<mpz_class>& p, double x) {
  const mpq_class q(x);
  mpq_class v = p.back();
  for (std::size_t i = p.size() - 1; i-- > 0;) v = v * q + p[i];
  return sgn(v);
}

struct Counts {
  std::int64_t self_failures = 0;
  std::int64_t roots_checked = 0;
  std::int64_t disagreements = 0;
  std::int64_t undecided = 0;
};

/// One anchor's real roots of one polynomial: rel(i, x) = sign(root_i - x), 0 when equal or
/// (Arb) not decided; decided(i, x) false when not decided.
struct AnchorRoots {
  std::size_t count = 0;
  std::vector<int> multiplicity;
  std::function<int(std::size_t, double)> rel;
  std::function<bool(std::size_t, double)> decided;
};

/// Compares kinetic's intervals with an anchor's roots; returns the number of disagreements
/// found (added to counts).
[[maybe_unused]] std::int64_t compare_with_anchor(const std::vector<CropInterval>& all,
                                                  const AnchorRoots& roots, Counts& counts) {
  std::int64_t bad = 0;
  for (std::size_t i = 0; i < roots.count; ++i) {
    const bool in_window = roots.rel(i, kLo) >= 0 && roots.rel(i, kHi) <= 0;
    if (!in_window) continue;
    ++counts.roots_checked;
    bool covered = false, unsure = false;
    for (const CropInterval& iv : all) {
      if (!roots.decided(i, iv.lambda) || !roots.decided(i, iv.rho)) unsure = true;
      if (roots.rel(i, iv.lambda) > 0 && roots.rel(i, iv.rho) < 0) covered = true;
    }
    if (!covered) {
      if (unsure) {
        ++counts.undecided;
      } else {
        ++bad;
      }
    }
  }
  for (const CropInterval& iv : all) {
    int inside = 0;
    bool unsure = false;
    for (std::size_t i = 0; i < roots.count; ++i) {
      if (!roots.decided(i, iv.lambda) || !roots.decided(i, iv.rho)) {
        unsure = true;
        continue;
      }
      if (roots.rel(i, iv.lambda) > 0 && roots.rel(i, iv.rho) < 0) inside += roots.multiplicity[i];
    }
    if ((inside % 2 == 1) != iv.is_event()) {
      if (unsure) {
        ++counts.undecided;
      } else {
        ++bad;
      }
    }
  }
  counts.disagreements += bad;
  return bad;
}

/// Exact self-checks of one kinetic result; returns the number of failures.
std::int64_t self_check(const TestPoly& p, const CropResult& timed, const CropResult& listed,
                        const std::vector<CropInterval>& all) {
  std::int64_t bad = 0;
  int events = 0;
  for (std::size_t k = 0; k < all.size(); ++k) {
    const CropInterval& iv = all[k];
    if (!(iv.lambda < iv.rho) || iv.rho - iv.lambda > kEps) ++bad;
    if (k > 0 && all[k - 1].rho > iv.lambda) ++bad;
    if (iv.sign_left != exact_sign(p.integer, iv.lambda)) ++bad;
    if (iv.sign_right != exact_sign(p.integer, iv.rho)) ++bad;
    if (iv.is_event()) {
      if (events >= listed.count ||
          listed.events[static_cast<std::size_t>(events)].lambda != iv.lambda ||
          listed.events[static_cast<std::size_t>(events)].rho != iv.rho)
        ++bad;
      ++events;
    }
  }
  if (events != listed.count) ++bad;
  if (listed.turbulent_count != static_cast<int>(all.size()) - events) ++bad;
  if (timed.count != listed.count || timed.sign_first != listed.sign_first) {
    ++bad;
  } else {
    for (int k = 0; k < timed.count; ++k) {
      const CropInterval& a = timed.events[static_cast<std::size_t>(k)];
      const CropInterval& b = listed.events[static_cast<std::size_t>(k)];
      if (a.lambda != b.lambda || a.rho != b.rho || a.sign_left != b.sign_left ||
          a.sign_right != b.sign_right)
        ++bad;
    }
  }
  if (listed.window_lo > kLo || listed.window_hi < kHi) ++bad;
  const int s_lo = exact_sign(p.integer, listed.window_lo);
  if (s_lo != 0 && (all.empty() || all.front().lambda > listed.window_lo) &&
      listed.sign_first != s_lo)
    ++bad;
  return bad;
}

// ---------------------------------------------------------------------------------------------
// FLINT/Arb.

#if KINETIC_BENCH_HAVE_ARB
class FmpzPoly {
 public:
  explicit FmpzPoly(const std::vector<mpz_class>& z) {
    fmpz_poly_init(p_);
    for (std::size_t i = 0; i < z.size(); ++i) {
      fmpz_t c;
      fmpz_init(c);
      fmpz_set_mpz(c, z[i].get_mpz_t());
      fmpz_poly_set_coeff_fmpz(p_, static_cast<slong>(i), c);
      fmpz_clear(c);
    }
  }
  ~FmpzPoly() { fmpz_poly_clear(p_); }
  FmpzPoly(const FmpzPoly&) = delete;
  FmpzPoly& operator=(const FmpzPoly&) = delete;
  [[nodiscard]] const fmpz_poly_struct* get() const { return p_; }

 private:
  fmpz_poly_t p_;
};

/// Does the real ball x meet [kLo, kHi]?
bool arb_meets_window(const arb_t x, arf_t lb, arf_t ub) {
  arb_get_lbound_arf(lb, x, 64);
  arb_get_ubound_arf(ub, x, 64);
  return !(arf_cmp_si(ub, static_cast<slong>(kLo)) < 0 ||
           arf_cmp_si(lb, static_cast<slong>(kHi)) > 0);
}

/// The anchor's procedure: real roots of f in [kLo, kHi], isolated to width <= 1e-9. Returns
/// how many there are.
int arb_isolate(const fmpz_poly_struct* f) {
  if (fmpz_poly_degree(f) < 1) return 0;
  fmpz_poly_t d, g, q;
  fmpz_poly_init(d);
  fmpz_poly_init(g);
  fmpz_poly_init(q);
  fmpz_poly_derivative(d, f);
  fmpz_poly_gcd(g, f, d);
  fmpz_poly_div(q, f, g);
  const slong n = fmpz_poly_degree(q);
  int found = 0;
  if (n > 0) {
    acb_ptr roots = _acb_vec_init(n);
    arf_t lb, ub;
    arf_init(lb);
    arf_init(ub);
    for (slong prec = 40;; prec *= 2) {
      arb_fmpz_poly_complex_roots(roots, q, 0, prec);
      bool narrow = true;
      found = 0;
      for (slong i = 0; i < n; ++i) {
        if (!arb_is_zero(acb_imagref(roots + i))) break;  // real roots come first
        if (!arb_meets_window(acb_realref(roots + i), lb, ub)) continue;
        ++found;
        // width = 2 rad <= 2^-30 < 1e-9
        if (mag_cmp_2exp_si(arb_radref(acb_realref(roots + i)), -31) > 0) narrow = false;
      }
      if (narrow) break;
    }
    arf_clear(lb);
    arf_clear(ub);
    _acb_vec_clear(roots, n);
  }
  fmpz_poly_clear(d);
  fmpz_poly_clear(g);
  fmpz_poly_clear(q);
  return found;
}

/// All real roots with multiplicities, at kVerifyBits, for the checks.
class ArbCheckRoots {
 public:
  explicit ArbCheckRoots(const fmpz_poly_struct* f) {
    fmpz_poly_factor_t fac;
    fmpz_poly_factor_init(fac);
    fmpz_poly_factor_squarefree(fac, f);
    for (slong k = 0; k < fac->num; ++k) {
      const slong n = fmpz_poly_degree(fac->p + k);
      if (n < 1) continue;
      acb_ptr roots = _acb_vec_init(n);
      arb_fmpz_poly_complex_roots(roots, fac->p + k, 0, kVerifyBits);
      for (slong i = 0; i < n; ++i) {
        if (!arb_is_zero(acb_imagref(roots + i))) break;
        balls_.emplace_back();
        arb_init(balls_.back().x);
        arb_set(balls_.back().x, acb_realref(roots + i));
        multiplicity_.push_back(static_cast<int>(fac->exp[k]));
      }
      _acb_vec_clear(roots, n);
    }
    fmpz_poly_factor_clear(fac);
  }
  ~ArbCheckRoots() {
    for (Ball& b : balls_) arb_clear(b.x);
  }
  ArbCheckRoots(const ArbCheckRoots&) = delete;
  ArbCheckRoots& operator=(const ArbCheckRoots&) = delete;

  [[nodiscard]] AnchorRoots view() const {
    AnchorRoots r;
    r.count = balls_.size();
    r.multiplicity = multiplicity_;
    r.rel = [this](std::size_t i, double x) {
      arb_t y;
      arb_init(y);
      arb_set_d(y, x);
      int s = 0;
      if (arb_gt(balls_[i].x, y)) s = 1;
      if (arb_lt(balls_[i].x, y)) s = -1;
      arb_clear(y);
      return s;
    };
    r.decided = [this](std::size_t i, double x) {
      arb_t y;
      arb_init(y);
      arb_set_d(y, x);
      const bool d = arb_gt(balls_[i].x, y) || arb_lt(balls_[i].x, y);
      arb_clear(y);
      return d;
    };
    return r;
  }

 private:
  struct Ball {
    arb_t x;
  };
  std::vector<Ball> balls_;
  std::vector<int> multiplicity_;
};
#endif

// ---------------------------------------------------------------------------------------------
// CGAL.

#if KINETIC_BENCH_HAVE_CGAL
using AK = CGAL::Algebraic_kernel_d_1<CGAL::Gmpz>;
using CgalPoly = AK::Polynomial_1;
using CgalBound = AK::Bound;

CgalPoly cgal_poly(const std::vector<mpz_class>& z) {
  std::vector<CGAL::Gmpz> c;
  c.reserve(z.size());
  for (const mpz_class& v : z) c.emplace_back(v.get_mpz_t());
  return CGAL::Polynomial_traits_d<CgalPoly>::Construct_polynomial()(c.begin(), c.end());
}

/// The anchor's procedure: real roots in [kLo, kHi] with multiplicities, approximated to 2^-30.
int cgal_isolate(const AK& ak, const CgalPoly& p, const CgalBound& lo, const CgalBound& hi) {
  std::vector<std::pair<AK::Algebraic_real_1, AK::Multiplicity_type>> roots;
  ak.solve_1_object()(p, lo, hi, std::back_inserter(roots));
  const auto approximate = ak.approximate_absolute_1_object();
  int found = 0;
  for (const auto& r : roots) {
    const std::pair<CgalBound, CgalBound> box = approximate(r.first, kAnchorBits);
    found += box.first <= box.second ? 1 : 0;
  }
  return found;
}

class CgalCheckRoots {
 public:
  CgalCheckRoots(const AK& ak, const CgalPoly& p) : ak_(ak) {
    ak.solve_1_object()(p, std::back_inserter(roots_));
  }
  [[nodiscard]] AnchorRoots view() const {
    AnchorRoots r;
    r.count = roots_.size();
    for (const auto& x : roots_) r.multiplicity.push_back(static_cast<int>(x.second));
    r.rel = [this](std::size_t i, double x) {
      const CGAL::Comparison_result c = ak_.compare_1_object()(roots_[i].first, CgalBound(x));
      return c == CGAL::LARGER ? 1 : (c == CGAL::SMALLER ? -1 : 0);
    };
    r.decided = [](std::size_t, double) { return true; };
    return r;
  }

 private:
  const AK& ak_;
  std::vector<std::pair<AK::Algebraic_real_1, AK::Multiplicity_type>> roots_;
};
#endif

// ---------------------------------------------------------------------------------------------
// One row of the table.

struct ToolTimes {
  Timing kinetic, arb, cgal;
  bool has_arb = false, has_cgal = false;
};

struct CategoryRow {
  Category category = Category::generic;
  std::size_t n = 0;
  ToolTimes times;
  double exact_call_fraction = 0.0;
};

struct Row {
  std::string degree;
  std::string set;
  std::size_t n = 0;
  Timing kinetic, arb, cgal;
  bool has_arb = false, has_cgal = false;
  double exact_call_fraction = 0.0;  // calls with at least one GMP decision
  double exact_per_call = 0.0;       // GMP decisions per call
  double fast_path_fraction = 0.0;
  double boxes_per_call = 0.0;
  double events_per_call = 0.0;
  double turbulent_per_call = 0.0;
  Counts self, vs_arb, vs_cgal;
  std::vector<CategoryRow> categories;  // hard mix only
  double slowest_us = 0.0;
  std::size_t slowest = 0;
  TestPoly slowest_input;
  double calibration_ms = 0.0;
};

struct Options {
  std::size_t n = 2000;
  std::size_t cert_n = 4096;
  std::uint64_t seed = 20240917;
  std::vector<int> degrees{1, 2, 4, 6};
  int kinetic_passes = 9;
  int anchor_passes = 5;
};

/// The three tools' inputs for one set of polynomials (anchors' conversions are not timed).
struct ToolInputs {
  const std::vector<TestPoly>* polys = nullptr;
#if KINETIC_BENCH_HAVE_ARB
  std::vector<std::unique_ptr<FmpzPoly>> arb;
#endif
#if KINETIC_BENCH_HAVE_CGAL
  AK ak;
  std::vector<CgalPoly> cgal;
  CgalBound lo{kLo}, hi{kHi};
#endif
  explicit ToolInputs(const std::vector<TestPoly>& p) : polys(&p) {
#if KINETIC_BENCH_HAVE_ARB
    for (const TestPoly& t : p) arb.push_back(std::make_unique<FmpzPoly>(t.integer));
#endif
#if KINETIC_BENCH_HAVE_CGAL
    for (const TestPoly& t : p) cgal.push_back(cgal_poly(t.integer));
#endif
  }
};

/// Times the three tools on the polynomials `subset` (indices into in.polys).
ToolTimes time_tools(const ToolInputs& in, const std::vector<std::size_t>& subset,
                     const Options& opt) {
  ToolTimes t;
  const std::vector<TestPoly>& polys = *in.polys;
  CropStats stats;
  t.kinetic = time_passes(opt.kinetic_passes, subset.size(), [&] {
    std::int64_t s = 0;
    for (const std::size_t k : subset) {
      const CropResult r = kinetic::crop(polys[k].upper, polys[k].lower, kLo, kHi, kEps, &stats);
      s += r.count;
    }
    g_sink = g_sink + s;
  });
#if KINETIC_BENCH_HAVE_ARB
  t.has_arb = true;
  t.arb = time_passes(opt.anchor_passes, subset.size(), [&] {
    std::int64_t s = 0;
    for (const std::size_t k : subset) s += arb_isolate(in.arb[k]->get());
    g_sink = g_sink + s;
  });
#endif
#if KINETIC_BENCH_HAVE_CGAL
  t.has_cgal = true;
  t.cgal = time_passes(opt.anchor_passes, subset.size(), [&] {
    std::int64_t s = 0;
    for (const std::size_t k : subset) s += cgal_isolate(in.ak, in.cgal[k], in.lo, in.hi);
    g_sink = g_sink + s;
  });
#endif
  return t;
}

Row run_row(const std::string& degree, const std::string& set, const std::vector<TestPoly>& polys,
            const Options& opt) {
  Row row;
  row.degree = degree;
  row.set = set;
  row.n = polys.size();

  const ToolInputs in(polys);
  row.calibration_ms = calibration_ms();
  std::vector<std::size_t> everything(polys.size());
  for (std::size_t k = 0; k < polys.size(); ++k) everything[k] = k;
  const ToolTimes times = time_tools(in, everything, opt);
  row.kinetic = times.kinetic;
  row.arb = times.arb;
  row.cgal = times.cgal;
  row.has_arb = times.has_arb;
  row.has_cgal = times.has_cgal;

  // Per category (the hard mix only).
  if (set == "mix") {
    for (int c = 0; c < kCategoryCount; ++c) {
      std::vector<std::size_t> subset;
      for (std::size_t k = 0; k < polys.size(); ++k)
        if (static_cast<int>(polys[k].category) == c) subset.push_back(k);
      if (subset.empty()) continue;
      CategoryRow cr;
      cr.category = static_cast<Category>(c);
      cr.n = subset.size();
      cr.times = time_tools(in, subset, opt);
      std::int64_t exact_calls = 0;
      for (const std::size_t k : subset) {
        CropStats one;
        (void)kinetic::crop(polys[k].upper, polys[k].lower, kLo, kHi, kEps, &one);
        exact_calls += one.predicates.exact > 0 ? 1 : 0;
      }
      cr.exact_call_fraction = static_cast<double>(exact_calls) / static_cast<double>(cr.n);
      row.categories.push_back(cr);
    }
  }

  // The slowest kinetic call of the row (each call timed alone, best of 5).
  for (std::size_t k = 0; k < polys.size(); ++k) {
    double best = 1e300;
    for (int rep = 0; rep < 5; ++rep) {
      const auto t0 = Clock::now();
      const CropResult r = kinetic::crop(polys[k].upper, polys[k].lower, kLo, kHi, kEps);
      const double dt = std::chrono::duration<double>(Clock::now() - t0).count();
      g_sink = g_sink + r.count;
      best = std::min(best, dt);
    }
    if (best * 1e6 > row.slowest_us) {
      row.slowest_us = best * 1e6;
      row.slowest = k;
      row.slowest_input = polys[k];
    }
  }

  // Checks and counters (not timed).
  std::int64_t exact_calls = 0, exact_total = 0, fast = 0, boxes = 0, events = 0, turbulent = 0;
  int printed = 0;
  for (std::size_t k = 0; k < polys.size(); ++k) {
    const TestPoly& p = polys[k];
    CropStats one;
    const CropResult timed = kinetic::crop(p.upper, p.lower, kLo, kHi, kEps, &one);
    exact_calls += one.predicates.exact > 0 ? 1 : 0;
    exact_total += static_cast<std::int64_t>(one.predicates.exact);
    fast += static_cast<std::int64_t>(one.fast_path);
    boxes += static_cast<std::int64_t>(one.bernstein_boxes);
    std::vector<CropInterval> all;
    const CropResult listed = kinetic::crop(p.upper, p.lower, kLo, kHi, kEps, nullptr, &all);
    events += listed.count;
    turbulent += listed.turbulent_count;
    std::int64_t bad_self = self_check(p, timed, listed, all);
    row.self.self_failures += bad_self;
    std::int64_t bad_arb = 0, bad_cgal = 0;
#if KINETIC_BENCH_HAVE_ARB
    {
      const ArbCheckRoots roots(in.arb[k]->get());
      bad_arb = compare_with_anchor(all, roots.view(), row.vs_arb);
    }
#endif
#if KINETIC_BENCH_HAVE_CGAL
    {
      const CgalCheckRoots roots(in.ak, in.cgal[k]);
      bad_cgal = compare_with_anchor(all, roots.view(), row.vs_cgal);
    }
#endif
    if ((bad_self != 0 || bad_arb != 0 || bad_cgal != 0) && printed < 5) {
      ++printed;
      out("  ! degree %s %s, polynomial %zu: %lld self-check failures, %lld disagreements "
          "with Arb, %lld with CGAL\n",
          degree.c_str(), set.c_str(), k, static_cast<long long>(bad_self),
          static_cast<long long>(bad_arb), static_cast<long long>(bad_cgal));
      print_poly("input", p);
      out("      sign_first %d, intervals:", listed.sign_first);
      for (const CropInterval& iv : all)
        out(" (%a, %a)%+d%+d", iv.lambda, iv.rho, iv.sign_left, iv.sign_right);
      out("\n");
    }
  }
  const auto n = static_cast<double>(polys.size());
  row.exact_call_fraction = static_cast<double>(exact_calls) / n;
  row.exact_per_call = static_cast<double>(exact_total) / n;
  row.fast_path_fraction = static_cast<double>(fast) / n;
  row.boxes_per_call = static_cast<double>(boxes) / n;
  row.events_per_call = static_cast<double>(events) / n;
  row.turbulent_per_call = static_cast<double>(turbulent) / n;
  return row;
}

std::string us(const Timing& t, bool has) {
  if (!has) return "n/a";
  char buf[32];
  if (t.us_per_poly < 1.0) {
    std::snprintf(buf, sizeof buf, "%.3f", t.us_per_poly);
  } else if (t.us_per_poly < 100.0) {
    std::snprintf(buf, sizeof buf, "%.2f", t.us_per_poly);
  } else {
    std::snprintf(buf, sizeof buf, "%.1f", t.us_per_poly);
  }
  return buf;
}

std::string ratio(const Timing& anchor, bool has, const Timing& kin) {
  if (!has || kin.us_per_poly <= 0.0) return "n/a";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1fx", anchor.us_per_poly / kin.us_per_poly);
  return buf;
}

using kinetic::bench::build_type;
using kinetic::bench::compiler;

std::vector<int> parse_degrees(const std::string& text) {
  std::vector<int> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    const int d = std::atoi(text.substr(start, comma - start).c_str());
    if (d < 1 || d > kinetic::kMaxMotionDegree) {
      std::fprintf(stderr, "bench_crop: bad degree in --degrees=%s\n", text.c_str());
      std::exit(2);
    }
    out.push_back(d);
    start = comma + 1;
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  std::size_t n = opt.n, cert_n = opt.cert_n;
  std::string degrees = "1,2,4,6";
  kinetic::bench::Harness harness("bench_crop",
                                  "CROP root isolation beside FLINT/Arb and CGAL, same exact "
                                  "polynomials");
  harness.option("--n", n, "polynomials per row");
  harness.option("--cert-n", cert_n, "certificates per row");
  harness.seed(opt.seed);
  harness.option("--degrees", degrees, "the degrees, comma-separated");
  harness.option("--kinetic-passes", opt.kinetic_passes, "passes of CROP (the fastest counts)");
  harness.option("--anchor-passes", opt.anchor_passes,
                 "passes of the anchors (the fastest counts)");
  harness.parse(argc, argv);
  opt.n = n;
  opt.cert_n = cert_n;
  opt.degrees = parse_degrees(degrees);
  opt.kinetic_passes = std::max(1, opt.kinetic_passes);
  opt.anchor_passes = std::max(1, opt.anchor_passes);
  harness.configured();
  if (opt.n == 0 || opt.cert_n == 0) {
    std::fprintf(stderr, "bench_crop: --n and --cert-n must be positive\n");
    return 2;
  }
  if (!kinetic::crop_precision_supported(kEps, kLo, kHi)) {
    std::fprintf(stderr, "bench_crop: eps not supported on the window\n");
    return 2;
  }

  out("  window:          [%g, %g], eps = %g (grid width %a)\n", kLo, kHi, kEps,
      kinetic::crop_grid_width(kEps));
  out("  polynomials:     %zu per row (degrees", opt.n);
  for (const int d : opt.degrees) out(" %d", d);
  out("; hard mix and generic), %zu certificates per row (linear, quadratic)\n", opt.cert_n);
  out("  seed:            %llu (mt19937_64)\n", static_cast<unsigned long long>(opt.seed));
  out("  passes:          kinetic %d, anchors %d; figures: fastest pass / count, CPU time\n",
      opt.kinetic_passes, opt.anchor_passes);
#if KINETIC_BENCH_HAVE_ARB
  out("  anchor Arb:      FLINT %s, Arb %d.%d.%d (squarefree part + "
      "arb_fmpz_poly_complex_roots)\n",
      FLINT_VERSION, __ARB_VERSION, __ARB_VERSION_MINOR, __ARB_VERSION_PATCHLEVEL);
#else
  out("  anchor Arb: not available\n");
#endif
#if KINETIC_BENCH_HAVE_CGAL
  out("  anchor CGAL:     CGAL %s (Algebraic_kernel_d_1<Gmpz>: Solve_1 + "
      "Approximate_absolute_1)\n",
      CGAL_VERSION_STR);
#else
  out("  anchor CGAL: not available\n");
#endif
  out("\n");
  std::fflush(stdout);

  // Inputs: one generator per row, seeded from the global seed and the row, so that a row's
  // polynomials do not depend on which other rows run.
  std::vector<Row> rows;
  std::array<std::int64_t, kCategoryCount> mix_categories{};
  for (const int d : opt.degrees) {
    for (const bool mix : {true, false}) {
      Rng rng(opt.seed * 1000003ULL + static_cast<std::uint64_t>(d) * 2 + (mix ? 1 : 0));
      std::vector<TestPoly> polys;
      polys.reserve(opt.n);
      for (std::size_t k = 0; k < opt.n; ++k) polys.push_back(make_poly(rng, d, mix));
      if (mix)
        for (const TestPoly& p : polys) ++mix_categories[static_cast<std::size_t>(p.category)];
      rows.push_back(run_row(std::to_string(d), mix ? "mix" : "generic", polys, opt));
      std::fflush(stdout);
    }
  }
  for (const int d : {1, 2}) {
    Rng rng(opt.seed * 1000003ULL + 100 + static_cast<std::uint64_t>(d));
    std::vector<TestPoly> polys;
    polys.reserve(opt.cert_n);
    for (std::size_t k = 0; k < opt.cert_n; ++k) polys.push_back(make_certificate(rng, d));
    rows.push_back(
        run_row(std::to_string(d), d == 1 ? "cert-linear" : "cert-quadratic", polys, opt));
    std::fflush(stdout);
  }

  out("Hard mix, all degrees together:");
  for (int c = 0; c < kCategoryCount; ++c)
    if (mix_categories[static_cast<std::size_t>(c)] != 0)
      out(" %s %lld;", category_name(static_cast<Category>(c)),
          static_cast<long long>(mix_categories[static_cast<std::size_t>(c)]));
  out("\n\n");

  out("%-6s %-14s %6s | %12s %12s %12s | %9s %9s | %8s %8s %7s %7s\n", "degree", "set", "polys",
      "kinetic us", "Arb us", "CGAL us", "Arb/kin", "CGAL/kin", "exact%", "GMP/call", "events",
      "turb.");
  for (const Row& r : rows) {
    out("%-6s %-14s %6zu | %12s %12s %12s | %9s %9s | %7.2f%% %8.3f %7.3f %7.3f\n",
        r.degree.c_str(), r.set.c_str(), r.n, us(r.kinetic, true).c_str(),
        us(r.arb, r.has_arb).c_str(), us(r.cgal, r.has_cgal).c_str(),
        ratio(r.arb, r.has_arb, r.kinetic).c_str(), ratio(r.cgal, r.has_cgal, r.kinetic).c_str(),
        100.0 * r.exact_call_fraction, r.exact_per_call, r.events_per_call, r.turbulent_per_call);
  }
  out("\n(us = microseconds per polynomial, fastest pass; exact%% = calls that needed the "
      "exact GMP fallback at least once (CropStats::predicates.exact > 0); GMP/call = exact "
      "decisions per call; events / turb. = event / turbulent intervals per call)\n\n");

  out("%-6s %-14s | %9s %9s | %-16s | %5s | %s\n", "degree", "set", "fast-path", "boxes",
      "cpu/wall", "calib", "checks (exact, not timed)");
  std::int64_t total_bad = 0;
  auto anchor_check = [](const char* name, bool has, const Counts& c) {
    char buf[96];
    if (!has) {
      std::snprintf(buf, sizeof buf, "%s n/a", name);
    } else {
      std::snprintf(buf, sizeof buf, "%s: %lld roots, %lld disagreements, %lld undecided", name,
                    static_cast<long long>(c.roots_checked),
                    static_cast<long long>(c.disagreements), static_cast<long long>(c.undecided));
    }
    return std::string(buf);
  };
  auto cpu_wall = [](const Row& r) {
    char buf[64];
    auto one = [](const Timing& t, bool has) {
      char b[16];
      if (has) {
        std::snprintf(b, sizeof b, "%.2f", t.cpu_over_wall);
      } else {
        std::snprintf(b, sizeof b, "n/a");
      }
      return std::string(b);
    };
    std::snprintf(buf, sizeof buf, "%s/%s/%s", one(r.kinetic, true).c_str(),
                  one(r.arb, r.has_arb).c_str(), one(r.cgal, r.has_cgal).c_str());
    return std::string(buf);
  };
  for (const Row& r : rows) {
    out("%-6s %-14s | %8.1f%% %9.2f | %-16s | %5.2f | self-check failures %lld; %s; %s\n",
        r.degree.c_str(), r.set.c_str(), 100.0 * r.fast_path_fraction, r.boxes_per_call,
        cpu_wall(r).c_str(), r.calibration_ms, static_cast<long long>(r.self.self_failures),
        anchor_check("vs Arb", r.has_arb, r.vs_arb).c_str(),
        anchor_check("vs CGAL", r.has_cgal, r.vs_cgal).c_str());
    total_bad += r.self.self_failures + r.vs_arb.disagreements + r.vs_cgal.disagreements;
  }
  out("(fast-path = calls finished by CROP's closed-form / guess fast path; boxes = "
      "Bernstein subdivision boxes per call; cpu/wall = kinetic/Arb/CGAL; calib = CPU ms of a "
      "fixed workload just before the row's timings (equal on every row when the machine's speed "
      "did not change); roots = anchor roots "
      "in the window, each checked to lie in a kinetic interval; every kinetic interval is also "
      "checked for the parity of the anchor's roots inside)\n\n");

  out("Hard mix by category (us per polynomial; exact%% as above):\n");
  out("%-6s %-28s %6s | %12s %12s %12s | %9s %9s | %8s\n", "degree", "category", "polys",
      "kinetic us", "Arb us", "CGAL us", "Arb/kin", "CGAL/kin", "exact%");
  for (const Row& r : rows) {
    for (const CategoryRow& c : r.categories) {
      out("%-6s %-28s %6zu | %12s %12s %12s | %9s %9s | %7.2f%%\n", r.degree.c_str(),
          category_name(c.category), c.n, us(c.times.kinetic, true).c_str(),
          us(c.times.arb, c.times.has_arb).c_str(), us(c.times.cgal, c.times.has_cgal).c_str(),
          ratio(c.times.arb, c.times.has_arb, c.times.kinetic).c_str(),
          ratio(c.times.cgal, c.times.has_cgal, c.times.kinetic).c_str(),
          100.0 * c.exact_call_fraction);
    }
  }
  out("\nSlowest kinetic call of each row (best of 5 timings of that call alone):\n");
  for (const Row& r : rows) {
    out("  degree %s %s: %.2f us, polynomial %zu\n", r.degree.c_str(), r.set.c_str(), r.slowest_us,
        r.slowest);
    print_poly("input", r.slowest_input);
  }
  out("\n");

  for (const Row& r : rows) {
    if (r.set == "cert-quadratic") {
      out("Generic quadratic certificate (two quadratic motions, different origins): "
          "%.1f ns per CROP call\n",
          r.kinetic.us_per_poly * 1000.0);
    }
    if (r.set == "cert-linear") {
      out("Generic linear certificate (two linear motions, different origins):       "
          "%.1f ns per CROP call\n",
          r.kinetic.us_per_poly * 1000.0);
    }
  }
  double calib_lo = 1e300, calib_hi = 0.0;
  for (const Row& r : rows) {
    calib_lo = std::min(calib_lo, r.calibration_ms);
    calib_hi = std::max(calib_hi, r.calibration_ms);
  }
  out("Machine speed: calibration %.2f..%.2f ms over the rows (%+.0f%%)%s\n", calib_lo, calib_hi,
      100.0 * (calib_hi / calib_lo - 1.0),
      calib_hi > 1.1 * calib_lo ? " -- the machine was slower during some rows: compare "
                                  "ratios, or rerun"
                                : "");
  out("Lowest cpu/wall of any measurement: %.2f%s\n", g_min_cpu_over_wall,
      g_min_cpu_over_wall < 0.9 ? " -- another process competed for the core at times (the "
                                  "fastest-pass CPU times are robust to that; a quiet "
                                  "machine is still better)"
                                : " (quiet machine)");
  out("Sanity check: %lld disagreements / self-check failures in total (0 expected)\n",
      static_cast<long long>(total_bad));
  return total_bad == 0 ? 0 : 1;
}
