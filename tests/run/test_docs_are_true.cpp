// The documentation says only what the build has: every `--structure X`, `--scheduler Y` and
// query `"type": "Z"` written in README.md and docs/ names a structure, scheduler or query type
// of the registry; no page says of a structure or scheduler the build has that it "is not
// built"; the library page's table of queries shows the session method of every query type. A
// planted stale page is shown to be caught. (test_docs_name_the_registry.cpp checks the other
// way: that the docs name everything the registry has.)

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include "kinetic/core/scheduler.hpp"
#include "kinetic/run/runner.hpp"
#include "kinetic/scenario/scenario.hpp"
#include "support/cli.hpp"

namespace kinetic {
namespace {

std::vector<std::string> structure_names() {
  std::vector<std::string> out;
  for (const run::StructureInfo& s : run::structures()) out.push_back(s.name);
  return out;
}

std::vector<std::string> scheduler_names() {
  std::vector<std::string> out;
  for (const SchedulerKind k :
       {SchedulerKind::Robust, SchedulerKind::Classic, SchedulerKind::Exact})
    out.emplace_back(to_string(k));
  return out;
}

bool contains(const std::vector<std::string>& names, std::string word) {
  std::transform(word.begin(), word.end(), word.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return std::find(names.begin(), names.end(), word) != names.end();
}

/// A placeholder of a usage line (`--structure NAME`, `--scheduler S`): capitals only.
bool placeholder(const std::string& word) {
  return std::all_of(word.begin(), word.end(),
                     [](unsigned char c) { return std::isupper(c) != 0 || c == '_'; });
}

/// The statements of `text` (the page `page`) that contradict the build, one message each
/// naming the page, the line and the fault.
std::vector<std::string> stale_statements(const std::string& page, const std::string& text) {
  const std::vector<std::string> structures = structure_names();
  const std::vector<std::string> schedulers = scheduler_names();
  std::vector<std::string> queries;
  for (const char* q : scenario::query_type_names()) queries.emplace_back(q);
  static const std::regex structure_flag(R"(--structure[ =]([A-Za-z0-9_-]+))");
  static const std::regex scheduler_flag(R"(--scheduler[ =]([A-Za-z0-9_-]+))");
  static const std::regex query_type(R"re("type": ?"([A-Za-z0-9_-]+)")re");
  static const std::regex not_built(R"re(`?([A-Za-z-]+)`?( scheduler)? (is|are) not built)re",
                                    std::regex::icase);
  std::vector<std::string> found;
  std::size_t line_number = 0, from = 0;
  while (from <= text.size()) {
    const std::size_t end = std::min(text.find('\n', from), text.size());
    const std::string line = text.substr(from, end - from);
    ++line_number;
    const std::string where = page + ":" + std::to_string(line_number) + ": ";
    const auto each = [&](const std::regex& r, auto&& check) {
      for (auto m = std::sregex_iterator(line.begin(), line.end(), r); m != std::sregex_iterator();
           ++m)
        check((*m)[1].str());
    };
    each(structure_flag, [&](const std::string& name) {
      if (!placeholder(name) && !contains(structures, name))
        found.push_back(where + "no structure '" + name + "'");
    });
    each(scheduler_flag, [&](const std::string& name) {
      if (!placeholder(name) && !contains(schedulers, name))
        found.push_back(where + "no scheduler '" + name + "'");
    });
    each(query_type, [&](const std::string& name) {
      if (!placeholder(name) && !contains(queries, name))
        found.push_back(where + "no query type '" + name + "'");
    });
    each(not_built, [&](const std::string& name) {
      if (contains(structures, name) || contains(schedulers, name))
        found.push_back(where + "says '" + name + "' is not built, which the build has");
    });
    from = end + 1;
  }
  return found;
}

TEST(DocsAreTrue, EveryNameAPageUsesIsTheBuildsAndNothingBuiltIsSaidMissing) {
  std::vector<std::string> pages{std::string(KINETIC_DOCS_DIR) + "/../README.md"};
  for (const auto& entry : std::filesystem::recursive_directory_iterator(KINETIC_DOCS_DIR)) {
    if (entry.path().extension() == ".md") pages.push_back(entry.path().string());
  }
  std::sort(pages.begin(), pages.end());
  ASSERT_GE(pages.size(), 20u);
  for (const std::string& page : pages) {
    for (const std::string& fault : stale_statements(page, test::read_file(page)))
      ADD_FAILURE() << fault;
  }
}

TEST(DocsAreTrue, ThePlantedStaleStatementsAreCaught) {
  const std::string planted =
      "Run `kinetic run --structure kd-tree`.\n"
      "The `Exact` scheduler is not built and is refused.\n"
      "{\"type\": \"knn\", \"k\": 3} with --scheduler fast\n"
      "Fine: --structure kdtree --scheduler exact, {\"type\": \"range\"}; the heap is not built;\n"
      "--structure NAME (a placeholder).\n";
  const std::vector<std::string> found = stale_statements("planted.md", planted);
  ASSERT_EQ(found.size(), 4u) << ::testing::PrintToString(found);
  EXPECT_EQ(found[0], "planted.md:1: no structure 'kd-tree'");
  EXPECT_EQ(found[1], "planted.md:2: says 'Exact' is not built, which the build has");
  EXPECT_EQ(found[2], "planted.md:3: no scheduler 'fast'");
  EXPECT_EQ(found[3], "planted.md:3: no query type 'knn'");
}

TEST(DocsAreTrue, TheLibraryPagesQueriesTableShowsEverySessionQuery) {
  const std::string library = test::read_file(std::string(KINETIC_DOCS_DIR) + "/library.md");
  const std::size_t from = library.find("| query | structures | answer |");
  ASSERT_NE(from, std::string::npos) << "docs/library.md: the table of queries is gone";
  const std::string table = library.substr(from, library.find("\n\n", from) - from);
  for (const char* q : scenario::query_type_names()) {
    // The session's method of each query type (max and min are top() on a tournament).
    const std::string type = q;
    const std::string method = type == "max" || type == "min" ? "top" : type;
    EXPECT_NE(table.find("`" + method + "("), std::string::npos)
        << "docs/library.md's table of queries lacks `" << method << "(...)` (query type " << q
        << ")";
  }
}

}  // namespace
}  // namespace kinetic
