#pragma once
// The kinetic Delaunay triangulation of points in the plane (Guibas, Mitchell, Roos, "Voronoi
// diagrams of moving points in the plane"; the design of CGAL's kinetic Delaunay triangulation,
// Russel): a triangulation of the points' convex hull closed by one vertex at infinity (every
// hull edge has an infinite triangle), so that every edge has two triangles and one certificate:
//  - an edge between two finite triangles (a, b, c) and (b, a, d): d outside the circle through
//    a, b, c: incircle(a, b, c, d) < 0 (core/incircle.hpp, degree 4 for lines);
//  - a hull edge a -> b with its finite triangle (a, b, c): orient(a, b, c) > 0;
//  - an edge from a hull vertex to infinity, the hull running o -> a -> q: orient(o, a, q) > 0
//    (a stays a convex hull vertex).
// When a certificate fails its edge is flipped; the certificates of the new diagonal (in
// exact terms the old polynomial negated, decided afresh) and of the quadrilateral's four sides
// are decided again.
//
// Scheduling, exact: every decision is the sign just after the exact current time, so
// simultaneous failures (co-circular grids) cascade through the queue at one instant until every
// certificate holds just after it.
//
// Scheduling, robust (CROP at eps; points on lines, in-circle certificates of degree 4): the
// structure's clock is the robust scheduler's grid. Every predicate is decided exactly just after
// the grid point g at or before now (world_time()), and every certificate's failure is the end
// of CROP's event interval (EVENTTIME), a grid point; all certificates share the grid, so the
// events of one cell are one instant at its end, processed out of order among themselves. At
// that instant the triangulation of the previous grid point may no longer be plane (a triangle
// inverted within the cell, its in-circle flip delayed): flips are made only where both old
// triangles turn counter-clockwise at g; a triangle found clockwise is repaired locally (one of
// its vertices, with a simple link, taken out by ear clipping of its link and inserted again,
// all with exact predicates at g), and the whole triangulation is built again at g only when no
// local repair applies or an instant's repairs exceed a budget; an orientation that may turn over
// and back within a cell is looked at again at its end, and instants that repair, change the hull
// or look again end with an audit of the hull's winding. Guarantee (docs/delaunay.md,
// "Robust scheduling"): after the simulator reaches t, triangles() is exactly the Delaunay
// triangulation just after world_time(), the last grid point at or before t (less than eps
// before it), ties broken as below. The classic scheduler is refused: its floating-point
// failure times can miss an orientation's failure and leave a folded triangulation undetected.
//
// Degenerate input, by rule (docs/delaunay.md):
//  - the triangulation at t is the one just after t (robust: just after the grid point at or
//    before t; the right limit), unique by
//  - co-circular for ever: the lifting perturbation by ids (core/incircle.hpp);
//  - collinear for ever: a point inside a hull edge is a vertex on it; all points collinear for
//    ever (or fewer than three): no triangle, the structure waits flat until an insert or an
//    update gives it a second dimension;
//  - identical motions: the smallest id stands for its group in the triangulation;
//  - a flip whose new triangles would not turn counter-clockwise just after now (points passing
//    through each other) is not made: the triangulation is rebuilt at that instant instead
//    (counted in `rebuilds`; robust: it first waits behind the instant's other events).
//
// Motions of degree <= 2 under the exact scheduler (in-circle certificates of degree 8, exact
// polynomials), <= 1 under the robust one (degree 4, CROP).

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "kinetic/core/description.hpp"
#include "kinetic/core/geometry.hpp"
#include "kinetic/core/id_order.hpp"
#include "kinetic/core/k_nearest.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/preconditions.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/structure.hpp"

namespace kinetic {

struct DelaunayCounters : ChangeCounters {
  std::uint64_t events = 0;
  std::uint64_t flips = 0;  ///< flips at events
  /// Flips made to restore the Delaunay property after a change: inserts, the repair of a
  /// removal's hole, and every insertion of a rebuild.
  std::uint64_t insert_flips = 0;
  /// Vertices taken out locally (remove, update) rather than by building again.
  std::uint64_t local_removals = 0;
  /// Whole triangulations built: at initialize(), after a refused flip, for a remove or update
  /// that could not be done locally (a hull vertex, a degenerate hole).
  std::uint64_t rebuilds = 0;
  std::uint64_t refused_flips = 0;  ///< flips that would have inverted a triangle
  /// Triangles that turned clockwise with no flip to mend them (points passing through each
  /// other): each built the triangulation again.
  std::uint64_t inversions = 0;
  /// Events among points at one place (passing through each other): each built it again.
  std::uint64_t collisions = 0;
  /// Robust scheduling: triangles found clockwise at a grid point (the triangulation folded
  /// within a cell), each repaired locally or by building again (local_repairs counts the first).
  std::uint64_t repairs = 0;
  std::uint64_t local_repairs = 0;
  /// Robust scheduling: events put back at the same instant, behind the others (an orientation
  /// event whose triangle's edge flips at this instant too, a flip refused for now).
  std::uint64_t deferrals = 0;
  /// Robust scheduling: certificates whose exact sign just after world_time() differed from
  /// CROP's pretended sign (a root exactly on a grid point): looked at again one cell later.
  std::uint64_t rechecks = 0;
  /// Robust scheduling: instants that ended with every triangle counter-clockwise but a hull
  /// winding twice (a double cover, from orientations that changed sign twice within a cell):
  /// each built the triangulation again.
  std::uint64_t unwound = 0;
  /// Robust scheduling: orientations looked at again at the end of a cell where they may turn
  /// over and back (CROP's turbulent intervals), each followed by an audit.
  std::uint64_t turbulent_checks = 0;
  std::uint64_t decisions = 0;  ///< certificates decided by the scheduler
  std::uint64_t queries = 0;
  std::uint64_t walk_steps = 0;  ///< triangles and vertices visited by point location and nearest
};

class KineticDelaunay {
 public:
  /// What the structure is and takes (core/description.hpp): the registry, the CLI and the
  /// Python class read it.
  [[nodiscard]] static StructureDescription description();

  /// Highest motion degree taken: in-circle certificates have degree 4 * 2 = 8 (exact
  /// scheduler); under the robust scheduler kMaxRobustDegree (CROP isolates the degree-4
  /// in-circles of points on lines).
  static constexpr int kMaxDegree = 2;
  static constexpr int kMaxRobustDegree = 1;
  /// The highest motion degree taken under a scheduler (0 for one it refuses).
  [[nodiscard]] static int max_degree(SchedulerKind kind) {
    return kind == SchedulerKind::Exact ? kMaxDegree
                                        : (kind == SchedulerKind::Robust ? kMaxRobustDegree : 0);
  }
  /// The motions' coefficients, expanded about t = 0, are 0 or of magnitude in
  /// [2^-kMagnitudeLog2, 2^kMagnitudeLog2) (about 2.9e-39 to 3.4e38): beyond, the exact
  /// in-circle arithmetic (coefficients of four times the motions' bits, roots at times as far
  /// as the magnitudes' ratio) takes seconds to minutes per run (docs/scheduling.md).
  static constexpr int kMagnitudeLog2 = 128;
  /// The vertex at infinity, in a triangle's vertex list.
  static constexpr std::uint32_t kInfinite = kNoIndex - 1;

  /// Points are the table's objects (dimension 2). Throws PreconditionError under the classic
  /// scheduler.
  KineticDelaunay(const MotionTable& points, Simulator& simulator, const Scheduler& scheduler);
  ~KineticDelaunay();
  KineticDelaunay(const KineticDelaunay&) = delete;
  KineticDelaunay& operator=(const KineticDelaunay&) = delete;

  void initialize();
  EventKind process(const Event& event);
  void insert(std::uint32_t index);
  void remove(std::uint32_t index);
  void motion_changed(std::uint32_t index);

  /// The time whose triangulation the structure holds: now under the exact scheduler; under
  /// the robust one the grid point at or before now (Scheduler::grid_floor), less than eps
  /// before now. Every predicate is decided just after it.
  [[nodiscard]] Time world_time() const;
  /// The triangles at now (point indices, each counter-clockwise from its smallest id, sorted by
  /// those ids): the Delaunay triangulation just after world_time(), ties broken as above.
  [[nodiscard]] std::vector<std::array<std::uint32_t, 3>> triangles();
  /// The exact nearest point to q at world_time() (t == now; the smallest id among equally near
  /// ones), by a greedy walk over Delaunay neighbours. `eps` is accepted for the query's contract
  /// and unused: the answer is exact. Empty when there are no points.
  [[nodiscard]] std::optional<std::uint32_t> nearest(Point2 q, double eps, Time t);
  /// The k points nearest to q at world_time() (t == now; all when fewer), by increasing
  /// distance, equal distances by id, exactly; `eps` accepted and unused. From the nearest
  /// vertex, a best-first search over Delaunay neighbours: the i-th nearest point is a Delaunay
  /// neighbour of a strictly nearer one (docs/delaunay.md), copies of identical motions beside
  /// their vertex.
  [[nodiscard]] std::vector<std::uint32_t> k_nearest(std::span<const double> q, std::size_t k,
                                                     double eps, Time t);
  /// The closest pair at world_time(), indices by ascending id (the smallest pair of ids among
  /// equally close ones): the shortest Delaunay edge, or two points at the same place. Empty for
  /// fewer than two points.
  [[nodiscard]] std::optional<std::array<std::uint32_t, 2>> closest_pair();
  /// The same answer from `pairs` (point indices, any order): a set of vertex pairs holding every
  /// closest pair of distinct vertices now, and every pair of vertices at one place now (e.g.
  /// the Delaunay edges of the shortest length now), the copies of identical motions added.
  [[nodiscard]] std::optional<std::array<std::uint32_t, 2>> closest_pair_among(
      std::span<const std::array<std::uint32_t, 2>> pairs) const;

  [[nodiscard]] std::size_t size() const { return size_; }
  /// The owner tags of its events: edge certificates, then triangle orientations.
  [[nodiscard]] OwnerRange owners() const { return OwnerRange{owner_, 2}; }
  [[nodiscard]] const DelaunayCounters& counters() const { return counters_; }
  [[nodiscard]] NamedCounters named_counters() const;
  [[nodiscard]] bool initialized() const { return sync_.initialized(); }
  [[nodiscard]] std::size_t certificates() const;
  [[nodiscard]] std::size_t certificates_per_object_max() const;
  /// Invariants: told every change; triangles and neighbours consistent (a sphere with the
  /// vertex at infinity); every finite triangle counter-clockwise just after now and every edge's
  /// certificate holding just after now, unless its event is due now; every queued event of
  /// this structure belongs to a live edge or triangle, and they are all counted; the groups of
  /// identical motions; once no event of the instant is left, a hull that winds once. Exact
  /// arithmetic at the exact now: O(n) certificates, for tests.
  [[nodiscard]] bool validate() const;

  /// The edge changes a structure built on the triangulation reads (KineticClosestPair), kept
  /// while record_edge_changes(true): the finite edge {a, b} entered a triangle (+1) or left one
  /// (-1), in the order the triangles changed. An edge is in the triangulation while its count
  /// (the triangles holding it) is positive. A rebuild (or going flat) is not itemised:
  /// edges_rebuilt() is set and every edge is to be read again (edges()).
  struct EdgeChange {
    std::uint32_t a = 0, b = 0;
    int delta = 0;
  };
  /// Starts (or stops) recording; edges_rebuilt() is true at the start.
  void record_edge_changes(bool on);
  [[nodiscard]] std::span<const EdgeChange> edge_changes() const { return edge_changes_; }
  [[nodiscard]] bool edges_rebuilt() const { return edges_rebuilt_; }
  void clear_edge_changes();
  /// The finite edges now, each once (point indices; none when flat).
  void edges(std::vector<std::array<std::uint32_t, 2>>& out) const;
  /// True when there is no triangulation (fewer than three points, or collinear for ever).
  [[nodiscard]] bool flat() const { return flat_; }

  /// Refuses a motion it cannot certify (degree > max_degree(kind), or a coefficient about t = 0
  /// of magnitude beyond kMagnitudeLog2), naming `where` and the id.
  static void require_motion(const MotionTable& points, std::uint32_t index, const char* where,
                             SchedulerKind kind = SchedulerKind::Exact);
  static void require_motion(std::span<const MotionPolynomial> motion, ObjectId id,
                             const char* where, SchedulerKind kind = SchedulerKind::Exact);

 private:
  // A triangle's record, an edge's decided certificate and what it watches: laid out in
  // src/delaunay/kinetic_delaunay.cpp (not part of the API).
  struct Face;
  struct Decision;
  struct Watch;

  [[nodiscard]] std::uint32_t twin(std::uint32_t h) const;
  [[nodiscard]] std::uint32_t canonical(std::uint32_t h) const;
  /// The four points of half-edge h = 3f + k: a = v[k+1], b = v[k+2], c = v[k], d across.
  [[nodiscard]] std::array<std::uint32_t, 4> quad(std::uint32_t h) const;
  [[nodiscard]] Watch watch(std::uint32_t h) const;
  /// The certificate of h's edge decided by the scheduler (exact: just after the exact now).
  [[nodiscard]] Decision decide(std::uint32_t h);
  /// The same under the robust scheduler: the exact sign just after the world time, and for a
  /// certificate holding there CROP's failure (motions valid since window_lo).
  [[nodiscard]] Decision decide_robust(const Watch& w, Time window_lo);
  /// The same sign by static predicates just after the world time (validate, insertion flips).
  [[nodiscard]] int holds_now(std::uint32_t h) const;
  [[nodiscard]] int orient_now(std::uint32_t a, std::uint32_t b, std::uint32_t c) const;
  /// orient_now of a face's vertices: > 0 for a finite face turning counter-clockwise, and for
  /// an infinite face.
  [[nodiscard]] int face_orientation(std::uint32_t f) const;
  /// sign(a - b) just after the world time.
  [[nodiscard]] int compare_now(const MotionPolynomial& a, const MotionPolynomial& b) const;
  /// u below w (then left of it) just after the world time.
  [[nodiscard]] bool below_now(std::uint32_t u, std::uint32_t w) const;
  /// The vertices around finite vertex v, counter-clockwise (out[j] follows v in its j-th face).
  void link_of(std::uint32_t v, std::vector<std::uint32_t>& out) const;
  /// Removes a queued event of this structure (a null or stale handle: nothing) and nulls it.
  void drop(EventHandle& e);
  /// True when the event is due at the current instant.
  [[nodiscard]] bool due_now(const EventHandle& e) const;
  /// Robust scheduling of a certificate `sign_of_holding * f > 0` holding just after the world
  /// time, checked against the scheduler's decision `at`: a failure to schedule, or a recheck
  /// one cell later where CROP's pretended sign disagrees.
  [[nodiscard]] Decision robust_decision(Scheduler::SignDecision at, int sign_of_holding);
  /// Robust scheduling: the grid point where the end t of a CROP interval is seen (t itself when
  /// that is not after now).
  [[nodiscard]] Time on_grid(Time t) const;
  /// Robust scheduling of an orientation certificate holding just after the world time: CROP's
  /// failure, or the end of the first cell where it may turn over and back, if earlier.
  [[nodiscard]] Decision robust_orientation(const ProductCombination& f, Time now, Time window_lo);
  /// Robust scheduling: one more deferral or repair at this instant; false (the caller builds
  /// again) once the instant's budget is spent, so an instant always ends.
  bool spend_instant_budget();
  /// Robust scheduling: face f is clockwise at the world time; repaired by taking out and
  /// inserting again a vertex of it whose link is a simple counter-clockwise polygon, else by
  /// building again.
  void repair(std::uint32_t f);
  /// The hull (the infinite faces' edges) is one cycle through distinct vertices winding once.
  [[nodiscard]] bool hull_winds_once() const;
  /// Robust scheduling: an audit event at the back of this instant (hull_winds_once(), else
  /// building again), after a repair or a change of the hull.
  void request_audit();
  /// The audit's payload, among the triangles' orientation events.
  static constexpr std::uint32_t kAudit = kNoIndex;
  /// True when finite, inner vertex v's link is a simple polygon turning counter-clockwise at
  /// the world time (ear clipping then triangulates it).
  [[nodiscard]] bool link_is_simple(std::uint32_t v) const;
  void cancel_certificates_of(std::uint32_t f);
  /// Decides and schedules the certificates of the faces' edges and orientations.
  void certify(std::span<const std::uint32_t> faces);
  void certify_orientation(std::uint32_t f);
  /// Decides and schedules the certificate of canonical half-edge h's edge.
  void certify_edge(std::uint32_t h);
  /// Flips h's edge; false (nothing changed) when a new finite triangle would not turn
  /// counter-clockwise just after now.
  bool flip(std::uint32_t h);
  /// The flip itself (no check): the triangles (a, b, c), (b, a, d) become (a, d, c), (d, b, c).
  void flip_edge(std::uint32_t h);
  /// Takes vertex v out of the triangulation: a hull vertex's triangles peeled off through its
  /// hull edges, an inner vertex's edges flipped away by ear clipping of its link, its last
  /// three triangles merged, Lawson's flips, the changed triangles certified. v's position is
  /// not read. False when no ear is found or a flip is refused (the caller builds again).
  bool remove_vertex(std::uint32_t v);
  /// Flips every edge on the stack (and those its flips uncover) that fails just after now;
  /// the faces changed are appended to `touched`. False when a flip was refused.
  bool restore(std::vector<std::uint32_t>& stack, std::vector<std::uint32_t>& touched);
  /// Adds point p to the triangulation (static: no certificate); the faces changed go to
  /// `touched`. False when p is a copy of a vertex (identical motions): it is hidden behind it.
  bool add_point(std::uint32_t p, std::vector<std::uint32_t>& touched);
  /// The face whose closure holds p just after now (a finite face, or an infinite one whose hull
  /// edge p sees strictly), by a visibility walk from `start`.
  [[nodiscard]] std::uint32_t locate(std::uint32_t p, std::uint32_t start);
  std::uint32_t new_face(std::array<std::uint32_t, 3> v, std::array<std::uint32_t, 3> n);
  void set_neighbour(std::uint32_t f, std::uint32_t old_n, std::uint32_t new_n);
  /// Sets face f's vertices, recording the edge changes.
  void set_vertices(std::uint32_t f, const std::array<std::uint32_t, 3>& v);
  /// Records the finite edges of a triangle entering (+1) or leaving (-1).
  void note_edges(const std::array<std::uint32_t, 3>& v, int delta);
  /// Builds the triangulation of the representatives from scratch at the exact now (or goes
  /// flat) and certifies every edge.
  void rebuild();
  /// Groups: the representative of p's identical-motion group (itself when it is a vertex).
  void hide(std::uint32_t p, std::uint32_t vertex);
  void unhide(std::uint32_t p);
  /// Replaces vertex `from` by `to` (same motion) in every face around it.
  void rename_vertex(std::uint32_t from, std::uint32_t to);
  [[nodiscard]] bool same_motion(std::uint32_t a, std::uint32_t b) const;
  /// True when u and w are joined by an edge (one of them finite).
  [[nodiscard]] bool adjacent(std::uint32_t u, std::uint32_t w) const;
  /// True when finite vertex v is a vertex of the hull (a face around it has infinity).
  [[nodiscard]] bool on_hull(std::uint32_t v) const;
  /// Calls visit(face) for the faces around finite vertex v, counter-clockwise, while it returns
  /// true (no allocation).
  template <class Visit>
  void around(std::uint32_t v, const Visit& visit) const;
  /// v's degree, counted up to `limit`.
  [[nodiscard]] std::size_t degree_up_to(std::uint32_t v, std::size_t limit) const;
  /// The faces around finite vertex v, counter-clockwise.
  void star(std::uint32_t v, std::vector<std::uint32_t>& out) const;
  /// sign(|a - q|^2 - |b - q|^2) at t, exactly.
  [[nodiscard]] int compare_distance(std::uint32_t a, std::uint32_t b, Point2 q, Time t) const;
  /// sign(|a - b|^2 - |c - d|^2) at t, exactly.
  [[nodiscard]] int compare_lengths(std::uint32_t a, std::uint32_t b, std::uint32_t c,
                                    std::uint32_t d, Time t) const;
  [[nodiscard]] bool coincide_at(std::uint32_t a, std::uint32_t b, Time t) const;
  [[nodiscard]] std::vector<std::uint32_t> vertices() const;
  /// Vertices of the triangulation (not flat): V = F / 2 + 1 on the sphere with infinity. O(1).
  [[nodiscard]] std::size_t vertex_count() const { return live_faces_ / 2 + 1; }
  /// add_point() and the certificates of the triangles it changed.
  void insert_vertex(std::uint32_t index);

  const MotionTable& points_;
  TableSync sync_{points_};
  Simulator& sim_;
  const Scheduler& scheduler_;
  const bool exact_;  ///< the exact scheduler (else robust)
  std::uint32_t owner_;
  std::vector<Face> faces_;
  // triangles() in the contract's order: the points' ranks by id, and scratch kept across queries.
  IdRanks id_ranks_;
  std::vector<std::array<std::uint32_t, 3>> triangle_scratch_;
  std::vector<std::uint32_t> count_scratch_;
  std::vector<std::uint32_t> free_faces_;
  std::size_t live_faces_ = 0;
  /// point index -> a face with it as a vertex (kNoIndex: not a vertex)
  std::vector<std::uint32_t> vertex_face_;
  /// Identical motions: rep_[p] is the vertex standing for p (p itself for a vertex, kNoIndex
  /// for an absent point); next_hidden_[v] chains the hidden members of v's group, by id.
  std::vector<std::uint32_t> rep_;
  std::vector<std::uint32_t> next_hidden_;
  std::size_t size_ = 0;  ///< live points (vertices and hidden)
  bool flat_ = true;      ///< no triangulation: fewer than 3 vertices, or collinear for ever
  std::uint32_t last_face_ = kNoIndex;  ///< where the next walk starts
  NearestCandidates nearest_;           ///< a k_nearest query's candidates (storage reused)
  std::vector<std::uint32_t> seen_;     ///< k_nearest: the query that reached a vertex
  std::uint32_t seen_round_ = 0;
  std::size_t queued_ = 0;
  std::vector<std::uint32_t> stamp_;  ///< scratch: per half-edge, the pass that certified it
  std::uint32_t pass_ = 0;
  bool building_ = false;  ///< inside rebuild(): no nested rebuild, no certificate yet
  bool record_edges_ = false;
  bool edges_rebuilt_ = false;
  std::vector<EdgeChange> edge_changes_;
  EventHandle audit_{};
  std::uint64_t budget_instant_ = ~std::uint64_t{0};  ///< the instant the budget below is for
  std::size_t budget_spent_ = 0;
  DelaunayCounters counters_;
};

static_assert(KineticStructure<KineticDelaunay>);

}  // namespace kinetic
