// The sample pattern of the stochastic rays (area-light shadow rays, ambient
// occlusion rays): a fixed function of (seed, stream, pixel, sample), so an
// image is the same for any thread count and tile order, with no random
// state anywhere.
//
// Sample j of n in a pixel is a point of the unit square
//   u = (j + xi) / n            (one point per stratum of u)
//   v = frac(j * g + eta)       (g = the golden ratio's fraction)
// where (xi, eta) are the pixel's shift. Over a pixel's n samples the
// points are a shifted rank-1 lattice: stratified in u and evenly spread in
// v, so four samples already cover the square. The shifts are interleaved
// (Keller and Heidrich's interleaved sampling): each pixel of a 2x2 block
// belongs to one of four classes in ordered-dither order (sample_class),
// the classes' shifts are themselves stratified over the square (one per
// quadrant), and the block repeats across the image, moved as a whole by an
// offset hashed from (seed, stream). So a block's 4 n samples cover the
// square evenly and the residual noise is a fine, even dither; and the
// pixels of one class take the same sample in a round, which the tracer
// uses: their rays to a light leave one point of it (a sphere light's for
// the hits that share its snapped disk, render/stages/sample_rays.cpp), so
// a packet of one class culls with frusta (render/stages/shadow_rays.cpp,
// the compaction).
// Two by two, not wider: a packet's group of eight then spans a strip of
// 16 pixels; wider interleaving spreads each group further and its frusta
// reach more triangles than the common point saves.
// On a disk the same point is radius sqrt(u), angle 2 pi v: the angle is
// the base angle 2 pi frac(j g), rotated by the pixel's 2 pi eta, so eight
// lanes rotate one shared unit vector by their own (cos, sin) (PixelShift).
#pragma once

#include <array>
#include <cstdint>

#include "runtime/math/types.h"

namespace sinew::rt {

// The most samples one pixel takes of one stream.
inline constexpr int kMaxSamples = 256;

// Streams: one per light (its index) and one for ambient occlusion.
inline constexpr std::uint32_t kAmbientOcclusionStream = 0xA0u;

// A pixel's shift of the pattern.
struct PixelShift {
  float xi = 0.0f;   // u's shift within the stratum, [0, 1)
  float eta = 0.0f;  // v's shift, [0, 1), a multiple of 1/kAngleSteps
  float cos_eta = 1.0f, sin_eta = 0.0f;  // cos and sin of 2 pi eta
};

// eta is quantised to this many steps, so its cosine and sine come from a
// table rather than from trigonometry per pixel.
inline constexpr int kAngleSteps = 1024;

// The interleaving: a pixel's class, 0 to kSampleClasses - 1, from its
// position in its kInterleave x kInterleave block.
inline constexpr int kInterleave = 2;
inline constexpr int kSampleClasses = kInterleave * kInterleave;
int sample_class(int x, int y);

PixelShift pixel_shift(std::uint32_t seed, std::uint32_t stream, int x, int y);

// Sample j's lattice terms, shared by every pixel: frac(j g) and the unit
// vector at angle 2 pi frac(j g).
struct LatticeSample {
  float v0 = 0.0f;
  float cos_v0 = 1.0f, sin_v0 = 0.0f;
};
LatticeSample lattice_sample(int j);

// Sample j of n of a pixel, in the unit square and on the unit disk (the
// reference the eight-lane code in render/stages follows).
Vec2 square_sample(const PixelShift& shift, int j, int n);
Vec2 disk_sample(const PixelShift& shift, int j, int n);

}  // namespace sinew::rt
