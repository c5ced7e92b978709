// The kinetic closest pair from cones (KineticConeClosestPair) against the brute-force oracle.
//  - Exact scheduler: the scenarios the Delaunay-based closest pair is held to
//    (tests/support/delaunay_run.hpp: random lines and parabolas with inserts, removes and
//    updates, integer grids with equal lengths and points meeting at integer times, a collision
//    course, groups of identical motions), validate() after every event (every candidate is the
//    first point of its cone in the scan, by brute force over the maintained orders), the answer
//    equal to the oracle's at every probe.
//  - Robust scheduler: the same validation, and at random probes the guarantee of
//    docs/closest-pair.md asserted with the orders' measured error rho: when no two points are
//    closer than 7 rho, some candidate is at most 24 rho longer than the closest pair.
//  - Classic scheduler: validate() after every event, runs end.
// Fixed seeds, printed on failure.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "kinetic/closest_pair/kinetic_cone_closest_pair.hpp"
#include "kinetic/core/error.hpp"
#include "kinetic/core/float_roots.hpp"
#include "support/delaunay_run.hpp"

namespace kinetic {
namespace {

using test::linear;
using test::Motion;
using test::parabola;
using test::Totals;

TEST(ConeClosestPairExact, TheDelaunayClosestPairsScenarios) {
  test::Scenarios<KineticConeClosestPair> scenarios;
  Totals all;
  for (const Totals t : {scenarios.random_lines(), scenarios.random_parabolas(),
                         scenarios.integer_grids(), scenarios.collision_course(),
                         scenarios.identical_groups()}) {
    all.events += t.events;
    all.probes += t.probes;
  }
  std::printf("[ cone closest pair ] exact: %llu events, %llu probes against the oracle\n",
              static_cast<unsigned long long>(all.events),
              static_cast<unsigned long long>(all.probes));
  EXPECT_GT(all.events, 1000u);
  EXPECT_GT(all.probes, 100u);
}

double distance_at(const MotionTable& table, std::uint32_t a, std::uint32_t b, Time t) {
  return std::hypot(table.motion(a, 0).evaluate(t) - table.motion(b, 0).evaluate(t),
                    table.motion(a, 1).evaluate(t) - table.motion(b, 1).evaluate(t));
}

/// rho: the largest inversion of the maintained orders at t, in distance units along each
/// direction (the key a x + b y divided by |(a, b)|), from values computed in double.
double order_error(const KineticConeClosestPair& cp, const MotionTable& table, Time t) {
  double rho = 0.0;
  for (int d = 0; d < 8; ++d) {
    const DirectionKeys::Direction dir = DirectionKeys::kDirections[static_cast<std::size_t>(d)];
    const double norm = std::hypot(dir.a, dir.b);
    double highest = -std::numeric_limits<double>::infinity();
    for (const std::uint32_t p : cp.order(d).order()) {
      const double key =
          (dir.a * table.motion(p, 0).evaluate(t) + dir.b * table.motion(p, 1).evaluate(t)) / norm;
      highest = std::max(highest, key);
      rho = std::max(rho, highest - key);
    }
  }
  return rho;
}

struct RobustTotals {
  std::uint64_t events = 0, probes = 0, checked = 0, tiny = 0, reported_exact = 0;
  double worst_excess = 0.0;  ///< (shortest candidate - closest distance) / rho, worst seen
  double worst_reported = 0.0;  ///< reported - closest distance, worst seen
};

/// Plays points under `kind` to `end`, validating after every event; at probes, under the
/// robust scheduler, asserts the guarantee with the measured rho.
void play(const std::vector<Motion>& points, SchedulerKind kind, double eps, Time end, int probes,
          std::uint64_t seed, RobustTotals& totals, const std::string& where) {
  MotionTable table(2);
  for (std::size_t i = 0; i < points.size(); ++i) (void)table.insert(static_cast<ObjectId>(i), points[i]);
  Simulator sim(0.0);
  const Scheduler scheduler(kind, eps, end);
  KineticConeClosestPair cp(table, sim, scheduler);
  cp.initialize();
  ASSERT_TRUE(cp.validate()) << where << ": after initialize";
  std::mt19937_64 rng(seed);
  std::vector<Time> times;
  for (int i = 0; i < probes; ++i) times.push_back(end * std::generate_canonical<double, 53>(rng));
  std::sort(times.begin(), times.end());
  for (const Time t : times) {
    while (sim.event_due_by(t)) {
      (void)sim.process_next(cp);
      ++totals.events;
      ASSERT_TRUE(cp.validate()) << where << ": validate() after an event at " << sim.now();
    }
    (void)sim.advance_to(t, cp);
    ++totals.probes;
    const auto pair = cp.closest_pair();
    ASSERT_TRUE(pair.has_value());
    if (kind != SchedulerKind::Robust) continue;
    const auto best = oracle::closest_pair_at(table, t);
    const double closest = distance_at(table, (*best)[0], (*best)[1], t);
    const double reported = distance_at(table, (*pair)[0], (*pair)[1], t);
    const double rho = order_error(cp, table, t);
    double shortest = std::numeric_limits<double>::infinity();
    for (std::uint32_t l = 0; l < cp.tournament().leaves(); ++l) {
      if (const auto e = cp.tournament().pair(l)) shortest = std::min(shortest, distance_at(table, (*e)[0], (*e)[1], t));
    }
    totals.reported_exact += reported == closest ? 1 : 0;
    totals.worst_reported = std::max(totals.worst_reported, reported - closest);
    const double rounding = 1e-12 * (1.0 + closest);
    if (closest <= 7.0 * rho + rounding) {
      ++totals.tiny;  // two points closer than 7 rho: outside the guarantee
      continue;
    }
    ++totals.checked;
    EXPECT_LE(shortest, closest + 24.0 * rho + rounding)
        << where << " at t=" << t << ": closest " << closest << ", rho " << rho;
    if (rho > 0.0) totals.worst_excess = std::max(totals.worst_excess, (shortest - closest) / rho);
    if (::testing::Test::HasFailure()) return;
  }
}

std::vector<Motion> random_points(std::mt19937_64& rng, int n, int degree) {
  std::uniform_real_distribution<double> u(-10.0, 10.0), v(-1.0, 1.0);
  std::vector<Motion> m;
  for (int i = 0; i < n; ++i) {
    m.push_back(degree == 2 ? parabola(u(rng), u(rng), v(rng), v(rng), 0.1 * v(rng), 0.1 * v(rng))
                            : linear(u(rng), u(rng), v(rng), v(rng)));
  }
  return m;
}

/// Degenerate input: an integer grid with integer velocities (equal lengths, points meeting at
/// integer times), copies of one motion, and points through one place at t = 1.
std::vector<Motion> degenerate_points(std::mt19937_64& rng) {
  std::vector<Motion> m;
  for (int x = 0; x < 4; ++x) {
    for (int y = 0; y < 4; ++y) {
      m.push_back(linear(x, y, static_cast<double>(rng() % 3) - 1.0,
                         static_cast<double>(rng() % 3) - 1.0));
    }
  }
  for (int k = 0; k < 3; ++k) m.push_back(linear(7.0, 7.0, -0.5, 0.25));
  for (int k = 0; k < 6; ++k) {
    const double vx = static_cast<double>(k % 3) - 1.0, vy = k < 3 ? 1.0 : -1.0;
    m.push_back(linear(-3.0 - vx, -3.0 - vy, vx, vy));  // all at (-3, -3) at t = 1
  }
  return m;
}

TEST(ConeClosestPairRobust, TheGuaranteeAtRandomTimes) {
  RobustTotals totals;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    std::mt19937_64 rng(seed);
    const int degree = seed % 3 == 0 ? 2 : 1;
    const std::vector<Motion> points =
        seed % 4 == 0 ? degenerate_points(rng) : random_points(rng, 30 + 10 * static_cast<int>(seed), degree);
    for (const double eps : {1e-3, 1e-7}) {
      play(points, SchedulerKind::Robust, eps, 10.0, 40, seed, totals,
           "robust, seed " + std::to_string(seed) + ", eps " + std::to_string(eps));
      if (::testing::Test::HasFailure()) return;
    }
  }
  std::printf(
      "[ cone closest pair ] robust: %llu events, %llu probes, %llu checked, %llu with two points "
      "closer than 7 rho; shortest candidate at most %.3g rho beyond the closest (bound 24); "
      "reported exact in %llu, worst reported excess %.3g\n",
      static_cast<unsigned long long>(totals.events), static_cast<unsigned long long>(totals.probes),
      static_cast<unsigned long long>(totals.checked), static_cast<unsigned long long>(totals.tiny),
      totals.worst_excess, static_cast<unsigned long long>(totals.reported_exact),
      totals.worst_reported);
  EXPECT_GT(totals.checked, 300u);
  EXPECT_GT(totals.events, 1000u);
}

/// A classic scheduler whose failures come late by a pseudo-random delay in [0, 0.05) drawn from
/// the certificate's motions: events processed out of order, so that the eight orders disagree
/// for a while about pairs that cross.
Time scrambled(void*, const Scheduler&, const MotionPolynomial& lower, const MotionPolynomial& upper,
               Time t_curr, Time, Counters&) {
  const Time t = classic_failure_time(lower, upper, t_curr);
  if (t == kTimeInfinity) return t;
  std::uint64_t h = 1469598103934665603ULL;
  for (const MotionPolynomial* m : {&lower, &upper}) {
    for (int k = 0; k <= m->degree; ++k) {
      std::uint64_t bits = 0;
      std::memcpy(&bits, &m->c[static_cast<std::size_t>(k)], sizeof bits);
      h = (h ^ bits) * 1099511628211ULL;
    }
  }
  return t + 0.05 * static_cast<double>(h >> 11) * 0x1p-53;
}

TEST(ConeClosestPairClassic, OrdersDisagreeingAboutEveryPairStillGiveAnAnswer) {
  // Two and three points passing through one place at t = 1, their crossings processed late and
  // out of order: for a while the eight orders may disagree about a pair so that neither point
  // lies in a cone of the other where the scan meets it, and there is no candidate at all. The
  // query then compares every pair exactly: every query has an answer, the right one for two
  // points, and the structure stays valid.
  std::mt19937_64 rng(1129);
  std::uniform_real_distribution<double> v(-1.0, 1.0);
  std::uint64_t fallbacks = 0, queries = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 2 + trial % 2;
    MotionTable table(2);
    for (int i = 0; i < n; ++i) {
      const double vx = v(rng), vy = v(rng);
      (void)table.insert(i, linear(-vx, -vy, vx, vy));  // at the origin at t = 1
    }
    Simulator sim(0.0);
    Scheduler scheduler(SchedulerKind::Classic, 1e-9, 4.0);
    scheduler.set_failure_time_model(&scrambled, nullptr);
    KineticConeClosestPair cp(table, sim, scheduler);
    cp.initialize();
    for (int k = 0; k < 80; ++k) {
      const Time t = 0.98 + 0.001 * k;
      ASSERT_EQ(sim.advance_to(t, cp), AdvanceOutcome::Reached);
      ASSERT_TRUE(cp.validate()) << "trial " << trial << " at t=" << t;
      const auto pair = cp.closest_pair();
      ++queries;
      ASSERT_TRUE(pair.has_value()) << "trial " << trial << " at t=" << t;
      if (n == 2) {
        EXPECT_EQ(table.id((*pair)[0]), 0);
        EXPECT_EQ(table.id((*pair)[1]), 1);
      }
    }
    fallbacks += cp.counters().brute_force_passes;
  }
  std::printf("[ cone closest pair ] scrambled crossings: %llu queries, %llu without a candidate\n",
              static_cast<unsigned long long>(queries), static_cast<unsigned long long>(fallbacks));
  EXPECT_GT(fallbacks, 0u);
}

TEST(ConeClosestPairClassic, RunsEndValid) {
  RobustTotals totals;
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    std::mt19937_64 rng(seed);
    const std::vector<Motion> points =
        seed % 2 == 0 ? degenerate_points(rng) : random_points(rng, 40, 1);
    play(points, SchedulerKind::Classic, 1e-9, 10.0, 20, seed, totals,
         "classic, seed " + std::to_string(seed));
    if (::testing::Test::HasFailure()) return;
  }
  EXPECT_GT(totals.events, 100u);
}

TEST(ConeClosestPair, RefusesOtherDimensions) {
  MotionTable line(1);
  Simulator sim(0.0);
  const Scheduler scheduler;
  EXPECT_THROW(KineticConeClosestPair(line, sim, scheduler), PreconditionError);
}

}  // namespace
}  // namespace kinetic
