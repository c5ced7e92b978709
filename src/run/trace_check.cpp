// The trace reader's checks (docs/trace-format.md, "What the reader checks"). A trace passes
// when it could have been written by `kinetic run --trace`: the header names a known structure
// and scheduler and holds a valid scenario the structure runs; the lines after it are the known
// kinds, in time order inside the window; ops and queries are the scenario's timeline in
// processing order; ids are those of objects alive at the line; snapshots have their structure's
// documented shape and come where the writer puts them; and the last line is the end line, whose
// counts agree with the lines and the limits. What it cannot tell from the format alone (whether
// an event or an answer is the right one) is the run's business, not the reader's.
#include "kinetic/run/trace_check.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "kinetic/run/runner.hpp"
#include "kinetic/scenario/scenario.hpp"
#include "kinetic/scenario/scenario_json.hpp"
#include "scenario/json_text.hpp"
#include "trace.hpp"

namespace kinetic::run {

namespace {

using json_text::describe;
using json_text::excerpt;
using json_text::Json;
using json_text::one_line;
using json_text::Path;

/// The reader's bound on nesting (a trace needs 7: a scenario's query polygon in the header).
constexpr std::size_t kMaxDepth = 64;
/// The levels of a tree a snapshot lists at most (docs/trace-format.md, "Snapshots"): the
/// tournaments' and the BVH's top six, the segment tree's top eight, the longest-side kd-tree's
/// top ten.
constexpr std::size_t kMaxTournamentLevels = 6;
constexpr std::uint64_t kBvhLevels = 6;
constexpr std::uint64_t kSegmentLevels = 8;
constexpr std::uint64_t kCellLevels = 10;

/// A time for a message: the shortest text that reads back as it.
std::string number_text(double v) { return describe(Json(v)); }

/// The checks of one trace, line by line (docs/trace-format.md, "What the reader checks").
class Checker {
 public:
  /// Checks the whole text; throws TraceError at the first fault.
  void check(const std::string& text) {
    if (text.empty()) {
      ++line_;
      fail(
          "expected a kinetic-trace header, got an empty file (make a trace with kinetic run "
          "--trace)");
    }
    std::size_t begin = 0;
    while (begin < text.size()) {
      ++line_;
      const std::size_t newline = text.find('\n', begin);
      if (newline == std::string::npos) {
        fail("expected a line ending in a newline, got " + std::to_string(text.size() - begin) +
             " bytes and the end of the file: the trace was cut off");
      }
      check_line(std::string_view(text).substr(begin, newline - begin));
      begin = newline + 1;
    }
    if (!ended_) {
      fail(std::string("expected the end line ({\"k\": \"end\", ...}) last, got ") +
           (line_ == 1 ? "the header" : "a \"" + last_kind_ + "\" line") +
           " and the end of the file: the trace was cut off (a trace without its end line is not "
           "whole)");
    }
  }

 private:
  // ---- Faults ---------------------------------------------------------------------------------
  [[noreturn]] void fail(const std::string& what) const { throw TraceError(line_, what); }
  [[noreturn]] void fail(const Path& at, const std::string& expected, const Json& got) const {
    fail(at.str() + ": expected " + expected + ", got " + describe(got));
  }
  [[noreturn]] void fail(const Path& at, const std::string& expected,
                         const std::string& got) const {
    fail(at.str() + ": expected " + expected + ", got " + got);
  }

  // ---- Fields ---------------------------------------------------------------------------------
  const Json& field(const Json& object, const Path& at, const char* key,
                    const char* expected) const {
    const auto it = object.find(key);
    if (it == object.end()) fail(at / key, expected, std::string("no such key"));
    return *it;
  }
  const Json& object_field(const Json& object, const Path& at, const char* key) const {
    const Json& v = field(object, at, key, "an object");
    if (!v.is_object()) fail(at / key, "an object", v);
    return v;
  }
  const Json& array_field(const Json& object, const Path& at, const char* key) const {
    const Json& v = field(object, at, key, "an array");
    if (!v.is_array()) fail(at / key, "an array", v);
    return v;
  }
  /// An array a newer writer added to a snapshot: an older trace of the version has none (an
  /// empty array stands for it), but one trace is one writer's, so every snapshot has it or none
  /// has (the first one seen decides).
  const Json& optional_array(const Json& object, const Path& at, const char* key) {
    static const Json none = Json::array();
    const auto it = object.find(key);
    present(object, at, key);
    if (it == object.end()) return none;
    if (!it->is_array()) fail(at / key, "an array", *it);
    return *it;
  }
  /// Whether `object` has `key`, refused when the trace's first snapshot decided otherwise.
  bool present(const Json& object, const Path& at, const char* key) {
    const bool here = object.find(key) != object.end();
    const auto [it, first] = shape_.emplace(key, here);
    if (!first && it->second != here) {
      const std::string name = std::string("\"") + key + "\"";
      fail(at / key,
           here ? "no " + name + " (the snapshots before have none: one writer writes them alike)"
                : name + " (the snapshots before have it: one writer writes them alike)",
           here ? describe(object[key]) : std::string("no such key"));
    }
    return here;
  }
  std::string string_field(const Json& object, const Path& at, const char* key) const {
    const Json& v = field(object, at, key, "a string");
    if (!v.is_string()) fail(at / key, "a string", v);
    return v.get<std::string>();
  }
  std::uint64_t count(const Json& v, const Path& at, const char* expected) const {
    if (!v.is_number_unsigned() && !(v.is_number_integer() && v.get<std::int64_t>() >= 0))
      fail(at, expected, v);
    return v.get<std::uint64_t>();
  }
  std::uint64_t count_field(const Json& object, const Path& at, const char* key) const {
    return count(field(object, at, key, "an integer >= 0"), at / key, "an integer >= 0");
  }
  double number(const Json& v, const Path& at) const {
    if (!v.is_number() || !std::isfinite(v.get<double>())) fail(at, "a finite number", v);
    return v.get<double>();
  }
  int axis(const Json& v, const Path& at) const {
    const std::string expected = "an axis, an integer in [0, " +
                                 std::to_string(scenario_.dimension - 1) + "] (the dimension)";
    if (!v.is_number_integer() || v.get<std::int64_t>() < 0 ||
        v.get<std::int64_t>() >= scenario_.dimension)
      fail(at, expected, v);
    return static_cast<int>(v.get<std::int64_t>());
  }

  // ---- Ids --------------------------------------------------------------------------------------
  /// An integer that fits an id (64-bit signed), or none.
  [[nodiscard]] static std::optional<ObjectId> id_of(const Json& v) {
    if (v.is_number_unsigned()) {
      if (v.get<std::uint64_t>() > static_cast<std::uint64_t>(std::numeric_limits<ObjectId>::max()))
        return std::nullopt;
      return static_cast<ObjectId>(v.get<std::uint64_t>());
    }
    if (v.is_number_integer()) return v.get<std::int64_t>();
    return std::nullopt;
  }
  /// The dense slot of an id of the scenario (objects and inserts), or none.
  [[nodiscard]] std::optional<std::uint32_t> slot_of(const Json& v) const {
    const auto id = id_of(v);
    if (!id) return std::nullopt;
    if (!dense_.empty()) {  // small ids: a table, not a hash (a snapshot holds up to 10^5)
      if (*id < 0 || static_cast<std::uint64_t>(*id) >= dense_.size() ||
          dense_[static_cast<std::size_t>(*id)] == kNoSlot)
        return std::nullopt;
      return dense_[static_cast<std::size_t>(*id)];
    }
    const auto it = slots_.find(*id);
    if (it == slots_.end()) return std::nullopt;
    return it->second;
  }
  std::string alive_text() const { return "the id of an object alive at t=" + number_text(t_); }
  /// An id alive now; returns its slot.
  std::uint32_t alive_id(const Json& v, const Path& at) const {
    const auto slot = slot_of(v);
    if (!slot || !alive_[*slot]) fail(at, alive_text(), v);
    return *slot;
  }
  void alive_id_or_null(const Json& v, const Path& at) const {
    if (!v.is_null()) alive_id(v, at);
  }
  /// An array of distinct alive ids (ascending too when `ascending`); returns its size.
  std::size_t distinct_ids(const Json& v, const Path& at, bool ascending = false) {
    if (!v.is_array()) fail(at, "an array of ids", v);
    const std::uint32_t stamp = next_stamp();
    for (std::size_t k = 0; k < v.size(); ++k) {
      const std::uint32_t slot = alive_id(v[k], at[k]);
      if (seen_[slot] == stamp) fail(at[k], "each id once", "id " + describe(v[k]) + " again");
      seen_[slot] = stamp;
      if (ascending && k > 0 && v[k].get<std::int64_t>() < v[k - 1].get<std::int64_t>())
        fail(at[k], "ids ascending (after " + describe(v[k - 1]) + ")", v[k]);
    }
    return v.size();
  }
  /// Every alive id once.
  void all_alive_ids(const Json& v, const Path& at) {
    const std::size_t n = distinct_ids(v, at);
    if (n != alive_count_)
      fail(at,
           "the " + std::to_string(alive_count_) +
               " ids of the objects alive at t=" + number_text(t_) + ", each once",
           v);
  }
  /// [a, b] of two alive ids, a != b.
  void id_pair(const Json& v, const Path& at) {
    if (!v.is_array() || v.size() != 2) fail(at, "a pair of ids [a, b]", v);
    distinct_ids(v, at);
  }
  void id_pairs(const Json& v, const Path& at) {
    if (!v.is_array()) fail(at, "an array of id pairs", v);
    for (std::size_t k = 0; k < v.size(); ++k) id_pair(v[k], at[k]);
  }
  void triangles(const Json& v, const Path& at) {
    if (!v.is_array()) fail(at, "an array of triangles [a, b, c]", v);
    for (std::size_t k = 0; k < v.size(); ++k) {
      if (!v[k].is_array() || v[k].size() != 3) fail(at[k], "a triangle of ids [a, b, c]", v[k]);
      distinct_ids(v[k], at[k]);
    }
  }
  std::uint32_t next_stamp() {
    if (++stamp_ == 0) {  // wrapped: forget every mark
      std::fill(seen_.begin(), seen_.end(), 0);
      std::fill(seen_right_.begin(), seen_right_.end(), 0);
      stamp_ = 1;
    }
    return stamp_;
  }
  std::uint32_t add_slot(ObjectId id) {
    const auto [it, fresh] = slots_.emplace(id, static_cast<std::uint32_t>(alive_.size()));
    if (fresh) {
      alive_.push_back(false);
      seen_.push_back(0);
      seen_right_.push_back(0);
    }
    return it->second;
  }
  void set_alive(ObjectId id, bool alive) {
    const std::uint32_t slot = add_slot(id);
    if (alive_[slot] != alive) alive_count_ += alive ? 1 : -1;
    alive_[slot] = alive;
  }

  // ---- Lines ------------------------------------------------------------------------------------
  void check_line(std::string_view text) {
    if (ended_) {
      fail("expected nothing after the end line (line " + std::to_string(line_ - 1) +
           "), got another line");
    }
    const Json j = json_text::read_strict(text, kMaxDepth, [this](const json_text::ReadFault& f) {
      using Kind = json_text::ReadFault::Kind;
      switch (f.kind) {
        case Kind::NulByte:
          fail("not a JSON line (a NUL byte at column " + std::to_string(f.offset + 1) +
               "; JSON text has none)");
        case Kind::DuplicateKey:
          fail(json_text::short_path(f.path) + ": expected each key once, got key " +
               excerpt(f.key) + " twice");
        case Kind::TooDeep:
          fail(json_text::short_path(f.path) + ": nested deeper than " + std::to_string(kMaxDepth) +
               " levels (a trace needs at most 7)");
        case Kind::Syntax:
          fail("not a JSON line (" + f.message + ")");
      }
    });
    if (line_ == 1) {
      header(j);
      return;
    }
    body(j, text.size());
  }

  void header(const Json& h) {
    const Path at;
    if (!h.is_object() || h.find("format") == h.end() ||
        (h["format"] != "kinetic-trace/2" && h["format"] != "kinetic-trace/1")) {
      const std::string got = !h.is_object()                ? describe(h)
                              : h.find("format") == h.end() ? "no \"format\""
                                                            : describe(h["format"]);
      fail(
          "not a kinetic-trace header: $.format: expected \"kinetic-trace/2\" (or the older "
          "\"kinetic-trace/1\"), got " +
          got + " (make a trace with kinetic run --trace)");
    }
    version_ = h["format"] == "kinetic-trace/2" ? 2 : 1;
    const std::string structure = string_field(h, at, "structure");
    for (const StructureInfo& s : structures()) {
      if (s.name == structure) info_ = &s;
    }
    if (info_ == nullptr) {
      std::string names;
      for (const StructureInfo& s : structures()) names += (names.empty() ? "" : ", ") + s.name;
      fail(at / "structure", "a structure this build offers (" + names + ")", h["structure"]);
    }
    const std::string scheduler = string_field(h, at, "scheduler");
    const auto kind = scheduler_from_string(scheduler);
    if (!kind) fail(at / "scheduler", "\"robust\", \"classic\" or \"exact\"", h["scheduler"]);
    options_.structure = structure;
    options_.scheduler = *kind;
    if (*kind == SchedulerKind::Robust) {
      const Json& eps = field(h, at, "eps", "the robust scheduler's precision, a number > 0");
      if (!eps.is_number() || !std::isfinite(eps.get<double>()) || !(eps.get<double>() > 0.0))
        fail(at / "eps", "the robust scheduler's precision, a finite number > 0", eps);
      options_.eps = eps.get<double>();
    } else if (h.find("eps") != h.end()) {
      fail(at / "eps", "no eps (the " + scheduler + " scheduler has none)", h["eps"]);
    }
    const Json& limits = object_field(h, at, "limits");
    const Path lat = at / "limits";
    max_events_ = count_field(limits, lat, "max_events");
    max_snapshots_ = count_field(limits, lat, "max_snapshots");
    max_snapshot_bytes_ = count_field(limits, lat, "max_snapshot_bytes");
    const Json& sc = object_field(h, at, "scenario");
    // The scenario as `kinetic run` reads it, and one the structure runs: the reader's and the
    // runner's messages, their "scenario: $" made the line's "$.scenario".
    const auto rebase = [](const std::string& message) {
      // Every path of the message ("scenario: $.objects[1].id: ... (also $.objects[0].id)")
      // made a path in the line.
      std::string text = message.rfind("scenario: ", 0) == 0 ? message.substr(10) : message;
      std::string out;
      for (std::size_t i = 0; i < text.size(); ++i) {
        const bool root = text[i] == '$' && (i == 0 || text[i - 1] == ' ' || text[i - 1] == '(');
        if (!root) {
          out += text[i];
          continue;
        }
        out += "$.scenario";  // "$.objects" -> "$.scenario.objects", "$" -> "$.scenario"
      }
      return out.rfind("$.scenario", 0) == 0 ? out : "$.scenario: " + out;
    };
    try {
      scenario_ = scenario::parse_scenario(sc.dump(), "scenario");
      check_runnable(scenario_, options_, "scenario");
    } catch (const scenario::ScenarioError& e) {
      fail(rebase(e.what()));
    } catch (const UsageError& e) {
      fail(rebase(e.what()) + " (the header's structure cannot run its scenario)");
    }
    if (version_ == 2) {
      // The event types: the structure's kinds (one per axis for the kinds of one axis), then
      // "external" and "internal", as the writer lists them.
      types_ = detail::event_types(*info_, scenario_.dimension);
      const Json expected = detail::event_types_json(types_);
      const Json& kinds = field(h, at, "kinds", "the event types");
      if (kinds != expected) {
        fail(at / "kinds",
             "the event types of " + info_->name + " in " + std::to_string(scenario_.dimension) +
                 "-D, " + excerpt(expected.dump()),
             kinds);
      }
    }
    for (const scenario::ObjectSpec& o : scenario_.objects) set_alive(o.id, true);
    for (const scenario::TimelineOp& op : scenario_.timeline) {
      if (op.op == scenario::OpKind::Insert) add_slot(op.id);
    }
    ObjectId max_id = -1;
    bool small = true;
    for (const auto& [id, slot] : slots_) {
      small = small && id >= 0;
      max_id = std::max(max_id, id);
    }
    if (small && static_cast<std::uint64_t>(max_id) < 4 * slots_.size() + 1024) {
      dense_.assign(static_cast<std::size_t>(max_id) + 1, kNoSlot);
      for (const auto& [id, slot] : slots_) dense_[static_cast<std::size_t>(id)] = slot;
    }
    t_ = scenario_.start_time;
    snapshot_due_ = max_snapshots_ > 0 && max_snapshot_bytes_ > 0;
    due_after_ = "the header";
  }

  /// A line's time: a finite number, not below the line before's (the second line's: not below
  /// start_time) and not beyond end_time.
  double time_of(const Json& tv, const Path& at) const {
    const double t = number(tv, at);
    if (t < t_) {
      fail(at,
           "a time >= " + number_text(t_) +
               (line_ == 2 ? " (the scenario's start_time)"
                           : " (the line before's: lines are in time order)"),
           tv);
    }
    if (scenario_.end_time && t > *scenario_.end_time) {
      fail(at, "a time <= " + number_text(*scenario_.end_time) + " (the scenario's end_time)", tv);
    }
    return t;
  }

  void body(const Json& j, std::size_t bytes) {
    const Path at;
    if (!j.is_object()) fail(at, "an object (a line of the trace)", j);
    // kinetic-trace/1: every line has its time. kinetic-trace/2: an events line and a snapshot
    // line may leave it out (the line before's).
    double t = t_;
    if (version_ == 1) t = time_of(field(j, at, "t", "the time (a number)"), at / "t");
    const std::string k = string_field(j, at, "k");
    const bool known =
        version_ == 1 ? k == "event" || k == "internal" || k == "op" || k == "query" ||
                            k == "snapshot" || k == "end"
                      : k == "events" || k == "op" || k == "query" || k == "snapshot" || k == "end";
    if (!known) {
      fail(at / "k",
           version_ == 1
               ? "one of \"event\", \"internal\", \"op\", \"query\", \"snapshot\", \"end\""
               : "one of \"events\", \"op\", \"query\", \"snapshot\", \"end\"",
           j["k"]);
    }
    if (version_ == 2 && (k == "events" || k == "snapshot")) {
      // These lines leave out what the line before tells: a key the reader does not know could be
      // one of theirs damaged, so there is none (a new key makes a new version).
      const auto allowed = k == "events"
                               ? std::vector<std::string>{"k", "t", "q", "dt", "kind", "ids"}
                               : std::vector<std::string>{"k", "t", "event", "snapshot", "patch"};
      for (const auto& item : j.items()) {
        if (std::find(allowed.begin(), allowed.end(), item.key()) == allowed.end()) {
          std::string names;
          for (const std::string& n : allowed) names += (names.empty() ? "" : ", ") + n;
          fail(at,
               "only the keys of " + std::string(k == "events" ? "an events" : "a snapshot") +
                   " line (" + names + ")",
               "key " + excerpt(item.key()));
        }
      }
    }
    if (version_ == 2 && ((k != "events" && k != "snapshot") || j.find("t") != j.end()))
      t = time_of(field(j, at, "t", "the time (a number)"), at / "t");
    if (snapshot_due_ && k != "snapshot") {
      fail(at / "k",
           "\"snapshot\" (one follows " + due_after_ +
               " while the limits leave room: limits.max_snapshots, limits.max_snapshot_bytes)",
           j["k"]);
    }
    const double before = t_;
    t_ = t;
    last_kind_ = k;
    if (k == "event" || k == "internal") {
      if (event_lines_ >= max_events_) {
        fail(at / "k",
             "no more event lines than limits.max_events (" + std::to_string(max_events_) + ")",
             j["k"]);
      }
      ++event_lines_;
      if (k == "event") event(j, at);
    } else if (k == "events") {
      events(j, at);
    } else if (k == "op" || k == "query") {
      timeline_entry(j, at, k == "query");
    } else if (k == "snapshot") {
      snapshot(j, at, bytes, before);
    } else {
      end(j, at);
    }
  }

  /// A kinetic-trace/2 events line: its times (each the one before plus dt * 2^q; the first's
  /// "one before" the line's `t`, or the line before's time), and each event's type and ids.
  void events(const Json& j, const Path& at) {
    const Json& qv = field(j, at, "q", "the exponent of the time unit 2^q");
    if (!qv.is_number_integer() || qv.get<std::int64_t>() < -1074 || qv.get<std::int64_t>() > 1023)
      fail(at / "q", "the exponent of the time unit 2^q, an integer in [-1074, 1023]", qv);
    const int q = static_cast<int>(qv.get<std::int64_t>());
    const Json& dt = array_field(j, at, "dt");
    const Json& kind = array_field(j, at, "kind");
    const Json& ids = array_field(j, at, "ids");
    if (dt.empty()) fail(at / "dt", "the time steps of the line's events (at least one)", dt);
    if (kind.size() != dt.size())
      fail(at / "kind", "one type per event, " + std::to_string(dt.size()) + " (as dt)", kind);
    if (ids.size() != dt.size())
      fail(at / "ids", "one array of ids per event, " + std::to_string(dt.size()) + " (as dt)",
           ids);
    constexpr std::int64_t kMaxStep = std::int64_t{1} << 53;
    // (A Path refers to its parent: each one named here lives as long as its children.)
    const Path dts = at / "dt", kinds = at / "kind", idss = at / "ids";
    for (std::size_t i = 0; i < dt.size(); ++i) {
      const Path dat = dts[i];
      if (!dt[i].is_number_integer() || dt[i].get<std::int64_t>() < -kMaxStep ||
          dt[i].get<std::int64_t>() > kMaxStep)
        fail(dat, "a time step, an integer of magnitude at most 2^53", dt[i]);
      const double t = t_ + std::ldexp(static_cast<double>(dt[i].get<std::int64_t>()), q);
      time_of(Json(t), dat);
      t_ = t;
      const Path kat = kinds[i];
      if (event_lines_ >= max_events_) {
        fail(kat, "no more events than limits.max_events (" + std::to_string(max_events_) + ")",
             kind[i]);
      }
      ++event_lines_;
      if (!kind[i].is_number_unsigned() || kind[i].get<std::uint64_t>() >= types_.size())
        fail(kat,
             "an event type, a place in the header's kinds (below " +
                 std::to_string(types_.size()) + ")",
             kind[i]);
      const detail::EventType& type = types_[kind[i].get<std::size_t>()];
      const Path iat = idss[i];
      if (!ids[i].is_array()) fail(iat, "an array of ids", ids[i]);
      if (type.kind == "external" || type.kind == "internal") {
        if (!ids[i].empty())
          fail(iat, "no ids (an event the structure did not log: \"" + type.kind + "\")", ids[i]);
        continue;
      }
      event_ids(type.kind, ids[i], iat);
      if (type.kind == "swap") swaps_.push_back({type.axis, *id_of(ids[i][0]), *id_of(ids[i][1])});
    }
  }

  void event(const Json& j, const Path& at) {
    const std::string kind = string_field(j, at, "kind");
    const Json& ids = array_field(j, at, "ids");
    if (kind == "external") {
      if (!ids.empty()) fail(at / "ids", "no ids (an event the structure did not log)", ids);
      if (j.find("axis") != j.end())
        fail(at / "axis", "no axis (an event the structure did not log)", j["axis"]);
      return;
    }
    if (std::find(info_->event_kinds.begin(), info_->event_kinds.end(), kind) ==
        info_->event_kinds.end()) {
      std::string names;
      for (const std::string& n : info_->event_kinds) names += "\"" + n + "\", ";
      fail(at / "kind", "an event kind of " + info_->name + " (" + names + "or \"external\")",
           j["kind"]);
    }
    event_ids(kind, ids, at / "ids");
    // `axis` on the kinds that belong to one axis, and only there.
    const bool on_axis = kind == "swap" || kind == "max_change" || kind == "min_change";
    const bool has_axis = j.find("axis") != j.end();
    if (on_axis && !has_axis)
      fail(at / "axis", "the axis of the \"" + kind + "\" event", std::string("no such key"));
    if (!on_axis && has_axis)
      fail(at / "axis", "no axis (a \"" + kind + "\" event belongs to no axis)", j["axis"]);
    if (has_axis) axis(j["axis"], at / "axis");
  }

  /// The ids of an event of the structure's `kind` (README, "--events"): objects alive now; two
  /// for the kinds of a pair (ascending for contacts and the closest pair), 3 or 4 for a flip,
  /// some for the others.
  void event_ids(const std::string& kind, const Json& ids, const Path& at) {
    for (std::size_t i = 0; i < ids.size(); ++i) alive_id(ids[i], at[i]);
    const bool pair = kind == "swap" || kind == "max_change" || kind == "min_change" ||
                      kind == "endpoint_swap" || kind == "contact_begin" || kind == "contact_end" ||
                      kind == "pair_change";
    const bool ascending =
        kind == "contact_begin" || kind == "contact_end" || kind == "pair_change";
    if (pair && ids.size() != 2) fail(at, "two ids (a \"" + kind + "\" event)", ids);
    if (ascending && !(ids[0].get<std::int64_t>() < ids[1].get<std::int64_t>()))
      fail(at, "two ids ascending (a \"" + kind + "\" event)",
           "[" + describe(ids[0]) + ", " + describe(ids[1]) + "]");
    if (kind == "flip" && ids.size() != 3 && ids.size() != 4)
      fail(at, "3 or 4 ids (a \"flip\" event)", ids);
    if (ids.empty()) fail(at, "the ids of the event", ids);
  }

  void timeline_entry(const Json& j, const Path& at, bool query) {
    const Json& index = field(j, at, "index", "the entry's index in the scenario's timeline");
    if (next_entry_ >= scenario_.timeline.size()) {
      fail(at / "k",
           "the end line (the " + std::to_string(scenario_.timeline.size()) +
               " timeline entries of the scenario have their lines)",
           j["k"]);
    }
    const scenario::TimelineOp& op = scenario_.timeline[next_entry_];
    const std::string entry = "timeline entry " + std::to_string(op.file_index) + " (" +
                              scenario::to_string(op.op) + " at t=" + number_text(op.time) + ")";
    if ((op.op == scenario::OpKind::Query) != query) {
      fail(at / "k", std::string("\"") + (query ? "op" : "query") + "\": the next is " + entry,
           j["k"]);
    }
    if (!index.is_number_integer() || id_of(index).value_or(-1) < 0 ||
        static_cast<std::size_t>(*id_of(index)) != op.file_index) {
      fail(at / "index", std::to_string(op.file_index) + ": the next is " + entry, index);
    }
    if (t_ != op.time) fail(at / "t", number_text(op.time) + ": the time of " + entry, j["t"]);
    ++next_entry_;
    snapshot_due_ = snapshots_fit();
    due_after_ =
        std::string("the ") + (query ? "query" : "op") + " on line " + std::to_string(line_);
    if (query) {
      const Json& type = field(j, at, "type", "the query's type");
      if (type != scenario::to_string(op.query.type))
        fail(at / "type",
             std::string("\"") + scenario::to_string(op.query.type) + "\" (" + entry + ")", type);
      const Json& result = field(j, at, "result", "the query's answer");
      answer(op.query, result, at / "result");
      return;
    }
    const Json& name = field(j, at, "op", "the op");
    if (name != scenario::to_string(op.op))
      fail(at / "op", std::string("\"") + scenario::to_string(op.op) + "\" (" + entry + ")", name);
    const Json& id = field(j, at, "id", "the op's id");
    if (id_of(id) != op.id) fail(at / "id", std::to_string(op.id) + " (" + entry + ")", id);
    if (op.op == scenario::OpKind::Insert) set_alive(op.id, true);
    if (op.op == scenario::OpKind::Remove) set_alive(op.id, false);
  }

  [[nodiscard]] bool snapshots_fit() const {
    return snapshot_lines_ < max_snapshots_ && snapshot_bytes_ < max_snapshot_bytes_;
  }

  /// A query's answer, as `kinetic run --out` writes it: ids of objects alive at the query.
  void answer(const scenario::QuerySpec& q, const Json& r, const Path& at) {
    using scenario::QueryType;
    switch (q.type) {
      case QueryType::Sorted:
        all_alive_ids(r, at);
        return;
      case QueryType::Max:
      case QueryType::Min:
      case QueryType::Nearest:
      case QueryType::Farthest:
        alive_id_or_null(r, at);
        return;
      case QueryType::KNearest:
        distinct_ids(r, at);
        if (r.size() > q.k) fail(at, "at most " + std::to_string(q.k) + " ids (k)", r);
        return;
      case QueryType::Extent:
        if (!r.is_array() || r.size() != static_cast<std::size_t>(scenario_.dimension))
          fail(at, "an array of " + std::to_string(scenario_.dimension) + " [min, max] id pairs",
               r);
        for (std::size_t a = 0; a < r.size(); ++a) {
          if (!r[a].is_array() || r[a].size() != 2) fail(at[a], "a pair of ids [min, max]", r[a]);
          alive_id_or_null(r[a][0], at[a][0]);
          alive_id_or_null(r[a][1], at[a][1]);
        }
        return;
      case QueryType::Range:
      case QueryType::ApproxRange:
      case QueryType::Stab:
        distinct_ids(r, at, /*ascending=*/true);
        return;
      case QueryType::Hull:
        distinct_ids(r, at);
        return;
      case QueryType::ClosestPair:
        if (!r.is_null()) id_pair(r, at);
        return;
      case QueryType::CollidingPairs:
        id_pairs(r, at);
        return;
      case QueryType::Delaunay:
        triangles(r, at);
        return;
    }
  }

  void snapshot(const Json& j, const Path& at, std::size_t bytes, double before) {
    if (!snapshots_fit()) {
      fail(at / "k",
           "no more snapshots: limits.max_snapshots (" + std::to_string(max_snapshots_) +
               ") or limits.max_snapshot_bytes (" + std::to_string(max_snapshot_bytes_) +
               ") is reached",
           j["k"]);
    }
    snapshot_due_ = false;
    ++snapshot_lines_;
    snapshot_bytes_ += bytes;
    // `event`: the event lines before it, counting those the limit left out (kinetic-trace/2:
    // the events before it; left out when no event was).
    std::uint64_t e = event_lines_;
    if (version_ == 1 || j.find("event") != j.end()) {
      const Json& ev = field(j, at, "event", "the number of event lines before it");
      e = count(ev, at / "event", "the number of event lines before it");
      if (event_lines_ < max_events_ && e != event_lines_) {
        fail(at / "event", std::to_string(event_lines_) + ", the number of event lines before it",
             ev);
      }
      if (e < event_lines_ || e < last_snapshot_event_) {
        fail(at / "event",
             "at least " + std::to_string(std::max(event_lines_, last_snapshot_event_)) +
                 " (the event lines before it, and the previous snapshot's)",
             ev);
      }
    }
    // The structure at the line before it (the header: the start), unless that was an event
    // line the limit left out.
    if (e == event_lines_ && t_ != before) {
      fail(
          at / "t",
          number_text(before) + ", the time of the line before (a snapshot is the structure there)",
          j["t"]);
    }
    last_snapshot_event_ = e;
    // A whole snapshot, or a patch against the one before (docs/trace-format.md, "Patches").
    const bool whole = j.find("snapshot") != j.end(), patched = j.find("patch") != j.end();
    if (whole == patched) {
      fail(at, "one of \"snapshot\" (the whole structure) and \"patch\" (its changes)",
           std::string(whole ? "both" : "neither"));
    }
    std::vector<detail::Swap> swaps;
    swaps.swap(swaps_);
    if (whole) {
      previous_snapshot_ = object_field(j, at, "snapshot");
      structure_snapshot(previous_snapshot_, at / "snapshot");
      return;
    }
    if (previous_snapshot_.is_null()) {
      fail(at / "patch", "no patch before a whole snapshot (a patch changes the one before)",
           j["patch"]);
    }
    // kinetic-trace/2: the swap events since the snapshot line before apply first.
    if (!detail::apply_swaps(previous_snapshot_, swaps)) {
      fail(at / "patch",
           "a patch of a snapshot with orders (the " + std::to_string(swaps.size()) +
               " swap events since the snapshot before exchange ids in its orders)",
           j["patch"]);
    }
    if (const std::optional<detail::PatchError> wrong =
            detail::apply_snapshot_patch(previous_snapshot_, j["patch"])) {
      fail((at / "patch")[wrong->entry], "a [path, value] pair that applies: " + wrong->what,
           j["patch"].is_array() && wrong->entry < j["patch"].size() ? j["patch"][wrong->entry]
                                                                      : j["patch"]);
    }
    if (!previous_snapshot_.is_object())
      fail(at / "patch", "a patch that leaves the snapshot an object", j["patch"]);
    structure_snapshot(previous_snapshot_, at / "patch");
  }

  void end(const Json& j, const Path& at) {
    ended_ = true;
    const std::string outcome = string_field(j, at, "outcome");
    bool known = false;
    for (const RunOutcome o :
         {RunOutcome::Completed, RunOutcome::LoopGuard, RunOutcome::EventBudget,
          RunOutcome::InvalidState, RunOutcome::Interrupted}) {
      if (outcome == to_string(o)) known = true;
    }
    if (!known) {
      fail(at / "outcome",
           "\"completed\", \"loop_guard\", \"event_budget\", \"invalid_state\" or \"interrupted\"",
           j["outcome"]);
    }
    if (j.find("message") != j.end() && !j["message"].is_string())
      fail(at / "message", "a string", j["message"]);
    if (outcome == "completed" && next_entry_ != scenario_.timeline.size()) {
      const scenario::TimelineOp& op = scenario_.timeline[next_entry_];
      fail(at / "k",
           "a line for timeline entry " + std::to_string(op.file_index) + " (" +
               scenario::to_string(op.op) + " at t=" + number_text(op.time) +
               ") before a completed run's end",
           j["k"]);
    }
    const Json& events = object_field(j, at, "events");
    const Path eat = at / "events";
    const std::uint64_t processed = count_field(events, eat, "processed");
    const std::uint64_t written = count_field(events, eat, "written");
    const std::uint64_t left_out = count_field(events, eat, "left_out");
    if (written != event_lines_) {
      fail(eat / "written", std::to_string(event_lines_) + ", the event lines of the trace",
           events["written"]);
    }
    if (left_out > 0 && written != max_events_) {
      fail(eat / "left_out",
           "0: events are left out only beyond limits.max_events (" + std::to_string(max_events_) +
               ")",
           events["left_out"]);
    }
    if (processed < written || processed - written != left_out) {
      fail(eat / "processed",
           "written + left_out, " + std::to_string(written) + " + " + std::to_string(left_out),
           events["processed"]);
    }
    if (processed < last_snapshot_event_) {
      fail(eat / "processed",
           "at least " + std::to_string(last_snapshot_event_) + " (the last snapshot's event)",
           events["processed"]);
    }
    const Json& snapshots = object_field(j, at, "snapshots");
    const Path sat = at / "snapshots";
    const std::uint64_t s_written = count_field(snapshots, sat, "written");
    const std::uint64_t s_left_out = count_field(snapshots, sat, "left_out");
    if (s_written != snapshot_lines_) {
      fail(sat / "written", std::to_string(snapshot_lines_) + ", the snapshot lines of the trace",
           snapshots["written"]);
    }
    if (s_left_out > 0 && snapshots_fit()) {
      fail(sat / "left_out",
           "0: snapshots are left out only once limits.max_snapshots or "
           "limits.max_snapshot_bytes is reached",
           snapshots["left_out"]);
    }
    if (outcome == "completed") {
      if (scenario_.end_time && t_ != *scenario_.end_time) {
        fail(at / "t",
             number_text(*scenario_.end_time) + ", the scenario's end_time (a completed run's end)",
             j["t"]);
      }
    }
  }

  // ---- Snapshots (docs/trace-format.md, "Snapshots") -------------------------------------------
  void structure_snapshot(const Json& s, const Path& at) {
    const std::string& name = info_->name;
    if (name == "sort" || name == "kdtree" || name == "range-tree" ||
        name == "longest-side-kdtree") {
      orders(s, at, name == "kdtree" || name == "range-tree");
    }
    if (name == "tournament" || name == "extent") tops(s, at);
    if (name == "longest-side-kdtree") cells(s, at);
    if (name == "segment-tree") segments(s, at);
    if (name == "hull") distinct_ids(field(s, at, "hull", "the hull's ids"), at / "hull");
    if (name == "delaunay") triangles(field(s, at, "delaunay", "the triangles"), at / "delaunay");
    if (name == "delaunay" || name == "closest-pair") {
      const Json& pair = field(s, at, "closest_pair", "the closest pair [a, b] or null");
      if (!pair.is_null()) id_pair(pair, at / "closest_pair");
    }
    if (name == "bvh" || name == "sweep-and-prune") {
      id_pairs(field(s, at, "colliding_pairs", "the pairs in contact"), at / "colliding_pairs");
    }
    if (name == "bvh") bvh_nodes(s, at);
  }

  /// One order per axis, each with every alive id once; with slots (strictly increasing, below
  /// slot_count, a power of two) where `slotted` allows them.
  void orders(const Json& s, const Path& at, bool slotted) {
    const Json& list = array_field(s, at, "orders");
    const Path oat = at / "orders";
    if (list.size() != static_cast<std::size_t>(scenario_.dimension))
      fail(oat, "one order per axis, " + std::to_string(scenario_.dimension), list);
    for (std::size_t k = 0; k < list.size(); ++k) {
      const Json& o = list[k];
      if (!o.is_object()) fail(oat[k], "an order {\"axis\", \"ids\", ...}", o);
      const Json& a = field(o, oat[k], "axis", "an axis");
      if (axis(a, oat[k] / "axis") != static_cast<int>(k))
        fail(oat[k] / "axis", std::to_string(k) + " (the orders by axis)", a);
      all_alive_ids(array_field(o, oat[k], "ids"), oat[k] / "ids");
      if (!slotted) continue;
      const bool has_slots = present(o, oat[k], "slots");
      const bool has_slot_count = present(o, oat[k], "slot_count");
      if (!has_slots && !has_slot_count) continue;  // an older trace
      const Json& u = field(o, oat[k], "slot_count", "the number of slots (with slots)");
      const std::uint64_t slot_count = count(u, oat[k] / "slot_count", "a power of two");
      if (!std::has_single_bit(slot_count)) fail(oat[k] / "slot_count", "a power of two", u);
      const Json& slots = array_field(o, oat[k], "slots");
      if (slots.size() != o["ids"].size())
        fail(oat[k] / "slots", "one slot per id, " + std::to_string(o["ids"].size()), slots);
      for (std::size_t i = 0; i < slots.size(); ++i) {
        const std::uint64_t v = count(slots[i], (oat[k] / "slots")[i], "a slot, an integer >= 0");
        if (v >= slot_count)
          fail((oat[k] / "slots")[i],
               "a slot below slot_count (" + std::to_string(slot_count) + ")", slots[i]);
        if (i > 0 && v <= slots[i - 1].get<std::uint64_t>())
          fail((oat[k] / "slots")[i],
               "slots strictly increasing (after " + describe(slots[i - 1]) + ")", slots[i]);
      }
    }
  }

  void tops(const Json& s, const Path& at) {
    const Json& list = array_field(s, at, "tops");
    const Path tat = at / "tops";
    for (std::size_t k = 0; k < list.size(); ++k) {
      const Json& top = list[k];
      const Path p = tat[k];
      if (!top.is_object())
        fail(p, "a tournament {\"axis\", \"extreme\", \"id\", \"levels\"}", top);
      axis(field(top, p, "axis", "an axis"), p / "axis");
      const std::string extreme = string_field(top, p, "extreme");
      if (extreme != "max" && extreme != "min")
        fail(p / "extreme", "\"max\" or \"min\"", top["extreme"]);
      const Json& id = field(top, p, "id", "the winner's id or null");
      alive_id_or_null(id, p / "id");
      const Json& levels = optional_array(top, p, "levels");
      if (levels.size() > kMaxTournamentLevels)
        fail(p / "levels", "at most " + std::to_string(kMaxTournamentLevels) + " levels", levels);
      for (std::size_t l = 0; l < levels.size(); ++l) {
        const std::size_t width = std::size_t{1} << l;
        if (!levels[l].is_array() || levels[l].size() != width)
          fail((p / "levels")[l], "a level of " + std::to_string(width) + " ids or nulls",
               levels[l]);
        for (std::size_t i = 0; i < width; ++i)
          alive_id_or_null(levels[l][i], (p / "levels")[l][i]);
      }
      if (!levels.empty() && levels[0][0] != id)
        fail((p / "levels")[0][0], "the winner, " + describe(id), levels[0][0]);
      // A node's winner is one of its two children's; an empty subtree's children are empty.
      for (std::size_t l = 0; l + 1 < levels.size(); ++l) {
        for (std::size_t i = 0; i < levels[l].size(); ++i) {
          const Json& w = levels[l][i];
          const Json& a = levels[l + 1][2 * i];
          const Json& b = levels[l + 1][2 * i + 1];
          if (w.is_null() ? !(a.is_null() && b.is_null()) : (w != a && w != b)) {
            fail((p / "levels")[l][i],
                 w.is_null()
                     ? "null, or a winner of its children " + describe(a) + " and " + describe(b)
                     : "one of its children's winners, " + describe(a) + " or " + describe(b),
                 w);
          }
        }
      }
    }
  }

  /// A node's depth: below `levels` (the levels a snapshot lists), and not below the node
  /// before's when the nodes are listed breadth first.
  std::uint64_t depth(const Json& node, const Path& at, std::uint64_t levels,
                      std::optional<std::uint64_t> before) const {
    const Json& d = field(node, at, "depth", "a depth");
    const std::uint64_t v = count(d, at / "depth", "a depth, an integer >= 0");
    if (v >= levels)
      fail(at / "depth", "a depth below " + std::to_string(levels) + " (the levels listed)", d);
    if (before && v < *before)
      fail(at / "depth", "a depth >= " + std::to_string(*before) + " (breadth first)", d);
    return v;
  }

  /// A pair [a, b] of alive ids (equal allowed: bounds of a region may coincide).
  void two_ids(const Json& v, const Path& at) {
    if (!v.is_array() || v.size() != 2) fail(at, "a pair of ids", v);
    alive_id(v[0], at[0]);
    alive_id(v[1], at[1]);
  }

  void cells(const Json& s, const Path& at) {
    const Json& list = optional_array(s, at, "cells");
    const Path cat = at / "cells";
    std::optional<std::uint64_t> before;
    for (std::size_t k = 0; k < list.size(); ++k) {
      const Json& c = list[k];
      const Path p = cat[k];
      if (!c.is_object()) fail(p, "a cell {\"depth\", \"lo\", \"top\", \"axis\", \"split\"}", c);
      before = depth(c, p, kCellLevels, before);
      two_ids(field(c, p, "lo", "a pair of ids"), p / "lo");
      two_ids(field(c, p, "top", "a pair of ids"), p / "top");
      axis(field(c, p, "axis", "an axis"), p / "axis");
      alive_id(field(c, p, "split", "an id"), p / "split");
    }
  }

  void segments(const Json& s, const Path& at) {
    const Json& list = array_field(s, at, "endpoints");
    const Path eat = at / "endpoints";
    if (list.size() != 2 * alive_count_)
      fail(eat,
           "the " + std::to_string(2 * alive_count_) +
               " endpoints of the intervals alive at t=" + number_text(t_),
           list);
    const std::uint32_t stamp = next_stamp();
    for (std::size_t k = 0; k < list.size(); ++k) {
      const Json& e = list[k];
      if (!e.is_array() || e.size() != 2 || !(e[1] == 0 || e[1] == 1))
        fail(eat[k], "an endpoint [id, side], side 0 or 1", e);
      const std::uint32_t slot = alive_id(e[0], eat[k][0]);
      std::vector<std::uint32_t>& seen = e[1] == 0 ? seen_ : seen_right_;
      if (seen[slot] == stamp) fail(eat[k], "each endpoint once", e);
      seen[slot] = stamp;
    }
    const Json& nodes = optional_array(s, at, "nodes");
    const Path nat = at / "nodes";
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      const Json& n = nodes[k];
      if (!n.is_object()) fail(nat[k], "a node {\"depth\", \"leaves\", \"ids\"}", n);
      depth(n, nat[k], kSegmentLevels, std::nullopt);
      const Json& leaves = field(n, nat[k], "leaves", "[first, last]");
      if (!leaves.is_array() || leaves.size() != 2)
        fail(nat[k] / "leaves", "[first, last], two leaf numbers", leaves);
      const std::uint64_t first =
          count(leaves[0], (nat[k] / "leaves")[0], "a leaf, an integer >= 0");
      const std::uint64_t last =
          count(leaves[1], (nat[k] / "leaves")[1], "a leaf, an integer >= 0");
      if (last < first) fail((nat[k] / "leaves")[1], "a last leaf >= the first", leaves[1]);
      const Json& ids = field(n, nat[k], "ids", "the node's interval ids");
      if (distinct_ids(ids, nat[k] / "ids") == 0)
        fail(nat[k] / "ids", "the ids of its canonical set (a node with none is left out)", ids);
    }
  }
  void bvh_nodes(const Json& s, const Path& at) {
    const Json& nodes = optional_array(s, at, "nodes");
    const Path nat = at / "nodes";
    std::optional<std::uint64_t> before;
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      const Json& n = nodes[k];
      if (!n.is_object()) fail(nat[k], "a node {\"depth\", \"sides\"}", n);
      before = depth(n, nat[k], kBvhLevels, before);
      if (k == 0 && *before != 0) fail(nat[k] / "depth", "0 (the root first)", n["depth"]);
      const Json& sides = array_field(n, nat[k], "sides");
      if (sides.size() != static_cast<std::size_t>(scenario_.dimension))
        fail(nat[k] / "sides",
             "one [lo, hi] pair of ids per axis, " + std::to_string(scenario_.dimension), sides);
      for (std::size_t a = 0; a < sides.size(); ++a) two_ids(sides[a], (nat[k] / "sides")[a]);
    }
    const Json& pairs = optional_array(s, at, "pairs");
    const Path pat = at / "pairs";
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      const Json& p = pairs[k];
      if (!p.is_array() || p.size() != 3) fail(pat[k], "a pair [i, j, state]", p);
      const std::uint64_t i = count(p[0], pat[k][0], "a position in nodes");
      const std::uint64_t jj = count(p[1], pat[k][1], "a position in nodes");
      if (i >= nodes.size())
        fail(pat[k][0], "a position in nodes (below " + std::to_string(nodes.size()) + ")", p[0]);
      if (jj >= nodes.size())
        fail(pat[k][1], "a position in nodes (below " + std::to_string(nodes.size()) + ")", p[1]);
      const Json& state = p[2];
      if (state != "separated" && state != "expanded" && state != "contact" && state != "self")
        fail(pat[k][2], "\"separated\", \"expanded\", \"contact\" or \"self\"", state);
      if ((state == "self") != (i == jj))
        fail(pat[k][2], i == jj ? "\"self\" (a node with itself)" : "not \"self\" (two nodes)",
             state);
    }
  }

  // ---- State ------------------------------------------------------------------------------------
  std::size_t line_ = 0;
  int version_ = 2;                       // the header's kinetic-trace/N
  std::vector<detail::EventType> types_;  // kinetic-trace/2: the header's kinds
  std::vector<detail::Swap> swaps_;       // ... the swap events since the last snapshot line
  const StructureInfo* info_ = nullptr;
  RunOptions options_;
  scenario::Scenario scenario_;
  std::uint64_t max_events_ = 0, max_snapshots_ = 0, max_snapshot_bytes_ = 0;
  double t_ = 0.0;  // the time of the line before
  std::string last_kind_;
  bool ended_ = false;
  bool snapshot_due_ = false;   // the next line must be a snapshot
  std::string due_after_;       // ... after what
  std::size_t next_entry_ = 0;  // the next timeline entry (processing order)
  std::uint64_t event_lines_ = 0, snapshot_lines_ = 0, snapshot_bytes_ = 0;
  std::uint64_t last_snapshot_event_ = 0;
  Json previous_snapshot_;  // the structure at the last snapshot line (whole or patched)
  // Ids: a dense slot per id of the scenario, whether it is alive now, marks for "seen".
  std::unordered_map<ObjectId, std::uint32_t> slots_;
  std::unordered_map<std::string, bool> shape_;  // the optional keys the snapshots have
  static constexpr std::uint32_t kNoSlot = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> dense_;  // slots_ as a table by id, when the ids are small
  std::vector<bool> alive_;
  std::vector<std::uint32_t> seen_, seen_right_;
  std::uint32_t stamp_ = 0;
  std::size_t alive_count_ = 0;
};

}  // namespace

void check_trace(const std::string& text, const std::string& file_name) {
  try {
    Checker().check(text);
  } catch (const TraceError& e) {
    throw TraceError(e.line(), json_text::short_path(file_name) + ":" + std::to_string(e.line()) +
                                   ": " + e.what());
  }
}

}  // namespace kinetic::run
