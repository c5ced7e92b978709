// The benchmarks' harness (harness.hpp): CLI11 for the options, nlohmann-json for --json.
#include "harness.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <deque>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>
#include <utility>

namespace kinetic::bench {
namespace {

/// What the bench printed through out(), for --json.
std::string& transcript() {
  static std::string text;
  return text;
}

/// The Markdown tables of a transcript: a table starts at a row followed by a separator row
/// (|---|...), its title the last other non-empty line before it; the rows after it (other lines
/// between them, such as a row's notes, are passed over) are its rows until the next table.
nlohmann::ordered_json tables_of(const std::string& text) {
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

std::string join(const std::vector<std::size_t>& v) {
  std::string s;
  for (const std::size_t x : v) s += (s.empty() ? "" : ",") + std::to_string(x);
  return s;
}

}  // namespace

void out(const char* format, ...) {
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

void flush_caches() {
  static std::vector<std::uint64_t> junk(std::size_t{8} << 20);
  static std::uint64_t round = 0;
  ++round;
  for (std::size_t i = 0; i < junk.size(); i += 8) junk[i] += round;
}

std::vector<double> median_passes(int rounds, std::size_t count,
                                  const std::function<double(std::size_t)>& pass) {
  std::vector<std::vector<double>> s(count);
  for (int r = 0; r < rounds; ++r) {
    for (std::size_t j = 0; j < count; ++j) {
      const std::size_t k = (j + static_cast<std::size_t>(r)) % count;
      flush_caches();
      s[k].push_back(pass(k));
    }
  }
  std::vector<double> median(count);
  for (std::size_t k = 0; k < count; ++k) {
    std::sort(s[k].begin(), s[k].end());
    median[k] = s[k].empty() ? 0.0 : s[k][s[k].size() / 2];
  }
  return median;
}

std::string processor() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("model name", 0) == 0) {
      const std::size_t colon = line.find(':');
      if (colon != std::string::npos) return line.substr(line.find_first_not_of(' ', colon + 1));
    }
  }
  return "unknown";
}

struct Harness::Impl {
  struct List {
    std::string name;
    std::vector<std::string>* values;
    std::string text;
  };
  struct Typed {  ///< an option or positional read as text, then into its variable
    std::string name, text;
    const char* description;
    std::function<bool(const std::string&)> read;
  };

  Impl(std::string program_name, std::string what_text)
      : program(std::move(program_name)), what(std::move(what_text)), app(what, program) {}

  [[nodiscard]] std::vector<std::pair<std::string, std::string>> option_values() const {
    std::vector<std::pair<std::string, std::string>> all;
    if (sizes != nullptr) all.emplace_back("--sizes", join(*sizes));
    for (const auto& [name, read] : values) all.emplace_back(name, read());
    for (const List& l : lists) {
      std::string s;
      for (const std::string& v : *l.values) s += (s.empty() ? "" : ",") + v;
      all.emplace_back(l.name, s);
    }
    return all;
  }

  void print_configuration() const {
    out("# %s: %s\n", program.c_str(), what.c_str());
    out("# build: %s; compiler: %s\n", build_type(), compiler());
    out("# machine: %u hardware threads, %s; single-threaded unless said\n",
        std::thread::hardware_concurrency(), processor().c_str());
    std::string options;
    for (const auto& [name, value] : configuration)
      options += " " + name + (name.rfind("--", 0) == 0 ? "=" : ": ") + value;
    out("# options:%s\n", options.c_str());
    std::fflush(stdout);
  }

  void write_json() const {
    if (json_path.empty()) return;
    nlohmann::ordered_json j;
    j["program"] = program;
    j["what"] = what;
    j["build"] = build_type();
    j["compiler"] = compiler();
    j["machine"] = {{"hardware_threads", std::thread::hardware_concurrency()},
                    {"processor", processor()}};
    nlohmann::ordered_json options = nlohmann::ordered_json::object();
    for (const auto& [name, value] : configuration)
      options[name.rfind("--", 0) == 0 ? name.substr(2) : name] = value;
    j["options"] = std::move(options);
    j["tables"] = tables_of(transcript());
    std::ofstream file(json_path);
    file << j.dump(1) << '\n';
    if (!file) std::fprintf(stderr, "%s: cannot write %s\n", program.c_str(), json_path.c_str());
  }

  std::string program, what;
  CLI::App app;
  std::string json_path;
  std::vector<std::size_t>* sizes = nullptr;
  std::string sizes_text;
  std::vector<std::pair<std::string, std::function<std::string()>>> values;
  std::deque<List> lists;   // (stable addresses: CLI11 writes into each text)
  std::deque<Typed> typed;  // (the same)
  std::vector<std::pair<std::string, std::string>> configuration;  ///< the options as parsed
};

Harness::Harness(std::string program, std::string what)
    : impl_(std::make_unique<Impl>(std::move(program), std::move(what))) {
  impl_->app.add_option("--json", impl_->json_path,
                        "also write the configuration and every table printed, as JSON, to FILE");
}

Harness::~Harness() { impl_->write_json(); }

void Harness::sizes(std::vector<std::size_t>& sizes, const std::string& help) {
  impl_->sizes = &sizes;
  impl_->sizes_text = join(sizes);
  impl_->app.add_option("--sizes", impl_->sizes_text, help + ", comma-separated")
      ->default_str(impl_->sizes_text);
}

void Harness::add_option(const std::string& name, const std::string& help, bool required, Kind kind,
                         std::string default_text, std::function<bool(const std::string&)> read,
                         std::function<std::string()> show) {
  impl_->typed.push_back({name, default_text, kind.description, std::move(read)});
  CLI::Option* o = impl_->app.add_option(name, impl_->typed.back().text, help);
  o->type_name(kind.type_name)->default_str(std::move(default_text));
  if (required) o->required();
  impl_->values.emplace_back(name, std::move(show));
}

void Harness::flag(const std::string& name, bool& value, const std::string& help) {
  impl_->app.add_flag(name, value, help);
  impl_->values.emplace_back(name, [&value] { return std::string(value ? "on" : "off"); });
}

void Harness::list(const std::string& name, std::vector<std::string>& values,
                   const std::string& help) {
  impl_->lists.push_back({name, &values, ""});
  Impl::List& l = impl_->lists.back();
  for (const std::string& v : values) l.text += (l.text.empty() ? "" : ",") + v;
  impl_->app.add_option(name, l.text, help + ", comma-separated")->default_str(l.text);
}

void Harness::parse(int argc, char** argv) {
  Impl& h = *impl_;
  try {
    h.app.parse(argc, argv);
    if (h.sizes != nullptr) *h.sizes = parse_sizes(h.sizes_text);
    for (Impl::Typed& t : h.typed) {
      if (!t.read(t.text)) {
        throw std::invalid_argument(t.name + ": '" + t.text + "' is not " + t.description);
      }
    }
    for (Impl::List& l : h.lists) {
      l.values->clear();
      std::string text = l.text + ",";
      for (std::size_t at = 0, comma; (comma = text.find(',', at)) != std::string::npos;
           at = comma + 1) {
        if (comma > at) l.values->push_back(text.substr(at, comma - at));
      }
    }
  } catch (const CLI::CallForHelp&) {
    std::exit(h.app.exit(CLI::CallForHelp()));
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "%s: %s (--help lists the options)\n", h.program.c_str(), e.what());
    std::exit(2);
  } catch (const std::exception& e) {  // a malformed --sizes or value
    std::fprintf(stderr, "%s: %s (--help lists the options)\n", h.program.c_str(), e.what());
    std::exit(2);
  }
}

bool Harness::given(const std::string& name) const { return impl_->app.count(name) > 0; }

void Harness::configured() {
  Impl& h = *impl_;
  h.configuration = h.option_values();
  h.sizes = nullptr;
  h.values.clear();
  h.lists.clear();
  h.typed.clear();
  h.print_configuration();
}

const std::string& Harness::program() const { return impl_->program; }

}  // namespace kinetic::bench
