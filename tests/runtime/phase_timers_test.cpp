#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "runtime/timing/phase_timers.h"

namespace sinew {
namespace {

TEST(PhaseTimers, MedianHandChecked) {
  EXPECT_EQ(median_of({}), 0.0);
  EXPECT_EQ(median_of({5.0}), 5.0);
  EXPECT_EQ(median_of({3.0, 1.0, 2.0}), 2.0);
  EXPECT_EQ(median_of({4.0, 1.0, 3.0, 2.0}), 2.5);
  EXPECT_EQ(median_of({1.0, 100.0, 2.0, 3.0, 1000.0}), 3.0);
}

TEST(PhaseTimers, SummariesKeepFirstUseOrder) {
  PhaseTimers t;
  for (double ms : {3.0, 1.0, 2.0}) t.record("trace", ms);
  for (double ms : {0.5, 0.7}) t.record("animation", ms);
  t.record("trace", 10.0);
  const auto s = t.summarize();
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].name, "trace");
  EXPECT_EQ(s[0].samples, 4u);
  EXPECT_DOUBLE_EQ(s[0].median_ms, 2.5);
  EXPECT_DOUBLE_EQ(s[0].min_ms, 1.0);
  EXPECT_DOUBLE_EQ(s[0].max_ms, 10.0);
  EXPECT_DOUBLE_EQ(s[0].mean_ms, 4.0);
  EXPECT_EQ(s[1].name, "animation");
  EXPECT_DOUBLE_EQ(s[1].median_ms, 0.6);
  EXPECT_DOUBLE_EQ(t.median_total_ms(), 3.1);
}

TEST(PhaseTimers, TableAndJsonNameEveryPhase) {
  PhaseTimers t;
  t.record("skinning", 1.25);
  t.record("top-level build", 0.01);
  EXPECT_THAT(t.table(), ::testing::HasSubstr("skinning"));
  EXPECT_THAT(t.table(), ::testing::HasSubstr("1.250"));
  const auto doc = nlohmann::json::parse(t.json());
  ASSERT_EQ(doc.size(), 2u);
  EXPECT_EQ(doc.begin().key(), "skinning");  // first-use order
  EXPECT_EQ(doc["top-level build"]["median_ms"].get<double>(), 0.01);
  EXPECT_EQ(doc["skinning"]["samples"].get<std::size_t>(), 1u);
}

TEST(PhaseTimers, JsonStaysValidForAnyPhaseName) {
  PhaseTimers t;
  const std::string odd = std::string("say \"hi\"\\ \n\t\x01 ") + "\xff\xfe";
  t.record(odd, 2.0);
  const auto doc = nlohmann::json::parse(t.json());  // throws on an invalid document
  ASSERT_EQ(doc.size(), 1u);
  // The name's valid part survives; the bytes that are not UTF-8 are replaced.
  EXPECT_EQ(doc.begin().key().rfind("say \"hi\"\\ \n\t\x01 ", 0), 0u);
  EXPECT_EQ(doc.begin().value()["max_ms"].get<double>(), 2.0);
}

TEST(PhaseTimers, ScopedPhaseRecordsOnce) {
  PhaseTimers t;
  {
    ScopedPhase p(t, "shade");
    const double ms = p.stop();
    EXPECT_GE(ms, 0.0);
  }
  ASSERT_EQ(t.summarize().size(), 1u);
  EXPECT_EQ(t.summarize()[0].samples, 1u);
}

}  // namespace
}  // namespace sinew

namespace sinew {
namespace {

TEST(PhaseTimers, LatestGivesEachPhasesNewestSampleInFirstUseOrder) {
  PhaseTimers t;
  EXPECT_TRUE(t.latest().empty());
  t.record("trace", 3.0);
  t.record("shade", 1.0);
  t.record("trace", 5.0);
  const auto row = t.latest();
  ASSERT_EQ(row.size(), 2u);
  EXPECT_EQ(row[0].first, "trace");
  EXPECT_EQ(row[0].second, 5.0);
  EXPECT_EQ(row[1].first, "shade");
  EXPECT_EQ(row[1].second, 1.0);
}

}  // namespace
}  // namespace sinew
