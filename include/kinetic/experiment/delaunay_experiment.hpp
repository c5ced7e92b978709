#pragma once
// The robust kinetic Delaunay triangulation in the style of the sorting experiment of Abam,
// Agarwal, de Berg, Yu (Section 6, Table 1): on random points moving on lines (random-linear,
// 2-D), the exact scheduler against the robust one at several eps, with
//  - the delay of the flips: for a flip processed at the grid point g whose in-circle changed
//    sign within the cell before g, g minus that root (found by bisection on exact signs), its
//    maximum and RMS against the grid width w;
//  - the geometric error at equally spaced sample times t: the edges whose in-circle fails at t
//    (the triangulation is exactly Delaunay at the grid point before t, not at t) and the
//    largest excess over 180 degrees of the two angles opposite such an edge (scale-free; the
//    points are within V_max w of where they stood at that grid point);
//  - the repairs of folds, the builds, the cost per flip.
// `kinetic experiment delaunay` runs it; docs/experiments.md shows the results.

#include <cstdint>
#include <string>
#include <vector>

#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/time.hpp"

namespace kinetic::experiment {

struct DelaunayExperimentOptions {
  std::size_t n = 1000;
  std::vector<double> eps = {1e-1, 1e-2, 1e-3, 1e-4, 1e-6, 1e-9};
  Time end = 2.0;  ///< the window [0, end] of random-linear
  std::uint64_t seed = 1;
  std::size_t samples = 200;  ///< equally spaced sample times for the geometric error
  bool exact = true;          ///< also run the exact scheduler (the reference: no delay, no error)
};

struct DelaunayRun {
  SchedulerKind scheduler = SchedulerKind::Robust;
  double eps = 0.0;   ///< robust
  double grid = 0.0;  ///< robust: the grid width w
  std::uint64_t flips = 0, repairs = 0, local_repairs = 0, builds = 0, deferrals = 0;
  double seconds = 0.0;  ///< CPU of the run (events and samples' advances, not the samples)
  /// Flips whose in-circle changed sign in the cell before their processing time, and the
  /// others (made by the cascade of the same instant, or hull flips).
  std::uint64_t delayed = 0, cascade = 0;
  double delay_max = 0.0, delay_rms = 0.0;
  /// Over the samples: the most edges failing at once, the fraction of samples with one, the
  /// largest angle excess (degrees), and V_max w.
  std::uint64_t samples = 0, violating_max = 0;
  double wrong_fraction = 0.0, excess_max = 0.0, displacement_bound = 0.0;

  [[nodiscard]] bool robust() const { return scheduler == SchedulerKind::Robust; }
};

struct DelaunayExperiment {
  DelaunayExperimentOptions options;
  std::vector<DelaunayRun> runs;
};

/// Throws PreconditionError unless n >= 3, samples >= 1 and every eps is a robust precision.
void check_options(const DelaunayExperimentOptions& options);

/// The experiment (its options checked first).
[[nodiscard]] DelaunayExperiment run_delaunay_experiment(const DelaunayExperimentOptions& options,
                                                         std::ostream* progress = nullptr);

[[nodiscard]] std::string delaunay_report_text(const DelaunayExperiment& e);
[[nodiscard]] std::string delaunay_runs_csv(const DelaunayExperiment& e);

}  // namespace kinetic::experiment
