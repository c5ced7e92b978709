#pragma once
// The timeline driver: the one place that builds the world a kinetic structure lives in -- the
// motion table, the simulator and the scheduler -- from a scenario, and plays the scenario's
// timeline on a structure: advance to each entry's time, then apply the entry (an insert, a
// remove, a flight-plan update) or hand it to the caller (a query). The runner, the test
// harnesses and the experiments all use it, so the order in which the table and a structure
// learn of a change is written once (apply()).

#include <concepts>
#include <cstdint>
#include <span>
#include <vector>

#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/polynomial.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/structure.hpp"
#include "kinetic/core/table_changes.hpp"
#include "kinetic/scenario/scenario.hpp"

namespace kinetic::run {

/// The motion polynomials of a scenario motion, one per coordinate, followed for a box by its
/// half extents as constant polynomials (the table layout of core/boxes.hpp).
[[nodiscard]] std::vector<MotionPolynomial> to_polynomials(
    const scenario::Motion& m, const std::vector<double>& half_extents = {});
/// The table's dimension for a scenario: boxes_table_dimension(d) for boxes, d otherwise.
[[nodiscard]] int table_dimension(const scenario::Scenario& s);

/// What a run of the scenario can hold at most, for the loop guard's bounds: objects alive at
/// once (the initial ones plus every insert), motions given (objects plus inserts and updates),
/// and the highest degree of any coordinate (trailing zero coefficients ignored).
struct ScenarioBounds {
  std::uint64_t max_objects = 0;
  std::uint64_t motion_changes = 0;
  int max_degree = 0;
};
[[nodiscard]] ScenarioBounds bounds_of(const scenario::Scenario& s);
/// The degree of a scenario motion: its highest non-zero coefficient over the axes.
[[nodiscard]] int degree_of(const scenario::Motion& m);

/// The result of play(): how the run ended and how many events it processed.
struct PlayResult {
  AdvanceOutcome outcome = AdvanceOutcome::Reached;
  std::uint64_t events = 0;
};

class TimelineDriver {
 public:
  /// The table holds the scenario's objects (their motions valid from start_time); the
  /// simulator starts at start_time; the scheduler bounds its windows by end_time. The driver
  /// keeps a reference to the scenario: it must outlive the driver.
  TimelineDriver(const scenario::Scenario& s, SchedulerKind kind, double eps);

  [[nodiscard]] const scenario::Scenario& scenario() const { return scenario_; }
  [[nodiscard]] MotionTable& motions() { return motions_; }
  [[nodiscard]] const MotionTable& motions() const { return motions_; }
  [[nodiscard]] Simulator& sim() { return sim_; }
  [[nodiscard]] const Simulator& sim() const { return sim_; }
  [[nodiscard]] Scheduler& scheduler() { return scheduler_; }
  [[nodiscard]] const Scheduler& scheduler() const { return scheduler_; }
  /// Where the run ends: end_time, or else the last timeline entry (start_time if none).
  [[nodiscard]] Time end() const;

  /// Applies a timeline change at op.time to the table and to the structure, in the order the
  /// structure contract asks for (core/table_changes.hpp: the table first, then the structure,
  /// then the simulator notes an external change). A query entry changes nothing.
  /// Precondition: the simulator was advanced to op.time.
  template <KineticStructure S>
  void apply(const scenario::TimelineOp& op, S& structure) {
    switch (op.op) {
      case scenario::OpKind::Insert:
        insert_object(motions_, sim_, structure, true, op.id,
                      to_polynomials(op.motion, op.half_extents), op.time);
        return;
      case scenario::OpKind::Remove:
        remove_object(motions_, sim_, structure, true, *motions_.find(op.id));
        return;
      case scenario::OpKind::Update: {
        const ObjectHandle h = *motions_.find(op.id);
        update_object(motions_, sim_, structure, true, h, updated_motion(op, h), op.time);
        return;
      }
      case scenario::OpKind::Query:
        return;
    }
  }

  /// Processes every event with time <= t, then moves the clock to t.
  template <KineticStructure S>
  AdvanceOutcome advance_to(Time t, S& structure) {
    return sim_.advance_to(t, structure);
  }
  /// The same, one event at a time, calling after_event() after each (validate, audit, count).
  template <KineticStructure S, std::invocable AfterEvent>
  AdvanceOutcome advance_to(Time t, S& structure, AfterEvent&& after_event) {
    while (sim_.event_due_by(t)) {
      const AdvanceOutcome o = sim_.process_next(structure);
      if (o != AdvanceOutcome::Reached) return o;
      after_event();
    }
    return sim_.advance_to(t, structure);
  }

  /// Plays the whole scenario on the structure: for each timeline entry in order, advance to
  /// its time, then hooks.query(op) for a query or apply(op) and hooks.change(op) for a change;
  /// at each time of `probes` (ascending) advance to it and call hooks.probe(t) before the
  /// entries at that time; finally run to end_time (or, without one, until no event is left).
  /// With hooks.event() defined, events are processed one at a time and it is called after
  /// each. Every hook is optional. Stops at the first outcome other than Reached.
  template <KineticStructure S, class Hooks>
  PlayResult play(S& structure, Hooks&& hooks, std::span<const Time> probes = {}) {
    PlayResult r;
    const std::uint64_t events_before = sim_.counters().events();
    auto advance = [&](Time t) {
      if constexpr (requires { hooks.event(); }) {
        return advance_to(t, structure, [&] { hooks.event(); });
      } else {
        return advance_to(t, structure);
      }
    };
    std::size_t next_probe = 0;
    auto probe_until = [&](Time t, bool inclusive) {
      while (next_probe < probes.size() &&
             (probes[next_probe] < t || (inclusive && probes[next_probe] == t))) {
        const Time p = probes[next_probe++];
        r.outcome = advance(p);
        if (r.outcome != AdvanceOutcome::Reached) return false;
        if constexpr (requires { hooks.probe(p); }) hooks.probe(p);
      }
      return true;
    };
    bool ok = true;
    for (const scenario::TimelineOp& op : scenario_.timeline) {
      if (!(ok = probe_until(op.time, true))) break;
      r.outcome = advance(op.time);
      if (!(ok = r.outcome == AdvanceOutcome::Reached)) break;
      if (op.op == scenario::OpKind::Query) {
        if constexpr (requires { hooks.query(op); }) hooks.query(op);
      } else {
        apply(op, structure);
        if constexpr (requires { hooks.change(op); }) hooks.change(op);
      }
    }
    if (ok && (ok = probe_until(kTimeInfinity, false))) {
      if (scenario_.end_time) {
        r.outcome = advance(*scenario_.end_time);
      } else if constexpr (requires { hooks.event(); }) {
        while (r.outcome == AdvanceOutcome::Reached && !sim_.queue().empty()) {
          r.outcome = sim_.process_next(structure);
          if (r.outcome == AdvanceOutcome::Reached) hooks.event();
        }
      } else {
        r.outcome = sim_.run_until_empty(structure);
      }
    }
    r.events = sim_.counters().events() - events_before;
    return r;
  }

 private:
  /// An update's new motion; a box update without half extents keeps the box's.
  [[nodiscard]] std::vector<MotionPolynomial> updated_motion(const scenario::TimelineOp& op,
                                                             ObjectHandle h) const;

  const scenario::Scenario& scenario_;
  MotionTable motions_;
  Simulator sim_;
  Scheduler scheduler_;
};

}  // namespace kinetic::run
