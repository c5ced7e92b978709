#pragma once
// The kinetic tournament (Abam, Agarwal, de Berg, Yu, Section 4; Basch, Guibas and Hershberger):
// the maximum (or minimum) of points moving on a line, kept in a tournament tree. Each internal
// node stores the winner of its two children and has one certificate [loser < winner]; a point
// takes part in at most one certificate per level, so O(log n) certificates per point.
//
// Robust scheduling (Algorithm KINETICTOURNAMENT): an event at node u re-decides every node on the
// path from u towards the root with COMPUTEMAX, and schedules the new certificates with EVENTTIME
// on the same CROP result, so a new event time is always in the future (Lemma 4) and no event is
// ever processed in the past. Classic scheduling, as a traditional KDS: the event's certificate is
// trusted (the winner at u changes); going up, a node whose winner was u's old winner is decided
// again from its children's floating-point values at t_curr, and the first node whose winner
// came from the other side keeps it (trusted: it beat the old winner, which the new one just
// crossed) and only gets its certificate for the new pair; failure times are floating-point
// roots. A node left wrong by a dropped event (a root rounded into the past) stays wrong until a
// change comes up through its winner's side. Scheduler::set_classic_exact_decisions(true) gives
// the careful variant: the nodes on the path re-decided by exact comparisons just after t_curr
// (COMPUTEMAX) until one keeps its winner, so a wrong node is repaired when a winner change
// reaches it from either child.
//
// Storage: core/tournament_tree.hpp's tree over `capacity` leaf slots (a power of two, the
// implicit complete binary tree: node 1 is the root, node v has children 2v and 2v + 1, leaves
// are the nodes capacity .. 2 capacity - 1). An empty slot holds no point; a node with one empty
// child copies the other and has no certificate. Inserts fill free slots (the capacity doubles
// when none is left, with a rebuild); removes free a slot.

#include <cstdint>
#include <optional>
#include <vector>

#include "kinetic/core/description.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/preconditions.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/structure.hpp"
#include "kinetic/core/tournament_tree.hpp"

namespace kinetic {

enum class Extreme { Max, Min };

struct TournamentCounters : ChangeCounters {
  std::uint64_t events = 0;
  std::uint64_t rebuilds = 0;
  std::uint64_t nodes_redecided = 0;  ///< COMPUTEMAX / comparisons on paths, all causes
  /// Robust scheduling: new certificates whose failure time was <= t_curr (Lemma 4 says none).
  std::uint64_t scheduled_not_in_future = 0;
};

/// The result of an audit against the brute-force oracle at one time.
struct TournamentAudit {
  bool ok = true;                  ///< the maintained top is a true extreme at t
  std::uint32_t maintained = 0;    ///< the maintained top (object index)
  std::uint32_t true_extreme = 0;  ///< an object with the extreme value at t
};

class KineticTournament {
 public:
  /// What the structure is and takes (core/description.hpp): the registry, the CLI and the
  /// Python class read it.
  [[nodiscard]] static StructureDescription description();

  KineticTournament(const MotionTable& motions, Simulator& simulator, const Scheduler& scheduler,
                    int axis, Extreme extreme);
  /// Not copied or moved: its tree's keys count into its counters.
  KineticTournament(const KineticTournament&) = delete;
  KineticTournament& operator=(const KineticTournament&) = delete;

  /// Builds the tree over every live object of the table at sim.now() and schedules the
  /// certificates. O(n) decisions.
  void initialize();

  /// The KDS event handler. External when the top changed.
  EventKind process(const Event& event);

  /// A live object of the table joins (O(log n), amortized: a full slot array doubles).
  void insert(std::uint32_t index);
  /// An object left the table (call after removing it there). O(log n).
  void remove(std::uint32_t index);
  /// The object's motion was replaced in the table. O(log n).
  void motion_changed(std::uint32_t index);

  /// The maintained extreme (object index), nullopt when empty.
  [[nodiscard]] std::optional<std::uint32_t> top() const;
  /// The winners of the tree's top `levels` levels (a picture of the tournament): level k holds
  /// the 2^k nodes of depth k from left to right, each an object index or nullopt (an empty
  /// subtree); fewer levels when the tree is shallower. O(2^levels).
  [[nodiscard]] std::vector<std::vector<std::optional<std::uint32_t>>> winner_levels(
      int levels) const;
  [[nodiscard]] int axis() const { return axis_; }
  [[nodiscard]] Extreme extreme() const { return extreme_; }
  [[nodiscard]] std::size_t size() const { return size_; }
  [[nodiscard]] const TournamentCounters& counters() const { return counters_; }
  [[nodiscard]] NamedCounters named_counters() const;
  /// The owner tag of this structure's events (one, reserved from the simulator).
  [[nodiscard]] OwnerRange owners() const { return OwnerRange{tree_.owner(), 1}; }
  /// Certificates alive: internal nodes with two non-empty children (n - 1 for n points).
  [[nodiscard]] std::size_t certificates() const { return tree_.certificates(); }
  /// The largest number of certificates one point takes part in (<= the tree's height). O(n).
  [[nodiscard]] std::size_t certificates_per_object_max() const;
  /// The tree's height (levels of internal nodes): ceil(log2 capacity).
  [[nodiscard]] int height() const { return height_; }

  /// Invariants: leaves and slots agree; every node's winner is one of its children's winners;
  /// every internal node with two non-empty children has exactly one scheduled event, and no
  /// other events of this structure exist. O(n).
  /// initialize() was called.
  [[nodiscard]] bool initialized() const { return sync_.initialized(); }
  [[nodiscard]] bool validate() const;
  /// Oracle audit at time t: the maintained top has the extreme value at t (exact comparisons).
  [[nodiscard]] TournamentAudit audit(Time t) const;
  /// Lemma 5, checked at node level: at every internal node whose winner is not the better child
  /// at t, the two children's winners cross in (t - eps, t). Returns the number of nodes where
  /// this fails (0 for a correct robust tournament at t = sim.now()).
  [[nodiscard]] std::size_t lemma5_violations(Time t, double eps) const;

 private:
  /// The tournament's entries: object indices compared on one axis (core/tournament_tree.hpp's
  /// Keys), counting their decisions into the tournament's counters.
  struct Keys {
    const MotionTable* motions;
    Simulator* sim;
    const Scheduler* scheduler;
    int axis;
    Extreme extreme;
    TournamentCounters* counters;  ///< the tournament's: nodes_redecided, scheduled_not_in_future
    /// x beats y as the scheduler sees it now (COMPUTEMAX), with the certificate's failure.
    Scheduler::MaxDecision decide(std::size_t node, std::uint32_t x, std::uint32_t y);
    /// The failure of [l behind w] (the classic policy's trusted certificate).
    [[nodiscard]] Time failure(std::size_t node, std::uint32_t w, std::uint32_t l) const;
  };

  [[nodiscard]] std::size_t capacity() const { return tree_.topology().capacity; }
  [[nodiscard]] bool is_leaf(std::size_t node) const { return tree_.topology().is_leaf(node); }
  void rebuild(std::size_t capacity);

  const MotionTable& motions_;
  TableSync sync_{motions_};  // told of every change to the table
  Simulator& sim_;
  const Scheduler& scheduler_;
  int axis_;
  Extreme extreme_;
  TournamentTree<Keys> tree_;  ///< over `capacity` leaf slots (0 when never initialized)
  int height_ = 0;
  std::size_t size_ = 0;
  std::vector<std::uint32_t> leaf_of_;  ///< object index -> leaf node (0: absent)
  std::vector<std::uint32_t> free_;     ///< free leaf nodes (a stack, highest first)
  TournamentCounters counters_;
};

static_assert(KineticStructure<KineticTournament>);

}  // namespace kinetic
