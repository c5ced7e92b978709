// The event queue's exact order and the simulator's exact clock (the exact scheduler's queue,
// docs/exact-design.md): events come out by their exact times (roots isolated exactly, rational
// points, the same algebraic number from different polynomials), equal times in scheduling order;
// advance_to() stops exactly at its target even between two doubles' worth of events; groups of
// events at one exact time are counted. Fixed seeds, printed on failure.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "kinetic/core/event_queue.hpp"
#include "kinetic/core/exact_time.hpp"
#include "kinetic/core/polynomial.hpp"
#include "kinetic/core/simulator.hpp"

namespace kinetic {
namespace {

ExactPolynomial poly(std::vector<mpq_class> c) { return ExactPolynomial(std::move(c)); }

/// Exact times in [0, 10]: roots of random cubics, their duplicates written with another factor
/// (the same number, a different polynomial), and rational points (doubles).
std::vector<ExactTime> times(std::mt19937_64& rng) {
  std::vector<ExactTime> out;
  for (int i = 0; i < 25; ++i) {
    std::vector<mpq_class> c;
    for (int k = 0; k <= 3; ++k) c.emplace_back(static_cast<long>(rng() % 41) - 20);
    const ExactPolynomial f = poly(c);
    if (f.degree() < 1) continue;
    for (const ExactTime& t : isolate_roots(f, 0, 10)) out.push_back(t);
    // The same roots from f (t + 1) (a different polynomial, other intervals).
    for (const ExactTime& t : isolate_roots(f * poly({1, 1}), -1, 10)) {
      if (t.hi() > 0) out.push_back(t);
    }
  }
  for (int i = 0; i < 30; ++i) {
    out.push_back(ExactTime::point(rational(static_cast<double>(rng() % 80) / 8.0)));
  }
  return out;
}

TEST(EventQueueExact, PopsInExactOrderThenSchedulingOrder) {
  constexpr std::uint64_t kSeed = 51;
  std::mt19937_64 rng(kSeed);
  std::vector<ExactTime> all = times(rng);
  ASSERT_GT(all.size(), 60u);
  std::shuffle(all.begin(), all.end(), rng);
  EventQueue q;
  std::vector<EventHandle> handles;
  for (std::uint32_t i = 0; i < all.size(); ++i) {
    handles.push_back(q.push_exact(all[i], 0, i));  // payload: the index (push order)
    ASSERT_TRUE(q.validate());
  }
  // A few removed, a few pushed as doubles (the rationals they are).
  for (std::uint32_t i = 0; i < all.size(); i += 7) {
    q.remove(handles[i]);
    ASSERT_TRUE(q.validate());
  }
  const auto payload_base = static_cast<std::uint32_t>(all.size());
  for (std::uint32_t i = 0; i < 10; ++i) {
    all.push_back(ExactTime::point(rational(static_cast<double>(i))));
    (void)q.push(static_cast<double>(i), 0, payload_base + i);
  }
  std::vector<bool> removed(all.size(), false);
  for (std::uint32_t i = 0; i < payload_base; i += 7) removed[i] = true;
  std::size_t expected = 0;
  for (bool r : removed) expected += r ? 0 : 1;
  ExactTime previous;
  std::uint32_t previous_payload = 0;
  std::size_t popped = 0, ties = 0;
  while (!q.empty()) {
    LazyTime lazy;
    const Event e = q.pop(&lazy);
    ExactTime& at = lazy.exact();
    ASSERT_TRUE(q.validate());
    ASSERT_FALSE(removed[e.payload]) << "seed " << kSeed;
    ExactTime mine = all[e.payload];
    EXPECT_EQ(compare(at, mine), 0);
    EXPECT_LE(e.time, mine.hi().get_d());  // Event::time at or below the exact time
    if (popped > 0) {
      const int c = compare(previous, at);
      EXPECT_LE(c, 0) << "seed " << kSeed << " pop " << popped;
      if (c == 0) {
        ++ties;
        // Equal times in scheduling order: the later push has the larger payload here, except
        // the doubles pushed after the exact ones.
        EXPECT_TRUE(previous_payload < e.payload || previous_payload >= payload_base);
      }
    }
    previous = at;
    previous_payload = e.payload;
    ++popped;
  }
  EXPECT_EQ(popped, expected);
  EXPECT_GT(ties, 10u);  // the duplicated roots and points
  EXPECT_GT(q.exact_comparisons(), 0u);
}

struct Recorder {
  std::vector<std::uint32_t> order;
  EventKind process(const Event& e) {
    order.push_back(e.payload);
    return EventKind::Internal;
  }
};

TEST(EventQueueExact, TheClockStopsExactlyAtItsTarget) {
  // sqrt(2) lies strictly between two adjacent doubles b < sqrt(2) < a.
  const double b = 1.4142135623730949, a = std::nextafter(b, 2.0);
  const ExactTime root2 = isolate_roots(poly({-2, 0, 1}), 1, 2)[0];
  ASSERT_GT(mpq_class(a) * mpq_class(a), 2);
  ASSERT_LT(mpq_class(b) * mpq_class(b), 2);
  Simulator sim(0.0);
  Recorder r;
  (void)sim.schedule(0.0, ExactFailure(LazyTime::of(ExactTime::point(rational(a)))), 0, 3);
  (void)sim.schedule(0.0, ExactFailure(LazyTime::of(root2)), 0, 2);
  (void)sim.schedule(0.0, ExactFailure(LazyTime::of(ExactTime::point(rational(b)))), 0, 1);
  // sqrt(2) again, as a root of (t^2 - 2)(t - 5), and 1 as a root of t - 1.
  (void)sim.schedule(0.0, ExactFailure(LazyTime::of(isolate_roots(poly({10, -2, -5, 1}), 0, 3)[0])),
                     0, 4);
  (void)sim.schedule(0.0, ExactFailure(LazyTime::of(isolate_roots(poly({-1, 1}), 0, 3)[0])), 0, 0);
  ASSERT_EQ(sim.advance_to(b, r), AdvanceOutcome::Reached);
  EXPECT_EQ(r.order, (std::vector<std::uint32_t>{0, 1}));
  EXPECT_EQ(sim.now(), b);
  ASSERT_EQ(sim.advance_to(b, r), AdvanceOutcome::Reached);  // nothing between
  EXPECT_EQ(r.order.size(), 2u);
  ASSERT_EQ(sim.process_next(r), AdvanceOutcome::Reached);  // sqrt(2), pushed as 2
  ASSERT_EQ(sim.process_next(r), AdvanceOutcome::Reached);  // sqrt(2), pushed as 4
  EXPECT_EQ(r.order, (std::vector<std::uint32_t>{0, 1, 2, 4}));
  ExactTime now = sim.exact_now().exact();
  ExactTime want = root2;
  EXPECT_EQ(compare(now, want), 0);
  EXPECT_EQ(sim.counters().equal_time_groups, 1u);
  EXPECT_LE(sim.now(), b);  // a double at or below the exact time (sqrt(2) is not one)
  ASSERT_EQ(sim.advance_to(a, r), AdvanceOutcome::Reached);
  EXPECT_EQ(r.order, (std::vector<std::uint32_t>{0, 1, 2, 4, 3}));
  EXPECT_EQ(sim.counters().events_in_past, 0u);
  EXPECT_EQ(sim.counters().equal_time_groups, 1u);
}

/// The exact order kept through the ladder's tiers (heap, calendar, far: split by keys, the
/// lower doubles of the exact times) and the tie classes (events found equal ordered by their
/// sequence without arithmetic), over a long run of pushes, removes and pops as a simulation
/// makes them: linear roots with small denominators (many equal times that are not doubles,
/// from different pairs), some nudged (distinct times within one bracket), points, slots reused.
/// Every pop is at or after the one before, equal times in push order; the queue validates; classes
/// are renumbered along the way.
TEST(EventQueueExact, TiersAndTieClassesKeepTheExactOrder) {
  constexpr std::uint64_t kSeed = 20261128;
  std::mt19937_64 rng(kSeed);
  auto pick = [&](int lo, int hi) {
    return static_cast<double>(lo +
                               static_cast<int>(rng() % static_cast<std::uint64_t>(hi - lo + 1)));
  };
  EventQueue q;
  q.use_exact_order();
  std::vector<LazyTime> time_of;       // by payload
  std::vector<EventHandle> handle_of;  // by payload
  std::vector<std::uint32_t> live;     // payloads queued
  LazyTime now = LazyTime::point(-1.0);
  std::optional<LazyTime> previous;
  std::uint32_t previous_payload = 0;
  std::size_t pops = 0, ties = 0, roots = 0;
  for (int step = 0; step < 120000; ++step) {
    SCOPED_TRACE("seed " + std::to_string(kSeed) + ", step " + std::to_string(step));
    const double op = pick(0, 19);
    if (op < 11 || q.empty()) {
      // A linear root after now (motions about o = floor(now), denominators up to 6: many
      // equal times that are not doubles), else a point.
      const double o = std::floor(now.lower());
      // (one in four nudged by a few units of 2^-50: distinct times within one double's
      // bracket, which only exact arithmetic orders)
      const double nudge = rng() % 4 == 0 ? pick(-2, 2) * 0x1p-50 : 0.0;
      const MotionPolynomial a =
          MotionPolynomial::from({pick(0, 40) * 0.5 + nudge, pick(-3, 3)}, o);
      const MotionPolynomial b = MotionPolynomial::from({pick(0, 40) * 0.5, pick(-3, 3)}, o);
      std::optional<LowDegreeDecision> d = decide_low_degree(a, b, now);
      if (d && !d->fails) d = decide_low_degree(b, a, now);
      LazyTime t = LazyTime::point(std::ceil(now.upper()) + pick(0, 40) * 0.25);
      if (d && d->fails) {
        t = std::move(d->failure);
        ++roots;
      }
      const auto payload = static_cast<std::uint32_t>(time_of.size());
      time_of.push_back(t);
      handle_of.push_back(q.push_exact(std::move(t), 0, payload));
      live.push_back(payload);
    } else if (op < 13) {
      const std::size_t k = rng() % live.size();
      const std::uint32_t payload = live[k];
      if (q.contains(handle_of[payload])) q.remove(handle_of[payload]);
      live[k] = live.back();
      live.pop_back();
    } else {
      LazyTime t;
      const Event e = q.pop(&t);
      ASSERT_EQ(compare(t, time_of[e.payload]), 0);
      if (previous) {
        const int c = compare(*previous, t);
        ASSERT_LE(c, 0);
        if (c == 0) {
          ++ties;
          ASSERT_LT(previous_payload, e.payload);  // equal times in push order
        }
      }
      previous = t;
      previous_payload = e.payload;
      now = std::move(t);
      live.erase(std::find(live.begin(), live.end(), e.payload));
      ++pops;
    }
    if (step % 997 == 0) {
      ASSERT_TRUE(q.validate());
    }
  }
  ASSERT_TRUE(q.validate());
  EXPECT_GT(pops, 40000u);
  EXPECT_GT(roots, 20000u);
  EXPECT_GT(ties, 2000u);
  // The tie classes answered most comparisons of equal times: the exact ones are fewer than
  // the ties the pops met.
  EXPECT_GT(q.exact_comparisons(), 0u);
  EXPECT_LT(q.exact_comparisons(), 4 * pops);
}

}  // namespace
}  // namespace kinetic
