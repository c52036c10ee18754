// Resource limits (docs/ROBUSTNESS.md): inputs beyond what the format or
// memory allows are refused with a clear message before any allocation in
// proportion to the claim, and the bake's memory is bounded and reported.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <unistd.h>

#include <cstring>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "character/bake.h"
#include "character/pack.h"
#include "content/mannequin/mannequin.h"
#include "editor/cli/pack_commands.h"
#include "raytrace/bake/fuzzy_bake.h"
#include "runtime/jobs/job_system.h"
#include "runtime/pack/checksum.h"
#include "runtime/pack/pack_reader.h"
#include "runtime/pack/pack_writer.h"
#include "tests/support/idle_mannequin.h"
#include "tests/support/temp_dir.h"

namespace sinew {
namespace {

constexpr std::uint64_t kTerabyte = std::uint64_t{1} << 40;

std::vector<std::byte> empty_pack() {
  PackWriter w;
  EXPECT_TRUE(w.add_section(make_section_id("TEST"), 1, std::vector<std::byte>(64, std::byte{0})).ok());
  return w.serialize().value();
}

void set_file_size(std::vector<std::byte>& bytes, std::uint64_t size) {
  PackHeader h = load_pack_header(std::span(bytes).first<kHeaderSize>());
  h.file_size = size;
  h.header_checksum = pack_header_checksum(h);
  store_pack_header(h, std::span(bytes).first<kHeaderSize>());
}

TEST(PackLimits, ASmallFileClaimingATerabyteReadsAsTruncated) {
  std::vector<std::byte> bytes = empty_pack();
  set_file_size(bytes, kTerabyte);
  const auto reader = PackReader::from_bytes(bytes, "claims.pack");
  ASSERT_FALSE(reader.ok());
  EXPECT_EQ(reader.status().code(), ErrorCode::kTruncated);
  EXPECT_EQ(reader.status().field(), "header.file_size");
  EXPECT_NE(reader.status().message().find(std::to_string(kTerabyte)), std::string::npos) << reader.status().message();
}

// A real (sparse) 1 TB file whose header agrees: refused from the header,
// without reading the terabyte of zero padding after it.
TEST(PackLimits, ATerabytePackIsRefusedFromItsHeader) {
  testing_support::TempDir dir;
  const std::string path = dir.file("huge.pack");
  std::vector<std::byte> bytes = empty_pack();
  set_file_size(bytes, kTerabyte);
  {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  }
  if (::truncate(path.c_str(), static_cast<off_t>(kTerabyte)) != 0) {
    GTEST_SKIP() << "this file system cannot hold a sparse 1 TB file";
  }
  const auto reader = PackReader::open(path);
  std::filesystem::remove(path);
  ASSERT_FALSE(reader.ok());
  if (reader.status().code() == ErrorCode::kIoError) GTEST_SKIP() << "cannot map 1 TB here: " << reader.status().message();
  EXPECT_EQ(reader.status().code(), ErrorCode::kLimitExceeded) << reader.status().message();
  EXPECT_EQ(reader.status().field(), "header.file_size");
  EXPECT_NE(reader.status().message().find("64 GiB"), std::string::npos) << reader.status().message();
}

// --- character pack sections claiming absurd counts -------------------------------

class CharacterPackLimits : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    const auto& m = testing_support::idle_mannequin();
    character::PackContents contents;
    contents.model = &m.model;
    contents.fuzzy = &m.bake.fuzzy;
    pristine_ = new std::vector<std::byte>(character::serialize_pack(contents).value());
  }
  static void TearDownTestSuite() { delete pristine_; }

  // The pack with one section's payload changed, the container rebuilt.
  static std::vector<std::byte> repack(const char (&id)[5], const std::function<void(std::vector<std::byte>&)>& edit) {
    const auto reader = PackReader::from_bytes(*pristine_, "pristine");
    EXPECT_TRUE(reader.ok());
    PackWriter w;
    for (const SectionInfo& s : reader->sections()) {
      const auto payload = reader->section_bytes(s);
      std::vector<std::byte> copy(payload.begin(), payload.end());
      if (s.id == make_section_id(id)) edit(copy);
      EXPECT_TRUE(w.add_section(s.id, s.version, std::move(copy)).ok());
    }
    return w.serialize().value();
  }

  static void put_u32(std::vector<std::byte>& payload, std::size_t offset, std::uint32_t value) {
    std::memcpy(payload.data() + offset, &value, sizeof value);
  }

  static Status load(const std::vector<std::byte>& bytes) {
    const auto pack = character::Pack::from_bytes(bytes, "absurd.pack");
    return pack.ok() ? Status{} : pack.status();
  }

  static inline std::vector<std::byte>* pristine_ = nullptr;
};

TEST_F(CharacterPackLimits, TheUnchangedPackLoads) { EXPECT_TRUE(load(*pristine_).ok()); }

TEST_F(CharacterPackLimits, AMeshDeclaringTwoToThe32TrianglesIsRefused) {
  // MESH: vertex_count, triangle_count, ... ; the largest u32 triangle count.
  const Status s = load(repack("MESH", [](auto& p) { put_u32(p, 4, 0xffffffffu); }));
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.code(), ErrorCode::kTruncated);
  EXPECT_NE(s.message().find("absurd.pack"), std::string::npos);
  EXPECT_NE(s.message().find("MESH.triangles"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("4294967295"), std::string::npos) << s.message();
}

TEST_F(CharacterPackLimits, AMillionJointSkeletonIsRefused) {
  const Status s = load(repack("SKEL", [](auto& p) { put_u32(p, 0, 1000000u); }));
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.code(), ErrorCode::kLimitExceeded);
  EXPECT_NE(s.message().find("SKEL.joint_count"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("1000000"), std::string::npos) << s.message();
}

TEST_F(CharacterPackLimits, FuzzyHeaderCountsThatDisagreeWithTheMeshAreRefused) {
  // FZHD: bone, sample, vertex, triangle counts (u32 each) first.
  Status s = load(repack("FZHD", [](auto& p) { put_u32(p, 12, 0xffffffffu); }));
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.field(), "FZHD.triangle_count") << s.message();
  s = load(repack("FZHD", [](auto& p) { put_u32(p, 8, 0xffffffffu); }));
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.field(), "FZHD.vertex_count") << s.message();
}

// --- the bake ---------------------------------------------------------------------

TEST(BakeLimits, AMillionBoneSkeletonIsRefusedBeforeAllocating) {
  const auto& m = testing_support::idle_mannequin();
  rt::FuzzyBakeInput input;
  input.mesh = &m.model.mesh;
  input.bone_count = 1000000;
  const std::vector<Affine3> one(1);
  input.samples = one;
  JobSystem jobs(1);
  const auto bake = rt::bake_fuzzy_character(input, rt::FuzzyBakeOptions{}, jobs);
  ASSERT_FALSE(bake.ok());
  EXPECT_EQ(bake.status().code(), ErrorCode::kLimitExceeded);
  EXPECT_EQ(bake.status().field(), "bone_count");
}

TEST(BakeLimits, APoseSpaceBeyondTheMemoryBoundIsRefusedWhileSampling) {
  const character::Model model = content::make_mannequin().value();
  character::BakeRequest request;
  request.pose_space.mode = anim::PoseSpaceMode::kArbitrary;
  request.pose_space.samples = anim::kMaxPoseSamples;
  request.fuzzy.memory_budget_bytes = std::size_t{1} << 20;
  request.max_memory_bytes = request.fuzzy.memory_budget_bytes + (std::size_t{2} << 20);
  JobSystem jobs(1);
  const auto bake = character::bake_in_memory(model, request, jobs);
  ASSERT_FALSE(bake.ok());
  EXPECT_EQ(bake.status().code(), ErrorCode::kLimitExceeded) << bake.status().message();
  EXPECT_EQ(bake.status().field(), "pose_space");
  EXPECT_NE(bake.status().message().find("1 MiB"), std::string::npos) << bake.status().message();
  // No room at all beside the box budget: a clear argument error.
  request.max_memory_bytes = request.fuzzy.memory_budget_bytes;
  const auto none = character::bake_in_memory(model, request, jobs);
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.status().field(), "max_memory_bytes");
}

// The reported peak counts the samples, their inverses and the vertex boxes
// (checked against the sizes computed here), and stays within the bound.
TEST(BakeLimits, TheBakeReportsItsPeakMemory) {
  const character::Model model = content::make_mannequin().value();
  character::BakeRequest request;
  request.pose_space.mode = anim::PoseSpaceMode::kClip;
  request.pose_space.clips = {"walk"};
  request.pose_space.samples = 0;
  request.fuzzy.memory_budget_bytes = std::size_t{256} << 10;  // forces bone chunks
  JobSystem jobs(2);
  const auto bake = character::bake_in_memory(model, request, jobs);
  ASSERT_TRUE(bake.ok()) << bake.status().message();
  const std::size_t bones = model.skeleton.joint_count();
  const std::size_t samples = bake->fuzzy.stats.sample_count;
  const std::size_t matrices = samples * bones * sizeof(Affine3);
  EXPECT_GE(bake->memory.pose_samples, matrices);
  EXPECT_LT(bake->memory.pose_samples, 2 * matrices + 4096) << "vector growth at most doubles";
  const std::size_t chunk_bones = std::clamp<std::size_t>(
      request.fuzzy.memory_budget_bytes / (model.mesh.vertex_count() * sizeof(Aabb)), 1, bones);

  EXPECT_LT(chunk_bones, bones) << "the budget should force bone chunks";
  EXPECT_GE(bake->memory.fuzzy_peak, matrices + chunk_bones * model.mesh.vertex_count() * sizeof(Aabb));
  EXPECT_LT(bake->memory.peak(), request.max_memory_bytes);
}

TEST(BakeLimits, SinewEditorBakePrintsTheBakeMemory) {
  testing_support::TempDir dir;
  const character::Model model = content::make_mannequin().value();
  character::PackContents contents;
  contents.model = &model;
  const std::string model_pack = dir.file("mannequin.pack");
  ASSERT_TRUE(character::write_pack(model_pack, contents).ok());
  std::ostringstream out, err;
  const int code = editor::run_bake({model_pack, "-o", dir.file("baked.pack"), "--pose-space", "clip:wave",
                                     "--samples", "8", "--threads", "2"},
                                    out, err);
  ASSERT_EQ(code, 0) << err.str();
  EXPECT_NE(out.str().find("bake memory: peak "), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("process peak RSS"), std::string::npos) << out.str();

  // Too little memory allowed for the pose space asked for: a clear refusal.
  std::ostringstream out2, err2;
  const int refused = editor::run_bake({model_pack, "-o", dir.file("refused.pack"), "--pose-space", "arbitrary",
                                        "--samples", "100000", "--max-memory-mib", "4", "--threads", "1"},
                                       out2, err2);
  EXPECT_NE(refused, 0);
  EXPECT_NE(err2.str().find("pose_space"), std::string::npos) << err2.str();
  EXPECT_FALSE(std::filesystem::exists(dir.file("refused.pack")));
}

}  // namespace
}  // namespace sinew
