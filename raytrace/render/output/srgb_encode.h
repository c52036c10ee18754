// Linear RGB to RGBA8 pixels, many at once, at the CPU's widest vectors:
// sixteen lanes an instruction where it has AVX-512 (chosen at run time),
// eight with AVX2. The encoding is a third of a colour-only frame's
// shading (docs/RAYTRACE.md, "Renderer", sRGB bytes), and it is all
// arithmetic, so twice the lanes is half the time. Every path gives
// srgb_steps' bytes (srgb.h), bit for bit, so an image does not depend on
// the CPU that made it.
#pragma once

#include <cstddef>
#include <cstdint>

namespace sinew::rt {

// count must be a multiple of this.
inline constexpr std::size_t kSrgbEncodeLanes = 16;

// rgba[i] = the sRGB bytes of (r[i], g[i], b[i]), R in the low byte, alpha
// 255, for i in [0, count).
void srgb_encode(const float* r, const float* g, const float* b, std::uint32_t* rgba, std::size_t count);

// The paths, for tests and benchmark labels. srgb_encode_16 runs only where
// srgb_encode_16_available() (it is AVX-512F code).
void srgb_encode_8(const float* r, const float* g, const float* b, std::uint32_t* rgba, std::size_t count);
void srgb_encode_16(const float* r, const float* g, const float* b, std::uint32_t* rgba, std::size_t count);
bool srgb_encode_16_available();
// "avx512", "avx2" or "scalar": the path srgb_encode takes here.
const char* srgb_encode_path();

}  // namespace sinew::rt
