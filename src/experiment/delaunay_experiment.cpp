#include "kinetic/experiment/delaunay_experiment.hpp"

#include "bookkeeping.hpp"
#include "options_check.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ostream>
#include <sstream>
#include <string_view>
#include <unordered_map>

#include "kinetic/core/crop.hpp"
#include "kinetic/core/incircle.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/delaunay/kinetic_delaunay.hpp"
#include "kinetic/run/timeline_driver.hpp"
#include "kinetic/scenario/generators.hpp"
#include "report_format.hpp"

namespace kinetic::experiment {
namespace {

using format::sci;

/// Collects the delays of a robust run's flips from the event log: a flip of four points logged
/// at the grid point g whose in-circle changed sign in (g - w, g) was delayed by g minus that
/// root, found by bisection on exact signs at doubles.
struct DelayLog {
  const MotionTable* motions = nullptr;
  double w = 0.0;
  bool robust = false;
  std::uint64_t delayed = 0, cascade = 0;
  double max = 0.0, sum_squares = 0.0;
  double seconds = 0.0;  ///< spent here (taken out of the run's cost)

  static void on_event(void* context, Time g, const char* kind, std::span<const ObjectId> ids,
                       int /*axis*/) {
    auto& self = *static_cast<DelayLog*>(context);
    if (!self.robust || std::string_view(kind) != "flip") return;
    const auto c0 = std::chrono::steady_clock::now();
    struct Timed {
      DelayLog& log;
      std::chrono::steady_clock::time_point c0;
      ~Timed() {
        log.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - c0).count();
      }
    } timed{self, c0};
    if (ids.size() != 4) {
      ++self.cascade;  // a hull flip (an orientation certificate)
      return;
    }
    const MotionTable& m = *self.motions;
    std::array<MovingPoint2, 4> p;
    for (std::size_t k = 0; k < 4; ++k) p[k] = moving_point(m, m.find(ids[k])->index);
    const InCircle f{{p[0], p[1], p[2], p[3]}};
    double lo = g - self.w, hi = g;
    const int s_lo = sign_at(f, lo), s_hi = sign_at(f, hi);
    if (s_lo == 0 || s_hi == 0 || s_lo == s_hi) {
      ++self.cascade;  // no sign change in the cell: made by the instant's cascade
      return;
    }
    for (int it = 0; it < 200; ++it) {
      const double mid = lo + 0.5 * (hi - lo);
      if (mid <= lo || mid >= hi) break;
      const int s = sign_at(f, mid);
      if (s == 0) {
        lo = hi = mid;
        break;
      }
      (s == s_lo ? lo : hi) = mid;
    }
    const double delay = g - hi;
    ++self.delayed;
    self.max = std::max(self.max, delay);
    self.sum_squares += delay * delay;
  }
};

struct SampleError {
  std::uint64_t violating = 0;
  double excess = 0.0;
};

/// The edges of the triangulation whose in-circle certificate fails at t (a triangle turned
/// clockwise counts as failing), and the largest excess over 180 degrees of the two angles
/// opposite such an edge (in double; 0 for a Delaunay edge): scale-free, where the depth of a
/// point inside a circumcircle grows without bound on thin triangles.
SampleError error_at(const MotionTable& m, KineticDelaunay& dt, Time t) {
  const auto tri = dt.triangles();
  std::unordered_map<std::uint64_t, std::uint32_t> opposite;
  opposite.reserve(3 * tri.size());
  const auto key = [](std::uint32_t u, std::uint32_t v) {
    return (static_cast<std::uint64_t>(u) << 32) | v;
  };
  for (const auto& x : tri) {
    for (int k = 0; k < 3; ++k) opposite[key(x[k], x[(k + 1) % 3])] = x[(k + 2) % 3];
  }
  const auto at = [&](std::uint32_t i) {
    return std::array<double, 2>{m.motion(i, 0).evaluate(t), m.motion(i, 1).evaluate(t)};
  };
  SampleError e;
  for (const auto& [k, w1] : opposite) {
    const std::uint32_t u = static_cast<std::uint32_t>(k >> 32), v = static_cast<std::uint32_t>(k);
    if (u > v) continue;
    const auto other = opposite.find(key(v, u));
    if (other == opposite.end()) continue;  // a hull edge
    const std::uint32_t w2 = other->second;
    if (sign_at(orientation(m, u, v, w1), t) <= 0) {
      ++e.violating;
      continue;
    }
    const InCircle f{
        {moving_point(m, u), moving_point(m, v), moving_point(m, w1), moving_point(m, w2)}};
    if (sign_at(f, t) <= 0) continue;
    ++e.violating;
    // The angles opposite the edge sum to more than 180 degrees: by how much (in double).
    const auto a = at(u), b = at(v);
    const auto angle = [&](const std::array<double, 2>& p) {
      const double ux = a[0] - p[0], uy = a[1] - p[1], vx = b[0] - p[0], vy = b[1] - p[1];
      return std::atan2(std::fabs(ux * vy - uy * vx), ux * vx + uy * vy);
    };
    const double excess = (angle(at(w1)) + angle(at(w2)) - M_PI) * 180.0 / M_PI;
    e.excess = std::max(e.excess, excess);
  }
  return e;
}

std::string label(const DelaunayRun& r) {
  return r.robust() ? "robust eps=" + format::eps(r.eps) : std::string("exact");
}

DelaunayRun run_one(const scenario::Scenario& s, SchedulerKind kind, double eps,
                    std::size_t samples) {
  DelaunayRun r;
  r.scheduler = kind;
  r.eps = kind == SchedulerKind::Robust ? eps : 0.0;
  r.grid = kind == SchedulerKind::Robust ? Scheduler::grid_width(eps) : 0.0;
  run::TimelineDriver<KineticDelaunay> driver(s, kind, eps);
  const MotionTable& motions = driver.motions();
  Simulator& sim = driver.sim();
  DelayLog log;
  log.motions = &motions;
  log.w = r.grid;
  log.robust = r.robust();
  sim.set_event_log(&DelayLog::on_event, &log);
  double v_max = 0.0;
  for (const std::uint32_t i : motions.alive_indices()) {
    v_max = std::max(v_max, std::hypot(motions.motion(i, 0).derivative(0.0),
                                       motions.motion(i, 1).derivative(0.0)));
  }
  r.displacement_bound = v_max * r.grid;
  using Clock = std::chrono::steady_clock;
  const Clock::time_point c0 = Clock::now();
  KineticDelaunay& dt = driver.structure();  // built here, timed
  double seconds = std::chrono::duration<double>(Clock::now() - c0).count();
  const Time start = s.start_time, end = *s.end_time;
  std::uint64_t wrong = 0;
  for (std::size_t k = 1; k <= samples; ++k) {
    const Time t = start + (end - start) * static_cast<double>(k) / static_cast<double>(samples);
    const Clock::time_point a = Clock::now();
    if (driver.advance_to(t) != AdvanceOutcome::Reached) break;
    seconds += std::chrono::duration<double>(Clock::now() - a).count();
    const SampleError e = error_at(motions, dt, t);
    ++r.samples;
    if (e.violating > 0) ++wrong;
    r.violating_max = std::max(r.violating_max, e.violating);
    r.excess_max = std::max(r.excess_max, e.excess);
  }
  const DelaunayCounters& c = dt.counters();
  r.flips = c.flips;
  r.repairs = c.repairs;
  r.local_repairs = c.local_repairs;
  r.builds = c.rebuilds - 1;  // the first is initialize()'s
  r.deferrals = c.deferrals;
  r.seconds = seconds - log.seconds;
  r.delayed = log.delayed;
  r.cascade = log.cascade;
  r.delay_max = log.max;
  r.delay_rms =
      log.delayed > 0 ? std::sqrt(log.sum_squares / static_cast<double>(log.delayed)) : 0.0;
  r.wrong_fraction =
      r.samples > 0 ? static_cast<double>(wrong) / static_cast<double>(r.samples) : 0.0;
  return r;
}

}  // namespace

void check_options(const DelaunayExperimentOptions& options) {
  detail::require_options("experiment delaunay", options.n, options.samples, options.eps);
  if (options.n < 3) precondition_failed("experiment delaunay", "n < 3 (at least 3 points)");
}

DelaunayExperiment run_delaunay_experiment(const DelaunayExperimentOptions& options,
                                           std::ostream* progress) {
  auto e = detail::checked_experiment<DelaunayExperiment>(options);
  scenario::GeneratorOptions g = detail::generator_options(options);
  g.dimension = 2;
  g.start_time = 0.0;
  g.end_time = options.end;
  const scenario::Scenario s = scenario::generate("random-linear", g);
  const auto one = [&](SchedulerKind kind, double eps) {
    DelaunayRun r = run_one(s, kind, eps, options.samples);
    detail::keep_run(e, r, progress, "random-linear 2-D", options.n, label(r), r.flips, "flips");
  };
  if (options.exact) one(SchedulerKind::Exact, 1e-9);
  for (const double eps : options.eps) one(SchedulerKind::Robust, eps);
  return e;
}

std::string delaunay_report_text(const DelaunayExperiment& e) {
  std::ostringstream out;
  using format::lpad;
  using format::pad;
  out << "Kinetic Delaunay triangulation on random-linear 2-D, n = " << e.options.n
      << ", window [0, " << e.options.end << "], " << e.options.samples << " samples\n";
  out << pad("run", 18) << lpad("flips", 8) << lpad("delayed", 9) << lpad("cascade", 9)
      << lpad("repairs", 9) << lpad("builds", 8) << lpad("us/flip", 9) << lpad("grid w", 10)
      << lpad("max delay", 11) << lpad("RMS delay", 11) << lpad("max/w", 7) << lpad("wrong", 8)
      << lpad("most", 6) << lpad("max excess", 11) << lpad("V_max w", 10) << "\n";
  for (const DelaunayRun& r : e.runs) {
    char wrong[32];
    std::snprintf(wrong, sizeof wrong, "%.1f %%", 100.0 * r.wrong_fraction);
    const double us = 1e6 * r.seconds / static_cast<double>(std::max<std::uint64_t>(1, r.flips));
    out << pad(label(r), 18) << lpad(std::to_string(r.flips), 8)
        << lpad(r.robust() ? std::to_string(r.delayed) : "-", 9)
        << lpad(r.robust() ? std::to_string(r.cascade) : "-", 9)
        << lpad(std::to_string(r.repairs), 9) << lpad(std::to_string(r.builds), 8)
        << lpad(format::fixed(us, 1), 9) << lpad(r.robust() ? sci(r.grid) : "-", 10)
        << lpad(r.robust() ? sci(r.delay_max) : "0", 11)
        << lpad(r.robust() ? sci(r.delay_rms) : "0", 11)
        << lpad(r.robust() ? format::fixed(r.delay_max / r.grid, 2) : "-", 7) << lpad(wrong, 8)
        << lpad(std::to_string(r.violating_max), 6) << lpad(format::fixed(r.excess_max, 3), 11)
        << lpad(r.robust() ? sci(r.displacement_bound) : "-", 10) << "\n";
  }
  return out.str();
}

std::string delaunay_runs_csv(const DelaunayExperiment& e) {
  std::ostringstream out;
  out.precision(17);
  out << "n,scheduler,eps,grid,flips,delayed,cascade,repairs,local_repairs,builds,deferrals,"
         "seconds,delay_max,delay_rms,samples,wrong_fraction,violating_max,angle_excess_max,"
         "displacement_bound\n";
  for (const DelaunayRun& r : e.runs) {
    out << e.options.n << ',' << to_string(r.scheduler) << ','
        << (r.robust() ? format::eps(r.eps) : "") << ',' << r.grid << ',' << r.flips << ','
        << r.delayed << ',' << r.cascade << ',' << r.repairs << ',' << r.local_repairs << ','
        << r.builds << ',' << r.deferrals << ',' << r.seconds << ',' << r.delay_max << ','
        << r.delay_rms << ',' << r.samples << ',' << r.wrong_fraction << ',' << r.violating_max
        << ',' << r.excess_max << ',' << r.displacement_bound << '\n';
  }
  return out.str();
}

}  // namespace kinetic::experiment
