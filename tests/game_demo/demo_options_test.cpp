// sinew-demo's options as parsed: the crowd's pace spread.
#include "game_demo/demo_options.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace sinew::demo {
namespace {

TEST(DemoOptions, PaceSpreadIsReadAndChecked) {
  const auto defaults = parse_demo_options({});
  ASSERT_TRUE(defaults.ok()) << defaults.status().message();
  EXPECT_EQ(defaults->pace_spread, 0.0f);
  const auto given = parse_demo_options({"--characters", "256", "--pace-spread", "0.25"});
  ASSERT_TRUE(given.ok()) << given.status().message();
  EXPECT_EQ(given->characters, 256);
  EXPECT_EQ(given->pace_spread, 0.25f);
  for (const std::string bad : {"0.6", "-0.1", "nope", "nan"}) {
    const auto refused = parse_demo_options({"--pace-spread", bad});
    ASSERT_FALSE(refused.ok()) << bad;
    EXPECT_EQ(refused.status().code(), ErrorCode::kInvalidArgument) << bad;
    EXPECT_NE(refused.status().message().find("--pace-spread"), std::string::npos) << refused.status().message();
  }
}

}  // namespace
}  // namespace sinew::demo
