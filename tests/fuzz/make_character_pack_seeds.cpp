// Writes the seed corpus for sinew_fuzz_character_pack: small, real
// character packs that show the fuzzer every section the loader knows. The
// committed files in tests/fuzz/corpus/character_pack/ come from this
// program; rerun it when the format changes:
//
//     sinew_make_character_pack_seeds tests/fuzz/corpus/character_pack
//
// * mannequin_baked.pack: the procedural mannequin (detail 1, 3,328
//   triangles, five clips, joint limits) baked over 8 arbitrary poses: every
//   section, fuzzy trees included.
// * mannequin_model.pack: the same model alone (no fuzzy sections, no limits).
// * two_bone_baked.pack / two_bone_model.pack: a 2-bone, 36-triangle tube
//   with one bending clip, baked over the clip's key times; small enough that
//   the fuzzer mutates mostly structure rather than vertex data.
// * The baked seeds hold kd-trees (FNOD); mannequin_baked_bvh.pack and
//   two_bone_baked_bvh.pack the same bakes with BVH bone trees of at most 4
//   triangles a leaf (FBVN, FITM version 3), the bake's default structure.
//
// Every seed must load (a seed that does not would only teach the fuzzer a
// dead end) and stay under 1 MB. character::Provenance is fixed so the bytes are
// reproducible.
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "character/bake.h"
#include "character/pack.h"
#include "content/mannequin/mannequin.h"
#include "runtime/jobs/job_system.h"

namespace {

using namespace sinew;

constexpr std::size_t kMaxSeedBytes = std::size_t{1} << 20;

bool report(const Status& status) {
  if (!status.ok()) std::fprintf(stderr, "%s\n", status.message().c_str());
  return status.ok();
}

bool emit(const std::string& dir, const std::string& name, const character::PackContents& contents) {
  const std::string path = dir + "/" + name;
  if (!report(character::write_pack(path, contents))) return false;
  auto pack = character::Pack::open(path);
  if (!pack.ok()) return report(pack.status());
  const std::size_t bytes = pack->reader().bytes().size();
  std::printf("%s: %zu triangles, %zu clips, %s, %zu bytes\n", path.c_str(),
              pack->model().mesh.triangle_count(), pack->model().clips.size(),
              pack->has_fuzzy() ? "baked" : "model only", bytes);
  if (bytes > kMaxSeedBytes) {
    std::fprintf(stderr, "%s: %zu bytes, over the %zu-byte seed limit\n", path.c_str(), bytes, kMaxSeedBytes);
    return false;
  }
  return true;
}

character::PackContents contents_for(const character::Model& model, const std::string& source) {
  character::PackContents contents;
  contents.model = &model;
  contents.provenance.source_name = source;
  contents.provenance.tool_version = "sinew_make_character_pack_seeds";
  contents.provenance.bake_unix_time = 0;
  return contents;
}

// A square tube along +Y from 0 to 2: rings of 4 vertices at y = 0, 0.5, ...,
// 2, bone 0 ("root") below y = 1 and bone 1 ("tip") above, blended over the
// middle ring. The clip bends the tip 60 degrees about Z and back.
Expected<character::Model> make_two_bone() {
  character::Model model;
  model.source = "two_bone";

  anim::RawSkeleton raw;
  raw.joints.resize(2);
  raw.joints[0].name = "root";
  raw.joints[1].name = "tip";
  raw.joints[1].parent = 0;
  raw.joints[1].rest.translation = Vec3(0.0f, 1.0f, 0.0f);
  raw.joints[1].inverse_bind = Affine3::translation(Vec3(0.0f, -1.0f, 0.0f));
  SINEW_ASSIGN_OR_RETURN(model.skeleton, anim::Skeleton::build(raw, "two_bone"));

  constexpr int kRings = 5;
  constexpr int kSides = 4;
  SkinnedMesh& mesh = model.mesh;
  for (int r = 0; r < kRings; ++r) {
    const float y = 0.5f * static_cast<float>(r);
    const float tip_weight = r < 2 ? 0.0f : (r == 2 ? 0.5f : 1.0f);
    for (int s = 0; s < kSides; ++s) {
      const float angle = static_cast<float>(s) * (std::numbers::pi_v<float> / 2.0f);
      const Vec3 out(std::cos(angle), 0.0f, std::sin(angle));
      mesh.positions.push_back(Vec3(0.2f * out.x, y, 0.2f * out.z));
      mesh.normals.push_back(out);
      mesh.uvs.push_back(Vec2(static_cast<float>(s) / kSides, y / 2.0f));
      std::array<std::uint16_t, kMaxInfluences> joints{};
      std::array<float, kMaxInfluences> weights{};
      joints[0] = 0;
      joints[1] = 1;
      weights[0] = 1.0f - tip_weight;
      weights[1] = tip_weight;
      mesh.joints.push_back(joints);
      mesh.weights.push_back(weights);
    }
  }
  for (int r = 0; r + 1 < kRings; ++r) {
    for (int s = 0; s < kSides; ++s) {
      const auto a = static_cast<std::uint32_t>(r * kSides + s);
      const auto b = static_cast<std::uint32_t>(r * kSides + (s + 1) % kSides);
      const auto c = a + kSides;
      const auto d = b + kSides;
      mesh.triangles.push_back({a, c, b});
      mesh.triangles.push_back({b, c, d});
      mesh.triangle_material.push_back(static_cast<std::uint32_t>(r % 2));
      mesh.triangle_material.push_back(static_cast<std::uint32_t>(r % 2));
    }
  }
  // Caps, so the tube is closed: a fan over each end ring.
  for (int s = 1; s + 1 < kSides; ++s) {
    const auto top = static_cast<std::uint32_t>((kRings - 1) * kSides);
    mesh.triangles.push_back({0, static_cast<std::uint32_t>(s), static_cast<std::uint32_t>(s + 1)});
    mesh.triangles.push_back({top, top + static_cast<std::uint32_t>(s + 1), top + static_cast<std::uint32_t>(s)});
    mesh.triangle_material.push_back(0);
    mesh.triangle_material.push_back(1);
  }
  mesh.material_colors = {Vec3(0.8f, 0.3f, 0.2f), Vec3(0.2f, 0.4f, 0.8f)};
  model.material_names = {"red", "blue"};

  anim::RawClip clip;
  clip.name = "bend";
  anim::JointTracks tip;
  tip.joint = 1;
  const Vec3 z(0.0f, 0.0f, 1.0f);
  tip.rotation.times = {0.0f, 0.5f, 1.0f};
  tip.rotation.values = {Quat(1.0f, 0.0f, 0.0f, 0.0f), glm::angleAxis(std::numbers::pi_v<float> / 3.0f, z),
                         Quat(1.0f, 0.0f, 0.0f, 0.0f)};
  clip.tracks.push_back(tip);
  SINEW_ASSIGN_OR_RETURN(anim::Clip built, anim::Clip::build(std::move(clip), model.skeleton, "two_bone"));
  model.clips.push_back(std::move(built));
  return model;
}

struct Baked {
  rt::FuzzyCharacterData fuzzy;
  character::PoseSpaceRecord pose_space;
};

Expected<Baked> bake(const character::Model& model, const anim::PoseSpaceDesc& space,
                     std::span<const anim::JointLimit> limits, rt::BoneTreeKind trees, JobSystem& jobs) {
  character::BakeRequest request;
  request.pose_space = space;
  request.fuzzy.bone_trees = trees;
  request.fuzzy.bvh.max_leaf_items = 4;
  request.limits.assign(limits.begin(), limits.end());
  request.fuzzy.padding = 0.01f;
  SINEW_ASSIGN_OR_RETURN(character::InMemoryBake baked, character::bake_in_memory(model, request, jobs));
  Baked out;
  out.fuzzy = std::move(baked.fuzzy);
  out.pose_space.desc = space;
  out.pose_space.padding = request.fuzzy.padding;
  out.pose_space.candidates = request.fuzzy.candidates;
  return out;
}

bool write_mannequin(const std::string& dir, JobSystem& jobs) {
  auto mannequin = content::make_mannequin();
  if (!mannequin.ok()) return report(mannequin.status());
  const anim::JointLimits limits = content::mannequin_joint_limits(mannequin->skeleton);

  anim::PoseSpaceDesc space;
  space.mode = anim::PoseSpaceMode::kArbitrary;
  space.samples = 8;
  space.seed = 7;
  auto baked = bake(*mannequin, space, limits, rt::BoneTreeKind::kKdTree, jobs);
  if (!baked.ok()) return report(baked.status());
  auto bvh = bake(*mannequin, space, limits, rt::BoneTreeKind::kBvh, jobs);
  if (!bvh.ok()) return report(bvh.status());

  character::PackContents contents = contents_for(*mannequin, "mannequin");
  bool ok = emit(dir, "mannequin_model.pack", contents);
  contents.limits = limits;
  contents.fuzzy = &baked->fuzzy;
  contents.pose_space = baked->pose_space;
  ok = emit(dir, "mannequin_baked.pack", contents) && ok;
  contents.fuzzy = &bvh->fuzzy;
  return emit(dir, "mannequin_baked_bvh.pack", contents) && ok;
}

bool write_two_bone(const std::string& dir, JobSystem& jobs) {
  auto model = make_two_bone();
  if (!model.ok()) return report(model.status());

  anim::PoseSpaceDesc space;
  space.mode = anim::PoseSpaceMode::kClips;
  space.samples = 0;  // every key time
  auto baked = bake(*model, space, {}, rt::BoneTreeKind::kKdTree, jobs);
  if (!baked.ok()) return report(baked.status());
  auto bvh = bake(*model, space, {}, rt::BoneTreeKind::kBvh, jobs);
  if (!bvh.ok()) return report(bvh.status());

  character::PackContents contents = contents_for(*model, "two_bone");
  bool ok = emit(dir, "two_bone_model.pack", contents);
  contents.fuzzy = &baked->fuzzy;
  contents.pose_space = baked->pose_space;
  ok = emit(dir, "two_bone_baked.pack", contents) && ok;
  contents.fuzzy = &bvh->fuzzy;
  return emit(dir, "two_bone_baked_bvh.pack", contents) && ok;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s <output folder>\n", argv[0]);
    return 2;
  }
  const std::string dir = argv[1];
  JobSystem jobs(1);  // one thread: the bake, and so the bytes, are deterministic
  bool ok = write_mannequin(dir, jobs);
  ok = write_two_bone(dir, jobs) && ok;
  return ok ? 0 : 1;
}
