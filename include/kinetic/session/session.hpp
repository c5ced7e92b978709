#pragma once
// The session: the library as a user meets it. One object owns the motion table, the simulator,
// the scheduler and one kinetic structure, speaks in object ids (never table indices), and
// cannot be used out of order:
//
//   kinetic::Session<kinetic::KineticKdTree> s(2);             // 2-D, robust scheduling, t = 0
//   s.insert(7, {MotionPolynomial::from({0.0, 1.0}), MotionPolynomial::from({3.0})});
//   ...
//   s.advance(2.5);                                            // events up to t = 2.5
//   std::vector<ObjectId> ids = s.range({{0, 4}, {0, 4}});      // the ids in the box at 2.5
//   s.update(7, {...});                                        // a flight-plan update at 2.5
//   ids = s.at(3.0).range(box);                                // advance first, then ask
//
// - The structure is built (initialize()) on the first advance or query (or structure(),
//   validate()): the objects inserted before it are loaded in one O(n log n) build.
// - insert, update and remove act at now(): the table changes, then the structure is told.
// - Queries answer at now(); `at(t)` advances first. Each query exists when the structure
//   offers it: sorted() (KineticSort), top() (KineticTournament), extent() (KineticExtent),
//   range(box) (the kd-tree, the range tree, the longest-side kd-tree), nearest / k_nearest
//   (the kd-tree, the longest-side kd-tree, the Delaunay triangulation), farthest /
//   approx_range (the longest-side kd-tree), stab(x) (the segment tree; objects are intervals:
//   coordinate 0 the left end, 1 the right end), hull() (the kinetic convex hull),
//   colliding_pairs() (sweep-and-prune; objects are boxes: the center's motions, then the half
//   extents as constants).
// - Every precondition is checked (PreconditionError): time moving backwards or past the
//   horizon, an unknown or duplicate id, the number of coordinates, a degree above 6, a box of
//   the wrong dimension.
// - position(id) and ids() tell where the objects are now (rounded; for display and checks).
// - set_interrupt(flag) lets a signal handler stop a long advance between two events
//   (SessionInterrupted; the session stays usable).
// - Advanced users reach the parts: motions(), simulator(), scheduler(), structure().

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "kinetic/core/box_contacts.hpp"
#include "kinetic/core/counters.hpp"
#include "kinetic/core/error.hpp"
#include "kinetic/core/geometry.hpp"
#include "kinetic/core/ids.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/polynomial.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/structure.hpp"
#include "kinetic/core/table_changes.hpp"

namespace kinetic {

/// How a session schedules and where its time starts and ends.
struct SessionOptions {
  /// Robust (the default), classic or exact; a structure that takes fewer refuses the others
  /// with the reason (the Delaunay triangulation: robust or exact; the closest pair over it:
  /// exact).
  SchedulerKind scheduler = SchedulerKind::Robust;
  /// The robust scheduler's precision: events are processed at most eps late.
  double eps = 1e-9;
  /// The time the objects given before the first advance are at.
  Time start = 0.0;
  /// No advance beyond this time (the scheduler schedules no event after it). +infinity: none
  /// but the robust scheduler's own limit, Scheduler::max_supported_time(eps) (about
  /// 2.6e5 time units at eps = 1e-9); an advance past either is refused.
  Time horizon = kTimeInfinity;
};

/// An advance stopped by the interrupt flag (set_interrupt) between two events. The session
/// stays usable: every event processed so far is consistent, now() is the last one's time, and
/// a later advance goes on from there.
class SessionInterrupted : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The scheduler's failure to finish an advance (the simulator's loop guard or event budget
/// tripped: a scheduling bug, never expected). The session cannot be used after it.
class SessionError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// How a session builds a structure that S's constructor alone does not make (a group of
/// structures, a scheduler configured first): `make(table, simulator, scheduler)` returns it as a
/// std::unique_ptr<S>. Session<S> s(d, options, build_with(make)).
template <class Make>
struct BuildWith {
  Make make;
};
template <class Make>
BuildWith<std::decay_t<Make>> build_with(Make&& make) {
  return {std::forward<Make>(make)};
}

namespace detail {
/// Calls a hook: one that returns a bool says whether to go on, one that returns nothing always
/// goes on (the drivers' event hooks, TimelineDriver::play's hooks).
template <class Hook>
bool hook_goes_on(Hook&& hook) {
  if constexpr (std::is_void_v<decltype(hook())>) {
    hook();
    return true;
  } else {
    return static_cast<bool>(hook());
  }
}
}  // namespace detail

template <KineticStructure S>
class Session {
 public:
  /// A session over objects of `dimension` coordinates; `structure_args` follow the table,
  /// simulator and scheduler in S's constructor (e.g. the axis of a KineticSort).
  template <class... Args>
    requires std::constructible_from<S, MotionTable&, Simulator&, Scheduler&, Args...>
  explicit Session(int dimension, SessionOptions options = {}, Args&&... structure_args)
      : motions_(dimension),
        sim_(options.start),
        scheduler_(checked_scheduler(options)),
        structure_(std::make_unique<S>(motions_, sim_, scheduler_,
                                       std::forward<Args>(structure_args)...)) {}
  /// A session whose structure `build.make(table, simulator, scheduler)` builds.
  template <class Make>
  Session(int dimension, SessionOptions options, BuildWith<Make> build)
      : motions_(dimension),
        sim_(options.start),
        scheduler_(checked_scheduler(options)),
        structure_(build.make(motions_, sim_, scheduler_)) {}
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  [[nodiscard]] int dimension() const { return motions_.dimension(); }
  [[nodiscard]] Time now() const { return sim_.now(); }
  [[nodiscard]] std::size_t size() const { return motions_.size(); }
  [[nodiscard]] bool contains(ObjectId id) const { return motions_.find(id).has_value(); }

  /// Adds object `id` moving as `motion` (one polynomial per coordinate) from now() on.
  void insert(ObjectId id, std::span<const MotionPolynomial> motion) {
    usable("Session::insert");
    require_structure_motion("Session::insert", id, motion);
    insert_checked(id, motion);
  }
  void insert(ObjectId id, std::initializer_list<MotionPolynomial> motion) {
    insert(id, std::span<const MotionPolynomial>(motion.begin(), motion.size()));
  }
  /// Replaces object `id`'s motion from now() on (a flight-plan update).
  void update(ObjectId id, std::span<const MotionPolynomial> motion) {
    usable("Session::update");
    (void)handle_of(id, "Session::update");  // an unknown id named before its motion
    require_structure_motion("Session::update", id, motion);
    update_checked(id, motion);
  }
  void update(ObjectId id, std::initializer_list<MotionPolynomial> motion) {
    update(id, std::span<const MotionPolynomial>(motion.begin(), motion.size()));
  }
  /// Removes object `id` at now().
  void remove(ObjectId id) {
    usable("Session::remove");
    const ObjectHandle h = handle_of(id, "Session::remove");
    remove_object(motions_, sim_, *structure_, started(), h);
  }

  /// Processes every event up to t and moves the clock to t. Throws PreconditionError when t is
  /// not finite, before now() or after the horizon, SessionError when the scheduler fails.
  void advance(Time t) {
    usable("Session::advance");
    if (std::isinf(t)) {
      precondition_failed("Session::advance", "t = " + format_number(t) + " (a finite time)");
    }
    sim_.require_time("Session::advance", t);  // NaN, or after the horizon
    if (!(t >= sim_.now())) {
      precondition_failed("Session::advance",
                          "t = " + format_number(t) + " is before the session's time " +
                              format_number(sim_.now()) + " (time only moves forward)");
    }
    start();
    sim_.set_guard(guard_ ? *guard_ : instant_guard());
    const AdvanceOutcome o = sim_.advance_to(t, *structure_);
    if (o == AdvanceOutcome::Interrupted) {
      throw SessionInterrupted("Session::advance: interrupted at t = " + format_number(now()) +
                               " on the way to " + format_number(t));
    }
    if (o != AdvanceOutcome::Reached) {
      failed_ = true;
      throw SessionError(
          "Session::advance: the " +
          std::string(o == AdvanceOutcome::LoopGuard ? "loop guard" : "event budget") +
          " tripped at t = " + format_number(sim_.guard_report().time));
    }
  }
  /// A flag that stops advance() between two events when it becomes true (e.g. from a signal
  /// handler): advance() then throws SessionInterrupted. nullptr: none. The flag must outlive
  /// the session's use of it.
  void set_interrupt(const std::atomic<bool>* flag) { sim_.set_interrupt(flag); }

  /// A loop guard of the caller's (bounds known in advance, e.g. over a whole scenario) in
  /// place of the one advance() derives from the objects present.
  void set_guard(const LoopGuard& guard) {
    guard_ = guard;
    sim_.set_guard(guard);
  }

  // --- For drivers (the timeline driver, the runner, experiments). ---------------------------
  // They handle an advance's outcome themselves: no precondition beyond the simulator's, the
  // outcome returned instead of thrown, the guard left as set, and with `after_event` the events
  // one at a time with after_event() called after each; after_event() returning false (a
  // validation failed) stops there, with Reached.

  /// insert() and update() for a driver whose motions were checked as a whole: a scenario's
  /// reader checks an interval only up to its next change, where insert() would ask it to hold
  /// to the horizon. The table's checks stay; the structure's own (require_motion,
  /// require_interval) are the driver's.
  void insert_checked(ObjectId id, std::span<const MotionPolynomial> motion) {
    usable("Session::insert");
    insert_object(motions_, sim_, *structure_, started(), id, motion, sim_.now(),
                  "Session::insert");
  }
  void update_checked(ObjectId id, std::span<const MotionPolynomial> motion) {
    usable("Session::update");
    update_object(motions_, sim_, *structure_, started(), handle_of(id, "Session::update"),
                  motion, sim_.now(), "Session::update");
  }
  /// The structure as it is, built or not: a driver sets it up (delay measurement, a guard
  /// from its size) before its build.
  [[nodiscard]] S& structure_as_is() { return *structure_; }
  /// Processes every event up to t (one at a time with after_event), then moves the clock to t.
  template <class AfterEvent = std::nullptr_t>
  AdvanceOutcome advance_until(Time t, AfterEvent&& after_event = nullptr) {
    start();
    if constexpr (std::is_null_pointer_v<std::decay_t<AfterEvent>>) {
      return note_failure(sim_.advance_to(t, *structure_));
    } else {
      while (sim_.event_due_by(t)) {
        const AdvanceOutcome o = note_failure(sim_.process_next(*structure_));
        if (o != AdvanceOutcome::Reached || !detail::hook_goes_on(after_event)) return o;
      }
      return note_failure(sim_.advance_to(t, *structure_));
    }
  }
  /// Processes events until none is left (a run without an end time).
  template <class AfterEvent = std::nullptr_t>
  AdvanceOutcome run_until_empty(AfterEvent&& after_event = nullptr) {
    start();
    if constexpr (std::is_null_pointer_v<std::decay_t<AfterEvent>>) {
      return note_failure(sim_.run_until_empty(*structure_));
    } else {
      while (!sim_.queue().empty()) {
        const AdvanceOutcome o = note_failure(sim_.process_next(*structure_));
        if (o != AdvanceOutcome::Reached || !detail::hook_goes_on(after_event)) return o;
      }
      return AdvanceOutcome::Reached;
    }
  }

  /// advance(t), then the session for a query: `s.at(3.0).range(box)`.
  Session& at(Time t) {
    advance(t);
    return *this;
  }

  // --- Queries at now(), in ids. --------------------------------------------------------------

  /// The objects in sorted order of the sort's axis (KineticSort).
  [[nodiscard]] std::vector<ObjectId> sorted() requires requires(const S& s) { s.order(); }
  {
    query("Session::sorted");
    return ids_in_order(structure_->order());
  }
  /// The object with the extreme coordinate (KineticTournament); nullopt when empty.
  [[nodiscard]] std::optional<ObjectId> top() requires requires(const S& s) { s.top(); }
  {
    query("Session::top");
    return id_of(structure_->top());
  }
  /// The bounding box (KineticExtent): per axis the ids of the objects with the smallest and
  /// the largest coordinate; empty when there is no object.
  [[nodiscard]] std::vector<std::array<ObjectId, 2>> extent() requires requires(const S& s) {
    s.extent();
  }
  {
    query("Session::extent");
    std::vector<std::array<ObjectId, 2>> out;
    for (const auto& [lo, hi] : structure_->extent())
      out.push_back({motions_.id(lo), motions_.id(hi)});
    return out;
  }
  /// The objects in the closed box (one [lo, hi] per axis), ids ascending.
  [[nodiscard]] std::vector<ObjectId> range(const Box& box) requires
      requires(S& s, const Box& b, Time t) {
    s.range(b, t);
  }
  {
    query("Session::range");
    return ids_ascending(structure_->range(box, sim_.now()));
  }
  /// A (1 + eps)-approximate nearest object to q (the longest-side kd-tree, the kd-tree, the
  /// Delaunay triangulation).
  [[nodiscard]] std::optional<ObjectId> nearest(Point2 q, double eps) requires
      requires(S& s, Point2 p, double e, Time t) {
    s.nearest(p, e, t);
  }
  {
    query("Session::nearest");
    return id_of(structure_->nearest(q, eps, sim_.now()));
  }
  /// The same in any dimension (the kd-tree; q has the table's dimension).
  [[nodiscard]] std::optional<ObjectId> nearest(std::span<const double> q, double eps) requires
      requires(S& s, std::span<const double> p, double e, Time t) {
    s.nearest(p, e, t);
  }
  {
    query("Session::nearest");
    return id_of(structure_->nearest(q, eps, sim_.now()));
  }
  /// The k objects nearest to q (all when fewer), by increasing distance, equal distances by
  /// id; with eps > 0 each distance within (1 + eps) of the true one of its rank (the kd-tree,
  /// the longest-side kd-tree, the Delaunay triangulation).
  [[nodiscard]] std::vector<ObjectId> k_nearest(std::span<const double> q, std::size_t k,
                                                double eps) requires
      requires(S& s, std::span<const double> p, std::size_t n, double e, Time t) {
    s.k_nearest(p, n, e, t);
  }
  {
    query("Session::k_nearest");
    return ids_in_order(structure_->k_nearest(q, k, eps, sim_.now()));
  }
  /// A (1 - eps)-approximate farthest object from q (the longest-side kd-tree).
  [[nodiscard]] std::optional<ObjectId> farthest(Point2 q, double eps) requires
      requires(S& s, Point2 p, double e, Time t) {
    s.farthest(p, e, t);
  }
  {
    query("Session::farthest");
    return id_of(structure_->farthest(q, eps, sim_.now()));
  }
  /// An eps-approximate range of a disk or polygon (the longest-side kd-tree), ids ascending.
  [[nodiscard]] std::vector<ObjectId> approx_range(const Shape& shape, double eps) requires
      requires(S& s, const Shape& sh, double e, Time t) {
    s.approx_range(sh, e, t);
  }
  {
    query("Session::approx_range");
    return ids_ascending(structure_->approx_range(shape, eps, sim_.now()));
  }
  /// The intervals containing x (the segment tree), ids ascending.
  [[nodiscard]] std::vector<ObjectId> stab(double x) requires requires(S& s, double v, Time t) {
    s.stab(v, t);
  }
  {
    query("Session::stab");
    return ids_ascending(structure_->stab(x, sim_.now()));
  }

  /// The convex hull (KineticHull): ids counter-clockwise from the lowest-then-leftmost point;
  /// points inside a hull edge are not vertices, of points with identical motions the smallest
  /// id is named (different motions meeting exactly at a vertex now: either; docs/hull.md).
  [[nodiscard]] std::vector<ObjectId> hull() requires requires(S& s) { s.hull(); }
  {
    query("Session::hull");
    return ids_in_order(structure_->hull());
  }

  /// The Delaunay triangles (KineticDelaunay): ids, each counter-clockwise from its smallest id,
  /// sorted; ties by the rule of docs/delaunay.md.
  [[nodiscard]] std::vector<std::array<ObjectId, 3>> delaunay() requires requires(S& s) {
    s.triangles();
  }
  {
    query("Session::delaunay");
    std::vector<std::array<ObjectId, 3>> out;
    for (const auto& t : structure_->triangles())
      out.push_back({motions_.id(t[0]), motions_.id(t[1]), motions_.id(t[2])});
    return out;
  }

  /// The closest pair (KineticDelaunay): ids ascending, the smallest pair of ids among equally
  /// close ones; empty for fewer than two objects.
  [[nodiscard]] std::optional<std::array<ObjectId, 2>> closest_pair() requires requires(S& s) {
    s.closest_pair();
  }
  {
    query("Session::closest_pair");
    const auto pair = structure_->closest_pair();
    if (!pair) return std::nullopt;
    return std::array<ObjectId, 2>{motions_.id((*pair)[0]), motions_.id((*pair)[1])};
  }

  /// The pairs of boxes in contact (KineticSweepAndPrune): each (smaller id, larger id), sorted.
  [[nodiscard]] std::vector<std::array<ObjectId, 2>> colliding_pairs() requires
      requires(S& s, Time t) {
    s.colliding_pairs(t);
  }
  {
    query("Session::colliding_pairs");
    std::vector<std::array<ObjectId, 2>> out;
    for (const auto& [a, b] : structure_->colliding_pairs(sim_.now()))
      out.push_back({motions_.id(a), motions_.id(b)});
    return out;
  }

  /// The broad phase's per-frame report at the cost of what changed (BoxContacts::
  /// contact_changes): the pairs that began and ended contact since the previous call, with
  /// their times, and the contacts that began and ended in between. The first call reports every
  /// pair in contact as begun.
  [[nodiscard]] ContactChanges contact_changes() requires requires(S& s, Time t) {
    s.contact_changes(t);
  }
  {
    query("Session::contact_changes");
    return structure_->contact_changes(sim_.now());
  }

  /// Object `id`'s coordinates at now(), rounded to double (for display and for checks of
  /// your own; the structures decide with exact predicates, not with these values).
  [[nodiscard]] std::vector<double> position(ObjectId id) const {
    const ObjectHandle h = handle_of(id, "Session::position");
    std::vector<double> x(static_cast<std::size_t>(motions_.dimension()));
    for (int a = 0; a < motions_.dimension(); ++a) {
      x[static_cast<std::size_t>(a)] = motions_.motion(h.index, a).evaluate(sim_.now());
    }
    return x;
  }
  /// The ids of the objects present, ascending.
  [[nodiscard]] std::vector<ObjectId> ids() const {
    return ids_ascending(motions_.alive_indices());
  }

  // --- The parts, for advanced use. ------------------------------------------------------------

  /// The table, read-only: objects change through insert, update and remove.
  [[nodiscard]] const MotionTable& motions() const { return motions_; }
  /// The simulator: its counters, event log and interrupt flag, its queue read-only (a loop
  /// guard goes through set_guard(): advance() sets the simulator's own).
  [[nodiscard]] Simulator& simulator() { return sim_; }
  [[nodiscard]] const Simulator& simulator() const { return sim_; }
  /// The scheduler (its settings; e.g. a failure-time model for experiments).
  [[nodiscard]] Scheduler& scheduler() { return scheduler_; }
  [[nodiscard]] const Scheduler& scheduler() const { return scheduler_; }
  /// The simulator's counters with the KDS measures of now filled in: the certificates alive
  /// (and their maximum over the calls of this function) and the most certificates one object
  /// takes part in (an O(n) count on some structures).
  [[nodiscard]] const Counters& counters() {
    usable("Session::counters");
    start();
    sim_.counters().set_certificates_alive(structure_->certificates());
    sim_.counters().note_certificates_per_object(structure_->certificates_per_object_max());
    return sim_.counters();
  }
  /// The structure, initialized (built on first use).
  [[nodiscard]] S& structure() {
    usable("Session::structure");
    start();
    return *structure_;
  }
  /// The structure's invariants and its agreement with the table (S::validate()).
  [[nodiscard]] bool validate() {
    start();
    return structure_->validate();
  }

 private:
  static Scheduler checked_scheduler(const SessionOptions& o) {
    if (!std::isfinite(o.start)) precondition_failed("Session", "start time not finite");
    if (o.scheduler == SchedulerKind::Robust && Scheduler::eps_supported(o.eps) &&
        !(std::abs(o.start) <= Scheduler::max_supported_time(o.eps))) {
      precondition_failed("Session", "start time " + format_number(o.start) +
                                         " is outside the times robust scheduling supports at "
                                         "eps = " +
                                         format_number(o.eps) + " (|t| <= " +
                                         format_number(Scheduler::max_supported_time(o.eps)) +
                                         "; a larger eps reaches further)");
    }
    if (!(o.horizon >= o.start)) precondition_failed("Session", "horizon before the start time");
    // eps is robust scheduling's; the others take it as given (0 included).
    if (!std::isfinite(o.eps) || !(o.eps > 0.0 || (o.scheduler != SchedulerKind::Robust &&
                                                  o.eps == 0.0))) {
      precondition_failed("Session", "eps = " + format_number(o.eps) +
                                         " (a finite eps > 0; 0 too for the classic and exact "
                                         "schedulers)");
    }
    if (!scheduler_available(o.scheduler)) {
      precondition_failed("Session",
                          std::string("the ") + to_string(o.scheduler) + " scheduler is not built");
    }
    return Scheduler(o.scheduler, o.eps, o.horizon);
  }
  [[nodiscard]] bool started() const { return structure_->initialized(); }
  /// What the structure itself asks of a motion (the segment tree: an interval never inside out
  /// from now to the horizon; the hull: degree <= 3), checked before the table changes (which
  /// checks the rest), so that a refused motion leaves the session as it was.
  void require_structure_motion(const char* where, ObjectId id,
                                std::span<const MotionPolynomial> motion) const {
    if constexpr (requires { S::require_interval(where, motion, Time{}, Time{}); }) {
      S::require_interval(where, motion, sim_.now(), sim_.horizon());
    }
    if constexpr (requires { S::require_motion(motion, id, where, scheduler_.kind()); }) {
      S::require_motion(motion, id, where, scheduler_.kind());  // a limit per scheduler
    } else if constexpr (requires { S::require_motion(motion, id, where); }) {
      S::require_motion(motion, id, where);
    }
  }
  /// A loop guard that only a scheduling loop can trip: every structure here keeps fewer than
  /// d + 2 sorted lists of at most 2n + 2 entries (or a tournament of n), and at one instant
  /// each pair of entries of a list crosses at most once; the hull (d = 2) has fewer than
  /// 16 (n + 1)^2 certificates alive (two sides, O(n log n) tests per side), each failing at most
  /// once at one instant. No total budget: a session is open.
  [[nodiscard]] LoopGuard instant_guard() const {
    const std::uint64_t m = 2 * static_cast<std::uint64_t>(motions_.size()) + 2;
    LoopGuard g;
    g.max_events_per_instant = static_cast<std::uint64_t>(motions_.dimension() + 2) * m * m + 1024;
    return g;
  }
  void start() {
    if (!started()) structure_->initialize();
  }
  /// An advance stopped by the loop guard or the event budget leaves the session unusable.
  AdvanceOutcome note_failure(AdvanceOutcome o) {
    if (o == AdvanceOutcome::LoopGuard || o == AdvanceOutcome::EventBudget) failed_ = true;
    return o;
  }
  void usable(const char* where) const {
    if (failed_) precondition_failed(where, "the session failed earlier (SessionError)");
  }
  void query(const char* where) {
    usable(where);
    start();
  }
  ObjectHandle handle_of(ObjectId id, const char* where) const {
    const std::optional<ObjectHandle> h = motions_.find(id);
    if (!h) precondition_failed(where, "no object with id " + std::to_string(id));
    return *h;
  }
  std::optional<ObjectId> id_of(std::optional<std::uint32_t> index) const {
    if (!index) return std::nullopt;
    return motions_.id(*index);
  }
  std::vector<ObjectId> ids_in_order(std::span<const std::uint32_t> indices) const {
    std::vector<ObjectId> ids;
    ids.reserve(indices.size());
    for (const std::uint32_t i : indices) ids.push_back(motions_.id(i));
    return ids;
  }
  [[nodiscard]] std::vector<ObjectId> ids_ascending(
      const std::vector<std::uint32_t>& indices) const {
    std::vector<ObjectId> ids = ids_in_order(indices);
    std::sort(ids.begin(), ids.end());
    return ids;
  }

  MotionTable motions_;
  Simulator sim_;
  Scheduler scheduler_;
  std::unique_ptr<S> structure_;
  std::optional<LoopGuard> guard_;
  bool failed_ = false;
};

}  // namespace kinetic
