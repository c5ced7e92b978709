#pragma once
// The kinetic-tournament experiment of Abam, Agarwal, de Berg, Yu, Section 6 (Figure 9): on RANDCR,
// the classic tournament with its event times rounded to 1e-5 (a traditional KDS: floating-point
// decisions, Scheduler::compute_max; and its careful variant with exact decisions) against the
// robust one at eps = 1e-3, 1e-4, 1e-5, and the exact scheduler; the geometric error err(t) =
// z(t) - y(t) (z the true maximum, y the maintained one) over the window, and Theorem 7's bound
// checked on the robust runs. `kinetic experiment tournament` runs it; docs/experiments.md shows
// the results.

#include <cstdint>
#include <string>
#include <vector>

#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/scenario/scenario.hpp"

namespace kinetic::experiment {

struct TournamentExperimentOptions {
  std::string dataset = "randcr";
  std::size_t n = 10000;  ///< the paper's size
  std::vector<double> eps = {1e-3, 1e-4, 1e-5};
  /// The classic run's event times are rounded to a multiple of this (the paper: 1e-5) and
  /// scheduled only when after t_curr, as in a traditional KDS: a failure that rounds to t_curr
  /// or before is dropped.
  double classic_rounding = 1e-5;
  std::uint64_t seed = 1;
  std::size_t bins = 2000;  ///< err is reported as its maximum over each part of the window
  bool exact = true;        ///< also run the exact scheduler (exact event times and decisions)
  /// Runs done at once, each on its own thread (1: one after the other). The results are the
  /// same whatever the number (each run is deterministic); its run times are the machine's.
  unsigned workers = 1;
};

struct TournamentRun {
  std::string dataset;
  std::size_t n = 0;
  SchedulerKind scheduler = SchedulerKind::Robust;
  double eps = 0.0;       ///< robust
  double rounding = 0.0;  ///< classic
  /// Classic: the careful variant (Scheduler::set_classic_exact_decisions), not the traditional
  /// one.
  bool exact_decisions = false;
  Time start = 0.0, end = 0.0;
  std::uint64_t events = 0, external = 0;
  AdvanceOutcome outcome = AdvanceOutcome::Reached;
  double seconds = 0.0;
  /// err over the window: its maximum (exact, from samples at every change), its RMS over time
  /// and the fraction of the time with err > 0 (both from 1000 equally spaced samples per bin).
  double err_max = 0.0, err_rms = 0.0;
  double wrong_fraction = 0.0;
  /// Robust: Theorem 7's bound (ceil(log n) + 1) eps V_max and the samples that exceed it.
  double theorem7_bound = 0.0;
  std::uint64_t samples = 0, theorem7_violations = 0;
  std::vector<double> envelope;  ///< max err per bin

  [[nodiscard]] bool robust() const { return scheduler == SchedulerKind::Robust; }
};

struct TournamentExperiment {
  TournamentExperimentOptions options;
  std::vector<TournamentRun> runs;
};

/// One run (max tournament on axis 0 of a 1-D scenario of lines or other motions).
[[nodiscard]] TournamentRun run_tournament(const scenario::Scenario& s, const std::string& dataset,
                                           SchedulerKind scheduler, double eps, double rounding,
                                           std::size_t bins, bool exact_decisions = false);

/// Throws PreconditionError unless n >= 2, bins >= 1 and every eps is a robust precision.
void check_options(const TournamentExperimentOptions& options);

/// The experiment (its options checked first: check_options).
[[nodiscard]] TournamentExperiment run_tournament_experiment(
    const TournamentExperimentOptions& options, std::ostream* progress = nullptr);

[[nodiscard]] std::string tournament_report_text(const TournamentExperiment& e);
[[nodiscard]] std::string tournament_runs_csv(const TournamentExperiment& e);
[[nodiscard]] std::string tournament_envelope_csv(const TournamentExperiment& e);

}  // namespace kinetic::experiment
