#include "kinetic/bvh/kinetic_bvh.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <string>

#include "kinetic/core/free_list.hpp"

namespace kinetic {

// The records behind KineticBvh (declared in its header, laid out here).

enum class KineticBvh::State : std::uint8_t { Separated, Expanded, Contact, Self };

struct KineticBvh::Node {
  std::uint32_t parent = kNoIndex;
  std::uint32_t left = kNoIndex;  // kNoIndex: a leaf
  std::uint32_t right = kNoIndex;
  std::uint32_t box = kNoIndex;  // leaves: the table index
};

/// A pair of the list. The list is a tree of pairs (the self-traversal's recursion): an
/// expanded or self pair holds its children pairs' records, in children_pairs() order, so
/// that nothing is looked up by node pair.
struct KineticBvh::PairRecord {
  std::uint32_t a = kNoIndex, b = kNoIndex;  // nodes, a <= b; kNoIndex: a free record
  State state = State::Separated;
  std::uint8_t child_count = 0;
  std::uint32_t first_cert = kNoIndex;  // certificates of this pair: a chain
  std::array<std::uint32_t, 4> child{kNoIndex, kNoIndex, kNoIndex, kNoIndex};
};

/// On f = side(upper_node, axis, upper_side) - side(lower_node, axis, lower_side): f > 0 for
/// a separated pair (the lower node's high side strictly below the upper node's low side), f <= 0
/// for an overlapping one (a low side not above the other node's high side). Both kinds
/// compare a low side minus a high side, so the decisions that classify a pair are the ones its
/// certificates are scheduled from.
/// An overlap certificate is kept when a watched side's winner changes at an event: a node's
/// low side is at most, its high side at least, the side of any of its leaves, so the old
/// winners' inequality (low(w) <= high(w')) implies the node's, and fails no later. When it
/// fires, the pair is decided on its current winners. It is rescheduled when a box it was
/// computed from (`from`) changes its motion or leaves. Separation certificates (the strict
/// inequality the other way) are rescheduled at every change of their winners.
struct KineticBvh::Cert {
  std::uint32_t pair = kNoIndex;
  std::uint32_t lower_node = kNoIndex, upper_node = kNoIndex;
  std::uint8_t axis = 0;
  BoxSide lower_side = BoxSide::Low, upper_side = BoxSide::Low;
  std::uint32_t next_of_pair = kNoIndex;
  std::array<std::uint32_t, 2> watch_next{kNoIndex, kNoIndex};  // links: cert * 2 + slot
  std::array<std::uint32_t, 2> watch_prev{kNoIndex, kNoIndex};
  std::array<std::uint32_t, 2> from{kNoIndex, kNoIndex};  // the lower's, the upper's winner
  EventHandle handle;
};

/// The decisions of a pair (a, b)'s 2d side comparisons, computed on demand and kept for the
/// certificates made from them: index 2 axis + 0 is sign(low(b) - high(a)) (> 0: a below b),
/// 2 axis + 1 is sign(low(a) - high(b)) (> 0: b below a).
struct KineticBvh::PairDecisions {
  std::array<Scheduler::SignDecision, 6> d{};
  std::uint8_t known = 0;  // bit k: d[k] computed
};

/// Calls f(c) for every certificate c watching slot s (the next link read first: f may
/// reschedule c, which keeps its links).
template <class F>
void KineticBvh::for_each_watcher(std::size_t s, F&& f) const {
  for (std::uint32_t link = watch_head_[s]; link != kNoIndex;) {
    const std::uint32_t c = link / 2;
    link = certs_[c].watch_next[link % 2];
    f(c);
  }
}

/// The children pairs of a pair (at most four): a fixed-size list, no allocation per
/// expansion or collapse.
struct KineticBvh::ChildPairs {
  std::array<std::pair<std::uint32_t, std::uint32_t>, 4> pairs{};
  std::size_t size = 0;
  void clear() { size = 0; }
  void emplace_back(std::uint32_t x, std::uint32_t y) { pairs[size++] = {x, y}; }
  [[nodiscard]] bool empty() const { return size == 0; }
  [[nodiscard]] const auto* begin() const { return pairs.data(); }
  [[nodiscard]] const auto* end() const { return pairs.data() + size; }
};

bool KineticBvh::leaf(std::uint32_t node) const { return nodes_[node].left == kNoIndex; }
bool KineticBvh::free_node(std::uint32_t node) const { return nodes_[node].left == kFreeNode; }
bool KineticBvh::internal(std::uint32_t node) const { return !leaf(node) && !free_node(node); }

KineticBvh::~KineticBvh() = default;

std::size_t KineticBvh::nodes() const { return nodes_.size() - free_nodes_.size(); }

}  // namespace kinetic

namespace kinetic {
namespace {

constexpr std::array<BoxSide, 2> kSides{BoxSide::Low, BoxSide::High};

/// Median-split topology over `boxes` (table indices) by their centers `at` (row-major, d per
/// box): the axis of largest spread, ties by id order of the input. Nodes appended to `out`;
/// returns the root.
struct TopologyBuilder {
  const std::vector<double>& centers;  // box index * d + axis
  const MotionTable& table;
  int d;
  std::vector<std::array<std::uint32_t, 4>>& out;  // parent, left, right, box

  std::uint32_t build(std::vector<std::uint32_t>& boxes, std::size_t lo, std::size_t hi,
                      std::uint32_t parent) {
    const auto me = static_cast<std::uint32_t>(out.size());
    out.push_back({parent, kNoIndex, kNoIndex, kNoIndex});
    if (hi - lo == 1) {
      out[me][3] = boxes[lo];
      return me;
    }
    int axis = 0;
    double spread = -1.0;
    for (int k = 0; k < d; ++k) {
      double a = HUGE_VAL, b = -HUGE_VAL;
      for (std::size_t i = lo; i < hi; ++i) {
        const double x =
            centers[boxes[i] * static_cast<std::size_t>(d) + static_cast<std::size_t>(k)];
        a = std::min(a, x);
        b = std::max(b, x);
      }
      if (b - a > spread) {
        spread = b - a;
        axis = k;
      }
    }
    const std::size_t mid = lo + (hi - lo) / 2;
    const auto at = [&](std::uint32_t i) {
      return centers[i * static_cast<std::size_t>(d) + static_cast<std::size_t>(axis)];
    };
    std::nth_element(boxes.begin() + static_cast<std::ptrdiff_t>(lo),
                     boxes.begin() + static_cast<std::ptrdiff_t>(mid),
                     boxes.begin() + static_cast<std::ptrdiff_t>(hi),
                     [&](std::uint32_t x, std::uint32_t y) {
                       if (at(x) != at(y)) return at(x) < at(y);
                       return table.id(x) < table.id(y);
                     });
    const std::uint32_t l = build(boxes, lo, mid, me);
    const std::uint32_t r = build(boxes, mid, hi, me);
    out[me][1] = l;
    out[me][2] = r;
    return me;
  }
};

}  // namespace

KineticBvh::KineticBvh(const MotionTable& boxes, Simulator& simulator, const Scheduler& scheduler)
    : BoxContacts(boxes, simulator, "KineticBvh::colliding_pairs",
                  "KineticBvh::contact_changes"),
      scheduler_(scheduler),
      d_(box_dimension(boxes)),
      owners_(simulator.reserve_owners(2)),
      tree_(simulator, owners_[0], SideKeys{this}, SideTopology{this}) {
  require_box_table(boxes, "KineticBvh");
  for (int axis = 0; axis < d_; ++axis) keys_.emplace_back(boxes, axis);
  simulator.attach(scheduler);
}

std::vector<std::pair<std::uint32_t, int>> KineticBvh::sketch_order(int levels) const {
  std::vector<std::pair<std::uint32_t, int>> queue;
  if (root_ == kNoIndex) return queue;
  queue.emplace_back(root_, 0);
  for (std::size_t k = 0; k < queue.size(); ++k) {
    const auto [node, depth] = queue[k];
    const Node& n = nodes_[node];
    if (n.left != kNoIndex && depth + 1 < levels) {
      queue.emplace_back(n.left, depth + 1);
      queue.emplace_back(n.right, depth + 1);
    }
  }
  return queue;
}

std::vector<KineticBvh::NodeSketch> KineticBvh::sketch(int levels) const {
  std::vector<NodeSketch> out;
  for (const auto& [node, depth] : sketch_order(levels)) {
    NodeSketch s;
    s.depth = depth;
    for (int a = 0; a < d_; ++a) {
      s.sides.push_back(
          {tree_.winner(slot(node, a, BoxSide::Low)), tree_.winner(slot(node, a, BoxSide::High))});
    }
    out.push_back(std::move(s));
  }
  return out;
}

std::vector<KineticBvh::PairSketch> KineticBvh::sketch_pairs(int levels) const {
  std::vector<PairSketch> out;
  if (root_ == kNoIndex || levels <= 0) return out;
  // The nodes' positions in sketch(levels).
  std::vector<std::uint32_t> position(nodes_.size(), kNoIndex);
  const auto order = sketch_order(levels);
  for (std::size_t k = 0; k < order.size(); ++k)
    position[order[k].first] = static_cast<std::uint32_t>(k);
  // The list is a tree of pairs from the root's self pair; a pair's children pairs are between
  // children of its nodes, so the walk stops at the first pair with a node beyond the levels.
  std::vector<std::uint32_t> stack;
  if (self_pair_[root_] != kNoIndex) stack.push_back(self_pair_[root_]);
  while (!stack.empty()) {
    const PairRecord& r = pairs_[stack.back()];
    stack.pop_back();
    if (position[r.a] == kNoIndex || position[r.b] == kNoIndex) continue;
    const char* state = r.state == State::Separated  ? "separated"
                        : r.state == State::Expanded ? "expanded"
                        : r.state == State::Contact  ? "contact"
                                                     : "self";
    out.push_back({position[r.a], position[r.b], state});
    for (std::uint8_t k = r.child_count; k-- > 0;) stack.push_back(r.child[k]);
  }
  return out;
}

NamedCounters KineticBvh::named_counters() const {
  return {{"tournament_events", counters_.tournament_events},
          {"winner_changes", counters_.winner_changes},
          {"separation_events", counters_.separation_events},
          {"overlap_events", counters_.overlap_events},
          {"expansions", counters_.expansions},
          {"collapses", counters_.collapses},
          {"contact_begins", counters_.contact_begins},
          {"contact_ends", counters_.contact_ends},
          {"instant_contacts", counters_.instant_contacts},
          {"reschedules", counters_.reschedules},
          {"lazy_keeps", counters_.lazy_keeps},
          {"rebuilds", counters_.rebuilds},
          {"local_rebuilds", counters_.local_rebuilds},
          {"moved_leaves", counters_.moved_leaves},
          {"rebuilt_leaves", counters_.rebuilt_leaves},
          {"quality_checks", counters_.quality_checks},
          {"updates", counters_.updates},
          {"inserts", counters_.inserts},
          {"removes", counters_.removes},
          {"queries", counters_.queries}};
}

// ---------------------------------------------------------------------------------------------
// The tree and its tournaments.

std::vector<double> KineticBvh::centers_now(std::span<const std::uint32_t> alive) const {
  std::vector<double> centers(boxes_.capacity() * static_cast<std::size_t>(d_), 0.0);
  for (const std::uint32_t i : alive) {
    for (int k = 0; k < d_; ++k)
      centers[i * static_cast<std::size_t>(d_) + static_cast<std::size_t>(k)] =
          center(boxes_, i, k).evaluate(sim_.now());
  }
  return centers;
}

void KineticBvh::clear_all() {
  tree_.assign(0);  // its events cancelled
  for (Cert& c : certs_) {
    if (c.pair != kNoIndex) sim_.cancel(c.handle);
  }
  nodes_.clear();
  watch_head_.clear();
  pairs_.clear();
  free_pairs_.clear();
  root_pair_ = kNoIndex;
  live_pairs_ = 0;
  free_nodes_.clear();
  self_pair_.clear();
  certs_.clear();
  free_certs_.clear();
  live_certs_ = 0;
  clear_contacts();
  root_ = kNoIndex;
}

void KineticBvh::build() {
  clear_all();
  std::vector<std::uint32_t> alive = boxes_.alive_indices();
  leaf_of_.assign(boxes_.capacity(), kNoIndex);
  for (const std::uint32_t i : alive) {
    for (BoxEndpointKeys& k : keys_) k.refresh(i);
  }
  if (alive.empty()) return;
  const std::vector<double> centers = centers_now(alive);
  std::vector<std::array<std::uint32_t, 4>> topology;
  topology.reserve(2 * alive.size());
  TopologyBuilder builder{centers, boxes_, d_, topology};
  root_ = builder.build(alive, 0, alive.size(), kNoIndex);
  nodes_.resize(topology.size());
  for (std::size_t v = 0; v < topology.size(); ++v) {
    nodes_[v] = Node{topology[v][0], topology[v][1], topology[v][2], topology[v][3]};
    if (topology[v][3] != kNoIndex) leaf_of_[topology[v][3]] = static_cast<std::uint32_t>(v);
  }
  const std::size_t slots = nodes_.size() * static_cast<std::size_t>(d_) * 2;
  tree_.assign(slots);
  watch_head_.assign(slots, kNoIndex);
  self_pair_.assign(nodes_.size(), kNoIndex);
  // Children come after their parent in the array: decide bottom-up by walking it backwards.
  for (std::size_t v = nodes_.size(); v-- > 0;) {
    const auto node = static_cast<std::uint32_t>(v);
    for (int axis = 0; axis < d_; ++axis) {
      for (const BoxSide side : kSides) {
        if (leaf(node)) {
          tree_.set_leaf(slot(node, axis, side), nodes_[node].box);
        } else {
          (void)decide(node, axis, side);
        }
      }
    }
  }
  events_since_check_ = 0;
  // The list as it is now: no contact begins (a build is not an event; the boxes that touch
  // only now are found by the caller when it needs them: touching_only_at).
  quiet_ = true;
  building_ = true;
  if (nodes_.size() > 1) {
    root_pair_ = add_pair(root_, root_);
    classify(root_pair_);
  }
  building_ = false;
  quiet_ = false;
}

Scheduler::SignDecision KineticBvh::compare(std::uint32_t x, BoxSide sx, std::uint32_t y,
                                            BoxSide sy, int axis) const {
  const std::uint32_t kx = key(x, axis, sx), ky = key(y, axis, sy);
  const Time window_lo = std::max(boxes_.valid_from(BoxEndpointKeys::box_of(kx)),
                                  boxes_.valid_from(BoxEndpointKeys::box_of(ky)));
  return keys_[static_cast<std::size_t>(axis)].decide(scheduler_, kx, ky, sim_.now(), window_lo,
                                                      sim_.counters());
}

Scheduler::MaxDecision KineticBvh::SideKeys::decide(std::size_t s, std::uint32_t a,
                                                    std::uint32_t b) const {
  const auto axis = static_cast<int>((s / 2) % static_cast<std::size_t>(bvh->d_));
  const auto side = static_cast<BoxSide>(s % 2);
  // One decision of sign(left - right) and its failure (COMPUTEMAX over the two children's
  // winners): High takes the larger side, Low the smaller; identical sides the left child's.
  const std::uint32_t ka = BoxEndpointKeys::key(a, side), kb = BoxEndpointKeys::key(b, side);
  const Time window_lo = std::max(bvh->boxes_.valid_from(BoxEndpointKeys::box_of(ka)),
                                  bvh->boxes_.valid_from(BoxEndpointKeys::box_of(kb)));
  Scheduler::SignDecision d = bvh->keys_[static_cast<std::size_t>(axis)].decide(
      bvh->scheduler_, ka, kb, bvh->sim_.now(), window_lo, bvh->sim_.counters());
  return {side == BoxSide::High ? d.sign >= 0 : d.sign <= 0, d.failure, std::move(d.exact)};
}

bool KineticBvh::SideTopology::is_leaf(std::size_t s) const {
  return bvh->leaf(static_cast<std::uint32_t>(s / (2 * static_cast<std::size_t>(bvh->d_))));
}

bool KineticBvh::SideTopology::internal(std::size_t s) const {
  return bvh->internal(static_cast<std::uint32_t>(s / (2 * static_cast<std::size_t>(bvh->d_))));
}

std::array<std::size_t, 2> KineticBvh::SideTopology::children(std::size_t s) const {
  const std::size_t per_node = 2 * static_cast<std::size_t>(bvh->d_);
  const Node& n = bvh->nodes_[s / per_node];
  return {n.left * per_node + s % per_node, n.right * per_node + s % per_node};
}

std::size_t KineticBvh::SideTopology::parent(std::size_t s) const {
  const std::size_t per_node = 2 * static_cast<std::size_t>(bvh->d_);
  const std::uint32_t p = bvh->nodes_[s / per_node].parent;
  return p == kNoIndex ? kNoNode : p * per_node + s % per_node;
}

bool KineticBvh::decide(std::uint32_t node, int axis, BoxSide side) {
  return tree_.decide(slot(node, axis, side));
}

void KineticBvh::winner_changed(std::uint32_t node, int axis, BoxSide side) {
  // Up from the node while the winners change (a parent whose winner is the same leaf changes
  // nothing above it): at each, the certificates that compare this node side, whose functions
  // changed.
  tree_.climb(slot(node, axis, side), [&](std::size_t s) {
    ++counters_.winner_changes;
    for_each_watcher(s, [&](std::uint32_t c) {
      if ((!collect_ || keep_overlaps_) && pairs_[certs_[c].pair].state != State::Separated) {
        ++counters_.lazy_keeps;  // still sufficient (Cert)
        return;
      }
      ++counters_.reschedules;
      schedule_cert(c);
      if (collect_) touched_.push_back(c);
    });
  });
}

void KineticBvh::on_tournament_event(const Event& event) {
  ++counters_.tournament_events;
  const std::size_t s = tree_.take_event(event);
  if (tree_.decide(s)) {
    const auto node = static_cast<std::uint32_t>(s / (2 * static_cast<std::size_t>(d_)));
    winner_changed(node, static_cast<int>((s / 2) % static_cast<std::size_t>(d_)),
                   static_cast<BoxSide>(s % 2));
  }
}

// ---------------------------------------------------------------------------------------------
// The separation list.

const Scheduler::SignDecision& KineticBvh::decision(std::uint32_t a, std::uint32_t b, int k,
                                                    PairDecisions& out) const {
  const auto bit = static_cast<std::uint8_t>(1U << k);
  if ((out.known & bit) == 0) {
    const int axis = k / 2;
    out.d[static_cast<std::size_t>(k)] = k % 2 == 0
                                             ? compare(b, BoxSide::Low, a, BoxSide::High, axis)
                                             : compare(a, BoxSide::Low, b, BoxSide::High, axis);
    out.known |= bit;
  }
  return out.d[static_cast<std::size_t>(k)];
}

std::pair<int, bool> KineticBvh::separating(std::uint32_t a, std::uint32_t b,
                                            PairDecisions& out) const {
  for (int axis = 0; axis < d_; ++axis) {
    if (decision(a, b, 2 * axis, out).sign > 0) return {axis, true};
    if (decision(a, b, 2 * axis + 1, out).sign > 0) return {axis, false};
  }
  return {-1, false};
}

void KineticBvh::children_pairs(std::uint32_t a, std::uint32_t b, ChildPairs& out) const {
  out.clear();
  const Node& na = nodes_[a];
  const Node& nb = nodes_[b];
  if (a == b) {
    if (leaf(a)) return;
    if (!leaf(na.left)) out.emplace_back(na.left, na.left);
    if (!leaf(na.right)) out.emplace_back(na.right, na.right);
    out.emplace_back(na.left, na.right);
    return;
  }
  if (leaf(a) && leaf(b)) return;
  if (leaf(a)) {
    out.emplace_back(a, nb.left);
    out.emplace_back(a, nb.right);
  } else if (leaf(b)) {
    out.emplace_back(na.left, b);
    out.emplace_back(na.right, b);
  } else {
    out.emplace_back(na.left, nb.left);
    out.emplace_back(na.left, nb.right);
    out.emplace_back(na.right, nb.left);
    out.emplace_back(na.right, nb.right);
  }
}

std::uint32_t KineticBvh::add_pair(std::uint32_t a, std::uint32_t b) {
  if (a > b) std::swap(a, b);
  const std::uint32_t p = take_record(pairs_, free_pairs_);
  pairs_[p] = PairRecord{};
  pairs_[p].a = a;
  pairs_[p].b = b;
  if (a == b) self_pair_[a] = p;
  ++live_pairs_;
  return p;
}

void KineticBvh::remove_pair(std::uint32_t p) {
  if (pairs_[p].a == pairs_[p].b && self_pair_[pairs_[p].a] == p)
    self_pair_[pairs_[p].a] = kNoIndex;
  pairs_[p] = PairRecord{};
  free_pairs_.push_back(p);
  --live_pairs_;
}

std::size_t KineticBvh::watch_slot(std::uint32_t c, int end) const {
  const Cert& x = certs_[c];
  return end == 0 ? slot(x.lower_node, x.axis, x.lower_side)
                  : slot(x.upper_node, x.axis, x.upper_side);
}

void KineticBvh::link(std::uint32_t c, int end) {
  const std::size_t s = watch_slot(c, end);
  const std::uint32_t me = 2 * c + static_cast<std::uint32_t>(end);
  const std::uint32_t head = watch_head_[s];
  certs_[c].watch_next[static_cast<std::size_t>(end)] = head;
  certs_[c].watch_prev[static_cast<std::size_t>(end)] = kNoIndex;
  if (head != kNoIndex) certs_[head / 2].watch_prev[head % 2] = me;
  watch_head_[s] = me;
}

void KineticBvh::unlink(std::uint32_t c, int end) {
  const std::uint32_t next = certs_[c].watch_next[static_cast<std::size_t>(end)];
  const std::uint32_t prev = certs_[c].watch_prev[static_cast<std::size_t>(end)];
  if (prev != kNoIndex) {
    certs_[prev / 2].watch_next[prev % 2] = next;
  } else {
    watch_head_[watch_slot(c, end)] = next;
  }
  if (next != kNoIndex) certs_[next / 2].watch_prev[next % 2] = prev;
}

std::uint32_t KineticBvh::add_cert(std::uint32_t pair, int k,
                                   const Scheduler::SignDecision& decided) {
  const std::uint32_t c = take_record(certs_, free_certs_);
  // Decision k of (a, b): low(b) - high(a) for k even, low(a) - high(b) for k odd.
  const std::uint32_t a = pairs_[pair].a, b = pairs_[pair].b;
  Cert& x = certs_[c];
  x = Cert{};
  x.pair = pair;
  x.lower_node = k % 2 == 0 ? a : b;
  x.upper_node = k % 2 == 0 ? b : a;
  x.axis = static_cast<std::uint8_t>(k / 2);
  x.lower_side = BoxSide::High;
  x.upper_side = BoxSide::Low;
  x.next_of_pair = pairs_[pair].first_cert;
  pairs_[pair].first_cert = c;
  ++live_certs_;
  link(c, 0);
  link(c, 1);
  schedule_cert(c, &decided);
  return c;
}

void KineticBvh::schedule_cert(std::uint32_t c, const Scheduler::SignDecision* decided) {
  Cert& x = certs_[c];
  sim_.cancel(x.handle);
  // sign(upper - lower) and its failure from one decision: a certificate the decision finds
  // violated is due now.
  const Scheduler::SignDecision d =
      decided != nullptr ? *decided
                         : compare(x.upper_node, x.upper_side, x.lower_node, x.lower_side, x.axis);
  x.from = {tree_.winner(slot(x.lower_node, x.axis, x.lower_side)),
            tree_.winner(slot(x.upper_node, x.axis, x.upper_side))};
  if (!holds(c, d.sign)) {
    x.handle = sim_.schedule_now(owners_[1], c);
  } else if (d.failure != kTimeInfinity) {
    x.handle = sim_.schedule(d.failure, d.exact, owners_[1], c);
  }
}

bool KineticBvh::holds(std::uint32_t c, int sign) const {
  return pairs_[certs_[c].pair].state == State::Separated ? sign > 0 : sign <= 0;
}

void KineticBvh::drop_certs(std::uint32_t pair) {
  for (std::uint32_t c = pairs_[pair].first_cert; c != kNoIndex;) {
    Cert& x = certs_[c];
    const std::uint32_t next = x.next_of_pair;
    sim_.cancel(x.handle);
    unlink(c, 0);
    unlink(c, 1);
    x = Cert{};
    free_certs_.push_back(c);
    --live_certs_;
    c = next;
  }
  pairs_[pair].first_cert = kNoIndex;
}

void KineticBvh::make_separated(std::uint32_t pair, int axis, bool a_below_b,
                                const PairDecisions& decisions) {
  pairs_[pair].state = State::Separated;
  const int k = 2 * axis + (a_below_b ? 0 : 1);
  add_cert(pair, k, decisions.d[static_cast<std::size_t>(k)]);
  if (!building_) note_touching_now(pair, axis);
}

bool KineticBvh::overlap_now(std::uint32_t a, std::uint32_t b, int first_axis) const {
  const Time t = sim_.now();
  for (int i = 0; i < d_; ++i) {
    const int axis = (first_axis + i) % d_;
    const BoxEndpointKeys& k = keys_[static_cast<std::size_t>(axis)];
    if (k.compare_at(key(b, axis, BoxSide::Low), key(a, axis, BoxSide::High), t) > 0) return false;
    if (k.compare_at(key(a, axis, BoxSide::Low), key(b, axis, BoxSide::High), t) > 0) return false;
  }
  return true;
}

void KineticBvh::note_touching_now(std::uint32_t pair, int axis) {
  const std::uint32_t a = pairs_[pair].a, b = pairs_[pair].b;
  if (!overlap_now(a, b, axis)) return;
  // Down the pairs of children whose closed boxes overlap now, to the leaves.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> stack{{a, b}};
  ChildPairs children;
  while (!stack.empty()) {
    const auto [x, y] = stack.back();
    stack.pop_back();
    if (leaf(x) && leaf(y)) {
      const std::uint32_t bx = nodes_[x].box, by = nodes_[y].box;
      if (x != y && !contact_set().contains(bx, by)) {
        ++counters_.instant_contacts;
        ended_.note_now(sim_, bx, by);
      }
      continue;
    }
    children_pairs(x, y, children);
    for (const auto& [u, v] : children) {
      if (u == v || overlap_now(u, v, axis)) stack.emplace_back(u, v);
    }
  }
}

void KineticBvh::note_contact(bool begins, std::uint32_t box_a, std::uint32_t box_b) {
  if (quiet_) {
    if (journal_quiet_)
      (begins ? quiet_begun_ : quiet_ended_).push_back(PairSet::key(box_a, box_b));
    return;
  }
  ++(begins ? counters_.contact_begins : counters_.contact_ends);
  log_contact(begins, box_a, box_b);
}

void KineticBvh::make_overlapping(std::uint32_t pair, const PairDecisions& decisions) {
  const std::uint32_t a = pairs_[pair].a, b = pairs_[pair].b;
  // The state first: the certificates are scheduled as an overlapping pair's.
  const bool contact = leaf(a) && leaf(b);
  pairs_[pair].state = contact ? State::Contact : State::Expanded;
  for (int k = 0; k < 2 * d_; ++k) add_cert(pair, k, decisions.d[static_cast<std::size_t>(k)]);
  if (contact) {
    begin_contact(nodes_[a].box, nodes_[b].box);
    note_contact(true, nodes_[a].box, nodes_[b].box);
  } else {
    ++counters_.expansions;
    expand_children(pair);
  }
}

void KineticBvh::expand_children(std::uint32_t pair) {
  ChildPairs children;
  children_pairs(pairs_[pair].a, pairs_[pair].b, children);
  // Every child's record first (add_pair may move pairs_), then their classification.
  pairs_[pair].child_count = 0;
  for (const auto& [x, y] : children) {
    const std::uint32_t c = add_pair(x, y);
    PairRecord& r = pairs_[pair];
    r.child[r.child_count++] = c;
  }
  for (std::uint8_t i = 0; i < pairs_[pair].child_count; ++i) classify(pairs_[pair].child[i]);
}

void KineticBvh::classify(std::uint32_t pair) {
  if (pairs_[pair].a == pairs_[pair].b) {
    pairs_[pair].state = State::Self;
    expand_children(pair);
    return;
  }
  PairDecisions decisions;
  reclassify(pair, decisions);
}

void KineticBvh::reclassify(std::uint32_t pair, PairDecisions& decisions) {
  const auto [axis, a_below_b] = separating(pairs_[pair].a, pairs_[pair].b, decisions);
  if (axis >= 0) {
    make_separated(pair, axis, a_below_b, decisions);
  } else {
    make_overlapping(pair, decisions);
  }
}

void KineticBvh::collapse(std::uint32_t pair) {
  const PairRecord r = pairs_[pair];
  for (std::uint8_t i = 0; i < r.child_count; ++i) {
    const std::uint32_t child = r.child[i];
    const State s = pairs_[child].state;
    if (s == State::Expanded || s == State::Self) collapse(child);
    if (s == State::Contact) {
      end_contact(nodes_[pairs_[child].a].box, nodes_[pairs_[child].b].box);
      note_contact(false, nodes_[pairs_[child].a].box, nodes_[pairs_[child].b].box);
    }
    drop_certs(child);
    remove_pair(child);
  }
  pairs_[pair].child_count = 0;
}

void KineticBvh::on_cert_event(std::uint32_t c) {
  certs_[c].handle = EventHandle{};  // popped
  const std::uint32_t pair = certs_[c].pair;
  const State state = pairs_[pair].state;
  const std::uint32_t a = pairs_[pair].a, b = pairs_[pair].b;
  // The certificate's decision, made now; it is decision k of the pair (upper b: k even).
  const int k = 2 * certs_[c].axis + (certs_[c].upper_node == b ? 0 : 1);
  PairDecisions decisions;
  const Scheduler::SignDecision& now = decision(a, b, k, decisions);
  if (state == State::Separated) {
    ++counters_.separation_events;
    if (holds(c, now.sign)) {  // still apart
      schedule_cert(c, &now);
      return;
    }
    drop_certs(pair);
    reclassify(pair, decisions);
    return;
  }
  ++counters_.overlap_events;
  if (holds(c, now.sign)) {  // still overlapping on this axis
    schedule_cert(c, &now);
    return;
  }
  if (state == State::Contact) {
    end_contact(nodes_[a].box, nodes_[b].box);
    note_contact(false, nodes_[a].box, nodes_[b].box);
  } else {
    ++counters_.collapses;
    collapse(pair);
  }
  drop_certs(pair);
  pairs_[pair].state = State::Separated;
  reclassify(pair, decisions);  // separated on this certificate's axis, normally
}

// ---------------------------------------------------------------------------------------------
// The contract.

void KineticBvh::initialize() {
  for (const std::uint32_t i : boxes_.alive_indices()) require_box(i, "KineticBvh::initialize");
  sync_.note();
  build();
  // Boxes that touch at the start and part just after it: a query at the start reports them.
  for (const auto& [a, b] : touching_only_at(boxes_, contact_set(), sim_.now()))
    ended_.note_now(sim_, a, b);
}

EventKind KineticBvh::process(const Event& event) {
  const std::uint64_t before = counters_.contact_begins + counters_.contact_ends;
  if (event.owner == tree_.owner()) {
    on_tournament_event(event);
  } else {
    on_cert_event(event.payload);
  }
  if (rebuild_policy_ &&
      ++events_since_check_ >= (check_interval_ != 0
                                    ? check_interval_
                                    : std::max<std::uint64_t>(1024, 4 * boxes_.size())))
    maybe_rebuild();
  return counters_.contact_begins + counters_.contact_ends != before ? EventKind::External
                                                                     : EventKind::Internal;
}

void KineticBvh::maybe_rebuild() {
  events_since_check_ = 0;
  ++counters_.quality_checks;
  if (boxes_.size() < 2) return;
  std::vector<std::uint32_t> inner, leaves;
  const std::vector<double> centers = centers_now(boxes_.alive_indices());
  subtree(root_, inner, leaves);
  const double now_cost = cost(inner);
  const double fresh = fresh_cost(leaves, centers);
  if (fresh <= 0.0 || now_cost <= rebuild_ratio() * fresh) return;
  ++counters_.rebuilds;
  // The excess cost to remove: a subtree's rebuild removes its own excess (its cost now minus
  // a fresh build's). Down from the root into a child whose excess alone is enough and holds
  // nearly all of the two children's (the other's at most a quarter of it: an excess spread
  // over both is better removed at once, by their parent), while there is one.
  const double needed = now_cost - rebuild_target() * fresh;
  std::uint32_t v = root_;
  for (;;) {
    std::array<double, 2> excess{0.0, 0.0};
    const std::array<std::uint32_t, 2> child{nodes_[v].left, nodes_[v].right};
    for (std::size_t k = 0; k < 2; ++k) {
      if (!internal(child[k])) continue;
      subtree(child[k], inner, leaves);
      excess[k] = cost(inner) - fresh_cost(leaves, centers);
    }
    const std::size_t k = excess[1] > excess[0] ? 1 : 0;
    if (!internal(child[k]) || excess[k] < needed || excess[1 - k] > excess[k] / 4) break;
    v = child[k];
  }
  if (v != root_) {
    rebuild_subtree(v, centers);
    return;
  }
  counters_.rebuilt_leaves += boxes_.size();
  // The contacts stay what they are; a pair the rebuilt list decides otherwise (the old one was
  // within a certificate's delay of changing) is logged as the event it is.
  std::vector<std::uint64_t> before(contact_set().keys().begin(), contact_set().keys().end());
  build();
  std::sort(before.begin(), before.end());
  std::vector<std::uint64_t> after(contact_set().keys().begin(), contact_set().keys().end());
  std::sort(after.begin(), after.end());
  std::vector<std::uint64_t> ended, begun;
  std::set_difference(before.begin(), before.end(), after.begin(), after.end(),
                      std::back_inserter(ended));
  std::set_difference(after.begin(), after.end(), before.begin(), before.end(),
                      std::back_inserter(begun));
  for (const std::uint64_t k : ended) note_contact(false, PairSet::first(k), PairSet::second(k));
  for (const std::uint64_t k : begun) note_contact(true, PairSet::first(k), PairSet::second(k));
}

void KineticBvh::subtree(std::uint32_t node, std::vector<std::uint32_t>& internal_nodes,
                         std::vector<std::uint32_t>& boxes) const {
  internal_nodes.clear();
  boxes.clear();
  std::vector<std::uint32_t> stack{node};
  while (!stack.empty()) {
    const std::uint32_t v = stack.back();
    stack.pop_back();
    if (leaf(v)) {
      boxes.push_back(nodes_[v].box);
      continue;
    }
    internal_nodes.push_back(v);
    stack.push_back(nodes_[v].right);
    stack.push_back(nodes_[v].left);
  }
}

void KineticBvh::rebuild_subtree(std::uint32_t node, const std::vector<double>& centers) {
  quiet_ = true;
  collect_ = true;
  keep_overlaps_ = true;  // the subtree keeps its boxes: kept overlap certificates still hold
  journal_quiet_ = true;
  touched_.clear();
  quiet_begun_.clear();
  quiet_ended_.clear();
  // Every pair with a node strictly below `node` descends from a pair of `node` with a node
  // outside (`outer`) or from its self pair: collapsed, nothing in the list reads the subtree
  // below `node` any more.
  std::vector<std::uint32_t> outer = pairs_of(node);
  clear_pairs(outer);
  const std::uint32_t self = self_pair_[node];
  collapse(self);
  // The nodes below go (their tournaments' events with them); a median build over the leaves
  // at now takes their place, `node` its root (its parent, its slots and its pairs kept).
  std::vector<std::uint32_t> inner, boxes;
  subtree(node, inner, boxes);
  ++counters_.local_rebuilds;
  counters_.rebuilt_leaves += boxes.size();
  for (const std::uint32_t v : inner) {
    if (v == node) continue;
    release_node(v);
  }
  for (const std::uint32_t b : boxes) release_node(leaf_of_[b]);
  std::vector<std::array<std::uint32_t, 4>> topology;
  topology.reserve(2 * boxes.size());
  TopologyBuilder builder{centers, boxes_, d_, topology};
  (void)builder.build(boxes, 0, boxes.size(), kNoIndex);
  std::vector<std::uint32_t> id(topology.size(), node);
  for (std::size_t t = 1; t < topology.size(); ++t) id[t] = new_node();
  for (std::size_t t = 0; t < topology.size(); ++t) {
    const auto& [parent, left, right, box] = topology[t];
    Node& n = nodes_[id[t]];
    if (t > 0) n.parent = id[parent];
    n.left = left == kNoIndex ? kNoIndex : id[left];
    n.right = right == kNoIndex ? kNoIndex : id[right];
    n.box = box;
    if (box != kNoIndex) leaf_of_[box] = id[t];
  }
  // Children come after their parent in the topology: decided bottom-up, `node` last (a new
  // winner of its own climbs to its ancestors and reschedules their watchers).
  for (std::size_t t = topology.size(); t-- > 1;) {
    for (int axis = 0; axis < d_; ++axis) {
      for (const BoxSide side : kSides) {
        if (leaf(id[t])) {
          tree_.set_leaf(slot(id[t], axis, side), nodes_[id[t]].box);
        } else {
          (void)decide(id[t], axis, side);
        }
      }
    }
  }
  for (int axis = 0; axis < d_; ++axis) {
    for (const BoxSide side : kSides) {
      if (decide(node, axis, side)) winner_changed(node, axis, side);
    }
  }
  for (const std::uint32_t p : outer) {
    PairDecisions decisions;
    reclassify(p, decisions);
  }
  classify(self);
  keep_overlaps_ = false;
  settle_touched();
  quiet_ = false;
  journal_quiet_ = false;
  // The contacts the new list decides otherwise (the old one was within a certificate's delay
  // of changing): the events they are.
  std::sort(quiet_begun_.begin(), quiet_begun_.end());
  std::sort(quiet_ended_.begin(), quiet_ended_.end());
  std::vector<std::uint64_t> ended, begun;
  std::set_difference(quiet_ended_.begin(), quiet_ended_.end(), quiet_begun_.begin(),
                      quiet_begun_.end(), std::back_inserter(ended));
  std::set_difference(quiet_begun_.begin(), quiet_begun_.end(), quiet_ended_.begin(),
                      quiet_ended_.end(), std::back_inserter(begun));
  for (const std::uint64_t k : ended) note_contact(false, PairSet::first(k), PairSet::second(k));
  for (const std::uint64_t k : begun) note_contact(true, PairSet::first(k), PairSet::second(k));
}

std::uint32_t KineticBvh::new_node() {
  const std::uint32_t v = take_record(nodes_, free_nodes_);
  const std::size_t slots = nodes_.size() * static_cast<std::size_t>(d_) * 2;
  if (tree_.size() < slots) {  // appended: its slots too
    tree_.grow(slots);
    watch_head_.resize(slots, kNoIndex);
    self_pair_.resize(nodes_.size(), kNoIndex);
  }
  nodes_[v] = Node{};
  return v;
}

void KineticBvh::release_node(std::uint32_t v) {
  for (int axis = 0; axis < d_; ++axis) {
    for (const BoxSide side : kSides) {
      tree_.release(slot(v, axis, side));
    }
  }
  nodes_[v] = Node{kNoIndex, kFreeNode, kNoIndex, kNoIndex};
  self_pair_[v] = kNoIndex;
  free_nodes_.push_back(v);
}

void KineticBvh::node_box(std::uint32_t node, std::array<double, 3>& lo,
                          std::array<double, 3>& hi) const {
  const Time t = sim_.now();
  for (int k = 0; k < d_; ++k) {
    const std::uint32_t top = tree_.winner(slot(node, k, BoxSide::High));
    const std::uint32_t bottom = tree_.winner(slot(node, k, BoxSide::Low));
    hi[static_cast<std::size_t>(k)] =
        center(boxes_, top, k).evaluate(t) + half_extent(boxes_, top, k).c[0];
    lo[static_cast<std::size_t>(k)] =
        center(boxes_, bottom, k).evaluate(t) - half_extent(boxes_, bottom, k).c[0];
  }
}

std::uint32_t KineticBvh::insertion_leaf(std::uint32_t box) const {
  std::array<double, 3> blo{}, bhi{};
  for (int k = 0; k < d_; ++k) {
    const double c = center(boxes_, box, k).evaluate(sim_.now());
    const double h = half_extent(boxes_, box, k).c[0];
    blo[static_cast<std::size_t>(k)] = c - h;
    bhi[static_cast<std::size_t>(k)] = c + h;
  }
  // The growth in surface measure of a child's box when the new box joins it.
  const auto growth = [&](std::uint32_t child) {
    std::array<double, 3> lo{}, hi{}, len{1.0, 1.0, 1.0}, merged{1.0, 1.0, 1.0};
    node_box(child, lo, hi);
    for (int k = 0; k < d_; ++k) {
      const auto x = static_cast<std::size_t>(k);
      len[x] = std::max(0.0, hi[x] - lo[x]);
      merged[x] = std::max(hi[x], bhi[x]) - std::min(lo[x], blo[x]);
    }
    return surface(merged) - surface(len);
  };
  std::uint32_t v = root_;
  while (!leaf(v)) {
    const std::uint32_t l = nodes_[v].left, r = nodes_[v].right;
    v = growth(r) < growth(l) ? r : l;
  }
  return v;
}

std::vector<std::uint32_t> KineticBvh::pairs_of(std::uint32_t node) const {
  std::vector<std::uint32_t> out;
  for (int axis = 0; axis < d_; ++axis) {
    for (const BoxSide side : kSides) {
      for_each_watcher(slot(node, axis, side),
                       [&](std::uint32_t c) { out.push_back(certs_[c].pair); });
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

void KineticBvh::clear_pair(std::uint32_t pair) {
  const PairRecord& r = pairs_[pair];
  if (r.state == State::Expanded || r.state == State::Self) {
    collapse(pair);
  } else if (r.state == State::Contact) {
    end_contact(nodes_[r.a].box, nodes_[r.b].box);
    note_contact(false, nodes_[r.a].box, nodes_[r.b].box);
  }
  drop_certs(pair);
  pairs_[pair].state = State::Separated;
}

void KineticBvh::clear_pairs(std::vector<std::uint32_t>& pairs) {
  // A leaf's pair may be below another of its pairs (a leaf against a subtree): the collapse of
  // the upper one removes it. Nothing is added meanwhile, so a removed record stays free.
  for (const std::uint32_t p : pairs) {
    if (pairs_[p].a != kNoIndex) clear_pair(p);
  }
  std::erase_if(pairs, [&](std::uint32_t p) { return pairs_[p].a == kNoIndex; });
}

void KineticBvh::move_pairs(const std::vector<std::uint32_t>& pairs, std::uint32_t from,
                            std::uint32_t to) {
  for (const std::uint32_t p : pairs) {
    PairRecord& r = pairs_[p];
    const std::uint32_t other = r.a == from ? r.b : r.a;
    r.a = std::min(other, to);
    r.b = std::max(other, to);
  }
  for (const std::uint32_t p : pairs) {
    PairDecisions decisions;
    reclassify(p, decisions);
  }
}

void KineticBvh::order_self_children(std::uint32_t node, std::uint32_t extra) {
  PairRecord& r = pairs_[self_pair_[node]];
  std::array<std::uint32_t, 5> have{};
  std::size_t count = 0;
  for (std::uint8_t i = 0; i < r.child_count; ++i) have[count++] = r.child[i];
  if (extra != kNoIndex) have[count++] = extra;
  ChildPairs want;
  children_pairs(node, node, want);
  r.child_count = 0;
  for (const auto& [x, y] : want) {
    for (std::size_t i = 0; i < count; ++i) {
      const PairRecord& c = pairs_[have[i]];
      if (c.a == std::min(x, y) && c.b == std::max(x, y)) {
        r.child[r.child_count++] = have[i];
        break;
      }
    }
  }
  assert(r.child_count == want.size && r.child_count == count);
}

void KineticBvh::redecide_ancestors(std::uint32_t node) {
  for (int axis = 0; axis < d_; ++axis) {
    for (const BoxSide side : kSides) {
      // A parent whose winner is the same leaf changes nothing above it; else its watchers
      // and the ancestors above follow (winner_changed).
      const std::uint32_t parent = nodes_[node].parent;
      if (parent != kNoIndex && decide(parent, axis, side)) winner_changed(parent, axis, side);
    }
  }
}

void KineticBvh::settle_touched() {
  // A change may leave a pair's state wrong now (its certificate was scheduled at now): handle
  // those as the events they would have been, quietly (a timeline change, not an event). A
  // handled pair may remove others' certificates (a collapse): skip those no longer alive.
  collect_ = false;
  std::vector<std::uint32_t> stale;
  for (const std::uint32_t c : touched_) {
    const EventHandle h = certs_[c].handle;
    if (certs_[c].pair != kNoIndex && !h.is_null() && sim_.queue().contains(h) &&
        sim_.queue().get(h).time <= sim_.now()) {
      stale.push_back(c);
    }
  }
  // The separated pairs whose certificates changed and still hold: apart just after now, their
  // boxes may touch now (a flight-plan update that leaves a box touching another as it parts).
  std::vector<std::uint32_t> kept;
  for (const std::uint32_t c : touched_) {
    if (certs_[c].pair != kNoIndex && pairs_[certs_[c].pair].state == State::Separated)
      kept.push_back(c);
  }
  touched_.clear();
  for (const std::uint32_t c : stale) {
    if (certs_[c].pair == kNoIndex) continue;
    sim_.cancel(certs_[c].handle);
    on_cert_event(c);
  }
  for (const std::uint32_t c : kept) {
    if (certs_[c].pair != kNoIndex && pairs_[certs_[c].pair].state == State::Separated)
      note_touching_now(certs_[c].pair, certs_[c].axis);
  }
}

void KineticBvh::insert(std::uint32_t index) {
  sync_.require_inserted("KineticBvh::insert", index);
  require_box(index, "KineticBvh::insert");
  ++counters_.inserts;
  if (leaf_of_.size() < boxes_.capacity()) leaf_of_.resize(boxes_.capacity(), kNoIndex);
  for (BoxEndpointKeys& k : keys_) k.refresh(index);
  if (root_ == kNoIndex) {  // the first box: a one-leaf tree
    build();
    return;
  }
  attach_leaf(index);
}

void KineticBvh::attach_leaf(std::uint32_t index) {
  quiet_ = true;
  collect_ = true;
  // Nodes only gain boxes: a kept overlap certificate still implies its pair's inequality.
  keep_overlaps_ = true;
  touched_.clear();
  // The new node n takes the leaf's place, with the leaf and the new leaf x as children.
  const std::uint32_t sibling = insertion_leaf(index);
  const std::uint32_t n = new_node();
  const std::uint32_t x = new_node();
  const std::uint32_t parent = nodes_[sibling].parent;
  nodes_[x] = Node{n, kNoIndex, kNoIndex, index};
  nodes_[n] = Node{parent, sibling, x, kNoIndex};
  leaf_of_[index] = x;
  nodes_[sibling].parent = n;
  if (parent == kNoIndex) {
    root_ = n;
  } else if (nodes_[parent].left == sibling) {
    nodes_[parent].left = n;
  } else {
    nodes_[parent].right = n;
  }
  for (int axis = 0; axis < d_; ++axis) {
    for (const BoxSide side : kSides) {
      tree_.set_leaf(slot(x, axis, side), index);
      (void)decide(n, axis, side);
    }
  }
  redecide_ancestors(n);
  // The leaf's pairs are n's now (n's box contains the leaf's): reclassified, they expand to
  // the leaf's and x's where they overlap.
  std::vector<std::uint32_t> moved = pairs_of(sibling);
  clear_pairs(moved);
  move_pairs(moved, sibling, n);
  // n's self pair, with the pair (leaf, x) below it, in the parent's self pair.
  const std::uint32_t self = add_pair(n, n);
  if (parent == kNoIndex) {
    root_pair_ = self;
  } else {
    order_self_children(parent, self);
  }
  classify(self);
  keep_overlaps_ = false;
  settle_touched();
  quiet_ = false;
}

void KineticBvh::remove(std::uint32_t index) {
  sync_.require_removed("KineticBvh::remove", index);
  ++counters_.removes;
  if (boxes_.size() <= 1) {  // at most one box left: its one-leaf tree
    build();
    return;
  }
  detach_leaf(index);
}

void KineticBvh::detach_leaf(std::uint32_t index) {
  const std::uint32_t x = leaf_of_[index];
  quiet_ = true;
  collect_ = true;
  touched_.clear();
  const std::uint32_t n = nodes_[x].parent;
  const std::uint32_t sibling = nodes_[n].left == x ? nodes_[n].right : nodes_[n].left;
  const std::uint32_t grand = nodes_[n].parent;
  // Certificates kept from the box where it is no longer the winner: its side is leaving.
  reschedule_computed_from(x, index);
  // n's pairs become the sibling's; the pairs below them (x's among them) go.
  std::vector<std::uint32_t> moved = pairs_of(n);
  clear_pairs(moved);
  // n's self pair goes; the sibling's self pair (when it has one) stays, everything else below
  // it ((sibling, x) and its descendants) goes.
  const std::uint32_t self = self_pair_[n];
  const PairRecord r = pairs_[self];
  for (std::uint8_t i = 0; i < r.child_count; ++i) {
    const std::uint32_t c = r.child[i];
    if (pairs_[c].a == pairs_[c].b) continue;  // the sibling's self pair
    clear_pair(c);
    remove_pair(c);
  }
  pairs_[self].child_count = 0;
  if (grand != kNoIndex) {  // n's self pair leaves its parent's list
    PairRecord& g = pairs_[self_pair_[grand]];
    std::uint8_t kept = 0;
    for (std::uint8_t i = 0; i < g.child_count; ++i) {
      if (g.child[i] != self) g.child[kept++] = g.child[i];
    }
    g.child_count = kept;
  }
  remove_pair(self);
  assert(pairs_of(x).empty());
  // The sibling takes n's place.
  nodes_[sibling].parent = grand;
  if (grand == kNoIndex) {
    root_ = sibling;
  } else if (nodes_[grand].left == n) {
    nodes_[grand].left = sibling;
  } else {
    nodes_[grand].right = sibling;
  }
  release_node(x);
  release_node(n);
  leaf_of_[index] = kNoIndex;
  redecide_ancestors(sibling);
  move_pairs(moved, n, sibling);
  if (grand == kNoIndex) {
    root_pair_ = self_pair_[sibling];  // internal: boxes_.size() >= 2
  } else {
    order_self_children(grand, leaf(sibling) ? kNoIndex : self_pair_[sibling]);
  }
  settle_touched();
  quiet_ = false;
}

bool KineticBvh::far_from_sibling(std::uint32_t box) const {
  const std::uint32_t x = leaf_of_[box];
  const std::uint32_t parent = nodes_[x].parent;
  if (parent == kNoIndex || boxes_.size() < 3) return false;
  const std::uint32_t sibling =
      nodes_[parent].left == x ? nodes_[parent].right : nodes_[parent].left;
  // The sibling's box and the box at now (the sibling's winners are other boxes): far when the
  // box would make its parent's surface measure more than twice the sibling's.
  std::array<double, 3> lo{}, hi{}, len{1.0, 1.0, 1.0}, merged{1.0, 1.0, 1.0};
  node_box(sibling, lo, hi);
  for (int k = 0; k < d_; ++k) {
    const auto a = static_cast<std::size_t>(k);
    const double c = center(boxes_, box, k).evaluate(sim_.now());
    const double h = half_extent(boxes_, box, k).c[0];
    len[a] = std::max(0.0, hi[a] - lo[a]);
    merged[a] = std::max(hi[a], c + h) - std::min(lo[a], c - h);
  }
  return surface(merged) > 2.0 * surface(len) + 1e-300;
}

void KineticBvh::motion_changed(std::uint32_t index) {
  sync_.require_updated("KineticBvh::motion_changed", index);
  require_box(index, "KineticBvh::motion_changed");
  ++counters_.updates;
  for (BoxEndpointKeys& k : keys_) k.refresh(index);
  if (far_from_sibling(index)) {
    // Moved away (a jump): kept in place, its ancestors would stretch to its new place and
    // their pairs expand. Its leaf leaves the tree (as at a remove: every certificate computed
    // from its old sides rescheduled) and goes in again where it is now (as at an insert).
    ++counters_.moved_leaves;
    detach_leaf(index);
    attach_leaf(index);
    return;
  }
  // The box's sides are new functions. Only the node sides whose winner is this box, and the
  // decisions between it and a sibling's winner, change: walk up from the leaf while the box is
  // the winner of the child on the path, deciding the parent again and rescheduling the
  // certificates that watch a side the box provides. O(depth) decisions per side at most, and
  // usually a few (the box is rarely its ancestors' extreme).
  touched_.clear();
  collect_ = true;
  const std::uint32_t leaf_node = leaf_of_[index];
  const auto reschedule_watchers = [&](std::uint32_t node, int axis, BoxSide side) {
    for_each_watcher(slot(node, axis, side), [&](std::uint32_t c) {
      schedule_cert(c);
      touched_.push_back(c);
    });
  };
  for (int axis = 0; axis < d_; ++axis) {
    for (const BoxSide side : kSides) {
      reschedule_watchers(leaf_node, axis, side);
      for (std::uint32_t child = leaf_node; nodes_[child].parent != kNoIndex;) {
        const std::uint32_t parent = nodes_[child].parent;
        // The parent's decision compares the child's winner, this box (the walk goes on only
        // while it is).
        if (decide(parent, axis, side)) {
          winner_changed(parent, axis, side);  // watchers and ancestors
          break;
        }
        if (tree_.winner(slot(parent, axis, side)) != index) break;  // the sibling's, unchanged
        reschedule_watchers(parent, axis, side);
        child = parent;
      }
    }
  }
  // Certificates kept from the box's old motion where it is no longer the winner.
  reschedule_computed_from(leaf_node, index);
  quiet_ = true;
  settle_touched();
  quiet_ = false;
}

void KineticBvh::reschedule_computed_from(std::uint32_t leaf_node, std::uint32_t box) {
  for (std::uint32_t v = leaf_node; v != kNoIndex; v = nodes_[v].parent) {
    for (int axis = 0; axis < d_; ++axis) {
      for (const BoxSide side : kSides) {
        const std::size_t s = slot(v, axis, side);
        if (tree_.winner(s) == box) continue;  // rescheduled with the side's changes
        for_each_watcher(s, [&](std::uint32_t c) {
          if (certs_[c].from[0] != box && certs_[c].from[1] != box) return;
          ++counters_.reschedules;
          schedule_cert(c);
          touched_.push_back(c);
        });
      }
    }
  }
}

bool KineticBvh::under(std::uint32_t box, std::uint32_t node) const {
  if (box >= leaf_of_.size() || leaf_of_[box] == kNoIndex) return false;
  for (std::uint32_t v = leaf_of_[box]; v != kNoIndex; v = nodes_[v].parent) {
    if (v == node) return true;
  }
  return false;
}

// ---------------------------------------------------------------------------------------------
// Quality and reports.

double KineticBvh::cost(std::span<const std::uint32_t> internal_nodes) const {
  // Surface area of each node's box at now (from its winners' sides, in double).
  double total = 0.0;
  const Time t = sim_.now();
  for (const std::uint32_t v : internal_nodes) {
    std::array<double, 3> len{1.0, 1.0, 1.0};
    for (int k = 0; k < d_; ++k) {
      const std::uint32_t hi = tree_.winner(slot(v, k, BoxSide::High));
      const std::uint32_t lo = tree_.winner(slot(v, k, BoxSide::Low));
      const double top = center(boxes_, hi, k).evaluate(t) + half_extent(boxes_, hi, k).c[0];
      const double bottom = center(boxes_, lo, k).evaluate(t) - half_extent(boxes_, lo, k).c[0];
      len[static_cast<std::size_t>(k)] = std::max(0.0, top - bottom);
    }
    total += surface(len);
  }
  return total;
}

double KineticBvh::quality_ratio() const {
  if (boxes_.size() < 2) return 1.0;
  std::vector<std::uint32_t> inner, leaves;
  subtree(root_, inner, leaves);
  const double fresh = fresh_cost(leaves, centers_now(boxes_.alive_indices()));
  return fresh > 0.0 ? cost(inner) / fresh : 1.0;
}

double KineticBvh::fresh_cost(std::vector<std::uint32_t>& boxes,
                              const std::vector<double>& centers) const {
  // The same builder over the centers at now, the node boxes by brute force bottom-up.
  std::vector<std::array<std::uint32_t, 4>> topology;
  topology.reserve(2 * boxes.size());
  TopologyBuilder builder{centers, boxes_, d_, topology};
  (void)builder.build(boxes, 0, boxes.size(), kNoIndex);
  std::vector<std::array<double, 6>> bounds(topology.size());
  double fresh = 0.0;
  for (std::size_t v = topology.size(); v-- > 0;) {
    std::array<double, 6>& b = bounds[v];
    if (topology[v][3] != kNoIndex) {
      const std::uint32_t i = topology[v][3];
      for (int k = 0; k < d_; ++k) {
        const double c = centers[i * static_cast<std::size_t>(d_) + static_cast<std::size_t>(k)];
        const double h = half_extent(boxes_, i, k).c[0];
        b[static_cast<std::size_t>(2 * k)] = c - h;
        b[static_cast<std::size_t>(2 * k + 1)] = c + h;
      }
      continue;
    }
    const auto& l = bounds[topology[v][1]];
    const auto& r = bounds[topology[v][2]];
    std::array<double, 3> len{1.0, 1.0, 1.0};
    for (int k = 0; k < d_; ++k) {
      b[static_cast<std::size_t>(2 * k)] =
          std::min(l[static_cast<std::size_t>(2 * k)], r[static_cast<std::size_t>(2 * k)]);
      b[static_cast<std::size_t>(2 * k + 1)] =
          std::max(l[static_cast<std::size_t>(2 * k + 1)], r[static_cast<std::size_t>(2 * k + 1)]);
      len[static_cast<std::size_t>(k)] =
          b[static_cast<std::size_t>(2 * k + 1)] - b[static_cast<std::size_t>(2 * k)];
    }
    fresh += surface(len);
  }
  return fresh;
}

bool KineticBvh::audit(Time t) const {
  const auto sign_at_t = [&](std::uint32_t x, BoxSide sx, std::uint32_t y, BoxSide sy, int axis) {
    // sign(side x - side y) at t
    return -keys_[static_cast<std::size_t>(axis)].compare_at(key(y, axis, sy), key(x, axis, sx), t);
  };
  for (std::uint32_t v = 0; v < nodes_.size(); ++v) {
    if (!internal(v)) continue;
    for (int k = 0; k < d_; ++k) {
      for (const BoxSide side : kSides) {
        const std::uint32_t other =
            tree_.winner(slot(v, k, side)) == tree_.winner(slot(nodes_[v].left, k, side))
                ? nodes_[v].right
                : nodes_[v].left;
        const int s = sign_at_t(v, side, other, side, k);  // the winner minus the loser
        if (side == BoxSide::High ? s < 0 : s > 0) return false;
      }
    }
  }
  for (const PairRecord& r : pairs_) {
    if (r.a == kNoIndex) continue;
    for (std::uint32_t c = r.first_cert; c != kNoIndex; c = certs_[c].next_of_pair) {
      const Cert& x = certs_[c];
      const int s = sign_at_t(x.upper_node, x.upper_side, x.lower_node, x.lower_side, x.axis);
      if (!holds(c, s)) return false;
    }
  }
  return true;
}

KineticBvh::ListSizes KineticBvh::list_sizes() const {
  ListSizes s;
  for (const PairRecord& r : pairs_) {
    if (r.a == kNoIndex) continue;
    switch (r.state) {
      case State::Separated:
        ++s.separated;
        break;
      case State::Expanded:
        ++s.expanded;
        break;
      case State::Contact:
        ++s.contact;
        break;
      case State::Self:
        ++s.self;
        break;
    }
  }
  return s;
}

std::size_t KineticBvh::certificates() const {
  const std::size_t inner = boxes_.size() > 0 ? boxes_.size() - 1 : 0;
  return inner * 2 * static_cast<std::size_t>(d_) + live_certs_;
}

std::size_t KineticBvh::certificates_per_object_max() const {
  // A box is the winner of at most every side of its ancestors; count the certificates whose
  // sides it currently provides, at most.
  std::vector<std::size_t> per_box(boxes_.capacity(), 0);
  for (const Cert& c : certs_) {
    if (c.pair == kNoIndex) continue;
    ++per_box[tree_.winner(slot(c.lower_node, c.axis, c.lower_side))];
    ++per_box[tree_.winner(slot(c.upper_node, c.axis, c.upper_side))];
  }
  for (std::uint32_t v = 0; v < nodes_.size(); ++v) {
    if (!internal(v)) continue;
    for (int k = 0; k < d_; ++k) {
      for (const BoxSide side : kSides) {
        ++per_box[tree_.winner(slot(nodes_[v].left, k, side))];
        ++per_box[tree_.winner(slot(nodes_[v].right, k, side))];
      }
    }
  }
  return per_box.empty() ? 0 : *std::max_element(per_box.begin(), per_box.end());
}

bool KineticBvh::validate() const {
  if (!sync_.current()) return false;
  if (boxes_.size() == 0) return nodes() == 0 && live_pairs_ == 0;
  if (nodes() != 2 * boxes_.size() - 1) return false;
  if (root_ >= nodes_.size() || free_node(root_) || nodes_[root_].parent != kNoIndex) return false;
  // Tree and tournaments.
  std::size_t leaves = 0;
  for (std::uint32_t v = 0; v < nodes_.size(); ++v) {
    const Node& n = nodes_[v];
    if (free_node(v)) {
      for (int k = 0; k < d_; ++k) {
        for (const BoxSide side : kSides) {
          if (watch_head_[slot(v, k, side)] != kNoIndex) return false;
          if (!tree_.certificate(slot(v, k, side)).is_null()) return false;
        }
      }
      continue;
    }
    if (v != root_ && (n.parent >= nodes_.size() || free_node(n.parent) ||
                       (nodes_[n.parent].left != v && nodes_[n.parent].right != v)))
      return false;
    if (leaf(v)) {
      ++leaves;
      if (!boxes_.alive_index(n.box) || leaf_of_[n.box] != v) return false;
      for (int k = 0; k < d_; ++k) {
        for (const BoxSide side : kSides) {
          if (tree_.winner(slot(v, k, side)) != n.box) return false;
        }
      }
      continue;
    }
    if (nodes_[n.left].parent != v || nodes_[n.right].parent != v) return false;
  }
  if (leaves != boxes_.size()) return false;
  // The internal nodes' winners and certificates (core/tournament_tree.hpp).
  if (!tree_.validate()) return false;
  // The pair set: closed under the children of expanded and self pairs, from the root's.
  std::vector<std::uint32_t> stack;
  std::size_t reached = 0;
  ChildPairs children;
  std::vector<std::uint64_t> contact_boxes;
  if (!leaf(root_)) {
    if (root_pair_ >= pairs_.size() || pairs_[root_pair_].a != root_ ||
        pairs_[root_pair_].b != root_)
      return false;
    stack.push_back(root_pair_);
  }
  while (!stack.empty()) {
    const std::uint32_t p = stack.back();
    stack.pop_back();
    if (++reached > live_pairs_) return false;  // a pair reached twice: not a tree of pairs
    const PairRecord& r = pairs_[p];
    std::size_t count = 0;
    for (std::uint32_t c = r.first_cert; c != kNoIndex; c = certs_[c].next_of_pair) {
      if (++count > 2 * static_cast<std::size_t>(d_)) return false;  // a cycle
      const Cert& x = certs_[c];
      if (x.pair != p) return false;
      const bool nodes_ok = (x.lower_node == r.a && x.upper_node == r.b) ||
                            (x.lower_node == r.b && x.upper_node == r.a);
      if (!nodes_ok) return false;
      // Computed from leaves of its nodes (the winners, for a separation certificate).
      if (!under(x.from[0], x.lower_node) || !under(x.from[1], x.upper_node)) return false;
      if (r.state == State::Separated &&
          (x.from[0] != tree_.winner(slot(x.lower_node, x.axis, x.lower_side)) ||
           x.from[1] != tree_.winner(slot(x.upper_node, x.axis, x.upper_side))))
        return false;
      if (!x.handle.is_null()) {
        if (!sim_.queue().contains(x.handle)) return false;
        const Event& e = sim_.queue().get(x.handle);
        if (e.owner != owners_[1] || e.payload != c) return false;
      }
    }
    const std::size_t want = r.state == State::Separated ? 1
                             : r.state == State::Self    ? 0
                                                         : 2 * static_cast<std::size_t>(d_);
    if (count != want) return false;
    if (r.state == State::Self && self_pair_[r.a] != p) return false;
    if (r.state == State::Contact) {
      if (!leaf(r.a) || !leaf(r.b)) return false;
      contact_boxes.push_back(PairSet::key(nodes_[r.a].box, nodes_[r.b].box));
    }
    if (r.state == State::Expanded || r.state == State::Self) {
      children_pairs(r.a, r.b, children);
      if (r.state == State::Expanded && children.empty()) return false;
      if (r.child_count != children.size) return false;
      for (std::size_t i = 0; i < children.size; ++i) {
        const std::uint32_t child = r.child[i];
        const auto [x, y] = children.pairs[i];
        if (child >= pairs_.size() || pairs_[child].a != std::min(x, y) ||
            pairs_[child].b != std::max(x, y))
          return false;
        stack.push_back(child);
      }
    } else if (r.child_count != 0) {
      return false;
    }
  }
  if (reached != live_pairs_) return false;
  std::size_t live = 0;
  for (const PairRecord& r : pairs_) live += r.a != kNoIndex ? 1 : 0;
  if (live != live_pairs_) return false;
  // Watch lists: every live certificate linked twice, in the lists of its two node sides.
  std::size_t links = 0;
  for (std::size_t s = 0; s < watch_head_.size(); ++s) {
    std::uint32_t prev = kNoIndex;
    for (std::uint32_t link = watch_head_[s]; link != kNoIndex;
         link = certs_[link / 2].watch_next[link % 2]) {
      if (certs_[link / 2].pair == kNoIndex ||
          watch_slot(link / 2, static_cast<int>(link % 2)) != s)
        return false;
      if (certs_[link / 2].watch_prev[link % 2] != prev) return false;
      prev = link;
      if (++links > 2 * live_certs_) return false;  // a cycle
    }
  }
  if (links != 2 * live_certs_) return false;
  // The contacts.
  if (contact_boxes.size() != contact_set().size()) return false;
  for (const std::uint64_t k : contact_boxes) {
    if (!contact_set().contains(PairSet::first(k), PairSet::second(k))) return false;
  }
  return true;
}

namespace {

/// The loop guard's bounds. Every certificate compares two of the 2dn box sides; at one instant a
/// pair of sides crosses at most once, and each crossing fails at most the certificates comparing
/// those two sides (a node side's tournament certificate and the pair certificates watching it):
/// loose, by a constant factor (16) per axis.
LoopGuard bvh_event_bounds(const RunBounds& b) {
  return crossing_guard(16 * static_cast<std::uint64_t>(b.dimension), 2 * b.max_objects,
                        2 * b.motion_changes, b.max_degree);
}

}  // namespace

StructureDescription KineticBvh::description() {
  return StructureDescription{
      "bvh",
      "Bvh",
      ObjectsAre::Boxes,
      {QueryType::CollidingPairs},
      {"contact_begin", "contact_end"},
      "The kinetic AABB tree with its separation list over moving boxes "
      "(colliding_pairs()); centers (n, d, k) and half_extents (n, d).",
      "kinetic AABB tree over moving boxes (node boxes kept by kinetic tournaments) with its "
      "kinetic separation list (node pairs expanded and collapsed at their overlap events): all "
      "pairs of boxes in contact"}
      .limit_dimensions(1, 3, "boxes in 1 to 3 dimensions")
      .bound_events(bvh_event_bounds);
}

}  // namespace kinetic
