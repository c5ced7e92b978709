#pragma once
// Fuzz support: reads numbers and choices from the fuzzer's bytes, deterministically; past the
// end every read returns zero, so any byte string is a valid input.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

namespace kinetic::fuzz {

/// A violated property: the harness aborts with this message (libFuzzer reports a crash and
/// keeps the input; the corpus replay fails the test).
/// What the current input plays (the structure, the scheduler), named by every failure.
inline std::string& context() {
  static std::string c;
  return c;
}

[[noreturn]] inline void fail(const std::string& what) {
  std::fprintf(stderr, "fuzz property violated: %s (%s)\n", what.c_str(), context().c_str());
  std::abort();
}

class Input {
 public:
  Input(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  [[nodiscard]] bool done() const { return pos_ >= size_; }
  std::uint8_t byte() { return pos_ < size_ ? data_[pos_++] : 0; }
  /// An integer in [0, n) (n >= 1).
  std::uint32_t below(std::uint32_t n) {
    const std::uint32_t v =
        static_cast<std::uint32_t>(byte()) | (static_cast<std::uint32_t>(byte()) << 8);
    return v % n;
  }
  /// A small integer in [-m, m].
  int small(int m) { return static_cast<int>(below(static_cast<std::uint32_t>(2 * m + 1))) - m; }
  /// A double that degenerate inputs are made of: small integers, halves and quarters, and now
  /// and then a power of two far from 1 or a raw bit pattern (finite only).
  double number() {
    switch (below(8)) {
      case 0: {
        std::uint64_t bits = 0;
        for (int k = 0; k < 8; ++k) bits |= static_cast<std::uint64_t>(byte()) << (8 * k);
        double v = 0.0;
        std::memcpy(&v, &bits, sizeof v);
        return std::isfinite(v) ? v : 0.0;
      }
      case 1:
        return std::ldexp(static_cast<double>(small(8)), small(60));
      case 2:
        return static_cast<double>(small(8)) / 4.0;
      default:
        return static_cast<double>(small(6));
    }
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

}  // namespace kinetic::fuzz
