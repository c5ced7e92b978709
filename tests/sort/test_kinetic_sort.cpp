// Kinetic sorting against the brute-force oracle: random linear and quadratic motions, flight-plan
// updates, inserts and removes, and degenerate inputs (identical motions, many points crossing at
// one instant, the paper's GRIDS and PARABOLA inputs). Fixed seeds, printed on failure.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <span>
#include <tuple>
#include <vector>

#include "kinetic/oracle/oracle.hpp"
#include "kinetic/scenario/generators.hpp"
#include "support/driver.hpp"

namespace kinetic {
namespace {

using scenario::GeneratorOptions;
using test::SortHarness;

constexpr double kDelta = 1e-6;  // query times within this of a crossing are exempt

/// Runs the scenario's timeline; at `checks` random times (and at every query op) the maintained
/// order must be the true one except for pairs crossing within kDelta.
void check_against_oracle(const scenario::Scenario& s, std::uint64_t seed, int checks,
                          bool validate, SortLayout layout = SortLayout::Dense) {
  SCOPED_TRACE("seed " + std::to_string(seed) +
               (layout == SortLayout::Gapped ? ", gapped layout" : ", dense layout"));
  SortHarness h(s, SchedulerKind::Classic, 1e-9, layout);
  std::mt19937_64 rng(seed * 7919 + 17);
  const Time end = *s.end_time;
  const std::vector<Time> times = test::random_times_in_window(s, rng, checks);
  std::size_t next_time = 0;
  auto check_until = [&](Time limit) {
    while (next_time < times.size() && times[next_time] < limit) {
      const Time t = times[next_time++];
      ASSERT_EQ(h.advance_to(t, validate), AdvanceOutcome::Reached);
      ASSERT_TRUE(h.order_ok_at(t, kDelta));
    }
  };
  for (const scenario::TimelineOp& op : s.timeline) {
    check_until(op.time);
    ASSERT_EQ(h.advance_to(op.time, validate), AdvanceOutcome::Reached);
    if (op.op == scenario::OpKind::Query) {
      ASSERT_TRUE(h.order_ok_at(op.time, kDelta));
    }
    h.apply(op);
    ASSERT_TRUE(h.sorts.validate()) << "after timeline entry " << op.file_index;
  }
  check_until(end);
  ASSERT_EQ(h.advance_to(end, validate), AdvanceOutcome::Reached);
  ASSERT_TRUE(h.order_ok_at(end, kDelta));
  ASSERT_TRUE(h.sorts.validate());
}

TEST(KineticSortOracle, RandomLinearManySeeds) {
  for (const SortLayout layout : {SortLayout::Dense, SortLayout::Gapped}) {
    for (std::uint64_t seed = 1; seed <= 40; ++seed) {
      GeneratorOptions o;
      o.seed = seed;
      o.n = seed % 4 == 0 ? 1000 : seed % 4 == 1 ? 2 : seed % 4 == 2 ? 17 : 200;
      o.queries = 5;
      check_against_oracle(scenario::generate("random-linear", o), seed, 20, o.n <= 200, layout);
      if (HasFatalFailure()) return;
    }
  }
}

TEST(KineticSortOracle, RandomQuadraticManySeeds) {
  for (std::uint64_t seed = 1; seed <= 30; ++seed) {
    GeneratorOptions o;
    o.seed = seed;
    o.degree = 2;
    o.n = seed % 3 == 0 ? 1000 : seed % 3 == 1 ? 50 : 300;
    o.queries = 5;
    check_against_oracle(scenario::generate("random-poly", o), seed, 20, o.n <= 50);
    if (HasFatalFailure()) return;
  }
}

TEST(KineticSortOracle, CubicAndHigherDegrees) {
  for (int degree = 3; degree <= 6; ++degree) {
    GeneratorOptions o;
    o.seed = static_cast<std::uint64_t>(100 + degree);
    o.degree = degree;
    o.n = 150;
    o.end_time = 3.0;
    check_against_oracle(scenario::generate("random-poly", o), o.seed, 25, true);
    if (HasFatalFailure()) return;
  }
}

TEST(KineticSortOracle, UpdatesInsertsRemoves) {
  for (std::uint64_t seed = 1; seed <= 30; ++seed) {
    GeneratorOptions o = test::with_changes(seed, seed % 2 == 0 ? 300 : 40, 60, 30, 30);
    o.queries = 10;
    const bool linear = seed % 3 != 0;
    if (!linear) o.degree = 2;
    const scenario::Scenario s = scenario::generate(linear ? "random-linear" : "random-poly", o);
    check_against_oracle(s, seed, 20, o.n <= 40);
    if (HasFatalFailure()) return;
    check_against_oracle(s, seed, 20, o.n <= 40, SortLayout::Gapped);
    if (HasFatalFailure()) return;
  }
}

/// The sort keeps the motions in sort order with room for the table's highest degree so far:
/// linear objects first, then inserts and updates of degree 4 widen every entry, and the sort
/// still validates (its copies equal the table's motions) and agrees with the oracle.
TEST(KineticSortOracle, HigherDegreesArriveAfterTheStart) {
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    GeneratorOptions o = test::with_changes(seed, 60, 20, 20, 10);
    o.degree = 4;
    o.queries = 5;
    scenario::Scenario s = scenario::generate("random-poly", o);
    for (scenario::ObjectSpec& object : s.objects) {
      for (std::vector<double>& c : object.motion.coordinates) c.resize(2);  // linear at first
    }
    check_against_oracle(s, seed, 10, true);
    if (HasFatalFailure()) return;
  }
}

/// The sort is a PrefetchingHandler: the simulator passes it memory hints for the next event.
/// Hints change nothing: the same events, in the same order, at the same times, as through a
/// handler that forwards process() without them (random input and the GRIDS input, with its
/// many simultaneous crossings).
TEST(KineticSortOracle, PrefetchHintsChangeNothing) {
  static_assert(PrefetchingHandler<KineticSort>);
  struct Plain {  // no prefetch(): the simulator gives no hints
    KineticSort& sort;
    EventKind process(const Event& e) { return sort.process(e); }
  };
  static_assert(!PrefetchingHandler<Plain>);
  using Log = std::vector<std::tuple<Time, std::uint32_t, std::uint32_t>>;
  const auto run = [](const scenario::Scenario& s, bool hints) {
    MotionTable motions(1);
    for (const scenario::ObjectSpec& o : s.objects) {
      const MotionPolynomial p =
          MotionPolynomial::from(o.motion.coordinates.at(0), o.motion.origin);
      motions.insert(o.id, std::span(&p, 1), s.start_time);
    }
    Simulator sim(s.start_time);
    const Scheduler scheduler(SchedulerKind::Robust, 1e-9, *s.end_time);
    KineticSort sort(motions, sim, scheduler, 0);
    sort.initialize();
    Log log;
    Plain plain{sort};
    while (!sim.queue().empty() && sim.queue().top().time <= *s.end_time) {
      const Event e = sim.queue().top();
      log.emplace_back(e.time, e.payload, sort.pending_swap(e).down);
      const AdvanceOutcome o = hints ? sim.process_next(sort) : sim.process_next(plain);
      if (o != AdvanceOutcome::Reached) break;
    }
    EXPECT_TRUE(sort.validate());
    return log;
  };
  GeneratorOptions o;
  o.seed = 3;
  o.n = 2000;
  o.end_time = 5.0;
  for (const char* dataset : {"random-linear", "grids"}) {
    const scenario::Scenario s = scenario::generate(dataset, o);
    const Log with = run(s, true), without = run(s, false);
    EXPECT_GT(with.size(), 1000u) << dataset;
    EXPECT_EQ(with, without) << dataset;
  }
}

/// Under the robust and the exact scheduler with linear motions, the certificate of the pair a
/// swap exchanged is settled without a root isolation (it never fails again:
/// swapped_pair_holds()). Settling changes nothing: the same events, in the same order, at the
/// same times, with the same swaps, as when every certificate gets its root isolation. Checked
/// on random input, on GRIDS (many simultaneous crossings), on equal trajectories, with objects
/// valid from different times, and (robust) at a coarse eps (wide event intervals, events in
/// the past); under exact also parabolas (random and the paper's PARABOLA).
TEST(KineticSortOracle, SettlingSwappedPairsChangesNothing) {
  using Log = std::vector<std::tuple<Time, std::uint32_t, std::uint32_t>>;
  struct Outcome {
    Log log;
    std::uint64_t settled = 0, isolations = 0;
  };
  const auto run = [](const scenario::Scenario& s, SchedulerKind kind, double eps, bool settle,
                      bool staggered) {
    MotionTable motions(1);
    std::size_t i = 0;
    for (const scenario::ObjectSpec& o : s.objects) {
      const MotionPolynomial p =
          MotionPolynomial::from(o.motion.coordinates.at(0), o.motion.origin);
      const Time from =
          staggered ? s.start_time + 0.25 * static_cast<double>(i++ % 4) : s.start_time;
      motions.insert(o.id, std::span(&p, 1), from);
    }
    Simulator sim(s.start_time + (staggered ? 1.0 : 0.0));
    const Scheduler scheduler(kind, eps, *s.end_time);
    KineticSort sort(motions, sim, scheduler, 0);
    sort.set_settle_swapped_pairs(settle);
    sort.initialize();
    Outcome out;
    while (!sim.queue().empty() && sim.queue().top().time <= *s.end_time) {
      const Event e = sim.queue().top();
      out.log.emplace_back(e.time, e.payload, sort.pending_swap(e).down);
      if (sim.process_next(sort) != AdvanceOutcome::Reached) break;
    }
    EXPECT_TRUE(sort.validate());
    // (under exact, now is a root inside its bracket: the order is audited at the end instead)
    if (kind == SchedulerKind::Exact) {
      EXPECT_EQ(sim.advance_to(*s.end_time, sort), AdvanceOutcome::Reached);
      EXPECT_TRUE(sort.audit(*s.end_time).ok);
    } else {
      EXPECT_TRUE(sort.audit(sim.now()).ok);
    }
    out.settled = sort.counters().swapped_pairs_settled;
    out.isolations = sim.counters().root_isolation_calls;
    return out;
  };
  GeneratorOptions o;
  o.seed = 5;
  o.n = 1500;
  o.end_time = 5.0;
  scenario::Scenario equal = scenario::generate("random-linear", o);
  for (std::size_t k = 1; k < equal.objects.size(); k += 3)
    equal.objects[k].motion = equal.objects[k - 1].motion;  // equal trajectories, in pairs
  struct Case {
    const char* name;
    scenario::Scenario s;
    double eps;
    bool staggered;
  };
  const std::vector<Case> cases = {
      {"random-linear", scenario::generate("random-linear", o), 1e-9, false},
      {"grids", scenario::generate("grids", o), 1e-9, false},
      {"equal trajectories", equal, 1e-9, false},
      {"valid from different times", scenario::generate("random-linear", o), 1e-9, true},
      {"coarse eps", scenario::generate("random-linear", o), 1e-2, false},
      {"grids, coarse eps", scenario::generate("grids", o), 0.25, false}};
  // Parabolas: settled under exact only (robust settles lines only).
  GeneratorOptions q = o;
  q.degree = 2;
  q.end_time = 2.0;
  const std::vector<Case> parabolas = {
      {"random-poly, degree 2", scenario::generate("random-poly", q), 1e-9, false},
      {"parabola", scenario::generate("parabola", o), 1e-9, false}};
  for (const SchedulerKind kind : {SchedulerKind::Robust, SchedulerKind::Exact}) {
    for (const Case& c : cases) {
      if (kind == SchedulerKind::Exact && c.eps != 1e-9) continue;  // (eps is CROP's)
      const std::string name = std::string(c.name) + ", " + to_string(kind);
      const Outcome on = run(c.s, kind, c.eps, true, c.staggered);
      const Outcome off = run(c.s, kind, c.eps, false, c.staggered);
      EXPECT_GT(on.log.size(), 500u) << name;
      EXPECT_EQ(on.log, off.log) << name;
      EXPECT_EQ(off.settled, 0u) << name;
      EXPECT_GT(on.settled, on.log.size() / 2) << name;
      EXPECT_EQ(on.isolations + on.settled, off.isolations) << name;
    }
  }
  for (const Case& c : parabolas) {
    const std::string name = std::string(c.name) + ", exact";
    const Outcome on = run(c.s, SchedulerKind::Exact, c.eps, true, c.staggered);
    const Outcome off = run(c.s, SchedulerKind::Exact, c.eps, false, c.staggered);
    EXPECT_GT(on.log.size(), 500u) << name;
    EXPECT_EQ(on.log, off.log) << name;
    EXPECT_EQ(off.settled, 0u) << name;
    EXPECT_GT(on.settled, on.log.size() / 4) << name;
    EXPECT_EQ(on.isolations + on.settled, off.isolations) << name;
  }
}

TEST(KineticSortOracle, MultiDimensionalOneSortPerAxis) {
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    GeneratorOptions o;
    o.seed = seed;
    o.n = 300;
    o.dimension = static_cast<int>(seed % 3) + 2;
    o.updates = 20;
    check_against_oracle(scenario::generate("random-linear", o), seed, 10, false);
    if (HasFatalFailure()) return;
  }
}

/// motion_changed() moves only the entries between the old and the new rank: the new rank is
/// rank_after_update(), the order equals a fresh sort of the same motions at that time (ties by
/// id), the certificates validate; updates to either end, onto another point's trajectory, to
/// random motions and to the same motion, between events.
TEST(KineticSortOracle, LocalUpdatesEqualAFreshSort) {
  GeneratorOptions o;
  o.seed = 5;
  o.n = 60;
  const scenario::Scenario s = scenario::generate("random-linear", o);
  // The parts by hand: the update is checked between the table's change and the sort's.
  test::Parts p(s, SchedulerKind::Classic);
  MotionTable& motions = p.motions;
  Simulator& sim = p.sim;
  KineticSort sort(motions, sim, p.scheduler, 0);
  sort.initialize();
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Time end = *s.end_time;
  for (int step = 1; step <= 200; ++step) {
    const Time t = s.start_time + (end - s.start_time) * step / 200.0;
    ASSERT_TRUE(p.advance_validating(t, sort));
    const auto idx = motions.alive_indices();
    const std::uint32_t i = idx[rng() % idx.size()];
    const std::uint32_t other = idx[rng() % idx.size()];
    const int kind = static_cast<int>(rng() % 5);
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (const std::uint32_t j : idx) {
      lo = std::min(lo, motions.motion(j, 0).evaluate(t));
      hi = std::max(hi, motions.motion(j, 0).evaluate(t));
    }
    MotionPolynomial m = motions.motion(i, 0);
    if (kind == 0) m = MotionPolynomial::from(std::vector<double>{hi + 1.5 + u(rng), 0.0}, t);
    if (kind == 1) m = MotionPolynomial::from(std::vector<double>{lo - 1.5 + u(rng), 0.0}, t);
    if (kind == 2) m = motions.motion(other, 0);
    if (kind == 3) m = MotionPolynomial::from(std::vector<double>{50.0 * u(rng), u(rng)}, t);
    motions.update(motions.handle(i), std::vector<MotionPolynomial>{m}, t);
    const std::uint32_t expected = sort.rank_after_update(i);
    sort.motion_changed(i);
    sim.note_external_change();
    ASSERT_EQ(sort.rank(i), expected) << "step " << step << " kind " << kind;
    ASSERT_TRUE(sort.validate()) << "step " << step << " kind " << kind;
    if (kind == 0) {
      ASSERT_EQ(expected, idx.size() - 1);
    }
    if (kind == 1) {
      ASSERT_EQ(expected, 0u);
    }
    Simulator fresh_sim(t);
    const Scheduler fresh_scheduler(SchedulerKind::Classic, 1e-9, end);
    KineticSort fresh(motions, fresh_sim, fresh_scheduler, 0);
    fresh.initialize();
    const auto a = sort.order(), b = fresh.order();
    ASSERT_TRUE(std::equal(a.begin(), a.end(), b.begin(), b.end()))
        << "step " << step << " kind " << kind << " t=" << t;
  }
  EXPECT_EQ(sort.counters().updates, 200u);
  EXPECT_GT(sort.counters().swaps, 50u);
}

scenario::Scenario lines(const std::vector<std::array<double, 2>>& coefficients, Time origin,
                         Time start, Time end) {
  scenario::Scenario s;
  s.start_time = start;
  s.end_time = end;
  for (std::size_t i = 0; i < coefficients.size(); ++i) {
    scenario::ObjectSpec o;
    o.id = static_cast<scenario::ObjectId>(i);
    o.motion.coordinates = {{coefficients[i][0], coefficients[i][1]}};
    o.motion.origin = origin;
    s.objects.push_back(o);
  }
  return s;
}

// The lines of test::kTieX (id 0) and kTieY (id 1): just after t = 1.3, x is above y exactly, but
// their floating-point values at 1.3 put x below. The traditional classic sort orders by those
// values at its build, at an insert and at an update; with exact decisions, and under the exact
// scheduler, the order is the one just after 1.3.
TEST(KineticSortClassic, OrdersByFloatingPointValuesAsATraditionalKds) {
  const std::array<double, 2> x = test::kTieX, y = test::kTieY;
  const Time t = test::kTieTime;
  for (const test::SchedulerChoice choice : test::kDecidingSchedulerChoices) {
    SCOPED_TRACE(to_string(choice));
    const std::uint32_t x_rank = choice.traditional_classic() ? 0u : 1u;
    {  // build
      SortHarness h(lines({x, y}, 0.0, t, 2.0), choice);
      EXPECT_EQ(h.sorts[0].rank(h.motions.find(0)->index), x_rank);
    }
    {  // insert y next to x
      SortHarness h(lines({x}, 0.0, t, 2.0), choice);
      const MotionPolynomial m = MotionPolynomial::from({y[0], y[1]});
      h.session().insert(1, {m});  // at t: the table, then the sort
      EXPECT_EQ(h.sorts[0].rank(h.motions.find(0)->index), x_rank);
      EXPECT_TRUE(h.sorts[0].validate());
    }
    {  // update a far point onto y's motion
      SortHarness h(lines({x, {100.0, 0.0}}, 0.0, t, 2.0), choice);
      h.session().update(1, {MotionPolynomial::from({y[0], y[1]})});  // at t
      EXPECT_EQ(h.sorts[0].rank(h.motions.find(0)->index), x_rank);
      EXPECT_TRUE(h.sorts[0].validate());
    }
  }
}

TEST(KineticSortDegenerate, IdenticalMotionsNeverSwap) {
  // Ten copies of one trajectory and ten of another: the copies never cross each other.
  std::vector<std::array<double, 2>> c;
  for (int i = 0; i < 10; ++i) c.push_back({0.0, 1.0});
  for (int i = 0; i < 10; ++i) c.push_back({5.0, -1.0});
  const scenario::Scenario s = lines(c, 0.0, 0.0, 10.0);
  SortHarness h(s);
  ASSERT_EQ(h.advance_to(10.0, true), AdvanceOutcome::Reached);
  EXPECT_TRUE(h.order_ok_at(10.0, 0.0));
  // Each of the 10 x 10 cross pairs swaps exactly once (at t = 2.5), copies never.
  EXPECT_EQ(h.sim.counters().events(), 100u);
  EXPECT_EQ(h.sorts[0].counters().swaps, 100u);
}

TEST(KineticSortDegenerate, ManyPointsCrossingAtOneInstant) {
  // 50 lines through the point (t0, x0) = (2.5, 1.0), written with origin t0 so that every
  // crossing time is exactly t0: 1225 simultaneous swaps reverse the order.
  std::vector<std::array<double, 2>> c;
  for (int i = 0; i < 50; ++i) c.push_back({1.0, static_cast<double>(i) - 24.5});
  const scenario::Scenario s = lines(c, 2.5, 0.0, 5.0);
  SortHarness h(s);
  ASSERT_TRUE(h.order_ok_at(0.0, 0.0));
  ASSERT_EQ(h.advance_to(2.5, true), AdvanceOutcome::Reached);
  ASSERT_EQ(h.advance_to(5.0, true), AdvanceOutcome::Reached);
  EXPECT_TRUE(h.order_ok_at(5.0, 0.0));
  EXPECT_TRUE(oracle::is_sorted_at(h.motions, h.sorts[0].order(), 0, 2.5 + 0x1p-30));
  EXPECT_EQ(h.sim.counters().events(), 50u * 49u / 2u);
}

TEST(KineticSortDegenerate, TangentialTouchIsNotAnEvent) {
  // x(t) = (t - 1)^2 touches y(t) = 0 at t = 1 without crossing.
  scenario::Scenario s;
  s.start_time = 0.0;
  s.end_time = 2.0;
  s.objects.push_back({0, {{{0.0}}, 0.0}});
  s.objects.push_back({1, {{{0.0, 0.0, 1.0}}, 1.0}});
  SortHarness h(s);
  ASSERT_EQ(h.advance_to(2.0, true), AdvanceOutcome::Reached);
  EXPECT_EQ(h.sim.counters().events(), 0u);
  EXPECT_TRUE(h.order_ok_at(2.0, 0.0));
}

TEST(KineticSortDegenerate, GridsAndParabolaNeverHangOrCrash) {
  // The classic scheduler may go wrong on these inputs (that is the paper's point), but it must
  // end: either the run completes or the loop guard stops it. Here it completes.
  for (const char* name : {"grids", "parabola"}) {
    SCOPED_TRACE(name);
    GeneratorOptions o;
    o.n = 400;
    const scenario::Scenario s = scenario::generate(name, o);
    SortHarness h(s);
    std::uint64_t bound = 400u * 399u;  // two crossings per pair at most, any order of processing
    h.sim.set_guard(LoopGuard{400u * 399u / 2u + 16u, bound + 16u});
    const AdvanceOutcome outcome = h.advance_to(*s.end_time);
    EXPECT_TRUE(outcome == AdvanceOutcome::Reached || outcome == AdvanceOutcome::LoopGuard);
    EXPECT_TRUE(h.sorts[0].validate());
  }
}

TEST(KineticSortDegenerate, GridsClassicIsExactWhenRootsRoundTheSame) {
  // GRIDS has integer slopes and intercepts: each crossing time -db/da is a correctly rounded
  // division, so simultaneous crossings get identical computed times and the classic scheduler
  // processes them consistently. The final order is the true one.
  GeneratorOptions o;
  o.n = 225;
  const scenario::Scenario s = scenario::generate("grids", o);
  SortHarness h(s);
  ASSERT_EQ(h.advance_to(*s.end_time, true), AdvanceOutcome::Reached);
  EXPECT_TRUE(oracle::is_sorted_at(h.motions, h.sorts[0].order(), 0, *s.end_time));
}

TEST(KineticSortAudit, DetectsAWrongOrder) {
  // The audit must be able to fail: a structure initialised at t = 0 and then audited at a time
  // after a crossing without processing events reports the inversion.
  const scenario::Scenario s = lines({{0.0, 1.0}, {1.0, -1.0}}, 0.0, 0.0, 1.0);
  SortHarness h(s);
  EXPECT_TRUE(h.sorts[0].audit(0.25).ok);
  const SortAudit a = h.sorts[0].audit(0.75);
  EXPECT_FALSE(a.ok);
  EXPECT_EQ(a.first_inversion, 0u);
}

}  // namespace
}  // namespace kinetic
