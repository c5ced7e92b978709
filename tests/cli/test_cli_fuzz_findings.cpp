// The defects an outside fuzzing campaign found in the structures over extreme and degenerate
// input, each as its reproducer through the `kinetic` program: a run gives the right answer, or
// is refused before any answer with exit 2 and one line naming the limit. (The crash of the
// Delaunay triangulation and the closest pair on identical motions is tested in their own files,
// on every order of updates and removes.)

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "support/cli.hpp"

namespace {

using Outcome = kinetic::test::CliOutcome;
using kinetic::test::write_file;

const kinetic::test::CliScratch scratch{"kinetic_fuzz_findings_"};

Outcome run(const std::string& scenario, const std::string& args, const std::string& tag) {
  const std::string path = scratch.path(tag + ".json");
  write_file(path, scenario);
  return scratch.run("run " + path + " " + args, tag);
}

void expect_answers(const Outcome& o, const std::string& expected, const std::string& what) {
  EXPECT_EQ(o.status, 0) << what << ": " << o.err;
  EXPECT_TRUE(o.err.empty()) << what << ": " << o.err;
  EXPECT_EQ(o.out, expected) << what;
}

// A quadratic motion whose origin is 1e300 (its expansion about 0 is beyond the doubles), and a
// point of velocity -1e308 with no end_time: the exact scheduler isolated roots beyond the
// largest double and converted the bound back into a rational (SIGFPE in GMP). Every scheduler
// now answers, and the same.
TEST(CliFuzzFindings, ExtremeOriginsAndVelocitiesAreAnsweredByEveryScheduler) {
  const std::string sort = R"({"format": "kinetic-scenario/1", "dimension": 1,
    "objects": [{"id": 0, "motion": [[-4.26, 1.7976931348623157e308]]},
                {"id": 1, "motion": [[-1e308]]},
                {"id": 2, "motion": [[0, 4.46, 4.09]]},
                {"id": 3, "motion": [[4.8, 3.0]], "origin": 1e300}],
    "timeline": [{"time": 3.02, "op": "query", "query": {"type": "sorted"}}]})";
  const std::string extent = R"({"format": "kinetic-scenario/1", "dimension": 2,
    "objects": [{"id": 0, "motion": [[-4.26, 1.7976931348623157e308], [0, 0.46, -1e-300]]},
                {"id": 1, "motion": [[-1e308], [1.08, 3.84]]},
                {"id": 2, "motion": [[0, 4.46, 4.09], [-3.05, -1e199]]},
                {"id": 3, "motion": [[4.84, 3.0], [0, 3.0]]}],
    "timeline": [{"time": 3.02, "op": "query", "query": {"type": "extent"}}]})";
  for (const char* scheduler : {"exact", "robust", "classic"}) {
    SCOPED_TRACE(scheduler);
    expect_answers(run(sort, std::string("--structure sort --scheduler ") + scheduler, "sort"),
                   "{\"time\":3.02,\"type\":\"sorted\",\"result\":[1,3,2,0]}\n", "sort");
    const Outcome e =
        run(extent, std::string("--structure extent --scheduler ") + scheduler, "extent");
    EXPECT_EQ(e.status, 0) << e.err;
    EXPECT_NE(e.out.find("\"type\":\"extent\""), std::string::npos) << e.out;
  }
}

// A window beyond the robust scheduler's horizon (262144 at eps 1e-9) was answered up to the
// horizon and then failed with exit 1 ("internal error: ... after the scheduler's horizon"); it
// is refused before the run, for every structure, naming the horizon and the ways around it.
TEST(CliFuzzFindings, AWindowBeyondTheRobustHorizonIsRefusedBeforeAnyAnswer) {
  const std::string points1 = R"({"format": "kinetic-scenario/1", "dimension": 1,
    "end_time": 3e5, "objects": [{"id": 0, "motion": [[0, 1]]}, {"id": 1, "motion": [[1, -1]]}],
    "timeline": [{"time": 1, "op": "query", "query": {"type": "sorted"}}]})";
  const std::string points2 = R"({"format": "kinetic-scenario/1", "dimension": 2,
    "end_time": 5e5, "objects": [{"id": 0, "motion": [[0, 1], [0, 1]]},
                                 {"id": 1, "motion": [[1, -1], [2, -0.5]]},
                                 {"id": 2, "motion": [[3], [1]]}],
    "timeline": [{"time": 1, "op": "query", "query": {"type": "range",
                                                      "box": [[-9, 9], [-9, 9]]}}]})";
  const std::string boxes = R"({"format": "kinetic-scenario/1", "dimension": 1,
    "objects_are": "boxes", "end_time": 3e5,
    "objects": [{"id": 0, "motion": [[0, 1]], "half_extents": [0.5]},
                {"id": 1, "motion": [[3, -1]], "half_extents": [0.5]}],
    "timeline": [{"time": 1, "op": "query", "query": {"type": "colliding_pairs"}}]})";
  const std::vector<std::pair<std::string, const std::string*>> cases{
      {"sort", &points1}, {"tournament", &points1},          {"kdtree", &points2},
      {"hull", &points2}, {"longest-side-kdtree", &points2}, {"range-tree", &points2},
      {"bvh", &boxes},    {"sweep-and-prune", &boxes}};
  for (const auto& [structure, scenario] : cases) {
    SCOPED_TRACE(structure);
    std::string text = *scenario;
    if (structure == "tournament") {
      text.replace(text.find(R"("sorted")"), 8, R"("max")");
    } else if (structure == "hull") {
      const std::size_t at = text.find(R"({"type": "range")");
      text.replace(at, text.find("}}", at) + 1 - at, R"({"type": "hull"})");
    }
    const Outcome o = run(text, "--structure " + structure, "horizon");
    EXPECT_EQ(o.status, 2) << o.err << o.out;
    EXPECT_TRUE(o.out.empty()) << o.out;
    EXPECT_EQ(o.err.rfind("kinetic: ", 0), 0u) << o.err;
    EXPECT_NE(o.err.find("$.end_time"), std::string::npos) << o.err;
    EXPECT_NE(o.err.find("beyond robust scheduling's horizon"), std::string::npos) << o.err;
    EXPECT_NE(o.err.find("262144"), std::string::npos) << o.err;
    EXPECT_EQ(o.err.find('\n'), o.err.size() - 1) << "one line";
    // The classic and exact schedulers have no such horizon: the same window is answered.
    for (const char* scheduler : {"classic", "exact"}) {
      const Outcome other =
          run(text, "--structure " + structure + " --scheduler " + scheduler, "no_horizon");
      EXPECT_EQ(other.status, 0) << scheduler << ": " << other.err;
    }
  }
}

// Under the classic scheduler, -(t - 1e308)^2 (fine under robust and exact) overflowed the
// floating-point difference of two motions ("internal error: MotionPolynomial::from: coefficient
// c0 is not finite"). A classic certificate beyond the doubles' range is decided on the exact
// polynomial.
TEST(CliFuzzFindings, ClassicDecidesCertificatesBeyondTheDoublesExactly) {
  const std::string boxes = R"({"format": "kinetic-scenario/1", "dimension": 1,
    "objects_are": "boxes", "end_time": 10,
    "objects": [{"id": 0, "motion": [[0, 1]], "half_extents": [0.5]},
                {"id": 1, "motion": [[3, -1]], "half_extents": [0.5]},
                {"id": 2, "motion": [[-9]], "half_extents": [0.5]}],
    "timeline": [{"time": 1, "op": "update", "id": 0, "motion": [[0, 0, -1]], "origin": 1e308},
                 {"time": 2, "op": "query", "query": {"type": "colliding_pairs"}},
                 {"time": 2, "op": "update", "id": 0, "motion": [[1.2, 1]], "origin": 2},
                 {"time": 2.25, "op": "query", "query": {"type": "colliding_pairs"}}]})";
  const std::string expected =
      "{\"time\":2.0,\"type\":\"colliding_pairs\",\"result\":[]}\n"
      "{\"time\":2.25,\"type\":\"colliding_pairs\",\"result\":[[0,1]]}\n";
  for (const char* structure : {"bvh", "sweep-and-prune"}) {
    for (const char* scheduler : {"classic", "robust", "exact"}) {
      SCOPED_TRACE(std::string(structure) + " " + scheduler);
      expect_answers(
          run(boxes, std::string("--structure ") + structure + " --scheduler " + scheduler,
              "classic_overflow"),
          expected, "boxes");
    }
  }
  const std::string points = R"({"format": "kinetic-scenario/1", "dimension": 2,
    "end_time": 10,
    "objects": [{"id": 0, "motion": [[0, 1.7976931348623157e308], [4.29, 2]]},
                {"id": 1, "motion": [[5e-324], [2, 3.29]], "origin": 1e308},
                {"id": 2, "motion": [[4.28, -3, 1e300], [1.73]], "origin": -1e199},
                {"id": 3, "motion": [[-2.62], [3, 0]]},
                {"id": 4, "motion": [[4.84, -2.42, 1.5], [4.23, -4.72]], "origin": 2}],
    "timeline": [{"time": 0.73, "op": "query", "query": {"type": "range",
                                                         "box": [[-5, 5], [-5, 5]]}}]})";
  for (const char* scheduler : {"classic", "robust", "exact"}) {
    SCOPED_TRACE(std::string("longest-side-kdtree ") + scheduler);
    expect_answers(
        run(points, std::string("--structure longest-side-kdtree --scheduler ") + scheduler,
            "classic_overflow_points"),
        "{\"time\":0.73,\"type\":\"range\",\"result\":[3]}\n", "points");
  }
}

// Boxes [-0.5, 0.5] and [0.5, 1.5] that overlapped before the window and touch at its start
// were not reported by a query at the start under the exact and classic schedulers (the contract:
// closed boxes, a contact ending at the instant is reported). Also in the plane, corner to
// corner, at a start time other than 0; and a query just after, where they are apart.
TEST(CliFuzzFindings, BoxesTouchingAtTheStartAreReportedThere) {
  const std::string line = R"({"format": "kinetic-scenario/1", "dimension": 1,
    "objects_are": "boxes", "start_time": 0, "end_time": 10,
    "objects": [{"id": 1, "motion": [[0]], "half_extents": [0.5]},
                {"id": 2, "motion": [[1, 1]], "half_extents": [0.5]},
                {"id": 3, "motion": [[7]], "half_extents": [0.5]}],
    "timeline": [{"time": 0, "op": "query", "query": {"type": "colliding_pairs"}},
                 {"time": 0.5, "op": "query", "query": {"type": "colliding_pairs"}}]})";
  const std::string plane = R"({"format": "kinetic-scenario/1", "dimension": 2,
    "objects_are": "boxes", "start_time": 2, "end_time": 10,
    "objects": [{"id": 4, "motion": [[0], [0]], "half_extents": [0.5, 0.5]},
                {"id": 5, "motion": [[1, 1], [1, 2]], "origin": 2, "half_extents": [0.5, 0.5]},
                {"id": 6, "motion": [[-1, -1], [0]], "origin": 2, "half_extents": [0.5, 0.5]}],
    "timeline": [{"time": 2, "op": "query", "query": {"type": "colliding_pairs"}},
                 {"time": 2.5, "op": "query", "query": {"type": "colliding_pairs"}}]})";
  for (const char* structure : {"bvh", "sweep-and-prune"}) {
    for (const char* scheduler : {"classic", "robust", "exact"}) {
      SCOPED_TRACE(std::string(structure) + " " + scheduler);
      const std::string args =
          std::string("--structure ") + structure + " --scheduler " + scheduler;
      expect_answers(run(line, args, "touch_line"),
                     "{\"time\":0.0,\"type\":\"colliding_pairs\",\"result\":[[1,2]]}\n"
                     "{\"time\":0.5,\"type\":\"colliding_pairs\",\"result\":[]}\n",
                     "line");
      // Box 5 = [0.5, 1.5]^2 + (t - 2)(1, 2) touches box 4 = [-0.5, 0.5]^2 at the corner at
      // t = 2; box 6 = [-1.5, -0.5] x [-0.5, 0.5] - (t - 2) touches box 4's left side.
      expect_answers(run(plane, args, "touch_plane"),
                     "{\"time\":2.0,\"type\":\"colliding_pairs\",\"result\":[[4,5],[4,6]]}\n"
                     "{\"time\":2.5,\"type\":\"colliding_pairs\",\"result\":[]}\n",
                     "plane");
    }
  }
}

// Found by the extended structures harness: point boxes 5 and 7 with identical motions, 7
// inserted at t = 3.5, the very time box 6's low side passes box 5 on axis 1. Under robust
// scheduling that event was still pending (processed at the end of its CROP interval), the
// insert placed 7's sides on the other side of box 6's from their identical twins, and
// identical functions never fail: 5 and 7 were never in contact. A pair of identical keys out
// of their tie order now fails at once.
TEST(CliFuzzFindings, AnIdenticalBoxInsertedAtAPendingEventIsInContactWithItsTwin) {
  const std::string boxes = R"({"format": "kinetic-scenario/1", "dimension": 2,
    "objects_are": "boxes", "end_time": 6,
    "objects": [{"id": 5, "motion": [[-3, -1], [-2, -0.5]], "half_extents": [0, 0]},
                {"id": 6, "motion": [[3], [3, -1.5]], "half_extents": [0.5, 1.5]}],
    "timeline": [{"time": 3.5, "op": "insert", "id": 7, "motion": [[-3, -1], [-2, -0.5]],
                  "half_extents": [0, 0]},
                 {"time": 5.5, "op": "query", "query": {"type": "colliding_pairs"}}]})";
  for (const char* structure : {"sweep-and-prune", "bvh"}) {
    for (const char* scheduler : {"robust", "classic", "exact"}) {
      SCOPED_TRACE(std::string(structure) + " " + scheduler);
      expect_answers(
          run(boxes, std::string("--structure ") + structure + " --scheduler " + scheduler,
              "twins"),
          "{\"time\":5.5,\"type\":\"colliding_pairs\",\"result\":[[5,7]]}\n", "twins");
    }
  }
}

// The same extreme magnitudes on the closest pair from cones, under the three schedulers: origins
// 1e-300, -1e300, 1e300 and coefficients near 1e199 and 5e-324 are answered (the cones' orders
// and length certificates are exact at any magnitude); an acceleration of 1e308, whose double
// (the orders along 2x + y and x + 2y) would overflow, is refused before the run, naming it.
TEST(CliFuzzFindings, ClosestPairTakesExtremeMagnitudesUnderEveryScheduler) {
  const std::vector<std::string> answered{
      R"({"format": "kinetic-scenario/1", "dimension": 2,
        "objects": [{"id": 0, "motion": [[0, 1], [0]], "origin": 1e-300},
                    {"id": 1, "motion": [[1, -1], [1]], "origin": -1e300},
                    {"id": 2, "motion": [[2], [0, 1]], "origin": 1e300},
                    {"id": 3, "motion": [[3, 0.5], [2]]}, {"id": 4, "motion": [[4], [3, -1]]}],
        "timeline": [{"time": 1, "op": "query", "query": {"type": "closest_pair"}}]})",
      R"({"format": "kinetic-scenario/1", "dimension": 2, "end_time": 10,
        "objects": [{"id": 0, "motion": [[0], [1e199, -2e199]]}, {"id": 1, "motion": [[1], [1]]},
                    {"id": 2, "motion": [[2], [0, 1]]}, {"id": 3, "motion": [[3, 0.5], [2]]}],
        "timeline": [{"time": 1, "op": "query", "query": {"type": "closest_pair"}}]})",
      R"({"format": "kinetic-scenario/1", "dimension": 2, "end_time": 10,
        "objects": [{"id": 0, "motion": [[0], [1]]}, {"id": 1, "motion": [[1], [1]]},
                    {"id": 2, "motion": [[2], [0, 1]]}, {"id": 3, "motion": [[3, 0.5], [2]]}],
        "timeline": [{"time": 1, "op": "query", "query": {"type": "closest_pair"}},
                     {"time": 2, "op": "update", "id": 2, "motion": [[2, 5e-324], [1]]},
                     {"time": 3, "op": "query", "query": {"type": "closest_pair"}}]})"};
  const std::vector<std::string> expected{"[3,4]", "[1,2]", "[0,1]"};
  for (const char* scheduler : {"exact", "robust", "classic"}) {
    for (std::size_t i = 0; i < answered.size(); ++i) {
      SCOPED_TRACE(std::string(scheduler) + " case " + std::to_string(i));
      const Outcome o = run(answered[i], std::string("--structure closest-pair --scheduler ") +
                                             scheduler, "extreme");
      EXPECT_EQ(o.status, 0) << o.err;
      EXPECT_NE(o.out.find("\"result\":" + expected[i]), std::string::npos) << o.out;
    }
    const Outcome refused = run(
        R"({"format": "kinetic-scenario/1", "dimension": 2,
        "objects": [{"id": 0, "motion": [[0, 1, 1e308], [0]]}, {"id": 1, "motion": [[1], [1]]},
                    {"id": 2, "motion": [[2], [0, 1]]}, {"id": 3, "motion": [[3, 0.5], [2]]}],
        "timeline": [{"time": 1, "op": "query", "query": {"type": "closest_pair"}}]})",
        std::string("--structure closest-pair --scheduler ") + scheduler, "huge");
    EXPECT_EQ(refused.status, 2) << refused.err;
    EXPECT_TRUE(refused.out.empty()) << refused.out;
    EXPECT_NE(refused.err.find("$.objects[0].motion[0][2]: structure closest-pair takes motion "
                               "coefficients of magnitude < 2^1023"),
              std::string::npos)
        << refused.err;
    EXPECT_EQ(refused.err.find('\n'), refused.err.size() - 1) << "one line";
  }
}

// Exact Delaunay runs of extreme magnitudes took from seconds to minutes (never
// ending, in effect, in the campaign: origins 1e-300, -1e300 and 1e300; an acceleration 1e308;
// coefficients near 1e199). They are refused before any answer, naming the motion and the limit:
// coefficients about t = 0 of magnitude 2^-128 <= |c| < 2^128, or 0. Within it, a scenario
// scaled by a power of two answers exactly as the unscaled one (the in-circle signs scale by a
// positive factor).
TEST(CliFuzzFindings, ExactDelaunayRefusesMagnitudesBeyondItsLimitBeforeTheRun) {
  struct Case {
    std::string scenario, path, magnitude;
  };
  const std::vector<Case> cases{{R"({"format": "kinetic-scenario/1", "dimension": 2,
        "objects": [{"id": 0, "motion": [[0, 1], [0]], "origin": 1e-300},
                    {"id": 1, "motion": [[1, -1], [1]], "origin": -1e300},
                    {"id": 2, "motion": [[2], [0, 1]], "origin": 1e300},
                    {"id": 3, "motion": [[3, 0.5], [2]]}, {"id": 4, "motion": [[4], [3, -1]]}],
        "timeline": [{"time": 1, "op": "query", "query": {"type": "closest_pair"}}]})",
                                 "$.objects[0].motion[0]", "2^-997"},
                                {R"({"format": "kinetic-scenario/1", "dimension": 2,
        "objects": [{"id": 0, "motion": [[0, 1, 1e308], [0]]}, {"id": 1, "motion": [[1], [1]]},
                    {"id": 2, "motion": [[2], [0, 1]]}, {"id": 3, "motion": [[3, 0.5], [2]]}],
        "timeline": [{"time": 1, "op": "query", "query": {"type": "closest_pair"}}]})",
                                 "$.objects[0].motion[0]", "2^1023"},
                                {R"({"format": "kinetic-scenario/1", "dimension": 2, "end_time": 10,
        "objects": [{"id": 0, "motion": [[0], [1e199, -2e199]]}, {"id": 1, "motion": [[1], [1]]},
                    {"id": 2, "motion": [[2], [0, 1]]}, {"id": 3, "motion": [[3, 0.5], [2]]}],
        "timeline": [{"time": 1, "op": "query", "query": {"type": "closest_pair"}}]})",
                                 "$.objects[0].motion[1]", "2^662"},
                                {R"({"format": "kinetic-scenario/1", "dimension": 2, "end_time": 10,
        "objects": [{"id": 0, "motion": [[0], [1]]}, {"id": 1, "motion": [[1], [1]]},
                    {"id": 2, "motion": [[2], [0, 1]]}, {"id": 3, "motion": [[3, 0.5], [2]]}],
        "timeline": [{"time": 1, "op": "query", "query": {"type": "closest_pair"}},
                     {"time": 2, "op": "update", "id": 2, "motion": [[2, 5e-324], [1]]},
                     {"time": 3, "op": "query", "query": {"type": "closest_pair"}}]})",
                                 "$.timeline[1].motion[0]", "2^-1074"}};
  for (const char* structure : {"delaunay"}) {
    for (const Case& c : cases) {
      SCOPED_TRACE(std::string(structure) + " " + c.path);
      const Outcome o =
          run(c.scenario, std::string("--structure ") + structure + " --scheduler exact", "far");
      EXPECT_EQ(o.status, 2) << o.err;
      EXPECT_TRUE(o.out.empty()) << o.out;
      EXPECT_EQ(o.err.rfind("kinetic: ", 0), 0u) << o.err;
      EXPECT_NE(o.err.find(c.path + ": structure " + structure), std::string::npos) << o.err;
      EXPECT_NE(o.err.find("2^-128 <= |c| < 2^128"), std::string::npos) << o.err;
      EXPECT_NE(o.err.find("; got " + c.magnitude + ";"), std::string::npos) << o.err;
      EXPECT_EQ(o.err.find('\n'), o.err.size() - 1) << "one line";
    }
  }
  // A seed and the same scaled by 2^100 and 2^-100 (positions, velocities, accelerations):
  // the same answers.
  const std::vector<std::array<std::vector<double>, 2>> motions{
      {{{0, 1}, {0.5}}},           {{{3, -1}, {1, 0.25}}}, {{{1}, {3, -1, 0.125}}},
      {{{-2, 0.75}, {2}}},         {{{2}, {-1, 0.5}}},     {{{-1.5, 0.5, -0.0625}, {-2, 1}}},
      {{{0.25, -0.5}, {4, -0.75}}}};
  const auto seed = [&](int e) {
    std::ostringstream text;
    text.precision(17);
    text << R"({"format": "kinetic-scenario/1", "dimension": 2, "objects": [)";
    for (std::size_t id = 0; id < motions.size(); ++id) {
      text << (id == 0 ? "" : ", ") << R"({"id": )" << id << R"(, "motion": [)";
      for (int axis = 0; axis < 2; ++axis) {
        text << (axis == 0 ? "[" : ", [");
        for (std::size_t k = 0; k < motions[id][axis].size(); ++k)
          text << (k == 0 ? "" : ", ") << std::ldexp(motions[id][axis][k], e);
        text << "]";
      }
      text << "]}";
    }
    text << R"(], "timeline": [)";
    for (const char* t : {"0.5", "1.5", "2.5", "4.5", "7.5"})
      text << (t[0] == '0' ? "" : ", ") << R"({"time": )" << t
           << R"(, "op": "query", "query": {"type": "closest_pair"}})";
    text << "]}";
    return text.str();
  };
  for (const char* structure : {"delaunay", "closest-pair"}) {
    SCOPED_TRACE(structure);
    const std::string args = std::string("--structure ") + structure + " --scheduler exact";
    const Outcome unscaled = run(seed(0), args, "unscaled");
    ASSERT_EQ(unscaled.status, 0) << unscaled.err;
    ASSERT_NE(unscaled.out.find("closest_pair"), std::string::npos);
    for (const int e : {100, -100}) {
      SCOPED_TRACE(e);
      expect_answers(run(seed(e), args, "scaled"), unscaled.out, "scaled");
    }
  }
}

}  // namespace
