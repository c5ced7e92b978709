#pragma once
// The kinetic closest pair of points in the plane from cones (after Basch, Guibas and Zhang,
// "Proximity problems on moving points": the closest pair is found among the nearest
// neighbours of each point in a fixed set of cones, kept with kinetic sorted orders, and a
// kinetic tournament over those candidates), under every scheduler: robust (the default), classic
// and exact.
//
// The cones. The plane around a point p is cut into eight cones of 45 degrees, C_0 .. C_7,
// bounded by the lines of the directions y, x - y, x and x + y through p (C_0: angles [0, 45),
// C_1: [45, 90), ..., C_4 .. C_7 the opposites of C_0 .. C_3). Each cone c has a target direction
// u_c strictly inside it (2x + y, x + 2y, -x + 2y, -2x + y for C_0 .. C_3, their opposites for
// C_4 .. C_7), and the candidate of p in c is N_c(p), the point of p's cone c whose key u_c . q is
// the smallest. Lemma (docs/closest-pair.md): if (p, q) is a closest pair and q lies in p's cone
// c, then q = N_c(p) (any other point r of the cone with u_c . r <= u_c . q is closer to q than p
// is: the triangle {x in the cone: u_c . x <= u_c . q} has its longest side at p, because u_c
// makes an angle of 18 to 27 degrees with each side of a 45-degree cone). So the closest pair is
// among the at most 8n candidate pairs (p, N_c(p)).
//
// What is kinetic. Eight KineticDirectionSorts keep the points sorted along y, x - y, x, x + y
// (the cones' sides: q lies in p's cone when it comes after or before p in two of these orders)
// and along the four target directions (sort/, core/sort_keys.hpp's DirectionKeys: exact
// certificates of four motions). N_c(p) is defined from the maintained orders alone: the first
// point after p in the order of u_c (before, for the opposite cones) that lies in p's cone by the
// maintained orders. A swap of two adjacent points changes only what it can: a swap on a side
// order moves one of the two in or out of the other's cones (a point that leaves as N_c(p) is
// replaced by scanning the order of u_c from where it stood); a swap on a target order hands
// the points whose candidate was the one passed to the one passing when it lies in their cone
// (each point's list of the points it is the candidate of: reverse lists). The candidates are
// the leaves of a PairTournament (closest_pair/pair_tournament.hpp) by squared length.
//
// Guarantees. Exact scheduler: the answer at t is the closest pair at t (the smallest pair of
// ids among equally close pairs; points at one place at t are found by a pass over the points,
// O(n log n), only then). Robust scheduler: the orders are sorted up to inversions of at most
// rho along each direction (Theorem 4 of Abam, Agarwal, de Berg, Yu); when no two points are
// closer than 7 rho, the reported pair is at most 24 rho longer than the closest pair, plus the
// tournament's own error (docs/closest-pair.md states and proves it; the tests assert it at
// random times). When the orders disagree about every pair (no candidate at all), the query
// compares every pair exactly (O(n^2), only then).
//
// Bounds: 8 (n - 1) order certificates and at most 8n - 1 length certificates (compact). A swap
// on a side order changes at most four candidates; a swap on a target order changes the
// candidates of the points whose candidate was the point passed (its reverse list: up to n,
// 0.02 to 0.2 per event on random input); a candidate that leaves its cone costs one scan of an
// order (a few hundred points at n = 10^5 on random input, up to n for a point whose cone
// empties); each changed candidate costs O(log n) length decisions.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "kinetic/core/description.hpp"
#include "kinetic/closest_pair/pair_tournament.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/preconditions.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/structure.hpp"
#include "kinetic/sort/kinetic_sort.hpp"

namespace kinetic {

struct ConeClosestPairCounters {
  std::uint64_t swaps = 0;               ///< events of the eight orders
  std::uint64_t tournament_events = 0;   ///< length certificates that failed
  std::uint64_t candidate_changes = 0;   ///< N_c(p) set to another point or to none
  std::uint64_t scans = 0;               ///< candidates found again by scanning an order
  std::uint64_t scan_steps = 0;          ///< points those scans read
  std::uint64_t queries = 0;
  std::uint64_t coincidence_passes = 0;  ///< queries that found points at one place (O(n log n))
  /// Queries that found no candidate (orders disagreeing about every pair): O(n^2) exact.
  std::uint64_t brute_force_passes = 0;
};

class KineticConeClosestPair {
 public:
  /// What the structure is and takes (core/description.hpp): the registry, the CLI and the
  /// Python class read it.
  [[nodiscard]] static StructureDescription description();

  /// Cones around a point.
  static constexpr int kCones = 8;
  /// Highest motion degree taken: the length certificates' degree (2k) is at most CROP's 6.
  static constexpr int kMaxDegree = 3;

  /// The coefficients taken (about the motion's origin): |c| < 2^1023, so that twice a
  /// coordinate (the orders along 2x + y, x + 2y, ...) is a double.
  static constexpr int kCoefficientLog2 = 1023;
  /// Refuses (PreconditionError naming `where` and the id) a motion of degree > kMaxDegree or
  /// with a coefficient beyond kCoefficientLog2: what a session checks before the table changes
  /// (the structure checks it too, at initialize, insert and motion_changed).
  static void require_motion(std::span<const MotionPolynomial> motion, ObjectId id,
                             const char* where);

  /// Points are the table's objects (dimension 2). Throws PreconditionError otherwise.
  KineticConeClosestPair(const MotionTable& points, Simulator& simulator,
                         const Scheduler& scheduler);
  ~KineticConeClosestPair();

  void initialize();
  EventKind process(const Event& event);
  void insert(std::uint32_t index);
  void remove(std::uint32_t index);
  void motion_changed(std::uint32_t index);

  /// The closest pair at now, indices by ascending id (the smallest pair of ids among equally
  /// close ones). Empty for fewer than two points.
  [[nodiscard]] std::optional<std::array<std::uint32_t, 2>> closest_pair();

  /// N_c(p) by the maintained orders, or kNoIndex (tests, audits).
  [[nodiscard]] std::uint32_t candidate(int cone, std::uint32_t p) const {
    return neighbour_[static_cast<std::size_t>(cone)][p];
  }
  /// The order along DirectionKeys::kDirections[direction].
  [[nodiscard]] const KineticDirectionSort& order(int direction) const {
    return *sorts_[static_cast<std::size_t>(direction)];
  }
  [[nodiscard]] const PairTournament& tournament() const { return tournament_; }
  [[nodiscard]] std::size_t size() const { return points_.size(); }
  [[nodiscard]] const ConeClosestPairCounters& counters() const { return counters_; }
  [[nodiscard]] NamedCounters named_counters() const;
  [[nodiscard]] bool initialized() const { return sync_.initialized(); }
  /// The eight orders' certificates and the tournament's.
  [[nodiscard]] std::size_t certificates() const;
  [[nodiscard]] std::size_t certificates_per_object_max() const;
  /// Invariants: the orders' own; every candidate N_c(p) is the first point after p in the
  /// order of u_c that lies in p's cone by the maintained orders (recomputed by brute force),
  /// the reverse lists agree, the tournament's leaves hold exactly the candidate pairs, and the
  /// tournament's invariants. O(n^2): for tests.
  [[nodiscard]] bool validate() const;

 private:
  /// True when q lies in p's cone c by the maintained orders.
  [[nodiscard]] bool in_cone(int c, std::uint32_t p, std::uint32_t q) const;
  /// The first point of p's cone c in the scan of u_c's order from slot `from` (inclusive),
  /// kNoIndex when none; counts the steps.
  [[nodiscard]] std::uint32_t scan(int c, std::uint32_t p, std::size_t from);
  /// The slot after p's in c's scan direction (kNoSlot at the end).
  [[nodiscard]] std::size_t after(int c, std::size_t slot) const;
  /// True when q comes before r in c's scan.
  [[nodiscard]] bool scans_before(int c, std::uint32_t q, std::uint32_t r) const;
  /// N_c(p) = q (kNoIndex: none): the reverse lists and the tournament's leaf follow.
  void set_candidate(int c, std::uint32_t p, std::uint32_t q);
  /// The points whose candidate in cone c is q (its reverse list), copied (into scratch_) so
  /// that the caller may change their candidates while it walks them.
  const std::vector<std::uint32_t>& candidate_of(int c, std::uint32_t q);
  /// N_c(p) found again by scanning from p.
  void rescan(int c, std::uint32_t p);
  /// q may have entered p's cone c (or moved ahead in its scan): made N_c(p) when it is in it,
  /// after p in the scan and before the current candidate; if it is the current candidate and
  /// no longer in the cone, the cone is scanned again from where it stood.
  void reconsider(int c, std::uint32_t p, std::uint32_t q);
  void on_swap(int direction, std::uint32_t up, std::uint32_t down);
  /// Every candidate involving `index` found again, and `index` considered for every point's
  /// cones (an insert or a motion change): O(n) checks and 8 scans.
  void refresh_object(std::uint32_t index);
  void detach(std::uint32_t index);
  /// require_motion() on the object's motion in the table.
  void check_motion(std::uint32_t index, const char* where) const;
  void grow();
  [[nodiscard]] std::uint32_t leaf(int c, std::uint32_t p) const {
    return p * kCones + static_cast<std::uint32_t>(c);
  }

  const MotionTable& points_;
  TableSync sync_{points_};
  Simulator& sim_;
  const Scheduler& scheduler_;
  std::array<std::unique_ptr<KineticDirectionSort>, 8> sorts_;
  std::uint32_t first_sort_owner_ = 0;
  PairTournament tournament_;
  // Per cone: candidate N_c(p), and the reverse lists (the points whose candidate q is, doubly
  // linked through next_/prev_ from head_[c][q]).
  std::array<std::vector<std::uint32_t>, kCones> neighbour_, head_, next_, prev_;
  std::vector<std::uint32_t> scratch_;
  std::vector<PairTournament::Pair> ties_;
  ConeClosestPairCounters counters_;
};

static_assert(KineticStructure<KineticConeClosestPair>);

}  // namespace kinetic
