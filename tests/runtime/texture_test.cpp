// Textures: the mip chain against hand-averaged texels, the sRGB curve at
// hand-checked points, bilinear lookups against a double-precision
// sampler written here from the definition (texel centres at (i + 0.5) /
// side, each wrap mode), level selection at exact powers of two, decoding
// through OpenImageIO against the bytes written, and the refusals.
#include <gtest/gtest.h>

#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/lsan_interface.h>
#endif

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <unistd.h>
#include <vector>

#include "runtime/image/image_io.h"
#include "runtime/image/texture.h"
#include "runtime/image/texture_decode.h"
#include "runtime/image/texture_sample.h"

namespace sinew {
namespace {

namespace fs = std::filesystem;

Texture texture_of(std::uint32_t w, std::uint32_t h, const std::vector<float>& rgba,
                   TextureWrap wrap_u = TextureWrap::kRepeat, TextureWrap wrap_v = TextureWrap::kRepeat) {
  auto t = make_texture("test", w, h, rgba, wrap_u, wrap_v);
  EXPECT_TRUE(t.ok()) << t.status().message();
  return std::move(*t);
}

TEST(Texture, TheMipChainHalvesEachSideDownToOneTexelAveragingWhatItCovers) {
  // 5x3 of known values: level 1 is 2x1 (the odd column and row dropped),
  // level 2 is 1x1.
  std::vector<float> rgba;
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 5; ++x) {
      const float v = static_cast<float>(x + 5 * y) / 16.0f;
      rgba.insert(rgba.end(), {v, 1.0f - v, 0.5f, 1.0f});
    }
  }
  const Texture t = texture_of(5, 3, rgba);
  ASSERT_EQ(t.levels.size(), 3u);
  EXPECT_EQ(t.levels[1].width, 2u);
  EXPECT_EQ(t.levels[1].height, 1u);
  EXPECT_EQ(t.levels[2].width, 1u);
  EXPECT_EQ(t.levels[2].height, 1u);
  const auto unorm = [](float v) { return static_cast<std::uint16_t>(v * 65535.0f + 0.5f); };
  // Level 1 texel 0: texels (0,0) (1,0) (0,1) (1,1) = 0, 1, 5, 6 sixteenths.
  const std::uint32_t sum = unorm(0.0f) + unorm(1 / 16.0f) + unorm(5 / 16.0f) + unorm(6 / 16.0f);
  EXPECT_EQ(t.levels[1].texels[0][0], (sum + 2) / 4);
  // Level 1 texel 1: 2, 3, 7, 8 sixteenths.
  const std::uint32_t sum1 = unorm(2 / 16.0f) + unorm(3 / 16.0f) + unorm(7 / 16.0f) + unorm(8 / 16.0f);
  EXPECT_EQ(t.levels[1].texels[1][0], (sum1 + 2) / 4);
  // Level 2 (a 2x1 level halves along x only).
  EXPECT_EQ(t.levels[2].texels[0][0], (t.levels[1].texels[0][0] + t.levels[1].texels[1][0] + 1) / 2);
  EXPECT_EQ(t.levels[0].texels[0][2], unorm(0.5f));
  EXPECT_TRUE(check_texture(t, "f", "t").ok());
}

TEST(Texture, SrgbDecodesOnTheStandardsCurve) {
  EXPECT_EQ(srgb_to_linear(0.0f), 0.0f);
  EXPECT_FLOAT_EQ(srgb_to_linear(1.0f), 1.0f);
  EXPECT_NEAR(srgb_to_linear(0.04045f), 0.04045 / 12.92, 1e-7);
  EXPECT_NEAR(srgb_to_linear(0.5f), 0.21404114, 1e-6);  // ((0.5 + 0.055) / 1.055)^2.4
  EXPECT_NEAR(srgb_to_linear(188.0f / 255.0f), 0.50289, 1e-5);
  EXPECT_EQ(srgb_to_linear(-1.0f), 0.0f);
  EXPECT_EQ(texel_from_linear(std::nanf(""), 2.0f, -1.0f, 0.5f), (Texel16{0, 65535, 0, 32768}));
}

// The reference: bilinear over level `l`'s stored values in double, with
// the wrap written out per mode.
double wrap_index(long i, long side, TextureWrap wrap) {
  switch (wrap) {
    case TextureWrap::kRepeat: return static_cast<double>(((i % side) + side) % side);
    default: return static_cast<double>(std::clamp(i, 0L, side - 1));
  }
}

double reference(const Texture& t, std::uint32_t l, double u, double v, int c) {
  const TextureLevel& level = t.levels[l];
  const auto coordinate = [](double x, TextureWrap wrap) {
    if (wrap == TextureWrap::kRepeat) return x - std::floor(x);
    if (wrap == TextureWrap::kClamp) return std::clamp(x, 0.0, 1.0);
    const double f = x - 2.0 * std::floor(x / 2.0);
    return f > 1.0 ? 2.0 - f : f;
  };
  const double x = coordinate(u, t.wrap_u) * level.width - 0.5;
  const double y = coordinate(v, t.wrap_v) * level.height - 0.5;
  const long x0 = static_cast<long>(std::floor(x)), y0 = static_cast<long>(std::floor(y));
  const double fx = x - static_cast<double>(x0), fy = y - static_cast<double>(y0);
  double out = 0.0;
  for (int dy = 0; dy < 2; ++dy) {
    for (int dx = 0; dx < 2; ++dx) {
      const auto xi = static_cast<std::size_t>(wrap_index(x0 + dx, level.width, t.wrap_u));
      const auto yi = static_cast<std::size_t>(wrap_index(y0 + dy, level.height, t.wrap_v));
      const double w = (dx ? fx : 1.0 - fx) * (dy ? fy : 1.0 - fy);
      out += w * level.texels[yi * level.width + xi][static_cast<std::size_t>(c)] / 65535.0;
    }
  }
  return out;
}

TEST(Texture, BilinearLookupsMatchTheDefinitionInEveryWrapMode) {
  std::mt19937 g(7);
  std::uniform_real_distribution<float> value(0.0f, 1.0f), coordinate(-2.5f, 3.5f);
  std::vector<float> rgba;
  for (int i = 0; i < 7 * 4; ++i) rgba.insert(rgba.end(), {value(g), value(g), value(g), 1.0f});
  for (const TextureWrap wrap : {TextureWrap::kRepeat, TextureWrap::kClamp, TextureWrap::kMirror}) {
    const Texture t = texture_of(7, 4, rgba, wrap, wrap);
    for (std::uint32_t l = 0; l < t.levels.size(); ++l) {
      for (int i = 0; i < 2000; ++i) {
        const Vec2 uv(coordinate(g), coordinate(g));
        const Vec3 got = sample_bilinear(t, l, uv);
        for (int c = 0; c < 3; ++c) {
          ASSERT_NEAR(got[c], reference(t, l, uv.x, uv.y, c), 2e-6)
              << "wrap " << static_cast<int>(wrap) << " level " << l << " uv " << uv.x << "," << uv.y;
        }
      }
    }
  }
  // At a texel centre the lookup is that texel.
  const Texture t = texture_of(7, 4, rgba);
  const Vec3 centre = sample_bilinear(t, 0, Vec2(2.5f / 7.0f, 1.5f / 4.0f));
  EXPECT_NEAR(centre.x, t.levels[0].texels[1 * 7 + 2][0] / 65535.0f, 1e-6f);
}

TEST(Texture, TheLevelIsHalfTheLog2OfTheTexelsAPixelCovers) {
  const Texture t = texture_of(64, 64, std::vector<float>(64 * 64 * 4, 0.5f));
  ASSERT_EQ(t.levels.size(), 7u);
  const float texel = 1.0f / (64.0f * 64.0f);  // one level-0 texel's uv area
  EXPECT_EQ(texture_level(t, 0.25f * texel), 0u);  // magnified
  EXPECT_EQ(texture_level(t, texel), 0u);
  EXPECT_EQ(texture_level(t, 4.0f * texel), 1u);   // 2x2 texels: level 1 exactly
  EXPECT_EQ(texture_level(t, 16.0f * texel), 2u);
  EXPECT_EQ(texture_level(t, 64.0f * texel), 3u);
  EXPECT_EQ(texture_level(t, 1.9f * texel), 0u);   // log2 0.93: rounds to 0
  EXPECT_EQ(texture_level(t, 2.2f * texel), 1u);   // 0.57: rounds to 1
  EXPECT_EQ(texture_level(t, 1e9f), 6u);           // clamped to the 1x1 level
  EXPECT_EQ(texture_level(t, std::numeric_limits<float>::infinity()), 6u);
  EXPECT_EQ(texture_level(t, std::nanf("")), 0u);
  EXPECT_EQ(texture_level(t, 0.0f), 0u);
}

TEST(Texture, MadeAndCheckedTexturesRefuseWhatTheRendererCouldNotSample) {
  EXPECT_FALSE(make_texture("x", 0, 4, {}, TextureWrap::kRepeat, TextureWrap::kRepeat).ok());
  EXPECT_FALSE(make_texture("x", kMaxTextureSide + 1, 1, std::vector<float>((kMaxTextureSide + 1) * 4),
                            TextureWrap::kRepeat, TextureWrap::kRepeat)
                   .ok());
  EXPECT_FALSE(make_texture("x", 2, 2, std::vector<float>(15), TextureWrap::kRepeat, TextureWrap::kRepeat).ok());
  const Texture good = texture_of(4, 2, std::vector<float>(32, 0.25f));
  Texture bad = good;
  bad.levels[1].width = 3;
  Status s = check_texture(bad, "a.pack", "TEXR.textures[0]");
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.field(), "TEXR.textures[0].levels[1].width");
  bad = good;
  bad.levels.pop_back();
  EXPECT_FALSE(check_texture(bad, "a.pack", "t").ok());  // the chain must reach 1x1
  bad = good;
  bad.levels[0].texels.pop_back();
  EXPECT_EQ(check_texture(bad, "a.pack", "t").field(), "t.levels[0].texels");
  bad = good;
  bad.wrap_v = static_cast<TextureWrap>(7);
  EXPECT_EQ(check_texture(bad, "a.pack", "t").field(), "t.wrap");
}

class TextureDecode : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("sinew_texture_test_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  fs::path dir_;
};

TEST_F(TextureDecode, PngBytesAndFilesDecodeToTheLinearValuesOfTheirSrgbBytes) {
  // 3x2 RGB with every byte different.
  std::vector<std::uint8_t> bytes;
  for (int i = 0; i < 3 * 2 * 3; ++i) bytes.push_back(static_cast<std::uint8_t>(13 * i + 5));
  const std::string path = (dir_ / "t.png").string();
  ASSERT_TRUE(write_png(path, 3, 2, 3, bytes).ok());
  std::ifstream in(path, std::ios::binary);
  const std::vector<char> file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto from_memory = decode_texture(std::as_bytes(std::span(file)), "image/png", "mem", TextureWrap::kClamp,
                                          TextureWrap::kMirror);
  ASSERT_TRUE(from_memory.ok()) << from_memory.status().message();
  const auto from_sniffed = decode_texture(std::as_bytes(std::span(file)), "", "mem", TextureWrap::kRepeat,
                                           TextureWrap::kRepeat);
  ASSERT_TRUE(from_sniffed.ok()) << from_sniffed.status().message();
  const auto from_file = read_texture(path, TextureWrap::kRepeat, TextureWrap::kRepeat);
  ASSERT_TRUE(from_file.ok()) << from_file.status().message();
  for (const Texture* t : {&*from_memory, &*from_sniffed, &*from_file}) {
    ASSERT_EQ(t->levels[0].width, 3u);
    ASSERT_EQ(t->levels[0].height, 2u);
    for (std::size_t p = 0; p < 6; ++p) {
      for (int c = 0; c < 3; ++c) {
        const float want = srgb_to_linear(static_cast<float>(bytes[3 * p + static_cast<std::size_t>(c)]) / 255.0f);
        EXPECT_NEAR(t->levels[0].texels[p][static_cast<std::size_t>(c)] / 65535.0f, want, 1.0f / 65535.0f);
      }
      EXPECT_EQ(t->levels[0].texels[p][3], 65535);  // no alpha: opaque
    }
  }
  EXPECT_EQ(from_memory->wrap_u, TextureWrap::kClamp);
  EXPECT_EQ(from_memory->wrap_v, TextureWrap::kMirror);
}

// Allocations made while it lives are not reported as leaks (a no-op
// without LeakSanitizer).
struct LeakCheckPause {
#if defined(__SANITIZE_ADDRESS__)
  LeakCheckPause() { __lsan_disable(); }
  ~LeakCheckPause() { __lsan_enable(); }
#endif
};

TEST_F(TextureDecode, BytesNoDecoderReadsAndMissingFilesAreErrorsNamingTheImage) {
  const std::vector<std::byte> junk(100, std::byte{0x5A});
  const auto junk_texture = decode_texture(junk, "image/png", "model.glb: images[3]", TextureWrap::kRepeat,
                                           TextureWrap::kRepeat);
  ASSERT_FALSE(junk_texture.ok());
  EXPECT_NE(junk_texture.status().message().find("images[3]"), std::string::npos);
  const auto missing = read_texture((dir_ / "none.tga").string(), TextureWrap::kRepeat, TextureWrap::kRepeat);
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().code(), ErrorCode::kNotFound);
  // A truncated PNG: the header promises what the bytes do not hold.
  std::vector<std::uint8_t> pixels(64 * 64 * 3, 200);
  const std::string path = (dir_ / "big.png").string();
  ASSERT_TRUE(write_png(path, 64, 64, 3, pixels).ok());
  std::ifstream in(path, std::ios::binary);
  std::vector<char> file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  file.resize(file.size() / 2);
  // OpenImageIO 2.4 leaks its error string when libpng fails mid-image
  // (libpng's longjmp leaves it behind), with no frame of Sinew's for a
  // suppression to name: LeakSanitizer ignores that one call's allocations.
  {
    [[maybe_unused]] const LeakCheckPause pause;
    EXPECT_FALSE(decode_texture(std::as_bytes(std::span(file)), "image/png", "half", TextureWrap::kRepeat,
                                TextureWrap::kRepeat)
                     .ok());
  }
}

}  // namespace
}  // namespace sinew
