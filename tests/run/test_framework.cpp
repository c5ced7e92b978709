// The framework a structure plugs into: owner ranges, StructureGroup, the TimelineDriver's
// change protocol and play() order, and the registry (names, counters, dimension checks).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "kinetic/core/structure.hpp"
#include "kinetic/core/structure_group.hpp"
#include "kinetic/run/runner.hpp"
#include "kinetic/run/timeline_driver.hpp"
#include "kinetic/scenario/generators.hpp"
#include "kinetic/sort/kinetic_sort.hpp"
#include "support/driver.hpp"

namespace kinetic {
namespace {

/// snake_case: lower-case words of letters and digits joined by single underscores.
bool is_snake_case(const std::string& name) {
  if (name.empty() || !(name.front() >= 'a' && name.front() <= 'z') || name.back() == '_')
    return false;
  for (std::size_t i = 0; i < name.size(); ++i) {
    const char c = name[i];
    const bool word = (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9');
    if (!word && !(c == '_' && name[i - 1] != '_')) return false;
  }
  return true;
}

scenario::Motion linear(double x0, double v) { return {{{x0, v}}, 0.0}; }

/// Four points on a line crossing each other, and a timeline with a change or a query at
/// t = 1, 2, 3.
scenario::Scenario small_scenario() {
  scenario::Scenario s;
  s.dimension = 1;
  s.start_time = 0.0;
  s.end_time = 4.0;
  s.objects = {{10, linear(0.0, 1.0)},
               {11, linear(1.0, -1.0)},
               {12, linear(2.0, 0.5)},
               {13, linear(3.0, -2.0)}};
  scenario::TimelineOp insert;
  insert.time = 1.0;
  insert.op = scenario::OpKind::Insert;
  insert.id = 14;
  insert.motion = linear(5.0, -1.0);
  scenario::TimelineOp query;
  query.time = 2.0;
  query.op = scenario::OpKind::Query;
  scenario::TimelineOp update;
  update.time = 2.0;
  update.op = scenario::OpKind::Update;
  update.id = 11;
  update.motion = {{{-1.0, 2.0}}, 2.0};
  scenario::TimelineOp remove;
  remove.time = 3.0;
  remove.op = scenario::OpKind::Remove;
  remove.id = 12;
  s.timeline = {insert, query, update, remove};
  for (std::size_t i = 0; i < s.timeline.size(); ++i) s.timeline[i].file_index = i;
  return s;
}

TEST(Framework, OwnerRangesAreConsecutiveAndDisjoint) {
  Simulator sim(0.0);
  const OwnerRange a = sim.reserve_owners(3);
  const OwnerRange b = sim.reserve_owners(1);
  const OwnerRange c = sim.reserve_owners(2);
  EXPECT_EQ(a.first, 0u);
  EXPECT_EQ(b.first, 3u);
  EXPECT_EQ(c.first, 4u);
  EXPECT_TRUE(a.contains(2));
  EXPECT_FALSE(a.contains(3));
  EXPECT_TRUE(b.contains(3));
  EXPECT_FALSE(c.contains(3));
  EXPECT_EQ(c[1], 5u);
}

TEST(Framework, StructureGroupRoutesEventsAndSumsCertificatesAndCounters) {
  scenario::GeneratorOptions o;
  o.n = 30;
  o.dimension = 2;
  o.seed = 5;
  const scenario::Scenario s = scenario::generate("random-linear", o);
  // The parts by hand: the contract between a group, its members and the simulator.
  test::Parts p(s);
  StructureGroup<KineticSort> group;
  group.add(std::make_unique<KineticSort>(p.motions, p.sim, p.scheduler, 0));
  group.add(std::make_unique<KineticSort>(p.motions, p.sim, p.scheduler, 1));
  EXPECT_EQ(group.owners().first, 0u);
  EXPECT_EQ(group.owners().count, 2u);
  group.initialize();
  EXPECT_EQ(group.certificates(), 2u * 29u);
  EXPECT_EQ(group.certificates_per_object_max(), 4u);
  ASSERT_EQ(p.sim.advance_to(*s.end_time, group), AdvanceOutcome::Reached);
  EXPECT_TRUE(group.validate());
  const std::uint64_t swaps = group[0].counters().swaps + group[1].counters().swaps;
  EXPECT_GT(group[0].counters().swaps, 0u);
  EXPECT_GT(group[1].counters().swaps, 0u);
  EXPECT_EQ(swaps, p.sim.counters().events());
  const NamedCounters named = group.named_counters();
  const auto it = std::find_if(named.begin(), named.end(),
                               [](const NamedCounter& c) { return c.name == "swaps"; });
  ASSERT_NE(it, named.end());
  EXPECT_EQ(it->value, swaps);
}

TEST(Framework, StructureGroupRefusesAMemberWhoseOwnerDoesNotFollow) {
  const scenario::Scenario s = small_scenario();
  test::Parts p(s, SchedulerKind::Classic);
  StructureGroup<KineticSort> group;
  group.add(std::make_unique<KineticSort>(p.motions, p.sim, p.scheduler, 0));
  (void)p.sim.reserve_owners(1);  // someone else reserves an owner in between
  EXPECT_THROW(group.add(std::make_unique<KineticSort>(p.motions, p.sim, p.scheduler, 0)),
               std::logic_error);
}

/// A structure that records what it is told and checks the table's state at each call.
struct Spy {
  const MotionTable* motions = nullptr;
  std::vector<std::string> log;
  void initialize() { log.push_back("initialize"); }
  EventKind process(const Event&) { return EventKind::Internal; }
  void insert(std::uint32_t i) {
    // Inserted: the object is in the table already.
    log.push_back("insert " + std::to_string(motions->id(i)) +
                  (motions->alive_index(i) ? " in table" : " NOT in table"));
  }
  void remove(std::uint32_t i) {
    // Removed: the object has left the table already (its index is not reused yet).
    log.push_back("remove index " + std::to_string(i) +
                  (motions->alive_index(i) ? " in table" : " NOT in table"));
  }
  void motion_changed(std::uint32_t i) {
    // Updated: the table holds the new motion already.
    log.push_back("update " + std::to_string(motions->id(i)) + " origin " +
                  std::to_string(static_cast<int>(motions->motion(i, 0).origin)));
  }
  [[nodiscard]] bool initialized() const { return !log.empty(); }
  [[nodiscard]] bool validate() const { return true; }
  [[nodiscard]] std::uint64_t certificates() const { return 0; }
  [[nodiscard]] std::uint64_t certificates_per_object_max() const { return 0; }
  [[nodiscard]] NamedCounters named_counters() const { return {}; }
};
static_assert(KineticStructure<Spy>);

/// A session over a Spy that sees the session's table.
auto spying() {
  return build_with([](MotionTable& m, Simulator&, Scheduler&) {
    return std::make_unique<Spy>(Spy{&m, {}});
  });
}

TEST(Framework, TimelineDriverAppliesChangesInTheContractsOrder) {
  const scenario::Scenario s = small_scenario();
  run::TimelineDriver<Spy> d(s, SchedulerKind::Robust, 1e-9, spying());
  EXPECT_EQ(d.motions().size(), 4u);  // the objects loaded, the structure not told
  EXPECT_TRUE(d.session().structure_as_is().log.empty());
  const std::uint32_t index_of_12 = d.motions().find(12)->index;
  for (const scenario::TimelineOp& op : s.timeline) {
    ASSERT_EQ(d.advance_to(op.time), AdvanceOutcome::Reached);
    d.apply(op);
  }
  const std::vector<std::string> expected = {
      "initialize", "insert 14 in table", "update 11 origin 2",
      "remove index " + std::to_string(index_of_12) + " NOT in table"};
  EXPECT_EQ(d.structure().log, expected);
  EXPECT_FALSE(d.motions().find(12).has_value());
  EXPECT_EQ(d.motions().size(), 4u);
  // A change applied away from its time is refused: the session changes objects at now().
  EXPECT_THROW(d.apply(s.timeline[0]), std::logic_error);
}

/// One kinetic sort of axis 0, as the runner's group.
auto sort_group() {
  return build_with([](MotionTable& m, Simulator& sim, Scheduler& scheduler) {
    auto sorts = std::make_unique<StructureGroup<KineticSort>>();
    sorts->add(std::make_unique<KineticSort>(m, sim, scheduler, 0));
    return sorts;
  });
}

TEST(Framework, PlayProbesBeforeTheEntriesAtTheSameTimeAndRunsToTheEnd) {
  const scenario::Scenario s = small_scenario();
  run::TimelineDriver<StructureGroup<KineticSort>> d(s, SchedulerKind::Robust, 1e-9, sort_group());
  std::vector<std::string> log;
  struct Hooks {
    std::vector<std::string>& log;
    void probe(Time t) { log.push_back("probe " + std::to_string(t)); }
    void query(const scenario::TimelineOp& op) {
      log.push_back("query " + std::to_string(op.time));
    }
    void change(const scenario::TimelineOp& op) {
      log.push_back(std::string(scenario::to_string(op.op)) + " " + std::to_string(op.time));
    }
  };
  const std::vector<Time> probes = {0.5, 2.0, 3.5};
  const run::PlayResult r = d.play(Hooks{log}, probes);
  EXPECT_EQ(r.outcome, AdvanceOutcome::Reached);
  EXPECT_FALSE(r.stopped);
  const std::vector<std::string> expected = {"probe 0.500000", "insert 1.000000", "probe 2.000000",
                                             "query 2.000000", "update 2.000000", "remove 3.000000",
                                             "probe 3.500000"};
  EXPECT_EQ(log, expected);
  EXPECT_EQ(d.sim().now(), 4.0);
  EXPECT_EQ(r.events, d.sim().counters().events());
  EXPECT_GT(r.events, 0u);
  EXPECT_TRUE(d.structure().validate());
}

TEST(Framework, PlayStopsWhereAHookSaysSoAndSlicesItsAdvances) {
  const scenario::Scenario s = small_scenario();
  struct NoHooks {};
  std::uint64_t all_events = 0;
  {
    run::TimelineDriver<StructureGroup<KineticSort>> d(s, SchedulerKind::Robust, 1e-9,
                                                       sort_group());
    all_events = d.play(NoHooks{}).events;  // no hooks: plays to the end
    ASSERT_GE(all_events, 2u);
  }
  {  // An event hook that returns false after the first event stops the play there.
    run::TimelineDriver<StructureGroup<KineticSort>> d(s, SchedulerKind::Robust, 1e-9,
                                                       sort_group());
    struct StopAfterOne {
      int events = 0;
      bool event() { return ++events < 1; }
    } hooks;
    const run::PlayResult r = d.play(hooks);
    EXPECT_TRUE(r.stopped);
    EXPECT_EQ(r.outcome, AdvanceOutcome::Reached);
    EXPECT_EQ(r.events, 1u);
    EXPECT_EQ(hooks.events, 1);
  }
  {  // A change hook that returns false stops before the next entry.
    run::TimelineDriver<StructureGroup<KineticSort>> d(s, SchedulerKind::Robust, 1e-9,
                                                       sort_group());
    struct StopAtFirstChange {
      int changes = 0, queries = 0;
      bool change(const scenario::TimelineOp&) { return ++changes == 0; }
      void query(const scenario::TimelineOp&) { ++queries; }
    } hooks;
    const run::PlayResult r = d.play(hooks);
    EXPECT_TRUE(r.stopped);
    EXPECT_EQ(hooks.changes, 1);
    EXPECT_EQ(hooks.queries, 0);  // the query at 2 comes after the insert at 1
    EXPECT_EQ(d.sim().now(), 1.0);
  }
  {  // Slices: progress() after each of the 8 slices of each advance, the same events.
    run::TimelineDriver<StructureGroup<KineticSort>> d(s, SchedulerKind::Robust, 1e-9,
                                                       sort_group());
    struct Sliced {
      int calls = 0;
      int slices() const { return 8; }
      void progress() { ++calls; }
    } hooks;
    const run::PlayResult r = d.play(hooks);
    EXPECT_FALSE(r.stopped);
    EXPECT_EQ(r.events, all_events);
    // Four entries and the end: five advances of eight slices each.
    EXPECT_EQ(hooks.calls, 5 * 8);
    EXPECT_EQ(d.sim().now(), 4.0);
  }
  {  // The interrupt flag stops the play between entries, where no event is left to stop at:
     // objects at rest, queries only; the flag is raised by the first query.
    scenario::Scenario still;
    still.dimension = 1;
    still.end_time = 4.0;
    still.objects = {{1, linear(0.0, 0.0)}, {2, linear(1.0, 0.0)}};
    for (const Time t : {1.0, 2.0, 3.0}) {
      scenario::TimelineOp query;
      query.time = t;
      query.op = scenario::OpKind::Query;
      still.timeline.push_back(query);
    }
    run::TimelineDriver<StructureGroup<KineticSort>> d(still, SchedulerKind::Robust, 1e-9,
                                                       sort_group());
    std::atomic<bool> flag{false};
    d.sim().set_interrupt(&flag);
    struct RaiseAtFirstQuery {
      std::atomic<bool>& flag;
      int queries = 0;
      void query(const scenario::TimelineOp&) {
        ++queries;
        flag = true;
      }
    } hooks{flag};
    const run::PlayResult r = d.play(hooks);
    EXPECT_EQ(r.outcome, AdvanceOutcome::Interrupted);
    EXPECT_EQ(hooks.queries, 1);
    EXPECT_EQ(r.events, 0u);
    EXPECT_EQ(d.sim().now(), 2.0);
  }
  {  // advanced() after every advance that reached its time: three entries and the end.
    run::TimelineDriver<StructureGroup<KineticSort>> d(s, SchedulerKind::Robust, 1e-9,
                                                       sort_group());
    struct Advances {
      std::vector<Time> at;
      const Simulator* sim = nullptr;
      bool advanced() {
        at.push_back(sim->now());
        return at.size() < 3;  // stops after the third
      }
    } hooks;
    hooks.sim = &d.sim();
    const run::PlayResult r = d.play(hooks);
    EXPECT_TRUE(r.stopped);
    EXPECT_EQ(hooks.at, (std::vector<Time>{1.0, 2.0, 2.0}));
  }
}

TEST(Framework, SnakeCaseCheck) {
  EXPECT_TRUE(is_snake_case("node_visits"));
  EXPECT_TRUE(is_snake_case("swaps_axis_0"));
  EXPECT_FALSE(is_snake_case("nodeVisits"));
  EXPECT_FALSE(is_snake_case("node__visits"));
  EXPECT_FALSE(is_snake_case("_visits"));
  EXPECT_FALSE(is_snake_case("visits_"));
  EXPECT_FALSE(is_snake_case(""));
}

TEST(Framework, RegistryNamesAreDistinctAndEveryStructureRunsWithSnakeCaseCounters) {
  std::set<std::string> names;
  for (const run::StructureInfo& info : run::structures()) {
    EXPECT_TRUE(names.insert(info.name).second) << "duplicate structure " << info.name;
    EXPECT_FALSE(info.queries.empty()) << info.name;
    EXPECT_FALSE(info.description.empty()) << info.name;
    // Run it on a small scenario of its kind with no queries.
    scenario::Scenario s;
    if (info.objects == scenario::ObjectsAre::Intervals) {
      s.dimension = 2;
      s.objects_are = scenario::ObjectsAre::Intervals;
      s.start_time = 0.0;
      s.end_time = 5.0;
      for (int i = 0; i < 12; ++i) {
        const double a = static_cast<double>(i % 5), v = static_cast<double>(i % 3) - 1.0;
        s.objects.push_back({i, {{{a, v}, {a + 1.0 + i % 2, v}}, 0.0}});
      }
    } else {
      scenario::GeneratorOptions o;
      o.n = 40;
      o.seed = 3;
      o.dimension = std::max(2, info.min_dimension);
      s = scenario::generate(
          info.objects == scenario::ObjectsAre::Boxes ? "boxes-linear" : "random-linear", o);
    }
    run::RunOptions options;
    options.structure = info.name;
    options.validate_every_event = true;
    // A structure restricted to some schedulers runs under the first it takes.
    if (!info.schedulers.empty()) options.scheduler = info.schedulers.front();
    ASSERT_NO_THROW(run::check_runnable(s, options, "generated.json")) << info.name;
    std::ostringstream answers;
    const run::RunResult r = run::run(s, options, answers);
    EXPECT_EQ(r.outcome, run::RunOutcome::Completed) << info.name << ": " << r.message;
    EXPECT_GT(r.stats.counters.events(), 0u) << info.name;
    std::set<std::string> counter_names;
    EXPECT_FALSE(r.stats.structure_counters.empty()) << info.name;
    for (const NamedCounter& c : r.stats.structure_counters) {
      EXPECT_TRUE(is_snake_case(c.name)) << info.name << ": " << c.name;
      EXPECT_TRUE(counter_names.insert(c.name).second) << info.name << ": twice " << c.name;
    }
  }
  EXPECT_EQ(names.size(), 13u);
}

TEST(Framework, CheckRunnableNamesTheDimensionAStructureSupports) {
  scenario::GeneratorOptions o;
  o.n = 10;
  o.dimension = 3;
  const scenario::Scenario s = scenario::generate("random-linear", o);
  run::RunOptions options;
  options.structure = "longest-side-kdtree";
  try {
    run::check_runnable(s, options, "f.json");
    FAIL() << "a 3-D scenario was accepted by longest-side-kdtree";
  } catch (const run::UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("f.json: $.dimension: structure longest-side-kdtree "
                                         "supports dimension 2 only"),
              std::string::npos)
        << e.what();
  }
  o.dimension = 5;
  options.structure = "range-tree";
  try {
    run::check_runnable(scenario::generate("random-linear", o), options, "g.json");
    FAIL() << "a 5-D scenario was accepted by range-tree";
  } catch (const run::UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("supports dimensions up to 4, got 5"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace kinetic
