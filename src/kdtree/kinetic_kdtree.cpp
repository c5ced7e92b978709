#include "kinetic/kdtree/kinetic_kdtree.hpp"

#include <algorithm>
#include <cassert>

#include "kinetic/core/predicates.hpp"

namespace kinetic {

KineticKdTree::KineticKdTree(const MotionTable& motions, Simulator& simulator,
                             const Scheduler& scheduler, std::uint32_t owner_base)
    : motions_(motions), sim_(simulator), d_(motions.dimension()), owner_base_(owner_base) {
  for (int axis = 0; axis < d_; ++axis) {
    sorts_.push_back(std::make_unique<KineticSort>(motions, simulator, scheduler, axis,
                                                   owner_base + static_cast<std::uint32_t>(axis)));
  }
}

// ---------------------------------------------------------------------------------------------
// Keys: the halving of the ranks [0, n - 1].

void KineticKdTree::rebuild_tables() {
  bits_.assign(n_, 0);
  // Halve every interval recursively; the median m = lo + (len + 1) / 2 ... written as the first
  // rank of the right half: left [lo, m - 1], right [m, hi].
  struct Item {
    std::uint32_t lo, hi, level;
  };
  std::vector<Item> stack;
  if (n_ > 0) stack.push_back({0, static_cast<std::uint32_t>(n_ - 1), 0});
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    if (it.lo >= it.hi) continue;  // one rank: no further split
    const std::uint32_t m = it.lo + (it.hi - it.lo + 1) / 2;
    for (std::uint32_t r = m; r <= it.hi; ++r) bits_[r] |= std::uint64_t{1} << it.level;
    stack.push_back({it.lo, m - 1, it.level + 1});
    stack.push_back({m, it.hi, it.level + 1});
  }
}

int KineticKdTree::bit(std::uint32_t point, std::uint32_t depth) const {
  const int axis = static_cast<int>(depth % static_cast<std::uint32_t>(d_));
  const std::uint32_t level = depth / static_cast<std::uint32_t>(d_);
  if (level >= 64) return 0;
  return static_cast<int>((bits_[rank_of(point, axis)] >> level) & 1U);
}

std::uint32_t KineticKdTree::median(std::uint32_t point, std::uint32_t depth) const {
  const int axis = static_cast<int>(depth % static_cast<std::uint32_t>(d_));
  const std::uint32_t level = depth / static_cast<std::uint32_t>(d_);
  const std::uint32_t r = rank_of(point, axis);
  std::uint32_t lo = 0, hi = static_cast<std::uint32_t>(n_ - 1);
  for (std::uint32_t l = 0; l < level && lo < hi; ++l) {
    const std::uint32_t m = lo + (hi - lo + 1) / 2;
    if (r >= m) {
      lo = m;
    } else {
      hi = m - 1;
    }
  }
  return lo + (hi - lo + 1) / 2;
}

// ---------------------------------------------------------------------------------------------
// The trie.

std::uint32_t KineticKdTree::new_node(Trie& t) const {
  std::uint32_t k = 0;
  if (!t.free.empty()) {
    k = t.free.back();
    t.free.pop_back();
    t.nodes[k] = Node{};
  } else {
    k = static_cast<std::uint32_t>(t.nodes.size());
    t.nodes.emplace_back();
    t.chains.resize(t.chains.size() + 2 * static_cast<std::size_t>(d_));
  }
  return k;
}

void KineticKdTree::set_chain(Trie& t, std::uint32_t node) const {
  // The skeleton nodes strictly between the parent (or above the root: from depth 0) and `node`
  // are degree-one nodes on the path of node's key. Keep those whose hyperplane bounds node's
  // region: the lowest one for each (axis, side) on that stretch (paper 002, "useful" nodes).
  Node& v = t.nodes[node];
  const std::uint32_t from =
      v.parent == kNone ? 0 : t.nodes[v.parent].depth + 1;  // first skeleton depth of the edge
  std::vector<std::uint8_t> seen(2 * static_cast<std::size_t>(d_), 0);
  ChainEntry* chain = &t.chains[static_cast<std::size_t>(node) * 2 * static_cast<std::size_t>(d_)];
  std::uint32_t size = 0;
  for (std::uint32_t s = v.depth; s-- > from;) {  // bottom-up: the first seen is the lowest
    const int axis = static_cast<int>(s % static_cast<std::uint32_t>(d_));
    const int side = bit(v.rep, s);
    std::uint8_t& mark = seen[static_cast<std::size_t>(axis) * 2 + static_cast<std::size_t>(side)];
    if (mark) continue;
    mark = 1;
    chain[size++] = ChainEntry{median(v.rep, s), static_cast<std::uint16_t>(axis),
                               static_cast<std::uint8_t>(side)};
  }
  std::reverse(chain, chain + size);  // top-down, as a query meets them
  v.chain_size = size;
}

std::uint32_t KineticKdTree::build(Trie& t, std::vector<std::uint32_t>& points, std::size_t lo,
                                   std::size_t hi, std::uint32_t depth,
                                   std::uint32_t parent) const {
  const std::uint32_t k = new_node(t);
  t.nodes[k].parent = parent;
  t.nodes[k].rep = points[lo];
  if (hi - lo == 1) {  // alone: a leaf at this depth
    t.nodes[k].depth = depth;
    t.nodes[k].point = points[lo];
    set_chain(t, k);
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
  t.nodes[k].median = median(points[lo], s);
  set_chain(t, k);
  const auto mid = std::stable_partition(points.begin() + static_cast<std::ptrdiff_t>(lo),
                                         points.begin() + static_cast<std::ptrdiff_t>(hi),
                                         [&](std::uint32_t p) { return bit(p, s) == 0; });
  const std::size_t m = static_cast<std::size_t>(mid - points.begin());
  const std::uint32_t left = build(t, points, lo, m, s + 1, k);
  const std::uint32_t right = build(t, points, m, hi, s + 1, k);
  t.nodes[k].child = {left, right};
  return k;
}

void KineticKdTree::build_all(Trie& t) const {
  t = Trie{};
  std::vector<std::uint32_t> points = motions_.alive_indices();
  if (!points.empty()) t.root = build(t, points, 0, points.size(), 0, kNone);
}

void KineticKdTree::rebuild() {
  n_ = motions_.size();
  rebuild_tables();
  build_all(trie_);
  leaf_of_.assign(motions_.capacity(), kNone);
  for (std::uint32_t k = 0; k < trie_.nodes.size(); ++k) {
    if (trie_.nodes[k].point != kNone) leaf_of_[trie_.nodes[k].point] = k;
  }
}

void KineticKdTree::initialize() {
  for (auto& s : sorts_) s->initialize();
  rebuild();
}

void KineticKdTree::erase(std::uint32_t point) {
  Trie& t = trie_;
  const std::uint32_t leaf = leaf_of_[point];
  leaf_of_[point] = kNone;
  const std::uint32_t u = t.nodes[leaf].parent;
  t.free.push_back(leaf);
  ++counters_.nodes_removed;
  if (u == kNone) {
    t.root = kNone;
    return;
  }
  // u stops being active: its other child takes its place under u's parent.
  const std::uint32_t c = t.nodes[u].child[0] == leaf ? t.nodes[u].child[1] : t.nodes[u].child[0];
  const std::uint32_t g = t.nodes[u].parent;
  t.nodes[c].parent = g;
  if (g == kNone) {
    t.root = c;
  } else {
    t.nodes[g].child[t.nodes[g].child[0] == u ? 0 : 1] = c;
  }
  t.free.push_back(u);
  ++counters_.nodes_removed;
  // A leaf is where its point is alone in the skeleton: right below its active parent.
  if (t.nodes[c].point != kNone) t.nodes[c].depth = g == kNone ? 0 : t.nodes[g].depth + 1;
  set_chain(t, c);  // the kept degree-one nodes above c change with its new parent
  for (std::uint32_t a = g; a != kNone; a = t.nodes[a].parent) {
    if (t.nodes[a].rep == point) t.nodes[a].rep = t.nodes[c].rep;
  }
}

void KineticKdTree::insert_point(std::uint32_t point) {
  Trie& t = trie_;
  const std::uint32_t leaf = new_node(t);
  ++counters_.nodes_created;
  t.nodes[leaf].point = point;
  t.nodes[leaf].rep = point;
  leaf_of_[point] = leaf;
  if (t.root == kNone) {
    t.root = leaf;
    t.nodes[leaf].depth = 0;
    set_chain(t, leaf);
    return;
  }
  std::uint32_t cur = t.root;
  std::uint32_t from = 0;  // depths < from are known to agree with cur's points
  for (;;) {
    const Node& c = t.nodes[cur];
    const std::uint32_t limit = c.point != kNone ? kNone : c.depth;  // a leaf: search below it
    std::uint32_t s = from;
    while ((limit == kNone || s < limit) && bit(point, s) == bit(c.rep, s)) ++s;
    if (limit != kNone && s == limit) {  // agrees down to the active node: descend
      from = c.depth + 1;
      cur = c.child[static_cast<std::size_t>(bit(point, c.depth))];
      continue;
    }
    // The key leaves cur's path at depth s: a new active node there, above cur.
    const std::uint32_t x = new_node(t);
    ++counters_.nodes_created;
    const std::uint32_t g = t.nodes[cur].parent;
    t.nodes[x].parent = g;
    t.nodes[x].depth = s;
    t.nodes[x].rep = t.nodes[cur].rep;
    t.nodes[x].median = median(point, s);  // p shares the prefix above s with cur's points
    if (g == kNone) {
      t.root = x;
    } else {
      t.nodes[g].child[t.nodes[g].child[0] == cur ? 0 : 1] = x;
    }
    const int side = bit(point, s);
    t.nodes[x].child[static_cast<std::size_t>(side)] = leaf;
    t.nodes[x].child[static_cast<std::size_t>(1 - side)] = cur;
    t.nodes[leaf].parent = x;
    t.nodes[leaf].depth = s + 1;
    t.nodes[cur].parent = x;
    if (t.nodes[cur].point != kNone) t.nodes[cur].depth = s + 1;  // a leaf: now alone below x
    set_chain(t, x);
    set_chain(t, cur);
    set_chain(t, leaf);
    return;
  }
}

EventKind KineticKdTree::process(const Event& event) {
  const std::uint32_t axis = event.owner - owner_base_;
  KineticSort& s = *sorts_[axis];
  const std::uint32_t x = event.payload;
  s.process(event);
  ++counters_.events;
  // x moved up one place past its neighbour y: only their keys changed.
  const std::uint32_t y = s.order()[s.rank(x) - 1];
  // The ranks are already swapped; erase() and insert_point() read the new ones, and erase()
  // needs nothing but the leaf, so delete both first, then insert both.
  erase(x);
  erase(y);
  insert_point(x);
  insert_point(y);
  counters_.reinsertions += 2;
  return EventKind::External;
}

void KineticKdTree::insert(std::uint32_t index) {
  for (auto& s : sorts_) s->insert(index);
  ++counters_.rebuilds;
  rebuild();
}

void KineticKdTree::remove(std::uint32_t index) {
  for (auto& s : sorts_) s->remove(index);
  ++counters_.rebuilds;
  // The table still holds the object: rebuild without it.
  n_ = motions_.size() - 1;
  rebuild_tables();
  Trie t;
  std::vector<std::uint32_t> points = motions_.alive_indices();
  points.erase(std::remove(points.begin(), points.end(), index), points.end());
  if (!points.empty()) t.root = build(t, points, 0, points.size(), 0, kNone);
  trie_ = std::move(t);
  leaf_of_.assign(motions_.capacity(), kNone);
  for (std::uint32_t k = 0; k < trie_.nodes.size(); ++k) {
    if (trie_.nodes[k].point != kNone) leaf_of_[trie_.nodes[k].point] = k;
  }
}

void KineticKdTree::motion_changed(std::uint32_t index) {
  for (auto& s : sorts_) s->motion_changed(index);
  ++counters_.rebuilds;
  rebuild();
}

// ---------------------------------------------------------------------------------------------
// Queries.

int KineticKdTree::compare_to(const MotionPolynomial& p, double x, Time t) const {
  // p(t) in double with a rigorous error bound (|value - p(t)| <= error); x - value is rounded
  // with a relative error <= 2^-53, so (x - value)(1 - 2^-52) > error proves x > p(t). The exact
  // predicate decides only what this cannot.
  const FilteredValue c = evaluate_filtered(p, t);
  if ((x - c.value) * (1.0 - 0x1p-52) > c.error) return -1;
  if ((c.value - x) * (1.0 - 0x1p-52) > c.error) return 1;
  return compare_at(p, MotionPolynomial::constant(x), t, &sim_.counters().predicates);
}

bool KineticKdTree::reaches(const KdBox& box, int axis, std::uint32_t median_rank, int side,
                            Time t) const {
  const std::uint32_t split = sorts_[static_cast<std::size_t>(axis)]->order()[median_rank];
  const MotionPolynomial& p = motions_.motion(split, axis);
  const auto& b = box[static_cast<std::size_t>(axis)];
  // Points of lower rank go left, so (with ties in coordinates) the left region is x <= c and
  // the right one x >= c, c the split point's coordinate.
  return side == 1 ? compare_to(p, b[1], t) <= 0   // reachable iff hi >= c
                   : compare_to(p, b[0], t) >= 0;  // reachable iff lo <= c
}

void KineticKdTree::report(std::uint32_t node, std::vector<std::uint32_t>& out) const {
  const Node& v = trie_.nodes[node];
  if (v.point != kNone) {
    out.push_back(v.point);
    return;
  }
  report(v.child[0], out);
  report(v.child[1], out);
}

void KineticKdTree::visit(std::uint32_t node, const KdBox& box, Time t,
                          std::vector<std::uint32_t>& out,
                          std::vector<std::array<std::uint32_t, 2>>& region,
                          std::uint64_t& visits) const {
  // region[axis] = {split point of the lower bound (x >= it), of the upper bound (x < it)},
  // kNone when unbounded: the region of the current node.
  const Node& v = trie_.nodes[node];
  const ChainEntry* chain =
      &trie_.chains[static_cast<std::size_t>(node) * 2 * static_cast<std::size_t>(d_)];
  // The chain narrows the region; its bounds are restored on the way out (at most 2d values).
  std::array<std::uint32_t, 2 * kMaxUndo> undo{};
  std::uint32_t applied = 0;
  auto restore = [&] {
    for (std::uint32_t k = applied; k-- > 0;) {
      const ChainEntry& e = chain[k];
      region[e.axis][e.side == 1 ? 0 : 1] = undo[k];
    }
  };
  for (std::uint32_t k = 0; k < v.chain_size; ++k) {
    ++visits;
    const ChainEntry& e = chain[k];
    if (!reaches(box, e.axis, e.median, e.side, t)) {
      restore();
      return;
    }
    auto& bound = region[e.axis][e.side == 1 ? 0 : 1];
    undo[k] = bound;
    bound = sorts_[e.axis]->order()[e.median];
    applied = k + 1;
  }
  ++visits;
  if (v.point != kNone) {
    bool inside = true;
    for (int axis = 0; axis < d_ && inside; ++axis) {
      const MotionPolynomial& p = motions_.motion(v.point, axis);
      const auto& b = box[static_cast<std::size_t>(axis)];
      inside = compare_to(p, b[0], t) >= 0 && compare_to(p, b[1], t) <= 0;
    }
    if (inside) out.push_back(v.point);
    restore();
    return;
  }
  // Region inside the box: report the whole subtree.
  bool contained = true;
  for (int axis = 0; axis < d_ && contained; ++axis) {
    const auto& b = box[static_cast<std::size_t>(axis)];
    const std::uint32_t lo = region[static_cast<std::size_t>(axis)][0];
    const std::uint32_t hi = region[static_cast<std::size_t>(axis)][1];
    contained = lo != kNone && hi != kNone && compare_to(motions_.motion(lo, axis), b[0], t) >= 0 &&
                compare_to(motions_.motion(hi, axis), b[1], t) <= 0;
  }
  if (contained) {
    report(node, out);
    restore();
    return;
  }
  const int axis = static_cast<int>(v.depth % static_cast<std::uint32_t>(d_));
  const std::uint32_t m = v.median;
  const std::uint32_t split = sorts_[static_cast<std::size_t>(axis)]->order()[m];
  for (int side = 0; side < 2; ++side) {
    if (!reaches(box, axis, m, side, t)) continue;
    auto& bound = region[static_cast<std::size_t>(axis)][side == 1 ? 0 : 1];
    const std::uint32_t old = bound;
    bound = split;
    visit(v.child[static_cast<std::size_t>(side)], box, t, out, region, visits);
    bound = old;
  }
  restore();
}

std::vector<std::uint32_t> KineticKdTree::range(const KdBox& box, Time t) {
  assert(box.size() == static_cast<std::size_t>(d_));
  std::vector<std::uint32_t> out;
  std::uint64_t visits = 0;
  if (trie_.root != kNone) {
    std::vector<std::array<std::uint32_t, 2>> region(static_cast<std::size_t>(d_), {kNone, kNone});
    visit(trie_.root, box, t, out, region, visits);
  }
  std::sort(out.begin(), out.end());
  ++counters_.queries;
  counters_.node_visits += visits;
  counters_.last_query_visits = visits;
  return out;
}

// ---------------------------------------------------------------------------------------------
// Measures and validation.

std::size_t KineticKdTree::node_count() const {
  std::size_t count = 0;
  for (std::uint32_t k = 0; k < trie_.nodes.size(); ++k) {
    if (std::find(trie_.free.begin(), trie_.free.end(), k) != trie_.free.end()) continue;
    count += 1 + trie_.nodes[k].chain_size;
  }
  return count;
}

int KineticKdTree::depth() const {
  std::uint32_t deepest = 0;
  for (const std::uint32_t leaf : leaf_of_) {
    if (leaf != kNone) deepest = std::max(deepest, trie_.nodes[leaf].depth);
  }
  return static_cast<int>(deepest);
}

std::size_t KineticKdTree::certificates() const {
  std::size_t c = 0;
  for (const auto& s : sorts_) c += s->certificates();
  return c;
}

std::size_t KineticKdTree::certificates_per_object_max() const {
  std::size_t c = 0;
  for (const auto& s : sorts_) c += s->certificates_per_object_max();
  return c;
}

bool KineticKdTree::same(const Trie& a, std::uint32_t x, const Trie& b, std::uint32_t y) const {
  if ((x == kNone) != (y == kNone)) return false;
  if (x == kNone) return true;
  const Node& u = a.nodes[x];
  const Node& v = b.nodes[y];
  if (u.depth != v.depth || u.point != v.point || u.chain_size != v.chain_size) return false;
  if (u.point == kNone && u.median != v.median) return false;
  const std::size_t stride = 2 * static_cast<std::size_t>(d_);
  for (std::uint32_t k = 0; k < u.chain_size; ++k) {
    const ChainEntry& e = a.chains[x * stride + k];
    const ChainEntry& f = b.chains[y * stride + k];
    if (e.axis != f.axis || e.side != f.side || e.median != f.median) return false;
  }
  if (u.point != kNone) return true;
  return same(a, u.child[0], b, v.child[0]) && same(a, u.child[1], b, v.child[1]);
}

bool KineticKdTree::validate() const {
  for (const auto& s : sorts_) {
    if (!s->validate()) return false;
  }
  if (n_ != motions_.size()) return false;
  Trie fresh;
  build_all(fresh);
  if (!same(trie_, trie_.root, fresh, fresh.root)) return false;
  // Parent links and leaves.
  for (std::uint32_t p : motions_.alive_indices()) {
    const std::uint32_t leaf = leaf_of_[p];
    if (leaf == kNone || trie_.nodes[leaf].point != p) return false;
  }
  if (n_ >= 2) {
    std::uint32_t log = 0;
    while ((std::size_t{1} << log) < n_) ++log;
    if (depth() > d_ * static_cast<int>(log)) return false;
    if (node_count() > (2 * n_ - 1) * (2 * static_cast<std::size_t>(d_) + 1)) return false;
  }
  return true;
}

}  // namespace kinetic
