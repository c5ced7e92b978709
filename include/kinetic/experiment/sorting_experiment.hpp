#pragma once
// The kinetic-sorting experiments of Abam, Agarwal, de Berg, Yu, Section 6 (Table 1, Figures 6-8):
// robust kinetic sorting at several precisions eps beside the classic scheduler, on GRIDS, PARABOLA
// and RANDDC. For every run: the event delays t_pr - t_ex (Table 1), the geometric error err(t) =
// max_i |y_i(t) - z_i(t)| over the whole window (Figures 6-8), what the classic scheduler missed,
// and the robust bounds of Theorems 1 and 2 checked on the run. docs/experiments.md describes the
// method and the results; `kinetic experiment sorting` runs it.

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/scenario/scenario.hpp"

namespace kinetic::experiment {

struct SortingExperimentOptions {
  std::vector<std::string> datasets = {"grids", "parabola", "randdc"};
  std::size_t n = 900;  ///< the paper's size
  std::vector<double> eps = {1e-6, 1e-7, 1e-8};
  bool classic = true;  ///< also run the classic scheduler
  bool exact = true;    ///< also run the exact scheduler (exact event times and order)
  /// Positions of grids and parabola scaled into [-1, 1] (scenario::unit_scale), as RANDDC's
  /// unit disk; false keeps the integer coordinates, where all arithmetic is exact.
  bool unit_scale = true;
  std::uint64_t seed = 1;
  /// The error err(t) is computed exactly at every time where the maintained or the true order
  /// changes (O(n) each), and reported as its maximum over each of `bins` equal parts of the
  /// window. With `envelope` false (large n) it is sampled at the bin edges only.
  bool envelope = true;
  std::size_t bins = 2000;
  /// Runs done at once, each on its own thread (1: one after the other). The results are the
  /// same whatever the number (each run is deterministic); its run times are the machine's.
  unsigned workers = 1;
  /// Tests: a model of root-finding errors given to the robust scheduler
  /// (Scheduler::set_failure_time_model), e.g. to check that the theorem checks can fail.
  Scheduler::FailureTimeModel failure_time_model = nullptr;
  void* failure_time_context = nullptr;
};

/// One run: one dataset, one scheduler (and eps for the robust one).
struct SortingRun {
  std::string dataset;
  std::size_t n = 0;
  SchedulerKind scheduler = SchedulerKind::Robust;
  double eps = 0.0;  ///< robust only
  Time start = 0.0, end = 0.0;
  double scale = 1.0;

  /// Oracle: sign changes of x_i - x_j over all pairs in [start, end] (floating-point roots).
  std::uint64_t crossings = 0;
  std::uint64_t events = 0;          ///< events processed
  std::uint64_t events_in_past = 0;  ///< robust: events processed after t_curr had passed them
  /// Exact: groups of two events or more at one exact time (simultaneous crossings).
  std::uint64_t equal_time_groups = 0;
  AdvanceOutcome outcome = AdvanceOutcome::Reached;  ///< LoopGuard / EventBudget: it looped
  double seconds = 0.0;                              ///< wall time of the whole run

  /// Robust: every event's delay t_pr - t_ex (t_ex by exact-sign bisection to w * 2^-24).
  std::uint64_t delays_measured = 0;
  double delay_rms = 0.0, delay_max = 0.0;

  double err_max = 0.0;    ///< max over the window of err(t)
  double err_final = 0.0;  ///< err(end)
  /// Pairs in the wrong relative order at the end (exact comparisons); the samples taken (change
  /// times and bin edges) and those with err > 0 in floating point (which includes rounding
  /// noise of order 1e-15 between equal values, so it is no exact measure of wrong orders).
  std::uint64_t final_inversions = 0;
  std::uint64_t samples = 0, samples_err_positive = 0;

  /// Robust: Theorem 1 through Lemma 2: every adjacent pair out of order at a sampled time t
  /// must be in order at t - eps (it crossed in (t - eps, t)). Pairs checked, and violations.
  std::uint64_t theorem1_checked = 0, theorem1_violations = 0;
  /// Robust: Theorem 2, every delay <= n s eps (s: crossings per pair at most, the degree).
  double theorem2_bound = 0.0;

  /// max err(t) over each bin of the window (bins equal parts of [start, end]).
  std::vector<double> envelope;

  [[nodiscard]] bool robust() const { return scheduler == SchedulerKind::Robust; }
  [[nodiscard]] bool looped() const { return outcome != AdvanceOutcome::Reached; }
  /// Classic: crossings that were never processed (0 when more events than crossings ran).
  [[nodiscard]] std::uint64_t missed() const { return crossings > events ? crossings - events : 0; }
  [[nodiscard]] bool theorem2_holds() const { return delay_max <= theorem2_bound; }
};

struct SortingExperiment {
  SortingExperimentOptions options;
  std::vector<SortingRun> runs;
};

/// One run on a scenario (1-D points). `dataset` only labels it.
[[nodiscard]] SortingRun run_sorting(const scenario::Scenario& s, const std::string& dataset,
                                     SchedulerKind scheduler, double eps,
                                     const SortingExperimentOptions& options);

/// Throws PreconditionError unless n >= 2, bins >= 1 and every eps is a robust precision.
void check_options(const SortingExperimentOptions& options);

/// Every dataset x (classic, eps...) of the options (checked first: check_options). Progress lines
/// go to `progress` if given.
[[nodiscard]] SortingExperiment run_sorting_experiment(const SortingExperimentOptions& options,
                                                       std::ostream* progress = nullptr);

/// The paper's Table 1 entry (RMS, max delay in units of eps) for n = 900, if it has one.
struct PaperDelay {
  double rms = 0.0, max = 0.0;
};
[[nodiscard]] std::optional<PaperDelay> paper_table1(const std::string& dataset, double eps);

/// Table 1 (ours beside the paper's), the classic scheduler's summary, and the robust runs'
/// theorem checks, as plain text.
[[nodiscard]] std::string report_text(const SortingExperiment& e);
/// CSV files: Table 1; one line per run; the error envelope of one dataset (one column per run).
/// The runs' wall times per dataset and scheduler, with their ratio to the finest robust run
/// (not part of report_text(), which is deterministic).
[[nodiscard]] std::string times_text(const SortingExperiment& e);
[[nodiscard]] std::string table1_csv(const SortingExperiment& e);
[[nodiscard]] std::string runs_csv(const SortingExperiment& e);
[[nodiscard]] std::string envelope_csv(const SortingExperiment& e, const std::string& dataset);

}  // namespace kinetic::experiment
