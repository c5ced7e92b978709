#include "kinetic/kdtree/kinetic_kdtree.hpp"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>

#include "core/compressed_trie.hpp"
#include "core/numeric/interval.hpp"
#include "core/numeric/linear_filter.hpp"
#include "kinetic/core/predicates.hpp"

namespace kinetic {

/// A motion as the queries' floating-point filter reads it, about the tree's reference time T
/// (reference_, the time of the last build): x(t) = c0 + c1 (t - T), c0 = fl(x(T)) within
/// reference_error_ of the true x(T), c1 the slope. c1 is NaN when the degree is above 1 or x(T)
/// has no finite bound (the filter then never decides and the exact path does). 16 bytes per
/// axis: a bucket's leaves are two thirds of what they were with the motion's own origin.
struct KineticKdTree::Linear {
  double c0 = 0.0;
  double c1 = 0.0;
};
struct KineticKdTree::ChainEntry {
  std::uint32_t median;  // rank in A_axis of the split point
  std::uint16_t axis;
  std::uint8_t side;  // 1: the region lies on the right (>=) side
};
struct alignas(64) KineticKdTree::Node {
  std::uint32_t parent = kNoIndex;
  std::array<std::uint32_t, 2> child{kNoIndex, kNoIndex};
  std::uint32_t point = kNoIndex;  // leaves
  std::uint32_t rep = kNoIndex;    // a point of the subtree (its key fixes the node's splits)
  std::uint32_t median = 0;        // active nodes: the split's rank on axis depth mod d (fixed: it
                                   // depends only on the key prefix the node's points share)
  std::uint32_t leaves = 1;        // the number of leaves of the subtree
  std::uint32_t depth = 0;         // in skeleton levels
  /// The inline chain (d <= 3): entry k is the split A_axis[chain_median[k]] with
  /// chain_tag[k] = 2 axis + side.
  std::array<std::uint32_t, kInline> chain_median{};
  std::array<std::uint8_t, kInline> chain_tag{};
  std::uint8_t chain_size = 0;
  /// Active nodes: the split's axis, depth mod d (kept so that a query needs no division).
  std::uint8_t axis = 0;
};
/// A trie (nodes and chains) built or maintained from the current ranks.
struct KineticKdTree::Trie {
  HugeVector<Node> nodes;
  HugeVector<ChainEntry> chains;  // d > 3: node k's chain, [k * 2d, k * 2d + chain_size)
  HugeVector<Linear> coef;        // leaf k's point's motion on axis i: coef[k * d + i]
  /// The leaves threaded left to right: leaf k's successor and point (what a report reads),
  /// its predecessor, and each node's first and last leaf. A subtree's leaves are the run
  /// from its first leaf to its last.
  HugeVector<std::array<std::uint32_t, 2>> link;  // {next leaf, point}
  std::vector<std::uint32_t> prev;
  HugeVector<std::array<std::uint32_t, 2>> span;   // {first leaf, last leaf}
  std::uint32_t tail = kNoIndex;                   // during a build: the last leaf made
  std::vector<std::uint32_t> free;                 // free active-node slots
  std::vector<std::uint32_t> free_leaves;          // free leaf slots
  /// Slots laid out by layout() for a build or a compaction (see upper()): leaves
  /// [0, first_inner), taken in order (next_leaf); active nodes after them, the upper ones from
  /// the front (next_inner), the others from the back (next_lower: one past the last unused).
  std::uint32_t next_leaf = 0, first_inner = 0, next_inner = 0, next_lower = 0;
  std::uint32_t root = kNoIndex;
};

/// A box side pair [lo, hi] of a query against its margin (numeric::below_cut / above_cut): a
/// stored motion's filtered value v (within the margin of x(t)) below below_lo is certainly below
/// lo, one above above_lo certainly above it; the same for hi.
struct KineticKdTree::SideCuts {
  double below_lo, above_lo, below_hi, above_hi;
};
struct KineticKdTree::Query {
  const Box* box;
  Time t;
  std::vector<std::uint32_t>* out;
  std::uint64_t visits;
  std::uint64_t all;  // the d low bits
  /// A subtree of at most this many leaves is scanned, not descended (range_bucket()).
  std::uint32_t bucket;
  /// The box's sides against the query's margin (query_margin(): at least the filter's error
  /// bound of every stored motion at t), per axis (SideCuts): a filtered value is compared with a
  /// side by one comparison per certain answer.
  const SideCuts* cuts;
};
/// A point's leaf and the leaf's depth (read by every event).
struct KineticKdTree::LeafRef {
  std::uint32_t node = kNoIndex;
  std::uint32_t depth = 0;
};

inline const KineticKdTree::Linear& KineticKdTree::split_motion(int axis,
                                                                std::uint32_t label) const {
  const auto a = static_cast<std::size_t>(axis);
  return by_rank_[a][split_slot(label, log_space_[a])];
}

inline KineticKdTree::Linear& KineticKdTree::row_entry(int axis, std::uint32_t label) {
  const auto a = static_cast<std::size_t>(axis);
  return by_rank_[a][split_slot(label, log_space_[a])];
}

/// Entry k of the node's chain (top-down), from the node or from Trie::chains.
inline KineticKdTree::ChainEntry KineticKdTree::chain_entry(const Trie& t, std::uint32_t node,
                                                            std::uint32_t k) const {
  if (inline_chains()) {
    const Node& v = t.nodes[node];
    return ChainEntry{v.chain_median[k], static_cast<std::uint16_t>(v.chain_tag[k] >> 1),
                      static_cast<std::uint8_t>(v.chain_tag[k] & 1U)};
  }
  return t.chains[static_cast<std::size_t>(node) * 2 * static_cast<std::size_t>(d_) + k];
}

KineticKdTree::KineticKdTree(const MotionTable& motions, Simulator& simulator,
                             const Scheduler& scheduler)
    : AxisSortedPoints(motions, simulator, scheduler, "KineticKdTree", 64,
                       "points in 1 to 64 dimensions"),
      trie_(std::make_unique<Trie>()),
      coef_max_(std::make_unique<Linear>()) {}

KineticKdTree::~KineticKdTree() {
  static_assert(sizeof(Node) == 64, "a node and its inline chain fill one cache line");
}

// ---------------------------------------------------------------------------------------------
// Keys: the halving of the labels [0, U_i - 1] (U_i a power of two: the side taken at level l is
// bit l of the label from the top).

void KineticKdTree::rebuild_tables() {
  log_space_.assign(static_cast<std::size_t>(d_), 0);
  for (int axis = 0; axis < d_; ++axis) {
    const std::size_t slots = sorts_[static_cast<std::size_t>(axis)].slots();
    std::uint32_t log = 0;
    while ((std::size_t{1} << log) < slots) ++log;
    log_space_[static_cast<std::size_t>(axis)] = log;
  }
}

int KineticKdTree::bit(std::uint32_t point, std::uint32_t depth) const {
  const int axis = axis_of(depth);
  const std::uint32_t level = depth / static_cast<std::uint32_t>(d_);
  const std::uint32_t log = log_space_[static_cast<std::size_t>(axis)];
  if (level >= log) return 0;  // a range of one label: no further split
  return static_cast<int>((rank_of(point, axis) >> (log - 1 - level)) & 1U);
}

std::uint32_t KineticKdTree::median(std::uint32_t point, std::uint32_t depth) const {
  // The range at this level holds the point's label; its median is the first label of its upper
  // half (the range itself when it is one label).
  const int axis = axis_of(depth);
  const std::uint32_t level = depth / static_cast<std::uint32_t>(d_);
  const std::uint32_t log = log_space_[static_cast<std::size_t>(axis)];
  const std::uint32_t r = rank_of(point, axis);
  if (level >= log) return r;
  const std::uint32_t width = std::uint32_t{1} << (log - level);  // the range's size
  return (r & ~(width - 1)) + width / 2;
}

// ---------------------------------------------------------------------------------------------
// The trie.

bool KineticKdTree::upper(const Trie& t, std::uint32_t parent) {
  return parent == kNoIndex || t.nodes[parent].leaves > kBucket;
}

std::uint32_t KineticKdTree::new_node(Trie& t, bool leaf, bool read_by_queries) const {
  // Leaves and active nodes have their own slots: a build or compaction (layout()) gives the
  // leaves the slots 0 .. n - 1 in thread order and the active nodes the slots after them (the
  // order of upper()); a freed leaf slot is reused by a leaf, so the leaves of a subtree stay
  // close to a contiguous run.
  std::vector<std::uint32_t>& pool = leaf ? t.free_leaves : t.free;
  const bool fresh = leaf ? t.next_leaf < t.first_inner : t.next_inner < t.next_lower;
  std::uint32_t k = 0;
  if (!pool.empty() || fresh) {
    if (!pool.empty()) {
      k = pool.back();
      pool.pop_back();
    } else if (leaf) {
      k = t.next_leaf++;
    } else {
      k = read_by_queries ? t.next_inner++ : --t.next_lower;
    }
    t.nodes[k] = Node{};
    t.link[k] = {kNoIndex, kNoIndex};
    t.prev[k] = kNoIndex;
    t.span[k] = {k, k};
  } else {
    k = static_cast<std::uint32_t>(t.nodes.size());
    t.nodes.emplace_back();
    if (!inline_chains()) t.chains.resize(t.chains.size() + 2 * static_cast<std::size_t>(d_));
    t.coef.resize(t.coef.size() + static_cast<std::size_t>(d_));
    t.link.push_back({kNoIndex, kNoIndex});
    t.prev.push_back(kNoIndex);
    t.span.push_back({k, k});
  }
  return k;
}

KineticKdTree::Linear KineticKdTree::to_linear(const MotionPolynomial& p, double& error) const {
  error = 0.0;
  const numeric::LinearParts m = numeric::linear_parts(p);
  if (m.c1 != m.c1) return Linear{m.c0, m.c1};  // degree above 1
  const FilteredValue x = numeric::linear_filtered(m.c0, m.c1, m.origin, reference_);
  if (!(x.error < HUGE_VAL) || !(std::fabs(x.value) < HUGE_VAL)) return Linear{m.c0, std::nan("")};
  error = x.error;
  return Linear{x.value, m.c1};
}

void KineticKdTree::note_linear(const Linear& l, double error) {
  coef_max_->c0 = std::max(coef_max_->c0, std::fabs(l.c0));
  if (l.c1 == l.c1) coef_max_->c1 = std::max(coef_max_->c1, std::fabs(l.c1));
  reference_error_ = std::max(reference_error_, error);
}

double KineticKdTree::filter_error(double own) const {
  // The stored value c0 is within reference_error_ of x(T); the sum's rounding is absorbed by
  // the factor.
  return (own + reference_error_) * (1.0 + 0x1p-50);
}

FilteredValue KineticKdTree::filtered(const Linear& l, Time t) const {
  FilteredValue x = numeric::linear_filtered(l.c0, l.c1, reference_, t);
  x.error = filter_error(x.error);
  return x;
}

void KineticKdTree::refresh_linear() {
  // In index order: one sequential pass over the table (a build then reads this compact copy),
  // about the build's time.
  const auto d = static_cast<std::size_t>(d_);
  reference_ = sim_.now();
  reference_error_ = 0.0;
  *coef_max_ = Linear{};
  linear_.assign(motions_.capacity() * d, Linear{});
  for (const std::uint32_t point : motions_.alive_indices()) {
    for (int axis = 0; axis < d_; ++axis) {
      double error = 0.0;
      const Linear l = to_linear(motions_.motion(point, axis), error);
      linear_[point * d + static_cast<std::size_t>(axis)] = l;
      note_linear(l, error);
    }
  }
}

KineticKdTree::Linear KineticKdTree::linear(std::uint32_t point, int axis) const {
  return linear_[static_cast<std::size_t>(point) * static_cast<std::size_t>(d_) +
                 static_cast<std::size_t>(axis)];
}

void KineticKdTree::set_leaf(Trie& t, std::uint32_t node, std::uint32_t point) const {
  t.nodes[node].point = point;
  t.nodes[node].rep = point;
  t.link[node][1] = point;
  t.span[node] = {node, node};
}

void KineticKdTree::set_leaf_motions(Trie& t, std::uint32_t node) const {
  const auto d = static_cast<std::size_t>(d_);
  const std::uint32_t point = t.nodes[node].point;
  for (std::size_t axis = 0; axis < d; ++axis) {
    t.coef[node * d + axis] = linear_[point * d + axis];
  }
}

void KineticKdTree::fill_leaf_motions(Trie& t) const {
  // Each leaf keeps its point's motions, so a query that checks neighbouring leaves reads
  // neighbouring memory (a build lays nodes out in depth-first order). The points are read in
  // random order: fetch a few leaves ahead.
  const auto d = static_cast<std::size_t>(d_);
  const std::size_t count = t.nodes.size();
  constexpr std::size_t kAhead = 16;
  for (std::size_t k = 0; k < count; ++k) {
    if (k + kAhead < count && t.nodes[k + kAhead].point != kNoIndex) {
      __builtin_prefetch(&linear_[t.nodes[k + kAhead].point * d]);
    }
    if (t.nodes[k].point != kNoIndex) set_leaf_motions(t, static_cast<std::uint32_t>(k));
  }
}

std::uint32_t KineticKdTree::logical_chain(const Trie& t, std::uint32_t node,
                                           std::array<ChainEntry, 128>& chain) const {
  // The skeleton nodes strictly between the parent (or above the root: from depth 0) and `node`
  // are degree-one nodes on the path of node's key. Keep those whose hyperplane bounds node's
  // region: the lowest one for each (axis, side) on that stretch (Abam, de Berg, Speckmann,
  // "useful" nodes).
  const Node& v = t.nodes[node];
  const std::uint32_t from =
      v.parent == kNoIndex ? 0 : t.nodes[v.parent].depth + 1;  // first skeleton depth of the edge
  std::array<std::uint8_t, 128> seen{};                        // 2d <= 128
  std::uint32_t size = 0;
  for (std::uint32_t s = v.depth; s-- > from;) {  // bottom-up: the first seen is the lowest
    const int axis = axis_of(s);
    const int side = bit(v.rep, s);
    std::uint8_t& mark = seen[static_cast<std::size_t>(axis) * 2 + static_cast<std::size_t>(side)];
    if (mark) continue;
    mark = 1;
    chain[size++] = ChainEntry{median(v.rep, s), static_cast<std::uint16_t>(axis),
                               static_cast<std::uint8_t>(side)};
  }
  std::reverse(chain.begin(), chain.begin() + size);  // top-down, as a query meets them
  return size;
}

void KineticKdTree::set_chain(Trie& t, std::uint32_t node) const {
  std::array<ChainEntry, 128> chain;
  const std::uint32_t size = logical_chain(t, node, chain);
  Node& v = t.nodes[node];
  v.chain_size = static_cast<std::uint8_t>(size);
  if (inline_chains()) {  // in the node's own cache line; the unused slots stay zero
    v.chain_median = {};
    v.chain_tag = {};
    for (std::uint32_t k = 0; k < size; ++k) {
      v.chain_median[k] = chain[k].median;
      v.chain_tag[k] = static_cast<std::uint8_t>(2 * chain[k].axis + chain[k].side);
    }
  } else {
    std::copy_n(chain.begin(), size,
                &t.chains[static_cast<std::size_t>(node) * 2 * static_cast<std::size_t>(d_)]);
  }
}

bool KineticKdTree::chains_valid() const {
  // Every node of the tree: its stored chain (inline for d <= 3) is the chain recomputed from
  // the current ranks, and an inline chain's unused slots are zero.
  const Trie& t = *trie_;
  if (t.root == kNoIndex) return true;
  if (inline_chains() && !t.chains.empty()) return false;
  std::vector<std::uint32_t> stack{t.root};
  std::array<ChainEntry, 128> chain;
  while (!stack.empty()) {
    const std::uint32_t k = stack.back();
    stack.pop_back();
    const Node& v = t.nodes[k];
    const std::uint32_t size = logical_chain(t, k, chain);
    if (v.chain_size != size) return false;
    for (std::uint32_t j = 0; j < size; ++j) {
      const ChainEntry e = chain_entry(t, k, j);
      if (e.median != chain[j].median || e.axis != chain[j].axis || e.side != chain[j].side) {
        return false;
      }
    }
    if (inline_chains()) {
      for (std::uint32_t j = size; j < kInline; ++j) {
        if (v.chain_median[j] != 0 || v.chain_tag[j] != 0) return false;
      }
    }
    if (v.point == kNoIndex) {
      stack.push_back(v.child[0]);
      stack.push_back(v.child[1]);
    }
  }
  return true;
}

std::uint32_t KineticKdTree::build(Trie& t, std::vector<std::uint32_t>& points, std::size_t lo,
                                   std::size_t hi, std::uint32_t depth,
                                   std::uint32_t parent) const {
  const std::uint32_t k = new_node(t, hi - lo == 1, upper(t, parent));
  t.nodes[k].parent = parent;
  t.nodes[k].rep = points[lo];
  if (hi - lo == 1) {  // alone: a leaf at this depth
    t.nodes[k].depth = depth;
    set_leaf(t, k, points[lo]);
    set_chain(t, k);
    if (t.tail != kNoIndex) t.link[t.tail][0] = k;  // leaves are made left to right
    t.prev[k] = t.tail;
    t.tail = k;
    return k;
  }
  // The first depth where the points do not all take the same side: an active node.
  std::uint32_t s = depth;
  for (;; ++s) {
    const int b0 = bit(points[lo], s);
    bool split = false;
    for (std::size_t j = lo + 1; j < hi && !split; ++j) split = bit(points[j], s) != b0;
    if (split) break;
    assert(s < 64u * static_cast<std::uint32_t>(d_));
  }
  t.nodes[k].depth = s;
  t.nodes[k].axis = static_cast<std::uint8_t>(axis_of(s));
  t.nodes[k].median = median(points[lo], s);
  t.nodes[k].leaves = static_cast<std::uint32_t>(hi - lo);  // read by the children's new_node()
  set_chain(t, k);
  const auto mid = std::stable_partition(points.begin() + static_cast<std::ptrdiff_t>(lo),
                                         points.begin() + static_cast<std::ptrdiff_t>(hi),
                                         [&](std::uint32_t p) { return bit(p, s) == 0; });
  const std::size_t m = static_cast<std::size_t>(mid - points.begin());
  const std::uint32_t left = build(t, points, lo, m, s + 1, k);
  const std::uint32_t right = build(t, points, m, hi, s + 1, k);
  t.nodes[k].child = {left, right};
  t.nodes[k].rep = t.nodes[left].rep;  // the invariant erase() relies on: a child's rep
  t.span[k] = {t.span[left][0], t.span[right][1]};
  assert(t.nodes[k].leaves == t.nodes[left].leaves + t.nodes[right].leaves);
  return k;
}

void KineticKdTree::build_all(Trie& t) const {
  t = Trie{};
  std::vector<std::uint32_t> points = motions_.alive_indices();
  layout(t, points.size());
  if (!points.empty()) t.root = build(t, points, 0, points.size(), 0, kNoIndex);
  assert(t.next_leaf == t.first_inner && t.next_inner == t.next_lower);  // every slot taken
}

void KineticKdTree::layout(Trie& t, std::size_t points) const {
  // All 2n - 1 slots at once: leaves first (made left to right by build(), so in thread order),
  // then the active nodes: the upper ones in preorder from the front, the others from the back.
  const std::size_t nodes = points == 0 ? 0 : 2 * points - 1;
  const auto d = static_cast<std::size_t>(d_);
  t.nodes.resize(nodes);
  if (!inline_chains()) t.chains.resize(nodes * 2 * d);
  t.coef.resize(nodes * d);
  t.link.resize(nodes, {kNoIndex, kNoIndex});
  t.prev.resize(nodes, kNoIndex);
  t.span.resize(nodes);
  t.next_leaf = 0;
  t.first_inner = t.next_inner = static_cast<std::uint32_t>(points);
  t.next_lower = static_cast<std::uint32_t>(nodes);
}

std::uint32_t KineticKdTree::copy_subtree(const Trie& from, std::uint32_t x, Trie& to,
                                          std::uint32_t parent) {
  const Node& v = from.nodes[x];
  const bool leaf = v.point != kNoIndex;
  const std::uint32_t k = new_node(to, leaf, upper(from, v.parent));
  to.nodes[k] = v;
  to.nodes[k].parent = parent;
  if (!inline_chains()) {  // an inline chain was copied with the node
    const std::size_t w = 2 * static_cast<std::size_t>(d_);
    std::copy_n(&from.chains[x * w], v.chain_size, &to.chains[k * w]);
  }
  if (leaf) {
    const auto d = static_cast<std::size_t>(d_);
    std::copy_n(&from.coef[x * d], d, &to.coef[k * d]);
    to.link[k][1] = v.point;
    if (to.tail != kNoIndex) to.link[to.tail][0] = k;  // leaves are copied left to right
    to.prev[k] = to.tail;
    to.tail = k;
    leaf_of_[v.point].node = k;
    return k;
  }
  const std::uint32_t left = copy_subtree(from, v.child[0], to, k);
  const std::uint32_t right = copy_subtree(from, v.child[1], to, k);
  to.nodes[k].child = {left, right};
  to.span[k] = {to.span[left][0], to.span[right][1]};
  to.nodes[k].leaves = to.nodes[left].leaves + to.nodes[right].leaves;
  return k;
}

void KineticKdTree::compact() {
  ++mutations_;
  moved_since_layout_ = 0;
  if (trie_->root == kNoIndex) return;
  Trie t;
  layout(t, trie_->nodes[trie_->root].leaves);
  t.root = copy_subtree(*trie_, trie_->root, t, kNoIndex);
  assert(t.next_leaf == t.first_inner && t.next_inner == t.next_lower);  // every slot taken
  t.tail = kNoIndex;
  *trie_ = std::move(t);
  ++counters_.compactions;
}

void KineticKdTree::rebuild() {
  ++mutations_;
  moved_since_layout_ = 0;
  n_ = motions_.size();
  rebuild_tables();
  refresh_linear();
  build_all(*trie_);
  leaf_of_.assign(motions_.capacity(), LeafRef{});
  for (std::uint32_t k = 0; k < trie_->nodes.size(); ++k) {
    const Node& v = trie_->nodes[k];
    if (v.point != kNoIndex) leaf_of_[v.point] = LeafRef{k, v.depth};
  }
  fill_leaf_motions(*trie_);
  refresh_coefficients();
}

void KineticKdTree::initialize() {
  sync_.note();
  sorts_.initialize();
  rebuild();
}

void KineticKdTree::erase(std::uint32_t point) {
  Trie& t = *trie_;
  const std::uint32_t leaf = leaf_of_[point].node;
  leaf_of_[point] = LeafRef{};
  const std::uint32_t u = t.nodes[leaf].parent;
  t.free_leaves.push_back(leaf);
  ++counters_.nodes_removed;
  // Unthread the leaf; ancestors that began (ended) with it now begin (end) with its successor
  // (predecessor), which lies in the same subtree. They are the lowest ones, up to the first
  // that neither begins nor ends with it (a node's first leaf is its left child's).
  const std::uint32_t before = t.prev[leaf], after = t.link[leaf][0];
  if (before != kNoIndex) t.link[before][0] = after;
  if (after != kNoIndex) t.prev[after] = before;
  for (std::uint32_t a = u == kNoIndex ? kNoIndex : t.nodes[u].parent; a != kNoIndex;
       a = t.nodes[a].parent) {
    bool changed = false;
    if (t.span[a][0] == leaf) t.span[a][0] = after, changed = true;
    if (t.span[a][1] == leaf) t.span[a][1] = before, changed = true;
    if (!changed) break;
  }
  // u stops being active: its other child takes its place under u's parent.
  const trie::Contraction k = trie::contract(t.nodes, t.root, leaf);
  if (k.removed == kNoIndex) return;
  const std::uint32_t c = k.survivor, g = k.parent;
  t.free.push_back(u);
  ++counters_.nodes_removed;
  // A leaf is where its point is alone in the skeleton: right below its active parent.
  if (t.nodes[c].point != kNoIndex) {
    t.nodes[c].depth = g == kNoIndex ? 0 : t.nodes[g].depth + 1;
    leaf_of_[t.nodes[c].point].depth = t.nodes[c].depth;
  }
  set_chain(t, c);  // the kept degree-one nodes above c change with its new parent
  // Every node's rep is the rep of one of its children, so the ancestors whose rep is `point`
  // are the lowest ones up to the first that is not: replace them by c's rep (a child's rep
  // again), and stop there. Their chains are read again from the new rep: a chain set while
  // `point` was the rep may have read its new labels (a change erases every moved point before
  // it inserts any, and set_chain(c) above reads c's rep, which may be a moved point still in the
  // tree at its old place), and this is where such a stale chain is put right.
  for (std::uint32_t a = g; a != kNoIndex && t.nodes[a].rep == point; a = t.nodes[a].parent) {
    t.nodes[a].rep = t.nodes[c].rep;
    set_chain(t, a);
  }
}

void KineticKdTree::insert_point(std::uint32_t point) {
  Trie& t = *trie_;
  const std::uint32_t leaf = new_node(t, true, false);
  ++counters_.nodes_created;
  set_leaf(t, leaf, point);
  set_leaf_motions(t, leaf);
  leaf_of_[point] = LeafRef{leaf, 0};
  if (t.root == kNoIndex) {
    t.root = leaf;
    t.nodes[leaf].depth = 0;
    set_chain(t, leaf);
    return;
  }
  std::uint32_t cur = t.root;
  std::uint32_t from = 0;  // depths < from are known to agree with cur's points
  for (;;) {
    const Node& c = t.nodes[cur];
    const std::uint32_t limit =
        c.point != kNoIndex ? kNoIndex : c.depth;  // a leaf: search below it
    std::uint32_t s = from;
    while ((limit == kNoIndex || s < limit) && bit(point, s) == bit(c.rep, s)) ++s;
    if (limit != kNoIndex && s == limit) {  // agrees down to the active node: descend
      from = c.depth + 1;
      cur = c.child[static_cast<std::size_t>(bit(point, c.depth))];
      continue;
    }
    // The key leaves cur's path at depth s: a new active node there, above cur.
    const std::uint32_t x = new_node(t, false, false);  // no fresh slot left: a freed one
    ++counters_.nodes_created;
    const std::uint32_t g = t.nodes[cur].parent;
    t.nodes[x].depth = s;
    t.nodes[x].axis = static_cast<std::uint8_t>(axis_of(s));
    t.nodes[x].rep = t.nodes[cur].rep;
    t.nodes[x].median = median(point, s);  // p shares the prefix above s with cur's points
    const int side = bit(point, s);
    trie::split_above(t.nodes, t.root, cur, x, leaf, side);
    // Thread the leaf before cur's first leaf (side 0) or after its last (side 1); x spans both,
    // and the ancestors that began (ended) with cur's first (last) leaf now begin (end) with it.
    const std::array<std::uint32_t, 2> around = t.span[cur];
    if (side == 0) {
      const std::uint32_t before = t.prev[around[0]];
      t.prev[leaf] = before;
      t.link[leaf][0] = around[0];
      t.prev[around[0]] = leaf;
      if (before != kNoIndex) t.link[before][0] = leaf;
      t.span[x] = {leaf, around[1]};
    } else {
      const std::uint32_t after = t.link[around[1]][0];
      t.prev[leaf] = around[1];
      t.link[leaf][0] = after;
      t.link[around[1]][0] = leaf;
      if (after != kNoIndex) t.prev[after] = leaf;
      t.span[x] = {around[0], leaf};
    }
    for (std::uint32_t a = g; a != kNoIndex; a = t.nodes[a].parent) {
      const auto end = static_cast<std::size_t>(side);
      if (t.span[a][end] != around[end]) break;
      t.span[a][end] = leaf;
    }
    t.nodes[leaf].depth = s + 1;
    leaf_of_[point].depth = s + 1;
    if (t.nodes[cur].point != kNoIndex) {  // a leaf: now alone below x
      t.nodes[cur].depth = s + 1;
      leaf_of_[t.nodes[cur].point].depth = s + 1;
    }
    set_chain(t, x);
    set_chain(t, cur);
    set_chain(t, leaf);
    return;
  }
}

EventKind KineticKdTree::process(const Event& event) {
  ++mutations_;
  const auto axis = static_cast<std::uint32_t>(sorts_.member_of(event));
  KineticSort& s = sorts_[axis];
  const KineticSort::Swap swap = s.process_swap(event);
  ++counters_.swaps;
  // x moved up from label j to the next point's label k past its neighbour y (k = j + 1 unless
  // j ends a segment of A_axis): only their keys changed.
  const std::uint32_t x = swap.up, y = swap.down;
  const std::uint32_t j = swap.position, k = swap.next;
  // The split coefficients follow the order.
  std::swap(row_entry(static_cast<int>(axis), j), row_entry(static_cast<int>(axis), k));
  // The empty slots before j and before k hold the motion of the point after them.
  for (std::uint32_t r = k; r-- > j + 1;) {
    row_entry(static_cast<int>(axis), r) = row_entry(static_cast<int>(axis), k);
  }
  if (j > 0 && s.order()[j - 1] == kNoIndex) refresh_rows(static_cast<int>(axis), j, j);
  // Labels j and k take the same sides at the halvings of [0, U - 1] above level L, the first
  // level whose bits differ (where a median between them separates them). So the keys of x and
  // y change only at skeleton depths >= s* = L d + axis. A point whose leaf lies at depth <= s* is
  // alone in the skeleton above s*: its longest common prefix with every other point (y included,
  // old or new key) is shorter than s*, so every branching node, side, chain and split it meets is
  // read from unchanged bits, and T(P) does not change for it. Only a point whose leaf lies
  // deeper is deleted and reinserted (the tree of the others does not depend on the other
  // point's bits below s* either, by the same argument). A split whose median label lies in
  // (j, k] reads the point at k, x now instead of y: x and y are next to each other in A_axis, so
  // the region bounds it gives change for no point but x and y.
  const auto level = log_space_[axis] - static_cast<std::uint32_t>(std::bit_width(j ^ k));
  const std::uint32_t changed = level * static_cast<std::uint32_t>(d_) + axis;  // s*
  const bool move_x = leaf_of_[x].depth > changed;
  const bool move_y = leaf_of_[y].depth > changed;
  if (!move_x && !move_y) {
    ++counters_.unchanged_events;
    return EventKind::External;
  }
  // The ranks are already swapped; erase() and insert_point() read the new ones, and erase()
  // needs nothing but the leaf, so delete first, then insert.
  if (move_x) erase(x);
  if (move_y) erase(y);
  if (move_x) insert_point(x);
  if (move_y) insert_point(y);
  counters_.reinsertions += (move_x ? 1U : 0U) + (move_y ? 1U : 0U);
  // Reinserted leaves and active nodes take freed slots: the slot order drifts from the thread
  // order (locally: a point moves within the subtree where its key changed). Every n / 8
  // reinsertions the tree is copied into fresh slots: O(dn), 12-20 ms at n = 10^5 in the event
  // that triggers it (docs/performance/kdtree.md).
  moved_since_layout_ += (move_x ? 1U : 0U) + (move_y ? 1U : 0U);
  if (moved_since_layout_ > n_ / 8) compact();
  return EventKind::External;
}

void KineticKdTree::set_linear(std::uint32_t point) {
  const auto d = static_cast<std::size_t>(d_);
  if (linear_.size() < motions_.capacity() * d) linear_.resize(motions_.capacity() * d, Linear{});
  for (int axis = 0; axis < d_; ++axis) {
    double error = 0.0;
    const Linear l = to_linear(motions_.motion(point, axis), error);
    linear_[point * d + static_cast<std::size_t>(axis)] = l;
    note_linear(l, error);
  }
}

bool KineticKdTree::follow_sort(int axis, std::uint64_t generation, std::uint32_t own) {
  const KineticSort& s = sorts_[static_cast<std::size_t>(axis)];
  if (s.layout_generation() != generation) return false;
  for (const auto& [lo, hi] : s.touched_slots()) refresh_rows(axis, lo, hi);
  if (moved_mark_.size() < motions_.capacity()) moved_mark_.resize(motions_.capacity(), 0);
  const auto told = s.relabeled();
  const auto from = s.relabeled_from();
  for (std::size_t k = 0; k < told.size(); ++k) {
    // Each moved key once, with the slot it held before the change.
    const std::uint32_t p = told[k];
    if (p == own) continue;
    const std::uint32_t was = from[k], now = rank_of(p, axis);
    if (was == now) continue;
    // As for an event: labels `was` and `now` take the same sides above level L, so p's key
    // changed only at depths >= s* = L d + axis; a leaf at depth <= s* stays (p is alone in the
    // skeleton above s*), and no other point's place depends on p's bits below its leaf.
    const auto level = log_space_[static_cast<std::size_t>(axis)] -
                       static_cast<std::uint32_t>(std::bit_width(was ^ now));
    if (leaf_of_[p].depth <=
        level * static_cast<std::uint32_t>(d_) + static_cast<std::uint32_t>(axis)) {
      ++counters_.unchanged_relabels;
      continue;
    }
    if (moved_mark_[p] == moved_round_) continue;
    moved_mark_[p] = moved_round_;
    moved_.push_back(p);
  }
  return true;
}

void KineticKdTree::reinsert_moved(std::uint32_t own) {
  // As for an event: every moved point out first (erase() needs only the leaf), then in again
  // with its new labels (insert_point() reads the others' current labels).
  for (const std::uint32_t p : moved_) erase(p);
  for (const std::uint32_t p : moved_) insert_point(p);
  if (own != kNoIndex) insert_point(own);
  counters_.relabel_reinsertions += moved_.size();
  ++counters_.local_changes;
  moved_since_layout_ += moved_.size() + 1;
  if (moved_since_layout_ > n_ / 8) compact();
}

template <class Change>
void KineticKdTree::change_sorts(std::uint32_t index, std::uint32_t reinsert, Change&& change) {
  ++moved_round_;
  moved_.clear();
  bool laid_out_again = false;
  for (int axis = 0; axis < d_; ++axis) {
    KineticSort& s = sorts_[static_cast<std::size_t>(axis)];
    const std::uint64_t generation = s.layout_generation();
    change(s);
    if (!follow_sort(axis, generation, index)) laid_out_again = true;
  }
  n_ = motions_.size();
  if (laid_out_again) {
    ++counters_.rebuilds;
    rebuild();
    return;
  }
  reinsert_moved(reinsert);
}

void KineticKdTree::insert(std::uint32_t index) {
  sync_.require_inserted("KineticKdTree::insert", index);
  ++mutations_;
  if (leaf_of_.size() < motions_.capacity()) leaf_of_.resize(motions_.capacity(), LeafRef{});
  set_linear(index);
  change_sorts(index, index, [index](KineticSort& s) { s.insert(index); });
}

void KineticKdTree::remove(std::uint32_t index) {
  sync_.require_removed("KineticKdTree::remove", index);
  ++mutations_;
  erase(index);  // its leaf first, while its labels are still the tree's
  leaf_of_[index] = LeafRef{};
  change_sorts(index, kNoIndex, [index](KineticSort& s) { s.remove(index); });
}

void KineticKdTree::motion_changed(std::uint32_t index) {
  sync_.require_updated("KineticKdTree::motion_changed", index);
  ++mutations_;
  erase(index);
  set_linear(index);
  change_sorts(index, index, [index](KineticSort& s) { s.motion_changed(index); });
}

// ---------------------------------------------------------------------------------------------
// Queries.

int KineticKdTree::compare_to(const MotionPolynomial& p, double x, Time t) const {
  return compare_at_value(p, x, t, &sim_.counters().predicates);
}

void KineticKdTree::refresh_coefficients() {
  const auto d = static_cast<std::size_t>(d_);
  by_rank_.assign(d, {});
  for (int axis = 0; axis < d_; ++axis) {
    const std::size_t slots = sorts_[static_cast<std::size_t>(axis)].slots();
    // Room for every label's place in the hierarchy's order (split_slot()).
    by_rank_[static_cast<std::size_t>(axis)].resize(
        slots == 0 ? 0 : std::size_t{1} << log_space_[static_cast<std::size_t>(axis)]);
    if (slots > 0) refresh_rows(axis, 0, slots - 1);
  }
}

void KineticKdTree::refresh_rows(int axis, std::size_t lo, std::size_t hi) {
  // Back to front, so that an empty slot takes the motion of the point after it; the empty
  // slots before lo too (they hold the motion of the point at lo or after).
  const auto order = sorts_[static_cast<std::size_t>(axis)].order();
  const std::size_t next = sorts_[static_cast<std::size_t>(axis)].slot_at_or_after(hi + 1);
  // +infinity after the last point (its value is exactly +infinity: split_vs_box() decides it
  // against a finite side at once, and the exact path sees no point).
  Linear after = next == KineticSort::kNoSlot ? Linear{HUGE_VAL, 0.0}
                                              : row_entry(axis, static_cast<std::uint32_t>(next));
  constexpr std::size_t kAhead = 16;  // random reads: fetch ahead
  std::size_t r = hi + 1;
  while (r-- > 0) {
    if (r < lo && order[r] != kNoIndex) break;
    if (order[r] != kNoIndex) {
      if (r >= lo + kAhead && order[r - kAhead] != kNoIndex) {
        __builtin_prefetch(&linear_[order[r - kAhead] * static_cast<std::size_t>(d_) +
                                    static_cast<std::size_t>(axis)]);
      }
      after = linear(order[r], axis);
    }
    row_entry(axis, static_cast<std::uint32_t>(r)) = after;
  }
}

[[gnu::always_inline]] inline int KineticKdTree::split_vs_box(int axis, std::uint32_t median_rank,
                                                              const Linear& l,
                                                              const std::array<double, 2>& b,
                                                              Time t, const SideCuts& cut) const {
  // c = x_axis(t) of the split point A_axis[median_rank] (its motion l, from split_motion()).
  // Bit 0: b[0] <= c, bit 1: c <= b[1], both exact: a side farther than the query's margin
  // (query_margin(), at least every stored motion's filter bound at t; `cut`) from the filtered
  // value is decided at once, as at the leaves (inside());
  // a closer one by the motion's own bound, then the exact predicate. A NaN value (degree above
  // 1) decides nothing here. The +infinity after the last point is not a filtered value (its own
  // bound is infinite) but the split's exact coordinate, so a finite side is decided right:
  // below it; against an infinite side the exact path decides, as it always did.
  const double v = numeric::linear_value(l.c0, l.c1, reference_, t);
  int lo = v > cut.above_lo ? 1 : (v < cut.below_lo ? -1 : 0);
  int hi = v > cut.above_hi ? 1 : (v < cut.below_hi ? -1 : 0);
  if (lo == 0 || hi == 0) [[unlikely]] {
    const FilteredValue c = filtered(l, t);
    if (lo == 0) lo = numeric::sign_versus(c, b[0]);
    if (hi == 0) hi = numeric::sign_versus(c, b[1]);
  }
  if (lo == 0 || hi == 0) {
    // The split point: the first point at a label >= median (none: the split is at +infinity).
    const KineticSort& s = sorts_[static_cast<std::size_t>(axis)];
    const std::size_t at = s.slot_at_or_after(median_rank);
    if (at == KineticSort::kNoSlot) {
      lo = 1;
      hi = b[1] == HUGE_VAL ? 0 : 1;
    } else {
      const MotionPolynomial& p = motions_.motion(s.order()[at], axis);
      if (lo == 0) lo = compare_to(p, b[0], t);
      if (hi == 0) hi = compare_to(p, b[1], t);
    }
  }
  return (lo >= 0 ? 1 : 0) | (hi <= 0 ? 2 : 0);
}

int KineticKdTree::leaf_side(const Linear& l, std::uint32_t point, int axis, double b,
                             Time t) const {
  const int sign = numeric::sign_versus(filtered(l, t), b);
  return sign != 0 ? sign : compare_to(motions_.motion(point, axis), b, t);
}

[[gnu::always_inline]] inline bool KineticKdTree::inside(std::uint32_t leaf, std::uint32_t point,
                                                         const Query& q, std::uint64_t lo_need,
                                                         std::uint64_t hi_need) const {
  // Only the sides in lo_need / hi_need are compared (exactly: the filter, then the exact
  // predicate with the point's motion); the others are certified by the region's bounds. The
  // value v is the filter's; a side farther from v than the query's margin (>= the leaf's own
  // bound; q.cuts) is decided at once, a closer one goes through the leaf's own bound, then the
  // exact predicate.
  const auto d = static_cast<std::size_t>(d_);
  const Box& box = *q.box;
  for (std::uint64_t m = lo_need | hi_need; m != 0; m &= m - 1) {
    const auto axis = static_cast<std::size_t>(std::countr_zero(m));
    const Linear& l = trie_->coef[leaf * d + axis];
    const auto& b = box[axis];
    const SideCuts& cut = q.cuts[axis];
    const double v = numeric::linear_value(l.c0, l.c1, reference_, q.t);
    if ((lo_need >> axis) & 1U) {
      if (v < cut.below_lo) return false;
      if (!(v > cut.above_lo)) [[unlikely]] {
        if (leaf_side(l, point, static_cast<int>(axis), b[0], q.t) < 0) return false;
      }
    }
    if ((hi_need >> axis) & 1U) {
      if (v > cut.above_hi) return false;
      if (!(v < cut.below_hi)) [[unlikely]] {
        if (leaf_side(l, point, static_cast<int>(axis), b[1], q.t) > 0) return false;
      }
    }
  }
  return true;
}

void KineticKdTree::report(std::uint32_t node, std::vector<std::uint32_t>& out) const {
  // The subtree's leaves: the run of the thread from its first leaf, as many as the node counts
  // (threads_valid() checks that the run ends at its last leaf): room for all at once, then plain
  // stores, exactly that many whatever the thread holds.
  const std::array<std::uint32_t, 2>* link = trie_->link.data();
  const std::size_t at = out.size();
  const std::uint32_t count = trie_->nodes[node].leaves;
  out.resize(at + count);
  std::uint32_t* to = out.data() + at;
  std::uint32_t leaf = trie_->span[node][0];
  for (std::uint32_t k = 0; k < count; ++k, leaf = link[leaf][0]) to[k] = link[leaf][1];
}

bool KineticKdTree::query_data_valid() const {
  // The motions the queries read: by rank on every axis, and at every leaf.
  const auto d = static_cast<std::size_t>(d_);
  auto same_motion = [](const Linear& a, const Linear& b) {
    return a.c0 == b.c0 && (a.c1 == b.c1 || (a.c1 != a.c1 && b.c1 != b.c1));
  };
  for (int axis = 0; axis < d_; ++axis) {
    const KineticSort& s = sorts_[static_cast<std::size_t>(axis)];
    const auto order = s.order();
    const auto& row = by_rank_[static_cast<std::size_t>(axis)];
    const std::size_t room =
        order.empty() ? 0 : std::size_t{1} << log_space_[static_cast<std::size_t>(axis)];
    if (row.size() != room) return false;
    for (std::size_t r = 0; r < order.size(); ++r) {
      // An empty slot: the motion of the next point, or +infinity after the last.
      const std::size_t at = s.slot_at_or_after(r);
      const Linear want =
          at == KineticSort::kNoSlot ? Linear{HUGE_VAL, 0.0} : linear(order[at], axis);
      if (!same_motion(split_motion(axis, static_cast<std::uint32_t>(r)), want)) return false;
    }
  }
  for (const std::uint32_t p : motions_.alive_indices()) {
    for (int axis = 0; axis < d_; ++axis) {
      double error = 0.0;
      const Linear want = to_linear(motions_.motion(p, axis), error);
      if (!same_motion(linear(p, axis), want)) return false;
      // The bounds the queries' margin is computed from.
      if (!(std::fabs(want.c0) <= coef_max_->c0) || !(error <= reference_error_) ||
          (want.c1 == want.c1 && !(std::fabs(want.c1) <= coef_max_->c1))) {
        return false;
      }
      const std::size_t leaf = leaf_of_[p].node;
      if (!same_motion(trie_->coef[leaf * d + static_cast<std::size_t>(axis)], want)) return false;
    }
  }
  return true;
}

bool KineticKdTree::threads_valid() const {
  const Trie& t = *trie_;
  if (t.root == kNoIndex) return true;
  // Depth-first, left to right: the leaves must be threaded in this order, and every node's
  // span must be its first and last leaf.
  std::uint32_t previous = kNoIndex;
  bool ok = true;
  auto walk = [&](auto&& self, std::uint32_t k) -> std::array<std::uint32_t, 2> {
    const Node& v = t.nodes[k];
    if (v.point != kNoIndex) {
      ok = ok && t.prev[k] == previous && t.link[k][1] == v.point;
      if (previous != kNoIndex) ok = ok && t.link[previous][0] == k;
      previous = k;
      ok = ok && t.span[k] == std::array<std::uint32_t, 2>{k, k} && v.leaves == 1;
      return {k, k};
    }
    const auto l = self(self, v.child[0]);
    const auto r = self(self, v.child[1]);
    ok = ok && t.span[k] == std::array<std::uint32_t, 2>{l[0], r[1]} &&
         v.leaves == t.nodes[v.child[0]].leaves + t.nodes[v.child[1]].leaves;
    return {l[0], r[1]};
  };
  walk(walk, t.root);
  return ok && t.link[previous][0] == kNoIndex;
}

void KineticKdTree::scan(std::uint32_t node, Query& q, std::uint64_t lo_in,
                         std::uint64_t hi_in) const {
  // Each leaf of the run is compared with the box, exactly, on the sides that the region's
  // bounds do not already certify inside the box (a certified side is taken without a test, as
  // for a region inside the box: docs/kdtree.md); each leaf tested counts as a visit (in 2-D
  // and 3-D each group's box tested too).
  const std::uint64_t lo_need = ~lo_in & q.all, hi_need = ~hi_in & q.all;
  if (d_ == 2) {
    scan_fixed<2>(node, q, lo_need, hi_need);
  } else if (d_ == 3) {
    scan_fixed<3>(node, q, lo_need, hi_need);
  } else {
    const auto [first, last] = trie_->span[node];
    const std::array<std::uint32_t, 2>* link = trie_->link.data();
    for (std::uint32_t leaf = first;; leaf = link[leaf][0]) {
      ++q.visits;
      const std::uint32_t point = link[leaf][1];
      if (inside(leaf, point, q, lo_need, hi_need)) q.out->push_back(point);
      if (leaf == last) break;
    }
  }
}

namespace {

/// A range scan's cuts in D dimensions (KineticKdTree::scan_fixed()): per axis, a value below
/// out_lo or above out_hi is certainly outside the box, one above in_lo and below in_hi certainly
/// inside; a side that needs no test is at -infinity (+infinity), which no value is beyond and
/// every finite value is inside of.
template <int D>
struct ScanCuts {
  std::array<double, D> out_lo, out_hi, in_lo, in_hi;

  /// Values between lo[a] and hi[a] on each axis a in kAxes (a group's box; one value: lo = hi):
  /// 0 every value certainly out, 1 every value certainly in, 2 neither (a side within the
  /// margin, a NaN value, or values on both sides).
  template <unsigned kAxes>
  [[gnu::always_inline]] [[nodiscard]] unsigned classify(const double* lo, const double* hi) const {
    bool beyond = false;
    bool within = true;
    for (std::size_t a = 0; a < D; ++a) {
      if (((kAxes >> a) & 1U) == 0) continue;
      beyond |= (hi[a] < out_lo[a]) | (lo[a] > out_hi[a]);
      within &= (lo[a] > in_lo[a]) & (hi[a] < in_hi[a]);
    }
    return beyond ? 0U : (within ? 1U : 2U);
  }
};

}  // namespace

template <int D>
void KineticKdTree::scan_fixed(std::uint32_t node, Query& q, std::uint64_t lo_need,
                               std::uint64_t hi_need) const {
  // The margin tests for every side at once, without a branch per side, each one comparison
  // with the query's cuts (SideCuts: a value below below_cut(b, margin) is certainly below b,
  // one above above_cut(b, margin) certainly above). A leaf beyond a side by more than the margin
  // is out; a leaf inside every side by more than it is in; any other (a side within the margin,
  // or a NaN value: a motion of degree above 1) goes through inside(), the filter with its own
  // bound and the exact predicate. Every decision is certain, so the answer is the exact one
  // whichever decides.
  ScanCuts<D> cuts{};
  for (std::size_t a = 0; a < D; ++a) {
    const SideCuts& cut = q.cuts[a];
    const bool lo = ((lo_need >> a) & 1U) != 0, hi = ((hi_need >> a) & 1U) != 0;
    cuts.out_lo[a] = lo ? cut.below_lo : -HUGE_VAL;
    cuts.in_lo[a] = lo ? cut.above_lo : -HUGE_VAL;
    cuts.out_hi[a] = hi ? cut.above_hi : HUGE_VAL;
    cuts.in_hi[a] = hi ? cut.below_hi : HUGE_VAL;
  }
  // The run's values at t: kept by an earlier query at this time, or computed now from the
  // leaves' coefficients and kept (kept_run(); docs/kdtree.md).
  assert(value_round_.current(q.t, mutations_));
  const RunView run = kept_run<D>(node);
  std::vector<std::uint32_t>& out = *q.out;
  std::uint64_t visits = 0;
  // The axes with a side to test are the same for every leaf of the run: the loop is compiled
  // for each set (`kAxes`, a bit per axis), so a leaf compares only those. Everything it
  // touches is local, so that it stays in registers across the rare exact tests.
  const auto test = [&]<unsigned kAxes>() {
    // Each group's box first: a group beyond a side is skipped, a group inside every side taken
    // whole, any other tested leaf by leaf.
    const ScanCuts<D> c = cuts;
    const RunView r = run;
    std::uint64_t met = 0;
    for (std::size_t g = 0; g < r.groups; ++g) {
      ++met;
      const double* b = r.box + g * 2 * D;
      const unsigned group = c.template classify<kAxes>(b, b + D);
      if (group == 0) continue;
      const std::size_t begin = g * kGroup, end = std::min<std::size_t>(begin + kGroup, r.count);
      if (group == 1) {
        out.insert(out.end(), r.point + begin, r.point + end);
        continue;
      }
      for (std::size_t i = begin; i < end; ++i) {
        ++met;
        const std::uint32_t p = r.point[i];
        const double* v = r.value + i * D;
        const unsigned in = c.template classify<kAxes>(v, v);
        if (in == 1 || (in == 2 && inside(leaf_of_[p].node, p, q, lo_need, hi_need))) {
          out.push_back(p);
        }
      }
    }
    visits = met;
  };
  switch (static_cast<unsigned>(lo_need | hi_need) & ((1U << D) - 1)) {
    case 1:
      test.template operator()<1>();
      break;
    case 2:
      test.template operator()<2>();
      break;
    case 3:
      test.template operator()<3>();
      break;
    case 4:
      if constexpr (D > 2) test.template operator()<4>();
      break;
    case 5:
      if constexpr (D > 2) test.template operator()<5>();
      break;
    case 6:
      if constexpr (D > 2) test.template operator()<6>();
      break;
    case 7:
      if constexpr (D > 2) test.template operator()<7>();
      break;
    default:  // no side to test: every leaf is in (a region inside the box is reported whole)
      test.template operator()<0>();
  }
  q.visits += visits;
}

template <int D>
KineticKdTree::RunView KineticKdTree::kept_run(std::uint32_t node) const {
  // The run of `node` at the round's time: kept already, or computed now and kept. In the
  // thread's order, each leaf's values (what linear_value() computes, and what the scans would
  // compute from the coefficients: the same doubles) and its point; each group's bounding box of
  // the values, -infinity and +infinity on an axis where a value is NaN (a motion of degree
  // above 1).
  assert(node < kept_run_.size());
  KeptRun& kept = kept_run_[node];
  const std::uint32_t count = trie_->nodes[node].leaves;
  constexpr std::size_t kBox = 2 * D;
  const std::size_t groups = (count + kGroup - 1) / kGroup;
  if (kept.round == value_round_.round) {
    return RunView{kept_value_.data() + kept.at * D, kept_point_.data() + kept.at,
                   kept_box_.data() + kept.at / kGroup * kBox, count, groups};
  }
  // Room first; the pools only grow (their entries are written before they are read in a
  // round), kept_point_ last: its size is the room of all three, so a failed allocation leaves
  // the run not kept and the next one tries again. Marked kept once written whole.
  const std::size_t at = kept_used_;
  const std::size_t used = at + groups * kGroup;
  assert(at % kGroup == 0);
  if (kept_point_.size() < used) {
    const std::size_t room = std::max(used, 2 * kept_point_.size());
    kept_value_.resize(room * D);
    kept_box_.resize(room / kGroup * kBox);
    kept_point_.resize(room);
  }
  kept_used_ = used;
  double* const value = kept_value_.data() + at * D;
  std::uint32_t* const point = kept_point_.data() + at;
  double* const box = kept_box_.data() + at / kGroup * kBox;
  const double s = value_round_.time - reference_;  // what linear_value() computes
  const auto [first, last] = trie_->span[node];
  const std::array<std::uint32_t, 2>* link = trie_->link.data();
  const Linear* coef = trie_->coef.data();
  std::array<double, D> lo{}, hi{};
  std::array<bool, D> nan{};
  std::size_t i = 0;
  for (std::uint32_t leaf = first;; leaf = link[leaf][0], ++i) {
    const Linear* l = coef + static_cast<std::size_t>(leaf) * D;
    double* v = value + i * D;
    for (std::size_t a = 0; a < D; ++a) v[a] = l[a].c1 * s + l[a].c0;
    point[i] = link[leaf][1];
    if (i % kGroup == 0) {
      std::copy(v, v + D, lo.begin());
      std::copy(v, v + D, hi.begin());
      nan = {};
    }
    for (std::size_t a = 0; a < D; ++a) {
      lo[a] = v[a] < lo[a] ? v[a] : lo[a];
      hi[a] = v[a] > hi[a] ? v[a] : hi[a];
      nan[a] = nan[a] || v[a] != v[a];
    }
    if (i % kGroup == kGroup - 1 || leaf == last) {
      double* b = box + i / kGroup * kBox;
      for (std::size_t a = 0; a < D; ++a) {
        b[a] = nan[a] ? -HUGE_VAL : lo[a];
        b[D + a] = nan[a] ? HUGE_VAL : hi[a];
      }
    }
    if (leaf == last) break;
  }
  assert(i + 1 == count);
  kept = KeptRun{value_round_.round, at};
  ++runs_kept_;
  return RunView{value, point, box, count, groups};
}

void KineticKdTree::prefetch_children(const Node& v) const {
  // The children's records were asked for one level up (by this function at the parent, or at
  // the root): read them, and ask for what their own visits read first (their splits' motions,
  // their children's records, a small subtree's first leaves), so that the descent waits for
  // about one memory access per level instead of two.
  const auto d = static_cast<std::size_t>(d_);
  for (const std::uint32_t x : v.child) {
    const Node& w = trie_->nodes[x];
    for (std::uint32_t k = 0; k < w.chain_size; ++k) {
      const ChainEntry e = chain_entry(*trie_, x, k);
      __builtin_prefetch(&split_motion(e.axis, e.median));
    }
    if (w.point != kNoIndex) {
      __builtin_prefetch(&trie_->coef[static_cast<std::size_t>(x) * d]);
    } else if (w.leaves <= kBucket) {
      // Whether its run is kept decides what it reads: a load here (overlapped with the other
      // prefetches of this level), not a prefetch.
      const KeptRun* kept = keeps_values() ? &kept_run_[x] : nullptr;
      if (kept != nullptr && kept->round == value_round_.round) {  // its groups' boxes and values
        __builtin_prefetch(&kept_box_[kept->at / kGroup * 2 * d]);
        __builtin_prefetch(&kept_value_[kept->at * d]);
      } else {
        const std::uint32_t first = trie_->span[x][0];
        __builtin_prefetch(&trie_->link[first]);
        __builtin_prefetch(&trie_->coef[static_cast<std::size_t>(first) * d]);
      }
    } else {
      __builtin_prefetch(&split_motion(w.axis, w.median));
      for (const std::uint32_t y : w.child) __builtin_prefetch(&trie_->nodes[y]);
    }
  }
}

void KineticKdTree::prefetch_splits_below(int axis, std::size_t e) const {
  // The splits on this axis one and two halvings below the one at place e (split_slot()):
  // whichever sides the descent takes, they are in these two lines.
  const auto& row = by_rank_[static_cast<std::size_t>(axis)];
  if (4 * e < row.size()) {
    __builtin_prefetch(&row[2 * e]);
    __builtin_prefetch(&row[4 * e]);
  } else if (2 * e < row.size()) {
    __builtin_prefetch(&row[2 * e]);
  }
}

void KineticKdTree::visit(std::uint32_t node, Query& q, std::uint64_t lo_in,
                          std::uint64_t hi_in) const {
  // lo_in / hi_in: bit `axis` is set when the region's lower / upper bound on that axis (the
  // last split on the path bounding it on that side) is certified inside the box: the region
  // is then x >= c >= box lo (x <= c <= box hi). Unbounded sides are never inside.
  const Node& v = trie_->nodes[node];
  // The splits' motions are random reads by rank, independent of each other: issue them all.
  for (std::uint32_t k = 0; k < v.chain_size; ++k) {
    const ChainEntry e = chain_entry(*trie_, node, k);
    __builtin_prefetch(&split_motion(e.axis, e.median));
  }
  // The node's own split: its place in the axis's row (split_slot()), found once.
  const int axis = v.axis;
  std::size_t own = 0;
  if (v.point == kNoIndex) {
    own = split_slot(v.median, log_space_[static_cast<std::size_t>(axis)]);
    __builtin_prefetch(&by_rank_[static_cast<std::size_t>(axis)][own]);
    if (v.leaves <= q.bucket) {  // likely scanned: the run's first leaves too
      const KeptRun* kept = keeps_values() ? &kept_run_[node] : nullptr;
      if (kept != nullptr && kept->round == value_round_.round) {  // kept at t: its boxes
        const std::size_t box = kept->at / kGroup * 2 * static_cast<std::size_t>(d_);
        const std::size_t last = kept_box_.size() - 1;  // the next lines, inside the array
        __builtin_prefetch(&kept_box_[box]);            // 8 values per line
        __builtin_prefetch(&kept_box_[std::min(box + 8, last)]);
        __builtin_prefetch(&kept_box_[std::min(box + 16, last)]);
      } else {
        const std::uint32_t first = trie_->span[node][0];
        __builtin_prefetch(&trie_->link[first]);
        const std::size_t c = static_cast<std::size_t>(first) * static_cast<std::size_t>(d_);
        const std::size_t last = trie_->coef.size() - 1;
        __builtin_prefetch(&trie_->coef[c]);  // 4 entries per line
        __builtin_prefetch(&trie_->coef[std::min(c + 4, last)]);
        __builtin_prefetch(&trie_->coef[std::min(c + 8, last)]);
      }
    }
  }
  for (std::uint32_t k = 0; k < v.chain_size; ++k) {
    ++q.visits;
    const ChainEntry e = chain_entry(*trie_, node, k);
    const std::uint64_t bit = std::uint64_t{1} << e.axis;
    const int r = split_vs_box(e.axis, e.median, split_motion(e.axis, e.median), (*q.box)[e.axis],
                               q.t, q.cuts[e.axis]);
    // The region lies on the right of c (x >= c, side 1) or on its left (x <= c): reachable
    // iff c <= hi (lo <= c), and the new bound is inside the box iff lo <= c (c <= hi).
    if (e.side == 1) {
      if ((r & 2) == 0) return;
      lo_in = (r & 1) ? lo_in | bit : lo_in & ~bit;
    } else {
      if ((r & 1) == 0) return;
      hi_in = (r & 2) ? hi_in | bit : hi_in & ~bit;
    }
  }
  ++q.visits;
  if (v.point != kNoIndex) {
    if (inside(node, v.point, q, ~lo_in & q.all, ~hi_in & q.all)) q.out->push_back(v.point);
    return;
  }
  if (lo_in == q.all && hi_in == q.all) {  // the region lies inside the box
    report(node, *q.out);
    return;
  }
  if (v.leaves <= q.bucket) {  // a small subtree: test its leaves, no further descent
    scan(node, q, lo_in, hi_in);
    return;
  }
  // Both children's nodes and spans are fetched while the split's motion (a random read by
  // rank) is: the descent then waits for about one memory access per level instead of two.
  for (const std::uint32_t c : v.child) {
    __builtin_prefetch(&trie_->nodes[c]);
    __builtin_prefetch(&trie_->span[c]);
    if (keeps_values()) __builtin_prefetch(&kept_run_[c]);
  }
  prefetch_splits_below(axis, own);
  const std::uint64_t bit = std::uint64_t{1} << axis;
  const auto a = static_cast<std::size_t>(axis);
  const int r = split_vs_box(axis, v.median, by_rank_[a][own], (*q.box)[a], q.t, q.cuts[a]);
  // Left (x <= c): reachable iff lo <= c; its upper bound c is inside iff c <= hi. Right
  // (x >= c): reachable iff c <= hi; its lower bound c is inside iff lo <= c.
  if (r == 3) {  // both children: fetch the right one's chain and motions (a leaf) as well
    const std::uint32_t right = v.child[1];
    if (!inline_chains()) {
      __builtin_prefetch(
          &trie_->chains[static_cast<std::size_t>(right) * 2 * static_cast<std::size_t>(d_)]);
    }
    __builtin_prefetch(
        &trie_->coef[static_cast<std::size_t>(right) * static_cast<std::size_t>(d_)]);
  }
  if (r & 1) visit(v.child[0], q, lo_in, (r & 2) ? hi_in | bit : hi_in & ~bit);
  if (r & 2) visit(v.child[1], q, (r & 1) ? lo_in | bit : lo_in & ~bit, hi_in);
}

double KineticKdTree::query_margin(Time t) const {
  // linear_filtered()'s bound for the largest |c0| and |c1| at |s| = |fl(t - T)| (the same
  // s every stored motion is evaluated with); the bound is monotone in its inputs
  // (linear_filter.hpp), so it is >= every stored motion's own bound at t; plus the stored
  // values' own error at T (filter_error()). NaN (no motion) or infinity only make the
  // shortcut never decide.
  const double s = std::fabs(t - reference_);
  return filter_error(numeric::linear_filtered(coef_max_->c0, coef_max_->c1, 0.0, s).error);
}

void KineticKdTree::begin_value_round(Time t) {
  // Another time, or a change: nothing kept is current.
  if (value_round_.begin(t, mutations_)) kept_used_ = 0;
  if (keeps_values() && kept_run_.size() < trie_->nodes.size()) {
    kept_run_.resize(trie_->nodes.size());
  }
}

void KineticKdTree::query(const Box& box, Time t, std::vector<std::uint32_t>& out) {
  require_range("KineticKdTree::range", box, t);
  out.clear();
  // An empty buffer (a caller's fresh vector) gets room for a small answer at once: one
  // allocation instead of the five of a doubling from 1 to 16.
  if (out.capacity() < kFirstCapacity) out.reserve(kFirstCapacity);
  const double margin = query_margin(t);
  cuts_.resize(static_cast<std::size_t>(d_));
  for (std::size_t a = 0; a < cuts_.size(); ++a) {
    cuts_[a] =
        SideCuts{numeric::below_cut(box[a][0], margin), numeric::above_cut(box[a][0], margin),
                 numeric::below_cut(box[a][1], margin), numeric::above_cut(box[a][1], margin)};
  }
  begin_value_round(t);
  Query q{&box,
          t,
          &out,
          0,
          d_ == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << d_) - 1,
          range_bucket(),
          cuts_.data()};
  if (trie_->root != kNoIndex) visit(trie_->root, q, 0, 0);
  ++counters_.queries;
  counters_.node_visits += q.visits;
  counters_.last_query_visits = q.visits;
  counters_.runs_kept = runs_kept_;
}

void KineticKdTree::range_unsorted(const Box& box, Time t, std::vector<std::uint32_t>& out) {
  query(box, t, out);
}

// ---------------------------------------------------------------------------------------------
// k nearest (docs/kdtree.md, "What a k_nearest answer guarantees").

struct KineticKdTree::NearestQuery {
  const double* q;
  Time t;
  /// At least the filter's error bound of every stored linear motion at t (as a range query's).
  double margin;
  /// |computed distance - true distance| <= root_d margin + rel * distance + tiny for a point
  /// whose motions are linear (see nearest_offer()).
  double root_d, rel, tiny;
  NearestCandidates* candidates;
  std::vector<std::pair<std::uint32_t, double>>* undo;
  std::uint64_t visits;
  /// A leaf whose computed squared distance is above this is not offered (nearest_offer()):
  /// +infinity until k points are offered, then from the candidates' limit.
  double reject_above_squared = HUGE_VAL;
};

namespace {

/// A lower bound on the distance from q_a to the side of a split beyond it, given fl(s - q_a)
/// or fl(q_a - s) > 0 for the split's filtered coordinate s (within `margin` of the true one):
/// the true distance is >= (s - q_a) - margin >= the value returned (each rounding absorbed by
/// kShrink); 0 when that is not positive (or NaN: a motion of degree above 1).
inline double split_gap(double difference, double margin) {
  const double g = (difference * numeric::kShrink - margin) * numeric::kShrink;
  return g > 0.0 ? g : 0.0;
}

/// The squared distance from the leaf's filtered coordinates (its motions l, as stored at the
/// leaf) to q at t, in doubles; D the dimension when known at compile time (0: d).
template <int D, class L>
[[gnu::always_inline]] inline double leaf_squared(const L* l, const double* q, Time reference,
                                                  Time t, std::size_t d) {
  double squared = 0.0;
  const std::size_t count = D > 0 ? static_cast<std::size_t>(D) : d;
  for (std::size_t a = 0; a < count; ++a) {
    const double delta = numeric::linear_value(l[a].c0, l[a].c1, reference, t) - q[a];
    squared += delta * delta;
  }
  return squared;
}

}  // namespace

void KineticKdTree::nearest_offer(std::uint32_t point, double squared, NearestQuery& nq) const {
  // The distance from the filtered coordinates x~_a (each within `margin` of x_a(t)): with
  // delta_a = fl(x~_a - q_a), |delta_a - (x_a - q_a)| <= margin + u |delta_a|, so the true
  // distance is within root_d margin + u |delta| of |delta|, and fl(sqrt(sum delta_a^2)) is
  // within ((d + 3) / 2) u |delta| of |delta| (plus sqrt(d) 2^-537 for squares that underflow):
  // rel = (d + 8) u and tiny = root_d 2^-530 cover both, with room for the bound's roundings.
  // `squared` is leaf_squared(); the caller has not offered points farther than
  // reject_above_squared (their lower bound r - error > W, the candidates' limit, when
  // r > (W + 2 (root_d margin + tiny)) (1 + 2 rel)).
  const auto d = static_cast<std::size_t>(d_);
  double error_sum = nq.root_d * nq.margin;
  if (!(squared < HUGE_VAL)) [[unlikely]] {
    // A motion of degree above 1 (c1 NaN), or an overflow: each coordinate with its own bound.
    squared = 0.0;
    error_sum = 0.0;
    for (std::size_t a = 0; a < d; ++a) {
      const FilteredValue x =
          numeric::filtered_value(motions_.motion(point, static_cast<int>(a)), nq.t);
      const double delta = x.value - nq.q[a];
      squared += delta * delta;
      error_sum += x.error;
    }
    if (!(squared < HUGE_VAL) || !(error_sum < HUGE_VAL)) {
      nq.candidates->offer(point, 0.0, HUGE_VAL);  // undecided: the exact comparisons decide
      return;
    }
  }
  const double r = std::sqrt(squared);
  const double error = (error_sum + r * nq.rel + nq.tiny) * (1.0 + 1e-10);
  nq.candidates->offer(point, std::max(0.0, numeric::down(r - error)), numeric::up(r + error));
  const double w = nq.candidates->prune_above();
  const double reach = w + 2.0 * (nq.root_d * nq.margin + nq.tiny);
  nq.reject_above_squared = reach * reach * (1.0 + 4.0 * nq.rel + 0x1p-40);
}

void KineticKdTree::nearest_visit(std::uint32_t node, NearestQuery& nq, double rd,
                                  double* gap2) const {
  const Node& v = trie_->nodes[node];
  const std::size_t undo_mark = nq.undo->size();
  // What this visit reads first (its splits' motions, a small subtree's first leaves) was asked
  // for at the parent (prefetch_children(); not for the root); ask for the children's now.
  if (v.point == kNoIndex && v.leaves > kBucket) prefetch_children(v);
  // The chain's splits bound the region further: x_a >= c (side 1) or x_a <= c (side 0); q on
  // the far side of one gives a lower bound on |x_a - q_a| over the region.
  for (std::uint32_t k = 0; k < v.chain_size; ++k) {
    ++nq.visits;
    const ChainEntry e = chain_entry(*trie_, node, k);
    const Linear& c = split_motion(e.axis, e.median);
    const double s = numeric::linear_value(c.c0, c.c1, reference_, nq.t);
    const double difference = e.side == 1 ? s - nq.q[e.axis] : nq.q[e.axis] - s;
    if (!(difference > 0.0)) continue;
    const double g = split_gap(difference, nq.margin);
    if (g * g > gap2[e.axis]) {
      nq.undo->emplace_back(e.axis, gap2[e.axis]);
      rd += g * g - gap2[e.axis];
      gap2[e.axis] = g * g;
    }
  }
  ++nq.visits;
  if (!(rd > nq.candidates->prune_above_squared())) {
    if (v.point == kNoIndex && v.leaves <= kBucket && keeps_values()) {
      // A small subtree in 2-D or 3-D: its run at t, kept (as a range scan's), group by group.
      if (d_ == 2) {
        nearest_scan<2>(node, nq, gap2);
      } else {
        nearest_scan<3>(node, nq, gap2);
      }
    } else if (v.point != kNoIndex || v.leaves <= kBucket) {
      // A leaf (in any dimension), or a small subtree for d other than 2 and 3: its leaves one by
      // one along the thread (the dimension known to the compiler for a leaf in the plane and in
      // space).
      const auto d = static_cast<std::size_t>(d_);
      const auto [first, last] = trie_->span[node];
      const std::array<std::uint32_t, 2>* link = trie_->link.data();
      const Linear* coef = trie_->coef.data();
      const auto scan = [&]<int D>() {
        for (std::uint32_t leaf = first;; leaf = link[leaf][0]) {
          if (v.point == kNoIndex) ++nq.visits;
          const double squared =
              leaf_squared<D>(coef + static_cast<std::size_t>(leaf) * d, nq.q, reference_, nq.t, d);
          if (!(squared > nq.reject_above_squared)) nearest_offer(link[leaf][1], squared, nq);
          if (leaf == last) break;
        }
      };
      if (d_ == 2) {
        scan.template operator()<2>();
      } else if (d_ == 3) {
        scan.template operator()<3>();
      } else {
        scan.template operator()<0>();
      }
    } else {
      const std::uint32_t axis = v.axis;
      const std::size_t own = split_slot(v.median, log_space_[axis]);
      prefetch_splits_below(static_cast<int>(axis), own);
      const Linear& c = by_rank_[axis][own];
      const double difference = nq.q[axis] - numeric::linear_value(c.c0, c.c1, reference_, nq.t);
      // The nearer child first: left (x <= c) when q_a < c.
      const int near = difference < 0.0 ? 0 : 1;
      nearest_visit(v.child[near], nq, rd, gap2);
      // The farther child lies beyond the split from q (by -difference or difference).
      const double g = split_gap(near == 0 ? -difference : difference, nq.margin);
      const double prior = gap2[axis];
      double rd_far = rd;
      if (g * g > prior) {
        rd_far += g * g - prior;
        gap2[axis] = g * g;
      }
      if (!(rd_far > nq.candidates->prune_above_squared())) {
        nearest_visit(v.child[1 - near], nq, rd_far, gap2);
      }
      gap2[axis] = prior;
    }
  }
  while (nq.undo->size() > undo_mark) {
    gap2[nq.undo->back().first] = nq.undo->back().second;
    nq.undo->pop_back();
  }
}

template <int D>
void KineticKdTree::nearest_scan(std::uint32_t node, NearestQuery& nq, const double* gap2) const {
  // Each group's box first: a lower bound on the distance from q to its points (per axis, the
  // larger of the region's bound gap2 and the box's own gap, as split_gap() bounds a split's:
  // the box bounds the filtered values, each within the margin of the true one) prunes the
  // group as the regions are pruned; the leaves of the others are offered as a leaf is.
  const RunView run = kept_run<D>(node);
  std::array<double, D> q{}, floor{};
  for (std::size_t a = 0; a < D; ++a) {
    q[a] = nq.q[a];
    floor[a] = gap2[a];
  }
  std::uint64_t visits = 0;
  for (std::size_t g = 0; g < run.groups; ++g) {
    ++visits;
    const double* b = run.box + g * 2 * D;
    double lower = 0.0;
    for (std::size_t a = 0; a < D; ++a) {
      // Below the box (its lowest value above q_a) or above it; a NaN value's +-infinity sides
      // give neither.
      const double below = b[a] - q[a], above = q[a] - b[D + a];
      const double difference = below > 0.0 ? below : above;
      double g2 = floor[a];
      if (difference > 0.0) {
        const double gap = split_gap(difference, nq.margin);
        g2 = std::max(g2, gap * gap);
      }
      lower += g2;
    }
    if (lower > nq.candidates->prune_above_squared()) continue;
    const std::size_t begin = g * kGroup, end = std::min<std::size_t>(begin + kGroup, run.count);
    for (std::size_t i = begin; i < end; ++i) {
      ++visits;
      double squared = 0.0;
      for (std::size_t a = 0; a < D; ++a) {
        const double delta = run.value[i * D + a] - q[a];
        squared += delta * delta;
      }
      if (!(squared > nq.reject_above_squared)) nearest_offer(run.point[i], squared, nq);
    }
  }
  nq.visits += visits;
}

void KineticKdTree::k_nearest(std::span<const double> q, std::size_t k, double eps, Time t,
                              std::vector<std::uint32_t>& out) {
  require_point_query_at("KineticKdTree::k_nearest", sync_, t, sim_.now(), q, d_, eps);
  nearest_.reset(k, eps);
  nearest_undo_.clear();
  // The margin of a range query (query()), and the distance's error terms of nearest_offer().
  const double margin = query_margin(t);
  const double root_d = std::sqrt(static_cast<double>(d_)) * (1.0 + 0x1p-50);
  NearestQuery nq{q.data(),
                  t,
                  margin,
                  root_d,
                  (static_cast<double>(d_) + 8.0) * 0x1p-53,
                  root_d * 0x1p-530,
                  &nearest_,
                  &nearest_undo_,
                  0,
                  HUGE_VAL};
  begin_value_round(t);  // the small subtrees' runs at t, shared with the range scans
  std::array<double, 64> gap2{};
  if (k > 0 && trie_->root != kNoIndex) nearest_visit(trie_->root, nq, 0.0, gap2.data());
  nearest_.finish(motions_, q, t, out);
  ++counters_.queries;
  counters_.node_visits += nq.visits;
  counters_.last_query_visits = nq.visits;
  counters_.runs_kept = runs_kept_;
}

std::vector<std::uint32_t> KineticKdTree::k_nearest(std::span<const double> q, std::size_t k,
                                                    double eps, Time t) {
  std::vector<std::uint32_t> out;
  k_nearest(q, k, eps, t, out);
  return out;
}

std::optional<std::uint32_t> KineticKdTree::nearest(std::span<const double> q, double eps, Time t) {
  std::vector<std::uint32_t> out;
  k_nearest(q, 1, eps, t, out);
  if (out.empty()) return std::nullopt;
  return out[0];
}

// ---------------------------------------------------------------------------------------------
// Measures and validation.

std::size_t KineticKdTree::node_count() const {
  std::size_t count = 0;
  for (std::uint32_t k = 0; k < trie_->nodes.size(); ++k) {
    if (std::find(trie_->free.begin(), trie_->free.end(), k) != trie_->free.end()) continue;
    if (std::find(trie_->free_leaves.begin(), trie_->free_leaves.end(), k) !=
        trie_->free_leaves.end()) {
      continue;
    }
    count += 1 + trie_->nodes[k].chain_size;
  }
  return count;
}

int KineticKdTree::depth() const {
  std::uint32_t deepest = 0;
  for (const LeafRef& leaf : leaf_of_) {
    if (leaf.node != kNoIndex) deepest = std::max(deepest, trie_->nodes[leaf.node].depth);
  }
  return static_cast<int>(deepest);
}

bool KineticKdTree::same(const Trie& a, std::uint32_t x, const Trie& b, std::uint32_t y) const {
  if ((x == kNoIndex) != (y == kNoIndex)) return false;
  if (x == kNoIndex) return true;
  const Node& u = a.nodes[x];
  const Node& v = b.nodes[y];
  if (u.depth != v.depth || u.point != v.point || u.chain_size != v.chain_size) return false;
  if (u.point == kNoIndex && (u.median != v.median || u.axis != v.axis)) return false;
  for (std::uint32_t k = 0; k < u.chain_size; ++k) {
    const ChainEntry e = chain_entry(a, x, k);
    const ChainEntry f = chain_entry(b, y, k);
    if (e.axis != f.axis || e.side != f.side || e.median != f.median) return false;
  }
  if (u.point != kNoIndex) return true;
  return same(a, u.child[0], b, v.child[0]) && same(a, u.child[1], b, v.child[1]);
}

bool KineticKdTree::validate() const {
  if (!sync_.current()) return false;
  if (!sorts_.validate()) return false;
  if (n_ != motions_.size()) return false;
  Trie fresh;
  build_all(fresh);
  if (!same(*trie_, trie_->root, fresh, fresh.root)) return false;
  if (!threads_valid()) return false;
  if (!chains_valid()) return false;
  if (!query_data_valid()) return false;
  // Parent links and leaves.
  for (std::uint32_t p : motions_.alive_indices()) {
    const LeafRef leaf = leaf_of_[p];
    if (leaf.node == kNoIndex || trie_->nodes[leaf.node].point != p ||
        trie_->nodes[leaf.node].depth != leaf.depth) {
      return false;
    }
  }
  // The label spaces are the sorts' current ones; the depth is at most d log2 max U_i.
  std::uint32_t log = 0;
  for (int axis = 0; axis < d_; ++axis) {
    const std::size_t slots = sorts_[static_cast<std::size_t>(axis)].slots();
    if (slots != (std::size_t{1} << log_space_[static_cast<std::size_t>(axis)])) return false;
    log = std::max(log, log_space_[static_cast<std::size_t>(axis)]);
  }
  if (n_ >= 2) {
    if (depth() > d_ * static_cast<int>(log)) return false;
    if (node_count() > (2 * n_ - 1) * (2 * static_cast<std::size_t>(d_) + 1)) return false;
  }
  return true;
}

NamedCounters KineticKdTree::named_counters() const {
  const KdTreeCounters& c = counters_;
  return {{"swaps", c.swaps},
          {"unchanged_events", c.unchanged_events},
          {"reinsertions", c.reinsertions},
          {"nodes_created", c.nodes_created},
          {"nodes_removed", c.nodes_removed},
          {"compactions", c.compactions},
          {"rebuilds", c.rebuilds},
          {"local_changes", c.local_changes},
          {"relabel_reinsertions", c.relabel_reinsertions},
          {"unchanged_relabels", c.unchanged_relabels},
          {"tree_nodes", node_count()},
          {"queries", c.queries},
          {"node_visits", c.node_visits},
          {"runs_kept", c.runs_kept}};
}

StructureDescription KineticKdTree::description() {
  return StructureDescription{
      "kdtree",
      "KdTree",
      ObjectsAre::Points,
      {QueryType::Range, QueryType::Nearest, QueryType::KNearest},
      {"swap"},
      "The kinetic rank-based kd-tree in d dimensions (range(box), range_many(boxes), "
      "k_nearest(point, k, eps), k_nearest_many(points, k, eps), nearest(point, eps)).",
      "kinetic rank-based kd-tree (any dimension <= 64): orthogonal range and k-nearest queries"}
      .limit_dimensions(1, 64, "")
      .bound_events(per_axis_sort_bounds);
}

}  // namespace kinetic
