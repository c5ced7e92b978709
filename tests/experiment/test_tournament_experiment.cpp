// The kinetic-tournament experiment (Abam, Agarwal, de Berg, Yu, Section 6, Figure 9) on a small
// RANDCR: the robust runs keep Theorem 7's bound at every sample, the error shrinks with eps, the
// classic tournament with event times rounded to 1e-5 errs more than the robust one at the same
// precision, and its careful variant (exact decisions, a change re-deciding the nodes above it
// whichever child it comes from) errs less than the traditional one; the exact scheduler's
// maximum is the true one up to rounding.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "kinetic/experiment/tournament_experiment.hpp"

namespace kinetic::experiment {
namespace {

TEST(TournamentExperiment, RobustWithinTheorem7AndBetterThanRoundedClassic) {
  TournamentExperimentOptions o;
  o.n = 4000;  // (at 2000 no event is dropped where the two classic variants differ)
  o.bins = 100;
  const TournamentExperiment e = run_tournament_experiment(o);
  ASSERT_EQ(e.runs.size(), 6u);  // classic, classic with exact decisions, 3 robust, exact
  const TournamentRun& classic = e.runs[0];
  const TournamentRun& careful = e.runs[1];
  EXPECT_FALSE(classic.robust());
  EXPECT_FALSE(classic.exact_decisions);
  EXPECT_EQ(classic.rounding, 1e-5);
  EXPECT_FALSE(careful.robust());
  EXPECT_TRUE(careful.exact_decisions);
  // The traditional propagation leaves a node wrong after a dropped event until a change comes
  // up through its winner's side; the careful one also when the change comes from the other child.
  EXPECT_GT(classic.err_rms, careful.err_rms);
  EXPECT_GT(classic.wrong_fraction, careful.wrong_fraction);
  for (std::size_t k = 2; k < 5; ++k) {
    const TournamentRun& r = e.runs[k];
    SCOPED_TRACE(r.eps);
    EXPECT_TRUE(r.robust());
    EXPECT_EQ(r.outcome, AdvanceOutcome::Reached);
    EXPECT_GT(r.events, 4000u);    // n log n order: internal events dominate
    EXPECT_GT(r.external, 1000u);  // RANDCR: about n / 2 new maxima
    EXPECT_GT(r.samples, 100000u);
    EXPECT_EQ(r.theorem7_violations, 0u);
    EXPECT_GT(r.err_max, 0.0);
    EXPECT_LE(r.err_max, r.theorem7_bound);
    ASSERT_EQ(r.envelope.size(), 100u);
    EXPECT_EQ(*std::max_element(r.envelope.begin(), r.envelope.end()), r.err_max);
    if (k > 2) {
      EXPECT_LT(r.err_max, e.runs[k - 1].err_max);  // smaller eps, smaller error
    }
  }
  // At the same precision 1e-5, the traditional rounded classic tournament errs far more.
  EXPECT_GT(classic.err_max, 10.0 * e.runs[4].err_max);
  EXPECT_GT(classic.err_rms, 10.0 * e.runs[4].err_rms);
  // The exact scheduler: the maintained maximum is the true one at every sample, up to the
  // rounding of evaluating two lines equal at a crossing (a sample at the double nearest it).
  const TournamentRun& exact = e.runs[5];
  EXPECT_EQ(exact.scheduler, SchedulerKind::Exact);
  EXPECT_EQ(exact.outcome, AdvanceOutcome::Reached);
  EXPECT_GT(exact.external, 1000u);
  EXPECT_LE(exact.err_max, 1e-14);
  EXPECT_EQ(exact.err_rms, 0.0);  // the equally spaced samples: never wrong
  EXPECT_EQ(exact.wrong_fraction, 0.0);
  EXPECT_LT(exact.err_max, e.runs[4].err_max);
  const std::string text = tournament_report_text(e);
  EXPECT_NE(text.find("classic, rounded to 1e-05"), std::string::npos);
  EXPECT_NE(text.find("classic, exact decisions, rounded to 1e-05"), std::string::npos);
  EXPECT_NE(text.find("robust eps=1e-04"), std::string::npos);
  const std::string csv = tournament_envelope_csv(e);
  EXPECT_EQ(csv.rfind("t_lo,t_hi,classic_rounded_1e-05,classic_exact_decisions_rounded_1e-05,"
                      "robust_1e-03,robust_1e-04,robust_1e-05,exact\n",
                      0),
            0u);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 101);
  EXPECT_EQ(tournament_report_text(run_tournament_experiment(o)), text);  // deterministic
}

/// Runs on two threads give the sequential runs' results, bit for bit, in the same order.
TEST(TournamentExperiment, RunsOnWorkersAreTheSequentialRuns) {
  TournamentExperimentOptions o;
  o.n = 1000;
  o.bins = 50;
  const TournamentExperiment one = run_tournament_experiment(o);
  o.workers = 2;
  const TournamentExperiment two = run_tournament_experiment(o);
  EXPECT_EQ(tournament_report_text(one), tournament_report_text(two));
  EXPECT_EQ(tournament_envelope_csv(one), tournament_envelope_csv(two));
  ASSERT_EQ(one.runs.size(), two.runs.size());
  for (std::size_t i = 0; i < one.runs.size(); ++i) {
    EXPECT_EQ(one.runs[i].events, two.runs[i].events) << i;
    EXPECT_EQ(one.runs[i].err_max, two.runs[i].err_max) << i;
    EXPECT_EQ(one.runs[i].envelope, two.runs[i].envelope) << i;
  }
}

}  // namespace
}  // namespace kinetic::experiment
