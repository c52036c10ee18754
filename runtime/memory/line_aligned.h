// Storage that starts on a 64-byte cache line: frame buffers handed to the
// renderer, whose rows it stores a whole line at a time when they start on
// one (raytrace/render/output/output_staging.h).
#pragma once

#include <cstddef>
#include <new>
#include <vector>

namespace sinew {

inline constexpr std::size_t kCacheLineBytes = 64;

template <class T>
struct LineAlignedAllocator {
  using value_type = T;
  LineAlignedAllocator() = default;
  template <class U>
  LineAlignedAllocator(const LineAlignedAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) {
    return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t{kCacheLineBytes}));
  }
  // The unsized form: clang declares the sized one only with
  // -fsized-deallocation.
  void deallocate(T* p, std::size_t /*n*/) noexcept { ::operator delete(p, std::align_val_t{kCacheLineBytes}); }
  template <class U>
  bool operator==(const LineAlignedAllocator<U>&) const noexcept {
    return true;
  }
};

template <class T>
using LineAlignedVector = std::vector<T, LineAlignedAllocator<T>>;

}  // namespace sinew
