#pragma once
// Storage for the large per-object and per-event arrays read at random places (the event
// path's: the sort's order, positions, certificates and motion entries, the queue's slots,
// positions and tiers; the motion table's coefficients; the kd-trees' query arrays): an
// allocation of 2 MiB or more is aligned to 2 MiB, rounded up to whole 2 MiB pages, and offered
// to the kernel for transparent huge pages (madvise MADV_HUGEPAGE on Linux; under THP "never",
// or without MADV_HUGEPAGE, the same aligned allocation without the advice). Smaller ones are
// aligned to a 64-byte cache line (the event queue's heap relies on it). At n = 10^6 the event path
// reads these arrays at random places; with 4 KiB pages nearly every such read also misses the TLB.
// A hint only: it changes no value and no decision.

#include <cstddef>
#include <new>
#include <vector>

namespace kinetic {

namespace huge_pages {
inline constexpr std::size_t kPage = std::size_t{2} << 20;
inline constexpr std::size_t kLine = 64;
/// Allocates `bytes`: >= kPage: 2 MiB aligned, rounded up to whole pages, advised; otherwise
/// kLine aligned.
void* allocate(std::size_t bytes);
void deallocate(void* p, std::size_t bytes) noexcept;
}  // namespace huge_pages

template <class T>
struct HugePageAllocator {
  using value_type = T;
  HugePageAllocator() = default;
  template <class U>
  explicit HugePageAllocator(const HugePageAllocator<U>&) {}
  T* allocate(std::size_t n) { return static_cast<T*>(huge_pages::allocate(n * sizeof(T))); }
  void deallocate(T* p, std::size_t n) noexcept { huge_pages::deallocate(p, n * sizeof(T)); }
  friend bool operator==(const HugePageAllocator&, const HugePageAllocator&) = default;
};

/// A vector whose large allocations are offered huge pages.
template <class T>
using HugeVector = std::vector<T, HugePageAllocator<T>>;

}  // namespace kinetic
