#pragma once
// The skeleton of a path-compressed binary trie over the points' keys, as the rank-based kd-tree
// and the rank-based longest-side kd-tree keep it (Abam, de Berg and Speckmann, "Kinetic
// kd-trees and longest-side kd-trees"): the active nodes (where the key sets of the two children
// differ) and the leaves (one point each), the degree-one nodes between them compressed away.
// A key is a sequence of binary digits: rank bits for the kd-tree, S-node sides for the
// longest-side kd-tree. How a structure walks its keys is its own; what is shared is the splice
// that an insert or a remove makes to the skeleton, written here once.
//
// A node type N is anything with the fields
//   std::uint32_t parent;                  // kNoIndex at the root
//   std::array<std::uint32_t, 2> child;    // active nodes
//   std::uint32_t leaves;                  // the subtree's leaves (1 at a leaf)
// stored in a random-access container of N (a std::vector, or a vector with another
// allocator) and addressed by index, with the root's index kept by the caller.
// Nothing here allocates, frees or counts events: the caller owns slot reuse and its counters.
// contract() and split_above() keep `leaves` on the path to the root (O(depth));
// replace_child() does not touch it: the new child must have as many leaves as the old one.

#include <array>
#include <cstdint>

#include "kinetic/core/ids.hpp"

namespace kinetic::trie {

/// Makes `now` take `old`'s place as a child of `parent` (or as the root when parent is
/// kNoIndex). Does not touch `now.parent`.
template <class Nodes>
inline void replace_child(Nodes& nodes, std::uint32_t& root, std::uint32_t parent,
                          std::uint32_t old, std::uint32_t now) {
  if (parent == kNoIndex) {
    root = now;
  } else {
    nodes[parent].child[nodes[parent].child[0] == old ? 0 : 1] = now;
  }
}

/// What a removal of a leaf leaves behind: the leaf's former parent u (no longer active, its
/// slot to be freed by the caller), u's other child c that took u's place, and c's new parent g.
struct Contraction {
  std::uint32_t removed;   // u
  std::uint32_t survivor;  // c
  std::uint32_t parent;    // g (kNoIndex: c is the root now)
};

/// Removes `leaf` from the skeleton. When it was the root the trie becomes empty and the result
/// has removed == kNoIndex. Otherwise its parent u stops being active: u's other child takes u's
/// place under u's parent, whose ancestors count one leaf less. The caller frees the slots of
/// `leaf` and u.
template <class Nodes>
inline Contraction contract(Nodes& nodes, std::uint32_t& root, std::uint32_t leaf) {
  const std::uint32_t u = nodes[leaf].parent;
  if (u == kNoIndex) {
    root = kNoIndex;
    return Contraction{kNoIndex, kNoIndex, kNoIndex};
  }
  const std::uint32_t c = nodes[u].child[0] == leaf ? nodes[u].child[1] : nodes[u].child[0];
  const std::uint32_t g = nodes[u].parent;
  nodes[c].parent = g;
  replace_child(nodes, root, g, u, c);
  for (std::uint32_t a = g; a != kNoIndex; a = nodes[a].parent) --nodes[a].leaves;
  return Contraction{u, c, g};
}

/// Hangs the new active node x in `cur`'s place, with the new leaf `leaf` as its child on
/// `side` and cur on the other side (an insert whose key leaves cur's path above cur). Sets the
/// parent and child links of x, leaf and cur, and the leaf counts of x (cur's and one) and of
/// its ancestors (one more); the caller sets depths and its own fields.
template <class Nodes>
inline void split_above(Nodes& nodes, std::uint32_t& root, std::uint32_t cur, std::uint32_t x,
                        std::uint32_t leaf, int side) {
  const std::uint32_t g = nodes[cur].parent;
  nodes[x].parent = g;
  replace_child(nodes, root, g, cur, x);
  nodes[x].child[static_cast<std::size_t>(side)] = leaf;
  nodes[x].child[static_cast<std::size_t>(1 - side)] = cur;
  nodes[leaf].parent = x;
  nodes[cur].parent = x;
  nodes[leaf].leaves = 1;
  nodes[x].leaves = nodes[cur].leaves + 1;
  for (std::uint32_t a = g; a != kNoIndex; a = nodes[a].parent) ++nodes[a].leaves;
}

}  // namespace kinetic::trie
