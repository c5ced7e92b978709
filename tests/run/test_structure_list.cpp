// The list of structures (structures.hpp) is what the registry serves: the same structures in
// the same order, each satisfying the structure contract, with a name and a Python class of its
// own (the Python module builds its classes from the list and the registry side by side, so a
// registry out of step with the list would give a class the wrong description or scheduler),
// and every one states its loop guard's bounds (the runner plays it on them).

#include <gtest/gtest.h>

#include <set>
#include <string>
#include <typeinfo>
#include <vector>

#include "kinetic/run/runner.hpp"
#include "kinetic/structures.hpp"
#include "run/registry.hpp"

namespace kinetic {
namespace {

TEST(StructureList, IsTheRegistryInOrderWithOneNameAndClassEach) {
  const std::vector<run::StructureInfo>& infos = run::structures();
  ASSERT_EQ(infos.size(), Structures::size);
  std::set<std::string> names, classes;
  std::size_t k = 0;
  Structures::for_each([&]<class S>() {
    static_assert(KineticStructure<S>);
    const run::StructureInfo& listed = infos[k];
    SCOPED_TRACE(typeid(S).name());
    EXPECT_EQ(S::description().name, listed.name) << "entry " << k << " of the list";
    EXPECT_NE(listed.event_bounds, nullptr) << listed.name << " has no loop-guard bounds";
    EXPECT_FALSE(listed.name.empty());
    EXPECT_FALSE(listed.python_class.empty()) << listed.name << " has no Python class";
    EXPECT_FALSE(listed.description.empty()) << listed.name;
    EXPECT_FALSE(listed.python_doc.empty()) << listed.name << " has no Python docstring";
    EXPECT_FALSE(listed.queries.empty()) << listed.name << " answers no query";
    EXPECT_TRUE(names.insert(listed.name).second) << "two structures named " << listed.name;
    EXPECT_TRUE(classes.insert(listed.python_class).second)
        << "two Python classes named " << listed.python_class;
    EXPECT_EQ(run::detail::find(listed.name), &run::detail::registry()[k]);
    ++k;
  });
  EXPECT_EQ(k, infos.size());
}

}  // namespace
}  // namespace kinetic
