#pragma once
// JSON text for the readers of the project's formats (the scenario reader, scenario_json.cpp;
// the trace reader, run/trace_check.cpp): a strict reader that refuses what a plain JSON reader
// resolves silently, and the pieces of their one-line messages (excerpts of strings from the
// input, paths, what a value is). Private to the libraries built with nlohmann-json.

#include <nlohmann/json.hpp>

#include <cstddef>
#include <functional>
#include <string>
#include <string_view>

namespace kinetic::json_text {

/// Keys in file order, so that "the first fault found" is the first in the file.
using Json = nlohmann::ordered_json;

/// Shortest text that reads back as the same double; always with a '.' or an exponent, so that
/// a JSON reader sees a floating-point number (and -0.0 keeps its sign).
[[nodiscard]] std::string format_double(double v);
/// A JSON string literal, ASCII only (so that cutting it for a message cannot split a
/// character).
[[nodiscard]] std::string quote(const std::string& s);
/// A string from the input, quoted for a message: at most 60 characters of it (a key or a string
/// may be megabytes long; a message is one short line).
[[nodiscard]] std::string excerpt(const std::string& s);
/// A literal from the input as it was written (a number), cut to 60 characters for a message.
[[nodiscard]] std::string excerpt_raw(const std::string& s);
/// What a value is, for "got ..." in messages. Never more than one short line.
[[nodiscard]] std::string describe(const Json& v);
/// `$.key` for plain names, `$["odd key"]` otherwise, so that a path always reads back.
[[nodiscard]] std::string member_path(const std::string& path, const std::string& key);
[[nodiscard]] std::string index_path(const std::string& path, std::size_t i);
/// A path or a file name for a message: whole up to 200 characters, else its start and its end
/// around "...", so that a message stays one short line.
[[nodiscard]] std::string short_path(const std::string& path);
/// Makes a JSON reader's message fit on one line, without its "[json.exception...] " tag.
[[nodiscard]] std::string one_line(std::string message);

/// A JSON path, spelled out only when a message needs it: validation must not build a string per
/// number of a large file. Each step refers to its parent, so a step must not outlive the full
/// expression that made its parent (name each step that is kept).
class Path {
 public:
  Path() = default;  ///< the root, "$"
  [[nodiscard]] Path operator/(const char* key) const { return Path(this, key, 0); }
  [[nodiscard]] Path operator[](std::size_t index) const { return Path(this, nullptr, index); }
  [[nodiscard]] std::string str() const {
    if (parent_ == nullptr) return "$";
    return key_ != nullptr ? member_path(parent_->str(), key_) : index_path(parent_->str(), index_);
  }

 private:
  Path(const Path* parent, const char* key, std::size_t index)
      : parent_(parent), key_(key), index_(index) {}
  const Path* parent_ = nullptr;
  const char* key_ = nullptr;
  std::size_t index_ = 0;
};

/// A fault read_strict() finds in the text itself.
struct ReadFault {
  enum class Kind {
    NulByte,       ///< a NUL byte (JSON text has none; the reader would stop there): `offset`
    DuplicateKey,  ///< a key given twice in an object (a plain reader keeps the last): `key`
    TooDeep,       ///< nesting deeper than the limit (the reader recurses)
    Syntax,        ///< not JSON: `message`, `id`
  };
  Kind kind = Kind::Syntax;
  /// DuplicateKey: the object's path; TooDeep and Syntax: the path of the value being read.
  std::string path;
  /// DuplicateKey: the key given twice; Syntax: the key of the member being read (empty in an
  /// array or outside any object).
  std::string key;
  std::string message;     ///< Syntax: the reader's message, on one line
  int id = 0;              ///< Syntax: the reader's error id (406: a number beyond the doubles)
  std::size_t offset = 0;  ///< NulByte: its offset in the text
};

/// Reads one JSON document (strict: nothing after it). At the first fault calls `fault`, which
/// must throw (the reader has no document to return); exceptions it throws pass through.
[[nodiscard]] Json read_strict(std::string_view text, std::size_t max_depth,
                               const std::function<void(const ReadFault&)>& fault);

}  // namespace kinetic::json_text
