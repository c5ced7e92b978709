#pragma once
// The structure registry (private to the run layer): one descriptor per structure -- its name,
// description, query types, object kind, dimensions (the public StructureInfo) and a factory for
// its adapter. The runner, `kinetic run --help` and check_runnable read only this table.
//
// An adapter is the face a structure shows the runner: one virtual call per timeline op, never
// per event (inside advance_to the simulator calls the structure's process() statically). One
// template, Adapter<S>, serves every structure that satisfies the structure contract. A structure
// is played on its description (its loop guard's bounds, its answers through the session) unless
// a file of src/run/structures/ gives it a Binding of its own: a picture for a trace's snapshot,
// or a group of structures chosen by the scenario's queries (the sorts, the tournaments).

#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include "kinetic/core/structure.hpp"
#include "kinetic/run/runner.hpp"
#include "kinetic/run/timeline_driver.hpp"
#include "kinetic/structures.hpp"

namespace kinetic::run::detail {

using Json = nlohmann::ordered_json;

/// What the runner does at the points of a play (runner.cpp): validate, answer, trace, show
/// progress. A bool false stops the play.
class RunHooks {
 public:
  virtual ~RunHooks() = default;
  /// Events one at a time with event() after each (validation after every event).
  [[nodiscard]] virtual bool each_event() const = 0;
  /// Slices per advance for the progress bar (1: none).
  [[nodiscard]] virtual int slices() const = 0;
  virtual bool event() = 0;
  /// After an advance that reached its time (TimelineDriver::play's advanced()).
  virtual bool advanced() = 0;
  virtual bool query(const scenario::TimelineOp& op) = 0;
  virtual bool change(const scenario::TimelineOp& op) = 0;
  virtual void progress() = 0;
};

class StructureAdapter {
 public:
  virtual ~StructureAdapter() = default;
  /// The session's simulator (counters, guard, event log, interrupt flag).
  virtual Simulator& sim() = 0;
  /// The loop guard for the whole run.
  virtual void set_guard(const LoopGuard& guard) = 0;
  virtual void initialize() = 0;
  /// Plays the scenario on the session (TimelineDriver::play): one virtual call per run, one
  /// per timeline entry and, when validating, one per event.
  virtual PlayResult play(RunHooks& hooks) = 0;
  virtual Json answer(const scenario::QuerySpec& q) = 0;
  /// Robust scheduling: measure event delays (structures that can).
  virtual void set_measure_delays(bool on) = 0;
  [[nodiscard]] virtual bool validate() = 0;
  /// Bounds for the loop guard over the whole scenario.
  [[nodiscard]] virtual LoopGuard guard(const ScenarioBounds& bounds) = 0;
  [[nodiscard]] virtual NamedCounters counters() = 0;
  /// What a picture of the structure needs now (a trace's snapshot; docs/trace-format.md).
  [[nodiscard]] virtual Json snapshot() = 0;
  /// Samples the certificates alive and per object into the simulator's counters (the run's
  /// end calls it; initialize() and every change do too, the per-object count amortised).
  virtual void note_measures() = 0;
};

/// What a query answer needs besides the structure: ids of table indices, the current time.
struct AnswerContext {
  const MotionTable& motions;
  Time now;
  /// The id of a table index, or null.
  [[nodiscard]] Json id(std::optional<std::uint32_t> index) const {
    return index ? Json(motions.id(*index)) : Json(nullptr);
  }
  /// The ids of table indices, ascending.
  [[nodiscard]] Json sorted_ids(const std::vector<std::uint32_t>& indices) const;
  /// The ids of the objects at `indices`, in order; kNoIndex entries (the empty slots of an
  /// order in the sort's gapped layout) are left out.
  [[nodiscard]] Json ids_in_order(std::span<const std::uint32_t> indices) const;
};

/// The answer to a query through the session's query methods (session/session.hpp), the one
/// answer path of the library's users and of the runner: null for a type S does not answer
/// (check_runnable excludes those before a run).
template <KineticStructure S>
Json session_answer(Session<S>& s, const scenario::QuerySpec& q) {
  using scenario::QueryType;
  const auto id = [](const std::optional<ObjectId>& x) { return x ? Json(*x) : Json(nullptr); };
  switch (q.type) {
    case QueryType::Sorted:
      if constexpr (requires { s.sorted(); }) return Json(s.sorted());
      break;
    case QueryType::Max:
    case QueryType::Min:
      if constexpr (requires { s.top(); }) return id(s.top());
      break;
    case QueryType::Extent:
      if constexpr (requires { s.extent(); }) return Json(s.extent());
      break;
    case QueryType::Range:
      if constexpr (requires { s.range(q.box); }) return Json(s.range(q.box));
      break;
    case QueryType::Nearest:
      if constexpr (requires { s.nearest(std::span<const double>{}, q.eps); })
        return id(s.nearest(std::span<const double>(q.point), q.eps));
      else if constexpr (requires { s.nearest(Point2{}, q.eps); })
        return id(s.nearest(Point2{q.point[0], q.point[1]}, q.eps));
      break;
    case QueryType::KNearest:
      if constexpr (requires { s.k_nearest(std::span<const double>{}, q.k, q.eps); })
        return Json(s.k_nearest(std::span<const double>(q.point), q.k, q.eps));
      break;
    case QueryType::Farthest:
      if constexpr (requires { s.farthest(Point2{}, q.eps); })
        return id(s.farthest({q.point[0], q.point[1]}, q.eps));
      break;
    case QueryType::ApproxRange:
      if constexpr (requires { s.approx_range(q.shape, q.eps); })
        return Json(s.approx_range(q.shape, q.eps));
      break;
    case QueryType::Stab:
      if constexpr (requires { s.stab(q.x); }) return Json(s.stab(q.x));
      break;
    case QueryType::Hull:
      if constexpr (requires { s.hull(); }) return Json(s.hull());
      break;
    case QueryType::Delaunay:
      if constexpr (requires { s.delaunay(); }) return Json(s.delaunay());
      break;
    case QueryType::ClosestPair:
      if constexpr (requires { s.closest_pair(); }) {
        const auto pair = s.closest_pair();
        return pair ? Json(*pair) : Json(nullptr);
      }
      break;
    case QueryType::CollidingPairs:
      if constexpr (requires { s.colliding_pairs(); }) return Json(s.colliding_pairs());
      break;
  }
  return Json(nullptr);
}

/// The query types of a description that take no arguments (extent, hull, delaunay,
/// closest_pair, colliding_pairs), in its order: a trace's snapshot holds their answers.
inline std::vector<scenario::QueryType> no_argument_queries(const StructureDescription& d) {
  using scenario::QueryType;
  std::vector<QueryType> out;
  for (const QueryType q : d.queries) {
    if (q == QueryType::Extent || q == QueryType::Hull || q == QueryType::Delaunay ||
        q == QueryType::ClosestPair || q == QueryType::CollidingPairs)
      out.push_back(q);
  }
  return out;
}

/// What is particular to a structure in the runner, where its description does not say it: a
/// picture of its own for a trace's snapshot, the answers the snapshot holds, and for a group of
/// structures chosen by the queries (the runner's structure is then not the session's) its loop
/// guard and its answers.
template <KineticStructure S>
struct Binding {
  using Answer = Json (*)(S& structure, const scenario::QuerySpec& q, const AnswerContext& c);
  using Guard = LoopGuard (*)(const S& structure, const ScenarioBounds& b);
  using Snapshot = Json (*)(S& structure, const AnswerContext& context);

  /// The binding of a structure played on its description: its loop guard's bounds, its answers
  /// through the session, and a snapshot of the answers to its queries without arguments.
  Binding() : snapshot_answers(no_argument_queries(S::description())) {}
  /// That binding with a picture of its own after those answers.
  explicit Binding(Snapshot snapshot_) : Binding() { snapshot = snapshot_; }
  /// A group's binding: its guard, picture and answers, and no answers in its snapshot.
  Binding(Guard guard_, Snapshot snapshot_, Answer answer_)
      : guard(guard_), snapshot(snapshot_), answer(answer_) {}

  /// The loop guard's bounds (null: the description's bound_events).
  Guard guard = nullptr;
  /// The structure's own picture for a trace (docs/trace-format.md), after snapshot_answers.
  Snapshot snapshot = nullptr;
  /// The answers a snapshot holds, by query type ({"hull": [...]} and the like).
  std::vector<scenario::QueryType> snapshot_answers;
  /// The answer to a query, when not the session's (null: session_answer).
  Answer answer = nullptr;
};

/// A structure's session over a scenario (TimelineDriver<S>) and its binding, seen by the runner.
template <KineticStructure S>
class Adapter final : public StructureAdapter {
 public:
  template <class... Args>
  Adapter(const scenario::Scenario& s, SchedulerKind kind, double eps, Binding<S> binding,
          Args&&... structure_args)
      : driver_(s, kind, eps, std::forward<Args>(structure_args)...), binding_(binding) {}

  Simulator& sim() override { return driver_.sim(); }
  void set_guard(const LoopGuard& guard) override { driver_.session().set_guard(guard); }
  void initialize() override {
    (void)driver_.structure();  // built on first use
    note_measures();
  }
  PlayResult play(RunHooks& hooks) override {
    struct Forward {
      RunHooks& hooks;
      Adapter& adapter;
      int slices() const { return hooks.slices(); }
      void progress() { hooks.progress(); }
      bool advanced() { return hooks.advanced(); }
      bool query(const scenario::TimelineOp& op) { return hooks.query(op); }
      bool change(const scenario::TimelineOp& op) {
        adapter.note_change();
        return hooks.change(op);
      }
    };
    struct ForwardEachEvent : Forward {
      bool event() { return this->hooks.event(); }
    };
    return hooks.each_event() ? driver_.play(ForwardEachEvent{{hooks, *this}})
                              : driver_.play(Forward{hooks, *this});
  }
  Json answer(const scenario::QuerySpec& q) override {
    if (binding_.answer != nullptr)
      return binding_.answer(structure(), q, AnswerContext{driver_.motions(), driver_.sim().now()});
    return session_answer(driver_.session(), q);
  }
  void set_measure_delays(bool on) override {
    if constexpr (requires(S & s) { s.set_measure_delays(on); }) {
      structure().set_measure_delays(on);
    }
  }
  bool validate() override { return structure().validate(); }
  LoopGuard guard(const ScenarioBounds& bounds) override {
    if constexpr (requires { S::description(); }) {
      if (binding_.guard == nullptr)
        return S::description().event_bounds(bounds);  // present: checked by registry()
    }
    return binding_.guard(structure(), bounds);
  }
  NamedCounters counters() override { return structure().named_counters(); }
  Json snapshot() override {
    Json j = Json::object();
    for (const scenario::QueryType type : binding_.snapshot_answers) {
      scenario::QuerySpec q;
      q.type = type;
      j[scenario::to_string(type)] = answer(q);
    }
    if (binding_.snapshot == nullptr) return j;
    Json own =
        binding_.snapshot(structure(), AnswerContext{driver_.motions(), driver_.sim().now()});
    for (auto& [key, value] : own.items()) j[key] = std::move(value);
    return j;
  }
  void note_measures() override {
    changes_since_note_ = 0;
    driver_.sim().counters().set_certificates_alive(structure().certificates());
    driver_.sim().counters().note_certificates_per_object(
        structure().certificates_per_object_max());
  }

 private:
  /// The structure, not built: the runner calls initialize() itself (an interrupt there is
  /// handled), and the guard and delay measurement are set before.
  S& structure() { return driver_.session().structure_as_is(); }
  /// After a timeline change: the certificates alive. certificates_per_object_max() may cost
  /// O(n) (a count over every certificate): sampled once per n / 16 changes, so that a timeline
  /// of many updates stays O(1) per change.
  void note_change() {
    driver_.sim().counters().set_certificates_alive(structure().certificates());
    if (16 * ++changes_since_note_ >= driver_.motions().size()) note_measures();
  }

  std::size_t changes_since_note_ = 0;
  TimelineDriver<S> driver_;
  Binding<S> binding_;
};

/// The adapter of a structure S over a scenario's session; the structure built from
/// `structure_args` as Session<S> builds it (S's constructor's extra arguments or build_with).
template <KineticStructure S, class... Args>
std::unique_ptr<StructureAdapter> make_structure(const scenario::Scenario& s, SchedulerKind kind,
                                                 double eps, Binding<S> binding,
                                                 Args&&... structure_args) {
  return std::make_unique<Adapter<S>>(s, kind, eps, binding, std::forward<Args>(structure_args)...);
}

/// The snapshot of a structure with one kinetic sort per axis (`sort(axis)`): the maintained
/// orders, {"orders": [{"axis": a, "ids": [...]}, ...]} (a picture draws the rank-based cells
/// from them; docs/trace-format.md).
template <class S>
Json sort_orders_snapshot(S& s, const AnswerContext& c) {
  Json orders = Json::array();
  for (int a = 0; a < c.motions.dimension(); ++a)
    orders.push_back({{"axis", a}, {"ids", c.ids_in_order(s.sort(a).order())}});
  return {{"orders", std::move(orders)}};
}

/// The snapshot of a structure over one gapped kinetic sort per axis whose shape is defined by
/// the keys' slots (the kd-tree halves [0, U_i - 1], the range tree's primary tree A_0's slots
/// [0, U_0 - 1]): the orders of sort_orders_snapshot, each with the slot of every key ("slots",
/// beside "ids": strictly increasing, each < U) and the number of slots U of its sort
/// ("slot_count", a power of two), {"orders": [{"axis": a, "ids": [...], "slots": [...],
/// "slot_count": U}, ...]} (docs/trace-format.md).
template <class S>
Json slotted_orders_snapshot(S& s, const AnswerContext& c) {
  Json orders = Json::array();
  for (int a = 0; a < c.motions.dimension(); ++a) {
    const auto& sort = s.sort(a);
    const std::span<const std::uint32_t> order = sort.order();
    Json ids = Json::array();
    Json slots = Json::array();
    for (std::size_t j = 0; j < order.size(); ++j) {
      if (order[j] == kNoIndex) continue;  // an empty slot
      ids.push_back(c.motions.id(order[j]));
      slots.push_back(j);
    }
    orders.push_back({{"axis", a},
                      {"ids", std::move(ids)},
                      {"slots", std::move(slots)},
                      {"slot_count", sort.slots()}});
  }
  return {{"orders", std::move(orders)}};
}

struct StructureDescriptor {
  StructureInfo info;
  /// Builds the structure's session over the scenario (the structure not initialized).
  std::unique_ptr<StructureAdapter> (*make)(const scenario::Scenario& s, SchedulerKind kind,
                                            double eps);
};

/// Every structure built, in the order `kinetic run --help` lists them.
[[nodiscard]] const std::vector<StructureDescriptor>& registry();
[[nodiscard]] const StructureDescriptor* find(const std::string& name);

/// The descriptor of a structure played on its description (Binding<S>()); its factory null when
/// a session cannot build S from motions alone (its constructor takes more: it needs a binding
/// of its own).
template <KineticStructure S>
StructureDescriptor default_descriptor() {
  StructureDescriptor d{S::description(), nullptr};
  if constexpr (std::is_constructible_v<Session<S>, int, SessionOptions>) {
    d.make = [](const scenario::Scenario& s, SchedulerKind kind, double eps) {
      return make_structure(s, kind, eps, Binding<S>());
    };
  }
  return d;
}

/// The descriptor of a structure played on its description with a picture of its own in a
/// trace's snapshot (after its answers): Binding<S>(snapshot).
template <KineticStructure S, Json (*snapshot)(S&, const AnswerContext&)>
StructureDescriptor with_picture() {
  return {S::description(), [](const scenario::Scenario& s, SchedulerKind kind, double eps) {
            return make_structure(s, kind, eps, Binding<S>(snapshot));
          }};
}

/// The descriptors of the structures whose run needs a Binding of its own: each file
/// src/run/structures/<stem>.cpp defines bind_<stem>(out), which appends its structures' (the
/// build lists those files in run_bindings.inc; registry() calls every one).
using OwnDescriptors = std::vector<StructureDescriptor>;
#define KINETIC_RUN_BINDING(stem) void bind_##stem(OwnDescriptors& out);
#include "run_bindings.inc"
#undef KINETIC_RUN_BINDING

}  // namespace kinetic::run::detail
