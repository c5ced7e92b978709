#pragma once
// The benchmarks' one harness. Every bench:
//  - declares its options on a Harness (the common ones -- --sizes, --seed, --budget, --quick,
//    --json -- and its own), parsed by CLI11: `--help` lists them the same way everywhere, a bad
//    option is one line naming it and exit status 2; `--name=value` and `--name value` alike;
//  - prints through out() (printf's format): its text goes to standard output as before;
//  - gets its configuration printed once, first (configured(), after its own adjustments such as
//    what --quick changes): the program and what it measures, the build, the compiler, the
//    machine (hardware threads, processor) and every option's value as the run uses it;
//  - with --json FILE, writes at exit the configuration and every Markdown table it printed
//    (title, columns, rows; a cell that reads as a number is a number), so runs can be compared
//    by program rather than by eye.
// Each bench keeps only its own measurements.

#include <CLI/CLI.hpp>

#include <array>
#include <charconv>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

#include "bench_config.hpp"

namespace kinetic::bench {

/// What the bench printed through out(), for --json.
inline std::string& transcript() {
  static std::string text;
  return text;
}

/// printf to standard output, kept in the transcript.
__attribute__((format(printf, 1, 2))) inline void out(const char* format, ...) {
  va_list args;
  va_start(args, format);
  va_list copy;
  va_copy(copy, args);
  const int n = std::vsnprintf(nullptr, 0, format, copy);
  va_end(copy);
  std::string text(static_cast<std::size_t>(n > 0 ? n : 0), '\0');
  if (n > 0) std::vsnprintf(text.data(), text.size() + 1, format, args);
  va_end(args);
  std::fwrite(text.data(), 1, text.size(), stdout);
  transcript() += text;
}

/// The first "model name" of /proc/cpuinfo, or "unknown".
inline std::string processor() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("model name", 0) == 0) {
      const std::size_t colon = line.find(':');
      if (colon != std::string::npos) return line.substr(line.find_first_not_of(' ', colon + 1));
    }
  }
  return "unknown";
}

/// The Markdown tables of a transcript: a table starts at a row followed by a separator row
/// (|---|...), its title the last other non-empty line before it; the rows after it (other lines
/// between them, such as a row's notes, are passed over) are its rows until the next table.
inline nlohmann::ordered_json tables_of(const std::string& text) {
  const auto cells = [](const std::string& line) {
    std::vector<std::string> out;
    std::size_t at = 1;
    while (at < line.size()) {
      const std::size_t bar = line.find('|', at);
      if (bar == std::string::npos) break;
      std::string cell = line.substr(at, bar - at);
      const std::size_t a = cell.find_first_not_of(' '), b = cell.find_last_not_of(' ');
      out.push_back(a == std::string::npos ? std::string() : cell.substr(a, b - a + 1));
      at = bar + 1;
    }
    return out;
  };
  const auto value = [](const std::string& cell) -> nlohmann::ordered_json {
    std::string s = cell;
    for (const char c : {'*', '`'}) std::erase(s, c);
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (!s.empty() && end == s.c_str() + s.size()) return v;
    return cell;
  };
  const auto is_row = [](const std::string& line) { return !line.empty() && line[0] == '|'; };
  const auto is_separator = [&](const std::string& line) {
    return is_row(line) && line.find_first_not_of("|-: ") == std::string::npos;
  };
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  nlohmann::ordered_json tables = nlohmann::ordered_json::array();
  std::string title;
  nlohmann::ordered_json table;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string& line = lines[i];
    if (!is_row(line)) {
      if (line.find_first_not_of(' ') != std::string::npos) title = line;
      continue;
    }
    if (is_separator(line)) continue;
    if (i + 1 < lines.size() && is_separator(lines[i + 1])) {
      if (!table.is_null()) tables.push_back(std::move(table));
      table = {
          {"title", title}, {"columns", cells(line)}, {"rows", nlohmann::ordered_json::array()}};
      continue;
    }
    if (table.is_null()) {
      table = {{"title", title},
               {"columns", nlohmann::ordered_json::array()},
               {"rows", nlohmann::ordered_json::array()}};
    }
    nlohmann::ordered_json r = nlohmann::ordered_json::array();
    for (const std::string& c : cells(line)) r.push_back(value(c));
    table["rows"].push_back(std::move(r));
  }
  if (!table.is_null()) tables.push_back(std::move(table));
  return tables;
}

class Harness {
 public:
  /// `program`: the executable's name; `what`: one line on what it measures.
  Harness(std::string program, std::string what)
      : program_(std::move(program)), what_(std::move(what)), app_(what_, program_) {
    app_.add_option("--json", json_path_,
                    "also write the configuration and every table printed, as JSON, to FILE");
  }
  Harness(const Harness&) = delete;
  Harness& operator=(const Harness&) = delete;
  /// Writes --json (when given) as the bench ends.
  ~Harness() { write_json(); }

  /// --sizes=N,N,... (into `sizes`; its value now is the default).
  void sizes(std::vector<std::size_t>& sizes, const std::string& help = "problem sizes n") {
    sizes_ = &sizes;
    sizes_text_ = join(sizes);
    app_.add_option("--sizes", sizes_text_, help + ", comma-separated")->default_str(sizes_text_);
  }
  void seed(std::uint64_t& seed) { option("--seed", seed, "random seed"); }
  void budget(double& seconds, const std::string& help = "CPU seconds per timed loop at most") {
    option("--budget", seconds, help);
  }
  void quick(bool& quick, const std::string& help) { flag("--quick", quick, help); }
  /// A bench's own option `--name=VALUE`, its variable's value now the default.
  template <class T>
  void option(const std::string& name, T& value, const std::string& help) {
    app_.add_option(name, value, help)->capture_default_str();
    values_.emplace_back(name, [&value] {
      if constexpr (std::is_floating_point_v<T>) {
        std::array<char, 32> text{};  // the shortest text that reads back as the same number
        const auto end = std::to_chars(text.data(), text.data() + text.size(), value).ptr;
        return std::string(text.data(), end);
      } else {
        std::ostringstream os;
        os << value;
        return os.str();
      }
    });
  }
  /// A positional argument `name` (no dashes), required, or optional with its variable's value
  /// now the default.
  template <class T>
  void positional(const std::string& name, T& value, const std::string& help, bool required) {
    option(name, value, help);
    if (required) app_.get_option(name)->required();
  }
  void flag(const std::string& name, bool& value, const std::string& help) {
    app_.add_flag(name, value, help);
    values_.emplace_back(name, [&value] { return std::string(value ? "on" : "off"); });
  }
  /// A comma-separated list `--name=a,b,...` into `values`.
  void list(const std::string& name, std::vector<std::string>& values, const std::string& help) {
    lists_.push_back({name, &values, ""});
    List& l = lists_.back();
    for (const std::string& v : values) l.text += (l.text.empty() ? "" : ",") + v;
    app_.add_option(name, l.text, help + ", comma-separated")->default_str(l.text);
  }

  /// Parses the command line (`--help`: the options, exit 0; a bad option: one line, exit 2).
  /// The bench then makes its own adjustments (what --quick changes, values clamped) and calls
  /// configured().
  void parse(int argc, char** argv) {
    try {
      app_.parse(argc, argv);
      if (sizes_ != nullptr) *sizes_ = parse_sizes(sizes_text_);
      for (List& l : lists_) {
        l.values->clear();
        std::string text = l.text + ",";
        for (std::size_t at = 0, comma; (comma = text.find(',', at)) != std::string::npos;
             at = comma + 1) {
          if (comma > at) l.values->push_back(text.substr(at, comma - at));
        }
      }
    } catch (const CLI::CallForHelp&) {
      std::exit(app_.exit(CLI::CallForHelp()));
    } catch (const CLI::ParseError& e) {
      std::fprintf(stderr, "%s: %s (--help lists the options)\n", program_.c_str(), e.what());
      std::exit(2);
    } catch (const std::exception& e) {  // a malformed --sizes
      std::fprintf(stderr, "%s: %s (--help lists the options)\n", program_.c_str(), e.what());
      std::exit(2);
    }
  }
  /// Whether the command line gave option `name` (a default --quick changes only what is not
  /// given).
  [[nodiscard]] bool given(const std::string& name) const { return app_.count(name) > 0; }
  /// Records and prints the configuration the bench runs with: every option's value as the
  /// bench will use it (after its adjustments). Call once, after parse() and before measuring;
  /// the variables behind the options are read here and not after.
  void configured() {
    configuration_ = option_values();
    sizes_ = nullptr;
    values_.clear();
    lists_.clear();
    print_configuration();
  }

  [[nodiscard]] const std::string& program() const { return program_; }

 private:
  struct List {
    std::string name;
    std::vector<std::string>* values;
    std::string text;
  };

  static std::string join(const std::vector<std::size_t>& v) {
    std::string s;
    for (const std::size_t x : v) s += (s.empty() ? "" : ",") + std::to_string(x);
    return s;
  }

  [[nodiscard]] std::vector<std::pair<std::string, std::string>> option_values() const {
    std::vector<std::pair<std::string, std::string>> all;
    if (sizes_ != nullptr) all.emplace_back("--sizes", join(*sizes_));
    for (const auto& [name, read] : values_) all.emplace_back(name, read());
    for (const List& l : lists_) {
      std::string s;
      for (const std::string& v : *l.values) s += (s.empty() ? "" : ",") + v;
      all.emplace_back(l.name, s);
    }
    return all;
  }

  void print_configuration() const {
    out("# %s: %s\n", program_.c_str(), what_.c_str());
    out("# build: %s; compiler: %s\n", build_type(), compiler());
    out("# machine: %u hardware threads, %s; single-threaded unless said\n",
        std::thread::hardware_concurrency(), processor().c_str());
    std::string options;
    for (const auto& [name, value] : configuration_)
      options += " " + name + (name.rfind("--", 0) == 0 ? "=" : ": ") + value;
    out("# options:%s\n", options.c_str());
    std::fflush(stdout);
  }

  void write_json() const {
    if (json_path_.empty()) return;
    nlohmann::ordered_json j;
    j["program"] = program_;
    j["what"] = what_;
    j["build"] = build_type();
    j["compiler"] = compiler();
    j["machine"] = {{"hardware_threads", std::thread::hardware_concurrency()},
                    {"processor", processor()}};
    nlohmann::ordered_json options = nlohmann::ordered_json::object();
    for (const auto& [name, value] : configuration_)
      options[name.rfind("--", 0) == 0 ? name.substr(2) : name] = value;
    j["options"] = std::move(options);
    j["tables"] = tables_of(transcript());
    std::ofstream file(json_path_);
    file << j.dump(1) << '\n';
    if (!file) std::fprintf(stderr, "%s: cannot write %s\n", program_.c_str(), json_path_.c_str());
  }

  std::string program_, what_;
  CLI::App app_;
  std::string json_path_;
  std::vector<std::size_t>* sizes_ = nullptr;
  std::string sizes_text_;
  std::vector<std::pair<std::string, std::function<std::string()>>> values_;
  std::deque<List> lists_;  // (stable addresses: CLI11 writes into each text)
  std::vector<std::pair<std::string, std::string>> configuration_;  ///< the options as parsed
};

}  // namespace kinetic::bench
