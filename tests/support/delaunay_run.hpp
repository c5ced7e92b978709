#pragma once
// The oracle harness of the structures built on the kinetic Delaunay triangulation (delaunay/,
// closest_pair/): motions of points in the plane, a run under the exact scheduler that validates
// after every event, and probes where the triangles, the closest pair and exact nearest
// neighbours are checked against the brute-force oracle, with inserts, removes and flight-plan
// updates between them. Seeds are the callers', printed in `where`.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
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
/// KineticClosestPair over it) under the exact scheduler, checked against the oracle.
template <class S>
class DelaunayRun {
 public:
  DelaunayRun(Time start, Time horizon)
      : sim(start), scheduler(SchedulerKind::Exact, 1e-9, horizon) {}

  MotionTable table{2};
  Simulator sim;
  Scheduler scheduler;
  std::unique_ptr<S> dt;
  /// Called at every probe after the oracle checks (e.g. another structure's cross-check).
  std::function<void(DelaunayRun&, const std::string&)> extra_check;

  KineticDelaunay& triangulation() {
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
    while (!sim.queue().empty() && sim.queue().top_at_or_before(t)) {
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
    const Time t = sim.now();
    ++totals.probes;
    const auto expected = ids(oracle::delaunay_at(table, t));
    const auto got = ids(triangulation().triangles());
    totals.triangles += got.size();
    EXPECT_EQ(got, expected) << where << " at t=" << t;
    if (got != expected) return false;
    const auto pair = dt->closest_pair();
    const auto pair_expected = oracle::closest_pair_at(table, t);
    EXPECT_EQ(pair.has_value(), pair_expected.has_value()) << where << " at t=" << t;
    if (pair && pair_expected) {
      EXPECT_EQ(table.id((*pair)[0]), table.id((*pair_expected)[0])) << where << " t=" << t;
      EXPECT_EQ(table.id((*pair)[1]), table.id((*pair_expected)[1])) << where << " t=" << t;
    }
    const auto idx = table.alive_indices();
    for (int k = 0; k < 4 && !idx.empty(); ++k) {
      // Query points: random, and exactly at a point's position.
      Point2 q;
      if (k == 0) {
        const std::uint32_t i = idx[rng() % idx.size()];
        q = {table.motion(i, 0).evaluate(t), table.motion(i, 1).evaluate(t)};
      } else {
        std::uniform_real_distribution<double> u(-12.0, 12.0);
        q = {u(rng), u(rng)};
      }
      const auto a = triangulation().nearest(q, 0.0, t);
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

/// S refuses the robust and classic schedulers (naming the exact one) and a cubic motion at an
/// insert (naming the degree limit).
template <class S>
void expect_refusals() {
  MotionTable table(2);
  (void)table.insert(0, linear(0, 0, 1, 0));
  for (const SchedulerKind kind : {SchedulerKind::Robust, SchedulerKind::Classic}) {
    Simulator sim(0.0);
    Scheduler scheduler(kind, 1e-9, 10.0);
    try {
      S s(table, sim, scheduler);
      ADD_FAILURE() << "accepted the " << to_string(kind) << " scheduler";
    } catch (const PreconditionError& e) {
      EXPECT_NE(std::string(e.what()).find("exact scheduler"), std::string::npos) << e.what();
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
}

}  // namespace kinetic::test
