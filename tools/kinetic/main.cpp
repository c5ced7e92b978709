// The `kinetic` command line (the contract: docs/scenario-format.md and the README).
//   kinetic run SCENARIO.json --structure NAME [--scheduler robust|classic|exact] [--eps E]
//               [--out ANSWERS.jsonl] [--stats STATS.json] [--progress]
//   kinetic generate DATASET --n N [--seed S] [--dimension D] [--scale S|unit] [--out FILE]
//   kinetic experiment sorting [--out DIR] [--n 900] [--quick] [--eps LIST] [--no-plots]
//   kinetic experiment tournament [--out DIR] [--n 10000] [--eps LIST] [--no-plots]
// Exit status: 0 done; 2 bad input or usage; 1 an internal failure (with a message).

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "kinetic/experiment/sorting_experiment.hpp"
#include "kinetic/experiment/tournament_experiment.hpp"
#include "kinetic/run/runner.hpp"
#include "kinetic/scenario/generators.hpp"
#include "kinetic/scenario/scenario_json.hpp"

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
  }
  return out.str();
}

/// Writes `text` to `path` ("-" = standard output). Returns false with a message on failure.
bool write_text(const std::string& path, const std::string& text, const char* what) {
  if (path == "-") {
    std::cout << text;
    std::cout.flush();
    return static_cast<bool>(std::cout);
  }
  std::ofstream f(path, std::ios::binary);
  f << text;
  f.close();
  if (!f) {
    std::cerr << "kinetic: cannot write " << what << " to " << path << "\n";
    return false;
  }
  return true;
}

struct RunArgs {
  std::string scenario;
  std::string structure;
  std::string scheduler = "robust";
  double eps = 1e-9;
  std::string out = "-";
  std::string stats;
  bool progress = false;
  bool measure_delays = false;
};

int do_run(const RunArgs& a) {
  kinetic::run::RunOptions options;
  options.structure = a.structure;
  options.eps = a.eps;
  options.progress = a.progress;
  options.measure_delays = a.measure_delays;
  const auto kind = kinetic::scheduler_from_string(a.scheduler);
  if (!kind) {
    std::cerr << "kinetic: --scheduler must be robust, classic or exact; got '" << a.scheduler
              << "'\n";
    return kExitUsage;
  }
  options.scheduler = *kind;
  kinetic::scenario::Scenario s;
  try {
    s = kinetic::scenario::load_scenario(a.scenario);
    kinetic::run::check_runnable(s, options, a.scenario == "-" ? "<stdin>" : a.scenario);
  } catch (const kinetic::scenario::ScenarioError& e) {
    std::cerr << e.what() << "\n";
    return kExitUsage;
  } catch (const kinetic::run::UsageError& e) {
    std::cerr << "kinetic: " << e.what() << "\n";
    return kExitUsage;
  }

  std::ofstream file;
  std::ostream* answers = &std::cout;
  if (a.out != "-") {
    file.open(a.out, std::ios::binary);
    if (!file) {
      std::cerr << "kinetic: cannot write answers to " << a.out << "\n";
      return kExitUsage;
    }
    answers = &file;
  }
  const kinetic::run::RunResult result = kinetic::run::run(s, options, *answers);
  if (file.is_open()) {
    file.close();
    if (!file) {
      std::cerr << "kinetic: cannot write answers to " << a.out << "\n";
      return kExitFailure;
    }
  }
  if (!a.stats.empty() &&
      !write_text(a.stats, kinetic::run::stats_json(result, options) + "\n", "stats")) {
    return kExitFailure;
  }
  if (result.outcome != kinetic::run::RunOutcome::Completed) {
    std::cerr << "kinetic: " << result.message << "\n";
    return kExitFailure;
  }
  return kExitOk;
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
    std::cerr << "kinetic: unknown --query-type '" << a.query_type << "'\n";
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
  return write_text(a.out, kinetic::scenario::write_scenario(s), "the scenario") ? kExitOk
                                                                                 : kExitFailure;
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
  for (const double e : o.eps) {
    if (!(e > 0.0) || !std::isfinite(e)) {
      std::cerr << "kinetic: --eps values must be positive and finite\n";
      return kExitUsage;
    }
  }
  if (o.n < 2 || o.bins < 1) {
    std::cerr << "kinetic: --n must be >= 2 and --bins >= 1\n";
    return kExitUsage;
  }
  const std::string dir = output_dir(a.out, "tournament");
  if (dir.empty()) return kExitUsage;
  std::cout << "kinetic experiment tournament: " << o.dataset << ", n = " << o.n << ", seed "
            << o.seed << "; classic with event times rounded to " << o.classic_rounding
            << ", robust at eps";
  for (const double e : o.eps) std::cout << " " << e;
  std::cout << "; output in " << dir << "/\n";
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

int do_experiment_sorting(const ExperimentArgs& a) {
  namespace ex = kinetic::experiment;
  for (const double e : a.eps) {
    if (!(e > 0.0) || !std::isfinite(e)) {
      std::cerr << "kinetic: --eps values must be positive and finite\n";
      return kExitUsage;
    }
  }
  if (a.n < 2 || a.bins < 1) {
    std::cerr << "kinetic: --n must be >= 2 and --bins >= 1\n";
    return kExitUsage;
  }
  const std::string dir = output_dir(a.out, "sorting");
  if (dir.empty()) return kExitUsage;
  ex::SortingExperimentOptions o;
  o.n = a.n;
  o.eps = a.eps;
  o.seed = a.seed;
  o.bins = a.bins;
  o.unit_scale = !a.integer_grids;
  std::cout << "kinetic experiment sorting: datasets grids, parabola, randdc (seed " << o.seed
            << (o.unit_scale ? ", grids and parabola scaled into [-1, 1]" : ", integer grids")
            << "), robust at eps";
  for (const double e : o.eps) std::cout << " " << e;
  std::cout << " and classic; output in " << dir << "/\n";
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
  if (violated) {
    std::cerr << "kinetic: a robust run violated Theorem 1 or 2 (see the table)\n";
    return kExitFailure;
  }
  return kExitOk;
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
                  "classic (floating-point failure times; the baseline); exact is not built yet")
      ->capture_default_str();
  run->add_option("--eps", run_args.eps, "root-isolation precision of the robust scheduler")
      ->capture_default_str();
  run->add_option("--out", run_args.out, "answers as JSON lines (default: standard output)");
  run->add_option("--stats", run_args.stats,
                  "write the run's figures as JSON (- for standard output)");
  run->add_flag("--progress", run_args.progress, "progress bar on standard error");
  run->add_flag("--measure-delays", run_args.measure_delays,
                "robust: measure each event's delay t_pr - t_ex (reported in --stats)");
  run->footer(structures_help());

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
      ->add_option("--dimension", gen.options.dimension, "dimension (random-linear, random-poly)")
      ->capture_default_str()
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
                   "sorting (Abam, Agarwal, de Berg, Yu, Section 6: Table 1, Figures 6-8) or "
                   "tournament (Figure 9)")
      ->required();
  experiment->add_option("--out", ex.out, "output directory (default: experiment-NAME)");
  experiment->add_option("--n", ex.n, "input size (the paper's: sorting 900, tournament 10000)");
  experiment->add_flag("--quick", ex.quick, "only --n (no larger run)");
  experiment->add_option("--large-n", ex.large_n, "size of the larger run (without --quick)")
      ->capture_default_str();
  experiment
      ->add_option("--eps", ex.eps,
                   "robust precisions (sorting: 1e-6,1e-7,1e-8; tournament: 1e-3,1e-4,1e-5)")
      ->delimiter(',');
  experiment->add_option("--seed", ex.seed, "random seed (randdc)")->capture_default_str();
  experiment->add_option("--bins", ex.bins, "parts of the window for err(t)")
      ->capture_default_str();
  experiment->add_flag("--integer-grids", ex.integer_grids,
                       "keep grids and parabola on integer coordinates (exact arithmetic)");
  experiment->add_flag("--no-plots", ex.no_plots, "write the CSV files only");

  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitUsage;
  }

  try {
    if (*run) return do_run(run_args);
    if (*generate) return do_generate(gen, *generate);
    if (*experiment) {
      if (ex.name == "sorting") return do_experiment_sorting(ex);
      if (ex.name == "tournament") return do_experiment_tournament(ex, *experiment);
      std::cerr << "kinetic: unknown experiment '" << ex.name << "' (built: sorting, tournament)\n";
      return kExitUsage;
    }
  } catch (const std::exception& e) {
    std::cerr << "kinetic: internal error: " << e.what() << "\n";
    return kExitFailure;
  }
  return kExitUsage;
}
