#pragma once
// Test support: a RapidCheck property run with a fixed seed (RapidCheck's default seed is
// random), reported as a GoogleTest failure naming the seed. Tests only.

#include <gtest/gtest.h>
#include <rapidcheck.h>

#include <cstdint>
#include <sstream>

namespace kinetic::test {

template <class Property>
void check_with_seed(const char* name, std::uint64_t seed, int runs, int max_size,
                     Property property) {
  rc::detail::TestParams params;
  params.seed = seed;
  params.maxSuccess = runs;
  params.maxSize = max_size;
  rc::detail::TestMetadata metadata;
  metadata.id = name;
  metadata.description = name;
  const auto result = rc::detail::checkTestable(property, metadata, params);
  if (!result.template is<rc::detail::SuccessResult>()) {
    std::ostringstream os;
    rc::detail::printResultMessage(result, os);
    ADD_FAILURE() << name << " failed with RapidCheck seed " << seed << "\n" << os.str();
  }
}

}  // namespace kinetic::test
