#pragma once
// Number and column formatting shared by the experiments' reports (internal to src/experiment).

#include <cstdio>
#include <string>

namespace kinetic::experiment::format {

/// 1e-06 style, for precisions.
inline std::string eps(double value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.0e", value);
  return buf;
}

/// 1.23e-04 style.
inline std::string sci(double value) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.2e", value);
  return buf;
}

inline std::string fixed(double value, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, value);
  return buf;
}

/// Left-aligned in `width` columns.
inline std::string pad(const std::string& s, std::size_t width) {
  return s.size() >= width ? s : s + std::string(width - s.size(), ' ');
}

/// Right-aligned in `width` columns.
inline std::string lpad(const std::string& s, std::size_t width) {
  return s.size() >= width ? s : std::string(width - s.size(), ' ') + s;
}

}  // namespace kinetic::experiment::format
