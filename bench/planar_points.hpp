#pragma once
// Shared by the benchmarks of the planar point structures (hull, Delaunay, closest pair): a
// generated 2-D dataset as a motion table, the structure's initialize and event loop timed (the
// loop under a CPU budget), the positions at a time in double (what a recompute-per-query
// baseline starts from), and the closest-pair baseline on them.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "harness.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/scenario/generators.hpp"

namespace kinetic::bench {

/// The dataset (kinetic generate's names) as a 2-D motion table, object i at index i, motions
/// valid from `start`.
inline MotionTable planar_table(const std::string& dataset, std::size_t n, std::uint64_t seed,
                                double start) {
  scenario::GeneratorOptions o;
  o.n = n;
  o.seed = seed;
  o.dimension = 2;
  const scenario::Scenario s = scenario::generate(dataset, o);
  MotionTable motions(2);
  std::uint32_t expected = 0;
  for (const auto& obj : s.objects) {
    std::array<MotionPolynomial, 2> p;
    for (std::size_t a = 0; a < 2; ++a)
      p[a] = MotionPolynomial::from(obj.motion.coordinates[a], obj.motion.origin);
    const auto h = motions.insert(obj.id, p, start);
    if (h.index != expected++) {
      std::fprintf(stderr, "unexpected object index\n");
      std::exit(2);
    }
  }
  return motions;
}

/// The CPU seconds of s.initialize().
template <class S>
double timed_initialize(S& s) {
  const double c0 = cpu_now();
  s.initialize();
  return cpu_now() - c0;
}

/// An event loop under a CPU budget: its CPU, whether the budget stopped it, and the simulated
/// time up to which every event was processed.
struct BudgetedLoop {
  double cpu = 0, reached = 0;
  bool stopped = false;
};

/// Processes the events of s at times <= end, one by one, until `budget` CPU seconds are spent
/// (checked every 16 events); reached: end, or the last event's time when the budget stopped it.
template <class S>
BudgetedLoop process_within_budget(Simulator& sim, S& s, double end, double budget) {
  BudgetedLoop l;
  const double c0 = cpu_now();
  std::uint64_t k = 0;
  while (!sim.queue().empty() && sim.queue().top().time <= end) {
    (void)sim.process_next(s);
    if ((++k & 15U) == 0 && cpu_now() - c0 > budget) {
      l.stopped = true;
      break;
    }
  }
  l.cpu = cpu_now() - c0;
  l.reached = l.stopped ? sim.now() : end;
  return l;
}

/// a per b (a count, taken as at least 1): CPU per event, decisions per event, ...
inline double per(double a, std::uint64_t b) {
  return a / static_cast<double>(std::max<std::uint64_t>(1, b));
}

/// `queries` query times in [start, start + span], sorted: drawn from `seed`, so the same for
/// every structure run on the dataset of that seed.
inline std::vector<double> query_times(std::uint64_t seed, double start, double span, int queries) {
  std::mt19937_64 rng(seed + 7);
  std::vector<double> times;
  for (int q = 0; q < queries; ++q)
    times.push_back(start + span * std::generate_canonical<double, 53>(rng));
  std::sort(times.begin(), times.end());
  return times;
}

/// The live objects' positions at t, in double.
inline std::vector<std::array<double, 2>> positions(const MotionTable& m, double t) {
  std::vector<std::array<double, 2>> out;
  for (const std::uint32_t i : m.alive_indices())
    out.push_back({m.motion(i, 0).evaluate(t), m.motion(i, 1).evaluate(t)});
  return out;
}

/// The closest pair's squared distance by a sort on x and a sweep (double): the baseline that
/// re-sorts per query.
inline double sweep_closest(std::vector<std::array<double, 2>> p) {
  std::sort(p.begin(), p.end());
  double best = HUGE_VAL;
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      const double dx = p[j][0] - p[i][0];
      if (dx * dx >= best) break;
      const double dy = p[j][1] - p[i][1];
      best = std::min(best, dx * dx + dy * dy);
    }
  }
  return best;
}

/// Whether the squared distances of a structure's closest pair and of the sweep's differ (beyond
/// rounding).
inline bool distances_differ(double pair_distance, double best) {
  return std::fabs(pair_distance - best) > 1e-9 * (1.0 + best);
}

/// The squared distance of objects a and b at t, in double.
inline double squared_distance(const MotionTable& m, std::uint32_t a, std::uint32_t b, double t) {
  const double dx = m.motion(a, 0).evaluate(t) - m.motion(b, 0).evaluate(t);
  const double dy = m.motion(a, 1).evaluate(t) - m.motion(b, 1).evaluate(t);
  return dx * dx + dy * dy;
}

/// The options of the planar benchmarks: --sizes --quick (n <= 10000) --budget --queries
/// --seed --eps --schedulers, declared on the harness and parsed.
struct PlanarOptions {
  std::vector<std::size_t> sizes{1000, 10000};
  double budget = 20.0;
  int queries = 50;
  std::uint64_t seed = 1;
  /// The robust scheduler's precision, for the benches that run it (--eps=).
  double eps = 1e-9;
  /// The schedulers to run, for the benches that run several (--schedulers=exact,robust).
  std::vector<std::string> schedulers;
  bool quick = false;  ///< only the sizes n <= 10000
};
/// Declares the options on the harness, parses them into `o` (the caller's, alive until the
/// harness ends) and records the configuration.
inline void parse_planar_options(Harness& h, int argc, char** argv, PlanarOptions& o) {
  h.sizes(o.sizes);
  h.budget(o.budget, "CPU seconds per event loop at most");
  h.option("--queries", o.queries, "queries per run");
  h.seed(o.seed);
  h.option("--eps", o.eps, "the robust scheduler's precision");
  h.list("--schedulers", o.schedulers, "the schedulers to run (exact, robust)");
  h.quick(o.quick, "only the sizes n <= 10000");
  h.parse(argc, argv);
  if (o.quick) {
    o.sizes.erase(
        std::remove_if(o.sizes.begin(), o.sizes.end(), [](std::size_t n) { return n > 10000; }),
        o.sizes.end());
  }
  h.configured();
}

}  // namespace kinetic::bench
