// Test entry point. Property tests must be reproducible: RapidCheck would otherwise seed itself
// from the clock, so a fixed seed is set unless RC_PARAMS is given (to reproduce or explore).

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>

int main(int argc, char** argv) {
  if (std::getenv("RC_PARAMS") == nullptr) {
    setenv("RC_PARAMS", "seed=20261122 max_success=200 verbose_progress=0", 0);
  }
  std::fprintf(stderr, "RapidCheck: RC_PARAMS=\"%s\"\n", std::getenv("RC_PARAMS"));
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
