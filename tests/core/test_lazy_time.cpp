// LazyTime and the exact scheduler's path without GMP (core/exact_time.hpp, lazy_time.cpp):
// certificates of degree <= 2 (lines, congruent parabolas, general parabolas) decided by exact
// signs in floating-point expansions, held against the general exact decision (decide_exact on
// the expanded polynomial, GMP) at clocks that are doubles, roots of other pairs and roots of the
// same pair (the pair that just swapped, from either side); every comparison made without GMP
// held against the exact comparison. Small value sets make roots coincide often (equal roots of
// different pairs, touching double roots). Fixed seeds, printed on failure.

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "kinetic/core/crop.hpp"
#include "kinetic/core/exact_time.hpp"
#include "kinetic/core/incircle.hpp"
#include "kinetic/core/scheduler.hpp"

namespace kinetic {
namespace {

/// Motions: lines (some with non-dyadic roots), congruent parabolas (c2 = 1/2) and general
/// parabolas, from small value sets, origins sometimes off 0; and lines of random doubles over
/// many magnitudes with one random origin (coefficient differences of two components, x - o
/// inexact: the linear path's exact sums).
class LowDegreeMotions {
 public:
  enum class Family { Lines, CongruentParabolas, Parabolas, RandomLines };
  explicit LowDegreeMotions(std::uint64_t seed) : rng_(seed) {}
  double pick(int lo, int hi) {
    return static_cast<double>(lo +
                               static_cast<int>(rng_() % static_cast<std::uint64_t>(hi - lo + 1)));
  }
  MotionPolynomial motion(Family family) {
    const double origin = rng_() % 3 == 0 ? pick(-3, 3) * 0.5 : 0.0;
    switch (family) {
      case Family::CongruentParabolas:
        return MotionPolynomial::from({pick(-5, 5), pick(-3, 3), 0.5}, origin);
      case Family::Parabolas:
        return MotionPolynomial::from({pick(-5, 5) * 0.5, pick(-3, 3), pick(-2, 2) * 0.25}, origin);
      case Family::RandomLines: {
        std::uniform_real_distribution<double> u(-1.0, 1.0);
        const double scale = std::ldexp(1.0, static_cast<int>(rng_() % 40) - 20);
        return MotionPolynomial::from({u(rng_) * scale, u(rng_) * std::ldexp(1.0, 2)},
                                      rng_() % 2 == 0 ? origin_ : 0.0);
      }
      case Family::Lines:
        break;
    }
    const double v = rng_() % 4 == 0 ? pick(-3, 3) / 3.0 : pick(-3, 3);  // some non-dyadic roots
    return MotionPolynomial::from({pick(-5, 5) + 0.1 * pick(0, 9), v}, origin);
  }
  std::uint64_t next() { return rng_(); }

 private:
  std::mt19937_64 rng_;
  double origin_ = 0.1 * 3.0 + 1.0 / 7.0;  ///< RandomLines' origin (not dyadic)
};

/// A certificate of two motions, upper - lower (the others are MotionCombination and
/// ProductCombination), and what the tests ask of each kind.
struct Pair {
  const MotionPolynomial* upper;
  const MotionPolynomial* lower;
};
Scheduler::SignDecision decide(Scheduler& s, const Pair& c, double t, Counters& counters) {
  return s.decide(*c.upper, *c.lower, t, t, counters);
}
template <class C>
Scheduler::SignDecision decide(Scheduler& s, const C& c, double t, Counters& counters) {
  return s.decide(c, t, t, counters);
}
Scheduler::SignDecision decide(Scheduler& s, const LengthComparison& c, double /*t*/,
                               Counters& counters) {
  return s.decide(c, counters);  // at the scheduler's clock
}
std::optional<LowDegreeDecision> lazy_decision(const Pair& c, const LazyTime& now) {
  return decide_low_degree(*c.upper, *c.lower, now);
}
template <class C>
std::optional<LowDegreeDecision> lazy_decision(const C& c, const LazyTime& now) {
  return decide_low_degree(c, now);
}
ExactPolynomial polynomial(const Pair& c) {
  return ExactPolynomial::difference(*c.upper, *c.lower);
}
template <class C>
ExactPolynomial polynomial(const C& c) {
  return ExactPolynomial::of(c);
}

/// The first root of certificate c after `after` where it changes sign, as the exact scheduler
/// makes it (nullopt when none before 100).
template <class C>
std::optional<LazyTime> lazy_root(const C& c, const LazyTime& after) {
  Counters counters;
  Scheduler probe(SchedulerKind::Exact, 1e-9, 100.0);
  LazyTime start = after;
  probe.use_clock(&start);
  const Scheduler::SignDecision s = decide(probe, c, start.lower(), counters);
  if (!s.exact) return std::nullopt;
  return *s.exact;
}

/// Counts of the decisions checked.
struct Tally {
  std::size_t lazy_decided = 0, failures = 0;
  std::size_t at_root = 0;  ///< clocks at a root of the function decided (both_sides_at_a_clock)
};

/// The exact scheduler's decision on c at `clock` equals the general exact decision (GMP on the
/// expanded polynomial, horizon 100): the sign just after the clock, whether it fails, and when.
template <class C>
void expect_decision_is_exact(const C& c, const LazyTime& clock, Tally& tally) {
  Scheduler scheduler(SchedulerKind::Exact, 1e-9, 100.0);
  LazyTime now_lazy = clock;
  scheduler.use_clock(&now_lazy);
  Counters counters;
  const Scheduler::SignDecision lazy = decide(scheduler, c, now_lazy.lower(), counters);
  if (lazy_decision(c, clock)) ++tally.lazy_decided;
  ExactTime now = now_lazy.exact();
  const ExactDecision want = decide_exact(polynomial(c), now, mpq_class(100));
  ASSERT_EQ(lazy.sign, want.sign);
  ASSERT_EQ(static_cast<bool>(lazy.exact), want.fails);
  if (want.fails) {
    ++tally.failures;
    LazyTime got = *lazy.exact;
    ExactTime w = want.failure;
    ASSERT_EQ(compare(got.exact(), w), 0);
    ASSERT_LE(got.lower(), w.upper());
    ASSERT_GE(got.upper(), w.lower());
  }
}

TEST(LazyTime, LowDegreeDecisionsEqualTheGeneralExactOnes) {
  using Family = LowDegreeMotions::Family;
  for (const Family family :
       {Family::Lines, Family::CongruentParabolas, Family::Parabolas, Family::RandomLines}) {
    const std::uint64_t seed = 20261125 + static_cast<std::uint64_t>(family);
    LowDegreeMotions gen(seed);
    Tally tally;
    std::size_t at_now = 0, second_roots = 0, tangencies = 0;
    for (int round = 0; round < 3000; ++round) {
      SCOPED_TRACE("family " + std::to_string(static_cast<int>(family)) + ", seed " +
                   std::to_string(seed) + ", round " + std::to_string(round));
      const MotionPolynomial a = gen.motion(family), b = gen.motion(family);
      // The clock: a double, a root of another pair, or a root (first or second) of this pair.
      LazyTime clock = LazyTime::point(gen.pick(-4, 4) * 0.25);
      const int kind = static_cast<int>(gen.next() % 3);
      if (kind > 0) {
        const MotionPolynomial c = kind == 1 ? gen.motion(family) : a;
        const MotionPolynomial d = kind == 1 ? gen.motion(family) : b;
        std::optional<LazyTime> root = lazy_root(Pair{&c, &d}, LazyTime::point(-50.0));
        if (!root) continue;
        if (kind == 2 && gen.next() % 2 == 0) {
          if (std::optional<LazyTime> next = lazy_root(Pair{&c, &d}, *root)) {
            root = std::move(next);
            ++second_roots;
          }
        }
        clock = std::move(*root);
        if (kind == 2) ++at_now;
      }
      const ExactPolynomial f = ExactPolynomial::difference(a, b);
      if (f.degree() == 2 && f.square_free().degree() == 1) ++tangencies;
      expect_decision_is_exact(Pair{&a, &b}, clock, tally);
      if (HasFatalFailure()) return;
    }
    EXPECT_GT(tally.failures, family == Family::RandomLines ? 300u : 500u);
    EXPECT_GT(tally.lazy_decided, 2000u);  // the lazy path was taken, not only the general one
    EXPECT_GT(at_now, 300u);
    if (family == Family::Parabolas) {
      EXPECT_GT(second_roots, 100u);
      EXPECT_GT(tangencies, 10u);
    }
  }
}

/// A function f and g = -f (the same certificate from the other side: swapped, flipped, both
/// ways) decided at a clock drawn from `gen`, a quarter-integer time or, half of the time, a root
/// of f when it has one (an instant where the certificate fails: decided there, both ways); each
/// decision as expect_decision_is_exact().
template <class C>
void expect_both_sides_exact_at_a_clock(LowDegreeMotions& gen, const C& f, const C& g,
                                        Tally& tally) {
  LazyTime clock = LazyTime::point(gen.pick(-4, 4) * 0.25);
  if (gen.next() % 2 == 0) {
    if (std::optional<LazyTime> root = lazy_root(f, LazyTime::point(-50.0))) {
      clock = std::move(*root);
      ++tally.at_root;
    }
  }
  for (const C* c : {&f, &g}) {
    expect_decision_is_exact(*c, clock, tally);
    if (::testing::Test::HasFatalFailure()) return;
  }
}

/// 3000 rounds of `round(gen, tally)`, the motions drawn from a generator seeded with `seed`
/// (printed on failure), each round deciding a function both ways
/// (expect_both_sides_exact_at_a_clock()); then the rounds must have exercised what they claim:
/// many failures, decisions taken lazily, clocks at a root.
template <class Round>
void expect_rounds_decided_exactly(std::uint64_t seed, Round&& round) {
  LowDegreeMotions gen(seed);
  Tally tally;
  for (int r = 0; r < 3000; ++r) {
    SCOPED_TRACE("seed " + std::to_string(seed) + ", round " + std::to_string(r));
    round(gen, tally);
    if (::testing::Test::HasFatalFailure()) return;
  }
  EXPECT_GT(tally.failures, 1000u);
  EXPECT_GT(tally.lazy_decided, 5000u);
  EXPECT_GT(tally.at_root, 500u);
}

TEST(LazyTime, CombinationDecisionsEqualTheGeneralExactOnes) {
  // Sides of moving boxes: (centre + half extent) - (centre' - half extent'), and other sums of
  // four motions of degree <= 2; clocks as above, roots of the same combination from either
  // side (plus and minus exchanged).
  using Family = LowDegreeMotions::Family;
  expect_rounds_decided_exactly(20261128, [](LowDegreeMotions& gen, Tally& tally) {
    const auto family = static_cast<Family>(gen.next() % 3);
    const MotionPolynomial p0 = gen.motion(family), m0 = gen.motion(family);
    const MotionPolynomial p1 = MotionPolynomial::constant(gen.pick(0, 4) * 0.25);
    const MotionPolynomial m1 = gen.next() % 2 == 0
                                    ? MotionPolynomial::constant(-gen.pick(0, 4) * 0.25)
                                    : gen.motion(family);
    const MotionCombination f{{&p0, &p1}, {&m0, &m1}};
    const MotionCombination g{{&m0, &m1}, {&p0, &p1}};  // -f
    expect_both_sides_exact_at_a_clock(gen, f, g, tally);
  });
}

TEST(LazyTime, OrientationDecisionsEqualTheGeneralExactOnes) {
  // Orientations of three points moving on lines (the hull's certificates): products of motion
  // differences, degree <= 2; small value sets make collinear instants and touching ones common.
  using Family = LowDegreeMotions::Family;
  expect_rounds_decided_exactly(20261129, [](LowDegreeMotions& gen, Tally& tally) {
    std::array<MotionPolynomial, 6> m;  // ax ay bx by cx cy
    for (MotionPolynomial& x : m) x = gen.motion(Family::Lines);
    const ProductCombination f = orientation(m[0], m[1], m[2], m[3], m[4], m[5]);
    const ProductCombination g = orientation(m[0], m[1], m[4], m[5], m[2], m[3]);  // -f
    expect_both_sides_exact_at_a_clock(gen, f, g, tally);
  });
}

TEST(LazyTime, LengthComparisonDecisionsEqualTheGeneralExactOnes) {
  // |a - b|^2 - |c - d|^2 of points moving on lines (the closest pair's certificates): sums of
  // products of motion differences, degree <= 2; small value sets make equal lengths at an
  // instant, touching ones and equal lengths for ever common. The same pair from either side.
  using Family = LowDegreeMotions::Family;
  expect_rounds_decided_exactly(20261130, [](LowDegreeMotions& gen, Tally& tally) {
    std::array<MotionPolynomial, 8> m;  // ax ay bx by cx cy dx dy
    for (MotionPolynomial& x : m) x = gen.motion(Family::Lines);
    if (gen.next() % 4 == 0) {  // congruent edges: d - c = b - a for ever
      m[4] = m[0];
      m[5] = m[1];
      m[6] = m[2];
      m[7] = m[3];
    }
    const MovingPoint2 a{&m[0], &m[1]}, b{&m[2], &m[3]}, c{&m[4], &m[5]}, d{&m[6], &m[7]};
    const LengthComparison f{{a, b, c, d}};
    const LengthComparison g{{c, d, a, b}};  // -f
    expect_both_sides_exact_at_a_clock(gen, f, g, tally);
  });
}

TEST(LazyTime, ComparisonsWithoutGmpEqualTheExactOnes) {
  // Roots of many pairs: equal roots of different pairs abound (GRIDS-like), and the roots of
  // one quadratic are met from either side (a - b, then b - a after the swap).
  using Family = LowDegreeMotions::Family;
  constexpr std::uint64_t kSeed = 20261126;
  LowDegreeMotions gen(kSeed);
  std::vector<LazyTime> times;
  for (int i = 0; i < 400; ++i) {
    const auto family = static_cast<Family>(gen.next() % 3);
    const MotionPolynomial a = gen.motion(family), b = gen.motion(family);
    std::optional<LazyTime> r = lazy_root(Pair{&a, &b}, LazyTime::point(-50.0));
    for (int k = 0; k < 2 && r; ++k) {
      times.push_back(*r);
      r = lazy_root(Pair{&b, &a}, *r);  // the same certificate from the other side: its next root
    }
  }
  std::size_t decided = 0, equal = 0, linear_pairs = 0, quadratic_pairs = 0;
  for (std::size_t i = 0; i < times.size(); ++i) {
    for (std::size_t j = 0; j < times.size(); ++j) {
      SCOPED_TRACE("seed " + std::to_string(kSeed) + ", times " + std::to_string(i) + ", " +
                   std::to_string(j));
      const std::optional<int> fast = compare_without_gmp(times[i], times[j]);
      if (!fast) continue;
      ++decided;
      if (order_by_brackets(times[i], times[j]) == 0 && times[i].root_degree() == 1 &&
          times[j].root_degree() == 1)
        ++linear_pairs;
      if (order_by_brackets(times[i], times[j]) == 0 && times[i].root_degree() == 2 &&
          times[j].root_degree() == 2)
        ++quadratic_pairs;
      LazyTime x = times[i], y = times[j];
      ExactTime ex = x.exact(), ey = y.exact();
      const int want = compare(ex, ey);
      ASSERT_EQ(*fast, want);
      if (want == 0) ++equal;
    }
  }
  EXPECT_GT(decided, times.size() * times.size() / 2);
  EXPECT_GT(equal, times.size() + 200);  // equal times of different pairs, not only i == j
  EXPECT_GT(linear_pairs, 100u);         // overlapping brackets decided by the determinant
  EXPECT_GT(quadratic_pairs, 100u);      // and by being the same root of the same quadratic
}

}  // namespace
}  // namespace kinetic
