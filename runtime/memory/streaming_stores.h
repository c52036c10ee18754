// Streaming (non-temporal) stores: bytes written to memory without being
// read into the cache first, for output a frame writes once and does not
// read back (the renderer's output planes). The one place outside the lane
// types where raw intrinsics appear for them.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "runtime/memory/line_aligned.h"

namespace sinew {

// `n` bytes from `src` to `dst`: the whole 64-byte lines of dst by
// streaming stores, the ragged ends by ordinary ones (a streaming store to
// part of a line costs memory far more than the ordinary store does).
inline void stream_copy(std::byte* dst, const std::byte* src, std::size_t n) {
#if defined(__SSE2__)
  const std::size_t misalign = reinterpret_cast<std::uintptr_t>(dst) % kCacheLineBytes;
  const std::size_t head = std::min(n, misalign == 0 ? 0 : kCacheLineBytes - misalign);
  std::memcpy(dst, src, head);
  std::size_t i = head;
  for (; i + kCacheLineBytes <= n; i += kCacheLineBytes) {
    for (std::size_t k = 0; k < kCacheLineBytes; k += 16) {
      const __m128i chunk = _mm_loadu_si128(reinterpret_cast<const __m128i*>(src + i + k));
      _mm_stream_si128(reinterpret_cast<__m128i*>(dst + i + k), chunk);
    }
  }
  std::memcpy(dst + i, src + i, n - i);
#else
  std::memcpy(dst, src, n);
#endif
}

// Orders the streaming stores before every later store (call once after a
// batch of stream_copy, before another thread may read the bytes).
inline void stream_fence() {
#if defined(__SSE2__)
  _mm_sfence();
#endif
}

}  // namespace sinew
