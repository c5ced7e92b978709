#pragma once
// Index-based record storage with a free list: the structures keep their nodes, pairs and
// certificates in flat vectors addressed by index, and reuse the indices of records they freed.

#include <cstdint>
#include <vector>

namespace kinetic {

/// A record index: the last one freed (its record keeps its old contents; the caller overwrites
/// it), or a new default-constructed record appended.
/// `Records`: a std::vector, or a vector with another allocator (HugeVector).
template <class Records>
std::uint32_t take_record(Records& records, std::vector<std::uint32_t>& free) {
  if (!free.empty()) {
    const std::uint32_t i = free.back();
    free.pop_back();
    return i;
  }
  records.emplace_back();
  return static_cast<std::uint32_t>(records.size() - 1);
}

}  // namespace kinetic
