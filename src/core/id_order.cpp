#include "kinetic/core/id_order.hpp"

#include <algorithm>

namespace kinetic {

void IdRanks::update(const MotionTable& table) {
  if (table_ == &table && version_ == table.version()) return;
  table_ = &table;
  version_ = table.version();
  by_rank_ = table.alive_indices();
  std::sort(by_rank_.begin(), by_rank_.end(),
            [&](std::uint32_t a, std::uint32_t b) { return table.id(a) < table.id(b); });
  rank_.assign(table.capacity(), 0);
  for (std::uint32_t r = 0; r < by_rank_.size(); ++r) rank_[by_rank_[r]] = r;
}

template <std::size_t K>
void sort_ranked(std::span<const std::array<std::uint32_t, K>> in, std::size_t rank_count,
                 std::vector<std::array<std::uint32_t, K>>& out,
                 std::vector<std::uint32_t>& counts) {
  using Tuple = std::array<std::uint32_t, K>;
  out.resize(in.size());
  // Where each first rank's run starts, then the tuples scattered there (stable).
  counts.assign(rank_count + 1, 0);
  for (const Tuple& t : in) ++counts[t[0] + 1];
  for (std::size_t r = 1; r <= rank_count; ++r) counts[r] += counts[r - 1];
  for (const Tuple& t : in) out[counts[t[0]]++] = t;
  // counts[r] is now the end of run r (the start of run r + 1). Each run sorted on the rest: a
  // short run (a point is the smallest of a few triangles) by insertion.
  std::size_t first = 0;
  for (std::size_t r = 0; r < rank_count; ++r) {
    const std::size_t last = counts[r];
    if (last - first > 16) {
      std::sort(out.begin() + static_cast<std::ptrdiff_t>(first),
                out.begin() + static_cast<std::ptrdiff_t>(last));
    } else {
      for (std::size_t i = first + 1; i < last; ++i) {
        const Tuple x = out[i];
        std::size_t j = i;
        for (; j > first && x < out[j - 1]; --j) out[j] = out[j - 1];
        out[j] = x;
      }
    }
    first = last;
  }
}

template void sort_ranked<2>(std::span<const std::array<std::uint32_t, 2>>, std::size_t,
                             std::vector<std::array<std::uint32_t, 2>>&,
                             std::vector<std::uint32_t>&);
template void sort_ranked<3>(std::span<const std::array<std::uint32_t, 3>>, std::size_t,
                             std::vector<std::array<std::uint32_t, 3>>&,
                             std::vector<std::uint32_t>&);

}  // namespace kinetic
