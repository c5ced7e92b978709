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
      sort_(endpoints_, simulator, scheduler, 0) {
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
  for (const std::uint32_t s : segments_) add_endpoints(s);
  sort_.initialize();
  rebuild();
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
  const std::size_t n = segments_.size();
  const std::size_t leaves = n == 0 ? 1 : 2 * n - 1;
  m_ = 1;
  levels_ = 0;
  while (m_ < leaves) {
    m_ *= 2;
    ++levels_;
  }
  sets_.assign(2 * static_cast<std::size_t>(m_), {});
  const std::size_t cap = intervals_.capacity();
  ring_head_.assign(cap, 0);
  ring_size_.assign(cap, 0);
  ring_base_.assign(cap, kNoIndex);
  ring_class_.assign(cap, 0);
  ring_.clear();
  for (auto& f : free_rings_) f.clear();
  std::vector<std::uint32_t> nodes;
  for (const std::uint32_t s : segments_) {
    nodes.clear();
    decompose(nodes, 1, 0, m_ - 1, leaf_lo(s), leaf_hi(s));
    std::uint8_t size_class = kMinRingClass;  // the smallest ring that holds L(s)
    while ((std::size_t{1} << size_class) < nodes.size()) ++size_class;
    ring_class_[s] = size_class;
    ring_base_[s] = allocate_ring(size_class);
    for (const std::uint32_t v : nodes) push_back(s, v);
  }
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

void KineticSegmentTree::change_range(std::uint32_t s, std::uint32_t old_lo, std::uint32_t old_hi) {
  const std::uint32_t lo = leaf_lo(s);
  const std::uint32_t hi = leaf_hi(s);
  // One swap moves each end by at most one leaf.
  if (hi == old_hi + 1) extend_right(s, hi);
  if (hi + 1 == old_hi) shrink_right(s, old_hi);
  if (lo + 1 == old_lo) extend_left(s, lo);
  if (lo == old_lo + 1) shrink_left(s, old_lo);
  assert(hi + 1 >= old_hi && hi <= old_hi + 1 && lo + 1 >= old_lo && lo <= old_lo + 1);
}

EventKind KineticSegmentTree::process(const Event& event) {
  // The endpoint at R[j] whose certificate failed moves past the one at R[j + 1].
  const KineticSort::Swap swap = sort_.pending_swap(event);
  const std::uint32_t sx = owner_of_[swap.up] / 2;
  const std::uint32_t sy = owner_of_[swap.down] / 2;
  const std::uint32_t lo_x = leaf_lo(sx), hi_x = leaf_hi(sx);
  const std::uint32_t lo_y = leaf_lo(sy), hi_y = leaf_hi(sy);
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
  change_range(sx, lo_x, hi_x);
  change_range(sy, lo_y, hi_y);
  return kind;
}

void KineticSegmentTree::insert(std::uint32_t index) {
  sync_.require_inserted("KineticSegmentTree::insert", index);
  add_endpoints(index);
  sort_.insert(endpoint_of_[2 * index]);
  sort_.insert(endpoint_of_[2 * index + 1]);
  segments_.push_back(index);
  rebuild();
}

void KineticSegmentTree::remove(std::uint32_t index) {
  sync_.require_removed("KineticSegmentTree::remove", index);
  for (std::uint32_t side = 0; side < 2; ++side) {
    const std::uint32_t e = endpoint_of_[2 * index + side];
    endpoints_.remove(endpoints_.handle(e));
    sort_.remove(e);
    owner_of_[e] = kNoIndex;
    endpoint_of_[2 * index + side] = kNoIndex;
  }
  segments_.erase(std::find(segments_.begin(), segments_.end(), index));
  rebuild();
}

void KineticSegmentTree::motion_changed(std::uint32_t index) {
  sync_.require_updated("KineticSegmentTree::motion_changed", index);
  for (std::uint32_t side = 0; side < 2; ++side) {
    const std::uint32_t e = endpoint_of_[2 * index + side];
    const std::array<MotionPolynomial, 1> c{intervals_.motion(index, static_cast<int>(side))};
    endpoints_.update(endpoints_.handle(e), c, intervals_.valid_from(index));
    sort_.motion_changed(e);
  }
  rebuild();
}

// --- Queries. -------------------------------------------------------------------------------

std::vector<std::uint32_t> KineticSegmentTree::stab(double x, Time t) {
  sync_.require_current("KineticSegmentTree::stab");
  require_query_time("KineticSegmentTree::stab", t, sim_.now());
  if (std::isnan(x)) precondition_failed("KineticSegmentTree::stab", "x is NaN");
  ++counters_.queries;
  std::vector<std::uint32_t> out;
  const std::size_t size = sort_.order().size();
  if (size == 0) return out;
  const MotionPolynomial q = MotionPolynomial::constant(x);
  PredicateStats* stats = &sim_.counters().predicates;
  const auto value_vs_x = [&](std::size_t r) {
    return compare_at(endpoints_.motion(sort_.order()[r], 0), q, t, stats);
  };
  // lo: first rank with R[r] >= x; hi + 1: first rank with R[r] > x.
  std::size_t lo = 0, hi = size;
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (value_vs_x(mid) < 0)
      lo = mid + 1;
    else
      hi = mid;
  }
  std::size_t end = lo;
  {
    std::size_t a = lo, b = size;
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
  // (every end there belongs to an answer, so scanning it costs O(k)), or has a < lo and
  // b >= end, so it covers leaf lo-1 = [R[lo-1], R[lo]]: the path from that leaf to the root.
  if (lo >= 1 && lo < size) report_path(lo - 1);  // leaves are 0..size-2
  for (std::size_t r = lo; r < end; ++r) out.push_back(owner_of_[sort_.order()[r]] / 2);
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
  std::vector<NodeSet> out;
  const std::uint64_t end = std::min<std::uint64_t>(
      sets_.size(), levels >= 32 ? sets_.size() : std::uint64_t{1} << levels);
  int depth = 0;
  for (std::uint64_t v = 1; v < end; ++v) {
    if (v >= (std::uint64_t{2} << depth)) ++depth;
    if (sets_[v].empty()) continue;
    NodeSet n;
    n.depth = depth;
    n.first_leaf = node_first_leaf(static_cast<std::uint32_t>(v));
    n.last_leaf = node_last_leaf(static_cast<std::uint32_t>(v));
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
  if (sort_.order().size() != 2 * segments_.size()) return false;
  if (segments_.size() != intervals_.size()) return false;
  const std::size_t leaves = segments_.empty() ? 1 : 2 * segments_.size() - 1;
  if (m_ < leaves || (m_ > 1 && m_ / 2 >= leaves)) return false;
  for (const std::uint32_t s : segments_) {
    if (!intervals_.alive_index(s)) return false;
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
          {"ring_resizes", c.ring_resizes},
          {"fragments", fragments()},
          {"fragments_per_segment_max", fragments_max()},
          {"queries", c.queries},
          {"node_visits", c.node_visits}};
}

}  // namespace kinetic
