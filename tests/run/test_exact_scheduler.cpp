// The exact scheduler on every registered structure: degenerate inputs (the paper's GRIDS and
// PARABOLA, integer grids of points, intervals and boxes with many simultaneous crossings,
// coincidences and touching sides), queried exactly at crossing times, every answer equal to the
// oracle's (approximate queries: within their guarantee), validate() after every event, no
// event in the past.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "kinetic/core/exact_time.hpp"
#include "kinetic/core/predicates.hpp"
#include "kinetic/oracle/oracle.hpp"
#include "kinetic/run/runner.hpp"
#include "kinetic/run/timeline_driver.hpp"
#include "kinetic/scenario/generators.hpp"

namespace kinetic::test {
namespace {

using scenario::ObjectsAre;
using scenario::QueryType;
using scenario::Scenario;
using Json = nlohmann::json;

/// Integer positions and velocities in {-1, 0, 1} (boxes: integer half extents): crossings,
/// coincidences and touching sides at integer and half-integer times, many at once.
Scenario integer_grid(ObjectsAre kind, int dimension, std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  Scenario s;
  s.objects_are = kind;
  s.dimension = dimension;
  s.start_time = 0.0;
  s.end_time = 6.0;
  auto small = [&](int lo, int hi) {
    return static_cast<double>(lo +
                               static_cast<int>(rng() % static_cast<std::uint64_t>(hi - lo + 1)));
  };
  for (std::size_t i = 0; i < n; ++i) {
    scenario::Motion m;
    std::vector<double> half;
    if (kind == ObjectsAre::Intervals) {
      const double left = small(-3, 3), v = small(-1, 1);
      m.coordinates = {{left, v}, {left + small(0, 3), v}};
    } else {
      for (int a = 0; a < dimension; ++a) m.coordinates.push_back({small(-3, 3), small(-1, 1)});
      if (kind == ObjectsAre::Boxes) {
        for (int a = 0; a < dimension; ++a) half.push_back(small(0, 1));
      }
    }
    s.objects.emplace_back(static_cast<ObjectId>(i), m, half);
  }
  return s;
}

/// Times in the window at which two coordinates (or box sides) of two objects are equal exactly:
/// crossing times, the ones the exact scheduler must get right.
std::vector<Time> crossing_times(const Scenario& s, const MotionTable& table, std::size_t most) {
  std::set<Time> found;
  const auto idx = table.alive_indices();
  const int coords = s.objects_are == ObjectsAre::Boxes ? s.dimension : table.dimension();
  for (std::size_t i = 0; i < idx.size(); ++i) {
    for (std::size_t j = i + 1; j < idx.size(); ++j) {
      for (int a = 0; a < coords; ++a) {
        const MotionPolynomial& p = table.motion(idx[i], a);
        const MotionPolynomial& q = table.motion(idx[j], a);
        for (const double shift : {0.0, 1.0, -1.0, 2.0, -2.0}) {
          // p - q + shift (box sides: centers +- integer half extents), its real roots in the
          // window isolated exactly; a root that is a double is a crossing time.
          const ExactPolynomial f = ExactPolynomial::difference(p, q) +
                                    ExactPolynomial(std::vector<mpq_class>{mpq_class(shift)});
          if (f.degree() < 1) continue;
          for (ExactTime r : isolate_roots(f, rational(s.start_time), rational(*s.end_time))) {
            r.tighten();
            if (!r.is_point() || r.lower() != r.upper()) continue;
            const Time t = r.lower();
            if (t > s.start_time && t < *s.end_time) found.insert(t);
          }
        }
      }
    }
  }
  std::vector<Time> out(found.begin(), found.end());
  if (out.size() > most) {  // evenly spread, deterministic
    std::vector<Time> pick;
    for (std::size_t k = 0; k < most; ++k) pick.push_back(out[k * out.size() / most]);
    out = pick;
  }
  return out;
}

/// Queries of `type` at time t, their parameters taken from the objects' positions at t (so that
/// box sides and stabbing points sit exactly on coordinates).
void add_queries(Scenario& s, const MotionTable& table, QueryType type, Time t,
                 std::mt19937_64& rng) {
  const auto idx = table.alive_indices();
  auto coord = [&](int axis) { return table.motion(idx[rng() % idx.size()], axis).evaluate(t); };
  auto add = [&](const scenario::QuerySpec& q) {
    scenario::TimelineOp op;
    op.time = t;
    op.op = scenario::OpKind::Query;
    op.query = q;
    s.timeline.push_back(op);
  };
  scenario::QuerySpec q;
  q.type = type;
  switch (type) {
    case QueryType::Sorted:
    case QueryType::Max:
    case QueryType::Min:
      for (int a = 0; a < s.dimension; ++a) {
        q.axis = a;
        add(q);
      }
      return;
    case QueryType::Range:
      for (int k = 0; k < 3; ++k) {
        q.box.clear();
        for (int a = 0; a < s.dimension; ++a) {
          double x = coord(a), y = coord(a);
          if (x > y) std::swap(x, y);
          q.box.push_back({x, y});
        }
        add(q);
      }
      return;
    case QueryType::Stab:
      for (int k = 0; k < 3; ++k) {
        q.x = coord(static_cast<int>(rng() % 2));
        add(q);
      }
      return;
    case QueryType::Nearest:
    case QueryType::Farthest:
      q.eps = 0.25;
      q.point.clear();
      for (int a = 0; a < s.dimension; ++a) q.point.push_back(coord(a));
      add(q);
      return;
    case QueryType::KNearest:  // exact: equal distances (grid points) ordered by id
      for (int k = 0; k < 3; ++k) {
        q.point.clear();
        for (int a = 0; a < s.dimension; ++a) q.point.push_back(coord(a));
        q.k = static_cast<std::size_t>(1 + 4 * k);
        add(q);
      }
      return;
    case QueryType::ApproxRange:
      return;  // (its epsilon-approximation is checked by the structure's own tests)
    default:
      add(q);  // extent, hull, colliding_pairs: no parameters
  }
}

Json ids(const MotionTable& m, const std::vector<std::uint32_t>& indices, bool sort_ids) {
  std::vector<ObjectId> out;
  for (const std::uint32_t i : indices) out.push_back(m.id(i));
  if (sort_ids) std::sort(out.begin(), out.end());
  return out;
}

/// The oracle's answer (exact) for the answer formats of the runner.
Json oracle_answer(const MotionTable& m, const scenario::QuerySpec& q, Time t) {
  switch (q.type) {
    case QueryType::Sorted:
      return ids(m, oracle::sorted_at(m, q.axis, t), false);
    case QueryType::Max:
      return m.id(oracle::max_at(m, q.axis, t));
    case QueryType::Min:
      return m.id(oracle::min_at(m, q.axis, t));
    case QueryType::Extent: {
      Json box = Json::array();
      for (int a = 0; a < m.dimension(); ++a)
        box.push_back({m.id(oracle::min_at(m, a, t)), m.id(oracle::max_at(m, a, t))});
      return box;
    }
    case QueryType::Range:
      return ids(m, oracle::in_box_at(m, q.box, t), true);
    case QueryType::KNearest:
      return ids(m, oracle::k_nearest_at(m, q.point, q.k, t), false);
    case QueryType::Stab:
      return ids(m, oracle::stab_at(m, q.x, t), true);
    case QueryType::Hull:
      return ids(m, oracle::hull_at(m, t), false);
    case QueryType::CollidingPairs: {
      Json pairs = Json::array();
      for (const auto& p : oracle::colliding_pairs_at(m, t))
        pairs.push_back({m.id(p[0]), m.id(p[1])});
      return pairs;
    }
    case QueryType::Delaunay: {
      Json triangles = Json::array();
      for (const auto& tri : oracle::delaunay_at(m, t))
        triangles.push_back({m.id(tri[0]), m.id(tri[1]), m.id(tri[2])});
      return triangles;
    }
    case QueryType::ClosestPair: {
      const auto p = oracle::closest_pair_at(m, t);
      return p ? Json{m.id((*p)[0]), m.id((*p)[1])} : Json(nullptr);
    }
    default:
      return nullptr;
  }
}

struct Checked {
  std::size_t queries = 0, exact_answers = 0;
};

/// Runs `s` on `structure` under the exact scheduler with validate() after every event, and
/// checks every answer against the oracle at its (crossing) time.
Checked check_exact_run(const Scenario& s, const std::string& structure, const std::string& what,
                        const std::set<Time>& crossings) {
  SCOPED_TRACE(structure + " on " + what);
  run::RunOptions o;
  o.structure = structure;
  o.scheduler = SchedulerKind::Exact;
  o.validate_every_event = true;
  std::ostringstream answers;
  const run::RunResult r = run::run(s, o, answers);
  EXPECT_EQ(r.outcome, run::RunOutcome::Completed) << r.message;
  EXPECT_EQ(r.stats.counters.events_in_past, 0u);
  const MotionTable m = run::table_of(s);
  std::istringstream lines(answers.str());
  std::string line;
  std::size_t k = 0;
  Checked c;
  for (const scenario::TimelineOp& op : s.timeline) {
    if (op.op != scenario::OpKind::Query) continue;
    if (!std::getline(lines, line)) {
      ADD_FAILURE() << "missing answer " << k;
      break;
    }
    ++k;
    ++c.queries;
    const Json got = Json::parse(line)["result"];
    const Time t = op.time;
    if (op.query.type == QueryType::Nearest || op.query.type == QueryType::Farthest) {
      // (1 + eps)-nearest / (1 - eps)-farthest: the guarantee, at a crossing time too.
      const double d =
          oracle::distance_at(m, m.find(got.get<ObjectId>()).value().index, op.query.point, t);
      if (op.query.type == QueryType::Nearest) {
        EXPECT_LE(
            d, (1 + op.query.eps) * oracle::nearest_distance_at(m, op.query.point, t) * (1 + 1e-12))
            << "t=" << t;
      } else {
        EXPECT_GE(d, (1 - op.query.eps) * oracle::farthest_distance_at(m, op.query.point, t) *
                         (1 - 1e-12))
            << "t=" << t;
      }
      continue;
    }
    const Json want = oracle_answer(m, op.query, t);
    const bool crossing = crossings.count(t) > 0;
    EXPECT_EQ(got, want) << to_string(op.query.type) << " at t=" << t
                         << (crossing ? " (a crossing time)" : "");
    ++c.exact_answers;
  }
  return c;
}

/// The structure's scenarios: its object kind, dimension and query types.
std::vector<std::pair<std::string, Scenario>> inputs_for(const run::StructureInfo& info) {
  std::vector<std::pair<std::string, Scenario>> out;
  const int d = std::max(info.min_dimension, info.objects == ObjectsAre::Points ? 1 : 2);
  if (info.objects == ObjectsAre::Points && d == 1) {
    scenario::GeneratorOptions g;
    g.n = 40;
    out.emplace_back("GRIDS", scenario::generate("grids", g));
    out.emplace_back("PARABOLA", scenario::generate("parabola", g));
    out.emplace_back("integer grid", integer_grid(ObjectsAre::Points, 1, 40, 3));
    out.emplace_back("integer grid 2-D", integer_grid(ObjectsAre::Points, 2, 30, 4));
  } else if (info.objects == ObjectsAre::Points) {
    out.emplace_back("integer grid", integer_grid(ObjectsAre::Points, d, 30, 5));
    out.emplace_back("integer grid (small)", integer_grid(ObjectsAre::Points, d, 8, 6));
  } else if (info.objects == ObjectsAre::Intervals) {
    out.emplace_back("integer intervals", integer_grid(ObjectsAre::Intervals, 2, 30, 7));
  } else {
    out.emplace_back("integer boxes 2-D", integer_grid(ObjectsAre::Boxes, 2, 24, 8));
    out.emplace_back("integer boxes 1-D", integer_grid(ObjectsAre::Boxes, 1, 16, 9));
  }
  return out;
}

TEST(ExactScheduler, EveryStructureIsExactAtCrossingTimesOnDegenerateInputs) {
  std::size_t structures = 0;
  for (const run::StructureInfo& info : run::structures()) {
    ++structures;
    Checked total;
    for (auto& [what, base] : inputs_for(info)) {
      if (base.dimension < info.min_dimension || base.dimension > info.max_dimension) continue;
      Scenario s = base;
      s.timeline.clear();
      const MotionTable table = run::table_of(s);
      std::mt19937_64 rng(11);
      const std::vector<Time> crossings = crossing_times(s, table, 25);
      ASSERT_GE(crossings.size(), 5u) << info.name << " on " << what;
      std::vector<Time> times = crossings;
      for (std::size_t k = 0; k + 1 < crossings.size(); k += 3)  // and between crossings
        times.push_back(crossings[k] + (crossings[k + 1] - crossings[k]) / 2);
      for (const Time t : times)
        for (const QueryType type : info.queries) add_queries(s, table, type, t, rng);
      std::stable_sort(s.timeline.begin(), s.timeline.end(),
                       [](const auto& a, const auto& b) { return a.time < b.time; });
      const Checked c =
          check_exact_run(s, info.name, what, std::set<Time>(crossings.begin(), crossings.end()));
      total.queries += c.queries;
      total.exact_answers += c.exact_answers;
    }
    EXPECT_GE(total.queries, 20u) << info.name;
    std::printf(
        "[ exact ] %-20s %4zu queries (most at crossing times), %4zu equal to the oracle's "
        "answer\n",
        info.name.c_str(), total.queries, total.exact_answers);
  }
  EXPECT_GE(structures, 10u);
}

/// The run's counters under the exact scheduler.
Counters exact_counters(const std::string& structure, const Scenario& s) {
  run::RunOptions options;
  options.structure = structure;
  options.scheduler = SchedulerKind::Exact;
  std::ostringstream answers;
  const run::RunResult r = run::run(s, options, answers);
  EXPECT_EQ(r.outcome, run::RunOutcome::Completed) << structure << ": " << r.message;
  return r.stats.counters;
}

/// More than `at_least` decisions in the run's counters, none of them by GMP.
void expect_no_gmp_decisions(const Counters& c, std::uint64_t at_least) {
  EXPECT_GT(c.exact_decisions, at_least);
  EXPECT_EQ(c.exact_decisions_gmp, 0u);
}

/// More than `at_least` decisions in the run's counters, under 1 % of them by GMP.
void expect_few_gmp_decisions(const Counters& c, std::uint64_t at_least) {
  EXPECT_GT(c.exact_decisions, at_least);
  EXPECT_LT(c.exact_decisions_gmp * 100, c.exact_decisions);
}

// How often the exact scheduler leaves floating point (Counters::exact_decisions_gmp,
// exact_comparisons_gmp; --stats "exact"): certificates of degree <= 2 (sorting lines and
// parabolas, GRIDS' many equal crossing times, the orientations of points on lines and
// parabolas) and the in-circles of points on lines and parabolas (degree 8) are decided and
// compared without GMP, but for under 1 % of the decisions.
TEST(ExactScheduler, CountsTheDecisionsAndComparisonsThatReachGmp) {
  scenario::GeneratorOptions g;
  g.n = 300;
  g.seed = 5;
  {
    SCOPED_TRACE("sort, random-linear");
    expect_no_gmp_decisions(exact_counters("sort", scenario::generate("random-linear", g)), 300u);
  }
  {
    SCOPED_TRACE("sort, random-poly");
    expect_no_gmp_decisions(exact_counters("sort", scenario::generate("random-poly", g)), 300u);
  }
  g.n = 100;
  const Counters grids = exact_counters("sort", scenario::generate("grids", g));
  EXPECT_GT(grids.exact_comparisons, 100u);  // equal crossing times, brackets overlapping
  EXPECT_EQ(grids.exact_comparisons_gmp, 0u);
  EXPECT_EQ(grids.exact_decisions_gmp, 0u);
  g.n = 60;
  g.dimension = 2;
  // The in-circles of points on lines in floating point too (core/float_decision.hpp): under
  // 1 % of the decisions reach GMP, on lines and on parabolas (in-circles of degree 8).
  {
    SCOPED_TRACE("delaunay, random-linear");
    expect_few_gmp_decisions(exact_counters("delaunay", scenario::generate("random-linear", g)),
                             200u);
  }
  {
    SCOPED_TRACE("delaunay, random-poly");
    expect_few_gmp_decisions(exact_counters("delaunay", scenario::generate("random-poly", g)),
                             200u);
  }
  {
    SCOPED_TRACE("hull, random-linear");
    expect_no_gmp_decisions(exact_counters("hull", scenario::generate("random-linear", g)), 60u);
  }
  g.n = 40;
  g.dimension = 0;
  // Orientations of points on parabolas (degree 4) in floating point as well.
  const Counters circle = exact_counters("hull", scenario::generate("circle", g));
  {
    SCOPED_TRACE("hull, circle");
    expect_few_gmp_decisions(circle, 100u);
  }
  EXPECT_LE(circle.exact_comparisons_gmp, circle.exact_comparisons);
}

}  // namespace
}  // namespace kinetic::test
