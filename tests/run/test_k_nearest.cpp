// The k_nearest query (docs/scenario-format.md) of the kinetic kd-tree (any dimension), the
// longest-side kd-tree and the Delaunay triangulation, against the brute-force oracle
// (oracle::k_nearest_at: every distance compared exactly, equal distances by id): whole runs with
// inserts, removes and updates under every scheduler each structure takes; integer grids queried
// at their tie instants from points with many equal distances, copies of one motion and points
// meeting at one place, k = 0, k > n; the (1 + eps) guarantee; the kd-tree's guarantee right
// after and before events of a robust run with a coarse eps; bad input refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "kinetic/core/error.hpp"
#include "kinetic/core/predicates.hpp"
#include "kinetic/delaunay/kinetic_delaunay.hpp"
#include "kinetic/kdtree/kinetic_kdtree.hpp"
#include "kinetic/longest_side_kdtree/longest_side_kdtree.hpp"
#include "kinetic/oracle/oracle.hpp"
#include "kinetic/run/runner.hpp"
#include "kinetic/run/timeline_driver.hpp"
#include "kinetic/scenario/generators.hpp"
#include "kinetic/scenario/scenario_json.hpp"
#include "support/driver.hpp"
#include "support/scenario_runs.hpp"

namespace kinetic {
namespace {

using run::TimelineDriver;
using scenario::OpKind;
using scenario::QueryType;

/// The scenario's answers to its k_nearest queries by brute force: the timeline replayed into a
/// table, each answer oracle::k_nearest_at() at the query's time, as `kinetic run` writes it.
std::string k_nearest_by_brute_force(const scenario::Scenario& s) {
  MotionTable table(s.dimension);
  std::map<scenario::ObjectId, ObjectHandle> handle;
  for (const auto& o : s.objects) handle[o.id] = table.insert(o.id, test::polynomials(o.motion));
  std::string out;
  for (const auto& op : s.timeline) {
    if (op.op == OpKind::Remove) {
      table.remove(handle.at(op.id));
      handle.erase(op.id);
    } else if (op.op == OpKind::Insert) {
      handle[op.id] = table.insert(op.id, test::polynomials(op.motion));
    } else if (op.op == OpKind::Update) {
      table.update(handle.at(op.id), test::polynomials(op.motion));
    } else {
      nlohmann::json ids = nlohmann::json::array();
      for (const std::uint32_t i : oracle::k_nearest_at(table, op.query.point, op.query.k, op.time))
        ids.push_back(table.id(i));
      out += test::answer_line(op.time, "k_nearest", ids);
    }
  }
  return out;
}

std::string run_answers(const scenario::Scenario& s, const std::string& structure,
                        SchedulerKind kind, double eps = 1e-9) {
  run::RunOptions options;
  options.structure = structure;
  options.scheduler = kind;
  options.eps = eps;
  run::check_runnable(s, options, "k_nearest.json");
  std::ostringstream answers;
  const run::RunResult r = run::run(s, options, answers);
  EXPECT_EQ(r.outcome, run::RunOutcome::Completed) << r.message;
  return answers.str();
}

struct Case {
  const char* structure;
  int dimension;
  std::vector<SchedulerKind> schedulers;
};

std::vector<Case> cases() {
  const std::vector<SchedulerKind> all{SchedulerKind::Robust, SchedulerKind::Classic,
                                       SchedulerKind::Exact};
  return {{"kdtree", 1, all},
          {"kdtree", 2, all},
          {"kdtree", 3, all},
          {"longest-side-kdtree", 2, {SchedulerKind::Robust, SchedulerKind::Classic}},
          {"delaunay", 2, {SchedulerKind::Robust, SchedulerKind::Exact}}};
}

/// k of the i-th query: 1, 4, 10, and more than there are points.
std::size_t k_of(std::size_t i, std::size_t n) {
  const std::size_t ks[] = {1, 4, 10, n + 7};
  return ks[i % 4];
}

TEST(KNearest, OracleOrdersByExactDistanceThenId) {
  // Four points at distance 5 from (0, 0) (3-4-5 triangles), one at the query point, one at
  // sqrt(25 + 2^-40): the oracle must tell it from the ties and order the ties by id.
  MotionTable t(2);
  auto at = [](double x, double y) {
    return std::vector<MotionPolynomial>{MotionPolynomial::constant(x),
                                         MotionPolynomial::constant(y)};
  };
  t.insert(40, at(3, 4));
  t.insert(10, at(-4, 3));
  t.insert(30, at(0, -5));
  t.insert(20, at(5, std::sqrt(0x1p-40)));  // 25 + 2^-40 when exact
  t.insert(50, at(0, 0));
  t.insert(60, at(-5, 0));
  const std::vector<double> q{0.0, 0.0};
  std::vector<ObjectId> ids;
  for (const std::uint32_t i : oracle::k_nearest_at(t, q, 10, 0.0)) ids.push_back(t.id(i));
  EXPECT_EQ(ids, (std::vector<ObjectId>{50, 10, 30, 40, 60, 20}));
  ids.clear();
  for (const std::uint32_t i : oracle::k_nearest_at(t, q, 3, 0.0)) ids.push_back(t.id(i));
  EXPECT_EQ(ids, (std::vector<ObjectId>{50, 10, 30}));
  EXPECT_TRUE(oracle::k_nearest_at(t, q, 0, 0.0).empty());
}

/// Whole runs of random points on lines with 5 updates, inserts and removes, 16 k_nearest
/// queries at random times (k = 1, 4, 10, n + 7): the answers equal the brute force's.
TEST(KNearest, RunsEqualBruteForceUnderEverySchedulerWithChanges) {
  for (const Case& c : cases()) {
    scenario::GeneratorOptions o = test::with_changes(5, 150, 5, 5, 5);
    o.dimension = c.dimension;
    o.queries = 16;
    o.query_type = QueryType::KNearest;
    scenario::Scenario s = scenario::generate("random-linear", o);
    std::size_t i = 0;
    for (auto& op : s.timeline) {
      if (op.op == OpKind::Query) op.query.k = k_of(i++, 150);
    }
    ASSERT_EQ(i, 16u);
    const std::string want = k_nearest_by_brute_force(s);
    for (const SchedulerKind kind : c.schedulers) {
      SCOPED_TRACE(std::string(c.structure) + " d=" + std::to_string(c.dimension) + " " +
                   to_string(kind) + " seed 5");
      EXPECT_EQ(run_answers(s, c.structure, kind), want);
    }
  }
}

/// Integer grids (equal coordinates and simultaneous events at every integer time) with copies
/// of one motion and points that meet at one place, queried at the tie instants and between,
/// from grid points and half-grid points (many equal distances): exact answers, ties by id.
TEST(KNearest, DegenerateGridsCopiesAndMeetingPointsAreExact) {
  for (const std::uint64_t seed : {3u, 8u}) {
    scenario::Scenario s = test::integer_grid_2d(40, seed, 4.0);
    // Five copies of object 0's motion, and three points that meet at (2, 2) at t = 2.
    for (int j = 0; j < 5; ++j) s.objects.push_back({100 + j, s.objects[0].motion});
    s.objects.push_back({200, {{{0.0, 1.0}, {0.0, 1.0}}, 0.0}});
    s.objects.push_back({201, {{{4.0, -1.0}, {2.0}}, 0.0}});
    s.objects.push_back({202, {{{2.0}, {6.0, -2.0}}, 0.0}});
    const std::size_t n = s.objects.size();
    std::mt19937_64 rng(seed);
    std::size_t i = 0;
    for (int step = 0; step <= 16; ++step) {
      for (int j = 0; j < 3; ++j) {
        scenario::TimelineOp op;
        op.time = 0.25 * step;
        op.query.type = QueryType::KNearest;
        op.query.point = {0.5 * static_cast<double>(rng() % 9),
                          0.5 * static_cast<double>(rng() % 9)};
        op.query.k = k_of(i++, n);
        s.timeline.push_back(op);
      }
    }
    const std::string want = k_nearest_by_brute_force(s);
    for (const Case& c : cases()) {
      if (c.dimension != 2) continue;
      for (const SchedulerKind kind : c.schedulers) {
        SCOPED_TRACE(std::string(c.structure) + " " + to_string(kind) + " seed " +
                     std::to_string(seed));
        if (std::string(c.structure) == "delaunay" && kind == SchedulerKind::Robust) continue;
        EXPECT_EQ(run_answers(s, c.structure, kind), want);
      }
    }
    // The robust Delaunay triangulation answers at its world_time(), the grid point at or before
    // now (docs/delaunay.md): exactly the oracle's answer there.
    scenario::Scenario objects_only = s;
    objects_only.timeline.clear();
    TimelineDriver<KineticDelaunay> dt(objects_only, SchedulerKind::Robust, 1e-9);
    for (const auto& op : s.timeline) {
      dt.session().advance(op.time);
      const Time world = dt.structure().world_time();
      EXPECT_LE(op.time - world, 1e-9);
      EXPECT_EQ(dt.structure().k_nearest(op.query.point, op.query.k, 0.0, op.time),
                oracle::k_nearest_at(dt.motions(), op.query.point, op.query.k, world))
          << "robust delaunay seed " << seed << " t=" << op.time;
    }
  }
}

/// The kd-tree in 1 to 4 dimensions at the tie instants of points on a small integer lattice
/// with integer velocities (many equal distances from lattice and half-lattice points).
TEST(KNearest, KdTreeInFourDimensionsAtTieInstants) {
  for (int d = 1; d <= 4; ++d) {
    scenario::Scenario s;
    s.dimension = d;
    s.end_time = 3.0;
    std::mt19937_64 rng(static_cast<std::uint64_t>(d) * 31);
    for (int id = 0; id < 60; ++id) {
      scenario::Motion m;
      for (int a = 0; a < d; ++a) {
        m.coordinates.push_back(
            {static_cast<double>(rng() % 4), static_cast<double>(static_cast<int>(rng() % 3) - 1)});
      }
      s.objects.push_back({id, m});
    }
    std::size_t i = 0;
    for (int step = 0; step <= 12; ++step) {
      scenario::TimelineOp op;
      op.time = 0.25 * step;
      op.query.type = QueryType::KNearest;
      for (int a = 0; a < d; ++a) op.query.point.push_back(0.5 * static_cast<double>(rng() % 7));
      op.query.k = k_of(i++, 60);
      s.timeline.push_back(op);
    }
    const std::string want = k_nearest_by_brute_force(s);
    for (const SchedulerKind kind :
         {SchedulerKind::Robust, SchedulerKind::Classic, SchedulerKind::Exact}) {
      SCOPED_TRACE("d=" + std::to_string(d) + " " + to_string(kind));
      EXPECT_EQ(run_answers(s, "kdtree", kind), want);
    }
  }
}

/// With eps > 0 the i-th reported distance is within (1 + eps) of the true i-th (kd-tree and
/// longest-side kd-tree), and eps = 0 is exact; fewer points are visited with eps > 0.
TEST(KNearest, ApproximateAnswersKeepTheirFactor) {
  const scenario::Scenario s = test::generated("random-linear", 1000, 2, 21, 1, false);
  for (const double eps : {0.1, 0.5, 2.0}) {
    TimelineDriver<KineticKdTree> kd(s, SchedulerKind::Robust, 1e-9);
    TimelineDriver<LongestSideKdTree> ls(s, SchedulerKind::Robust, 1e-9);
    std::mt19937_64 rng(99);
    for (const Time t : test::random_times_in_window(s, rng, 5)) {
      kd.session().advance(t);
      ls.session().advance(t);
      for (int j = 0; j < 5; ++j) {
        const Box box = test::random_box(kd.motions(), t, rng);
        const std::vector<double> q{box[0][0], box[1][1]};
        const std::size_t k = j == 0 ? 1 : 10;
        const std::vector<std::uint32_t> truth = oracle::k_nearest_at(kd.motions(), q, k, t);
        for (int which = 0; which < 2; ++which) {
          const std::vector<std::uint32_t> got = which == 0
                                                     ? kd.structure().k_nearest(q, k, eps, t)
                                                     : ls.structure().k_nearest(q, k, eps, t);
          const MotionTable& m = which == 0 ? kd.motions() : ls.motions();
          ASSERT_EQ(got.size(), truth.size());
          for (std::size_t r = 0; r < got.size(); ++r) {
            const double d_got = oracle::distance_at(m, got[r], q, t);
            const double d_true = oracle::distance_at(m, truth[r], q, t);
            EXPECT_LE(d_got, (1.0 + eps) * d_true * (1.0 + 1e-12))
                << (which == 0 ? "kdtree" : "longest-side") << " eps " << eps << " rank " << r
                << " t=" << t;
            EXPECT_GE(d_got, d_true * (1.0 - 1e-12));
          }
          // The search is local: far fewer nodes than points for k = 1, and no more with a
          // larger eps than with eps = 0.
          if (which == 0) {
            const std::uint64_t visits = kd.structure().counters().last_query_visits;
            (void)kd.structure().k_nearest(q, k, 0.0, t);
            const std::uint64_t exact_visits = kd.structure().counters().last_query_visits;
            EXPECT_LE(visits, exact_visits);
            if (k == 1) {
              EXPECT_LT(exact_visits, 200u) << "t=" << t;
            }
          }
        }
      }
    }
  }
}

/// Right after and just before events of a robust run with eps = 1e-3 the ranks may be briefly
/// wrong: every reported distance is then within sqrt(d) Delta of the true one of its rank,
/// Delta = 2 n eps V_max (docs/kdtree.md), and never below it.
TEST(KNearest, KdTreeNearEventsWithinItsBound) {
  const double eps = 1e-3;
  for (int d = 2; d <= 3; ++d) {
    const scenario::Scenario s = test::generated("random-linear", 120, d, 13, 1, false);
    TimelineDriver<KineticKdTree> h(s, SchedulerKind::Robust, eps);
    (void)h.structure();
    double v_max = 0.0;
    for (const std::uint32_t i : h.motions().alive_indices())
      for (int a = 0; a < d; ++a) v_max = std::max(v_max, std::fabs(h.motions().motion(i, a).c[1]));
    const double bound = std::sqrt(static_cast<double>(d)) * 2.0 * 120 * eps * v_max;
    std::mt19937_64 rng(17);
    std::uint64_t checked = 0, inexact = 0;
    Simulator& sim = h.sim();
    while (sim.event_due_by(*s.end_time) && checked < 3000) {
      ASSERT_EQ(sim.process_next(h.structure()), AdvanceOutcome::Reached);
      const Time next = sim.queue().empty() ? *s.end_time : sim.queue().top().time;
      for (int j = 0; j < 2; ++j) {
        const Time t = j == 0 ? sim.now() + (next - sim.now()) * 0.5
                              : std::max(sim.now(), std::nextafter(next, -HUGE_VAL));
        ASSERT_EQ(sim.advance_to(t, h.structure()), AdvanceOutcome::Reached);
        const Box box = test::random_box(h.motions(), t, rng);
        std::vector<double> q;
        for (int a = 0; a < d; ++a) q.push_back(box[static_cast<std::size_t>(a)][0]);
        const std::vector<std::uint32_t> got = h.structure().k_nearest(q, 5, 0.0, t);
        const std::vector<std::uint32_t> want = oracle::k_nearest_at(h.motions(), q, 5, t);
        ++checked;
        ASSERT_EQ(got.size(), want.size());
        if (got == want) continue;
        ++inexact;
        for (std::size_t r = 0; r < got.size(); ++r) {
          const double d_got = oracle::distance_at(h.motions(), got[r], q, t);
          const double d_true = oracle::distance_at(h.motions(), want[r], q, t);
          EXPECT_GE(d_got, d_true * (1.0 - 1e-12)) << "t=" << t;
          EXPECT_LE(d_got, d_true + bound) << "rank " << r << " t=" << t;
        }
      }
    }
    EXPECT_GT(checked, 500u);
    std::printf("d=%d near-event k_nearest answers checked: %llu, inexact: %llu\n", d,
                static_cast<unsigned long long>(checked), static_cast<unsigned long long>(inexact));
  }
}

/// Bad input: the point's size, NaN, a negative eps, a query at another time; k = 0 answers
/// nothing, k > n everything; the scenario reader names the fault's path.
TEST(KNearest, BadInputIsRefusedClearly) {
  const scenario::Scenario s = test::generated("random-linear", 30, 3, 4, 1, false);
  TimelineDriver<KineticKdTree> h(s, SchedulerKind::Robust, 1e-9);
  KineticKdTree& tree = h.structure();
  const std::vector<double> two{0.0, 0.0}, three{0.0, 0.0, 0.0};
  const std::vector<double> nan{0.0, std::nan(""), 0.0};
  EXPECT_THROW((void)tree.k_nearest(two, 3, 0.0, 0.0), PreconditionError);
  EXPECT_THROW((void)tree.k_nearest(nan, 3, 0.0, 0.0), PreconditionError);
  EXPECT_THROW((void)tree.k_nearest(three, 3, -1.0, 0.0), PreconditionError);
  EXPECT_THROW((void)tree.k_nearest(three, 3, 0.0, 1.0), PreconditionError);
  EXPECT_TRUE(tree.k_nearest(three, 0, 0.0, 0.0).empty());
  EXPECT_EQ(tree.k_nearest(three, 1000, 0.0, 0.0),
            oracle::k_nearest_at(h.motions(), three, 30, 0.0));
  EXPECT_EQ(tree.nearest(three, 0.0, 0.0), oracle::k_nearest_at(h.motions(), three, 1, 0.0)[0]);
  try {
    (void)tree.k_nearest(two, 3, 0.0, 0.0);
  } catch (const PreconditionError& e) {
    EXPECT_NE(std::string(e.what()).find("KineticKdTree::k_nearest"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("2 coordinates"), std::string::npos) << e.what();
  }
  const std::string head =
      R"({"format": "kinetic-scenario/1", "dimension": 2, "end_time": 1,
          "objects": [{"id": 1, "motion": [[0], [0]]}], "timeline": [{"time": 0.5, "op": "query",
          "query": )";
  const auto refused = [&](const std::string& query, const std::string& expected) {
    try {
      (void)scenario::parse_scenario(head + query + "}]}", "q.json");
      ADD_FAILURE() << "accepted " << query;
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  refused(R"({"type": "k_nearest", "point": [0, 0]})", "\"k\"");
  refused(R"({"type": "k_nearest", "point": [0, 0], "k": -1})", "$.timeline[0].query.k");
  refused(R"({"type": "k_nearest", "point": [0, 0], "k": 1.5})", "$.timeline[0].query.k");
  refused(R"({"type": "k_nearest", "point": [0], "k": 2})", "$.timeline[0].query.point");
  refused(R"({"type": "k_nearest", "point": [0, 0], "k": 2, "eps": -1})",
          "$.timeline[0].query.eps");
  refused(R"({"type": "k_nearest", "point": [0, 0], "k": 2, "radius": 1})", "radius");
  const scenario::Scenario ok = scenario::parse_scenario(
      head + R"({"type": "k_nearest", "point": [0, 0], "k": 2}}]})", "q.json");
  EXPECT_EQ(ok.timeline[0].query.k, 2u);
  EXPECT_EQ(ok.timeline[0].query.eps, 0.0);
  // Written and read back the same.
  EXPECT_EQ(scenario::parse_scenario(scenario::write_scenario(ok), "w.json").timeline[0].query,
            ok.timeline[0].query);
}

}  // namespace
}  // namespace kinetic
