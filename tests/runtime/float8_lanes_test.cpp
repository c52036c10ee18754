// Lane helpers of runtime/math/float8.h that shading and shadow compaction
// rely on, against hand-checked lane patterns (both the AVX2 and the
// lane-by-lane build run the same cases).
#include <gtest/gtest.h>

#include <array>
#include <cstdint>

#include "runtime/math/float8.h"

namespace sinew {
namespace {

TEST(Float8Lanes, LanesEqualSetsTheBitsOfMatchingValues) {
  const std::array<std::uint32_t, 9> v = {7, 7, 3, 7, 0xFFFFFFFFu, 7, 0, 7, 7};
  EXPECT_EQ(lanes_equal(v.data(), 7), 0b10101011u);
  EXPECT_EQ(lanes_equal(v.data(), 3), 0b00000100u);
  EXPECT_EQ(lanes_equal(v.data(), 0xFFFFFFFFu), 0b00010000u);  // kInvalidId-like values compare as values
  EXPECT_EQ(lanes_equal(v.data(), 5), 0u);
  // Unaligned: the eight values from the second on.
  EXPECT_EQ(lanes_equal(v.data() + 1, 7), 0b11010101u);
  const std::array<std::uint32_t, 8> same = {4, 4, 4, 4, 4, 4, 4, 4};
  EXPECT_EQ(lanes_equal(same.data(), 4), 0xFFu);
}

TEST(Float8Lanes, CompressStoreKeepsTheMaskedLanesInOrder) {
  alignas(32) const float in[8] = {0.5f, 1.5f, 2.5f, 3.5f, 4.5f, 5.5f, 6.5f, 7.5f};
  float out[8] = {};
  compress_store(out, Float8::load(in), 0b10010110u);
  EXPECT_EQ(out[0], 1.5f);
  EXPECT_EQ(out[1], 2.5f);
  EXPECT_EQ(out[2], 4.5f);
  EXPECT_EQ(out[3], 7.5f);
  std::uint32_t ids[8] = {};
  compress_store_lane_indices(ids, 40, 0b10000001u);
  EXPECT_EQ(ids[0], 40u);
  EXPECT_EQ(ids[1], 47u);
}

TEST(Float8Lanes, StoreWhereWritesOnlyTheMaskedLanes) {
  // One word of padding either side: nothing outside the eight is touched,
  // and ids that read as NaN floats keep their bits.
  std::array<std::uint32_t, 10> words = {1, 10, 11, 12, 13, 14, 15, 16, 17, 2};
  store_where(Mask8::from_bits(0b10100101u), 0xFFFFFFFFu, words.data() + 1);
  EXPECT_EQ(words, (std::array<std::uint32_t, 10>{1, 0xFFFFFFFFu, 11, 0xFFFFFFFFu, 13, 14, 0xFFFFFFFFu, 16,
                                                    0xFFFFFFFFu, 2}));
  store_where(Mask8::from_bits(0u), 7u, words.data() + 1);
  EXPECT_EQ(words[2], 11u);
  store_where(Mask8::from_bits(0xFFu), 0x7FA00001u, words.data() + 1);  // a signalling NaN's bits
  for (std::size_t i = 1; i <= 8; ++i) EXPECT_EQ(words[i], 0x7FA00001u) << i;
  EXPECT_EQ(words[0], 1u);
  EXPECT_EQ(words[9], 2u);
}

}  // namespace
}  // namespace sinew
