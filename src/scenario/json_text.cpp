#include "json_text.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <utility>
#include <vector>

namespace kinetic::json_text {

std::string format_double(double v) {
  std::array<char, 64> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), v);
  std::string text(buffer.data(), result.ptr);
  if (std::isfinite(v) && text.find_first_of(".e") == std::string::npos) text += ".0";
  return text;
}

std::string quote(const std::string& s) {
  return Json(s).dump(-1, ' ', /*ensure_ascii=*/true, Json::error_handler_t::replace);
}

std::string excerpt(const std::string& s) {
  std::string text = quote(s);
  if (text.size() > 60) {
    text = text.substr(0, 56);
    // Do not end inside an escape sequence (\uXXXX or \x).
    const auto backslash = text.rfind('\\');
    if (backslash != std::string::npos && backslash + 6 > text.size()) text.resize(backslash);
    text += "...\" (" + std::to_string(s.size()) + " bytes)";
  }
  return text;
}

std::string excerpt_raw(const std::string& s) {
  return s.size() <= 60 ? s : s.substr(0, 56) + "... (" + std::to_string(s.size()) + " bytes)";
}

std::string describe(const Json& v) {
  switch (v.type()) {
    case Json::value_t::null:
      return "null";
    case Json::value_t::boolean:
      return v.get<bool>() ? "true" : "false";
    case Json::value_t::string:
      return excerpt(v.get<std::string>());
    case Json::value_t::number_integer:
      return std::to_string(v.get<std::int64_t>());
    case Json::value_t::number_unsigned:
      return std::to_string(v.get<std::uint64_t>());
    case Json::value_t::number_float: {
      const double d = v.get<double>();
      // The JSON reader turns a literal beyond the double range (1e999) into an infinity.
      if (!std::isfinite(d)) return "a number beyond the range of a double";
      return format_double(d);
    }
    case Json::value_t::array:
      if (v.empty()) return "an empty array";
      return "an array of " + std::to_string(v.size()) + (v.size() == 1 ? " element" : " elements");
    case Json::value_t::object:
      return "an object";
    default:
      return "a value of an unexpected kind";
  }
}

std::string member_path(const std::string& path, const std::string& key) {
  const bool plain = !key.empty() && std::all_of(key.begin(), key.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
  });
  if (plain && key.size() <= 60) return path + "." + key;
  return path + "[" + excerpt(key) + "]";
}

std::string index_path(const std::string& path, std::size_t i) {
  return path + "[" + std::to_string(i) + "]";
}

std::string short_path(const std::string& path) {
  if (path.size() <= 200) return path;
  return path.substr(0, 60) + "..." + path.substr(path.size() - 120);
}

std::string one_line(std::string message) {
  if (!message.empty() && message.front() == '[') {
    const auto close = message.find("] ");
    if (close != std::string::npos) message.erase(0, close + 2);
  }
  for (char& c : message) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = ' ';
  }
  // The reader quotes the last token it read, which may be a megabyte-long string.
  constexpr std::size_t kMaxLength = 200;
  if (message.size() > kMaxLength) {
    std::size_t cut = kMaxLength;
    while (cut > 0 && (static_cast<unsigned char>(message[cut]) & 0xc0) == 0x80) --cut;
    message = message.substr(0, cut) + "... (" + std::to_string(message.size()) + " characters)";
  }
  return message;
}

namespace {

ReadFault fault_of(ReadFault::Kind kind, std::string path, std::string key = {},
                   std::string message = {}, int id = 0) {
  ReadFault f;
  f.kind = kind;
  f.path = std::move(path);
  f.key = std::move(key);
  f.message = std::move(message);
  f.id = id;
  return f;
}

// A SAX handler builds the document and knows the path of the value being read, so that the
// faults the reader itself finds are reported with their path too. (nlohmann's parser callbacks
// would do the path tracking, but they cost quadratic time on long arrays of objects.)
class StrictBuilder {
 public:
  StrictBuilder(std::size_t max_depth, const std::function<void(const ReadFault&)>& fault)
      : max_depth_(max_depth), fault_(fault) {}

  Json take() { return std::move(root_); }

  // The nlohmann SAX interface.
  bool null() { return add(Json(nullptr)); }
  bool boolean(bool v) { return add(Json(v)); }
  bool number_integer(std::int64_t v) { return add(Json(v)); }
  bool number_unsigned(std::uint64_t v) { return add(Json(v)); }
  bool number_float(double v, const std::string& /*text*/) { return add(Json(v)); }
  bool string(std::string& v) { return add(Json(std::move(v))); }
  bool binary(Json::binary_t& v) { return add(Json::binary(std::move(v))); }
  bool start_object(std::size_t /*size*/) { return open(Json::object()); }
  bool start_array(std::size_t /*size*/) { return open(Json::array()); }
  bool end_object() { return close(); }
  bool end_array() { return close(); }

  bool key(std::string& name) {
    Frame& top = frames_.back();
    if (top.node->contains(name)) {
      raise(fault_of(ReadFault::Kind::DuplicateKey, container_path(frames_.size()), name));
    }
    top.key = std::move(name);
    return true;
  }

  bool parse_error(std::size_t /*position*/, const std::string& /*last_token*/,
                   const Json::exception& error) {
    const std::string key =
        !frames_.empty() && frames_.back().node->is_object() ? frames_.back().key : std::string();
    raise(fault_of(ReadFault::Kind::Syntax, value_path(), key, one_line(error.what()), error.id));
    return false;
  }

 private:
  struct Frame {
    Json* node;  // an open object or array; stays put while it is open (it is its parent's last
                 // element)
    std::string key;  // objects: key of the member being read
  };

  void raise(const ReadFault& f) const {
    fault_(f);
    throw std::logic_error("json_text::read_strict: the fault handler returned");
  }

  /// Places `value` where the reader is; returns where it went.
  Json* place(Json value) {
    if (frames_.empty()) {
      root_ = std::move(value);
      return &root_;
    }
    Frame& top = frames_.back();
    if (top.node->is_array()) {
      top.node->push_back(std::move(value));
      return &top.node->back();
    }
    return &((*top.node)[top.key] = std::move(value));
  }

  bool add(Json value) {
    place(std::move(value));
    return true;
  }
  bool open(Json container) {
    if (frames_.size() >= max_depth_) raise(fault_of(ReadFault::Kind::TooDeep, value_path()));
    frames_.push_back(Frame{place(std::move(container)), {}});
    return true;
  }
  bool close() {
    frames_.pop_back();
    return true;
  }

  /// Path of frames_[depth - 1], the open container at that depth ("$" for the root).
  [[nodiscard]] std::string container_path(std::size_t depth) const {
    std::string out = "$";
    for (std::size_t i = 0; i + 1 < depth; ++i) {
      const Frame& parent = frames_[i];
      out = parent.node->is_array() ? index_path(out, parent.node->size() - 1)
                                    : member_path(out, parent.key);
    }
    return out;
  }

  /// Path of the value being read now.
  [[nodiscard]] std::string value_path() const {
    if (frames_.empty()) return "$";
    const Frame& top = frames_.back();
    const std::string container = container_path(frames_.size());
    return top.node->is_array() ? index_path(container, top.node->size())
                                : member_path(container, top.key);
  }

  std::size_t max_depth_;
  const std::function<void(const ReadFault&)>& fault_;
  Json root_;
  std::vector<Frame> frames_;
};

}  // namespace

Json read_strict(std::string_view text, std::size_t max_depth,
                 const std::function<void(const ReadFault&)>& fault) {
  // The JSON reader takes a NUL byte for the end of the input, so that a text with a NUL and
  // anything after its document would be accepted: JSON text has no NUL (a string escapes it).
  const std::size_t nul = text.find('\0');
  if (nul != std::string_view::npos) {
    ReadFault f = fault_of(ReadFault::Kind::NulByte, "$");
    f.offset = nul;
    fault(f);
    throw std::logic_error("json_text::read_strict: the fault handler returned");
  }
  StrictBuilder builder(max_depth, fault);
  Json::sax_parse(text, &builder, Json::input_format_t::json, /*strict=*/true,
                  /*ignore_comments=*/false);
  return builder.take();
}

}  // namespace kinetic::json_text
