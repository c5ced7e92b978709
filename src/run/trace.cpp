#include "trace.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <ostream>
#include <stdexcept>
#include <unordered_map>
#include <vector>

#include "kinetic/scenario/scenario_json.hpp"

namespace kinetic::run::detail {

std::vector<EventType> event_types(const StructureInfo& structure, int dimension) {
  std::vector<EventType> out;
  for (const std::string& kind : structure.event_kinds) {
    if (kind == "swap" || kind == "max_change" || kind == "min_change") {
      for (int a = 0; a < dimension; ++a) out.push_back({kind, a});
    } else {
      out.push_back({kind, -1});
    }
  }
  out.push_back({"external", -1});
  out.push_back({"internal", -1});
  return out;
}

nlohmann::ordered_json event_types_json(const std::vector<EventType>& types) {
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (const EventType& e : types) {
    out.push_back(e.axis >= 0 ? nlohmann::ordered_json::array({e.kind, e.axis})
                              : nlohmann::ordered_json::array({e.kind}));
  }
  return out;
}

int unit_exponent(Time t) {
  if (t == 0.0) return 0;
  int e = 0;
  (void)std::frexp(t, &e);
  return std::max(e - std::numeric_limits<double>::digits, -1074);
}

std::optional<std::int64_t> time_step(Time before, Time t, int q) {
  constexpr double kMaxStep = 9007199254740992.0;  // 2^53: integers up to it are exact doubles
  const double dt = std::ldexp(t - before, -q);
  if (!std::isfinite(dt) || dt != std::floor(dt) || std::fabs(dt) > kMaxStep ||
      before + std::ldexp(dt, q) != t)
    return std::nullopt;
  return static_cast<std::int64_t>(dt);
}

TraceWriter::TraceWriter(std::ostream& out, const scenario::Scenario& s, const RunOptions& options,
                         std::function<Json()> snapshot)
    : out_(out), scenario_(s), options_(options), snapshot_(std::move(snapshot)) {
  next_snapshot_ = s.start_time;
  last_time_ = s.start_time;
  for (const StructureInfo& info : structures()) {
    if (info.name == options.structure) types_ = event_types(info, s.dimension);
  }
  if (types_.empty()) types_ = event_types(StructureInfo{}, s.dimension);
}

void TraceWriter::line(const Json& j) {
  flush_events();
  out_ << j.dump() << '\n';
}

namespace {

/// The batch size at which a batch is written whatever follows (lines stay of bounded length).
constexpr std::size_t kMaxBatch = 4096;

}  // namespace

void TraceWriter::event(Time time, std::size_t type, std::span<const ObjectId> ids) {
  ++events_;
  if (events_written_ >= options_.trace_limits.max_events) return;
  ++events_written_;
  // The time: each as the one before (the first: the line before's, or the batch's own `t`)
  // plus dt * 2^q, with dt an integer of at most 2^53, exactly (a reader computes the same
  // double); a new batch when it is not one.
  if (!batch_times_.empty()) {
    const std::optional<std::int64_t> dt = time_step(batch_times_.back(), time, batch_q_);
    if (dt && batch_times_.size() < kMaxBatch) {
      batch_dt_.push_back(*dt);
    } else {
      flush_events();
    }
  }
  if (batch_times_.empty()) {
    batch_q_ = unit_exponent(last_time_);
    batch_base_.reset();
    batch_dt_ = Json::array();
    batch_kind_ = Json::array();
    batch_ids_ = Json::array();
    std::optional<std::int64_t> dt = time_step(last_time_, time, batch_q_);
    if (!dt) {  // not a step from the line before: the batch's own base
      batch_q_ = unit_exponent(time);
      batch_base_ = time;
      dt = 0;
    }
    batch_dt_.push_back(*dt);
  }
  const EventType& e = types_[type];
  if (e.kind == "swap" && ids.size() == 2) swaps_.push_back({e.axis, ids[0], ids[1]});
  batch_times_.push_back(time);
  batch_kind_.push_back(type);
  batch_ids_.push_back(Json(std::vector<ObjectId>(ids.begin(), ids.end())));
}

void TraceWriter::flush_events() {
  if (batch_times_.empty()) return;
  // The coarsest unit that every step is a multiple of (the robust scheduler's times lie on a
  // grid: far fewer digits).
  int shift = 63;
  for (const Json& dt : batch_dt_) {
    const auto v = dt.get<std::int64_t>();
    if (v != 0) shift = std::min(shift, std::countr_zero(static_cast<std::uint64_t>(v)));
  }
  if (shift == 63) shift = 0;
  if (shift > 0) {
    for (Json& dt : batch_dt_) dt = dt.get<std::int64_t>() / (std::int64_t{1} << shift);
    batch_q_ += shift;
  }
  Json j;
  j["k"] = "events";
  if (batch_base_) j["t"] = *batch_base_;
  j["q"] = batch_q_;
  j["dt"] = std::move(batch_dt_);
  j["kind"] = std::move(batch_kind_);
  j["ids"] = std::move(batch_ids_);
  last_time_ = batch_times_.back();
  batch_times_.clear();
  out_ << j.dump() << '\n';
}

void TraceWriter::header() {
  Json h;
  h["format"] = "kinetic-trace/2";
  h["structure"] = options_.structure;
  h["scheduler"] = to_string(options_.scheduler);
  if (options_.scheduler == SchedulerKind::Robust) h["eps"] = options_.eps;
  const TraceLimits& l = options_.trace_limits;
  h["limits"] = {{"max_events", l.max_events},
                 {"max_snapshots", l.max_snapshots},
                 {"max_snapshot_bytes", l.max_snapshot_bytes}};
  h["kinds"] = event_types_json(types_);
  h["scenario"] = Json::parse(scenario::write_scenario(scenario_));
  line(h);
}

void TraceWriter::logged(Time time, const char* kind, std::span<const ObjectId> ids, int axis) {
  logged_since_hook_ = true;
  for (std::size_t k = 0; k + 2 < types_.size(); ++k) {
    if (types_[k].kind == kind && types_[k].axis == (types_[k].axis < 0 ? -1 : axis)) {
      event(time, k, ids);
      return;
    }
  }
  // The structure's description lists every kind it logs (the trace's tests check it).
  throw std::logic_error(std::string("trace: the structure logged an event kind its description "
                                     "does not list: ") +
                         kind);
}

void TraceWriter::processed(Time time, EventKind kind) {
  // An event the structure logged is told by its log lines; one it did not log gets an event of
  // its own ("internal", or an external event without ids).
  const bool logged = std::exchange(logged_since_hook_, false);
  if (kind == EventKind::Internal) {
    if (!logged) event(time, types_.size() - 1, {});
    return;
  }
  if (!logged) event(time, types_.size() - 2, {});
  // Snapshots: after every external event while half the budget lasts, then sampled: the first
  // external event at or after each of the equally spaced times that the other half covers
  // from here to the window's end (every event when the window has no end).
  // The budget is max_snapshots, or fewer when whole snapshots of the size seen last would reach
  // max_snapshot_bytes first (a big structure).
  if (time >= next_snapshot_) {
    snapshot(time);
    const TraceLimits& l = options_.trace_limits;
    // (The size of a whole one: patches are small, but a reader rebuilds a whole snapshot for
    // each one it shows.)
    const std::uint64_t size = whole_bytes_;
    const std::uint64_t budget = std::min<std::uint64_t>(
        l.max_snapshots, l.max_snapshot_bytes / std::max<std::uint64_t>(1, size));
    if (2 * snapshots_ >= budget && scenario_.end_time && budget > snapshots_) {
      if (snapshot_step_ == 0.0) {
        snapshot_step_ = (*scenario_.end_time - time) / static_cast<double>(budget - snapshots_);
      }
      next_snapshot_ = time + snapshot_step_;
    } else if (2 * snapshots_ >= budget) {
      next_snapshot_ = kTimeInfinity;  // the budget is spent (or no window to spread it over)
    }
  }
}

std::size_t TraceWriter::index_of(const scenario::TimelineOp& op) const {
  // The header's scenario holds the timeline in processing order (write_scenario), and the
  // runner passes its entries: the entry's place there, which is its place in the file only when
  // the file's timeline was in time order.
  const std::vector<scenario::TimelineOp>& timeline = scenario_.timeline;
  const std::less<const scenario::TimelineOp*> before;
  if (!timeline.empty() && !before(&op, timeline.data()) &&
      before(&op, timeline.data() + timeline.size()))
    return static_cast<std::size_t>(&op - timeline.data());
  return op.file_index;
}

void TraceWriter::op(Time time, const scenario::TimelineOp& op) {
  line(Json{{"t", time},
            {"k", "op"},
            {"op", scenario::to_string(op.op)},
            {"index", index_of(op)},
            {"id", op.id}});
  last_time_ = time;
  snapshot(time);
}

void TraceWriter::query(Time time, const scenario::TimelineOp& op, const Json& answer) {
  line(Json{{"t", time},
            {"k", "query"},
            {"index", index_of(op)},
            {"type", scenario::to_string(op.query.type)},
            {"result", answer}});
  last_time_ = time;
  snapshot(time);  // the structure as the query saw it
}

namespace {

void patch_into(const TraceWriter::Json& from, const TraceWriter::Json& to, TraceWriter::Json& path,
                TraceWriter::Json& out) {
  if (from.is_object() && to.is_object() && from.size() == to.size() &&
      std::equal(from.items().begin(), from.items().end(), to.items().begin(),
                 [](const auto& a, const auto& b) { return a.key() == b.key(); })) {
    for (auto a = from.begin(), b = to.begin(); b != to.end(); ++a, ++b) {
      path.push_back(b.key());
      patch_into(*a, *b, path, out);
      path.erase(path.size() - 1);
    }
    return;
  }
  if (from.is_array() && to.is_array() && from.size() == to.size()) {
    for (std::size_t i = 0; i < to.size(); ++i) {
      path.push_back(i);
      patch_into(from[i], to[i], path, out);
      path.erase(path.size() - 1);
    }
    return;
  }
  if (from != to) out.push_back(TraceWriter::Json::array({path, to}));
}

}  // namespace

namespace {

/// The place of each id in an order's `ids`: a table by id when the ids are small (a snapshot of
/// 10^5 objects is indexed in well under a millisecond), a hash otherwise.
class Places {
 public:
  /// False when an element is not an integer id or an id is there twice.
  bool index(const nlohmann::ordered_json& ids) {
    std::int64_t max = -1;
    bool small = true;
    for (const nlohmann::ordered_json& v : ids) {
      if (!v.is_number_integer()) return false;
      const auto id = v.get<std::int64_t>();
      small = small && id >= 0;
      max = std::max(max, id);
    }
    dense_ = small && static_cast<std::uint64_t>(max) < 4 * ids.size() + 1024;
    if (dense_) table_.assign(static_cast<std::size_t>(max) + 1, kNone);
    for (std::size_t i = 0; i < ids.size(); ++i) {
      const auto id = ids[i].get<std::int64_t>();
      std::size_t& at = dense_ ? table_[static_cast<std::size_t>(id)] : hash_[id];
      if (dense_ ? at != kNone : hash_.size() != i + 1) return false;
      at = i;
    }
    indexed_ = true;
    return true;
  }
  [[nodiscard]] bool indexed() const { return indexed_; }
  /// The place of `id`, or nullptr.
  std::size_t* find(std::int64_t id) {
    if (dense_) {
      if (id < 0 || static_cast<std::uint64_t>(id) >= table_.size()) return nullptr;
      std::size_t& at = table_[static_cast<std::size_t>(id)];
      return at == kNone ? nullptr : &at;
    }
    const auto it = hash_.find(id);
    return it == hash_.end() ? nullptr : &it->second;
  }

 private:
  static constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
  bool indexed_ = false, dense_ = false;
  std::vector<std::size_t> table_;
  std::unordered_map<std::int64_t, std::size_t> hash_;
};

}  // namespace

bool apply_swaps(nlohmann::ordered_json& snapshot, std::span<const Swap> swaps) {
  if (swaps.empty()) return true;
  const auto orders = snapshot.find("orders");
  if (orders == snapshot.end() || !orders->is_array()) return false;
  // The place of each id in each order (made once per call: linear in the snapshot's size).
  std::vector<Places> places(orders->size());
  for (const Swap& s : swaps) {
    if (s.axis < 0 || static_cast<std::size_t>(s.axis) >= orders->size()) return false;
    nlohmann::ordered_json& order = (*orders)[static_cast<std::size_t>(s.axis)];
    if (!order.is_object() || !order.contains("ids") || !order["ids"].is_array()) return false;
    nlohmann::ordered_json& ids = order["ids"];
    Places& at = places[static_cast<std::size_t>(s.axis)];
    if (!at.indexed() && !at.index(ids)) return false;
    std::size_t* const a = at.find(s.a);
    std::size_t* const b = at.find(s.b);
    if (a == nullptr || b == nullptr || a == b) return false;
    std::swap(ids[*a], ids[*b]);
    std::swap(*a, *b);
  }
  return true;
}

void snapshot_patch(const nlohmann::ordered_json& from, const nlohmann::ordered_json& to,
                    nlohmann::ordered_json& out) {
  nlohmann::ordered_json path = nlohmann::ordered_json::array();
  patch_into(from, to, path, out);
}

std::optional<PatchError> apply_snapshot_patch(nlohmann::ordered_json& target,
                                               const nlohmann::ordered_json& patch) {
  if (!patch.is_array()) return PatchError{0, "the patch is not an array of [path, value] pairs"};
  for (std::size_t k = 0; k < patch.size(); ++k) {
    const nlohmann::ordered_json& entry = patch[k];
    if (!entry.is_array() || entry.size() != 2 || !entry[0].is_array())
      return PatchError{k, "expected [path, value], the path an array of keys and indices"};
    nlohmann::ordered_json* at = &target;
    for (const nlohmann::ordered_json& step : entry[0]) {
      if (step.is_string() && at->is_object()) {
        const auto it = at->find(step.get<std::string>());
        if (it == at->end()) return PatchError{k, "the path names no key " + step.dump()};
        at = &*it;
      } else if (step.is_number_unsigned() && at->is_array()) {
        const auto i = step.get<std::size_t>();
        if (i >= at->size())
          return PatchError{k, "the path's index " + step.dump() + " is past the array's " +
                                   std::to_string(at->size()) + " elements"};
        at = &(*at)[i];
      } else {
        return PatchError{k, "the path's step " + step.dump() + " names nothing in a " +
                                 std::string(at->type_name())};
      }
    }
    *at = entry[1];
  }
  return std::nullopt;
}

void TraceWriter::snapshot(Time time) {
  const TraceLimits& l = options_.trace_limits;
  if (snapshots_ >= l.max_snapshots || snapshot_bytes_ >= l.max_snapshot_bytes) {
    ++snapshots_skipped_;
    return;
  }
  flush_events();
  Json j;
  j["k"] = "snapshot";
  // The time and the events processed before it: left out when they are the line before's
  // time and the events written (no event left out).
  if (time != last_time_ || events_ != events_written_) {
    j["t"] = time;
    j["event"] = events_;
  }
  Json now = snapshot_();
  // A patch against the snapshot before with the swaps since applied, while the patches and
  // swaps since the last whole one stay below four times its size (8 bytes a swap: a reader
  // rebuilds any snapshot from the last whole one in time linear in its size).
  bool whole = true;
  if (have_previous_ && apply_swaps(previous_, swaps_)) {
    Json patch = Json::array();
    snapshot_patch(previous_, now, patch);
    const std::uint64_t bytes = patch.dump().size() + 8 * swaps_.size();
    if (patch_bytes_ + bytes < 4 * whole_bytes_) {
      j["patch"] = std::move(patch);
      patch_bytes_ += bytes;
      whole = false;
    }
  }
  swaps_.clear();
  if (whole) j["snapshot"] = now;
  const std::string text = j.dump();
  if (whole) {
    whole_bytes_ = text.size();
    patch_bytes_ = 0;
  }
  previous_ = std::move(now);
  have_previous_ = true;
  last_time_ = time;
  snapshot_bytes_ += text.size();
  ++snapshots_;
  out_ << text << '\n';
}

void TraceWriter::end(Time time, const RunResult& result) {
  Json j;
  j["t"] = time;
  j["k"] = "end";
  j["outcome"] = to_string(result.outcome);
  if (!result.message.empty()) j["message"] = result.message;
  j["events"] = {{"processed", events_},
                 {"written", events_written_},
                 {"left_out", events_ - events_written_}};
  j["snapshots"] = {{"written", snapshots_}, {"left_out", snapshots_skipped_}};
  line(j);
  out_.flush();
}

}  // namespace kinetic::run::detail
