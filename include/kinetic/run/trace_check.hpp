#pragma once
// Reading a trace back (kinetic-trace/2, or /1, docs/trace-format.md, "What the reader checks"):
// the whole trace is checked against its format before anything is made from it (`kinetic view`
// makes a page only of a trace that passes), so that a trace cut off or damaged (a byte changed,
// a line lost) is refused with one line naming the line and what was expected there, never
// turned into a replay of something else. The writer is the runner's (`kinetic run --trace`).

#include <cstddef>
#include <stdexcept>
#include <string>

namespace kinetic::run {

/// A trace that breaks its format: `line` (1-based; 1 is the header) and the message
/// "FILE:LINE: $.PATH: expected WHAT, got WHAT" (one line, bounded length; a file name longer
/// than 200 characters by its start and end).
class TraceError : public std::runtime_error {
 public:
  TraceError(std::size_t line, const std::string& what) : std::runtime_error(what), line_(line) {}
  [[nodiscard]] std::size_t line() const { return line_; }

 private:
  std::size_t line_;
};

/// Checks a trace's whole text (read from `file_name`, for messages) against its format:
/// passes when `kinetic run --trace` could have written it; throws TraceError at the first
/// fault, line by line.
void check_trace(const std::string& text, const std::string& file_name);

}  // namespace kinetic::run
