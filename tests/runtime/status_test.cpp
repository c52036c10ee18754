#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "runtime/core/expected.h"
#include "runtime/core/status.h"

namespace sinew {
namespace {

using ::testing::HasSubstr;

TEST(Status, DefaultIsOk) {
  Status s;
  EXPECT_TRUE(s.ok());
  EXPECT_EQ(s.code(), ErrorCode::kOk);
  EXPECT_EQ(s.message(), "ok");
}

TEST(Status, MessageNamesFileFieldAndValue) {
  Status s = make_error(ErrorCode::kOutOfBounds, "cally.pack", "section[3].offset", "4096",
                        "past the end of the file");
  EXPECT_FALSE(s.ok());
  EXPECT_EQ(s.code(), ErrorCode::kOutOfBounds);
  EXPECT_EQ(s.file(), "cally.pack");
  EXPECT_EQ(s.field(), "section[3].offset");
  EXPECT_EQ(s.value(), "4096");
  EXPECT_EQ(s.message(), "cally.pack: section[3].offset = 4096: past the end of the file");
}

TEST(Status, MessageOmitsEmptyParts) {
  EXPECT_EQ(invalid_argument("threads", "-3", "must be positive").message(),
            "threads = -3: must be positive");
  EXPECT_EQ(make_error(ErrorCode::kNotFound, "a.cfg", "", "", "").message(), "a.cfg: not found");
  EXPECT_EQ(make_error(ErrorCode::kIoError, "", "", "", "disk full").message(), "disk full");
}

TEST(Status, OkCodeIsNotSilentlySuccess) {
  Status s(ErrorCode::kOk, "f", "x", "1", "oops");
  EXPECT_FALSE(s.ok());
  EXPECT_EQ(s.code(), ErrorCode::kInternal);
}

TEST(Status, CopyIsDeepAndWithFileFillsOnlyMissingFile) {
  Status a = make_error(ErrorCode::kInvalidData, "", "weights[7]", "nan", "not finite");
  Status b = a.with_file("model.gltf");
  EXPECT_EQ(a.file(), "");
  EXPECT_EQ(b.file(), "model.gltf");
  Status c = b.with_file("other.gltf");
  EXPECT_EQ(c.file(), "model.gltf");
  Status d = c;
  EXPECT_EQ(d.message(), c.message());
  EXPECT_TRUE(Status{}.with_file("x").ok());
}

TEST(Status, EveryCodeHasAName) {
  for (int c = 0; c <= static_cast<int>(ErrorCode::kInternal); ++c) {
    EXPECT_NE(error_code_name(static_cast<ErrorCode>(c)), "unknown error") << c;
  }
}

Expected<int> parse_positive(int v) {
  if (v <= 0) return invalid_argument("v", std::to_string(v), "must be positive");
  return v;
}

Expected<int> doubled(int v) {
  SINEW_ASSIGN_OR_RETURN(int x, parse_positive(v));
  return 2 * x;
}

Status check(int v) {
  SINEW_RETURN_IF_ERROR(parse_positive(v).ok() ? Status{} : parse_positive(v).status());
  return {};
}

TEST(Expected, HoldsValueOrError) {
  Expected<int> good = parse_positive(5);
  ASSERT_TRUE(good.ok());
  EXPECT_EQ(*good, 5);
  Expected<int> bad = parse_positive(-1);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_THAT(bad.status().message(), HasSubstr("v = -1"));
}

TEST(Expected, MacrosPropagate) {
  EXPECT_EQ(*doubled(4), 8);
  EXPECT_EQ(doubled(0).status().code(), ErrorCode::kInvalidArgument);
  EXPECT_TRUE(check(1).ok());
  EXPECT_FALSE(check(-1).ok());
}

TEST(Expected, MoveOnlyValues) {
  Expected<std::unique_ptr<int>> e = std::make_unique<int>(7);
  ASSERT_TRUE(e.ok());
  std::unique_ptr<int> p = std::move(e).value();
  EXPECT_EQ(*p, 7);
}

TEST(Expected, OkStatusBecomesInternalError) {
  Expected<int> e = Status{};
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.status().code(), ErrorCode::kInternal);
}

TEST(ExpectedDeathTest, ValueOfErrorStopsLoudly) {
  EXPECT_DEATH(
      {
        Expected<int> e = parse_positive(-2);
        (void)e.value();
      },
      "Expected misuse");
}

}  // namespace
}  // namespace sinew
