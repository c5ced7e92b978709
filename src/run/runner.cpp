#include "kinetic/run/runner.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <sstream>
#include <vector>

#include "kinetic/core/exact_time.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/core/spelling.hpp"
#include "kinetic/run/timeline_driver.hpp"
#include "registry.hpp"
#include "trace.hpp"

namespace kinetic::run {

using scenario::QueryType;
using Json = nlohmann::ordered_json;

namespace {

/// The progress bar on standard error: the share of simulated time done, the events per second
/// and the time left (from the wall time per unit of simulated time so far). Redrawn at most
/// five times a second, and once at the end.
class Progress {
 public:
  using Clock = std::chrono::steady_clock;
  Progress(bool enabled, Time start, Time end)
      : enabled_(enabled), start_(start), end_(end), began_(Clock::now()) {}
  void show(Time t, std::uint64_t events, bool final = false) {
    if (!enabled_) return;
    const Clock::time_point now = Clock::now();
    if (!final && drawn_ && now - last_ < std::chrono::milliseconds(200)) return;
    drawn_ = true;
    last_ = now;
    const double f = end_ > start_ ? std::clamp((t - start_) / (end_ - start_), 0.0, 1.0) : 1.0;
    const double seconds = std::chrono::duration<double>(now - began_).count();
    const int width = 30;
    const int filled = static_cast<int>(f * width);
    std::ostringstream line;
    line.precision(3);
    line << "\r[" << std::string(static_cast<std::size_t>(filled), '#')
         << std::string(static_cast<std::size_t>(width - filled), ' ') << "] "
         << static_cast<int>(f * 100.0) << "%  t=" << t << "  events=" << events;
    if (seconds > 0.0) line << "  " << static_cast<double>(events) / seconds << " events/s";
    if (final) {
      line << "  in " << seconds << " s";
    } else if (f > 0.0) {
      line << "  about " << static_cast<long long>(seconds * (1.0 - f) / f + 0.5) << " s left";
    }
    line << "   ";  // clears the tail of a longer previous line
    std::cerr << line.str() << std::flush;
  }
  /// Counts the wall time from now (after the structure's build).
  void restart() { began_ = Clock::now(); }
  void done() {
    if (enabled_ && drawn_) std::cerr << "\n";
  }

 private:
  bool enabled_;
  Time start_, end_;
  Clock::time_point began_, last_{};
  bool drawn_ = false;
};

/// Where the external events go: the event log (`kinetic run --events`, one JSON line each)
/// and the trace.
struct EventSinks {
  std::ostream* events = nullptr;
  detail::TraceWriter* trace = nullptr;
};

void write_event(void* context, Time time, const char* kind, std::span<const ObjectId> ids,
                 int axis) {
  const EventSinks& sinks = *static_cast<const EventSinks*>(context);
  if (sinks.events != nullptr) {
    Json line;
    line["time"] = time;
    line["kind"] = kind;
    line["ids"] = Json(std::vector<ObjectId>(ids.begin(), ids.end()));
    if (axis >= 0) line["axis"] = axis;
    *sinks.events << line.dump() << '\n';
  }
  if (sinks.trace != nullptr) sinks.trace->logged(time, kind, ids, axis);
}

void trace_event(void* context, Time time, EventKind kind) {
  static_cast<detail::TraceWriter*>(context)->processed(time, kind);
}

}  // namespace

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
    case RunOutcome::Interrupted:
      return "interrupted";
  }
  return "?";
}

SchedulerKind default_scheduler(const StructureInfo& info, int max_degree) {
  const auto takes = [&](SchedulerKind k) {
    return info.schedulers.empty() ||
           std::find(info.schedulers.begin(), info.schedulers.end(), k) != info.schedulers.end();
  };
  if (takes(SchedulerKind::Robust) &&
      (info.robust_max_degree < 0 || max_degree <= info.robust_max_degree)) {
    return SchedulerKind::Robust;
  }
  return takes(SchedulerKind::Exact) ? SchedulerKind::Exact : SchedulerKind::Classic;
}

SchedulerKind default_scheduler(const scenario::Scenario& s, const std::string& structure) {
  const detail::StructureDescriptor* descriptor = detail::find(structure);
  if (descriptor == nullptr) return SchedulerKind::Robust;
  int degree = 0;
  for (const scenario::ObjectSpec& o : s.objects) degree = std::max(degree, degree_of(o.motion));
  for (const scenario::TimelineOp& op : s.timeline) {
    if (op.op == scenario::OpKind::Insert || op.op == scenario::OpKind::Update)
      degree = std::max(degree, degree_of(op.motion));
  }
  return default_scheduler(descriptor->info, degree);
}

void check_runnable(const scenario::Scenario& s, const RunOptions& options,
                    const std::string& file_name) {
  const detail::StructureDescriptor* descriptor = detail::find(options.structure);
  if (descriptor == nullptr) {
    std::string names;
    std::vector<std::string> all;
    for (const StructureInfo& b : structures()) {
      names += (names.empty() ? "" : ", ") + b.name;
      all.push_back(b.name);
    }
    const std::string guess = closest_name(options.structure, all);
    throw UsageError("unknown structure '" + options.structure + "'" +
                     (guess.empty() ? "" : " (did you mean " + guess + "?)") + "; built: " + names);
  }
  const StructureInfo* info = &descriptor->info;
  if (options.log_events && info->event_kinds.empty()) {
    std::string names;
    for (const StructureInfo& b : structures()) {
      if (!b.event_kinds.empty()) names += (names.empty() ? "" : ", ") + b.name;
    }
    throw UsageError("--events: structure " + info->name +
                     " does not log its events yet (structures that do: " + names + ")");
  }
  if (!info->schedulers.empty() && std::find(info->schedulers.begin(), info->schedulers.end(),
                                             options.scheduler) == info->schedulers.end()) {
    std::string names;
    for (const SchedulerKind k : info->schedulers)
      names += (names.empty() ? "" : ", ") + std::string(to_string(k));
    throw UsageError("--scheduler " + std::string(to_string(options.scheduler)) + ": structure " +
                     info->name + " takes --scheduler " + names +
                     (info->scheduler_note.empty() ? "" : " (" + info->scheduler_note + ")"));
  }
  if (!(options.eps > 0.0) || !std::isfinite(options.eps)) {
    throw UsageError("--eps must be a positive finite number");
  }
  if (options.scheduler == SchedulerKind::Robust && !Scheduler::eps_supported(options.eps)) {
    std::ostringstream msg;
    msg << "--eps " << options.eps << " is larger than robust scheduling takes (at most "
        << Scheduler::kMaxEps << ")";
    throw UsageError(msg.str());
  }
  if (options.scheduler == SchedulerKind::Robust) {
    // The times the scenario names: its window, or its start and last timeline entry.
    const Time last =
        s.end_time.value_or(s.timeline.empty() ? s.start_time : s.timeline.back().time);
    const Time reach = Scheduler::max_supported_time(options.eps);
    if (std::max(std::fabs(s.start_time), std::fabs(last)) > reach) {
      // Checked before the run: robust scheduling finds no event beyond its horizon, so answers
      // there would be stale.
      std::ostringstream msg;
      msg << file_name << ": $." << (s.end_time ? "end_time" : "timeline")
          << ": the scenario's times [" << s.start_time << ", " << last
          << "] reach beyond robust scheduling's horizon at --eps " << options.eps
          << " (|t| <= " << reach
          << "); use a larger --eps, times nearer to 0, or --scheduler classic or exact";
      throw UsageError(msg.str());
    }
    if (!Scheduler::precision_supported(options.eps, s.start_time, last)) {
      std::ostringstream msg;
      msg << "--eps " << options.eps << " is finer than doubles resolve on the scenario's times ["
          << s.start_time << ", " << last << "]; use a larger --eps or times nearer to 0";
      throw UsageError(msg.str());
    }
  }
  if (s.dimension < info->min_dimension || s.dimension > info->max_dimension) {
    std::string supported = info->min_dimension == info->max_dimension
                                ? "dimension " + std::to_string(info->min_dimension) + " only"
                            : info->min_dimension <= 1
                                ? "dimensions up to " + std::to_string(info->max_dimension)
                                : "dimensions " + std::to_string(info->min_dimension) + " to " +
                                      std::to_string(info->max_dimension);
    if (!info->dimension_note.empty()) supported += " (" + info->dimension_note + ")";
    throw UsageError(file_name + ": $.dimension: structure " + info->name + " supports " +
                     supported + ", got " + std::to_string(s.dimension));
  }
  if (s.objects_are != info->objects) {
    throw UsageError(file_name + ": $.objects_are: structure " + info->name + " expects \"" +
                     scenario::to_string(info->objects) + "\", got \"" +
                     scenario::to_string(s.objects_are) + "\"");
  }
  const auto require_degree = [&](const scenario::Motion& m, const std::string& path) {
    const int degree = degree_of(m);
    const bool robust = options.scheduler == SchedulerKind::Robust && info->robust_max_degree >= 0;
    const int limit = robust ? info->robust_max_degree : info->max_degree;
    if (degree <= limit) return;
    const std::string& note = robust ? info->robust_degree_note : info->degree_note;
    std::string why = note.empty() ? "" : " (" + note + ")";
    throw UsageError(file_name + ": " + path + ": structure " + info->name +
                     " takes motions of degree <= " + std::to_string(limit) +
                     (robust ? " under --scheduler robust" : "") + why + ", got degree " +
                     std::to_string(degree));
  };
  const auto require_magnitude = [&](const scenario::Motion& m, const std::string& path) {
    if (info->magnitude_log2 <= 0) return;
    for (std::size_t axis = 0; axis < m.coordinates.size(); ++axis) {
      const std::optional<long> e = magnitude_beyond(
          MotionPolynomial::from(m.coordinates[axis], m.origin), info->magnitude_log2);
      if (!e) continue;
      const std::string bound = std::to_string(info->magnitude_log2);
      std::ostringstream range;
      range.precision(2);
      range << std::ldexp(1.0, -info->magnitude_log2) << " to "
            << std::ldexp(1.0, info->magnitude_log2);
      throw UsageError(file_name + ": " + path + "[" + std::to_string(axis) + "]: structure " +
                       info->name +
                       " takes motion coefficients (expanded about t = 0) of "
                       "magnitude 2^-" +
                       bound + " <= |c| < 2^" + bound + ", about " + range.str() + ", or 0 (" +
                       info->magnitude_note + "); got 2^" + std::to_string(*e) +
                       "; rescale the units or write negligible coefficients as 0");
    }
  };
  const auto require_coefficients = [&](const scenario::Motion& m, const std::string& path) {
    if (info->coefficient_log2 <= 0) return;
    const double limit = std::ldexp(1.0, info->coefficient_log2);
    for (std::size_t axis = 0; axis < m.coordinates.size(); ++axis) {
      for (std::size_t k = 0; k < m.coordinates[axis].size(); ++k) {
        const double c = m.coordinates[axis][k];
        if (std::fabs(c) < limit) continue;
        throw UsageError(file_name + ": " + path + "[" + std::to_string(axis) + "][" +
                         std::to_string(k) + "]: structure " + info->name +
                         " takes motion coefficients of magnitude < 2^" +
                         std::to_string(info->coefficient_log2) + " (" + info->coefficient_note +
                         "); got 2^" + std::to_string(std::ilogb(c)));
      }
    }
  };
  for (std::size_t i = 0; i < s.objects.size(); ++i) {
    const std::string path = "$.objects[" + std::to_string(i) + "].motion";
    require_degree(s.objects[i].motion, path);
    require_magnitude(s.objects[i].motion, path);
    require_coefficients(s.objects[i].motion, path);
  }
  for (const scenario::TimelineOp& op : s.timeline) {
    if (op.op == scenario::OpKind::Insert || op.op == scenario::OpKind::Update) {
      const std::string path = "$.timeline[" + std::to_string(op.file_index) + "].motion";
      require_degree(op.motion, path);
      require_magnitude(op.motion, path);
      require_coefficients(op.motion, path);
    }
  }
  for (const scenario::TimelineOp& op : s.timeline) {
    if (op.op != scenario::OpKind::Query) continue;
    if (std::find(info->queries.begin(), info->queries.end(), op.query.type) ==
        info->queries.end()) {
      std::string names;
      for (QueryType q : info->queries)
        names += std::string(names.empty() ? "" : ", ") + scenario::to_string(q);
      std::string others;
      for (const StructureInfo& b : structures()) {  // those that take this scenario's objects
        if (std::find(b.queries.begin(), b.queries.end(), op.query.type) != b.queries.end() &&
            b.objects == s.objects_are && s.dimension >= b.min_dimension &&
            s.dimension <= b.max_dimension)
          others += (others.empty() ? "" : ", ") + b.name;
      }
      throw UsageError(file_name + ": $.timeline[" + std::to_string(op.file_index) +
                       "].query.type: structure " + info->name + " answers " + names + "; got \"" +
                       scenario::to_string(op.query.type) + "\"" +
                       (others.empty() ? std::string(" (no structure answers it on these objects)")
                                       : " (answered by --structure " + others + ")"));
    }
  }
}

namespace {

/// What the runner does at the points of a play: validate, answer and log queries, trace,
/// move the progress bar.
class Runner final : public detail::RunHooks {
 public:
  Runner(const RunOptions& options, detail::StructureAdapter& structure, std::ostream& answers,
         detail::TraceWriter* tracer, Progress& progress, RunResult& result)
      : options_(options),
        structure_(structure),
        answers_(answers),
        tracer_(tracer),
        progress_(progress),
        result_(result) {}

  bool each_event() const override { return options_.validate_every_event; }
  int slices() const override { return options_.progress ? 200 : 1; }
  bool event() override { return valid_now(); }
  bool advanced() override { return valid_now(); }
  bool query(const scenario::TimelineOp& op) override {
    Json line;
    line["time"] = op.time;
    line["type"] = scenario::to_string(op.query.type);
    line["result"] = structure_.answer(op.query);
    answers_ << line.dump() << '\n';
    if (tracer_ != nullptr) tracer_->query(sim().now(), op, line["result"]);
    ++result_.stats.queries;
    return after_entry(op);
  }
  bool change(const scenario::TimelineOp& op) override {
    if (tracer_ != nullptr) tracer_->op(sim().now(), op);
    return after_entry(op);
  }
  void progress() override { progress_.show(sim().now(), sim().counters().events()); }

  /// The run's outcome for an advance that did not reach its time (a guard, an interrupt).
  void stopped_by(AdvanceOutcome o) {
    const GuardReport& g = sim().guard_report();
    std::ostringstream msg;
    msg.precision(17);
    if (o == AdvanceOutcome::Interrupted) {
      result_.outcome = RunOutcome::Interrupted;
      msg << "interrupted at t=" << sim().now() << " after " << sim().counters().events()
          << " events";
    } else if (o == AdvanceOutcome::LoopGuard) {
      result_.outcome = RunOutcome::LoopGuard;
      msg << "the " << to_string(options_.scheduler) << " scheduler looped: " << g.events_at_instant
          << " events at t=" << g.time
          << " without time advancing (more than a correct run can have at one "
          << "instant); stopped by the loop guard";
    } else {
      result_.outcome = RunOutcome::EventBudget;
      msg << "the " << to_string(options_.scheduler) << " scheduler processed " << g.events_total
          << " events by t=" << g.time
          << ", more than a correct run can have; stopped by the event guard";
    }
    result_.message = msg.str();
  }

 private:
  Simulator& sim() { return structure_.sim(); }
  /// Validates after an event or an advance when validating every event.
  bool valid_now() {
    return valid([&] { return "validate() failed at t=" + std::to_string(sim().now()); });
  }
  /// Validates after a timeline entry when validating every event.
  bool after_entry(const scenario::TimelineOp& op) {
    return valid(
        [&] { return "validate() failed after timeline entry " + std::to_string(op.file_index); });
  }
  template <class Message>
  bool valid(Message&& message) {
    if (!options_.validate_every_event || structure_.validate()) return true;
    result_.outcome = RunOutcome::InvalidState;
    result_.message = message();
    return false;
  }

  const RunOptions& options_;
  detail::StructureAdapter& structure_;
  std::ostream& answers_;
  detail::TraceWriter* tracer_;
  Progress& progress_;
  RunResult& result_;
};

}  // namespace

RunResult run(const scenario::Scenario& s, const RunOptions& options, std::ostream& answers,
              std::ostream* events, std::ostream* trace) {
  const auto wall_start = std::chrono::steady_clock::now();
  RunResult result;
  const std::unique_ptr<detail::StructureAdapter> structure =
      detail::find(options.structure)->make(s, options.scheduler, options.eps);
  Simulator& sim = structure->sim();
  structure->set_measure_delays(options.measure_delays);
  structure->set_guard(structure->guard(bounds_of(s)));
  sim.set_interrupt(options.interrupt);
  std::optional<detail::TraceWriter> tracer;
  if (trace != nullptr) {
    tracer.emplace(*trace, s, options, [&structure] { return structure->snapshot(); });
    tracer->header();
    sim.set_event_hook(trace_event, &*tracer);
  }
  EventSinks sinks{options.log_events ? events : nullptr, tracer ? &*tracer : nullptr};
  if (sinks.events != nullptr || sinks.trace != nullptr) sim.set_event_log(write_event, &sinks);
  // SIGINT and SIGTERM stop the exact arithmetic too (a decision at extreme magnitudes may take
  // long): it throws ExactInterrupted, and the run stops where it was.
  const ExactInterruptScope exact_interrupt(options.interrupt);
  Progress progress(options.progress, s.start_time, end_of(s));
  Runner runner(options, *structure, answers, tracer ? &*tracer : nullptr, progress, result);
  result.stats.objects_initial = s.objects.size();
  try {
    structure->initialize();
    if (tracer) tracer->snapshot(sim.now());
    progress.restart();  // the bar times the events, not the build
    const PlayResult played = structure->play(runner);
    if (played.outcome != AdvanceOutcome::Reached) runner.stopped_by(played.outcome);
  } catch (const ExactInterrupted&) {
    runner.stopped_by(AdvanceOutcome::Interrupted);
  }
  progress.show(sim.now(), sim.counters().events(), /*final=*/true);
  progress.done();
  answers.flush();
  if (events != nullptr) events->flush();

  structure->note_measures();
  result.stats.counters = sim.counters();
  result.stats.queue_max = sim.queue().max_size();
  result.stats.final_time = sim.now();
  result.stats.structure_counters = structure->counters();
  result.stats.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  if (tracer) tracer->end(sim.now(), result);
  return result;
}

namespace {

Json counters_object(const Counters& c, const NamedCounters& structure_counters,
                     SchedulerKind scheduler, double eps, bool delays) {
  Json j = Json::object();
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
  if (scheduler == SchedulerKind::Robust) {
    j["crop"] = {{"calls", c.crop.calls},
                 {"bernstein_boxes", c.crop.bernstein_boxes},
                 {"fast_path", c.crop.fast_path},
                 {"bounded_float", c.crop.bounded_float},
                 {"exact_boxes", c.crop.exact_boxes}};
  }
  if (scheduler == SchedulerKind::Classic) j["classic_exact_fallbacks"] = c.classic_exact_fallbacks;
  if (scheduler == SchedulerKind::Exact) {
    const auto share = [](std::uint64_t part, std::uint64_t whole) {
      return whole == 0 ? 0.0 : static_cast<double>(part) / static_cast<double>(whole);
    };
    j["exact"] = {{"equal_time_groups", c.equal_time_groups},
                  {"comparisons", c.exact_comparisons},
                  {"comparisons_gmp", c.exact_comparisons_gmp},
                  {"comparisons_gmp_share", share(c.exact_comparisons_gmp, c.exact_comparisons)},
                  {"decisions", c.exact_decisions},
                  {"decisions_gmp", c.exact_decisions_gmp},
                  {"decisions_gmp_share", share(c.exact_decisions_gmp, c.exact_decisions)},
                  {"refinements", c.exact_refinements}};
  }
  if (delays && scheduler == SchedulerKind::Robust) {
    const double n = static_cast<double>(std::max<std::uint64_t>(1, c.delays_measured));
    const double rms = std::sqrt(c.delay_sum_squares / n);
    j["delays"] = {{"measured", c.delays_measured},
                   {"max", c.delay_max},
                   {"rms", rms},
                   {"max_in_eps", c.delay_max / eps},
                   {"rms_in_eps", rms / eps}};
  }
  if (!structure_counters.empty()) {
    Json sc = Json::object();
    for (const NamedCounter& c2 : structure_counters) sc[c2.name] = c2.value;
    j["structure_counters"] = sc;
  }
  return j;
}

}  // namespace

std::string counters_json(const Counters& counters, const NamedCounters& structure_counters,
                          SchedulerKind scheduler, double eps) {
  return counters_object(counters, structure_counters, scheduler, eps, counters.delays_measured > 0)
      .dump();
}

std::string stats_json(const RunResult& result, const RunOptions& options) {
  const Counters& c = result.stats.counters;
  Json j;
  j["structure"] = options.structure;
  j["scheduler"] = to_string(options.scheduler);
  if (options.scheduler == SchedulerKind::Robust) j["eps"] = options.eps;
  j["outcome"] = to_string(result.outcome);
  if (!result.message.empty()) j["message"] = result.message;
  j["objects"] = result.stats.objects_initial;
  j["queries"] = result.stats.queries;
  j.update(counters_object(c, result.stats.structure_counters, options.scheduler, options.eps,
                           options.measure_delays));
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
