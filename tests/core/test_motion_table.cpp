// The motion table: insert / remove / update / find, stale handles (after remove and after index
// reuse), alive_indices, capacity, motion_changes and max_degree; plus a deterministic random run
// against a std::map model.

#include "kinetic/core/motion_table.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <random>
#include <vector>

namespace kinetic {
namespace {

std::vector<MotionPolynomial> motion2(double x0, double vx, double y0, int y_degree = 0) {
  std::vector<double> cx = {x0, vx};
  std::vector<double> cy(static_cast<std::size_t>(y_degree) + 1, 0.0);
  cy[0] = y0;
  if (y_degree > 0) cy[static_cast<std::size_t>(y_degree)] = 1.0;
  return {MotionPolynomial::from(cx, 0.5), MotionPolynomial::from(cy)};
}

TEST(MotionTable, InsertFindAndReadBack) {
  MotionTable table(2);
  EXPECT_EQ(table.dimension(), 2);
  EXPECT_EQ(table.size(), 0u);
  EXPECT_EQ(table.capacity(), 0u);
  EXPECT_EQ(table.motion_changes(), 0u);
  EXPECT_FALSE(table.find(42).has_value());

  const ObjectHandle a = table.insert(42, motion2(1.0, 2.0, 3.0));
  const ObjectHandle b = table.insert(-7, motion2(4.0, 5.0, 6.0, 3));
  EXPECT_NE(a, b);
  EXPECT_TRUE(table.alive(a));
  EXPECT_TRUE(table.alive(b));
  EXPECT_EQ(table.size(), 2u);
  EXPECT_EQ(table.capacity(), 2u);
  EXPECT_EQ(table.motion_changes(), 2u);
  EXPECT_EQ(table.max_degree(), 3);
  ASSERT_TRUE(table.find(42).has_value());
  EXPECT_EQ(*table.find(42), a);
  EXPECT_EQ(*table.find(-7), b);
  EXPECT_EQ(table.id(a.index), 42);
  EXPECT_EQ(table.id(b.index), -7);
  EXPECT_EQ(table.handle(a.index), a);
  EXPECT_TRUE(table.alive_index(a.index));
  EXPECT_FALSE(table.alive_index(1000));
  EXPECT_EQ(table.motion(a.index, 0), motion2(1.0, 2.0, 3.0)[0]);
  EXPECT_EQ(table.motion(a.index, 1), motion2(1.0, 2.0, 3.0)[1]);
  EXPECT_EQ(table.motion(b.index, 1).degree, 3);
  EXPECT_EQ(table.motion(b.index, 0).origin, 0.5);
}

TEST(MotionTable, UpdateReplacesTheMotionAndCounts) {
  MotionTable table(1);
  const std::vector<double> c1 = {1.0, 1.0};
  const std::vector<double> c2 = {2.0, 0.0, 0.0, 0.0, 0.0, 5.0};
  const ObjectHandle h = table.insert(1, std::vector<MotionPolynomial>{MotionPolynomial::from(c1)});
  EXPECT_EQ(table.max_degree(), 1);
  table.update(h, std::vector<MotionPolynomial>{MotionPolynomial::from(c2, 3.0)});
  EXPECT_EQ(table.motion(h.index, 0), MotionPolynomial::from(c2, 3.0));
  EXPECT_EQ(table.motion_changes(), 2u);
  EXPECT_EQ(table.max_degree(), 5);
  EXPECT_TRUE(table.alive(h));  // an update does not invalidate the handle
  EXPECT_EQ(*table.find(1), h);
  table.update(h, std::vector<MotionPolynomial>{MotionPolynomial::from(c1)});
  EXPECT_EQ(table.motion_changes(), 3u);
  EXPECT_EQ(table.max_degree(), 5);  // "ever inserted": does not go down
  EXPECT_EQ(table.size(), 1u);
}

TEST(MotionTable, RemoveMakesHandlesStaleAndIndicesAreReused) {
  MotionTable table(2);
  const ObjectHandle a = table.insert(1, motion2(1, 1, 1));
  const ObjectHandle b = table.insert(2, motion2(2, 2, 2));
  const ObjectHandle c = table.insert(3, motion2(3, 3, 3));
  table.remove(b);
  EXPECT_FALSE(table.alive(b));
  EXPECT_FALSE(table.alive_index(b.index));
  EXPECT_FALSE(table.find(2).has_value());
  EXPECT_TRUE(table.alive(a));
  EXPECT_TRUE(table.alive(c));
  EXPECT_EQ(table.size(), 2u);
  EXPECT_EQ(table.capacity(), 3u);
  EXPECT_EQ(table.motion_changes(), 3u);  // a remove is not a motion change
  EXPECT_EQ(table.alive_indices(), (std::vector<std::uint32_t>{a.index, c.index}));

  // The freed index is reused, with a new generation: the old handle stays stale.
  const ObjectHandle d = table.insert(4, motion2(4, 4, 4));
  EXPECT_EQ(d.index, b.index);
  EXPECT_NE(d.generation, b.generation);
  EXPECT_FALSE(table.alive(b));
  EXPECT_TRUE(table.alive(d));
  EXPECT_EQ(table.capacity(), 3u);
  EXPECT_EQ(table.id(d.index), 4);
  EXPECT_EQ(table.motion(d.index, 0), motion2(4, 4, 4)[0]);
  EXPECT_EQ(*table.find(4), d);

  // The id of a removed object can be inserted again.
  const ObjectHandle b2 = table.insert(2, motion2(5, 5, 5));
  EXPECT_TRUE(table.alive(b2));
  EXPECT_EQ(b2.index, 3u);  // no free index left: a new one
  EXPECT_EQ(table.capacity(), 4u);
  EXPECT_FALSE(table.alive(b));
  EXPECT_EQ(*table.find(2), b2);

  // Out-of-range and default handles are not alive.
  EXPECT_FALSE(table.alive(ObjectHandle{}));
  EXPECT_FALSE(table.alive(ObjectHandle{99, 0}));
  // A handle with the right index but an old generation after two reuses.
  table.remove(d);
  const ObjectHandle e = table.insert(5, motion2(6, 6, 6));
  EXPECT_EQ(e.index, b.index);
  EXPECT_FALSE(table.alive(b));
  EXPECT_FALSE(table.alive(d));
  EXPECT_TRUE(table.alive(e));
}

TEST(MotionTable, RandomOperationsAgainstAModel) {
  const std::uint64_t seed = 0x7AB1E;
  std::mt19937_64 rng(seed);
  MotionTable table(3);
  struct Obj {
    ObjectHandle h;
    double tag;
  };
  std::map<ObjectId, Obj> model;
  std::vector<ObjectHandle> stale;
  std::uint64_t changes = 0;
  std::size_t max_live = 0;
  ObjectId next_id = 1000;
  for (int step = 0; step < 5000; ++step) {
    const int op = static_cast<int>(rng() % 10);
    if (op < 5 || model.empty()) {
      const ObjectId id = (rng() % 2) ? next_id++ : -static_cast<ObjectId>(next_id++);
      const double tag = static_cast<double>(step);
      const std::vector<MotionPolynomial> m(3, MotionPolynomial::constant(tag));
      model[id] = Obj{table.insert(id, m), tag};
      ++changes;
    } else {
      auto it = model.begin();
      std::advance(it, static_cast<long>(rng() % model.size()));
      if (op < 8) {
        stale.push_back(it->second.h);
        table.remove(it->second.h);
        model.erase(it);
      } else {
        const double tag = -static_cast<double>(step);
        table.update(it->second.h,
                     std::vector<MotionPolynomial>(3, MotionPolynomial::constant(tag)));
        it->second.tag = tag;
        ++changes;
      }
    }
    max_live = std::max(max_live, model.size());
    ASSERT_EQ(table.size(), model.size()) << "seed=" << seed << " step=" << step;
    ASSERT_EQ(table.motion_changes(), changes) << "seed=" << seed << " step=" << step;
    ASSERT_LE(table.capacity(), max_live)
        << "indices are reused; seed=" << seed << " step=" << step;
    if (step % 50 == 0 || step == 4999) {
      std::vector<std::uint32_t> expected;
      for (const auto& [id, o] : model) {
        ASSERT_TRUE(table.alive(o.h)) << "seed=" << seed << " step=" << step;
        ASSERT_EQ(table.find(id), o.h);
        ASSERT_EQ(table.id(o.h.index), id);
        for (int axis = 0; axis < 3; ++axis) ASSERT_EQ(table.motion(o.h.index, axis).c[0], o.tag);
        ASSERT_LT(o.h.index, table.capacity());
        expected.push_back(o.h.index);
      }
      std::sort(expected.begin(), expected.end());
      ASSERT_EQ(table.alive_indices(), expected) << "seed=" << seed << " step=" << step;
      for (const ObjectHandle& h : stale)
        ASSERT_FALSE(table.alive(h)) << "seed=" << seed << " step=" << step;
    }
  }
  EXPECT_GT(stale.size(), 1000u);
}

}  // namespace
}  // namespace kinetic
