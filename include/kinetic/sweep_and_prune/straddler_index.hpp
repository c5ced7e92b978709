#pragma once
// The boxes whose interval on one axis straddles a range of that axis's maintained order: a
// max-tree over the slots of the axis's gapped sort, holding at each slot of a low side the slot
// of the same box's high side (plus one; 0 at every other slot). The boxes whose low side is at a
// slot before p and whose high side is at a slot after q are the leaves before p holding more
// than q + 1: found by a descent that skips every subtree whose maximum is at most q + 1,
// O((k + 1) log U) for k boxes. A swap changes at most four leaves, and a leaf's change climbs
// only while it changes its parent's maximum (two low sides swapping leave every maximum above
// them as it was). Kinetic sweep-and-prune uses it to find an inserted or moved box's
// contacts without a pass over all boxes.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace kinetic::detail {

class StraddlerIndex {
 public:
  /// Every leaf 0, over `slots` slots (a power of two, or 0).
  void reset(std::size_t slots) {
    slots_ = slots;
    max_.assign(2 * slots, 0);
  }
  [[nodiscard]] std::size_t slots() const { return slots_; }

  /// Leaf s holds v (the high side's slot plus one at a low side's slot, else 0).
  void set(std::size_t s, std::uint32_t v) {
    std::size_t i = slots_ + s;
    if (max_[i] == v) return;
    max_[i] = v;
    for (i /= 2; i >= 1; i /= 2) {
      const std::uint32_t m = std::max(max_[2 * i], max_[2 * i + 1]);
      if (max_[i] == m) break;
      max_[i] = m;
    }
  }
  /// Every leaf recomputed at once from the leaves' values (after a relayout). O(U).
  void set_all_leaves_then_build(const std::vector<std::uint32_t>& leaves) {
    reset(leaves.size());
    std::copy(leaves.begin(), leaves.end(), max_.begin() + static_cast<std::ptrdiff_t>(slots_));
    for (std::size_t i = slots_; i-- > 1;) max_[i] = std::max(max_[2 * i], max_[2 * i + 1]);
  }
  [[nodiscard]] std::uint32_t leaf(std::size_t s) const { return max_[slots_ + s]; }

  /// Calls f(s) for every slot s < p whose leaf holds more than `above`, in slot order.
  template <class F>
  void report(std::size_t p, std::uint32_t above, F&& f) const {
    if (p == 0 || slots_ == 0 || max_[1] <= above) return;
    // Iterative descent over the nodes covering [0, p): node i covers [lo, lo + width).
    struct Frame {
      std::size_t node, lo, width;
    };
    Frame stack[64];
    std::size_t top = 0;
    stack[top++] = {1, 0, slots_};
    while (top > 0) {
      const Frame fr = stack[--top];
      if (fr.lo >= p || max_[fr.node] <= above) continue;
      if (fr.width == 1) {
        f(fr.lo);
        continue;
      }
      const std::size_t half = fr.width / 2;
      stack[top++] = {2 * fr.node + 1, fr.lo + half, half};  // right after left
      stack[top++] = {2 * fr.node, fr.lo, half};
    }
  }
  /// Every internal node holds the maximum of its two children (validate()). O(U).
  [[nodiscard]] bool consistent() const {
    for (std::size_t i = 1; i < slots_; ++i) {
      if (max_[i] != std::max(max_[2 * i], max_[2 * i + 1])) return false;
    }
    return true;
  }
  [[nodiscard]] std::size_t bytes() const { return max_.capacity() * sizeof(std::uint32_t); }

 private:
  std::size_t slots_ = 0;
  std::vector<std::uint32_t> max_;  // node i: the max of its leaves; leaves at slots_ + s
};

}  // namespace kinetic::detail
