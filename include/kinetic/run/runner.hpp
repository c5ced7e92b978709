#pragma once
// Runs a scenario through a named structure: builds its session, plays the timeline in order
// (advance to each entry's time, then apply it or answer it), writes one JSON line per query
// and collects the run's figures. Used by the command line, the tests and the experiments.

#include <atomic>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "kinetic/core/counters.hpp"
#include "kinetic/core/description.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/structure.hpp"
#include "kinetic/scenario/scenario.hpp"

namespace kinetic::run {

/// A structure this build offers: its description (core/description.hpp), as the runner and the CLI
/// read it.
using StructureInfo = StructureDescription;

/// The structures built, in the order `kinetic run --help` lists them.
[[nodiscard]] const std::vector<StructureInfo>& structures();

/// What a trace (`kinetic run --trace`) keeps of a long run (docs/trace-format.md): events
/// beyond max_events are counted, not written; snapshots are sampled (max_snapshots over the
/// window) and stop at max_snapshot_bytes. The last line says what was left out.
struct TraceLimits {
  std::uint64_t max_events = 1'000'000;
  std::uint64_t max_snapshots = 2'000;
  std::uint64_t max_snapshot_bytes = std::uint64_t{64} << 20;
};

struct RunOptions {
  std::string structure;  ///< a registered structure's name (`kinetic run --help` lists them)
  SchedulerKind scheduler = SchedulerKind::Robust;
  double eps = 1e-9;
  /// A progress bar on standard error (for long runs).
  bool progress = false;
  /// Test mode: check the structure's invariants (validate()) after every event and op.
  bool validate_every_event = false;
  /// Robust scheduling: measure every event's delay t_pr - t_ex (costs ~30 exact signs/event).
  bool measure_delays = false;
  /// Log every external event (`kinetic run --events`): check_runnable refuses a structure that
  /// does not log its events; run() writes them to its `events` stream.
  bool log_events = false;
  /// When it becomes true (a signal handler sets it), the run stops between two events with
  /// outcome Interrupted: the answers so far are written, the stats tell the time reached.
  const std::atomic<bool>* interrupt = nullptr;
  /// The limits of the trace, when run() is given a trace stream.
  TraceLimits trace_limits;
};

/// The request cannot be run (unknown structure, unsupported query type or scheduler, wrong kind
/// of objects). One line, naming the file and the JSON path where it applies. Exit status 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class RunOutcome {
  Completed,
  LoopGuard,     ///< stopped: the scheduling looped at one instant
  EventBudget,   ///< stopped: more events than a correct run can have
  InvalidState,  ///< test mode only: validate() failed
  Interrupted,   ///< RunOptions::interrupt was raised
};
[[nodiscard]] const char* to_string(RunOutcome outcome);

struct RunStats {
  std::size_t objects_initial = 0;
  std::size_t queries = 0;
  Counters counters;
  std::uint64_t queue_max = 0;
  double wall_seconds = 0.0;
  Time final_time = 0.0;
  /// The structure's own counters at the end of the run, by name (e.g. its events by kind and
  /// its node visits per query); empty for structures that have none beyond Counters.
  NamedCounters structure_counters;
};

struct RunResult {
  RunOutcome outcome = RunOutcome::Completed;
  std::string message;  ///< why the run stopped early, when it did
  RunStats stats;
};

/// The scheduler a structure runs `s` on when none is asked for (CONTRACTS.md: robust wherever
/// robust is offered, otherwise the one it takes, never a refusal for a missing option): robust
/// when the structure takes it and takes every motion of `s` under it (e.g. the Delaunay
/// triangulation takes points on lines under robust), otherwise exact where the structure takes
/// it, otherwise classic. An unknown structure gets robust (check_runnable names the error).
[[nodiscard]] SchedulerKind default_scheduler(const scenario::Scenario& s,
                                              const std::string& structure);
/// The same rule for motions of degree at most `max_degree` (a session's objects): robust when
/// the structure takes it at that degree, otherwise exact where it takes exact, otherwise
/// classic.
[[nodiscard]] SchedulerKind default_scheduler(const StructureInfo& structure, int max_degree);

/// Throws UsageError when `options` cannot run `s` (checked before anything runs).
void check_runnable(const scenario::Scenario& s, const RunOptions& options,
                    const std::string& file_name);

/// Runs the scenario; answers go to `answers` as JSON lines in timeline order; with
/// options.log_events, every external event goes to `events` as it is processed, one JSON line
/// each: {"time": t, "kind": "...", "ids": [...]}; with `trace`, the run's trace goes there
/// (kinetic-trace/2, docs/trace-format.md). Precondition: check_runnable passed.
RunResult run(const scenario::Scenario& s, const RunOptions& options, std::ostream& answers,
              std::ostream* events = nullptr, std::ostream* trace = nullptr);

/// The counters as one JSON object: events, certificates, root isolations, predicates, the
/// scheduler's own figures (crop / exact; delays where measured) and the structure's counters by
/// name. The fields of the `--stats` file that count, and the Python module's `counters()`.
[[nodiscard]] std::string counters_json(const Counters& counters,
                                        const NamedCounters& structure_counters,
                                        SchedulerKind scheduler, double eps);

/// The run's figures as a JSON document (the `--stats` file).
[[nodiscard]] std::string stats_json(const RunResult& result, const RunOptions& options);

}  // namespace kinetic::run
