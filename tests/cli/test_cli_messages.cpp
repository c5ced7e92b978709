// The command line's refusals as a newcomer meets them: one line, prefixed "kinetic", naming
// what is wrong and what would be right (the structure meant, the structures that answer a query
// type, the choices of a required option), with exit status 2.

#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "support/cli.hpp"

namespace {

using kinetic::test::CliOutcome;

const kinetic::test::CliScratch scratch{"kinetic_cli_messages_"};

/// A 2-D scenario with one range query.
std::string range_scenario() {
  const std::string path = scratch.path("range.json");
  std::ofstream(path) << R"({"format": "kinetic-scenario/1", "dimension": 2, "start_time": 0,
    "objects": [{"id": 1, "motion": [[0.0, 1.0], [0.0]]}, {"id": 2, "motion": [[1.0], [1.0]]}],
    "timeline": [{"time": 1.0, "op": "query",
                  "query": {"type": "range", "box": [[0, 2], [0, 2]]}}]})";
  return path;
}

/// The one line of a refusal, and its status.
void expect_refusal(const CliOutcome& o, const std::string& text) {
  EXPECT_EQ(o.status, 2) << o.err;
  EXPECT_NE(o.err.find(text), std::string::npos) << o.err;
  EXPECT_EQ(o.err.rfind("kinetic", 0), 0u) << "prefixed: " << o.err;
  EXPECT_EQ(o.err.find('\n'), o.err.size() - 1) << "one line: " << o.err;
}

TEST(CliMessages, AMisspeltStructureGetsTheOneMeant) {
  const CliOutcome o = scratch.run("run " + range_scenario() + " --structure kd-tree", "kd_tree");
  expect_refusal(o, "unknown structure 'kd-tree' (did you mean kdtree?)");
  // Nothing close: no guess, the list of structures built.
  const CliOutcome far = scratch.run("run " + range_scenario() + " --structure heap", "heap");
  expect_refusal(far, "unknown structure 'heap'; built: sort, ");
  EXPECT_EQ(far.err.find("did you mean"), std::string::npos) << far.err;
}

TEST(CliMessages, AQueryTypeAStructureDoesNotAnswerNamesThoseThatDo) {
  const CliOutcome o = scratch.run("run " + range_scenario() + " --structure hull", "hull_range");
  expect_refusal(o,
                 "structure hull answers hull; got \"range\" (answered by --structure kdtree, "
                 "range-tree, longest-side-kdtree)");
}

TEST(CliMessages, AMissingRequiredOptionIsPrefixedAndListsTheChoices) {
  const CliOutcome o = scratch.run("run " + range_scenario(), "no_structure");
  expect_refusal(o, "kinetic run: --structure is required (one of: sort, tournament, ");
  EXPECT_NE(o.err.find("; see kinetic run --help"), std::string::npos) << o.err;
  const CliOutcome n = scratch.run("generate random-linear --n", "no_n");
  expect_refusal(n, "kinetic generate: --n");
  expect_refusal(scratch.run("", "no_subcommand"), "kinetic: A subcommand is required");
  // The structures are listed only where --structure is what is missing.
  const CliOutcome eps =
      scratch.run("run " + range_scenario() + " --structure kdtree --eps abc", "eps");
  expect_refusal(eps, "kinetic run: ");
  EXPECT_EQ(eps.err.find("one of: sort"), std::string::npos) << eps.err;
  const CliOutcome file = scratch.run("run --structure kdtree", "no_file");
  expect_refusal(file, "kinetic run: SCENARIO is required");
  EXPECT_EQ(file.err.find("one of: sort"), std::string::npos) << file.err;
}

}  // namespace
