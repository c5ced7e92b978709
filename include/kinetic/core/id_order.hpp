#pragma once
// Answers in the contract's order (sorted by object ids) without comparing through the ids: the
// live objects' ranks by id, kept while the table stands, and tuples of ranks sorted with a
// counting sort on their first element (linear time; a comparison sort of n tuples through a
// table of ids was most of a query that lists every triangle).

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "kinetic/core/motion_table.hpp"

namespace kinetic {

/// Every live object's rank in increasing id order. Recomputed (a sort of the ids) only when the
/// table changed since the last update() (MotionTable::version()).
class IdRanks {
 public:
  void update(const MotionTable& table);
  /// The rank of live index `index`.
  [[nodiscard]] std::uint32_t rank(std::uint32_t index) const { return rank_[index]; }
  /// The live index of rank `r` (< size()).
  [[nodiscard]] std::uint32_t index(std::uint32_t r) const { return by_rank_[r]; }
  [[nodiscard]] std::size_t size() const { return by_rank_.size(); }

 private:
  const MotionTable* table_ = nullptr;
  std::uint64_t version_ = 0;
  std::vector<std::uint32_t> rank_;     // by table index (meaningful for live ones)
  std::vector<std::uint32_t> by_rank_;  // live indices by increasing id
};

/// `in`, tuples of ranks (each < rank_count), sorted lexicographically into `out`: a counting
/// sort on the first element, then each run of equal first elements on the rest. `counts` is
/// scratch (kept by the caller across queries: no page of it is touched anew per query).
template <std::size_t K>
void sort_ranked(std::span<const std::array<std::uint32_t, K>> in, std::size_t rank_count,
                 std::vector<std::array<std::uint32_t, K>>& out,
                 std::vector<std::uint32_t>& counts);

extern template void sort_ranked<2>(std::span<const std::array<std::uint32_t, 2>>, std::size_t,
                                    std::vector<std::array<std::uint32_t, 2>>&,
                                    std::vector<std::uint32_t>&);
extern template void sort_ranked<3>(std::span<const std::array<std::uint32_t, 3>>, std::size_t,
                                    std::vector<std::array<std::uint32_t, 3>>&,
                                    std::vector<std::uint32_t>&);

}  // namespace kinetic
