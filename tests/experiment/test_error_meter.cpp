// The sorting experiment's error meter against its definition computed the slow way: every value
// evaluated, all n sorted, err = max_k |w_k - z_k|, and 0 when every descent of w is a pair in
// order exactly. Random orders (nearly sorted, as a robust run's; far from sorted, as a classic
// run's), equal and coincident lines, parabolas and mixed degrees, removes and inserts between
// samples, and sample sequences that switch between the meter's two paths.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "experiment/error_meter.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/predicates.hpp"

namespace kinetic::experiment {
namespace {

double brute_error(const MotionTable& m, const std::vector<std::uint32_t>& order, Time t) {
  std::vector<double> w, z;
  for (const std::uint32_t i : order) w.push_back(m.motion(i, 0).evaluate(t));
  z = w;
  std::sort(z.begin(), z.end());
  double err = 0.0;
  for (std::size_t k = 0; k < w.size(); ++k) err = std::max(err, std::fabs(w[k] - z[k]));
  if (err == 0.0) return 0.0;
  for (std::size_t k = 0; k + 1 < w.size(); ++k) {
    if (w[k] > w[k + 1] && compare_at(m.motion(order[k], 0), m.motion(order[k + 1], 0), t) > 0)
      return err;  // a descent that is one exactly
  }
  return 0.0;
}

/// Lines or parabolas whose values often coincide: integer starts and speeds scaled by 1/29 (as
/// GRIDS), some duplicated trajectories, and with `mixed` a few constants and cubics.
void fill(MotionTable& m, std::mt19937_64& rng, std::size_t n, int degree, bool mixed) {
  std::uniform_int_distribution<int> small(-6, 6);
  const double s = 1.0 / 29.0;
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<double> c;
    if (i > 0 && i % 7 == 0) {  // the previous object's trajectory again
      const MotionPolynomial& p = m.motion(m.find(static_cast<ObjectId>(i - 1))->index, 0);
      c.assign(p.c.begin(), p.c.begin() + p.degree + 1);
    } else {
      const int deg = mixed ? static_cast<int>(i % 4) : degree;
      for (int j = 0; j <= deg; ++j) c.push_back(small(rng) * s);
      if (deg > 0 && c.back() == 0.0) c.back() = s;
    }
    const MotionPolynomial p = MotionPolynomial::from(std::span<const double>(c));
    m.insert(static_cast<ObjectId>(i), std::span<const MotionPolynomial>(&p, 1));
  }
}

std::vector<std::uint32_t> true_order(const MotionTable& m, Time t) {
  std::vector<std::uint32_t> o = m.alive_indices();
  std::sort(o.begin(), o.end(), [&](std::uint32_t a, std::uint32_t b) {
    const int c = compare_at(m.motion(a, 0), m.motion(b, 0), t);
    return c != 0 ? c < 0 : a < b;
  });
  return o;
}

TEST(ErrorMeter, EqualsTheSlowDefinitionOnNearlySortedAndFarFromSortedOrders) {
  int zero_with_descents = 0;  // samples where every descent was rounding, over all inputs
  for (const std::uint64_t seed : {1u, 2u, 3u, 4u, 5u, 6u}) {
    for (const int degree : {1, 2}) {
      for (const bool mixed : {false, true}) {
        SCOPED_TRACE("seed " + std::to_string(seed) + " degree " + std::to_string(degree) +
                     (mixed ? " mixed" : ""));
        std::mt19937_64 rng(seed);
        MotionTable m(1);
        fill(m, rng, 120, degree, mixed);
        detail::ErrorMeter meter(m);
        std::uniform_int_distribution<int> tick(-58, 58);
        int positive = 0;
        for (int sample = 0; sample < 300; ++sample) {
          // Times on the grid of 1/2 (where many GRIDS lines meet) and off it.
          const Time t = sample % 3 == 0 ? tick(rng) * 0.5 : tick(rng) * 0.4375 + 1e-9 * sample;
          std::vector<std::uint32_t> order = true_order(m, t);
          const int kind = sample % 5;
          if (kind == 1 || kind == 2) {  // a few neighbours swapped: short blocks
            std::uniform_int_distribution<std::size_t> at(0, order.size() - 2);
            for (int s = 0; s < kind * 2; ++s) std::swap(order[at(rng)], order[at(rng) + 1]);
          } else if (kind == 3) {  // far from sorted: the whole order re-sorted
            std::shuffle(order.begin(), order.end(), rng);
          } else if (kind == 4) {  // a long reversed run
            std::reverse(order.begin() + 10, order.begin() + 90);
          }
          const double expected = brute_error(m, order, t);
          EXPECT_EQ(meter.error(order, t), expected) << "sample " << sample << " t " << t;
          if (expected > 0.0) ++positive;
          // not_below(): exactly the positions whose values do not increase.
          std::vector<std::size_t> nb;
          for (std::size_t k = 0; k + 1 < order.size(); ++k) {
            if (!(m.motion(order[k], 0).evaluate(t) < m.motion(order[k + 1], 0).evaluate(t)))
              nb.push_back(k);
          }
          const auto got = meter.not_below();
          EXPECT_EQ(std::vector<std::size_t>(got.begin(), got.end()), nb) << "sample " << sample;
          bool descent = false;
          for (const std::size_t k : nb) {
            descent = descent ||
                      m.motion(order[k], 0).evaluate(t) > m.motion(order[k + 1], 0).evaluate(t);
          }
          if (expected == 0.0 && descent) ++zero_with_descents;
        }
        EXPECT_GT(positive, 100);  // the comparisons are not all of zeros
      }
    }
  }
  EXPECT_GT(zero_with_descents, 0);  // the rounding rule is exercised
}

TEST(ErrorMeter, RoundingDescentsCountZeroAndRealOnesCount) {
  // Two lines that meet at t = 1/3 (not a double): near it their rounded values can descend
  // while the order is right, and the meter says 0; the wrong order says |difference|.
  MotionTable m(1);
  const MotionPolynomial a = MotionPolynomial::from({0.0, 3.0});
  const MotionPolynomial b = MotionPolynomial::from({1.0, 0.0});
  m.insert(0, std::span<const MotionPolynomial>(&a, 1));
  m.insert(1, std::span<const MotionPolynomial>(&b, 1));
  detail::ErrorMeter meter(m);
  const std::vector<std::uint32_t> ab{0, 1}, ba{1, 0};
  EXPECT_EQ(meter.error(ab, 0.0), 0.0);
  EXPECT_EQ(meter.error(ab, 2.0), 6.0 - 1.0);
  EXPECT_EQ(meter.error(ba, 0.0), 1.0);
  EXPECT_EQ(meter.error(ba, 2.0), 0.0);
  for (Time t = 1.0 / 3.0 - 4e-16; t < 1.0 / 3.0 + 4e-16; t = std::nextafter(t, 1.0)) {
    const bool a_below = compare_at(a, b, t)<0, a_above = compare_at(a, b, t)> 0;
    const std::vector<std::uint32_t>& right = a_below ? ab : ba;
    EXPECT_EQ(meter.error(right, t), 0.0) << t;
    if (a_below || a_above) {
      const std::vector<std::uint32_t>& wrong = a_below ? ba : ab;
      EXPECT_EQ(meter.error(wrong, t), std::fabs(a.evaluate(t) - b.evaluate(t))) << t;
    }
  }
}

TEST(ErrorMeter, FollowsInsertsAndRemovesOfTheTable) {
  std::mt19937_64 rng(7);
  MotionTable m(1);
  fill(m, rng, 60, 1, false);
  detail::ErrorMeter meter(m);
  for (int round = 0; round < 20; ++round) {
    SCOPED_TRACE("round " + std::to_string(round));
    const Time t = 0.25 * round - 2.0;
    std::vector<std::uint32_t> order = true_order(m, t);
    std::reverse(order.begin(), order.end());
    EXPECT_EQ(meter.error(order, t), brute_error(m, order, t));
    // Remove one object and insert another (its index is reused): the meter sees new motions.
    const std::uint32_t victim = order[static_cast<std::size_t>(round) % order.size()];
    const ObjectId id = m.id(victim);
    m.remove(m.handle(victim));
    const MotionPolynomial p = MotionPolynomial::from({0.5 * round, -1.0 + 0.1 * round});
    m.insert(id + 1000, std::span<const MotionPolynomial>(&p, 1));
  }
}

}  // namespace
}  // namespace kinetic::experiment
