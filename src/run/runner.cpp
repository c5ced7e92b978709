#include "kinetic/run/runner.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/kdtree/kinetic_kdtree.hpp"
#include "kinetic/lskdtree/longest_side_kdtree.hpp"
#include "kinetic/rangetree/kinetic_range_tree.hpp"
#include "kinetic/segtree/segment_tree.hpp"
#include "kinetic/sort/kinetic_sort.hpp"
#include "kinetic/tournament/kinetic_tournament.hpp"

namespace kinetic::run {

using scenario::QueryType;
using Json = nlohmann::ordered_json;

namespace {

/// The face a structure shows the runner: one virtual call per timeline op, never per event
/// (events go from the simulator to the structure's process() statically, inside advance_to).
class StructureAdapter {
 public:
  virtual ~StructureAdapter() = default;
  virtual void initialize() = 0;
  virtual AdvanceOutcome advance_to(Time t) = 0;
  virtual AdvanceOutcome run_until_empty() = 0;
  virtual AdvanceOutcome process_next() = 0;
  virtual void inserted(std::uint32_t index) = 0;
  virtual void removing(std::uint32_t index) = 0;
  virtual void updated(std::uint32_t index) = 0;
  virtual Json answer(const scenario::QuerySpec& q) = 0;
  /// Robust scheduling: measure event delays (structures that can).
  virtual void set_measure_delays(bool) {}
  [[nodiscard]] virtual bool validate() const = 0;
  /// Bounds for the loop guard, given the largest number of objects the run can hold.
  [[nodiscard]] virtual LoopGuard guard_for(std::uint64_t max_objects, std::uint64_t motion_changes,
                                            int max_degree) const = 0;
  /// The structure's own counters, by name, for the stats file (none by default).
  [[nodiscard]] virtual std::vector<std::pair<std::string, std::uint64_t>> structure_counters()
      const {
    return {};
  }
};

/// What every adapter shares: the simulator's loop calls with the adapter itself as the event
/// handler (a static call per event: Derived::process), and the certificate counters.
template <class Derived>
class SimulatedAdapter : public StructureAdapter {
 public:
  explicit SimulatedAdapter(Simulator& sim) : sim_(sim) {}
  AdvanceOutcome advance_to(Time t) override { return sim_.advance_to(t, self()); }
  AdvanceOutcome run_until_empty() override { return sim_.run_until_empty(self()); }
  AdvanceOutcome process_next() override { return sim_.process_next(self()); }

 protected:
  void note_certificates(std::uint64_t alive, std::uint64_t per_object) {
    sim_.counters().set_certificates_alive(alive);
    sim_.counters().note_certificates_per_object(per_object);
  }
  Simulator& sim_;

 private:
  Derived& self() { return static_cast<Derived&>(*this); }
};

/// Loop-guard bounds for `copies` structures whose events are crossings of pairs of motions: at
/// one instant each pair crosses at most once per structure; over a run, two degree-s motions
/// cross at most s times per pair of motion pieces.
LoopGuard pairwise_guard(std::uint64_t copies, std::uint64_t n, std::uint64_t changes,
                         int max_degree) {
  const std::uint64_t s = static_cast<std::uint64_t>(std::max(1, max_degree));
  const std::uint64_t pairs = n * (n > 0 ? n - 1 : 0) / 2;
  LoopGuard g;
  g.max_events_per_instant = copies * pairs + 16;
  g.max_events_total = copies * s * (pairs + changes * n) + 16;
  return g;
}

/// `sort`: one kinetic sort per axis, all sharing the simulator's queue (owner = axis).
class SortAdapter final : public SimulatedAdapter<SortAdapter> {
 public:
  SortAdapter(const MotionTable& motions, Simulator& sim, const Scheduler& scheduler)
      : SimulatedAdapter(sim) {
    for (int axis = 0; axis < motions.dimension(); ++axis) {
      sorts_.push_back(std::make_unique<KineticSort>(motions, sim, scheduler, axis,
                                                     static_cast<std::uint32_t>(axis)));
    }
    motions_ = &motions;
  }
  EventKind process(const Event& e) { return sorts_[e.owner]->process(e); }

  void initialize() override {
    for (auto& s : sorts_) s->initialize();
    note_certificates();
  }
  void inserted(std::uint32_t index) override {
    for (auto& s : sorts_) s->insert(index);
    note_certificates();
  }
  void removing(std::uint32_t index) override {
    for (auto& s : sorts_) s->remove(index);
    note_certificates();
  }
  void updated(std::uint32_t index) override {
    for (auto& s : sorts_) s->motion_changed(index);
    note_certificates();
  }
  Json answer(const scenario::QuerySpec& q) override {
    const auto order = sorts_[q.axis]->order();
    switch (q.type) {
      case QueryType::Sorted: {
        Json ids = Json::array();
        for (std::uint32_t i : order) ids.push_back(motions_->id(i));
        return ids;
      }
      case QueryType::Max:
        return order.empty() ? Json(nullptr) : Json(motions_->id(order.back()));
      case QueryType::Min:
        return order.empty() ? Json(nullptr) : Json(motions_->id(order.front()));
      default:
        return Json(nullptr);  // excluded by check_runnable
    }
  }
  void set_measure_delays(bool on) override {
    for (auto& s : sorts_) s->set_measure_delays(on);
  }
  bool validate() const override {
    return std::all_of(sorts_.begin(), sorts_.end(), [](const auto& s) { return s->validate(); });
  }
  LoopGuard guard_for(std::uint64_t n, std::uint64_t changes, int max_degree) const override {
    return pairwise_guard(sorts_.size(), n, changes, max_degree);  // one sort per axis
  }

 private:
  void note_certificates() {
    std::uint64_t total = 0, per_object = 0;
    for (auto& s : sorts_) {
      total += s->certificates();
      per_object += s->certificates_per_object_max();
    }
    SimulatedAdapter::note_certificates(total, per_object);
  }

  const MotionTable* motions_ = nullptr;
  std::vector<std::unique_ptr<KineticSort>> sorts_;
};

/// `tournament` and `extent`: kinetic tournaments sharing the simulator's queue (owner = position
/// in the list). `extent` keeps a max and a min tournament per axis (the kinetic bounding box);
/// `tournament` keeps those the scenario's queries ask for (max on axis 0 when there are none).
class TournamentAdapter final : public SimulatedAdapter<TournamentAdapter> {
 public:
  TournamentAdapter(const MotionTable& motions, Simulator& sim, const Scheduler& scheduler,
                    const std::vector<std::pair<int, Extreme>>& which)
      : SimulatedAdapter(sim), motions_(&motions) {
    for (const auto& [axis, extreme] : which) {
      slot_[static_cast<std::size_t>(axis) * 2 + (extreme == Extreme::Max ? 1 : 0)] =
          static_cast<int>(tournaments_.size());
      tournaments_.push_back(std::make_unique<KineticTournament>(
          motions, sim, scheduler, axis, extreme, static_cast<std::uint32_t>(tournaments_.size())));
    }
  }
  EventKind process(const Event& e) { return tournaments_[e.owner]->process(e); }

  void initialize() override {
    for (auto& t : tournaments_) t->initialize();
    note_certificates();
  }
  void inserted(std::uint32_t index) override {
    for (auto& t : tournaments_) t->insert(index);
    note_certificates();
  }
  void removing(std::uint32_t index) override {
    for (auto& t : tournaments_) t->remove(index);
    note_certificates();
  }
  void updated(std::uint32_t index) override {
    for (auto& t : tournaments_) t->motion_changed(index);
    note_certificates();
  }
  Json answer(const scenario::QuerySpec& q) override {
    switch (q.type) {
      case QueryType::Max:
      case QueryType::Min:
        return top(q.axis, q.type == QueryType::Max ? Extreme::Max : Extreme::Min);
      case QueryType::Extent: {
        Json box = Json::array();
        for (int axis = 0; axis < motions_->dimension(); ++axis)
          box.push_back(Json::array({top(axis, Extreme::Min), top(axis, Extreme::Max)}));
        return box;
      }
      default:
        return Json(nullptr);  // excluded by check_runnable
    }
  }
  bool validate() const override {
    return std::all_of(tournaments_.begin(), tournaments_.end(),
                       [](const auto& t) { return t->validate(); });
  }
  LoopGuard guard_for(std::uint64_t n, std::uint64_t changes, int max_degree) const override {
    // A certificate at a node fails only when its two points cross (at their lowest common
    // ancestor): each tournament is bounded like one sort.
    return pairwise_guard(tournaments_.size(), n, changes, max_degree);
  }

 private:
  Json top(int axis, Extreme extreme) const {
    const int i = slot_.at(static_cast<std::size_t>(axis) * 2 + (extreme == Extreme::Max ? 1 : 0));
    const std::optional<std::uint32_t> t = tournaments_[static_cast<std::size_t>(i)]->top();
    return t ? Json(motions_->id(*t)) : Json(nullptr);
  }
  void note_certificates() {
    std::uint64_t total = 0, per_object = 0;
    for (auto& t : tournaments_) {
      total += t->certificates();
      per_object += t->certificates_per_object_max();
    }
    SimulatedAdapter::note_certificates(total, per_object);
  }

  const MotionTable* motions_;
  std::vector<std::unique_ptr<KineticTournament>> tournaments_;
  std::map<std::size_t, int> slot_;  // 2 axis + (max ? 1 : 0) -> tournament
};

/// What the adapters of a single tree structure share (kdtree, longest-side-kdtree,
/// segment-tree): the tree, built on owners from 0, gets the events and the timeline's changes,
/// and the certificate counters are noted after each change. Derived may hide
/// certificates_per_object() when its objects are not the tree's objects.
template <class Derived, class Tree>
class TreeAdapter : public SimulatedAdapter<Derived> {
 public:
  TreeAdapter(const MotionTable& motions, Simulator& sim, const Scheduler& scheduler)
      : SimulatedAdapter<Derived>(sim), motions_(&motions), tree_(motions, sim, scheduler, 0) {}
  EventKind process(const Event& e) { return tree_.process(e); }

  void initialize() override {
    tree_.initialize();
    note_certificates();
  }
  void inserted(std::uint32_t index) override {
    tree_.insert(index);
    note_certificates();
  }
  void removing(std::uint32_t index) override {
    tree_.remove(index);
    note_certificates();
  }
  void updated(std::uint32_t index) override {
    tree_.motion_changed(index);
    note_certificates();
  }
  bool validate() const override { return tree_.validate(); }

  [[nodiscard]] std::uint64_t certificates_per_object() const {
    return tree_.certificates_per_object_max();
  }

 protected:
  /// The scenario ids of table indices, ascending.
  [[nodiscard]] Json sorted_ids(const std::vector<std::uint32_t>& indices) const {
    std::vector<ObjectId> ids;
    ids.reserve(indices.size());
    for (const std::uint32_t i : indices) ids.push_back(motions_->id(i));
    std::sort(ids.begin(), ids.end());
    return Json(ids);
  }

  const MotionTable* motions_;
  Tree tree_;

 private:
  void note_certificates() {
    SimulatedAdapter<Derived>::note_certificates(
        tree_.certificates(), static_cast<const Derived&>(*this).certificates_per_object());
  }
};

/// A structure over points whose events are those of one kinetic sort per axis (owner = axis),
/// answering closed-box range queries: the kd-tree and the range tree.
template <class Derived, class Tree>
class BoxRangeAdapter : public TreeAdapter<Derived, Tree> {
 public:
  using TreeAdapter<Derived, Tree>::TreeAdapter;
  Json answer(const scenario::QuerySpec& q) override {
    if (q.type != QueryType::Range) return Json(nullptr);  // excluded by check_runnable
    return this->sorted_ids(this->tree_.range(q.box, this->sim_.now()));
  }
  LoopGuard guard_for(std::uint64_t n, std::uint64_t changes, int max_degree) const override {
    // The events are those of one kinetic sort per axis.
    return pairwise_guard(static_cast<std::uint64_t>(this->motions_->dimension()), n, changes,
                          max_degree);
  }
};

/// `kdtree`: the kinetic rank-based kd-tree.
class KdTreeAdapter final : public BoxRangeAdapter<KdTreeAdapter, KineticKdTree> {
 public:
  using BoxRangeAdapter::BoxRangeAdapter;
  std::vector<std::pair<std::string, std::uint64_t>> structure_counters() const override {
    const KdTreeCounters& c = tree_.kd_counters();
    return {{"swaps", c.events},
            {"unchanged_events", c.unchanged_events},
            {"reinsertions", c.reinsertions},
            {"nodes_created", c.nodes_created},
            {"nodes_removed", c.nodes_removed},
            {"compactions", c.compactions},
            {"rebuilds", c.rebuilds},
            {"tree_nodes", tree_.node_count()},
            {"queries", c.queries},
            {"node_visits", c.node_visits}};
  }
};

/// `longest-side-kdtree`: the kinetic rank-based longest-side kd-tree in the plane (owners 0, 1:
/// the sorts of the two axes; 2: the side-length list).
class LongestSideAdapter final : public TreeAdapter<LongestSideAdapter, LongestSideKdTree> {
 public:
  using TreeAdapter::TreeAdapter;
  Json answer(const scenario::QuerySpec& q) override {
    const Time t = sim_.now();
    auto one = [this](std::optional<std::uint32_t> i) {
      return i ? Json(motions_->id(*i)) : Json(nullptr);
    };
    switch (q.type) {
      case QueryType::Nearest:
        return one(tree_.nearest({q.point[0], q.point[1]}, q.eps, t));
      case QueryType::Farthest:
        return one(tree_.farthest({q.point[0], q.point[1]}, q.eps, t));
      case QueryType::Range:
        return sorted_ids(tree_.range({q.box[0], q.box[1]}, t));
      case QueryType::ApproxRange: {
        LsShape shape;
        if (q.shape.kind == scenario::Shape::Kind::Disk) {
          shape.kind = LsShape::Kind::Disk;
          shape.center = {q.shape.disk.center[0], q.shape.disk.center[1]};
          shape.radius = q.shape.disk.radius;
        } else {
          shape.kind = LsShape::Kind::Polygon;
          shape.polygon = q.shape.polygon;
        }
        return sorted_ids(tree_.approx_range(shape, q.eps, t));
      }
      default:
        return Json(nullptr);  // excluded by check_runnable
    }
  }
  std::vector<std::pair<std::string, std::uint64_t>> structure_counters() const override {
    const LongestSideCounters& c = tree_.ls_counters();
    return {{"ordering_events", c.ordering_events},
            {"longest_side_events", c.side_events},
            {"longest_side_events_real", c.side_events_real},
            {"longest_side_events_rebuilt_below", c.side_events_rebuilt},
            {"longest_side_events_dropped_same_axis", c.side_events_same_axis},
            {"longest_side_events_dropped_no_region", c.side_events_no_region},
            {"reinsertions", c.reinsertions},
            {"rebuilds", c.rebuilds},
            {"combined_lengths", c.combined_lengths},
            {"queries", c.queries},
            {"node_visits", c.node_visits}};
  }
  LoopGuard guard_for(std::uint64_t n, std::uint64_t changes, int max_degree) const override {
    // Ordering events are crossings in the two sorts. The side-length list has m < 2n
    // elements; a pair of elements crosses at most s times while both keep their length
    // polynomials, and an ordering event gives new polynomials to at most 12 ceil(log2 n) + 12
    // elements (a rank ends at most 3 ranges per level on each axis), each of which may then
    // cross every other element once more. Saturating arithmetic: the bounds are huge for large n.
    const LoopGuard sorts = pairwise_guard(2, n, changes, max_degree);
    const std::uint64_t s = static_cast<std::uint64_t>(std::max(1, max_degree));
    std::uint64_t log = 0;
    while ((std::uint64_t{1} << log) < n) ++log;
    const std::uint64_t m = 2 * n;
    const std::uint64_t pairs_m = m * (m > 0 ? m - 1 : 0) / 2;
    const std::uint64_t per_ordering = (12 * log + 12) * m;
    auto mul = [](std::uint64_t a, std::uint64_t b) {
      return (a != 0 && b > UINT64_MAX / a) ? UINT64_MAX : a * b;
    };
    auto add = [](std::uint64_t a, std::uint64_t b) {
      return a > UINT64_MAX - b ? UINT64_MAX : a + b;
    };
    LoopGuard g;
    g.max_events_per_instant = add(sorts.max_events_per_instant,
                                   add(pairs_m, mul(sorts.max_events_per_instant, per_ordering)));
    g.max_events_total = add(
        sorts.max_events_total,
        add(mul(s, mul(changes + 1, pairs_m)), mul(s, mul(sorts.max_events_total, per_ordering))));
    return g;
  }
};

/// `segment-tree`: the kinetic segment tree over moving intervals (one kinetic sort of the 2n
/// endpoints, owner 0); stabbing queries.
class SegmentTreeAdapter final : public TreeAdapter<SegmentTreeAdapter, KineticSegmentTree> {
 public:
  using TreeAdapter::TreeAdapter;
  Json answer(const scenario::QuerySpec& q) override {
    if (q.type != QueryType::Stab) return Json(nullptr);  // excluded by check_runnable
    return sorted_ids(tree_.stab(q.x, sim_.now()));
  }
  std::vector<std::pair<std::string, std::uint64_t>> structure_counters() const override {
    const SegmentTreeCounters& c = tree_.st_counters();
    return {{"swaps", c.swaps},
            {"walks", c.walks},
            {"walk_height_total", c.walk_height},
            {"walk_height_max", c.walk_height_max},
            {"own_endpoint_meetings", c.own_meetings},
            {"rebuilds", c.rebuilds},
            {"fragments", tree_.fragments()},
            {"fragments_per_segment_max", tree_.fragments_max()},
            {"queries", c.queries},
            {"nodes_visited", c.nodes_visited}};
  }
  LoopGuard guard_for(std::uint64_t n, std::uint64_t changes, int max_degree) const override {
    // The events are those of one kinetic sort of 2n endpoints (an insert or update changes two).
    return pairwise_guard(1, 2 * n, 2 * changes, max_degree);
  }

  /// One certificate per adjacent pair of R; an interval's two endpoints take part in <= 4.
  [[nodiscard]] std::uint64_t certificates_per_object() const {
    return 2 * tree_.endpoint_sort().certificates_per_object_max();
  }
};

/// `range-tree`: the kinetic range tree.
class RangeTreeAdapter final : public BoxRangeAdapter<RangeTreeAdapter, KineticRangeTree> {
 public:
  using BoxRangeAdapter::BoxRangeAdapter;
  std::vector<std::pair<std::string, std::uint64_t>> structure_counters() const override {
    const RangeTreeCounters& c = tree_.rt_counters();
    std::vector<std::pair<std::string, std::uint64_t>> out;
    for (std::size_t a = 0; a < c.events_by_axis.size(); ++a) {
      out.emplace_back("swaps_axis_" + std::to_string(a), c.events_by_axis[a]);
    }
    out.insert(out.end(), {{"swaps", c.events},
                           {"nodes_touched", c.nodes_touched},
                           {"adjacent_swaps", c.adjacent_swaps},
                           {"replacements", c.replacements},
                           {"shifts", c.shifts},
                           {"rebuilt_entries", c.rebuilt_entries},
                           {"local_updates", c.local_updates},
                           {"update_rebuilds", c.update_rebuilds},
                           {"replayed_swaps", c.replayed_swaps},
                           {"rebuilds", c.rebuilds},
                           {"stored_entries", tree_.stored_entries()},
                           {"queries", c.queries},
                           {"node_visits", c.node_visits}});
    return out;
  }
};

std::vector<MotionPolynomial> to_polynomials(const scenario::Motion& m) {
  std::vector<MotionPolynomial> out;
  out.reserve(m.coordinates.size());
  for (const auto& c : m.coordinates) out.push_back(MotionPolynomial::from(c, m.origin));
  return out;
}

std::unique_ptr<StructureAdapter> make_adapter(const std::string& name, const scenario::Scenario& s,
                                               const MotionTable& motions, Simulator& sim,
                                               const Scheduler& scheduler) {
  if (name == "sort") return std::make_unique<SortAdapter>(motions, sim, scheduler);
  if (name == "kdtree") return std::make_unique<KdTreeAdapter>(motions, sim, scheduler);
  if (name == "range-tree") return std::make_unique<RangeTreeAdapter>(motions, sim, scheduler);
  if (name == "longest-side-kdtree") {
    return std::make_unique<LongestSideAdapter>(motions, sim, scheduler);
  }
  if (name == "segment-tree") return std::make_unique<SegmentTreeAdapter>(motions, sim, scheduler);
  std::vector<std::pair<int, Extreme>> which;
  if (name == "extent") {
    for (int axis = 0; axis < s.dimension; ++axis) {
      which.emplace_back(axis, Extreme::Min);
      which.emplace_back(axis, Extreme::Max);
    }
  } else if (name == "tournament") {
    for (const scenario::TimelineOp& op : s.timeline) {
      if (op.op != scenario::OpKind::Query) continue;
      const std::pair<int, Extreme> w{
          op.query.axis, op.query.type == QueryType::Min ? Extreme::Min : Extreme::Max};
      if (std::find(which.begin(), which.end(), w) == which.end()) which.push_back(w);
    }
    std::sort(which.begin(), which.end());
    if (which.empty()) which.emplace_back(0, Extreme::Max);
  } else {
    return nullptr;
  }
  return std::make_unique<TournamentAdapter>(motions, sim, scheduler, which);
}

const StructureInfo* find_structure(const std::string& name) {
  for (const StructureInfo& s : structures()) {
    if (s.name == name) return &s;
  }
  return nullptr;
}

class Progress {
 public:
  Progress(bool enabled, Time start, Time end) : enabled_(enabled), start_(start), end_(end) {}
  void show(Time t, std::uint64_t events) {
    if (!enabled_) return;
    const double f = end_ > start_ ? std::clamp((t - start_) / (end_ - start_), 0.0, 1.0) : 1.0;
    const int width = 40;
    const int filled = static_cast<int>(f * width);
    std::cerr << "\r[" << std::string(static_cast<std::size_t>(filled), '#')
              << std::string(static_cast<std::size_t>(width - filled), ' ') << "] "
              << static_cast<int>(f * 100.0) << "%  t=" << t << "  events=" << events << std::flush;
  }
  void done() {
    if (enabled_) std::cerr << "\n";
  }

 private:
  bool enabled_;
  Time start_, end_;
};

}  // namespace

const std::vector<StructureInfo>& structures() {
  static const std::vector<StructureInfo> built = {
      {"sort",
       "kinetic sorting of points along each axis (one sorted array per axis)",
       {QueryType::Sorted, QueryType::Max, QueryType::Min},
       scenario::ObjectsAre::Points},
      {"tournament",
       "kinetic tournaments: the maximum / minimum of points along an axis (one tournament per "
       "axis and extreme that the queries ask for)",
       {QueryType::Max, QueryType::Min},
       scenario::ObjectsAre::Points},
      {"extent",
       "kinetic bounding box: a max and a min tournament per axis",
       {QueryType::Extent, QueryType::Max, QueryType::Min},
       scenario::ObjectsAre::Points},
      {"kdtree",
       "kinetic rank-based kd-tree (any dimension <= 64): orthogonal range queries",
       {QueryType::Range},
       scenario::ObjectsAre::Points},
      {"range-tree",
       "kinetic range tree (dimension <= 4; one kinetic sort per axis, Basch-Guibas-Zhang): "
       "orthogonal range queries",
       {QueryType::Range},
       scenario::ObjectsAre::Points},
      {"longest-side-kdtree",
       "kinetic rank-based longest-side kd-tree (dimension 2): (1+eps)-nearest, "
       "(1-eps)-farthest, eps-approximate range (disk or simple polygon), exact box range",
       {QueryType::Nearest, QueryType::Farthest, QueryType::ApproxRange, QueryType::Range},
       scenario::ObjectsAre::Points},
      {"segment-tree",
       "kinetic segment tree over moving intervals: stabbing queries (ids of the intervals "
       "containing x)",
       {QueryType::Stab},
       scenario::ObjectsAre::Intervals},
  };
  return built;
}

const char* to_string(RunOutcome outcome) {
  switch (outcome) {
    case RunOutcome::Completed:
      return "completed";
    case RunOutcome::LoopGuard:
      return "loop_guard";
    case RunOutcome::EventBudget:
      return "event_budget";
    case RunOutcome::InvalidState:
      return "invalid_state";
  }
  return "?";
}

void check_runnable(const scenario::Scenario& s, const RunOptions& options,
                    const std::string& file_name) {
  const StructureInfo* info = find_structure(options.structure);
  if (info == nullptr) {
    std::string names;
    for (const StructureInfo& b : structures()) names += (names.empty() ? "" : ", ") + b.name;
    throw UsageError("unknown structure '" + options.structure + "' (built: " + names + ")");
  }
  if (!scheduler_available(options.scheduler)) {
    throw UsageError(std::string("scheduler '") + to_string(options.scheduler) +
                     "' is not built yet; use --scheduler classic");
  }
  if (!(options.eps > 0.0) || !std::isfinite(options.eps)) {
    throw UsageError("--eps must be a positive finite number");
  }
  if (options.scheduler == SchedulerKind::Robust) {
    // The times the scenario names: its window, or its start and last timeline entry.
    const Time last =
        s.end_time.value_or(s.timeline.empty() ? s.start_time : s.timeline.back().time);
    if (!Scheduler::precision_supported(options.eps, s.start_time, last)) {
      std::ostringstream msg;
      msg << "--eps " << options.eps << " is finer than doubles resolve on the scenario's times ["
          << s.start_time << ", " << last << "]; use a larger --eps or times nearer to 0";
      throw UsageError(msg.str());
    }
  }
  if (info->name == "kdtree" && s.dimension > 64) {
    throw UsageError(file_name +
                     ": $.dimension: structure kdtree supports dimensions up to 64, got " +
                     std::to_string(s.dimension));
  }
  if (info->name == "range-tree" && s.dimension > 4) {
    // Its space is n (ceil(log2 n) + 1)^(d - 1) ids and positions.
    throw UsageError(file_name +
                     ": $.dimension: structure range-tree supports dimensions up to 4, got " +
                     std::to_string(s.dimension));
  }
  if (info->name == "longest-side-kdtree" && s.dimension != 2) {
    throw UsageError(file_name +
                     ": $.dimension: structure longest-side-kdtree supports dimension 2 only "
                     "(paper 002, Section 3), got " +
                     std::to_string(s.dimension));
  }
  if (s.objects_are != info->objects) {
    throw UsageError(
        file_name + ": $.objects_are: structure " + info->name + " expects " +
        (info->objects == scenario::ObjectsAre::Points ? "\"points\"" : "\"intervals\""));
  }
  for (const scenario::TimelineOp& op : s.timeline) {
    if (op.op != scenario::OpKind::Query) continue;
    if (std::find(info->queries.begin(), info->queries.end(), op.query.type) ==
        info->queries.end()) {
      std::string names;
      for (QueryType q : info->queries)
        names += std::string(names.empty() ? "" : ", ") + scenario::to_string(q);
      throw UsageError(file_name + ": $.timeline[" + std::to_string(op.file_index) +
                       "].query.type: structure " + info->name + " answers " + names + "; got \"" +
                       scenario::to_string(op.query.type) + "\"");
    }
  }
}

RunResult run(const scenario::Scenario& s, const RunOptions& options, std::ostream& answers) {
  const auto wall_start = std::chrono::steady_clock::now();
  RunResult result;
  MotionTable motions(s.dimension);
  for (const scenario::ObjectSpec& o : s.objects) {
    motions.insert(o.id, to_polynomials(o.motion), s.start_time);
  }
  Simulator sim(s.start_time);
  const Scheduler scheduler(options.scheduler, options.eps, s.end_time.value_or(kTimeInfinity));
  std::unique_ptr<StructureAdapter> structure =
      make_adapter(options.structure, s, motions, sim, scheduler);
  structure->set_measure_delays(options.measure_delays);

  std::uint64_t max_objects = s.objects.size(), changes = s.objects.size();
  int max_degree = 0;
  auto note_degree = [&](const scenario::Motion& m) {
    for (const auto& c : m.coordinates) {
      std::size_t n = c.size();
      while (n > 1 && c[n - 1] == 0.0) --n;
      max_degree = std::max(max_degree, static_cast<int>(n) - 1);
    }
  };
  for (const scenario::ObjectSpec& o : s.objects) note_degree(o.motion);
  for (const scenario::TimelineOp& op : s.timeline) {
    if (op.op == scenario::OpKind::Insert) ++max_objects;
    if (op.op == scenario::OpKind::Insert || op.op == scenario::OpKind::Update) {
      ++changes;
      note_degree(op.motion);
    }
  }
  sim.set_guard(structure->guard_for(max_objects, changes, max_degree));
  structure->initialize();
  result.stats.objects_initial = s.objects.size();

  const Time end = s.end_time.value_or(s.timeline.empty() ? s.start_time : s.timeline.back().time);
  Progress progress(options.progress, s.start_time, end);

  auto stop = [&](AdvanceOutcome o) -> bool {
    if (o == AdvanceOutcome::Reached) {
      if (options.validate_every_event && !structure->validate()) {
        result.outcome = RunOutcome::InvalidState;
        result.message = "validate() failed at t=" + std::to_string(sim.now());
        return true;
      }
      return false;
    }
    const GuardReport& g = sim.guard_report();
    std::ostringstream msg;
    msg.precision(17);
    if (o == AdvanceOutcome::LoopGuard) {
      result.outcome = RunOutcome::LoopGuard;
      msg << "the " << to_string(options.scheduler) << " scheduler looped: " << g.events_at_instant
          << " events at t=" << g.time
          << " without time advancing (more than a correct run can have at one "
          << "instant); stopped by the loop guard";
    } else {
      result.outcome = RunOutcome::EventBudget;
      msg << "the " << to_string(options.scheduler) << " scheduler processed " << g.events_total
          << " events by t=" << g.time
          << ", more than a correct run can have; stopped by the event guard";
    }
    result.message = msg.str();
    return true;
  };

  // In test mode, validate after every event by advancing one event at a time.
  auto advance = [&](Time t) -> bool {
    if (!options.validate_every_event && !options.progress) return stop(structure->advance_to(t));
    if (options.progress) {
      // Advance in slices so that the bar moves during long stretches without ops.
      const Time from = sim.now();
      for (int k = 1; k <= 20; ++k) {
        const Time slice = k == 20 ? t : from + (t - from) * (k / 20.0);
        if (slice < sim.now()) continue;
        if (stop(structure->advance_to(slice))) return true;
        progress.show(sim.now(), sim.counters().events());
      }
      return false;
    }
    while (!sim.queue().empty() && sim.queue().top().time <= t) {
      if (stop(structure->process_next())) return true;
    }
    return stop(structure->advance_to(t));
  };

  bool stopped = false;
  for (const scenario::TimelineOp& op : s.timeline) {
    if ((stopped = advance(op.time))) break;
    switch (op.op) {
      case scenario::OpKind::Query: {
        Json line;
        line["time"] = op.time;
        line["type"] = scenario::to_string(op.query.type);
        line["result"] = structure->answer(op.query);
        answers << line.dump() << '\n';
        ++result.stats.queries;
        break;
      }
      case scenario::OpKind::Insert: {
        const ObjectHandle h = motions.insert(op.id, to_polynomials(op.motion), op.time);
        structure->inserted(h.index);
        break;
      }
      case scenario::OpKind::Remove: {
        const ObjectHandle h = *motions.find(op.id);
        structure->removing(h.index);
        motions.remove(h);
        break;
      }
      case scenario::OpKind::Update: {
        const ObjectHandle h = *motions.find(op.id);
        motions.update(h, to_polynomials(op.motion), op.time);
        structure->updated(h.index);
        break;
      }
    }
    sim.note_external_change();
    if (options.validate_every_event && !structure->validate()) {
      result.outcome = RunOutcome::InvalidState;
      result.message = "validate() failed after timeline entry " + std::to_string(op.file_index);
      stopped = true;
      break;
    }
  }
  if (!stopped) {
    if (s.end_time) {
      stopped = advance(*s.end_time);
    } else {
      stopped = stop(structure->run_until_empty());
    }
  }
  progress.show(sim.now(), sim.counters().events());
  progress.done();
  answers.flush();

  result.stats.counters = sim.counters();
  result.stats.queue_max = sim.queue().max_size();
  result.stats.final_time = sim.now();
  result.stats.structure_counters = structure->structure_counters();
  result.stats.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return result;
}

std::string stats_json(const RunResult& result, const RunOptions& options) {
  const Counters& c = result.stats.counters;
  Json j;
  j["structure"] = options.structure;
  j["scheduler"] = to_string(options.scheduler);
  if (options.scheduler != SchedulerKind::Classic) j["eps"] = options.eps;
  j["outcome"] = to_string(result.outcome);
  if (!result.message.empty()) j["message"] = result.message;
  j["objects"] = result.stats.objects_initial;
  j["queries"] = result.stats.queries;
  j["events"] = {{"processed", c.events()},
                 {"internal", c.events_internal},
                 {"external", c.events_external},
                 {"in_past", c.events_in_past}};
  j["certificates"] = {{"alive_max", c.certificates_alive_max},
                       {"alive_end", c.certificates_alive},
                       {"per_object_max", c.certificates_per_object_max}};
  j["root_isolation_calls"] = c.root_isolation_calls;
  j["exact_fallbacks"] = c.exact_fallbacks();
  j["predicates"] = {{"filtered", c.predicates.filtered + c.crop.predicates.filtered},
                     {"exact", c.predicates.exact + c.crop.predicates.exact}};
  if (options.scheduler == SchedulerKind::Robust) {
    j["crop"] = {{"calls", c.crop.calls},
                 {"bernstein_boxes", c.crop.bernstein_boxes},
                 {"fast_path", c.crop.fast_path},
                 {"exact_boxes", c.crop.exact_boxes}};
  }
  if (options.measure_delays && options.scheduler == SchedulerKind::Robust) {
    const double n = static_cast<double>(std::max<std::uint64_t>(1, c.delays_measured));
    const double rms = std::sqrt(c.delay_sum_squares / n);
    j["delays"] = {{"measured", c.delays_measured},
                   {"max", c.delay_max},
                   {"rms", rms},
                   {"max_in_eps", c.delay_max / options.eps},
                   {"rms_in_eps", rms / options.eps}};
  }
  if (!result.stats.structure_counters.empty()) {
    Json sc = Json::object();
    for (const auto& [name, value] : result.stats.structure_counters) sc[name] = value;
    j["structure_counters"] = sc;
  }
  j["queue_max"] = result.stats.queue_max;
  j["final_time"] = result.stats.final_time;
  j["wall_time_s"] = result.stats.wall_seconds;
  j["events_per_second"] = result.stats.wall_seconds > 0.0
                               ? static_cast<double>(c.events()) / result.stats.wall_seconds
                               : 0.0;
  j["time_per_event_us"] =
      c.events() > 0 ? result.stats.wall_seconds * 1e6 / static_cast<double>(c.events()) : 0.0;
  return j.dump(2);
}

}  // namespace kinetic::run
