#include "runtime/image/texture.h"

#include <algorithm>
#include <cmath>

namespace sinew {

float srgb_to_linear(float encoded) {
  const float c = std::clamp(encoded, 0.0f, 1.0f);
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

namespace {

std::uint16_t unorm16(float x) {
  // NaN fails both comparisons and reads as 0.
  const float c = x > 0.0f ? (x < 1.0f ? x : 1.0f) : 0.0f;
  return static_cast<std::uint16_t>(c * 65535.0f + 0.5f);
}

// The next level from `fine`: each texel the mean of the up to 2x2 it
// covers (a side of 1 stays 1 and averages one texel along it); an odd
// side's last row or column is dropped, as mip_side rounds down.
TextureLevel halved(const TextureLevel& fine) {
  TextureLevel coarse;
  coarse.width = mip_side(fine.width);
  coarse.height = mip_side(fine.height);
  coarse.texels.resize(static_cast<std::size_t>(coarse.width) * coarse.height);
  const std::uint32_t sx = fine.width > 1 ? 2 : 1, sy = fine.height > 1 ? 2 : 1;
  for (std::uint32_t y = 0; y < coarse.height; ++y) {
    for (std::uint32_t x = 0; x < coarse.width; ++x) {
      std::array<std::uint32_t, 4> sum{};
      for (std::uint32_t dy = 0; dy < sy; ++dy) {
        for (std::uint32_t dx = 0; dx < sx; ++dx) {
          const Texel16& t = fine.texels[static_cast<std::size_t>(y * sy + dy) * fine.width + x * sx + dx];
          for (int c = 0; c < 4; ++c) sum[c] += t[c];
        }
      }
      const std::uint32_t n = sx * sy;
      Texel16& out = coarse.texels[static_cast<std::size_t>(y) * coarse.width + x];
      for (int c = 0; c < 4; ++c) out[c] = static_cast<std::uint16_t>((sum[c] + n / 2) / n);
    }
  }
  return coarse;
}

bool known_wrap(TextureWrap wrap) {
  return wrap == TextureWrap::kRepeat || wrap == TextureWrap::kClamp || wrap == TextureWrap::kMirror;
}

}  // namespace

Texel16 texel_from_linear(float r, float g, float b, float a) { return {unorm16(r), unorm16(g), unorm16(b), unorm16(a)}; }

Expected<Texture> make_texture(std::string name, std::uint32_t width, std::uint32_t height,
                               std::span<const float> linear, TextureWrap wrap_u, TextureWrap wrap_v) {
  if (width == 0 || height == 0 || width > kMaxTextureSide || height > kMaxTextureSide) {
    return make_error(ErrorCode::kInvalidArgument, name, "size", std::to_string(width) + "x" + std::to_string(height),
                      "each side must be 1 to " + std::to_string(kMaxTextureSide) + " texels");
  }
  const std::size_t count = static_cast<std::size_t>(width) * height;
  if (linear.size() != count * 4) {
    return make_error(ErrorCode::kInvalidArgument, name, "pixels", std::to_string(linear.size()) + " floats",
                      "expected width x height x 4 = " + std::to_string(count * 4));
  }
  Texture texture;
  texture.name = std::move(name);
  texture.wrap_u = wrap_u;
  texture.wrap_v = wrap_v;
  TextureLevel& base = texture.levels.emplace_back();
  base.width = width;
  base.height = height;
  base.texels.resize(count);
  for (std::size_t i = 0; i < count; ++i) {
    base.texels[i] = texel_from_linear(linear[4 * i], linear[4 * i + 1], linear[4 * i + 2], linear[4 * i + 3]);
  }
  while (texture.levels.back().width > 1 || texture.levels.back().height > 1) {
    TextureLevel next = halved(texture.levels.back());
    texture.levels.push_back(std::move(next));
  }
  return texture;
}

Status check_texture(const Texture& texture, std::string_view file, const std::string& field) {
  if (!known_wrap(texture.wrap_u) || !known_wrap(texture.wrap_v)) {
    return make_error(ErrorCode::kInvalidData, file, field + ".wrap",
                      std::to_string(static_cast<int>(texture.wrap_u)) + "," +
                          std::to_string(static_cast<int>(texture.wrap_v)),
                      "wrap modes are 0 (repeat), 1 (clamp) or 2 (mirror)");
  }
  if (texture.levels.empty()) return make_error(ErrorCode::kInvalidData, file, field + ".levels", "0", "no level");
  for (std::size_t l = 0; l < texture.levels.size(); ++l) {
    const TextureLevel& level = texture.levels[l];
    const std::string at = field + ".levels[" + std::to_string(l) + "]";
    const std::uint32_t want_w = l == 0 ? level.width : mip_side(texture.levels[l - 1].width);
    const std::uint32_t want_h = l == 0 ? level.height : mip_side(texture.levels[l - 1].height);
    if (level.width == 0 || level.width > kMaxTextureSide || level.width != want_w) {
      return make_error(ErrorCode::kInvalidData, file, at + ".width", std::to_string(level.width),
                        l == 0 ? "must be 1 to " + std::to_string(kMaxTextureSide)
                               : "must be half the level above, rounded down: " + std::to_string(want_w));
    }
    if (level.height == 0 || level.height > kMaxTextureSide || level.height != want_h) {
      return make_error(ErrorCode::kInvalidData, file, at + ".height", std::to_string(level.height),
                        l == 0 ? "must be 1 to " + std::to_string(kMaxTextureSide)
                               : "must be half the level above, rounded down: " + std::to_string(want_h));
    }
    if (level.texels.size() != static_cast<std::size_t>(level.width) * level.height) {
      return make_error(ErrorCode::kInvalidData, file, at + ".texels", std::to_string(level.texels.size()),
                        "must be width x height");
    }
  }
  const TextureLevel& last = texture.levels.back();
  if (last.width != 1 || last.height != 1) {
    return make_error(ErrorCode::kInvalidData, file, field + ".levels", std::to_string(texture.levels.size()),
                      "the chain must end at 1x1");
  }
  return {};
}

}  // namespace sinew
