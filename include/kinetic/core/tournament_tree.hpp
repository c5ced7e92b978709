#pragma once
// The kinetic tournament, written once: a binary tree whose every internal node holds the winner
// of its two children and one certificate [loser behind winner] as an event of the simulator
// (the kinetic priority queue of Basch, Guibas and Hershberger, "Data structures for mobile
// data"; its robust scheduling is Algorithm KINETICTOURNAMENT of Abam, Agarwal, de Berg and Yu,
// "Out-of-order event processing in kinetic data structures", Section 4).
//
// What the structures above it give:
// - Keys, the entries and their certificates: `Scheduler::MaxDecision decide(node, a, b)` says
//   whether entry a beats entry b just after now and when that certificate fails (infinite: it
//   never does; COMPUTEMAX / EVENTTIME under the robust scheduler, floating-point roots under
//   the classic one, exact times under the exact one). The classic policy's trusted event also
//   needs `Time failure(node, winner, loser)`: the certificate's failure time without a decision.
// - Topology, the tree: `is_leaf(v)`, `children(v)` and `parent(v)` (kNoNode at the root) over
//   node numbers that index the tree's arrays. HeapTopology is the implicit complete binary tree
//   (the tournament and extent, the closest pair's pairs); the BVH gives its own hierarchy, one
//   node per (tree node, axis, side).
//
// Entries are uint32 (kNoIndex: an empty subtree); a node with one empty child copies the other
// and has no certificate. Every certificate is an event of one owner tag with its node as the
// payload, rescheduled in place when decided again: the queue is touched only through the
// simulator's schedule / reschedule / cancel.
//
// The policies, as the structures compose them:
// - robust / exact: decide(v) at the event's node, then climb(v): each parent decided again up to
//   the first whose winner stays;
// - classic, a traditional KDS: trust_failure(v) makes the certificate's loser the winner, then
//   propagate_traditionally carries it up without deciding what it trusts.

#include <array>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "kinetic/core/event_queue.hpp"
#include "kinetic/core/ids.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"

namespace kinetic {

/// No node (the root's parent).
inline constexpr std::size_t kNoNode = SIZE_MAX;

/// The implicit complete binary tree over `capacity` leaf slots (a power of two, 0: no tree):
/// node 1 is the root, node v has children 2v and 2v + 1, leaf slot l is node capacity + l
/// (capacity 1: the root is the only leaf). Node 0 is unused.
struct HeapTopology {
  std::size_t capacity = 0;

  [[nodiscard]] std::size_t nodes() const { return 2 * capacity; }
  [[nodiscard]] bool is_leaf(std::size_t v) const { return v >= capacity; }
  [[nodiscard]] bool internal(std::size_t v) const { return v >= 1 && v < capacity; }
  [[nodiscard]] std::array<std::size_t, 2> children(std::size_t v) const {
    return {2 * v, 2 * v + 1};
  }
  [[nodiscard]] std::size_t parent(std::size_t v) const { return v > 1 ? v / 2 : kNoNode; }
  [[nodiscard]] std::size_t leaf(std::size_t slot) const { return capacity + slot; }
};

template <class Keys, class Topology = HeapTopology>
class TournamentTree {
 public:
  TournamentTree(Simulator& simulator, std::uint32_t owner, Keys keys, Topology topology = {})
      : sim_(simulator), owner_(owner), keys_(std::move(keys)), topology_(std::move(topology)) {}

  [[nodiscard]] Keys& keys() { return keys_; }
  [[nodiscard]] const Keys& keys() const { return keys_; }
  [[nodiscard]] Topology& topology() { return topology_; }
  [[nodiscard]] const Topology& topology() const { return topology_; }
  [[nodiscard]] std::uint32_t owner() const { return owner_; }
  /// Size of the node arrays.
  [[nodiscard]] std::size_t size() const { return winner_.size(); }

  /// Every certificate cancelled; `nodes` nodes, every one empty.
  void assign(std::size_t nodes) {
    cancel_all();
    winner_.assign(nodes, kNoIndex);
    certificate_.assign(nodes, EventHandle{});
    both_.assign(nodes, 0);
    certificates_ = 0;
  }
  /// Room for `nodes` nodes, the existing ones kept (new ones empty).
  void grow(std::size_t nodes) {
    if (nodes <= winner_.size()) return;
    winner_.resize(nodes, kNoIndex);
    certificate_.resize(nodes, EventHandle{});
    both_.resize(nodes, 0);
  }
  void cancel_all() {
    for (EventHandle& h : certificate_) sim_.cancel(h);
  }

  /// Node v's winner (kNoIndex: an empty subtree).
  [[nodiscard]] std::uint32_t winner(std::size_t v) const { return winner_[v]; }
  /// Sets a leaf's entry (no decision: the nodes above are decided by the caller).
  void set_leaf(std::size_t v, std::uint32_t entry) {
    assert(topology_.is_leaf(v));
    winner_[v] = entry;
  }
  /// Node v leaves the tree: its certificate cancelled, empty.
  void release(std::size_t v) {
    sim_.cancel(certificate_[v]);
    certificates_ -= both_[v];
    both_[v] = 0;
    winner_[v] = kNoIndex;
  }
  [[nodiscard]] EventHandle certificate(std::size_t v) const { return certificate_[v]; }
  /// Nodes with two non-empty children, each with its certificate (n - 1 for n entries).
  [[nodiscard]] std::size_t certificates() const { return certificates_; }

  /// Re-decides internal node v from its children's winners (Keys::decide) and reschedules its
  /// certificate (none with an empty child). True when its winner changed.
  bool decide(std::size_t v) {
    assert(!topology_.is_leaf(v));
    const auto [left, right] = topology_.children(v);
    const std::uint32_t a = winner_[left], b = winner_[right];
    const std::uint32_t before = winner_[v];
    const std::uint8_t both = a != kNoIndex && b != kNoIndex ? 1 : 0;
    certificates_ = certificates_ + both - both_[v];
    both_[v] = both;
    std::uint32_t w = kNoIndex;
    if (both == 0) {
      sim_.cancel(certificate_[v]);
      w = a == kNoIndex ? b : a;
    } else {
      Scheduler::MaxDecision d = keys_.decide(v, a, b);
      w = d.first_wins ? a : b;
      sim_.reschedule(certificate_[v], d.failure, std::move(d.exact), owner_,
                      static_cast<std::uint32_t>(v));
    }
    winner_[v] = w;
    return w != before;
  }
  /// After node v changed: on_change(v), then its parent decided again, and so on up to the
  /// root or the first node whose winner stays (on_change is not called for that one).
  template <class OnChange>
  void climb(std::size_t v, OnChange&& on_change) {
    for (;;) {
      on_change(v);
      const std::size_t p = topology_.parent(v);
      if (p == kNoNode || !decide(p)) return;
      v = p;
    }
  }
  void climb(std::size_t v) {
    climb(v, [](std::size_t) {});
  }
  /// Every node on the path from v to the root decided again (a leaf's entry changed).
  void decide_to_root(std::size_t v) {
    for (; v != kNoNode; v = topology_.parent(v)) decide(v);
  }

  /// The event of node v's certificate was popped: its handle forgotten. Returns v.
  std::size_t take_event(const Event& event) {
    assert(event.owner == owner_);
    const std::size_t v = event.payload;
    assert(v < certificate_.size() && !topology_.is_leaf(v));
    certificate_[v] = EventHandle{};
    return v;
  }

  /// Node v's winner is w and its certificate [l behind w] is scheduled without a decision
  /// (Keys::failure): a trusted certificate of the classic policy.
  void certify(std::size_t v, std::uint32_t w, std::uint32_t l) {
    winner_[v] = w;
    sim_.reschedule(certificate_[v], keys_.failure(v, w, l), std::nullopt, owner_,
                    static_cast<std::uint32_t>(v));
  }
  /// The classic policy at the event of node v: the certificate failed, so the loser wins now
  /// (trusted) and gets its certificate. Returns the old winner.
  std::uint32_t trust_failure(std::size_t v) {
    const auto [left, right] = topology_.children(v);
    const std::uint32_t a = winner_[left], b = winner_[right];
    assert(a != kNoIndex && b != kNoIndex);
    const std::uint32_t old = winner_[v];
    certify(v, old == a ? b : a, old);
    return old;
  }
  /// The classic policy after v's winner changed from `old`: at the parent u, when u's winner
  /// was `old`, u is decided again and the change goes on up; otherwise u's winner came from
  /// the other child and is trusted to stay ahead (the new winner below just crossed `old`,
  /// which u's winner beat): only u's certificate now watches the new pair, and the walk stops.
  /// A node left wrong by a dropped event stays wrong until a change reaches it through its
  /// winner's side.
  void propagate_traditionally(std::size_t v, std::uint32_t old) {
    for (std::size_t u = topology_.parent(v); u != kNoNode; v = u, u = topology_.parent(u)) {
      const std::uint32_t now_below = winner_[v];
      const std::uint32_t before = winner_[u];
      if (before == old) {
        decide(u);  // (old is in neither child now: u's winner changes, the walk goes on)
        continue;
      }
      certify(u, before, now_below);  // before stays ahead of the new winner below
      return;
    }
  }

  /// The leaves under `root` whose entries tie the root's winner: a subtree is entered when its
  /// winner is the root's or `ties(entry)` says it ties it (a subtree's winner is its best, so
  /// no other subtree holds a tie). visit(entry) for each such leaf, the right child's first.
  /// Returns the nodes visited.
  template <class Ties, class Visit>
  std::size_t for_each_tie(std::size_t root, Ties&& ties, Visit&& visit) const {
    const std::uint32_t top = winner_[root];
    if (top == kNoIndex) return 0;
    std::size_t visited = 0;
    std::vector<std::size_t> stack{root};  // (a query's, not the tree's: const calls may overlap)
    while (!stack.empty()) {
      const std::size_t v = stack.back();
      stack.pop_back();
      ++visited;
      if (topology_.is_leaf(v)) {
        visit(winner_[v]);
        continue;
      }
      for (const std::size_t c : topology_.children(v)) {
        const std::uint32_t x = winner_[c];
        if (x != kNoIndex && (x == top || ties(x))) stack.push_back(c);
      }
    }
    return visited;
  }

  /// f(v, winner, loser) for every internal node with two non-empty children, in node order.
  template <class F>
  void for_each_certificate(F&& f) const {
    for (std::size_t v = 0; v < winner_.size(); ++v) {
      if (!topology_.internal(v)) continue;
      const auto [left, right] = topology_.children(v);
      const std::uint32_t a = winner_[left], b = winner_[right];
      if (a == kNoIndex || b == kNoIndex) continue;
      f(v, winner_[v], winner_[v] == a ? b : a);
    }
  }

  /// The tree's own invariants: every internal node's winner is one of its children's (the
  /// other's when one is empty, with no certificate then); its certificate, when it has one, is
  /// queued under this owner for it; the count of certificates right. `also(v, winner, loser,
  /// event)` adds a structure's own check at each certified node (event: its queued event or
  /// null). O(nodes).
  template <class Also>
  [[nodiscard]] bool validate(Also&& also) const {
    std::size_t pairs = 0;
    for (std::size_t v = 0; v < winner_.size(); ++v) {
      if (!topology_.internal(v)) continue;
      const auto [left, right] = topology_.children(v);
      const std::uint32_t a = winner_[left], b = winner_[right], w = winner_[v];
      const EventHandle h = certificate_[v];
      if (a == kNoIndex || b == kNoIndex) {
        if (w != (a == kNoIndex ? b : a) || !h.is_null() || both_[v] != 0) return false;
        continue;
      }
      ++pairs;
      if ((w != a && w != b) || both_[v] != 1) return false;
      const Event* event = nullptr;
      if (!h.is_null()) {
        if (!sim_.queue().contains(h)) return false;
        event = &sim_.queue().get(h);
        if (event->owner != owner_ || event->payload != v) return false;
      }
      if (!also(v, w, w == a ? b : a, event)) return false;
    }
    return pairs == certificates_;
  }
  [[nodiscard]] bool validate() const {
    return validate([](std::size_t, std::uint32_t, std::uint32_t, const Event*) { return true; });
  }

 private:
  Simulator& sim_;
  std::uint32_t owner_;
  Keys keys_;
  Topology topology_;
  std::vector<std::uint32_t> winner_;     ///< node -> its winner (kNoIndex: empty)
  std::vector<EventHandle> certificate_;  ///< node -> its certificate's event
  std::vector<std::uint8_t> both_;        ///< node -> two non-empty children (a certificate)
  std::size_t certificates_ = 0;
};

}  // namespace kinetic
