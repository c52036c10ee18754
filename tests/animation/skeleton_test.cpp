#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>

#include "animation/skeleton.h"

namespace sinew::anim {
namespace {

using ::testing::HasSubstr;

RawJoint joint(std::string name, int parent) {
  RawJoint j;
  j.name = std::move(name);
  j.parent = parent;
  return j;
}

TEST(Skeleton, KeepsAnAlreadySortedOrder) {
  RawSkeleton raw{{joint("root", -1), joint("a", 0), joint("b", 0), joint("a1", 1)}};
  std::vector<int> remap;
  auto s = Skeleton::build(raw, "test", &remap);
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(remap, (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(std::vector<int>(s->parents().begin(), s->parents().end()),
            (std::vector<int>{-1, 0, 0, 1}));
  EXPECT_EQ(*s->find("a1"), 3);
  EXPECT_FALSE(s->find("zz").has_value());
}

TEST(Skeleton, SortsParentsBeforeChildren) {
  // glTF allows joints listed children-first.
  RawSkeleton raw{{joint("hand", 2), joint("root", -1), joint("arm", 1)}};
  std::vector<int> remap;
  auto s = Skeleton::build(raw, "test", &remap);
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(remap, (std::vector<int>{2, 0, 1}));
  EXPECT_EQ(s->names()[0], "root");
  EXPECT_EQ(s->names()[1], "arm");
  EXPECT_EQ(s->names()[2], "hand");
  for (std::size_t j = 0; j < 3; ++j) EXPECT_LT(s->parents()[j], static_cast<int>(j));
}

TEST(Skeleton, RejectsBadInputWithClearErrors) {
  {
    auto s = Skeleton::build({{joint("a", -1), joint("b", 7)}}, "m.gltf");
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.status().code(), ErrorCode::kOutOfBounds);
    EXPECT_THAT(s.status().message(), HasSubstr("m.gltf: joints[1].parent = 7"));
  }
  {
    auto s = Skeleton::build({{joint("a", 1), joint("b", 0)}}, "m.gltf");
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.status().code(), ErrorCode::kInvalidData);
    EXPECT_THAT(s.status().message(), HasSubstr("cycle"));
  }
  {
    auto s = Skeleton::build({{joint("a", 0)}}, "m.gltf");
    EXPECT_EQ(s.status().code(), ErrorCode::kInvalidData);
  }
  {
    auto s = Skeleton::build({{joint("a", -1), joint("a", 0)}}, "m.gltf");
    EXPECT_EQ(s.status().code(), ErrorCode::kDuplicate);
  }
  {
    RawSkeleton raw{{joint("a", -1)}};
    raw.joints[0].rest.translation.x = std::numeric_limits<float>::quiet_NaN();
    EXPECT_EQ(Skeleton::build(raw, "m").status().code(), ErrorCode::kInvalidData);
  }
  {
    RawSkeleton raw{{joint("a", -1)}};
    raw.joints[0].rest.rotation = Quat(0, 0, 0, 0);
    EXPECT_EQ(Skeleton::build(raw, "m").status().code(), ErrorCode::kInvalidData);
  }
  {
    RawSkeleton raw;
    raw.joints.resize(kMaxJoints + 1);
    EXPECT_EQ(Skeleton::build(raw, "m").status().code(), ErrorCode::kLimitExceeded);
  }
}

}  // namespace
}  // namespace sinew::anim
