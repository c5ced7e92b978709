// The `kinetic` command line (the contract: docs/scenario-format.md and the README).
//   kinetic run SCENARIO.json --structure NAME [--scheduler robust|classic|exact] [--eps E]
//               [--out ANSWERS.jsonl] [--stats STATS.json] [--progress]
//   kinetic generate DATASET --n N [--seed S] [--dimension D] [--scale S|unit] [--out FILE]
//   kinetic experiment sorting [--out DIR] [--n 900] [--quick] [--eps LIST] [--no-plots]
//   kinetic experiment tournament [--out DIR] [--n 10000] [--eps LIST] [--no-plots]
//   kinetic experiment delaunay [--out DIR] [--n 1000] [--eps LIST] [--no-plots]
// Exit status: 0 done; 2 bad input or usage; 1 an internal failure (with a message).

#include <unistd.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <array>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>
#include <streambuf>
#include <string>
#include <vector>

#include "kinetic/core/error.hpp"
#include "kinetic/core/spelling.hpp"
#include "kinetic/experiment/delaunay_experiment.hpp"
#include "kinetic/experiment/sorting_experiment.hpp"
#include "kinetic/experiment/tournament_experiment.hpp"
#include "kinetic/run/runner.hpp"
#include "kinetic/run/trace_check.hpp"
#include "kinetic/scenario/generators.hpp"
#include "kinetic/scenario/scenario_json.hpp"
#include "viewer_assets.hpp"

namespace {

constexpr int kExitOk = 0;
constexpr int kExitFailure = 1;
constexpr int kExitUsage = 2;

std::string structures_help() {
  std::ostringstream out;
  out << "Structures built (--structure NAME: query types answered):\n";
  for (const kinetic::run::StructureInfo& s : kinetic::run::structures()) {
    out << "  " << s.name << ": ";
    for (std::size_t i = 0; i < s.queries.size(); ++i) {
      out << (i ? ", " : "") << kinetic::scenario::to_string(s.queries[i]);
    }
    out << "\n      " << s.description << "\n";
    if (!s.event_kinds.empty()) {
      out << "      --events kinds: ";
      for (std::size_t i = 0; i < s.event_kinds.size(); ++i)
        out << (i ? ", " : "") << s.event_kinds[i];
      out << "\n";
    }
  }
  return out.str();
}

/// Standard output as a stream that remembers why a write failed (std::cout forgets: a full
/// disk would only show as a failed stream, with no reason to report).
class StdoutBuffer : public std::streambuf {
 public:
  StdoutBuffer() { setp(buffer_.data(), buffer_.data() + buffer_.size()); }
  ~StdoutBuffer() override { (void)flush(); }
  StdoutBuffer(const StdoutBuffer&) = delete;
  StdoutBuffer& operator=(const StdoutBuffer&) = delete;
  /// errno of the first failed write (0: none).
  [[nodiscard]] int error() const { return error_; }

 protected:
  int_type overflow(int_type ch) override {
    if (!flush()) return traits_type::eof();
    if (!traits_type::eq_int_type(ch, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(ch);
      pbump(1);
    }
    return traits_type::not_eof(ch);
  }
  int sync() override { return flush() ? 0 : -1; }

 private:
  bool flush() {
    const char* p = pbase();
    std::size_t left = static_cast<std::size_t>(pptr() - pbase());
    while (left > 0 && error_ == 0) {
      const ssize_t n = ::write(STDOUT_FILENO, p, left);
      if (n < 0) {
        if (errno == EINTR) continue;
        error_ = errno;
      } else {
        p += n;
        left -= static_cast<std::size_t>(n);
      }
    }
    setp(buffer_.data(), buffer_.data() + buffer_.size());
    return error_ == 0;
  }

  std::array<char, 1 << 16> buffer_{};
  int error_ = 0;
};

/// A file the command writes ("-" = standard output). It is opened before any work, so that a
/// path that cannot be written is refused at once (exit 2, nothing run); finish() flushes it and
/// reports a failure during the work, such as a full disk (exit 1). Messages name the file and
/// the reason.
class Output {
 public:
  Output(std::string path, const char* what) : path_(std::move(path)), what_(what) {}

  /// Opens (truncates) the file; false with a message when it cannot be written.
  [[nodiscard]] bool open() {
    if (path_ == "-") return true;
    errno = 0;
    file_.open(path_, std::ios::binary | std::ios::trunc);
    if (!file_) {
      report();
      return false;
    }
    return true;
  }
  [[nodiscard]] std::ostream& stream() { return path_ == "-" ? stdout_ : file_; }
  /// Flushes and closes; false with a message when anything written was lost.
  [[nodiscard]] bool finish() {
    errno = 0;
    if (path_ == "-") {
      stdout_.flush();
      if (!stdout_ || stdout_buffer_.error() != 0) {
        errno = stdout_buffer_.error();
        report();
        return false;
      }
      return true;
    }
    file_.close();
    if (!file_) {
      report();
      return false;
    }
    return true;
  }

 private:
  void report() const {
    const int error = errno;
    std::cerr << "kinetic: cannot write " << what_ << " to "
              << (path_ == "-" ? std::string("standard output") : path_);
    if (error != 0) std::cerr << ": " << std::strerror(error);
    std::cerr << "\n";
  }

  std::string path_;
  const char* what_;
  std::ofstream file_;
  StdoutBuffer stdout_buffer_;
  std::ostream stdout_{&stdout_buffer_};
};

/// Writes `text` to `path` ("-" = standard output). Returns false with a message on failure.
bool write_text(const std::string& path, const std::string& text, const char* what) {
  Output out(path, what);
  if (!out.open()) return false;
  out.stream() << text;
  return out.finish();
}

struct RunArgs {
  std::string scenario;
  std::string structure;
  std::string scheduler;  ///< empty: the structure's default for the scenario
  double eps = 1e-9;
  std::string out = "-";
  std::string stats;
  std::string events;
  std::string trace;
  kinetic::run::TraceLimits trace_limits;
  bool progress = false;
  bool measure_delays = false;
  bool eps_given = false;
};

/// Raised by SIGINT / SIGTERM during a run: the run stops between two events, writes what it
/// has and its stats ("outcome": "interrupted"). A second signal ends the program at once.
std::atomic<bool> g_interrupt{false};
volatile std::sig_atomic_t g_signal = 0;

extern "C" void on_interrupt(int signal) {
  if (g_interrupt.load()) std::_Exit(128 + signal);
  g_signal = signal;
  g_interrupt.store(true);
}

int do_run(const RunArgs& a) {
  kinetic::run::RunOptions options;
  options.structure = a.structure;
  options.eps = a.eps;
  options.progress = a.progress;
  options.measure_delays = a.measure_delays;
  options.log_events = !a.events.empty();
  options.trace_limits = a.trace_limits;
  if (!a.scheduler.empty()) {
    const auto kind = kinetic::scheduler_from_string(a.scheduler);
    if (!kind) {
      std::cerr << "kinetic: --scheduler must be robust, classic or exact; got '" << a.scheduler
                << "'\n";
      return kExitUsage;
    }
    options.scheduler = *kind;
    if (a.eps_given && options.scheduler != kinetic::SchedulerKind::Robust) {
      std::cerr << "kinetic: --eps is the robust scheduler's precision; --scheduler " << a.scheduler
                << " does not use it\n";
      return kExitUsage;
    }
  }
  kinetic::scenario::Scenario s;
  try {
    s = kinetic::scenario::load_scenario(a.scenario);
    if (a.scheduler.empty()) {
      // No --scheduler: the structure's default for this scenario (robust where it takes it).
      options.scheduler = kinetic::run::default_scheduler(s, a.structure);
      if (a.eps_given && options.scheduler != kinetic::SchedulerKind::Robust) {
        throw kinetic::run::UsageError(
            "--eps is the robust scheduler's precision; structure " + a.structure +
            " runs this scenario under " + kinetic::to_string(options.scheduler) +
            " (robust does not take its motions: kinetic run --help lists each structure's "
            "schedulers), which does not use it");
      }
    }
    kinetic::run::check_runnable(s, options, a.scenario == "-" ? "<stdin>" : a.scenario);
  } catch (const kinetic::scenario::ScenarioError& e) {
    std::cerr << "kinetic: " << e.what() << "\n";
    return kExitUsage;
  } catch (const kinetic::run::UsageError& e) {
    std::cerr << "kinetic: " << e.what() << "\n";
    return kExitUsage;
  }

  // Both outputs are opened before the run: a path that cannot be written costs no run.
  Output answers(a.out, "answers");
  if (!answers.open()) return kExitUsage;
  std::optional<Output> stats;
  if (!a.stats.empty()) {
    stats.emplace(a.stats, "stats");
    if (!stats->open()) return kExitUsage;
  }
  std::optional<Output> events;
  if (!a.events.empty()) {
    events.emplace(a.events, "events");
    if (!events->open()) return kExitUsage;
  }
  std::optional<Output> trace;
  if (!a.trace.empty()) {
    trace.emplace(a.trace, "trace");
    if (!trace->open()) return kExitUsage;
  }
  options.interrupt = &g_interrupt;
  std::signal(SIGINT, on_interrupt);
  std::signal(SIGTERM, on_interrupt);
  const kinetic::run::RunResult result =
      kinetic::run::run(s, options, answers.stream(), events ? &events->stream() : nullptr,
                        trace ? &trace->stream() : nullptr);
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  bool written = answers.finish();
  if (events) written = events->finish() && written;
  if (trace) written = trace->finish() && written;
  if (stats) {
    stats->stream() << kinetic::run::stats_json(result, options) << "\n";
    written = stats->finish() && written;
  }
  if (!written) return kExitFailure;
  if (result.outcome == kinetic::run::RunOutcome::Interrupted) {
    std::cerr << "kinetic: " << (g_signal == SIGTERM ? "SIGTERM" : "SIGINT") << ": "
              << result.message << "; the answers up to there are written"
              << (stats ? ", and the stats" : "") << "\n";
    return 128 + static_cast<int>(g_signal);
  }
  if (result.outcome != kinetic::run::RunOutcome::Completed) {
    std::cerr << "kinetic: " << result.message << "\n";
    return kExitFailure;
  }
  return kExitOk;
}

struct ViewArgs {
  std::string trace;
  std::string out;
};

/// `kinetic view TRACE --out REPLAY.html`: the replay page with the trace inside. The whole trace
/// is checked against its format first (kinetic/run/trace_check.hpp, docs/trace-format.md): a trace
/// that breaks it -- cut off, a byte changed, not a trace at all -- is refused with one line naming
/// the file and the line (exit 2) and no page is written. The trace goes into the page as it is,
/// "</" written "<\/" (the same JSON) so that no line ends the script. A page whose writing
/// fails is removed, so that no part of one is left behind.
int do_view(const ViewArgs& a) {
  std::ifstream in(a.trace, std::ios::binary);
  std::error_code error;
  if (!in || std::filesystem::is_directory(a.trace, error)) {
    std::cerr << "kinetic: cannot read " << a.trace << ": " << std::strerror(in ? EISDIR : errno)
              << "\n";
    return kExitUsage;
  }
  std::string trace;
  {
    std::ostringstream text;
    text << in.rdbuf();
    if (in.bad()) {
      std::cerr << "kinetic: cannot read " << a.trace << ": " << std::strerror(errno) << "\n";
      return kExitUsage;
    }
    trace = std::move(text).str();
  }
  try {
    kinetic::run::check_trace(trace, a.trace);
  } catch (const kinetic::run::TraceError& e) {
    std::cerr << "kinetic: " << e.what() << "\n";
    return kExitUsage;
  }
  // The page: the template with the viewer's code and the trace at their markers, the trace's
  // "</" written "<\/", in one pass (a trace may be 10^8 bytes, and hold many "</").
  const std::string html = kinetic::cli::kViewerHtml;
  const std::string js = kinetic::cli::kViewerJs;
  const std::string trace_marker = "/*KINETIC_TRACE*/", js_marker = "/*KINETIC_VIEWER_JS*/";
  std::string page;
  page.reserve(html.size() + js.size() + trace.size() + trace.size() / 16);
  const auto put_trace = [&page, &trace] {
    for (std::size_t from = 0;;) {
      const std::size_t p = trace.find("</", from);
      page.append(trace, from, p == std::string::npos ? std::string::npos : p - from);
      if (p == std::string::npos) break;
      page += "<\\/";
      from = p + 2;
    }
  };
  for (std::size_t from = 0;;) {
    const std::size_t t = html.find(trace_marker, from), j = html.find(js_marker, from);
    const std::size_t p = std::min(t, j);
    page.append(html, from, p == std::string::npos ? std::string::npos : p - from);
    if (p == std::string::npos) break;
    if (p == t) {
      put_trace();
      from = p + trace_marker.size();
    } else {
      page += js;
      from = p + js_marker.size();
    }
  }
  if (write_text(a.out, page, "the replay")) return kExitOk;
  std::error_code ignored;
  if (a.out != "-" && std::filesystem::is_regular_file(a.out, ignored))
    std::filesystem::remove(a.out, ignored);
  return kExitFailure;
}

struct GenerateArgs {
  std::string dataset;
  kinetic::scenario::GeneratorOptions options;
  std::string out = "-";
  double start = 0.0, end = 0.0;
  std::string query_type = "sorted";
  std::string scale = "1";
};

int do_generate(GenerateArgs& a, const CLI::App& cmd) {
  if (cmd.count("--start")) a.options.start_time = a.start;
  if (cmd.count("--end")) a.options.end_time = a.end;
  try {
    if (a.scale == "unit") {
      a.options.scale = kinetic::scenario::unit_scale(a.dataset, a.options.n);
    } else {
      std::size_t used = 0;
      a.options.scale = std::stod(a.scale, &used);
      if (used != a.scale.size()) throw std::invalid_argument(a.scale);
    }
  } catch (const std::exception&) {
    std::cerr << "kinetic: --scale must be a number or 'unit'; got '" << a.scale << "'\n";
    return kExitUsage;
  }
  const auto q = kinetic::scenario::query_type_from_string(a.query_type);
  if (!q) {
    std::string known;
    for (const char* name : kinetic::scenario::query_type_names()) {
      known += (known.empty() ? "" : ", ") + std::string(name);
    }
    std::cerr << "kinetic: unknown --query-type '" << a.query_type << "' (one of: " << known
              << ")\n";
    return kExitUsage;
  }
  a.options.query_type = *q;
  kinetic::scenario::Scenario s;
  try {
    s = kinetic::scenario::generate(a.dataset, a.options);
  } catch (const std::invalid_argument& e) {
    std::cerr << "kinetic: " << e.what() << "\n";
    return kExitUsage;
  }
  Output out(a.out, "the scenario");
  if (!out.open()) return kExitUsage;
  out.stream() << kinetic::scenario::write_scenario(s);
  return out.finish() ? kExitOk : kExitFailure;
}

struct ExperimentArgs {
  std::string name;
  std::string out;
  std::size_t n = 900;
  std::size_t large_n = 10000;
  bool quick = false;
  bool no_plots = false;
  bool integer_grids = false;
  std::vector<double> eps = {1e-6, 1e-7, 1e-8};
  std::uint64_t seed = 1;
  std::size_t bins = 2000;
  unsigned workers = 1;
};

/// The plotting script `name`: $KINETIC_SCRIPTS_DIR, the source tree, or the installed copy
/// (found relative to this executable, so that a moved install prefix still finds it).
std::string find_script(const std::string& name) {
  std::vector<std::string> dirs;
  if (const char* env = std::getenv("KINETIC_SCRIPTS_DIR")) dirs.emplace_back(env);
  dirs.emplace_back(KINETIC_SCRIPTS_SOURCE_DIR);
  std::error_code exe_error;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", exe_error);
  if (!exe_error) dirs.push_back((exe.parent_path() / KINETIC_SCRIPTS_INSTALL_DIR).string());
  for (const std::string& d : dirs) {
    const std::filesystem::path p = std::filesystem::path(d) / name;
    std::error_code ec;
    if (std::filesystem::is_regular_file(p, ec)) return p.string();
  }
  return {};
}

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (const char ch : s) q += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return q + "'";
}

/// Draws the plots of an experiment's output directory with scripts/plot_experiments.py (the
/// first Python that has matplotlib: $KINETIC_PYTHON, python3 on the PATH, then the system's).
void draw_plots(const std::string& dir) {
  const std::string script = find_script("plot_experiments.py");
  if (script.empty()) {
    std::cout << "\nplots: scripts/plot_experiments.py not found (set KINETIC_SCRIPTS_DIR); the "
                 "CSV files are written\n";
    return;
  }
  std::vector<std::string> pythons;
  if (const char* env = std::getenv("KINETIC_PYTHON")) pythons.emplace_back(env);
  pythons.emplace_back("python3");
  pythons.emplace_back("/usr/bin/python3");
  std::string python;
  for (const std::string& p : pythons) {
    const std::string probe = shell_quote(p) + " -c 'import matplotlib' >/dev/null 2>&1";
    if (std::system(probe.c_str()) == 0) {
      python = p;
      break;
    }
  }
  std::cout << "\n";
  std::cout.flush();
  const std::string cmd = shell_quote(python) + " " + shell_quote(script) + " " + shell_quote(dir);
  if (python.empty()) {
    std::cout << "plots: no python3 with matplotlib found (install python3-matplotlib, or set "
                 "KINETIC_PYTHON); the CSV files are written\n";
  } else if (std::system(cmd.c_str()) != 0) {
    std::cout << "plots: `" << cmd << "` failed; the CSV files are written\n";
  }
}

/// The output directory of an experiment, created. Empty (with a message) on failure.
std::string output_dir(const std::string& out, const std::string& name) {
  const std::string dir = out.empty() ? "experiment-" + name : out;
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    std::cerr << "kinetic: cannot create the output directory " << dir << ": " << ec.message()
              << "\n";
    return {};
  }
  return dir;
}

int do_experiment_tournament(const ExperimentArgs& a, const CLI::App& cmd) {
  namespace ex = kinetic::experiment;
  ex::TournamentExperimentOptions o;
  if (cmd.count("--n")) o.n = a.n;
  if (cmd.count("--eps")) o.eps = a.eps;
  o.seed = a.seed;
  o.bins = a.bins;
  o.workers = a.workers;
  try {
    ex::check_options(o);
  } catch (const kinetic::PreconditionError& e) {
    std::cerr << "kinetic: " << e.what() << "\n";
    return kExitUsage;
  }
  const std::string dir = output_dir(a.out, "tournament");
  if (dir.empty()) return kExitUsage;
  std::cout << "kinetic experiment tournament: " << o.dataset << ", n = " << o.n << ", seed "
            << o.seed << "; classic with event times rounded to " << o.classic_rounding
            << " (traditional, and with exact decisions), robust at eps";
  for (const double e : o.eps) std::cout << " " << e;
  std::cout << ", exact; output in " << dir << "/\n";
  std::cout.flush();
  const ex::TournamentExperiment e = ex::run_tournament_experiment(o, &std::cerr);
  std::cout << "\n" << ex::tournament_report_text(e);
  if (!write_text(dir + "/tournament_runs.csv", ex::tournament_runs_csv(e), "the runs") ||
      !write_text(dir + "/err_tournament_" + o.dataset + ".csv", ex::tournament_envelope_csv(e),
                  "the error"))
    return kExitFailure;
  if (!a.no_plots) draw_plots(dir);
  std::cout << "\nCSV files" << (a.no_plots ? "" : " and plots") << " in " << dir << "/\n";
  for (const ex::TournamentRun& r : e.runs) {
    if (r.robust() && r.theorem7_violations > 0) {
      std::cerr << "kinetic: a robust run violated Theorem 7 (see the table)\n";
      return kExitFailure;
    }
  }
  return kExitOk;
}

int do_experiment_delaunay(const ExperimentArgs& a, const CLI::App& cmd) {
  namespace ex = kinetic::experiment;
  ex::DelaunayExperimentOptions o;
  if (cmd.count("--n")) o.n = a.n;
  if (cmd.count("--eps")) o.eps = a.eps;
  o.seed = a.seed;
  try {
    ex::check_options(o);
  } catch (const kinetic::PreconditionError& e) {
    std::cerr << "kinetic: " << e.what() << "\n";
    return kExitUsage;
  }
  const std::string dir = output_dir(a.out, "delaunay");
  if (dir.empty()) return kExitUsage;
  std::cout << "kinetic experiment delaunay: random-linear 2-D, n = " << o.n << ", seed " << o.seed
            << "; exact, robust at eps";
  for (const double e : o.eps) std::cout << " " << e;
  std::cout << "; output in " << dir << "/\n";
  std::cout.flush();
  const ex::DelaunayExperiment e = ex::run_delaunay_experiment(o, &std::cerr);
  std::cout << "\n" << ex::delaunay_report_text(e);
  if (!write_text(dir + "/delaunay_runs.csv", ex::delaunay_runs_csv(e), "the runs"))
    return kExitFailure;
  if (!a.no_plots) draw_plots(dir);
  std::cout << "\nCSV files" << (a.no_plots ? "" : " and plots") << " in " << dir << "/\n";
  // The exact scheduler's guarantee, checked: its triangulation is Delaunay at every sample.
  for (const ex::DelaunayRun& r : e.runs) {
    if (!r.robust() && r.wrong_fraction > 0.0) {
      std::cerr << "kinetic: the exact run was not Delaunay at a sample (see the table)\n";
      return kExitFailure;
    }
  }
  return kExitOk;
}

int do_experiment_sorting(const ExperimentArgs& a) {
  namespace ex = kinetic::experiment;
  ex::SortingExperimentOptions o;
  o.n = a.n;
  o.eps = a.eps;
  o.seed = a.seed;
  o.bins = a.bins;
  o.workers = a.workers;
  o.unit_scale = !a.integer_grids;
  try {
    ex::check_options(o);
  } catch (const kinetic::PreconditionError& e) {
    std::cerr << "kinetic: " << e.what() << "\n";
    return kExitUsage;
  }
  const std::string dir = output_dir(a.out, "sorting");
  if (dir.empty()) return kExitUsage;
  std::cout << "kinetic experiment sorting: datasets grids, parabola, randdc (seed " << o.seed
            << (o.unit_scale ? ", grids and parabola scaled into [-1, 1]" : ", integer grids")
            << "), robust at eps";
  for (const double e : o.eps) std::cout << " " << e;
  std::cout << ", classic and exact; output in " << dir << "/\n";
  std::cout.flush();
  const ex::SortingExperiment e = ex::run_sorting_experiment(o, &std::cerr);
  std::cout << "\n" << ex::report_text(e);
  bool ok = write_text(dir + "/table1.csv", ex::table1_csv(e), "Table 1") &&
            write_text(dir + "/runs.csv", ex::runs_csv(e), "the runs");
  for (const std::string& d : o.datasets)
    ok = ok && write_text(dir + "/err_" + d + ".csv", ex::envelope_csv(e, d), "the error");
  if (!a.quick) {
    // Larger inputs: delays, classic failures and theorem checks; err sampled at bin edges.
    ex::SortingExperimentOptions large = o;
    large.n = a.large_n;
    large.envelope = false;
    const ex::SortingExperiment el = ex::run_sorting_experiment(large, &std::cerr);
    std::cout << "\n" << ex::report_text(el);
    ok = ok &&
         write_text(dir + "/table1_n" + std::to_string(large.n) + ".csv", ex::table1_csv(el),
                    "Table 1") &&
         write_text(dir + "/runs_n" + std::to_string(large.n) + ".csv", ex::runs_csv(el),
                    "the runs");
  }
  if (!ok) return kExitFailure;
  bool violated = false;
  for (const ex::SortingRun& r : e.runs)
    violated = violated || (r.robust() && (r.theorem1_violations > 0 || !r.theorem2_holds()));
  if (!a.no_plots) draw_plots(dir);
  std::cout << "\nCSV files" << (a.no_plots ? "" : " and plots") << " in " << dir << "/\n";
  std::cout << "\n" << ex::times_text(e);
  if (violated) {
    std::cerr << "kinetic: a robust run violated Theorem 1 or 2 (see the table)\n";
    return kExitFailure;
  }
  return kExitOk;
}

/// Names the first unknown --option of the subcommand's arguments (with a "did you mean"),
/// before CLI11 parses them: CLI11 would report a required option as missing first, or quote
/// the unknown option and its value as unexpected arguments. Returns false after the message.
bool check_option_names(const CLI::App& sub, int argc, char** argv, int first) {
  std::vector<std::string> names{"--help"};
  std::vector<std::string> takes_value;
  for (const CLI::Option* opt : sub.get_options()) {
    for (const std::string& n : opt->get_lnames()) {
      names.push_back("--" + n);
      if (opt->get_type_size() != 0) takes_value.push_back("--" + n);
    }
  }
  for (int i = first; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--") break;
    if (arg.size() < 3 || arg.compare(0, 2, "--") != 0) continue;
    const std::string name = arg.substr(0, arg.find('='));
    if (std::find(names.begin(), names.end(), name) != names.end()) {
      const bool value_follows =
          name.size() == arg.size() &&
          std::find(takes_value.begin(), takes_value.end(), name) != takes_value.end();
      if (value_follows) ++i;
      continue;
    }
    const std::string shown = name.size() > 60 ? name.substr(0, 56) + "..." : name;
    std::cerr << "kinetic " << sub.get_name() << ": unknown option " << shown;
    const std::string guess = kinetic::closest_name(name, names);
    if (!guess.empty()) std::cerr << " (did you mean " << guess << "?)";
    std::cerr << "; see kinetic " << sub.get_name() << " --help\n";
    return false;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"kinetic: kinetic data structures over moving objects"};
  app.set_version_flag("--version", std::string("kinetic ") + KINETIC_VERSION);
  app.require_subcommand(1);

  RunArgs run_args;
  CLI::App* run = app.add_subcommand("run", "Simulate a scenario with a kinetic structure");
  run->add_option("SCENARIO", run_args.scenario,
                  "scenario file (kinetic-scenario/1 JSON; - for stdin)")
      ->required();
  run->add_option("--structure", run_args.structure, "structure to maintain")->required();
  run->add_option("--scheduler", run_args.scheduler,
                  "event scheduling: robust (out-of-order-safe, CROP root isolation at --eps), "
                  "classic (floating-point failure times; the baseline), exact (exact event times "
                  "and order: algebraic numbers, GMP); default: robust wherever the structure "
                  "takes the scenario under it, otherwise the scheduler it takes");
  run->add_option("--eps", run_args.eps, "root-isolation precision of the robust scheduler")
      ->capture_default_str();
  run->add_option("--out", run_args.out, "answers as JSON lines (default: standard output)");
  run->add_option("--stats", run_args.stats,
                  "write the run's figures as JSON (- for standard output)");
  run->add_option("--events", run_args.events,
                  "write every external event as a JSON line {\"time\", \"kind\", \"ids\"[, "
                  "\"axis\"]} as it is processed (- for standard output; kinds per structure "
                  "below)");
  run->add_option("--trace", run_args.trace,
                  "write the run's trace for a replay (kinetic-trace/2 JSON lines: motions, "
                  "events, ops, answers, structure snapshots; docs/trace-format.md) and view it "
                  "with `kinetic view`");
  run->add_option("--trace-max-events", run_args.trace_limits.max_events,
                  "events written to the trace at most (later ones are counted)")
      ->capture_default_str();
  run->add_option("--trace-max-snapshots", run_args.trace_limits.max_snapshots,
                  "structure snapshots in the trace at most (sampled over the window)")
      ->capture_default_str();
  run->add_flag("--progress", run_args.progress, "progress bar on standard error");
  run->add_flag("--measure-delays", run_args.measure_delays,
                "robust: measure each event's delay t_pr - t_ex (reported in --stats)");
  run->footer(structures_help());

  ViewArgs view_args;
  CLI::App* view = app.add_subcommand(
      "view", "Make a replay page (one self-contained HTML file) from a trace of kinetic run");
  view->add_option("TRACE", view_args.trace, "trace file (kinetic run --trace)")->required();
  view->add_option("--out", view_args.out, "the replay page to write (HTML)")->required();

  GenerateArgs gen;
  CLI::App* generate = app.add_subcommand("generate", "Write a generated scenario");
  std::string datasets;
  for (const std::string& d : kinetic::scenario::dataset_names())
    datasets += (datasets.empty() ? "" : ", ") + d;
  generate->add_option("DATASET", gen.dataset, "one of: " + datasets)->required();
  generate->add_option("--n", gen.options.n, "number of objects")
      ->required()
      ->check(CLI::Range(1, 100000000));
  generate->add_option("--seed", gen.options.seed, "random seed")->capture_default_str();
  generate
      ->add_option("--dimension", gen.options.dimension,
                   "dimension (random-linear, random-poly; default: the dataset's own, 1, or 2 "
                   "for circle)")
      ->check(CLI::Range(1, 64));
  generate->add_option("--degree", gen.options.degree, "polynomial degree (random-poly)")
      ->capture_default_str()
      ->check(CLI::Range(1, 6));
  generate->add_option("--queries", gen.options.queries, "query ops evenly spaced over the window")
      ->capture_default_str();
  generate->add_option("--query-type", gen.query_type, "type of those queries")
      ->capture_default_str();
  generate->add_option("--updates", gen.options.updates, "random flight-plan updates");
  generate->add_option("--inserts", gen.options.inserts, "random inserts");
  generate->add_option("--removes", gen.options.removes, "random removes");
  generate->add_option("--start", gen.start, "start time (default: the dataset's window)");
  generate->add_option("--end", gen.end, "end time (default: the dataset's window)");
  generate
      ->add_option("--scale", gen.scale,
                   "multiply positions by this number, or 'unit' (grids and parabola into "
                   "[-1, 1])")
      ->capture_default_str();
  generate->add_option("--out", gen.out, "output file (default: standard output)");

  ExperimentArgs ex;
  CLI::App* experiment = app.add_subcommand("experiment", "Run one of the papers' experiments");
  experiment
      ->add_option("NAME", ex.name,
                   "sorting (Abam, Agarwal, de Berg, Yu, Section 6: Table 1, Figures 6-8), "
                   "tournament (Figure 9), or delaunay (the robust Delaunay triangulation in "
                   "their style: delays and geometric error against eps)")
      ->required();
  experiment->add_option("--out", ex.out, "output directory (default: experiment-NAME)");
  experiment->add_option("--n", ex.n,
                         "input size (the paper's: sorting 900, tournament 10000; delaunay 1000)");
  experiment->add_flag("--quick", ex.quick, "only --n (no larger run)");
  experiment->add_option("--large-n", ex.large_n, "size of the larger run (without --quick)")
      ->capture_default_str();
  experiment
      ->add_option(
          "--eps", ex.eps,
          "robust precisions (sorting: 1e-6,1e-7,1e-8; tournament: 1e-3,1e-4,1e-5; delaunay: "
          "1e-1,1e-2,1e-3,1e-4,1e-6,1e-9)")
      ->delimiter(',');
  experiment->add_option("--seed", ex.seed, "random seed (randdc)")->capture_default_str();
  experiment->add_option("--bins", ex.bins, "parts of the window for err(t)")
      ->capture_default_str();
  experiment
      ->add_option("--workers", ex.workers,
                   "sorting, tournament: runs done at once, one thread each (the results are "
                   "the same; only the run times differ)")
      ->check(CLI::Range(1U, 256U))
      ->capture_default_str();
  experiment->add_flag("--integer-grids", ex.integer_grids,
                       "keep grids and parabola on integer coordinates (exact arithmetic)");
  experiment->add_flag("--no-plots", ex.no_plots, "write the CSV files only");

  if (argc >= 2) {
    for (CLI::App* sub : {run, generate, experiment, view}) {
      if (sub->get_name() == argv[1] && !check_option_names(*sub, argc, argv, 2)) return kExitUsage;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // One line, prefixed like every other refusal, naming the subcommand and its help.
    std::string where = "kinetic";
    for (const CLI::App* sub : {run, generate, experiment, view}) {
      if (argc >= 2 && sub->get_name() == argv[1]) where += " " + sub->get_name();
    }
    std::cerr << where << ": " << e.what();
    if (where == "kinetic run" && dynamic_cast<const CLI::RequiredError*>(&e) != nullptr &&
        std::string(e.what()).find("--structure") != std::string::npos) {
      std::string names;
      for (const kinetic::run::StructureInfo& info : kinetic::run::structures())
        names += (names.empty() ? "" : ", ") + info.name;
      std::cerr << " (one of: " << names << ")";
    }
    std::cerr << "; see " << where << " --help\n";
    return kExitUsage;
  }

  try {
    if (*run) {
      run_args.eps_given = run->count("--eps") > 0;
      return do_run(run_args);
    }
    if (*generate) return do_generate(gen, *generate);
    if (*view) return do_view(view_args);
    if (*experiment) {
      if (ex.name == "sorting") return do_experiment_sorting(ex);
      if (ex.name == "tournament") return do_experiment_tournament(ex, *experiment);
      if (ex.name == "delaunay") return do_experiment_delaunay(ex, *experiment);
      std::cerr << "kinetic: unknown experiment '" << ex.name
                << "' (built: sorting, tournament, delaunay)\n";
      return kExitUsage;
    }
  } catch (const std::exception& e) {
    std::cerr << "kinetic: internal error: " << e.what() << "\n";
    return kExitFailure;
  }
  return kExitUsage;
}
