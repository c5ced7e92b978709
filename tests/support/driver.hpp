#pragma once
// Test support: a kinetic structure in the session a TimelineDriver builds from a scenario (the
// same driver the runner uses), with hooks for oracle checks between events. Header-only, tests
// only.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <memory>
#include <random>
#include <span>
#include <vector>

#include "kinetic/core/float_roots.hpp"
#include "kinetic/core/geometry.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/predicates.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/structure.hpp"
#include "kinetic/core/structure_group.hpp"
#include "kinetic/oracle/oracle.hpp"
#include "kinetic/run/timeline_driver.hpp"
#include "kinetic/scenario/generators.hpp"
#include "kinetic/scenario/scenario.hpp"
#include "kinetic/session/session.hpp"
#include "kinetic/sort/kinetic_sort.hpp"
#include "kinetic/tournament/kinetic_tournament.hpp"
#include "support/crossing.hpp"
#include "support/schedulers.hpp"

namespace kinetic::test {

inline std::vector<MotionPolynomial> polynomials(const scenario::Motion& m) {
  return run::to_polynomials(m);
}

/// A random closed box (per axis [lo, hi]) inside the points' bounding box at t: sometimes a
/// degenerate slab, sometimes everything, sometimes ending exactly on a point's coordinate.
inline Box random_box(const MotionTable& motions, Time t, std::mt19937_64& rng) {
  const int d = motions.dimension();
  Box box(static_cast<std::size_t>(d));
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto idx = motions.alive_indices();
  for (int a = 0; a < d; ++a) {
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (const std::uint32_t i : idx) {
      const double x = motions.motion(i, a).evaluate(t);
      lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
    if (!(lo <= hi)) lo = hi = 0.0;
    double x = lo + (hi - lo) * u(rng), y = lo + (hi - lo) * u(rng);
    if (x > y) std::swap(x, y);
    const int kind = static_cast<int>(rng() % 8);
    if (kind == 0) y = x;                       // a degenerate slab
    if (kind == 1) x = lo - 1.0, y = hi + 1.0;  // everything
    if (kind == 2 && !idx.empty()) {            // ends exactly on a point's coordinate
      x = motions.motion(idx[rng() % idx.size()], a).evaluate(t);
      y = std::max(x, y);
    }
    box[static_cast<std::size_t>(a)] = {x, y};
  }
  return box;
}

/// A generated scenario without queries, in dimension d; with `changes`, 5 flight-plan updates,
/// 5 inserts and 5 removes on its timeline.
inline scenario::Scenario generated(const std::string& dataset, std::size_t n, int d,
                                    std::uint64_t seed, int degree, bool changes) {
  scenario::GeneratorOptions o;
  o.n = n;
  o.dimension = d;
  o.seed = seed;
  o.degree = degree;
  o.queries = 0;
  if (changes) {
    o.updates = 5;
    o.inserts = 5;
    o.removes = 5;
  }
  return scenario::generate(dataset, o);
}

/// The generator's options for n objects from `seed` with `updates` flight-plan updates,
/// `inserts` and `removes` at random times of the run (the rest the defaults).
inline scenario::GeneratorOptions with_changes(std::uint64_t seed, std::size_t n,
                                               std::size_t updates, std::size_t inserts,
                                               std::size_t removes) {
  scenario::GeneratorOptions o;
  o.n = n;
  o.seed = seed;
  o.updates = updates;
  o.inserts = inserts;
  o.removes = removes;
  return o;
}

/// `count` times drawn uniformly from the scenario's window with rng (53 random bits each),
/// sorted.
inline std::vector<Time> random_times_in_window(const scenario::Scenario& s, std::mt19937_64& rng,
                                                int count) {
  const Time end = *s.end_time;
  std::vector<Time> times;
  for (int i = 0; i < count; ++i) {
    times.push_back(s.start_time +
                    (end - s.start_time) * static_cast<double>(rng() >> 11) * 0x1p-53);
  }
  std::sort(times.begin(), times.end());
  return times;
}

/// A long mixed sequence for the local inserts and removes of the trees: n objects at the start,
/// then `inserts`, `removes` and `updates` at random times of the run (the generator's), so that
/// the set grows or shrinks past the doublings and halvings of the gapped orders.
inline scenario::Scenario long_mixed(const std::string& dataset, std::size_t n, int d,
                                     std::uint64_t seed, std::size_t inserts, std::size_t removes,
                                     std::size_t updates) {
  scenario::GeneratorOptions o = with_changes(seed, n, updates, inserts, removes);
  o.dimension = d;
  o.queries = 0;
  return scenario::generate(dataset, o);
}

/// An upper bound on the speed of p over [a, b]: max(|p'(a)|, |p'(b)|) + (b - a) max|p''|.
inline double speed_bound(const MotionPolynomial& p, Time a, Time b) {
  double v = std::max(std::fabs(p.derivative(a)), std::fabs(p.derivative(b)));
  const double m = std::max(std::fabs(a - p.origin), std::fabs(b - p.origin));
  double second = 0.0, power = 1.0;
  for (int k = 2; k <= p.degree; ++k) {
    second += k * (k - 1) * std::fabs(p.c[k]) * power;
    power *= m;
  }
  return (v + (b - a) * second) * (1.0 + 1e-12);
}

/// n points of the plane on a small integer grid ([0, 4]^2) moving with integer velocities
/// ([-2, 2]^2) over [0, end]: equal coordinates at every integer time, simultaneous swaps on
/// both axes. Fixed seed.
inline scenario::Scenario integer_grid_2d(int n, std::uint64_t seed, Time end) {
  scenario::Scenario s;
  s.dimension = 2;
  s.start_time = 0.0;
  s.end_time = end;
  std::mt19937_64 rng(seed);
  for (int i = 0; i < n; ++i) {
    const double x = static_cast<double>(rng() % 5), y = static_cast<double>(rng() % 5);
    const double vx = static_cast<double>(static_cast<int>(rng() % 5) - 2);
    const double vy = static_cast<double>(static_cast<int>(rng() % 5) - 2);
    s.objects.push_back({i, {{{x, vx}, {y, vy}}, 0.0}});
  }
  return s;
}

/// `count` times drawn uniformly in [lo, hi) (sorted), plus `extra` times, all ascending.
inline std::vector<Time> probe_times(Time lo, Time hi, int count, std::mt19937_64& rng,
                                     std::span<const Time> extra = {}) {
  std::vector<Time> probes;
  for (int i = 0; i < count; ++i)
    probes.push_back(lo + (hi - lo) * std::generate_canonical<double, 53>(rng));
  probes.insert(probes.end(), extra.begin(), extra.end());
  std::sort(probes.begin(), probes.end());
  return probes;
}

/// The parts a session owns, by hand, for tests of the structure contract itself (a structure
/// checked between the table's change and its own, a structure group's owners): the scenario's
/// table, a simulator at its start, a scheduler up to its end.
struct Parts {
  explicit Parts(const scenario::Scenario& s, SchedulerKind kind = SchedulerKind::Robust,
                 double eps = 1e-9)
      : motions(run::table_of(s)),
        sim(s.start_time),
        scheduler(kind, eps, s.end_time.value_or(kTimeInfinity)) {}
  /// Advances the structure to t, one event at a time with validate() after each.
  template <KineticStructure S>
  ::testing::AssertionResult advance_validating(Time t, S& structure) {
    while (sim.event_due_by(t)) {
      if (sim.process_next(structure) != AdvanceOutcome::Reached)
        return ::testing::AssertionFailure() << "an event at t=" << sim.now() << " failed";
      if (!structure.validate())
        return ::testing::AssertionFailure() << "validate() after an event at t=" << sim.now();
    }
    if (sim.advance_to(t, structure) != AdvanceOutcome::Reached)
      return ::testing::AssertionFailure() << "the advance to " << t << " failed";
    return ::testing::AssertionSuccess();
  }
  MotionTable motions;
  Simulator sim;
  Scheduler scheduler;
};

/// A kinetic structure in the session a TimelineDriver builds from a scenario (as the runner's);
/// it follows the timeline's inserts, removes and updates through the session. `motions`, `sim`
/// and `scheduler` name the session's; `structure` is built (initialized) at construction.
template <KineticStructure S>
struct Harness {
  using Make = std::function<std::unique_ptr<S>(MotionTable&, Simulator&, Scheduler&)>;
  Harness(const scenario::Scenario& s, SchedulerChoice choice, double eps, const Make& make)
      : driver(s, choice.kind, eps, build_with([&](MotionTable& m, Simulator& sm, Scheduler& sc) {
                 return make(m, sm, choice.configure(sc));
               })),
        scenario(s),
        motions(driver.motions()),
        sim(driver.sim()),
        scheduler(driver.scheduler()),
        structure(&driver.structure()) {}
  Harness(const Harness&) = delete;
  Harness& operator=(const Harness&) = delete;
  EventKind process(const Event& e) { return structure->process(e); }
  void apply(const scenario::TimelineOp& op) { driver.apply(op); }
  [[nodiscard]] Session<S>& session() { return driver.session(); }

  /// Advances to t; with `validate`, one event at a time with validate() after each.
  AdvanceOutcome advance_to(Time t, bool validate = false) {
    if (!validate) return driver.advance_to(t);
    return driver.advance_to(
        t, [&] { EXPECT_TRUE(structure->validate()) << "after an event at t=" << sim.now(); });
  }

  /// The generic oracle check: plays the whole scenario through the driver, calls probe(t) at
  /// every time of `probes` and at every timeline entry's time (before the entry), validate()
  /// after every event when `validate_each` and after every change and at the end. Returns the
  /// events processed.
  /// `after_event`, when given, runs after every event too (theorems checked between events).
  std::uint64_t check(std::span<const Time> probes, bool validate_each,
                      const std::function<void(Time)>& probe,
                      const std::function<void()>& after_event = {}) {
    std::vector<Time> all(probes.begin(), probes.end());
    for (const auto& op : scenario.timeline) all.push_back(op.time);
    std::sort(all.begin(), all.end());
    struct Plain {
      std::function<void(Time)> at;
      std::function<void(const scenario::TimelineOp&)> changed;
      void probe(Time t) { at(t); }
      void change(const scenario::TimelineOp& op) { changed(op); }
    };
    struct EachEvent : Plain {
      std::function<void()> after_event;
      void event() { after_event(); }
    };
    std::size_t probed = 0;
    auto counted_probe = [&](Time t) {
      ++probed;
      probe(t);
    };
    Plain plain{counted_probe, [this](const scenario::TimelineOp& op) {
                  EXPECT_TRUE(structure->validate()) << "after timeline entry " << op.file_index;
                }};
    auto each_event = [&] {
      if (validate_each) {
        EXPECT_TRUE(structure->validate()) << "after an event at t=" << sim.now();
      }
      if (after_event) after_event();
    };
    const run::PlayResult r = validate_each || after_event
                                  ? driver.play(EachEvent{plain, each_event}, all)
                                  : driver.play(plain, all);
    EXPECT_EQ(r.outcome, AdvanceOutcome::Reached);
    EXPECT_EQ(probed, all.size()) << "every probe time must be checked";
    EXPECT_TRUE(structure->validate());
    return r.events;
  }

  run::TimelineDriver<S> driver;
  const scenario::Scenario& scenario;
  const MotionTable& motions;
  Simulator& sim;
  Scheduler& scheduler;
  S* structure;
};

/// One kinetic structure built like KineticKdTree (motions, simulator, scheduler), as `tree`.
template <class Tree>
struct TreeHarness : Harness<Tree> {
  TreeHarness(const scenario::Scenario& s, SchedulerChoice kind, double eps)
      : Harness<Tree>(s, kind, eps, [](MotionTable& m, Simulator& sm, Scheduler& sc) {
          return std::make_unique<Tree>(m, sm, sc);
        }) {}
  Tree* tree = this->structure;
};

/// One kinetic sort per axis (a StructureGroup, as the runner's `sort`), as `sorts`.
struct SortHarness : Harness<StructureGroup<KineticSort>> {
  explicit SortHarness(const scenario::Scenario& s, SchedulerChoice kind = SchedulerKind::Classic,
                       double eps = 1e-9, SortLayout layout = SortLayout::Dense)
      : Harness(s, kind, eps, [layout](MotionTable& m, Simulator& sm, Scheduler& sc) {
          auto group = std::make_unique<StructureGroup<KineticSort>>();
          for (int axis = 0; axis < m.dimension(); ++axis)
            group->add(std::make_unique<KineticSort>(m, sm, sc, axis, layout));
          return group;
        }) {}

  void apply(const scenario::TimelineOp& op) {
    Harness::apply(op);
    if (op.op == scenario::OpKind::Insert || op.op == scenario::OpKind::Update) {
      last_change = op.time;
    }
  }

  /// Every adjacent pair that is out of order at t must cross within [t - delta, t + delta]
  /// (a time away from every crossing therefore has the exact sorted order).
  ::testing::AssertionResult order_ok_at(Time t, double delta) const {
    for (const KineticSort& k : sorts.members()) {
      std::vector<std::uint32_t> order;  // the keys in order (the gapped layout's empty slots out)
      for (const std::uint32_t x : k.order()) {
        if (x != kNoIndex) order.push_back(x);
      }
      if (order.size() != motions.size()) return ::testing::AssertionFailure() << "size mismatch";
      for (std::size_t j = 0; j + 1 < order.size(); ++j) {
        const auto& a = motions.motion(order[j], k.axis());
        const auto& b = motions.motion(order[j + 1], k.axis());
        if (compare_at(a, b, t) <= 0) continue;
        if (cross_within(a, b, t - delta, t + delta)) continue;
        return ::testing::AssertionFailure()
               << "axis " << k.axis() << ": ids " << motions.id(order[j]) << " > "
               << motions.id(order[j + 1]) << " at position " << j << ", t=" << t
               << " and they do not cross within " << delta;
      }
    }
    return ::testing::AssertionSuccess();
  }

  StructureGroup<KineticSort>& sorts = *structure;
  Time last_change = kTimeMinusInfinity;
};

/// The oracle check of a structure over points answering closed boxes (the kd-tree, the range
/// tree): plays the scenario, validate() after each event (when `validate_each`), 6 random boxes
/// at each of 30 random times plus the timeline's times, `range(tree, box, t)` against brute
/// force; at the end `finally(tree, events)` (the structure's own counters). At least 21
/// events are required: the run must move.
template <class Tree, class Range, class Finally>
void check_box_range_run(const scenario::Scenario& s, SchedulerKind kind, std::uint64_t seed,
                         bool validate_each, Range&& range, Finally&& finally) {
  SCOPED_TRACE("seed " + std::to_string(seed) + ", " + to_string(kind) + ", d " +
               std::to_string(s.dimension));
  TreeHarness<Tree> h(s, kind, 1e-9);
  EXPECT_TRUE(h.tree->validate());
  std::mt19937_64 rng(seed);
  const std::vector<Time> probes = probe_times(s.start_time, *s.end_time, 30, rng);
  const std::uint64_t events = h.check(probes, validate_each, [&](Time t) {
    for (int q = 0; q < 6; ++q) {
      const Box box = random_box(h.motions, t, rng);
      EXPECT_EQ(range(*h.tree, box, t), oracle::in_box_at(h.motions, box, t)) << "t=" << t;
    }
  });
  EXPECT_EQ(h.tree->counters().swaps, events);
  EXPECT_GT(events, 20u);
  finally(*h.tree, events);
}

}  // namespace kinetic::test
