#include "kinetic/range_tree/kinetic_range_tree.hpp"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
#include <span>

#include "core/numeric/linear_filter.hpp"
#include "kinetic/core/predicates.hpp"

namespace kinetic {

/// The arrays of one level. Only the arrays under a node of two positions or more are stored:
/// array a (numbered by its tuple of depths, child_array()) is the c-th stored one, c =
/// place[a] (kNoIndex: not stored); its entries are ord[c * U + i], and a point's position in it
/// pos[p * arrays + c], point-major, so that a point's positions lie together and a growing table
/// only appends.
struct KineticRangeTree::Level {
  std::vector<std::uint32_t> ord;
  std::vector<std::uint32_t> pos;
  std::vector<std::uint32_t> place;
  std::vector<std::uint32_t> size;  // block size of each array (0: not stored)
  std::size_t arrays = 0;
  [[nodiscard]] std::uint32_t* block(std::size_t a, std::size_t u) {
    return ord.data() + std::size_t{place[a]} * u;
  }
  [[nodiscard]] const std::uint32_t* block(std::size_t a, std::size_t u) const {
    return ord.data() + std::size_t{place[a]} * u;
  }
  [[nodiscard]] std::uint32_t& at(std::uint32_t p, std::size_t a) {
    return pos[p * arrays + place[a]];
  }
  [[nodiscard]] std::uint32_t at(std::uint32_t p, std::size_t a) const {
    return pos[p * arrays + place[a]];
  }
};

/// The position map of one array: view[p] is p's position there, or kNoIndex.
struct KineticRangeTree::PosView {
  std::uint32_t* base;
  std::size_t stride;
  std::uint32_t& operator[](std::uint32_t p) const { return base[p * stride]; }
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

/// An entry of a block that changed positions.
struct KineticRangeTree::Move {
  std::uint32_t point;
  std::uint32_t from;
  std::uint32_t to;
};

namespace {

constexpr std::uint32_t kVacant = kNoIndex;

/// log2 of a power of two.
std::uint32_t log2_of(std::size_t size) {
  return static_cast<std::uint32_t>(std::bit_width(size)) - 1;
}

/// The deepest depth of a block's tree (block of 2^h positions, aligned) whose node holds both
/// positions.
std::uint32_t lca_depth(std::uint32_t h, std::uint32_t i, std::uint32_t k) {
  return h - static_cast<std::uint32_t>(std::bit_width(i ^ k));
}

/// The k-th of m entries spread evenly over w positions starting at s (m <= w).
std::uint32_t spread_position(std::uint32_t s, std::size_t w, std::size_t m, std::size_t k) {
  return s + static_cast<std::uint32_t>(((2 * k + 1) * w) / (2 * m));
}

/// In ord[lo, end): the first position whose first entry at or after it (vacancies skipped)
/// satisfies `past`, or `end`. `past` must be monotone along the entries. Adds to *visits the
/// probes and the vacancies they skipped.
template <class Past>
std::uint32_t first_past(const std::uint32_t* ord, std::uint32_t lo, std::uint32_t end, Past&& past,
                         std::uint64_t* visits) {
  std::uint32_t hi = end;
  while (lo < hi) {
    const std::uint32_t mid = lo + (hi - lo) / 2;
    std::uint32_t k = mid;
    while (k < hi && ord[k] == kVacant) ++k;
    *visits += 1 + (k - mid);
    if (k == hi || past(ord[k])) {
      hi = mid;
    } else {
      lo = k + 1;
    }
  }
  return lo;
}

/// An aligned window of a block: positions [first, first + width), holding `count` entries.
struct Window {
  std::uint32_t first;
  std::uint32_t width;
  std::size_t count;
};

/// The smallest aligned window of `width` positions or more (doubling) around `anchor` in the
/// block [s, s + size) whose count `good(count, width)` accepts, or the whole block.
template <class Good>
Window smallest_window(const std::uint32_t* ord, std::uint32_t s, std::uint32_t size,
                       std::uint32_t anchor, std::uint32_t width, Good&& good) {
  Window w{s, std::min(size, width), 0};
  for (;;) {
    w.first = s + ((anchor - s) / w.width) * w.width;
    w.count = static_cast<std::size_t>(std::count_if(ord + w.first, ord + w.first + w.width,
                                                     [](std::uint32_t p) { return p != kVacant; }));
    if (w.width == size || good(w.count, std::size_t{w.width})) return w;
    w.width *= 2;
  }
}

}  // namespace

KineticRangeTree::~KineticRangeTree() = default;

std::uint32_t* KineticRangeTree::ord_of(int j, std::size_t a) {
  return layout_[static_cast<std::size_t>(j)].block(a, u_);
}

KineticRangeTree::PosView KineticRangeTree::pos_of(int j, std::size_t a) {
  Level& lv = layout_[static_cast<std::size_t>(j)];
  return PosView{lv.pos.data() + lv.place[a], lv.arrays};
}

KineticRangeTree::KineticRangeTree(const MotionTable& motions, Simulator& simulator,
                                   const Scheduler& scheduler)
    : AxisSortedPoints(motions, simulator, scheduler, "KineticRangeTree", 8,
                       "points in 1 to 8 dimensions") {
  counters_.swaps_by_axis.assign(static_cast<std::size_t>(d_), 0);
}

// ---------------------------------------------------------------------------------------------
// Building.

std::uint64_t KineticRangeTree::build_block(Layout& l, int j, std::size_t a, std::uint32_t s,
                                            std::uint32_t size) const {
  if (j + 1 >= d_ || size < 2) return 0;
  const auto here = static_cast<std::size_t>(j);
  const Level& lv = l[here];
  const std::uint32_t* ord = lv.block(a, u_);
  Level& next = l[here + 1];
  auto spread_into = [&](std::size_t b, std::uint32_t first, std::uint32_t w,
                         const std::vector<std::uint32_t>& points) {
    for (std::size_t k = 0; k < points.size(); ++k) {
      const std::uint32_t at = spread_position(first, w, points.size(), k);
      next.block(b, u_)[at] = points[k];
      next.at(points[k], b) = at;
    }
  };
  std::uint64_t written = 0;
  std::vector<std::uint32_t> points;
  // Depth 0: the whole block, sorted by axis j + 1.
  for (std::uint32_t i = s; i < s + size; ++i) {
    if (ord[i] != kVacant) points.push_back(ord[i]);
  }
  const int axis = j + 1;
  std::sort(points.begin(), points.end(),
            [&](std::uint32_t p, std::uint32_t q) { return label(p, axis) < label(q, axis); });
  spread_into(child_array(a, 0), s, size, points);
  written += points.size() + build_block(l, j + 1, child_array(a, 0), s, size);
  // Deeper nodes: each child's points are its part of the parent's block, in the parent's order.
  for (std::uint32_t k = 1; (size >> k) >= 2; ++k) {
    const std::uint32_t sub = size >> k;
    const std::size_t parent = child_array(a, k - 1), b = child_array(a, k);
    for (std::uint32_t ns = s; ns < s + size; ns += sub) {
      const std::uint32_t ps = ns & ~(2 * sub - 1);
      points.clear();
      for (std::uint32_t i = ps; i < ps + 2 * sub; ++i) {
        const std::uint32_t p = next.block(parent, u_)[i];
        if (p != kVacant && lv.at(p, a) >= ns && lv.at(p, a) < ns + sub) {
          points.push_back(p);
        }
      }
      spread_into(b, ns, sub, points);
      written += points.size() + build_block(l, j + 1, b, ns, sub);
    }
  }
  return written;
}

void KineticRangeTree::build_all(Layout& out) const {
  out = Layout();
  out.resize(static_cast<std::size_t>(d_));
  // The stored arrays: those whose blocks have two positions or more.
  out[0].place = {0};
  out[0].size = {static_cast<std::uint32_t>(u_)};
  out[0].arrays = 1;
  for (std::size_t j = 1; j < out.size(); ++j) {
    const Level& up = out[j - 1];
    Level& lv = out[j];
    lv.place.assign(up.place.size() * (height_ + 1), kNoIndex);
    lv.size.assign(lv.place.size(), 0);
    for (std::size_t a = 0; a < up.place.size(); ++a) {
      for (std::uint32_t k = 0; k <= height_ && (up.size[a] >> k) >= 2; ++k) {
        const std::size_t b = child_array(a, k);
        lv.place[b] = static_cast<std::uint32_t>(lv.arrays++);
        lv.size[b] = up.size[a] >> k;
      }
    }
  }
  for (Level& lv : out) {
    lv.ord.assign(lv.arrays * u_, kVacant);
    lv.pos.assign(lv.arrays * cap_, kVacant);
  }
  const auto order = sorts_[0].order();
  for (std::uint32_t i = 0; i < u_; ++i) {
    out[0].ord[i] = order[i];
    if (order[i] != kVacant) out[0].pos[order[i]] = i;
  }
  if (u_ > 0) build_block(out, 0, 0, 0, static_cast<std::uint32_t>(u_));
}

void KineticRangeTree::refresh_linear(std::uint32_t point) {
  const auto d = static_cast<std::size_t>(d_);
  for (int axis = 0; axis < d_; ++axis) {
    const numeric::LinearParts m = numeric::linear_parts(motions_.motion(point, axis));
    linear_[point * d + static_cast<std::size_t>(axis)] = Linear{m.c0, m.c1, m.origin};
  }
}

void KineticRangeTree::rebuild() {
  n_ = motions_.size();
  cap_ = motions_.capacity();
  u_ = sorts_[0].slots();
  assert(u_ == 0 || std::has_single_bit(u_));
  height_ = u_ == 0 ? 0 : log2_of(u_);
  // The queries' copy of the motions (degree <= 1: c0, c1, origin; NaN slope otherwise).
  const auto d = static_cast<std::size_t>(d_);
  linear_.assign(cap_ * d, Linear{});
  for (const std::uint32_t point : motions_.alive_indices()) refresh_linear(point);
  build_all(layout_);
  moves_.assign(d, {});
  window_.assign(d, {});
}

void KineticRangeTree::initialize() {
  sync_.note();
  sorts_.initialize();
  rebuild();
}

// ---------------------------------------------------------------------------------------------
// The block operations.

void KineticRangeTree::vacate(int j, std::size_t a, std::uint32_t size, std::uint32_t point) {
  const PosView pos = pos_of(j, a);
  const std::uint32_t i = pos[point];
  assert(i != kVacant);
  ord_of(j, a)[i] = kVacant;
  pos[point] = kVacant;
  ++counters_.vacated;
  ++counters_.nodes_touched;
  ++counters_.last_event_nodes;
  if (j + 1 < d_) {
    for (std::uint32_t k = 0; (size >> k) >= 2; ++k) {
      vacate(j + 1, child_array(a, k), size >> k, point);
    }
  }
  // A long run of vacancies would make the searches through this block scan it (A_0's mirror
  // is the sort's packed-memory array, whose runs are shorter than a segment).
  if (j > 0) close_gap(j, a, size, i);
}

void KineticRangeTree::place_below(int j, std::size_t a, std::uint32_t size, std::uint32_t at,
                                   std::uint32_t point) {
  for (std::uint32_t k = 0; (size >> k) >= 2; ++k) {
    const std::uint32_t sub = size >> k;
    place(j + 1, child_array(a, k), at & ~(sub - 1), sub, point);
  }
}

void KineticRangeTree::move_below(int j, std::size_t a, std::uint32_t size) {
  const std::vector<Move>& moves = moves_[static_cast<std::size_t>(j)];
  const std::uint32_t h = log2_of(size);
  // Every moved point out of the nodes it leaves first: a block then never holds more points
  // than positions while the others enter.
  for (const Move& m : moves) {
    for (std::uint32_t k = lca_depth(h, m.from, m.to) + 1; k < h; ++k) {
      vacate(j + 1, child_array(a, k), size >> k, m.point);
    }
  }
  for (const Move& m : moves) {
    for (std::uint32_t k = lca_depth(h, m.from, m.to) + 1; k < h; ++k) {
      const std::uint32_t sub = size >> k;
      place(j + 1, child_array(a, k), m.to & ~(sub - 1), sub, m.point);
    }
  }
}

std::uint32_t KineticRangeTree::respread(int j, std::size_t a, std::uint32_t w0, std::uint32_t w,
                                         std::uint32_t at, std::uint32_t point) {
  std::uint32_t* ord = ord_of(j, a);
  const PosView pos = pos_of(j, a);
  std::vector<std::uint32_t>& entries = window_[static_cast<std::size_t>(j)];
  entries.clear();
  for (std::uint32_t i = w0; i < w0 + w; ++i) {
    if (i == at && point != kVacant) entries.push_back(point);
    if (ord[i] != kVacant) entries.push_back(ord[i]);
  }
  if (point != kVacant && at >= w0 + w) entries.push_back(point);
  std::fill(ord + w0, ord + w0 + w, kVacant);
  std::vector<Move>& moves = moves_[static_cast<std::size_t>(j)];
  const bool below = j + 1 < d_;  // the moved entries change the blocks below
  std::uint32_t mine = kVacant;
  for (std::size_t k = 0; k < entries.size(); ++k) {
    const std::uint32_t p = entries[k];
    const std::uint32_t to = spread_position(w0, w, entries.size(), k);
    ord[to] = p;
    if (p == point) {
      mine = to;
    } else if (below && pos[p] != to) {
      moves.push_back({p, pos[p], to});
    }
    pos[p] = to;
  }
  ++counters_.window_spreads;
  counters_.spread_entries += entries.size();
  return mine;
}

std::uint32_t KineticRangeTree::spread_window(int j, std::size_t a, std::uint32_t s,
                                              std::uint32_t size, std::uint32_t at,
                                              std::uint32_t point) {
  const Window w = smallest_window(
      ord_of(j, a), s, size, std::min(at, s + size - 1), 2 * kShiftReach,
      [](std::size_t count, std::size_t width) { return (count + 1) * 8 <= width * 7; });
  assert(w.count < w.width);  // a block holds fewer points than positions before a place
  return respread(j, a, w.first, w.width, at, point);
}

void KineticRangeTree::close_gap(int j, std::size_t a, std::uint32_t size, std::uint32_t i) {
  if (size <= kMaxVacantRun) return;
  const std::uint32_t* ord = ord_of(j, a);
  const std::uint32_t s = i & ~(size - 1), e = s + size - 1;
  // The run of vacancies through i, measured up to kMaxVacantRun.
  std::uint32_t l = i, r = i;
  while (l > s && ord[l - 1] == kVacant && r - l + 1 < kMaxVacantRun) --l;
  while (r < e && ord[r + 1] == kVacant && r - l + 1 < kMaxVacantRun) ++r;
  if (r - l + 1 < kMaxVacantRun) return;
  // The smallest aligned window around i with more than one entry per kMaxVacantRun / 2
  // positions (or the whole block), spread evenly: its runs are then shorter than
  // kMaxVacantRun / 2.
  const Window w = smallest_window(
      ord, s, size, i, 2 * kMaxVacantRun,
      [](std::size_t count, std::size_t width) { return count * (kMaxVacantRun / 2) > width; });
  if (w.count == 0) return;  // an empty block: nothing to spread
  ++counters_.gap_spreads;
  moves_[static_cast<std::size_t>(j)].clear();
  respread(j, a, w.first, w.width, kVacant, kVacant);
  if (j + 1 < d_) move_below(j, a, size);
}

void KineticRangeTree::place(int j, std::size_t a, std::uint32_t s, std::uint32_t size,
                             std::uint32_t point) {
  std::uint32_t* ord = ord_of(j, a);
  const PosView pos = pos_of(j, a);
  const std::uint32_t e = s + size - 1;
  const std::uint32_t key = label(point, j);
  // The first position whose first entry at or after it has a larger label (or e + 1): the
  // point goes just before that entry.
  std::uint64_t probes = 0;  // (not counted: the queries' visits)
  const std::uint32_t lo = first_past(
      ord, s, e + 1, [&](std::uint32_t p) { return label(p, j) > key; }, &probes);
  ++counters_.placements;
  ++counters_.nodes_touched;
  ++counters_.last_event_nodes;
  std::vector<Move>& moves = moves_[static_cast<std::size_t>(j)];
  moves.clear();
  std::uint32_t at = kVacant;
  // (The entry before lo, if any, is occupied: lo is s or just after an occupied entry.)
  if (lo <= e && ord[lo] == kVacant) {
    at = lo;
  } else {
    // The nearest vacancy within kShiftReach; the entries between shift one position toward it.
    const auto shift = [&](std::uint32_t from, std::uint32_t to) {
      const std::uint32_t p = ord[from];
      ord[to] = p;
      pos[p] = to;
      if (j + 1 < d_) moves.push_back({p, from, to});
      ++counters_.shifts;
    };
    for (std::uint32_t r = 1; r <= kShiftReach && at == kVacant; ++r) {
      if (lo + r <= e && ord[lo + r] == kVacant) {
        for (std::uint32_t k = lo + r; k > lo; --k) shift(k - 1, k);
        at = lo;
      } else if (lo >= s + r + 1 && ord[lo - 1 - r] == kVacant) {
        for (std::uint32_t k = lo - 1 - r; k + 1 < lo; ++k) shift(k + 1, k);
        at = lo - 1;
      }
    }
    if (at == kVacant) at = spread_window(j, a, s, size, lo, point);
  }
  ord[at] = point;
  pos[point] = at;
  if (j + 1 >= d_) return;
  if (!moves.empty()) move_below(j, a, size);
  place_below(j, a, size, at, point);
}

void KineticRangeTree::swap_in(int j, std::size_t a, std::uint32_t size, int axis, std::uint32_t x,
                               std::uint32_t y) {
  const PosView pos = pos_of(j, a);
  const std::uint32_t ix = pos[x], iy = pos[y];
  assert(ix != kVacant && iy != kVacant && ix != iy);
  const std::uint32_t h = log2_of(size);
  const std::uint32_t lca = lca_depth(h, ix, iy);
  if (j < axis) {
    // The nodes holding both: from the block's root down to their lowest common ancestor.
    for (std::uint32_t k = 0; k <= lca; ++k) {
      swap_in(j + 1, child_array(a, k), size >> k, axis, x, y);
    }
    return;
  }
  // j == axis: next to each other here (up to vacancies); they exchange positions.
  std::uint32_t* ord = ord_of(j, a);
  ord[ix] = y;
  pos[y] = ix;
  ord[iy] = x;
  pos[x] = iy;
  ++counters_.adjacent_swaps;
  ++counters_.nodes_touched;
  ++counters_.last_event_nodes;
  if (j + 1 >= d_) return;
  // Strictly below their lowest common ancestor, x's nodes take y and y's take x.
  std::vector<Move>& moves = moves_[static_cast<std::size_t>(j)];
  moves.assign({Move{x, ix, iy}, Move{y, iy, ix}});
  counters_.replacements += 2 * (h - 1 - lca);
  move_below(j, a, size);
}

EventKind KineticRangeTree::process(const Event& event) {
  const auto axis = static_cast<std::uint32_t>(sorts_.member_of(event));
  KineticSort& s = sorts_[axis];
  const KineticSort::Swap swap = s.process_swap(event);
  ++counters_.swaps;
  ++counters_.swaps_by_axis[axis];
  counters_.last_event_nodes = 0;
  // x moved up one place past its neighbour y.
  swap_in(0, 0, static_cast<std::uint32_t>(u_), static_cast<int>(axis), swap.up, swap.down);
  return EventKind::External;
}

// ---------------------------------------------------------------------------------------------
// Inserts, removes, flight-plan updates.

void KineticRangeTree::follow_sorts(std::uint32_t own, std::uint64_t generation) {
  const KineticSort& s = sorts_[0];
  n_ = motions_.size();
  if (s.layout_generation() != generation || s.slots() != u_) {
    // A_0 laid out again: every slot may have changed.
    ++counters_.rebuilds;
    rebuild();
    return;
  }
  if (motions_.capacity() > cap_) {
    // The table grew: the position maps (point-major) and the motions' copy take new rows.
    cap_ = motions_.capacity();
    for (Level& lv : layout_) lv.pos.resize(cap_ * lv.arrays, kVacant);
    linear_.resize(cap_ * static_cast<std::size_t>(d_), Linear{});
  }
  // The mirror of A_0 over the slots the sort touched.
  Level& top = layout_[0];
  const auto order = s.order();
  for (const auto& [first, last] : s.touched_slots()) {
    for (std::size_t i = first; i <= last; ++i) {
      top.ord[i] = order[i];
      if (order[i] != kVacant) top.pos[order[i]] = static_cast<std::uint32_t>(i);
    }
  }
  // The keys whose slot moved change nodes of the primary tree; labels moved on the other axes
  // keep their order, so those blocks stay as they are.
  std::vector<Move>& moves = moves_[0];
  moves.clear();
  const auto told = s.relabeled();
  const auto from = s.relabeled_from();
  for (std::size_t k = 0; k < told.size(); ++k) {
    const std::uint32_t p = told[k];
    if (p == own) continue;
    const std::uint32_t now = s.rank(p);
    if (from[k] != now) moves.push_back({p, from[k], now});
  }
  counters_.relabel_moves += moves.size();
  if (d_ > 1) {
    move_below(0, 0, static_cast<std::uint32_t>(u_));
    if (own != kNoIndex) place_below(0, 0, static_cast<std::uint32_t>(u_), s.rank(own), own);
  }
  if (own != kNoIndex) refresh_linear(own);
  ++counters_.local_changes;
}

void KineticRangeTree::insert(std::uint32_t index) {
  sync_.require_inserted("KineticRangeTree::insert", index);
  const std::uint64_t generation = sorts_[0].layout_generation();
  sorts_.insert(index);
  follow_sorts(index, generation);
}

void KineticRangeTree::remove(std::uint32_t index) {
  sync_.require_removed("KineticRangeTree::remove", index);
  const std::uint64_t generation = sorts_[0].layout_generation();
  vacate(0, 0, static_cast<std::uint32_t>(u_), index);  // while its entries are the tree's
  sorts_.remove(index);
  follow_sorts(kNoIndex, generation);
}

void KineticRangeTree::motion_changed(std::uint32_t index) {
  sync_.require_updated("KineticRangeTree::motion_changed", index);
  const std::uint64_t generation = sorts_[0].layout_generation();
  vacate(0, 0, static_cast<std::uint32_t>(u_), index);
  sorts_.motion_changed(index);
  follow_sorts(index, generation);
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

void KineticRangeTree::search(int j, std::size_t a, std::uint32_t s, std::uint32_t size,
                              Query& q) const {
  // Binary searches over the block's order on axis j, skipping vacancies: they follow the array
  // as it is (a robust order may be briefly unsorted; Abam, Agarwal, de Berg, Yu, Theorem 8).
  const std::uint32_t* ord = layout_[static_cast<std::size_t>(j)].block(a, u_);
  const auto& b = (*q.box)[static_cast<std::size_t>(j)];
  const std::uint32_t e = s + size - 1;
  const std::uint32_t first = first_past(
      ord, s, e + 1, [&](std::uint32_t p) { return compare(p, j, b[0], q.t) >= 0; }, &q.visits);
  const std::uint32_t end = first_past(
      ord, first, e + 1, [&](std::uint32_t p) { return compare(p, j, b[1], q.t) > 0; }, &q.visits);
  if (first >= end) return;
  if (j == d_ - 1) {
    // The run's entries without its vacancies (written unconditionally, kept when not vacant).
    std::vector<std::uint32_t>& out = *q.out;
    std::size_t w = out.size();
    out.resize(w + (end - first));
    std::uint32_t* dst = out.data();
    for (std::uint32_t i = first; i < end; ++i) {
      dst[w] = ord[i];
      w += ord[i] != kVacant ? 1 : 0;
    }
    out.resize(w);
    return;
  }
  canonical(j, a, s, size, 0, first, end - 1, q);
}

void KineticRangeTree::canonical(int j, std::size_t a, std::uint32_t s, std::uint32_t size,
                                 std::uint32_t k, std::uint32_t lo, std::uint32_t hi,
                                 Query& q) const {
  ++q.visits;
  const std::uint32_t e = s + size - 1;
  if (e < lo || s > hi) return;
  if (lo <= s && e <= hi) {
    if (size == 1) {
      const std::uint32_t p = layout_[static_cast<std::size_t>(j)].block(a, u_)[s];
      if (p != kVacant && inside_from(p, j + 1, q)) q.out->push_back(p);
    } else {
      search(j + 1, child_array(a, k), s, size, q);
    }
    return;
  }
  canonical(j, a, s, size / 2, k + 1, lo, hi, q);
  canonical(j, a, s + size / 2, size / 2, k + 1, lo, hi, q);
}

void KineticRangeTree::query(const Box& box, Time t, std::vector<std::uint32_t>& out) {
  require_range("KineticRangeTree::range", box, t);
  Query q{&box, t, &out, 0};
  if (n_ > 0) search(0, 0, 0, static_cast<std::uint32_t>(u_), q);
  ++counters_.queries;
  counters_.node_visits += q.visits;
  counters_.last_query_visits = q.visits;
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

std::size_t KineticRangeTree::longest_vacant_run() const {
  std::size_t longest = 0;
  for (std::size_t j = 1; j < layout_.size(); ++j) {
    const Level& lv = layout_[j];
    for (std::size_t a = 0; a < lv.place.size(); ++a) {
      if (lv.place[a] == kNoIndex) continue;
      const std::uint32_t* ord = lv.block(a, u_);
      const std::size_t size = lv.size[a];
      for (std::size_t s = 0; s < u_; s += size) {
        std::size_t run = 0, block_longest = 0;
        bool any = false;
        for (std::size_t i = s; i < s + size; ++i) {
          run = ord[i] == kVacant ? run + 1 : 0;
          any = any || ord[i] != kVacant;
          block_longest = std::max(block_longest, run);
        }
        if (any) longest = std::max(longest, block_longest);
      }
    }
  }
  return longest;
}

std::size_t KineticRangeTree::memory_bytes() const {
  std::size_t bytes = 0;
  for (const Level& lv : layout_) {
    bytes += (lv.ord.capacity() + lv.pos.capacity()) * sizeof(std::uint32_t);
  }
  return bytes;
}

bool KineticRangeTree::validate() const {
  if (!sync_.current()) return false;
  if (!sorts_.validate()) return false;
  const KineticSort& s0 = sorts_[0];
  if (n_ != motions_.size() || n_ != s0.size() || u_ != s0.slots() || cap_ != motions_.capacity() ||
      layout_.size() != static_cast<std::size_t>(d_)) {
    return false;
  }
  for (const std::uint32_t p : motions_.alive_indices()) {
    for (int axis = 0; axis < d_; ++axis) {
      const MotionPolynomial& m = motions_.motion(p, axis);
      const Linear& l = linear_[p * static_cast<std::size_t>(d_) + static_cast<std::size_t>(axis)];
      const bool slope = m.degree <= 1 ? l.c1 == m.c[1] : std::isnan(l.c1);
      if (l.c0 != m.c[0] || l.origin != m.origin || !slope) return false;
    }
  }
  // Level 0 mirrors A_0.
  const Level& top = layout_[0];
  if (top.ord.size() != u_ || top.pos.size() != cap_) return false;
  const auto order = s0.order();
  if (!std::equal(order.begin(), order.end(), top.ord.begin())) return false;
  std::size_t mapped = 0;
  for (std::uint32_t p = 0; p < cap_; ++p) {
    if (top.pos[p] == kVacant) continue;
    ++mapped;
    if (top.pos[p] >= u_ || top.ord[top.pos[p]] != p) return false;
  }
  if (mapped != n_) return false;
  // Below: each stored array at level j >= 1 holds, for a node of size >= 2 of the tree over a
  // block of the array above, exactly that level's points, each in its node, in label order.
  std::size_t per_level_bound = n_ * std::max<std::size_t>(height_, 1);  // n H^j at level j
  for (int j = 1; j < d_; ++j) {
    const Level& up = layout_[static_cast<std::size_t>(j - 1)];
    const Level& lv = layout_[static_cast<std::size_t>(j)];
    if (lv.place.size() != up.place.size() * (height_ + 1) || lv.size.size() != lv.place.size() ||
        lv.ord.size() != lv.arrays * u_ || lv.pos.size() != lv.arrays * cap_) {
      return false;
    }
    std::size_t used = 0, stored = 0;
    for (std::size_t a = 0; a < up.place.size(); ++a) {
      if (up.place[a] == kNoIndex) continue;
      std::size_t above = 0;  // entries of the parent array
      const std::uint32_t* parent = up.block(a, u_);
      for (std::size_t i = 0; i < u_; ++i) above += parent[i] != kVacant ? 1 : 0;
      for (std::uint32_t k = 0; k <= height_; ++k) {
        const std::size_t b = child_array(a, k);
        const std::uint32_t sub = k < 32 ? up.size[a] >> k : 0;
        if (sub < 2) {
          if (lv.place[b] != kNoIndex || lv.size[b] != 0) return false;
          continue;
        }
        if (lv.place[b] == kNoIndex || lv.size[b] != sub) return false;
        ++stored;
        const std::uint32_t* ord = lv.block(b, u_);
        std::size_t entries = 0;
        std::uint32_t previous = kVacant;  // label of the previous entry in the same block
        for (std::uint32_t i = 0; i < u_; ++i) {
          if (i % sub == 0) previous = kVacant;
          const std::uint32_t p = ord[i];
          if (p == kVacant) continue;
          if (p >= cap_ || lv.at(p, b) != i) return false;
          const std::uint32_t there = up.at(p, a);
          if (there == kVacant || there / sub != i / sub) return false;
          const std::uint32_t key = label(p, j);
          if (previous != kVacant && previous >= key) return false;
          previous = key;
          ++entries;
        }
        if (entries != above) return false;
        std::size_t maps = 0;
        for (std::uint32_t p = 0; p < cap_; ++p) maps += lv.at(p, b) != kVacant ? 1 : 0;
        if (maps != entries) return false;
        used += entries;
      }
    }
    if (stored != lv.arrays || used > per_level_bound) return false;
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
                         {"placements", c.placements},
                         {"vacated", c.vacated},
                         {"shifts", c.shifts},
                         {"window_spreads", c.window_spreads},
                         {"gap_spreads", c.gap_spreads},
                         {"spread_entries", c.spread_entries},
                         {"relabel_moves", c.relabel_moves},
                         {"local_changes", c.local_changes},
                         {"rebuilds", c.rebuilds},
                         {"stored_entries", stored_entries()},
                         {"slots", u_},
                         {"queries", c.queries},
                         {"node_visits", c.node_visits}});
  return out;
}

StructureDescription KineticRangeTree::description() {
  // Its space is U (log2 U + 1)^(d - 1) ids and positions, U the slots of A_0 (2n to 4n).
  return StructureDescription{
      "range-tree",
      "RangeTree",
      ObjectsAre::Points,
      {QueryType::Range},
      {"swap"},
      "The kinetic range tree, d = 1 to 8 (range(box), range_many(boxes); Delta-approximate"
      " near events).",
      "kinetic range tree (dimension <= 4; one kinetic sort per axis, Basch-Guibas-Zhang): "
      "orthogonal range queries"}
      .limit_dimensions(1, 4, "")
      .bound_events(per_axis_sort_bounds);
}

}  // namespace kinetic
