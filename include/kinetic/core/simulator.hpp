#pragma once
// The simulator: the KDS main loop (the KDS lecture notes; Abam, Agarwal, de Berg, Yu, Algorithm
// KINETICSORTING lines 2-4). It owns the global event queue and the current time t_curr, pops the
// earliest event, and hands it to the structure that owns it; the structure repairs itself and
// reschedules the certificates it names. The simulator knows nothing of the structures above it: a
// structure is any Handler with
//     EventKind process(const Event& event);
// called statically (no virtual call per event).
//
// t_curr is the maximum time of all processed events (and of every time advanced to), so with
// robust scheduling an event "in the past" is processed without moving the clock back.
//
// The loop guard turns a would-be infinite loop into an outcome the caller reports: at one
// instant (t_curr not advancing) a correct KDS processes a bounded number of events, given by
// the structure (e.g. n(n-1)/2 swaps for kinetic sorting: each pair crosses at most once at an
// instant), and over a run a bounded total (e.g. s * n(n-1)/2 for degree-s motions).

#include <algorithm>
#include <atomic>
#include <cassert>
#include <cstdint>
#include <limits>
#include <span>

#include "kinetic/core/counters.hpp"
#include "kinetic/core/error.hpp"
#include "kinetic/core/event_queue.hpp"
#include "kinetic/core/ids.hpp"
#include "kinetic/core/loop_guard.hpp"
#include "kinetic/core/time.hpp"

namespace kinetic {

class Scheduler;

/// What an event did to the maintained attribute (KDS terminology).
enum class EventKind { Internal, External };

enum class AdvanceOutcome {
  Reached,      ///< every event up to the requested time was processed
  LoopGuard,    ///< too many events at one instant: the scheduling loops (see guard_report())
  EventBudget,  ///< more events in total than a correct run can have
  Interrupted,  ///< the interrupt flag was raised (set_interrupt): stopped between two events
};

/// A contiguous range of owner tags [first, first + count) in the event queue, reserved by one
/// structure (or sub-structure) for its events: it pushes events with these owners and receives
/// them back in process(). Ranges never overlap within one simulator.
struct OwnerRange {
  std::uint32_t first = 0;
  std::uint32_t count = 0;
  [[nodiscard]] bool contains(std::uint32_t owner) const { return owner - first < count; }
  /// The k-th owner of the range. Precondition: k < count.
  [[nodiscard]] std::uint32_t operator[](std::uint32_t k) const {
    assert(k < count);  // debug builds only
    return first + k;
  }
};

struct GuardReport {
  Time time = 0.0;  ///< t_curr when the guard tripped
  std::uint64_t events_at_instant = 0;
  std::uint64_t events_total = 0;
};

/// An event handler that may tell the memory what the next event will touch before it is
/// processed (a hint only: nothing it does may change what the handler does). The simulator
/// calls prefetch(next, false) right after popping the current event (the first lines, e.g.
/// where the key's position is) and prefetch(next, true) after processing it (those lines have
/// arrived: the rest).
template <class Handler>
concept PrefetchingHandler = requires(const Handler& h, const Event& e) {
  h.prefetch(e, true);
};

class Simulator {
 public:
  explicit Simulator(Time start_time)
      : t_curr_(start_time), exact_now_(LazyTime::point(start_time)) {}

  [[nodiscard]] Time now() const { return t_curr_; }
  /// Under the queue's exact order (EventQueue::push_exact), the exact time of the last event
  /// processed or of the last time advanced to; now() is then a double at or below it.
  [[nodiscard]] LazyTime& exact_now() { return exact_now_; }
  /// The queue, read-only: structures schedule, reschedule and cancel through the simulator.
  [[nodiscard]] const EventQueue& queue() const { return queue_; }
  /// Whether an event is queued at or before t (under the exact order: its exact time; the
  /// comparison may refine the queued times' brackets, hence not const).
  [[nodiscard]] bool event_due_by(Time t) { return !queue_.empty() && queue_.top_at_or_before(t); }
  /// The next event's exact time under the exact order. Precondition: an event is queued and
  /// queue().exact_order().
  [[nodiscard]] LazyTime& next_exact_time() { return queue_.top_exact(); }
  [[nodiscard]] Counters& counters() { return counters_; }
  [[nodiscard]] const Counters& counters() const { return counters_; }

  /// Reserves `count` owner tags for a structure's events, after those reserved before (the
  /// first structure built on a simulator gets owners from 0). Structures call this in their
  /// constructors; nobody picks owner numbers by hand.
  OwnerRange reserve_owners(std::uint32_t count) {
    const OwnerRange r{next_owner_, count};
    next_owner_ += count;
    return r;
  }

  void set_guard(const LoopGuard& guard) { guard_ = guard; }
  /// A flag that stops an advance between two events when it becomes true (a signal handler
  /// sets it): the advance returns Interrupted with every event processed so far consistent and
  /// no event lost; t_curr stays at the last event processed. nullptr: none.
  void set_interrupt(const std::atomic<bool>* flag) { interrupt_ = flag; }
  /// The interrupt flag is raised.
  [[nodiscard]] bool interrupted() const {
    return interrupt_ != nullptr && interrupt_->load(std::memory_order_relaxed);
  }
  /// The event log (`kinetic run --events`): structures tell it their external events as they
  /// process them, with a kind (a documented word per structure: "swap", "contact_begin", ...),
  /// the ids of the objects involved and the axis (-1: none); the time is t_curr. One branch per
  /// event when unset.
  using EventLog = void (*)(void* context, Time time, const char* kind,
                            std::span<const ObjectId> ids, int axis);
  void set_event_log(EventLog log, void* context) {
    log_ = log;
    log_context_ = context;
  }
  [[nodiscard]] bool logging_events() const { return log_ != nullptr; }
  /// Told of every event processed, internal or external, after the structure processed it (a
  /// trace records them all; the event log above has only the external ones, with their ids).
  /// One branch per event when unset.
  using EventHook = void (*)(void* context, Time time, EventKind kind);
  void set_event_hook(EventHook hook, void* context) {
    hook_ = hook;
    hook_context_ = context;
  }
  void log_event(const char* kind, std::span<const ObjectId> ids, int axis = -1) const {
    if (log_ != nullptr) log_(log_context_, t_curr_, kind, ids, axis);
  }
  [[nodiscard]] const LoopGuard& guard() const { return guard_; }
  [[nodiscard]] const GuardReport& guard_report() const { return report_; }

  /// The structure changed from outside (insert, remove, flight-plan update): the per-instant
  /// event count starts again.
  void note_external_change() {
    events_at_instant_ = 0;
    ++instant_;
  }
  /// A stamp of the current instant: it changes whenever the clock moves on (exact_now() under
  /// the exact order, now() otherwise) and at every external change, so a structure can tell
  /// "at this same instant" (e.g. the contacts that ended exactly now).
  [[nodiscard]] std::uint64_t instant() const { return instant_; }

  /// A structure built on this simulator with `scheduler` calls this in its constructor:
  /// limit_horizon(scheduler.time_limit()), and for the exact scheduler the exact event order
  /// and the scheduler's clock bound to exact_now().
  void attach(const Scheduler& scheduler);

  /// Schedules a failure the scheduler computed: at its exact time when there is one (the exact
  /// scheduler), otherwise at t. Precondition: t is not NaN.
  EventHandle schedule(Time t, const ExactFailure& exact, std::uint32_t owner,
                       std::uint32_t payload) {
    return exact ? queue_.push_exact(*exact, owner, payload) : queue_.push(t, owner, payload);
  }
  /// The same, the exact time moved into the queue.
  EventHandle schedule(Time t, ExactFailure&& exact, std::uint32_t owner, std::uint32_t payload) {
    return exact ? queue_.push_exact(std::move(*exact), owner, payload)
                 : queue_.push(t, owner, payload);
  }
  /// Removes a certificate's event, if it is still queued (a null or stale handle: nothing), and
  /// nulls the handle. True when an event was removed.
  bool cancel(EventHandle& h) {
    const bool queued = !h.is_null() && queue_.contains(h);
    if (queued) queue_.remove(h);
    h = EventHandle{};
    return queued;
  }
  /// Replaces the event of a certificate whose failure time was computed again: `h` is its
  /// handle (null, or stale once popped: none), and becomes the new event's (null when t is
  /// infinite). A scheduled event is moved in place (one sift instead of a remove and a push)
  /// when neither it nor the new one is exact; either way it gets a new sequence number, so the
  /// event order is the same as a remove and a push would give.
  void reschedule(EventHandle& h, Time t, const ExactFailure& exact, std::uint32_t owner,
                  std::uint32_t payload) {
    if (replace_in_place(h, t, exact.has_value(), payload)) return;
    h = schedule(t, exact, owner, payload);
  }
  /// The same, the exact time moved into the queue.
  void reschedule(EventHandle& h, Time t, ExactFailure&& exact, std::uint32_t owner,
                  std::uint32_t payload) {
    if (replace_in_place(h, t, exact.has_value(), payload)) return;
    h = schedule(t, std::move(exact), owner, payload);
  }
  /// Schedules an event now (a certificate found invalid): at exact_now() under the exact order,
  /// otherwise at now().
  EventHandle schedule_now(std::uint32_t owner, std::uint32_t payload) {
    return queue_.exact_order() ? queue_.push_exact(exact_now_, owner, payload)
                                : queue_.push(t_curr_, owner, payload);
  }

  /// The structures on this simulator use schedulers that schedule no event after `horizon`
  /// (Scheduler::horizon()): advancing past the earliest such horizon is refused. Structures
  /// call this in their constructors.
  void limit_horizon(Time horizon) { horizon_ = std::min(horizon_, horizon); }
  [[nodiscard]] Time horizon() const { return horizon_; }
  /// Throws PreconditionError (named `where`) when t is NaN or after horizon(): no event after
  /// the horizon is scheduled, so a structure would be wrong there. advance_to() checks it.
  void require_time(const char* where, Time t) const {
    if (!(t <= horizon_)) refuse_time(where, t);
  }

  /// Processes every event with time <= t (in queue order), then sets t_curr = max(t_curr, t).
  /// Throws PreconditionError when t is NaN or after horizon(), or when the handler has an
  /// initialized() that is false.
  template <class Handler>
  AdvanceOutcome advance_to(Time t, Handler& handler) {
    require_time("Simulator::advance_to", t);
    require_initialized(handler);
    while (event_due_by(t)) {
      if (interrupted()) return AdvanceOutcome::Interrupted;
      const AdvanceOutcome o = step(handler);
      if (o != AdvanceOutcome::Reached) return o;
    }
    advance_clock(t);
    if (queue_.exact_order()) {
      sync_exact_counters();
      LazyTime target = LazyTime::point(t);
      if (compare(target, exact_now_) > 0) {
        exact_now_ = std::move(target);
        events_at_exact_now_ = 0;
        ++instant_;
      }
    }
    return AdvanceOutcome::Reached;
  }

  /// Processes events until the queue is empty ("until no event is left").
  template <class Handler>
  AdvanceOutcome run_until_empty(Handler& handler) {
    require_initialized(handler);
    while (!queue_.empty()) {
      if (interrupted()) return AdvanceOutcome::Interrupted;
      const AdvanceOutcome o = step(handler);
      if (o != AdvanceOutcome::Reached) return o;
    }
    return AdvanceOutcome::Reached;
  }

  /// Processes exactly one event (test mode: validate between events). Precondition: !empty().
  template <class Handler>
  AdvanceOutcome process_next(Handler& handler) {
    require_initialized(handler);
    return step(handler);
  }

 private:
  /// reschedule()'s first half: cancels (t infinite), or moves the queued event in place (no exact
  /// time, the double order), and returns true; otherwise removes the queued event, if any, and
  /// returns false (the caller schedules anew).
  bool replace_in_place(EventHandle& h, Time t, bool exact, std::uint32_t payload) {
    const bool queued = !h.is_null() && queue_.contains(h);
    if (t == kTimeInfinity) {
      cancel(h);
      return true;
    }
    if (queued && !exact && !queue_.exact_order()) {
      queue_.update(h, t, payload);
      return true;
    }
    if (queued) queue_.remove(h);
    return false;
  }
  template <class Handler>
  static void require_initialized(const Handler& handler) {
    if constexpr (requires { handler.initialized(); }) {
      if (!handler.initialized()) {
        precondition_failed("Simulator",
                            "the structure was not initialized (call its "
                            "initialize() before advancing)");
      }
    }
  }
  [[noreturn]] void refuse_time(const char* where, Time t) const;

  template <class Handler>
  AdvanceOutcome step(Handler& handler) {
    if (queue_.exact_order()) return step_exact(handler);
    const Event e = queue_.pop();
    if (e.time < t_curr_) {
      ++counters_.events_in_past;
    } else {
      advance_clock(e.time);
    }
    if constexpr (PrefetchingHandler<Handler>) {
      if (queue_.empty()) return process(handler, e);
      queue_.prefetch_second();
      handler.prefetch(queue_.top(), false);
      const AdvanceOutcome o = process(handler, e);
      if (!queue_.empty()) handler.prefetch(queue_.top(), true);
      return o;
    } else {
      return process(handler, e);
    }
  }

  /// Under the exact order: the clock is the event's exact time; events at one exact time are
  /// an equal-time group (processed in scheduling order, counted).
  template <class Handler>
  AdvanceOutcome step_exact(Handler& handler) {
    LazyTime at;
    const Event e = queue_.pop(&at);
    const std::size_t refined = at.refinements() + exact_now_.refinements();
    const int c = compare(at, exact_now_);
    counters_.exact_refinements += at.refinements() + exact_now_.refinements() - refined;
    sync_exact_counters();
    if (c < 0) {
      ++counters_.events_in_past;  // (the exact order never does this)
    } else if (c > 0) {
      ++instant_;
      exact_now_ = std::move(at);
      if (exact_now_.lower() > t_curr_) {
        t_curr_ = exact_now_.lower();
        events_at_instant_ = 0;
      }
      events_at_exact_now_ = 0;
    }
    if (c >= 0 && ++events_at_exact_now_ == 2) ++counters_.equal_time_groups;
    return process(handler, e);
  }

  template <class Handler>
  AdvanceOutcome process(Handler& handler, const Event& e) {
    ++events_at_instant_;
    const std::uint64_t total = counters_.events() + 1;
    if (events_at_instant_ > guard_.max_events_per_instant || total > guard_.max_events_total) {
      report_ = GuardReport{t_curr_, events_at_instant_, total - 1};
      return events_at_instant_ > guard_.max_events_per_instant ? AdvanceOutcome::LoopGuard
                                                                : AdvanceOutcome::EventBudget;
    }
    const EventKind kind = handler.process(e);
    if (kind == EventKind::External) {
      ++counters_.events_external;
    } else {
      ++counters_.events_internal;
    }
    if (hook_ != nullptr) hook_(hook_context_, t_curr_, kind);
    return AdvanceOutcome::Reached;
  }

  /// The queue's exact comparisons and refinements into the counters.
  void sync_exact_counters() {
    counters_.exact_comparisons = queue_.exact_comparisons();
    counters_.exact_comparisons_gmp = queue_.exact_comparisons_gmp();
    counters_.exact_refinements += queue_.exact_refinements() - queue_refinements_seen_;
    queue_refinements_seen_ = queue_.exact_refinements();
  }

  void advance_clock(Time t) {
    if (t > t_curr_) {
      t_curr_ = t;
      events_at_instant_ = 0;
      if (!queue_.exact_order()) ++instant_;
    }
  }

  EventQueue queue_;
  Counters counters_;
  LoopGuard guard_;
  const std::atomic<bool>* interrupt_ = nullptr;
  EventHook hook_ = nullptr;
  void* hook_context_ = nullptr;
  EventLog log_ = nullptr;
  void* log_context_ = nullptr;
  GuardReport report_;
  Time t_curr_;
  LazyTime exact_now_;
  std::uint64_t events_at_exact_now_ = 0;  // events processed at exact_now_
  std::uint64_t queue_refinements_seen_ = 0;
  std::uint64_t instant_ = 0;
  std::uint64_t events_at_instant_ = 0;
  std::uint32_t next_owner_ = 0;
  Time horizon_ = kTimeInfinity;
};

}  // namespace kinetic
