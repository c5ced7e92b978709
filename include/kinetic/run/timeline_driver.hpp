#pragma once
// The timeline driver: a session (Session<S>, the one owner of the motion table, the simulator,
// the scheduler and the structure) built from a scenario, and the one loop that plays a
// scenario's timeline on it: advance to each entry's time, then apply the entry (an insert, a
// remove, a flight-plan update, through the session) or hand it to the caller (a query). The
// runner, the test harnesses, the experiments and the benchmarks all play scenarios through it.

#include <concepts>
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <vector>

#include "kinetic/core/loop_guard.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/polynomial.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/structure.hpp"
#include "kinetic/core/table_changes.hpp"
#include "kinetic/scenario/scenario.hpp"
#include "kinetic/session/session.hpp"

namespace kinetic::run {

/// The motion polynomials of a scenario motion, one per coordinate, followed for a box by its
/// half extents as constant polynomials (the table layout of core/boxes.hpp).
[[nodiscard]] std::vector<MotionPolynomial> to_polynomials(
    const scenario::Motion& m, const std::vector<double>& half_extents = {});
/// The table's dimension for a scenario: boxes_table_dimension(d) for boxes, d otherwise.
[[nodiscard]] int table_dimension(const scenario::Scenario& s);

/// What a run of the scenario can hold at most, for the loop guard's bounds (core/loop_guard.hpp):
/// objects alive at once (the initial ones plus every insert), motions given (objects plus
/// inserts and updates), the highest degree of any coordinate (trailing zero coefficients
/// ignored), and the scenario's dimension.
using ScenarioBounds = RunBounds;
[[nodiscard]] ScenarioBounds bounds_of(const scenario::Scenario& s);
/// The degree of a scenario motion: its highest non-zero coefficient over the axes.
[[nodiscard]] int degree_of(const scenario::Motion& m);

/// The scenario's objects in a table, their motions valid from start_time (for oracles and
/// checks beside a run; a run's own table is its session's).
[[nodiscard]] MotionTable table_of(const scenario::Scenario& s);
/// Where a run of the scenario ends: end_time, or else the last timeline entry (start_time if
/// none).
[[nodiscard]] Time end_of(const scenario::Scenario& s);
/// A session's options for a run of the scenario: the scheduler and eps given, the clock at
/// start_time, the horizon at end_time (none without one).
[[nodiscard]] SessionOptions session_options(const scenario::Scenario& s, SchedulerKind kind,
                                             double eps);
/// An update's new motion: a box update without half extents keeps the box's (read from the
/// table, where object h's are).
[[nodiscard]] std::vector<MotionPolynomial> updated_motion(const scenario::Scenario& s,
                                                           const scenario::TimelineOp& op,
                                                           const MotionTable& table,
                                                           ObjectHandle h);

/// The result of play(): how the run ended, how many events it processed, and whether a hook
/// stopped it (outcome Reached then).
struct PlayResult {
  AdvanceOutcome outcome = AdvanceOutcome::Reached;
  std::uint64_t events = 0;
  bool stopped = false;
};

template <KineticStructure S>
class TimelineDriver {
 public:
  /// The session holds the scenario's objects (their motions valid from start_time), its clock
  /// at start_time and its horizon at end_time; the structure is built from `structure_args`
  /// as Session<S> builds it (S's constructor's arguments after the table, simulator and
  /// scheduler, or a build_with(make)), and initialized on first use. The driver keeps a
  /// reference to the scenario: it must outlive the driver.
  template <class... Args>
  TimelineDriver(const scenario::Scenario& s, SchedulerKind kind, double eps,
                 Args&&... structure_args)
      : scenario_(s),
        session_(table_dimension(s), session_options(s, kind, eps),
                 std::forward<Args>(structure_args)...) {
    // The scenario's reader checked the motions (an interval up to its next change).
    for (const scenario::ObjectSpec& o : s.objects)
      session_.insert_checked(o.id, to_polynomials(o.motion, o.half_extents));
  }

  [[nodiscard]] const scenario::Scenario& scenario() const { return scenario_; }
  [[nodiscard]] Session<S>& session() { return session_; }
  [[nodiscard]] const MotionTable& motions() const { return session_.motions(); }
  [[nodiscard]] Simulator& sim() { return session_.simulator(); }
  [[nodiscard]] const Simulator& sim() const { return session_.simulator(); }
  [[nodiscard]] Scheduler& scheduler() { return session_.scheduler(); }
  /// The structure, initialized (built on first use).
  [[nodiscard]] S& structure() { return session_.structure(); }
  /// Where the run ends (end_of).
  [[nodiscard]] Time end() const { return end_of(scenario_); }

  /// Applies a timeline change through the session (the table first, then the structure, then
  /// the simulator notes an external change: core/table_changes.hpp). A query entry changes
  /// nothing. Precondition: the clock is at op.time (advance_to(op.time) first).
  void apply(const scenario::TimelineOp& op) {
    if (op.op == scenario::OpKind::Query) return;
    if (!(op.time == session_.now())) {
      throw std::logic_error("TimelineDriver::apply: the clock is not at the entry's time");
    }
    switch (op.op) {
      case scenario::OpKind::Insert:
        session_.insert_checked(op.id, to_polynomials(op.motion, op.half_extents));
        return;
      case scenario::OpKind::Remove:
        session_.remove(op.id);
        return;
      case scenario::OpKind::Update:
        session_.update(op.id, updated_motion(scenario_, op, motions(), *motions().find(op.id)));
        return;
      case scenario::OpKind::Query:
        return;
    }
  }

  /// Processes every event with time <= t, then moves the clock to t; with after_event, one
  /// event at a time, calling it after each (validate, audit, count; false stops).
  template <class AfterEvent = std::nullptr_t>
  AdvanceOutcome advance_to(Time t, AfterEvent&& after_event = nullptr) {
    return session_.advance_until(t, std::forward<AfterEvent>(after_event));
  }

  /// Plays the whole scenario: for each timeline entry in order, advance to its time, then
  /// hooks.query(op) for a query or apply(op) and hooks.change(op) for a change; at each time of
  /// `probes` (ascending) advance to it and call hooks.probe(t) before the entries at that
  /// time; finally run to end_time (or, without one, until no event is left). Every hook is
  /// optional:
  /// - hooks.event(): events are processed one at a time and it is called after each;
  /// - hooks.slices() (an int) and hooks.progress(): each advance is cut into that many slices
  ///   of time, progress() called after each (a progress bar moves during long stretches);
  /// - hooks.advanced(): called after every advance that reached its time (to an entry, a
  ///   probe, a slice, the end; before the entry), and after the events left are run out;
  /// - event(), advanced(), query(op) and change(op) may return a bool: false stops the play
  ///   there (PlayResult::stopped).
  /// Stops at the first outcome other than Reached, and when the simulator's interrupt flag is
  /// raised (checked between entries too: a timeline of queries has no events to stop at).
  template <class Hooks>
  PlayResult play(Hooks&& hooks, std::span<const Time> probes = {}) {
    PlayResult r;
    Simulator& sim = session_.simulator();
    const std::uint64_t events_before = sim.counters().events();
    auto after_event = [&] {
      if constexpr (requires { hooks.event(); }) {
        r.stopped = !kinetic::detail::hook_goes_on([&] { return hooks.event(); });
      }
      return !r.stopped;
    };
    // After an advance that reached its time: hooks.advanced().
    auto note_reached = [&](AdvanceOutcome o) {
      if constexpr (requires { hooks.advanced(); }) {
        if (o == AdvanceOutcome::Reached && !r.stopped) {
          r.stopped = !kinetic::detail::hook_goes_on([&] { return hooks.advanced(); });
        }
      }
      return o;
    };
    auto advance_once = [&](Time t) {
      if constexpr (requires { hooks.event(); }) {
        return note_reached(session_.advance_until(t, after_event));
      } else {
        return note_reached(session_.advance_until(t));
      }
    };
    auto advance = [&](Time t) {
      int slices = 1;
      if constexpr (requires { hooks.slices(); }) slices = hooks.slices();
      if (slices <= 1) return advance_once(t);
      const Time from = sim.now();
      for (int k = 1; k <= slices; ++k) {
        const Time slice = k == slices ? t : from + (t - from) * (static_cast<double>(k) / slices);
        if (slice < sim.now()) continue;
        const AdvanceOutcome o = advance_once(slice);
        if (o != AdvanceOutcome::Reached || r.stopped) return o;
        if constexpr (requires { hooks.progress(); }) hooks.progress();
      }
      return AdvanceOutcome::Reached;
    };
    auto reached = [&](AdvanceOutcome o) {
      r.outcome = o;
      return o == AdvanceOutcome::Reached && !r.stopped;
    };
    std::size_t next_probe = 0;
    auto probe_until = [&](Time t, bool inclusive) {
      while (next_probe < probes.size() &&
             (probes[next_probe] < t || (inclusive && probes[next_probe] == t))) {
        const Time p = probes[next_probe++];
        if (!reached(advance(p))) return false;
        if constexpr (requires { hooks.probe(p); }) hooks.probe(p);
      }
      return true;
    };
    bool ok = true;
    for (const scenario::TimelineOp& op : scenario_.timeline) {
      if (!(ok = probe_until(op.time, true) && reached(advance(op.time)))) break;
      if (sim.interrupted()) {
        r.outcome = AdvanceOutcome::Interrupted;
        ok = false;
        break;
      }
      if (op.op == scenario::OpKind::Query) {
        if constexpr (requires { hooks.query(op); }) {
          r.stopped = !kinetic::detail::hook_goes_on([&] { return hooks.query(op); });
        }
      } else {
        apply(op);
        if constexpr (requires { hooks.change(op); }) {
          r.stopped = !kinetic::detail::hook_goes_on([&] { return hooks.change(op); });
        }
      }
      if (!(ok = !r.stopped)) break;
    }
    if (ok && probe_until(kTimeInfinity, false)) {
      if (scenario_.end_time) {
        reached(advance(*scenario_.end_time));
      } else if constexpr (requires { hooks.event(); }) {
        reached(note_reached(session_.run_until_empty(after_event)));
      } else {
        reached(note_reached(session_.run_until_empty()));
      }
    }
    r.events = sim.counters().events() - events_before;
    return r;
  }

 private:
  const scenario::Scenario& scenario_;
  Session<S> session_;
};

}  // namespace kinetic::run
