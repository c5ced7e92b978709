#include "kinetic/experiment/sorting_experiment.hpp"

#include "bookkeeping.hpp"
#include "error_meter.hpp"
#include "options_check.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <ostream>
#include <span>
#include <sstream>
#include <vector>

#include "kinetic/core/float_roots.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/predicates.hpp"
#include "kinetic/run/timeline_driver.hpp"
#include "kinetic/scenario/generators.hpp"
#include "kinetic/sort/kinetic_sort.hpp"
#include "report_format.hpp"

namespace kinetic::experiment {
namespace {

using format::fixed;
using format::lpad;
using format::pad;
using format::sci;
const auto& format_eps = format::eps;

/// Times at which x_i - x_j changes sign in [lo, hi], over all pairs (floating-point roots: these
/// are sampling times and a count, not decisions), sorted; only counted when `times` is null.
std::uint64_t crossing_times(const MotionTable& motions, Time lo, Time hi,
                             std::vector<Time>* times) {
  std::uint64_t count = 0;
  const std::vector<std::uint32_t> idx = motions.alive_indices();
  std::array<double, kMaxMotionDegree + 1> d{};
  std::array<FloatRoot, kMaxMotionDegree> roots{};
  for (std::size_t a = 0; a < idx.size(); ++a) {
    const MotionPolynomial& pa = motions.motion(idx[a], 0);
    for (std::size_t b = a + 1; b < idx.size(); ++b) {
      const MotionPolynomial& pb = motions.motion(idx[b], 0);
      const int degree = float_difference(pa, pb, d);
      if (degree == 0) continue;
      const int m = float_sign_change_roots(d, degree, lo - pb.origin, hi - pb.origin, roots);
      for (int k = 0; k < m; ++k) {
        const Time t = pb.origin + roots[static_cast<std::size_t>(k)].at;
        if (t >= lo && t <= hi) {
          ++count;
          if (times) times->push_back(t);
        }
      }
    }
  }
  if (times) std::sort(times->begin(), times->end());
  return count;
}

/// Pairs in the wrong relative order at t (exact comparisons), by merge sort.
std::uint64_t inversions_at(const MotionTable& motions, std::span<const std::uint32_t> order,
                            Time t) {
  std::vector<std::uint32_t> a(order.begin(), order.end()), tmp(a.size());
  std::uint64_t count = 0;
  for (std::size_t width = 1; width < a.size(); width *= 2) {
    for (std::size_t lo = 0; lo < a.size(); lo += 2 * width) {
      const std::size_t mid = std::min(lo + width, a.size()),
                        hi = std::min(lo + 2 * width, a.size());
      std::size_t i = lo, j = mid, k = lo;
      while (i < mid && j < hi) {
        if (compare_at(motions.motion(a[i], 0), motions.motion(a[j], 0), t) > 0) {
          count += mid - i;  // a[j] precedes everything left in the left half
          tmp[k++] = a[j++];
        } else {
          tmp[k++] = a[i++];
        }
      }
      while (i < mid) tmp[k++] = a[i++];
      while (j < hi) tmp[k++] = a[j++];
    }
    a.swap(tmp);
  }
  return count;
}

std::string run_label(const SortingRun& r) {
  return r.robust() ? "robust eps=" + format_eps(r.eps) : std::string(to_string(r.scheduler));
}

}  // namespace

SortingRun run_sorting(const scenario::Scenario& s, const std::string& dataset,
                       SchedulerKind scheduler, double eps,
                       const SortingExperimentOptions& options) {
  const auto wall_start = std::chrono::steady_clock::now();
  SortingRun r = detail::line_run<SortingRun>(s, dataset, scheduler, eps, "sorting");

  run::TimelineDriver<KineticSort> driver(
      s, scheduler, eps, build_with([&](MotionTable& m, Simulator& sm, Scheduler& sched) {
        if (options.failure_time_model != nullptr)
          sched.set_failure_time_model(options.failure_time_model, options.failure_time_context);
        return std::make_unique<KineticSort>(m, sm, sched, 0);
      }));
  const MotionTable& motions = driver.motions();
  Simulator& sim = driver.sim();
  driver.session().structure_as_is().set_measure_delays(scheduler == SchedulerKind::Robust);
  // A correct run has at most n(n-1)/2 swaps at one instant and s n(n-1)/2 in all (no changes).
  driver.session().set_guard(crossing_guard(1, r.n, 0, motions.max_degree()));
  const KineticSort& sort = driver.structure();

  std::vector<Time> crossings;  // sampling times: only for the exact envelope
  r.crossings = crossing_times(motions, r.start, r.end, options.envelope ? &crossings : nullptr);
  detail::ErrorMeter meter(motions);
  const std::size_t bins = std::max<std::size_t>(1, options.bins);
  r.envelope.assign(bins, 0.0);
  const double span = r.end - r.start;
  auto edge = [&](std::size_t b) {
    return b == bins ? r.end : r.start + span * static_cast<double>(b) / static_cast<double>(bins);
  };
  auto bin_of = [&](Time t) {
    const double x = (t - r.start) / span * static_cast<double>(bins);
    return std::min(bins - 1, static_cast<std::size_t>(std::max(0.0, x)));
  };

  // check_theorem1: at processing times and bin edges (at a crossing time the crossing pair is
  // exactly tied, and deciding that costs an exact evaluation for nothing).
  auto sample = [&](Time t, bool is_edge, std::size_t edge_index, bool check_theorem1) {
    const double err = meter.error(sort.order(), t);
    ++r.samples;
    if (err > 0.0) ++r.samples_err_positive;
    r.err_max = std::max(r.err_max, err);
    if (is_edge) {  // a bin edge belongs to the bins on both sides
      if (edge_index > 0) r.envelope[edge_index - 1] = std::max(r.envelope[edge_index - 1], err);
      if (edge_index < bins) r.envelope[edge_index] = std::max(r.envelope[edge_index], err);
    } else {
      double& e = r.envelope[bin_of(t)];
      e = std::max(e, err);
    }
    if (scheduler != SchedulerKind::Robust || !check_theorem1) return;
    // Lemma 2 / Theorem 1: an adjacent pair out of order at t crossed in (t - eps, t).
    const auto order = sort.order();
    for (const std::size_t k : meter.not_below()) {  // the other pairs are certainly in order
      const MotionPolynomial& a = motions.motion(order[k], 0);
      const MotionPolynomial& b = motions.motion(order[k + 1], 0);
      if (compare_at(a, b, t) <= 0) continue;
      ++r.theorem1_checked;
      if (compare_at(a, b, t - eps) > 0) ++r.theorem1_violations;
    }
  };

  // Sampling times: every crossing, every bin edge, and each processing time just before and
  // just after its events. Between two consecutive ones neither order changes, and err is the
  // maximum of |x_a - x_b| over fixed pairs: for the linear differences of these datasets a
  // convex function, largest at the ends. So the samples give err's exact maximum per bin.
  std::size_t next_crossing = 0, next_edge = 0;
  auto sample_until = [&](Time t, bool inclusive) {  // crossings and bin edges before t
    for (;;) {
      const Time tc = next_crossing < crossings.size() ? crossings[next_crossing] : kTimeInfinity;
      const Time te = next_edge <= bins ? edge(next_edge) : kTimeInfinity;
      const Time tn = std::min(tc, te);
      if (!(tn < t || (inclusive && tn == t))) return;
      if (te <= tc) {
        sample(te, true, next_edge, true);
        ++next_edge;
      } else {
        // A crossing time from floating-point roots can lie an ulp before the clock (the
        // structure's state is now's): sample it at now.
        sample(std::max(tc, sim.now()), false, 0, false);
        ++next_crossing;
      }
    }
  };

  while (sim.event_due_by(r.end)) {
    const Time tb = std::max(sim.queue().top().time, sim.now());
    // Bin edges (and, with the envelope, crossings) before tb; under the exact scheduler at tb
    // too when the next event's exact time lies above it (not a double).
    const bool above_tb = sim.queue().exact_order() &&
                          sim.next_exact_time().lower() < sim.next_exact_time().upper();
    sample_until(tb, above_tb);
    if (options.envelope) sample(tb, false, 0, true);
    // Exact: tb is a double at or below the exact time; the events come at the double above it.
    const Time to = sim.queue().exact_order()
                        ? std::min(r.end, std::max(tb, sim.next_exact_time().upper()))
                        : tb;
    r.outcome = driver.advance_to(to);
    if (r.outcome != AdvanceOutcome::Reached) break;
    if (options.envelope) sample(to, false, 0, true);
  }
  if (r.outcome == AdvanceOutcome::Reached) r.outcome = driver.advance_to(r.end);
  sample_until(r.end, true);
  r.err_final = meter.error(sort.order(), r.end);
  r.final_inversions = inversions_at(motions, sort.order(), r.end);

  const Counters& c = sim.counters();
  r.events = c.events();
  r.events_in_past = c.events_in_past;
  r.equal_time_groups = c.equal_time_groups;
  r.delays_measured = c.delays_measured;
  r.delay_max = c.delay_max;
  r.delay_rms = c.delays_measured
                    ? std::sqrt(c.delay_sum_squares / static_cast<double>(c.delays_measured))
                    : 0.0;
  r.theorem2_bound = static_cast<double>(r.n) * std::max(1, motions.max_degree()) * eps;
  r.seconds = detail::seconds_since(wall_start);
  return r;
}

void check_options(const SortingExperimentOptions& options) {
  detail::require_options("experiment sorting", options.n, options.bins, options.eps);
}

SortingExperiment run_sorting_experiment(const SortingExperimentOptions& options,
                                         std::ostream* progress) {
  auto e = detail::checked_experiment<SortingExperiment>(options);
  struct Job {
    std::size_t dataset;
    SchedulerKind kind;
    double eps;
  };
  std::vector<scenario::Scenario> scenarios;
  std::vector<double> scales;
  std::vector<Job> jobs;
  for (const std::string& dataset : options.datasets) {
    scenario::GeneratorOptions g = detail::generator_options(options);
    g.scale = options.unit_scale ? scenario::unit_scale(dataset, options.n) : 1.0;
    scenarios.push_back(scenario::generate(dataset, g));
    scales.push_back(g.scale);
    const std::size_t d = scenarios.size() - 1;
    if (options.classic) jobs.push_back({d, SchedulerKind::Classic, 0.0});
    for (const double eps : options.eps) jobs.push_back({d, SchedulerKind::Robust, eps});
    if (options.exact) jobs.push_back({d, SchedulerKind::Exact, 0.0});
  }
  std::vector<SortingRun> runs = detail::run_jobs<SortingRun>(
      jobs.size(), options.workers,
      [&](std::size_t i) {
        const Job& j = jobs[i];
        SortingRun r =
            run_sorting(scenarios[j.dataset], options.datasets[j.dataset], j.kind, j.eps, options);
        r.scale = scales[j.dataset];
        return r;
      },
      [&](const SortingRun& r) {
        detail::report_run(progress, r.dataset, r.n, run_label(r), r.events, "events", r.seconds);
      });
  for (SortingRun& r : runs) e.runs.push_back(std::move(r));
  return e;
}

std::optional<PaperDelay> paper_table1(const std::string& dataset, double eps) {
  // Abam, Agarwal, de Berg, Yu, Table 1 ("Delay of events in kinetic sorting", n = 900).
  struct Row {
    double eps;
    PaperDelay grids, parabola, randdc;
  };
  static const std::array<Row, 3> rows = {{
      {1e-6, {0.48, 2.00}, {0.37, 1.00}, {0.42, 1.00}},
      {1e-7, {0.43, 1.00}, {0.37, 1.00}, {0.42, 1.00}},
      {1e-8, {0.42, 1.00}, {0.39, 1.00}, {0.41, 1.00}},
  }};
  for (const Row& row : rows) {
    if (row.eps != eps) continue;
    if (dataset == "grids") return row.grids;
    if (dataset == "parabola") return row.parabola;
    if (dataset == "randdc") return row.randdc;
  }
  return std::nullopt;
}

namespace {

std::string upper(std::string s) {
  for (char& ch : s) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  return s;
}

const SortingRun* find_run(const SortingExperiment& e, const std::string& dataset,
                           SchedulerKind kind, double eps) {
  for (const SortingRun& r : e.runs) {
    if (r.dataset == dataset && r.scheduler == kind &&
        (kind != SchedulerKind::Robust || r.eps == eps))
      return &r;
  }
  return nullptr;
}

}  // namespace

std::string report_text(const SortingExperiment& e) {
  std::ostringstream out;
  const auto& o = e.options;
  out << "Table 1. Delay of events in robust kinetic sorting, n = " << o.n
      << " (t_pr - t_ex in units of eps; the paper's value in brackets)\n";
  out << pad("eps", 8);
  for (const std::string& d : o.datasets)
    out << " | " << pad(upper(d) + " RMS", 14) << pad("Max", 14);
  out << "\n";
  for (const double eps : o.eps) {
    out << pad(format_eps(eps), 8);
    for (const std::string& d : o.datasets) {
      const SortingRun* r = find_run(e, d, SchedulerKind::Robust, eps);
      const auto paper = o.n == 900 ? paper_table1(d, eps) : std::nullopt;
      std::string rms = r ? fixed(r->delay_rms / eps, 2) : "-";
      std::string mx = r ? fixed(r->delay_max / eps, 2) : "-";
      if (paper) {
        rms += " [" + fixed(paper->rms, 2) + "]";
        mx += " [" + fixed(paper->max, 2) + "]";
      }
      out << " | " << pad(rms, 14) << pad(mx, 14);
    }
    out << "\n";
  }

  out << "\nRobust runs: error and the bounds of Theorems 1 and 2\n";
  out << pad("dataset", 10) << pad("eps", 7) << lpad("events", 9) << lpad("in past", 9)
      << lpad("max err", 11) << lpad("final err", 11) << lpad("Thm 1 (viol./pairs)", 21)
      << lpad("Thm 2 (max delay <= n s eps)", 30) << "\n";
  for (const SortingRun& r : e.runs) {
    if (!r.robust()) continue;
    out << pad(r.dataset, 10) << pad(format_eps(r.eps), 7) << lpad(std::to_string(r.events), 9)
        << lpad(std::to_string(r.events_in_past), 9) << lpad(sci(r.err_max), 11)
        << lpad(sci(r.err_final), 11)
        << lpad(std::to_string(r.theorem1_violations) + "/" + std::to_string(r.theorem1_checked),
                21)
        << lpad(sci(r.delay_max) + (r.theorem2_holds() ? " <= " : " > ") + sci(r.theorem2_bound) +
                    (r.theorem2_holds() ? " ok" : " FAIL"),
                30)
        << "\n";
  }

  if (o.classic) {
    out << "\nClassic scheduler (floating-point failure times), n = " << o.n << "\n";
    out << pad("dataset", 10) << lpad("crossings", 11) << lpad("events", 9) << lpad("missed", 9)
        << lpad("looped", 8) << lpad("max err", 11) << lpad("final err", 11)
        << lpad("final inversions", 18) << "\n";
    for (const SortingRun& r : e.runs) {
      if (r.scheduler != SchedulerKind::Classic) continue;
      out << pad(r.dataset, 10) << lpad(std::to_string(r.crossings), 11)
          << lpad(std::to_string(r.events), 9) << lpad(std::to_string(r.missed()), 9)
          << lpad(r.looped() ? "yes" : "no", 8) << lpad(sci(r.err_max), 11)
          << lpad(sci(r.err_final), 11) << lpad(std::to_string(r.final_inversions), 18) << "\n";
    }
  }
  out << "\nThe three schedulers side by side, n = " << o.n
      << " (max err: over the window, 0 when the order is exactly sorted)\n";
  out << pad("dataset", 10) << pad("scheduler", 20) << lpad("events", 9) << lpad("in past", 9)
      << lpad("equal-time groups", 19) << lpad("max err", 11) << lpad("final inversions", 18)
      << "\n";
  for (const std::string& d : o.datasets) {
    for (const SortingRun& r : e.runs) {
      if (r.dataset != d) continue;
      const bool exact = r.scheduler == SchedulerKind::Exact;
      out << pad(r.dataset, 10) << pad(run_label(r), 20) << lpad(std::to_string(r.events), 9)
          << lpad(std::to_string(r.events_in_past), 9)
          << lpad(exact ? std::to_string(r.equal_time_groups) : "-", 19)
          << lpad(r.err_max == 0.0 ? "0" : sci(r.err_max), 11)
          << lpad(std::to_string(r.final_inversions), 18) << "\n";
    }
  }
  // No trailing blanks (the report is quoted in docs/experiments.md).
  std::string text = out.str(), trimmed;
  std::size_t from = 0;
  while (from < text.size()) {
    std::size_t to = text.find('\n', from);
    if (to == std::string::npos) to = text.size();
    std::size_t last = to;
    while (last > from && text[last - 1] == ' ') --last;
    trimmed.append(text, from, last - from);
    if (to < text.size()) trimmed += '\n';
    from = to + 1;
  }
  return trimmed;
}

std::string times_text(const SortingExperiment& e) {
  std::ostringstream out;
  out << "Run times on this machine, n = " << e.options.n
      << " (seconds, the whole run with its error sampling; ratio to the finest robust run)\n";
  out << pad("dataset", 10);
  for (const SortingRun& r : e.runs) {
    if (r.dataset == e.runs.front().dataset) out << lpad(run_label(r), 20);
  }
  out << "\n";
  for (const std::string& d : e.options.datasets) {
    out << pad(d, 10);
    const SortingRun* finest = nullptr;
    for (const SortingRun& r : e.runs)
      if (r.dataset == d && r.robust() && (finest == nullptr || r.eps < finest->eps)) finest = &r;
    for (const SortingRun& r : e.runs) {
      if (r.dataset != d) continue;
      std::string cell = fixed(r.seconds, 2);
      if (finest != nullptr && finest->seconds > 0)
        cell += " (" + fixed(r.seconds / finest->seconds, 2) + "x)";
      out << lpad(cell, 20);
    }
    out << "\n";
  }
  return out.str();
}

std::string table1_csv(const SortingExperiment& e) {
  std::ostringstream out;
  out << "dataset,n,eps,delays_measured,rms_in_eps,max_in_eps,paper_rms_in_eps,paper_max_in_eps\n";
  for (const SortingRun& r : e.runs) {
    if (!r.robust()) continue;
    const auto paper = r.n == 900 ? paper_table1(r.dataset, r.eps) : std::nullopt;
    out << r.dataset << ',' << r.n << ',' << format_eps(r.eps) << ',' << r.delays_measured << ','
        << fixed(r.delay_rms / r.eps, 4) << ',' << fixed(r.delay_max / r.eps, 4) << ','
        << (paper ? fixed(paper->rms, 2) : "") << ',' << (paper ? fixed(paper->max, 2) : "")
        << '\n';
  }
  return out.str();
}

std::string runs_csv(const SortingExperiment& e) {
  std::ostringstream out;
  out << "dataset,n,scale,scheduler,eps,start,end,crossings,events,events_in_past,missed,looped,"
         "delay_rms,delay_max,err_max,err_final,final_inversions,samples,samples_err_positive,"
         "theorem1_checked,theorem1_violations,theorem2_bound,seconds\n";
  out.precision(17);
  for (const SortingRun& r : e.runs) {
    out << r.dataset << ',' << r.n << ',' << r.scale << ',' << to_string(r.scheduler) << ','
        << (r.robust() ? format_eps(r.eps) : "") << ',' << r.start << ',' << r.end << ','
        << r.crossings << ',' << r.events << ',' << r.events_in_past << ',' << r.missed() << ','
        << (r.looped() ? 1 : 0) << ',' << r.delay_rms << ',' << r.delay_max << ',' << r.err_max
        << ',' << r.err_final << ',' << r.final_inversions << ',' << r.samples << ','
        << r.samples_err_positive << ',' << r.theorem1_checked << ',' << r.theorem1_violations
        << ',' << r.theorem2_bound << ',' << fixed(r.seconds, 3) << '\n';
  }
  return out.str();
}

std::string envelope_csv(const SortingExperiment& e, const std::string& dataset) {
  std::vector<const SortingRun*> runs;
  for (const SortingRun& r : e.runs)
    if (r.dataset == dataset) runs.push_back(&r);
  std::ostringstream out;
  out.precision(17);
  out << "t_lo,t_hi";
  for (const SortingRun* r : runs)
    out << ',' << (r->robust() ? "robust_" + format_eps(r->eps) : to_string(r->scheduler));
  out << '\n';
  if (runs.empty()) return out.str();
  const std::size_t bins = runs.front()->envelope.size();
  const double start = runs.front()->start, span = runs.front()->end - start;
  for (std::size_t b = 0; b < bins; ++b) {
    out << start + span * static_cast<double>(b) / static_cast<double>(bins) << ','
        << (b + 1 == bins ? runs.front()->end
                          : start + span * static_cast<double>(b + 1) / static_cast<double>(bins));
    for (const SortingRun* r : runs) out << ',' << r->envelope[b];
    out << '\n';
  }
  return out.str();
}

}  // namespace kinetic::experiment
