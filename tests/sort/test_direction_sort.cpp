// Kinetic sorting of points of the plane along the integer directions a x + b y
// (DirectionKeys, the cones of the kinetic closest pair) under the three schedulers, against
// exact key values: exact order at random times under the exact scheduler; under the robust
// scheduler Theorem 4(i) of Abam, Agarwal, de Berg, Yu (neighbours out of order by at most
// 2 eps V_max of the key); on random lines and parabolas and on degenerate input (identical
// trajectories, points on one line for ever, a translating grid, many points through one place
// at one instant). Fixed seeds, printed on failure.

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "kinetic/sort/kinetic_sort.hpp"
#include "support/exact_poly.hpp"

namespace kinetic {
namespace {

namespace ex = ::kinetic::test::exact;

struct Input {
  std::string name;
  std::vector<std::array<MotionPolynomial, 2>> points;
};

Input random_input(std::mt19937_64& rng, int n, int degree) {
  Input in{degree == 1 ? "random lines" : "random parabolas", {}};
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < n; ++i) {
    std::array<MotionPolynomial, 2> p;
    for (MotionPolynomial& m : p) {
      m = degree == 1 ? MotionPolynomial::from({10.0 * u(rng), u(rng)})
                      : MotionPolynomial::from({10.0 * u(rng), u(rng), 0.25 * u(rng)});
    }
    in.points.push_back(p);
  }
  return in;
}

/// Identical trajectories, points on one moving line for ever (x - y the same: ties of the
/// direction x - y for ever), a translating integer grid (ties of every direction along its
/// rows, columns and diagonals for ever), and 12 points through (1, 1) at t = 1.
Input degenerate_input() {
  Input in{"degenerate", {}};
  for (int i = 0; i < 4; ++i) {  // four copies of one trajectory
    in.points.push_back({MotionPolynomial::from({0.5, 0.25}), MotionPolynomial::from({-1.0, 0.5})});
  }
  for (int i = 0; i < 6; ++i) {  // on the line y = x - 2 + t, moving along it at different speeds
    const double s = 0.125 * i;
    in.points.push_back({MotionPolynomial::from({static_cast<double>(i), s}),
                         MotionPolynomial::from({i - 2.0, s + 1.0})});
  }
  for (int gx = 0; gx < 4; ++gx) {  // a 4 x 4 grid translating as one
    for (int gy = 0; gy < 4; ++gy) {
      in.points.push_back({MotionPolynomial::from({gx + 3.0, -0.5}), MotionPolynomial::from({gy - 1.0, 0.25})});
    }
  }
  for (int i = 0; i < 12; ++i) {  // through (1, 1) at t = 1 from every side
    const double vx = std::cos(0.5 * i), vy = std::sin(0.5 * i);
    in.points.push_back({MotionPolynomial::from({1.0, vx}, 1.0), MotionPolynomial::from({1.0, vy}, 1.0)});
  }
  return in;
}

/// The exact key of a point at t.
ex::Q key_at(const std::array<MotionPolynomial, 2>& p, DirectionKeys::Direction d, Time t) {
  return ex::Q(d.a) * ex::eval(ex::from_motion(p[0]), ex::Q(t)) +
         ex::Q(d.b) * ex::eval(ex::from_motion(p[1]), ex::Q(t));
}

/// A bound on |d key / dt| over [t0, t1] (|a| + |b| times the largest speed bound).
double key_speed(const std::vector<std::array<MotionPolynomial, 2>>& points, DirectionKeys::Direction d,
                 Time t0, Time t1) {
  double v = 0.0;
  for (const auto& p : points) {
    for (const MotionPolynomial& m : p) {
      for (const Time t : {t0, t1}) v = std::max(v, std::fabs(m.derivative(t)));
    }
  }
  return (std::abs(d.a) + std::abs(d.b)) * v * 1.0001;
}

void run(const Input& in, SchedulerKind kind, std::uint64_t seed) {
  SCOPED_TRACE(in.name + ", " + to_string(kind) + " scheduler, seed " + std::to_string(seed));
  constexpr double kEps = 1e-7;
  constexpr Time kEnd = 4.0;
  MotionTable table(2);
  for (std::size_t i = 0; i < in.points.size(); ++i)
    (void)table.insert(static_cast<ObjectId>(1000 - 3 * i), in.points[i]);
  Simulator sim(0.0);
  const Scheduler scheduler(kind, kEps, kEnd);
  sim.attach(scheduler);
  std::vector<std::unique_ptr<KineticDirectionSort>> sorts;
  for (int d = 0; d < 8; ++d) {
    sorts.push_back(std::make_unique<KineticDirectionSort>(table, sim, scheduler, d));
    sorts.back()->initialize();
  }
  struct All {
    std::vector<std::unique_ptr<KineticDirectionSort>>* s;
    std::uint32_t first_owner;
    bool initialized() const { return true; }
    EventKind process(const Event& e) { return (*s)[e.owner - first_owner]->process(e); }
  } all{&sorts, sorts.front()->owners().first};
  std::mt19937_64 rng(seed);
  std::vector<Time> times{0.0, 1.0, kEnd};  // 1.0: the instant the 12 points meet
  for (int i = 0; i < 12; ++i) times.push_back(kEnd * static_cast<double>(rng() >> 11) * 0x1p-53);
  std::sort(times.begin(), times.end());
  Time before = 0.0;
  for (const Time t : times) {
    ASSERT_EQ(sim.advance_to(t, all), AdvanceOutcome::Reached);
    for (const auto& s : sorts) {
      ASSERT_TRUE(s->validate()) << "direction " << s->axis() << " at t = " << t;
      const DirectionKeys::Direction d = s->keys().direction();
      const auto order = s->order();
      const double bound = 2.0 * kEps * key_speed(in.points, d, std::max(0.0, before - kEps), t);
      for (std::size_t j = 0; j + 1 < order.size(); ++j) {
        const ex::Q gap = key_at(in.points[order[j]], d, t) - key_at(in.points[order[j + 1]], d, t);
        if (kind == SchedulerKind::Exact) {
          // Sorted at t; equal keys at t are ordered as just after t (checked by the sort's own
          // exact comparisons, compare_after) and, equal for ever, by the direction's id order.
          ASSERT_LE(gap, 0) << "direction " << s->axis() << " positions " << j << ", " << j + 1
                            << " at t = " << t;
          if (gap == 0 && s->keys().compare_after(order[j], order[j + 1], t, nullptr) == 0) {
            EXPECT_TRUE(s->keys().tie_before(order[j], order[j + 1]));
          }
        } else if (kind == SchedulerKind::Robust) {
          ASSERT_LE(gap.get_d(), bound) << "Theorem 4(i), direction " << s->axis() << " at t = " << t;
        }
      }
    }
    before = t;
  }
}

TEST(DirectionSort, RandomAndDegenerateUnderEveryScheduler) {
  constexpr std::uint64_t kSeed = 112901;
  std::mt19937_64 rng(kSeed);
  const std::vector<Input> inputs{random_input(rng, 60, 1), random_input(rng, 40, 2),
                                  degenerate_input()};
  for (const Input& in : inputs) {
    for (const SchedulerKind kind :
         {SchedulerKind::Exact, SchedulerKind::Robust, SchedulerKind::Classic}) {
      run(in, kind, kSeed);
    }
  }
}

TEST(DirectionSort, IdenticalTrajectoriesFollowOnePerturbation) {
  // Two copies: every direction orders them as the translation id * (1, delta) would, by id
  // ascending for a > 0 or (a = 0, b > 0), descending for the directions -x + 2y and -2x + y.
  MotionTable table(2);
  const std::array<MotionPolynomial, 2> p{MotionPolynomial::from({1.0, 1.0}),
                                          MotionPolynomial::from({2.0, -1.0})};
  (void)table.insert(7, p);
  (void)table.insert(3, p);
  for (int d = 0; d < 8; ++d) {
    DirectionKeys keys(table, d);
    keys.refresh(0);
    keys.refresh(1);
    const DirectionKeys::Direction dir = keys.direction();
    const bool ascending = dir.a > 0 || (dir.a == 0 && dir.b > 0);
    EXPECT_EQ(keys.compare_after(0, 1, 0.0, nullptr), 0);
    EXPECT_EQ(keys.tie_before(1, 0), ascending) << "direction " << d;  // id 3 before id 7
  }
}

TEST(DirectionSort, RefusesOtherDimensionsAndDirections) {
  MotionTable line(1), plane(2);
  EXPECT_THROW(DirectionKeys(line, 0), PreconditionError);
  EXPECT_THROW(DirectionKeys(plane, 8), PreconditionError);
  EXPECT_THROW(DirectionKeys(plane, -1), PreconditionError);
  // Twice a coefficient near the largest double overflows: refused with the object's id.
  const std::array<MotionPolynomial, 2> huge{MotionPolynomial::from({0x1.8p1023, 1.0}),
                                             MotionPolynomial::from({0.0})};
  (void)plane.insert(42, huge);
  DirectionKeys keys(plane, 4);  // 2x + y
  try {
    keys.refresh(0);
    ADD_FAILURE() << "overflow not refused";
  } catch (const PreconditionError& e) {
    EXPECT_NE(std::string(e.what()).find("object 42"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace kinetic
