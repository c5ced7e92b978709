#include "kinetic/fat_bvh/fat_box_tree.hpp"

#include <algorithm>
#include <cstddef>
#include <limits>

namespace kinetic {

std::uint32_t FatBoxTree::new_node() {
  if (!free_.empty()) {
    const std::uint32_t v = free_.back();
    free_.pop_back();
    nodes_[v] = Node{};
    return v;
  }
  nodes_.emplace_back();
  return static_cast<std::uint32_t>(nodes_.size() - 1);
}

void FatBoxTree::free_node(std::uint32_t v) {
  nodes_[v] = Node{};
  nodes_[v].height = -1;
  free_.push_back(v);
}

void FatBoxTree::clear() {
  nodes_.clear();
  free_.clear();
  root_ = kNoIndex;
  leaves_ = 0;
}

std::vector<std::uint32_t> FatBoxTree::build(const std::vector<ConstantBox>& boxes,
                                             const std::vector<std::uint32_t>& items) {
  clear();
  std::vector<std::uint32_t> leaf_of(boxes.size(), kNoIndex);
  if (boxes.empty()) return leaf_of;
  nodes_.reserve(2 * boxes.size());
  std::vector<std::uint32_t> order(boxes.size());
  for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  leaves_ = boxes.size();
  root_ = build_range(boxes, items, order, 0, order.size(), kNoIndex, leaf_of);
  return leaf_of;
}

std::uint32_t FatBoxTree::build_range(const std::vector<ConstantBox>& boxes,
                                      const std::vector<std::uint32_t>& items,
                                      std::vector<std::uint32_t>& order, std::size_t lo,
                                      std::size_t hi, std::uint32_t parent,
                                      std::vector<std::uint32_t>& leaf_of) {
  const std::uint32_t v = new_node();
  nodes_[v].parent = parent;
  if (hi - lo == 1) {
    nodes_[v].box = boxes[order[lo]];
    nodes_[v].item = items[order[lo]];
    leaf_of[order[lo]] = v;
    return v;
  }
  // The axis where the centers spread most (twice the center: no rounding by halving).
  std::array<double, 3> cmin{}, cmax{};
  cmin.fill(std::numeric_limits<double>::infinity());
  cmax.fill(-std::numeric_limits<double>::infinity());
  for (std::size_t i = lo; i < hi; ++i) {
    const ConstantBox& b = boxes[order[i]];
    for (std::size_t k = 0; k < static_cast<std::size_t>(d_); ++k) {
      const double c = b.lo[k] + b.hi[k];
      cmin[k] = std::min(cmin[k], c);
      cmax[k] = std::max(cmax[k], c);
    }
  }
  std::size_t axis = 0;
  for (std::size_t k = 1; k < static_cast<std::size_t>(d_); ++k) {
    if (cmax[k] - cmin[k] > cmax[axis] - cmin[axis]) axis = k;
  }
  const std::size_t mid = lo + (hi - lo) / 2;
  std::nth_element(order.begin() + static_cast<std::ptrdiff_t>(lo),
                   order.begin() + static_cast<std::ptrdiff_t>(mid),
                   order.begin() + static_cast<std::ptrdiff_t>(hi),
                   [&](std::uint32_t x, std::uint32_t y) {
                     const double cx = boxes[x].lo[axis] + boxes[x].hi[axis];
                     const double cy = boxes[y].lo[axis] + boxes[y].hi[axis];
                     return cx < cy || (cx == cy && x < y);
                   });
  const std::uint32_t left = build_range(boxes, items, order, lo, mid, v, leaf_of);
  const std::uint32_t right = build_range(boxes, items, order, mid, hi, v, leaf_of);
  nodes_[v].child = {left, right};
  refit(v);
  return v;
}

void FatBoxTree::replace_child(std::uint32_t parent, std::uint32_t old_child,
                               std::uint32_t new_child) {
  Node& p = nodes_[parent];
  p.child[p.child[0] == old_child ? 0 : 1] = new_child;
}

void FatBoxTree::refit(std::uint32_t v) {
  Node& n = nodes_[v];
  const Node& a = nodes_[n.child[0]];
  const Node& b = nodes_[n.child[1]];
  n.box = merged(a.box, b.box);
  n.height = 1 + std::max(a.height, b.height);
}

std::uint32_t FatBoxTree::insert(const ConstantBox& box, std::uint32_t item) {
  const std::uint32_t leaf = new_node();
  nodes_[leaf].box = box;
  nodes_[leaf].item = item;
  ++leaves_;
  if (root_ == kNoIndex) {
    root_ = leaf;
    return leaf;
  }
  // The descent: stop where making a new parent here costs less than going down either child
  // (a child's cost: the growth of its box, or a new parent's whole box at a leaf, plus what
  // every ancestor on the way grows by).
  std::uint32_t v = root_;
  while (nodes_[v].child[0] != kNoIndex) {
    const Node& n = nodes_[v];
    const double area = measure(n.box);
    const double combined = measure(merged(n.box, box));
    const double here = 2.0 * combined;
    const double inherited = 2.0 * (combined - area);
    std::array<double, 2> down{};
    for (std::size_t c = 0; c < 2; ++c) {
      const Node& child = nodes_[n.child[c]];
      const double grown = measure(merged(child.box, box));
      down[c] = (child.child[0] == kNoIndex ? grown : grown - measure(child.box)) + inherited;
    }
    if (here < down[0] && here < down[1]) break;
    v = down[0] <= down[1] ? n.child[0] : n.child[1];
  }
  const std::uint32_t sibling = v;
  const std::uint32_t old_parent = nodes_[sibling].parent;
  const std::uint32_t parent = new_node();
  Node& p = nodes_[parent];
  p.parent = old_parent;
  p.box = merged(box, nodes_[sibling].box);
  p.height = nodes_[sibling].height + 1;
  p.child = {sibling, leaf};
  if (old_parent == kNoIndex) {
    root_ = parent;
  } else {
    replace_child(old_parent, sibling, parent);
  }
  nodes_[sibling].parent = parent;
  nodes_[leaf].parent = parent;
  repair_upwards(parent, true);
  return leaf;
}

void FatBoxTree::remove(std::uint32_t leaf) {
  --leaves_;
  if (leaf == root_) {
    root_ = kNoIndex;
    free_node(leaf);
    return;
  }
  const std::uint32_t parent = nodes_[leaf].parent;
  const std::uint32_t grand = nodes_[parent].parent;
  const std::uint32_t sibling =
      nodes_[parent].child[0] == leaf ? nodes_[parent].child[1] : nodes_[parent].child[0];
  nodes_[sibling].parent = grand;
  free_node(parent);
  free_node(leaf);
  if (grand == kNoIndex) {
    root_ = sibling;
    return;
  }
  replace_child(grand, parent, sibling);
  repair_upwards(grand, false);
}

void FatBoxTree::repair_upwards(std::uint32_t v, bool rotations) {
  // Up to the first node (past v, which is new or lost a child) whose box and height the change
  // leaves as they were: every node above it is as it was too.
  for (bool first = true; v != kNoIndex; first = false) {
    const ConstantBox before = nodes_[v].box;
    const std::int32_t height = nodes_[v].height;
    refit(v);
    if (rotations) {
      rotate(v);
      refit(v);  // its height (its box is the same)
    }
    if (!first && nodes_[v].height == height && same(nodes_[v].box, before)) return;
    v = nodes_[v].parent;
  }
}

void FatBoxTree::rotate(std::uint32_t a) {
  // A rotation swaps a child of a with a grandchild under its other child when that makes the
  // other child's box smaller (Kensler's tree rotations): a's box and its leaves stay.
  const std::array<std::uint32_t, 2> child = nodes_[a].child;
  double best = 0.0;  // the largest decrease of a child's surface measure
  std::size_t lift_side = 0, grand_side = 0;
  for (std::size_t side = 0; side < 2; ++side) {
    const std::uint32_t low = child[side], high = child[1 - side];
    const Node& under = nodes_[low];
    if (under.child[0] == kNoIndex) continue;
    const double now = measure(under.box);
    for (std::size_t g = 0; g < 2; ++g) {
      // high goes down into low, in place of low's child g; low's child 1 - g stays.
      const double after = measure(merged(nodes_[high].box, nodes_[under.child[1 - g]].box));
      if (now - after > best) {
        best = now - after;
        lift_side = side;
        grand_side = g;
      }
    }
  }
  if (best <= 0.0) return;
  const std::uint32_t low = child[lift_side], high = child[1 - lift_side];
  const std::uint32_t lifted = nodes_[low].child[grand_side];
  nodes_[a].child[1 - lift_side] = lifted;
  nodes_[lifted].parent = a;
  nodes_[low].child[grand_side] = high;
  nodes_[high].parent = low;
  refit(low);
  ++rotations_;
}

double FatBoxTree::cost() const {
  double sum = 0.0;
  for (const Node& n : nodes_) {
    if (n.height > 0) sum += measure(n.box);
  }
  return sum;
}

bool FatBoxTree::validate() const {
  if (root_ == kNoIndex) return leaves_ == 0;
  if (nodes_[root_].parent != kNoIndex) return false;
  std::size_t leaves = 0;
  std::vector<std::uint32_t> stack{root_};
  while (!stack.empty()) {
    const std::uint32_t v = stack.back();
    stack.pop_back();
    const Node& n = nodes_[v];
    if (n.height < 0) return false;
    if (n.child[0] == kNoIndex) {
      if (n.child[1] != kNoIndex || n.height != 0) return false;
      ++leaves;
      continue;
    }
    for (const std::uint32_t c : n.child) {
      if (c >= nodes_.size() || nodes_[c].parent != v) return false;
      stack.push_back(c);
    }
    const ConstantBox m = merged(nodes_[n.child[0]].box, nodes_[n.child[1]].box);
    for (std::size_t k = 0; k < static_cast<std::size_t>(d_); ++k) {
      if (m.lo[k] != n.box.lo[k] || m.hi[k] != n.box.hi[k]) return false;
    }
    if (n.height != 1 + std::max(nodes_[n.child[0]].height, nodes_[n.child[1]].height))
      return false;
  }
  return leaves == leaves_;
}

}  // namespace kinetic
