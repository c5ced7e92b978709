#pragma once
// Reading and writing `kinetic-scenario/1` files (JSON). The format, its defaults and every
// validation rule are described in docs/scenario-format.md. A scenario is validated completely
// before anything simulates it: a caller either gets a Scenario that every structure may trust
// (ids consistent along the timeline, degrees supported, intervals never inside out, ...) or a
// ScenarioError, never half of a run.

#include <cstddef>
#include <string>

#include "kinetic/scenario/scenario.hpp"

namespace kinetic::scenario {

/// The reader's bounds (ScenarioError beyond them): containers nested at most this deep (a
/// scenario needs 6), and at most this many bytes of text (the parsed document takes about ten
/// times as much memory).
inline constexpr std::size_t kMaxScenarioDepth = 64;
inline constexpr std::size_t kMaxScenarioBytes = std::size_t{1} << 30;

/// Parses and validates `text`. Throws ScenarioError on the first fault found, with a one-line
/// message "FILE: JSON-PATH: expected WHAT[, got WHAT]" (FILE = `file_name`, JSON-PATH such as
/// `$.objects[3].motion[1][2]`; `$` is the root; strings from the input are quoted by an excerpt
/// of at most 60 characters). Any byte after the document but white space is a fault. The timeline
/// comes back sorted by time, stable for equal times, each entry keeping its position in the file
/// in `file_index`.
[[nodiscard]] Scenario parse_scenario(const std::string& text, const std::string& file_name);

/// Reads the file at `path` ("-" = standard input, named "<stdin>" in messages), then
/// parse_scenario. An unreadable file throws ScenarioError "FILE: cannot read: REASON".
[[nodiscard]] Scenario load_scenario(const std::string& path);

/// Serialises to `kinetic-scenario/1` text: deterministic, one object or timeline entry per line,
/// doubles in their shortest round-trip form (always with a '.' or an exponent, so -0.0 survives).
/// The timeline is written in its stored order, so parse_scenario(write_scenario(s)) == s field
/// by field (bit for bit for the doubles) when s is valid, its timeline in time order and
/// s.timeline[i].file_index == i: true of anything parse_scenario returned from a time-sorted file.
/// Precondition: every number in `s` is finite (throws std::invalid_argument otherwise, since the
/// text would not be JSON).
[[nodiscard]] std::string write_scenario(const Scenario& s);

}  // namespace kinetic::scenario
