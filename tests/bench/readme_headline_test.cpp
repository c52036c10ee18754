#include "tests/bench/readme_headline.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

namespace sinew::bench {
namespace {

using Json = nlohmann::ordered_json;

Json read_json(const std::string& path) {
  std::ifstream in(path);
  return Json::parse(in, nullptr, /*allow_exceptions=*/false);
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// An embree run as the benchmark writes it, cut to what the table reads.
Json run_with(double sinew_ms, double embree_ms, int threads) {
  Json best = {{"label", "refit rtcIntersect16"}, {"total_ms", embree_ms}, {"trace_ms", embree_ms - 2.0},
               {"sinew_total_ms", sinew_ms}, {"sinew_trace_ms", sinew_ms - 1.0}};
  Json one = {{"clip", "walk"}, {"threads", 1}, {"best_embree", best}};
  Json two = {{"clip", "walk"}, {"threads", threads}, {"best_embree", best}};
  Json kick = {{"clip", "kick"}, {"threads", 8}, {"best_embree", best}};
  return {{"model", "cally"},          {"subdivide", 0},       {"triangles", 3342},
          {"size", {1024, 1024}},      {"cpu", "Test CPU"},    {"isa", "x86-64-v3"},
          {"date", "2026-01-02 03:04:05 UTC"}, {"configurations", {one, two, kick}}};
}

TEST(ReadmeHeadline, RowsQuoteTheFirstClipAtTheMostThreadsWithHandComputedRatios) {
  const Json small = run_with(10.0, 25.0, 2);
  Json large = run_with(50.0, 40.0, 2);
  large["subdivide"] = 4;
  large["triangles"] = 855552;
  const std::string table = headline_table(&small, &large);
  // 25 / 10 = 2.50 total, 23 / 9 = 2.56 trace; 40 / 50 = 0.80, 38 / 49 = 0.78.
  EXPECT_NE(table.find("| cally (3,342 triangles), walk, 1024×1024, shadows, 2 threads | 10.0 | refit rtcIntersect16 "
                       "| 25.0 | **2.50×** | 2.56× | Test CPU, x86-64-v3 build | 2026-01-02 |"),
            std::string::npos)
      << table;
  EXPECT_NE(table.find("| cally subdivided 4× (855,552 triangles), walk, 1024×1024, shadows, 2 threads | 50.0 | "
                       "refit rtcIntersect16 | 40.0 | **0.80×** | 0.78× |"),
            std::string::npos)
      << table;
  EXPECT_EQ(table.find("kick"), std::string::npos) << "only the first clip is quoted";
}

TEST(ReadmeHeadline, RunsWithoutAnEmbreeRowGiveNoRow) {
  Json run = run_with(10.0, 25.0, 2);
  for (Json& c : run["configurations"]) c.erase("best_embree");
  EXPECT_EQ(headline_table(&run, nullptr), "");
  EXPECT_EQ(headline_table(nullptr, nullptr), "");
  const Json empty = Json::object();
  EXPECT_EQ(headline_table(&empty, &empty), "");
}

TEST(ReadmeHeadline, ReplacesOnlyWhatLiesBetweenTheMarkers) {
  const std::string text = std::string("before\n") + kHeadlineBegin + "\nold table\n" + kHeadlineEnd + "\nafter\n";
  const auto updated = replace_headline(text, "new table\n");
  ASSERT_TRUE(updated.has_value());
  EXPECT_EQ(*updated, std::string("before\n") + kHeadlineBegin + "\nnew table\n" + kHeadlineEnd + "\nafter\n");
  EXPECT_FALSE(replace_headline("no markers here", "t").has_value());
  EXPECT_FALSE(replace_headline(std::string(kHeadlineEnd) + " then " + kHeadlineBegin, "t").has_value());
}

// The front page quotes the report: its table is exactly what the report's
// JSON in docs/bench-data/ gives.
TEST(ReadmeHeadline, TheReadmeTableIsTheOneTheReportsJsonGives) {
  const std::string docs = std::string(SINEW_SOURCE_DIR) + "/docs/bench-data/";
  const Json small = read_json(docs + "embree.json");
  const Json large = read_json(docs + "embree-large.json");
  const std::string table = headline_table(small.is_discarded() ? nullptr : &small,
                                           large.is_discarded() ? nullptr : &large);
  ASSERT_FALSE(table.empty()) << "docs/bench-data has no Embree run with a best Embree row";
  const std::string readme = read_text(std::string(SINEW_SOURCE_DIR) + "/README.md");
  const auto regenerated = replace_headline(readme, table);
  ASSERT_TRUE(regenerated.has_value()) << "README.md lacks the headline table markers";
  EXPECT_EQ(readme, *regenerated) << "README.md's headline table differs from docs/bench-data: rerun "
                                     "`sinew-bench report --sections embree`";
}

}  // namespace
}  // namespace sinew::bench
