// The demo's timings.json is valid JSON whatever the model's path holds,
// and carries what the run measured.
#include "game_demo/timings_json.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

namespace sinew::demo {
namespace {

TEST(TimingsJson, AnyModelPathGivesAValidDocument) {
  PhaseTimers timers;
  for (const double ms : {2.0, 4.0, 3.0}) {
    timers.record("trace primary", ms);
    timers.record("shade", ms / 2.0);
  }
  TimingsRun run;
  run.timers = &timers;
  run.frames = {{{"trace primary", 2.0}, {"shade", 1.0}},
                {{"trace primary", std::numeric_limits<double>::quiet_NaN()}, {"shade", 2.0}}};
  run.model = "C:\\models\\the \"hero\"\n\tmodel é.glb";
  run.triangles = 3342;
  run.pose_samples = 566;
  run.characters = 6;
  run.width = 1024;
  run.height = 768;
  run.threads = 2;
  run.escaped_triangles = 7;
  const std::string text = timings_json(run);
  ASSERT_FALSE(text.empty());
  EXPECT_EQ(text.back(), '\n');
  const nlohmann::json doc = nlohmann::json::parse(text);  // throws on invalid JSON
  const nlohmann::json& summary = doc.at("summary");
  EXPECT_EQ(summary.at("model").get<std::string>(), run.model);
  EXPECT_EQ(summary.at("triangles").get<std::size_t>(), 3342u);
  EXPECT_EQ(summary.at("pose_samples").get<std::uint32_t>(), 566u);
  EXPECT_EQ(summary.at("characters").get<int>(), 6);
  EXPECT_EQ(summary.at("size"), nlohmann::json::array({1024, 768}));
  EXPECT_EQ(summary.at("threads").get<int>(), 2);
  EXPECT_EQ(summary.at("escaped_triangles").get<std::uint64_t>(), 7u);
  // Medians: primary 3 ms, shade 1.5 ms; fps from their sum.
  EXPECT_DOUBLE_EQ(summary.at("phases").at("trace primary").at("median_ms").get<double>(), 3.0);
  EXPECT_DOUBLE_EQ(summary.at("phases").at("shade").at("median_ms").get<double>(), 1.5);
  EXPECT_EQ(summary.at("phases").at("shade").at("samples").get<std::size_t>(), 3u);
  EXPECT_DOUBLE_EQ(summary.at("frame_median_ms").get<double>(), 4.5);
  EXPECT_NEAR(summary.at("fps").get<double>(), 1000.0 / 4.5, 1e-9);
  // Frames in order; a non-finite time is written as 0.
  ASSERT_EQ(doc.at("frames").size(), 2u);
  EXPECT_EQ(doc.at("frames")[1].at("frame").get<int>(), 1);
  EXPECT_EQ(doc.at("frames")[0].at("trace primary").get<double>(), 2.0);
  EXPECT_EQ(doc.at("frames")[1].at("trace primary").get<double>(), 0.0);
}

TEST(TimingsJson, InvalidUtf8InAPathIsReplacedNotThrown) {
  TimingsRun run;
  run.model = std::string("bad\xff\xfe") + "path.glb";
  const nlohmann::json doc = nlohmann::json::parse(timings_json(run));
  const std::string model = doc.at("summary").at("model").get<std::string>();
  EXPECT_EQ(model.substr(0, 3), "bad");
  EXPECT_NE(model.find("path.glb"), std::string::npos);
  EXPECT_EQ(doc.at("summary").at("fps").get<double>(), 0.0);  // no timers: no frames timed
}

}  // namespace
}  // namespace sinew::demo
