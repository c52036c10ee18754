// The editor window under Xvfb, in-process: what the window shows (read back
// from the back buffer) against an independent headless render, the
// overlays, bakes from the app, and run_gui's exit codes.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <thread>

#include "character/bake.h"
#include "character/framing.h"
#include "character/pack.h"
#include "content/mannequin/mannequin.h"
#include "editor/gui/editor_app.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "runtime/display/window.h"
#include "runtime/jobs/job_system.h"

namespace sinew::editor::gui {
namespace {

constexpr int kWindowWidth = 980;  // a 640x480 viewport beside the 340-pixel panel column
constexpr int kWindowHeight = 480;

struct Rgb {
  std::uint8_t r, g, b;
};

// The viewport region of a screenshot (top-left, 1:1 with the render).
Rgb shot_pixel(const Screenshot& shot, int x, int y) {
  const std::size_t i = 4 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(shot.width) +
                             static_cast<std::size_t>(x));
  return {shot.rgba[i], shot.rgba[i + 1], shot.rgba[i + 2]};
}

std::size_t count_color(const Screenshot& shot, int vw, int vh, const std::uint8_t (&c)[3]) {
  std::size_t n = 0;
  for (int y = 0; y < vh; ++y) {
    for (int x = 0; x < vw; ++x) {
      const Rgb p = shot_pixel(shot, x, y);
      n += p.r == c[0] && p.g == c[1] && p.b == c[2];
    }
  }
  return n;
}

class EditorGuiTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!Window::display_available()) return;
    GuiOptions options;
    options.width = kWindowWidth;
    options.height = kWindowHeight;
    auto app = EditorApp::create(options);
    ASSERT_TRUE(app.ok()) << app.status().message();
    app_ = std::move(*app).release();
    auto mannequin = content::make_mannequin();
    ASSERT_TRUE(mannequin.ok()) << mannequin.status().message();
    const Status loaded = app_->load(std::move(*mannequin));
    ASSERT_TRUE(loaded.ok()) << loaded.message();
    app_->set_playing(false);
    app_->set_capture(true);
  }
  static void TearDownTestSuite() {
    delete app_;
    app_ = nullptr;
  }
  void SetUp() override {
    // ctest runs this under xvfb-run: no display is a broken set-up, not a skip.
    ASSERT_TRUE(app_ != nullptr) << "no display or no window: run this test under xvfb-run";
    app_->set_overlay(Overlay::kNone);
  }

  // Poses, steps one frame and returns what the window showed.
  static Screenshot show(const std::string& clip, double seconds, Overlay overlay) {
    EXPECT_TRUE(app_->set_clip(clip).ok());
    EXPECT_TRUE(app_->set_time(seconds).ok());
    app_->set_overlay(overlay);
    auto stepped = app_->step();
    EXPECT_TRUE(stepped.ok() && *stepped);
    return app_->last_shown();
  }

  // The view's pose and camera rendered by a fresh scene over the same
  // mesh and trees, with `settings`: RGBA bytes, and the instance ids.
  static std::vector<std::uint8_t> headless_render(const rt::RenderSettings& settings,
                                                   std::vector<std::uint32_t>* instance_id = nullptr,
                                                   std::uint32_t* character_instance = nullptr) {
    const Viewport& view = app_->viewport();
    const int vw = view.width(), vh = view.height();
    rt::Scene scene;
    auto character = scene.add_character(app_->model()->mesh, app_->fuzzy());
    EXPECT_TRUE(character.ok());
    auto instance = scene.add_instance(*character);
    EXPECT_TRUE(instance.ok());
    EXPECT_TRUE(scene.add_static_mesh(character::ground_plane_for(*app_->model())).ok());
    EXPECT_TRUE(scene.set_bones(*instance, app_->skinning()).ok());
    JobSystem jobs(2);
    EXPECT_TRUE(scene.prepare_frame(rt::FrameOptions{}, jobs).ok());
    auto camera = rt::PinholeCamera::create(view.camera(), vw, vh);
    EXPECT_TRUE(camera.ok());
    const std::size_t pixels = static_cast<std::size_t>(vw) * static_cast<std::size_t>(vh);
    std::vector<std::uint8_t> color(4 * pixels);
    std::vector<std::uint32_t> ids(pixels);
    rt::FrameBuffers buffers;
    buffers.width = vw;
    buffers.height = vh;
    buffers.color_rgba8 = color;
    buffers.instance_id = ids;
    rt::Renderer renderer;
    EXPECT_TRUE(renderer.render(scene, *camera, settings, buffers, jobs).ok());
    if (instance_id != nullptr) *instance_id = std::move(ids);
    if (character_instance != nullptr) *character_instance = *instance;
    return color;
  }

  static void wait_for_bake() {
    for (int i = 0; i < 6000 && app_->bake_running(); ++i) {
      ASSERT_TRUE(app_->step().ok());
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    ASSERT_FALSE(app_->bake_running());
  }

  static EditorApp* app_;
};
EditorApp* EditorGuiTest::app_ = nullptr;

TEST_F(EditorGuiTest, WindowShowsTheCharacterExactlyAsAHeadlessRender) {
  const Screenshot shot = show("walk", 0.3, Overlay::kNone);
  const Viewport& view = app_->viewport();
  const int vw = view.width();
  const int vh = view.height();
  ASSERT_EQ(vw, 640);
  ASSERT_EQ(vh, 480);
  ASSERT_EQ(shot.width, kWindowWidth);
  ASSERT_EQ(shot.height, kWindowHeight);

  // Independent render: a fresh scene over the same mesh, trees, pose and camera.
  std::vector<std::uint32_t> instance_id;
  std::uint32_t instance = 0;
  const std::vector<std::uint8_t> color = headless_render(view.settings, &instance_id, &instance);
  const std::size_t pixels = static_cast<std::size_t>(vw) * static_cast<std::size_t>(vh);

  std::size_t mismatches = 0;
  std::size_t character_pixels = 0;
  std::size_t central_differs_from_background = 0;
  const Rgb background = shot_pixel(shot, 0, 0);  // the sky: the camera looks slightly down
  for (int y = 0; y < vh; ++y) {
    for (int x = 0; x < vw; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(vw) + static_cast<std::size_t>(x);
      const Rgb p = shot_pixel(shot, x, y);
      mismatches += p.r != color[4 * i] || p.g != color[4 * i + 1] || p.b != color[4 * i + 2];
      character_pixels += instance_id[i] == instance;
      const bool central = x > vw / 4 && x < 3 * vw / 4 && y > vh / 8 && y < 7 * vh / 8;
      central_differs_from_background += central && (p.r != background.r || p.g != background.g || p.b != background.b);
    }
  }
  EXPECT_EQ(mismatches, 0u);
  EXPECT_GT(character_pixels, pixels / 50);  // framed: a visible share of the view
  EXPECT_GT(central_differs_from_background, character_pixels / 2);
}

// The Lights panel's list is what the view shades with: three lights, one
// per colour channel, give exactly a headless render with those three, and
// differ from a render with the first alone.
TEST_F(EditorGuiTest, TheViewShadesWithEveryLightInItsList) {
  Viewport& view = app_->viewport();
  (void)show("idle", 0.5, Overlay::kNone);
  ASSERT_EQ(view.lights.size(), 1u);  // the default light of a framed model
  const std::vector<rt::Light> saved = view.lights;
  std::vector<rt::Light> lights(3);
  lights[0].position = saved[0].position;
  lights[0].color = Vec3(1.0f, 0.0f, 0.0f);
  lights[1].position = Vec3(-saved[0].position.x, saved[0].position.y, -saved[0].position.z);
  lights[1].color = Vec3(0.0f, 1.0f, 0.0f);
  lights[2].kind = rt::Light::Kind::kDirectional;
  lights[2].direction = Vec3(0.3f, 1.0f, -0.6f);
  lights[2].color = Vec3(0.0f, 0.0f, 1.0f);
  view.lights = lights;
  const Screenshot shot = show("idle", 0.5, Overlay::kNone);
  rt::RenderSettings settings = view.settings;
  settings.lights = lights;
  const std::vector<std::uint8_t> all = headless_render(settings);
  settings.lights = std::span<const rt::Light>(lights.data(), 1);
  const std::vector<std::uint8_t> first = headless_render(settings);
  view.lights = saved;
  const int vw = view.width(), vh = view.height();
  std::size_t mismatches = 0, differ_from_first = 0;
  for (int y = 0; y < vh; ++y) {
    for (int x = 0; x < vw; ++x) {
      const std::size_t i = 4 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(vw) + static_cast<std::size_t>(x));
      const Rgb p = shot_pixel(shot, x, y);
      mismatches += p.r != all[i] || p.g != all[i + 1] || p.b != all[i + 2];
      differ_from_first += all[i + 1] != first[i + 1] || all[i + 2] != first[i + 2];
    }
  }
  EXPECT_EQ(mismatches, 0u);
  EXPECT_GT(differ_from_first, static_cast<std::size_t>(vw * vh / 50));
}

// The Lights panel's soft lighting is what the view renders with: a sphere
// light and ambient occlusion give exactly a headless render with them and
// change the picture; a new model's occlusion reaches half its height; the
// Stats panel's figures count the shadow and occlusion rays.
TEST_F(EditorGuiTest, TheViewShadesWithItsSoftShadowsAndAmbientOcclusion) {
  Viewport& view = app_->viewport();
  (void)show("idle", 0.5, Overlay::kNone);
  ASSERT_EQ(view.lights.size(), 1u);
  EXPECT_EQ(view.lights[0].radius, 0.0f) << "a hard light by default";
  EXPECT_EQ(view.settings.ao_rays, 0) << "no ambient occlusion by default";
  EXPECT_FLOAT_EQ(view.settings.ao_radius, 0.5f * view.character_height());
  const EditorStats hard = app_->stats();
  EXPECT_GT(hard.shadow_rays, 0u);
  EXPECT_EQ(hard.ao_rays, 0u);
  const std::vector<rt::Light> saved = view.lights;
  rt::RenderSettings settings = view.settings;
  settings.lights = saved;
  const std::vector<std::uint8_t> hard_render = headless_render(settings);

  view.lights[0].radius = 0.3f * view.character_height();
  view.settings.shadow_samples = 4;
  view.settings.ao_rays = 4;
  const Screenshot shot = show("idle", 0.5, Overlay::kNone);
  const EditorStats soft = app_->stats();
  const std::vector<rt::Light> soft_lights = view.lights;
  settings = view.settings;
  settings.lights = soft_lights;
  const std::vector<std::uint8_t> soft_render = headless_render(settings);
  view.lights = saved;
  view.settings.ao_rays = 0;
  (void)show("idle", 0.5, Overlay::kNone);

  const int vw = view.width(), vh = view.height();
  std::size_t mismatches = 0, differ_from_hard = 0;
  for (int y = 0; y < vh; ++y) {
    for (int x = 0; x < vw; ++x) {
      const std::size_t i = 4 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(vw) + static_cast<std::size_t>(x));
      const Rgb p = shot_pixel(shot, x, y);
      mismatches += p.r != soft_render[i] || p.g != soft_render[i + 1] || p.b != soft_render[i + 2];
      differ_from_hard += soft_render[i] != hard_render[i] || soft_render[i + 1] != hard_render[i + 1] ||
                          soft_render[i + 2] != hard_render[i + 2];
    }
  }
  EXPECT_EQ(mismatches, 0u);
  EXPECT_GT(differ_from_hard, static_cast<std::size_t>(vw * vh / 100));
  EXPECT_GT(soft.shadow_rays, 3 * hard.shadow_rays) << "4 samples per lit hit";
  EXPECT_GT(soft.ao_rays, 0u);
  EXPECT_GE(soft.trace_ao_ms, 0.0);
  EXPECT_GE(soft.trace_shadow_ms, 0.0);
}

TEST_F(EditorGuiTest, BoxesOverlayDrawsTheBoneBoxWireframe) {
  ASSERT_TRUE(app_->set_bone("chest").ok());
  const Screenshot plain = show("idle", 0.5, Overlay::kNone);
  const Screenshot boxes = show("idle", 0.5, Overlay::kBoxes);
  const int vw = app_->viewport().width();
  const int vh = app_->viewport().height();
  EXPECT_EQ(count_color(plain, vw, vh, kRootBoxColor), 0u);
  EXPECT_EQ(count_color(plain, vw, vh, kLeafBoxColor), 0u);
  // The root box of a torso bone spans dozens of pixels per edge.
  EXPECT_GT(count_color(boxes, vw, vh, kRootBoxColor), 200u);
  EXPECT_GT(count_color(boxes, vw, vh, kLeafBoxColor), 200u);
  EXPECT_FALSE(app_->set_bone("no_such_bone").ok());
}

TEST_F(EditorGuiTest, HeatMapTintsTheCharacterAndNothingElse) {
  const Screenshot plain = show("idle", 0.5, Overlay::kNone);
  const Screenshot heat = show("idle", 0.5, Overlay::kHeat);
  const Viewport& view = app_->viewport();
  const auto ids = view.instance_ids();
  std::size_t character = 0, changed_character = 0, changed_other = 0;
  for (int y = 0; y < view.height(); ++y) {
    for (int x = 0; x < view.width(); ++x) {
      const Rgb a = shot_pixel(plain, x, y);
      const Rgb b = shot_pixel(heat, x, y);
      const bool changed = a.r != b.r || a.g != b.g || a.b != b.b;
      if (ids[static_cast<std::size_t>(y * view.width() + x)] == view.character_instance()) {
        ++character;
        changed_character += changed;
      } else {
        changed_other += changed;
      }
    }
  }
  ASSERT_GT(character, 1000u);
  EXPECT_GT(changed_character, character * 9 / 10);
  EXPECT_EQ(changed_other, 0u);
}

TEST_F(EditorGuiTest, EscapesShowRedOnlyForPosesOutsideThePoseSpace) {
  BakeSettings idle_only;
  idle_only.mode = anim::PoseSpaceMode::kClip;
  idle_only.clip = "idle";
  ASSERT_TRUE(app_->start_bake(idle_only).ok());
  wait_for_bake();
  ASSERT_NE(app_->message().find("bake done"), std::string::npos) << app_->message();
  const int vw = app_->viewport().width();
  const int vh = app_->viewport().height();

  const Screenshot inside = show("idle", 1.0, Overlay::kEscapes);
  EXPECT_EQ(app_->stats().escaped_triangles, 0u);
  EXPECT_EQ(count_color(inside, vw, vh, kEscapeColor), 0u);

  const Screenshot outside = show("kick", 0.4, Overlay::kEscapes);
  EXPECT_GT(app_->stats().escaped_triangles, 0u);
  const std::size_t red = count_color(outside, vw, vh, kEscapeColor);
  EXPECT_GT(red, 0u);
  EXPECT_EQ(red, app_->stats().escaped_pixels);
  const Screenshot plain = show("kick", 0.4, Overlay::kNone);
  EXPECT_EQ(count_color(plain, vw, vh, kEscapeColor), 0u);
}

TEST_F(EditorGuiTest, BakeFromTheAppChangesThePoseSamplesAndCancelKeepsThem) {
  (void)show("idle", 0.0, Overlay::kNone);
  BakeSettings arbitrary;
  arbitrary.mode = anim::PoseSpaceMode::kArbitrary;
  arbitrary.samples = 37;
  ASSERT_TRUE(app_->start_bake(arbitrary).ok());
  EXPECT_FALSE(app_->start_bake(arbitrary).ok());  // one at a time
  wait_for_bake();
  (void)show("idle", 0.0, Overlay::kNone);
  EXPECT_EQ(app_->stats().pose_samples, 37u);

  arbitrary.samples = 20000;  // long enough to be cancelled mid-way
  ASSERT_TRUE(app_->start_bake(arbitrary).ok());
  ASSERT_TRUE(app_->step().ok());
  app_->cancel_bake();
  wait_for_bake();
  (void)show("idle", 0.0, Overlay::kNone);
  EXPECT_EQ(app_->stats().pose_samples, 37u);
  EXPECT_NE(app_->message().find("cancelled"), std::string::npos) << app_->message();
}

TEST(EditorOverlayTest, ProjectionInvertsThePinholeCameraRays) {
  rt::CameraDesc desc;
  desc.eye = {1.0f, 2.0f, 5.0f};
  desc.target = {0.2f, 0.9f, -0.3f};
  desc.up = {0.0f, 1.0f, 0.0f};
  desc.fovy_degrees = 50.0f;
  const int w = 320, h = 200;
  auto camera = rt::PinholeCamera::create(desc, w, h);
  ASSERT_TRUE(camera.ok());
  const Projection projection(desc, w, h);
  for (const auto& [x, y] : {std::pair{0, 0}, {319, 199}, {160, 100}, {17, 181}}) {
    const Ray ray = camera->ray(x, y);
    const Vec3 p = ray.origin + 3.7f * ray.direction;
    EXPECT_GT(projection.depth(p), 0.0f);
    const Vec2 px = projection.to_pixel(p);
    EXPECT_NEAR(px.x, static_cast<float>(x) + 0.5f, 1e-3f);
    EXPECT_NEAR(px.y, static_cast<float>(y) + 0.5f, 1e-3f);
  }
}

TEST(EditorOverlayTest, SegmentsBehindTheEyeAreClippedAway) {
  rt::CameraDesc desc;  // at (0,1,4) looking at -Z
  const int w = 64, h = 48;
  std::vector<std::uint8_t> rgba(4 * w * h, 0);
  const ImageRef image{w, h, rgba};
  const Projection projection(desc, w, h);
  const std::uint8_t white[3] = {255, 255, 255};
  // Entirely behind the eye: nothing.
  draw_segment(image, projection, {-1.0f, 1.0f, 6.0f}, {1.0f, 1.0f, 7.0f}, white);
  EXPECT_EQ(std::count(rgba.begin(), rgba.end(), 255), 0);
  // From behind the eye to the target: only the part in front, ending at
  // the image centre (the target's pixel).
  draw_segment(image, projection, {0.0f, 1.0f, 9.0f}, {0.0f, 1.0f, 0.0f}, white);
  std::size_t lit = 0;
  for (std::size_t i = 0; i < rgba.size(); i += 4) lit += rgba[i] == 255;
  EXPECT_GE(lit, 1u);
  EXPECT_EQ(rgba[4 * (24 * w + 32)], 255);
}

TEST(EditorOverlayTest, LeafHeatIsTheLargestLeafOfEachTriangle) {
  auto mannequin = content::make_mannequin();
  ASSERT_TRUE(mannequin.ok());
  JobSystem jobs(2);
  for (const rt::BoneTreeKind kind : {rt::BoneTreeKind::kKdTree, rt::BoneTreeKind::kBvh}) {
    SCOPED_TRACE(kind == rt::BoneTreeKind::kBvh ? "BVHs" : "kd-trees");
    character::BakeRequest request;
    request.pose_space.mode = anim::PoseSpaceMode::kClip;
    request.pose_space.clips = {"walk"};
    request.fuzzy.bone_trees = kind;
    request.fuzzy.bvh.max_leaf_items = 4;
    auto baked = character::bake_in_memory(*mannequin, request, jobs);
    ASSERT_TRUE(baked.ok());
    const rt::FuzzyCharacterView view = baked->fuzzy.view();
    const std::size_t triangles = mannequin->mesh.triangle_count();
    const std::vector<std::uint32_t> heat = leaf_heat(view, triangles);
    // Reference: every leaf of every tree, per triangle, the hard way.
    std::vector<std::uint32_t> expected(triangles, 0);
    std::size_t leaves = 0;
    const auto count_leaf = [&](std::span<const std::uint32_t> items) {
      ++leaves;
      for (const std::uint32_t t : items) {
        expected[t] = std::max(expected[t], static_cast<std::uint32_t>(items.size()));
      }
    };
    for (std::uint32_t b = 0; b < view.bone_count; ++b) {
      if (view.has_bvhs()) {
        const rt::BvhView tree = view.bvh_view(view.bone_trees[b]);
        for (const rt::BvhNode& node : tree.nodes) {
          if (node.is_leaf()) count_leaf(tree.items.subspan(node.first, node.count));
        }
        // Every leaf yields its box, inside the root box.
        for (const Aabb& box : bvh_leaf_boxes(tree)) EXPECT_TRUE(tree.bounds.contains(box));
        continue;
      }
      const rt::KdTreeView tree = view.bone_tree(b);
      for (const rt::KdNode& node : tree.nodes) {
        if (node.is_leaf() && node.item_count() > 0) count_leaf(tree.items.subspan(node.first_item(), node.item_count()));
      }
      // Every non-empty leaf yields one cell, inside the root box.
      for (const Aabb& cell : leaf_cells(tree)) EXPECT_TRUE(tree.bounds.contains(cell));
    }
    EXPECT_GT(leaves, 0u);
    EXPECT_EQ(heat, expected);
    for (std::size_t t = 0; t < triangles; ++t) EXPECT_GT(heat[t], 0u) << t;  // every triangle is in a leaf
  }
}

TEST_F(EditorGuiTest, OrbitTurnsTheCameraAboutItsTarget) {
  (void)show("idle", 0.0, Overlay::kNone);
  const rt::CameraDesc before = app_->viewport().camera();
  app_->orbit(0.4f, 0.1f);
  const rt::CameraDesc after = app_->viewport().camera();
  EXPECT_NEAR(glm::length(after.eye - after.target), glm::length(before.eye - before.target), 1e-3f);
  EXPECT_GT(glm::length(after.eye - before.eye), 0.1f);
  EXPECT_EQ(after.target, before.target);
  const Screenshot shot = show("idle", 0.0, Overlay::kNone);
  EXPECT_EQ(shot.width, kWindowWidth);
}

TEST(EditorGuiCommandTest, UsageErrorsAndMissingModels) {
  std::ostringstream out, err;
  EXPECT_EQ(run_gui({"--frames", "x"}, out, err), 2);
  EXPECT_EQ(run_gui({"--overlay", "sparkles"}, out, err), 2);
  EXPECT_EQ(run_gui({"--size", "10"}, out, err), 2);
  EXPECT_EQ(run_gui({"--bogus"}, out, err), 2);
  EXPECT_EQ(run_gui({"a.glb", "b.glb"}, out, err), 2);
  EXPECT_EQ(run_gui({"--help"}, out, err), 0);
  EXPECT_NE(out.str().find("--screenshot"), std::string::npos);
  ASSERT_TRUE(Window::display_available()) << "run this test under xvfb-run";
  err.str("");
  EXPECT_EQ(run_gui({"/nonexistent/model.glb", "--frames", "1"}, out, err), 1);
  EXPECT_NE(err.str().find("model.glb"), std::string::npos) << err.str();
}

TEST(EditorGuiCommandTest, WritesAScreenshotOfAPack) {
  ASSERT_TRUE(Window::display_available()) << "run this test under xvfb-run";
  auto mannequin = content::make_mannequin();
  ASSERT_TRUE(mannequin.ok());
  JobSystem jobs(2);
  character::BakeRequest request;
  request.pose_space.mode = anim::PoseSpaceMode::kClips;
  request.pose_space.samples = 20;
  request.pose_space.every_frame_30hz = false;
  auto baked = character::bake_in_memory(*mannequin, request, jobs);
  ASSERT_TRUE(baked.ok()) << baked.status().message();
  const auto dir = std::filesystem::temp_directory_path() / "sinew_editor_gui_test";
  std::filesystem::create_directories(dir);
  const std::string pack = (dir / "mannequin.pack").string();
  character::PackContents contents;
  contents.model = &*mannequin;
  contents.fuzzy = &baked->fuzzy;
  ASSERT_TRUE(character::write_pack(pack, contents).ok());
  const std::string png = (dir / "shot.png").string();
  std::filesystem::remove(png);
  std::ostringstream out, err;
  EXPECT_EQ(run_gui({pack, "--size", "720x400", "--frames", "2", "--screenshot", png, "--overlay", "boxes",
                     "--bone", "pelvis", "--clip", "walk", "--time", "0.25"},
                    out, err),
            0)
      << err.str();
  EXPECT_TRUE(std::filesystem::exists(png));
  EXPECT_GT(std::filesystem::file_size(png), 1000u);
  err.str("");
  EXPECT_EQ(run_gui({pack, "--frames", "1", "--clip", "moonwalk"}, out, err), 1);
  EXPECT_NE(err.str().find("moonwalk"), std::string::npos) << err.str();
}

}  // namespace
}  // namespace sinew::editor::gui
