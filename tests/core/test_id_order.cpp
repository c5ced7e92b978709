// Ranks by id and tuples sorted by ids (core/id_order.hpp) against std::sort through the ids:
// random ids (negative too), removals and index reuse, runs longer than the insertion sort
// takes (one point the smallest of many tuples), repeated tuples, empty and single inputs.

#include "kinetic/core/id_order.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <random>
#include <vector>

namespace kinetic {
namespace {

std::vector<MotionPolynomial> still(double x) {
  return {MotionPolynomial::from({x}), MotionPolynomial::from({0.0})};
}

template <std::size_t K>
std::vector<std::array<std::uint32_t, K>> by_comparison(
    std::vector<std::array<std::uint32_t, K>> tuples, const MotionTable& table) {
  std::sort(tuples.begin(), tuples.end(), [&](const auto& x, const auto& y) {
    for (std::size_t i = 0; i < K; ++i)
      if (table.id(x[i]) != table.id(y[i])) return table.id(x[i]) < table.id(y[i]);
    return false;
  });
  return tuples;
}

template <std::size_t K>
std::vector<std::array<std::uint32_t, K>> by_ranks(std::vector<std::array<std::uint32_t, K>> tuples,
                                                   const IdRanks& ranks) {
  for (auto& t : tuples)
    for (std::uint32_t& x : t) x = ranks.rank(x);
  std::vector<std::array<std::uint32_t, K>> out;
  std::vector<std::uint32_t> counts;
  sort_ranked<K>(tuples, ranks.size(), out, counts);
  for (auto& t : out)
    for (std::uint32_t& x : t) x = ranks.index(x);
  return out;
}

TEST(IdOrder, TuplesSortedByIdsAsAComparisonSortDoes) {
  for (const std::uint64_t seed : {1u, 2u, 3u, 4u, 5u}) {
    SCOPED_TRACE(::testing::Message() << "seed " << seed);
    std::mt19937_64 rng(seed);
    MotionTable table(2);
    std::vector<ObjectHandle> handles;
    std::uniform_int_distribution<ObjectId> id(-1'000'000, 1'000'000);
    while (table.size() < 300) {
      const ObjectId i = id(rng);
      if (!table.find(i)) handles.push_back(table.insert(i, still(0.0)));
    }
    // Some removed and their indices reused by new ids: ranks follow the table's changes.
    IdRanks ranks;
    ranks.update(table);
    for (int k = 0; k < 40; ++k) table.remove(handles[static_cast<std::size_t>(k * 7)]);
    while (table.size() < 300) {
      const ObjectId i = id(rng);
      if (!table.find(i)) table.insert(i, still(0.0));
    }
    ranks.update(table);
    const std::vector<std::uint32_t> live = table.alive_indices();
    ASSERT_EQ(ranks.size(), live.size());
    for (std::uint32_t r = 0; r + 1 < ranks.size(); ++r)
      ASSERT_LT(table.id(ranks.index(r)), table.id(ranks.index(r + 1)));
    for (const std::uint32_t i : live) ASSERT_EQ(ranks.index(ranks.rank(i)), i);

    std::uniform_int_distribution<std::size_t> pick(0, live.size() - 1);
    std::vector<std::array<std::uint32_t, 3>> triples;
    for (int k = 0; k < 2000; ++k)
      triples.push_back({live[pick(rng)], live[pick(rng)], live[pick(rng)]});
    // One point first in 100 tuples (a run past the insertion sort), and repeated tuples.
    for (int k = 0; k < 100; ++k) triples.push_back({live[0], live[pick(rng)], live[pick(rng)]});
    for (int k = 0; k < 20; ++k) triples.push_back(triples[static_cast<std::size_t>(k)]);
    EXPECT_EQ(by_ranks(triples, ranks), by_comparison(triples, table));

    std::vector<std::array<std::uint32_t, 2>> pairs;
    for (int k = 0; k < 1000; ++k) pairs.push_back({live[pick(rng)], live[pick(rng)]});
    EXPECT_EQ(by_ranks(pairs, ranks), by_comparison(pairs, table));
  }
}

TEST(IdOrder, EmptyAndSingleInputs) {
  MotionTable table(2);
  IdRanks ranks;
  ranks.update(table);
  EXPECT_EQ(ranks.size(), 0u);
  EXPECT_TRUE(by_ranks(std::vector<std::array<std::uint32_t, 3>>{}, ranks).empty());
  const ObjectHandle a = table.insert(5, still(1.0));
  ranks.update(table);
  const std::vector<std::array<std::uint32_t, 2>> one{{a.index, a.index}};
  EXPECT_EQ(by_ranks(one, ranks), one);
}

}  // namespace
}  // namespace kinetic
