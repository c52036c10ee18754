#include "raytrace/render/stages/tile_stages.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "raytrace/render/output/srgb.h"
#include "raytrace/render/output/srgb_encode.h"
#include "raytrace/render/stages/stage_support.h"

namespace sinew::rt {

using namespace stages;

namespace {

// A light's terms for the shading, eight lanes wide, made once per tile.
struct LightTerms {
  bool point;  // a point, sphere or rectangle light: towards `at` from the hit
  // Its shadow is the fraction of its samples that reach the hit
  // (s.light_fraction), not a bit of s.lit.
  bool soft;
  Vec3x8 at;  // the position (point) or the direction (directional)
  Vec3x8 color;
};

// The terms of `lights` (at most kMaxLights), in their order.
struct ShadingLights {
  std::array<LightTerms, kMaxLights> terms;
  std::size_t count = 0;
  bool ambient_occlusion = false;  // the ambient term is scaled by s.ao_open
  ShadingLights(const RenderSettings& settings, std::span<const Light> lights)
      : count(std::min(lights.size(), kMaxLights)), ambient_occlusion(settings.ao_rays > 0) {
    for (std::size_t l = 0; l < count; ++l) {
      const Light& light = lights[l];
      const bool point = light.kind != Light::Kind::kDirectional;
      const Vec3 at = point ? light.position : light.direction;
      terms[l] = {point, settings.shadows && light.is_area(), {Float8(at.x), Float8(at.y), Float8(at.z)},
                  {Float8(light.color.x), Float8(light.color.y), Float8(light.color.z)}};
    }
  }
  std::span<const LightTerms> span() const { return {terms.data(), count}; }
};

// The linear colour of block b's hits: ambient (times the open fraction of
// the ambient occlusion rays) plus each light's N·L to its centre, times
// the fraction of it that reaches the hit (0 or 1 for a hard light), times
// the albedo.
Vec3x8 block_color(const RenderSettings& settings, const ShadingLights& shading, const TileScratch& s,
                   std::size_t b, std::uint32_t hits) {
  const std::size_t k0 = b * kBlockLanes;
  const Vec3x8 position = load3(s.px, s.py, s.pz, k0);
  const Vec3x8 n = load3(s.nx, s.ny, s.nz, k0);
  Vec3x8 radiance{Float8(settings.ambient.x), Float8(settings.ambient.y), Float8(settings.ambient.z)};
  if (shading.ambient_occlusion) radiance = Float8::load(&s.ao_open[k0]) * radiance;
  const std::span<const LightTerms> lights = shading.span();
  for (std::size_t l = 0; l < lights.size(); ++l) {
    const LightTerms& light = lights[l];
    const std::uint32_t lit_bits = light.soft ? hits : lane_bits(&s.lit[k0], static_cast<int>(l)) & hits;
    if (lit_bits == 0) continue;
    const Vec3x8 to_light = light.point ? light.at - position : light.at;
    Float8 cosine = select(Mask8::from_bits(lit_bits),
                           max(dot(n, to_light) / sqrt(dot(to_light, to_light)), Float8(0.0f)), Float8(0.0f));
    if (light.soft) cosine = cosine * Float8::load(&s.light_fraction[l * s.lanes + k0]);
    radiance = radiance + Vec3x8{light.color.x * cosine, light.color.y * cosine, light.color.z * cosine};
  }
  return {Float8::load(&s.ar[k0]) * radiance.x, Float8::load(&s.ag[k0]) * radiance.y,
          Float8::load(&s.ab[k0]) * radiance.z};
}

// Colour alone, the output a game asks for, in three passes: the blocks'
// linear colours, their sRGB bytes sixteen lanes at a time where the CPU
// has AVX-512 (render/output/srgb_encode.h), and the rows. The plane's base and
// pitch sit in locals: stores through a plane's bytes could otherwise alias
// every field the loop reads, and each would be loaded again after every
// store.
void shade_rgba8_only(const RenderSettings& settings, std::span<const Light> lights,
                      const OutputPlane<std::uint8_t>& plane, TileScratch& s) {
  const ShadingLights shading_lights(settings, lights);
  std::byte* const base = plane.base;
  const std::size_t pitch = plane.pitch;
  const int x0 = plane.x0, y0 = plane.y0;
  std::uint32_t background;
  const std::array<std::uint8_t, 4> background_bytes = {srgb_byte(settings.background.x),
                                                         srgb_byte(settings.background.y),
                                                         srgb_byte(settings.background.z), 255};
  std::memcpy(&background, background_bytes.data(), 4);
  std::uint32_t background_row[kBlockWidth];
  for (std::uint32_t& pixel : background_row) pixel = background;
  const std::size_t blocks = s.lanes / kBlockLanes;
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::uint32_t hits = s.block_hits[b];
    if (hits == 0) continue;
    const Vec3x8 color = block_color(settings, shading_lights, s, b, hits);
    const std::size_t k0 = b * kBlockLanes;
    color.x.store(&s.lr[k0]);
    color.y.store(&s.lg[k0]);
    color.z.store(&s.lb[k0]);
  }
  // Encoded a pair of blocks at a time, in runs of pairs with a hit (the
  // lanes without one encode what they held, and are not written).
  const std::size_t pairs = (blocks + 1) / 2;
  std::size_t run = 0;
  for (std::size_t pair = 0; pair <= pairs; ++pair) {
    if (pair < pairs) {
      const std::size_t b = 2 * pair;
      if ((s.block_hits[b] | (b + 1 < blocks ? s.block_hits[b + 1] : 0u)) != 0) continue;
    }
    if (pair > run) {
      const std::size_t k = run * kSrgbEncodeLanes;
      srgb_encode(&s.lr[k], &s.lg[k], &s.lb[k], &s.rgba8[k], (pair - run) * kSrgbEncodeLanes);
    }
    run = pair + 1;
  }
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::uint32_t pixels = s.block_pixels[b];
    const std::uint32_t hits = s.block_hits[b];
    const std::uint32_t* const rgba = &s.rgba8[b * kBlockLanes];
    std::byte* const row0 = base + static_cast<std::size_t>(s.block_y0(b) - y0) * pitch +
                            static_cast<std::size_t>(s.block_x0(b) - x0) * 4;
    if (pixels == 0xFFu && (hits == 0xFFu || hits == 0u)) {
      const std::uint32_t* const source = hits != 0 ? rgba : nullptr;
      for (int row = 0; row < kBlockHeight; ++row) {
        std::memcpy(row0 + static_cast<std::size_t>(row) * pitch,
                    source ? source + row * kBlockWidth : background_row, sizeof(background_row));
      }
      continue;
    }
    for (std::uint32_t m = pixels; m != 0; m &= m - 1) {
      const int lane = std::countr_zero(m);
      std::byte* const pixel = row0 + static_cast<std::size_t>(lane / kBlockWidth) * pitch +
                               static_cast<std::size_t>(lane % kBlockWidth) * 4;
      std::memcpy(pixel, hits >> lane & 1u ? &rgba[lane] : &background, 4);
    }
  }
}

}  // namespace

void write_visibility_masks(const RenderSettings& settings, std::span<const Light> lights, const OutputPlanes& out,
                            const TileScratch& s) {
  // Which lights' masks are fractions of samples (light_fraction) rather
  // than their bit of s.lit.
  std::uint32_t soft = 0;
  for (std::size_t l = 0; l < out.shadow.channels && l < lights.size(); ++l) {
    if (settings.shadows && lights[l].is_area()) soft |= 1u << l;
  }
  const bool ambient_occlusion = settings.ao_rays > 0;
  for (std::size_t b = 0; b < s.blocks(); ++b) {
    const std::uint32_t hits = s.block_hits[b];
    for (std::uint32_t m = s.block_pixels[b]; m != 0; m &= m - 1) {
      const int lane = std::countr_zero(m);
      const std::size_t k = b * kBlockLanes + static_cast<std::size_t>(lane);
      const int x = s.block_x0(b) + lane % kBlockWidth;
      const int y = s.block_y0(b) + lane / kBlockWidth;
      const bool hit = (hits >> lane & 1u) != 0;
      if (out.shadow.wanted()) {
        float* mask = out.shadow.at(x, y);
        for (std::size_t l = 0; l < out.shadow.channels; ++l) {
          const bool fraction = (soft >> l & 1u) != 0;
          mask[l] = !hit ? 1.0f : fraction ? s.light_fraction[l * s.lanes + k] : static_cast<float>(s.lit[k] >> l & 1u);
        }
      }
      if (out.ambient_occlusion.wanted()) {
        *out.ambient_occlusion.at(x, y) = hit && ambient_occlusion ? s.ao_open[k] : 1.0f;
      }
    }
  }
}

void shade_and_write(const RenderSettings& settings, std::span<const Light> lights, const OutputPlanes& host,
                     TileScratch& s) {
  // Written to the tile's staging planes, stored to the host's at the end.
  const OutputPlanes& out = s.staging.stage(host, s.tile);
  if (host.rgba8.wanted() && !host.want_other_than_rgba8()) {
    shade_rgba8_only(settings, lights, out.rgba8, s);
    s.staging.flush(host);
    return;
  }
  const std::size_t blocks = s.lanes / kBlockLanes;
  const bool want_color = out.want_color();
  const ShadingLights shading_lights(settings, lights);
  const std::array<std::uint8_t, 4> background_bytes = {srgb_byte(settings.background.x),
                                                         srgb_byte(settings.background.y),
                                                         srgb_byte(settings.background.z), 255};
  // A row of a block that missed, whole.
  std::uint32_t background_row[kBlockWidth];
  for (std::uint32_t& pixel : background_row) std::memcpy(&pixel, background_bytes.data(), 4);
  if (out.shadow.wanted() || out.ambient_occlusion.wanted()) write_visibility_masks(settings, lights, out, s);
  static constexpr float kMissDepths[kBlockWidth] = {kInf, kInf, kInf, kInf};
  static constexpr std::uint32_t kMissIds[kBlockWidth] = {kInvalidId, kInvalidId, kInvalidId, kInvalidId};
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::size_t k0 = b * kBlockLanes;
    const std::uint32_t pixels = s.block_pixels[b];
    const std::uint32_t hits = s.block_hits[b];
    // Filled below for blocks with hits, each only when its output is
    // wanted, and read only then (so not zeroed per block).
    alignas(32) float depth[8], linear[3][8];
    alignas(32) std::uint32_t pixels_rgba8[8];
    if (hits != 0) {
      if (out.depth.wanted()) {
        const Vec3x8 dir = load3(s.dir_x, s.dir_y, s.dir_z, k0);
        (Float8::load(&s.t[k0]) * sqrt(dot(dir, dir))).store(depth);
      }
      if (want_color) {
        const Vec3x8 color = block_color(settings, shading_lights, s, b, hits);
        color.x.store(linear[0]);
        color.y.store(linear[1]);
        color.z.store(linear[2]);
        if (out.rgba8.wanted()) srgb_rgba8(color, pixels_rgba8);
      }
    }
    const int bx = s.block_x0(b);
    const int by = s.block_y0(b);
    if (pixels == 0xFFu && (hits == 0xFFu || hits == 0u)) {
      // A whole block of one kind: each output's two rows of four pixels
      // are contiguous.
      for (int row = 0; row < kBlockHeight; ++row) {
        const std::size_t k = k0 + static_cast<std::size_t>(row * kBlockWidth);
        const int y = by + row;
        if (out.triangle.wanted()) std::memcpy(out.triangle.at(bx, y), &s.triangle[k], 4 * sizeof(std::uint32_t));
        if (out.instance.wanted()) std::memcpy(out.instance.at(bx, y), &s.instance[k], 4 * sizeof(std::uint32_t));
        if (hits == 0u) {
          if (out.depth.wanted()) std::memcpy(out.depth.at(bx, y), kMissDepths, sizeof(kMissDepths));
          if (out.material.wanted()) std::memcpy(out.material.at(bx, y), kMissIds, sizeof(kMissIds));
          if (out.rgba8.wanted()) std::memcpy(out.rgba8.at(bx, y), background_row, sizeof(background_row));
          for (int i = 0; i < kBlockWidth; ++i) {
            if (out.normal.wanted()) out.normal.at(bx, y)[i] = Vec3(0.0f);
            if (out.uv.wanted()) out.uv.at(bx, y)[i] = Vec2(0.0f);
            if (out.barycentric.wanted()) out.barycentric.at(bx, y)[i] = Vec2(0.0f);
            if (out.rgba32f.wanted()) {
              float* rgba = out.rgba32f.at(bx + i, y);
              for (int c = 0; c < 3; ++c) rgba[c] = settings.background[c];
              rgba[3] = 1.0f;
            }
          }
          continue;
        }
        const int l0 = row * kBlockWidth;
        if (out.depth.wanted()) std::memcpy(out.depth.at(bx, y), &depth[l0], 4 * sizeof(float));
        if (out.normal.wanted()) {
          for (int i = 0; i < kBlockWidth; ++i) out.normal.at(bx, y)[i] = Vec3(s.nx[k + i], s.ny[k + i], s.nz[k + i]);
        }
        for (int i = 0; i < kBlockWidth; ++i) {
          if (out.uv.wanted()) out.uv.at(bx, y)[i] = Vec2(s.uv_x[k + i], s.uv_y[k + i]);
          if (out.barycentric.wanted()) out.barycentric.at(bx, y)[i] = Vec2(s.u[k + i], s.v[k + i]);
        }
        if (out.material.wanted()) std::memcpy(out.material.at(bx, y), &s.material[k], 4 * sizeof(std::uint32_t));
        if (out.rgba8.wanted()) std::memcpy(out.rgba8.at(bx, y), &pixels_rgba8[l0], 4 * sizeof(std::uint32_t));
        if (out.rgba32f.wanted()) {
          float* rgba = out.rgba32f.at(bx, y);
          for (int i = 0; i < kBlockWidth; ++i) {
            for (int c = 0; c < 3; ++c) rgba[4 * i + c] = linear[c][l0 + i];
            rgba[4 * i + 3] = 1.0f;
          }
        }
      }
      continue;
    }
    for (std::uint32_t m = pixels; m != 0; m &= m - 1) {
      const int lane = std::countr_zero(m);
      const std::size_t k = k0 + static_cast<std::size_t>(lane);
      const int x = bx + lane % kBlockWidth;
      const int y = by + lane / kBlockWidth;
      if (out.triangle.wanted()) *out.triangle.at(x, y) = s.triangle[k];
      if (out.instance.wanted()) *out.instance.at(x, y) = s.instance[k];
      if (!(hits >> lane & 1u)) {
        if (out.depth.wanted()) *out.depth.at(x, y) = kInf;
        if (out.normal.wanted()) *out.normal.at(x, y) = Vec3(0.0f);
        if (out.uv.wanted()) *out.uv.at(x, y) = Vec2(0.0f);
        if (out.barycentric.wanted()) *out.barycentric.at(x, y) = Vec2(0.0f);
        if (out.material.wanted()) *out.material.at(x, y) = kInvalidId;
        if (out.rgba32f.wanted()) {
          float* rgba = out.rgba32f.at(x, y);
          for (int c = 0; c < 3; ++c) rgba[c] = settings.background[c];
          rgba[3] = 1.0f;
        }
        if (out.rgba8.wanted()) std::memcpy(out.rgba8.at(x, y), background_bytes.data(), 4);
        continue;
      }
      if (out.depth.wanted()) *out.depth.at(x, y) = depth[lane];
      if (out.normal.wanted()) *out.normal.at(x, y) = Vec3(s.nx[k], s.ny[k], s.nz[k]);
      if (out.uv.wanted()) *out.uv.at(x, y) = Vec2(s.uv_x[k], s.uv_y[k]);
      if (out.barycentric.wanted()) *out.barycentric.at(x, y) = Vec2(s.u[k], s.v[k]);
      if (out.material.wanted()) *out.material.at(x, y) = s.material[k];
      if (out.rgba32f.wanted()) {
        float* rgba = out.rgba32f.at(x, y);
        for (int c = 0; c < 3; ++c) rgba[c] = linear[c][lane];
        rgba[3] = 1.0f;
      }
      if (out.rgba8.wanted()) std::memcpy(out.rgba8.at(x, y), &pixels_rgba8[lane], 4);
    }
  }
  s.staging.flush(host);
}

}  // namespace sinew::rt
