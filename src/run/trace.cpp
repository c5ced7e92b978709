#include "trace.hpp"

#include <algorithm>
#include <functional>
#include <ostream>
#include <vector>

#include "kinetic/scenario/scenario_json.hpp"

namespace kinetic::run::detail {

TraceWriter::TraceWriter(std::ostream& out, const scenario::Scenario& s, const RunOptions& options,
                         std::function<Json()> snapshot)
    : out_(out), scenario_(s), options_(options), snapshot_(std::move(snapshot)) {
  next_snapshot_ = s.start_time;
}

void TraceWriter::line(const Json& j) { out_ << j.dump() << '\n'; }

void TraceWriter::header() {
  Json h;
  h["format"] = "kinetic-trace/1";
  h["structure"] = options_.structure;
  h["scheduler"] = to_string(options_.scheduler);
  if (options_.scheduler == SchedulerKind::Robust) h["eps"] = options_.eps;
  const TraceLimits& l = options_.trace_limits;
  h["limits"] = {{"max_events", l.max_events},
                 {"max_snapshots", l.max_snapshots},
                 {"max_snapshot_bytes", l.max_snapshot_bytes}};
  h["scenario"] = Json::parse(scenario::write_scenario(scenario_));
  line(h);
}

void TraceWriter::event_line(Json j) {
  ++events_;
  if (events_written_ >= options_.trace_limits.max_events) return;
  ++events_written_;
  line(j);
}

void TraceWriter::logged(Time time, const char* kind, std::span<const ObjectId> ids, int axis) {
  logged_since_hook_ = true;
  Json j;
  j["t"] = time;
  j["k"] = "event";
  j["kind"] = kind;
  j["ids"] = Json(std::vector<ObjectId>(ids.begin(), ids.end()));
  if (axis >= 0) j["axis"] = axis;
  event_line(std::move(j));
}

void TraceWriter::processed(Time time, EventKind kind) {
  // An event the structure logged is told by its log lines; one it did not log gets a line of
  // its own ("internal", or an external event without ids).
  const bool logged = std::exchange(logged_since_hook_, false);
  if (kind == EventKind::Internal) {
    if (!logged) event_line(Json{{"t", time}, {"k", "internal"}});
    return;
  }
  if (!logged) {
    event_line(Json{{"t", time}, {"k", "event"}, {"kind", "external"}, {"ids", Json::array()}});
  }
  // Snapshots: after every external event while half the budget lasts, then sampled: the first
  // external event at or after each of the equally spaced times that the other half covers
  // from here to the window's end (every event when the window has no end).
  // The budget is max_snapshots, or fewer when snapshots of the size seen so far would reach
  // max_snapshot_bytes first (a big structure).
  if (time >= next_snapshot_) {
    snapshot(time);
    const TraceLimits& l = options_.trace_limits;
    const std::uint64_t size = snapshot_bytes_ / std::max<std::uint64_t>(1, snapshots_);
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
  snapshot(time);
}

void TraceWriter::query(Time time, const scenario::TimelineOp& op, const Json& answer) {
  line(Json{{"t", time},
            {"k", "query"},
            {"index", index_of(op)},
            {"type", scenario::to_string(op.query.type)},
            {"result", answer}});
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
  Json j;
  j["t"] = time;
  j["k"] = "snapshot";
  j["event"] = events_;  // the events processed before it
  Json now = snapshot_();
  // A patch against the previous snapshot while the patches since the last whole one stay below
  // four times its size (a replay rebuilds any snapshot from the last whole one in linear time).
  bool whole = true;
  if (have_previous_) {
    Json patch = Json::array();
    snapshot_patch(previous_, now, patch);
    const std::size_t bytes = patch.dump().size();
    if (patch_bytes_ + bytes < 4 * whole_bytes_) {
      j["patch"] = std::move(patch);
      patch_bytes_ += bytes;
      whole = false;
    }
  }
  if (whole) j["snapshot"] = now;
  const std::string text = j.dump();
  if (whole) {
    whole_bytes_ = text.size();
    patch_bytes_ = 0;
  }
  previous_ = std::move(now);
  have_previous_ = true;
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
