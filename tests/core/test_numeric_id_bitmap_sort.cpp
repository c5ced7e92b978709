// The id-bitmap sort of range answers (core/numeric/id_bitmap_sort.hpp): the same order as
// std::sort on random sets of distinct ids of every size around its threshold and its word and
// summary boundaries, with the bitmaps left all zero between calls.

#include "core/numeric/id_bitmap_sort.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

namespace kinetic {
namespace {

bool all_zero(const std::vector<std::uint64_t>& v) {
  return std::all_of(v.begin(), v.end(), [](std::uint64_t w) { return w == 0; });
}

TEST(NumericIdBitmapSort, SortsLikeStdSortAndLeavesTheBitmapsZero) {
  const std::uint64_t seed = 0x1d5e0001;
  std::mt19937_64 rng(seed);
  std::vector<std::uint64_t> bits, summary;  // reused across calls, as the structures do
  for (int it = 0; it < 400; ++it) {
    // Capacities below, at and across the 64-id words and 4096-id summary words.
    const std::size_t capacity =
        std::vector<std::size_t>{1, 63, 64, 65, 4095, 4096, 4097, 10000, 70000}[rng() % 9];
    std::vector<std::uint32_t> all(capacity);
    std::iota(all.begin(), all.end(), 0U);
    std::shuffle(all.begin(), all.end(), rng);
    const std::size_t k = std::min<std::size_t>(
        capacity, std::vector<std::size_t>{0, 1, 63, 64, 65, 500, 4096, capacity}[rng() % 8]);
    std::vector<std::uint32_t> ids(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(k));
    if (rng() % 4 == 0 && k > 0) ids.back() = static_cast<std::uint32_t>(capacity - 1);
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    std::vector<std::uint32_t> expected = ids;
    std::shuffle(ids.begin(), ids.end(), rng);
    numeric::sort_ids_ascending(ids, capacity, bits, summary);
    EXPECT_EQ(ids, expected) << "seed=" << seed << " it=" << it << " capacity=" << capacity
                             << " k=" << expected.size();
    EXPECT_TRUE(all_zero(bits) && all_zero(summary)) << "seed=" << seed << " it=" << it;
    if (HasFailure()) return;
  }
}

}  // namespace
}  // namespace kinetic
