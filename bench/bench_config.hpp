#pragma once
// What every benchmark shares: what it prints first about how it was built (its configuration
// line), and its clocks.

#include <malloc.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

namespace kinetic::bench {

/// CPU time of the process, of the calling thread, and wall time, in seconds.
inline double cpu_now() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}
inline double thread_now() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}
inline double wall_now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
/// A comma-separated list of sizes ("1000,10000" or "1e3,1e4"), as the --sizes options take
/// them; std::invalid_argument naming a bad item.
inline std::vector<std::size_t> parse_sizes(const std::string& s) {
  std::vector<std::size_t> out;
  std::size_t pos = 0;
  while (pos <= s.size()) {
    const std::size_t comma = std::min(s.find(',', pos), s.size());
    const std::string item = s.substr(pos, comma - pos);
    char* end = nullptr;
    const double value = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !(value >= 1.0) || value > 1e9 ||
        value != static_cast<double>(static_cast<std::size_t>(value))) {
      throw std::invalid_argument("--sizes: bad item '" + item + "' (a whole number >= 1)");
    }
    out.push_back(static_cast<std::size_t>(value));
    pos = comma + 1;
  }
  return out;
}

/// Bytes of heap in use (glibc's mallinfo2).
inline std::size_t heap_bytes() { return mallinfo2().uordblks; }

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
