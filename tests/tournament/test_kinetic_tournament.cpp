// Kinetic tournaments, classic and robust (Abam, Agarwal, de Berg, Yu, Section 4): the maintained
// maximum/minimum against the brute-force oracle at random times, validate() after every event,
// Lemma 4 (every new event time in the future), Lemma 5 and Theorem 7 (geometric error) on robust
// runs, degenerate inputs (equal values, identical motions, simultaneous crossings), inserts,
// removes and updates.
#include <gtest/gtest.h>

#include <array>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "kinetic/core/predicates.hpp"
#include "kinetic/scenario/generators.hpp"
#include "kinetic/tournament/kinetic_tournament.hpp"
#include "support/driver.hpp"

namespace kinetic {
namespace {

using test::cross_within;
using test::polynomials;

/// A max and a min tournament on axis 0 over a scenario (a StructureGroup, as the runner's
/// `extent` on one axis), with its timeline applied through the driver.
struct TournamentHarness : test::Harness<StructureGroup<KineticTournament>> {
  TournamentHarness(const scenario::Scenario& s, SchedulerKind kind, double eps)
      : Harness(s, kind, eps, [](MotionTable& m, Simulator& sm, Scheduler& sc) {
          auto group = std::make_unique<StructureGroup<KineticTournament>>();
          group->add(std::make_unique<KineticTournament>(m, sm, sc, 0, Extreme::Max));
          group->add(std::make_unique<KineticTournament>(m, sm, sc, 0, Extreme::Min));
          return group;
        }) {}
  KineticTournament* max = &(*structure)[0];
  KineticTournament* min = &(*structure)[1];
};

/// The maintained extreme is right at t, or the true extreme and the maintained one cross within
/// [t - delta, t + delta].
::testing::AssertionResult top_ok_at(const TournamentHarness& h, const KineticTournament& k, Time t,
                                     double delta) {
  const TournamentAudit a = k.audit(t);
  if (a.ok) return ::testing::AssertionSuccess();
  const MotionPolynomial& m = h.motions.motion(a.maintained, 0);
  const MotionPolynomial& x = h.motions.motion(a.true_extreme, 0);
  if (cross_within(m, x, t - delta, t + delta)) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << (k.extreme() == Extreme::Max ? "max" : "min") << " at t=" << t << ": maintained id "
         << h.motions.id(a.maintained) << ", true id " << h.motions.id(a.true_extreme)
         << ", no crossing within " << delta;
}

/// Largest |velocity| of any motion over [lo, hi] (degree <= 2: at the ends).
double v_max(const MotionTable& motions, Time lo, Time hi) {
  double v = 0.0;
  for (const std::uint32_t i : motions.alive_indices()) {
    const MotionPolynomial& p = motions.motion(i, 0);
    v = std::max({v, std::fabs(p.derivative(lo)), std::fabs(p.derivative(hi))});
  }
  return v;
}

struct RunFigures {
  std::uint64_t events = 0;
  std::uint64_t checks = 0;
};

/// Runs the whole scenario one event at a time: validate() after each event, the oracle at random
/// query times, and for robust runs Lemma 4, Lemma 5 and Theorem 7 after every event.
RunFigures check_run(const scenario::Scenario& s, SchedulerKind kind, double eps,
                     std::uint64_t seed, bool check_theorem7) {
  SCOPED_TRACE("seed " + std::to_string(seed) + ", " + to_string(kind) + ", eps " +
               std::to_string(eps));
  TournamentHarness h(s, kind, eps);
  EXPECT_TRUE(h.max->validate());
  EXPECT_TRUE(h.min->validate());
  const Time end = *s.end_time;
  std::mt19937_64 rng(seed);
  const std::vector<Time> probes = test::probe_times(s.start_time, end, 40, rng);
  RunFigures r;
  const double log_n =
      std::ceil(std::log2(std::max<double>(2.0, static_cast<double>(h.motions.size()))));
  const double delta = kind == SchedulerKind::Robust ? eps : 1e-7;
  auto after_event = [&] {
    if (kind != SchedulerKind::Robust) return;
    const Time t = h.sim.now();
    EXPECT_EQ(h.max->lemma5_violations(t, eps), 0u) << "Lemma 5, t=" << t;
    EXPECT_EQ(h.min->lemma5_violations(t, eps), 0u) << "Lemma 5, t=" << t;
    if (!check_theorem7) return;
    // Theorem 7: x(t) >= y(t) - (ceil(log n) + 1) eps V_max.
    const double bound = (log_n + 1.0) * eps * v_max(h.motions, t - eps, t);
    for (const KineticTournament* k : {h.max, h.min}) {
      const TournamentAudit a = k->audit(t);
      const double x = value_at(h.motions.motion(a.maintained, 0), t);
      const double y = value_at(h.motions.motion(a.true_extreme, 0), t);
      const double err = k->extreme() == Extreme::Max ? y - x : x - y;
      EXPECT_LE(err, bound + 1e-12 * (1.0 + std::fabs(y))) << "Theorem 7 at t=" << t;
      ++r.checks;
    }
  };
  r.events = h.check(
      probes, true,
      [&](Time probe) {
        EXPECT_TRUE(top_ok_at(h, *h.max, probe, delta));
        EXPECT_TRUE(top_ok_at(h, *h.min, probe, delta));
        ++r.checks;
      },
      after_event);
  EXPECT_EQ(h.sim.now(), end);
  EXPECT_TRUE(top_ok_at(h, *h.max, end, delta));
  EXPECT_TRUE(top_ok_at(h, *h.min, end, delta));
  if (kind == SchedulerKind::Robust) {
    EXPECT_EQ(h.max->counters().scheduled_not_in_future, 0u) << "Lemma 4";
    EXPECT_EQ(h.min->counters().scheduled_not_in_future, 0u) << "Lemma 4";
    EXPECT_EQ(h.sim.counters().events_in_past, 0u);
  }
  // Compact and local: n - 1 certificates, at most one per level per point.
  const std::size_t n = h.motions.size();
  EXPECT_EQ(h.max->certificates(), n > 0 ? n - 1 : 0);
  EXPECT_LE(h.max->certificates_per_object_max(), static_cast<std::size_t>(h.max->height()));
  return r;
}

scenario::Scenario make(const std::string& dataset, std::size_t n, std::uint64_t seed, int degree,
                        bool changes) {
  scenario::GeneratorOptions o;
  o.n = n;
  o.seed = seed;
  o.degree = degree;
  if (changes) {
    o.updates = n / 4;
    o.inserts = n / 4;
    o.removes = n / 5;
  }
  return scenario::generate(dataset, o);
}

TEST(KineticTournament, RandomMotionsAgainstTheOracle) {
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    const int degree = static_cast<int>(seed % 3) + 1;  // linear, quadratic, cubic
    const bool changes = seed % 2 == 0;
    const scenario::Scenario s =
        make(degree == 1 ? "random-linear" : "random-poly", 200, seed, degree, changes);
    for (const SchedulerKind kind :
         {SchedulerKind::Classic, SchedulerKind::Robust, SchedulerKind::Exact}) {
      const RunFigures r = check_run(s, kind, 1e-9, seed, degree <= 2);
      EXPECT_GT(r.events, 10u);
    }
  }
}

TEST(KineticTournament, DegenerateInputs) {
  // GRIDS on integers (many equal values, crossings shared by many pairs at one time), PARABOLA,
  // RANDCR (many external events), each with a coarse eps so that crossings share CROP cells.
  for (const std::string name : {"grids", "parabola", "randcr", "randdc"}) {
    SCOPED_TRACE(name);
    for (const bool changes : {false, true}) {
      const scenario::Scenario s = make(name, 49, 7, 2, changes);
      for (const double eps : {1e-3, 1e-9}) {
        (void)check_run(s, SchedulerKind::Robust, eps, 11, true);
      }
      (void)check_run(s, SchedulerKind::Classic, 1e-9, 11, false);
    }
  }
}

TEST(KineticTournament, IdenticalMotionsAndTinySets) {
  scenario::Scenario s;
  s.start_time = 0.0;
  s.end_time = 10.0;
  for (int i = 0; i < 9; ++i) s.objects.push_back({i, {{{1.0, -0.5, 0.125}}, 2.0}});
  s.objects.push_back({9, {{{0.0, 1.0}}, 0.0}});  // crosses all nine at once, twice
  for (const SchedulerKind kind :
       {SchedulerKind::Classic, SchedulerKind::Robust, SchedulerKind::Exact}) {
    TournamentHarness h(s, kind, 1e-6);
    ASSERT_EQ(h.sim.advance_to(10.0, h), AdvanceOutcome::Reached);
    EXPECT_TRUE(h.max->validate());
    EXPECT_TRUE(h.max->audit(10.0).ok);
    EXPECT_TRUE(h.min->audit(10.0).ok);
    EXPECT_LE(h.sim.counters().events(), 40u);  // no loop over the identical motions
  }
  // Empty and single-point tournaments, grown by inserts and emptied by removes.
  scenario::Scenario empty;
  empty.end_time = 1.0;
  TournamentHarness h(empty, SchedulerKind::Robust, 1e-9);
  EXPECT_FALSE(h.max->top());
  EXPECT_TRUE(h.max->validate());
  const MotionPolynomial p = MotionPolynomial::constant(3.0);
  for (int i = 0; i < 5; ++i) {
    h.session().insert(i, {MotionPolynomial::constant(static_cast<double>(i))});  // both told
    EXPECT_TRUE(h.max->validate());
    EXPECT_EQ(h.motions.id(*h.max->top()), i);
    EXPECT_EQ(h.motions.id(*h.min->top()), 0);
  }
  EXPECT_EQ(h.max->counters().rebuilds, 3u);  // capacity 1 -> 2 -> 4 -> 8
  for (int i = 4; i >= 0; --i) {
    h.session().remove(i);
    EXPECT_TRUE(h.max->validate());
    if (i > 0) {
      EXPECT_EQ(h.motions.id(*h.max->top()), i - 1);
    }
  }
  EXPECT_FALSE(h.max->top());
  (void)p;
}

/// A scripted late robust scheduler (EVENTTIME + 3 eps): Lemma 5's check must catch it, so the
/// check is not vacuous.
Time late(void*, const Scheduler& s, const MotionPolynomial& lower, const MotionPolynomial& upper,
          Time t_curr, Time window_lo, Counters& c) {
  const Time t = event_time(s.crop_certificate(upper, lower, t_curr, window_lo, c), t_curr);
  return t == kTimeInfinity ? t : t + 3.0 * s.eps();
}

TEST(KineticTournament, Lemma5CheckDetectsALateScheduler) {
  const scenario::Scenario s = make("randcr", 64, 3, 1, false);
  TournamentHarness h(s, SchedulerKind::Robust, 1e-3);
  h.scheduler.set_failure_time_model(&late, nullptr);
  h.max->initialize();
  h.min->initialize();
  std::size_t violations = 0;
  while (h.sim.event_due_by(*s.end_time)) {
    ASSERT_EQ(h.sim.process_next(h), AdvanceOutcome::Reached);
    // Just before the next event, the late certificates are wrong for up to 3 eps.
    if (!h.sim.queue().empty()) {
      const Time next = h.sim.queue().top().time;
      violations += h.max->lemma5_violations(next, 1e-3);
    }
  }
  EXPECT_GT(violations, 0u);
}

TEST(KineticTournament, ClassicDecidesInFloatingPointAsATraditionalKds) {
  // Two lines that cross 6e-18 before t = 1.3: just after 1.3, y is ahead (exactly), but their
  // floating-point values at 1.3 put x ahead. The classic scheduler decides as a traditional
  // KDS does, from the floating-point values; its exact-decisions variant and the exact scheduler
  // follow the true order. (The robust scheduler pretends the order before the crossing's CROP
  // interval until that interval ends, by design: x here, then an event within eps.)
  const MotionPolynomial x = MotionPolynomial::from({2.7578711760429035, -2.8060372436779373});
  const MotionPolynomial y = MotionPolynomial::from({1.2439683266570858, -1.6414965903042313});
  const Time t = 1.3;
  ASSERT_GT(x.evaluate(t), y.evaluate(t));  // floating point: x
  ASSERT_LT(compare_after(x, y, t), 0);     // exactly: y
  Counters counters;
  Scheduler classic(SchedulerKind::Classic, 1e-9);
  EXPECT_TRUE(classic.compute_max(x, y, t, 0.0, counters).first_wins);
  Scheduler careful(SchedulerKind::Classic, 1e-9);
  careful.set_classic_exact_decisions(true);
  EXPECT_FALSE(careful.compute_max(x, y, t, 0.0, counters).first_wins);

  // The same in a tournament built at t = 1.3: the classic maximum is x, the careful classic's
  // and the exact scheduler's y.
  scenario::Scenario s;
  s.start_time = t;
  s.end_time = 2.0;
  s.objects.push_back({0, {{{2.7578711760429035, -2.8060372436779373}}, 0.0}});
  s.objects.push_back({1, {{{1.2439683266570858, -1.6414965903042313}}, 0.0}});
  for (const SchedulerKind kind : {SchedulerKind::Classic, SchedulerKind::Exact}) {
    for (const bool exact_decisions : {false, true}) {
      if (kind != SchedulerKind::Classic && exact_decisions) continue;
      SCOPED_TRACE(std::string(to_string(kind)) + (exact_decisions ? ", exact decisions" : ""));
      TournamentHarness h(s, kind, 1e-9);
      h.scheduler.set_classic_exact_decisions(exact_decisions);
      h.max->initialize();
      ASSERT_TRUE(h.max->top().has_value());
      const bool traditional = kind == SchedulerKind::Classic && !exact_decisions;
      EXPECT_EQ(h.motions.id(*h.max->top()), traditional ? 0 : 1);
    }
  }
}

/// Classic failure times, except that the certificate [lower < upper] of one given pair is never
/// scheduled (a root dropped as "in the past", as rounding does in Figure 9).
Time dropping(void* context, const Scheduler&, const MotionPolynomial& lower,
              const MotionPolynomial& upper, Time t_curr, Time, Counters&) {
  const auto* pair = static_cast<const std::array<MotionPolynomial, 2>*>(context);
  if (lower == (*pair)[0] && upper == (*pair)[1]) return kTimeInfinity;
  return classic_failure_time(lower, upper, t_curr);
}

TEST(KineticTournament, ClassicPropagatesAsATraditionalKds) {
  // Leaves a = 10 - t, b = 0 | c = 5, d = t - 2. The root's event (a falls below c at t = 5) is
  // dropped, so the root keeps a. At t = 7, d passes c below the root: c was not the root's
  // winner, so a traditional KDS trusts a to stay ahead of d and only re-certifies the root
  // (still wrong: d = 7.5 > a = 2.5 at t = 7.5); the careful variant re-decides the root exactly
  // and takes d.
  scenario::Scenario s;
  s.start_time = 0.0;
  s.end_time = 8.0;
  s.objects.push_back({0, {{{10.0, -1.0}}, 0.0}});
  s.objects.push_back({1, {{{0.0}}, 0.0}});
  s.objects.push_back({2, {{{5.0}}, 0.0}});
  s.objects.push_back({3, {{{-2.0, 1.0}}, 0.0}});
  std::array<MotionPolynomial, 2> dropped{MotionPolynomial::from({5.0}),
                                          MotionPolynomial::from({10.0, -1.0})};  // [c < a]
  for (const bool exact_decisions : {false, true}) {
    SCOPED_TRACE(exact_decisions ? "exact decisions" : "traditional");
    TournamentHarness h(s, SchedulerKind::Classic, 1e-9);
    h.scheduler.set_classic_exact_decisions(exact_decisions);
    h.scheduler.set_failure_time_model(&dropping, &dropped);
    h.max->initialize();
    ASSERT_EQ(h.motions.id(*h.max->top()), 0);
    ASSERT_EQ(h.sim.advance_to(6.0, h), AdvanceOutcome::Reached);
    EXPECT_EQ(h.motions.id(*h.max->top()), 0);  // wrong (c = 5 > a = 4): the event was dropped
    ASSERT_EQ(h.sim.advance_to(7.5, h), AdvanceOutcome::Reached);
    EXPECT_EQ(h.motions.id(*h.max->top()), exact_decisions ? 3 : 0);
    EXPECT_TRUE(h.max->validate());
  }
}

}  // namespace
}  // namespace kinetic
