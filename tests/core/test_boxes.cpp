// Moving boxes in a motion table (core/boxes.hpp): exact side comparisons and overlap tests
// against the brute-force oracle (rational arithmetic), at random times and at the exact
// instants where boxes start or stop touching; the scenario's table layout (timeline driver).

#include "kinetic/core/boxes.hpp"

#include <gmpxx.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "kinetic/core/crop.hpp"
#include "kinetic/oracle/oracle.hpp"
#include "kinetic/run/timeline_driver.hpp"
#include "kinetic/scenario/scenario_json.hpp"

namespace kinetic {
namespace {

/// A box with center motions (coefficients per axis) and half extents, in a table of d = 2.
ObjectHandle add_box(MotionTable& t, ObjectId id, std::array<std::vector<double>, 2> center,
                     std::array<double, 2> half) {
  std::vector<MotionPolynomial> m;
  for (const auto& c : center) m.push_back(MotionPolynomial::from(c));
  for (const double h : half) m.push_back(MotionPolynomial::from({h}));
  return t.insert(id, m);
}

/// Pairs of ids from the oracle's index pairs.
std::vector<std::array<ObjectId, 2>> ids_of(const MotionTable& t,
                                            const std::vector<std::array<std::uint32_t, 2>>& p) {
  std::vector<std::array<ObjectId, 2>> out;
  for (const auto& q : p) out.push_back({t.id(q[0]), t.id(q[1])});
  return out;
}

/// Brute force with boxes_overlap_at(), pairs by ascending ids.
std::vector<std::array<ObjectId, 2>> overlapping(const MotionTable& t, Time at) {
  std::vector<std::uint32_t> alive = t.alive_indices();
  std::sort(alive.begin(), alive.end(),
            [&](std::uint32_t a, std::uint32_t b) { return t.id(a) < t.id(b); });
  std::vector<std::array<ObjectId, 2>> out;
  for (std::size_t i = 0; i < alive.size(); ++i) {
    for (std::size_t j = i + 1; j < alive.size(); ++j) {
      if (boxes_overlap_at(t, alive[i], alive[j], at))
        out.push_back({t.id(alive[i]), t.id(alive[j])});
    }
  }
  return out;
}

TEST(Boxes, FaceToFaceContactIsClosedAndExact) {
  MotionTable t(boxes_table_dimension(2));
  // a: [t - 1, t + 1] x [-1, 1]; b: [2, 4] x [1, 3] (corner contact at t = 1 exactly: a's high
  // x side reaches b's low x side, and their y sides touch at y = 1 for all t).
  const ObjectHandle a = add_box(t, 1, {{{0, 1}, {0}}}, {1, 1});
  const ObjectHandle b = add_box(t, 2, {{{3}, {2}}}, {1, 1});
  EXPECT_EQ(compare_sides_at(t, a.index, BoxSide::High, b.index, BoxSide::Low, 0, 1.0), 0);
  EXPECT_EQ(compare_sides_at(t, a.index, BoxSide::High, b.index, BoxSide::Low, 0, 0.5), -1);
  EXPECT_EQ(compare_sides_at(t, a.index, BoxSide::Low, b.index, BoxSide::Low, 0, 1.0), -1);
  EXPECT_EQ(compare_sides_at(t, a.index, BoxSide::High, b.index, BoxSide::Low, 1, 7.0), 0);
  EXPECT_FALSE(boxes_overlap_at(t, a.index, b.index, std::nextafter(1.0, 0.0)));
  EXPECT_TRUE(boxes_overlap_at(t, a.index, b.index, 1.0));
  EXPECT_TRUE(boxes_overlap_at(t, a.index, b.index, 5.0));  // a's x span [4, 6] touches b's at 4
  EXPECT_FALSE(boxes_overlap_at(t, a.index, b.index, std::nextafter(5.0, 6.0)));
  // 0.1 is not a dyadic fraction: the sides 0.1 - 0.1 and 0 must compare equal exactly.
  MotionTable u(boxes_table_dimension(1));
  const std::vector<MotionPolynomial> c{MotionPolynomial::from({0.1}),
                                        MotionPolynomial::from({0.1})};
  const std::vector<MotionPolynomial> d{MotionPolynomial::from({-0.2}),
                                        MotionPolynomial::from({0.2})};
  const ObjectHandle p = u.insert(1, c), q = u.insert(2, d);
  EXPECT_EQ(compare_sides_at(u, p.index, BoxSide::Low, q.index, BoxSide::High, 0, 3.0), 0);
  EXPECT_TRUE(boxes_overlap_at(u, p.index, q.index, 3.0));
  EXPECT_EQ(ids_of(u, oracle::colliding_pairs_at(u, 3.0)),
            (std::vector<std::array<ObjectId, 2>>{{1, 2}}));
}

/// The constant combinations of resting boxes' sides are decided by error-free sums, exactly:
/// against rational arithmetic on random doubles of all magnitudes and on exact cancellations.
TEST(Boxes, ConstantCombinationsHaveTheirExactSign) {
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int zeros = 0;
  for (int i = 0; i < 20000; ++i) {
    std::array<double, 4> v{};
    for (double& x : v) x = std::ldexp(u(rng), static_cast<int>(rng() % 120) - 60);
    if (i % 4 == 0) v[3] = v[0] + v[1] - v[2];     // rounded: often not an exact cancellation
    if (i % 4 == 1) v = {v[0], v[1], v[1], v[0]};  // an exact cancellation
    if (i % 4 == 2) v = {0.1, 0.2, 0.3, 0.0};
    const MotionPolynomial a = MotionPolynomial::from({v[0]}), b = MotionPolynomial::from({v[1]}),
                           c = MotionPolynomial::from({v[2]}), d = MotionPolynomial::from({v[3]});
    const MotionCombination f{{&a, &b}, {&c, &d}};
    const mpq_class exact = mpq_class(v[0]) + mpq_class(v[1]) - mpq_class(v[2]) - mpq_class(v[3]);
    const std::optional<int> s = constant_sign(f);
    ASSERT_TRUE(s.has_value());
    ASSERT_EQ(*s, sgn(exact)) << v[0] << " " << v[1] << " " << v[2] << " " << v[3];
    EXPECT_EQ(sign_at(f, 3.0), sgn(exact));
    zeros += sgn(exact) == 0 ? 1 : 0;
  }
  EXPECT_GT(zeros, 4000);
  const MotionPolynomial moving = MotionPolynomial::from({0.0, 1.0}),
                         still = MotionPolynomial::from({1.0});
  EXPECT_FALSE(constant_sign(MotionCombination{{&moving, &still}, {&still, &still}}).has_value());
}

/// compare_sides_at against rational arithmetic (nothing shared with the library): box sides
/// c0 + c1 (t - o) +- h on lines with full-mantissa and small-integer data, at times where two
/// sides meet exactly, a few ulps around them and at random; the floating-point filter decides
/// the far ones, the exact path the rest, and every sign must be the exact one.
TEST(Boxes, SideComparisonsHaveTheirExactSign) {
  constexpr std::uint64_t kSeed = 31;
  std::mt19937_64 rng(kSeed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int zeros = 0, checked = 0;
  for (int i = 0; i < 3000; ++i) {
    MotionTable t(boxes_table_dimension(1));
    const bool grid = i % 2 == 0;
    std::array<std::uint32_t, 2> box{};
    std::array<std::array<double, 4>, 2> data{};  // c0, c1, origin, h
    for (int k = 0; k < 2; ++k) {
      const double c0 =
          grid ? std::round(8 * u(rng)) : std::ldexp(u(rng), static_cast<int>(rng() % 40) - 20);
      const double c1 = grid ? std::round(4 * u(rng)) : u(rng);
      const double o = grid ? 0.0 : std::ldexp(u(rng), static_cast<int>(rng() % 10));
      const double h = grid ? std::round(4 * std::abs(u(rng))) / 2 : std::abs(u(rng));
      data[static_cast<std::size_t>(k)] = {c0, c1, o, h};
      const std::vector<MotionPolynomial> m{MotionPolynomial::from({c0, c1}, o),
                                            MotionPolynomial::from({h})};
      box[static_cast<std::size_t>(k)] = t.insert(k + 1, m).index;
    }
    const auto side = [&](int k, BoxSide s, const mpq_class& at) -> mpq_class {
      const auto& d = data[static_cast<std::size_t>(k)];
      const mpq_class h(d[3]);
      return mpq_class(d[0]) + mpq_class(d[1]) * (at - mpq_class(d[2])) +
             (s == BoxSide::High ? h : mpq_class(-h));
    };
    for (const BoxSide sa : {BoxSide::Low, BoxSide::High}) {
      for (const BoxSide sb : {BoxSide::Low, BoxSide::High}) {
        std::vector<double> times{0.0, 4 * u(rng), 100 * u(rng)};
        // Where the two sides meet (when their speeds differ), rounded, and its neighbours.
        const mpq_class dv = mpq_class(data[0][1]) - mpq_class(data[1][1]);
        if (dv != 0) {
          const mpq_class meet = (side(1, sb, 0) - side(0, sa, 0)) / dv;
          double m = meet.get_d();
          times.push_back(m);
          for (int k = 0; k < 3; ++k) {
            m = std::nextafter(m, 1e300);
            times.push_back(m);
          }
          m = meet.get_d();
          for (int k = 0; k < 3; ++k) {
            m = std::nextafter(m, -1e300);
            times.push_back(m);
          }
        }
        for (const double at : times) {
          const int want = sgn(side(0, sa, mpq_class(at)) - side(1, sb, mpq_class(at)));
          ASSERT_EQ(compare_sides_at(t, box[0], sa, box[1], sb, 0, at), want)
              << "seed " << kSeed << " case " << i << " t = " << at;
          zeros += want == 0 ? 1 : 0;
          ++checked;
        }
      }
    }
  }
  EXPECT_GT(zeros, 500);
  EXPECT_GT(checked, 50000);
}

TEST(Boxes, OverlapsAgreeWithTheOracle) {
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    MotionTable t(boxes_table_dimension(2));
    ObjectId id = 100;
    for (int i = 0; i < 40; ++i) {
      // Integer-ish data every other box, so sides meet exactly at dyadic times; zero extents
      // (points) and identical boxes too.
      const bool grid = i % 2 == 0;
      const double cx = grid ? std::round(4 * u(rng)) : 4 * u(rng);
      const double cy = grid ? std::round(4 * u(rng)) : 4 * u(rng);
      const double vx = grid ? std::round(2 * u(rng)) : u(rng);
      const double vy = grid ? std::round(2 * u(rng)) : u(rng);
      const double hx = i % 7 == 0 ? 0.0 : (grid ? 0.5 : std::abs(u(rng)));
      const double hy = i % 5 == 0 ? 0.0 : (grid ? 1.0 : std::abs(u(rng)));
      add_box(t, id--, {{{cx, vx}, {cy, vy}}}, {hx, hy});
      if (i % 13 == 0) add_box(t, id--, {{{cx, vx}, {cy, vy}}}, {hx, hy});
    }
    int contacts = 0;
    for (const Time at : {0.0, 0.25, 0.5, 1.0, 1.5, 2.0, 0.3, 1.7}) {
      const auto want = ids_of(t, oracle::colliding_pairs_at(t, at));
      EXPECT_EQ(overlapping(t, at), want) << "seed " << seed << ", t = " << at;
      contacts += static_cast<int>(want.size());
    }
    EXPECT_GT(contacts, 20) << "seed " << seed;
  }
}

TEST(Boxes, TheTimelineDriverLaysBoxesOutAndKeepsHalfExtentsOnUpdate) {
  const scenario::Scenario s = scenario::parse_scenario(
      R"({"format": "kinetic-scenario/1", "dimension": 2, "objects_are": "boxes", "end_time": 4,
          "objects": [{"id": 1, "motion": [[0, 1], [2]], "half_extents": [0.5, 0.25]}],
          "timeline": [{"time": 1, "op": "update", "id": 1, "motion": [[1], [2]], "origin": 1},
                       {"time": 2, "op": "update", "id": 1, "motion": [[1], [2]], "half_extents": [0, 3]},
                       {"time": 3, "op": "insert", "id": 2, "motion": [[0], [0]], "half_extents": [1, 2]}]})",
      "boxes.json");
  // The timeline applied to the table and to a structure that only records what it is told.
  struct Recorder {
    std::vector<std::uint32_t> changed;
    bool built = false;
    void initialize() { built = true; }
    EventKind process(const Event&) { return EventKind::Internal; }
    void insert(std::uint32_t i) { changed.push_back(i); }
    void remove(std::uint32_t i) { changed.push_back(i); }
    void motion_changed(std::uint32_t i) { changed.push_back(i); }
    [[nodiscard]] bool initialized() const { return built; }
    [[nodiscard]] bool validate() const { return true; }
    [[nodiscard]] std::uint64_t certificates() const { return 0; }
    [[nodiscard]] std::uint64_t certificates_per_object_max() const { return 0; }
    [[nodiscard]] NamedCounters named_counters() const { return {}; }
  };
  run::TimelineDriver<Recorder> driver(s, SchedulerKind::Robust, 1e-9,
                                       build_with([](MotionTable&, Simulator&, Scheduler&) {
                                         return std::make_unique<Recorder>();
                                       }));
  const MotionTable& t = driver.motions();
  ASSERT_EQ(t.dimension(), 4);
  ASSERT_EQ(box_dimension(t), 2);
  const std::uint32_t box = t.find(1)->index;
  EXPECT_EQ(half_extent(t, box, 0).c[0], 0.5);
  EXPECT_EQ(half_extent(t, box, 1).c[0], 0.25);
  const Recorder& recorder = driver.structure();
  (void)driver.advance_to(1.0);
  driver.apply(s.timeline[0]);
  EXPECT_EQ(center(t, box, 0).c[0], 1.0);
  EXPECT_EQ(half_extent(t, box, 0).c[0], 0.5);  // kept
  EXPECT_EQ(half_extent(t, box, 1).c[0], 0.25);
  (void)driver.advance_to(2.0);
  driver.apply(s.timeline[1]);
  EXPECT_EQ(half_extent(t, box, 0).c[0], 0.0);
  EXPECT_EQ(half_extent(t, box, 1).c[0], 3.0);
  (void)driver.advance_to(3.0);
  driver.apply(s.timeline[2]);
  const std::uint32_t inserted = t.find(2)->index;
  EXPECT_EQ(half_extent(t, inserted, 1).c[0], 2.0);
  EXPECT_EQ(recorder.changed.size(), 3u);
  // Box 1 is [1, 1] x [-1, 5] now, box 2 [-1, 1] x [-2, 2]: they touch along x = 1.
  EXPECT_EQ(ids_of(t, oracle::colliding_pairs_at(t, 3.0)),
            (std::vector<std::array<ObjectId, 2>>{{1, 2}}));
}

}  // namespace
}  // namespace kinetic
