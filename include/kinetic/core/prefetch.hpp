#pragma once
// A memory hint: asks for the cache line at `p` before it is read. It changes no value and no
// decision. The empty volatile asm keeps the compiler from treating a function made only of
// hints as pure and deleting the calls to it (GCC does so with __builtin_prefetch alone).

namespace kinetic {

inline void prefetch_line(const void* p) {
#if defined(__GNUC__)
  __builtin_prefetch(p);
  asm volatile("" : : "r"(p));
#else
  (void)p;
#endif
}

}  // namespace kinetic
