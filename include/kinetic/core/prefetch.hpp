#pragma once
// A memory hint: asks for the cache line at `p` before it is read. It changes no value and no
// decision. The empty volatile asm keeps the compiler from treating a function made only of
// hints as pure and deleting the calls to it (GCC does so with __builtin_prefetch alone).

#include <cstdint>

namespace kinetic {

inline void prefetch_line(const void* p) {
#if defined(__GNUC__)
  __builtin_prefetch(p);
  asm volatile("" : : "r"(p));
#else
  (void)p;
#endif
}

/// Asks for every cache line of [first, last), from the line that holds `first`.
inline void prefetch_range(const void* first, const void* last) {
  constexpr std::uintptr_t kLine = 64;
  const auto end = reinterpret_cast<std::uintptr_t>(last);
  for (std::uintptr_t a = reinterpret_cast<std::uintptr_t>(first) & ~(kLine - 1); a < end;
       a += kLine) {
    prefetch_line(reinterpret_cast<const void*>(a));
  }
}

}  // namespace kinetic
