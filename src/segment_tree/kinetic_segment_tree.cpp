#include "kinetic/segment_tree/kinetic_segment_tree.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <optional>

#include "kinetic/core/predicates.hpp"

namespace kinetic {

struct KineticSegmentTree::Entry {  // an element of S(v): the segment and the slot of v in L(s)
  std::uint32_t segment;
  std::uint32_t slot;
};
struct KineticSegmentTree::Fragment {  // an element of L(s): the node and the position in S(node)
  std::uint32_t node;
  std::uint32_t pos;
};

KineticSegmentTree::KineticSegmentTree(const MotionTable& intervals, Simulator& simulator,
                                       const Scheduler& scheduler)
    : intervals_(intervals),
      sim_(simulator),
      endpoints_(1),
      sort_(endpoints_, simulator, scheduler, 0, SortLayout::Gapped) {
  require_dimension("KineticSegmentTree", intervals.dimension(), 2, 2,
                    "intervals (coordinate 0 the left end, 1 the right end)");
}

KineticSegmentTree::~KineticSegmentTree() = default;

void KineticSegmentTree::require_interval(const char* where, std::span<const MotionPolynomial> ends,
                                          Time from, Time until) {
  if (ends.size() != 2) return;  // the coordinate count is the table's check
  for (const MotionPolynomial& end : ends) check_motion(end, where);  // finite, before GMP
  if (const std::optional<Time> t = find_time_below(ends[1], ends[0], from, until)) {
    precondition_failed(where, "the interval is inside out (right end below its left end) at t = " +
                                   format_number(*t) +
                                   "; an interval must keep left <= right from now on");
  }
}

void KineticSegmentTree::add_endpoints(std::uint32_t index) {
  const std::size_t need = 2 * static_cast<std::size_t>(index) + 2;
  if (endpoint_of_.size() < need) endpoint_of_.resize(need, kNoIndex);
  for (std::uint32_t side = 0; side < 2; ++side) {
    const std::array<MotionPolynomial, 1> c{intervals_.motion(index, static_cast<int>(side))};
    // Identical end motions (a point interval): the left end first, by the endpoint id.
    const ObjectHandle h =
        endpoints_.insert(2 * intervals_.id(index) + side, c, intervals_.valid_from(index));
    endpoint_of_[2 * index + side] = h.index;
    if (owner_of_.size() <= h.index) owner_of_.resize(h.index + 1, kNoIndex);
    owner_of_[h.index] = 2 * index + side;
  }
}

void KineticSegmentTree::initialize() {
  sync_.note();
  // Start from an empty endpoint table (initialize may be called again).
  for (const std::uint32_t s : segments_) {
    for (std::uint32_t side = 0; side < 2; ++side)
      endpoints_.remove(endpoints_.handle(endpoint_of_[2 * s + side]));
  }
  segments_ = intervals_.alive_indices();
  grow();
  for (std::size_t k = 0; k < segments_.size(); ++k) {
    segment_at_[segments_[k]] = static_cast<std::uint32_t>(k);
    add_endpoints(segments_[k]);
  }
  sort_.initialize();
  rebuild();
}

void KineticSegmentTree::grow() {
  const std::size_t cap = intervals_.capacity();
  if (ring_head_.size() >= cap) return;
  ring_head_.resize(cap, 0);
  ring_size_.resize(cap, 0);
  ring_base_.resize(cap, kNoIndex);
  ring_class_.resize(cap, 0);
  range_lo_.resize(cap, 0);
  range_hi_.resize(cap, 0);
  segment_at_.resize(cap, kNoIndex);
  touched_mark_.resize(cap, 0);
}

std::uint32_t KineticSegmentTree::leaf_lo(std::uint32_t s) const {
  const std::uint32_t a = sort_.rank(endpoint_of_[2 * s]);
  const std::uint32_t b = sort_.rank(endpoint_of_[2 * s + 1]);
  return std::min(a, b);
}

std::uint32_t KineticSegmentTree::leaf_hi(std::uint32_t s) const {
  const std::uint32_t a = sort_.rank(endpoint_of_[2 * s]);
  const std::uint32_t b = sort_.rank(endpoint_of_[2 * s + 1]);
  return std::max(a, b) - 1;
}

void KineticSegmentTree::rebuild() {
  ++counters_.rebuilds;
  generation_ = sort_.layout_generation();
  m_ = static_cast<std::uint32_t>(std::max<std::size_t>(sort_.slots(), 1));  // a power of two
  levels_ = 0;
  while ((std::uint32_t{1} << levels_) < m_) ++levels_;
  sets_.assign(2 * static_cast<std::size_t>(m_), {});
  grow();
  std::fill(ring_base_.begin(), ring_base_.end(), kNoIndex);
  std::fill(ring_size_.begin(), ring_size_.end(), 0);
  ring_.clear();
  for (auto& f : free_rings_) f.clear();
  for (const std::uint32_t s : segments_) decompose_into_ring(s);
}

void KineticSegmentTree::decompose_into_ring(std::uint32_t s) {
  const std::uint32_t lo = leaf_lo(s), hi = leaf_hi(s);
  nodes_scratch_.clear();
  decompose(nodes_scratch_, 1, 0, m_ - 1, lo, hi);
  std::uint8_t size_class = kMinRingClass;  // the smallest ring that holds L(s)
  while ((std::size_t{1} << size_class) < nodes_scratch_.size()) ++size_class;
  ring_class_[s] = size_class;
  ring_base_[s] = allocate_ring(size_class);
  ring_head_[s] = 0;
  ring_size_[s] = 0;
  for (const std::uint32_t v : nodes_scratch_) push_back(s, v);
  range_lo_[s] = lo;
  range_hi_[s] = hi;
}

void KineticSegmentTree::clear_ring(std::uint32_t s) {
  for (std::uint32_t k = 0; k < ring_size_[s]; ++k) {
    const Fragment f = frag(s, k);
    detach(f.node, f.pos);
  }
  free_rings_[ring_class_[s]].push_back(ring_base_[s]);
  ring_base_[s] = kNoIndex;
  ring_size_[s] = 0;
}

void KineticSegmentTree::decompose(std::vector<std::uint32_t>& out, std::uint32_t v,
                                   std::uint32_t lo, std::uint32_t hi, std::uint32_t a,
                                   std::uint32_t b) {
  // Left to right: the fragments come out in the order of L(s).
  if (b < lo || hi < a) return;
  if (a <= lo && hi <= b) {
    out.push_back(v);
    return;
  }
  const std::uint32_t mid = lo + (hi - lo) / 2;
  decompose(out, 2 * v, lo, mid, a, b);
  decompose(out, 2 * v + 1, mid + 1, hi, a, b);
}

// --- L(s): a ring per segment, sized by its contents. -------------------------------------------
// The rings live in one array, in blocks of 2^c fragments (c >= kMinRingClass) with a free list per
// size. A ring doubles when full and halves when a quarter full (O(1) amortized: between two
// resizes of a ring, at least a quarter of the fragments a resize copies were pushed or popped); a
// resize moves the fragments to slots 0.. of the new block and fixes their back-pointers in the
// canonical sets. Otherwise a fragment's slot never moves.

std::uint32_t KineticSegmentTree::ring_capacity(std::uint32_t s) const {
  return std::uint32_t{1} << ring_class_[s];
}

std::uint32_t KineticSegmentTree::slot_of(std::uint32_t s, std::uint32_t k) const {
  return (ring_head_[s] + k) & (ring_capacity(s) - 1);
}

KineticSegmentTree::Fragment& KineticSegmentTree::frag(std::uint32_t s, std::uint32_t k) {
  return ring_[static_cast<std::size_t>(ring_base_[s]) + slot_of(s, k)];
}

const KineticSegmentTree::Fragment& KineticSegmentTree::frag(std::uint32_t s,
                                                             std::uint32_t k) const {
  return ring_[static_cast<std::size_t>(ring_base_[s]) + slot_of(s, k)];
}

std::uint32_t KineticSegmentTree::allocate_ring(std::uint8_t size_class) {
  std::vector<std::uint32_t>& free = free_rings_[size_class];
  if (!free.empty()) {
    const std::uint32_t base = free.back();
    free.pop_back();
    return base;
  }
  const auto base = static_cast<std::uint32_t>(ring_.size());
  ring_.resize(ring_.size() + (std::size_t{1} << size_class), Fragment{kNoIndex, kNoIndex});
  return base;
}

void KineticSegmentTree::resize_ring(std::uint32_t s, std::uint8_t size_class) {
  const std::uint32_t base = allocate_ring(size_class);
  for (std::uint32_t k = 0; k < ring_size_[s]; ++k) {
    const Fragment f = frag(s, k);
    ring_[static_cast<std::size_t>(base) + k] = f;
    sets_[f.node][f.pos].slot = k;
  }
  free_rings_[ring_class_[s]].push_back(ring_base_[s]);
  ring_base_[s] = base;
  ring_class_[s] = size_class;
  ring_head_[s] = 0;
  ++counters_.ring_resizes;
}

void KineticSegmentTree::attach(std::uint32_t s, std::uint32_t slot, std::uint32_t node) {
  std::vector<Entry>& set = sets_[node];
  ring_[static_cast<std::size_t>(ring_base_[s]) + slot] =
      Fragment{node, static_cast<std::uint32_t>(set.size())};
  set.push_back(Entry{s, slot});
}

void KineticSegmentTree::detach(std::uint32_t node, std::uint32_t pos) {
  // O(1) delete from S(node): move its last entry into the hole and fix that entry's fragment.
  std::vector<Entry>& set = sets_[node];
  const Entry last = set.back();
  set[pos] = last;
  ring_[static_cast<std::size_t>(ring_base_[last.segment]) + last.slot].pos = pos;
  set.pop_back();
}

void KineticSegmentTree::push_back(std::uint32_t s, std::uint32_t node) {
  if (ring_size_[s] == ring_capacity(s))
    resize_ring(s, static_cast<std::uint8_t>(ring_class_[s] + 1));
  const std::uint32_t slot = slot_of(s, ring_size_[s]);
  ++ring_size_[s];
  attach(s, slot, node);
}

void KineticSegmentTree::push_front(std::uint32_t s, std::uint32_t node) {
  if (ring_size_[s] == ring_capacity(s))
    resize_ring(s, static_cast<std::uint8_t>(ring_class_[s] + 1));
  ring_head_[s] = (ring_head_[s] + ring_capacity(s) - 1) & (ring_capacity(s) - 1);
  ++ring_size_[s];
  attach(s, ring_head_[s], node);
}

void KineticSegmentTree::shrink_ring_if_sparse(std::uint32_t s) {
  if (ring_class_[s] > kMinRingClass && 4 * ring_size_[s] <= ring_capacity(s))
    resize_ring(s, static_cast<std::uint8_t>(ring_class_[s] - 1));
}

void KineticSegmentTree::pop_back(std::uint32_t s) {
  assert(ring_size_[s] > 0);
  const Fragment f = frag(s, ring_size_[s] - 1);
  detach(f.node, f.pos);
  --ring_size_[s];
  shrink_ring_if_sparse(s);
}

void KineticSegmentTree::pop_front(std::uint32_t s) {
  assert(ring_size_[s] > 0);
  const Fragment f = frag(s, 0);
  detach(f.node, f.pos);
  ring_head_[s] = (ring_head_[s] + 1) & (ring_capacity(s) - 1);
  --ring_size_[s];
  shrink_ring_if_sparse(s);
}

// --- The four walks. ------------------------------------------------------------------------

void KineticSegmentTree::note_walk(std::uint64_t h) {
  ++counters_.walks;
  counters_.walk_height_total += h;
  counters_.walk_height_max = std::max(counters_.walk_height_max, h);
}

void KineticSegmentTree::extend_right(std::uint32_t s, std::uint32_t j) {
  // s covers ..j-1 and gains leaf j. Climb while v is a right child whose (left) brother holds
  // s; that brother ends at the right end of s, so it is the last fragment of L(s).
  std::uint32_t v = m_ + j;
  std::uint64_t h = 0;
  while (v > 1 && (v & 1U) != 0 && ring_size_[s] > 0 && frag(s, ring_size_[s] - 1).node == v - 1) {
    pop_back(s);
    v >>= 1;
    ++h;
  }
  push_back(s, v);
  note_walk(h);
}

void KineticSegmentTree::extend_left(std::uint32_t s, std::uint32_t j) {
  std::uint32_t v = m_ + j;
  std::uint64_t h = 0;
  while (v > 1 && (v & 1U) == 0 && ring_size_[s] > 0 && frag(s, 0).node == v + 1) {
    pop_front(s);
    v >>= 1;
    ++h;
  }
  push_front(s, v);
  note_walk(h);
}

void KineticSegmentTree::shrink_right(std::uint32_t s, std::uint32_t j) {
  // s covers ..j and loses leaf j: the last fragment w ends at leaf j. Replace w by the left
  // children hanging off the path from w down to leaf j (the walk of extend_right reversed).
  const std::uint32_t target = m_ + j;
  std::uint32_t v = frag(s, ring_size_[s] - 1).node;
  pop_back(s);
  std::uint64_t h = 0;
  while (v != target) {
    push_back(s, 2 * v);
    v = 2 * v + 1;
    ++h;
  }
  note_walk(h);
}

void KineticSegmentTree::shrink_left(std::uint32_t s, std::uint32_t j) {
  const std::uint32_t target = m_ + j;
  std::uint32_t v = frag(s, 0).node;
  pop_front(s);
  std::uint64_t h = 0;
  while (v != target) {
    push_front(s, 2 * v + 1);
    v = 2 * v;
    ++h;
  }
  note_walk(h);
}

void KineticSegmentTree::refit(std::uint32_t s) {
  const std::uint32_t lo = leaf_lo(s), hi = leaf_hi(s);
  std::uint32_t a = range_lo_[s], b = range_hi_[s];
  if (lo == a && hi == b) return;
  const auto distance = [](std::uint32_t x, std::uint32_t y) { return x > y ? x - y : y - x; };
  // (Never for a swap: it moves an end by at most a segment of R, whatever the tree's height.)
  const auto walk_limit =
      std::max(static_cast<std::uint32_t>(2 * levels_ + 2), 2 * KineticSort::kGapSegment);
  if (distance(lo, a) + distance(hi, b) > walk_limit) {
    // Moved farther than the tree is high: L(s) decomposed again is cheaper than the walks.
    clear_ring(s);
    decompose_into_ring(s);
    ++counters_.redecompositions;
    return;
  }
  // One leaf at a time (a swap moves an end by next(j) - j leaves): first the extensions, so that
  // the range never empties, then the shrinks.
  while (b < hi) extend_right(s, ++b);
  while (a > lo) extend_left(s, --a);
  while (b > hi) shrink_right(s, b--);
  while (a < lo) shrink_left(s, a++);
  range_lo_[s] = lo;
  range_hi_[s] = hi;
}

void KineticSegmentTree::follow_sort(std::uint64_t generation_before, std::uint32_t own) {
  if (sort_.layout_generation() != generation_before) {
    rebuild();  // R was laid out again: every slot may have changed
    return;
  }
  // Each interval with an endpoint that moved, once (in the order the sort told them).
  ++touch_round_;
  touched_.clear();
  for (const std::uint32_t e : sort_.relabeled()) {
    const std::uint32_t s = owner_of_[e] / 2;
    if (s == own || ring_base_[s] == kNoIndex || touched_mark_[s] == touch_round_) continue;
    touched_mark_[s] = touch_round_;
    touched_.push_back(s);
  }
  for (const std::uint32_t s : touched_) {
    refit(s);
    ++counters_.refits;
  }
}

EventKind KineticSegmentTree::process(const Event& event) {
  // The endpoint at R[j] whose certificate failed moves past the one at R[j + 1].
  const KineticSort::Swap swap = sort_.pending_swap(event);
  const std::uint32_t sx = owner_of_[swap.up] / 2;
  const std::uint32_t sy = owner_of_[swap.down] / 2;
  const EventKind kind = sort_.process(event);
  ++counters_.swaps;
  if (sim_.logging_events()) {  // the endpoints' intervals (the same twice: its own two ends)
    const std::array<ObjectId, 2> ids{intervals_.id(sx), intervals_.id(sy)};
    sim_.log_event("endpoint_swap", ids);
  }
  if (sx == sy) {
    ++counters_.own_endpoint_meetings;  // [min, max - 1] is unchanged
    return kind;
  }
  refit(sx);
  refit(sy);
  return kind;
}

void KineticSegmentTree::insert(std::uint32_t index) {
  sync_.require_inserted("KineticSegmentTree::insert", index);
  grow();
  add_endpoints(index);
  for (std::uint32_t side = 0; side < 2; ++side) {
    const std::uint64_t generation = sort_.layout_generation();
    sort_.insert(endpoint_of_[2 * index + side]);
    follow_sort(generation, index);
  }
  segment_at_[index] = static_cast<std::uint32_t>(segments_.size());
  segments_.push_back(index);
  decompose_into_ring(index);
}

void KineticSegmentTree::remove(std::uint32_t index) {
  sync_.require_removed("KineticSegmentTree::remove", index);
  clear_ring(index);
  const std::uint32_t at = segment_at_[index];
  segments_[at] = segments_.back();
  segment_at_[segments_[at]] = at;
  segments_.pop_back();
  segment_at_[index] = kNoIndex;
  for (std::uint32_t side = 0; side < 2; ++side) {
    const std::uint32_t e = endpoint_of_[2 * index + side];
    endpoints_.remove(endpoints_.handle(e));
    const std::uint64_t generation = sort_.layout_generation();
    sort_.remove(e);
    follow_sort(generation, index);
    owner_of_[e] = kNoIndex;
    endpoint_of_[2 * index + side] = kNoIndex;
  }
}

void KineticSegmentTree::motion_changed(std::uint32_t index) {
  sync_.require_updated("KineticSegmentTree::motion_changed", index);
  for (std::uint32_t side = 0; side < 2; ++side) {
    const std::uint32_t e = endpoint_of_[2 * index + side];
    const std::array<MotionPolynomial, 1> c{intervals_.motion(index, static_cast<int>(side))};
    endpoints_.update(endpoints_.handle(e), c, intervals_.valid_from(index));
    const std::uint64_t generation = sort_.layout_generation();
    sort_.motion_changed(e);
    follow_sort(generation, index);
  }
  refit(index);
}

// --- Queries. -------------------------------------------------------------------------------

std::vector<std::uint32_t> KineticSegmentTree::stab(double x, Time t) {
  sync_.require_current("KineticSegmentTree::stab");
  require_query_time("KineticSegmentTree::stab", t, sim_.now());
  if (std::isnan(x)) precondition_failed("KineticSegmentTree::stab", "x is NaN");
  ++counters_.queries;
  std::vector<std::uint32_t> out;
  if (sort_.size() == 0) return out;
  const std::size_t slots = sort_.slots();
  const MotionPolynomial q = MotionPolynomial::constant(x);
  PredicateStats* stats = &sim_.counters().predicates;
  // R as a function of the slot: an empty slot takes the value of the next key (+infinity after
  // the last), so it is non-decreasing and the searches below are over slots.
  const auto value_vs_x = [&](std::size_t r) {
    const std::size_t k = sort_.slot_at_or_after(r);
    if (k == KineticSort::kNoSlot) return 1;
    return compare_at(endpoints_.motion(sort_.order()[k], 0), q, t, stats);
  };
  // lo: first slot with R[r] >= x; end: first slot with R[r] > x.
  std::size_t lo = 0, hi = slots;
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (value_vs_x(mid) < 0)
      lo = mid + 1;
    else
      hi = mid;
  }
  std::size_t end = lo;
  {
    std::size_t a = lo, b = slots;
    while (a < b) {
      const std::size_t mid = a + (b - a) / 2;
      if (value_vs_x(mid) <= 0)
        a = mid + 1;
      else
        b = mid;
    }
    end = a;
  }
  const auto report_path = [&](std::size_t leaf) {
    for (std::uint32_t v = m_ + static_cast<std::uint32_t>(leaf); v >= 1; v >>= 1) {
      ++counters_.node_visits;
      for (const Entry& e : sets_[v]) out.push_back(e.segment);
    }
  };
  // An interval containing x either has an end equal to x, i.e. in the tie block R[lo..end-1]
  // (every end there belongs to an answer, so scanning it costs O(k) plus the empty slots, a
  // constant fraction), or has a < lo and b >= end, so it covers leaf lo-1 = [R[lo-1], R[lo]]
  // (slot lo - 1 holds a key: an empty one would have the value of slot lo's, >= x): the path
  // from that leaf to the root.
  if (lo >= 1 && sort_.slot_at_or_after(lo) != KineticSort::kNoSlot) report_path(lo - 1);
  for (std::size_t r = lo; r < end; ++r) {
    if (sort_.order()[r] != kNoIndex) out.push_back(owner_of_[sort_.order()[r]] / 2);
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

// --- Invariants. ----------------------------------------------------------------------------

std::uint32_t KineticSegmentTree::node_first_leaf(std::uint32_t v) const {
  while (v < m_) v = 2 * v;
  return v - m_;
}

std::uint32_t KineticSegmentTree::node_last_leaf(std::uint32_t v) const {
  while (v < m_) v = 2 * v + 1;
  return v - m_;
}

std::vector<KineticSegmentTree::NodeSet> KineticSegmentTree::canonical_sets(int levels) const {
  // Slots to ranks: keys_before[j] = the keys in slots < j, so a node over slots [a, b] spans the
  // keys of ranks keys_before[a] .. keys_before[b + 1] - 1 (empty slots are of length zero).
  std::vector<std::uint32_t> keys_before(static_cast<std::size_t>(m_) + 1, 0);
  for (std::size_t j = 0; j < m_; ++j) {
    const bool key = j < sort_.slots() && sort_.order()[j] != kNoIndex;
    keys_before[j + 1] = keys_before[j] + (key ? 1 : 0);
  }
  std::vector<NodeSet> out;
  const std::uint64_t end = std::min<std::uint64_t>(
      sets_.size(), levels >= 32 ? sets_.size() : std::uint64_t{1} << levels);
  int depth = 0;
  for (std::uint64_t v = 1; v < end; ++v) {
    if (v >= (std::uint64_t{2} << depth)) ++depth;
    if (sets_[v].empty()) continue;
    const std::uint32_t first = keys_before[node_first_leaf(static_cast<std::uint32_t>(v))];
    const std::uint32_t after = keys_before[node_last_leaf(static_cast<std::uint32_t>(v)) + 1];
    if (after == first) continue;  // only empty slots: no length to draw
    NodeSet n;
    n.depth = depth;
    n.first_leaf = first;
    n.last_leaf = after - 1;
    for (const Entry& e : sets_[v]) n.intervals.push_back(e.segment);
    out.push_back(std::move(n));
  }
  return out;
}

std::size_t KineticSegmentTree::fragments() const {
  std::size_t total = 0;
  for (const std::uint32_t s : segments_) total += ring_size_[s];
  return total;
}

std::size_t KineticSegmentTree::fragments_max() const {
  std::size_t best = 0;
  for (const std::uint32_t s : segments_) best = std::max<std::size_t>(best, ring_size_[s]);
  return best;
}

std::vector<std::vector<std::uint32_t>> KineticSegmentTree::fresh_sets() const {
  // A fresh build from the ranks, by the definition: s in S(v) iff int(v) is within s and
  // int(parent(v)) is not (the top-down decomposition yields exactly these nodes).
  std::vector<std::vector<std::uint32_t>> sets(2 * static_cast<std::size_t>(m_));
  const auto sift = [&](const auto& self, std::uint32_t s, std::uint32_t v, std::uint32_t lo,
                        std::uint32_t hi, std::uint32_t a, std::uint32_t b) -> void {
    if (b < lo || hi < a) return;
    if (a <= lo && hi <= b) {
      sets[v].push_back(s);
      return;
    }
    const std::uint32_t mid = lo + (hi - lo) / 2;
    self(self, s, 2 * v, lo, mid, a, b);
    self(self, s, 2 * v + 1, mid + 1, hi, a, b);
  };
  for (const std::uint32_t s : segments_) sift(sift, s, 1, 0, m_ - 1, leaf_lo(s), leaf_hi(s));
  for (auto& set : sets) std::sort(set.begin(), set.end());
  return sets;
}

bool KineticSegmentTree::validate() const {
  if (!sync_.current()) return false;
  if (!sort_.validate()) return false;
  if (sort_.size() != 2 * segments_.size()) return false;
  if (segments_.size() != intervals_.size()) return false;
  if (m_ != sort_.slots() || generation_ != sort_.layout_generation()) return false;
  for (std::size_t at = 0; at < segments_.size(); ++at) {
    const std::uint32_t s = segments_[at];
    if (!intervals_.alive_index(s) || segment_at_[s] != at) return false;
    if (range_lo_[s] != leaf_lo(s) || range_hi_[s] != leaf_hi(s)) return false;
    for (std::uint32_t side = 0; side < 2; ++side) {
      const std::uint32_t e = endpoint_of_[2 * s + side];
      if (e == kNoIndex || owner_of_[e] != 2 * s + side) return false;
    }
    // L(s): ordered left to right, adjacent fragments tile [lo, hi], back-pointers agree; its
    // ring is at most four times its size (or the smallest), at most 2 log2(m) + 2.
    if (ring_base_[s] == kNoIndex || ring_size_[s] > ring_capacity(s)) return false;
    if (ring_class_[s] > kMinRingClass && 4 * ring_size_[s] <= ring_capacity(s)) return false;
    if (ring_size_[s] > static_cast<std::uint32_t>(2 * levels_ + 2)) return false;
    std::uint32_t next = leaf_lo(s);
    for (std::uint32_t k = 0; k < ring_size_[s]; ++k) {
      const Fragment& f = frag(s, k);
      if (f.node == 0 || f.node >= 2 * m_) return false;
      if (node_first_leaf(f.node) != next) return false;
      next = node_last_leaf(f.node) + 1;
      const std::vector<Entry>& set = sets_[f.node];
      if (f.pos >= set.size() || set[f.pos].segment != s || set[f.pos].slot != slot_of(s, k))
        return false;
    }
    if (next != leaf_hi(s) + 1) return false;
  }
  // Every canonical set equals a fresh build's (as sets), and has no stale entries.
  const std::vector<std::vector<std::uint32_t>> fresh = fresh_sets();
  for (std::uint32_t v = 1; v < 2 * m_; ++v) {
    std::vector<std::uint32_t> mine;
    for (const Entry& e : sets_[v]) mine.push_back(e.segment);
    std::sort(mine.begin(), mine.end());
    if (mine != fresh[v]) return false;
  }
  return true;
}

NamedCounters KineticSegmentTree::named_counters() const {
  const SegmentTreeCounters& c = counters_;
  return {{"swaps", c.swaps},
          {"walks", c.walks},
          {"walk_height_total", c.walk_height_total},
          {"walk_height_max", c.walk_height_max},
          {"own_endpoint_meetings", c.own_endpoint_meetings},
          {"rebuilds", c.rebuilds},
          {"refits", c.refits},
          {"redecompositions", c.redecompositions},
          {"ring_resizes", c.ring_resizes},
          {"fragments", fragments()},
          {"fragments_per_segment_max", fragments_max()},
          {"queries", c.queries},
          {"node_visits", c.node_visits}};
}

namespace {

/// The loop guard's bounds: the events are those of one kinetic sort of the 2n endpoints (an
/// insert or update changes two).
LoopGuard segment_tree_event_bounds(const RunBounds& b) {
  return crossing_guard(1, 2 * b.max_objects, 2 * b.motion_changes, b.max_degree);
}

}  // namespace

StructureDescription KineticSegmentTree::description() {
  return StructureDescription{
      "segment-tree",
      "SegmentTree",
      ObjectsAre::Intervals,
      {QueryType::Stab},
      {"endpoint_swap"},
      "The kinetic segment tree over moving intervals (stab(x), stab_many(xs)); motions (n,"
      " 2, k): the left end, then the right end.",
      "kinetic segment tree over moving intervals: stabbing queries (ids of the intervals "
      "containing x)"}
      .bound_events(segment_tree_event_bounds);
}

}  // namespace kinetic
