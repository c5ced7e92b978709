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
//
// CLI11 and nlohmann-json are used by harness.cpp alone, compiled once for every bench: this
// header keeps them out of the benches' translation units (they were most of each one's compile
// time).

#include <array>
#include <charconv>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <memory>
#include <sstream>
#include <string>
#include <system_error>
#include <type_traits>
#include <vector>

#include "bench_config.hpp"

namespace kinetic::bench {

/// printf to standard output, kept in the transcript that --json reads its tables from.
__attribute__((format(printf, 1, 2))) void out(const char* format, ...);

/// The first "model name" of /proc/cpuinfo, or "unknown".
std::string processor();

/// Writes a 64 MiB buffer, more than the private caches (1 MiB L2 per core, 32 MiB L3 here):
/// a timed pass that follows starts without the previous pass's data in the private caches,
/// so the order of passes over the same queries favours none of them.
void flush_caches();

/// Times `count` passes over `rounds` rounds, each pass after flush_caches() and the order
/// rotated every round (none always runs first, and a slow moment of a shared machine falls on
/// one round of every pass rather than on one pass): the median over the rounds of what each
/// pass returns (its CPU seconds per query, say). pass(k) runs pass k and times it itself (its
/// untimed set-up first).
std::vector<double> median_passes(int rounds, std::size_t count,
                                  const std::function<double(std::size_t)>& pass);

class Harness {
 public:
  /// `program`: the executable's name; `what`: one line on what it measures.
  Harness(std::string program, std::string what);
  Harness(const Harness&) = delete;
  Harness& operator=(const Harness&) = delete;
  /// Writes --json (when given) as the bench ends.
  ~Harness();

  /// --sizes=N,N,... (into `sizes`; its value now is the default).
  void sizes(std::vector<std::size_t>& sizes, const std::string& help = "problem sizes n");
  void seed(std::uint64_t& seed) { option("--seed", seed, "random seed"); }
  void budget(double& seconds, const std::string& help = "CPU seconds per timed loop at most") {
    option("--budget", seconds, help);
  }
  void quick(bool& quick, const std::string& help) { flag("--quick", quick, help); }
  /// A bench's own option `--name=VALUE`, its variable's value now the default.
  template <class T>
  void option(const std::string& name, T& value, const std::string& help) {
    typed(name, value, help, false);
  }
  /// A positional argument `name` (no dashes), required, or optional with its variable's value
  /// now the default.
  template <class T>
  void positional(const std::string& name, T& value, const std::string& help, bool required) {
    typed(name, value, help, required);
  }
  void flag(const std::string& name, bool& value, const std::string& help);
  /// A comma-separated list `--name=a,b,...` into `values`.
  void list(const std::string& name, std::vector<std::string>& values, const std::string& help);

  /// Parses the command line (`--help`: the options, exit 0; a bad option or value: one line,
  /// exit 2). The bench then makes its own adjustments (what --quick changes, values clamped)
  /// and calls configured().
  void parse(int argc, char** argv);
  /// Whether the command line gave option `name` (a default --quick changes only what is not
  /// given).
  [[nodiscard]] bool given(const std::string& name) const;
  /// Records and prints the configuration the bench runs with: every option's value as the
  /// bench will use it (after its adjustments). Call once, after parse() and before measuring;
  /// the variables behind the options are read here and not after.
  void configured();

  [[nodiscard]] const std::string& program() const;

 private:
  /// What an option of type T takes: the name --help shows, and the words of the refusal.
  struct Kind {
    const char* type_name;
    const char* description;
  };
  template <class T>
  static Kind kind_of() {
    if constexpr (std::is_floating_point_v<T>) return {"FLOAT", "a number"};
    if constexpr (std::is_integral_v<T> && std::is_unsigned_v<T>) {
      return {"UINT", "a whole number >= 0"};
    }
    if constexpr (std::is_integral_v<T>) return {"INT", "a whole number"};
    return {"TEXT", "a value"};
  }
  /// An option's value as text: the shortest text that reads back as the same number.
  template <class T>
  static std::string to_text(const T& value) {
    if constexpr (std::is_same_v<T, std::string>) {
      return value;
    } else if constexpr (std::is_floating_point_v<T> || std::is_integral_v<T>) {
      std::array<char, 32> text{};
      const auto end = std::to_chars(text.data(), text.data() + text.size(), value).ptr;
      return std::string(text.data(), end);
    } else {
      std::ostringstream os;
      os << value;
      return os.str();
    }
  }
  /// Reads `text` whole into `value`; false when it is not one.
  template <class T>
  static bool from_text(const std::string& text, T& value) {
    if constexpr (std::is_same_v<T, std::string>) {
      value = text;
      return true;
    } else if constexpr (std::is_floating_point_v<T>) {
      if (text.empty()) return false;
      char* end = nullptr;
      const double v = std::strtod(text.c_str(), &end);
      if (end != text.c_str() + text.size()) return false;
      value = static_cast<T>(v);
      return true;
    } else if constexpr (std::is_integral_v<T>) {
      T v{};
      const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), v);
      if (error != std::errc() || end != text.data() + text.size()) return false;
      value = v;
      return true;
    } else {
      std::istringstream in(text);
      T v{};
      if (!(in >> v) || !in.eof()) return false;
      value = v;
      return true;
    }
  }
  /// An option or positional of type T: read as text by CLI11, then into `value`.
  template <class T>
  void typed(const std::string& name, T& value, const std::string& help, bool required) {
    add_option(
        name, help, required, kind_of<T>(), to_text(value),
        [&value](const std::string& text) { return from_text(text, value); },
        [&value] { return to_text(value); });
  }
  void add_option(const std::string& name, const std::string& help, bool required, Kind kind,
                  std::string default_text, std::function<bool(const std::string&)> read,
                  std::function<std::string()> show);

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace kinetic::bench
