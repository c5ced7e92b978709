// The documentation names what the registry has: every structure `kinetic run` offers appears in
// the README's list, in the library page's list of the runner's structures (the one a C++ user
// reads), in the architecture page's folders table and in the Python page's table of classes
// (with its class); every query type in the scenario format's table (in backticks), every
// scheduler in the README. A structure or query type added without its docs fails here, naming
// what is missing and where (test_structure_list.cpp checks the registry against the list).

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
  const std::string architecture = doc("architecture.md");
  const std::string python = doc("python.md");
  ASSERT_FALSE(readme.empty());
  ASSERT_FALSE(library.empty());
  ASSERT_FALSE(format.empty());
  // The library page's list of the runner's structures: the paragraph on RunOptions.
  const std::size_t at = library.find("`RunOptions` names the structure");
  ASSERT_NE(at, std::string::npos) << "docs/library.md: the paragraph on RunOptions is gone";
  const std::string runner_list = library.substr(at, library.find("\n\n", at) - at);
  // The architecture page's folders table and the Python page's table of classes.
  const auto section = [](const std::string& page, const char* heading) {
    const std::size_t from = page.find(heading);
    return from == std::string::npos ? std::string()
                                     : page.substr(from, page.find("\n## ", from + 1) - from);
  };
  const std::string folders = section(architecture, "## Folders");
  const std::string classes = section(python, "| class |");
  ASSERT_FALSE(folders.empty()) << "docs/architecture.md: the section \"## Folders\" is gone";
  ASSERT_FALSE(classes.empty()) << "docs/python.md: the table of classes (\"| class |\") is gone";
  std::size_t structures = 0;
  for (const run::StructureInfo& s : run::structures()) {
    ++structures;
    EXPECT_NE(readme.find(between('`', s.name)), std::string::npos)
        << "README.md does not name the structure `" << s.name << "`";
    EXPECT_NE(runner_list.find(between('"', s.name)), std::string::npos)
        << "docs/library.md's list of the runner's structures (RunOptions) lacks \"" << s.name
        << "\"";
    EXPECT_NE(folders.find(between('`', s.name)), std::string::npos)
        << "docs/architecture.md's folders table does not name the structure `" << s.name << "`";
    EXPECT_NE(classes.find("| " + between('`', s.python_class) + " | " + between('`', s.name)),
              std::string::npos)
        << "docs/python.md's table of classes has no row \"| `" << s.python_class << "` | `"
        << s.name << "`\"";
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
