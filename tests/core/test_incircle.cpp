// The in-circle certificate (core/incircle.hpp) against rational arithmetic of its own (positions
// evaluated in mpq from the motions' coefficients, the determinant expanded here): exact signs at
// random times and at co-circular instants, signs just after them, the lifting perturbation
// consistent under every relabelling of the four points (the sign of the permutation), points at
// one place at an exact time, and the exact scheduler's decisions. Fixed seeds.

#include "kinetic/core/incircle.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <set>
#include <string>

#include "kinetic/core/counters.hpp"
#include "kinetic/core/error.hpp"
#include "kinetic/core/exact_time.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"

namespace kinetic {
namespace {

using Motion = std::array<MotionPolynomial, 2>;

mpq_class value(const MotionPolynomial& p, const mpq_class& t) {
  const mpq_class s = t - mpq_class(p.origin);
  mpq_class v = 0, power = 1;
  for (int k = 0; k <= p.degree; ++k) {
    v += mpq_class(p.c[static_cast<std::size_t>(k)]) * power;
    power *= s;
  }
  return v;
}

/// The sign of the 4 x 4 lifted determinant | x y x^2+y^2 1 | over rows a, b, c, d: > 0 when d
/// is inside the counter-clockwise circle through a, b, c.
int oracle_sign(const std::array<Motion, 4>& p, const mpq_class& t) {
  mpq_class m[4][4];
  for (int i = 0; i < 4; ++i) {
    const mpq_class x = value(p[i][0], t), y = value(p[i][1], t);
    m[i][0] = x;
    m[i][1] = y;
    m[i][2] = x * x + y * y;
    m[i][3] = 1;
  }
  // Gaussian elimination in rationals.
  int sign = 1;
  for (int c = 0; c < 4; ++c) {
    int pivot = -1;
    for (int r = c; r < 4 && pivot < 0; ++r) {
      if (m[r][c] != 0) pivot = r;
    }
    if (pivot < 0) return 0;
    if (pivot != c) {
      for (int k = 0; k < 4; ++k) std::swap(m[pivot][k], m[c][k]);
      sign = -sign;
    }
    if (m[c][c] < 0) sign = -sign;
    for (int r = c + 1; r < 4; ++r) {
      const mpq_class f = m[r][c] / m[c][c];
      for (int k = c; k < 4; ++k) m[r][k] -= f * m[c][k];
    }
  }
  return sign;
}

InCircle of(const std::array<Motion, 4>& p) {
  InCircle f;
  for (std::size_t i = 0; i < 4; ++i) f.p[i] = MovingPoint2{&p[i][0], &p[i][1]};
  return f;
}

Motion line(double x, double y, double vx, double vy) {
  return {MotionPolynomial::from({x, vx}), MotionPolynomial::from({y, vy})};
}

TEST(InCircle, SignsEqualTheRationalDeterminant) {
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> small(-4, 4);
  int zeros = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    std::array<Motion, 4> p;
    const bool quadratic = trial % 3 == 0;
    for (auto& m : p) {
      for (auto& c : m) {
        c = quadratic
                ? MotionPolynomial::from({double(small(rng)), double(small(rng)), 0.5 * small(rng)})
                : MotionPolynomial::from({double(small(rng)), double(small(rng))});
      }
    }
    const double t = trial % 2 == 0 ? double(small(rng)) : small(rng) + 0.375;
    const int expected = oracle_sign(p, mpq_class(t));
    zeros += expected == 0;
    ASSERT_EQ(sign_at(of(p), t), expected) << "trial " << trial << " t=" << t;
    // Just after t: the sign at t + 2^-40 when no root lies in between (checked at 2^-41).
    const int later = oracle_sign(p, mpq_class(t) + mpq_class(1.0 / 1099511627776.0));
    if (later != 0 && later == oracle_sign(p, mpq_class(t) + mpq_class(1.0 / 2199023255552.0))) {
      ASSERT_EQ(sign_after(of(p), t), later) << "trial " << trial << " t=" << t;
    }
  }
  EXPECT_GT(zeros, 20);  // co-circular and collinear instants were met
}

/// The in-circle determinant's value at t, in rationals, from its 3 x 3 form.
mpq_class determinant_value(const std::array<Motion, 4>& p, const mpq_class& t) {
  std::array<mpq_class, 3> dx, dy, lift;
  const mpq_class x3 = value(p[3][0], t), y3 = value(p[3][1], t);
  for (std::size_t i = 0; i < 3; ++i) {
    dx[i] = value(p[i][0], t) - x3;
    dy[i] = value(p[i][1], t) - y3;
    lift[i] = dx[i] * dx[i] + dy[i] * dy[i];
  }
  return dx[0] * (dy[1] * lift[2] - lift[1] * dy[2]) - dy[0] * (dx[1] * lift[2] - lift[1] * dx[2]) +
         lift[0] * (dx[1] * dy[2] - dy[1] * dx[2]);
}

// The exact polynomial of the in-circle determinant (in floating-point expansions for lines and
// parabolas, made rational once) agrees with the determinant at 10 rational times, so it is the
// same polynomial (degree <= 8): origins off 0, magnitudes far apart, non-dyadic times.
TEST(InCircle, ExactPolynomialEqualsTheDeterminant) {
  std::mt19937_64 rng(17);
  std::uniform_int_distribution<int> small(-6, 6), scale(-40, 40);
  for (int trial = 0; trial < 400; ++trial) {
    std::array<Motion, 4> p;
    const int degree = 1 + trial % 2;
    for (auto& m : p) {
      for (auto& c : m) {
        std::vector<double> coefficients;
        for (int k = 0; k <= degree; ++k)
          coefficients.push_back(std::ldexp(small(rng) + 0.1 * small(rng), scale(rng) / 4));
        const double origin = trial % 3 == 0 ? 0.0 : 0.5 * small(rng) + 0.1;
        c = MotionPolynomial::from(coefficients, origin);
      }
    }
    const std::optional<ExactPolynomial> fast = incircle_polynomial_in_expansions(of(p));
    ASSERT_TRUE(fast.has_value()) << "trial " << trial << ": the expansions gave up";
    const ExactPolynomial& f = *fast;
    ASSERT_LE(f.degree(), 4 * degree);
    for (int k = 0; k < 10; ++k) {
      mpq_class t(small(rng) * 7 + k, 3);
      t.canonicalize();
      ASSERT_EQ(f(t), determinant_value(p, t)) << "trial " << trial << " t=" << t;
    }
  }
}

int permutation_sign(const std::array<int, 4>& q) {
  int inversions = 0;
  for (int i = 0; i < 4; ++i) {
    for (int j = i + 1; j < 4; ++j) inversions += q[i] > q[j];
  }
  return inversions % 2 == 0 ? 1 : -1;
}

// The perturbed determinant is a determinant of perturbed points: relabelling the four points
// multiplies it by the sign of the permutation, whatever ties it breaks.
TEST(InCircle, LiftingPerturbationIsConsistentUnderRelabelling) {
  std::mt19937_64 rng(12);
  std::uniform_int_distribution<int> small(-3, 3);
  int tied = 0;
  for (int trial = 0; trial < 600; ++trial) {
    std::array<Motion, 4> p;
    std::array<ObjectId, 4> ids{};
    const double vx = small(rng), vy = small(rng);
    for (int i = 0; i < 4; ++i) {
      // Half the trials: a grid translating as one (co-circular or collinear for ever often).
      p[static_cast<std::size_t>(i)] = trial % 2 == 0
                                           ? line(small(rng), small(rng), vx, vy)
                                           : line(small(rng), small(rng), small(rng), small(rng));
      ids[static_cast<std::size_t>(i)] = static_cast<ObjectId>(rng() % 1000);
    }
    if (std::set<ObjectId>(ids.begin(), ids.end()).size() < 4) continue;
    const double t = small(rng);
    const int base = perturbed_sign_after(of(p), ids, t);
    if (sign_after(of(p), t) == 0) ++tied;
    std::array<int, 4> q{0, 1, 2, 3};
    do {
      std::array<Motion, 4> r;
      std::array<ObjectId, 4> rid{};
      for (int i = 0; i < 4; ++i) {
        r[static_cast<std::size_t>(i)] = p[static_cast<std::size_t>(q[i])];
        rid[static_cast<std::size_t>(i)] = ids[static_cast<std::size_t>(q[i])];
      }
      ASSERT_EQ(perturbed_sign_after(of(r), rid, t), permutation_sign(q) * base)
          << "trial " << trial;
    } while (std::next_permutation(q.begin(), q.end()));
  }
  EXPECT_GT(tied, 20);  // the perturbation decided
}

TEST(InCircle, PointsAtOnePlaceAtAnExactTime) {
  // Two points meeting at t = 1/3 (not a double), another passing by.
  const Motion a = line(0, 0, 3, 3), b = line(2, 0, -3, 3), c = line(0, 5, 1, 0);
  const MovingPoint2 pa{&a[0], &a[1]}, pb{&b[0], &b[1]}, pc{&c[0], &c[1]};
  LazyTime third = LazyTime::of(ExactTime::point(mpq_class(1, 3)));
  EXPECT_TRUE(coincide_at(pa, pb, third));
  EXPECT_FALSE(coincide_at(pa, pc, third));
  LazyTime one = LazyTime::point(1.0);
  EXPECT_FALSE(coincide_at(pa, pb, one));
  const Motion d = line(1, 1, 2, 2);
  const MovingPoint2 pd{&d[0], &d[1]};
  EXPECT_TRUE(coincide_at(pa, pd, one));
}

TEST(InCircle, OnlyTheExactSchedulerDecidesIt) {
  // d crosses the circle through a, b, c twice.
  const std::array<Motion, 4> p{line(1, 0, 0, 0), line(0, 1, 0, 0), line(-1, 0, 0, 0),
                                line(-3, 0.25, 1, 0)};
  Counters counters;
  for (const SchedulerKind kind : {SchedulerKind::Robust, SchedulerKind::Classic}) {
    Scheduler s(kind, 1e-9, 10.0);
    EXPECT_THROW((void)s.decide(of(p), counters), PreconditionError);
  }
  Scheduler s(SchedulerKind::Exact, 1e-9, 10.0);
  Simulator sim(0.0);
  sim.attach(s);
  const Scheduler::SignDecision d = s.decide(of(p), counters);
  EXPECT_EQ(d.sign, -1);  // outside at first
  ASSERT_TRUE(d.exact.has_value());
  // It enters the unit circle where x^2 + 1/16 = 1, x = -3 + t: t = 3 - sqrt(15)/4.
  const double root = 3.0 - std::sqrt(15.0) / 4.0;
  EXPECT_NEAR(d.failure, root, 1e-12);
  EXPECT_EQ(sign_at(of(p), d.exact->lower()), -1);
  EXPECT_EQ(sign_at(of(p), d.exact->upper()), 1);
}

}  // namespace
}  // namespace kinetic
