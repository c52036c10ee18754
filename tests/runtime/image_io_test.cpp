#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "runtime/image/image_io.h"
#include "tests/support/temp_dir.h"

namespace sinew {
namespace {

TEST(ImageIo, PngRoundTripIsExact) {
  testing_support::TempDir dir;
  const int w = 37, h = 19;  // odd sizes catch row-stride mistakes
  std::vector<std::uint8_t> rgba(static_cast<std::size_t>(w * h * 4));
  for (std::size_t i = 0; i < rgba.size(); ++i) rgba[i] = static_cast<std::uint8_t>((i * 7919) % 256);
  const std::string path = dir.file("color.png");
  ASSERT_TRUE(write_png(path, w, h, 4, rgba).ok());
  auto image = read_image(path);
  ASSERT_TRUE(image.ok()) << image.status().message();
  EXPECT_EQ(image->desc.width, w);
  EXPECT_EQ(image->desc.height, h);
  EXPECT_EQ(image->desc.channels, 4);
  EXPECT_EQ(image->desc.type, PixelType::kU8);
  const auto px = image->as<std::uint8_t>();
  ASSERT_EQ(px.size(), rgba.size());
  EXPECT_TRUE(std::equal(px.begin(), px.end(), rgba.begin()));
}

TEST(ImageIo, FloatExrRoundTripKeepsInfinityAndBits) {
  testing_support::TempDir dir;
  const int w = 8, h = 5;
  std::vector<float> depth(static_cast<std::size_t>(w * h));
  for (std::size_t i = 0; i < depth.size(); ++i) depth[i] = 0.001f * float(i * i) + 1e-7f;
  depth[3] = std::numeric_limits<float>::infinity();  // a miss
  const std::string path = dir.file("depth.exr");
  ASSERT_TRUE(write_exr(path, w, h, 1, depth).ok());
  auto image = read_image(path);
  ASSERT_TRUE(image.ok()) << image.status().message();
  EXPECT_EQ(image->desc.type, PixelType::kF32);
  const auto px = image->as<float>();
  ASSERT_EQ(px.size(), depth.size());
  for (std::size_t i = 0; i < depth.size(); ++i) EXPECT_EQ(px[i], depth[i]) << i;
}

TEST(ImageIo, Uint32ExrRoundTripKeepsAllBits) {
  testing_support::TempDir dir;
  const int w = 4, h = 3;
  std::vector<std::uint32_t> ids = {0, 1, 2, 0xFFFFFFFFu, 16777217u, 123456789u,
                                    0x80000000u, 7, 8, 9, 10, 0xFFFFFFFEu};
  const std::string path = dir.file("triangle_id.exr");
  ASSERT_TRUE(write_exr(path, w, h, 1, ids).ok());
  auto image = read_image(path);
  ASSERT_TRUE(image.ok()) << image.status().message();
  EXPECT_EQ(image->desc.type, PixelType::kU32);
  const auto px = image->as<std::uint32_t>();
  ASSERT_EQ(px.size(), ids.size());
  for (std::size_t i = 0; i < ids.size(); ++i) EXPECT_EQ(px[i], ids[i]) << i;
}

TEST(ImageIo, RejectsBadArguments) {
  testing_support::TempDir dir;
  std::vector<std::uint8_t> small(10);
  Status s = write_png(dir.file("a.png"), 4, 4, 4, small);
  EXPECT_EQ(s.code(), ErrorCode::kInvalidArgument);
  EXPECT_THAT(s.message(), ::testing::HasSubstr("10 bytes"));
  std::vector<float> f(16);
  EXPECT_EQ(write_exr(dir.file("a.png"), 4, 4, 1, f).code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(write_png(dir.file("a.png"), 0, 4, 4, {}).code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(write_exr(dir.file("nope.unknownext"), 4, 4, 1, f).code(), ErrorCode::kIoError);
  EXPECT_TRUE(std::filesystem::is_empty(dir.path())) << "failed writes leave nothing behind";
}

TEST(ImageIo, ReadErrors) {
  testing_support::TempDir dir;
  EXPECT_EQ(read_image(dir.file("missing.png")).status().code(), ErrorCode::kNotFound);
}

}  // namespace
}  // namespace sinew
