// The documentation says only what the build has: every `--structure X`, `--scheduler Y` and
// query `"type": "Z"` written in README.md and docs/ names a structure, scheduler or query type
// of the registry; no page says of a structure or scheduler the build has that it "is not
// built"; the library page's table of queries shows the session method of every query type. A
// planted stale page is shown to be caught. (test_docs_name_the_registry.cpp checks the other
// way: that the docs name everything the registry has.)

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
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

bool name_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '-';
}

/// f(word) for every `flag` followed by a space or '=' and a word ([A-Za-z0-9_-]+).
template <class F>
void each_after_flag(const std::string& line, const std::string& flag, F&& f) {
  for (std::size_t at = line.find(flag); at != std::string::npos; at = line.find(flag, at + 1)) {
    std::size_t b = at + flag.size();
    if (b >= line.size() || (line[b] != ' ' && line[b] != '=')) continue;
    std::size_t e = ++b;
    while (e < line.size() && name_char(line[e])) ++e;
    if (e > b) f(line.substr(b, e - b));
  }
}

/// f(word) for every `"type": "word"` (the space optional).
template <class F>
void each_query_type(const std::string& line, F&& f) {
  const std::string key = "\"type\":";
  for (std::size_t at = line.find(key); at != std::string::npos; at = line.find(key, at + 1)) {
    std::size_t b = at + key.size();
    if (b < line.size() && line[b] == ' ') ++b;
    if (b >= line.size() || line[b] != '"') continue;
    std::size_t e = ++b;
    while (e < line.size() && name_char(line[e])) ++e;
    if (e > b && e < line.size() && line[e] == '"') f(line.substr(b, e - b));
  }
}

/// f(word) for every "word is not built", "`word` are not built", "word scheduler is not built"
/// (any case).
template <class F>
void each_said_not_built(const std::string& line, F&& f) {
  std::string lower = line;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  const std::string said = " not built";
  for (std::size_t at = lower.find(said); at != std::string::npos; at = lower.find(said, at + 1)) {
    std::size_t e = at;
    for (const std::string verb : {" is", " are"}) {
      if (e >= verb.size() && lower.compare(e - verb.size(), verb.size(), verb) == 0) {
        e -= verb.size();
        break;
      }
    }
    if (e == at) continue;
    const std::string scheduler = " scheduler";
    if (e >= scheduler.size() &&
        lower.compare(e - scheduler.size(), scheduler.size(), scheduler) == 0)
      e -= scheduler.size();
    if (e > 0 && line[e - 1] == '`') --e;
    std::size_t b = e;
    while (b > 0 &&
           (std::isalpha(static_cast<unsigned char>(line[b - 1])) != 0 || line[b - 1] == '-'))
      --b;
    if (b < e) f(line.substr(b, e - b));
  }
}

/// The statements of `text` (the page `page`) that contradict the build, one message each
/// naming the page, the line and the fault.
std::vector<std::string> stale_statements(const std::string& page, const std::string& text) {
  const std::vector<std::string> structures = structure_names();
  const std::vector<std::string> schedulers = scheduler_names();
  std::vector<std::string> queries;
  for (const char* q : scenario::query_type_names()) queries.emplace_back(q);
  std::vector<std::string> found;
  std::size_t line_number = 0, from = 0;
  while (from <= text.size()) {
    const std::size_t end = std::min(text.find('\n', from), text.size());
    const std::string line = text.substr(from, end - from);
    ++line_number;
    const std::string where = page + ":" + std::to_string(line_number) + ": ";
    // (Scanned by hand: std::regex draws a false warning from GCC 12 under the sanitizers.)
    each_after_flag(line, "--structure", [&](const std::string& name) {
      if (!placeholder(name) && !contains(structures, name))
        found.push_back(where + "no structure '" + name + "'");
    });
    each_after_flag(line, "--scheduler", [&](const std::string& name) {
      if (!placeholder(name) && !contains(schedulers, name))
        found.push_back(where + "no scheduler '" + name + "'");
    });
    each_query_type(line, [&](const std::string& name) {
      if (!placeholder(name) && !contains(queries, name))
        found.push_back(where + "no query type '" + name + "'");
    });
    each_said_not_built(line, [&](const std::string& name) {
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
