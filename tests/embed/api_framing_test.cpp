// Character::framing against independent references: the rest bounds
// against every vertex skinned by hand with the bone transforms the API's
// own mixer reports at rest (World::bone_transform), the camera against a
// hand projection of the bounds' corners, and CesiumMan, whose stored mesh
// is Z-up while its posed skeleton stands along +Y.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

#include "character/bake.h"
#include "character/pack.h"
#include "editor/import/model_loader.h"
#include "runtime/pack/pack_reader.h"
#include "runtime/pack/pack_writer.h"
#include "tests/embed/api_test_support.h"

namespace sinew::testing_support {
namespace {

Vec3 v3(const api::Float3& f) { return {f.x, f.y, f.z}; }

std::vector<std::byte> read_file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  const std::vector<char> chars((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::byte> bytes(chars.size());
  std::memcpy(bytes.data(), chars.data(), chars.size());
  return bytes;
}

// p' = m p, m a row-major 3x4.
Vec3 apply(const api::Matrix3x4& m, const Vec3& p) {
  Vec3 out;
  for (int r = 0; r < 3; ++r) out[r] = m.m[r][0] * p.x + m.m[r][1] * p.y + m.m[r][2] * p.z + m.m[r][3];
  return out;
}

// The bounds of every vertex, skinned by hand (linear blend) with the
// bone transforms of a fresh mixer-driven instance (nothing played: the
// rest pose) times the inverse bind matrices.
Aabb rest_bounds_by_hand(const api::Character& c, const character::Model& model) {
  auto world = api::World::create();
  EXPECT_TRUE(world.ok());
  auto instance = world->add_instance(c);
  EXPECT_TRUE(instance.ok());
  std::vector<api::Matrix3x4> bones;
  for (std::size_t b = 0; b < c.bone_count(); ++b) bones.push_back(world->bone_transform(*instance, b).value());
  Aabb box;
  const SkinnedMesh& mesh = model.mesh;
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    Vec3 p(0.0f);
    for (int k = 0; k < kMaxInfluences; ++k) {
      const float weight = mesh.weights[v][k];
      if (weight == 0.0f) continue;
      const std::uint16_t bone = mesh.joints[v][k];
      const Affine3& inverse_bind = model.skeleton.inverse_bind()[bone];
      p += weight * apply(bones[bone], inverse_bind.transform_point(mesh.positions[v]));
    }
    box.extend(p);
  }
  return box;
}

void expect_bounds_near(const api::Character::Bounds& got, const Aabb& want) {
  const float tolerance = 1e-4f * std::max(1.0f, glm::length(want.extent()));
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR((&got.min.x)[a], want.lower[a], tolerance) << "axis " << a;
    EXPECT_NEAR((&got.max.x)[a], want.upper[a], tolerance) << "axis " << a;
  }
}

// Every corner of the bounds lies inside the camera's view of an image
// `aspect` times as wide as high, the up axis up, looking from the front.
void expect_camera_frames(const api::Character::Framing& f, float aspect) {
  const Vec3 eye = v3(f.camera.eye), target = v3(f.camera.target), up = v3(f.camera.up);
  Vec3 axis_up(0.0f);
  axis_up[f.up_axis] = 1.0f;
  EXPECT_EQ(up, axis_up);
  const Vec3 forward = glm::normalize(target - eye);
  const Vec3 right = glm::normalize(glm::cross(forward, up));
  const Vec3 true_up = glm::cross(right, forward);
  const float tan_y = std::tan(glm::radians(0.5f * f.camera.fovy_degrees));
  const float tan_x = tan_y * aspect;
  const Vec3 lo = v3(f.rest_bounds.min), hi = v3(f.rest_bounds.max);
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3 p((corner & 1) ? hi.x : lo.x, (corner & 2) ? hi.y : lo.y, (corner & 4) ? hi.z : lo.z);
    const Vec3 d = p - eye;
    const float depth = glm::dot(d, forward);
    ASSERT_GT(depth, 0.0f) << "corner " << corner << " behind the camera";
    EXPECT_LT(std::abs(glm::dot(d, right)) / depth, tan_x) << "corner " << corner << " left or right of the view";
    EXPECT_LT(std::abs(glm::dot(d, true_up)) / depth, tan_y) << "corner " << corner << " above or below the view";
  }
  // From the front (+Z for Y-up, -Y for Z-up) and a little above.
  const Vec3 from = eye - target;
  if (f.up_axis == 1) {
    EXPECT_GT(from.z, 0.0f);
  } else {
    EXPECT_LT(from.y, 0.0f);
  }
  EXPECT_GT(from[f.up_axis], 0.0f);
  EXPECT_LT(from[f.up_axis], std::abs(f.up_axis == 1 ? from.z : from.y));
  EXPECT_EQ(f.light.kind, api::Light::Kind::kPoint);
  EXPECT_GT(v3(f.light.position)[f.up_axis], hi[f.up_axis]) << "the light is above the character";
}

TEST(ApiCharacter, FramingIsTheRestPoseAsTheMixerPosesIt) {
  const api::Character c = load_mannequin();
  const character::Pack pack = character::Pack::open(mannequin_pack_path()).value();
  EXPECT_TRUE(pack.framing_stored()) << "write_pack records FRAM";
  const Aabb want = rest_bounds_by_hand(c, pack.model());
  for (const float aspect : {1.0f, 16.0f / 9.0f, 0.5f}) {
    const api::Character::Framing f = c.framing(aspect);
    expect_bounds_near(f.rest_bounds, want);
    // The mannequin stands along +Y, taller than deep.
    EXPECT_EQ(f.up_axis, 1);
    expect_camera_frames(f, aspect);
  }
  // A degenerate aspect is taken as a square image.
  const api::Character::Framing square = c.framing(1.0f);
  for (const float bad : {0.0f, -1.0f, std::numeric_limits<float>::quiet_NaN()}) {
    const api::Character::Framing f = c.framing(bad);
    EXPECT_EQ(v3(f.camera.eye), v3(square.camera.eye)) << bad;
  }
}

// A pack baked before FRAM existed: the same framing, computed on load.
TEST(ApiCharacter, APackWithoutTheFramingSectionGetsItComputed) {
  const auto bytes = read_file_bytes(mannequin_pack_path());
  auto reader = PackReader::from_bytes(bytes, "with");
  ASSERT_TRUE(reader.ok());
  PackWriter w;
  for (const SectionInfo& s : reader->sections()) {
    if (s.id == make_section_id("FRAM")) continue;
    ASSERT_TRUE(w.add_section(s.id, s.version, reader->section_bytes(s)).ok());
  }
  const auto old = w.serialize().value();
  ASSERT_LT(old.size(), bytes.size());
  const character::Pack loaded = character::Pack::from_bytes(old, "old.pack").value();
  EXPECT_FALSE(loaded.framing_stored());
  auto old_character = api::Character::from_memory(old, "old.pack");
  ASSERT_TRUE(old_character.ok()) << old_character.error().message;
  const api::Character c = load_mannequin();
  const api::Character::Framing a = c.framing(), b = old_character->framing();
  EXPECT_EQ(a.up_axis, b.up_axis);
  EXPECT_EQ(v3(a.rest_bounds.min), v3(b.rest_bounds.min));
  EXPECT_EQ(v3(a.rest_bounds.max), v3(b.rest_bounds.max));
  EXPECT_EQ(v3(a.camera.eye), v3(b.camera.eye));
  EXPECT_EQ(v3(a.light.position), v3(b.light.position));
}

// CesiumMan's mesh is stored Z-up; its skeleton's rest pose, which the
// mixer poses from, stands it along +Y. The framing follows the pose.
TEST(ApiCharacter, CesiumManIsFramedAsPosedNotAsStored) {
  const std::string model_path = SINEW_SHARED_DIR "/content/gltf/CesiumMan/CesiumMan.glb";
  ASSERT_TRUE(std::filesystem::exists(model_path)) << model_path << " is not there";
  auto model = editor::load_model(model_path);
  ASSERT_TRUE(model.ok()) << model.status().message();
  character::BakeRequest request;
  request.pose_space.mode = anim::PoseSpaceMode::kClips;
  request.pose_space.samples = 3;
  request.pose_space.every_frame_30hz = false;
  JobSystem jobs(2);
  auto bake = character::bake_in_memory(*model, request, jobs);
  ASSERT_TRUE(bake.ok()) << bake.status().message();
  character::PackContents contents;
  contents.model = &*model;
  contents.fuzzy = &bake->fuzzy;
  contents.pose_space.desc = request.pose_space;
  const auto bytes = character::serialize_pack(contents).value();
  auto c = api::Character::from_memory(bytes, "cesium.pack");
  ASSERT_TRUE(c.ok()) << c.error().message;

  const api::Character::Bounds stored = c->bind_bounds();
  // As stored it is tallest along Z (1.51 against its arms' 1.14 along Y)...
  const Vec3 stored_extent = v3(stored.max) - v3(stored.min);
  EXPECT_GT(stored_extent.z, 1.2f * stored_extent.y) << "the mesh as stored is Z-up";
  EXPECT_GT(stored_extent.z, 1.2f * stored_extent.x);
  const api::Character::Framing f = c->framing();
  EXPECT_EQ(f.up_axis, 1);
  const Aabb want = rest_bounds_by_hand(*c, *model);
  expect_bounds_near(f.rest_bounds, want);
  // ...and posed at rest tallest along Y, its arms along X.
  EXPECT_GT(want.extent().y, 1.2f * want.extent().x) << "the posed character is Y-up";
  EXPECT_GT(want.extent().y, 1.2f * want.extent().z);
  expect_camera_frames(f, 1.0f);
}

}  // namespace
}  // namespace sinew::testing_support
