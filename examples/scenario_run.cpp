// The "scenario" component: make one of the seed paper's datasets, save it in the scenario
// format, read it back and run it through the kinetic sort, as `kinetic run` does.
//
// GRIDS (Abam, Agarwal, de Berg, Yu, Section 6) is the hard degenerate input: lines through the
// points of a grid, with many crossings at the same instant. The runner processes the timeline
// (here 5 sorted-order queries) with robust scheduling, checks the structure's invariants and
// its agreement with the motions after every event (validate_every_event), writes the answers
// as JSON lines and reports the run's figures. Exit status 0 iff the run completed valid.
#include <cstdio>
#include <sstream>
#include <string>

#include <kinetic/run/runner.hpp>
#include <kinetic/scenario/generators.hpp>
#include <kinetic/scenario/scenario_json.hpp>

int main() {
  namespace sc = kinetic::scenario;
  sc::GeneratorOptions options;
  options.n = 400;
  options.seed = 5;
  options.queries = 5;
  const sc::Scenario generated = sc::generate("grids", options);

  // The scenario format round trip: write_scenario gives the JSON text of a scenario file.
  const std::string text = sc::write_scenario(generated);
  const sc::Scenario scenario = sc::parse_scenario(text, "grids.json");

  kinetic::run::RunOptions run_options;
  run_options.structure = "sort";
  run_options.validate_every_event = true;  // a test mode: slower, checks every step
  std::ostringstream sort_answers;
  kinetic::run::check_runnable(scenario, run_options, "grids.json");
  const kinetic::run::RunResult sorted = kinetic::run::run(scenario, run_options, sort_answers);

  std::printf("GRIDS, n = %zu (%zu bytes of JSON): %s, %llu events, %zu queries answered\n",
              scenario.objects.size(), text.size(), kinetic::run::to_string(sorted.outcome),
              static_cast<unsigned long long>(sorted.stats.counters.events()),
              sorted.stats.queries);
  std::printf("first answer: %.120s...\n", sort_answers.str().c_str());
  std::printf("run statistics (the --stats file):\n%s\n",
              kinetic::run::stats_json(sorted, run_options).c_str());

  const bool ok = sorted.outcome == kinetic::run::RunOutcome::Completed &&
                  sorted.stats.queries == options.queries;
  std::printf("%s\n", ok ? "the scenario ran to its end" : "FAILED");
  return ok ? 0 : 1;
}
