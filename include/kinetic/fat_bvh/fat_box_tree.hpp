#pragma once
// A dynamic AABB tree over constant boxes (the fat boxes of core/boxes.hpp's moving boxes): the
// tree the per-frame broad phases keep (Box2D's b2DynamicTree, Bullet's btDbvt), here over boxes
// that do not move between two refits. A leaf is inserted beside the node where the tree's
// surface measure grows least (the greedy descent of Catto's "Dynamic bounding volume
// hierarchies"), and the path back to the root is refitted and improved by tree rotations
// (Kensler, "Tree rotations for improving bounding volume hierarchies": a child swapped with a
// grandchild when that shrinks the other child's box); a leaf is removed by putting its sibling
// in its parent's place. Either walk stops at the first node left as it was. O(depth) per insert
// and remove; query(box) reports every leaf whose closed box meets the given closed box.
// Flat storage: nodes in one array, freed nodes reused, an explicit stack for queries.

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "kinetic/core/boxes.hpp"
#include "kinetic/core/ids.hpp"

namespace kinetic {

/// A closed box [lo, hi] in d <= 3 dimensions, in double (a constant box: its sides are numbers).
struct ConstantBox {
  std::array<double, 3> lo{};
  std::array<double, 3> hi{};
};

/// Whether two closed boxes meet (touching counts) on the first d axes.
[[nodiscard]] inline bool boxes_meet(const ConstantBox& a, const ConstantBox& b, int d) {
  for (int k = 0; k < d; ++k) {
    const auto i = static_cast<std::size_t>(k);
    if (a.lo[i] > b.hi[i] || b.lo[i] > a.hi[i]) return false;
  }
  return true;
}

class FatBoxTree {
 public:
  explicit FatBoxTree(int dimension) : d_(dimension) {}

  /// A new leaf holding `item` with this box; returns the leaf's node.
  std::uint32_t insert(const ConstantBox& box, std::uint32_t item);
  /// Replaces the tree by one over these boxes (items[i] with boxes[i]), built top down by
  /// median splits of the boxes' centers on the axis where they spread most; returns each
  /// item's leaf, in the same order. O(n log n).
  std::vector<std::uint32_t> build(const std::vector<ConstantBox>& boxes,
                                   const std::vector<std::uint32_t>& items);
  /// Removes a leaf returned by insert().
  void remove(std::uint32_t leaf);
  void clear();

  /// Calls f(item) for every leaf whose box meets `box` (closed), in a fixed order (depth first,
  /// the first child first).
  template <class F>
  void query(const ConstantBox& box, F&& f) const {
    if (root_ == kNoIndex || !boxes_meet(nodes_[root_].box, box, d_)) return;
    stack_.clear();
    stack_.push_back(root_);
    while (!stack_.empty()) {
      const Node& node = nodes_[stack_.back()];
      stack_.pop_back();
      if (node.child[0] == kNoIndex) {
        f(node.item);
        continue;
      }
      // Children tested before they are pushed (their boxes are read once, here).
      const std::uint32_t c0 = node.child[0], c1 = node.child[1];
      if (boxes_meet(nodes_[c1].box, box, d_)) stack_.push_back(c1);
      if (boxes_meet(nodes_[c0].box, box, d_)) stack_.push_back(c0);
    }
  }

  [[nodiscard]] const ConstantBox& box(std::uint32_t node) const { return nodes_[node].box; }
  [[nodiscard]] std::uint32_t item(std::uint32_t leaf) const { return nodes_[leaf].item; }
  [[nodiscard]] std::size_t leaves() const { return leaves_; }
  /// The longest path from the root to a leaf, in edges (0: one leaf or none).
  [[nodiscard]] int height() const { return root_ == kNoIndex ? 0 : nodes_[root_].height; }
  /// Rotations done since the tree was made.
  [[nodiscard]] std::uint64_t rotations() const { return rotations_; }
  /// The sum of the internal nodes' surface measures (length, half perimeter, half area): the
  /// tree's cost as the descent minimises it.
  [[nodiscard]] double cost() const;
  /// Parent and child links agree, every internal node's box is its children's bounding box
  /// exactly and its height one more than its taller child's, and the leaves are `leaves()`.
  [[nodiscard]] bool validate() const;
  /// Bytes held by the nodes.
  [[nodiscard]] std::size_t bytes() const { return nodes_.capacity() * sizeof(Node); }

 private:
  struct Node {
    ConstantBox box;
    std::uint32_t parent = kNoIndex;
    std::array<std::uint32_t, 2> child{kNoIndex, kNoIndex};
    std::int32_t height = 0;  // 0 for a leaf; -1 for a free node
    std::uint32_t item = kNoIndex;
  };
  [[nodiscard]] double measure(const ConstantBox& b) const {
    std::array<double, 3> len{};
    for (std::size_t k = 0; k < static_cast<std::size_t>(d_); ++k) len[k] = b.hi[k] - b.lo[k];
    return surface_measure(d_, len);
  }
  [[nodiscard]] ConstantBox merged(const ConstantBox& a, const ConstantBox& b) const {
    ConstantBox m;
    for (std::size_t k = 0; k < 3; ++k) {  // all three: no loop bound to test
      m.lo[k] = a.lo[k] < b.lo[k] ? a.lo[k] : b.lo[k];
      m.hi[k] = a.hi[k] > b.hi[k] ? a.hi[k] : b.hi[k];
    }
    return m;
  }
  std::uint32_t build_range(const std::vector<ConstantBox>& boxes,
                            const std::vector<std::uint32_t>& items,
                            std::vector<std::uint32_t>& order, std::size_t lo, std::size_t hi,
                            std::uint32_t parent, std::vector<std::uint32_t>& leaf_of);
  std::uint32_t new_node();
  void free_node(std::uint32_t v);
  /// Refits (and rotates, after an insert) from v up, while the nodes change.
  void repair_upwards(std::uint32_t v, bool rotations);
  [[nodiscard]] bool same(const ConstantBox& a, const ConstantBox& b) const {
    for (std::size_t k = 0; k < static_cast<std::size_t>(d_); ++k) {
      if (a.lo[k] != b.lo[k] || a.hi[k] != b.hi[k]) return false;
    }
    return true;
  }
  /// The rotation at v that shrinks one of its children's boxes most, if any.
  void rotate(std::uint32_t v);
  void refit(std::uint32_t v);
  void replace_child(std::uint32_t parent, std::uint32_t old_child, std::uint32_t new_child);

  int d_;
  std::vector<Node> nodes_;
  std::vector<std::uint32_t> free_;
  std::uint32_t root_ = kNoIndex;
  std::size_t leaves_ = 0;
  std::uint64_t rotations_ = 0;
  mutable std::vector<std::uint32_t> stack_;
};

}  // namespace kinetic
