// The kinetic-sorting experiment (Abam, Agarwal, de Berg, Yu, Section 6): its measurements checked
// on small inputs against what must hold (every crossing processed, delays below one grid cell,
// Theorems 1 and 2), the classic scheduler's failure on the scaled degenerate inputs, and checks
// that can fail (a scripted late scheduler violates Theorem 1).
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "kinetic/core/crop.hpp"
#include "kinetic/experiment/sorting_experiment.hpp"
#include "kinetic/scenario/generators.hpp"

namespace kinetic::experiment {
namespace {

scenario::Scenario dataset(const std::string& name, std::size_t n, bool unit = true) {
  scenario::GeneratorOptions g;
  g.n = n;
  g.seed = 3;
  g.scale = unit ? scenario::unit_scale(name, n) : 1.0;
  return scenario::generate(name, g);
}

TEST(SortingExperiment, RobustRunsProcessEveryCrossingWithinTheBounds) {
  SortingExperimentOptions o;
  o.bins = 200;
  for (const std::string name : {"grids", "parabola", "randdc"}) {
    for (const double eps : {1e-6, 1e-8}) {
      SCOPED_TRACE(name + " eps " + std::to_string(eps));
      const SortingRun r = run_sorting(dataset(name, 100), name, SchedulerKind::Robust, eps, o);
      EXPECT_EQ(r.outcome, AdvanceOutcome::Reached);
      EXPECT_GT(r.crossings, 1000u);
      EXPECT_EQ(r.events, r.crossings);  // each pair crosses once: one swap per crossing
      EXPECT_EQ(r.delays_measured, r.events);
      EXPECT_GT(r.delay_max, 0.0);
      EXPECT_LT(r.delay_max, Scheduler::grid_width(eps));  // the right end of the cell
      EXPECT_LE(r.delay_rms, r.delay_max);
      EXPECT_GT(r.theorem1_checked, 0u);
      EXPECT_EQ(r.theorem1_violations, 0u);
      EXPECT_TRUE(r.theorem2_holds());
      EXPECT_EQ(r.final_inversions, 0u);
      EXPECT_EQ(r.err_final, 0.0);
      // The envelope: its maximum is the run's, and the errors are those of a delay below eps.
      ASSERT_EQ(r.envelope.size(), 200u);
      EXPECT_EQ(*std::max_element(r.envelope.begin(), r.envelope.end()), r.err_max);
      EXPECT_GT(r.err_max, 0.0);
    }
  }
}

TEST(SortingExperiment, ClassicFailsOnScaledDegenerateInputsButNotOnIntegerOnes) {
  SortingExperimentOptions o;
  o.bins = 50;
  for (const std::string name : {"grids", "parabola"}) {
    SCOPED_TRACE(name);
    const SortingRun scaled = run_sorting(dataset(name, 100), name, SchedulerKind::Classic, 0, o);
    EXPECT_GT(scaled.missed(), 0u);
    EXPECT_GT(scaled.final_inversions, 0u);
    EXPECT_GT(scaled.err_final, 0.0);
    // Integer coordinates: every computation is exact and the classic scheduler gets it right.
    const SortingRun exact =
        run_sorting(dataset(name, 100, false), name, SchedulerKind::Classic, 0, o);
    EXPECT_EQ(exact.missed(), 0u);
    EXPECT_EQ(exact.final_inversions, 0u);
  }
}

/// EVENTTIME delayed by 3 eps: a pair stays out of order for longer than Theorem 1 allows.
Time late_by_three_eps(void*, const Scheduler& s, const MotionPolynomial& lower,
                       const MotionPolynomial& upper, Time t_curr, Time window_lo, Counters& c) {
  const Time t = event_time(s.crop_certificate(upper, lower, t_curr, window_lo, c), t_curr);
  return t == kTimeInfinity ? t : t + 3.0 * s.eps();
}

TEST(SortingExperiment, TheoremChecksDetectALateScheduler) {
  SortingExperimentOptions o;
  o.bins = 100;
  o.failure_time_model = &late_by_three_eps;
  const SortingRun r = run_sorting(dataset("randdc", 60), "randdc", SchedulerKind::Robust, 1e-6, o);
  EXPECT_GT(r.theorem1_violations, 0u);
  EXPECT_EQ(r.final_inversions, 0u);  // late, but every swap still happens
}

TEST(SortingExperiment, WithoutTheEnvelopeTheBinEdgesAreSampledInTime) {
  // Large-n mode: err only at the bin edges, each taken when the run reaches it.
  SortingExperimentOptions o;
  o.bins = 50;
  o.envelope = false;
  for (const std::string name : {"grids", "randdc"}) {
    const SortingRun r = run_sorting(dataset(name, 100), name, SchedulerKind::Robust, 1e-6, o);
    EXPECT_EQ(r.samples, 51u) << name;
    EXPECT_EQ(r.theorem1_violations, 0u) << name;
    EXPECT_LT(r.err_max, 1e-4) << name;  // a delay below eps times speeds of order 1
    EXPECT_GT(r.crossings, 1000u);
    EXPECT_EQ(r.events, r.crossings);
  }
}

TEST(SortingExperiment, PaperTable1) {
  ASSERT_TRUE(paper_table1("grids", 1e-6));
  EXPECT_EQ(paper_table1("grids", 1e-6)->rms, 0.48);
  EXPECT_EQ(paper_table1("grids", 1e-6)->max, 2.00);
  EXPECT_EQ(paper_table1("parabola", 1e-8)->rms, 0.39);
  EXPECT_EQ(paper_table1("randdc", 1e-7)->rms, 0.42);
  EXPECT_FALSE(paper_table1("randdc", 1e-9));
  EXPECT_FALSE(paper_table1("randcr", 1e-6));
}

TEST(SortingExperiment, ReportAndCsvFormats) {
  SortingExperimentOptions o;
  o.n = 64;
  o.bins = 10;
  o.eps = {1e-6, 1e-7};
  const SortingExperiment e = run_sorting_experiment(o);
  ASSERT_EQ(e.runs.size(), 12u);  // 3 datasets x (classic + 2 eps + exact)
  const std::string text = report_text(e);
  EXPECT_NE(text.find("Table 1. Delay of events in robust kinetic sorting, n = 64"),
            std::string::npos);
  EXPECT_NE(text.find("GRIDS RMS"), std::string::npos);
  EXPECT_NE(text.find("Classic scheduler"), std::string::npos);
  EXPECT_EQ(text.find("[0.48]"), std::string::npos);  // the paper's values are for n = 900 only
  const std::string t1 = table1_csv(e);
  EXPECT_EQ(std::count(t1.begin(), t1.end(), '\n'), 1 + 6);
  EXPECT_EQ(t1.rfind("dataset,n,eps,delays_measured,rms_in_eps,max_in_eps,", 0), 0u);
  const std::string runs = runs_csv(e);
  EXPECT_EQ(std::count(runs.begin(), runs.end(), '\n'), 1 + 12);
  const std::string env = envelope_csv(e, "grids");
  EXPECT_EQ(env.rfind("t_lo,t_hi,classic,robust_1e-06,robust_1e-07,exact\n", 0), 0u);
  // The exact scheduler: every crossing, zero error at every sample, equal times grouped.
  for (const SortingRun& r : e.runs) {
    if (r.scheduler != SchedulerKind::Exact) continue;
    EXPECT_EQ(r.err_max, 0.0) << r.dataset;
    EXPECT_EQ(r.final_inversions, 0u) << r.dataset;
    EXPECT_EQ(r.events_in_past, 0u) << r.dataset;
    EXPECT_EQ(r.events, r.crossings) << r.dataset;
    if (r.dataset != "randdc") {
      EXPECT_GT(r.equal_time_groups, 0u) << r.dataset;
    }
  }
  EXPECT_NE(text.find("The three schedulers side by side"), std::string::npos);
  EXPECT_NE(times_text(e).find("exact"), std::string::npos);
  EXPECT_EQ(std::count(env.begin(), env.end(), '\n'), 1 + 10);
  // Deterministic: the same options give the same report, bit for bit.
  EXPECT_EQ(report_text(run_sorting_experiment(o)), text);
}

/// The runs without their wall times (the last column of runs_csv: the one field that depends on
/// the machine and on what else runs).
std::string without_seconds(const std::string& csv) {
  std::string out;
  std::size_t at = 0;
  while (at < csv.size()) {
    const std::size_t end = csv.find('\n', at);
    const std::string line = csv.substr(at, end - at);
    out += line.substr(0, line.rfind(',')) + "\n";
    at = end == std::string::npos ? csv.size() : end + 1;
  }
  return out;
}

/// Runs on two threads give the sequential runs' results, bit for bit, in the same order: the
/// report, Table 1, every envelope and every run's figures but its wall time.
TEST(SortingExperiment, RunsOnWorkersAreTheSequentialRuns) {
  SortingExperimentOptions o;
  o.n = 64;
  o.bins = 10;
  o.eps = {1e-6, 1e-7};
  const SortingExperiment one = run_sorting_experiment(o);
  o.workers = 2;
  const SortingExperiment two = run_sorting_experiment(o);
  const std::string header = runs_csv(one).substr(0, runs_csv(one).find('\n'));
  ASSERT_TRUE(header.ends_with(",seconds")) << header;
  EXPECT_EQ(report_text(one), report_text(two));
  EXPECT_EQ(table1_csv(one), table1_csv(two));
  EXPECT_EQ(without_seconds(runs_csv(one)), without_seconds(runs_csv(two)));
  for (const std::string& d : o.datasets)
    EXPECT_EQ(envelope_csv(one, d), envelope_csv(two, d)) << d;
  o.workers = 16;  // more workers than runs
  EXPECT_EQ(report_text(run_sorting_experiment(o)), report_text(one));
}

}  // namespace
}  // namespace kinetic::experiment
