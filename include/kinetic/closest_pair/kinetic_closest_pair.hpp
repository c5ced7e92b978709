#pragma once
// The kinetic closest pair of points in the plane: a kinetic tournament (minimum) over the edges
// of the kinetic Delaunay triangulation, keyed by their squared lengths (Basch, Guibas,
// Hershberger, "Data structures for mobile data": the closest pair is an edge of the Delaunay
// triangulation, so a tournament over its O(n) edges keeps it; Guibas, Mitchell, Roos for the
// triangulation).
//
// The triangulation (delaunay/) records which edges enter and leave it (a flip takes one and
// gives one; an insert or remove a vertex's star); after every event or change of the
// triangulation the tournament (a PairTournament, closest_pair/pair_tournament.hpp) takes the
// changes: a new edge gets a leaf, a gone edge frees its leaf, and the nodes above the changed
// leaves are decided again, from the bottom up, each once. A node's certificate is [|winner|^2
// <= |loser|^2], a LengthComparison of the two edges' four points (degree 2k for motions of
// degree k), decided by the exact scheduler; it fails when the loser becomes shorter, and the
// node and those above it are decided again. Edges of equal length for ever are ordered by
// their ids (smaller pair first).
//
// Bounds: the tournament has one leaf per Delaunay edge (at most 3n - 6), so O(n) certificates,
// O(log n) per edge; an edge change costs O(log n) decisions; a query walks the subtrees whose
// winner ties the shortest length now (one path without ties). Every event of the triangulation
// (a flip) costs O(log n) tournament decisions on top of its own.
//
// Degenerate input follows the triangulation's rules (docs/delaunay.md): the answer at t is the
// closest pair at t (the smallest pair of ids among equally close pairs); copies (identical
// motions) are at distance 0 for ever; points at one place now are found through their
// zero-length edges; points collinear for ever (no triangulation) are answered by the
// triangulation's own pass over all pairs (O(n^2), documented).
//
// Scheduling: the exact scheduler only: its tournament compares the edges' lengths now, while the
// robust triangulation below it is exact at the grid point before now.

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "kinetic/closest_pair/pair_tournament.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/pair_set.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/structure.hpp"
#include "kinetic/delaunay/kinetic_delaunay.hpp"

namespace kinetic {

struct ClosestPairCounters {
  std::uint64_t events = 0;  ///< tournament events: a length certificate failed
  /// Delaunay edges that entered / left the tournament.
  std::uint64_t edge_inserts = 0, edge_removes = 0;
  /// The triangulation was built again: every edge read again, the tournament laid out anew.
  std::uint64_t rebuilds = 0;
  std::uint64_t nodes_redecided = 0;  ///< length comparisons decided by the scheduler
  std::uint64_t queries = 0;
  std::uint64_t tie_visits = 0;  ///< tournament nodes visited by queries (ties)
};

class KineticClosestPair {
 public:
  /// Highest motion degree taken (the triangulation's).
  static constexpr int kMaxDegree = KineticDelaunay::kMaxDegree;
  /// The magnitudes of the motions' coefficients taken (the triangulation's).
  static constexpr int kMagnitudeLog2 = KineticDelaunay::kMagnitudeLog2;
  /// Refuses a motion the triangulation cannot certify (KineticDelaunay::require_motion).
  static void require_motion(std::span<const MotionPolynomial> motion, ObjectId id,
                             const char* where) {
    KineticDelaunay::require_motion(motion, id, where);
  }

  /// Points are the table's objects (dimension 2). Throws PreconditionError unless the
  /// scheduler is exact.
  KineticClosestPair(const MotionTable& points, Simulator& simulator, const Scheduler& scheduler);

  void initialize();
  EventKind process(const Event& event);
  void insert(std::uint32_t index);
  void remove(std::uint32_t index);
  void motion_changed(std::uint32_t index);

  /// The closest pair at now, indices by ascending id (the smallest pair of ids among equally
  /// close ones). Empty for fewer than two points.
  [[nodiscard]] std::optional<std::array<std::uint32_t, 2>> closest_pair();

  /// The triangulation's queries, answered by the triangulation below (what `closest-pair`
  /// answers besides the pair; the session's delaunay() and nearest()).
  [[nodiscard]] std::vector<std::array<std::uint32_t, 3>> triangles() { return dt_.triangles(); }
  [[nodiscard]] std::optional<std::uint32_t> nearest(Point2 q, double eps, Time t) {
    return dt_.nearest(q, eps, t);
  }

  /// The triangulation below (its queries: triangles, nearest).
  [[nodiscard]] KineticDelaunay& triangulation() { return dt_; }
  [[nodiscard]] const KineticDelaunay& triangulation() const { return dt_; }
  [[nodiscard]] std::size_t size() const { return dt_.size(); }
  /// Edges in the tournament (the triangulation's finite edges).
  [[nodiscard]] std::size_t edges() const { return edges_.size(); }
  /// Its counters, the tournament's included.
  [[nodiscard]] ClosestPairCounters counters() const;
  /// The triangulation's counters, then the tournament's (prefixed `tournament_` where a name
  /// would repeat).
  [[nodiscard]] NamedCounters named_counters() const;
  [[nodiscard]] bool initialized() const { return dt_.initialized(); }
  /// The triangulation's certificates and the tournament's (edges - 1).
  [[nodiscard]] std::size_t certificates() const;
  [[nodiscard]] std::size_t certificates_per_object_max() const;
  /// Invariants: the triangulation's; the tournament's edges are the triangulation's edges,
  /// each held by two triangles; every node's winner is one of its children's, the shorter
  /// just after now (ties by ids) unless its event is due now; every queued event of the
  /// tournament belongs to its node and is counted (a node whose certificate does not fail
  /// before the horizon has none). Exact arithmetic: for tests.
  [[nodiscard]] bool validate() const;

 private:
  using Pair = std::array<std::uint32_t, 2>;
  /// Takes the triangulation's recorded edge changes into the tournament.
  void take_edge_changes();
  /// Reads every edge of the triangulation again and lays the tournament out anew.
  void reread_edges();
  /// Every record's edge into the tournament's leaves (empty for free records), every node
  /// decided: after a rebuild, or when the leaves ran out.
  void lay_out();
  /// A new leaf for edge {a, b}.
  void add_edge(std::uint32_t a, std::uint32_t b);
  void remove_edge(std::size_t position);
  [[nodiscard]] Pair ends(std::uint32_t record) const;

  const MotionTable& points_;
  Simulator& sim_;
  const Scheduler& scheduler_;
  KineticDelaunay dt_;
  // Edges: a record per edge (stable while the edge lives; its tournament leaf), found by the
  // pair of its ends through the set's dense position.
  PairSet edges_;                         ///< the edges, dense
  std::vector<std::uint32_t> record_of_;  ///< dense position -> record
  std::vector<std::uint64_t> key_;        ///< record -> PairSet key of its ends
  std::vector<std::uint8_t> held_;        ///< record -> triangles holding the edge (0..2)
  std::vector<std::uint32_t> free_records_;
  /// Records freed in the batch being taken: not reused before its nodes are decided (a node
  /// whose winner keeps its record would not see that the record's edge changed).
  std::vector<std::uint32_t> freed_records_;
  PairTournament tournament_;  ///< leaf r: the edge of record r (its owner after the dt's)
  bool grow_ = false;  ///< a record of the batch being taken has no leaf: lay out at its end
  std::vector<Pair> scratch_edges_;
  ClosestPairCounters counters_;
};

static_assert(KineticStructure<KineticClosestPair>);

}  // namespace kinetic
