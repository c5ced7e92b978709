// The simulator main loop with tiny handlers that record what they see: advance_to / process_next
// / run_until_empty, t_curr as the maximum processed time, events in the past, the loop guard and
// the event budget, internal/external counts.

#include "kinetic/core/simulator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <limits>
#include <vector>

namespace kinetic {
namespace {

struct Seen {
  Event event;
  Time now;  // sim.now() while processing
};

/// Records every event; returns External for odd payloads; an optional hook may schedule more.
struct Recorder {
  Simulator* sim = nullptr;
  std::vector<Seen> seen;
  std::function<void(const Event&)> hook;
  EventKind process(const Event& e) {
    seen.push_back(Seen{e, sim->now()});
    if (hook) hook(e);
    return (e.payload % 2 == 1) ? EventKind::External : EventKind::Internal;
  }
  std::vector<std::uint32_t> payloads() const {
    std::vector<std::uint32_t> out;
    for (const Seen& s : seen) out.push_back(s.event.payload);
    return out;
  }
};

/// Schedules one event at each of the times, in order, its payload the time's index (owner 0).
void schedule_in_order(Simulator& sim, std::initializer_list<Time> times) {
  std::uint32_t payload = 0;
  for (const Time t : times) sim.schedule(t, ExactFailure{}, 0, payload++);
}

TEST(SimulatorAdvance, ProcessesExactlyTheEventsUpToTInOrder) {
  Simulator sim(0.0);
  Recorder r{&sim, {}, {}};
  schedule_in_order(sim, {3.0, 1.0, 2.0, 5.0, 2.0, 2.5000000000000004});  // the last just after 2.5

  EXPECT_EQ(sim.advance_to(2.5, r), AdvanceOutcome::Reached);
  EXPECT_EQ(r.payloads(), (std::vector<std::uint32_t>{1, 2, 4}));  // ties in push order
  EXPECT_EQ(sim.now(), 2.5);
  EXPECT_EQ(sim.queue().size(), 3u);
  // While processing, now() is the event's time (the maximum processed so far).
  EXPECT_EQ(r.seen[0].now, 1.0);
  EXPECT_EQ(r.seen[1].now, 2.0);
  EXPECT_EQ(r.seen[2].now, 2.0);

  EXPECT_EQ(sim.advance_to(5.0, r), AdvanceOutcome::Reached);  // inclusive: 5.0 <= 5.0
  EXPECT_EQ(r.payloads(), (std::vector<std::uint32_t>{1, 2, 4, 5, 0, 3}));
  EXPECT_EQ(sim.now(), 5.0);
  EXPECT_TRUE(sim.queue().empty());
  EXPECT_EQ(sim.counters().events(), 6u);
  EXPECT_EQ(sim.counters().events_in_past, 0u);

  // Advancing to an earlier time does not move the clock back.
  EXPECT_EQ(sim.advance_to(4.0, r), AdvanceOutcome::Reached);
  EXPECT_EQ(sim.now(), 5.0);
  EXPECT_EQ(sim.advance_to(7.0, r), AdvanceOutcome::Reached);
  EXPECT_EQ(sim.now(), 7.0);
  EXPECT_EQ(r.seen.size(), 6u);
}

TEST(SimulatorAdvance, EventsScheduledWhileProcessingAreIncludedUpToT) {
  Simulator sim(0.0);
  Recorder r{&sim, {}, {}};
  r.hook = [&](const Event& e) {
    if (e.payload == 0) {
      sim.schedule(1.5, ExactFailure{}, 0, 10);  // within the advance
      sim.schedule(4.0, ExactFailure{}, 0, 11);  // beyond it
      sim.schedule(1.0, ExactFailure{}, 0, 12);  // at the same instant: after the current event
    }
  };
  sim.schedule(1.0, ExactFailure{}, 0, 0);
  sim.schedule(1.0, ExactFailure{}, 0, 2);
  EXPECT_EQ(sim.advance_to(2.0, r), AdvanceOutcome::Reached);
  EXPECT_EQ(r.payloads(), (std::vector<std::uint32_t>{0, 2, 12, 10}));
  EXPECT_EQ(sim.now(), 2.0);
  ASSERT_EQ(sim.queue().size(), 1u);
  EXPECT_EQ(sim.queue().top().payload, 11u);
}

TEST(SimulatorAdvance, EventInThePastIsProcessedWithoutMovingTheClockBack) {
  Simulator sim(10.0);
  Recorder r{&sim, {}, {}};
  sim.schedule(7.0, ExactFailure{}, 0, 0);
  EXPECT_EQ(sim.advance_to(10.0, r), AdvanceOutcome::Reached);
  ASSERT_EQ(r.seen.size(), 1u);
  EXPECT_EQ(r.seen[0].now, 10.0);
  EXPECT_EQ(sim.now(), 10.0);
  EXPECT_EQ(sim.counters().events_in_past, 1u);

  // A handler that schedules into the past (as robust scheduling may): processed next, counted.
  r.hook = [&](const Event& e) {
    if (e.payload == 2) sim.schedule(11.0, ExactFailure{}, 0, 4);
  };
  sim.schedule(12.0, ExactFailure{}, 0, 2);
  EXPECT_EQ(sim.run_until_empty(r), AdvanceOutcome::Reached);
  ASSERT_EQ(r.seen.size(), 3u);
  EXPECT_EQ(r.seen[1].now, 12.0);
  EXPECT_EQ(r.seen[2].event.time, 11.0);
  EXPECT_EQ(r.seen[2].now, 12.0);
  EXPECT_EQ(sim.now(), 12.0);
  EXPECT_EQ(sim.counters().events_in_past, 2u);
  // An event exactly at t_curr is not in the past.
  sim.schedule(12.0, ExactFailure{}, 0, 6);
  EXPECT_EQ(sim.process_next(r), AdvanceOutcome::Reached);
  EXPECT_EQ(sim.counters().events_in_past, 2u);
  EXPECT_EQ(sim.counters().events(), 4u);
}

TEST(SimulatorAdvance, ProcessNextProcessesExactlyOne) {
  Simulator sim(0.0);
  Recorder r{&sim, {}, {}};
  schedule_in_order(sim, {3.0, 1.0, 2.0});
  EXPECT_EQ(sim.process_next(r), AdvanceOutcome::Reached);
  EXPECT_EQ(r.payloads(), (std::vector<std::uint32_t>{1}));
  EXPECT_EQ(sim.now(), 1.0);
  EXPECT_EQ(sim.queue().size(), 2u);
  EXPECT_EQ(sim.process_next(r), AdvanceOutcome::Reached);
  EXPECT_EQ(r.payloads(), (std::vector<std::uint32_t>{1, 2}));
  EXPECT_EQ(sim.now(), 2.0);
  EXPECT_EQ(sim.queue().size(), 1u);
  EXPECT_EQ(sim.counters().events(), 2u);
}

TEST(SimulatorAdvance, RunUntilEmptyAndInternalExternalCounts) {
  Simulator sim(-5.0);
  Recorder r{&sim, {}, {}};
  for (std::uint32_t i = 0; i < 10; ++i)
    sim.schedule(static_cast<double>(i) * 0.25, ExactFailure{}, 0, i);
  EXPECT_EQ(sim.run_until_empty(r), AdvanceOutcome::Reached);
  EXPECT_EQ(r.seen.size(), 10u);
  EXPECT_EQ(sim.now(), 2.25);
  EXPECT_EQ(sim.counters().events_external, 5u);  // odd payloads
  EXPECT_EQ(sim.counters().events_internal, 5u);
  EXPECT_EQ(sim.counters().events(), 10u);
  EXPECT_EQ(sim.queue().max_size(), 10u);
  // Empty queue: nothing happens.
  EXPECT_EQ(sim.run_until_empty(r), AdvanceOutcome::Reached);
  EXPECT_EQ(sim.counters().events(), 10u);
}

// ---------------------------------------------------------------------------------------------
// Loop guard.

/// A guard of at most `per_instant` events at one instant and `total` in all.
LoopGuard guard_of(std::uint64_t per_instant,
                   std::uint64_t total = std::numeric_limits<std::uint64_t>::max()) {
  LoopGuard g;
  g.max_events_per_instant = per_instant;
  g.max_events_total = total;
  return g;
}

/// Reschedules every event at the same time, forever.
struct SameTimeLooper {
  Simulator* sim;
  std::uint64_t processed = 0;
  EventKind process(const Event& e) {
    ++processed;
    sim->schedule(e.time, ExactFailure{}, e.owner, e.payload + 1);
    return EventKind::Internal;
  }
};

/// Reschedules every event at the next double, forever: time advances by tiny steps.
struct TinyStepLooper {
  Simulator* sim;
  std::uint64_t processed = 0;
  EventKind process(const Event& e) {
    ++processed;
    sim->schedule(std::nextafter(e.time, kTimeInfinity), ExactFailure{}, e.owner, e.payload + 1);
    return EventKind::External;
  }
};

TEST(SimulatorGuard, SameTimeLoopStoppedByTheLoopGuard) {
  Simulator sim(0.0);
  sim.set_guard(guard_of(50, 1000000));
  EXPECT_EQ(sim.guard().max_events_per_instant, 50u);
  SameTimeLooper h{&sim};
  sim.schedule(3.0, ExactFailure{}, 7, 0);
  EXPECT_EQ(sim.advance_to(10.0, h), AdvanceOutcome::LoopGuard);
  EXPECT_EQ(h.processed, 50u);  // exactly the allowed number of events at the instant
  EXPECT_EQ(sim.counters().events(), 50u);
  EXPECT_EQ(sim.now(), 3.0);  // the clock did not jump to 10
  const GuardReport& rep = sim.guard_report();
  EXPECT_EQ(rep.time, 3.0);
  EXPECT_GT(rep.events_at_instant, 50u);
  EXPECT_EQ(rep.events_at_instant, 51u);  // the event that tripped the guard is counted
  EXPECT_EQ(rep.events_total, 50u);
}

/// A same-time loop under a guard of `max_per_instant` events at one instant: one event queued
/// at t = 1, its handler rescheduling it there forever.
struct GuardedSameTimeLoop {
  Simulator sim{0.0};
  SameTimeLooper h{&sim};

  explicit GuardedSameTimeLoop(std::uint64_t max_per_instant) {
    sim.set_guard(guard_of(max_per_instant));
    sim.schedule(1.0, ExactFailure{}, 0, 0);
  }
};

TEST(SimulatorGuard, RunUntilEmptyAndProcessNextAlsoGuarded) {
  {
    GuardedSameTimeLoop loop(5);
    EXPECT_EQ(loop.sim.run_until_empty(loop.h), AdvanceOutcome::LoopGuard);
    EXPECT_EQ(loop.h.processed, 5u);
    EXPECT_EQ(loop.sim.guard_report().time, 1.0);
  }
  {
    GuardedSameTimeLoop loop(2);
    EXPECT_EQ(loop.sim.process_next(loop.h), AdvanceOutcome::Reached);
    EXPECT_EQ(loop.sim.process_next(loop.h), AdvanceOutcome::Reached);
    EXPECT_EQ(loop.sim.process_next(loop.h), AdvanceOutcome::LoopGuard);
    EXPECT_EQ(loop.h.processed, 2u);
  }
}

TEST(SimulatorGuard, TinyStepLoopStoppedByTheEventBudget) {
  Simulator sim(0.0);
  sim.set_guard(guard_of(3, 2000));
  TinyStepLooper h{&sim};
  sim.schedule(1.0, ExactFailure{}, 0, 0);
  EXPECT_EQ(sim.advance_to(2.0, h), AdvanceOutcome::EventBudget);
  EXPECT_EQ(h.processed, 2000u);
  EXPECT_EQ(sim.counters().events(), 2000u);
  EXPECT_EQ(sim.counters().events_external, 2000u);
  const GuardReport& rep = sim.guard_report();
  EXPECT_EQ(rep.events_total, 2000u);
  EXPECT_EQ(rep.events_at_instant, 1u);  // every event is at a new instant
  EXPECT_GT(rep.time, 1.0);
  EXPECT_LT(rep.time, 1.0 + 1e-12);
  EXPECT_EQ(rep.time, sim.now());
}

TEST(SimulatorGuard, PerInstantCountRestartsWhenTimeAdvancesOrOnExternalChange) {
  // 4 events at each of the times 1, 2, 3 with a limit of 4 per instant: no trip.
  Simulator sim(0.0);
  sim.set_guard(guard_of(4));
  Recorder r{&sim, {}, {}};
  for (int t = 1; t <= 3; ++t)
    for (std::uint32_t i = 0; i < 4; ++i) sim.schedule(t, ExactFailure{}, 0, i);
  EXPECT_EQ(sim.run_until_empty(r), AdvanceOutcome::Reached);
  EXPECT_EQ(r.seen.size(), 12u);
  // 4 more at the current instant (3.0) trip the guard unless an external change intervenes.
  for (std::uint32_t i = 0; i < 4; ++i) sim.schedule(3.0, ExactFailure{}, 0, i);
  sim.note_external_change();
  EXPECT_EQ(sim.run_until_empty(r), AdvanceOutcome::Reached);
  EXPECT_EQ(r.seen.size(), 16u);
  sim.schedule(3.0, ExactFailure{}, 0, 0);
  EXPECT_EQ(sim.run_until_empty(r), AdvanceOutcome::LoopGuard);
  EXPECT_EQ(r.seen.size(), 16u);
  EXPECT_EQ(sim.guard_report().events_total, 16u);
}

TEST(SimulatorGuard, DefaultGuardDoesNotTrip) {
  Simulator sim(0.0);
  struct Bounded {
    Simulator* sim;
    int left;
    EventKind process(const Event& e) {
      if (left-- > 0) sim->schedule(e.time, ExactFailure{}, 0, 0);
      return EventKind::Internal;
    }
  } h{&sim, 10000};
  sim.schedule(0.5, ExactFailure{}, 0, 0);
  EXPECT_EQ(sim.run_until_empty(h), AdvanceOutcome::Reached);
  EXPECT_EQ(sim.counters().events(), 10001u);
  EXPECT_EQ(sim.now(), 0.5);
}

}  // namespace
}  // namespace kinetic
