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

// Values read from files may hold any bytes: a message is one line of
// printable text, whatever its parts hold. Valid UTF-8 (names in other
// scripts) stays; control bytes, C1 controls, invalid or overlong UTF-8
// and lone surrogates become \xHH; long values are cut.
TEST(Status, MessagesArePrintableAndOneLine) {
  using namespace std::string_literals;
  const std::pair<std::string, std::string> cases[] = {
      {"plain", "plain"},
      {"Gr\xc3\xb6\xc3\x9f" "e \xe6\x97\xa5\xe6\x9c\xac \xf0\x9f\x98\x80", "Gr\xc3\xb6\xc3\x9f" "e \xe6\x97\xa5\xe6\x9c\xac \xf0\x9f\x98\x80"},
      {"a\nb\tc", "a\\nb\\tc"},
      {"nul\0byte"s, "nul\\x00byte"},
      {"\x01\x1f\x7f", "\\x01\\x1f\\x7f"},
      {"\xff\xfe", "\\xff\\xfe"},
      {"\xc2\x85", "\\xc2\\x85"},          // U+0085, a C1 control
      {"\xc0\xaf", "\\xc0\\xaf"},          // overlong '/'
      {"\xed\xa0\x80", "\\xed\\xa0\\x80"},  // a surrogate
      {"\xe6\x97", "\\xe6\\x97"},          // cut short
  };
  for (const auto& [raw, shown] : cases) {
    EXPECT_EQ(printable(raw), shown) << raw;
    const std::string message = make_error(ErrorCode::kInvalidData, raw, raw, raw, raw).message();
    EXPECT_EQ(message, shown + ": " + shown + " = " + shown + ": " + shown);
    EXPECT_EQ(message.find('\n'), std::string::npos);
  }
  // A long part keeps its start and its end; the line is at most 300 bytes.
  const std::string long_value = std::string(500, 'a') + std::string(500, 'z');
  const std::string cut = make_error(ErrorCode::kInvalidData, "f", "field", long_value, "d").message();
  EXPECT_EQ(cut, "f: field = " + std::string(48, 'a') + "..." + std::string(49, 'z') + ": d");
  const std::string huge(5000, 'x');
  const std::string line = make_error(ErrorCode::kInvalidData, huge, huge, huge, huge).message();
  EXPECT_EQ(line.size(), 300u);
  EXPECT_EQ(line.substr(line.size() - 3), "...");
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
