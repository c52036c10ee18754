// sinew-editor bake, subdivide, inspect and validate, run in-process on real
// models: exit codes, the files they write, reproducible bytes, an existing
// pack kept when a bake fails, and rendering from a pack equal to rendering
// after an in-memory bake of the same pose space.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/inotify.h>
#include <sys/wait.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <regex>
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "character/pack.h"
#include "editor/cli/pack_commands.h"
#include "editor/cli/render_command.h"
#include "editor/import/model_loader.h"
#include "runtime/io/mapped_file.h"
#include "runtime/pack/checksum.h"
#include "sinew/sinew.h"

namespace sinew::editor {
namespace {

const std::string kCesiumMan = std::string(SINEW_SHARED_DIR) + "/content/gltf/CesiumMan/CesiumMan.glb";

struct CommandRun {
  int code = -1;
  std::string out;
  std::string err;
};

CommandRun run(int (*command)(const std::vector<std::string>&, std::ostream&, std::ostream&),
        const std::vector<std::string>& args) {
  std::ostringstream out, err;
  CommandRun r;
  r.code = command(args, out, err);
  r.out = out.str();
  r.err = err.str();
  return r;
}

std::string fresh_dir(const std::string& name) {
  const auto dir = std::filesystem::path(::testing::TempDir()) / ("sinew_pack_commands_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

class PackCommands : public testing::Test {
 protected:
  void SetUp() override {
    if (!std::filesystem::exists(kCesiumMan)) GTEST_SKIP() << kCesiumMan << " not found (shared content)";
  }
};

TEST_F(PackCommands, BakeWritesAPackThatValidatesAndInspects) {
  const std::string dir = fresh_dir("bake");
  const std::string pack = dir + "/cesium.pack";
  const CommandRun bake = run(run_bake, {kCesiumMan, "-o", pack, "--pose-space", "arbitrary", "--samples", "30",
                                  "--seed", "5", "--pad", "0.01", "--candidates", "influencing", "--threads", "2"});
  ASSERT_EQ(bake.code, 0) << bake.err;
  EXPECT_NE(bake.out.find("wrote " + pack), std::string::npos) << bake.out;
  EXPECT_NE(bake.err.find("100% build"), std::string::npos) << "progress lines: " << bake.err;

  const CommandRun valid = run(run_validate, {pack});
  EXPECT_EQ(valid.code, 0) << valid.err;
  EXPECT_NE(valid.out.find("valid"), std::string::npos);

  const CommandRun inspect = run(run_inspect, {pack, "--json"});
  ASSERT_EQ(inspect.code, 0) << inspect.err;
  const auto j = nlohmann::json::parse(inspect.out);
  EXPECT_EQ(j["pose_space"]["mode"], "arbitrary");
  EXPECT_EQ(j["pose_space"]["samples_requested"], 30);
  EXPECT_EQ(j["pose_space"]["seed"], 5);
  EXPECT_FLOAT_EQ(j["pose_space"]["padding"].get<float>(), 0.01f);
  EXPECT_EQ(j["pose_space"]["candidates"], "influencing");
  EXPECT_EQ(j["fuzzy"]["pose_samples"], 30);
  EXPECT_GT(j["fuzzy"]["fuzzy_area_ratio"].get<double>(), 1.0);  // the fuzzy boxes hold every pose
  EXPECT_GT(j["fuzzy"]["triangles_per_leaf"].get<double>(), 0.0);
  EXPECT_EQ(j["provenance"]["source"], "CesiumMan.glb");
  auto file = MappedFile::open(kCesiumMan);
  ASSERT_TRUE(file.ok());
  EXPECT_EQ(j["provenance"]["source_xxh3"].get<std::uint64_t>(), checksum64(file->bytes()));
  EXPECT_EQ(j["model"]["triangles"].get<int>() > 0, true);
  // The text form names the same facts.
  const CommandRun text = run(run_inspect, {pack});
  ASSERT_EQ(text.code, 0);
  EXPECT_NE(text.out.find("pose space: arbitrary"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("FBVN"), std::string::npos) << "the default bone trees are BVHs";
  EXPECT_EQ(text.out.find("FNOD"), std::string::npos);
}

// The share of triangles outside the pack's pose space in the poses a
// world is given, measured through the public API (a mixer-driven instance
// and the pass's escape count): independent of the bake's own report.
double api_outside_share(const std::string& pack, const std::function<void(api::World&, api::InstanceId)>& pose) {
  auto character = api::Character::load(pack);
  EXPECT_TRUE(character.ok());
  auto world = api::World::create();
  auto instance = world->add_instance(*character);
  pose(*world, *instance);
  auto pass = api::RayTracePass::create({.width = 8, .height = 8, .outputs = api::Output::kDepth, .threads = 2});
  std::vector<float> depth(64);
  api::PassOutputs out;
  out.depth = {depth.data(), 0};
  const auto stats = pass->execute(*world, {}, out);
  EXPECT_TRUE(stats.ok()) << stats.error().message;
  return static_cast<double>(stats->escaped_triangles) / static_cast<double>(character->triangle_count());
}

// "NN.N%" after `prefix` in `text`, as a share (0 to 1); -1 when absent.
double printed_share(const std::string& text, const std::string& prefix) {
  const auto at = text.find(prefix);
  if (at == std::string::npos) return -1.0;
  const std::string value = text.substr(at + prefix.size());
  if (value.rfind("< 0.1%", 0) == 0) return 0.0005;  // a few triangles
  return std::stod(value) / 100.0;
}

// No silent cliffs: a bake of CesiumMan's one clip says how much of the
// rest pose (where a host's idle instance stands) lies outside its pose
// space; a bake of random poses says it for the clip it was not given too.
TEST_F(PackCommands, TheBakeSaysHowMuchOfTheRestPoseAndOfEachClipNotGivenLiesOutside) {
  const std::string dir = fresh_dir("outside");
  const std::string pack = dir + "/cesium.pack";
  const CommandRun bake = run(run_bake, {kCesiumMan, "-o", pack, "--threads", "2"});
  ASSERT_EQ(bake.code, 0) << bake.err;
  const double rest = printed_share(bake.out, "rest pose: ");
  ASSERT_GE(rest, 0.0) << bake.out;
  EXPECT_NE(bake.out.find("of triangles outside the pose space (they will render through the fallback)"),
            std::string::npos) << bake.out;
  const double rest_api = api_outside_share(pack, [](api::World&, api::InstanceId) {});  // at rest
  EXPECT_GT(rest_api, 0.05) << "CesiumMan's rest pose (arms out) lies outside its walk";
  EXPECT_NEAR(rest, rest_api, 0.0005 + 1e-9) << bake.out;
  EXPECT_EQ(bake.out.find("(not baked)"), std::string::npos) << "its one clip was baked";
  EXPECT_NE(bake.out.find("bake the poses you will play"), std::string::npos) << bake.out;

  // 20 random poses: the clip was not given. Its poses every 1/30 s over
  // its 2 s, at most 30 evenly spread: the report's mean and worst.
  const std::string random_pack = dir + "/random.pack";
  const CommandRun random = run(run_bake, {kCesiumMan, "-o", random_pack, "--pose-space", "arbitrary", "--samples",
                                           "20", "--threads", "2"});
  ASSERT_EQ(random.code, 0) << random.err;
  auto character = api::Character::load(random_pack);
  ASSERT_TRUE(character.ok());
  ASSERT_EQ(character->clip_count(), 1u);
  const std::string clip(character->clip_name(0));
  const double duration = character->clip_duration(0);
  const int poses = std::min(30, static_cast<int>(std::floor(duration * 30.0)) + 1);
  double sum = 0.0, worst = 0.0;
  for (int i = 0; i < poses; ++i) {
    const double t = std::min(duration * i / (poses - 1), std::nextafter(duration, 0.0));
    const double share = api_outside_share(random_pack, [&](api::World& w, api::InstanceId id) {
      ASSERT_TRUE(w.pose_at(id, clip, t).ok());
    });
    sum += share;
    worst = std::max(worst, share);
  }
  const std::string line = "clip " + clip + " (not baked): ";
  const auto at = random.out.find(line);
  ASSERT_NE(at, std::string::npos) << random.out;
  EXPECT_NEAR(printed_share(random.out, line), sum / poses, 0.0005 + 1e-9) << random.out;
  EXPECT_NEAR(printed_share(random.out.substr(at), "on average, "), worst, 0.0005 + 1e-9) << random.out;
  EXPECT_NE(random.out.find("at worst over " + std::to_string(poses) + " poses"), std::string::npos) << random.out;
}

// A static glTF (no skin) bakes, with one warning line naming the file.
TEST_F(PackCommands, AStaticGltfBakesWithOneWarningLine) {
  const std::string box = "/usr/share/assimp/models/glTF2/BoxTextured-glTF-Binary/BoxTextured.glb";
  // ./sinew installs Debian's assimp-testmodels: a missing file is a failure, not a skip.
  ASSERT_TRUE(std::filesystem::exists(box)) << box << " not found (Debian's assimp-testmodels)";
  const std::string dir = fresh_dir("static");
  const CommandRun bake = run(run_bake, {box, "-o", dir + "/box.pack", "--threads", "2"});
  ASSERT_EQ(bake.code, 0) << bake.err;
  std::size_t warnings = 0;
  std::istringstream lines(bake.err);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("sinew-editor bake: warning: ", 0) != 0) continue;
    ++warnings;
    EXPECT_NE(line.find("BoxTextured.glb: skins: none: a static model"), std::string::npos) << line;
  }
  EXPECT_EQ(warnings, 1u) << bake.err;
}

// Without a terminal the bake prints a line per phase and quarter. With
// its bones in chunks (a small memory bound), sampling and assignment
// alternate inside the bake; the lines still never go back: the percentage
// never falls and no phase returns once another began.
TEST_F(PackCommands, NonTerminalProgressNeverGoesBack) {
  const std::string dir = fresh_dir("progress");
  const CommandRun bake = run(run_bake, {kCesiumMan, "-o", dir + "/p.pack", "--max-memory-mib", "4", "--pose-clusters",
                                         "2", "--threads", "2"});
  ASSERT_EQ(bake.code, 0) << bake.err;
  std::istringstream lines(bake.err);
  std::vector<std::string> phases;
  int last = -1, reports = 0;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("bake: ", 0) != 0) continue;
    ++reports;
    const int percent = std::stoi(line.substr(6));
    const auto space = line.find(' ', line.find('%'));
    const std::string phase = line.substr(space + 1, line.find(" (") - space - 1);
    EXPECT_GE(percent, last) << bake.err;
    last = percent;
    if (phases.empty() || phases.back() != phase) {
      EXPECT_EQ(std::find(phases.begin(), phases.end(), phase), phases.end())
          << "phase " << phase << " came back:\n" << bake.err;
      phases.push_back(phase);
    }
  }
  EXPECT_GE(reports, 5) << bake.err;
  EXPECT_EQ(phases, (std::vector<std::string>{"sampling", "checks", "clusters", "build"})) << bake.err;
  EXPECT_EQ(last, 100);
}

// inspect prints for people: sizes in KiB and MiB, measured numbers to 3
// significant digits, and what each section tag holds. Each figure is
// checked against the full-precision JSON.
TEST_F(PackCommands, InspectPrintsHumanUnitsAndExplainsTheSections) {
  const std::string dir = fresh_dir("inspect_units");
  const std::string pack = dir + "/c.pack";
  ASSERT_EQ(run(run_bake, {kCesiumMan, "-o", pack, "--threads", "2"}).code, 0);
  const CommandRun text = run(run_inspect, {pack});
  ASSERT_EQ(text.code, 0) << text.err;
  const auto j = nlohmann::json::parse(run(run_inspect, {pack, "--json"}).out);
  // A printed number equals the exact one to 3 significant digits.
  const auto expect_3_digits = [&](const std::string& printed, double exact, const std::string& what) {
    const double value = std::stod(printed);
    const double unit = std::pow(10.0, std::floor(std::log10(std::abs(exact))) - 2);
    EXPECT_LE(std::abs(value - exact), std::max(0.5, 0.5 + 1e-9) * std::max(unit, 1e-12) + 1e-9)
        << what << ": " << printed << " for " << exact;
    const std::string digits = std::regex_replace(printed, std::regex("[^0-9]"), "");
    const std::string significant = std::regex_replace(digits, std::regex("^0+"), "");
    EXPECT_LE(significant.size(), std::max<std::size_t>(3, std::to_string(static_cast<long long>(std::abs(value))).size()))
        << what << ": " << printed;
  };
  std::smatch m;
  // The file's size, then each section's: "11.2 MiB (11785856 bytes)", "182 KiB", "28 bytes".
  ASSERT_TRUE(std::regex_search(text.out, m, std::regex(R"(: ([0-9.]+) (KiB|MiB) \(([0-9]+) bytes\))"))) << text.out;
  EXPECT_EQ(std::stoull(m[3].str()), j["bytes"].get<std::uint64_t>());
  expect_3_digits(m[1].str(), j["bytes"].get<double>() / (m[2].str() == "KiB" ? 1024.0 : 1024.0 * 1024.0),
                  "file size");
  for (const auto& s : j["sections"]) {
    const std::string id = s["id"].get<std::string>();
    const std::uint64_t bytes = s["bytes"].get<std::uint64_t>();
    ASSERT_TRUE(std::regex_search(text.out, m, std::regex("  " + id + R"( v[0-9]+  ([0-9.]+) (bytes|KiB|MiB) +(.+)\n)")))
        << id << "\n" << text.out;
    if (bytes < 1024) {
      EXPECT_EQ(m[1].str(), std::to_string(bytes)) << id;
      EXPECT_EQ(m[2].str(), "bytes") << id;
    } else {
      EXPECT_EQ(m[2].str(), bytes < 1024 * 1024 ? "KiB" : "MiB") << id;
      expect_3_digits(m[1].str(), static_cast<double>(bytes) / (bytes < 1024 * 1024 ? 1024.0 : 1024.0 * 1024.0), id);
    }
    EXPECT_FALSE(s["holds"].get<std::string>().empty()) << id;
    EXPECT_EQ(m[3].str(), s["holds"].get<std::string>()) << id;
  }
  EXPECT_NE(text.out.find("  FRAM v1  28 bytes    framing: up axis, rest bounds\n"), std::string::npos) << text.out;
  const auto& clip = j["model"]["clips"][0];
  ASSERT_TRUE(std::regex_search(text.out, m, std::regex("clip " + clip["name"].get<std::string>() + R"( \(([0-9.]+) s\))")));
  expect_3_digits(m[1].str(), clip["seconds"].get<double>(), "clip length");
  ASSERT_TRUE(std::regex_search(text.out, m, std::regex(R"(fuzzy area ([0-9.]+)x the rest pose's, ([0-9.]+) triangles per leaf)")));
  expect_3_digits(m[1].str(), j["fuzzy"]["fuzzy_area_ratio"].get<double>(), "fuzzy area");
  expect_3_digits(m[2].str(), j["fuzzy"]["triangles_per_leaf"].get<double>(), "triangles per leaf");
  ASSERT_TRUE(std::regex_search(text.out, m, std::regex(R"(boxes ([0-9.]+) ms)")));
  expect_3_digits(m[1].str(), j["provenance"]["sampling_ms"].get<double>(), "boxes ms");
  // CesiumMan stands along +Y as posed (docs/EMBEDDING.md, "Framing a character").
  EXPECT_NE(text.out.find("framing: stands along +Y, rest bounds ("), std::string::npos) << text.out;
  EXPECT_EQ(j["framing"]["up_axis"], 1);
  EXPECT_TRUE(j["framing"]["stored"].get<bool>());
  // No long decimals anywhere.
  EXPECT_FALSE(std::regex_search(text.out, std::regex(R"([0-9]\.[0-9]{4,})"))) << text.out;
}

TEST_F(PackCommands, SourceDateEpochMakesBakesByteIdentical) {
  const std::string dir = fresh_dir("reproducible");
  ASSERT_EQ(setenv("SOURCE_DATE_EPOCH", "1700000000", 1), 0);
  const CommandRun a = run(run_bake, {kCesiumMan, "-o", dir + "/a.pack", "--samples", "8", "--threads", "2"});
  const CommandRun b = run(run_bake, {kCesiumMan, "-o", dir + "/b.pack", "--samples", "8", "--threads", "1"});
  unsetenv("SOURCE_DATE_EPOCH");
  ASSERT_EQ(a.code, 0) << a.err;
  ASSERT_EQ(b.code, 0) << b.err;
  const std::string bytes_a = read_file(dir + "/a.pack");
  EXPECT_FALSE(bytes_a.empty());
  EXPECT_TRUE(bytes_a == read_file(dir + "/b.pack")) << "same inputs, different packs";
  const CommandRun inspect = run(run_inspect, {dir + "/a.pack", "--json"});
  const auto j = nlohmann::json::parse(inspect.out);
  EXPECT_EQ(j["provenance"]["bake_unix_time"], 1700000000);
  EXPECT_EQ(j["provenance"]["bake_date"], "2023-11-14 22:13:20 UTC");
  EXPECT_EQ(j["provenance"]["build_ms"], 0.0);
}

TEST_F(PackCommands, AFailedBakeLeavesTheExistingPackAlone) {
  const std::string dir = fresh_dir("keep");
  const std::string pack = dir + "/keep.pack";
  std::ofstream(pack) << "the previous pack";
  const CommandRun bad = run(run_bake, {kCesiumMan, "-o", pack, "--pose-space", "clip:no_such_clip"});
  EXPECT_EQ(bad.code, 1);
  EXPECT_NE(bad.err.find("no_such_clip"), std::string::npos) << bad.err;
  EXPECT_EQ(read_file(pack), "the previous pack");
  // No temporary files left beside it either.
  int files = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 1);
}

// The bone trees' SAH triangle cost reaches the build: a dearer triangle
// splits more (more nodes, fewer triangles per leaf), and both packs hold
// the same fuzzy boxes and validate.
TEST_F(PackCommands, SahIntersectionCostShapesTheBoneTrees) {
  const std::string dir = fresh_dir("sah");
  const auto bake_and_inspect = [&](const std::string& name, std::vector<std::string> extra) {
    std::vector<std::string> args = {kCesiumMan, "-o", dir + "/" + name, "--samples", "8", "--threads", "2",
                                     "--bone-trees", "kd"};
    args.insert(args.end(), extra.begin(), extra.end());
    const CommandRun bake = run(run_bake, args);
    EXPECT_EQ(bake.code, 0) << bake.err;
    EXPECT_EQ(run(run_validate, {dir + "/" + name}).code, 0);
    const CommandRun inspect = run(run_inspect, {dir + "/" + name, "--json"});
    EXPECT_EQ(inspect.code, 0) << inspect.err;
    return nlohmann::json::parse(inspect.out)["fuzzy"];
  };
  const auto packet = bake_and_inspect("default.pack", {});
  const auto explicit_default = bake_and_inspect("default_named.pack", {"--sah-intersection-cost", "0.15"});
  const auto single_ray = bake_and_inspect("deep.pack", {"--sah-intersection-cost", "1.5"});
  EXPECT_EQ(packet["nodes"], explicit_default["nodes"]);
  EXPECT_GT(single_ray["nodes"].get<std::size_t>(), packet["nodes"].get<std::size_t>());
  EXPECT_LT(single_ray["triangles_per_leaf"].get<double>(), packet["triangles_per_leaf"].get<double>());
  EXPECT_DOUBLE_EQ(single_ray["fuzzy_area"].get<double>(), packet["fuzzy_area"].get<double>());
}

// --bone-trees picks the structure the pack holds (BVHs by default), and
// both render the same image from the pack.
TEST_F(PackCommands, BoneTreesPicksTheStructure) {
  const std::string dir = fresh_dir("bone_trees");
  std::map<std::string, nlohmann::json> fuzzy;
  for (const std::string kind : {"", "kd", "bvh"}) {
    std::vector<std::string> args = {kCesiumMan, "-o", dir + "/" + (kind.empty() ? "default" : kind) + ".pack",
                                     "--samples", "8", "--threads", "2"};
    if (!kind.empty()) args.insert(args.end(), {"--bone-trees", kind});
    const CommandRun bake = run(run_bake, args);
    ASSERT_EQ(bake.code, 0) << bake.err;
    const std::string pack = dir + "/" + (kind.empty() ? "default" : kind) + ".pack";
    EXPECT_EQ(run(run_validate, {pack}).code, 0);
    const CommandRun inspect = run(run_inspect, {pack, "--json"});
    ASSERT_EQ(inspect.code, 0) << inspect.err;
    fuzzy[kind] = nlohmann::json::parse(inspect.out)["fuzzy"];
  }
  EXPECT_EQ(fuzzy[""]["bone_trees"], "bvh");
  EXPECT_EQ(fuzzy["bvh"]["bone_trees"], "bvh");
  EXPECT_EQ(fuzzy["kd"]["bone_trees"], "kd");
  EXPECT_EQ(fuzzy[""]["nodes"], fuzzy["bvh"]["nodes"]);
  EXPECT_DOUBLE_EQ(fuzzy["kd"]["fuzzy_area"].get<double>(), fuzzy["bvh"]["fuzzy_area"].get<double>());
  // A BVH leaf holds at most --bvh-leaf triangles.
  ASSERT_EQ(run(run_bake, {kCesiumMan, "-o", dir + "/small.pack", "--samples", "8", "--bvh-leaf", "2"}).code, 0);
  const CommandRun small = run(run_inspect, {dir + "/small.pack", "--json"});
  EXPECT_LE(nlohmann::json::parse(small.out)["fuzzy"]["triangles_per_leaf"].get<double>(), 2.0);
  const CommandRun bad = run(run_bake, {kCesiumMan, "-o", dir + "/bad.pack", "--bone-trees", "octree"});
  EXPECT_NE(bad.code, 0);
  EXPECT_NE(bad.err.find("--bone-trees"), std::string::npos) << bad.err;
  EXPECT_FALSE(std::filesystem::exists(dir + "/bad.pack"));
}

// Renders `o` from the source model and from the pack baked from it: every
// output the same bit for bit (depth as bytes: +inf misses too). Returns the
// pack's pose-sample count (0 when a render failed).
std::uint32_t expect_pack_renders_like_source(RenderOptions o, const std::string& source, const std::string& pack) {
  o.model_path = source;
  const auto a = render_model(o);
  o.model_path = pack;
  const auto b = render_model(o);
  EXPECT_TRUE(a.ok()) << a.status().message();
  EXPECT_TRUE(b.ok()) << b.status().message();
  if (!a.ok() || !b.ok()) return 0;
  EXPECT_TRUE(a->color_rgba8 == b->color_rgba8);
  EXPECT_TRUE(a->triangle_id == b->triangle_id);
  EXPECT_TRUE(a->instance_id == b->instance_id);
  EXPECT_EQ(a->depth.size(), b->depth.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < std::min(a->depth.size(), b->depth.size()); ++i) {
    if (std::memcmp(&a->depth[i], &b->depth[i], sizeof(float)) != 0) ++differ;
  }
  EXPECT_EQ(differ, 0u) << "of " << a->depth.size() << " depths";
  return b->stats.pose_samples;
}

TEST_F(PackCommands, RenderingFromThePackEqualsTheInMemoryBake) {
  const std::string dir = fresh_dir("render");
  const std::string pack = dir + "/cesium.pack";
  ASSERT_EQ(run(run_bake, {kCesiumMan, "-o", pack, "--pose-space", "arbitrary", "--samples", "16"}).code, 0);
  RenderOptions o;
  o.width = 80;
  o.height = 80;
  o.threads = 2;
  o.time_seconds = 0.4;
  o.pose_space.emplace();
  o.pose_space->mode = anim::PoseSpaceMode::kArbitrary;
  o.pose_space->samples = 16;
  o.pose_space->every_frame_30hz = false;
  EXPECT_EQ(expect_pack_renders_like_source(o, kCesiumMan, pack), 16u);
}

// Cally in the default pose space, from the issue that found it: the pack's
// skeleton used to be normalised again on load, moving the last bit of its
// rest rotations, the rest bounds and so the ground under the model (the
// depth of 45% of the pixels differed in its last bits).
TEST_F(PackCommands, RenderingCallyFromThePackEqualsTheInMemoryBakeBitForBit) {
  const std::string dir = fresh_dir("render_cally");
  const std::string cally = std::string(SINEW_SHARED_DIR) + "/content/cal3d/cally/cally.cfg";
  const std::string pack = dir + "/cally.pack";
  ASSERT_EQ(run(run_bake, {cally, "-o", pack, "--threads", "2"}).code, 0);
  RenderOptions o;
  o.width = 96;
  o.height = 96;
  o.threads = 2;
  o.clip = "walk";
  o.time_seconds = 0.3;
  o.pose_space = character::default_pose_space();  // the pack's
  rt::CameraDesc camera;
  camera.eye = Vec3(0.0f, -400.0f, 100.0f);
  camera.target = Vec3(0.0f, 0.0f, 90.0f);
  camera.up = Vec3(0.0f, 0.0f, 1.0f);
  camera.fovy_degrees = 40.0f;
  o.camera = camera;
  EXPECT_GT(expect_pack_renders_like_source(o, cally, pack), 0u);
}

TEST_F(PackCommands, SubdivideWritesAModelOnlyPackThatBakes) {
  const std::string dir = fresh_dir("subdivide");
  const CommandRun sub = run(run_subdivide, {kCesiumMan, "--levels", "1", "-o", dir + "/fine.pack"});
  ASSERT_EQ(sub.code, 0) << sub.err;
  const CommandRun inspect = run(run_inspect, {dir + "/fine.pack", "--json"});
  ASSERT_EQ(inspect.code, 0) << inspect.err;
  const auto fine = nlohmann::json::parse(inspect.out);
  EXPECT_TRUE(fine["fuzzy"].is_null());
  // Four times the triangles of the source.
  ASSERT_EQ(run(run_bake, {kCesiumMan, "-o", dir + "/coarse.pack", "--samples", "4"}).code, 0);
  const auto coarse = nlohmann::json::parse(run(run_inspect, {dir + "/coarse.pack", "--json"}).out);
  EXPECT_EQ(fine["model"]["triangles"].get<int>(), 4 * coarse["model"]["triangles"].get<int>());
  const CommandRun bake = run(run_bake, {dir + "/fine.pack", "-o", dir + "/fine_baked.pack", "--samples", "4"});
  EXPECT_EQ(bake.code, 0) << bake.err;
  EXPECT_EQ(run(run_validate, {dir + "/fine_baked.pack"}).code, 0);
}

TEST_F(PackCommands, ASceneRecipeBakesOnlyItsClips) {
  const std::string dir = fresh_dir("scene");
  const std::string recipe = dir + "/scene.json";
  std::ofstream(recipe) << R"({"model": ")" << kCesiumMan << R"(", "clips": ["animation_0"],
                               "pose_space": {"samples": 10, "every_frame_30hz": false}})";
  const CommandRun bake = run(run_bake, {"--scene", recipe, "-o", dir + "/scene.pack"});
  ASSERT_EQ(bake.code, 0) << bake.err;
  const auto j = nlohmann::json::parse(run(run_inspect, {dir + "/scene.pack", "--json"}).out);
  EXPECT_EQ(j["pose_space"]["mode"], "clips");
  EXPECT_EQ(j["pose_space"]["clips"], nlohmann::json::array({"animation_0"}));
  EXPECT_EQ(j["fuzzy"]["pose_samples"], 10);
  ASSERT_EQ(j["model"]["clips"].size(), 1u);
  // The recipe owns the pose space.
  EXPECT_EQ(run(run_bake, {"--scene", recipe, "-o", dir + "/x.pack", "--pose-space", "arbitrary"}).code, 2);
  std::ofstream(dir + "/bad.json") << R"({"clips": ["no_such_clip"]})";
  const CommandRun bad = run(run_bake, {kCesiumMan, "--scene", dir + "/bad.json", "-o", dir + "/y.pack"});
  EXPECT_EQ(bad.code, 1);
  EXPECT_NE(bad.err.find("no_such_clip"), std::string::npos) << bad.err;
}

// bake --scene reports what the scene saved against the whole model, in
// the same run: the clips it dropped, its bone trees against one per bone
// (checked against a bake of every clip with rigid bones kept and
// `inspect`), the two packs' bytes (the scene's against its file) and both
// packs' fps playing the recipe's first clip.
TEST_F(PackCommands, ASceneBakeReportsWhatItSaved) {
  const std::string dir = fresh_dir("scene_report");
  const std::string cally = std::string(SINEW_SHARED_DIR) + "/content/cal3d/cally/cally.cfg";
  const std::string recipe = dir + "/walk.json";
  std::ofstream(recipe) << R"({"model": ")" << cally << R"(", "clips": ["walk"],
                               "pose_space": {"samples": 20, "every_frame_30hz": false}})";
  const CommandRun bake = run(run_bake, {"--scene", recipe, "-o", dir + "/scene.pack", "--threads", "2",
                                         "--scene-report-frames", "2", "--scene-report-size", "64x48"});
  ASSERT_EQ(bake.code, 0) << bake.err;
  const auto number_after = [&](const std::string& text, const std::string& key) -> long long {
    const std::size_t at = text.find(key);
    if (at == std::string::npos) return -1;
    return std::stoll(text.substr(at + key.size()));
  };
  const auto whole_j = [&] {
    EXPECT_EQ(run(run_bake, {cally, "-o", dir + "/whole.pack", "--samples", "20", "--rigid-bones", "keep",
                             "--threads", "2"})
                  .code,
              0);
    return nlohmann::json::parse(run(run_inspect, {dir + "/whole.pack", "--json"}).out);
  }();
  const auto scene_j = nlohmann::json::parse(run(run_inspect, {dir + "/scene.pack", "--json"}).out);
  const auto trees = [](const nlohmann::json& j) {
    long long n = 0;
    for (const auto& bone : j["fuzzy"]["bones"]) n += bone["triangles"].get<long long>() > 0 ? 1 : 0;
    return n;
  };
  const std::size_t clips = whole_j["model"]["clips"].size();
  EXPECT_NE(bake.out.find("scene drops " + std::to_string(clips - 1) + " of " + std::to_string(clips) + " clips ("),
            std::string::npos)
      << bake.out;
  EXPECT_EQ(bake.out.find("walk,"), std::string::npos) << "walk is kept: " << bake.out;
  EXPECT_EQ(number_after(bake.out, "scene bone trees: "), trees(scene_j)) << bake.out;
  EXPECT_EQ(number_after(bake.out, " per instance instead of "), trees(whole_j)) << bake.out;
  EXPECT_LT(trees(scene_j), trees(whole_j));
  EXPECT_EQ(number_after(bake.out, "scene pack: "),
            static_cast<long long>(std::filesystem::file_size(dir + "/scene.pack")))
      << bake.out;
  const long long whole_bytes = number_after(bake.out, " bytes instead of ");
  const long long whole_file = static_cast<long long>(std::filesystem::file_size(dir + "/whole.pack"));
  EXPECT_NEAR(static_cast<double>(whole_bytes), static_cast<double>(whole_file), 0.01 * static_cast<double>(whole_file))
      << bake.out;
  EXPECT_EQ(number_after(bake.out, " pose samples instead of "), whole_j["fuzzy"]["pose_samples"].get<long long>());
  const std::size_t fps = bake.out.find("scene fps (clip 'walk', 64x48, 2 frames, 2 threads");
  ASSERT_NE(fps, std::string::npos) << bake.out;
  EXPECT_GT(number_after(bake.out.substr(fps), "): "), 0);
  // The temporary pack of the whole model is gone.
  for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::temp_directory_path())) {
    EXPECT_NE(entry.path().filename().string().rfind("sinew-scene-whole-" + std::to_string(::getpid()), 0), 0u);
  }
  // --scene-report sizes renders nothing; off prints nothing; without --scene it is refused.
  const CommandRun sizes =
      run(run_bake, {"--scene", recipe, "-o", dir + "/s.pack", "--threads", "2", "--scene-report", "sizes"});
  ASSERT_EQ(sizes.code, 0) << sizes.err;
  EXPECT_NE(sizes.out.find("scene pack: "), std::string::npos);
  EXPECT_EQ(sizes.out.find("scene fps"), std::string::npos);
  const CommandRun off = run(run_bake, {"--scene", recipe, "-o", dir + "/o.pack", "--scene-report", "off"});
  ASSERT_EQ(off.code, 0) << off.err;
  EXPECT_EQ(off.out.find("scene "), std::string::npos) << off.out;
  EXPECT_EQ(run(run_bake, {cally, "-o", dir + "/n.pack", "--scene-report", "sizes"}).code, 2);
  EXPECT_EQ(run(run_bake, {"--scene", recipe, "-o", dir + "/n.pack", "--scene-report", "most"}).code, 2);
}

// Named pipes given as a model, a pack or a scene recipe are refused at
// once with a message saying what they are. A reader that blocked in
// open() instead would wait for a writer forever: the watchdog plays that
// writer (so a regression fails instead of hanging) and records that it
// was needed.
TEST_F(PackCommands, NonRegularFilesAreRefusedWithoutBlocking) {
  const std::string dir = fresh_dir("fifo");
  std::vector<std::string> fifos;
  for (const char* name : {"a.pack", "a.glb", "a.gltf", "a.cfg", "scene.json"}) {
    fifos.push_back(dir + "/" + name);
    ASSERT_EQ(::mkfifo(fifos.back().c_str(), 0600), 0) << fifos.back();
  }
  std::filesystem::create_directory(dir + "/folder.pack");
  std::atomic<bool> stop{false}, reader_blocked{false};
  std::thread watchdog([&] {
    while (!stop) {
      for (const std::string& f : fifos) {
        // Succeeds only while some reader sits in open(): then it returns.
        const int fd = ::open(f.c_str(), O_WRONLY | O_NONBLOCK);
        if (fd >= 0) {
          reader_blocked = true;
          ::close(fd);
        }
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  });
  struct Case {
    int (*command)(const std::vector<std::string>&, std::ostream&, std::ostream&);
    std::vector<std::string> args;
    std::string file;
  };
  const std::vector<Case> cases = {
      {run_validate, {fifos[0]}, fifos[0]},
      {run_inspect, {fifos[0]}, fifos[0]},
      {run_render, {fifos[0], "--frames", "1", "--out", dir + "/out"}, fifos[0]},
      {run_bake, {fifos[1], "-o", dir + "/x.pack"}, fifos[1]},
      {run_bake, {fifos[2], "-o", dir + "/x.pack"}, fifos[2]},
      {run_bake, {fifos[3], "-o", dir + "/x.pack"}, fifos[3]},
      {run_bake, {kCesiumMan, "--scene", fifos[4], "-o", dir + "/x.pack"}, fifos[4]},
      {run_render, {dir + "/folder.pack", "--frames", "1", "--out", dir + "/out"}, dir + "/folder.pack"},
  };
  for (const Case& c : cases) {
    const CommandRun r = run(c.command, c.args);
    EXPECT_EQ(r.code, 1) << c.args[0] << ": " << r.err;
    EXPECT_NE(r.err.find(c.file + ": is a"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("not a regular file"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
  }
  stop = true;
  watchdog.join();
  EXPECT_FALSE(reader_blocked) << "some command blocked opening a FIFO";
  EXPECT_FALSE(std::filesystem::exists(dir + "/x.pack"));
}

// Error messages are one line of printable text naming the file, whatever
// bytes the input holds: a Cal3D .cfg line of binary garbage, a file name
// with control bytes, and tinygltf's one-line-per-problem errors.
TEST_F(PackCommands, MessagesAreOneLineOfPrintableText) {
  const std::string dir = fresh_dir("messages");
  const std::string cfg = dir + "/garbage.cfg";
  std::ofstream(cfg, std::ios::binary) << std::string("skeleton=\x01\xff\x00\x1b[31mred\n", 17) << "mesh=\xfe\xfd\n";
  const std::string gltf = dir + "/two_missing.gltf";
  std::ofstream(gltf) << R"({"asset": {"version": "2.0"}, "buffers": [{"uri": "a.bin", "byteLength": 4},)"
                      << R"({"uri": "b.bin", "byteLength": 4}]})";
  const std::string odd = dir + "/odd\x01name\x7f.glb";
  std::ofstream(odd, std::ios::binary) << "glTF";
  for (const std::string& model : {cfg, gltf, odd}) {
    const CommandRun r = run(run_bake, {model, "-o", dir + "/x.pack"});
    EXPECT_EQ(r.code, 1) << r.err;
    ASSERT_FALSE(r.err.empty());
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.back(), '\n');
    for (std::size_t i = 0; i + 1 < r.err.size(); ++i) {
      const unsigned char c = static_cast<unsigned char>(r.err[i]);
      EXPECT_TRUE(c >= 0x20 && c < 0x7f) << "byte " << int{c} << " at " << i << " in " << r.err;
    }
  }
}

// True when `text` holds no control byte but newlines and no byte of
// invalid UTF-8 (here: no byte >= 0x80 at all; the names below are ASCII
// but for their odd bytes).
bool plain_terminal_text(const std::string& text) {
  return std::none_of(text.begin(), text.end(), [](char c) {
    const auto u = static_cast<unsigned char>(c);
    return (u < 0x20 && u != '\n') || u >= 0x7f;
  });
}

// A path holding a byte of invalid UTF-8 made `inspect --json` and
// `render` (its stats.json) fail with nlohmann's internal error, where bake
// took the same path; `inspect` printed clip and source names as they were,
// so a file could send control sequences to the terminal. Both are written
// escaped (\xHH) now.
TEST_F(PackCommands, OddBytesInPathsAndNamesAreWrittenEscaped) {
  const std::string dir = fresh_dir("odd_bytes");
  auto model = load_model(kCesiumMan);
  ASSERT_TRUE(model.ok()) << model.status().message();
  anim::RawClip raw;
  raw.name = "evil\x1b]0;title\x07\xff";
  raw.tracks.assign(model->clips.front().tracks().begin(), model->clips.front().tracks().end());
  model->clips.front() = anim::Clip::build(std::move(raw), model->skeleton, "test").value();
  character::PackContents contents;
  contents.model = &*model;
  contents.provenance.source_name = "source\x1b[2J\xfe";
  const auto bytes = character::serialize_pack(contents);
  ASSERT_TRUE(bytes.ok()) << bytes.status().message();
  const std::string pack = dir + "/odd\xff\x1b[31mname.pack";
  std::ofstream(pack, std::ios::binary).write(reinterpret_cast<const char*>(bytes->data()),
                                              static_cast<std::streamsize>(bytes->size()));

  const CommandRun json = run(run_inspect, {pack, "--json"});
  ASSERT_EQ(json.code, 0) << json.err;
  const auto j = nlohmann::json::parse(json.out);
  EXPECT_EQ(j["file"], dir + "/odd\\xff\\x1b[31mname.pack");
  EXPECT_EQ(j["model"]["clips"][0]["name"], "evil\\x1b]0;title\\x07\\xff");
  EXPECT_EQ(j["provenance"]["source"], "source\\x1b[2J\\xfe");
  const CommandRun text = run(run_inspect, {pack});
  ASSERT_EQ(text.code, 0) << text.err;
  EXPECT_TRUE(plain_terminal_text(text.out)) << text.out;
  EXPECT_NE(text.out.find("clip evil\\x1b]0;title\\x07\\xff"), std::string::npos) << text.out;

  const CommandRun render = run(run_render, {pack, "--out", dir + "/out\xff", "--size", "16x16", "--threads", "1"});
  ASSERT_EQ(render.code, 0) << render.err;
  EXPECT_TRUE(plain_terminal_text(render.out)) << render.out;
  const auto stats = nlohmann::json::parse(read_file(dir + "/out\xff/stats.json"));
  EXPECT_EQ(stats["model"], dir + "/odd\\xff\\x1b[31mname.pack");
  EXPECT_EQ(stats["clip"], "evil\\x1b]0;title\\x07\\xff");
}

// SIGTERM during bake's final write killed the program and left its hidden
// temporary file beside the output (SIGINT was handled only while baking).
// Both are handled alike until the pack is in place. A real sinew-editor is
// stopped the moment its temporary file appears (inotify), sent SIGTERM
// there, and continued: it exits 1 leaving the old pack and nothing else.
// (Stopped after its last check, it may still finish: then the new pack is
// whole; either way it is never killed and leaves no temporary file.)
TEST_F(PackCommands, SigtermDuringTheFinalWriteLeavesTheOldPackAndNoTemporaryFile) {
  const std::string dir = fresh_dir("sigterm");
  const std::string out = dir + "/keep.pack";
  const int watch = inotify_init1(IN_CLOEXEC);
  ASSERT_GE(watch, 0);
  ASSERT_GE(inotify_add_watch(watch, dir.c_str(), IN_CREATE), 0);
  int interrupted = 0;
  for (int attempt = 0; attempt < 20 && interrupted == 0; ++attempt) {
    std::ofstream(out, std::ios::binary | std::ios::trunc) << "previous";
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      const int null = open("/dev/null", O_WRONLY);
      dup2(null, 1);
      dup2(null, 2);
      execl(SINEW_EDITOR, "sinew-editor", "bake", kCesiumMan.c_str(), "-o", out.c_str(), "--samples", "4",
            "--threads", "1", static_cast<char*>(nullptr));
      _exit(127);
    }
    // The pack's temporary file: "dir/.keep.tmp-<pid>-<n>.pack".
    std::string temp;
    alignas(inotify_event) char events[4096];
    pollfd ready{watch, POLLIN, 0};
    while (temp.empty() && poll(&ready, 1, 120'000) > 0) {  // a guard against a child that never writes
      const ssize_t n = read(watch, events, sizeof events);
      for (ssize_t at = 0; at < n;) {
        const auto* e = reinterpret_cast<const inotify_event*>(events + at);
        if (e->len > 0 && std::string_view(e->name).starts_with(".keep.tmp-")) temp = dir + "/" + e->name;
        at += static_cast<ssize_t>(sizeof(inotify_event) + e->len);
      }
    }
    int status = 0;
    kill(child, SIGSTOP);
    waitpid(child, &status, WUNTRACED);
    if (WIFSTOPPED(status)) {
      const bool writing = !temp.empty() && std::filesystem::exists(temp);
      if (writing) kill(child, SIGTERM);
      kill(child, SIGCONT);
      waitpid(child, &status, 0);
      if (!writing) continue;  // stopped after the write: try again
    } else {
      continue;  // finished before it stopped: try again
    }
    ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    std::vector<std::string> left;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) left.push_back(entry.path().filename().string());
    EXPECT_EQ(left, std::vector<std::string>{"keep.pack"});
    if (WEXITSTATUS(status) == 1) {
      ++interrupted;
      EXPECT_EQ(read_file(out), "previous");
    } else {
      EXPECT_EQ(WEXITSTATUS(status), 0);
      EXPECT_TRUE(character::Pack::open(out).ok());
    }
  }
  close(watch);
  EXPECT_EQ(interrupted, 1) << "no attempt was stopped inside its write";
}

TEST_F(PackCommands, UsageAndUserErrorsHaveTheirExitCodes) {
  const std::string dir = fresh_dir("errors");
  struct Case {
    std::vector<std::string> args;
    int code;
    std::string message;
  };
  const std::vector<Case> bake_cases = {
      {{kCesiumMan}, 2, "-o"},
      {{kCesiumMan, "-o", dir + "/x.glb"}, 2, "expected a .pack file name"},
      {{kCesiumMan, "-o", dir + "/x.pack", "--pose-space", "wild"}, 2, "--pose-space = wild"},
      {{kCesiumMan, "-o", dir + "/x.pack", "--pose-space", "arbitrary", "--clips", "a"}, 2,
       "only with --pose-space clips"},
      {{kCesiumMan, "-o", dir + "/x.pack", "--clips", "a"}, 1, "pose_space.clips[0] = a: no clip of that name"},
      {{kCesiumMan, "-o", dir + "/x.pack", "--pose-space", "limits"}, 2, "--limits"},
      {{kCesiumMan, "-o", dir + "/x.pack", "--pose-space", "arbitrary", "--samples", "0"}, 2, "--samples = 0"},
      {{kCesiumMan, "-o", dir + "/x.pack", "--pad", "-1"}, 2, "--pad = -1"},
      {{kCesiumMan, "-o", dir + "/x.pack", "--sah-intersection-cost", "0"}, 2, "--sah-intersection-cost = 0"},
      {{kCesiumMan, "-o", dir + "/x.pack", "--sah-intersection-cost", "nan"}, 2, "--sah-intersection-cost = nan"},
      {{dir + "/missing.glb", "-o", dir + "/x.pack"}, 1, "missing.glb: no such file"},
  };
  for (const Case& c : bake_cases) {
    const CommandRun r = run(run_bake, c.args);
    EXPECT_EQ(r.code, c.code) << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << "expected '" << c.message << "' in: " << r.err;
  }
  std::ofstream(dir + "/garbage.pack") << "not a pack at all, but long enough to hold a header...................";
  const CommandRun garbage = run(run_validate, {dir + "/garbage.pack"});
  EXPECT_EQ(garbage.code, 1);
  EXPECT_NE(garbage.err.find("garbage.pack"), std::string::npos) << garbage.err;
  EXPECT_EQ(run(run_validate, {}).code, 2);
  EXPECT_EQ(run(run_inspect, {dir + "/none.pack"}).code, 1);
  EXPECT_EQ(run(run_subdivide, {kCesiumMan, "--levels", "9", "-o", dir + "/y.pack"}).code, 2);
  EXPECT_EQ(run(run_bake, {"--help"}).code, 0);
}

}  // namespace
}  // namespace sinew::editor
