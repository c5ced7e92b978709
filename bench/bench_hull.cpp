// Kinetic convex hull benchmark (plain timing program).
//
//  1. Events over the dataset window [0, 10] for random-linear (2-D) and circle (points on a
//     breathing, turning circle: many hull changes, long chains), n in --sizes, robust (eps the
//     Scheduler default) and classic scheduling: internal / external events per unit simulated
//     time, cost per event (CPU of the event loop / events), initialize time, certificates,
//     merges and decisions per event. Every run has a CPU budget (--budget) for its event loop:
//     an event can cost O(n) on circle (a node re-merge walks its children's chains), so the loop
//     stops when the budget is spent and the rates are those of what was processed. A
//     configuration is skipped only when a measured initialize at a smaller n, scaled linearly
//     (a lower bound: every point takes part in at least one merge per level), exceeds the budget.
//     Baseline of the section: classic scheduling (robust / classic ratios).
//  2. Q hull queries at random sorted times in the window (robust run): the kinetic hull (advance
//     to the query time, then hull(), only hull() timed as the query) against recomputing the
//     hull on the positions at that time: evaluate every motion in double (timed), then CGAL's
//     convex_hull_2 (Epick), qhull (section 2b) and Andrew's monotone chain in double. Hull sizes
//     are compared on every query answered by both; the break-even query rate uses the robust run
//     of section 1.
//  3. Hull sizes h over the queries.
//  4. The three schedulers side by side (classic, robust, exact), n = 10^4, each dataset.
//
// CGAL and qhull (libqhull-dev) are benchmark-only dependencies: when one is missing, "peer X:
// not available".
// Options: --sizes=1000,10000,100000,1000000  --quick (n <= 100000)  --budget=SECONDS (20)
//          --queries=Q (200)  --seed=S  --eps=E (robust; default the Scheduler's)
//          --datasets=random-linear,circle
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "harness.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/hull/kinetic_hull.hpp"
#include "kinetic/scenario/generators.hpp"
#include "planar_points.hpp"
#include "scheduler_table.hpp"

#if defined(KINETIC_BENCH_HAVE_QHULL)
extern "C" {
#include <libqhull_r/qhull_ra.h>
}
#endif
#if defined(KINETIC_BENCH_HAVE_CGAL)
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/convex_hull_2.h>
#include <CGAL/version.h>
#endif

using kinetic::bench::out;

namespace {

using kinetic::bench::cpu_now;
using kinetic::bench::wall_now;

using kinetic::KineticHull;
using kinetic::MotionTable;
using kinetic::Scheduler;
using kinetic::SchedulerKind;
using kinetic::Simulator;

constexpr double kStart = 0.0, kEnd = 10.0;  // both datasets' window

double ratio(double a, double b) { return b > 0.0 ? a / b : HUGE_VAL; }
using kinetic::bench::per;

MotionTable make_table(const std::string& dataset, std::size_t n, std::uint64_t seed) {
  return kinetic::bench::planar_table(dataset, n, seed, kStart);
}

/// A kinetic hull over a table, advanced under a CPU budget for its event loop.
struct Run {
  Simulator sim{kStart};
  Scheduler sched;
  KineticHull hull;
  double budget;
  double init_cpu = 0.0;
  double loop_cpu = 0.0;  ///< CPU of the event loop (advance) so far
  bool stopped = false;   ///< the budget ran out before the last requested time
  double at = kStart;     ///< the last requested time reached
  kinetic::HullCounters after_init;

  Run(const MotionTable& motions, SchedulerKind kind, double eps, double budget_s)
      : sched(kind, eps, kEnd), hull(motions, sim, sched), budget(budget_s) {}

  void initialize() {
    init_cpu = kinetic::bench::timed_initialize(hull);
    after_init = hull.counters();
  }

  /// Processes every event up to t unless the budget runs out; true when t was reached.
  bool advance(double t) {
    if (stopped) return false;
    const double c0 = cpu_now();
    stopped = kinetic::bench::process_within_budget(sim, hull, t, budget - loop_cpu).stopped;
    if (!stopped) {
      (void)sim.advance_to(t, hull);
      at = t;
    }
    loop_cpu += cpu_now() - c0;
    return !stopped;
  }

  /// The simulated time up to which every event was processed (stopped: the last event's).
  [[nodiscard]] double reached() const { return stopped ? sim.now() : at; }
  [[nodiscard]] std::uint64_t events() const { return sim.counters().events(); }
};

// ---------------------------------------------------------------------------------------------
// 1. Events.

struct EventFigures {
  bool skipped = false;
  std::string skip_reason;
  double init_cpu = 0, loop_cpu = 0, reached = 0;
  bool stopped = false, valid = false;
  std::size_t certificates = 0, queued = 0;
  std::uint64_t internal = 0, external = 0, merges = 0, decisions = 0;
  [[nodiscard]] std::uint64_t events() const { return internal + external; }
  [[nodiscard]] double us_per_event() const { return 1e6 * per(loop_cpu, events()); }
  [[nodiscard]] double cpu_per_time() const { return ratio(loop_cpu, reached - kStart); }
};

EventFigures run_events(const MotionTable& motions, SchedulerKind kind, double eps, double budget) {
  Run r(motions, kind, eps, budget);
  r.initialize();
  EventFigures f;
  f.init_cpu = r.init_cpu;
  f.certificates = r.hull.certificates();
  f.queued = r.sim.queue().size();
  (void)r.advance(kEnd);
  f.loop_cpu = r.loop_cpu;
  f.stopped = r.stopped;
  f.reached = r.reached();
  f.internal = r.sim.counters().events_internal;
  f.external = r.sim.counters().events_external;
  f.merges = r.hull.counters().merges - r.after_init.merges;
  f.decisions = r.hull.counters().decisions - r.after_init.decisions;
  f.valid = r.hull.validate();
  return f;
}

std::string status(const EventFigures& f) {
  char buf[96];
  if (f.stopped) {
    std::snprintf(buf, sizeof buf, "stopped at t=%.4g (budget)", f.reached);
  } else {
    std::snprintf(buf, sizeof buf, "window done");
  }
  return buf;
}

void print_event_row(const char* dataset, std::size_t n, const char* sched, const EventFigures& f,
                     const EventFigures* classic) {
  if (f.skipped) {
    out("| %s | %zu | %s | skipped: %s | | | | | | | | | | |\n", dataset, n, sched,
        f.skip_reason.c_str());
    return;
  }
  const double span = f.reached - kStart;
  char vs[64] = "1 (baseline)";
  if (classic != nullptr) {
    if (classic->skipped || classic->events() == 0) {
      std::snprintf(vs, sizeof vs, "-");
    } else {
      std::snprintf(vs, sizeof vs, "%.2f / %.2f", f.us_per_event() / classic->us_per_event(),
                    ratio(static_cast<double>(f.events()) / span,
                          static_cast<double>(classic->events()) / (classic->reached - kStart)));
    }
  }
  out("| %s | %zu | %s | %.3f | %zu | %zu | %s | %llu | %.4g / %.4g | %.2f | %.2f | %.1f | %s | %s "
      "|\n",
      dataset, n, sched, f.init_cpu, f.certificates, f.queued, status(f).c_str(),
      static_cast<unsigned long long>(f.events()), ratio(static_cast<double>(f.internal), span),
      ratio(static_cast<double>(f.external), span), f.us_per_event(),
      per(static_cast<double>(f.merges), f.events()),
      per(static_cast<double>(f.decisions), f.events()), vs, f.valid ? "ok" : "FAIL");
  std::fflush(stdout);
}

// ---------------------------------------------------------------------------------------------
// 2. Queries.

struct P2 {
  double x, y;
};

double cross(const P2& o, const P2& a, const P2& b) {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

/// Andrew's monotone chain in double (strict turns): the number of hull vertices.
std::size_t monotone_chain(std::vector<P2> p) {
  std::sort(p.begin(), p.end(),
            [](const P2& a, const P2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  p.erase(std::unique(p.begin(), p.end(),
                      [](const P2& a, const P2& b) { return a.x == b.x && a.y == b.y; }),
          p.end());
  if (p.size() <= 2) return p.size();
  std::vector<P2> h(2 * p.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  for (std::size_t i = p.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  return k - 1;
}

#if defined(KINETIC_BENCH_HAVE_QHULL)
/// qhull (reentrant libqhull_r, default options "qhull": Quickhull with merged facets) on n
/// points in the plane given as x0 y0 x1 y1 ...: the number of hull vertices, 0 on an error.
std::size_t qhull_vertices(std::vector<double>& coordinates) {
  qhT qh_storage;
  qhT* qh = &qh_storage;
  qh_zero(qh, stderr);
  char options[] = "qhull";
  const int n = static_cast<int>(coordinates.size() / 2);
  const int status = qh_new_qhull(qh, 2, n, coordinates.data(), False, options, nullptr, stderr);
  const std::size_t vertices = status == 0 ? static_cast<std::size_t>(qh->num_vertices) : 0;
  qh_freeqhull(qh, !qh_ALL);
  int still_long = 0, total_long = 0;
  qh_memfreeshort(qh, &still_long, &total_long);
  return vertices;
}
#endif

struct QueryFigures {
  int queries = 0;
  int answered = 0;  ///< by the kinetic hull (within its budget)
  bool stopped = false;
  double reached = 0;
  double advance_cpu = 0, kinetic_cpu = 0;
  double sum_h = 0, sum_candidates = 0;
  // Baselines (over the queries measured within their own budget).
  int measured = 0;
  double eval_cpu = 0, cgal_cpu = 0, mono_cpu = 0, qhull_cpu = 0;
  double sum_h_cgal = 0, sum_h_mono = 0;
  int compared = 0, cgal_differs = 0, mono_differs = 0, qhull_differs = 0;
  double sum_h_compared = 0, sum_h_cgal_compared = 0;  ///< over the compared queries
  std::vector<std::string> examples;
};

QueryFigures run_queries(const MotionTable& motions, double eps, double budget, int queries,
                         std::uint64_t seed) {
  QueryFigures f;
  f.queries = queries;
  std::mt19937_64 rng(seed * 1000003 + motions.size());
  std::uniform_real_distribution<double> u(kStart, kEnd);
  std::vector<double> times(static_cast<std::size_t>(queries));
  for (double& t : times) t = u(rng);
  std::sort(times.begin(), times.end());

  Run r(motions, SchedulerKind::Robust, eps, budget);
  r.initialize();
  const std::uint32_t n = static_cast<std::uint32_t>(motions.size());
  std::vector<P2> pos(n);
#if defined(KINETIC_BENCH_HAVE_CGAL)
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  std::vector<K::Point_2> cpts(n), cout;
#endif
#if defined(KINETIC_BENCH_HAVE_QHULL)
  std::vector<double> qpts(2 * static_cast<std::size_t>(n));
#endif
  for (const double t : times) {
    std::size_t hk = 0;
    const bool reached = r.advance(t);
    if (reached) {
      const double c0 = cpu_now();
      const std::vector<std::uint32_t> h = r.hull.hull();
      f.kinetic_cpu += cpu_now() - c0;
      ++f.answered;
      hk = h.size();
      f.sum_h += static_cast<double>(hk);
      f.sum_candidates += static_cast<double>(r.hull.candidates().size());
    }
    if (f.eval_cpu + f.cgal_cpu + f.mono_cpu + f.qhull_cpu > budget) continue;
    ++f.measured;
    double c0 = cpu_now();
    for (std::uint32_t i = 0; i < n; ++i)
      pos[i] = P2{motions.motion(i, 0).evaluate(t), motions.motion(i, 1).evaluate(t)};
    f.eval_cpu += cpu_now() - c0;
    std::size_t hc = 0;
#if defined(KINETIC_BENCH_HAVE_CGAL)
    c0 = cpu_now();
    for (std::uint32_t i = 0; i < n; ++i) cpts[i] = K::Point_2(pos[i].x, pos[i].y);
    cout.clear();
    CGAL::convex_hull_2(cpts.begin(), cpts.end(), std::back_inserter(cout));
    f.cgal_cpu += cpu_now() - c0;
    hc = cout.size();
    f.sum_h_cgal += static_cast<double>(hc);
#endif
    c0 = cpu_now();
    const std::size_t hm = monotone_chain(pos);
    f.mono_cpu += cpu_now() - c0;
    f.sum_h_mono += static_cast<double>(hm);
#if defined(KINETIC_BENCH_HAVE_QHULL)
    c0 = cpu_now();
    for (std::uint32_t i = 0; i < n; ++i) {
      qpts[2 * i] = pos[i].x;
      qpts[2 * i + 1] = pos[i].y;
    }
    const std::size_t hq = qhull_vertices(qpts);
    f.qhull_cpu += cpu_now() - c0;
    if (reached && hq != hk) ++f.qhull_differs;
#endif
    if (reached) {
      ++f.compared;
      f.sum_h_compared += static_cast<double>(hk);
      f.sum_h_cgal_compared += static_cast<double>(hc);
#if defined(KINETIC_BENCH_HAVE_CGAL)
      if (hc != hk) ++f.cgal_differs;
#endif
      if (hm != hk) ++f.mono_differs;
      if ((hc != hk || hm != hk) && f.examples.size() < 3) {
        char buf[128];
        std::snprintf(buf, sizeof buf, "t=%.6f: kinetic %zu, CGAL %zu, monotone chain %zu", t, hk,
                      hc, hm);
        f.examples.emplace_back(buf);
      }
    }
  }
  f.advance_cpu = r.loop_cpu;
  f.stopped = r.stopped;
  f.reached = r.reached();
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::size_t> sizes = {1000, 10000, 100000, 1000000};
  std::uint64_t seed = 1;
  double eps = Scheduler().eps();
  double budget = 20.0;
  int queries = 200;
  bool quick = false;
  std::vector<std::string> datasets = {"random-linear", "circle"};
  kinetic::bench::Harness harness(
      "bench_hull",
      "the kinetic convex hull (robust and classic scheduling) against "
      "CGAL's convex_hull_2 recomputed per query; times are process CPU");
  harness.sizes(sizes);
  harness.seed(seed);
  harness.option("--eps", eps, "the robust scheduler's precision");
  harness.budget(budget, "CPU seconds per event loop at most");
  harness.option("--queries", queries, "queries per run");
  harness.list("--datasets", datasets, "the datasets (random-linear, circle)");
  harness.quick(quick, "only the sizes n <= 100000");
  harness.parse(argc, argv);
  queries = std::max(1, queries);
  for (const std::string& d : datasets) {
    if (d != "random-linear" && d != "circle") {
      std::fprintf(stderr, "bench_hull: unknown dataset '%s' (random-linear, circle)\n", d.c_str());
      return 2;
    }
  }
  if (quick)
    sizes.erase(
        std::remove_if(sizes.begin(), sizes.end(), [](std::size_t n) { return n > 100000; }),
        sizes.end());
  harness.configured();
  const double wall0 = wall_now(), cpu0 = cpu_now();

  out("bench_hull: kinetic convex hull (kinetic divide and conquer, re-merge on failure); "
      "window [%g, %g], seed %llu; datasets:\n",
      kStart, kEnd, static_cast<unsigned long long>(seed));
  for (const std::string& name : datasets) {
    out("  %s %s\n", name.c_str(),
        name == "circle" ? "(2-D points on a breathing, turning unit circle, degree 2)"
                         : "(2-D: positions uniform in [0, sqrt n]^2, velocities in "
                           "[-1, 1]^2)");
  }
  out("  sizes:");
  for (const std::size_t s : sizes) out(" %zu", s);
  out("%s; robust eps %g, classic; CPU budget per event loop %g s; %d queries\n",
      quick ? " (--quick)" : "", eps, budget, queries);
#if defined(KINETIC_BENCH_HAVE_CGAL)
  out("  peer CGAL %s: convex_hull_2 (Epick, default Akl-Toussaint) on the positions evaluated "
      "in double\n",
      CGAL_VERSION_STR);
#else
  out("  peer CGAL: not available\n");
#endif
#if defined(KINETIC_BENCH_HAVE_QHULL)
  out("  peer qhull %s: qh_new_qhull (libqhull_r, options \"qhull\") on the same positions\n",
      qh_version);
#else
  out("  peer qhull: not available\n");
#endif

  // 1. Events.
  out("\n1. Events over [%g, %g] (robust and classic; CPU budget %g s per event loop; rates over "
      "the simulated time reached; baseline: classic)\n",
      kStart, kEnd, budget);
  out("| dataset | n | scheduler | initialize s | certificates | queued | run | events | "
      "internal / external per unit time | us/event | merges/event | decisions/event | "
      "us/event, events per unit time vs classic | validate |\n");
  out("|---|---:|---|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---|\n");
  std::map<std::pair<std::string, std::size_t>, EventFigures> robust_figures;
  bool all_valid = true;
  for (const std::string& name : datasets) {
    const char* dataset = name.c_str();
    // Per scheduler: the last measured initialize (n, CPU s).
    std::map<SchedulerKind, std::pair<std::size_t, double>> last_init;
    for (const std::size_t n : sizes) {
      const MotionTable motions = make_table(dataset, n, seed);
      EventFigures fig[2];
      const SchedulerKind kinds[2] = {SchedulerKind::Robust, SchedulerKind::Classic};
      for (int k = 0; k < 2; ++k) {
        const auto it = last_init.find(kinds[k]);
        if (it != last_init.end()) {
          const double bound =
              it->second.second * static_cast<double>(n) / static_cast<double>(it->second.first);
          if (bound > budget) {
            fig[k].skipped = true;
            char buf[160];
            std::snprintf(buf, sizeof buf,
                          "initialize measured %.2f s at n=%zu, so >= %.1f s here > budget",
                          it->second.second, it->second.first, bound);
            fig[k].skip_reason = buf;
            continue;
          }
        }
        fig[k] = run_events(motions, kinds[k], eps, budget);
        last_init[kinds[k]] = {n, fig[k].init_cpu};
        all_valid = all_valid && fig[k].valid;
      }
      print_event_row(dataset, n, "robust", fig[0], &fig[1]);
      print_event_row(dataset, n, "classic", fig[1], nullptr);
      robust_figures[{dataset, n}] = fig[0];
    }
  }

  // 2. Queries.
  out("\n2. %d hull queries at random sorted times in [%g, %g] (robust run, budget %g s for "
      "advancing; baselines timed within their own budget of %g s): mean us per query\n",
      queries, kStart, kEnd, budget, budget);
  out("| dataset | n | answered / measured | kinetic hull() | evaluate n positions | CGAL only | "
      "CGAL + evaluate | monotone chain + evaluate | speedup vs CGAL (+evaluate / only) | "
      "kinetic CPU per unit time (section 1) | break-even queries per unit time vs CGAL / "
      "monotone | size disagreements vs CGAL / monotone (of compared) |\n");
  out("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  std::map<std::pair<std::string, std::size_t>, QueryFigures> query_figures;
  std::vector<std::string> notes;
  for (const std::string& name : datasets) {
    const char* dataset = name.c_str();
    for (const std::size_t n : sizes) {
      const auto rf = robust_figures.find({dataset, n});
      if (rf == robust_figures.end() || rf->second.skipped) {
        out("| %s | %zu | skipped (section 1 skipped) | | | | | | | | | |\n", dataset, n);
        continue;
      }
      const MotionTable motions = make_table(dataset, n, seed);
      const QueryFigures q = run_queries(motions, eps, budget, queries, seed);
      query_figures[{dataset, n}] = q;
      const double kin = per(q.kinetic_cpu, static_cast<std::uint64_t>(q.answered));
      const double ev = per(q.eval_cpu, static_cast<std::uint64_t>(q.measured));
      const double cg = per(q.cgal_cpu, static_cast<std::uint64_t>(q.measured));
      const double mo = per(q.mono_cpu, static_cast<std::uint64_t>(q.measured));
      const double K = rf->second.cpu_per_time();
      // "never": recomputing costs less than the kinetic query alone.
      const auto breakeven = [&](double recompute) {
        char buf[32];
        if (recompute > kin) {
          std::snprintf(buf, sizeof buf, "%.3g", K / (recompute - kin));
        } else {
          std::snprintf(buf, sizeof buf, "never");
        }
        return std::string(buf);
      };
#if defined(KINETIC_BENCH_HAVE_CGAL)
      char cgal_cols[96], speedup[64], be_cgal[32], dis_cgal[32];
      std::snprintf(cgal_cols, sizeof cgal_cols, "%.1f | %.1f", 1e6 * cg, 1e6 * (ev + cg));
      std::snprintf(speedup, sizeof speedup, "%.1f / %.1f", ratio(ev + cg, kin), ratio(cg, kin));
      std::snprintf(be_cgal, sizeof be_cgal, "%s", breakeven(ev + cg).c_str());
      std::snprintf(dis_cgal, sizeof dis_cgal, "%d", q.cgal_differs);
#else
      const char* cgal_cols = "n/a | n/a";
      const char* speedup = "n/a";
      const char* be_cgal = "n/a";
      const char* dis_cgal = "n/a";
      (void)cg;
#endif
      const std::string stop =
          q.stopped ? " (stopped at t=" + std::to_string(q.reached) + ", budget)" : "";
      out("| %s | %zu | %d / %d%s | %.2f | %.1f | %s | %.1f | %s | %.3g s | %s / %s | %s / %d "
          "(of %d) |\n",
          dataset, n, q.answered, q.measured, stop.c_str(), 1e6 * kin, 1e6 * ev, cgal_cols,
          1e6 * (ev + mo), speedup, K, be_cgal, breakeven(ev + mo).c_str(), dis_cgal,
          q.mono_differs, q.compared);
      std::fflush(stdout);
      for (const std::string& e : q.examples)
        notes.push_back(std::string(dataset) + " n=" + std::to_string(n) + ": " + e);
    }
  }
  for (const std::string& s : notes) out("  disagreement %s\n", s.c_str());
#if defined(KINETIC_BENCH_HAVE_QHULL)
  out("\n2b. qhull on the same queries (mean us per query; it copies the positions into its "
      "array)\n| dataset | n | measured | qhull + evaluate | kinetic speedup vs qhull + evaluate "
      "| size disagreements vs kinetic (of compared) |\n|---|---:|---:|---:|---:|---:|\n");
  for (const std::string& name : datasets) {
    for (const std::size_t n : sizes) {
      const auto it = query_figures.find({name, n});
      if (it == query_figures.end()) continue;
      const QueryFigures& q = it->second;
      const double kin = per(q.kinetic_cpu, static_cast<std::uint64_t>(q.answered));
      const double ev = per(q.eval_cpu, static_cast<std::uint64_t>(q.measured));
      const double qh = per(q.qhull_cpu, static_cast<std::uint64_t>(q.measured));
      out("| %s | %zu | %d | %.1f | %.1f | %d (of %d) |\n", name.c_str(), n, q.measured,
          1e6 * (ev + qh), ratio(ev + qh, kin), q.qhull_differs, q.compared);
    }
  }
#endif
  out("  (break-even rate* = kinetic CPU per unit simulated time / (recompute per query - "
      "kinetic hull() per query); the kinetic advance in this section's run is not in the "
      "table: see below)\n");
  std::vector<std::pair<std::string, std::size_t>> order;
  for (const std::string& name : datasets) {
    const char* dataset = name.c_str();
    for (const std::size_t n : sizes) {
      if (query_figures.count({dataset, n}) != 0) order.emplace_back(dataset, n);
    }
  }
  for (const auto& key : order) {
    const QueryFigures& q = query_figures[key];
    out("  %s n=%zu: advancing in the query run %.3f s CPU to t=%.4g (%.3g s per unit time)\n",
        key.first.c_str(), key.second, q.advance_cpu, q.reached,
        ratio(q.advance_cpu, q.reached - kStart));
  }

  // 3. Hull sizes.
  out("\n3. Hull size h over the queries (mean; baseline: CGAL on the rounded positions)\n");
  out("| dataset | n | h kinetic (answered) | h CGAL (measured) | h monotone chain | h kinetic / h "
      "CGAL "
      "(same queries) | "
      "root-chain candidates | h / ln n | h / n |\n");
  out("|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const auto& key : order) {
    const QueryFigures& q = query_figures[key];
    const double n = static_cast<double>(key.second);
    const double hk = q.sum_h / std::max(1, q.answered);
    const double hc = q.sum_h_cgal / std::max(1, q.measured);
    const double hm = q.sum_h_mono / std::max(1, q.measured);
#if defined(KINETIC_BENCH_HAVE_CGAL)
    char cg[32], rt[32];
    std::snprintf(cg, sizeof cg, "%.1f", hc);
    std::snprintf(rt, sizeof rt, "%.3f", ratio(q.sum_h_compared, q.sum_h_cgal_compared));
#else
    const char* cg = "n/a";
    const char* rt = "n/a";
    (void)hc;
#endif
    out("| %s | %zu | %.1f (%d) | %s | %.1f | %s | %.1f | %.2f | %.3g |\n", key.first.c_str(),
        key.second, hk, q.answered, cg, hm, rt, q.sum_candidates / std::max(1, q.answered),
        hk / std::log(n), hk / n);
  }

  // 4. The three schedulers side by side (exact beside robust and classic).
  for (const std::string& name : datasets) {
    const std::size_t n_side = std::min<std::size_t>(10000, sizes.back());
    kinetic::bench::print_scheduler_table<KineticHull>(
        "convex hull", name.c_str(), make_table(name, n_side, seed), kStart, kEnd, eps, budget);
  }
  const double wall = wall_now() - wall0, cpu = cpu_now() - cpu0;
  out("\nWhole run: %.1f s wall, %.1f s CPU (wall/CPU %.2f: above 1, other processes shared "
      "the core)\n",
      wall, cpu, wall / std::max(1e-9, cpu));
  return all_valid ? 0 : 1;
}
