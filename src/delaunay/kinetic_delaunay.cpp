#include "kinetic/delaunay/kinetic_delaunay.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numeric>
#include <queue>
#include <stdexcept>
#include <string>

#include "kinetic/core/crop.hpp"
#include "kinetic/core/exact_time.hpp"
#include "kinetic/core/free_list.hpp"
#include "kinetic/core/incircle.hpp"

namespace kinetic {

// The records behind KineticDelaunay (declared in its header, laid out here).

struct KineticDelaunay::Face {
  std::array<std::uint32_t, 3> v{};  ///< counter-clockwise; kInfinite for the vertex at infinity
  std::array<std::uint32_t, 3> n{};  ///< n[k]: the face across the edge opposite v[k]
  /// cert[k]: the event of the edge opposite v[k], kept in the half-edge 3f + k that is the
  /// smaller of the edge's two (the other is null).
  std::array<EventHandle, 3> cert{};
  /// The event of the triangle's orientation (finite triangles): it turns clockwise only where
  /// points pass through each other, which no in-circle certificate sees.
  EventHandle orientation{};
  bool alive = false;
};

/// The certificate of an edge decided by the scheduler: holds (> 0) or fails now (< 0).
struct KineticDelaunay::Decision {
  int holds = 1;
  Scheduler::SignDecision at;  ///< failure of the certificate (when it holds)
};

/// What the certificate of h's edge watches, from its quad: nothing (both triangles infinite
/// on one side), the orientation of three finite points p[0], p[1], p[2] (an edge of an
/// infinite triangle: holds while > 0), or the in-circle of the quad (holds while < 0).
struct KineticDelaunay::Watch {
  enum class Kind : std::uint8_t { kNothing, kOrientation, kInCircle };
  Kind kind = Kind::kNothing;
  std::array<std::uint32_t, 4> p{};
};

namespace {
constexpr std::uint32_t next3(std::uint32_t k) { return k == 2 ? 0 : k + 1; }
constexpr std::uint32_t prev3(std::uint32_t k) { return k == 0 ? 2 : k - 1; }
}  // namespace

KineticDelaunay::KineticDelaunay(const MotionTable& points, Simulator& simulator,
                                 const Scheduler& scheduler)
    : points_(points),
      sim_(simulator),
      scheduler_(scheduler),
      exact_(scheduler.kind() == SchedulerKind::Exact),
      owner_(simulator.reserve_owners(2).first) {
  if (points.dimension() != 2) {
    precondition_failed("KineticDelaunay",
                        "the Delaunay triangulation takes points in the plane (dimension 2), not "
                        "dimension " +
                            std::to_string(points.dimension()));
  }
  if (scheduler.kind() == SchedulerKind::Classic) {
    precondition_failed("KineticDelaunay",
                        "the kinetic Delaunay triangulation takes the robust or the exact "
                        "scheduler, not the classic one: floating-point failure times can miss "
                        "a triangle's inversion and leave a folded triangulation undetected");
  }
  simulator.attach(scheduler);
}

KineticDelaunay::~KineticDelaunay() = default;

void KineticDelaunay::require_motion(std::span<const MotionPolynomial> motion, ObjectId id,
                                     const char* where, SchedulerKind kind) {
  for (std::size_t axis = 0; axis < motion.size(); ++axis) {
    if (motion[axis].degree > max_degree(kind)) {
      precondition_failed(
          where, "object " + std::to_string(id) + " moves with degree " +
                     std::to_string(motion[axis].degree) + " on axis " + std::to_string(axis) +
                     "; the Delaunay triangulation takes motions of degree <= " +
                     std::to_string(max_degree(kind)) +
                     (kind == SchedulerKind::Exact
                          ? std::string(" (its in-circle certificates have four times the "
                                        "motions' degree)")
                          : std::string(" under the robust scheduler (CROP isolates in-circle "
                                        "certificates of degree 4), of degree <= " +
                                        std::to_string(kMaxDegree) + " under the exact one")));
    }
    static_assert(kMagnitudeLog2 == 128, "the message below names the limit");
    if (const auto e = magnitude_beyond(motion[axis], kMagnitudeLog2)) {
      precondition_failed(
          where, "object " + std::to_string(id) + " moves on axis " + std::to_string(axis) +
                     " with a coefficient (about t = 0) of magnitude 2^" + std::to_string(*e) +
                     "; the Delaunay triangulation takes coefficients of "
                     "magnitude 2^-128 <= |c| < 2^128, about 2.9e-39 to 3.4e+38, "
                     "or 0 (its exact in-circle arithmetic takes seconds to "
                     "minutes beyond); rescale the units or write negligible "
                     "coefficients as 0");
    }
  }
}

void KineticDelaunay::require_motion(const MotionTable& points, std::uint32_t index,
                                     const char* where, SchedulerKind kind) {
  const std::array<MotionPolynomial, 2> motion{points.motion(index, 0), points.motion(index, 1)};
  require_motion(motion, points.id(index), where, kind);
}

NamedCounters KineticDelaunay::named_counters() const {
  return {{"events", counters_.events},
          {"flips", counters_.flips},
          {"insert_flips", counters_.insert_flips},
          {"inserts", counters_.inserts},
          {"removes", counters_.removes},
          {"updates", counters_.updates},
          {"rebuilds", counters_.rebuilds},
          {"local_removals", counters_.local_removals},
          {"refused_flips", counters_.refused_flips},
          {"inversions", counters_.inversions},
          {"collisions", counters_.collisions},
          {"repairs", counters_.repairs},
          {"local_repairs", counters_.local_repairs},
          {"deferrals", counters_.deferrals},
          {"rechecks", counters_.rechecks},
          {"unwound", counters_.unwound},
          {"turbulent_checks", counters_.turbulent_checks},
          {"decisions", counters_.decisions},
          {"queries", counters_.queries},
          {"walk_steps", counters_.walk_steps}};
}

// ---------------------------------------------------------------------------------------------
// Topology

std::uint32_t KineticDelaunay::twin(std::uint32_t h) const {
  const std::uint32_t f = h / 3;
  const std::uint32_t g = faces_[f].n[h % 3];
  const Face& G = faces_[g];
  for (std::uint32_t j = 0; j < 3; ++j) {
    if (G.n[j] == f) return 3 * g + j;
  }
  assert(false && "neighbours are not symmetric");
  return kNoIndex;
}

std::uint32_t KineticDelaunay::canonical(std::uint32_t h) const { return std::min(h, twin(h)); }

std::array<std::uint32_t, 4> KineticDelaunay::quad(std::uint32_t h) const {
  const Face& F = faces_[h / 3];
  const std::uint32_t k = h % 3;
  const std::uint32_t t = twin(h);
  return {F.v[next3(k)], F.v[prev3(k)], F.v[k], faces_[t / 3].v[t % 3]};
}

std::uint32_t KineticDelaunay::new_face(std::array<std::uint32_t, 3> v,
                                        std::array<std::uint32_t, 3> n) {
  const std::uint32_t f = take_record(faces_, free_faces_);
  Face& F = faces_[f];
  F.v = v;
  F.n = n;
  F.cert = {};
  F.alive = true;
  ++live_faces_;
  note_edges(v, +1);
  return f;
}

void KineticDelaunay::note_edges(const std::array<std::uint32_t, 3>& v, int delta) {
  if (!record_edges_ || building_) return;
  for (std::uint32_t k = 0; k < 3; ++k) {
    const std::uint32_t a = v[k], b = v[next3(k)];
    if (a != kInfinite && b != kInfinite) edge_changes_.push_back({a, b, delta});
  }
}

void KineticDelaunay::set_vertices(std::uint32_t f, const std::array<std::uint32_t, 3>& v) {
  note_edges(faces_[f].v, -1);
  faces_[f].v = v;
  note_edges(v, +1);
}

void KineticDelaunay::record_edge_changes(bool on) {
  record_edges_ = on;
  clear_edge_changes();
  edges_rebuilt_ = on;  // nothing recorded yet: the edges are to be read
}

void KineticDelaunay::clear_edge_changes() {
  edge_changes_.clear();
  edges_rebuilt_ = false;
}

void KineticDelaunay::edges(std::vector<std::array<std::uint32_t, 2>>& out) const {
  out.clear();
  if (flat_) return;
  for (std::uint32_t f = 0; f < faces_.size(); ++f) {
    const Face& F = faces_[f];
    if (!F.alive) continue;
    for (std::uint32_t k = 0; k < 3; ++k) {
      const std::uint32_t a = F.v[next3(k)], b = F.v[prev3(k)];
      if (a != kInfinite && b != kInfinite && canonical(3 * f + k) == 3 * f + k)
        out.push_back({a, b});
    }
  }
}

void KineticDelaunay::set_neighbour(std::uint32_t f, std::uint32_t old_n, std::uint32_t new_n) {
  for (std::uint32_t& x : faces_[f].n) {
    if (x == old_n) {
      x = new_n;
      return;
    }
  }
  assert(false && "not a neighbour");
}

template <class Visit>
void KineticDelaunay::around(std::uint32_t v, const Visit& visit) const {
  const std::uint32_t start = vertex_face_[v];
  std::uint32_t f = start;
  std::size_t steps = 0;
  do {
    if (!visit(f)) return;
    const Face& F = faces_[f];
    std::uint32_t i = 0;
    while (F.v[i] != v) ++i;
    f = F.n[next3(i)];  // across the edge (v[i+2], v): the next face counter-clockwise
  } while (f != start && ++steps <= faces_.size());
}

void KineticDelaunay::star(std::uint32_t v, std::vector<std::uint32_t>& out) const {
  out.clear();
  around(v, [&](std::uint32_t f) {
    out.push_back(f);
    return true;
  });
}

bool KineticDelaunay::adjacent(std::uint32_t u, std::uint32_t w) const {
  if (u == kInfinite) std::swap(u, w);
  if (u == kInfinite) return true;
  bool found = false;
  around(u, [&](std::uint32_t f) {
    const auto& v = faces_[f].v;
    found = v[0] == w || v[1] == w || v[2] == w;
    return !found;
  });
  return found;
}

bool KineticDelaunay::on_hull(std::uint32_t v) const {
  bool hull = false;
  around(v, [&](std::uint32_t f) {
    const auto& w = faces_[f].v;
    hull = std::find(w.begin(), w.end(), kInfinite) != w.end();
    return !hull;
  });
  return hull;
}

std::size_t KineticDelaunay::degree_up_to(std::uint32_t v, std::size_t limit) const {
  std::size_t d = 0;
  around(v, [&](std::uint32_t) { return ++d < limit; });
  return d;
}

// ---------------------------------------------------------------------------------------------
// Predicates just after the exact now

Time KineticDelaunay::world_time() const {
  return exact_ ? sim_.now() : Scheduler::grid_floor(scheduler_.eps(), sim_.now());
}

int KineticDelaunay::orient_now(std::uint32_t a, std::uint32_t b, std::uint32_t c) const {
  if (exact_) return sign_after(orientation(points_, a, b, c), sim_.exact_now());
  return sign_after(orientation(points_, a, b, c), world_time());
}

int KineticDelaunay::face_orientation(std::uint32_t f) const {
  const auto& v = faces_[f].v;
  if (v[0] == kInfinite || v[1] == kInfinite || v[2] == kInfinite) return 1;
  return orient_now(v[0], v[1], v[2]);
}

int KineticDelaunay::compare_now(const MotionPolynomial& a, const MotionPolynomial& b) const {
  return exact_ ? compare_after(a, b, sim_.exact_now()) : compare_after(a, b, world_time());
}

bool KineticDelaunay::below_now(std::uint32_t u, std::uint32_t w) const {
  const int sy = compare_now(points_.motion(u, 1), points_.motion(w, 1));
  if (sy != 0) return sy < 0;
  return compare_now(points_.motion(u, 0), points_.motion(w, 0)) < 0;
}

bool KineticDelaunay::due_now(const EventHandle& e) const {
  if (e.is_null() || !sim_.queue().contains(e)) return false;
  const Time t = sim_.queue().get(e).time;
  return exact_ ? t <= sim_.exact_now().upper() : t <= sim_.now();
}

KineticDelaunay::Watch KineticDelaunay::watch(std::uint32_t h) const {
  const auto [a, b, c, d] = quad(h);
  using Kind = Watch::Kind;
  if (a == kInfinite) return {Kind::kOrientation, {c, b, d, kNoIndex}};
  if (b == kInfinite) return {Kind::kOrientation, {d, a, c, kNoIndex}};
  if (d == kInfinite) {
    if (c == kInfinite) return {};
    return {Kind::kOrientation, {a, b, c, kNoIndex}};
  }
  if (c == kInfinite) return {Kind::kOrientation, {b, a, d, kNoIndex}};
  return {Kind::kInCircle, {a, b, c, d}};
}

int KineticDelaunay::holds_now(std::uint32_t h) const {
  const Watch w = watch(h);
  const auto& [a, b, c, d] = w.p;
  int s = 1;
  if (w.kind == Watch::Kind::kOrientation) {
    s = orient_now(a, b, c);
  } else if (w.kind == Watch::Kind::kInCircle) {
    const auto& m = points_;
    const InCircle f{
        {moving_point(m, a), moving_point(m, b), moving_point(m, c), moving_point(m, d)}};
    const std::array<ObjectId, 4> ids{m.id(a), m.id(b), m.id(c), m.id(d)};
    s = exact_ ? -perturbed_sign_after(f, ids, sim_.exact_now())
               : -perturbed_sign_after(f, ids, world_time());
  }
  return s == 0 ? 1 : s;  // collinear for ever: holds (never fails)
}

KineticDelaunay::Decision KineticDelaunay::robust_decision(Scheduler::SignDecision at,
                                                           int sign_of_holding) {
  Decision r;                  // holds (r.holds == 1)
  if (at.sign == 0) return r;  // never fails (the zero polynomial)
  if (at.sign * sign_of_holding > 0) {
    // CROP's pretended sign agrees: its EVENTTIME, the end of an event interval. That is a grid
    // point, or for a root exactly on grid point g the double after g: moved to g, where the
    // sign just after g already fails (unless that is now: a second root between g and the
    // double after it, left to CROP's order).
    r.at = std::move(at);
    if (r.at.failure != kTimeInfinity) r.at.failure = on_grid(r.at.failure);
    return r;
  }
  // The exact sign just after the grid point differs from CROP's pretended sign (a root exactly
  // on the grid point): looked at again at the next grid point, where the two agree.
  ++counters_.rechecks;
  r.at.failure = world_time() + Scheduler::grid_width(scheduler_.eps());
  return r;
}

KineticDelaunay::Decision KineticDelaunay::decide(std::uint32_t h) {
  ++counters_.decisions;
  const Watch w = watch(h);
  if (w.kind == Watch::Kind::kNothing) return Decision{};
  Time window_lo = -kTimeInfinity;
  const std::size_t count = w.kind == Watch::Kind::kInCircle ? 4 : 3;
  for (std::size_t i = 0; i < count; ++i) {
    window_lo = std::max(window_lo, points_.valid_from(w.p[i]));
  }
  if (!exact_) return decide_robust(w, window_lo);
  const Time now = sim_.now();
  const auto& m = points_;
  const auto& [a, b, c, d] = w.p;
  if (w.kind == Watch::Kind::kOrientation) {
    // An orientation certificate: it holds while the orientation is > 0.
    Decision r;
    r.at = scheduler_.decide(orientation(m, a, b, c), now, window_lo, sim_.counters());
    r.holds = r.at.sign >= 0 ? 1 : -1;  // 0: collinear for ever, never fails
    return r;
  }
  // In-circle: holds while incircle(a, b, c, d) < 0; the zero polynomial by the perturbation.
  const InCircle f{
      {moving_point(m, a), moving_point(m, b), moving_point(m, c), moving_point(m, d)}};
  Decision r;
  r.at = scheduler_.decide(f, sim_.counters());
  if (r.at.sign != 0) {
    r.holds = -r.at.sign;
    return r;
  }
  for (const int k : lifting_order({m.id(a), m.id(b), m.id(c), m.id(d)})) {
    const LiftingCofactor cof = lifting_cofactor(f, k);
    r.at = scheduler_.decide(cof.orientation, now, window_lo, sim_.counters());
    if (r.at.sign != 0) {
      r.holds = -cof.sign * r.at.sign;
      return r;
    }
  }
  return Decision{};  // four points collinear for ever: not an edge of a valid triangulation
}

KineticDelaunay::Decision KineticDelaunay::decide_robust(const Watch& w, Time window_lo) {
  // The exact sign just after the world time decides; a certificate failing there is flipped at
  // this instant (no failure time needed), one holding gets CROP's failure.
  const Time now = sim_.now(), world = world_time();
  const auto& m = points_;
  const auto& [a, b, c, d] = w.p;
  if (w.kind == Watch::Kind::kOrientation) {
    const ProductCombination f = orientation(m, a, b, c);
    const int s = sign_after(f, world);
    Decision r;
    if (s == 0) return r;  // collinear for ever: never fails
    r.holds = s;
    if (s < 0) return r;
    return robust_orientation(f, now, window_lo);
  }
  // In-circle: holds while incircle(a, b, c, d) < 0 just after the world time; the zero
  // polynomial by the perturbation's cofactors.
  const InCircle f{
      {moving_point(m, a), moving_point(m, b), moving_point(m, c), moving_point(m, d)}};
  int s = 0;
  const Scheduler::SignDecision at_g =
      scheduler_.decide_after_grid_point(f, -1, now, window_lo, sim_.counters(), s);
  if (s != 0) {
    Decision r;
    r.holds = -s;
    if (s > 0) return r;
    return robust_decision(at_g, -1);
  }
  for (const int k : lifting_order({m.id(a), m.id(b), m.id(c), m.id(d)})) {
    const LiftingCofactor cof = lifting_cofactor(f, k);
    const int sc = sign_after(cof.orientation, world);
    if (sc == 0) continue;
    Decision r;
    r.holds = -cof.sign * sc;
    if (r.holds < 0) return r;
    return robust_decision(scheduler_.decide(cof.orientation, now, window_lo, sim_.counters()),
                           -cof.sign);
  }
  return Decision{};  // four points collinear for ever: not an edge of a valid triangulation
}

// ---------------------------------------------------------------------------------------------
// Certificates

void KineticDelaunay::drop(EventHandle& e) {
  if (sim_.cancel(e)) --queued_;
}

void KineticDelaunay::cancel_certificates_of(std::uint32_t f) {
  drop(faces_[f].orientation);
  for (std::uint32_t k = 0; k < 3; ++k) {
    for (const std::uint32_t h : {3 * f + k, twin(3 * f + k)}) drop(faces_[h / 3].cert[h % 3]);
  }
}

void KineticDelaunay::certify(std::span<const std::uint32_t> faces) {
  ++pass_;
  if (stamp_.size() < 3 * faces_.size()) stamp_.resize(3 * faces_.size(), 0);
  for (const std::uint32_t f : faces) {
    if (!faces_[f].alive) continue;
    certify_orientation(f);
    for (std::uint32_t k = 0; k < 3; ++k) {
      const std::uint32_t h = canonical(3 * f + k);
      if (stamp_[h] == pass_) continue;
      stamp_[h] = pass_;
      certify_edge(h);
    }
  }
}

void KineticDelaunay::certify_edge(std::uint32_t h) {
  for (const std::uint32_t x : {h, twin(h)}) drop(faces_[x / 3].cert[x % 3]);
  const Decision d = decide(h);
  EventHandle& e = faces_[h / 3].cert[h % 3];
  if (d.holds < 0) {
    e = sim_.schedule_now(owner_, h);  // fails just after now: flipped at this instant
    ++queued_;
  } else if (d.at.failure != kTimeInfinity) {
    e = sim_.schedule(d.at.failure, d.at.exact, owner_, h);
    ++queued_;
  }
}

void KineticDelaunay::certify_orientation(std::uint32_t f) {
  Face& F = faces_[f];
  drop(F.orientation);
  if (std::find(F.v.begin(), F.v.end(), kInfinite) != F.v.end()) return;
  const auto& m = points_;
  const auto [a, b, c] = F.v;
  Time window_lo = std::max({m.valid_from(a), m.valid_from(b), m.valid_from(c)});
  ++counters_.decisions;
  Scheduler::SignDecision d;
  if (exact_) {
    d = scheduler_.decide(orientation(m, a, b, c), sim_.now(), window_lo, sim_.counters());
  } else if (orient_now(a, b, c) > 0) {
    // Robust: counter-clockwise just after the world time; CROP's failure when they agree.
    const Decision r = robust_orientation(orientation(m, a, b, c), sim_.now(), window_lo);
    d = r.at;
    d.sign = 1;
  }  // else not counter-clockwise: due now (d.sign == 0)
  EventHandle& e = faces_[f].orientation;
  if (d.sign <= 0) {
    e = sim_.schedule_now(owner_ + 1, f);  // not counter-clockwise just after now
    ++queued_;
  } else if (d.failure != kTimeInfinity) {
    e = sim_.schedule(d.failure, d.exact, owner_ + 1, f);
    ++queued_;
  }
}

// ---------------------------------------------------------------------------------------------
// Flips and insertion

bool KineticDelaunay::flip(std::uint32_t h) {
  const auto [a, b, c, d] = quad(h);
  // The new triangles (a, d, c) and (d, b, c) must turn counter-clockwise just after now.
  if (a != kInfinite && c != kInfinite && d != kInfinite && orient_now(a, d, c) <= 0) return false;
  if (b != kInfinite && c != kInfinite && d != kInfinite && orient_now(d, b, c) <= 0) return false;
  // The same vertex on both sides (a hull of three vertices losing one): no quadrilateral.
  if (c == d) return false;
  // A hull edge flipped makes the opposite vertex a hull vertex: not when it is one already (an
  // ear whose middle vertex goes inside at the same instant: that vertex's own edge to infinity
  // is the flip to make; the order of simultaneous events is not theirs to choose here).
  if ((c == kInfinite && on_hull(d)) || (d == kInfinite && on_hull(c))) return false;
  // An end of degree 3 would be left with degree 2 (two triangles on the same three points): a
  // vertex crossing the opposite edge of its only finite triangle at this instant.
  for (const std::uint32_t v : {a, b}) {
    if (v != kInfinite && degree_up_to(v, 4) <= 3) return false;
  }
  flip_edge(h);
  return true;
}

void KineticDelaunay::flip_edge(std::uint32_t h) {
  const std::uint32_t f = h / 3, k = h % 3;
  const std::uint32_t th = twin(h);
  const std::uint32_t g = th / 3, j = th % 3;
  const auto [a, b, c, d] = quad(h);
  const std::uint32_t n_bc = faces_[f].n[next3(k)], n_ca = faces_[f].n[prev3(k)];
  const std::uint32_t n_ad = faces_[g].n[next3(j)], n_db = faces_[g].n[prev3(j)];
  cancel_certificates_of(f);
  cancel_certificates_of(g);
  set_vertices(f, {a, d, c});
  set_vertices(g, {d, b, c});
  faces_[f].n = {g, n_ca, n_ad};
  faces_[g].n = {n_bc, f, n_db};
  set_neighbour(n_ad, g, f);
  set_neighbour(n_bc, f, g);
  for (const auto& [v, face] :
       {std::pair{a, f}, std::pair{c, f}, std::pair{d, g}, std::pair{b, g}}) {
    if (v != kInfinite) vertex_face_[v] = face;
  }
  last_face_ = f;
}

bool KineticDelaunay::remove_vertex(std::uint32_t v) {
  std::vector<std::uint32_t> ring, link, touched;
  const auto at = [&](std::uint32_t f, std::uint32_t k) {  // the vertex k after v in face f
    const Face& F = faces_[f];
    std::uint32_t i = 0;
    while (F.v[i] != v) ++i;
    return F.v[(i + k) % 3];
  };
  const auto infinite = [&](std::uint32_t f) {
    return std::find(faces_[f].v.begin(), faces_[f].v.end(), kInfinite) != faces_[f].v.end();
  };
  // A hull vertex: its finite triangles are peeled off the triangulated region one by one, by
  // flipping its hull edge v-x (triangles (v, x, y) and (x, v, infinity)) into (v, infinity, y)
  // and (infinity, x, y): the region stays simple, its boundary runs x -> y instead of through
  // v, and Lawson's flips below make it convex again (the pockets lie in v's old star, which
  // holds no other point). Left with one finite triangle, v has degree 3.
  while (on_hull(v) && degree_up_to(v, 4) > 3) {
    star(v, ring);
    bool peeled = false;
    for (const std::uint32_t f : ring) {
      if (infinite(f)) continue;
      const std::uint32_t y = at(f, 2);
      std::uint32_t k = 0;
      while (faces_[f].v[k] != y) ++k;
      const std::uint32_t g = twin(3 * f + k) / 3;
      if (!infinite(g)) continue;  // v-x is not a hull edge
      if (on_hull(y)) continue;    // y would be on the hull twice (points collinear for ever)
      flip_edge(3 * f + k);
      touched.insert(touched.end(), {f, g});
      peeled = true;
      break;
    }
    if (!peeled) return false;
  }
  // Ear clipping of the hole around v, by flips of v's edges: an edge v-w goes when its link
  // neighbours p, n make (p, w, n) an ear of the link polygon (convex at w, no other link vertex
  // in it or on it), which the flip makes a triangle. v's own position is never read: it may
  // have left the table or moved elsewhere.
  while (true) {
    star(v, ring);
    if (ring.size() <= 3) break;
    link_of(v, link);  // link[j] follows v in ring[j]
    const std::size_t m = link.size();
    bool clipped = false;
    for (std::size_t j = 0; j < m && !clipped; ++j) {
      const std::uint32_t p = link[(j + m - 1) % m], w = link[j], n = link[(j + 1) % m];
      if (orient_now(p, w, n) <= 0) continue;
      // Its diagonal p-n must not be an edge already (it can be, outside the link, in a
      // triangulation folded over itself: the flip would make a second p-n edge).
      if (adjacent(p, n)) continue;
      bool ear = true;
      for (std::size_t i = 0; i < m && ear; ++i) {
        const std::uint32_t u = link[i];
        if (u == p || u == w || u == n) continue;
        ear = !(orient_now(p, w, u) >= 0 && orient_now(w, n, u) >= 0 && orient_now(n, p, u) >= 0);
      }
      if (!ear) continue;
      // The edge v-w in the face (v, w, n): opposite n.
      const std::uint32_t f = ring[j];
      std::uint32_t k = 0;
      while (faces_[f].v[k] != n) ++k;
      const std::uint32_t g = twin(3 * f + k) / 3;
      flip_edge(3 * f + k);
      touched.insert(touched.end(), {f, g});
      clipped = true;
    }
    if (!clipped) return false;
  }
  // Three triangles (v, x1, x2), (v, x2, x3), (v, x3, x1) become (x1, x2, x3).
  std::array<std::uint32_t, 3> x{}, outer{};
  for (std::size_t j = 0; j < 3; ++j) {
    x[j] = at(ring[j], 1);
    const Face& F = faces_[ring[j]];
    std::uint32_t i = 0;
    while (F.v[i] != v) ++i;
    outer[j] = F.n[i];  // across the edge (x_j, x_j+1)
  }
  const bool merged_infinite = x[0] == kInfinite || x[1] == kInfinite || x[2] == kInfinite;
  if (!merged_infinite && orient_now(x[0], x[1], x[2]) <= 0) return false;
  for (const std::uint32_t f : ring) cancel_certificates_of(f);
  const std::uint32_t merged = ring[0];
  set_vertices(merged, {x[0], x[1], x[2]});
  faces_[merged].n = {outer[1], outer[2], outer[0]};
  for (std::size_t j = 1; j < 3; ++j) {
    set_neighbour(outer[j], ring[j], merged);
    note_edges(faces_[ring[j]].v, -1);
    faces_[ring[j]].alive = false;
    free_faces_.push_back(ring[j]);
    --live_faces_;
  }
  for (const std::uint32_t q : x) {
    if (q != kInfinite) vertex_face_[q] = merged;
  }
  vertex_face_[v] = kNoIndex;
  last_face_ = merged;
  touched.push_back(merged);
  // The ears are triangles, not yet Delaunay: Lawson's flips from every edge touched.
  std::vector<std::uint32_t> stack;
  for (const std::uint32_t f : touched) {
    if (!faces_[f].alive) continue;
    for (std::uint32_t k = 0; k < 3; ++k) stack.push_back(3 * f + k);
  }
  if (!restore(stack, touched)) return false;
  ++counters_.local_removals;
  certify(touched);
  return true;
}

bool KineticDelaunay::restore(std::vector<std::uint32_t>& stack,
                              std::vector<std::uint32_t>& touched) {
  std::size_t guard = 0;
  const std::size_t limit = 64 * (faces_.size() + 16) * (faces_.size() + 16);
  while (!stack.empty()) {
    const std::uint32_t h = stack.back();
    stack.pop_back();
    if (!faces_[h / 3].alive || holds_now(h) > 0) continue;
    const std::uint32_t f = h / 3, g = twin(h) / 3;
    if (++guard > limit) return false;
    if (!flip(h)) return false;
    ++counters_.insert_flips;
    touched.push_back(f);
    touched.push_back(g);
    // The quadrilateral's sides: in F = (a, d, c) the edges opposite c and a... all four outer.
    stack.push_back(3 * f + 1);  // (c, a)
    stack.push_back(3 * f + 2);  // (a, d)
    stack.push_back(3 * g + 0);  // (b, c)
    stack.push_back(3 * g + 2);  // (d, b)
  }
  return true;
}

std::uint32_t KineticDelaunay::locate(std::uint32_t p, std::uint32_t start) {
  std::uint32_t f = start;
  const std::size_t limit = 4 * faces_.size() + 16;
  for (std::size_t step = 0; step < limit; ++step) {
    ++counters_.walk_steps;
    const Face& F = faces_[f];
    std::uint32_t inf = 3;
    for (std::uint32_t k = 0; k < 3; ++k) {
      if (F.v[k] == kInfinite) inf = k;
    }
    if (inf < 3) {
      // Outside the hull edge (v[inf+1], v[inf+2]) strictly: here; otherwise back inside.
      if (orient_now(F.v[next3(inf)], F.v[prev3(inf)], p) > 0) return f;
      f = F.n[inf];
      continue;
    }
    bool moved = false;
    for (std::uint32_t r = 0; r < 3 && !moved; ++r) {
      const std::uint32_t k = (r + static_cast<std::uint32_t>(step)) % 3;
      if (orient_now(F.v[next3(k)], F.v[prev3(k)], p) < 0) {
        f = F.n[k];
        moved = true;
      }
    }
    if (!moved) return f;
  }
  // The walk did not end (it does in a Delaunay triangulation): scan every face.
  for (std::uint32_t g = 0; g < faces_.size(); ++g) {
    const Face& F = faces_[g];
    if (!F.alive) continue;
    bool inside = true;
    for (std::uint32_t k = 0; k < 3 && inside; ++k) {
      const std::uint32_t u = F.v[next3(k)], w = F.v[prev3(k)];
      if (F.v[k] == kInfinite) {
        inside = orient_now(u, w, p) > 0;
      } else if (u != kInfinite && w != kInfinite) {
        inside = orient_now(u, w, p) >= 0;
      }
    }
    if (inside) return g;
  }
  assert(false && "no face holds the point");
  return start;
}

bool KineticDelaunay::add_point(std::uint32_t p, std::vector<std::uint32_t>& touched) {
  std::uint32_t start = last_face_;
  if (start == kNoIndex || start >= faces_.size() || !faces_[start].alive) {
    start = 0;
    while (!faces_[start].alive) ++start;
  }
  const std::uint32_t f = locate(p, start);
  const Face F = faces_[f];
  std::vector<std::uint32_t> stack;
  bool infinite = false;
  for (const std::uint32_t v : F.v) infinite = infinite || v == kInfinite;
  std::uint32_t on_edge = 3;
  if (!infinite) {
    int zeros = 0;
    for (std::uint32_t k = 0; k < 3; ++k) {
      if (orient_now(F.v[next3(k)], F.v[prev3(k)], p) == 0) {
        ++zeros;
        on_edge = k;
      }
    }
    if (zeros >= 2) {
      // On two edges' lines for ever: at their common vertex, the same motion.
      for (std::uint32_t k = 0; k < 3; ++k) {
        if (same_motion(F.v[k], p)) {
          hide(p, F.v[k]);
          return false;
        }
      }
      assert(false && "a point on two edges' lines is at their vertex");
    }
  }
  if (on_edge == 3) {
    // Split f in three: (p, v1, v2) in f, (v0, p, v2), (v0, v1, p).
    const auto [v0, v1, v2] = F.v;
    const auto [n0, n1, n2] = F.n;
    cancel_certificates_of(f);
    const std::uint32_t f1 = new_face({v0, p, v2}, {f, n1, kNoIndex});
    const std::uint32_t f2 = new_face({v0, v1, p}, {f, f1, n2});
    faces_[f1].n[2] = f2;
    set_vertices(f, {p, v1, v2});
    faces_[f].n = {n0, f1, f2};
    set_neighbour(n1, f, f1);
    set_neighbour(n2, f, f2);
    vertex_face_[p] = f;
    for (const auto& [v, face] : {std::pair{v0, f1}, std::pair{v1, f}, std::pair{v2, f}}) {
      if (v != kInfinite) vertex_face_[v] = face;
    }
    touched.insert(touched.end(), {f, f1, f2});
    stack = {3 * f + 0, 3 * f1 + 1, 3 * f2 + 2};
  } else {
    // On the edge opposite v[on_edge]: split both triangles of the edge.
    const std::uint32_t h = 3 * f + on_edge;
    const std::uint32_t th = twin(h);
    const std::uint32_t g = th / 3, j = th % 3;
    const auto [a, b, c, d] = quad(h);
    const std::uint32_t n_bc = F.n[next3(on_edge)], n_ca = F.n[prev3(on_edge)];
    const std::uint32_t n_ad = faces_[g].n[next3(j)], n_db = faces_[g].n[prev3(j)];
    cancel_certificates_of(f);
    cancel_certificates_of(g);
    const std::uint32_t h1 = new_face({c, p, b}, {g, n_bc, f});
    const std::uint32_t h2 = new_face({d, p, a}, {f, n_ad, g});
    set_vertices(f, {c, a, p});
    faces_[f].n = {h2, h1, n_ca};
    set_vertices(g, {d, b, p});
    faces_[g].n = {h1, h2, n_db};
    set_neighbour(n_bc, f, h1);
    set_neighbour(n_ad, g, h2);
    vertex_face_[p] = f;
    for (const auto& [v, face] :
         {std::pair{a, f}, std::pair{b, g}, std::pair{c, f}, std::pair{d, g}}) {
      if (v != kInfinite) vertex_face_[v] = face;
    }
    touched.insert(touched.end(), {f, g, h1, h2});
    stack = {3 * f + 2, 3 * h1 + 1, 3 * g + 2, 3 * h2 + 1};
  }
  rep_[p] = p;
  last_face_ = f;
  if (!restore(stack, touched)) {
    // A static insertion into a triangulation that is Delaunay just after now never meets a
    // refused flip; if it does while building, building again would meet it again.
    if (building_) {
      throw std::logic_error(
          "KineticDelaunay: a flip was refused while building the triangulation (an internal "
          "failure; please report the scenario)");
    }
    rebuild();
  }
  return true;
}

// ---------------------------------------------------------------------------------------------
// Groups of identical motions

bool KineticDelaunay::same_motion(std::uint32_t a, std::uint32_t b) const {
  return compare_now(points_.motion(a, 0), points_.motion(b, 0)) == 0 &&
         compare_now(points_.motion(a, 1), points_.motion(b, 1)) == 0;
}

void KineticDelaunay::rename_vertex(std::uint32_t from, std::uint32_t to) {
  if (!flat_ && vertex_face_[from] != kNoIndex) {
    std::vector<std::uint32_t> faces;
    star(from, faces);
    for (const std::uint32_t f : faces) {
      std::array<std::uint32_t, 3> v = faces_[f].v;
      std::replace(v.begin(), v.end(), from, to);
      set_vertices(f, v);
    }
    vertex_face_[to] = vertex_face_[from];
    vertex_face_[from] = kNoIndex;
    // The same motion, another id: the lifting perturbation orders ties by id, so the star's
    // edges may no longer hold just after now: flipped until they do, then decided again.
    if (!building_) {
      std::vector<std::uint32_t> stack;
      for (const std::uint32_t f : faces) {
        for (std::uint32_t k = 0; k < 3; ++k) stack.push_back(3 * f + k);
      }
      if (!restore(stack, faces)) {
        rebuild();
        return;
      }
      certify(faces);
    }
    return;
  }
  vertex_face_[from] = kNoIndex;
}

void KineticDelaunay::hide(std::uint32_t p, std::uint32_t vertex) {
  // The two groups merged, their members by id: the vertex and its chain, p and its chain (p
  // may stand for a group of its own: a rebuild after an update meets the group the update
  // left, and its chain must not be lost).
  std::vector<std::uint32_t> members;
  for (std::uint32_t x = vertex; x != kNoIndex; x = next_hidden_[x]) members.push_back(x);
  assert(rep_[p] == p || rep_[p] == kNoIndex);
  for (std::uint32_t x = p; x != kNoIndex; x = next_hidden_[x]) members.push_back(x);
  std::sort(members.begin(), members.end(),
            [&](std::uint32_t x, std::uint32_t y) { return points_.id(x) < points_.id(y); });
  const std::uint32_t rep = members.front();
  // The groups first, then the rename (which may build the triangulation again from them).
  for (std::size_t i = 0; i < members.size(); ++i) {
    rep_[members[i]] = rep;
    next_hidden_[members[i]] = i + 1 < members.size() ? members[i + 1] : kNoIndex;
  }
  if (rep != vertex) rename_vertex(vertex, rep);
}

void KineticDelaunay::unhide(std::uint32_t p) {
  const std::uint32_t rep = rep_[p];
  assert(rep != kNoIndex);
  if (rep == p) {
    // p is the vertex: the next member takes its place. The groups are made right before the
    // triangles are renamed, since a rename that cannot restore the Delaunay property builds
    // the triangulation again from the groups.
    const std::uint32_t next = next_hidden_[p];
    rep_[p] = kNoIndex;
    next_hidden_[p] = kNoIndex;
    if (next != kNoIndex) {
      for (std::uint32_t x = next; x != kNoIndex; x = next_hidden_[x]) rep_[x] = next;
      rename_vertex(p, next);
    }
    return;
  }
  std::uint32_t x = rep;
  while (next_hidden_[x] != p) x = next_hidden_[x];
  next_hidden_[x] = next_hidden_[p];
  rep_[p] = kNoIndex;
  next_hidden_[p] = kNoIndex;
}

// ---------------------------------------------------------------------------------------------
// Building

std::vector<std::uint32_t> KineticDelaunay::vertices() const {
  std::vector<std::uint32_t> out;
  for (const std::uint32_t i : points_.alive_indices()) {
    if (i < rep_.size() && rep_[i] == i) out.push_back(i);
  }
  return out;
}

void KineticDelaunay::rebuild() {
  ++counters_.rebuilds;
  // A structure reading the edge changes reads every edge again instead.
  edge_changes_.clear();
  edges_rebuilt_ = true;
  struct Building {
    bool& flag;
    explicit Building(bool& f) : flag(f) { flag = true; }
    ~Building() { flag = false; }
  } building(building_);
  for (std::uint32_t f = 0; f < faces_.size(); ++f) {
    if (!faces_[f].alive) continue;
    for (EventHandle* e :
         {&faces_[f].cert[0], &faces_[f].cert[1], &faces_[f].cert[2], &faces_[f].orientation})
      drop(*e);
  }
  faces_.clear();
  free_faces_.clear();
  live_faces_ = 0;
  last_face_ = kNoIndex;
  std::fill(vertex_face_.begin(), vertex_face_.end(), kNoIndex);
  std::vector<std::uint32_t> order = vertices();
  const auto& m = points_;
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    const int sx = compare_now(m.motion(a, 0), m.motion(b, 0));
    if (sx != 0) return sx < 0;
    const int sy = compare_now(m.motion(a, 1), m.motion(b, 1));
    if (sy != 0) return sy < 0;
    return m.id(a) < m.id(b);
  });
  // Identical motions are adjacent now (equal just after now means equal for ever).
  std::vector<std::uint32_t> distinct;
  for (const std::uint32_t p : order) {
    if (!distinct.empty() && same_motion(distinct.back(), p)) {
      hide(p, distinct.back());
      distinct.back() = rep_[p];
    } else {
      distinct.push_back(p);
    }
  }
  flat_ = true;
  std::size_t third = distinct.size();
  for (std::size_t k = 2; k < distinct.size() && third == distinct.size(); ++k) {
    if (orient_now(distinct[0], distinct[1], distinct[k]) != 0) third = k;
  }
  if (third == distinct.size()) return;  // fewer than three, or collinear for ever
  flat_ = false;
  std::uint32_t a = distinct[0], b = distinct[1];
  const std::uint32_t c = distinct[third];
  if (orient_now(a, b, c) < 0) std::swap(a, b);
  // The triangle (a, b, c) and the infinite triangles on its three sides.
  const std::uint32_t t = new_face({a, b, c}, {});
  const std::uint32_t i0 = new_face({b, a, kInfinite}, {});
  const std::uint32_t i1 = new_face({c, b, kInfinite}, {});
  const std::uint32_t i2 = new_face({a, c, kInfinite}, {});
  faces_[t].n = {i1, i2, i0};
  faces_[i0].n = {i2, i1, t};
  faces_[i1].n = {i0, i2, t};
  faces_[i2].n = {i1, i0, t};
  vertex_face_[a] = vertex_face_[b] = vertex_face_[c] = t;
  last_face_ = t;
  std::vector<std::uint32_t> touched;
  const std::uint64_t build = counters_.rebuilds;
  for (std::size_t k = 2; k < distinct.size(); ++k) {
    if (k == third) continue;
    touched.clear();
    (void)add_point(distinct[k], touched);
    if (counters_.rebuilds != build) return;  // a refused flip built it again, wholly
  }
  std::vector<std::uint32_t> all;
  for (std::uint32_t f = 0; f < faces_.size(); ++f) {
    if (faces_[f].alive) all.push_back(f);
  }
  certify(all);
}

void KineticDelaunay::initialize() {
  const std::vector<std::uint32_t> alive = points_.alive_indices();
  for (const std::uint32_t i : alive)
    require_motion(points_, i, "KineticDelaunay::initialize", scheduler_.kind());
  const std::size_t cap = points_.capacity();
  vertex_face_.assign(cap, kNoIndex);
  rep_.assign(cap, kNoIndex);
  next_hidden_.assign(cap, kNoIndex);
  size_ = alive.size();
  for (const std::uint32_t i : alive) rep_[i] = i;
  rebuild();
  sync_.note();
}

// ---------------------------------------------------------------------------------------------
// Events and changes

EventKind KineticDelaunay::process(const Event& event) {
  const auto log = [&](const char* kind, std::span<const std::uint32_t> corners) {
    if (!sim_.logging_events()) return;
    std::vector<ObjectId> ids;
    for (const std::uint32_t q : corners) {
      if (q != kInfinite) ids.push_back(points_.id(q));
    }
    std::sort(ids.begin(), ids.end());
    sim_.log_event(kind, ids);
  };
  if (event.owner != owner_ && event.payload == kAudit) {
    // Robust: the instant's folds are mended; once no other event is due at it, the hull must
    // wind once (every triangle then turns counter-clockwise, so the triangulation is plane).
    audit_ = EventHandle{};
    if (sim_.event_due_by(sim_.now()) && spend_instant_budget()) {
      request_audit();  // behind the instant's other events (within the instant's budget)
      return EventKind::Internal;
    }
    if (flat_ || hull_winds_once()) return EventKind::Internal;
    ++counters_.unwound;
    rebuild();
    return EventKind::External;
  }
  if (event.owner != owner_) {
    // A triangle turns clockwise: points passing through each other (no in-circle certificate
    // fails there), or under robust scheduling a flip delayed to the end of its cell. When an
    // edge of it has its own event at this instant, that flip may mend it: looked at again after
    // them. Otherwise built again just after now (exact), repaired (robust).
    const std::uint32_t f = event.payload;
    faces_[f].orientation = EventHandle{};
    --queued_;
    ++counters_.events;
    if (!exact_ && face_orientation(f) > 0) {
      // Counter-clockwise at the grid point after all (a recheck, or the end of a cell where it
      // may have turned over and back): decided again, and the hull audited.
      certify_orientation(f);
      request_audit();
      return EventKind::Internal;
    }
    bool pending = false;
    for (std::uint32_t k = 0; k < 3 && !pending; ++k) {
      const std::uint32_t h = canonical(3 * f + k);
      pending = due_now(faces_[h / 3].cert[h % 3]);
    }
    if (pending && (exact_ || spend_instant_budget())) {
      if (!exact_) ++counters_.deferrals;
      faces_[f].orientation = sim_.schedule_now(owner_ + 1, f);
      ++queued_;
      return EventKind::Internal;
    }
    ++counters_.inversions;
    const std::array<std::uint32_t, 3> corners = faces_[f].v;
    if (exact_) {
      rebuild();
    } else {
      repair(f);
    }
    log("inversion", corners);
    return EventKind::External;
  }
  const std::uint32_t h = event.payload;
  faces_[h / 3].cert[h % 3] = EventHandle{};
  --queued_;
  ++counters_.events;
  if (!exact_ && holds_now(h) > 0) {
    // Holds just after the grid point (a recheck, or the end of a cell where a hull turn may
    // have turned over and back): decided again, and the hull audited.
    certify_edge(h);
    request_audit();
    return EventKind::Internal;
  }
  const auto [a, b, c, d] = quad(h);
  const std::uint32_t f = h / 3, g = twin(h) / 3;
  const std::array<std::uint32_t, 4> corners{a, b, c, d};
  // Two of the four points at one place now (points passing through each other): a flip there
  // may leave a triangulation that covers the plane twice with every certificate holding, so it
  // is built again just after now instead.
  bool collision = false;
  const auto at = [&](std::uint32_t i) { return moving_point(points_, i); };
  for (std::size_t i = 0; i < 4 && !collision; ++i) {
    for (std::size_t j = i + 1; j < 4 && !collision; ++j) {
      if (corners[i] == kInfinite || corners[j] == kInfinite) continue;
      collision = exact_ ? kinetic::coincide_at(at(corners[i]), at(corners[j]), sim_.exact_now())
                         : coincide_at(corners[i], corners[j], world_time());
    }
  }
  // Robust: one of the edge's triangles clockwise at the grid point (folded within the cell):
  // the fold is repaired, and the edge decided again with the triangles around it.
  // (A hull edge's certificate is its triangle's orientation: its flip is the mend.)
  const bool in_circle = a != kInfinite && b != kInfinite && c != kInfinite && d != kInfinite;
  const std::uint32_t folded = exact_ || collision || !in_circle ? kNoIndex
                               : face_orientation(f) <= 0        ? f
                               : face_orientation(g) <= 0        ? g
                                                                 : kNoIndex;
  if (collision) {
    ++counters_.collisions;
    rebuild();
  } else if (folded != kNoIndex) {
    ++counters_.inversions;
    repair(folded);
    log("inversion", corners);  // the edge's four points: one of its triangles had turned
    return EventKind::External;
  } else if (flip(h)) {
    ++counters_.flips;
    if (!exact_ && !in_circle) request_audit();  // the hull changed
    const std::array<std::uint32_t, 2> changed{f, g};
    certify(changed);
  } else if (!exact_ && sim_.event_due_by(sim_.now()) && spend_instant_budget()) {
    // Refused for now (simultaneous events decide the order): behind the instant's others.
    ++counters_.deferrals;
    faces_[h / 3].cert[h % 3] = sim_.schedule_now(owner_, h);
    ++queued_;
    return EventKind::Internal;
  } else {
    ++counters_.refused_flips;
    rebuild();
  }
  log("flip", corners);
  return EventKind::External;
}

Time KineticDelaunay::on_grid(Time t) const {
  // An interval of CROP ends on a grid point g; around a root exactly on g it ends at the double
  // after g (the sign just after g is already the new one: g), or at the double before g (the
  // cell's own end: g). Either way the time a decision just after a grid point sees it; kept as
  // it is when that is not after now (a second root right after g: the decision at t looks
  // again one cell later, so every instant moves on).
  const Time g = Scheduler::grid_floor(scheduler_.eps(), t);
  Time to = t;
  if (t == g || t == std::nextafter(g, kTimeInfinity)) {
    to = g;
  } else {
    to = g + Scheduler::grid_width(scheduler_.eps());
  }
  return to > sim_.now() ? to : t;
}

KineticDelaunay::Decision KineticDelaunay::robust_orientation(const ProductCombination& f, Time now,
                                                              Time window_lo) {
  // An orientation that may turn over and back within one cell (a turbulent interval, which
  // EVENTTIME does not report) is looked at again at the end of that cell, where an audit
  // checks that the triangulation did not end up covering the plane twice.
  Time turbulent = kTimeInfinity;
  Decision r =
      robust_decision(scheduler_.decide(f, now, window_lo, sim_.counters(), &turbulent), 1);
  if (turbulent < r.at.failure) {
    r.at.failure = on_grid(turbulent);
    r.at.exact = {};
    ++counters_.turbulent_checks;
  }
  return r;
}

bool KineticDelaunay::spend_instant_budget() {
  if (sim_.instant() != budget_instant_) {
    budget_instant_ = sim_.instant();
    budget_spent_ = 0;
  }
  return ++budget_spent_ <= 4 * live_faces_ + 64;
}

void KineticDelaunay::repair(std::uint32_t f) {
  ++counters_.repairs;
  request_audit();
  if (spend_instant_budget() && vertex_count() > 4) {
    std::array<std::uint32_t, 3> v = faces_[f].v;  // a finite face: its orientation failed
    assert(std::find(v.begin(), v.end(), kInfinite) == v.end());
    std::sort(v.begin(), v.end(),
              [&](std::uint32_t x, std::uint32_t y) { return points_.id(x) < points_.id(y); });
    for (const std::uint32_t x : v) {
      if (on_hull(x) || !link_is_simple(x)) continue;
      // x's star is the fold: its hole is filled from its link alone (x's position unread), and
      // x goes in again where it is.
      const std::uint64_t builds = counters_.rebuilds;
      if (!remove_vertex(x)) break;
      insert_vertex(x);
      if (counters_.rebuilds == builds) ++counters_.local_repairs;
      return;
    }
  }
  rebuild();
}

void KineticDelaunay::link_of(std::uint32_t v, std::vector<std::uint32_t>& out) const {
  out.clear();
  around(v, [&](std::uint32_t f) {
    const auto& w = faces_[f].v;
    const std::uint32_t i = w[0] == v ? 0 : (w[1] == v ? 1 : 2);
    out.push_back(w[next3(i)]);
    return true;
  });
}

bool KineticDelaunay::link_is_simple(std::uint32_t v) const {
  std::vector<std::uint32_t> link;
  link_of(v, link);
  const std::size_t m = link.size();
  if (m < 3) return false;
  std::vector<std::uint32_t> sorted = link;
  std::sort(sorted.begin(), sorted.end());
  if (sorted.back() == kInfinite ||
      std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end())
    return false;
  const auto at = [&](std::size_t i) { return link[i % m]; };
  // No two edges meet but neighbours at their common vertex, and no turn is straight (a
  // polygon turning back on itself), checked conservatively: touching counts as meeting.
  for (std::size_t i = 0; i < m; ++i) {
    if (orient_now(at(i + m - 1), at(i), at(i + 1)) == 0) return false;
    for (std::size_t j = i + 2; j < m; ++j) {
      if (i == 0 && j == m - 1) continue;
      const std::uint32_t p = at(i), q = at(i + 1), r = at(j), s = at(j + 1);
      const int o1 = orient_now(p, q, r), o2 = orient_now(p, q, s);
      const int o3 = orient_now(r, s, p), o4 = orient_now(r, s, q);
      if (o1 * o2 <= 0 && o3 * o4 <= 0) return false;
    }
  }
  // Simple: it turns counter-clockwise when it turns left at its lowest (then leftmost) vertex.
  std::size_t low = 0;
  for (std::size_t i = 1; i < m; ++i) {
    if (below_now(link[i], link[low])) low = i;
  }
  return orient_now(at(low + m - 1), at(low), at(low + 1)) > 0;
}

void KineticDelaunay::insert(std::uint32_t index) {
  if (points_.alive_index(index))
    require_motion(points_, index, "KineticDelaunay::insert", scheduler_.kind());
  sync_.require_inserted("KineticDelaunay::insert", index);
  ++counters_.inserts;
  const std::size_t cap = points_.capacity();
  if (vertex_face_.size() < cap) {
    vertex_face_.resize(cap, kNoIndex);
    rep_.resize(cap, kNoIndex);
    next_hidden_.resize(cap, kNoIndex);
  }
  ++size_;
  rep_[index] = index;
  if (flat_) {
    rebuild();
    return;
  }
  insert_vertex(index);
}

void KineticDelaunay::insert_vertex(std::uint32_t index) {
  std::vector<std::uint32_t> touched;
  const std::uint64_t built = counters_.rebuilds;
  // (A rebuild inside add_point certified everything, with other face ids.)
  if (add_point(index, touched) && !flat_ && counters_.rebuilds == built) certify(touched);
}

void KineticDelaunay::remove(std::uint32_t index) {
  sync_.require_removed("KineticDelaunay::remove", index);
  ++counters_.removes;
  --size_;
  const bool vertex = rep_[index] == index;
  const bool alone = next_hidden_[index] == kNoIndex;
  unhide(index);
  // A vertex of the triangulation without a copy to stand for it: taken out locally, or (fewer
  // than four vertices left, a degenerate hole) built again.
  if (vertex && alone && (flat_ || vertex_count() <= 3 || !remove_vertex(index))) rebuild();
}

void KineticDelaunay::motion_changed(std::uint32_t index) {
  if (points_.alive_index(index))
    require_motion(points_, index, "KineticDelaunay::motion_changed", scheduler_.kind());
  sync_.require_updated("KineticDelaunay::motion_changed", index);
  ++counters_.updates;
  const bool vertex = rep_[index] == index;
  const bool alone = next_hidden_[index] == kNoIndex;
  if (flat_) {
    unhide(index);
    rep_[index] = index;
    rebuild();
    return;
  }
  if (!vertex || !alone) {
    // It leaves its group (a copy stands in for it, or it was hidden) and comes in anew.
    unhide(index);
    insert_vertex(index);
    return;
  }
  // A vertex with a new motion: a flight-plan update may move it anywhere (the contract lets
  // a new motion start elsewhere), so it is taken out of the triangulation (its old star's
  // hole filled without reading its position) and inserted again.
  if (vertex_count() <= 3 || !remove_vertex(index)) {
    rebuild();
    return;
  }
  insert_vertex(index);
}

// ---------------------------------------------------------------------------------------------
// Queries

std::vector<std::array<std::uint32_t, 3>> KineticDelaunay::triangles() {
  sync_.require_current("KineticDelaunay::triangles");
  ++counters_.queries;
  std::vector<std::array<std::uint32_t, 3>> out;
  if (flat_) return out;
  // In ranks by id, each from its smallest (into scratch kept across queries), sorted into out,
  // then back to point indices.
  id_ranks_.update(points_);
  triangle_scratch_.clear();
  triangle_scratch_.reserve(faces_.size());
  for (const Face& F : faces_) {
    if (!F.alive || F.v[0] == kInfinite || F.v[1] == kInfinite || F.v[2] == kInfinite) continue;
    const std::array<std::uint32_t, 3> r{id_ranks_.rank(F.v[0]), id_ranks_.rank(F.v[1]),
                                         id_ranks_.rank(F.v[2])};
    const std::uint32_t k = r[0] < r[1] ? (r[0] < r[2] ? 0 : 2) : (r[1] < r[2] ? 1 : 2);
    triangle_scratch_.push_back({r[k], r[next3(k)], r[prev3(k)]});
  }
  sort_ranked<3>(triangle_scratch_, id_ranks_.size(), out, count_scratch_);
  for (auto& t : out)
    for (std::uint32_t& x : t) x = id_ranks_.index(x);
  return out;
}

int KineticDelaunay::compare_distance(std::uint32_t a, std::uint32_t b, Point2 q, Time t) const {
  const MotionPolynomial qx = MotionPolynomial::from({q[0]}), qy = MotionPolynomial::from({q[1]});
  return compare_squared_distances_at(moving_point(points_, a), MovingPoint2{&qx, &qy},
                                      moving_point(points_, b), MovingPoint2{&qx, &qy}, t);
}

int KineticDelaunay::compare_lengths(std::uint32_t a, std::uint32_t b, std::uint32_t c,
                                     std::uint32_t d, Time t) const {
  const auto& m = points_;
  return compare_squared_distances_at(moving_point(m, a), moving_point(m, b), moving_point(m, c),
                                      moving_point(m, d), t);
}

bool KineticDelaunay::coincide_at(std::uint32_t a, std::uint32_t b, Time t) const {
  return compare_at(points_.motion(a, 0), points_.motion(b, 0), t) == 0 &&
         compare_at(points_.motion(a, 1), points_.motion(b, 1), t) == 0;
}

std::optional<std::uint32_t> KineticDelaunay::nearest(Point2 q, double /*eps*/, Time t) {
  sync_.require_current("KineticDelaunay::nearest");
  require_query_time("KineticDelaunay::nearest", t, sim_.now());
  if (!std::isfinite(q[0]) || !std::isfinite(q[1])) {
    precondition_failed("KineticDelaunay::nearest", "the query point must be finite");
  }
  ++counters_.queries;
  t = world_time();  // t == now: the triangulation's time (robust: the grid point before)
  const std::vector<std::uint32_t> all = flat_ ? vertices() : std::vector<std::uint32_t>{};
  const auto closer = [&](std::uint32_t a, std::uint32_t b) {
    const int s = compare_distance(a, b, q, t);
    return s < 0 || (s == 0 && points_.id(a) < points_.id(b));
  };
  if (flat_) {
    if (all.empty()) return std::nullopt;
    return *std::min_element(all.begin(), all.end(), closer);
  }
  // Greedy walk over Delaunay neighbours, from the set of equally near vertices connected by
  // edges (points at one place now, or on one circle about q): when no member of the set has a
  // strictly nearer neighbour, the set holds the nearest points (the triangulation is a Delaunay
  // triangulation of the positions at now; coincident points split one Voronoi cell between
  // them, joined by their zero-length edges).
  std::uint32_t v = kNoIndex;
  for (const std::uint32_t x : faces_[last_face_].v) {
    if (x != kInfinite) v = x;
  }
  std::vector<std::uint32_t> ring, tied;
  for (bool moved = true; moved;) {
    moved = false;
    tied.assign(1, v);
    for (std::size_t i = 0; i < tied.size() && !moved; ++i) {
      star(tied[i], ring);
      for (const std::uint32_t f : ring) {
        ++counters_.walk_steps;
        for (const std::uint32_t w : faces_[f].v) {
          if (w == kInfinite || std::find(tied.begin(), tied.end(), w) != tied.end()) continue;
          const int s = compare_distance(w, v, q, t);
          if (s < 0) {
            v = w;
            moved = true;
            break;
          }
          if (s == 0) tied.push_back(w);
        }
        if (moved) break;
      }
    }
  }
  return *std::min_element(tied.begin(), tied.end(), closer);
}

std::vector<std::uint32_t> KineticDelaunay::k_nearest(std::span<const double> q, std::size_t k,
                                                      double eps, Time t) {
  require_point_query_at("KineticDelaunay::k_nearest", sync_, t, sim_.now(), q, 2, eps);
  std::vector<std::uint32_t> out;
  if (k == 0 || size_ == 0) {
    ++counters_.queries;
    return out;
  }
  const Point2 p{q[0], q[1]};
  const std::optional<std::uint32_t> first = nearest(p, 0.0, t);  // counts the query
  t = world_time();
  nearest_.reset(k, 0.0);
  // A point's enclosure [lo, hi] of its distance to q: the filtered coordinates (each within
  // its bound) and hypot's rounding; [0, +infinity) where that is not finite.
  const auto enclosure = [&](std::uint32_t v) {
    const FilteredValue x = evaluate_filtered(points_.motion(v, 0), t);
    const FilteredValue y = evaluate_filtered(points_.motion(v, 1), t);
    const double d = std::hypot(x.value - p[0], y.value - p[1]);
    const double error = (x.error + y.error + 8.0 * 0x1p-53 * d + 0x1p-1000) * (1.0 + 1e-10);
    const double hi = d + error;
    if (!(hi < HUGE_VAL)) return std::array<double, 2>{0.0, HUGE_VAL};
    return std::array<double, 2>{std::max(0.0, d - error) * (1.0 - 0x1p-52), hi * (1.0 + 0x1p-52)};
  };
  // A vertex, and the copies of identical motions hidden behind it (at its distance).
  const auto offer = [&](std::uint32_t v) {
    const auto [lo, hi] = enclosure(v);
    for (std::uint32_t c = v; c != kNoIndex; c = next_hidden_[c]) nearest_.offer(c, lo, hi);
  };
  if (flat_) {
    for (const std::uint32_t v : vertices()) offer(v);
  } else {
    // Best first from the nearest vertex by the lower bounds: a vertex of the answer is reached
    // through a strictly nearer one (the search stops only above the candidates' limit).
    if (seen_.size() < points_.capacity()) seen_.resize(points_.capacity(), 0);
    if (++seen_round_ == 0) {
      std::fill(seen_.begin(), seen_.end(), 0);
      seen_round_ = 1;
    }
    using Item = std::pair<double, std::uint32_t>;
    std::priority_queue<Item, std::vector<Item>, std::greater<>> heap;
    heap.emplace(0.0, *first);
    seen_[*first] = seen_round_;
    while (!heap.empty()) {
      const auto [key, v] = heap.top();
      heap.pop();
      if (key > nearest_.prune_above()) break;
      ++counters_.walk_steps;
      offer(v);
      around(v, [&](std::uint32_t f) {
        for (const std::uint32_t w : faces_[f].v) {
          if (w == kInfinite || seen_[w] == seen_round_) continue;
          seen_[w] = seen_round_;
          heap.emplace(enclosure(w)[0], w);
        }
        return true;
      });
    }
  }
  nearest_.finish(points_, q, t, out);
  return out;
}

std::optional<std::array<std::uint32_t, 2>> KineticDelaunay::closest_pair() {
  sync_.require_current("KineticDelaunay::closest_pair");
  ++counters_.queries;
  using Pair = std::array<std::uint32_t, 2>;
  std::vector<Pair> candidates;
  if (flat_) {
    const std::vector<std::uint32_t> vs = vertices();
    for (std::size_t i = 0; i < vs.size(); ++i) {
      for (std::size_t j = i + 1; j < vs.size(); ++j) candidates.push_back({vs[i], vs[j]});
    }
  } else {
    edges(candidates);
  }
  return closest_pair_among(candidates);
}

std::optional<std::array<std::uint32_t, 2>> KineticDelaunay::closest_pair_among(
    std::span<const std::array<std::uint32_t, 2>> pairs) const {
  sync_.require_current("KineticDelaunay::closest_pair");
  const Time t = world_time();
  using Pair = std::array<std::uint32_t, 2>;
  const auto ordered = [&](std::uint32_t a, std::uint32_t b) {
    return points_.id(a) < points_.id(b) ? Pair{a, b} : Pair{b, a};
  };
  const auto id_less = [&](const Pair& x, const Pair& y) {
    if (points_.id(x[0]) != points_.id(y[0])) return points_.id(x[0]) < points_.id(y[0]);
    return points_.id(x[1]) < points_.id(y[1]);
  };
  // Copies (identical motions): distance 0 for ever; the smallest pair of ids of any group.
  std::optional<Pair> best;
  const bool copies = flat_ || size_ > vertex_count();  // some points hidden behind vertices
  for (const std::uint32_t v : copies ? vertices() : std::vector<std::uint32_t>{}) {
    if (next_hidden_[v] != kNoIndex) {
      const Pair p{v, next_hidden_[v]};
      if (!best || id_less(p, *best)) best = p;
    }
  }
  std::vector<Pair> candidates;
  candidates.reserve(pairs.size());
  for (const Pair& p : pairs) candidates.push_back(ordered(p[0], p[1]));
  std::optional<Pair> shortest;
  for (const Pair& p : candidates) {
    if (!shortest) {
      shortest = p;
      continue;
    }
    const int s = compare_lengths(p[0], p[1], (*shortest)[0], (*shortest)[1], t);
    if (s < 0 || (s == 0 && id_less(p, *shortest))) shortest = p;
  }
  if (shortest && coincide_at((*shortest)[0], (*shortest)[1], t)) {
    // Points at one place now: every pair of a cluster is at distance 0, and a cluster is
    // connected by its zero-length Delaunay edges; its smallest pair of ids counts.
    std::vector<std::uint32_t> parent(points_.capacity());
    std::iota(parent.begin(), parent.end(), 0u);
    const auto find = [&](std::uint32_t x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    for (const Pair& p : candidates) {
      if (coincide_at(p[0], p[1], t)) parent[find(p[0])] = find(p[1]);
    }
    std::vector<std::uint32_t> members;
    for (const Pair& p : candidates) {
      if (coincide_at(p[0], p[1], t)) members.insert(members.end(), {p[0], p[1]});
    }
    std::sort(members.begin(), members.end(),
              [&](std::uint32_t x, std::uint32_t y) { return points_.id(x) < points_.id(y); });
    members.erase(std::unique(members.begin(), members.end()), members.end());
    // The first two members (by id) of one cluster.
    std::vector<std::uint32_t> first(points_.capacity(), kNoIndex);
    for (const std::uint32_t x : members) {
      std::uint32_t& r = first[find(x)];
      if (r == kNoIndex) {
        r = x;
      } else if (r != kNoIndex - 2) {
        const Pair p{r, x};
        if (!best || id_less(p, *best)) best = p;
        r = kNoIndex - 2;  // the cluster's pair is taken
      }
    }
    return best;
  }
  if (best) return best;  // copies are nearer than any two distinct points
  return shortest;
}

// ---------------------------------------------------------------------------------------------
// Measures and invariants

std::size_t KineticDelaunay::certificates() const { return flat_ ? 0 : live_faces_ * 3 / 2; }

std::size_t KineticDelaunay::certificates_per_object_max() const {
  if (flat_) return 0;
  // An edge's certificate involves its two ends and the two opposite vertices.
  std::vector<std::uint32_t> count(points_.capacity(), 0);
  std::size_t best = 0;
  for (std::uint32_t f = 0; f < faces_.size(); ++f) {
    if (!faces_[f].alive) continue;
    for (std::uint32_t k = 0; k < 3; ++k) {
      if (canonical(3 * f + k) != 3 * f + k) continue;
      for (const std::uint32_t q : quad(3 * f + k)) {
        if (q != kInfinite) best = std::max<std::size_t>(best, ++count[q]);
      }
    }
  }
  return best;
}

bool KineticDelaunay::validate() const {
  if (!sync_.current()) return false;
  // Groups: every live point has a representative vertex with the same motion and a smaller id.
  std::size_t live = 0;
  for (const std::uint32_t i : points_.alive_indices()) {
    ++live;
    if (i >= rep_.size() || rep_[i] == kNoIndex) return false;
    const std::uint32_t r = rep_[i];
    if (rep_[r] != r || (r != i && (!same_motion(r, i) || points_.id(r) > points_.id(i))))
      return false;
    if (!flat_ && r == i && vertex_face_[i] == kNoIndex) return false;
  }
  if (live != size_) return false;
  // Every group's chain, from its representative by increasing id, holds exactly its members.
  std::size_t chained = 0;
  for (const std::uint32_t r : points_.alive_indices()) {
    if (rep_[r] != r) continue;
    for (std::uint32_t x = r, steps = 0; x != kNoIndex; x = next_hidden_[x], ++steps) {
      if (steps > live || x >= rep_.size() || !points_.alive_index(x) || rep_[x] != r) return false;
      const std::uint32_t y = next_hidden_[x];
      if (y != kNoIndex && (y >= rep_.size() || points_.id(y) <= points_.id(x))) return false;
      ++chained;
    }
  }
  if (chained != live) return false;
  if (flat_) {
    if (live_faces_ != 0 || queued_ != 0) return false;
    // Flat means collinear for ever (or fewer than three).
    const std::vector<std::uint32_t> vs = vertices();
    for (std::size_t k = 2; k < vs.size(); ++k) {
      if (orient_now(vs[0], vs[1], vs[k]) != 0) return false;
    }
    return true;
  }
  std::size_t alive = 0, queued = 0, vertex_count = 0;
  std::vector<char> seen(points_.capacity(), 0);
  for (std::uint32_t f = 0; f < faces_.size(); ++f) {
    const Face& F = faces_[f];
    if (!F.alive) continue;
    ++alive;
    int infinite = 0;
    for (std::uint32_t k = 0; k < 3; ++k) {
      const std::uint32_t v = F.v[k];
      if (v == kInfinite) {
        ++infinite;
      } else {
        if (v >= points_.capacity() || !points_.alive_index(v) || rep_[v] != v) return false;
        if (!seen[v]) {
          seen[v] = 1;
          ++vertex_count;
        }
      }
      const std::uint32_t g = F.n[k];
      if (g >= faces_.size() || !faces_[g].alive) return false;
      // The neighbour shares the edge, reversed.
      const std::uint32_t t = twin(3 * f + k);
      if (t == kNoIndex) return false;
      const Face& G = faces_[t / 3];
      if (G.v[next3(t % 3)] != F.v[prev3(k)] || G.v[prev3(t % 3)] != F.v[next3(k)]) return false;
    }
    if (infinite > 1) return false;
    // A finite triangle's orientation event is queued while it may fail, and due now when the
    // triangle is not counter-clockwise just after now; an infinite one has none.
    if (infinite == 1 && !F.orientation.is_null()) return false;
    if (!F.orientation.is_null()) {
      if (!sim_.queue().contains(F.orientation)) return false;
      const Event& ev = sim_.queue().get(F.orientation);
      if (ev.owner != owner_ + 1 || ev.payload != f) return false;
      ++queued;
    }
    if (infinite == 0 && orient_now(F.v[0], F.v[1], F.v[2]) <= 0 && !due_now(F.orientation))
      return false;
    for (std::uint32_t k = 0; k < 3; ++k) {
      const std::uint32_t h = 3 * f + k;
      const std::uint32_t c = canonical(h);
      const EventHandle& e = F.cert[k];
      if (c != h) {
        if (!e.is_null()) return false;
        continue;
      }
      if (!e.is_null()) {
        if (!sim_.queue().contains(e)) return false;
        const Event& ev = sim_.queue().get(e);
        if (ev.owner != owner_ || ev.payload != h) return false;
        ++queued;
      }
      // Failing just after now: its event must be due now.
      if (holds_now(h) < 0 && !due_now(e)) return false;
    }
  }
  if (alive != live_faces_ || queued != queued_) return false;
  // Every vertex is in the triangulation; a sphere: V - E + F = 2 with the vertex at infinity.
  if (vertex_count != vertices().size()) return false;
  if ((vertex_count + 1) + alive - alive * 3 / 2 != 2) return false;
  for (const std::uint32_t v : vertices()) {
    const Face& F = faces_[vertex_face_[v]];
    if (!F.alive || std::find(F.v.begin(), F.v.end(), v) == F.v.end()) return false;
  }
  // Once no event of this instant is left (a cascade of simultaneous flips may pass through
  // states that are not plane), the hull (the edges of the infinite triangles) is one cycle that
  // winds once: with every turn to the left, exactly one vertex is lowest-then-leftmost among
  // its two neighbours (a polygon winding twice, every certificate holding, has two).
  bool settled = true;
  for (const Face& F : faces_) {
    if (!F.alive) continue;
    for (const EventHandle* e : {&F.cert[0], &F.cert[1], &F.cert[2], &F.orientation}) {
      if (due_now(*e)) settled = false;
    }
  }
  if (due_now(audit_)) settled = false;
  return !settled || hull_winds_once();
}

bool KineticDelaunay::hull_winds_once() const {
  // The infinite faces in order around the vertex at infinity: (q, p, infinity) rotated is the
  // hull edge p -> q, and the face across its edge (infinity, q) holds the next hull edge.
  std::uint32_t first = 0;
  const auto infinity_at = [&](std::uint32_t f) -> std::uint32_t {
    const auto& v = faces_[f].v;
    return v[0] == kInfinite ? 0 : (v[1] == kInfinite ? 1 : (v[2] == kInfinite ? 2 : 3));
  };
  while (first < faces_.size() && (!faces_[first].alive || infinity_at(first) == 3)) ++first;
  if (first == faces_.size()) return false;
  std::vector<std::uint32_t> hull;
  std::uint32_t f = first;
  do {
    const std::uint32_t k = infinity_at(f);
    if (k == 3 || hull.size() > live_faces_) return false;
    hull.push_back(faces_[f].v[prev3(k)]);
    f = faces_[f].n[prev3(k)];
  } while (f != first);
  std::vector<std::uint32_t> sorted = hull;
  std::sort(sorted.begin(), sorted.end());
  if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) return false;
  // With every turn to the left, it winds once when exactly one vertex is lowest-then-leftmost
  // among its two neighbours (a polygon winding twice, every certificate holding, has two).
  const std::size_t m = hull.size();
  std::size_t minima = 0;
  for (std::size_t i = 0; i < m; ++i) {
    const std::uint32_t v = hull[i];
    if (below_now(v, hull[(i + m - 1) % m]) && below_now(v, hull[(i + 1) % m])) ++minima;
  }
  return minima == 1;
}

void KineticDelaunay::request_audit() {
  sim_.cancel(audit_);
  audit_ = sim_.schedule_now(owner_ + 1, kAudit);
}

namespace {

/// The loop guard's bounds. A flip at one instant makes an edge that the perturbed lifting says is
/// lower, so flips at one instant end after at most as many as there are pairs of points (each
/// edge appears once), n^2. Over a run, an edge's four points' certificate (degree <= 8 per
/// motion piece) fails at most 8 times per piece: at most 8 n^4 per piece of motions, loose but
/// finite.
LoopGuard delaunay_event_bounds(const RunBounds& b) {
  const std::uint64_t n = b.max_objects + 3;
  const std::uint64_t degree = static_cast<std::uint64_t>(std::max(1, 4 * b.max_degree));
  LoopGuard g;
  g.max_events_per_instant = saturating_product({4, n, n});
  const std::uint64_t pieces = b.motion_changes + 1;
  const std::uint64_t all = saturating_product({degree, pieces, n, n, n, n});
  constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();
  g.max_events_total = all >= kMax - 16 ? kMax : all + 16;
  return g;
}

}  // namespace

StructureDescription KineticDelaunay::description() {
  return StructureDescription{
      "delaunay",
      "Delaunay",
      ObjectsAre::Points,
      {QueryType::Delaunay, QueryType::Nearest, QueryType::KNearest, QueryType::ClosestPair},
      {"flip", "inversion"},
      "The kinetic Delaunay triangulation of points in the plane (delaunay(), nearest(), "
      "k_nearest(), "
      "closest_pair()); robust by default for points on lines (exact just after the grid "
      "point at or before now, docs/delaunay.md), exact by default for parabolas (degree <="
      " 2).",
      "kinetic Delaunay triangulation of points in the plane (edge flips at in-circle failures; "
      "robust: exact just after the grid point before the query, points on lines; exact: "
      "degree <= 2): the triangles, the exact nearest and k nearest points, the closest pair"}
      .limit_dimensions(2, 2, "points in the plane")
      .limit_degree(KineticDelaunay::kMaxDegree,
                    "its in-circle certificates have four times the motions' degree")
      .limit_robust_degree(
          KineticDelaunay::kMaxRobustDegree,
          "CROP isolates in-circle certificates of degree 4; the exact scheduler takes degree 2")
      .limit_magnitudes(KineticDelaunay::kMagnitudeLog2,
                        "its exact in-circle arithmetic takes seconds to minutes beyond")
      .limit_schedulers(
          {SchedulerKind::Robust, SchedulerKind::Exact},
          "floating-point failure times can miss a triangle's inversion and leave a folded "
          "triangulation undetected")
      .bound_events(delaunay_event_bounds);
}

}  // namespace kinetic
