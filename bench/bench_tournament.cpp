// Kinetic tournament benchmark (plain timing program, docs/performance/tournament.md).
//
//  1. Events over all time ([-10^6, +infinity)) for lines, n = 10^3 .. 10^6, beside n log2 n (a
//     kinetic tournament has O(n log n) events for lines): random-linear (random lines, whose
//     subtree envelopes are short) and RANDCR (dual points on a circle: every line is on the
//     upper envelope, the worst case), classic and robust.
//  2. Events per second of both schedulers.
//  3. Q max queries at arbitrary times over a horizon: the kinetic tournament (advance to the
//     query time, read the root) against a linear scan of all n positions per query, and the
//     break-even query rate.
//  4. The three schedulers side by side (classic, robust, exact) on random-linear and GRIDS.
//
// Options: --sizes=1000,10000,100000,1000000  --seed=S  --quick (n <= 10^5)  --eps=E (robust)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "harness.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/scenario/generators.hpp"
#include "kinetic/tournament/kinetic_tournament.hpp"
#include "scheduler_table.hpp"

namespace {

using kinetic::bench::out;

/// "All time" starts here (and the robust scheduler searches up to max_supported_time).
constexpr double kSpan = 1e6;

using kinetic::Extreme;
using kinetic::KineticTournament;
using kinetic::MotionPolynomial;
using kinetic::MotionTable;
using kinetic::Scheduler;
using kinetic::SchedulerKind;
using kinetic::Simulator;

double cpu_seconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

struct Handler {
  KineticTournament* t;
  kinetic::EventKind process(const kinetic::Event& e) { return t->process(e); }
};

/// A dataset of the generators (docs/datasets.md) as a motion table and, for the scan baseline,
/// flat arrays of the lines' coefficients (every motion here is a line x0 + v (t - origin)).
struct Input {
  std::vector<double> x0, v;  // x0 + v t (origin folded in)
  MotionTable motions{1};
};

Input make_input(const std::string& dataset, std::size_t n, std::uint64_t seed) {
  kinetic::scenario::GeneratorOptions o;
  o.n = n;
  o.seed = seed;
  const kinetic::scenario::Scenario s = kinetic::scenario::generate(dataset, o);
  Input in;
  for (const auto& obj : s.objects) {
    const MotionPolynomial p = MotionPolynomial::from(obj.motion.coordinates[0], obj.motion.origin);
    const double v = p.degree >= 1 ? p.c[1] : 0.0;
    in.x0.push_back(p.c[0] - v * p.origin);
    in.v.push_back(v);
    in.motions.insert(obj.id, std::span<const MotionPolynomial>(&p, 1), -kSpan);
  }
  return in;
}

struct RunFigures {
  std::uint64_t events = 0, external = 0;
  double cpu = 0.0, wall = 0.0, setup_cpu = 0.0;
  bool audit_ok = false;
};

/// All events of [start, horizon] (horizon = infinity: until none is left).
RunFigures run(const Input& in, SchedulerKind kind, double eps, double start, double horizon) {
  Simulator sim(start);
  const Scheduler sched(kind, eps, horizon);
  KineticTournament t(in.motions, sim, sched, 0, Extreme::Max);
  Handler h{&t};
  RunFigures f;
  double c0 = cpu_seconds();
  t.initialize();
  f.setup_cpu = cpu_seconds() - c0;
  const auto w0 = std::chrono::steady_clock::now();
  c0 = cpu_seconds();
  if (std::isinf(horizon)) {
    (void)sim.run_until_empty(h);
  } else {
    (void)sim.advance_to(horizon, h);
  }
  f.cpu = cpu_seconds() - c0;
  f.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
  f.events = sim.counters().events();
  f.external = sim.counters().events_external;
  const double t_end = std::isinf(horizon) ? std::max(1.0, sim.now()) + 1.0 : horizon;
  f.audit_ok = t.audit(t_end).ok;
  return f;
}

/// Seconds per query of the linear scan: the max of x0 + v t over all points, t in [-T, T].
double scan_seconds_per_query(const Input& in, double horizon, int queries) {
  volatile double sink = 0.0;
  const double c0 = cpu_seconds();
  for (int q = 0; q < queries; ++q) {
    const double t = horizon * (2.0 * (q + 0.5) / queries - 1.0);  // in [-T, T]
    double best = -HUGE_VAL;
    const std::size_t n = in.x0.size();
    for (std::size_t i = 0; i < n; ++i) best = std::max(best, in.x0[i] + in.v[i] * t);
    sink = sink + best;
  }
  return (cpu_seconds() - c0) / queries;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::size_t> sizes = {1000, 10000, 100000, 1000000};
  std::uint64_t seed = 1;
  double eps = 1e-6;
  bool quick = false;
  kinetic::bench::Harness harness(
      "bench_tournament",
      "kinetic tournament (max) over lines, datasets random-linear (x0 uniform in [0, n], v "
      "uniform in [-1, 1]) and randcr (dual points on the unit circle)");
  harness.sizes(sizes);
  harness.seed(seed);
  harness.option("--eps", eps, "the robust scheduler's precision");
  harness.quick(quick, "sizes 10^3 to 10^5");
  harness.parse(argc, argv);
  if (quick && !harness.given("--sizes")) sizes = {1000, 10000, 100000};
  harness.configured();

  out("\n1-2. Events over all time ([-1e6, until none is left)), and their cost\n");
  out("| dataset | n | n log2 n | events classic | events robust | events / (n log2 n) | "
      "external | classic ns/event | robust ns/event | robust/classic | audit |\n");
  out("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n");
  for (const char* dataset : {"random-linear", "randcr"}) {
    for (const std::size_t n : sizes) {
      const Input in = make_input(dataset, n, seed);
      const RunFigures c = run(in, SchedulerKind::Classic, eps, -kSpan, kinetic::kTimeInfinity);
      const RunFigures r = run(in, SchedulerKind::Robust, eps, -kSpan, kinetic::kTimeInfinity);
      const double nlogn = static_cast<double>(n) * std::log2(static_cast<double>(n));
      out("| %s | %zu | %.0f | %llu | %llu | %.3f | %llu | %.0f | %.0f | %.2f | %s |\n", dataset, n,
          nlogn, static_cast<unsigned long long>(c.events),
          static_cast<unsigned long long>(r.events), static_cast<double>(r.events) / nlogn,
          static_cast<unsigned long long>(r.external),
          1e9 * c.cpu / static_cast<double>(std::max<std::uint64_t>(1, c.events)),
          1e9 * r.cpu / static_cast<double>(std::max<std::uint64_t>(1, r.events)),
          r.cpu / std::max(1e-12, c.cpu), c.audit_ok && r.audit_ok ? "ok" : "FAIL");
      std::fflush(stdout);
    }
  }

  out("\n3. Max queries at arbitrary times over [-T, T], T = 10 (RANDCR's window): kinetic "
      "vs linear scan\n");
  out("| dataset | n | events in [-T, T] | kinetic run over [-T, T] (robust) | scan per query "
      "| break-even (queries per unit time) | kinetic cost per query at 10 / 1000 "
      "queries per unit time |\n");
  out("|---|---:|---:|---:|---:|---:|---:|\n");
  const double horizon = 10.0;
  for (const char* dataset : {"random-linear", "randcr"}) {
    for (const std::size_t n : sizes) {
      const Input in = make_input(dataset, n, seed);
      const RunFigures r = run(in, SchedulerKind::Robust, eps, -horizon, horizon);
      const int queries = static_cast<int>(std::max<std::size_t>(20, 20000000 / n));
      const double scan = scan_seconds_per_query(in, horizon, queries);
      const double breakeven = r.cpu / (scan * 2.0 * horizon);
      auto per_query = [&](double rate) { return r.cpu / (rate * 2.0 * horizon); };
      out("| %s | %zu | %llu | %.3g s | %.3g us | %.3g | %.3g us / %.3g us |\n", dataset, n,
          static_cast<unsigned long long>(r.events), r.cpu, 1e6 * scan, breakeven,
          1e6 * per_query(10.0), 1e6 * per_query(1000.0));
      std::fflush(stdout);
    }
  }
  out("\n(CPU time of this process; reading the root after advance_to(t) costs O(1) and is "
      "not counted.)\n");

  // 4. The three schedulers side by side (exact beside robust and classic).
  const double budget = 20.0;
  const std::size_t n_side = std::min<std::size_t>(100000, sizes.back());
  kinetic::bench::print_scheduler_table<KineticTournament>(
      "tournament (max)", "random-linear", make_input("random-linear", n_side, seed).motions,
      -kSpan, kSpan, eps, budget, 0, Extreme::Max);
  kinetic::bench::print_scheduler_table<KineticTournament>(
      "tournament (max)", "grids", make_input("grids", 900, seed).motions, -kSpan, kSpan, eps,
      budget, 0, Extreme::Max);
  return 0;
}
