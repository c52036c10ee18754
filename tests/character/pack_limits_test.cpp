// The pack's joint limits (LIMT, version 2): binary, read back bit for bit,
// every field validated on load with an error naming the joint and field,
// and the JSON text of version 1 refused with a re-bake message (loading a
// pack parses no JSON).
#include <gtest/gtest.h>

#include <bit>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "animation/joint_limits.h"
#include "character/pack.h"
#include "content/mannequin/mannequin.h"
#include "runtime/pack/pack_reader.h"
#include "tests/support/repack.h"

namespace sinew::editor {
namespace {

constexpr std::size_t kJointBytes = 56;  // kind, order, reserved u16, 13 floats

class PackLimits : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto model = content::make_mannequin();
    ASSERT_TRUE(model.ok());
    model_ = new character::Model(std::move(*model));
    limits_ = new anim::JointLimits(content::mannequin_joint_limits(model_->skeleton));
    character::PackContents c;
    c.model = model_;
    c.limits = *limits_;
    c.provenance.source_name = "mannequin";
    auto bytes = character::serialize_pack(c);
    ASSERT_TRUE(bytes.ok()) << bytes.status().message();
    bytes_ = new std::vector<std::byte>(std::move(*bytes));
  }
  static void TearDownTestSuite() {
    delete model_;
    delete limits_;
    delete bytes_;
  }

  // The pack with LIMT's payload replaced by mutate(payload) and its
  // version by `version` (tests/support/repack.h).
  static std::vector<std::byte> repack(const std::function<void(std::vector<std::byte>&)>& mutate,
                                       std::uint32_t version = 2) {
    return testing_support::repack_section(*bytes_, make_section_id("LIMT"), mutate, version);
  }
  template <typename T>
  static void put(std::vector<std::byte>& payload, std::size_t offset, const T& value) {
    ASSERT_LE(offset + sizeof(T), payload.size());
    std::memcpy(payload.data() + offset, &value, sizeof(T));
  }
  static std::size_t joint_at(std::size_t j) { return 4 + j * kJointBytes; }
  static std::size_t first_of(anim::LimitKind kind) {
    for (std::size_t j = 0; j < limits_->size(); ++j) {
      if ((*limits_)[j].kind == kind) return j;
    }
    ADD_FAILURE() << "the mannequin has no joint of limit kind " << static_cast<int>(kind);
    return 0;
  }
  // Loading must fail with `code`, the message naming the pack and `says`.
  static void expect_refused(const std::vector<std::byte>& bytes, const std::string& says,
                             ErrorCode code = ErrorCode::kInvalidData) {
    auto pack = character::Pack::from_bytes(bytes, "corrupt.pack");
    ASSERT_FALSE(pack.ok()) << "accepted; expected an error saying " << says;
    EXPECT_EQ(pack.status().code(), code) << pack.status().message();
    EXPECT_NE(pack.status().message().find("corrupt.pack"), std::string::npos) << pack.status().message();
    EXPECT_NE(pack.status().message().find(says), std::string::npos) << pack.status().message();
  }

  static inline character::Model* model_ = nullptr;
  static inline anim::JointLimits* limits_ = nullptr;
  static inline std::vector<std::byte>* bytes_ = nullptr;
};

TEST_F(PackLimits, ReadBackBitForBit) {
  ASSERT_EQ(limits_->size(), model_->skeleton.joint_count());
  first_of(anim::LimitKind::kEuler);
  first_of(anim::LimitKind::kSwingTwist);
  auto pack = character::Pack::from_bytes(*bytes_, "limits.pack");
  ASSERT_TRUE(pack.ok()) << pack.status().message();
  ASSERT_EQ(pack->limits().size(), limits_->size());
  const auto bits = [](const Vec3& v) {
    return std::vector<std::uint32_t>{std::bit_cast<std::uint32_t>(v.x), std::bit_cast<std::uint32_t>(v.y),
                                      std::bit_cast<std::uint32_t>(v.z)};
  };
  for (std::size_t j = 0; j < limits_->size(); ++j) {
    SCOPED_TRACE(j);
    const anim::JointLimit& a = (*limits_)[j];
    const anim::JointLimit& b = pack->limits()[j];
    EXPECT_EQ(a.kind, b.kind);
    EXPECT_EQ(a.euler.order, b.euler.order);
    EXPECT_EQ(bits(a.euler.min), bits(b.euler.min));
    EXPECT_EQ(bits(a.euler.max), bits(b.euler.max));
    EXPECT_EQ(bits(a.swing_twist.twist_axis), bits(b.swing_twist.twist_axis));
    const auto scalar_bits = [](const anim::SwingTwistLimit& st) {
      return std::vector<std::uint32_t>{
          std::bit_cast<std::uint32_t>(st.swing_max_1), std::bit_cast<std::uint32_t>(st.swing_max_2),
          std::bit_cast<std::uint32_t>(st.twist_min), std::bit_cast<std::uint32_t>(st.twist_max)};
    };
    EXPECT_EQ(scalar_bits(a.swing_twist), scalar_bits(b.swing_twist));
  }
  // The payload is exactly a count and one record per joint.
  auto reader = PackReader::from_bytes(*bytes_, "limits.pack");
  ASSERT_TRUE(reader.ok());
  const SectionInfo* info = reader->find(make_section_id("LIMT"));
  ASSERT_NE(info, nullptr);
  EXPECT_EQ(info->version, 2u);
  EXPECT_EQ(info->size, 4 + kJointBytes * limits_->size());
}

TEST_F(PackLimits, EveryFieldIsValidatedOnLoad) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::size_t euler = first_of(anim::LimitKind::kEuler);
  const std::size_t swing = first_of(anim::LimitKind::kSwingTwist);
  const std::string e = "joints[" + std::to_string(euler) + "]";
  const std::string s = "joints[" + std::to_string(swing) + "]";
  expect_refused(repack([](auto& p) { put(p, joint_at(0), std::uint8_t{7}); }), "LIMT.joints[0].kind");
  expect_refused(repack([](auto& p) { put(p, joint_at(1) + 1, std::uint8_t{6}); }), "LIMT.joints[1].euler.order");
  expect_refused(repack([](auto& p) { put(p, joint_at(2) + 2, std::uint16_t{1}); }), "LIMT.joints[2].reserved");
  // Values the decoder reads fine but the limit checks refuse.
  expect_refused(repack([&](auto& p) { put(p, joint_at(euler) + 4, nan); }), e + ".euler.min.x");
  expect_refused(repack([&](auto& p) { put(p, joint_at(euler) + 4 + 12 + 4, 9.0f); }), e + ".euler.max.y");
  expect_refused(repack([&](auto& p) { put(p, joint_at(swing) + 4 + 24, 2.0f); }), s + ".swing_twist.twist_axis");
  // Counts and sizes: checked before anything is allocated.
  expect_refused(repack([](auto& p) { put(p, 0, std::uint32_t{0xFFFFFFF0u}); }), "LIMT.joint_count");
  expect_refused(repack([](auto& p) { p.erase(p.end() - 3, p.end()); }), "LIMT", ErrorCode::kTruncated);
  expect_refused(repack([](auto& p) { p.push_back(std::byte{0}); }), "LIMT");
}

TEST_F(PackLimits, OldJsonAndUnknownVersionsAskForARebake) {
  const std::string json = anim::joint_limits_to_json(*limits_, model_->skeleton);
  const auto as_json = [&](std::vector<std::byte>& p) {
    p.resize(json.size());
    std::memcpy(p.data(), json.data(), json.size());
  };
  expect_refused(repack(as_json, 1), "re-bake", ErrorCode::kUnsupportedVersion);
  expect_refused(repack([](auto&) {}, 3), "LIMT.version", ErrorCode::kUnsupportedVersion);
}

TEST_F(PackLimits, LimitsForAnotherSkeletonAreNotWritten) {
  character::PackContents c;
  c.model = model_;
  c.limits = std::span<const anim::JointLimit>(limits_->data(), limits_->size() - 1);
  const auto bytes = character::serialize_pack(c);
  ASSERT_FALSE(bytes.ok());
  EXPECT_NE(bytes.status().message().find("contents.limits"), std::string::npos) << bytes.status().message();
}

}  // namespace
}  // namespace sinew::editor
