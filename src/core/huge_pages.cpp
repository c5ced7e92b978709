#include "kinetic/core/huge_pages.hpp"

#include <cstdlib>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace kinetic::huge_pages {

void* allocate(std::size_t bytes) {
  if (bytes < kPage) return ::operator new (bytes, std::align_val_t{kLine});
  const std::size_t rounded = (bytes + kPage - 1) / kPage * kPage;
  void* p = std::aligned_alloc(kPage, rounded);
  if (p == nullptr) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  (void)madvise(p, rounded, MADV_HUGEPAGE);  // (a hint: refused is fine)
#endif
  return p;
}

void deallocate(void* p, std::size_t bytes) noexcept {
  if (bytes < kPage) {
    ::operator delete (p, std::align_val_t{kLine});
  } else {
    std::free(p);
  }
}

}  // namespace kinetic::huge_pages
