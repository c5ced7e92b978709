#include "kinetic/experiment/tournament_experiment.hpp"

#include "bookkeeping.hpp"
#include "options_check.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ostream>
#include <sstream>

#include "kinetic/core/float_roots.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/run/timeline_driver.hpp"
#include "kinetic/scenario/generators.hpp"
#include "kinetic/tournament/kinetic_tournament.hpp"
#include "report_format.hpp"

namespace kinetic::experiment {
namespace {

using format::sci;
const auto& eps_text = format::eps;

/// The classic scheduler of the paper's Figure 9: floating-point failure times rounded to a
/// multiple of `rounding`, scheduled only when after t_curr, as a traditional KDS does (a root at
/// t_curr is taken for the event just processed): a failure that rounds to t_curr or before is
/// dropped.
Time rounded_classic(void* context, const Scheduler&, const MotionPolynomial& lower,
                     const MotionPolynomial& upper, Time t_curr, Time, Counters& counters) {
  ++counters.root_isolation_calls;
  const Time t = classic_failure_time(lower, upper, t_curr);
  if (t == kTimeInfinity) return t;
  const double q = *static_cast<const double*>(context);
  const Time r = std::nearbyint(t / q) * q;
  return r <= t_curr ? kTimeInfinity : r;
}

/// The true maximum over time. For lines: their upper envelope, built once, walked forward as the
/// samples advance (amortized O(1) per sample). Otherwise: a scan of every object (O(n)).
class TrueMaximum {
 public:
  explicit TrueMaximum(const MotionTable& motions) : motions_(motions) {
    objects_ = motions.alive_indices();
    linear_ = std::all_of(objects_.begin(), objects_.end(),
                          [&](std::uint32_t i) { return motions.motion(i, 0).degree <= 1; });
    if (linear_) build_envelope();
  }

  /// The value of the maximum at t; t must not decrease between calls (lines).
  double at(Time t) {
    if (!linear_) {
      double best = -HUGE_VAL;
      for (const std::uint32_t i : objects_)
        best = std::max(best, motions_.motion(i, 0).evaluate(t));
      return best;
    }
    while (next_ + 1 < hull_.size() && breaks_[next_] <= t) ++next_;
    // Near a breakpoint the neighbours may tie or win by rounding: take the best of three.
    double best = motions_.motion(hull_[next_], 0).evaluate(t);
    if (next_ > 0) best = std::max(best, motions_.motion(hull_[next_ - 1], 0).evaluate(t));
    if (next_ + 1 < hull_.size())
      best = std::max(best, motions_.motion(hull_[next_ + 1], 0).evaluate(t));
    return best;
  }

 private:
  struct Line {
    double a, b;  // a t + b (rounded from the motion; only to find the envelope's order)
    std::uint32_t index;
  };

  void build_envelope() {
    std::vector<Line> lines;
    for (const std::uint32_t i : objects_) {
      const MotionPolynomial& p = motions_.motion(i, 0);
      const double a = p.degree >= 1 ? p.c[1] : 0.0;
      lines.push_back({a, p.c[0] - a * p.origin, i});
    }
    std::sort(lines.begin(), lines.end(),
              [](const Line& x, const Line& y) { return x.a != y.a ? x.a < y.a : x.b < y.b; });
    // Upper envelope for t from -infinity to +infinity: slopes ascending.
    std::vector<Line> hull;
    auto cross = [](const Line& x, const Line& y) { return (x.b - y.b) / (y.a - x.a); };
    for (const Line& l : lines) {
      if (!hull.empty() && hull.back().a == l.a) hull.pop_back();  // same slope: higher b wins
      while (hull.size() >= 2 &&
             cross(hull[hull.size() - 2], l) <= cross(hull[hull.size() - 2], hull.back()))
        hull.pop_back();
      hull.push_back(l);
    }
    for (std::size_t k = 0; k < hull.size(); ++k) {
      hull_.push_back(hull[k].index);
      if (k + 1 < hull.size()) breaks_.push_back(cross(hull[k], hull[k + 1]));
    }
  }

  const MotionTable& motions_;
  std::vector<std::uint32_t> objects_;
  bool linear_ = false;
  std::vector<std::uint32_t> hull_;  // envelope lines, left to right
  std::vector<double> breaks_;       // breaks_[k]: where hull_[k + 1] takes over
  std::size_t next_ = 0;
};

std::string label(const TournamentRun& r) {
  if (r.robust()) return "robust eps=" + eps_text(r.eps);
  if (r.scheduler == SchedulerKind::Exact) return "exact";
  return std::string(r.exact_decisions ? "classic, exact decisions" : "classic") + ", rounded to " +
         eps_text(r.rounding);
}

/// The run's column in the envelope CSV.
std::string column(const TournamentRun& r) {
  if (r.robust()) return "robust_" + eps_text(r.eps);
  if (r.scheduler == SchedulerKind::Exact) return "exact";
  return std::string(r.exact_decisions ? "classic_exact_decisions" : "classic") + "_rounded_" +
         eps_text(r.rounding);
}

std::string pad(const std::string& s, std::size_t width, bool left = true) {
  return left ? format::pad(s, width) : format::lpad(s, width);
}

}  // namespace

TournamentRun run_tournament(const scenario::Scenario& s, const std::string& dataset,
                             SchedulerKind scheduler, double eps, double rounding, std::size_t bins,
                             bool exact_decisions) {
  const auto wall_start = std::chrono::steady_clock::now();
  TournamentRun r = detail::line_run<TournamentRun>(s, dataset, scheduler, eps, "tournament");
  r.rounding = scheduler == SchedulerKind::Classic ? rounding : 0.0;
  r.exact_decisions = scheduler == SchedulerKind::Classic && exact_decisions;

  run::TimelineDriver<KineticTournament> driver(
      s, scheduler, eps, build_with([&](MotionTable& m, Simulator& sm, Scheduler& sched) {
        if (scheduler == SchedulerKind::Classic && rounding > 0.0)
          sched.set_failure_time_model(&rounded_classic, &rounding);
        sched.set_classic_exact_decisions(r.exact_decisions);
        return std::make_unique<KineticTournament>(m, sm, sched, 0, Extreme::Max);
      }));
  const MotionTable& motions = driver.motions();
  Simulator& sim = driver.sim();
  // Lines: each pair crosses at most once (no changes).
  driver.session().set_guard(crossing_guard(1, r.n, 0, 1));
  const KineticTournament& tournament = driver.structure();

  double v_max = 0.0;
  for (const std::uint32_t i : motions.alive_indices()) {
    const MotionPolynomial& p = motions.motion(i, 0);
    v_max = std::max({v_max, std::fabs(p.derivative(r.start)), std::fabs(p.derivative(r.end))});
  }
  const double log_n = std::ceil(std::log2(std::max(2.0, static_cast<double>(r.n))));
  r.theorem7_bound = (log_n + 1.0) * eps * v_max;

  TrueMaximum truth(motions);
  bins = std::max<std::size_t>(1, bins);
  r.envelope.assign(bins, 0.0);
  const double span = r.end - r.start;
  // Samples at every processing time (just before and just after its events) and at
  // kUniformPerBin equally spaced times per bin. Between two samples the maintained maximum is
  // one fixed motion and the true maximum the upper envelope (convex for lines), so err = z - y
  // is convex there: the largest sample in a bin is err's maximum over the bin. The RMS over
  // time and the fraction of time with err > 0 are estimated from the equally spaced samples
  // only (unbiased), as the paper sampled at fixed steps.
  constexpr std::size_t kUniformPerBin = 1000;
  const std::size_t uniform = bins * kUniformPerBin;
  double sum_squares = 0.0;
  std::uint64_t uniform_wrong = 0;
  auto sample = [&](Time t, bool is_uniform) {
    const double z = truth.at(t);
    const double y = motions.motion(*tournament.top(), 0).evaluate(t);
    const double err = std::max(0.0, z - y);
    ++r.samples;
    if (r.robust() && err > r.theorem7_bound * (1.0 + 1e-12) + 1e-12) ++r.theorem7_violations;
    r.err_max = std::max(r.err_max, err);
    const double x = (t - r.start) / span * static_cast<double>(bins);
    const std::size_t b = std::min(bins - 1, static_cast<std::size_t>(std::max(0.0, x)));
    r.envelope[b] = std::max(r.envelope[b], err);
    if (b > 0 && x == static_cast<double>(b)) r.envelope[b - 1] = std::max(r.envelope[b - 1], err);
    if (is_uniform) {
      sum_squares += err * err;
      if (err > 0.0) ++uniform_wrong;
    }
  };
  std::size_t next_uniform = 0;
  auto uniform_until = [&](Time t) {
    while (next_uniform <= uniform) {
      const Time u = next_uniform == uniform ? r.end
                                             : r.start + span * static_cast<double>(next_uniform) /
                                                             static_cast<double>(uniform);
      if (!(u < t)) return;
      sample(u, true);
      ++next_uniform;
    }
  };
  while (sim.event_due_by(r.end)) {
    const Time tb = std::max(sim.queue().top().time, sim.now());
    uniform_until(tb);
    sample(tb, false);
    // Exact: tb is a double at or below the exact time; when that time is no double, its events
    // are processed by advancing to the double above it, where the next sample is taken.
    const Time to = sim.queue().exact_order()
                        ? std::min(r.end, std::max(tb, sim.next_exact_time().upper()))
                        : tb;
    uniform_until(to);
    r.outcome = driver.advance_to(to);
    if (r.outcome != AdvanceOutcome::Reached) break;
    sample(to, false);
  }
  if (r.outcome == AdvanceOutcome::Reached) r.outcome = driver.advance_to(r.end);
  uniform_until(kTimeInfinity);
  r.events = sim.counters().events();
  r.external = sim.counters().events_external;
  r.err_rms = std::sqrt(sum_squares / static_cast<double>(uniform + 1));
  r.wrong_fraction = static_cast<double>(uniform_wrong) / static_cast<double>(uniform + 1);
  r.seconds = detail::seconds_since(wall_start);
  return r;
}

void check_options(const TournamentExperimentOptions& options) {
  detail::require_options("experiment tournament", options.n, options.bins, options.eps);
}

TournamentExperiment run_tournament_experiment(const TournamentExperimentOptions& options,
                                               std::ostream* progress) {
  auto e = detail::checked_experiment<TournamentExperiment>(options);
  const scenario::Scenario s =
      scenario::generate(options.dataset, detail::generator_options(options));
  struct Job {
    SchedulerKind kind;
    double eps;
    bool exact_decisions;
  };
  std::vector<Job> jobs{{SchedulerKind::Classic, 0.0, false},  // a traditional KDS
                        {SchedulerKind::Classic, 0.0, true}};  // its careful variant
  for (const double eps : options.eps) jobs.push_back({SchedulerKind::Robust, eps, false});
  if (options.exact) jobs.push_back({SchedulerKind::Exact, 0.0, false});
  std::vector<TournamentRun> runs = detail::run_jobs<TournamentRun>(
      jobs.size(), options.workers,
      [&](std::size_t i) {
        return run_tournament(s, options.dataset, jobs[i].kind, jobs[i].eps,
                              options.classic_rounding, options.bins, jobs[i].exact_decisions);
      },
      [&](const TournamentRun& r) {
        detail::report_run(progress, r.dataset, r.n, label(r), r.events, "events", r.seconds);
      });
  for (TournamentRun& r : runs) e.runs.push_back(std::move(r));
  return e;
}

std::string tournament_report_text(const TournamentExperiment& e) {
  std::ostringstream out;
  out << "Kinetic tournament (maximum) on " << e.options.dataset << ", n = " << e.options.n
      << ": err(t) = z(t) - y(t) over the window\n";
  out << pad("run", 44) << pad("events", 9, false) << pad("external", 10, false)
      << pad("max err", 11, false) << pad("RMS err", 11, false) << pad("time wrong", 12, false)
      << pad("classic/this (max, RMS)", 26, false) << pad("Thm 7 bound", 13, false)
      << pad("viol.", 7, false) << "\n";
  const TournamentRun* classic = nullptr;
  for (const TournamentRun& r : e.runs)
    if (!r.robust() && !r.exact_decisions && classic == nullptr) classic = &r;
  for (const TournamentRun& r : e.runs) {
    std::string ratio = "-";
    if (classic && &r != classic) {
      auto q = [](double a, double b) { return b > 0.0 ? sci(a / b) : std::string("inf"); };
      ratio = q(classic->err_max, r.err_max) + ", " + q(classic->err_rms, r.err_rms);
    }
    char wrong[32];
    std::snprintf(wrong, sizeof wrong, "%.2f %%", 100.0 * r.wrong_fraction);
    out << pad(label(r), 44) << pad(std::to_string(r.events), 9, false)
        << pad(std::to_string(r.external), 10, false) << pad(sci(r.err_max), 11, false)
        << pad(sci(r.err_rms), 11, false) << pad(wrong, 12, false) << pad(ratio, 26, false)
        << pad(r.robust() ? sci(r.theorem7_bound) : "-", 13, false)
        << pad(r.robust() ? std::to_string(r.theorem7_violations) : "-", 7, false) << "\n";
  }
  return out.str();
}

std::string tournament_runs_csv(const TournamentExperiment& e) {
  std::ostringstream out;
  out.precision(17);
  out << "dataset,n,scheduler,exact_decisions,eps,rounding,events,external,looped,err_max,err_rms,"
         "wrong_fraction,theorem7_bound,samples,theorem7_violations,seconds\n";
  for (const TournamentRun& r : e.runs) {
    out << r.dataset << ',' << r.n << ',' << to_string(r.scheduler) << ','
        << (r.exact_decisions ? 1 : 0) << ',' << (r.robust() ? eps_text(r.eps) : "") << ','
        << (r.scheduler == SchedulerKind::Classic ? eps_text(r.rounding) : "") << ',' << r.events
        << ',' << r.external << ',' << (r.outcome == AdvanceOutcome::Reached ? 0 : 1) << ','
        << r.err_max << ',' << r.err_rms << ',' << r.wrong_fraction << ',' << r.theorem7_bound
        << ',' << r.samples << ',' << r.theorem7_violations << ',' << r.seconds << '\n';
  }
  return out.str();
}

std::string tournament_envelope_csv(const TournamentExperiment& e) {
  std::ostringstream out;
  out.precision(17);
  out << "t_lo,t_hi";
  for (const TournamentRun& r : e.runs) out << ',' << column(r);
  out << '\n';
  if (e.runs.empty()) return out.str();
  const TournamentRun& f = e.runs.front();
  const std::size_t bins = f.envelope.size();
  const double span = f.end - f.start;
  for (std::size_t b = 0; b < bins; ++b) {
    out << f.start + span * static_cast<double>(b) / static_cast<double>(bins) << ','
        << (b + 1 == bins
                ? f.end
                : f.start + span * static_cast<double>(b + 1) / static_cast<double>(bins));
    for (const TournamentRun& r : e.runs) out << ',' << r.envelope[b];
    out << '\n';
  }
  return out.str();
}

}  // namespace kinetic::experiment
