// The documentation names what the registry has: every structure `kinetic run` offers appears in
// the README's list and in the library page's list of the runner's structures (the one a C++ user
// reads), every query type in the scenario format's table (in backticks), every scheduler in the
// README. A structure or query type added without its docs fails here, naming what is missing and
// where.

#include <gtest/gtest.h>

#include <string>

#include "kinetic/core/scheduler.hpp"
#include "kinetic/run/runner.hpp"
#include "kinetic/scenario/scenario.hpp"
#include "support/cli.hpp"

namespace kinetic {
namespace {

using test::read_file;

/// `x` between the two characters c (GCC 12 warns wrongly on "c" + std::string(x) + "c").
std::string between(char c, const std::string& x) {
  std::string out(1, c);
  out.append(x);
  out.push_back(c);
  return out;
}

std::string doc(const std::string& relative) {
  return read_file(std::string(KINETIC_DOCS_DIR) + "/" + relative);
}

TEST(DocsNameTheRegistry, EveryStructureQueryTypeAndScheduler) {
  const std::string readme = doc("../README.md");
  const std::string library = doc("library.md");
  const std::string format = doc("scenario-format.md");
  ASSERT_FALSE(readme.empty());
  ASSERT_FALSE(library.empty());
  ASSERT_FALSE(format.empty());
  // The library page's list of the runner's structures: the paragraph on RunOptions.
  const std::size_t at = library.find("`RunOptions` names the structure");
  ASSERT_NE(at, std::string::npos) << "docs/library.md: the paragraph on RunOptions is gone";
  const std::string runner_list = library.substr(at, library.find("\n\n", at) - at);
  std::size_t structures = 0;
  for (const run::StructureInfo& s : run::structures()) {
    ++structures;
    EXPECT_NE(readme.find(between('`', s.name)), std::string::npos)
        << "README.md does not name the structure `" << s.name << "`";
    EXPECT_NE(runner_list.find(between('"', s.name)), std::string::npos)
        << "docs/library.md's list of the runner's structures (RunOptions) lacks \"" << s.name
        << "\"";
  }
  EXPECT_GE(structures, 12u);
  for (const char* q : scenario::query_type_names()) {
    EXPECT_NE(format.find(between('`', q)), std::string::npos)
        << "docs/scenario-format.md does not name the query type \"" << q << "\"";
  }
  for (const SchedulerKind k :
       {SchedulerKind::Robust, SchedulerKind::Classic, SchedulerKind::Exact}) {
    EXPECT_NE(readme.find(between('`', to_string(k))), std::string::npos)
        << "README.md does not name the scheduler `" << to_string(k) << "`";
  }
}

}  // namespace
}  // namespace kinetic
