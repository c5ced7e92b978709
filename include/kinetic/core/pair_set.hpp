#pragma once
// A set of unordered pairs of indices {a, b} (a != b), flat: the pairs in one dense array (for
// iteration) and an open-addressing table of positions in it (linear probing, load <= 1/2,
// backward-shift deletion). Insert, erase and contains are O(1) expected and allocate only when
// the table grows. The overlapping-pair set of the collision structures.

#include <cassert>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

namespace kinetic {

class PairSet {
 public:
  /// The key of {a, b}: the smaller index in the high half.
  [[nodiscard]] static std::uint64_t key(std::uint32_t a, std::uint32_t b) {
    if (a > b) std::swap(a, b);
    return (std::uint64_t{a} << 32) | b;
  }
  [[nodiscard]] static std::uint32_t first(std::uint64_t key) {
    return static_cast<std::uint32_t>(key >> 32);
  }
  [[nodiscard]] static std::uint32_t second(std::uint64_t key) {
    return static_cast<std::uint32_t>(key);
  }

  /// Adds {a, b}; false when it was there.
  bool insert(std::uint32_t a, std::uint32_t b) {
    assert(a != b);
    if (2 * (pairs_.size() + 1) > slots_.size()) grow();
    const std::uint64_t k = key(a, b);
    std::size_t i = home(k);
    while (slots_[i] != 0) {
      if (pairs_[slots_[i] - 1] == k) return false;
      i = (i + 1) & mask();
    }
    pairs_.push_back(k);
    slots_[i] = static_cast<std::uint32_t>(pairs_.size());
    return true;
  }

  /// Removes {a, b}; false when it was not there. The last pair of pairs() takes its place.
  bool erase(std::uint32_t a, std::uint32_t b) {
    const std::uint64_t k = key(a, b);
    const std::size_t s = find(k);
    if (s == kAbsent) return false;
    const std::size_t d = slots_[s] - 1, last = pairs_.size() - 1;
    if (d != last) {
      slots_[find(pairs_[last])] = static_cast<std::uint32_t>(d + 1);
      pairs_[d] = pairs_[last];
    }
    pairs_.pop_back();
    remove_slot(s);
    return true;
  }

  [[nodiscard]] bool contains(std::uint32_t a, std::uint32_t b) const {
    return find(key(a, b)) != kAbsent;
  }
  /// "Absent", from position().
  static constexpr std::size_t npos = ~std::size_t{0};
  /// The position of {a, b} in keys(), npos when absent. Positions move only at an erase (the
  /// last pair takes the erased one's place).
  [[nodiscard]] std::size_t position(std::uint32_t a, std::uint32_t b) const {
    const std::size_t s = find(key(a, b));
    return s == kAbsent ? npos : std::size_t{slots_[s]} - 1;
  }
  [[nodiscard]] std::size_t size() const { return pairs_.size(); }
  [[nodiscard]] bool empty() const { return pairs_.empty(); }
  /// The pairs as keys (first(), second()), in no particular order.
  [[nodiscard]] std::span<const std::uint64_t> keys() const { return pairs_; }
  void clear() {
    pairs_.clear();
    slots_.assign(slots_.size(), 0);
  }
  /// Bytes held (the dense array and the table).
  [[nodiscard]] std::size_t bytes() const {
    return pairs_.capacity() * sizeof(std::uint64_t) + slots_.capacity() * sizeof(std::uint32_t);
  }

 private:
  static constexpr std::size_t kAbsent = ~std::size_t{0};
  [[nodiscard]] std::size_t mask() const { return slots_.size() - 1; }
  [[nodiscard]] std::size_t home(std::uint64_t k) const {
    k ^= k >> 33;  // the finaliser of MurmurHash3
    k *= 0xff51afd7ed558ccdULL;
    k ^= k >> 33;
    k *= 0xc4ceb9fe1a85ec53ULL;
    k ^= k >> 33;
    return static_cast<std::size_t>(k) & mask();
  }
  [[nodiscard]] std::size_t find(std::uint64_t k) const {
    if (slots_.empty()) return kAbsent;
    for (std::size_t i = home(k); slots_[i] != 0; i = (i + 1) & mask()) {
      if (pairs_[slots_[i] - 1] == k) return i;
    }
    return kAbsent;
  }
  void remove_slot(std::size_t i) {
    // Backward-shift deletion: move later entries of the probe run into the hole when their
    // home does not lie cyclically in (hole, their slot].
    std::size_t j = i;
    for (;;) {
      j = (j + 1) & mask();
      if (slots_[j] == 0) break;
      const std::size_t h = home(pairs_[slots_[j] - 1]);
      const bool stays = (i <= j) ? (i < h && h <= j) : (i < h || h <= j);
      if (!stays) {
        slots_[i] = slots_[j];
        i = j;
      }
    }
    slots_[i] = 0;
  }
  void grow() {
    slots_.assign(slots_.empty() ? 16 : 2 * slots_.size(), 0);
    for (std::size_t d = 0; d < pairs_.size(); ++d) {
      std::size_t i = home(pairs_[d]);
      while (slots_[i] != 0) i = (i + 1) & mask();
      slots_[i] = static_cast<std::uint32_t>(d + 1);
    }
  }

  std::vector<std::uint64_t> pairs_;  // dense
  std::vector<std::uint32_t> slots_;  // 0 empty, else position in pairs_ + 1
};

}  // namespace kinetic
