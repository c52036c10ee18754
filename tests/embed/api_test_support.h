// Shared by the public-API tests: the mannequin baked and written as a
// pack once per test binary, and the internal renderer as the reference
// the API's pass must reproduce.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "character/pack.h"
#include "raytrace/camera/camera.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "runtime/jobs/job_system.h"
#include "sinew/sinew.h"
#include "tests/support/aov_frame.h"
#include "tests/support/idle_mannequin.h"

namespace sinew::testing_support {

// A baked model as a pack file in the temporary folder, removed when the
// object is (a static one: when the process exits; ctest runs each test in
// a process of its own, so a file left behind per process filled the
// folder).
class TemporaryPackFile {
 public:
  TemporaryPackFile(const BakedModel& baked, const std::string& stem) {
    character::PackContents contents;
    contents.model = &baked.model;
    contents.fuzzy = &baked.bake.fuzzy;
    contents.pose_space.desc.mode = anim::PoseSpaceMode::kClip;
    contents.pose_space.desc.clips = {"idle"};
    contents.provenance.source_name = stem;
    contents.provenance.tool_version = "api test";
    path_ = (std::filesystem::temp_directory_path() /
             ("sinew_api_test_" + stem + "_" + std::to_string(::getpid()) + ".pack"))
                .string();
    EXPECT_TRUE(character::write_pack(path_, contents).ok());
  }
  ~TemporaryPackFile() {
    std::error_code ignored;
    std::filesystem::remove(path_, ignored);
  }
  TemporaryPackFile(const TemporaryPackFile&) = delete;
  TemporaryPackFile& operator=(const TemporaryPackFile&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// The idle-baked mannequin as a pack file, written once per test process.
inline const std::string& mannequin_pack_path() {
  static const TemporaryPackFile pack(idle_mannequin(), "mannequin");
  return pack.path();
}

// The mannequin pack through the public API.
inline api::Character load_mannequin() {
  auto character = api::Character::load(mannequin_pack_path());
  EXPECT_TRUE(character.ok()) << character.error().message;
  return std::move(character).value();
}

// Every output of one frame, packed rows, also as the API's PassOutputs.
struct Frame : AovFrame {
  using AovFrame::AovFrame;
  api::PassOutputs outputs() {
    api::PassOutputs o;
    o.color_rgba8 = {rgba8.data(), 0};
    o.color_rgba32f = {rgba32f.data(), 0};
    o.depth = {depth.data(), 0};
    o.normal = {normal.data(), 0};
    o.instance_id = {instance_id.data(), 0};
    o.triangle_id = {triangle_id.data(), 0};
    o.uv = {uv.data(), 0};
    o.barycentrics = {barycentric.data(), 0};
    o.material_id = {material_id.data(), 0};
    return o;
  }
};

inline constexpr api::OutputMask kEveryOutput =
    api::Output::kColorRgba8 | api::Output::kColorRgba32f | api::Output::kDepth | api::Output::kNormal |
    api::Output::kInstanceId | api::Output::kTriangleId | api::Output::kUv | api::Output::kBarycentrics |
    api::Output::kMaterialId;

// The camera and light the API tests use, in both vocabularies.
inline api::Camera test_camera() { return {{0.4f, 1.1f, 3.2f}, {0.0f, 0.9f, 0.0f}, {0.0f, 1.0f, 0.0f}, 45.0f}; }
inline rt::CameraDesc test_camera_internal() {
  const api::Camera c = test_camera();
  return {{c.eye.x, c.eye.y, c.eye.z}, {c.target.x, c.target.y, c.target.z}, {c.up.x, c.up.y, c.up.z}, c.fovy_degrees};
}
inline api::Light test_light() {
  api::Light l;
  l.position = {2.0f, 4.0f, 3.0f};
  return l;
}

// The reference: the internal Scene and Renderer over the same baked data.
inline Frame render_internal(const character::Pack& pack, const std::vector<std::vector<Affine3>>& poses,
                             int width, int height, bool shadows = true) {
  Frame frame(width, height);
  rt::Scene scene;
  const auto character = scene.add_character(pack.model().mesh, pack.fuzzy());
  EXPECT_TRUE(character.ok());
  for (const auto& pose : poses) {
    const auto id = scene.add_instance(*character);
    EXPECT_TRUE(id.ok());
    EXPECT_TRUE(scene.set_bones(*id, pose).ok());
  }
  JobSystem jobs(2);
  EXPECT_TRUE(scene.prepare_frame({}, jobs).ok());
  rt::RenderSettings settings;
  settings.shadows = shadows;
  settings.light.position = Vec3(2.0f, 4.0f, 3.0f);
  const auto camera = rt::PinholeCamera::create(test_camera_internal(), width, height);
  EXPECT_TRUE(camera.ok());
  rt::Renderer renderer;
  EXPECT_TRUE(renderer.render(scene, *camera, settings, frame.buffers(), jobs).ok());
  return frame;
}

}  // namespace sinew::testing_support
