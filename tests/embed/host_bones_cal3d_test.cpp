// A host with its own animation system: the Cal3D library animates Cally,
// the host hands Sinew one skinning matrix per bone (found by name), and
// the image equals the one Sinew's own mixer renders at the same pose.
#include <gtest/gtest.h>

#include <cal3d/cal3d.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "character/bake.h"
#include "character/framing.h"
#include "character/pack.h"
#include "editor/import/cal3d_importer.h"
#include "runtime/jobs/job_system.h"
#include "sinew/sinew.h"
#include "tests/support/cal3d_support.h"
#include "tests/support/temp_dir.h"

namespace sinew {
namespace {

std::string cally_file(const std::string& file) { return std::string(SINEW_SHARED_DIR) + "/content/cal3d/cally/" + file; }

// Cal3D's model of Cally, walking.
struct CalCally {
  CalCoreModel core{"host"};
  std::vector<int> mesh_ids;
  std::unique_ptr<CalModel> model;
  ~CalCally() {
    model.reset();
    testing_support::free_cal3d_animation_tracks(core);
  }
};

// Cal3D's skinning transform of a bone (what its physique applies to a
// bind-pose vertex: v' = R v + t) as the API's row-major 3x4.
api::Matrix3x4 skinning_of(CalBone& bone) {
  const CalMatrix& r = bone.getTransformMatrix();
  const CalVector& t = bone.getTranslationBoneSpace();
  api::Matrix3x4 m;
  const float rows[3][4] = {{r.dxdx, r.dxdy, r.dxdz, t.x}, {r.dydx, r.dydy, r.dydz, t.y}, {r.dzdx, r.dzdy, r.dzdz, t.z}};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 4; ++j) m.m[i][j] = rows[i][j];
  }
  return m;
}

struct Image {
  std::vector<std::uint8_t> rgba8;
  std::vector<std::uint32_t> triangle_id;
};

Image render(api::RayTracePass& pass, api::World& world, const api::PassInputs& inputs, int w, int h) {
  Image image{std::vector<std::uint8_t>(4 * static_cast<std::size_t>(w * h)),
              std::vector<std::uint32_t>(static_cast<std::size_t>(w * h))};
  api::PassOutputs out;
  out.color_rgba8 = {image.rgba8.data(), 0};
  out.triangle_id = {image.triangle_id.data(), 0};
  const auto stats = pass.execute(world, inputs, out);
  EXPECT_TRUE(stats.ok()) << stats.error().message;
  return image;
}

TEST(HostBones, Cal3dMatricesRenderLikeTheMixerAtTheSamePose) {
  const std::string cfg_path = cally_file("cally.cfg");
  if (!std::filesystem::exists(cfg_path)) GTEST_SKIP() << "shared content missing: " << cfg_path;

  // The pack, baked over Cally's clips.
  auto model = editor::import_cal3d(cfg_path);
  ASSERT_TRUE(model.ok()) << model.status().message();
  JobSystem jobs(2);
  character::BakeRequest request;
  auto bake = character::bake_in_memory(*model, request, jobs);
  ASSERT_TRUE(bake.ok()) << bake.status().message();
  testing_support::TempDir dir;
  character::PackContents contents;
  contents.model = &*model;
  contents.fuzzy = &bake->fuzzy;
  contents.pose_space.desc = request.pose_space;
  ASSERT_TRUE(character::write_pack(dir.file("cally.pack"), contents).ok());
  auto character = api::Character::load(dir.file("cally.pack"));
  ASSERT_TRUE(character.ok()) << character.error().message;

  // Cal3D animates its own Cally: the walk cycle at 0.5 s.
  std::ifstream in(cfg_path);
  std::stringstream text;
  text << in.rdbuf();
  auto cfg = editor::parse_cal3d_config(text.str(), "cally.cfg");
  ASSERT_TRUE(cfg.ok());
  ASSERT_EQ(cfg->scale, 1.0f);
  CalCally cal;
  ASSERT_TRUE(cal.core.loadCoreSkeleton(cally_file(cfg->skeleton)));
  for (const std::string& mesh : cfg->meshes) cal.mesh_ids.push_back(cal.core.loadCoreMesh(cally_file(mesh)));
  const int walk = cal.core.loadCoreAnimation(cally_file("cally_walk.caf"));
  ASSERT_GE(walk, 0);
  cal.model = std::make_unique<CalModel>(&cal.core);
  ASSERT_TRUE(cal.model->getMixer()->blendCycle(walk, 1.0f, 0.0f));
  cal.model->getMixer()->updateAnimation(0.0f);  // starts the clock, as World::play_cycle does
  cal.model->getMixer()->updateAnimation(0.5f);
  cal.model->getMixer()->updateSkeleton();

  // The host's matrices, in the pack's bone order, matched by name.
  std::vector<api::Matrix3x4> host(character->bone_count());
  for (std::size_t b = 0; b < host.size(); ++b) {
    const int id = cal.core.getCoreSkeleton()->getCoreBoneId(std::string(character->bone_name(b)));
    ASSERT_GE(id, 0) << character->bone_name(b);
    host[b] = skinning_of(*cal.model->getSkeleton()->getBone(id));
  }

  auto hosted_world = api::World::create();
  ASSERT_TRUE(hosted_world.ok());
  api::InstanceDesc host_driven;
  host_driven.driver = api::Driver::kHost;
  const auto hosted = hosted_world->add_instance(*character, host_driven);
  ASSERT_TRUE(hosted.ok());
  ASSERT_TRUE(hosted_world->set_bone_matrices(*hosted, host).ok());

  auto mixer_world = api::World::create();
  ASSERT_TRUE(mixer_world.ok());
  const auto mixed = mixer_world->add_instance(*character);
  ASSERT_TRUE(mixed.ok());
  ASSERT_TRUE(mixer_world->play_cycle(*mixed, "walk", 1.0f, 0.0f).ok());
  ASSERT_TRUE(mixer_world->advance(0.5f).ok());

  // Both framed like sinew-editor render frames Cally.
  constexpr int kSize = 256;
  const Aabb rest = character::rest_bounds(*model);
  const int up = character::up_axis_of(rest);
  const rt::CameraDesc c = character::default_camera(rest, up, kSize, kSize);
  const Vec3 l = character::default_light(rest, up);
  api::PassInputs inputs;
  inputs.camera = {{c.eye.x, c.eye.y, c.eye.z}, {c.target.x, c.target.y, c.target.z}, {c.up.x, c.up.y, c.up.z},
                   c.fovy_degrees};
  api::Light light;
  light.position = {l.x, l.y, l.z};
  inputs.lights = std::span<const api::Light>(&light, 1);
  api::PassDesc desc;
  desc.width = kSize;
  desc.height = kSize;
  desc.outputs = api::Output::kColorRgba8 | api::Output::kTriangleId;
  auto pass = api::RayTracePass::create(desc);
  ASSERT_TRUE(pass.ok());
  const Image a = render(*pass, *hosted_world, inputs, kSize, kSize);
  const Image b = render(*pass, *mixer_world, inputs, kSize, kSize);

  // Cal3D and our mixer agree to ~1e-6 of the model's size (the mixer
  // oracle), so a few silhouette pixels may flip; nothing more.
  std::size_t hits = 0, id_differs = 0, colour_differs = 0;
  for (std::size_t i = 0; i < a.triangle_id.size(); ++i) {
    hits += a.triangle_id[i] != api::kNoHit;
    id_differs += a.triangle_id[i] != b.triangle_id[i];
    for (std::size_t ch = 0; ch < 3; ++ch) {
      if (std::abs(int(a.rgba8[4 * i + ch]) - int(b.rgba8[4 * i + ch])) > 2) {
        ++colour_differs;
        break;
      }
    }
  }
  std::printf("[host bones] Cally walk 0.5 s: %zu hit pixels, %zu differ in triangle, %zu in colour (> 2/255)\n",
              hits, id_differs, colour_differs);
  EXPECT_GT(hits, 2500u);
  EXPECT_LE(id_differs, hits / 500);
  EXPECT_LE(colour_differs, hits / 500);
}

}  // namespace
}  // namespace sinew
