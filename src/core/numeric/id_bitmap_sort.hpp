#pragma once
// Sorting the answer of a range query, a list of distinct table indices, ascending. A large
// answer goes through a bitmap over the table's indices with a summary bit per word of it, so
// that reading it back costs O(k + capacity / 4096) for k indices; a small one (k < 64) through
// std::sort. Used by the kd-tree and the range tree (sort_ids()), which keep the two bitmaps as
// scratch members.

#include <algorithm>
#include <bit>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace kinetic::numeric {

/// Sorts `ids` ascending. Preconditions: the ids are distinct and each is < capacity; `bits`
/// and `summary` are all zero (or empty). They are all zero again on return (cleared as they
/// are read), sized for `capacity` when the bitmap was used.
inline void sort_ids_ascending(std::vector<std::uint32_t>& ids, std::size_t capacity,
                               std::vector<std::uint64_t>& bits,
                               std::vector<std::uint64_t>& summary) {
  if (ids.size() < 64) {
    std::sort(ids.begin(), ids.end());
    return;
  }
  const std::size_t words = (capacity + 63) / 64;
  bits.resize(words, 0);
  summary.resize((words + 63) / 64, 0);
  for (const std::uint32_t p : ids) {
    bits[p >> 6] |= std::uint64_t{1} << (p & 63);
    summary[p >> 12] |= std::uint64_t{1} << ((p >> 6) & 63);
  }
  std::size_t k = 0;
  for (std::size_t s = 0; s < summary.size(); ++s) {
    for (std::uint64_t word_bits = summary[s]; word_bits != 0; word_bits &= word_bits - 1) {
      const std::size_t w = s * 64 + static_cast<std::size_t>(std::countr_zero(word_bits));
      for (std::uint64_t word = bits[w]; word != 0; word &= word - 1) {
        ids[k++] =
            static_cast<std::uint32_t>(w * 64 + static_cast<std::size_t>(std::countr_zero(word)));
      }
      bits[w] = 0;
    }
    summary[s] = 0;
  }
  assert(k == ids.size());
}

}  // namespace kinetic::numeric
