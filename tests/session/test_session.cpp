// The session API against the brute-force oracle: every structure through ids, with inserts,
// flight-plan updates and removes at random times, and its misuses refused.

#include "kinetic/session/session.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "kinetic/bvh/kinetic_bvh.hpp"
#include "kinetic/closest_pair/kinetic_closest_pair.hpp"
#include "kinetic/delaunay/kinetic_delaunay.hpp"
#include "kinetic/hull/kinetic_hull.hpp"
#include "kinetic/kdtree/kinetic_kdtree.hpp"
#include "kinetic/longest_side_kdtree/longest_side_kdtree.hpp"
#include "kinetic/oracle/oracle.hpp"
#include "kinetic/range_tree/kinetic_range_tree.hpp"
#include "kinetic/segment_tree/kinetic_segment_tree.hpp"
#include "kinetic/sort/kinetic_sort.hpp"
#include "kinetic/sweep_and_prune/kinetic_sweep_and_prune.hpp"
#include "kinetic/tournament/kinetic_extent.hpp"
#include "kinetic/tournament/kinetic_tournament.hpp"

namespace kinetic {
namespace {

constexpr std::uint64_t kSeed = 20261123;

MotionPolynomial linear(double c0, double c1, Time origin = 0.0) {
  return MotionPolynomial::from(std::array<double, 2>{c0, c1}, origin);
}

/// A random linear motion per coordinate, at origin `now`.
std::vector<MotionPolynomial> random_motion(std::mt19937_64& rng, int d, Time now) {
  std::uniform_real_distribution<double> pos(0.0, 100.0), vel(-5.0, 5.0);
  std::vector<MotionPolynomial> m;
  for (int a = 0; a < d; ++a) m.push_back(linear(pos(rng), vel(rng), now));
  return m;
}

template <class S>
std::vector<ObjectId> ids_of(const Session<S>& s, const std::vector<std::uint32_t>& indices) {
  std::vector<ObjectId> ids;
  for (const std::uint32_t i : indices) ids.push_back(s.motions().id(i));
  std::sort(ids.begin(), ids.end());
  return ids;
}

/// Plays a random life on the session: n objects at the start, then at 40 random times a random
/// change (insert of a new id, update, remove), calling check() after each advance.
template <class S, class Check>
void play(Session<S>& s, int n, std::mt19937_64& rng, Check&& check) {
  for (int i = 0; i < n; ++i) s.insert(100 + i, random_motion(rng, s.dimension(), s.now()));
  ObjectId next_id = 100 + n;
  std::vector<ObjectId> alive;
  for (int i = 0; i < n; ++i) alive.push_back(100 + i);
  std::uniform_real_distribution<double> step(0.0, 0.5);
  for (int k = 0; k < 40; ++k) {
    s.advance(s.now() + step(rng));
    check();
    const int what = static_cast<int>(rng() % 3);
    if (what == 0 || alive.size() < 3) {
      s.insert(next_id, random_motion(rng, s.dimension(), s.now()));
      alive.push_back(next_id++);
    } else {
      const std::size_t j = rng() % alive.size();
      if (what == 1) {
        s.update(alive[j], random_motion(rng, s.dimension(), s.now()));
      } else {
        s.remove(alive[j]);
        alive.erase(alive.begin() + static_cast<std::ptrdiff_t>(j));
      }
    }
    check();
  }
  EXPECT_TRUE(s.validate());
  EXPECT_GT(s.simulator().counters().events(), 10u);  // the structure had work to do
}

TEST(Session, SortedMatchesTheOracle) {
  std::mt19937_64 rng(kSeed);
  Session<KineticSort> s(1, {}, 0);
  play(s, 200, rng, [&] {
    const std::vector<ObjectId> ids = s.sorted();
    ASSERT_EQ(ids.size(), s.size()) << "seed " << kSeed;
    std::vector<std::uint32_t> indices;
    for (const ObjectId id : ids) indices.push_back(s.motions().find(id)->index);
    ASSERT_TRUE(oracle::is_sorted_at(s.motions(), indices, 0, s.now()))
        << "seed " << kSeed << " t " << s.now();
  });
}

TEST(Session, TournamentTopMatchesTheOracleThroughFlightPlans) {
  std::mt19937_64 rng(kSeed + 1);
  Session<KineticTournament> s(1, {SchedulerKind::Classic, 1e-9, 0.0, kTimeInfinity}, 0,
                               Extreme::Max);
  play(s, 100, rng, [&] {
    const std::optional<ObjectId> top = s.top();
    ASSERT_TRUE(top.has_value());
    const std::uint32_t want = oracle::max_at(s.motions(), 0, s.now());
    const std::uint32_t got = s.motions().find(*top)->index;
    ASSERT_EQ(s.motions().motion(got, 0).evaluate(s.now()),
              s.motions().motion(want, 0).evaluate(s.now()))
        << "seed " << kSeed + 1 << " t " << s.now();
  });
}

TEST(Session, ExtentMatchesTheOracleThroughChanges) {
  std::mt19937_64 rng(kSeed + 20);
  Session<KineticExtent> s(3);
  EXPECT_TRUE(s.extent().empty());
  play(s, 120, rng, [&] {
    const std::vector<std::array<ObjectId, 2>> box = s.extent();
    ASSERT_EQ(box.size(), 3u);
    for (int axis = 0; axis < 3; ++axis) {
      const auto value = [&](ObjectId id) {
        return s.motions().motion(s.motions().find(id)->index, axis).evaluate(s.now());
      };
      const std::uint32_t lo = oracle::min_at(s.motions(), axis, s.now());
      const std::uint32_t hi = oracle::max_at(s.motions(), axis, s.now());
      ASSERT_EQ(value(box[static_cast<std::size_t>(axis)][0]),
                s.motions().motion(lo, axis).evaluate(s.now()))
          << "seed " << kSeed + 20 << " t " << s.now() << " axis " << axis;
      ASSERT_EQ(value(box[static_cast<std::size_t>(axis)][1]),
                s.motions().motion(hi, axis).evaluate(s.now()))
          << "seed " << kSeed + 20 << " t " << s.now() << " axis " << axis;
    }
  });
}

TEST(Session, CountersFillInTheCertificates) {
  Session<KineticSort> s(1, {}, 0);
  for (int i = 0; i < 10; ++i) s.insert(i, {linear(i, -i)});
  s.advance(5.0);
  const Counters& c = s.counters();
  EXPECT_EQ(c.certificates_alive, 9u);  // one per adjacent pair
  EXPECT_GE(c.certificates_alive_max, 9u);
  EXPECT_GE(c.certificates_per_object_max, 1u);
  EXPECT_EQ(c.events(), 45u);  // every pair of the 10 lines crosses once before t = 5
}

TEST(Session, AnAdvanceToAnInfiniteTimeIsRefused) {
  for (const SchedulerKind k : {SchedulerKind::Classic, SchedulerKind::Exact}) {
    Session<KineticSort> s(1, {k, 1e-9, 0.0, kTimeInfinity}, 0);  // no horizon: only t decides
    s.insert(1, {linear(0, 1)});
    s.insert(2, {linear(1, -1)});
    EXPECT_THROW(s.advance(kTimeInfinity), PreconditionError);
    EXPECT_THROW(s.advance(-kTimeInfinity), PreconditionError);
    EXPECT_EQ(s.now(), 0.0);
    s.advance(2.0);  // still usable
    EXPECT_EQ(s.sorted(), (std::vector<ObjectId>{2, 1}));
  }
}

TEST(Session, AnInterruptStopsAnAdvanceAndTheSessionGoesOn) {
  Session<KineticSort> s(1, {}, 0);
  for (int i = 0; i < 50; ++i) s.insert(i, {linear(i, -i)});  // all cross by t = 1
  std::atomic<bool> stop{true};
  s.set_interrupt(&stop);
  EXPECT_THROW(s.advance(10.0), SessionInterrupted);
  EXPECT_LT(s.now(), 10.0);
  EXPECT_EQ(s.simulator().counters().events(), 0u);  // raised before the first event
  EXPECT_TRUE(s.validate());
  stop = false;
  s.advance(10.0);
  EXPECT_EQ(s.now(), 10.0);
  EXPECT_EQ(s.simulator().counters().events(), 50u * 49u / 2u);
  std::vector<ObjectId> want;
  for (int i = 49; i >= 0; --i) want.push_back(i);
  EXPECT_EQ(s.sorted(), want);
}

template <class Tree>
void check_box_range(std::uint64_t seed, int d) {
  std::mt19937_64 rng(seed);
  Session<Tree> s(d);
  std::uniform_real_distribution<double> corner(-20.0, 120.0), side(0.0, 60.0);
  play(s, 150, rng, [&] {
    Box box;
    for (int a = 0; a < d; ++a) {
      const double lo = corner(rng);
      box.push_back({lo, lo + side(rng)});
    }
    ASSERT_EQ(s.range(box), ids_of(s, oracle::in_box_at(s.motions(), box, s.now())))
        << "seed " << seed << " t " << s.now();
  });
}

TEST(Session, HullMatchesTheOracle) {
  for (const SchedulerKind kind :
       {SchedulerKind::Robust, SchedulerKind::Classic, SchedulerKind::Exact}) {
    std::mt19937_64 rng(kSeed + 7);
    Session<KineticHull> s(2, {kind, 1e-9, 0.0, kTimeInfinity});
    play(s, 120, rng, [&] {
      std::vector<ObjectId> want;
      for (const std::uint32_t i : oracle::hull_at(s.motions(), s.now()))
        want.push_back(s.motions().id(i));
      ASSERT_EQ(s.hull(), want) << "seed " << kSeed + 7 << " " << to_string(kind) << " t "
                                << s.now();
    });
  }
  // The hull takes motions of degree <= 3: a quartic is refused with its id, the session intact.
  Session<KineticHull> s(2);
  s.insert(1, {MotionPolynomial::from({0.0, 1.0}), MotionPolynomial::from({0.0})});
  s.advance(1.0);
  EXPECT_THROW(s.insert(2, {MotionPolynomial::from({0.0, 0.0, 0.0, 0.0, 1.0}),
                            MotionPolynomial::from({0.0})}),
               PreconditionError);
  EXPECT_FALSE(s.contains(2));
  EXPECT_EQ(s.hull(), std::vector<ObjectId>{1});
  s.insert(3, {MotionPolynomial::from({1.0, 0.0, 0.0, 1.0}), MotionPolynomial::from({1.0})});
  EXPECT_THROW(s.update(3, {MotionPolynomial::from({0.0, 0.0, 0.0, 0.0, 1.0}),
                            MotionPolynomial::from({0.0})}),
               PreconditionError);
  EXPECT_TRUE(s.validate());
  EXPECT_EQ(s.hull(), (std::vector<ObjectId>{1, 3}));
}

TEST(Session, SweepAndPruneCollidingPairsMatchTheOracle) {
  // Two boxes sliding onto a third; a negative half extent is refused with its id and axis, the
  // session intact.
  Session<KineticSweepAndPrune> s(boxes_table_dimension(2));
  const auto box = [](double x, double v, double y, double hx, double hy) {
    return std::vector<MotionPolynomial>{MotionPolynomial::from({x, v}),
                                         MotionPolynomial::from({y}), MotionPolynomial::from({hx}),
                                         MotionPolynomial::from({hy})};
  };
  s.insert(1, box(0, 1, 0, 1, 1));
  s.insert(2, box(10, -1, 1.5, 1, 1));
  s.insert(3, box(5, 0, 10, 1, 1));
  EXPECT_TRUE(s.at(1.0).colliding_pairs().empty());
  EXPECT_EQ(s.at(4.5).colliding_pairs(), (std::vector<std::array<ObjectId, 2>>{{1, 2}}));
  EXPECT_THROW(s.insert(4, box(0, 0, 0, -1, 1)), PreconditionError);
  EXPECT_FALSE(s.contains(4));
  EXPECT_THROW(s.update(3, {MotionPolynomial::from({5.0}), MotionPolynomial::from({10.0}),
                            MotionPolynomial::from({1.0}), MotionPolynomial::from({0.0, 1.0})}),
               PreconditionError);
  s.update(3, box(5.5, 0, 1, 1, 1));  // jumps onto boxes 1 and 2
  EXPECT_TRUE(s.validate());
  const std::vector<std::array<ObjectId, 2>> want{{1, 2}, {1, 3}, {2, 3}};
  EXPECT_EQ(s.colliding_pairs(), want);
  std::vector<std::array<ObjectId, 2>> oracle;
  for (const auto& p : oracle::colliding_pairs_at(s.motions(), s.now()))
    oracle.push_back({s.motions().id(p[0]), s.motions().id(p[1])});
  EXPECT_EQ(oracle, want);
}

TEST(Session, BvhCollidingPairsMatchTheOracle) {
  // Boxes on an integer grid moving onto each other; a bad half extent refused, session intact.
  Session<KineticBvh> s(boxes_table_dimension(3));
  std::mt19937_64 rng(kSeed + 11);
  for (ObjectId id = 0; id < 40; ++id) {
    std::vector<MotionPolynomial> m;
    for (int k = 0; k < 3; ++k) {
      m.push_back(MotionPolynomial::from(
          {static_cast<double>(rng() % 9), static_cast<double>(rng() % 3) - 1.0}));
    }
    for (int k = 0; k < 3; ++k)
      m.push_back(MotionPolynomial::from({0.5 * static_cast<double>(rng() % 3)}));
    s.insert(id, m);
  }
  EXPECT_THROW(s.insert(99, {MotionPolynomial::from({0.0}), MotionPolynomial::from({0.0}),
                             MotionPolynomial::from({0.0}), MotionPolynomial::from({1.0}),
                             MotionPolynomial::from({-1.0}), MotionPolynomial::from({1.0})}),
               PreconditionError);
  EXPECT_FALSE(s.contains(99));
  for (const Time t : {0.25, 1.75, 2.5, 3.3}) {
    s.advance(t);
    std::vector<std::array<ObjectId, 2>> want;
    for (const auto& p : oracle::colliding_pairs_at(s.motions(), t))
      want.push_back({s.motions().id(p[0]), s.motions().id(p[1])});
    EXPECT_EQ(s.colliding_pairs(), want) << "t " << t;
    EXPECT_TRUE(s.validate());
  }
}

TEST(Session, KdTreeRangeMatchesTheOracle) { check_box_range<KineticKdTree>(kSeed + 2, 2); }
TEST(Session, RangeTreeRangeMatchesTheOracle) { check_box_range<KineticRangeTree>(kSeed + 3, 3); }
TEST(Session, LongestSideKdTreeRangeMatchesTheOracle) {
  check_box_range<LongestSideKdTree>(kSeed + 4, 2);
}

TEST(Session, LongestSideKdTreeNearestIsWithinOnePlusEps) {
  std::mt19937_64 rng(kSeed + 5);
  Session<LongestSideKdTree> s(2);
  std::uniform_real_distribution<double> coord(0.0, 100.0);
  const double eps = 0.1;
  play(s, 120, rng, [&] {
    const Point2 q{coord(rng), coord(rng)};
    const std::optional<ObjectId> got = s.nearest(q, eps);
    ASSERT_TRUE(got.has_value());
    const std::array<double, 2> qq{q[0], q[1]};
    const double best = oracle::nearest_distance_at(s.motions(), qq, s.now());
    const double d = oracle::distance_at(s.motions(), s.motions().find(*got)->index, qq, s.now());
    ASSERT_LE(d, (1.0 + eps) * best * (1.0 + 1e-12) + 1e-12) << "seed " << kSeed + 5;
  });
}

TEST(Session, SegmentTreeStabMatchesTheOracle) {
  std::mt19937_64 rng(kSeed + 6);
  Session<KineticSegmentTree> s(2);
  // Intervals [c - w(t), c + w(t)] whose centres move and whose half widths stay positive.
  std::uniform_real_distribution<double> centre(0.0, 100.0), vel(-3.0, 3.0), width(1.0, 15.0);
  const auto interval = [&](Time now) {
    const double c = centre(rng), v = vel(rng), w = width(rng);
    return std::vector<MotionPolynomial>{linear(c - w, v, now), linear(c + w, v, now)};
  };
  for (int i = 0; i < 150; ++i) s.insert(i, interval(0.0));
  std::uniform_real_distribution<double> x(-20.0, 120.0), step(0.0, 0.5);
  for (int k = 0; k < 40; ++k) {
    s.advance(s.now() + step(rng));
    const double q = x(rng);
    ASSERT_EQ(s.stab(q), ids_of(s, oracle::stab_at(s.motions(), q, s.now())))
        << "seed " << kSeed + 6 << " t " << s.now();
    s.update(static_cast<ObjectId>(rng() % 150), interval(s.now()));
  }
  EXPECT_TRUE(s.validate());
}

/// Runs f and returns the message of the PreconditionError it throws ("" when none).
template <class F>
std::string refused(F&& f) {
  try {
    f();
  } catch (const PreconditionError& e) {
    return e.what();
  }
  return "";
}

TEST(Session, MisusesAreRefusedWithWhatWasWrong) {
  Session<KineticKdTree> s(2, {SchedulerKind::Robust, 1e-9, 0.0, 10.0});
  s.insert(1, {linear(0.0, 1.0), linear(0.0, 0.0)});
  s.insert(2, {linear(5.0, -1.0), linear(0.0, 0.0)});
  s.advance(2.0);
  const auto has = [](const std::string& m, const char* needle) {
    return m.find(needle) != std::string::npos;
  };
  EXPECT_TRUE(has(refused([&] { s.advance(1.0); }), "before the session's time 2"));
  EXPECT_TRUE(has(refused([&] { s.advance(11.0); }),
                  "Session::advance: t = 11 is after the scheduler's horizon 10"));
  EXPECT_TRUE(has(refused([&] {
                    s.update(3, {linear(0, 0), linear(0, 0)});
                  }),
                  "no object with id 3"));
  EXPECT_TRUE(has(refused([&] { s.remove(3); }), "no object with id 3"));
  EXPECT_TRUE(has(refused([&] {
                    s.insert(1, {linear(0, 0), linear(0, 0)});
                  }),
                  "Session::insert: id 1 is present"));
  EXPECT_TRUE(has(refused([&] { s.insert(4, {linear(0, 0)}); }),
                  "Session::insert: 1 coordinates for a table of dimension 2"));
  EXPECT_TRUE(has(refused([&] { (void)s.range(Box{{0.0, 1.0}}); }), "the box has 1 axis"));
  // A box inside out on an axis is refused, not answered with nothing.
  EXPECT_TRUE(has(refused([&] { (void)s.range(Box{{0.0, 1.0}, {3.0, 1.0}}); }),
                  "the box's interval on axis 1 is [3, 1]: lo > hi"));
  EXPECT_EQ(s.size(), 2u);
  // The session is still usable and right after every refusal.
  EXPECT_EQ(s.range(Box{{1.5, 3.5}, {-1.0, 1.0}}), (std::vector<ObjectId>{1, 2}));
  EXPECT_EQ(s.at(4.0).range(Box{{3.5, 4.5}, {-1.0, 1.0}}), (std::vector<ObjectId>{1}));
  EXPECT_EQ(s.now(), 4.0);
  EXPECT_TRUE(has(refused([] {
                    Session<KineticSort> bad(1, {SchedulerKind::Robust, 0.0}, 0);
                  }),
                  "eps = 0"));
}

TEST(Session, AdvancingPastWhatRobustSchedulingReachesIsRefused) {
  // Robust scheduling at eps = 1e-9 finds events up to Scheduler::max_supported_time(1e-9),
  // about 2.6e5. Two points that cross at t = 5e5: advancing to 1e6 would give the old order
  // with no event and no error; it is refused, and the session stays usable before the limit.
  const Time limit = Scheduler::max_supported_time(1e-9);
  ASSERT_GT(limit, 2e5);
  ASSERT_LT(limit, 5e5);
  Session<KineticSort> s(1, {}, 0);
  s.insert(1, {linear(0.0, 2e-5)});  // 2e-5 t
  s.insert(2, {linear(5.0, 1e-5)});  // 5 + 1e-5 t: they meet at t = 5e5
  const std::string m = refused([&] { s.advance(1e6); });
  EXPECT_NE(m.find("Session::advance: t = 1e+06 is after the scheduler's horizon"),
            std::string::npos)
      << m;
  EXPECT_NE(m.find("max_supported_time"), std::string::npos) << m;
  s.advance(limit);
  EXPECT_EQ(s.sorted(), (std::vector<ObjectId>{1, 2}));
  // A larger eps reaches the crossing, and the order is right after it.
  Session<KineticSort> wide(1, {SchedulerKind::Robust, 1e-3}, 0);
  wide.insert(1, {linear(0.0, 2e-5)});
  wide.insert(2, {linear(5.0, 1e-5)});
  ASSERT_GT(Scheduler::max_supported_time(1e-3), 1e6);
  EXPECT_EQ(wide.at(1e6).sorted(), (std::vector<ObjectId>{2, 1}));
  // Classic scheduling has no such limit.
  Session<KineticSort> classic(1, {SchedulerKind::Classic}, 0);
  classic.insert(1, {linear(0.0, 2e-5)});
  classic.insert(2, {linear(5.0, 1e-5)});
  EXPECT_EQ(classic.at(1e6).sorted(), (std::vector<ObjectId>{2, 1}));
}

TEST(Session, ANaNTimeOrAStartBeyondRobustReachIsRefused) {
  Session<KineticSort> s(1, {}, 0);
  s.insert(1, {linear(0.0, 1.0)});
  EXPECT_NE(refused([&] { s.advance(std::nan("")); }).find("Session::advance: t is NaN"),
            std::string::npos);
  EXPECT_NE(refused([] {
              Session<KineticSort> far(1, {SchedulerKind::Robust, 1e-9, 1e6}, 0);
            }).find("start time 1e+06 is outside the times robust scheduling supports"),
            std::string::npos);
  EXPECT_EQ(refused([] {
              Session<KineticSort> far(1, {SchedulerKind::Classic, 1e-9, 1e6}, 0);
            }),
            "");
}

TEST(Session, UpdateWithTheWrongNumberOfCoordinatesIsRefused) {
  Session<KineticKdTree> s(2);
  s.insert(1, {linear(0.0, 1.0), linear(0.0, 0.0)});
  EXPECT_NE(refused([&] {
              s.update(1, {linear(0.0, 1.0)});
            }).find("Session::update: 1 coordinates for a table of dimension 2"),
            std::string::npos);
  EXPECT_EQ(s.at(1.0).range(Box{{0.5, 1.5}, {-1.0, 1.0}}), (std::vector<ObjectId>{1}));
}

}  // namespace
}  // namespace kinetic

namespace kinetic {
namespace {

// The hardening issue, defect 6: points whose coordinates are about 1e-300 at the query time
// while their coefficients are about 1e149 (x(t) = c + 1e149 t - 1e149 t^2: the terms cancel
// exactly at t = 1). The filtered distances carry errors of about 1e133, so the exact nearest
// (eps = 0) and farthest are decided from the exact squared distances; the oracle, too, computes
// distances without underflow.
TEST(Session, LongestSideKdTreeNearestAndFarthestAtExtremeScales) {
  const auto cancelling = [](double c) {
    return MotionPolynomial::from({c, 1e149, -1e149});  // c at t = 0 and at t = 1
  };
  const MotionPolynomial zero = MotionPolynomial::from({0.0});
  for (const SchedulerKind kind :
       {SchedulerKind::Robust, SchedulerKind::Classic, SchedulerKind::Exact}) {
    Session<LongestSideKdTree> s(2, {kind});
    s.insert(5, {cancelling(3e-300), zero});   // 3e-300 from q = (0, 0) at t = 1
    s.insert(9, {cancelling(1e-300), zero});   // 1e-300: the nearest
    s.insert(7, {cancelling(-2e-300), zero});  // 2e-300
    s.insert(4, {cancelling(-5e-300), zero});  // 5e-300: the farthest
    s.advance(1.0);
    EXPECT_EQ(s.nearest({0.0, 0.0}, 0.0), std::optional<ObjectId>(9)) << to_string(kind);
    EXPECT_EQ(s.farthest({0.0, 0.0}, 0.0), std::optional<ObjectId>(4)) << to_string(kind);
    // The oracle agrees (its squared distances used to underflow to 0).
    const std::array<double, 2> q{0.0, 0.0};
    EXPECT_EQ(oracle::nearest_distance_at(s.motions(), q, 1.0), 1e-300);
    EXPECT_EQ(oracle::farthest_distance_at(s.motions(), q, 1.0), 5e-300);
    EXPECT_TRUE(s.validate());
  }
}

}  // namespace
}  // namespace kinetic

namespace kinetic {
namespace {

// An interval that would turn inside out (right end below its left end) is refused before the
// table changes, as the scenario reader refuses it; the session stays usable and right.
TEST(Session, ASegmentTreeIntervalThatTurnsInsideOutIsRefused) {
  Session<KineticSegmentTree> s(2);
  s.insert(1, {linear(0.0, 0.0), linear(4.0, 0.0)});  // [0, 4]
  const std::string m = refused([&] {
    s.insert(2, {linear(0.0, 1.0), linear(2.0, -1.0)});  // [t, 2 - t]: inside out after t = 1
  });
  EXPECT_NE(m.find("Session::insert: the interval is inside out (right end below its left end)"),
            std::string::npos)
      << m;
  EXPECT_FALSE(s.contains(2));
  s.advance(0.5);
  EXPECT_NE(refused([&] {
              s.update(1, {linear(3.0, 0.0, 0.5), linear(1.0, 0.0, 0.5)});  // [3, 1] now
            }).find("Session::update: the interval is inside out"),
            std::string::npos);
  // A growing interval and one that only touches (a point) are fine.
  s.insert(3, {linear(1.0, -1.0, 0.5), linear(1.0, 1.0, 0.5)});
  s.insert(4, {linear(2.0, 0.0, 0.5), linear(2.0, 0.0, 0.5)});
  EXPECT_EQ(s.at(1.0).stab(2.0), (std::vector<ObjectId>{1, 4}));
  EXPECT_EQ(s.stab(1.4), (std::vector<ObjectId>{1, 3}));
  EXPECT_TRUE(s.validate());
}

}  // namespace
}  // namespace kinetic

namespace kinetic {
namespace {

// The Delaunay triangulation through the session (the example of docs/library.md): a point rises
// through the triangle of three others; its triangles, the closest pair and the nearest point
// at two times, worked out by hand, under the exact and the robust scheduler (the times are far
// from the flip). The classic scheduler is refused with the reason, and so is a parabola under
// the robust one, before the session changes.
void delaunay_by_hand(SchedulerKind kind) {
  SCOPED_TRACE(to_string(kind));
  Session<KineticDelaunay> s(2, {kind, 1e-9, 0.0, kTimeInfinity});
  s.insert(1, {MotionPolynomial::from({0.0}), MotionPolynomial::from({0.0})});
  s.insert(2, {MotionPolynomial::from({4.0}), MotionPolynomial::from({0.0})});
  s.insert(3, {MotionPolynomial::from({2.0}), MotionPolynomial::from({3.0})});
  s.insert(4, {MotionPolynomial::from({2.0}), MotionPolynomial::from({-3.0, 1.0})});
  using Triangles = std::vector<std::array<ObjectId, 3>>;
  // t = 1: 4 at (2, -2); the circle through 1, 4, 2 (centre (2, 0), radius 2) leaves 3 out.
  EXPECT_EQ(s.at(1.0).delaunay(), (Triangles{{1, 2, 3}, {1, 4, 2}}));
  EXPECT_EQ(s.closest_pair(), (std::array<ObjectId, 2>{1, 4}));
  // t = 5: 4 at (2, 2), inside the triangle 1, 2, 3.
  EXPECT_EQ(s.at(5.0).delaunay(), (Triangles{{1, 2, 4}, {1, 4, 3}, {2, 3, 4}}));
  EXPECT_EQ(s.closest_pair(), (std::array<ObjectId, 2>{3, 4}));
  EXPECT_EQ(s.nearest({2.0, 1.0}, 0.0), std::optional<ObjectId>{4});
  EXPECT_TRUE(s.validate());
  if (kind == SchedulerKind::Robust) {
    EXPECT_THROW(
        s.insert(5, {MotionPolynomial::from({1.0, 0.0, 1.0}), MotionPolynomial::from({1.0})}),
        PreconditionError);
    EXPECT_EQ(s.size(), 4u);
    EXPECT_TRUE(s.validate());
  }
}

TEST(Session, DelaunayTrianglesClosestPairAndNearest) {
  delaunay_by_hand(SchedulerKind::Exact);
  delaunay_by_hand(SchedulerKind::Robust);
  EXPECT_THROW(Session<KineticDelaunay>(2, {SchedulerKind::Classic, 1e-9, 0.0, kTimeInfinity}),
               PreconditionError);
}

// The kinetic closest pair through the session: the same points, its answer kept by the
// tournament over the Delaunay edges; its triangulation answers too.
TEST(Session, ClosestPairFollowsTheMovingPoint) {
  Session<KineticClosestPair> s(2, {SchedulerKind::Exact, 1e-9, 0.0, kTimeInfinity});
  s.insert(1, {MotionPolynomial::from({0.0}), MotionPolynomial::from({0.0})});
  s.insert(2, {MotionPolynomial::from({4.0}), MotionPolynomial::from({0.0})});
  s.insert(3, {MotionPolynomial::from({2.0}), MotionPolynomial::from({3.0})});
  s.insert(4, {MotionPolynomial::from({2.0}), MotionPolynomial::from({-3.0, 1.0})});
  // t = 1: 4 at (2, -2), at distance sqrt 8 from 1 and 2: the smaller ids, (1, 4).
  EXPECT_EQ(s.at(1.0).closest_pair(), (std::array<ObjectId, 2>{1, 4}));
  // t = 2.5: 4 at (2, -0.5): 1 and 2 at sqrt 4.25, 3 at 3.5.
  EXPECT_EQ(s.at(2.5).closest_pair(), (std::array<ObjectId, 2>{1, 4}));
  // t = 5: 4 at (2, 2), 1 from 3.
  EXPECT_EQ(s.at(5.0).closest_pair(), (std::array<ObjectId, 2>{3, 4}));
  s.remove(3);
  EXPECT_EQ(s.closest_pair(), (std::array<ObjectId, 2>{1, 4}));
  EXPECT_TRUE(s.validate());
  EXPECT_GT(s.structure().counters().events, 0u);
  EXPECT_THROW(Session<KineticClosestPair>(2, {SchedulerKind::Classic, 1e-9, 0.0, kTimeInfinity}),
               PreconditionError);
}

}  // namespace
}  // namespace kinetic
