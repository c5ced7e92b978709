#include "kinetic/longest_side_kdtree/longest_side_kdtree.hpp"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/compressed_trie.hpp"
#include "core/numeric/linear_filter.hpp"
#include "kinetic/core/free_list.hpp"
#include "kinetic/core/predicates.hpp"
#include "kinetic/core/prefetch.hpp"

namespace kinetic {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// Relative slack that covers the roundings of a distance computed from bounded coordinates (a
/// handful of operations, each within 2^-53): see docs/longest-side-kdtree.md.
constexpr double kRho = 0x1p-40;

std::uint32_t level(std::uint32_t h) { return static_cast<std::uint32_t>(std::bit_width(h)) - 1; }

/// h2 is h1 or a descendant of h1 in a heap-numbered tree.
bool descends(std::uint32_t h2, std::uint32_t h1) {
  const std::uint32_t l2 = level(h2), l1 = level(h1);
  return l2 >= l1 && (h2 >> (l2 - l1)) == h1;
}

/// A double below (above) x: x widened by one unit in the last place and 2^-1070 (the interval
/// bound of core/numeric/interval.hpp, without a library call), or the next double where that
/// is not finite.
inline double down(double x) {
  const double y = (x - std::fabs(x) * 0x1p-52) - 0x1p-1070;
  return std::isfinite(y) ? y : std::nextafter(x, -kInf);
}
inline double up(double x) {
  const double y = (x + std::fabs(x) * 0x1p-52) + 0x1p-1070;
  return std::isfinite(y) ? y : std::nextafter(x, kInf);
}

/// sqrt(dx^2 + dy^2) within 2 ulps (what the searches' factors 1 -+ 2^-40 absorb), without
/// std::hypot's cost; std::hypot where the squares could overflow or underflow.
inline double distance2d(double dx, double dy) {
  const double s = dx * dx + dy * dy;
  if (s < 0x1p1000 && s > 0x1p-1000) return std::sqrt(s);
  return dx == 0.0 && dy == 0.0 ? 0.0 : std::hypot(dx, dy);  // q in a region's box: key 0
}

/// Signed distance from x to the shape (negative inside), in floating point.
double signed_distance(const Shape& shape, std::array<double, 2> x) {
  if (shape.kind == Shape::Kind::Disk) {
    return std::hypot(x[0] - shape.disk.center[0], x[1] - shape.disk.center[1]) - shape.disk.radius;
  }
  const auto& poly = shape.polygon;
  double best = kInf;
  bool inside = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const auto& a = poly[j];
    const auto& b = poly[i];
    // Even-odd crossing test on the horizontal ray to the right of x.
    if ((a[1] > x[1]) != (b[1] > x[1])) {
      const double cross = a[0] + (x[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
      if (x[0] < cross) inside = !inside;
    }
    const double ex = b[0] - a[0], ey = b[1] - a[1];
    const double len2 = ex * ex + ey * ey;
    double u = len2 > 0.0 ? ((x[0] - a[0]) * ex + (x[1] - a[1]) * ey) / len2 : 0.0;
    u = std::clamp(u, 0.0, 1.0);
    best = std::min(best, std::hypot(x[0] - (a[0] + u * ex), x[1] - (a[1] + u * ey)));
  }
  return inside ? -best : best;
}

double diameter(const Shape& shape) {
  if (shape.kind == Shape::Kind::Disk) return 2.0 * shape.disk.radius;
  double d = 0.0;
  for (const auto& a : shape.polygon) {
    for (const auto& b : shape.polygon) d = std::max(d, std::hypot(a[0] - b[0], a[1] - b[1]));
  }
  return d;
}

double magnitude(const Shape& shape) {
  if (shape.kind == Shape::Kind::Disk) {
    return std::max(std::abs(shape.disk.center[0]), std::abs(shape.disk.center[1])) +
           shape.disk.radius;
  }
  double m = 0.0;
  for (const auto& a : shape.polygon) m = std::max({m, std::abs(a[0]), std::abs(a[1])});
  return m;
}

}  // namespace

/// A node of S: its range on each axis, as heap indices in T_0, T_1.
struct LongestSideKdTree::State {
  std::array<std::uint32_t, 2> h{1, 1};
  friend bool operator==(const State&, const State&) = default;
};

/// A live region: a node of S with two points or more, its stored split axis and its certificate
/// [side `1 - axis` < side `axis`]; linked into the lists of its two side elements.
struct LongestSideKdTree::Region {
  State s;
  EventHandle certificate;
  std::array<std::uint32_t, 2> next{kNoIndex, kNoIndex};  // per axis: the element's list
  std::array<std::uint32_t, 2> prev{kNoIndex, kNoIndex};
  std::uint8_t axis = 0;
};

namespace {
/// The child of range `from` towards its descendant range `to` (0 left, 1 right).
int side_towards(std::uint32_t from, std::uint32_t to) {
  return static_cast<int>((to >> (level(to) - level(from) - 1)) & 1U);
}
}  // namespace

std::array<std::uint32_t, 2> LongestSideKdTree::sides(const Region& g) const {
  const int a = g.axis;
  return {element(1 - a, g.s.h[static_cast<std::size_t>(1 - a)]),
          element(a, g.s.h[static_cast<std::size_t>(a)])};
}

inline std::uint32_t LongestSideKdTree::find_region(const State& s) const {
  const std::size_t k = region_keys_.position(s.h[0], table_size_ + s.h[1]);
  return k == PairSet::npos ? kNoIndex : region_of_[k];
}

inline int LongestSideKdTree::fresh_axis(const State& s) const {
  return side_before_after_now(element(0, s.h[0]), element(1, s.h[1])) ? 1 : 0;
}

inline int LongestSideKdTree::split_axis(const State& s) const {
  const std::uint32_t r = find_region(s);
  return r != kNoIndex ? regions_[r].axis : fresh_axis(s);
}
inline int LongestSideKdTree::side_of(std::uint32_t point, const State& s, int axis) const {
  return rank_of(point, axis) >= median(axis, s.h[static_cast<std::size_t>(axis)]) ? 1 : 0;
}
inline LongestSideKdTree::State LongestSideKdTree::child_state(State s, int axis, int side) {
  s.h[static_cast<std::size_t>(axis)] =
      2 * s.h[static_cast<std::size_t>(axis)] + static_cast<std::uint32_t>(side);
  return s;
}

struct LongestSideKdTree::Node {
  std::uint32_t parent = kNoIndex;
  std::array<std::uint32_t, 2> child{kNoIndex, kNoIndex};
  std::uint32_t point = kNoIndex;  // leaves
  std::uint32_t rep = kNoIndex;    // the subtree's leftmost leaf's point
  std::uint32_t depth = 0;         // in skeleton levels
  State state;                     // the S-ranges at this node (before its split)
  std::uint8_t axis = 0;           // active nodes: the split axis
  std::uint8_t chain = 0;          // kept degree-one nodes on the edge above
  std::uint32_t leaves = 1;        // the subtree's leaves
};
struct LongestSideKdTree::Trie {
  HugeVector<Node> nodes;
  std::vector<std::uint32_t> free;
  std::uint32_t root = kNoIndex;
};

template <class F>
void LongestSideKdTree::for_each_leaf(const Trie& t, std::uint32_t node, F&& f) const {
  const Node& v = t.nodes[node];
  if (v.point != kNoIndex) {
    f(node);
    return;
  }
  for_each_leaf(t, v.child[0], f);
  for_each_leaf(t, v.child[1], f);
}

LongestSideKdTree::LongestSideKdTree(const MotionTable& motions, Simulator& simulator,
                                     const Scheduler& scheduler)
    : motions_(motions), sim_(simulator), scheduler_(scheduler), trie_(std::make_unique<Trie>()) {
  require_dimension("LongestSideKdTree", motions.dimension(), 2, 2, "points in the plane");
  for (int axis = 0; axis < 2; ++axis) {
    sorts_
        .add(std::make_unique<KineticSort>(motions, simulator, scheduler, axis, SortLayout::Gapped))
        .set_log_swaps(true);  // every rank swap is an external event (kind "swap")
  }
  region_owner_ = simulator.reserve_owners(1).first;  // after the sorts' two
}

LongestSideKdTree::~LongestSideKdTree() = default;

// ---------------------------------------------------------------------------------------------
// T_0, T_1 (the halving of the labels [0, U_i - 1]), the end points and the side lengths.

void LongestSideKdTree::rebuild_tables() {
  for (int axis = 0; axis < 2; ++axis) {
    const std::size_t slots = sorts_[static_cast<std::size_t>(axis)].slots();
    assert(std::has_single_bit(slots));
    log_space_[static_cast<std::size_t>(axis)] =
        static_cast<std::uint32_t>(std::countr_zero(slots));
  }
  table_size_ = std::max(space(0), space(1));
}

std::uint32_t LongestSideKdTree::end_point(int axis, std::size_t label) const {
  const KineticSort& s = sorts_[static_cast<std::size_t>(axis)];
  std::size_t j = s.slot_at_or_after(label);
  if (j == KineticSort::kNoSlot) j = s.prev_slot(s.slots());  // the last point
  return j == KineticSort::kNoSlot ? kNoIndex : s.order()[j];
}

void LongestSideKdTree::ends_in(int axis, std::size_t first, std::size_t last,
                                std::vector<std::uint32_t>& out) const {
  const std::uint32_t log = log_space_[static_cast<std::size_t>(axis)];
  const std::size_t u = space(axis);
  for (std::size_t label = first; label <= last; ++label) {
    // The ranges of 2^b labels (level log - b) with label as their start or just after their end.
    for (std::uint32_t b = 1; b <= log; ++b) {
      const std::size_t size = std::size_t{1} << b;
      if (label % size != 0) break;
      const std::uint32_t base = std::uint32_t{1} << (log - b);
      const auto k = static_cast<std::uint32_t>(label / size);
      if (label < u) out.push_back(element(axis, base + k));
      if (label >= size) out.push_back(element(axis, base + k - 1));
    }
  }
}

void LongestSideKdTree::ends_at_slot(int axis, std::size_t j,
                                     std::vector<std::uint32_t>& out) const {
  // end(L) is the point at slot j for L after the occupied slot before j, up to j; and, when
  // j is the last point, for every L after it.
  const KineticSort& s = sorts_[static_cast<std::size_t>(axis)];
  const std::size_t before = s.prev_slot(j);
  const std::size_t first = before == KineticSort::kNoSlot ? 0 : before + 1;
  const std::size_t last = s.next_slot(j) == KineticSort::kNoSlot ? s.slots() : j;
  ends_in(axis, first, last, out);
}

void LongestSideKdTree::set_length(std::uint32_t e) {
  const int axis = static_cast<int>(e / table_size_);
  const std::uint32_t h = e % table_size_;
  const std::uint32_t top = top_point(axis, h), low = lo_point(axis, h);
  if (top == kNoIndex || low == kNoIndex) {  // no points: a side of no region
    length_[e] = MotionPolynomial{};
    length_exact_[e] = 1;
    ends_[e] = {};
    return;
  }
  const MotionPolynomial& t = motions_.motion(top, axis);
  const MotionPolynomial& l = motions_.motion(low, axis);
  const MotionDifference d = motion_difference(t, l);
  length_[e] = d.p;
  length_exact_[e] = d.exact ? 1 : 0;
  ends_[e] = {t, l};
  if (!d.exact) ++counters_.combined_lengths;
}

MotionCombination LongestSideKdTree::length_difference(std::uint32_t a, std::uint32_t b) const {
  // L_b - L_a = top_b - lo_b - (top_a - lo_a) = (top_b + lo_a) - (lo_b + top_a).
  MotionCombination f;
  f.plus = {&ends_[b][0], &ends_[a][1]};
  f.minus = {&ends_[b][1], &ends_[a][0]};
  return f;
}

int LongestSideKdTree::compare_lengths_after(std::uint32_t a, std::uint32_t b, Time t,
                                             PredicateStats* stats) const {
  if (length_exact_[a] != 0 && length_exact_[b] != 0)
    return compare_after(length_[a], length_[b], t, stats);
  return -sign_after(length_difference(a, b), t, stats);
}

int LongestSideKdTree::compare_lengths_at(std::uint32_t a, std::uint32_t b, Time t) const {
  if (length_exact_[a] != 0 && length_exact_[b] != 0) return compare_at(length_[a], length_[b], t);
  return -sign_at(length_difference(a, b), t);
}

bool LongestSideKdTree::side_before_after_now(std::uint32_t a, std::uint32_t b) const {
  if (scheduler_.floating_point_decisions()) {
    // A traditional KDS compares the two lengths top - low computed in floating point at now.
    const Time t = sim_.now();
    const double la = ends_[a][0].evaluate(t) - ends_[a][1].evaluate(t);
    const double lb = ends_[b][0].evaluate(t) - ends_[b][1].evaluate(t);
    if (la != lb) return la < lb;
    return a < b;
  }
  const int s = compare_lengths_after(a, b, sim_.now(), &sim_.counters().predicates);
  if (s != 0) return s < 0;
  return a < b;  // identical lengths: a fixed, deterministic order
}

void LongestSideKdTree::schedule_region(std::uint32_t r) {
  Region& g = regions_[r];
  const auto [lower, upper] = sides(g);
  Time window_lo = -kTimeInfinity;
  for (int a = 0; a < 2; ++a) {
    const std::uint32_t h = g.s.h[static_cast<std::size_t>(a)];
    window_lo = std::max(
        {window_lo, motions_.valid_from(lo_point(a, h)), motions_.valid_from(top_point(a, h))});
  }
  // Both lengths exact single polynomials: the two-motion certificate; otherwise the exact
  // four-motion combination L_upper - L_lower (never a rounded length).
  ExactFailure exact;
  const Time t = length_exact_[lower] != 0 && length_exact_[upper] != 0
                     ? scheduler_.failure_time(length_[lower], length_[upper], sim_.now(),
                                               window_lo, sim_.counters(), &exact)
                     : scheduler_.failure_time(length_difference(lower, upper), sim_.now(),
                                               window_lo, sim_.counters(), &exact);
  sim_.reschedule(g.certificate, t, exact, region_owner_, r);  // (in place when it can)
}

void LongestSideKdTree::add_region(const State& s) {
  assert(find_region(s) == kNoIndex);
  const std::uint32_t r = take_record(regions_, free_regions_);
  Region& g = regions_[r];
  g = Region{};
  g.s = s;
  g.axis = static_cast<std::uint8_t>(fresh_axis(s));
  for (int a = 0; a < 2; ++a) {  // push front on the list of the side element on axis a
    const std::uint32_t e = element(a, s.h[static_cast<std::size_t>(a)]);
    const std::uint32_t head = region_head_[e];
    g.next[static_cast<std::size_t>(a)] = head;
    if (head != kNoIndex) regions_[head].prev[static_cast<std::size_t>(a)] = r;
    region_head_[e] = r;
  }
  region_keys_.insert(s.h[0], table_size_ + s.h[1]);
  region_of_.push_back(r);
  schedule_region(r);
}

void LongestSideKdTree::remove_region(const State& s) {
  const std::size_t k = region_keys_.position(s.h[0], table_size_ + s.h[1]);
  assert(k != PairSet::npos);
  const std::uint32_t r = region_of_[k];
  region_keys_.erase(s.h[0], table_size_ + s.h[1]);  // the last key moves to position k
  region_of_[k] = region_of_.back();
  region_of_.pop_back();
  Region& g = regions_[r];
  sim_.cancel(g.certificate);
  for (std::size_t a = 0; a < 2; ++a) {
    if (g.prev[a] != kNoIndex) {
      regions_[g.prev[a]].next[a] = g.next[a];
    } else {
      region_head_[element(static_cast<int>(a), s.h[a])] = g.next[a];
    }
    if (g.next[a] != kNoIndex) regions_[g.next[a]].prev[a] = g.prev[a];
  }
  free_regions_.push_back(r);
}

void LongestSideKdTree::clear_regions() {
  for (const std::uint32_t r : region_of_) sim_.cancel(regions_[r].certificate);
  regions_.clear();
  free_regions_.clear();
  region_keys_.clear();
  region_of_.clear();
}

void LongestSideKdTree::rebuild_lengths() {
  clear_regions();
  const std::size_t elements = 2 * static_cast<std::size_t>(table_size_);
  length_.assign(elements, MotionPolynomial{});
  length_exact_.assign(elements, 0);
  ends_.assign(elements, {});
  region_head_.assign(elements, kNoIndex);
  for (int axis = 0; axis < 2; ++axis) {
    for (std::uint32_t h = 1; h < space(axis); ++h) set_length(element(axis, h));
  }
}

template <class F>
void LongestSideKdTree::for_each_on_path(State from, const State& to, F&& f) const {
  for (;;) {
    if (from == to) {
      f(from);
      return;
    }
    const int axis = split_axis(from);  // before f, which may change what is stored
    const std::size_t a = static_cast<std::size_t>(axis);
    State next = from;
    next.h[a] = 2 * from.h[a] + static_cast<std::uint32_t>(side_towards(from.h[a], to.h[a]));
    f(from);
    from = next;
  }
}

template <class F>
void LongestSideKdTree::for_each_live(std::uint32_t node, State s, F&& f) const {
  const Trie& t = *trie_;
  std::vector<std::pair<std::uint32_t, State>> stack{{node, s}};
  while (!stack.empty()) {
    const auto [k, from] = stack.back();
    stack.pop_back();
    const Node& c = t.nodes[k];
    if (c.point != kNoIndex) continue;  // the edge above a leaf: one point
    for_each_on_path(from, c.state, f);
    for (int side = 1; side >= 0; --side) {
      stack.emplace_back(c.child[static_cast<std::size_t>(side)],
                         child_state(c.state, c.axis, side));
    }
  }
}

// ---------------------------------------------------------------------------------------------
// The trie of the keys.

std::uint32_t LongestSideKdTree::new_node(Trie& t) const {
  const std::uint32_t k = take_record(t.nodes, t.free);
  t.nodes[k] = Node{};
  return k;
}

void LongestSideKdTree::set_chain(Trie& t, std::uint32_t node) const {
  // The skeleton nodes strictly between the parent and `node` are degree-one nodes; the useful
  // ones define a side of region(node) (Abam, de Berg, Speckmann, Section 3): one per side of
  // region(node) that differs from the region of the parent's child on this path.
  Node& v = t.nodes[node];
  State ref;
  if (v.parent != kNoIndex) {
    const Node& u = t.nodes[v.parent];
    // The side node hangs on (read from its representative while the links are being built).
    const int side = u.child[1] == node   ? 1
                     : u.child[0] == node ? 0
                                          : side_of(v.rep, u.state, u.axis);
    ref = child_state(u.state, u.axis, side);
  }
  std::uint8_t count = 0;  // sides (first and last label of a range) that differ
  for (int a = 0; a < 2; ++a) {
    const std::uint32_t r = ref.h[static_cast<std::size_t>(a)];
    const std::uint32_t w = v.state.h[static_cast<std::size_t>(a)];
    if (lo(a, r) != lo(a, w)) ++count;
    if (lo(a, r) + range_size(a, r) != lo(a, w) + range_size(a, w)) ++count;
  }
  v.chain = count;
}

std::uint32_t LongestSideKdTree::build(Trie& t, std::vector<std::uint32_t>& points,
                                       std::size_t begin, std::size_t end, State s,
                                       std::uint32_t depth, std::uint32_t parent) const {
  const std::uint32_t k = new_node(t);
  t.nodes[k].parent = parent;
  t.nodes[k].rep = points[begin];
  if (end - begin == 1) {
    t.nodes[k].point = points[begin];
    t.nodes[k].state = s;
    t.nodes[k].depth = depth;
    set_chain(t, k);
    return k;
  }
  // Down the degree-one nodes of S to the first split that separates the points.
  int axis = 0;
  std::size_t right = 0;
  for (;;) {
    axis = split_axis(s);
    right = 0;
    for (std::size_t j = begin; j < end; ++j)
      right += static_cast<std::size_t>(side_of(points[j], s, axis));
    if (right != 0 && right != end - begin) break;
    s = child_state(s, axis, right != 0 ? 1 : 0);
    ++depth;
  }
  t.nodes[k].state = s;
  t.nodes[k].depth = depth;
  t.nodes[k].axis = static_cast<std::uint8_t>(axis);
  set_chain(t, k);
  const auto mid = std::stable_partition(points.begin() + static_cast<std::ptrdiff_t>(begin),
                                         points.begin() + static_cast<std::ptrdiff_t>(end),
                                         [&](std::uint32_t p) { return side_of(p, s, axis) == 0; });
  const std::size_t m = static_cast<std::size_t>(mid - points.begin());
  const std::uint32_t left = build(t, points, begin, m, child_state(s, axis, 0), depth + 1, k);
  const std::uint32_t rgt = build(t, points, m, end, child_state(s, axis, 1), depth + 1, k);
  t.nodes[k].child = {left, rgt};
  t.nodes[k].leaves = static_cast<std::uint32_t>(end - begin);
  t.nodes[k].rep = t.nodes[left].rep;  // the leftmost leaf's point (see Node::rep)
  return k;
}

void LongestSideKdTree::reps_up(Trie& t, std::uint32_t node) const {
  for (std::uint32_t p = t.nodes[node].parent;
       p != kNoIndex && t.nodes[p].child[0] == node && t.nodes[p].rep != t.nodes[node].rep;
       node = p, p = t.nodes[p].parent) {
    t.nodes[p].rep = t.nodes[node].rep;
  }
}

void LongestSideKdTree::build_all(Trie& t) const {
  t = Trie{};
  std::vector<std::uint32_t> points = motions_.alive_indices();
  if (!points.empty()) t.root = build(t, points, 0, points.size(), State{}, 0, kNoIndex);
}

void LongestSideKdTree::rebuild() {
  ++mutations_;
  n_ = motions_.size();
  rebuild_tables();
  rebuild_lengths();
  build_all(*trie_);
  leaf_of_.assign(motions_.capacity(), kNoIndex);
  for (std::uint32_t k = 0; k < trie_->nodes.size(); ++k) {
    if (trie_->nodes[k].point != kNoIndex) leaf_of_[trie_->nodes[k].point] = k;
  }
  leaf_motion_.assign(motions_.capacity(), LeafMotion{});
  for (const std::uint32_t p : motions_.alive_indices()) set_leaf_motion(p);
  if (trie_->root != kNoIndex) {
    for_each_live(trie_->root, State{}, [this](const State& v) { add_region(v); });
  }
}

void LongestSideKdTree::initialize() {
  sync_.note();
  sorts_.initialize();
  rebuild();
}

void LongestSideKdTree::erase(std::uint32_t point) {
  Trie& t = *trie_;
  const std::uint32_t leaf = leaf_of_[point];
  leaf_of_[point] = kNoIndex;
  const std::uint32_t u = t.nodes[leaf].parent;
  if (u != kNoIndex) {
    // The nodes of S on u's edge and u itself hold two points or more; when the other child of
    // u is a leaf they hold exactly these two, and stop being live regions.
    const Node& un = t.nodes[u];
    const std::uint32_t other = un.child[un.child[0] == leaf ? 1 : 0];
    if (t.nodes[other].point != kNoIndex) {
      State from;
      if (un.parent != kNoIndex) {
        const Node& gn = t.nodes[un.parent];
        from = child_state(gn.state, gn.axis, gn.child[1] == u ? 1 : 0);
      }
      for_each_on_path(from, un.state, [this](const State& v) { remove_region(v); });
    }
  }
  t.free.push_back(leaf);
  // u stops being active: its other child c takes its place under u's parent g.
  const trie::Contraction k = trie::contract(t.nodes, t.root, leaf);
  if (k.removed == kNoIndex) return;
  const std::uint32_t c = k.survivor, g = k.parent;
  t.free.push_back(u);
  if (t.nodes[c].point != kNoIndex) {  // a leaf sits right below its active parent
    if (g == kNoIndex) {
      t.nodes[c].state = State{};
      t.nodes[c].depth = 0;
    } else {
      const Node& gn = t.nodes[g];
      t.nodes[c].state = child_state(gn.state, gn.axis, gn.child[1] == c ? 1 : 0);
      t.nodes[c].depth = gn.depth + 1;
    }
  }
  set_chain(t, c);
  // Representatives (the leftmost leaf's point): the nodes that had `point` are the ancestors
  // whose leftmost leaf it was, a path up from u; c took u's place, so they take c's.
  for (std::uint32_t a = g; a != kNoIndex && t.nodes[a].rep == point; a = t.nodes[a].parent)
    t.nodes[a].rep = t.nodes[c].rep;
}

void LongestSideKdTree::insert_point(std::uint32_t point) {
  Trie& t = *trie_;
  const std::uint32_t leaf = new_node(t);
  t.nodes[leaf].point = point;
  t.nodes[leaf].rep = point;
  leaf_of_[point] = leaf;
  if (t.root == kNoIndex) {
    t.root = leaf;
    set_chain(t, leaf);
    return;
  }
  std::uint32_t cur = t.root;
  State s;  // the S node at `depth` on the path shared by `point` and cur's points
  std::uint32_t depth = 0;
  for (;;) {
    const bool is_leaf = t.nodes[cur].point != kNoIndex;
    const std::uint32_t limit = t.nodes[cur].depth;
    const std::uint32_t rep = t.nodes[cur].rep;
    int axis = 0;
    int side = 0;
    bool diverged = false;
    while (is_leaf || depth < limit) {
      axis = split_axis(s);
      side = side_of(point, s, axis);
      if (side != side_of(rep, s, axis)) {
        diverged = true;
        break;
      }
      s = child_state(s, axis, side);
      ++depth;
    }
    if (!diverged) {  // down to the active node cur: descend
      axis = t.nodes[cur].axis;
      side = side_of(point, s, axis);
      s = child_state(s, axis, side);
      ++depth;
      cur = t.nodes[cur].child[static_cast<std::size_t>(side)];
      continue;
    }
    // The key leaves cur's path at (s, depth): a new active node there, above cur. When cur is a
    // leaf, the nodes of S from its state down to s now hold two points: live regions.
    if (is_leaf) {
      for_each_on_path(t.nodes[cur].state, s, [this](const State& v) { add_region(v); });
    }
    const std::uint32_t x = new_node(t);
    t.nodes[x].depth = depth;
    t.nodes[x].state = s;
    t.nodes[x].axis = static_cast<std::uint8_t>(axis);
    t.nodes[x].rep = side == 0 ? point : rep;
    trie::split_above(t.nodes, t.root, cur, x, leaf, side);
    reps_up(t, x);  // a new leftmost point for the ancestors whose left path leads to x
    t.nodes[leaf].depth = depth + 1;
    t.nodes[leaf].state = child_state(s, axis, side);
    if (is_leaf) {
      t.nodes[cur].depth = depth + 1;
      t.nodes[cur].state = child_state(s, axis, 1 - side);
    }
    set_chain(t, x);
    set_chain(t, cur);
    set_chain(t, leaf);
    return;
  }
}

std::uint32_t LongestSideKdTree::locate(const State& target, std::uint32_t& depth_out) const {
  const Trie& t = *trie_;
  if (t.root == kNoIndex || t.nodes[t.root].point != kNoIndex) return kNoIndex;
  std::uint32_t cur = t.root;
  State s;
  std::uint32_t depth = 0;
  for (;;) {
    const Node& c = t.nodes[cur];  // an active node
    for (;;) {
      if (s == target) {
        depth_out = depth;
        return cur;
      }
      if (!descends(target.h[0], s.h[0]) || !descends(target.h[1], s.h[1])) return kNoIndex;
      if (depth == c.depth) break;
      const int axis = split_axis(s);
      s = child_state(s, axis, side_of(c.rep, s, axis));
      ++depth;
    }
    const std::uint32_t hs = s.h[c.axis];
    const std::uint32_t ht = target.h[c.axis];
    if (ht == hs) return kNoIndex;  // v would have to keep its range on the axis c splits
    const int side = side_towards(hs, ht);
    s = child_state(s, c.axis, side);
    ++depth;
    cur = c.child[static_cast<std::size_t>(side)];
    if (t.nodes[cur].point != kNoIndex) return kNoIndex;  // below: one point
  }
}

void LongestSideKdTree::collect(const Trie& t, std::uint32_t node,
                                std::vector<std::uint32_t>& out) const {
  for_each_leaf(t, node, [&](std::uint32_t leaf) { out.push_back(t.nodes[leaf].point); });
}

void LongestSideKdTree::release(Trie& t, std::uint32_t node) const {
  const Node v = t.nodes[node];
  t.free.push_back(node);
  if (v.point != kNoIndex) return;
  release(t, v.child[0]);
  release(t, v.child[1]);
}

// ---------------------------------------------------------------------------------------------
// Events.

EventKind LongestSideKdTree::process(const Event& event) {
  ++mutations_;
  if (event.owner == region_owner_) return process_region(event);
  const std::size_t which = sorts_.member_of(event);
  const int axis = static_cast<int>(which);
  KineticSort& s = sorts_[which];
  const KineticSort::Swap swap = s.process_swap(event);
  ++counters_.ordering_events;
  // x moved up one place past y: the labels at slots j and k (the next occupied one) of axis
  // `axis` changed hands.
  const std::uint32_t x = swap.up, y = swap.down;
  // The side lengths with the point at j or k as an end, each once: new polynomials
  // (continuous, so every live region keeps its longer side).
  changed_.clear();
  ends_at_slot(axis, swap.position, changed_);
  ends_at_slot(axis, swap.next, changed_);
  std::sort(changed_.begin(), changed_.end());
  changed_.erase(std::unique(changed_.begin(), changed_.end()), changed_.end());
  for (const std::uint32_t e : changed_) set_length(e);
  // The tree: only the keys of x and y changed (Abam, de Berg, Speckmann, Section 3, ordering
  // event); a point whose label changed only below its leaf keeps its path. The others are
  // deleted and reinserted; regions that stop or start holding two points are removed or added
  // (with the new lengths) on the way.
  const bool move_x = !keeps_path(x, axis, swap.position, swap.next);
  const bool move_y = !keeps_path(y, axis, swap.next, swap.position);
  if (move_x) erase(x);
  if (move_y) erase(y);
  if (move_x) insert_point(x);
  if (move_y) insert_point(y);
  counters_.reinsertions += (move_x ? 1 : 0) + (move_y ? 1 : 0);
  if (!move_x && !move_y) ++counters_.unchanged_events;
  // The certificates of the live regions with one of those sides (a region has one side per
  // axis, so it is met once).
  for (const std::uint32_t e : changed_) {
    for (std::uint32_t g = region_head_[e]; g != kNoIndex;
         g = regions_[g].next[static_cast<std::size_t>(axis)]) {
      schedule_region(g);
      ++counters_.region_reschedules;
    }
  }
  return EventKind::External;
}

EventKind LongestSideKdTree::process_region(const Event& event) {
  const std::uint32_t r = event.payload;
  Region& g = regions_[r];
  g.certificate = EventHandle{};  // popped by the simulator
  ++counters_.longest_side_events;
  if (sim_.logging_events()) {  // the points that bound the two sides whose lengths crossed
    std::array<ObjectId, 4> ids{};
    std::size_t w = 0;
    for (int axis = 0; axis < 2; ++axis) {
      const std::uint32_t h = g.s.h[static_cast<std::size_t>(axis)];
      ids[w++] = motions_.id(lo_point(axis, h));
      ids[w++] = motions_.id(top_point(axis, h));
    }
    std::sort(ids.begin(), ids.end());
    const auto last = std::unique(ids.begin(), ids.end());
    sim_.log_event("longest_side", std::span<const ObjectId>(ids.data(), last));
  }
  if (!flip_region(r)) ++counters_.longest_side_events_rebuilt_below;
  return EventKind::External;
}

bool LongestSideKdTree::flip_region(std::uint32_t r) {
  Region& g = regions_[r];
  const State target = g.s;
  const int old_axis = g.axis;
  const int new_axis = 1 - old_axis;
  g.axis = static_cast<std::uint8_t>(new_axis);
  schedule_region(r);
  // The node v of S with these ranges (two points or more) now splits on new_axis.
  std::uint32_t depth = 0;
  const std::uint32_t u = locate(target, depth);
  assert(u != kNoIndex);
  if (regroup(u, target, depth, old_axis, new_axis)) return true;
  rebuild_below(u, target, depth);
  return false;
}

bool LongestSideKdTree::regroup(std::uint32_t u, const State& v, std::uint32_t depth, int old_axis,
                                int new_axis) {
  // Abam, de Berg, Speckmann, Section 3, Figure 3. Before, v split on old_axis and both its
  // children on new_axis (the same median: the children keep v's range on new_axis); after, v
  // splits on new_axis and both children on old_axis. The four grandchildren A, B, C, D (the cells
  // of the two medians) keep their ranges, hence their subtrees: only the two levels of S below v
  // are regrouped. When the list does not give the children that axis before or after (lengths tied
  // with the two sides of v), the caller rebuilds below v instead.
  // Before: an old child with two points or more must split on new_axis. (A child with at most
  // one point has no split; its range on old_axis may hold a single rank, not a list element.)
  const Node& un = trie_->nodes[u];
  std::array<bool, 2> crowded_before{};
  for (int side = 0; side < 2; ++side) {
    const bool crowded =
        un.depth > depth ? side_of(un.rep, v, old_axis) == side
                         : trie_->nodes[un.child[static_cast<std::size_t>(side)]].point == kNoIndex;
    if (crowded && split_axis(child_state(v, old_axis, side)) != new_axis) return false;
    crowded_before[static_cast<std::size_t>(side)] = crowded;
  }
  // The items below v: whole subtrees at skeleton depth >= depth + 2 (one per cell with two
  // points or more) and single points; the active nodes above them are freed below.
  struct Item {
    std::uint32_t node;  // a trie node (kept), or kNoIndex for a single point
    std::uint32_t point;
    int cell;  // 2 * (side on new_axis) + (side on old_axis)
  };
  std::array<Item, 4> items{};
  int count = 0;
  std::vector<std::uint32_t> freed;
  const std::uint32_t parent = un.parent;
  std::vector<std::uint32_t> stack{u};
  while (!stack.empty()) {
    const std::uint32_t w = stack.back();
    stack.pop_back();
    const Node& wn = trie_->nodes[w];
    if (wn.point == kNoIndex && wn.depth < depth + 2) {
      stack.push_back(wn.child[0]);
      stack.push_back(wn.child[1]);
      freed.push_back(w);
      continue;
    }
    assert(count < 4);
    const std::uint32_t rep = wn.rep;
    const int cell = 2 * side_of(rep, v, new_axis) + side_of(rep, v, old_axis);
    if (wn.point != kNoIndex) {
      items[static_cast<std::size_t>(count++)] = Item{kNoIndex, wn.point, cell};
      freed.push_back(w);
    } else {
      items[static_cast<std::size_t>(count++)] = Item{w, rep, cell};
    }
  }
  // After: a new child with two points or more must split on old_axis.
  std::array<bool, 2> crowded_after{};
  for (int side = 0; side < 2; ++side) {
    int points = 0;
    for (int j = 0; j < count; ++j) {
      const Item& it = items[static_cast<std::size_t>(j)];
      if ((it.cell >> 1) == side) points += it.node == kNoIndex ? 1 : 2;
    }
    if (points >= 2 && split_axis(child_state(v, new_axis, side)) != old_axis) return false;
    crowded_after[static_cast<std::size_t>(side)] = points >= 2;
  }
  // The live regions one level below v change (the grandchildren are the same nodes of S, with
  // the same points, before and after).
  for (int side = 0; side < 2; ++side) {
    if (crowded_before[static_cast<std::size_t>(side)])
      remove_region(child_state(v, old_axis, side));
  }
  for (int side = 0; side < 2; ++side) {
    if (crowded_after[static_cast<std::size_t>(side)]) add_region(child_state(v, new_axis, side));
  }
  trie_->free.insert(trie_->free.end(), freed.begin(), freed.end());
  // Reassemble the two levels with the new axes (new_axis at v, old_axis below).
  const std::uint32_t top = assemble(std::span<Item>(items.data(), static_cast<std::size_t>(count)),
                                     v, depth, parent, new_axis, old_axis, 0);
  trie::replace_child(trie_->nodes, trie_->root, parent, u, top);
  reps_up(*trie_, top);
  return true;
}

template <class ItemSpan>
std::uint32_t LongestSideKdTree::assemble(ItemSpan items, State s, std::uint32_t depth,
                                          std::uint32_t parent, int first_axis, int second_axis,
                                          int level) {
  if (items.size() == 1) {
    auto& it = items[0];
    if (it.node == kNoIndex) {  // a single point: a leaf right below its active parent
      const std::uint32_t leaf = new_node(*trie_);
      Node& ln = trie_->nodes[leaf];
      ln.point = it.point;
      ln.rep = it.point;
      ln.parent = parent;
      ln.state = s;
      ln.depth = depth;
      leaf_of_[it.point] = leaf;
      set_chain(*trie_, leaf);
      return leaf;
    }
    trie_->nodes[it.node].parent = parent;  // a kept subtree (a cell, depth >= v's + 2)
    set_chain(*trie_, it.node);
    return it.node;
  }
  assert(level < 2);
  const int axis = level == 0 ? first_axis : second_axis;
  const int bit = level == 0 ? 2 : 1;
  const auto mid = std::stable_partition(items.begin(), items.end(),
                                         [&](const auto& it) { return (it.cell & bit) == 0; });
  const std::size_t left = static_cast<std::size_t>(mid - items.begin());
  if (left == 0 || left == items.size()) {  // a degree-one node of S: pruned
    return assemble(items, child_state(s, axis, left == 0 ? 1 : 0), depth + 1, parent, first_axis,
                    second_axis, level + 1);
  }
  const std::uint32_t k = new_node(*trie_);
  {
    Node& kn = trie_->nodes[k];
    kn.parent = parent;
    kn.state = s;
    kn.depth = depth;
    kn.axis = static_cast<std::uint8_t>(axis);
    kn.rep = items[0].point;
  }
  set_chain(*trie_, k);
  const std::uint32_t l = assemble(items.subspan(0, left), child_state(s, axis, 0), depth + 1, k,
                                   first_axis, second_axis, level + 1);
  const std::uint32_t r = assemble(items.subspan(left), child_state(s, axis, 1), depth + 1, k,
                                   first_axis, second_axis, level + 1);
  trie_->nodes[k].child = {l, r};
  trie_->nodes[k].leaves = trie_->nodes[l].leaves + trie_->nodes[r].leaves;
  trie_->nodes[k].rep = trie_->nodes[l].rep;  // the leftmost leaf's point
  return k;
}

void LongestSideKdTree::rebuild_below(std::uint32_t u, const State& v, std::uint32_t depth) {
  std::vector<std::uint32_t> points;
  collect(*trie_, u, points);
  counters_.rebuilt_points += points.size();
  // The live regions strictly below v go; v's own stays (its axis is the new one). The old
  // subtree hangs from v's old axis: walk it with that one.
  Region& g = regions_[find_region(v)];
  g.axis = static_cast<std::uint8_t>(1 - g.axis);
  std::vector<State> below;
  for_each_live(u, v, [&below](const State& s) { below.push_back(s); });
  g.axis = static_cast<std::uint8_t>(1 - g.axis);
  for (std::size_t k = 1; k < below.size(); ++k) remove_region(below[k]);
  const std::uint32_t parent = trie_->nodes[u].parent;
  release(*trie_, u);
  const std::uint32_t fresh = build(*trie_, points, 0, points.size(), v, depth, parent);
  trie::replace_child(trie_->nodes, trie_->root, parent, u, fresh);
  reps_up(*trie_, fresh);
  bool first = true;
  for_each_live(fresh, v, [&](const State& s) {
    if (!first) add_region(s);
    first = false;
  });
  for_each_leaf(*trie_, fresh,
                [this](std::uint32_t leaf) { leaf_of_[trie_->nodes[leaf].point] = leaf; });
}

namespace {
constexpr int kInsert = 0, kRemove = 1, kUpdate = 2;
}  // namespace

std::array<std::uint64_t, 2> LongestSideKdTree::layout_generations() const {
  return {sorts_[0].layout_generation(), sorts_[1].layout_generation()};
}

void LongestSideKdTree::insert(std::uint32_t index) {
  sync_.require_inserted("LongestSideKdTree::insert", index);
  ++mutations_;
  const std::array<std::uint64_t, 2> generation = layout_generations();
  set_leaf_motion(index);
  sorts_.insert(index);
  follow_sorts(index, kInsert, generation);
}

void LongestSideKdTree::remove(std::uint32_t index) {
  sync_.require_removed("LongestSideKdTree::remove", index);
  ++mutations_;
  const std::array<std::uint64_t, 2> generation = layout_generations();
  erase(index);  // its leaf first, while its labels are still the tree's
  sorts_.remove(index);
  follow_sorts(index, kRemove, generation);
}

void LongestSideKdTree::motion_changed(std::uint32_t index) {
  sync_.require_updated("LongestSideKdTree::motion_changed", index);
  ++mutations_;
  const std::array<std::uint64_t, 2> generation = layout_generations();
  erase(index);
  set_leaf_motion(index);
  sorts_.motion_changed(index);
  follow_sorts(index, kUpdate, generation);
}

bool LongestSideKdTree::keeps_path(std::uint32_t point, int axis, std::size_t was,
                                   std::size_t now) const {
  // The labels agree on their first L bits, L = log2 U_i - bit_width(was ^ now), so they take the
  // same sides at the ranges of levels < L; the point's path refined axis i down to its leaf's
  // range only, so a leaf whose range on axis i has level <= L stays where it is (as in the
  // kd-tree). Its points' paths depend on their own labels only, so nothing else moves.
  const std::uint32_t same = log_space_[static_cast<std::size_t>(axis)] -
                             static_cast<std::uint32_t>(std::bit_width(was ^ now));
  const State& at = trie_->nodes[leaf_of_[point]].state;
  return level(at.h[static_cast<std::size_t>(axis)]) <= same;
}

void LongestSideKdTree::follow_sorts(std::uint32_t index, int kind,
                                     const std::array<std::uint64_t, 2>& generation) {
  if (leaf_of_.size() < motions_.capacity()) leaf_of_.resize(motions_.capacity(), kNoIndex);
  if (sorts_[0].layout_generation() != generation[0] ||
      sorts_[1].layout_generation() != generation[1]) {
    ++counters_.rebuilds;  // U_i doubled or halved: every label may have changed
    rebuild();
    return;
  }
  ++counters_.local_changes;
  n_ = motions_.size();
  // The lengths with a moved end: end(L) changed only for the labels L after the last occupied
  // slot before a touched range and up to its end (to U_i when no point follows it).
  changed_.clear();
  for (int axis = 0; axis < 2; ++axis) {
    const KineticSort& s = sorts_[static_cast<std::size_t>(axis)];
    for (const auto& [lo_slot, hi_slot] : s.touched_slots()) {
      std::size_t first = lo_slot;
      while (first > 0 && s.order()[first - 1] == kNoIndex) --first;
      const std::size_t last =
          s.slot_at_or_after(hi_slot + 1) == KineticSort::kNoSlot ? s.slots() : hi_slot;
      ends_in(axis, first, last, changed_);
    }
  }
  std::sort(changed_.begin(), changed_.end());
  changed_.erase(std::unique(changed_.begin(), changed_.end()), changed_.end());
  for (const std::uint32_t e : changed_) set_length(e);
  // The points whose path in S changed: a moved label keeps the sides taken at the ranges of
  // levels < L = log2 U_i - bit_width(was ^ now); the path on axis i stopped at its leaf's range,
  // so a leaf whose range on axis i has level <= L stays (as in the kd-tree).
  if (moved_mark_.size() < motions_.capacity()) moved_mark_.resize(motions_.capacity(), 0);
  ++moved_round_;
  moved_.clear();
  for (int axis = 0; axis < 2; ++axis) {
    const KineticSort& s = sorts_[static_cast<std::size_t>(axis)];
    const auto told = s.relabeled();
    const auto from = s.relabeled_from();
    for (std::size_t k = 0; k < told.size(); ++k) {
      const std::uint32_t p = told[k];
      const std::uint32_t was = from[k], now = rank_of(p, axis);
      if (p == index || was == now || moved_mark_[p] == moved_round_) continue;
      if (keeps_path(p, axis, was, now)) {
        ++counters_.unchanged_relabels;
        continue;
      }
      moved_mark_[p] = moved_round_;
      moved_.push_back(p);
    }
  }
  // Deleted with their old paths, then reinserted with the new labels (regions that stop or
  // start holding two points are removed or added with the new lengths on the way).
  for (const std::uint32_t p : moved_) erase(p);
  if (kind != kRemove) insert_point(index);
  for (const std::uint32_t p : moved_) insert_point(p);
  counters_.relabel_reinsertions += moved_.size();
  // The live regions with a changed side, parents first: rescheduled, or split on their other
  // side now when it became the longer one (a change is not continuous).
  flip_candidates_.clear();
  for (const std::uint32_t e : changed_) {
    const auto axis = static_cast<std::size_t>(e / table_size_);
    for (std::uint32_t g = region_head_[e]; g != kNoIndex; g = regions_[g].next[axis])
      flip_candidates_.push_back(regions_[g].s);
  }
  const auto key = [](const State& v) {
    return std::array<std::uint32_t, 3>{level(v.h[0]) + level(v.h[1]), v.h[0], v.h[1]};
  };
  std::sort(flip_candidates_.begin(), flip_candidates_.end(),
            [&key](const State& a, const State& b) { return key(a) < key(b); });
  flip_candidates_.erase(std::unique(flip_candidates_.begin(), flip_candidates_.end()),
                         flip_candidates_.end());
  for (const State& v : flip_candidates_) {
    const std::uint32_t r = find_region(v);  // it may have gone with a region above
    if (r == kNoIndex) continue;
    if (fresh_axis(v) != regions_[r].axis) {
      ++counters_.change_axis_flips;
      flip_region(r);
    } else {
      schedule_region(r);
      ++counters_.region_reschedules;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Queries.

int LongestSideKdTree::compare_to(const MotionPolynomial& p, double x, Time t) const {
  return compare_at_value(p, x, t, &sim_.counters().predicates);
}

void LongestSideKdTree::boxes_at(Time t) {
  // A new time or any change since the last query: every cached box and bucket is stale.
  if (box_round_.begin(t, mutations_)) bucket_points_.clear();
  if (box_cache_.size() < trie_->nodes.size()) box_cache_.resize(trie_->nodes.size());
}

inline const LongestSideKdTree::CellBox& LongestSideKdTree::node_box(std::uint32_t node, Time t) {
  assert(box_round_.current(t, mutations_) && node < box_cache_.size());
  CachedBox& c = box_cache_[node];
  if (c.stamp != box_round_.round) {
    c.box = region_box(trie_->nodes[node].state, t);
    c.stamp = box_round_.round;
    c.bucket = kNoIndex;
  }
  return c.box;
}

LongestSideKdTree::CellBox LongestSideKdTree::region_box(const State& s, Time t) const {
  CellBox b{};
  for (int a = 0; a < 2; ++a) {
    const std::uint32_t h = s.h[static_cast<std::size_t>(a)];
    const FilteredValue l = numeric::filtered_value(motions_.motion(lo_point(a, h), a), t);
    const FilteredValue u = numeric::filtered_value(motions_.motion(top_point(a, h), a), t);
    b[static_cast<std::size_t>(a)] = {down(l.value - l.error), up(u.value + u.error)};
  }
  return b;
}

void LongestSideKdTree::set_leaf_motion(std::uint32_t point) {
  if (leaf_motion_.size() < motions_.capacity()) leaf_motion_.resize(motions_.capacity());
  leaf_motion_[point] = leaf_motion_of(point);
}

LongestSideKdTree::LeafMotion LongestSideKdTree::leaf_motion_of(std::uint32_t point) const {
  LeafMotion m;
  for (std::size_t a = 0; a < 2; ++a) {
    const numeric::LinearParts p =
        numeric::linear_parts(motions_.motion(point, static_cast<int>(a)));
    m.c0[a] = p.c0;
    m.c1[a] = p.c1;
    m.origin[a] = p.origin;
  }
  return m;
}

std::array<double, 2> LongestSideKdTree::point_at(std::uint32_t p, Time t, double& error) const {
  // The copy at the leaf when both motions are linear: the same arithmetic as
  // numeric::filtered_value() on the table's motion, so the same values and bounds.
  const LeafMotion& m = leaf_motion_[p];
  FilteredValue x, y;
  if (m.c1[0] == m.c1[0] && m.c1[1] == m.c1[1]) [[likely]] {
    x = numeric::linear_filtered(m.c0[0], m.c1[0], m.origin[0], t);
    y = numeric::linear_filtered(m.c0[1], m.c1[1], m.origin[1], t);
  } else {
    x = numeric::filtered_value(motions_.motion(p, 0), t);
    y = numeric::filtered_value(motions_.motion(p, 1), t);
  }
  // A NaN bound stays NaN (undecided); std::max alone could drop it.
  error = x.error != x.error || y.error != y.error ? kNaN : std::max(x.error, y.error);
  return {x.value, y.value};
}

inline double LongestSideKdTree::leaf_distance_from(std::uint32_t point, std::array<double, 2> p,
                                                    std::array<double, 2> q, Time t,
                                                    double& error) const {
  const double d = distance2d(p[0] - q[0], p[1] - q[1]);
  // The filtered coordinates are within `error` of the truth, about u times the coordinates'
  // size: when d is not far above that (q next to the point, or the motion's terms cancel), the
  // bound U = (d + 2 error)(1 + rho) says little and two points could not be told apart: then
  // refined_distance().
  if (!(2.0 * error <= kRho * d)) [[unlikely]]
    return refined_distance(point, q, t, error);
  return d;
}

double LongestSideKdTree::refined_distance(std::uint32_t point, std::array<double, 2> q, Time t,
                                           double& error) const {
  // The differences x(t) - q_x and y(t) - q_y of linear motions, compensated (their bounds
  // about u times the differences themselves); where even these do not give 2 error <= rho d,
  // the exact squared distance: relative error <= 2^-50 (as `error` = that fraction of d in
  // the bounds above), plus DBL_MIN * 2^-50 for distances below DBL_MIN.
  const std::array<const MotionPolynomial*, 2> xy{&motions_.motion(point, 0),
                                                  &motions_.motion(point, 1)};
  if (xy[0]->degree <= 1 && xy[1]->degree <= 1) {
    std::array<FilteredValue, 2> delta{};
    for (std::size_t a = 0; a < 2; ++a) {
      const MotionPolynomial& m = *xy[a];
      delta[a] = numeric::linear_minus_compensated(m.c[0], m.degree == 1 ? m.c[1] : 0.0, m.origin,
                                                   t, q[a]);
    }
    const double dc = distance2d(delta[0].value, delta[1].value);
    // Each bound on its own: false on a NaN one (undecided), which std::max could drop.
    if (2.0 * delta[0].error <= kRho * dc && 2.0 * delta[1].error <= kRho * dc) {
      error = std::max(delta[0].error, delta[1].error);
      return dc;
    }
  }
  const double exact = point_distance_at(xy, q, t);
  error = 0x1p-50 * (exact + DBL_MIN);
  return exact;
}

double LongestSideKdTree::leaf_distance(std::uint32_t point, std::array<double, 2> q, Time t,
                                        double& error) const {
  return leaf_distance_from(point, point_at(point, t, error), q, t, error);
}

void LongestSideKdTree::finish_query(std::uint64_t visits) {
  ++counters_.queries;
  counters_.node_visits += visits;
  counters_.last_query_visits = visits;
}

void LongestSideKdTree::require_point_query(const char* where, std::array<double, 2> q, double eps,
                                            Time t) const {
  sync_.require_current(where);
  require_query_time(where, t, sim_.now());
  if (!std::isfinite(q[0]) || !std::isfinite(q[1])) precondition_failed(where, "q is not finite");
  if (!(eps >= 0.0) || !std::isfinite(eps)) {
    precondition_failed(where, "eps = " + format_number(eps) + " (a finite eps >= 0)");
  }
}

void LongestSideKdTree::require_shape_query(const char* where, const Shape& shape, double eps,
                                            Time t) const {
  sync_.require_current(where);
  require_query_time(where, t, sim_.now());
  if (!(eps >= 0.0) || !std::isfinite(eps)) {
    precondition_failed(where, "eps = " + format_number(eps) + " (a finite eps >= 0)");
  }
  if (shape.kind == Shape::Kind::Disk) {
    if (shape.disk.center.size() != 2) {
      precondition_failed(where, "the disk's center has " +
                                     std::to_string(shape.disk.center.size()) +
                                     " coordinates (the plane: 2)");
    }
    if (!std::isfinite(shape.disk.center[0]) || !std::isfinite(shape.disk.center[1]) ||
        !(shape.disk.radius >= 0.0) || !std::isfinite(shape.disk.radius)) {
      precondition_failed(where, "the disk needs a finite center and a finite radius >= 0");
    }
  } else if (shape.kind == Shape::Kind::Polygon) {
    if (shape.polygon.size() < 3) precondition_failed(where, "a polygon needs 3 vertices or more");
    for (const Point2& v : shape.polygon) {
      if (!std::isfinite(v[0]) || !std::isfinite(v[1])) {
        precondition_failed(where, "a polygon vertex is not finite");
      }
    }
  } else {
    precondition_failed(where, "the shape is neither a disk nor a polygon");
  }
}

namespace {

// The three searches over the regions (LongestSideKdTree::search_below()): a region's key, when a
// region is skipped, and what a leaf does.

/// nearest(): Arya-Mount style; the packing property of Theorem 8(ii) bounds the regions met,
/// Theorem 9. A region's key is a lower bound on the distance from q to its points, nearest
/// first; a leaf's bound is an upper bound on its distance, and the best is the smallest bound
/// (equal bounds: the smaller id); a region is skipped when the best bound found is within
/// (1 + eps/2) of its key (docs: why eps/2 keeps the (1 + eps) guarantee despite rounding). The
/// best bound only decreases, so every point of a skipped region is at distance >= key >=
/// best / (1 + eps/2) at the end, as when the regions are taken smallest key first.
struct NearestSearch {
  double stop;
  std::uint32_t best = kNoIndex;
  double best_bound = kInf;

  static double key(const auto& b, std::array<double, 2> q) {
    const double dx = std::max({0.0, b[0][0] - q[0], q[0] - b[0][1]});
    const double dy = std::max({0.0, b[1][0] - q[1], q[1] - b[1][1]});
    return distance2d(dx, dy) * (1.0 - kRho);
  }
  /// Region a is searched before region b.
  static bool first(double a, double b) { return a <= b; }
  [[nodiscard]] bool skip(double key) const { return best != kNoIndex && key * stop >= best_bound; }
  void leaf(std::uint32_t point, double d, double err) {
    const double bound = (d + 2.0 * err) * (1.0 + kRho);
    if (bound < best_bound || (bound == best_bound && point < best)) {
      best = point;
      best_bound = bound;
    }
  }
};

/// farthest(): a region's key is an upper bound on the distance from q to its points, farthest
/// first; a leaf's bound is a lower bound on its distance, the best the largest; a region is
/// skipped when the best bound found is at least (1 - eps/2) times its key.
struct FarthestSearch {
  double stop;
  std::uint32_t best = kNoIndex;
  double best_bound = -1.0;

  static double key(const auto& b, std::array<double, 2> q) {
    const double dx = std::max(std::abs(q[0] - b[0][0]), std::abs(q[0] - b[0][1]));
    const double dy = std::max(std::abs(q[1] - b[1][0]), std::abs(q[1] - b[1][1]));
    return distance2d(dx, dy) * (1.0 + kRho);
  }
  static bool first(double a, double b) { return a >= b; }
  [[nodiscard]] bool skip(double key) const { return best != kNoIndex && best_bound >= key * stop; }
  void leaf(std::uint32_t point, double d, double err) {
    const double bound = std::max(0.0, d - 2.0 * err) * (1.0 - kRho);
    if (best == kNoIndex || bound > best_bound || (bound == best_bound && point < best)) {
      best = point;
      best_bound = bound;
    }
  }
};

/// k_nearest(): NearestSearch's keys; a leaf is offered to the candidates with the enclosure of
/// NearestSearch's bounds, [(d - 2 err)(1 - rho), (d + 2 err)(1 + rho)], and a region is skipped
/// when its key is above the candidates' limit (core/k_nearest.hpp).
struct KNearestSearch {
  NearestCandidates* candidates;

  static double key(const auto& b, std::array<double, 2> q) { return NearestSearch::key(b, q); }
  static bool first(double a, double b) { return a <= b; }
  [[nodiscard]] bool skip(double key) const { return key > candidates->prune_above(); }
  void leaf(std::uint32_t point, double d, double err) const {
    candidates->offer(point, std::max(0.0, (d - 2.0 * err) * (1.0 - kRho)),
                      (d + 2.0 * err) * (1.0 + kRho));
  }
};

}  // namespace

template <class Search>
void LongestSideKdTree::search_below(std::uint32_t node, std::array<double, 2> q, Time t,
                                     Search& search, std::uint64_t& visits) {
  // Depth first, the child with the better key first; a child is skipped when its key says so
  // at the moment it would be entered (after its sibling's search).
  ++visits;
  const Node& v = trie_->nodes[node];
  if (v.point != kNoIndex) {
    double err = 0.0;
    const double d = leaf_distance(v.point, q, t, err);
    search.leaf(v.point, d, err);
    return;
  }
  if (v.leaves <= kBucket) {  // a bucket: its points' positions at t, one after the other
    const BucketPoint* b = bucket_at(node, t);
    visits += v.leaves;
    for (std::uint32_t i = 0; i < v.leaves; ++i) {
      double err = b[i].error;  // the distance's bound, once it is computed
      const double d = leaf_distance_from(b[i].point, {b[i].x, b[i].y}, q, t, err);
      search.leaf(b[i].point, d, err);
    }
    return;
  }
  const std::array<std::uint32_t, 2> c = v.child;
  // One level ahead: the children's records and boxes were asked for at the parent (or are the
  // root's); ask for the grandchildren's now, or a leaf child's motions, so that the descent
  // waits for about one memory access per level, not two.
  for (const std::uint32_t x : c) {
    const Node& w = trie_->nodes[x];
    if (w.point != kNoIndex) {
      __builtin_prefetch(&leaf_motion_[w.point]);
    } else if (w.leaves <= kBucket) {
      // A bucket filled at this time (by an earlier query): its points, a few lines in a row.
      const CachedBox& cb = box_cache_[x];
      if (cb.stamp == box_round_.round && cb.bucket != kNoIndex) {
        const BucketPoint* b = bucket_points_.data() + cb.bucket;
        prefetch_range(b, b + w.leaves);
      } else {
        __builtin_prefetch(&leaf_motion_[w.rep]);  // not yet: its first point's motions
      }
    } else {
      for (const std::uint32_t y : w.child) {
        __builtin_prefetch(&trie_->nodes[y]);
        __builtin_prefetch(&box_cache_[y]);
      }
    }
  }
  const std::array<double, 2> key{Search::key(node_box(c[0], t), q),
                                  Search::key(node_box(c[1], t), q)};
  const int near = Search::first(key[0], key[1]) ? 0 : 1;
  if (!search.skip(key[near])) search_below(c[near], q, t, search, visits);
  if (!search.skip(key[1 - near])) search_below(c[1 - near], q, t, search, visits);
}

const LongestSideKdTree::BucketPoint* LongestSideKdTree::bucket_at(std::uint32_t node, Time t) {
  CachedBox& cached = box_cache_[node];
  assert(cached.stamp == box_round_.round);  // node_box(node) first: its key decided the visit
  if (cached.bucket == kNoIndex) {
    // The subtree's leaves left to right, each point as point_at() gives it. Buckets are the
    // largest subtrees of at most kBucket leaves (a search stops at the first one on its way
    // down), so they do not overlap: at most n points per round.
    cached.bucket = static_cast<std::uint32_t>(bucket_points_.size());
    for_each_leaf(*trie_, node, [&](std::uint32_t leaf) {
      BucketPoint b;
      b.point = trie_->nodes[leaf].point;
      const std::array<double, 2> p = point_at(b.point, t, b.error);
      b.x = p[0];
      b.y = p[1];
      bucket_points_.push_back(b);
    });
    assert(bucket_points_.size() - cached.bucket == trie_->nodes[node].leaves);
  }
  return bucket_points_.data() + cached.bucket;
}

template <class Search>
std::optional<std::uint32_t> LongestSideKdTree::search(std::array<double, 2> q, Time t,
                                                       Search& search) {
  std::uint64_t visits = 0;
  boxes_at(t);
  if (trie_->root != kNoIndex && !search.skip(Search::key(node_box(trie_->root, t), q))) {
    search_below(trie_->root, q, t, search, visits);
  }
  finish_query(visits);
  if constexpr (requires { search.best; }) {
    if (search.best == kNoIndex) return std::nullopt;
    return search.best;
  } else {
    return std::nullopt;
  }
}

std::optional<std::uint32_t> LongestSideKdTree::nearest(std::array<double, 2> q, double eps,
                                                        Time t) {
  require_point_query("LongestSideKdTree::nearest", q, eps, t);
  NearestSearch s{1.0 + 0.5 * eps};
  return search(q, t, s);
}

std::optional<std::uint32_t> LongestSideKdTree::farthest(std::array<double, 2> q, double eps,
                                                         Time t) {
  require_point_query("LongestSideKdTree::farthest", q, eps, t);
  FarthestSearch s{1.0 - 0.5 * eps};
  return search(q, t, s);
}

std::vector<std::uint32_t> LongestSideKdTree::k_nearest(std::span<const double> q, std::size_t k,
                                                        double eps, Time t) {
  require_point_query_at("LongestSideKdTree::k_nearest", sync_, t, sim_.now(), q, 2, eps);
  nearest_.reset(k, eps);
  KNearestSearch s{&nearest_};
  if (k > 0) (void)search({q[0], q[1]}, t, s);
  std::vector<std::uint32_t> out;
  nearest_.finish(motions_, q, t, out);
  return out;
}

template <class Visit>
std::vector<std::uint32_t> LongestSideKdTree::depth_first(Visit&& visit) {
  std::vector<std::uint32_t> out;
  std::uint64_t visits = 0;
  std::vector<std::uint32_t> stack;
  if (trie_->root != kNoIndex) stack.push_back(trie_->root);
  while (!stack.empty()) {
    const std::uint32_t node = stack.back();
    stack.pop_back();
    ++visits;
    const Node& v = trie_->nodes[node];
    if (visit(node, v, out)) {
      stack.push_back(v.child[0]);
      stack.push_back(v.child[1]);
    }
  }
  std::sort(out.begin(), out.end());
  finish_query(visits);
  return out;
}

std::vector<std::uint32_t> LongestSideKdTree::approx_range(const Shape& shape, double eps, Time t) {
  require_shape_query("LongestSideKdTree::approx_range", shape, eps, t);
  // A region is skipped when it certainly misses the shape, reported whole when it certainly
  // lies inside, or when it is small (diameter <= eps diam(Q)) and may meet the shape: then all
  // its points are within eps diam(Q) of Q. Signed distances are computed in floating point with
  // the slack eta (docs/longest-side-kdtree.md).
  const double diam = diameter(shape);
  const double eta = 0x1p-40 * (1.0 + magnitude(shape));
  boxes_at(t);
  return depth_first([&](std::uint32_t node, const Node& v, std::vector<std::uint32_t>& out) {
    if (v.point != kNoIndex) {
      double err = 0.0;
      const auto p = point_at(v.point, t, err);
      if (signed_distance(shape, p) <= eta + 2.0 * err) out.push_back(v.point);
      return false;
    }
    const CellBox b = node_box(node, t);
    const std::array<double, 2> m{0.5 * (b[0][0] + b[0][1]), 0.5 * (b[1][0] + b[1][1])};
    const double hd = 0.5 * std::hypot(b[0][1] - b[0][0], b[1][1] - b[1][0]) * (1.0 + kRho);
    const double sd = signed_distance(shape, m);
    if (sd - hd > eta) return false;
    if (sd + hd < -eta || 2.0 * (hd + eta) <= eps * diam) {
      collect(*trie_, node, out);
      return false;
    }
    return true;
  });
}

std::vector<std::uint32_t> LongestSideKdTree::range(const Box& box, Time t) {
  sync_.require_current("LongestSideKdTree::range");
  require_query_time("LongestSideKdTree::range", t, sim_.now());
  require_box("LongestSideKdTree::range", box, 2);
  auto inside = [&](std::uint32_t p) {
    for (int a = 0; a < 2; ++a) {
      const auto& m = motions_.motion(p, a);
      const auto& bb = box[static_cast<std::size_t>(a)];
      if (compare_to(m, bb[0], t) < 0 || compare_to(m, bb[1], t) > 0) return false;
    }
    return true;
  };
  std::vector<std::uint32_t> sub;
  return depth_first([&](std::uint32_t node, const Node& v, std::vector<std::uint32_t>& out) {
    if (v.point != kNoIndex) {
      if (inside(v.point)) out.push_back(v.point);
      return false;
    }
    bool disjoint = false;
    bool contained = true;
    for (int a = 0; a < 2 && !disjoint; ++a) {
      const std::uint32_t h = v.state.h[static_cast<std::size_t>(a)];
      const auto& lower = motions_.motion(lo_point(a, h), a);
      const auto& upper = motions_.motion(top_point(a, h), a);
      const auto& bb = box[static_cast<std::size_t>(a)];
      if (compare_to(upper, bb[0], t) < 0 || compare_to(lower, bb[1], t) > 0) disjoint = true;
      if (contained && (compare_to(lower, bb[0], t) < 0 || compare_to(upper, bb[1], t) > 0)) {
        contained = false;
      }
    }
    if (disjoint) return false;
    if (contained) {
      // Every point of the region is inside; each is still checked exactly (cheap, filtered),
      // so a report never depends on the maintained order being exact at t.
      sub.clear();
      collect(*trie_, node, sub);
      for (const std::uint32_t p : sub) {
        if (inside(p)) out.push_back(p);
      }
      return false;
    }
    return true;
  });
}

// ---------------------------------------------------------------------------------------------
// Measures and validation.

std::size_t LongestSideKdTree::node_count() const {
  std::size_t count = 0;
  std::vector<std::uint32_t> stack;
  if (trie_->root != kNoIndex) stack.push_back(trie_->root);
  while (!stack.empty()) {
    const Node& v = trie_->nodes[stack.back()];
    stack.pop_back();
    count += 1 + v.chain;
    if (v.point == kNoIndex) {
      stack.push_back(v.child[0]);
      stack.push_back(v.child[1]);
    }
  }
  return count;
}

std::vector<LongestSideKdTree::CellSketch> LongestSideKdTree::sketch(int levels) const {
  std::vector<CellSketch> out;
  if (trie_->root == kNoIndex || levels <= 0) return out;
  std::vector<std::pair<std::uint32_t, int>> queue{{trie_->root, 0}};
  for (std::size_t k = 0; k < queue.size(); ++k) {
    const auto [node, level] = queue[k];
    const Node& v = trie_->nodes[node];
    if (v.point != kNoIndex) continue;  // a leaf
    CellSketch c;
    c.depth = level;
    for (int a = 0; a < 2; ++a) {
      const std::uint32_t h = v.state.h[static_cast<std::size_t>(a)];
      c.lo[static_cast<std::size_t>(a)] = lo_point(a, h);
      c.top[static_cast<std::size_t>(a)] = top_point(a, h);
    }
    c.axis = v.axis;
    c.split = end_point(c.axis, median(c.axis, v.state.h[v.axis]));
    out.push_back(c);
    if (level + 1 < levels) {
      queue.emplace_back(v.child[0], level + 1);
      queue.emplace_back(v.child[1], level + 1);
    }
  }
  return out;
}

int LongestSideKdTree::depth() const {
  std::uint32_t deepest = 0;
  for (const std::uint32_t leaf : leaf_of_) {
    if (leaf != kNoIndex) deepest = std::max(deepest, trie_->nodes[leaf].depth);
  }
  return static_cast<int>(deepest);
}

std::size_t LongestSideKdTree::certificates() const {
  return live_regions() + sorts_.certificates();
}

std::size_t LongestSideKdTree::certificates_per_object_max() const {
  std::size_t best = 0;
  std::vector<std::uint32_t> mine, ends;
  for (const std::uint32_t p : motions_.alive_indices()) {
    if (p >= leaf_of_.size() || leaf_of_[p] == kNoIndex) continue;
    std::size_t count = 0;
    mine.clear();
    for (int a = 0; a < 2; ++a) {
      const KineticSort& s = sorts_[static_cast<std::size_t>(a)];
      const std::uint32_t r = rank_of(p, a);
      count += (s.prev_slot(r) != KineticSort::kNoSlot ? 1 : 0) +
               (s.next_slot(r) != KineticSort::kNoSlot ? 1 : 0);  // the sort's certificates
      ends.clear();
      ends_at_slot(a, r, ends);  // the live regions with a side ending at p
      for (const std::uint32_t e : ends) {
        for (std::uint32_t g = region_head_[e]; g != kNoIndex;
             g = regions_[g].next[static_cast<std::size_t>(a)]) {
          mine.push_back(g);
        }
      }
    }
    std::sort(mine.begin(), mine.end());
    count += static_cast<std::size_t>(std::unique(mine.begin(), mine.end()) - mine.begin());
    best = std::max(best, count);
  }
  return best;
}

bool LongestSideKdTree::same(const Trie& a, std::uint32_t x, const Trie& b, std::uint32_t y) const {
  if ((x == kNoIndex) != (y == kNoIndex)) return false;
  if (x == kNoIndex) return true;
  const Node& u = a.nodes[x];
  const Node& v = b.nodes[y];
  if (u.depth != v.depth || u.point != v.point || !(u.state == v.state) || u.chain != v.chain ||
      u.leaves != v.leaves) {
    return false;
  }
  if (u.point != kNoIndex) return true;
  if (u.axis != v.axis) return false;
  if (a.nodes[u.child[0]].parent != x || a.nodes[u.child[1]].parent != x) return false;
  return same(a, u.child[0], b, v.child[0]) && same(a, u.child[1], b, v.child[1]);
}

bool LongestSideKdTree::validate() const {
  if (!sync_.current()) return false;
  if (!sorts_.validate()) return false;
  if (n_ != motions_.size()) return false;
  // The leaves' copies of the motions are the table's, bit for bit (NaN slopes for degree > 1).
  for (const std::uint32_t p : motions_.alive_indices()) {
    if (p >= leaf_motion_.size()) return false;
    const LeafMotion want = leaf_motion_of(p);
    const LeafMotion& have = leaf_motion_[p];
    // The fields, not the object: its padding is not a value.
    if (std::memcmp(have.c0.data(), want.c0.data(), sizeof(want.c0)) != 0 ||
        std::memcmp(have.c1.data(), want.c1.data(), sizeof(want.c1)) != 0 ||
        std::memcmp(have.origin.data(), want.origin.data(), sizeof(want.origin)) != 0) {
      return false;
    }
  }
  // Every element's length is its ends' current difference.
  for (int axis = 0; axis < 2; ++axis) {
    for (std::uint32_t h = 1; h < space(axis); ++h) {
      const std::uint32_t e = element(axis, h);
      const std::uint32_t top = top_point(axis, h), low = lo_point(axis, h);
      if (top == kNoIndex || low == kNoIndex) {
        if (!(length_[e] == MotionPolynomial{})) return false;
        continue;
      }
      const MotionPolynomial& tm = motions_.motion(top, axis);
      const MotionPolynomial& lm = motions_.motion(low, axis);
      const MotionDifference d = motion_difference(tm, lm);
      if (!(d.p == length_[e]) || (d.exact ? 1 : 0) != length_exact_[e]) return false;
      if (!(ends_[e][0] == tm) || !(ends_[e][1] == lm)) return false;
    }
  }
  // The live regions are the nodes of S with two points or more, each once, each in the lists of
  // its two sides, each with its certificate scheduled (or none: no failure ahead).
  std::size_t live = 0;
  bool regions_ok = true;
  if (trie_->root != kNoIndex) {
    for_each_live(trie_->root, State{}, [&](const State& v) {
      ++live;
      const std::uint32_t r = find_region(v);
      if (r == kNoIndex || !(regions_[r].s == v)) {
        regions_ok = false;
        return;
      }
      const EventHandle c = regions_[r].certificate;
      if (c.is_null()) return;  // no failure ahead
      if (!sim_.queue().contains(c)) {
        regions_ok = false;
        return;
      }
      const Event& ev = sim_.queue().get(c);
      if (ev.owner != region_owner_ || ev.payload != r) regions_ok = false;
    });
  }
  if (!regions_ok || live != region_keys_.size() || region_of_.size() != live) return false;
  std::size_t linked = 0;
  for (int axis = 0; axis < 2; ++axis) {
    for (std::uint32_t h = 0; h < table_size_; ++h) {
      const std::uint32_t e = element(axis, h);
      std::uint32_t prev = kNoIndex;
      for (std::uint32_t g = region_head_[e]; g != kNoIndex;
           g = regions_[g].next[static_cast<std::size_t>(axis)]) {
        if (regions_[g].prev[static_cast<std::size_t>(axis)] != prev) return false;
        if (element(axis, regions_[g].s.h[static_cast<std::size_t>(axis)]) != e) return false;
        if (++linked > 2 * live) return false;
        prev = g;
      }
    }
  }
  if (linked != 2 * live) return false;
  // The tree equals a fresh build.
  Trie fresh;
  build_all(fresh);
  if (!same(*trie_, trie_->root, fresh, fresh.root)) return false;
  if (trie_->root != kNoIndex && trie_->nodes[trie_->root].parent != kNoIndex) return false;
  // Representatives: a leaf's is its point, an active node's its left child's (its leftmost
  // leaf's point, which erase() relies on to stop early).
  {
    std::vector<std::uint32_t> stack;
    if (trie_->root != kNoIndex) stack.push_back(trie_->root);
    while (!stack.empty()) {
      const Node& v = trie_->nodes[stack.back()];
      stack.pop_back();
      if (v.point != kNoIndex) {
        if (v.rep != v.point) return false;
        continue;
      }
      if (v.rep != trie_->nodes[v.child[0]].rep) return false;
      stack.push_back(v.child[0]);
      stack.push_back(v.child[1]);
    }
  }
  for (const std::uint32_t p : motions_.alive_indices()) {
    if (p >= leaf_of_.size()) return false;
    const std::uint32_t leaf = leaf_of_[p];
    if (leaf == kNoIndex || trie_->nodes[leaf].point != p) return false;
  }
  if (n_ >= 2) {
    if (depth() > static_cast<int>(log_space_[0] + log_space_[1])) return false;
    if (node_count() > 5 * (2 * n_ - 1)) return false;
  }
  return true;
}

bool LongestSideKdTree::audit_regions(Time t) const {
  for (const std::uint32_t r : region_of_) {
    const auto [shorter, longer] = sides(regions_[r]);
    if (compare_lengths_at(shorter, longer, t) > 0) return false;
  }
  return true;
}

NamedCounters LongestSideKdTree::named_counters() const {
  const LongestSideCounters& c = counters_;
  return {{"ordering_events", c.ordering_events},
          {"longest_side_events", c.longest_side_events},
          {"longest_side_events_rebuilt_below", c.longest_side_events_rebuilt_below},
          {"reinsertions", c.reinsertions},
          {"unchanged_events", c.unchanged_events},
          {"region_reschedules", c.region_reschedules},
          {"rebuilds", c.rebuilds},
          {"local_changes", c.local_changes},
          {"relabel_reinsertions", c.relabel_reinsertions},
          {"unchanged_relabels", c.unchanged_relabels},
          {"change_axis_flips", c.change_axis_flips},
          {"combined_lengths", c.combined_lengths},
          {"queries", c.queries},
          {"node_visits", c.node_visits}};
}

namespace {

/// The loop guard's bounds. Ordering events are crossings in the two sorts. The side-length list
/// has m < 2n elements; a pair of elements crosses at most s times while both keep their length
/// polynomials, and an ordering event gives new polynomials to at most 12 ceil(log2 n) + 12
/// elements (a rank ends at most 3 ranges per level on each axis), each of which may then cross
/// every other element once more. Saturating arithmetic: the bounds are huge for large n.
LoopGuard longest_side_event_bounds(const RunBounds& b) {
  const std::uint64_t n = b.max_objects, changes = b.motion_changes;
  const LoopGuard sorts = crossing_guard(2, n, changes, b.max_degree);
  const std::uint64_t s = static_cast<std::uint64_t>(std::max(1, b.max_degree));
  std::uint64_t log = 0;
  while ((std::uint64_t{1} << log) < n) ++log;
  const std::uint64_t m = 2 * n;
  const std::uint64_t pairs_m = m * (m > 0 ? m - 1 : 0) / 2;
  const std::uint64_t per_ordering = (12 * log + 12) * m;
  auto mul = [](std::uint64_t x, std::uint64_t y) {
    return (x != 0 && y > UINT64_MAX / x) ? UINT64_MAX : x * y;
  };
  auto add = [](std::uint64_t x, std::uint64_t y) {
    return x > UINT64_MAX - y ? UINT64_MAX : x + y;
  };
  LoopGuard g;
  g.max_events_per_instant = add(sorts.max_events_per_instant,
                                 add(pairs_m, mul(sorts.max_events_per_instant, per_ordering)));
  g.max_events_total = add(
      sorts.max_events_total,
      add(mul(s, mul(changes + 1, pairs_m)), mul(s, mul(sorts.max_events_total, per_ordering))));
  return g;
}

}  // namespace

StructureDescription LongestSideKdTree::description() {
  return StructureDescription{
      "longest-side-kdtree",
      "LongestSideKdTree",
      ObjectsAre::Points,
      {QueryType::Nearest, QueryType::KNearest, QueryType::Farthest, QueryType::ApproxRange,
       QueryType::Range},
      {"swap", "longest_side"},
      "The kinetic rank-based longest-side kd-tree in the plane (range, nearest, k_nearest, "
      "farthest, approx_range).",
      "kinetic rank-based longest-side kd-tree (dimension 2): (1+eps)-nearest, k nearest, "
      "(1-eps)-farthest, eps-approximate range (disk or simple polygon), exact box range"}
      .limit_dimensions(2, 2, "Abam, de Berg, Speckmann, Section 3")
      .bound_events(longest_side_event_bounds);
}

}  // namespace kinetic
