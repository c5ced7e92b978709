#pragma once
// The trace of a run (`kinetic run --trace`, format kinetic-trace/2, docs/trace-format.md): one
// JSON line per thing a replay needs -- the header with the scenario (every motion), the events
// processed (in batches: a line of columns per run of events between two other lines; external
// ones with their kind and ids, internal ones with their time), each timeline op and query
// answer, and snapshots of the structure a picture needs, sampled so that a big run stays usable
// (TraceLimits). Private to the run layer; the runner drives it.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "kinetic/core/ids.hpp"
#include "kinetic/core/structure.hpp"
#include "kinetic/run/runner.hpp"
#include "kinetic/scenario/scenario.hpp"

namespace kinetic::run::detail {

/// An event's type, a place in the header's `kinds` (docs/trace-format.md): a kind of the
/// structure, with its axis for the kinds of one axis (`swap`, `max_change`, `min_change`: one
/// type per axis), then "external" (an event the structure did not log) and "internal".
struct EventType {
  std::string kind;
  int axis = -1;
};
/// The types of a structure's events in a scenario of `dimension` axes, in the header's order.
[[nodiscard]] std::vector<EventType> event_types(const StructureInfo& structure, int dimension);
/// The header's `kinds`: [kind] or [kind, axis] each.
[[nodiscard]] nlohmann::ordered_json event_types_json(const std::vector<EventType>& types);

/// The exponent q of the unit 2^q of a batch's time steps at `t` (0 for 0): the spacing of the
/// doubles at t, so that every time not below t's magnitude is a multiple of 2^q.
[[nodiscard]] int unit_exponent(Time t);
/// The integer dt, of magnitude at most 2^53, with before + dt * 2^q == t in doubles (exactly t),
/// or none.
[[nodiscard]] std::optional<std::int64_t> time_step(Time before, Time t, int q);

/// A swap event: ids `a` and `b` exchange their places in the order of `axis`.
struct Swap {
  int axis = 0;
  ObjectId a = 0, b = 0;
};

class TraceWriter {
 public:
  using Json = nlohmann::ordered_json;
  /// `snapshot` returns the structure's snapshot now (an object; empty when it has none).
  TraceWriter(std::ostream& out, const scenario::Scenario& s, const RunOptions& options,
              std::function<Json()> snapshot);

  /// The header: format, structure, scheduler, the limits and the whole scenario.
  void header();
  /// An external event the structure logged (Simulator::EventLog).
  void logged(Time time, const char* kind, std::span<const ObjectId> ids, int axis);
  /// Every event processed (Simulator::EventHook): one the structure logged is told by its log
  /// lines; an internal one it did not log gets an "internal" line, an external one an "event"
  /// line without ids; a snapshot follows an external event when one is due.
  void processed(Time time, EventKind kind);
  /// A timeline change, after it was applied (the op itself is the header's timeline entry).
  void op(Time time, const scenario::TimelineOp& op);
  /// A query's answer (as `kinetic run` writes it).
  void query(Time time, const scenario::TimelineOp& op, const Json& answer);
  /// A snapshot now, whatever the sampling says (the start, after each change), within the
  /// byte budget.
  void snapshot(Time time);
  /// The last line: how the run ended and what the limits left out.
  void end(Time time, const RunResult& result);

 private:
  /// A line other than an event batch: the batch of events before it is written first.
  void line(const Json& j);
  /// A timeline entry's `index`: its place in the header's scenario's timeline.
  [[nodiscard]] std::size_t index_of(const scenario::TimelineOp& op) const;
  /// An event (its type's place in the header's `kinds`, its ids) into the batch, within the
  /// event limit.
  void event(Time time, std::size_t type, std::span<const ObjectId> ids);
  /// Writes the batch of events (an "events" line), if any.
  void flush_events();

  std::ostream& out_;
  const scenario::Scenario& scenario_;
  const RunOptions& options_;
  std::function<Json()> snapshot_;
  /// The header's `kinds` (event_types).
  std::vector<EventType> types_;
  /// The batch of events not written yet: their times (the line's `t` when not the line
  /// before's, `q` and `dt`) and columns.
  std::vector<Time> batch_times_;
  std::optional<Time> batch_base_;
  int batch_q_ = 0;
  Json batch_dt_, batch_kind_, batch_ids_;
  /// The swap events written since the last snapshot line (a patch applies to the snapshot
  /// before with them applied).
  std::vector<Swap> swaps_;
  /// The time of the last line written (a snapshot at it leaves its `t` out).
  Time last_time_ = 0.0;
  bool logged_since_hook_ = false;
  std::uint64_t events_ = 0, events_written_ = 0;
  std::uint64_t snapshots_ = 0, snapshots_skipped_ = 0, snapshot_bytes_ = 0;
  Time next_snapshot_ = 0.0, snapshot_step_ = 0.0;
  /// The last snapshot written (a patch is against it), the size of the last whole one and the
  /// bytes of the patches written since: a whole snapshot again once they would reach four
  /// times it.
  Json previous_;
  bool have_previous_ = false;
  std::uint64_t whole_bytes_ = 0, patch_bytes_ = 0;
};

/// Applies swap events to a snapshot's `orders` (kinetic-trace/2, "Patches"): each exchanges its
/// two ids in the `ids` of its axis's order. Returns false, leaving `snapshot` partly changed,
/// when a swap names an order or an id the snapshot does not have (nothing to do for no swaps).
[[nodiscard]] bool apply_swaps(nlohmann::ordered_json& snapshot, std::span<const Swap> swaps);

/// The changes that make `from` into `to`, appended to `out` as [path, value] pairs (path: the
/// keys and indices from the snapshot's root): objects with the same keys in the same order are
/// compared key by key, arrays of one length element by element, anything else is replaced
/// whole. Applied in order to `from` they give `to` (apply_snapshot_patch).
void snapshot_patch(const nlohmann::ordered_json& from, const nlohmann::ordered_json& to,
                    nlohmann::ordered_json& out);

/// Why a snapshot patch cannot apply: the entry (its index in the patch) and what is wrong.
struct PatchError {
  std::size_t entry = 0;
  std::string what;
};
/// Applies a patch (snapshot_patch's [path, value] pairs, in order) to `target`: each path's
/// keys must name keys `target` has, its indices elements it has; an empty path replaces the
/// whole. Returns what is wrong, leaving `target` partly patched, or nothing.
[[nodiscard]] std::optional<PatchError> apply_snapshot_patch(nlohmann::ordered_json& target,
                                                             const nlohmann::ordered_json& patch);

}  // namespace kinetic::run::detail
