// The character pack end to end: bake -> write -> load renders the same
// image as the in-memory bake, bit for bit; the same inputs give the same
// bytes; and every kind of corruption of a real pack is refused with an
// error naming the section and field, never a crash (this suite also runs
// under ASan + UBSan).
#include <gtest/gtest.h>
#include <fstream>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "character/bake.h"
#include "character/framing.h"
#include "character/pack.h"
#include "content/mannequin/mannequin.h"
#include "raytrace/camera/camera.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "runtime/io/atomic_file.h"
#include "runtime/jobs/job_system.h"
#include "runtime/pack/pack_writer.h"
#include "tests/support/damaged_packs.h"
#include "tests/support/repack.h"
#include "tests/support/same_model.h"
#if SINEW_HAVE_CAL3D
#include "editor/import/cal3d_importer.h"
#endif

namespace sinew::editor {
namespace {

struct Baked {
  character::Model model;
  rt::FuzzyCharacterData fuzzy;
  character::PoseSpaceRecord pose_space;
};

Baked bake(character::Model model, JobSystem& jobs, const character::BakeRequest& request = {}) {
  Baked b;
  auto baked = character::bake_in_memory(model, request, jobs);
  EXPECT_TRUE(baked.ok()) << baked.status().message();
  if (baked.ok()) b.fuzzy = std::move(baked->fuzzy);
  b.pose_space.desc = request.pose_space;
  b.pose_space.padding = request.fuzzy.padding;
  b.pose_space.candidates = request.fuzzy.candidates;
  b.model = std::move(model);
  return b;
}

character::PackContents contents_of(const Baked& b) {
  character::PackContents c;
  c.model = &b.model;
  c.fuzzy = &b.fuzzy;
  c.pose_space = b.pose_space;
  c.provenance.source_name = "test";
  c.provenance.tool_version = "sinew-editor test";
  return c;
}

std::vector<std::byte> pack_bytes(const Baked& b) {
  auto bytes = character::serialize_pack(contents_of(b));
  EXPECT_TRUE(bytes.ok()) << bytes.status().message();
  return bytes.ok() ? std::move(*bytes) : std::vector<std::byte>{};
}

// Colour and triangle ids of the model posed by its first clip (or the
// rest pose), seen by the render command's default camera.
struct Image {
  std::vector<std::uint8_t> rgba;
  std::vector<std::uint32_t> triangles;
  bool operator==(const Image&) const = default;
};

// `strict`: every step must succeed. Damaged packs that still load may pose
// the character anywhere (huge but finite matrices): then only the absence
// of crashes and sanitizer reports is asserted.
Image render(const character::Model& model, const rt::FuzzyCharacterView& fuzzy, JobSystem& jobs, bool strict = true) {
  constexpr int kSize = 96;
  Image image;
  rt::Scene scene;
  auto character = scene.add_character(model.mesh, fuzzy);
  EXPECT_TRUE(!strict || character.ok()) << character.status().message();
  if (!character.ok()) return image;
  auto instance = scene.add_instance(*character);
  EXPECT_TRUE(instance.ok());
  if (!model.clips.empty()) {
    auto skinning = character::clip_skinning(model, model.clips.front(), 0.37);
    EXPECT_TRUE(!strict || skinning.ok()) << skinning.status().message();
    if (!skinning.ok()) return image;
    const Status bones = scene.set_bones(*instance, *skinning);
    EXPECT_TRUE(!strict || bones.ok()) << bones.message();
  }
  const auto frame = scene.prepare_frame(rt::FrameOptions{}, jobs);
  EXPECT_TRUE(!strict || frame.ok());
  if (!frame.ok()) return image;
  const int up = character::up_axis_of(character::rest_bounds(model));
  auto camera = rt::PinholeCamera::create(character::default_camera(character::posed_bounds(scene), up, kSize, kSize), kSize, kSize);
  EXPECT_TRUE(!strict || camera.ok()) << camera.status().message();
  if (!camera.ok()) return image;
  image.rgba.resize(kSize * kSize * 4);
  image.triangles.resize(kSize * kSize);
  rt::FrameBuffers buffers;
  buffers.width = kSize;
  buffers.height = kSize;
  buffers.color_rgba8 = image.rgba;
  buffers.triangle_id = image.triangles;
  rt::RenderSettings settings;
  settings.light.position = character::default_light(character::posed_bounds(scene), up);
  auto stats = rt::Renderer().render(scene, *camera, settings, buffers, jobs);
  EXPECT_TRUE(!strict || stats.ok()) << stats.status().message();
  return image;
}

void check_round_trip(character::Model model) {
  JobSystem jobs(2);
  const Baked baked = bake(std::move(model), jobs);
  const Image in_memory = render(baked.model, baked.fuzzy.view(), jobs);

  // Through a file, mapped.
  const std::string path = (std::filesystem::temp_directory_path() / "sinew_character_pack_test.pack").string();
  ASSERT_TRUE(character::write_pack(path, contents_of(baked)).ok());
  auto pack = character::Pack::open(path);
  ASSERT_TRUE(pack.ok()) << pack.status().message();
  ASSERT_TRUE(pack->has_fuzzy());
  testing_support::expect_same_model(baked.model, pack->model());
  EXPECT_EQ(pack->fuzzy_stats().fuzzy_area, baked.fuzzy.stats.fuzzy_area);
  EXPECT_EQ(pack->fuzzy_stats().sample_count, baked.fuzzy.stats.sample_count);
  // The fuzzy data is used in place: the view points into the mapping.
  const auto mapped = pack->reader().bytes();
  ASSERT_EQ(pack->fuzzy().tree_kind, baked.fuzzy.tree_kind);
  const void* nodes = pack->fuzzy().has_bvhs() ? static_cast<const void*>(pack->fuzzy().bvh_nodes.data())
                                               : static_cast<const void*>(pack->fuzzy().nodes.data());
  EXPECT_GE(nodes, static_cast<const void*>(mapped.data()));
  EXPECT_LT(nodes, static_cast<const void*>(mapped.data() + mapped.size()));
  const Image from_pack = render(pack->model(), pack->fuzzy(), jobs);
  EXPECT_TRUE(from_pack == in_memory) << "rendering from the pack differs from the in-memory bake";
  std::size_t hits = 0;
  for (std::uint32_t t : in_memory.triangles) hits += t != kInvalidId ? 1 : 0;
  EXPECT_GT(hits, 500u) << "the character should fill part of the image";
  std::filesystem::remove(path);
}

// write_character_pack loads what it wrote before the rename: contents
// the loader refuses (here a NaN vertex, which nothing before the loader
// checks) leave an existing pack byte-identical and no temporary file.
TEST(CharacterPack, APackThatWouldNotLoadReplacesNothing) {
  auto model = content::make_mannequin();
  ASSERT_TRUE(model.ok());
  JobSystem jobs(2);
  const Baked good = bake(std::move(*model), jobs);
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "sinew_pack_not_replaced";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "character.pack").string();
  ASSERT_TRUE(character::write_pack(path, contents_of(good)).ok());
  const auto read_all = [&] { return read_file_text(path).value(); };
  const std::string before = read_all();
  Baked broken = good;
  broken.model.mesh.positions[0].y = std::numeric_limits<float>::quiet_NaN();
  ASSERT_TRUE(character::serialize_pack(contents_of(broken)).ok()) << "the writer alone does not see it";
  const Status s = character::write_pack(path, contents_of(broken));
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.file(), path);
  EXPECT_NE(s.message().find("the written pack does not load, so nothing was replaced"), std::string::npos)
      << s.message();
  EXPECT_NE(s.message().find("MESH.positions[0]"), std::string::npos) << s.message();
  EXPECT_EQ(read_all(), before);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator{}), 1)
      << "no temporary file left";
  std::filesystem::remove_all(dir);
}

TEST(CharacterPack, MannequinRoundTripRendersBitIdentically) {
  auto model = content::make_mannequin();
  ASSERT_TRUE(model.ok());
  check_round_trip(std::move(*model));
}

TEST(CharacterPack, CallyRoundTripRendersBitIdentically) {
#if SINEW_HAVE_CAL3D
  const std::string cfg = std::string(SINEW_SHARED_DIR) + "/content/cal3d/cally/cally.cfg";
  if (!std::filesystem::exists(cfg)) GTEST_SKIP() << cfg << " not found (shared content)";
  auto model = import_cal3d(cfg);
  ASSERT_TRUE(model.ok()) << model.status().message();
  check_round_trip(std::move(*model));
#else
  GTEST_SKIP() << "built without libcal3d";
#endif
}

TEST(CharacterPack, TheSameInputsAndSeedGiveTheSameBytes) {
  JobSystem jobs(2);
  character::BakeRequest request;
  request.pose_space.mode = anim::PoseSpaceMode::kArbitrary;
  request.pose_space.samples = 40;
  request.pose_space.seed = 7;
  request.fuzzy.padding = 0.01f;
  auto model = content::make_mannequin();
  ASSERT_TRUE(model.ok());
  const auto a = pack_bytes(bake(*model, jobs, request));
  JobSystem one(1);
  const auto b = pack_bytes(bake(*model, one, request));
  ASSERT_FALSE(a.empty());
  EXPECT_TRUE(a == b) << "two bakes of the same inputs differ";
  request.pose_space.seed = 8;
  EXPECT_FALSE(a == pack_bytes(bake(*model, jobs, request)));
}

TEST(CharacterPack, PoseSpaceAndProvenanceRoundTrip) {
  JobSystem jobs(2);
  auto model = content::make_mannequin();
  ASSERT_TRUE(model.ok());
  character::BakeRequest request;
  request.pose_space.mode = anim::PoseSpaceMode::kClip;
  request.pose_space.clips = {model->clips.front().name()};
  request.pose_space.samples = 0;
  request.pose_space.every_frame_30hz = true;
  request.fuzzy.candidates = rt::CandidateBones::kInfluencing;
  Baked baked = bake(std::move(*model), jobs, request);
  character::PackContents c = contents_of(baked);
  c.provenance.source_name = "mannequin.glb";
  c.provenance.source_hash = 0x0123456789abcdefull;
  c.provenance.bake_unix_time = 1'700'000'000;
  c.provenance.build_ms = 12.5;
  auto bytes = character::serialize_pack(c);
  ASSERT_TRUE(bytes.ok());
  auto pack = character::Pack::from_bytes(*bytes, "mem.pack");
  ASSERT_TRUE(pack.ok()) << pack.status().message();
  EXPECT_EQ(pack->pose_space().desc.mode, anim::PoseSpaceMode::kClip);
  EXPECT_EQ(pack->pose_space().desc.clips, request.pose_space.clips);
  EXPECT_TRUE(pack->pose_space().desc.every_frame_30hz);
  EXPECT_EQ(pack->pose_space().candidates, rt::CandidateBones::kInfluencing);
  EXPECT_EQ(pack->provenance().source_name, "mannequin.glb");
  EXPECT_EQ(pack->provenance().source_hash, 0x0123456789abcdefull);
  EXPECT_EQ(pack->provenance().bake_unix_time, 1'700'000'000);
  EXPECT_EQ(pack->provenance().build_ms, 12.5);
  // A model-only pack loads without fuzzy data.
  c.fuzzy = nullptr;
  auto model_only = character::serialize_pack(c);
  ASSERT_TRUE(model_only.ok());
  auto loaded = character::Pack::from_bytes(*model_only, "model.pack");
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  EXPECT_FALSE(loaded->has_fuzzy());
  testing_support::expect_same_model(baked.model, loaded->model());
}

// --- corruption ------------------------------------------------------------------

class CorruptPack : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    JobSystem jobs(2);
    auto model = content::make_mannequin();
    ASSERT_TRUE(model.ok());
    // The kd-trees' sections (FNOD); BvhPack below corrupts the BVHs'.
    character::BakeRequest request;
    request.fuzzy.bone_trees = rt::BoneTreeKind::kKdTree;
    baked_ = new Baked(bake(std::move(*model), jobs, request));
    bytes_ = new std::vector<std::byte>(pack_bytes(*baked_));
  }
  static void TearDownTestSuite() {
    delete baked_;
    delete bytes_;
    baked_ = nullptr;
    bytes_ = nullptr;
  }

  // The pack with section `id`'s payload replaced by mutate(payload)
  // (tests/support/repack.h).
  static std::vector<std::byte> repack(SectionId id, const std::function<void(std::vector<std::byte>&)>& mutate) {
    return testing_support::repack_section(*bytes_, id, mutate);
  }

  template <typename T>
  static void overwrite(std::vector<std::byte>& payload, std::size_t index, const T& value) {
    ASSERT_LE((index + 1) * sizeof(T), payload.size());
    std::memcpy(payload.data() + index * sizeof(T), &value, sizeof(T));
  }

  // Three random bytes of one of `sections` overwritten, `trials` times
  // each: every damaged pack is refused or renders (without a strict
  // check: the sanitizers and the absence of crashes are the test).
  // Returns how many were refused.
  static int damaged_packs_refused(std::span<const SectionId> sections, int trials, std::uint32_t seed) {
    std::mt19937 random(seed);
    JobSystem jobs(1);
    int refused = 0;
    for (const SectionId id : sections) {
      for (int trial = 0; trial < trials; ++trial) {
        const auto bytes = repack(id, [&](std::vector<std::byte>& p) {
          if (p.empty()) return;
          for (int k = 0; k < 3; ++k) p[random() % p.size()] = static_cast<std::byte>(random() & 0xffu);
        });
        auto pack = character::Pack::from_bytes(bytes, "damaged.pack");
        if (!pack.ok()) {
          ++refused;
          continue;
        }
        render(pack->model(), pack->fuzzy(), jobs, /*strict=*/false);
      }
    }
    return refused;
  }

  // Loading must fail, naming `section` in the message.
  static void expect_rejected(const std::vector<std::byte>& bytes, const std::string& section) {
    auto pack = character::Pack::from_bytes(bytes, "corrupt.pack");
    ASSERT_FALSE(pack.ok()) << "a corrupt " << section << " was accepted";
    EXPECT_NE(pack.status().message().find("corrupt.pack"), std::string::npos) << pack.status().message();
    EXPECT_NE(pack.status().message().find(section), std::string::npos) << pack.status().message();
  }

  static inline Baked* baked_ = nullptr;
  static inline std::vector<std::byte>* bytes_ = nullptr;
};

TEST_F(CorruptPack, ThePristinePackLoads) {
  auto pack = character::Pack::from_bytes(*bytes_, "pristine.pack");
  ASSERT_TRUE(pack.ok()) << pack.status().message();
}

TEST_F(CorruptPack, TruncationAtEverySectionIsRefused) {
  auto reader = PackReader::from_bytes(*bytes_, "pristine");
  ASSERT_TRUE(reader.ok());
  for (const SectionInfo& s : reader->sections()) {
    for (std::uint64_t cut : {s.offset, s.offset + s.size / 2}) {
      std::vector<std::byte> cut_bytes(bytes_->begin(), bytes_->begin() + static_cast<std::ptrdiff_t>(cut));
      auto pack = character::Pack::from_bytes(cut_bytes, "cut.pack");
      EXPECT_FALSE(pack.ok()) << "cut at " << cut << " in " << section_id_name(s.id);
    }
  }
}

TEST_F(CorruptPack, AFlippedByteInEverySectionIsRefusedByItsChecksum) {
  auto reader = PackReader::from_bytes(*bytes_, "pristine");
  ASSERT_TRUE(reader.ok());
  for (const SectionInfo& s : reader->sections()) {
    if (s.size == 0) continue;
    std::vector<std::byte> flipped = *bytes_;
    flipped[s.offset + s.size / 3] ^= std::byte{0x40};
    auto pack = character::Pack::from_bytes(flipped, "flipped.pack");
    ASSERT_FALSE(pack.ok()) << section_id_name(s.id);
    EXPECT_EQ(pack.status().code(), ErrorCode::kChecksumMismatch) << pack.status().message();
  }
}

// FZHD bytes 25 (merge_rigid_bones), 26-27 (merged_bones) and 28-31
// (reserved): docs/PACK_FORMAT.md.
TEST_F(CorruptPack, TheRigidBoneFieldsRoundTripAndAreValidated) {
  const SectionId header = make_section_id("FZHD");
  auto pack = character::Pack::from_bytes(*bytes_, "pristine.pack");
  ASSERT_TRUE(pack.ok()) << pack.status().message();
  EXPECT_TRUE(pack->fuzzy_stats().merge_rigid_bones);
  EXPECT_EQ(pack->fuzzy_stats().merged_bones, baked_->fuzzy.stats.merged_bones);
  // A pack from before the option (both 0) still loads, as a bake that merged nothing.
  auto old = character::Pack::from_bytes(repack(header, [](auto& p) {
                                           overwrite(p, 25, std::uint8_t{0});
                                           overwrite(p, 13, std::uint16_t{0});
                                         }),
                                         "old.pack");
  ASSERT_TRUE(old.ok()) << old.status().message();
  EXPECT_FALSE(old->fuzzy_stats().merge_rigid_bones);
  EXPECT_EQ(old->fuzzy_stats().merged_bones, 0u);
  expect_rejected(repack(header, [](auto& p) { overwrite(p, 25, std::uint8_t{2}); }), "FZHD.merge_rigid_bones");
  expect_rejected(repack(header, [](auto& p) { overwrite(p, 13, std::uint16_t{60000}); }), "FZHD.merged_bones");
  expect_rejected(repack(header,
                         [](auto& p) {
                           overwrite(p, 25, std::uint8_t{0});
                           overwrite(p, 13, std::uint16_t{1});
                         }),
                  "FZHD.merged_bones");
  expect_rejected(repack(header, [](auto& p) { overwrite(p, 29, std::uint8_t{1}); }), "FZHD.reserved");
}

// FRAM: byte 0 the up axis, 1-3 reserved, 4-15 the rest bounds' lower
// corner, 16-27 the upper (docs/PACK_FORMAT.md).
TEST_F(CorruptPack, TheFramingSectionRoundTripsAndIsValidated) {
  const SectionId fram = make_section_id("FRAM");
  auto pack = character::Pack::from_bytes(*bytes_, "pristine.pack");
  ASSERT_TRUE(pack.ok()) << pack.status().message();
  ASSERT_TRUE(pack->framing_stored());
  // What the writer computed: the rest pose skinned vertex by vertex.
  const auto skin = character::rest_skinning(baked_->model).value();
  Aabb rest;
  for (std::size_t v = 0; v < baked_->model.mesh.vertex_count(); ++v) {
    Vec3 p(0.0f);
    for (int k = 0; k < kMaxInfluences; ++k) {
      p += baked_->model.mesh.weights[v][k] *
           skin[baked_->model.mesh.joints[v][k]].transform_point(baked_->model.mesh.positions[v]);
    }
    rest.extend(p);
  }
  const float tolerance = 1e-5f * glm::length(rest.extent());
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(pack->framing().rest_bounds.lower[a], rest.lower[a], tolerance);
    EXPECT_NEAR(pack->framing().rest_bounds.upper[a], rest.upper[a], tolerance);
  }
  EXPECT_EQ(pack->framing().up_axis, 1);  // the mannequin stands along +Y
  // A framing the writer is given is stored as given.
  character::PackContents given = contents_of(*baked_);
  given.framing = character::PackFraming{Aabb{Vec3(-1.0f, -2.0f, -3.0f), Vec3(4.0f, 5.0f, 6.0f)}, 2};
  auto given_bytes = character::serialize_pack(given);
  ASSERT_TRUE(given_bytes.ok());
  auto given_pack = character::Pack::from_bytes(*given_bytes, "given.pack");
  ASSERT_TRUE(given_pack.ok()) << given_pack.status().message();
  EXPECT_EQ(given_pack->framing().up_axis, 2);
  EXPECT_EQ(given_pack->framing().rest_bounds.lower, Vec3(-1.0f, -2.0f, -3.0f));
  EXPECT_EQ(given_pack->framing().rest_bounds.upper, Vec3(4.0f, 5.0f, 6.0f));

  const float nan = std::numeric_limits<float>::quiet_NaN();
  expect_rejected(repack(fram, [](auto& p) { overwrite(p, 0, std::uint8_t{0}); }), "FRAM.up_axis");
  expect_rejected(repack(fram, [](auto& p) { overwrite(p, 0, std::uint8_t{3}); }), "FRAM.up_axis");
  expect_rejected(repack(fram, [](auto& p) { overwrite(p, 2, std::uint8_t{1}); }), "FRAM.reserved");
  expect_rejected(repack(fram, [&](auto& p) { overwrite(p, 1, nan); }), "FRAM.rest_bounds.lower.x");
  expect_rejected(repack(fram, [](auto& p) { overwrite(p, 6, 2e9f); }), "FRAM.rest_bounds.upper.z");
  expect_rejected(repack(fram, [](auto& p) { overwrite(p, 2, 1e6f); }), "FRAM.rest_bounds.lower.y");  // above upper.y
  expect_rejected(repack(fram, [](auto& p) { p.pop_back(); }), "FRAM");
  expect_rejected(repack(fram, [](auto& p) { p.push_back(std::byte{0}); }), "FRAM");
  expect_rejected(testing_support::repack_section(*bytes_, fram, [](auto&) {}, 2u), "FRAM.version");
}

TEST_F(CorruptPack, KdNodeLinksOutsideTheTreeAreRefused) {
  // An inner node whose above child points past the bone's slice.
  std::size_t inner = 0;
  while (inner < baked_->fuzzy.nodes.size() && baked_->fuzzy.nodes[inner].is_leaf()) ++inner;
  ASSERT_LT(inner, baked_->fuzzy.nodes.size());
  rt::KdNode bad = baked_->fuzzy.nodes[inner];
  bad.word1 = (rt::KdNode::kMaxIndex << 2) | (bad.word1 & 3u);
  expect_rejected(repack(make_section_id("FNOD"), [&](auto& p) { overwrite(p, inner, bad); }), "fuzzy");
  // A child pointing back at its parent: a cycle.
  bad.word1 = (static_cast<std::uint32_t>(0) << 2) | (bad.word1 & 3u);
  expect_rejected(repack(make_section_id("FNOD"), [&](auto& p) { overwrite(p, inner, bad); }), "fuzzy");
}

TEST_F(CorruptPack, LeafListsPastTheEndAreRefused) {
  std::size_t leaf = 0;
  while (leaf < baked_->fuzzy.nodes.size() && !baked_->fuzzy.nodes[leaf].is_leaf()) ++leaf;
  ASSERT_LT(leaf, baked_->fuzzy.nodes.size());
  const rt::KdNode bad = rt::KdNode::leaf(static_cast<std::uint32_t>(baked_->fuzzy.items.size()), 3);
  expect_rejected(repack(make_section_id("FNOD"), [&](auto& p) { overwrite(p, leaf, bad); }), "fuzzy");
  // An item that is not a triangle of the mesh.
  expect_rejected(repack(make_section_id("FITM"), [&](auto& p) { overwrite(p, 0, std::uint32_t{0xfffffff0u}); }), "fuzzy");
}

TEST_F(CorruptPack, NanBoxesAreRefused) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  rt::BoneTree tree = baked_->fuzzy.bone_trees[1];
  tree.bounds.upper.y = nan;
  expect_rejected(repack(make_section_id("FBTR"), [&](auto& p) { overwrite(p, 1, tree); }), "bounds");
  rt::VertexCheck check = baked_->fuzzy.vertex_checks[5];
  check.box.lower.x = nan;
  expect_rejected(repack(make_section_id("FVCK"), [&](auto& p) { overwrite(p, 5, check); }), "box");
}

TEST_F(CorruptPack, BadMeshSkeletonAndClipDataAreRefused) {
  // MESH: after 16 bytes of counts and flags come the positions; a NaN there.
  expect_rejected(repack(make_section_id("MESH"), [](auto& p) { overwrite(p, 4, std::numeric_limits<float>::quiet_NaN()); }),
                  "MESH.positions[0]");
  // A vertex count far beyond the section: refused before allocating.
  expect_rejected(repack(make_section_id("MESH"), [](auto& p) { overwrite(p, 0, std::uint32_t{0xffffffffu}); }), "MESH.positions");
  // SKEL: a joint count beyond the limit.
  expect_rejected(repack(make_section_id("SKEL"), [](auto& p) { overwrite(p, 0, std::uint32_t{1u << 30}); }), "SKEL.joint_count");
  // CLIP: a clip count far beyond the section.
  expect_rejected(repack(make_section_id("CLIP"), [](auto& p) { overwrite(p, 0, std::uint32_t{60000}); }), "CLIP");
  // FTBN: a triangle assigned to a bone that does not exist.
  expect_rejected(repack(make_section_id("FTBN"), [](auto& p) { overwrite(p, 0, std::uint16_t{999}); }), "triangle_bone");
  // A section of the wrong size.
  expect_rejected(repack(make_section_id("FNOD"), [](auto& p) { p.erase(p.end() - 4, p.end()); }), "FNOD");
  // Trailing bytes after a decoded section.
  expect_rejected(repack(make_section_id("POSE"), [](auto& p) { p.push_back(std::byte{0}); }), "POSE.size");
  // A missing required section.
  auto reader = PackReader::from_bytes(*bytes_, "pristine");
  ASSERT_TRUE(reader.ok());
  PackWriter w;
  for (const SectionInfo& s : reader->sections()) {
    if (s.id != make_section_id("FBTR")) {
      ASSERT_TRUE(w.add_section(s.id, s.version, reader->section_bytes(s)).ok());
    }
  }
  auto missing = w.serialize();
  ASSERT_TRUE(missing.ok());
  expect_rejected(*missing, "FBTR");
}

// Skin weights that are all zero or sum to 2 passed the loader (each weight
// was finite and >= 0), and the vertex collapsed toward the origin. The
// importers refuse or renormalise such rows; a pack, written after them, is
// held to the same tolerance, naming the file, the vertex and the sum.
TEST_F(CorruptPack, SkinWeightsThatDoNotSumToOneAreRefused) {
  struct Case {
    float scale;         // vertex 7's weights multiplied by this
    std::string value;   // the value the message must show
  };
  for (const Case& c : {Case{0.0f, "0"}, Case{2.0f, "sum 2"}, Case{1.02f, "sum 1.02"}}) {
    character::Model model = baked_->model;
    for (float& w : model.mesh.weights[7]) w *= c.scale;
    character::PackContents contents = contents_of(*baked_);
    contents.model = &model;
    auto bytes = character::serialize_pack(contents);
    ASSERT_TRUE(bytes.ok()) << bytes.status().message();
    auto pack = character::Pack::from_bytes(*bytes, "weights.pack");
    ASSERT_FALSE(pack.ok()) << "weights scaled by " << c.scale << " were accepted";
    EXPECT_EQ(pack.status().code(), ErrorCode::kInvalidData);
    EXPECT_EQ(pack.status().file(), "weights.pack");
    EXPECT_EQ(pack.status().field(), "MESH.weights[7]") << pack.status().message();
    EXPECT_EQ(pack.status().value(), c.value) << pack.status().message();
  }
  // Within the importers' tolerance (8-bit weights), the pack loads.
  character::Model model = baked_->model;
  for (float& w : model.mesh.weights[7]) w *= 1.005f;
  character::PackContents contents = contents_of(*baked_);
  contents.model = &model;
  auto bytes = character::serialize_pack(contents);
  ASSERT_TRUE(bytes.ok());
  auto pack = character::Pack::from_bytes(*bytes, "weights.pack");
  EXPECT_TRUE(pack.ok()) << pack.status().message();
}

// Random byte changes inside each section, checksums recomputed: whatever
// the loader accepts must render without tripping the sanitizers.
// Well-formed but wrong fuzzy data, checksums recomputed: every fuzzy
// section zeroed in turn, two bones' trees swapped, one triangle dropped
// from a leaf. Each is refused by the check that the trees list every
// triangle where its fuzzy box reaches (a zeroed tree table used to load
// and render no character).
TEST_F(CorruptPack, WellFormedButInconsistentFuzzyDataIsRefused) {
  const std::pair<SectionId, const char*> sections[] = {
      {make_section_id("FTBN"), "FTBN"}, {make_section_id("FBTR"), "FBTR"}, {make_section_id("FNOD"), "FNOD"},
      {make_section_id("FITM"), "FITM"}, {make_section_id("FVCB"), "FVCB"}, {make_section_id("FVCK"), "FVCK"},
      {make_section_id("FTCK"), "FTCK"}};
  for (const auto& [id, name] : sections) {
    const auto zeroed = repack(id, [](auto& p) { std::fill(p.begin(), p.end(), std::byte{0}); });
    auto pack = character::Pack::from_bytes(zeroed, "corrupt.pack");
    EXPECT_FALSE(pack.ok()) << name << " zeroed was accepted";
  }
  // Two bones with triangles swap their tree entries (48 bytes each).
  const rt::FuzzyCharacterView f = baked_->fuzzy.view();
  std::vector<std::uint32_t> with_triangles;
  for (std::uint32_t b = 0; b < f.bone_count; ++b) {
    if (f.bone_trees[b].triangle_count > 0) with_triangles.push_back(b);
  }
  ASSERT_GE(with_triangles.size(), 2u);
  const std::size_t a = with_triangles.front(), b = with_triangles.back();
  expect_rejected(repack(make_section_id("FBTR"),
                         [&](auto& p) {
                           std::swap_ranges(p.begin() + static_cast<std::ptrdiff_t>(48 * a),
                                            p.begin() + static_cast<std::ptrdiff_t>(48 * a + 48),
                                            p.begin() + static_cast<std::ptrdiff_t>(48 * b));
                         }),
                  "bone_trees");
  // One leaf item replaced by the next triangle of the same bone that the
  // leaf does not list: the replaced one is then missing.
  const rt::KdTreeView tree = f.bone_tree(static_cast<std::uint32_t>(a));
  std::size_t leaf_item = SIZE_MAX;
  std::uint32_t replacement = 0;
  for (const rt::KdNode& node : tree.nodes) {
    if (!node.is_leaf() || node.item_count() == 0) continue;
    const std::uint32_t last = tree.items[node.first_item() + node.item_count() - 1];
    for (std::uint32_t t = last + 1; t < f.triangle_bone.size(); ++t) {
      if (f.triangle_bone[t] == a) {
        leaf_item = f.bone_trees[a].item_begin + node.first_item() + node.item_count() - 1;
        replacement = t;
        break;
      }
    }
    if (leaf_item != SIZE_MAX) break;
  }
  ASSERT_NE(leaf_item, SIZE_MAX);
  expect_rejected(repack(make_section_id("FITM"),
                         [&](auto& p) { std::memcpy(p.data() + 4 * leaf_item, &replacement, 4); }),
                  "missing from a leaf");
}

// Every refusal of the corruption suite is one line of at most 300 bytes
// naming the pack, then a section and its field ("damaged.pack: SKEL...").
// A skeleton, clip or limit the builders refused used to run the pack's
// path into the section's name, without its ':'.
TEST_F(CorruptPack, EveryRefusalNamesThePackAndAFieldInOneShortLine) {
  const auto expect_shape = [](const Status& s, const std::string& what) {
    const std::string message = s.message();
    EXPECT_LE(message.size(), 300u) << what << ": " << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << what;
    EXPECT_EQ(s.file(), "damaged.pack") << what << ": " << message;
    EXPECT_EQ(message.rfind("damaged.pack: ", 0), 0u) << what << ": " << message;
    EXPECT_FALSE(s.field().empty()) << what << ": " << message;
  };
  int refused = 0;
  for (const testing_support::DamagedPack& damaged : testing_support::randomly_damaged_packs(*bytes_, 12, 1234)) {
    auto pack = character::Pack::from_bytes(damaged.bytes, "damaged.pack");
    if (pack.ok()) continue;
    ++refused;
    expect_shape(pack.status(), damaged.what);
  }
  EXPECT_GT(refused, 0);
  // Joint 0's rest rotation (after the joint count, its name, parent and
  // translation) made NaN: refused by the skeleton's builder.
  const std::size_t rotation = 4 + 4 + baked_->model.skeleton.names()[0].size() + 4 + 12;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  auto nan_rotation = character::Pack::from_bytes(
      repack(make_section_id("SKEL"), [&](auto& p) { std::memcpy(p.data() + rotation, &nan, sizeof nan); }),
      "damaged.pack");
  ASSERT_FALSE(nan_rotation.ok());
  expect_shape(nan_rotation.status(), "SKEL rotation NaN");
  EXPECT_EQ(nan_rotation.status().field().substr(0, 14), "SKEL.joints[0]") << nan_rotation.status().message();
}

TEST_F(CorruptPack, RandomDamageNeverCrashes) {
  JobSystem jobs(1);
  int accepted = 0, refused = 0;
  for (const testing_support::DamagedPack& damaged : testing_support::randomly_damaged_packs(*bytes_, 12, 1234)) {
    auto pack = character::Pack::from_bytes(damaged.bytes, "damaged.pack");
    if (!pack.ok()) {
      ++refused;
      continue;
    }
    ++accepted;
    if (pack->has_fuzzy()) render(pack->model(), pack->fuzzy(), jobs, /*strict=*/false);
  }
  EXPECT_GT(refused, 0);
  RecordProperty("accepted", accepted);
}


// --- pose-space clusters -----------------------------------------------------------

// The cluster sections (FCHD and the arrays after it) of a bake with
// FuzzyBakeOptions::pose_clusters.
const SectionId kClusterSections[] = {make_section_id("FCHD"), make_section_id("FCLB"), make_section_id("FCLS"),
                                      make_section_id("FCKR"), make_section_id("FCLX"), make_section_id("FFBB"),
                                      make_section_id("FFBN"), make_section_id("FCCN")};

// The pack without the sections `drop`, everything else as it was.
std::vector<std::byte> without_sections(std::span<const std::byte> bytes, std::span<const SectionId> drop) {
  auto reader = PackReader::from_bytes(bytes, "pristine");
  EXPECT_TRUE(reader.ok());
  if (!reader.ok()) return {};
  PackWriter w;
  for (const SectionInfo& s : reader->sections()) {
    if (std::find(drop.begin(), drop.end(), s.id) != drop.end()) continue;
    EXPECT_TRUE(w.add_section(s.id, s.version, reader->section_bytes(s)).ok());
  }
  auto out = w.serialize();
  EXPECT_TRUE(out.ok());
  return out.ok() ? std::move(*out) : std::vector<std::byte>{};
}

template <typename T>
void expect_same_array(std::span<const T> loaded, const std::vector<T>& baked, const char* name) {
  ASSERT_EQ(loaded.size(), baked.size()) << name;
  EXPECT_EQ(std::memcmp(loaded.data(), baked.data(), baked.size() * sizeof(T)), 0) << name << " differs";
}

// The mannequin (two bones blended at every joint, so most bones have
// feature bones) over 40 arbitrary poses, in at most 4 clusters a bone.
// It keeps its pack in CorruptPack's slots, which repack() reads: the two
// suites run one after the other, each setting them up and freeing them.
class ClusterPack : public CorruptPack {
 protected:
  static void SetUpTestSuite() { bake_clustered(rt::BoneTreeKind::kKdTree); }
  // The mannequin over 40 arbitrary poses, 4 clusters a bone, `trees` (BVH
  // leaves of at most 4 triangles, so that its small meshes have inner nodes).
  static void bake_clustered(rt::BoneTreeKind trees) {
    JobSystem jobs(2);
    auto model = content::make_mannequin();
    ASSERT_TRUE(model.ok());
    character::BakeRequest request;
    request.pose_space.mode = anim::PoseSpaceMode::kArbitrary;
    request.pose_space.samples = 40;
    request.pose_space.seed = 7;
    request.fuzzy.pose_clusters = 4;
    request.fuzzy.bone_trees = trees;
    request.fuzzy.bvh.max_leaf_items = 4;
    baked_ = new Baked(bake(std::move(*model), jobs, request));
    bytes_ = new std::vector<std::byte>(pack_bytes(*baked_));
  }
  static void TearDownTestSuite() { CorruptPack::TearDownTestSuite(); }

  // The first cluster of a bone, and that bone.
  static std::pair<std::uint32_t, std::uint32_t> first_cluster() {
    const rt::FuzzyCharacterData& f = baked_->fuzzy;
    for (std::uint32_t b = 0; b < f.bone_count; ++b) {
      if (f.bone_cluster_begin[b] != f.bone_cluster_begin[b + 1]) return {f.bone_cluster_begin[b], b};
    }
    ADD_FAILURE() << "no bone has clusters";
    return {0, 0};
  }

  static void expect_rejected_with(const std::vector<std::byte>& bytes, ErrorCode code, const std::string& field) {
    auto pack = character::Pack::from_bytes(bytes, "corrupt.pack");
    ASSERT_FALSE(pack.ok()) << "a corrupt " << field << " was accepted";
    EXPECT_EQ(pack.status().code(), code) << pack.status().message();
    EXPECT_NE(pack.status().message().find("corrupt.pack"), std::string::npos) << pack.status().message();
    EXPECT_NE(pack.status().message().find(field), std::string::npos) << pack.status().message();
  }
};

TEST_F(ClusterPack, TheClusterArraysRoundTripElementForElement) {
  const rt::FuzzyCharacterData& f = baked_->fuzzy;
  ASSERT_FALSE(f.clusters.empty()) << "the test bake should cluster";
  ASSERT_EQ(f.stats.clusters_per_bone, 4u);
  auto pack = character::Pack::from_bytes(*bytes_, "clusters.pack");
  ASSERT_TRUE(pack.ok()) << pack.status().message();
  const rt::FuzzyCharacterView& v = pack->fuzzy();
  ASSERT_TRUE(v.has_clusters());
  expect_same_array(v.bone_cluster_begin, f.bone_cluster_begin, "bone_cluster_begin");
  expect_same_array(v.clusters, f.clusters, "clusters");
  expect_same_array(v.check_rank, f.check_rank, "check_rank");
  expect_same_array(v.cluster_boxes, f.cluster_boxes, "cluster_boxes");
  expect_same_array(v.feature_bone_begin, f.feature_bone_begin, "feature_bone_begin");
  expect_same_array(v.feature_bones, f.feature_bones, "feature_bones");
  expect_same_array(v.cluster_centres, f.cluster_centres, "cluster_centres");
  // The cluster trees live in the node and item arrays after the bones'.
  expect_same_array(v.nodes, f.nodes, "nodes");
  expect_same_array(v.items, f.items, "items");
  EXPECT_EQ(v.feature_translation_scale, f.feature_translation_scale);
  for (std::uint32_t b = 0; b < f.bone_count; ++b) {
    EXPECT_EQ(v.bone_clusters(b).size(), f.view().bone_clusters(b).size()) << "bone " << b;
  }
  const rt::FuzzyBakeStats& st = pack->fuzzy_stats();
  EXPECT_EQ(st.clusters_per_bone, 4u);
  EXPECT_EQ(st.cluster_count, f.clusters.size());
  EXPECT_EQ(st.cluster_count, f.stats.cluster_count);
  EXPECT_EQ(st.cluster_fuzzy_area, f.stats.cluster_fuzzy_area);
  EXPECT_EQ(st.clustering_ms, 0.0) << "timings are not stored in the fuzzy sections";
  // Used in place, like the rest of the fuzzy data.
  const auto mapped = pack->reader().bytes();
  EXPECT_GE(static_cast<const void*>(v.cluster_boxes.data()), static_cast<const void*>(mapped.data()));
  EXPECT_LT(static_cast<const void*>(v.cluster_boxes.data()), static_cast<const void*>(mapped.data() + mapped.size()));
  // And it renders as the in-memory bake does (the scene uses clusters by default).
  JobSystem jobs(2);
  const Image in_memory = render(baked_->model, f.view(), jobs);
  EXPECT_TRUE(render(pack->model(), v, jobs) == in_memory) << "rendering from the pack differs from the in-memory bake";
  // The same inputs give the same bytes.
  EXPECT_TRUE(pack_bytes(*baked_) == *bytes_);
}

// A bake without clusters writes none of the cluster sections, so its pack
// is what the writer made before they existed; a clustering bake writes all.
TEST_F(ClusterPack, APackWithoutClustersHasNoClusterSections) {
  JobSystem jobs(2);
  auto model = content::make_mannequin();
  ASSERT_TRUE(model.ok());
  character::BakeRequest kd;
  kd.fuzzy.bone_trees = rt::BoneTreeKind::kKdTree;  // as the fixture's pack
  const Baked plain = bake(std::move(*model), jobs, kd);
  ASSERT_TRUE(plain.fuzzy.bone_cluster_begin.empty());
  const auto bytes = pack_bytes(plain);
  auto reader = PackReader::from_bytes(bytes, "plain");
  ASSERT_TRUE(reader.ok());
  for (const SectionId id : kClusterSections) EXPECT_FALSE(reader->contains(id)) << section_id_name(id);
  auto pack = character::Pack::from_bytes(bytes, "plain.pack");
  ASSERT_TRUE(pack.ok()) << pack.status().message();
  EXPECT_FALSE(pack->fuzzy().has_clusters());
  EXPECT_TRUE(pack->fuzzy().bone_cluster_begin.empty());
  EXPECT_EQ(pack->fuzzy_stats().clusters_per_bone, 0u);
  EXPECT_EQ(pack->fuzzy_stats().cluster_count, 0u);

  auto clustered = PackReader::from_bytes(*bytes_, "clustered");
  ASSERT_TRUE(clustered.ok());
  for (const SectionId id : kClusterSections) EXPECT_TRUE(clustered->contains(id)) << section_id_name(id);
  // A pack with clusters writes its trees (the bones', then the clusters')
  // as FNOD and FITM version 2, so a reader that predates the clusters
  // refuses it by version; without the cluster sections this build does
  // the same rather than read nodes no bone tree covers.
  EXPECT_EQ(reader->find(make_section_id("FNOD"))->version, 1u);
  EXPECT_EQ(clustered->find(make_section_id("FNOD"))->version, 2u);
  EXPECT_EQ(clustered->find(make_section_id("FITM"))->version, 2u);
  expect_rejected_with(without_sections(*bytes_, kClusterSections), ErrorCode::kUnsupportedVersion, "FNOD.version");
}

TEST_F(ClusterPack, ThePristineClusterPackLoads) {
  auto pack = character::Pack::from_bytes(*bytes_, "pristine.pack");
  ASSERT_TRUE(pack.ok()) << pack.status().message();
  EXPECT_TRUE(pack->fuzzy().has_clusters());
}

TEST_F(ClusterPack, AClusterBoxRangePastTheEndIsRefused) {
  const std::uint32_t q = first_cluster().first;
  rt::BoneCluster bad = baked_->fuzzy.clusters[q];
  bad.box_begin = static_cast<std::uint32_t>(baked_->fuzzy.cluster_boxes.size());
  expect_rejected_with(repack(make_section_id("FCLS"), [&](auto& p) { overwrite(p, q, bad); }),
                       ErrorCode::kInvalidData, "clusters[" + std::to_string(q) + "].box_begin");
  bad = baked_->fuzzy.clusters[q];
  bad.centre_begin = static_cast<std::uint32_t>(baked_->fuzzy.cluster_centres.size());
  expect_rejected_with(repack(make_section_id("FCLS"), [&](auto& p) { overwrite(p, q, bad); }),
                       ErrorCode::kInvalidData, "clusters[" + std::to_string(q) + "].centre_begin");
}

TEST_F(ClusterPack, NanClusterBoxesAndCentresAreRefused) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::size_t i = baked_->fuzzy.cluster_boxes.size() / 2;
  Aabb box = baked_->fuzzy.cluster_boxes[i];
  box.upper.z = nan;
  expect_rejected_with(repack(make_section_id("FCLX"), [&](auto& p) { overwrite(p, i, box); }),
                       ErrorCode::kInvalidData, "cluster_boxes[" + std::to_string(i) + "]");
  const std::uint32_t c = baked_->fuzzy.clusters[first_cluster().first].centre_begin;
  expect_rejected_with(repack(make_section_id("FCCN"), [&](auto& p) { overwrite(p, c, nan); }),
                       ErrorCode::kInvalidData, "cluster_centres[" + std::to_string(c) + "]");
}

TEST_F(ClusterPack, ACheckRankOutOfRangeIsRefused) {
  const rt::FuzzyCharacterData& f = baked_->fuzzy;
  const std::uint32_t bone = first_cluster().second;
  std::size_t c = 0;
  while (c < f.vertex_checks.size() && f.vertex_checks[c].bone != bone) ++c;
  ASSERT_LT(c, f.vertex_checks.size());
  expect_rejected_with(repack(make_section_id("FCKR"), [&](auto& p) { overwrite(p, c, std::uint32_t{0x7fffffffu}); }),
                       ErrorCode::kInvalidData, "check_rank[" + std::to_string(c) + "]");
  // One rank short: one rank per check.
  // (Guarded: GCC at -O1 cannot see the payload holds a rank and warns.)
  expect_rejected_with(repack(make_section_id("FCKR"),
                              [](auto& p) {
                                if (p.size() >= 4) p.resize(p.size() - 4);
                              }),
                       ErrorCode::kInvalidData, "check_rank");
}

TEST_F(ClusterPack, BadOffsetsAndFeatureBonesAreRefused) {
  const rt::FuzzyCharacterData& f = baked_->fuzzy;
  expect_rejected_with(repack(make_section_id("FCLB"),
                              [&](auto& p) { overwrite(p, f.bone_count, std::uint32_t{0xffffu}); }),
                       ErrorCode::kInvalidData, "bone_cluster_begin");
  // An empty FCLB beside a header that says the bake clustered.
  expect_rejected_with(repack(make_section_id("FCLB"), [](auto& p) { p.clear(); }), ErrorCode::kInvalidData,
                       "FCLB");
  expect_rejected_with(repack(make_section_id("FFBB"), [](auto& p) { overwrite(p, 0, std::uint32_t{1}); }),
                       ErrorCode::kInvalidData, "feature_bone_begin");
  ASSERT_FALSE(f.feature_bones.empty());
  expect_rejected_with(repack(make_section_id("FFBN"), [](auto& p) { overwrite(p, 0, std::uint16_t{60000}); }),
                       ErrorCode::kInvalidData, "feature_bones[0]");
}

TEST_F(ClusterPack, AMissingClusterSectionIsRefusedByName) {
  for (const SectionId id : kClusterSections) {
    if (id == make_section_id("FCHD")) continue;
    const SectionId drop[] = {id};
    expect_rejected_with(without_sections(*bytes_, drop), ErrorCode::kNotFound, section_id_name(id));
  }
  // Cluster sections without their header.
  const SectionId header[] = {make_section_id("FCHD")};
  expect_rejected_with(without_sections(*bytes_, header), ErrorCode::kNotFound, "FCHD");
  // A cluster section of a version this build does not read.
  expect_rejected_with(testing_support::repack_section(*bytes_, make_section_id("FCLS"), [](auto&) {}, 2u),
                       ErrorCode::kUnsupportedVersion, "FCLS.version");
  // Cluster sections in a pack without fuzzy data.
  const SectionId fuzzy[] = {make_section_id("FZHD"), make_section_id("FTBN"), make_section_id("FBTR"),
                             make_section_id("FNOD"), make_section_id("FITM"), make_section_id("FVCB"),
                             make_section_id("FVCK"), make_section_id("FTCK")};
  expect_rejected_with(without_sections(*bytes_, fuzzy), ErrorCode::kNotFound, "FZHD");
}

// FCHD: scale (float, bytes 0-3), clusters_per_bone (4-7), cluster_count
// (8-11), reserved (12-15), cluster_fuzzy_area (double, 16-23).
TEST_F(ClusterPack, ABadClusterHeaderIsRefused) {
  const SectionId header = make_section_id("FCHD");
  const auto with = [&](std::size_t offset, auto value) {
    return repack(header, [&](auto& p) {
      ASSERT_LE(offset + sizeof(value), p.size());
      std::memcpy(p.data() + offset, &value, sizeof(value));
    });
  };
  const auto clusters = static_cast<std::uint32_t>(baked_->fuzzy.clusters.size());
  expect_rejected_with(with(8, clusters + 1), ErrorCode::kInvalidData, "FCHD.cluster_count");
  expect_rejected_with(with(8, clusters - 1), ErrorCode::kInvalidData, "FCHD.cluster_count");
  expect_rejected_with(with(0, std::numeric_limits<float>::quiet_NaN()), ErrorCode::kInvalidData,
                       "FCHD.feature_translation_scale");
  expect_rejected_with(with(0, 0.0f), ErrorCode::kInvalidData, "FCHD.feature_translation_scale");
  expect_rejected_with(with(0, std::numeric_limits<float>::infinity()), ErrorCode::kInvalidData,
                       "FCHD.feature_translation_scale");
  expect_rejected_with(with(4, std::uint32_t{0}), ErrorCode::kInvalidData, "FCHD.clusters_per_bone");
  expect_rejected_with(with(4, rt::kMaxPoseClusters + 1), ErrorCode::kInvalidData, "FCHD.clusters_per_bone");
  // Fewer than a bone has.
  std::uint32_t most = 0;
  for (std::uint32_t b = 0; b < baked_->fuzzy.bone_count; ++b) {
    most = std::max(most, baked_->fuzzy.bone_cluster_begin[b + 1] - baked_->fuzzy.bone_cluster_begin[b]);
  }
  ASSERT_GE(most, 2u);
  expect_rejected_with(with(4, most - 1), ErrorCode::kInvalidData, "FCHD.clusters_per_bone");
  expect_rejected_with(with(13, std::uint8_t{1}), ErrorCode::kInvalidData, "FCHD.reserved");
  expect_rejected_with(with(16, -1.0), ErrorCode::kInvalidData, "FCHD.cluster_fuzzy_area");
  expect_rejected_with(repack(header, [](auto& p) { p.push_back(std::byte{0}); }), ErrorCode::kInvalidData,
                       "FCHD");
  expect_rejected_with(repack(header, [](auto& p) { p.resize(20); }), ErrorCode::kTruncated, "FCHD.header");
  // A scale that is finite and positive but not the bake's still loads: only
  // the choice of cluster changes, never what a ray can reach.
  auto other_scale = character::Pack::from_bytes(with(0, 3.5f), "scale.pack");
  ASSERT_TRUE(other_scale.ok()) << other_scale.status().message();
  EXPECT_EQ(other_scale->fuzzy().feature_translation_scale, 3.5f);
}

// Random damage to the cluster sections: refused or safe to render.
TEST_F(ClusterPack, RandomDamageToClusterSectionsNeverCrashes) {
  EXPECT_GT(damaged_packs_refused(kClusterSections, 12, 4321), 0);
}

// --- BVH bone trees --------------------------------------------------------------

// The mannequin over 40 arbitrary poses with BVH bone trees (leaves of at
// most 4, so that the small meshes have inner nodes) and 4 clusters a bone:
// every BVH section of a pack. Like ClusterPack it keeps its pack in
// CorruptPack's slots.
class BvhPack : public ClusterPack {
 protected:
  static void SetUpTestSuite() { bake_clustered(rt::BoneTreeKind::kBvh); }
  static void TearDownTestSuite() { CorruptPack::TearDownTestSuite(); }

  // The first node of the pack's BVH nodes that is (or is not) a leaf.
  static std::size_t first_node(bool leaf) {
    const std::vector<rt::BvhNode>& nodes = baked_->fuzzy.bvh_nodes;
    for (std::size_t n = 0; n < nodes.size(); ++n) {
      if (nodes[n].is_leaf() == leaf) return n;
    }
    ADD_FAILURE() << "no " << (leaf ? "leaf" : "inner node");
    return 0;
  }

  // Where leaf `node`'s first item lies in the pack's item array (its
  // tree's slice offset plus the tree-relative index).
  static std::size_t leaf_item_index(std::size_t node) {
    const rt::FuzzyCharacterData& f = baked_->fuzzy;
    std::vector<rt::BoneTree> trees(f.bone_trees.begin(), f.bone_trees.end());
    for (const rt::BoneCluster& c : f.clusters) trees.push_back(c.tree);
    for (const rt::BoneTree& t : trees) {
      if (node >= t.node_begin && node < std::size_t{t.node_begin} + t.node_count) {
        return t.item_begin + f.bvh_nodes[node].first;
      }
    }
    ADD_FAILURE() << "node " << node << " in no tree";
    return 0;
  }
};

TEST_F(BvhPack, TheTreesRoundTripAndRenderAsTheInMemoryBake) {
  const rt::FuzzyCharacterData& f = baked_->fuzzy;
  ASSERT_EQ(f.tree_kind, rt::BoneTreeKind::kBvh);
  ASSERT_TRUE(f.nodes.empty());
  ASSERT_FALSE(f.bvh_nodes.empty());
  ASSERT_FALSE(f.clusters.empty());
  auto pack = character::Pack::from_bytes(*bytes_, "bvh.pack");
  ASSERT_TRUE(pack.ok()) << pack.status().message();
  const rt::FuzzyCharacterView& v = pack->fuzzy();
  EXPECT_TRUE(v.has_bvhs());
  EXPECT_TRUE(v.nodes.empty());
  expect_same_array(v.bvh_nodes, f.bvh_nodes, "bvh_nodes");
  expect_same_array(v.items, f.items, "items");
  expect_same_array(v.bone_trees, f.bone_trees, "bone_trees");
  expect_same_array(v.clusters, f.clusters, "clusters");
  // Each tree lists each of its bone's triangles once.
  for (const rt::BoneTree& bt : f.bone_trees) EXPECT_EQ(bt.item_count, bt.triangle_count);
  for (const rt::BoneCluster& c : f.clusters) EXPECT_EQ(c.tree.item_count, c.tree.triangle_count);
  const auto mapped = pack->reader().bytes();
  EXPECT_GE(static_cast<const void*>(v.bvh_nodes.data()), static_cast<const void*>(mapped.data()));
  EXPECT_LT(static_cast<const void*>(v.bvh_nodes.data()), static_cast<const void*>(mapped.data() + mapped.size()));
  JobSystem jobs(2);
  const Image in_memory = render(baked_->model, f.view(), jobs);
  EXPECT_TRUE(render(pack->model(), v, jobs) == in_memory) << "rendering from the pack differs from the in-memory bake";
  EXPECT_TRUE(pack_bytes(*baked_) == *bytes_);
}

// FBVN instead of FNOD, and FITM as version 3: a reader that predates BVHs
// refuses the pack by FITM's version (or FNOD's absence), never reads BVH
// items as kd leaves; this build refuses mixtures.
TEST_F(BvhPack, ItsSectionsAndVersionsTellItApart) {
  auto reader = PackReader::from_bytes(*bytes_, "bvh");
  ASSERT_TRUE(reader.ok());
  EXPECT_TRUE(reader->contains(make_section_id("FBVN")));
  EXPECT_FALSE(reader->contains(make_section_id("FNOD")));
  EXPECT_EQ(reader->find(make_section_id("FITM"))->version, 3u);
  EXPECT_EQ(reader->find(make_section_id("FBVN"))->version, 1u);
  expect_rejected_with(testing_support::repack_section(*bytes_, make_section_id("FITM"), [](auto&) {}, 2u),
                       ErrorCode::kUnsupportedVersion, "FITM.version");
  expect_rejected_with(testing_support::repack_section(*bytes_, make_section_id("FBVN"), [](auto&) {}, 2u),
                       ErrorCode::kUnsupportedVersion, "FBVN.version");
  // Without FBVN the items read as a kd pack's, whose nodes are missing.
  const SectionId bvh[] = {make_section_id("FBVN")};
  expect_rejected_with(without_sections(*bytes_, bvh), ErrorCode::kNotFound, "FNOD");
  // Both kinds of node.
  PackWriter w;
  for (const SectionInfo& s : reader->sections()) ASSERT_TRUE(w.add_section(s.id, s.version, reader->section_bytes(s)).ok());
  const rt::KdNode leaf = rt::KdNode::leaf(0, 1);
  ASSERT_TRUE(w.add_section(make_section_id("FNOD"), 2, std::as_bytes(std::span(&leaf, 1))).ok());
  auto both = w.serialize();
  ASSERT_TRUE(both.ok());
  expect_rejected_with(*both, ErrorCode::kInvalidData, "FNOD");
}

TEST_F(BvhPack, BadNodeLinksAndLeafRangesAreRefused) {
  const SectionId nodes = make_section_id("FBVN");
  const std::size_t inner = first_node(false);
  rt::BvhNode bad = baked_->fuzzy.bvh_nodes[inner];
  bad.first = 0xfffffff0u;
  expect_rejected_with(repack(nodes, [&](auto& p) { overwrite(p, inner, bad); }), ErrorCode::kInvalidData,
                       "child index outside the tree");
  bad.first = static_cast<std::uint32_t>(inner);  // itself: a cycle
  expect_rejected_with(repack(nodes, [&](auto& p) { overwrite(p, inner, bad); }), ErrorCode::kInvalidData,
                       "child index outside the tree");
  const std::size_t leaf = first_node(true);
  bad = baked_->fuzzy.bvh_nodes[leaf];
  bad.first = 0xfffffff0u;
  expect_rejected_with(repack(nodes, [&](auto& p) { overwrite(p, leaf, bad); }), ErrorCode::kInvalidData,
                       "leaf items outside the item array");
  bad = baked_->fuzzy.bvh_nodes[leaf];
  bad.box.lower.x = std::numeric_limits<float>::quiet_NaN();
  expect_rejected_with(repack(nodes, [&](auto& p) { overwrite(p, leaf, bad); }), ErrorCode::kInvalidData,
                       "bvh_nodes[" + std::to_string(leaf) + "].box");
}

// The conservativeness a walk relies on: a leaf's box holds its triangles'
// fuzzy boxes and a parent's box its children's; each triangle listed once.
TEST_F(BvhPack, BoxesThatLeaveTheirParentsOrTrianglesAreRefused) {
  const SectionId nodes = make_section_id("FBVN");
  const std::size_t leaf = first_node(true);
  rt::BvhNode bad = baked_->fuzzy.bvh_nodes[leaf];
  // Shrunk to its lower corner on x: its triangles' boxes stick out.
  bad.box.upper.x = bad.box.lower.x;
  expect_rejected_with(repack(nodes, [&](auto& p) { overwrite(p, leaf, bad); }), ErrorCode::kInvalidData,
                       "leaves its BVH leaf's box");
  // Grown past its parent's box.
  bad = baked_->fuzzy.bvh_nodes[leaf];
  bad.box.upper.x += 1.0f;
  expect_rejected_with(repack(nodes, [&](auto& p) { overwrite(p, leaf, bad); }), ErrorCode::kInvalidData,
                       "a child's box leaves its parent's");
  // One triangle listed twice (and its neighbour in the item array not at all).
  const rt::BvhNode& l = baked_->fuzzy.bvh_nodes[leaf];
  ASSERT_GE(l.count, 2u);
  const SectionId items = make_section_id("FITM");
  const std::size_t first_item = leaf_item_index(leaf);
  const std::uint32_t twin = baked_->fuzzy.items[first_item];
  expect_rejected_with(repack(items, [&](auto& p) { overwrite(p, first_item + 1, twin); }), ErrorCode::kInvalidData,
                       "listed twice");
}

TEST_F(BvhPack, RandomDamageToTheTreesNeverCrashes) {
  const SectionId trees[] = {make_section_id("FBVN"), make_section_id("FITM"), make_section_id("FBTR")};
  EXPECT_GT(damaged_packs_refused(trees, 16, 99), 0);
}

}  // namespace
}  // namespace sinew::editor
