// The event queue against a model (an ordered set keyed by (time, sequence)): RapidCheck with a
// fixed seed, and a long deterministic random run; stale handles, ties, max_size.

#include "kinetic/core/event_queue.hpp"
#include "support/rapidcheck.hpp"

#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

namespace kinetic {
namespace {

/// Times drawn from a small set, so that ties are frequent (including 0.0 == -0.0 and +inf).
constexpr double kTimes[] = {0.0,  -0.0, 0.5,    1.0,           1.0, 2.0,
                             -1.0, 3.0,  1e-300, kTimeInfinity, 1.0, 0.5};
constexpr std::size_t kTimeCount = sizeof(kTimes) / sizeof(kTimes[0]);

/// A model of the queue: live events keyed by (time, sequence), plus the handles that went stale.
class Model {
 public:
  struct Entry {
    EventHandle handle;
    Event event;
  };

  explicit Model(EventQueue& q) : q_(q) {}

  void push(Time t, std::uint32_t owner, std::uint32_t payload) {
    const EventHandle h = q_.push(t, owner, payload);
    const std::uint64_t id = next_id_++;
    entries_[id] = Entry{h, Event{t, next_seq_++, owner, payload}};
    order_.emplace(t, entries_[id].event.sequence, id);
    ids_.push_back(id);
    max_size_ = std::max(max_size_, entries_.size());
  }

  void remove(std::size_t pick) {
    if (ids_.empty()) return;
    const std::uint64_t id = take(pick);
    const Entry e = entries_[id];
    q_.remove(e.handle);
    forget(id, e);
  }

  void update(std::size_t pick, Time t) {
    if (ids_.empty()) return;
    const std::uint64_t id = ids_[pick % ids_.size()];
    Entry& e = entries_[id];
    q_.update(e.handle, t);
    order_.erase({e.event.time, e.event.sequence, id});
    e.event.time = t;
    e.event.sequence = next_seq_++;
    order_.emplace(t, e.event.sequence, id);
  }

  /// Pops and returns an error message when the popped event is not the model's minimum.
  std::string pop() {
    if (order_.empty()) return "";
    const auto [t, seq, id] = *order_.begin();
    const Entry e = entries_[id];
    const Event got = q_.pop();
    std::string err;
    if (!same(got, e.event)) err = "pop: got " + show(got) + " expected " + show(e.event);
    ids_.erase(std::find(ids_.begin(), ids_.end(), id));
    forget(id, e);
    return err;
  }

  void clear() {
    q_.clear();
    for (const auto& [id, e] : entries_) stale_.push_back(e.handle);
    entries_.clear();
    order_.clear();
    ids_.clear();
  }

  /// Compares everything observable; "" when the queue agrees with the model.
  std::string check(bool all_stale, std::mt19937_64* rng = nullptr) const {
    if (!q_.validate()) return "validate() false";
    if (q_.size() != entries_.size())
      return "size " + std::to_string(q_.size()) + " != " + std::to_string(entries_.size());
    if (q_.empty() != entries_.empty()) return "empty() mismatch";
    if (q_.max_size() != max_size_)
      return "max_size " + std::to_string(q_.max_size()) + " != " + std::to_string(max_size_);
    if (!order_.empty()) {
      const Entry& m = entries_.at(std::get<2>(*order_.begin()));
      if (!same(q_.top(), m.event)) return "top " + show(q_.top()) + " expected " + show(m.event);
    }
    for (const auto& [id, e] : entries_) {
      if (e.handle.is_null()) return "null handle";
      if (!q_.contains(e.handle)) return "live handle not contained: " + show(e.event);
      if (!same(q_.get(e.handle), e.event))
        return "get " + show(q_.get(e.handle)) + " expected " + show(e.event);
    }
    if (all_stale || rng == nullptr) {
      for (const EventHandle& h : stale_)
        if (q_.contains(h)) return "stale handle contained (slot " + std::to_string(h.slot) + ")";
    } else if (!stale_.empty()) {
      for (int i = 0; i < 16; ++i) {
        const EventHandle& h = stale_[(*rng)() % stale_.size()];
        if (q_.contains(h)) return "stale handle contained (slot " + std::to_string(h.slot) + ")";
      }
    }
    if (q_.contains(EventHandle{})) return "null handle contained";
    return "";
  }

  std::size_t size() const { return entries_.size(); }
  std::size_t stale_count() const { return stale_.size(); }

 private:
  static bool same(const Event& a, const Event& b) {
    return a.time == b.time && a.sequence == b.sequence && a.owner == b.owner &&
           a.payload == b.payload;
  }
  static std::string show(const Event& e) {
    std::ostringstream os;
    os << "{t=" << e.time << " seq=" << e.sequence << " owner=" << e.owner
       << " payload=" << e.payload << "}";
    return os.str();
  }
  std::uint64_t take(std::size_t pick) {
    const std::size_t i = pick % ids_.size();
    const std::uint64_t id = ids_[i];
    ids_[i] = ids_.back();
    ids_.pop_back();
    return id;
  }
  void forget(std::uint64_t id, const Entry& e) {
    order_.erase({e.event.time, e.event.sequence, id});
    entries_.erase(id);
    stale_.push_back(e.handle);
  }

  EventQueue& q_;
  std::map<std::uint64_t, Entry> entries_;
  std::set<std::tuple<Time, std::uint64_t, std::uint64_t>> order_;
  std::vector<std::uint64_t> ids_;
  std::vector<EventHandle> stale_;
  std::uint64_t next_id_ = 0;
  std::uint64_t next_seq_ = 0;
  std::size_t max_size_ = 0;
};

/// Applies one encoded operation. Returns an error message or "".
std::string apply(Model& m, std::uint8_t kind, std::uint8_t time_pick, std::uint16_t pick) {
  const Time t = kTimes[time_pick % kTimeCount];
  switch (kind % 20) {
    case 0:
    case 1:
    case 2:
    case 3:
    case 4:
    case 5:
    case 6:
    case 7:
      m.push(t, pick % 7, pick);
      return "";
    case 8:
    case 9:
    case 10:
      m.remove(pick);
      return "";
    case 11:
    case 12:
    case 13:
      m.update(pick, t);
      return "";
    case 14:
    case 15:
    case 16:
    case 17:
    case 18:
      return m.pop();
    default:
      if (pick % 4 == 0) m.clear();
      return "";
  }
}

/// Applies an operation of a kind below `kinds`, its time and pick drawn from rng.
std::string apply_random(Model& m, std::mt19937_64& rng, std::uint64_t kinds) {
  return apply(m, static_cast<std::uint8_t>(rng() % kinds), static_cast<std::uint8_t>(rng()),
               static_cast<std::uint16_t>(rng()));
}

/// A model run from a seed: the seed, the generator it seeds, a queue and its model.
struct SeededRun {
  explicit SeededRun(std::uint64_t s) : seed(s), rng(s), m(q) {}
  std::uint64_t seed;
  std::mt19937_64 rng;
  EventQueue q;
  Model m;
};

using Ops = std::vector<std::tuple<std::uint8_t, std::uint8_t, std::uint16_t>>;

// ---------------------------------------------------------------------------------------------

TEST(EventQueueModel, RapidCheckAgainstAModel) {
  test::check_with_seed("EventQueueModel", 0xC0FFEEull, 300, 200, [](const Ops& ops) {
    EventQueue q;
    Model m(q);
    RC_ASSERT(q.empty());
    RC_ASSERT(q.validate());
    for (const auto& [kind, time_pick, pick] : ops) {
      const std::string err = apply(m, kind, time_pick, pick);
      if (!err.empty()) RC_FAIL(err);
      const std::string chk = m.check(true);
      if (!chk.empty()) RC_FAIL(chk);
    }
    // Drain: the rest pops in (time, sequence) order.
    while (m.size() > 0) {
      const std::string err = m.pop();
      if (!err.empty()) RC_FAIL(err);
    }
    RC_ASSERT(q.empty());
    const std::string chk = m.check(true);
    if (!chk.empty()) RC_FAIL(chk);
  });
}

TEST(EventQueueModel, LongDeterministicRun) {
  SeededRun run(0xABCDEF12ull);
  auto& [seed, rng, q, m] = run;
  for (int step = 0; step < 20000; ++step) {
    // Drift between growing and shrinking phases so that the heap gets deep and slots get reused.
    const bool grow = (step / 2500) % 2 == 0;
    std::uint8_t kind = static_cast<std::uint8_t>(rng() % 20);
    if (grow && kind >= 8 && kind < 19 && rng() % 2) kind = static_cast<std::uint8_t>(rng() % 8);
    if (!grow && kind < 8 && rng() % 2) kind = static_cast<std::uint8_t>(14 + rng() % 5);
    if (kind == 19 && rng() % 50 != 0) kind = 0;  // clear rarely
    const std::string err =
        apply(m, kind, static_cast<std::uint8_t>(rng()), static_cast<std::uint16_t>(rng()));
    ASSERT_EQ(err, "") << "seed=" << seed << " step=" << step;
    const std::string chk = m.check(false, &rng);
    ASSERT_EQ(chk, "") << "seed=" << seed << " step=" << step;
  }
  ASSERT_EQ(m.check(true), "") << "seed=" << seed;
  EXPECT_GT(q.max_size(), 500u);
  EXPECT_GT(m.stale_count(), 5000u);
}

/// The queue keeps a heap of its earliest events, a calendar of buckets and a far tier; the
/// calendar is laid out from the earliest quarter (or 1024) of the far tier when it runs empty.
/// At tens of thousands of events with times from a small set (ties everywhere, infinities, one
/// bucket when every time is equal), pops, removes and updates keep the model's order;
/// validate() checks every tier's bounds.
TEST(EventQueueModel, TiersAtScaleWithFewDistinctTimes) {
  SeededRun run(0x7135ull);
  auto& [seed, rng, q, m] = run;
  for (int i = 0; i < 30000; ++i) {
    ASSERT_EQ(apply_random(m, rng, 8), "");
  }
  for (int step = 0; step < 40000; ++step) {
    const std::string err = apply_random(m, rng, 19);
    ASSERT_EQ(err, "") << "seed=" << seed << " step=" << step;
    if (step % 4000 == 0) {
      ASSERT_EQ(m.check(false, &rng), "") << "seed=" << seed;
    }
  }
  ASSERT_EQ(m.check(true), "") << "seed=" << seed;
  EXPECT_GT(q.size(), 10000u);
  while (m.size() > 0) ASSERT_EQ(m.pop(), "") << "seed=" << seed;
}

/// The tiers at work as a kinetic structure uses them: the clock moves with the pops, and every
/// pop reschedules events near now, far ahead, at now itself (ties), in the past (the robust
/// scheduler's events in the past), at +infinity or -infinity (through spills and calendars
/// too), or to the same bucket. The first calendar is
/// laid out from the first event pushed, so the initial pushes fall into the heap until it
/// spills; the heap stays within max(4096, size / 4) + 1 throughout (without spilling it holds
/// thousands), and every pop agrees with the model.
TEST(EventQueueModel, LadderWithKineticTimes) {
  SeededRun run(0x1add3full);
  auto& [seed, rng, q, m] = run;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double now = 0.0;
  const auto draw = [&](std::uint64_t kind) {
    switch (kind % 10) {
      case 0:
        return now;  // a tie with the clock
      case 1:
        return now - 1e-3 * unit(rng);  // in the past
      case 2:
        return now + 1e3 * unit(rng);  // far ahead
      case 3:
        return kind % 20 == 3 ? kTimeInfinity : -kTimeInfinity;
      default:
        return now + unit(rng) * unit(rng);  // near now, denser close to it
    }
  };
  for (int i = 0; i < 20000; ++i) m.push(draw(rng()), 1, static_cast<std::uint32_t>(i));
  std::size_t largest_heap = 0;
  for (int step = 0; step < 120000; ++step) {
    const std::uint64_t r = rng();
    const std::uint64_t op = r % 16;
    std::string err;
    if (op < 5) {
      if (!q.empty() && q.top().time != kTimeInfinity) now = std::max(now, q.top().time);
      err = m.pop();
    } else if (op < 9) {
      m.update(static_cast<std::size_t>(r >> 8), draw(r >> 40));
    } else if (op < 10) {
      m.remove(static_cast<std::size_t>(r >> 8));
    } else {
      m.push(draw(r >> 8), 1, static_cast<std::uint32_t>(step));
    }
    ASSERT_EQ(err, "") << "seed=" << seed << " step=" << step;
    largest_heap = std::max(largest_heap, q.heap_size());
    ASSERT_LE(q.heap_size(), std::max<std::size_t>(4096, q.size() / 4) + 1)
        << "seed=" << seed << " step=" << step;
    if (step % 5000 == 0) {
      ASSERT_EQ(m.check(false, &rng), "") << "seed=" << seed << " step=" << step;
    }
  }
  ASSERT_EQ(m.check(true), "") << "seed=" << seed;
  EXPECT_GT(q.size(), 10000u);
  EXPECT_GT(largest_heap, 1000u);  // (the first calendar's heap grew until it spilled)
  while (m.size() > 0) ASSERT_EQ(m.pop(), "") << "seed=" << seed;
  EXPECT_TRUE(q.validate());
}

/// Simultaneous events are the normal case: 20,000 events at one time fill one bucket, whatever
/// the calendar, so the heap holds them all. It spills only after doubling since it was filled
/// (a handful of spills), not at every insert (which made every push O(n): about 20,000 spills
/// here), and ties still pop in scheduling order.
TEST(EventQueueModel, ManyEqualTimesSpillRarely) {
  SeededRun run(0xe9a1ull);
  auto& [seed, rng, q, m] = run;
  for (std::uint32_t i = 0; i < 20000; ++i) m.push(1.0, 0, i);
  for (int step = 0; step < 20000; ++step) {
    ASSERT_EQ(m.pop(), "") << "seed=" << seed << " step=" << step;
    m.push(1.0, 0, static_cast<std::uint32_t>(step));
    if (rng() % 4 == 0) m.update(static_cast<std::size_t>(rng()), 1.0);
  }
  ASSERT_EQ(m.check(false, &rng), "") << "seed=" << seed;
  EXPECT_EQ(q.heap_size(), q.size());
  EXPECT_LE(q.spills(), 8u);
  while (m.size() > 0) ASSERT_EQ(m.pop(), "") << "seed=" << seed;
}

/// The order keys are 32 bits, renumbered when they run out: renumbering at any moment keeps
/// every event's place (the model's (time, sequence) order), ties and updates included.
TEST(EventQueueModel, RenumberingKeepsTheOrder) {
  SeededRun run(0x5EEDull);
  auto& [seed, rng, q, m] = run;
  for (int step = 0; step < 6000; ++step) {
    const std::string err = apply_random(m, rng, 19);
    ASSERT_EQ(err, "") << "seed=" << seed << " step=" << step;
    if (step % 37 == 0) q.renumber();
    ASSERT_EQ(m.check(false, &rng), "") << "seed=" << seed << " step=" << step;
  }
  while (m.size() > 0) ASSERT_EQ(m.pop(), "") << "seed=" << seed;
}

/// The calendar's limit is a quantile of a strided sample of the far tier. When the sample holds
/// only the earliest times (here every 8th entry, the sample's stride, is early), the limit
/// would move 257 events instead of about 2048; an exact selection of the rest then fills the
/// calendar to the share it should hold, and the order is kept.
TEST(EventQueue, AnUnluckySampleStillFillsTheCalendar) {
  EventQueue q;
  q.push(0.0, 0, 0);  // the first calendar: this event alone; the next pushes wait in order
  const std::uint32_t m = 8192;
  for (std::uint32_t i = 0; i < m; ++i) q.push(i % 8 == 0 ? 1.0 + 1e-6 * i : 1000.0 + i, 0, i + 1);
  EXPECT_EQ(q.pop().payload, 0u);  // the heap runs empty: a calendar laid out from the 8192
  EXPECT_TRUE(q.validate());
  EXPECT_GE(q.heap_size() + q.calendar_size(), 2048u);
  double last = 0.0;
  while (!q.empty()) {
    const Event e = q.pop();
    ASSERT_GE(e.time, last);
    last = e.time;
  }
  EXPECT_TRUE(q.validate());
}

/// update() with a payload moves the event and changes what it carries.
TEST(EventQueue, UpdateWithAPayload) {
  EventQueue q;
  const EventHandle a = q.push(1.0, 3, 10);
  q.push(2.0, 3, 11);
  q.update(a, 3.0, 12);
  EXPECT_TRUE(q.validate());
  EXPECT_EQ(q.pop().payload, 11u);
  const Event e = q.pop();
  EXPECT_EQ(e.payload, 12u);
  EXPECT_EQ(e.owner, 3u);
  EXPECT_EQ(e.time, 3.0);
}

TEST(EventQueue, EqualTimesPopInPushOrder) {
  EventQueue q;
  for (std::uint32_t i = 0; i < 100; ++i) q.push(i % 3 == 0 ? 2.0 : 1.0, 0, i);
  std::vector<std::uint32_t> ones, twos;
  for (std::uint32_t i = 0; i < 100; ++i) (i % 3 == 0 ? twos : ones).push_back(i);
  std::vector<std::uint32_t> got;
  std::uint64_t last_seq = 0;
  while (!q.empty()) {
    const Event e = q.pop();
    if (!got.empty() && e.time == 1.0) {
      EXPECT_GT(e.sequence, last_seq);
    }
    last_seq = e.sequence;
    got.push_back(e.payload);
    EXPECT_TRUE(q.validate());
  }
  std::vector<std::uint32_t> expected = ones;
  expected.insert(expected.end(), twos.begin(), twos.end());
  EXPECT_EQ(got, expected);
}

TEST(EventQueue, UpdateToTheSameTimeMovesBehindTies) {
  EventQueue q;
  const EventHandle a = q.push(1.0, 0, 0);
  q.push(1.0, 0, 1);
  q.push(1.0, 0, 2);
  q.update(a, 1.0);  // new sequence number: now last among the ties
  EXPECT_TRUE(q.contains(a));
  EXPECT_EQ(q.pop().payload, 1u);
  EXPECT_EQ(q.pop().payload, 2u);
  EXPECT_EQ(q.pop().payload, 0u);
  EXPECT_FALSE(q.contains(a));
}

TEST(EventQueue, StaleHandlesAfterPopRemoveAndSlotReuse) {
  EventQueue q;
  const EventHandle h1 = q.push(1.0, 1, 10);
  EXPECT_TRUE(q.contains(h1));
  EXPECT_FALSE(h1.is_null());
  EXPECT_EQ(q.get(h1).payload, 10u);
  EXPECT_EQ(q.pop().payload, 10u);
  EXPECT_FALSE(q.contains(h1));
  // The slot is reused by the next push, under a new generation.
  const EventHandle h2 = q.push(2.0, 2, 20);
  EXPECT_EQ(h2.slot, h1.slot);
  EXPECT_NE(h2.generation, h1.generation);
  EXPECT_NE(h1, h2);
  EXPECT_FALSE(q.contains(h1));
  EXPECT_TRUE(q.contains(h2));
  q.remove(h2);
  EXPECT_FALSE(q.contains(h2));
  EXPECT_FALSE(q.contains(h1));
  EXPECT_TRUE(q.empty());
  const EventHandle h3 = q.push(3.0, 3, 30);
  EXPECT_EQ(h3.slot, h1.slot);
  EXPECT_FALSE(q.contains(h1));
  EXPECT_FALSE(q.contains(h2));
  EXPECT_TRUE(q.contains(h3));
  // Null and out-of-range handles.
  EXPECT_TRUE(EventHandle{}.is_null());
  EXPECT_FALSE(q.contains(EventHandle{}));
  EXPECT_FALSE(q.contains(EventHandle{12345, 0}));
  // clear() makes every handle stale.
  const EventHandle h4 = q.push(4.0, 4, 40);
  q.clear();
  EXPECT_TRUE(q.empty());
  EXPECT_FALSE(q.contains(h3));
  EXPECT_FALSE(q.contains(h4));
  EXPECT_TRUE(q.validate());
  const EventHandle h5 = q.push(5.0, 5, 50);
  EXPECT_TRUE(q.contains(h5));
  EXPECT_FALSE(q.contains(h3));
  EXPECT_FALSE(q.contains(h4));
  EXPECT_EQ(q.top().payload, 50u);
}

TEST(EventQueue, RemoveAndUpdateKeepTheHeapOrdered) {
  EventQueue q;
  std::vector<EventHandle> hs;
  for (std::uint32_t i = 0; i < 64; ++i)
    hs.push_back(q.push(static_cast<double>((i * 37) % 64), 0, i));
  // Remove the minimum, a middle and the last-pushed element; move one to the front, one back.
  q.remove(hs[0]);  // time 0
  q.remove(hs[63]);
  q.remove(hs[20]);
  EXPECT_TRUE(q.validate());
  q.update(hs[5], -1.0);
  q.update(hs[7], 100.0);
  EXPECT_TRUE(q.validate());
  EXPECT_EQ(q.top().payload, 5u);
  double last = -kTimeInfinity;
  std::size_t n = 0;
  while (!q.empty()) {
    const Event e = q.pop();
    EXPECT_GE(e.time, last);
    last = e.time;
    ++n;
    EXPECT_TRUE(q.validate());
  }
  EXPECT_EQ(last, 100.0);
  EXPECT_EQ(n, 61u);
}

TEST(EventQueue, MaxSizeIsTheLargestSizeEver) {
  EventQueue q;
  EXPECT_EQ(q.max_size(), 0u);
  std::vector<EventHandle> hs;
  for (int i = 0; i < 5; ++i) hs.push_back(q.push(i, 0, 0));
  EXPECT_EQ(q.max_size(), 5u);
  q.pop();
  q.pop();
  q.remove(hs[4]);
  EXPECT_EQ(q.size(), 2u);
  EXPECT_EQ(q.max_size(), 5u);
  q.push(0.0, 0, 0);
  q.push(0.0, 0, 0);
  q.push(0.0, 0, 0);
  EXPECT_EQ(q.max_size(), 5u);
  q.push(0.0, 0, 0);
  EXPECT_EQ(q.size(), 6u);
  EXPECT_EQ(q.max_size(), 6u);
  q.clear();
  EXPECT_EQ(q.size(), 0u);
  EXPECT_EQ(q.max_size(), 6u);
}

}  // namespace
}  // namespace kinetic
