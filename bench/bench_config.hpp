#pragma once
// What every benchmark prints first about how it was built (its configuration line).

namespace kinetic::bench {

inline const char* build_type() {
#if defined(NDEBUG) && defined(__OPTIMIZE__)
  return "optimised, NDEBUG (Release)";
#elif defined(__OPTIMIZE__)
  return "optimised, assertions on";
#else
  return "NOT optimised (Debug): figures are meaningless";
#endif
}

inline const char* compiler() {
#if defined(__clang__)
  return "clang " __clang_version__;
#elif defined(__GNUC__)
  return "GCC " __VERSION__;
#else
  return "unknown";
#endif
}

}  // namespace kinetic::bench
