// The `kinetic` command line (the contract: docs/scenario-format.md and the README).
//   kinetic run SCENARIO.json --structure NAME [--scheduler robust|classic|exact] [--eps E]
//               [--out ANSWERS.jsonl] [--stats STATS.json] [--progress]
//   kinetic generate DATASET --n N [--seed S] [--dimension D] [--out SCENARIO.json]
//   kinetic experiment NAME [--out DIR]
// Exit status: 0 done; 2 bad input or usage; 1 an internal failure (with a message).

#include <CLI/CLI.hpp>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

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
};

int do_generate(GenerateArgs& a, const CLI::App& cmd) {
  if (cmd.count("--start")) a.options.start_time = a.start;
  if (cmd.count("--end")) a.options.end_time = a.end;
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
  generate->add_option("--out", gen.out, "output file (default: standard output)");

  std::string experiment_name, experiment_out;
  CLI::App* experiment = app.add_subcommand("experiment", "Run one of the papers' experiments");
  experiment->add_option("NAME", experiment_name, "experiment name")->required();
  experiment->add_option("--out", experiment_out, "output directory");

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
      std::cerr << "kinetic: unknown experiment '" << experiment_name << "' (none is built yet)\n";
      return kExitUsage;
    }
  } catch (const std::exception& e) {
    std::cerr << "kinetic: internal error: " << e.what() << "\n";
    return kExitFailure;
  }
  return kExitUsage;
}
