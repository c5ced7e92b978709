#include "kinetic/range_tree/kinetic_range_tree.hpp"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
#include <span>

#include "core/numeric/id_bitmap_sort.hpp"
#include "core/numeric/linear_filter.hpp"
#include "kinetic/core/predicates.hpp"

namespace kinetic {

/// The arrays of one level: ord[a * n + i], pos[a * cap + p] for array a.
struct KineticRangeTree::Level {
  std::vector<std::uint32_t> ord;
  std::vector<std::uint32_t> pos;
};

struct KineticRangeTree::Query {
  const Box* box;
  Time t;
  std::vector<std::uint32_t>* out;
  std::uint64_t visits;
};

/// A motion x(t) = c0 + c1 (t - origin) for the queries' floating-point filter (c1 NaN above
/// degree 1).
struct KineticRangeTree::Linear {
  double c0 = 0.0;
  double c1 = 0.0;
  double origin = 0.0;
};

KineticRangeTree::~KineticRangeTree() = default;

inline void KineticRangeTree::set(Layout& l, int j, std::size_t a, std::uint32_t i,
                                  std::uint32_t p) const {
  Level& lv = l[static_cast<std::size_t>(j)];
  lv.ord[a * n_ + i] = p;
  lv.pos[a * cap_ + p] = i;
}

KineticRangeTree::KineticRangeTree(const MotionTable& motions, Simulator& simulator,
                                   const Scheduler& scheduler)
    : motions_(motions), sim_(simulator), d_(motions.dimension()) {
  require_dimension("KineticRangeTree", d_, 1, 8, "points in 1 to 8 dimensions");
  for (int axis = 0; axis < d_; ++axis) {
    sorts_.add(std::make_unique<KineticSort>(motions, simulator, scheduler, axis))
        .set_log_swaps(true);  // every rank swap is an external event (kind "swap")
  }
  counters_.swaps_by_axis.assign(static_cast<std::size_t>(d_), 0);
}

// ---------------------------------------------------------------------------------------------
// Building.

std::uint64_t KineticRangeTree::build_block(Layout& l, int j, std::size_t a, std::uint32_t s,
                                            std::uint32_t e) const {
  if (j + 1 >= d_ || e <= s) return 0;
  const auto next = static_cast<std::size_t>(j + 1);
  const std::size_t n = n_;
  const std::vector<std::uint32_t>& ord = l[static_cast<std::size_t>(j)].ord;
  const std::vector<std::uint32_t>& pos = l[static_cast<std::size_t>(j)].pos;
  std::vector<std::uint32_t>& child = l[next].ord;
  std::uint64_t written = 0;
  // Depth 0: the whole block, sorted by axis j + 1.
  {
    const std::size_t b = child_array(a, 0);
    std::vector<std::uint32_t> block(ord.begin() + static_cast<std::ptrdiff_t>(a * n + s),
                                     ord.begin() + static_cast<std::ptrdiff_t>(a * n + e + 1));
    const int axis = j + 1;
    std::sort(block.begin(), block.end(), [&](std::uint32_t p, std::uint32_t q) {
      return rank_of(p, axis) < rank_of(q, axis);
    });
    for (std::uint32_t i = s; i <= e; ++i) set(l, j + 1, b, i, block[i - s]);
    written += e - s + 1;
    written += build_block(l, j + 1, b, s, e);
  }
  // Deeper nodes: each child's block is its part of the parent's block, in the parent's order
  // (a stable partition by the position in this level's order).
  struct Item {
    std::uint32_t s, e, ps, pe, k;
  };
  std::vector<Item> stack;
  auto push_children = [&](std::uint32_t cs, std::uint32_t ce, std::uint32_t k) {
    const std::uint32_t m = cs + (ce - cs) / 2;
    if (m > cs) stack.push_back({cs, m, cs, ce, k + 1});
    if (ce > m + 1) stack.push_back({m + 1, ce, cs, ce, k + 1});
  };
  push_children(s, e, 0);
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    const std::size_t parent = child_array(a, it.k - 1);
    const std::size_t b = child_array(a, it.k);
    std::uint32_t w = it.s;
    for (std::uint32_t i = it.ps; i <= it.pe; ++i) {
      const std::uint32_t p = child[parent * n + i];
      const std::uint32_t at = pos[a * cap_ + p];
      if (at >= it.s && at <= it.e) set(l, j + 1, b, w++, p);
    }
    assert(w == it.e + 1);
    written += it.e - it.s + 1;
    written += build_block(l, j + 1, b, it.s, it.e);
    push_children(it.s, it.e, it.k);
  }
  return written;
}

void KineticRangeTree::build_all(Layout& out) const {
  out = Layout();
  out.resize(static_cast<std::size_t>(d_));
  std::size_t arrays = 1;
  for (int j = 0; j < d_; ++j) {
    Level& lv = out[static_cast<std::size_t>(j)];
    lv.ord.assign(arrays * n_, kNoIndex);
    lv.pos.assign(arrays * cap_, kNoIndex);
    arrays *= height_ + 1;
  }
  const auto order = sorts_[0].order();
  for (std::uint32_t i = 0; i < n_; ++i) set(out, 0, 0, i, order[i]);
  if (n_ > 0) build_block(out, 0, 0, 0, static_cast<std::uint32_t>(n_ - 1));
}

void KineticRangeTree::refresh_linear(std::uint32_t point) {
  const auto d = static_cast<std::size_t>(d_);
  for (int axis = 0; axis < d_; ++axis) {
    const MotionPolynomial& p = motions_.motion(point, axis);
    linear_[point * d + static_cast<std::size_t>(axis)] =
        Linear{p.c[0], p.degree <= 1 ? p.c[1] : std::nan(""), p.origin};
  }
}

void KineticRangeTree::rebuild() {
  n_ = sorts_[0].order().size();
  cap_ = motions_.capacity();
  // The queries' copy of the motions (degree <= 1: c0, c1, origin; NaN slope otherwise).
  const auto d = static_cast<std::size_t>(d_);
  linear_.assign(cap_ * d, Linear{});
  for (const std::uint32_t point : motions_.alive_indices()) refresh_linear(point);
  height_ = 0;
  while ((std::size_t{1} << height_) < n_) ++height_;
  build_all(layout_);
}

void KineticRangeTree::initialize() {
  sync_.note();
  sorts_.initialize();
  rebuild();
}

// ---------------------------------------------------------------------------------------------
// Events.

void KineticRangeTree::replace_in(int j, std::size_t a, std::uint32_t s, std::uint32_t e,
                                  std::uint32_t i, std::uint32_t new_point) {
  ++counters_.replacements;
  ++counters_.nodes_touched;
  ++counters_.last_event_nodes;
  Level& lv = layout_[static_cast<std::size_t>(j)];
  std::uint32_t* ord = lv.ord.data() + a * n_;
  std::uint32_t* pos = lv.pos.data() + a * cap_;
  if (j == d_ - 1) {
    // The last level: move the new point from slot i to its place in the sorted block.
    const std::uint32_t r = rank_of(new_point, j);
    while (i > s && rank_of(ord[i - 1], j) > r) {
      ord[i] = ord[i - 1];
      pos[ord[i]] = i;
      --i;
      ++counters_.shifts;
    }
    while (i < e && rank_of(ord[i + 1], j) < r) {
      ord[i] = ord[i + 1];
      pos[ord[i]] = i;
      ++i;
      ++counters_.shifts;
    }
    ord[i] = new_point;
    pos[new_point] = i;
    return;
  }
  // Above the last level (d >= 3): the node's block is re-sorted and its structure rebuilt.
  ord[i] = new_point;
  std::vector<std::uint32_t> block(ord + s, ord + e + 1);
  std::sort(block.begin(), block.end(),
            [&](std::uint32_t p, std::uint32_t q) { return rank_of(p, j) < rank_of(q, j); });
  for (std::uint32_t k = s; k <= e; ++k) set(layout_, j, a, k, block[k - s]);
  counters_.rebuilt_entries += (e - s + 1) + build_block(layout_, j, a, s, e);
}

void KineticRangeTree::swap_in(int j, std::size_t a, std::uint32_t s, std::uint32_t e, int axis,
                               std::uint32_t x, std::uint32_t y) {
  Level& lv = layout_[static_cast<std::size_t>(j)];
  const std::uint32_t ix = lv.pos[a * cap_ + x];
  const std::uint32_t iy = lv.pos[a * cap_ + y];
  assert(ix >= s && ix <= e && iy >= s && iy <= e);
  if (j < axis) {
    // The nodes holding both: from the block's root down to their lowest common ancestor.
    std::uint32_t cs = s, ce = e, k = 0;
    for (;;) {
      swap_in(j + 1, child_array(a, k), cs, ce, axis, x, y);
      const std::uint32_t m = cs + (ce - cs) / 2;
      if (ix <= m && iy <= m) {
        ce = m;
      } else if (ix > m && iy > m) {
        cs = m + 1;
      } else {
        break;
      }
      ++k;
    }
    return;
  }
  // j == axis: adjacent here; they exchange places.
  assert(ix + 1 == iy || iy + 1 == ix);
  const std::uint32_t lo = std::min(ix, iy);
  const std::uint32_t before_lo = lv.ord[a * n_ + lo];  // moves to lo + 1
  const std::uint32_t after_lo = lv.ord[a * n_ + lo + 1];
  set(layout_, j, a, lo, after_lo);
  set(layout_, j, a, lo + 1, before_lo);
  ++counters_.adjacent_swaps;
  ++counters_.nodes_touched;
  ++counters_.last_event_nodes;
  if (j == d_ - 1) return;
  // Down to the lowest common ancestor of positions lo and lo + 1 (split at m = lo).
  std::uint32_t cs = s, ce = e, k = 0;
  for (;;) {
    const std::uint32_t m = cs + (ce - cs) / 2;
    if (lo + 1 <= m) {
      ce = m;
    } else if (lo > m) {
      cs = m + 1;
    } else {
      break;
    }
    ++k;
  }
  // Strictly below it: on the left the nodes ending at lo lose before_lo and gain after_lo; on
  // the right the nodes starting at lo + 1 the converse. Both positions are read before either
  // block is changed (the two nodes of a depth share one array).
  const std::uint32_t m = cs + (ce - cs) / 2;
  std::uint32_t ls = cs, le = m, rs = m + 1, re = ce;
  Level& next = layout_[static_cast<std::size_t>(j + 1)];
  for (std::uint32_t kk = k + 1; le > ls || re > rs; ++kk) {
    const std::size_t b = child_array(a, kk);
    const bool left = le > ls, right = re > rs;
    const std::uint32_t il = left ? next.pos[b * cap_ + before_lo] : 0;
    const std::uint32_t ir = right ? next.pos[b * cap_ + after_lo] : 0;
    if (left) {
      replace_in(j + 1, b, ls, le, il, after_lo);
      ls = ls + (le - ls) / 2 + 1;  // the right child holds lo
    }
    if (right) {
      replace_in(j + 1, b, rs, re, ir, before_lo);
      re = rs + (re - rs) / 2;  // the left child holds lo + 1
    }
  }
}

EventKind KineticRangeTree::process(const Event& event) {
  const auto axis = static_cast<std::uint32_t>(sorts_.member_of(event));
  KineticSort& s = sorts_[axis];
  const KineticSort::Swap swap = s.process_swap(event);
  ++counters_.swaps;
  ++counters_.swaps_by_axis[axis];
  counters_.last_event_nodes = 0;
  // x moved up one place past its neighbour y.
  swap_in(0, 0, 0, static_cast<std::uint32_t>(n_ - 1), static_cast<int>(axis), swap.up, swap.down);
  return EventKind::External;
}

void KineticRangeTree::insert(std::uint32_t index) {
  sync_.require_inserted("KineticRangeTree::insert", index);
  sorts_.insert(index);
  ++counters_.rebuilds;
  rebuild();
}

void KineticRangeTree::remove(std::uint32_t index) {
  sync_.require_removed("KineticRangeTree::remove", index);
  sorts_.remove(index);
  ++counters_.rebuilds;
  rebuild();
}

void KineticRangeTree::motion_changed(std::uint32_t index) {
  sync_.require_updated("KineticRangeTree::motion_changed", index);
  // n is unchanged, so is every tree's shape: replay the move on each axis as adjacent swaps
  // (header comment), axis by axis, unless they exceed the limit in total.
  std::size_t moves = 0;
  for (const KineticSort& s : sorts_.members()) {
    const std::uint32_t r = s.rank(index), r2 = s.rank_after_update(index);
    moves += r2 > r ? r2 - r : r - r2;
  }
  const std::size_t limit = update_swap_limit();
  if (motions_.capacity() != cap_ || sorts_[0].order().size() != n_ || limit == 0 ||
      moves > limit) {
    sorts_.motion_changed(index);
    ++counters_.rebuilds;
    ++counters_.update_rebuilds;
    rebuild();
    return;
  }
  const auto last = static_cast<std::uint32_t>(n_ - 1);
  for (int axis = 0; axis < d_; ++axis) {
    KineticSort& s = sorts_[static_cast<std::size_t>(axis)];
    const std::uint32_t r = s.rank(index);
    s.motion_changed(index);
    const std::uint32_t r2 = s.rank(index);
    // On the intermediate order, `index` and the point it passes are adjacent on this axis.
    const std::span<const std::uint32_t> order = s.order();
    if (r2 > r) {
      for (std::uint32_t k = r; k < r2; ++k) swap_in(0, 0, 0, last, axis, index, order[k]);
    } else {
      for (std::uint32_t k = r; k > r2; --k) swap_in(0, 0, 0, last, axis, index, order[k]);
    }
  }
  counters_.replayed_swaps += moves;
  refresh_linear(index);
  ++counters_.local_updates;
}

// ---------------------------------------------------------------------------------------------
// Queries.

int KineticRangeTree::compare(std::uint32_t point, int axis, double v, Time t) const {
  const Linear& l = linear_[static_cast<std::size_t>(point) * static_cast<std::size_t>(d_) +
                            static_cast<std::size_t>(axis)];
  // The linear filter (a NaN c1 marks a motion of degree above 1: undecided), then exactly.
  const int s = numeric::linear_sign_versus(l.c0, l.c1, l.origin, t, v);
  if (s != 0) return s;
  return compare_at_value(motions_.motion(point, axis), v, t, &sim_.counters().predicates);
}

bool KineticRangeTree::inside_from(std::uint32_t point, int axis, const Query& q) const {
  for (int i = axis; i < d_; ++i) {
    const auto& b = (*q.box)[static_cast<std::size_t>(i)];
    if (compare(point, i, b[0], q.t) < 0 || compare(point, i, b[1], q.t) > 0) return false;
  }
  return true;
}

void KineticRangeTree::search(int j, std::size_t a, std::uint32_t s, std::uint32_t e,
                              Query& q) const {
  // Binary searches over the block's order on axis j: they follow the array as it is (a robust
  // order may be briefly unsorted; Abam, Agarwal, de Berg, Yu, Theorem 8).
  const std::uint32_t* ord = layout_[static_cast<std::size_t>(j)].ord.data() + a * n_;
  const auto& b = (*q.box)[static_cast<std::size_t>(j)];
  std::uint32_t lo = s, hi = e + 1;  // first position with x >= b[0]
  while (lo < hi) {
    const std::uint32_t mid = lo + (hi - lo) / 2;
    ++q.visits;
    if (compare(ord[mid], j, b[0], q.t) < 0) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  const std::uint32_t first = lo;
  hi = e + 1;  // first position with x > b[1]
  while (lo < hi) {
    const std::uint32_t mid = lo + (hi - lo) / 2;
    ++q.visits;
    if (compare(ord[mid], j, b[1], q.t) <= 0) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  const std::uint32_t end = lo;
  if (first >= end) return;
  if (j == d_ - 1) {
    q.out->insert(q.out->end(), ord + first, ord + end);
    return;
  }
  canonical(j, a, s, e, 0, first, end - 1, q);
}

void KineticRangeTree::canonical(int j, std::size_t a, std::uint32_t s, std::uint32_t e,
                                 std::uint32_t k, std::uint32_t lo, std::uint32_t hi,
                                 Query& q) const {
  ++q.visits;
  if (e < lo || s > hi) return;
  if (lo <= s && e <= hi) {
    if (s == e) {
      const std::uint32_t p = layout_[static_cast<std::size_t>(j)].ord[a * n_ + s];
      if (inside_from(p, j + 1, q)) q.out->push_back(p);
    } else {
      search(j + 1, child_array(a, k), s, e, q);
    }
    return;
  }
  const std::uint32_t m = s + (e - s) / 2;
  canonical(j, a, s, m, k + 1, lo, hi, q);
  canonical(j, a, m + 1, e, k + 1, lo, hi, q);
}

void KineticRangeTree::sort_ids(std::vector<std::uint32_t>& out) {
  numeric::sort_ids_ascending(out, motions_.capacity(), seen_, seen_words_);
}

std::vector<std::uint32_t> KineticRangeTree::range(const Box& box, Time t) {
  sync_.require_current("KineticRangeTree::range");
  require_query_time("KineticRangeTree::range", t, sim_.now());
  require_box("KineticRangeTree::range", box, d_);
  std::vector<std::uint32_t> out;
  Query q{&box, t, &out, 0};
  if (n_ > 0) search(0, 0, 0, static_cast<std::uint32_t>(n_ - 1), q);
  sort_ids(out);
  ++counters_.queries;
  counters_.node_visits += q.visits;
  counters_.last_query_visits = q.visits;
  return out;
}

// ---------------------------------------------------------------------------------------------
// Measures and validation.

std::size_t KineticRangeTree::stored_entries() const {
  std::size_t count = 0;
  for (const Level& lv : layout_) {
    count += static_cast<std::size_t>(
        std::count_if(lv.ord.begin(), lv.ord.end(), [](std::uint32_t p) { return p != kNoIndex; }));
  }
  return count;
}

std::size_t KineticRangeTree::memory_bytes() const {
  std::size_t bytes = 0;
  for (const Level& lv : layout_) {
    bytes += (lv.ord.capacity() + lv.pos.capacity()) * sizeof(std::uint32_t);
  }
  return bytes;
}

std::size_t KineticRangeTree::certificates() const { return sorts_.certificates(); }

std::size_t KineticRangeTree::certificates_per_object_max() const {
  return sorts_.certificates_per_object_max();
}

bool KineticRangeTree::validate() const {
  if (!sync_.current()) return false;
  if (!sorts_.validate()) return false;
  if (n_ != motions_.size() || n_ != sorts_[0].order().size()) return false;
  for (const std::uint32_t p : motions_.alive_indices()) {
    for (int axis = 0; axis < d_; ++axis) {
      const MotionPolynomial& m = motions_.motion(p, axis);
      const Linear& l = linear_[p * static_cast<std::size_t>(d_) + static_cast<std::size_t>(axis)];
      const bool slope = m.degree <= 1 ? l.c1 == m.c[1] : std::isnan(l.c1);
      if (l.c0 != m.c[0] || l.origin != m.origin || !slope) return false;
    }
  }
  Layout fresh;
  build_all(fresh);
  if (fresh.size() != layout_.size()) return false;
  std::size_t arrays = 1;
  std::size_t per_level_bound = n_;  // n H^j entries at level j
  for (std::size_t j = 0; j < layout_.size(); ++j) {
    const Level& lv = layout_[j];
    if (lv.ord != fresh[j].ord) return false;
    if (lv.pos.size() != arrays * cap_) return false;
    std::size_t used = 0;
    for (std::size_t a = 0; a < arrays; ++a) {
      for (std::size_t i = 0; i < n_; ++i) {
        const std::uint32_t p = lv.ord[a * n_ + i];
        if (p == kNoIndex) continue;
        ++used;
        if (lv.pos[a * cap_ + p] != i) return false;
      }
    }
    if (used > per_level_bound) return false;
    arrays *= height_ + 1;
    per_level_bound *= std::max<std::size_t>(height_, 1);
  }
  return true;
}

NamedCounters KineticRangeTree::named_counters() const {
  const RangeTreeCounters& c = counters_;
  NamedCounters out;
  for (std::size_t a = 0; a < c.swaps_by_axis.size(); ++a) {
    out.push_back({"swaps_axis_" + std::to_string(a), c.swaps_by_axis[a]});
  }
  out.insert(out.end(), {{"swaps", c.swaps},
                         {"nodes_touched", c.nodes_touched},
                         {"adjacent_swaps", c.adjacent_swaps},
                         {"replacements", c.replacements},
                         {"shifts", c.shifts},
                         {"rebuilt_entries", c.rebuilt_entries},
                         {"local_updates", c.local_updates},
                         {"update_rebuilds", c.update_rebuilds},
                         {"replayed_swaps", c.replayed_swaps},
                         {"rebuilds", c.rebuilds},
                         {"stored_entries", stored_entries()},
                         {"queries", c.queries},
                         {"node_visits", c.node_visits}});
  return out;
}

}  // namespace kinetic
