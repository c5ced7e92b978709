// The documentation names what the registry has. The README's table of structures is the docs'
// one list of them: a row per structure `kinetic run` offers, with its Python class, objects and
// queries as its description says, and no row for a structure that is not built. The Python
// page's table of classes and the architecture page's folders table name only structures that
// are built. Every query type is in the scenario format's table (in backticks), every scheduler in
// the README. A structure or query type added without its docs, or docs left naming one that is
// gone, fails here, naming what is wrong and where (test_structure_list.cpp checks the registry
// against the list).

#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

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

/// The rows ("| `...") of the table that starts at the line holding `header`, up to its end.
std::vector<std::string> table_rows(const std::string& page, const std::string& header) {
  std::vector<std::string> rows;
  const std::size_t at = page.find(header);
  if (at == std::string::npos) return rows;
  std::istringstream lines(page.substr(page.rfind('\n', at) + 1));
  std::string line;
  std::getline(lines, line);  // the header
  std::getline(lines, line);  // |---|
  while (std::getline(lines, line) && line.rfind("| ", 0) == 0) rows.push_back(line);
  return rows;
}

/// The name in backticks in the k-th cell of a table row ("" when that cell is not one).
std::string cell_name(const std::string& row, int k) {
  std::size_t from = 0;
  for (int i = 0; i <= k; ++i) {
    from = row.find("| ", from);
    if (from == std::string::npos) return "";
    from += 2;
  }
  if (from >= row.size() || row[from] != '`') return "";
  const std::size_t end = row.find('`', from + 1);
  return end == std::string::npos ? "" : row.substr(from + 1, end - from - 1);
}

/// The README row's start a structure's description gives: name, Python class, objects, queries.
std::string expected_row(const run::StructureInfo& s) {
  std::string row = "| " + between('`', s.name) + " | " + between('`', s.python_class) + " | ";
  row += to_string(s.objects);
  row += " | ";
  for (std::size_t k = 0; k < s.queries.size(); ++k) {
    if (k > 0) row += ", ";
    row += between('`', to_string(s.queries[k]));
  }
  return row + " |";
}

bool is_built(const std::string& name) {
  const std::vector<run::StructureInfo>& all = run::structures();
  return std::any_of(all.begin(), all.end(),
                     [&](const run::StructureInfo& s) { return s.name == name; });
}

TEST(DocsNameTheRegistry, EveryStructureQueryTypeAndScheduler) {
  const std::string readme = doc("../README.md");
  const std::string format = doc("scenario-format.md");
  ASSERT_FALSE(readme.empty());
  ASSERT_FALSE(format.empty());
  const std::vector<std::string> rows =
      table_rows(readme, "| `--structure` | Python class | objects | queries |");
  ASSERT_FALSE(rows.empty()) << "README.md: the table of structures (\"| `--structure` | Python "
                                "class | objects | queries |\") is gone";
  std::size_t structures = 0;
  for (const run::StructureInfo& s : run::structures()) {
    ++structures;
    const std::string want = expected_row(s);
    EXPECT_TRUE(std::any_of(rows.begin(), rows.end(),
                            [&](const std::string& r) { return r.rfind(want, 0) == 0; }))
        << "README.md's table of structures has no row starting \"" << want << "\"";
  }
  EXPECT_GE(structures, 12u);
  EXPECT_EQ(rows.size(), structures) << "README.md's table of structures: one row per structure";
  for (const std::string& r : rows)
    EXPECT_TRUE(is_built(cell_name(r, 0))) << "README.md's table of structures: " << r;
  // The other pages that name structures name only those built.
  for (const std::string& r : table_rows(doc("python.md"), "| class | CLI name |"))
    EXPECT_TRUE(is_built(cell_name(r, 1))) << "docs/python.md's table of classes: " << r;
  for (const std::string& r : table_rows(doc("architecture.md"), "| folder | CLI name |")) {
    const std::string name = cell_name(r, 1);
    EXPECT_TRUE(name.empty() || is_built(name)) << "docs/architecture.md's folders table: " << r;
  }
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
