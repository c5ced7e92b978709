#pragma once
// The oracle harness of the structures built on the kinetic Delaunay triangulation (delaunay/,
// closest_pair/): motions of points in the plane, a run (exact scheduler, or the robust one for
// the triangulation) that validates after every event, and probes where the triangles, the
// closest pair and exact nearest neighbours are checked against the brute-force oracle, with
// inserts, removes and flight-plan updates between them. Under the robust scheduler the oracle
// is asked for the grid point at or before the probe (the triangulation's guarantee), computed
// here from the grid's definition. Seeds are the callers', printed in `where`.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "kinetic/core/error.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/delaunay/kinetic_delaunay.hpp"
#include "kinetic/oracle/oracle.hpp"
#include "support/grid.hpp"

namespace kinetic::test {

using Motion = std::array<MotionPolynomial, 2>;

inline Motion linear(double x, double y, double vx, double vy) {
  return {MotionPolynomial::from({x, vx}), MotionPolynomial::from({y, vy})};
}
inline Motion parabola(double x, double y, double vx, double vy, double ax, double ay) {
  return {MotionPolynomial::from({x, vx, ax}), MotionPolynomial::from({y, vy, ay})};
}

struct Totals {
  std::uint64_t events = 0, probes = 0, triangles = 0;
};

/// A run of a structure built on the kinetic Delaunay triangulation (KineticDelaunay itself, or
/// KineticClosestPair over it) under the exact scheduler (or `kind`), checked against the oracle.
template <class S>
class DelaunayRun {
 public:
  DelaunayRun(Time start, Time horizon, SchedulerKind kind = SchedulerKind::Exact,
              double eps = 1e-9)
      : sim(start), scheduler(kind, eps, horizon) {}

  /// The time the oracle is asked for at now: now, or under the robust scheduler the grid point
  /// at or before it (checked against the structure's own world_time()).
  Time oracle_time() const {
    if (scheduler.kind() != SchedulerKind::Robust) return sim.now();
    return grid_point_before(sim.now(), scheduler.eps());
  }

  MotionTable table{2};
  Simulator sim;
  Scheduler scheduler;
  std::unique_ptr<S> dt;
  /// Called at every probe after the oracle checks (e.g. another structure's cross-check).
  std::function<void(DelaunayRun&, const std::string&)> extra_check;

  /// S keeps a triangulation (KineticDelaunay, KineticClosestPair); the closest pair from cones
  /// (KineticConeClosestPair) does not, and is checked on its closest pair alone.
  static constexpr bool kTriangulated = std::is_same_v<S, KineticDelaunay> || requires(S & s) {
    s.triangulation();
  };

  KineticDelaunay& triangulation() requires kTriangulated {
    if constexpr (std::is_same_v<S, KineticDelaunay>) {
      return *dt;
    } else {
      return dt->triangulation();
    }
  }

  void add(ObjectId id, const Motion& m) { (void)table.insert(id, m); }
  void start() {
    dt = std::make_unique<S>(table, sim, scheduler);
    dt->initialize();
    ASSERT_TRUE(dt->validate()) << "after initialize";
  }

  /// Advances to t event by event, validating after each; false on a failure.
  bool advance(Time t, Totals& totals, const std::string& where) {
    while (sim.event_due_by(t)) {
      (void)sim.process_next(*dt);
      ++totals.events;
      if (!dt->validate()) {
        ADD_FAILURE() << where << ": validate() failed after an event at " << sim.now();
        return false;
      }
    }
    (void)sim.advance_to(t, *dt);
    return true;
  }

  std::vector<std::array<ObjectId, 3>> ids(const std::vector<std::array<std::uint32_t, 3>>& tri) {
    std::vector<std::array<ObjectId, 3>> out;
    for (const auto& t : tri) out.push_back({table.id(t[0]), table.id(t[1]), table.id(t[2])});
    return out;
  }

  /// The oracle check at now: triangles, closest pair, a few nearest queries.
  bool check(Totals& totals, std::mt19937_64& rng, const std::string& where) {
    const Time t = oracle_time();
    ++totals.probes;
    if constexpr (kTriangulated) {
      EXPECT_EQ(triangulation().world_time(), t) << where << " at now = " << sim.now();
      const auto expected = ids(oracle::delaunay_at(table, t));
      const auto got = ids(triangulation().triangles());
      totals.triangles += got.size();
      EXPECT_EQ(got, expected) << where << " at t=" << t;
      if (got != expected) return false;
    }
    const auto pair = dt->closest_pair();
    const auto pair_expected = oracle::closest_pair_at(table, t);
    EXPECT_EQ(pair.has_value(), pair_expected.has_value()) << where << " at t=" << t;
    if (pair && pair_expected) {
      EXPECT_EQ(table.id((*pair)[0]), table.id((*pair_expected)[0])) << where << " t=" << t;
      EXPECT_EQ(table.id((*pair)[1]), table.id((*pair_expected)[1])) << where << " t=" << t;
    }
    const auto idx = table.alive_indices();
    for (int k = 0; k < 4 && !idx.empty() && kTriangulated; ++k) {
      // Query points: random, and exactly at a point's position.
      Point2 q;
      if (k == 0) {
        const std::uint32_t i = idx[rng() % idx.size()];
        q = {table.motion(i, 0).evaluate(t), table.motion(i, 1).evaluate(t)};
      } else {
        std::uniform_real_distribution<double> u(-12.0, 12.0);
        q = {u(rng), u(rng)};
      }
      std::optional<std::uint32_t> a;
      if constexpr (kTriangulated) a = triangulation().nearest(q, 0.0, sim.now());
      const auto b = oracle::exact_nearest_at(table, q, t);
      EXPECT_EQ(a.has_value(), b.has_value());
      if (a && b) {
        EXPECT_EQ(table.id(*a), table.id(*b))
            << where << " nearest to (" << q[0] << ", " << q[1] << ") at t=" << t;
      }
    }
    if (extra_check) extra_check(*this, where);
    return !::testing::Test::HasFailure();
  }
};

/// Plays the run to `end` with `probes` random probe times (and `extra` given ones), at each
/// probe checking the oracle and, when `change` is set, changing the table (insert, remove,
/// update) and telling the structure.
template <class S>
void play(DelaunayRun<S>& run, Time end, int probes, std::vector<Time> extra, std::uint64_t seed,
          bool change, int degree, Totals& totals, const std::string& where) {
  std::mt19937_64 rng(seed);
  std::vector<Time> times(extra);
  for (int i = 0; i < probes; ++i) times.push_back(end * std::generate_canonical<double, 53>(rng));
  std::sort(times.begin(), times.end());
  ObjectId next_id = 1000;
  std::uniform_real_distribution<double> u(-10.0, 10.0), v(-1.0, 1.0);
  for (const Time t : times) {
    if (!run.advance(t, totals, where)) return;
    if (!run.check(totals, rng, where)) return;
    if (!change) continue;
    const auto idx = run.table.alive_indices();
    const int what = static_cast<int>(rng() % 3);
    Motion m = degree == 2 ? parabola(u(rng), u(rng), v(rng), v(rng), 0.1 * v(rng), 0.1 * v(rng))
                           : linear(u(rng), u(rng), v(rng), v(rng));
    for (auto& c : m) c.origin = t;
    if (what == 0 || idx.size() < 4) {
      const std::uint32_t i = run.table.insert(next_id++, m, t).index;
      run.dt->insert(i);
    } else if (what == 1) {
      const std::uint32_t i = idx[rng() % idx.size()];
      run.table.remove(run.table.handle(i));
      run.dt->remove(i);
    } else {
      const std::uint32_t i = idx[rng() % idx.size()];
      run.table.update(run.table.handle(i), m, t);
      run.dt->motion_changed(i);
    }
    EXPECT_TRUE(run.dt->validate()) << where << ": after a change at t=" << t;
    if (!run.check(totals, rng, where + " after a change")) return;
  }
  (void)run.advance(end, totals, where);
}

/// The scenarios both structures are held to (each test adds its own expectations): `extra` is
/// set as the runs' extra_check, `after` sees each run when it ended.
template <class S>
struct Scenarios {
  using Run = DelaunayRun<S>;
  std::function<void(Run&, const std::string&)> extra;
  std::function<void(Run&)> after;
  /// The runs' scheduler (the robust one takes points on lines only) and its precision.
  SchedulerKind kind = SchedulerKind::Exact;
  double eps = 1e-9;
  /// Appended to every run's description (e.g. the scheduler).
  std::string tag;

  void finish(Run& run) {
    if (after) after(run);
  }

  /// Random lines: 12 seeds, n = 3..16, inserts, removes and updates on even seeds.
  Totals random_lines() {
    Totals totals;
    for (std::uint64_t seed = 1; seed <= 12; ++seed) {
      std::mt19937_64 rng(seed);
      const int n = 3 + static_cast<int>(seed % 14);
      Run run(0.0, 20.0, kind, eps);
      std::uniform_real_distribution<double> u(-10.0, 10.0), v(-1.0, 1.0);
      for (int i = 0; i < n; ++i) run.add(i, linear(u(rng), u(rng), v(rng), v(rng)));
      run.extra_check = extra;
      run.start();
      play(run, 20.0, 10, {}, seed, seed % 2 == 0, 1, totals,
           "random lines, seed " + std::to_string(seed) + ", n = " + std::to_string(n) + tag);
      if (::testing::Test::HasFailure()) break;
      finish(run);
    }
    return totals;
  }

  /// Random parabolas: 4 seeds, with changes on odd seeds.
  Totals random_parabolas() {
    Totals totals;
    for (std::uint64_t seed = 1; seed <= 4; ++seed) {
      std::mt19937_64 rng(seed + 100);
      const int n = 4 + static_cast<int>(seed % 6);
      Run run(0.0, 6.0);
      std::uniform_real_distribution<double> u(-10.0, 10.0), v(-1.0, 1.0);
      for (int i = 0; i < n; ++i)
        run.add(i, parabola(u(rng), u(rng), v(rng), v(rng), 0.2 * v(rng), 0.2 * v(rng)));
      run.extra_check = extra;
      run.start();
      play(run, 6.0, 6, {}, seed, seed % 2 == 1, 2, totals,
           "random parabolas, seed " + std::to_string(seed));
      if (::testing::Test::HasFailure()) break;
      finish(run);
    }
    return totals;
  }

  /// Points of a small integer grid with integer velocities: co-circular and collinear
  /// quadruples, equal lengths and points meeting at every integer time; probes at every half
  /// and whole time.
  Totals integer_grids() {
    Totals totals;
    for (std::uint64_t seed = 1; seed <= 16; ++seed) {
      std::mt19937_64 rng(seed * 7919);
      const int n = 4 + static_cast<int>(seed % 10);
      Run run(0.0, 6.0, kind, eps);
      for (int i = 0; i < n; ++i) {
        const double x = static_cast<double>(rng() % 5), y = static_cast<double>(rng() % 5);
        const double vx = static_cast<double>(static_cast<int>(rng() % 3) - 1);
        const double vy = static_cast<double>(static_cast<int>(rng() % 3) - 1);
        run.add(i, linear(x, y, vx, vy));
      }
      run.extra_check = extra;
      run.start();
      std::vector<Time> instants;
      for (int k = 1; k <= 5; ++k)
        instants.insert(instants.end(), {k - 0.5, static_cast<double>(k)});
      play(run, 6.0, 4, instants, seed, seed % 3 == 0, 1, totals,
           "integer grid, seed " + std::to_string(seed) + ", n = " + std::to_string(n) + tag);
      if (::testing::Test::HasFailure()) break;
      finish(run);
    }
    return totals;
  }

  /// Points on a circle moving through its centre (all meet at t = 1) and a head-on pair.
  Totals collision_course() {
    Totals totals;
    for (int n = 3; n <= 9; ++n) {
      Run run(0.0, 3.0, kind, eps);
      for (int i = 0; i < n; ++i) {
        // Integer directions: rational positions, all at the origin at t = 1.
        const double dx[] = {4, -3, 0, 5, -4, 1, -1, 3, -5}, dy[] = {1, 4, -5, 2, -2, 3, -4, -3, 0};
        run.add(i, linear(dx[i], dy[i], -dx[i], -dy[i]));
      }
      run.add(50, linear(-6.0, 0.5, 3.0, 0.0));  // head on with the next
      run.add(51, linear(6.0, 0.5, -3.0, 0.0));
      run.extra_check = extra;
      run.start();
      play(run, 3.0, 6, {1.0, 2.0}, static_cast<std::uint64_t>(n), false, 1, totals,
           "collision course, n = " + std::to_string(n) + tag);
      if (::testing::Test::HasFailure()) break;
      finish(run);
    }
    return totals;
  }

  /// Identical motions: 5 and its copy 2 (a smaller id) beside three others, the two at distance
  /// 0 (the closest pair, named by the ids 2 and 5); at t = 3 the copy 2 leaves and 5 stands in
  /// for the group; a new copy of 8 with a smaller id joins; then random changes to the end.
  Totals copies() {
    Totals totals;
    std::mt19937_64 rng(9);
    Run run(0.0, 10.0, kind, eps);
    run.add(5, linear(0, 0, 1, 0));
    run.add(2, linear(0, 0, 1, 0));  // a copy of 5, smaller id
    run.add(7, linear(4, 1, -1, 0.5));
    run.add(8, linear(1, 5, 0, -1));
    run.add(9, linear(-3, 2, 0.5, 0));
    run.extra_check = extra;
    run.start();
    if (!run.check(totals, rng, "copies" + tag)) return totals;
    const auto pair = run.dt->closest_pair();
    EXPECT_TRUE(pair.has_value());
    if (!pair) return totals;
    EXPECT_EQ(run.table.id((*pair)[0]), 2);
    EXPECT_EQ(run.table.id((*pair)[1]), 5);
    if (!run.advance(3.0, totals, "copies" + tag)) return totals;
    // The representative leaves: its copy stands in (the edges are renamed).
    const std::uint32_t two = run.table.find(2)->index;
    run.table.remove(run.table.handle(two));
    run.dt->remove(two);
    EXPECT_TRUE(run.dt->validate());
    if (!run.check(totals, rng, "copy removed" + tag)) return totals;
    // A new copy of 8 with a smaller id joins.
    const std::uint32_t one = run.table.insert(1, linear(1, 5, 0, -1), 3.0).index;
    run.dt->insert(one);
    EXPECT_TRUE(run.dt->validate());
    if (!run.check(totals, rng, "new copy" + tag)) return totals;
    play(run, 10.0, 5, {}, 9, true, 1, totals, "copies, then changes" + tag);
    finish(run);
    return totals;
  }

  /// A long mixed sequence on 40 random points on lines (seed 21) over [0, horizon]: at t = 0.1 k
  /// for k < 60 a remove, a flight-plan update and an insert in turn (of random points; new
  /// motions drawn only for updates and inserts), each validated and checked against the oracle.
  /// Returns the structure's counters just after the start and at the end.
  auto mixed_changes(Time horizon) {
    Totals totals;
    std::mt19937_64 rng(21);
    Run run(0.0, horizon, kind, eps);
    std::uniform_real_distribution<double> u(-10.0, 10.0), v(-1.0, 1.0);
    for (int i = 0; i < 40; ++i) run.add(i, linear(u(rng), u(rng), v(rng), v(rng)));
    run.extra_check = extra;
    run.start();
    const auto at_start = run.dt->counters();
    ObjectId next = 100;
    for (int step = 0; step < 60; ++step) {
      const Time t = 0.1 * step;
      if (!run.advance(t, totals, "mixed changes" + tag)) break;
      const auto idx = run.table.alive_indices();
      const std::uint32_t i = idx[rng() % idx.size()];
      if (step % 3 == 0) {
        run.table.remove(run.table.handle(i));
        run.dt->remove(i);
      } else {
        Motion m = linear(u(rng), u(rng), v(rng), v(rng));
        for (auto& c : m) c.origin = t;
        if (step % 3 == 1) {
          run.table.update(run.table.handle(i), m, t);
          run.dt->motion_changed(i);
        } else {
          run.dt->insert(run.table.insert(next++, m, t).index);
        }
      }
      EXPECT_TRUE(run.dt->validate()) << "after change " << step << tag;
      if (::testing::Test::HasFailure()) break;
      if (!run.check(totals, rng, "mixed changes, step " + std::to_string(step) + tag)) break;
    }
    finish(run);
    return std::pair{at_start, run.dt->counters()};
  }

  /// Groups of identical motions changed in every order: a group of `size` copies (alone, so the
  /// triangulation is flat, or beside three other points), a flight-plan update of one member
  /// onto the group's own motion (it leaves its group and joins it again) or onto another, then
  /// every member removed one by one in the order given by a rotation of the ids. The oracle
  /// after every change. (Found by fuzzing: an update onto the group's motion, then the remove of
  /// its largest id, lost the group's chain and crashed.)
  Totals identical_groups() {
    Totals totals;
    std::mt19937_64 rng(47);
    for (int size = 2; size <= 4; ++size) {
      for (const bool others : {false, true}) {
        for (int updated = 0; updated < size; ++updated) {
          for (const bool onto_group : {true, false}) {
            for (int first = 0; first < size; ++first) {
              const std::string where = "identical group of " + std::to_string(size) +
                                        (others ? " beside 3 points" : "") + ", update of id " +
                                        std::to_string(updated) +
                                        (onto_group ? " onto the group's motion" : " elsewhere") +
                                        ", removes from id " + std::to_string(first) + tag;
              Run run(0.0, 10.0, kind, eps);
              const Motion group = linear(0.0, 0.0, 1.0, 0.5);
              for (int i = 0; i < size; ++i) run.add(i, group);
              if (others) {
                run.add(10, linear(5.0, 1.0, 0.0, 0.0));
                run.add(11, linear(-2.0, 4.0, 0.5, -0.5));
                run.add(12, linear(1.0, -6.0, 0.0, 1.0));
              }
              run.extra_check = extra;
              run.start();
              if (!run.advance(1.0, totals, where)) return totals;
              Motion m = onto_group ? group : linear(2.0, 2.0, -1.0, 0.0);
              const std::uint32_t u = run.table.find(updated)->index;
              run.table.update(run.table.handle(u), m, 1.0);
              run.dt->motion_changed(u);
              EXPECT_TRUE(run.dt->validate()) << where << ": after the update";
              if (!run.check(totals, rng, where + ", after the update")) return totals;
              for (int k = 0; k < size; ++k) {
                const ObjectId id = (first + k) % size;
                const Time t = 2.0 + k;
                if (!run.advance(t, totals, where)) return totals;
                const std::uint32_t i = run.table.find(id)->index;
                run.table.remove(run.table.handle(i));
                run.dt->remove(i);
                EXPECT_TRUE(run.dt->validate()) << where << ": after the remove of id " << id;
                if (!run.check(totals, rng,
                               where + ", after the remove of id " + std::to_string(id)))
                  return totals;
              }
              finish(run);
            }
          }
        }
      }
    }
    return totals;
  }
};

/// S refuses the schedulers `kinds` (its message holding `named`) and a cubic motion at an
/// insert under the exact scheduler (naming the degree limit).
template <class S>
void expect_refusals(std::vector<SchedulerKind> kinds, const std::string& named) {
  MotionTable table(2);
  (void)table.insert(0, linear(0, 0, 1, 0));
  for (const SchedulerKind kind : kinds) {
    Simulator sim(0.0);
    Scheduler scheduler(kind, 1e-9, 10.0);
    try {
      S s(table, sim, scheduler);
      ADD_FAILURE() << "accepted the " << to_string(kind) << " scheduler";
    } catch (const PreconditionError& e) {
      EXPECT_NE(std::string(e.what()).find(named), std::string::npos) << e.what();
    }
  }
  Simulator sim(0.0);
  Scheduler scheduler(SchedulerKind::Exact, 1e-9, 10.0);
  S s(table, sim, scheduler);
  s.initialize();
  const std::uint32_t i =
      table.insert(1, Motion{MotionPolynomial::from({0, 0, 0, 1}), MotionPolynomial::from({1})})
          .index;
  try {
    s.insert(i);
    ADD_FAILURE() << "accepted a cubic motion";
  } catch (const PreconditionError& e) {
    EXPECT_NE(std::string(e.what()).find("degree <= 2"), std::string::npos) << e.what();
  }
  // Coefficients about t = 0 of magnitude beyond [2^-128, 2^128) (the exact in-circle arithmetic
  // takes seconds to minutes there), also when an origin far from 0 makes them so, are refused
  // (what a session checks before the table changes); the bounds themselves and 0 are taken.
  const auto refused = [](ObjectId id, const Motion& m, const std::string& magnitude) {
    try {
      S::require_motion(m, id, "test");
      ADD_FAILURE() << "accepted a coefficient of magnitude " << magnitude;
    } catch (const PreconditionError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("object " + std::to_string(id)), std::string::npos) << what;
      EXPECT_NE(what.find("magnitude " + magnitude + ";"), std::string::npos) << what;
      EXPECT_NE(what.find("2^-128 <= |c| < 2^128"), std::string::npos) << what;
    }
  };
  refused(2, Motion{MotionPolynomial::from({0, std::ldexp(1.0, 128)}), MotionPolynomial::from({1})},
          "2^128");
  refused(3, Motion{MotionPolynomial::from({1}), MotionPolynomial::from({std::ldexp(1.5, -129)})},
          "2^-129");
  // 1 + 2^60 (t - 2^70): its constant term is 1 - 2^130.
  refused(4,
          Motion{MotionPolynomial::from({1, std::ldexp(1.0, 60)}, std::ldexp(1.0, 70)),
                 MotionPolynomial::from({2})},
          "2^129");
  // The structure itself refuses them at initialize, insert and motion_changed.
  MotionTable points(2);
  for (int p = 0; p < 3; ++p) (void)points.insert(p, linear(p, p * p, 1, -p));
  const std::uint32_t edge =
      points
          .insert(5,
                  Motion{MotionPolynomial::from({std::ldexp(1.0, -128), 0, std::ldexp(1.9, 127)}),
                         MotionPolynomial::from({0.5, -std::ldexp(1.0, -128)})})
          .index;
  Simulator clock(0.0);
  S t(points, clock, scheduler);
  t.initialize();  // the bounds are taken
  EXPECT_TRUE(t.validate());
  points.update(points.handle(edge),
                Motion{MotionPolynomial::from({1e300}), MotionPolynomial::from({0.5})});
  try {
    t.motion_changed(edge);
    ADD_FAILURE() << "accepted an update to 1e300";
  } catch (const PreconditionError& e) {
    EXPECT_NE(std::string(e.what()).find("magnitude 2^996;"), std::string::npos) << e.what();
  }
  MotionTable far(2);
  (void)far.insert(0, Motion{MotionPolynomial::from({1, 1}, -1e300), MotionPolynomial::from({0})});
  Simulator far_clock(0.0);
  S u(far, far_clock, scheduler);
  try {
    u.initialize();
    ADD_FAILURE() << "accepted an origin of -1e300";
  } catch (const PreconditionError& e) {
    EXPECT_NE(std::string(e.what()).find("magnitude 2^996;"), std::string::npos) << e.what();
  }
}

}  // namespace kinetic::test
