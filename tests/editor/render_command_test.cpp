// sinew-editor render, in-process: the files it writes read back as
// written; its depth and triangle-id AOVs agree with an independent brute
// force (the model imported and posed again here, every triangle
// intersected one by one); multi-frame stats and instances; and every kind
// of bad input gives exit code 2 (usage) or 1 (user error) with one message
// naming the flag or file and the value.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "character/bake.h"
#include "character/framing.h"
#include "character/pack.h"
#include "runtime/cli/command_line.h"
#include "runtime/cli/option_values.h"
#include "editor/cli/render_command.h"
#include "editor/import/gltf_importer.h"
#include "raytrace/camera/camera.h"
#include "raytrace/geometry/triangle_intersect.h"
#include "raytrace/skinning/skinning.h"
#include "runtime/image/image_io.h"
#include "runtime/io/atomic_file.h"
#include "runtime/jobs/job_system.h"
#if SINEW_HAVE_CAL3D
#include "editor/import/cal3d_importer.h"
#endif

namespace sinew::editor {
namespace {

const std::string kCesiumMan = std::string(SINEW_SHARED_DIR) + "/content/gltf/CesiumMan/CesiumMan.glb";
const std::string kCally = std::string(SINEW_SHARED_DIR) + "/content/cal3d/cally/cally.cfg";

std::string fresh_dir(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / ("sinew_render_command_" + name);
  std::filesystem::remove_all(dir);
  return dir.string();
}

// Small, quick renders: a handful of pose samples is enough for tests that
// are not about the bake (the fallback keeps any pose exact).
RenderOptions small_options(const std::string& model) {
  RenderOptions o;
  o.model_path = model;
  o.width = 96;
  o.height = 96;
  o.pose_space = character::default_pose_space();
  o.pose_space->samples = 24;
  o.threads = 2;
  return o;
}

// --- files and stats -----------------------------------------------------------

TEST(RenderCommand, WritesFilesThatReadBackAsRendered) {
  RenderOptions o = small_options(kCesiumMan);
  o.time_seconds = 0.3;
  o.out_dir = fresh_dir("files");
  const auto outputs = render_model(o);
  ASSERT_TRUE(outputs.ok()) << outputs.status().message();
  const std::size_t pixels = 96 * 96;

  const auto color = read_image(o.out_dir + "/color.png");
  ASSERT_TRUE(color.ok()) << color.status().message();
  EXPECT_EQ(color->desc.width, 96);
  EXPECT_EQ(color->desc.height, 96);
  EXPECT_EQ(color->desc.channels, 4);
  EXPECT_EQ(color->desc.type, PixelType::kU8);
  const auto rgba = color->as<std::uint8_t>();
  ASSERT_EQ(rgba.size(), 4 * pixels);
  EXPECT_TRUE(std::equal(rgba.begin(), rgba.end(), outputs->color_rgba8.begin()));

  const auto depth = read_image(o.out_dir + "/depth.exr");
  ASSERT_TRUE(depth.ok()) << depth.status().message();
  EXPECT_EQ(depth->desc.channels, 1);
  EXPECT_EQ(depth->desc.type, PixelType::kF32);
  const auto d = depth->as<float>();
  ASSERT_EQ(d.size(), pixels);
  std::size_t misses = 0;
  for (std::size_t i = 0; i < pixels; ++i) {
    ASSERT_TRUE(d[i] == outputs->depth[i]) << "pixel " << i;  // +inf compares equal too
    if (std::isinf(d[i])) ++misses;
  }

  const auto ids = read_image(o.out_dir + "/triangle_id.exr");
  ASSERT_TRUE(ids.ok()) << ids.status().message();
  EXPECT_EQ(ids->desc.channels, 1);
  EXPECT_EQ(ids->desc.type, PixelType::kU32);
  const auto t = ids->as<std::uint32_t>();
  ASSERT_EQ(t.size(), pixels);
  EXPECT_TRUE(std::equal(t.begin(), t.end(), outputs->triangle_id.begin()));
  // The default camera sees the model, the ground and some sky.
  EXPECT_EQ(std::count(t.begin(), t.end(), kInvalidId), static_cast<std::ptrdiff_t>(misses));
  EXPECT_GT(misses, 0u);
  EXPECT_LT(misses, pixels);
  EXPECT_GT(std::count(outputs->instance_id.begin(), outputs->instance_id.end(), 0u), 100);

  const auto text = read_file_text(o.out_dir + "/stats.json");
  ASSERT_TRUE(text.ok()) << text.status().message();
  const nlohmann::json stats = nlohmann::json::parse(*text, nullptr, false);
  ASSERT_FALSE(stats.is_discarded()) << *text;
  EXPECT_EQ(*text, outputs->stats_json);
  EXPECT_EQ(stats["model"], kCesiumMan);
  EXPECT_EQ(stats["triangles"], 4672);  // CesiumMan's one primitive
  EXPECT_EQ(stats["bones"], 19);
  EXPECT_EQ(stats["instances"], 1);
  EXPECT_EQ(stats["size"], nlohmann::json::array({96, 96}));
  EXPECT_GT(stats["samples"].get<int>(), 1);
  EXPECT_LE(stats["samples"].get<int>(), 24);
  for (const char* key : {"sampling_ms", "assignment_ms", "build_ms", "fuzzy_area", "mean_items_per_leaf",
                          "max_depth", "pose_sampling_ms"}) {
    EXPECT_TRUE(stats["bake"].contains(key)) << key;
  }
  EXPECT_GT(stats["bake"]["fuzzy_area"].get<double>(), 0.0);
  for (const char* phase : {"animation", "skinning", "boxes", "fallback", "top level", "trace primary",
                            "trace shadow", "shade"}) {
    ASSERT_TRUE(stats["phases"].contains(phase)) << phase;
    EXPECT_EQ(stats["phases"][phase]["samples"], 1) << phase;
    EXPECT_GE(stats["phases"][phase]["median_ms"].get<double>(), 0.0) << phase;
    EXPECT_GE(stats["phases"][phase]["min_ms"].get<double>(), 0.0) << phase;
  }
  EXPECT_EQ(stats["rays"]["primary"], pixels);
  // Shadows are on: at most one shadow ray per hit (hits facing away from
  // the light need none).
  EXPECT_LE(stats["rays"]["shadow"].get<std::size_t>(), pixels - misses);
  EXPECT_GT(stats["rays"]["shadow"].get<std::size_t>(), (pixels - misses) / 2);
  for (const char* key : {"escaped_checks", "escaped_triangles", "total_escaped_checks", "total_escaped_triangles"}) {
    EXPECT_TRUE(stats["escapes"].contains(key)) << key;
  }
  EXPECT_GT(stats["fps"].get<double>(), 0.0);
}

// --- AOVs against brute force ------------------------------------------------

struct SoupTriangle {
  Vec3 p0, p1, p2;
  bool ground = false;
  std::uint32_t id = 0;  // triangle id within the model or the ground
};

struct RefHit {
  float t = std::numeric_limits<float>::infinity();
  const SoupTriangle* triangle = nullptr;
};

RefHit nearest(const std::vector<SoupTriangle>& soup, const Ray& ray) {
  const rt::WatertightRay wr = rt::prepare_watertight(ray);
  RefHit best;
  for (const SoupTriangle& tri : soup) {
    rt::TriangleHit h;
    if (rt::intersect_triangle_watertight(wr, ray, best.t, tri.p0, tri.p1, tri.p2, h)) best = {h.t, &tri};
  }
  return best;
}

Expected<character::Model> import_any(const std::string& path) {
#if SINEW_HAVE_CAL3D
  if (path.ends_with(".cfg")) return import_cal3d(path);
#endif
  return import_gltf(path);
}

// The model posed again from scratch: clip_skinning at the same time, each
// vertex skinned with the scalar reference, plus the ground quad.
std::vector<SoupTriangle> posed_soup(const character::Model& model, const anim::Clip& clip, double seconds,
                                     const rt::StaticMeshDesc& ground) {
  const auto bones = character::clip_skinning(model, clip, seconds);
  EXPECT_TRUE(bones.ok()) << bones.status().message();
  if (!bones.ok()) return {};
  std::vector<Vec3> world(model.mesh.vertex_count());
  for (std::size_t v = 0; v < world.size(); ++v) world[v] = rt::skin_point(model.mesh, v, *bones);
  std::vector<SoupTriangle> soup;
  for (std::uint32_t t = 0; t < model.mesh.triangle_count(); ++t) {
    const auto& tri = model.mesh.triangles[t];
    soup.push_back({world[tri[0]], world[tri[1]], world[tri[2]], false, t});
  }
  for (std::uint32_t t = 0; t < ground.triangles.size(); ++t) {
    const auto& tri = ground.triangles[t];
    soup.push_back({ground.positions[tri[0]], ground.positions[tri[1]], ground.positions[tri[2]], true, t});
  }
  return soup;
}

bool near(float a, float b) { return std::fabs(a - b) <= 1e-5f * std::max(std::fabs(b), 1e-30f); }

void expect_aovs_match_brute_force(const std::string& path, double seconds) {
  RenderOptions o = small_options(path);
  o.clip = "#0";
  o.time_seconds = seconds;
  o.triangle_test = rt::TriangleTest::kWatertight;
  const auto outputs = render_model(o);
  ASSERT_TRUE(outputs.ok()) << outputs.status().message();

  const auto model = import_any(path);
  ASSERT_TRUE(model.ok()) << model.status().message();
  ASSERT_FALSE(model->clips.empty());
  // The ground the command added, derived again from the model alone.
  const rt::StaticMeshDesc ground = character::ground_plane_for(*model, 1);
  ASSERT_EQ(ground.positions.size(), outputs->ground.positions.size());
  for (std::size_t i = 0; i < ground.positions.size(); ++i) EXPECT_EQ(ground.positions[i], outputs->ground.positions[i]);
  const std::vector<SoupTriangle> soup = posed_soup(*model, model->clips.front(), seconds, ground);
  const auto camera = rt::PinholeCamera::create(outputs->camera, o.width, o.height);
  ASSERT_TRUE(camera.ok()) << camera.status().message();

  std::size_t checked = 0, model_hits = 0, ground_hits = 0, wrong = 0;
  std::string first;
  for (int y = 0; y < o.height; y += 2) {
    for (int x = 0; x < o.width; x += 2) {
      const Ray ray = camera->ray(x, y);
      const RefHit ref = nearest(soup, ray);
      const std::size_t i = static_cast<std::size_t>(y * o.width + x);
      const float depth = outputs->depth[i];
      const std::uint32_t tri = outputs->triangle_id[i];
      const std::uint32_t inst = outputs->instance_id[i];
      ++checked;
      bool ok = true;
      if (ref.triangle == nullptr) {
        ok = std::isinf(depth) && depth > 0.0f && tri == kInvalidId && inst == kInvalidId;
      } else {
        ok = near(depth, ref.t);
        const bool ours_ground = inst == outputs->ground_instance_id;
        ok = ok && (inst == 0 || ours_ground);
        if (ok && (ref.triangle->ground != ours_ground || ref.triangle->id != tri)) {
          // Another triangle at the same t: a shared edge or vertex. It must
          // really be hit there.
          ok = false;
          for (const SoupTriangle& s : soup) {
            if (s.ground != ours_ground || s.id != tri) continue;
            rt::TriangleHit h;
            ok = rt::intersect_triangle_watertight(rt::prepare_watertight(ray), ray,
                                                   std::numeric_limits<float>::infinity(), s.p0, s.p1, s.p2, h) &&
                 near(h.t, ref.t);
          }
        }
        (ref.triangle->ground ? ground_hits : model_hits) += 1;
      }
      if (!ok && wrong++ == 0) {
        first = "pixel (" + std::to_string(x) + "," + std::to_string(y) + "): depth " + std::to_string(depth) +
                " tri " + std::to_string(tri) + " inst " + std::to_string(inst) + "; reference t " +
                std::to_string(ref.t) + " tri " + (ref.triangle ? std::to_string(ref.triangle->id) : "-") +
                (ref.triangle && ref.triangle->ground ? " (ground)" : "");
      }
    }
  }
  EXPECT_EQ(wrong, 0u) << "of " << checked << "; first: " << first;
  // Not vacuous: the default camera sees plenty of both.
  EXPECT_GT(model_hits, checked / 20);
  EXPECT_GT(ground_hits, checked / 20);
}

TEST(RenderCommand, AovsMatchBruteForceCesiumMan) { expect_aovs_match_brute_force(kCesiumMan, 0.7); }

#if SINEW_HAVE_CAL3D
TEST(RenderCommand, AovsMatchBruteForceCally) { expect_aovs_match_brute_force(kCally, 0.45); }
#endif

// --- frames and instances ------------------------------------------------------

TEST(RenderCommand, FramesRecordOneSamplePerPhasePerFrame) {
  RenderOptions o = small_options(kCesiumMan);
  o.frames = 3;
  o.time_seconds = 0.25;
  const auto outputs = render_model(o);
  ASSERT_TRUE(outputs.ok()) << outputs.status().message();
  const auto phases = outputs->timers.summarize();
  ASSERT_EQ(phases.size(), 8u);
  for (const PhaseSummary& p : phases) EXPECT_EQ(p.samples, 3u) << p.name;
  const nlohmann::json stats = nlohmann::json::parse(outputs->stats_json);
  EXPECT_EQ(stats["frames"], 3);
  EXPECT_EQ(stats["phases"]["trace primary"]["samples"], 3);
  EXPECT_NEAR(outputs->last_frame_seconds, 0.25 + 2.0 / 30.0, 1e-12);
  EXPECT_NEAR(stats["fps"].get<double>(), 1000.0 / outputs->stats.median_frame_ms, 1e-9);
}

TEST(RenderCommand, InstancesStandSideBySideWithDifferentPoses) {
  RenderOptions o = small_options(kCesiumMan);
  o.instances = 2;
  o.width = 128;
  const auto outputs = render_model(o);
  ASSERT_TRUE(outputs.ok()) << outputs.status().message();
  EXPECT_EQ(outputs->ground_instance_id, 2u);
  const std::set<std::uint32_t> seen(outputs->instance_id.begin(), outputs->instance_id.end());
  EXPECT_TRUE(seen.count(0) && seen.count(1) && seen.count(2)) << "instances 0, 1 and the ground all visible";
  ASSERT_EQ(outputs->instance_placements.size(), 2u);
  const Vec3 offset = outputs->instance_placements[1].translation_part();
  EXPECT_GT(offset.x, 0.0f);
  EXPECT_EQ(offset.y, 0.0f);
  EXPECT_EQ(offset.z, 0.0f);

  // The second instance plays 0.37 s later: posed differently from the first.
  const auto model = import_gltf(kCesiumMan);
  ASSERT_TRUE(model.ok());
  const auto a = character::clip_skinning(*model, model->clips.front(), 0.0);
  const auto b = character::clip_skinning(*model, model->clips.front(), character::instance_time_offset(1));
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(character::instance_time_offset(1), 0.37);
  bool differ = false;
  for (std::size_t j = 0; j < a->size(); ++j) differ = differ || (*a)[j].rows != (*b)[j].rows;
  EXPECT_TRUE(differ);
}

TEST(RenderCommand, GroundOffLeavesTheCharactersAlone) {
  auto parsed = parse_render_options({"m.glb", "--out", "o", "--ground", "off"});
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  EXPECT_FALSE(parsed->ground);
  EXPECT_FALSE(parse_render_options({"m.glb", "--out", "o", "--ground", "maybe"}).ok());

  RenderOptions o = small_options(kCesiumMan);
  o.ground = false;
  const auto outputs = render_model(o);
  ASSERT_TRUE(outputs.ok()) << outputs.status().message();
  EXPECT_EQ(outputs->ground_instance_id, kInvalidId);
  EXPECT_TRUE(outputs->ground.triangles.empty());
  const std::set<std::uint32_t> seen(outputs->instance_id.begin(), outputs->instance_id.end());
  EXPECT_EQ(seen, (std::set<std::uint32_t>{0u, kInvalidId})) << "the character and misses only";
}

// CesiumMan's one material is white with a texture: on, the character's
// pixels take many colours; off, they are the white material shaded, whose
// hue does not change (grey levels only).
TEST(RenderCommand, TexturesOnShowTheMapAndOffShowTheMaterialColour) {
  auto parsed = parse_render_options({"m.glb", "--out", "o", "--textures", "off"});
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  EXPECT_FALSE(parsed->textures);
  EXPECT_FALSE(parse_render_options({"m.glb", "--out", "o", "--textures", "maybe"}).ok());
  const auto coloured_pixels = [](const RenderOutputs& r) {
    int coloured = 0, on_character = 0;
    for (std::size_t p = 0; p < r.instance_id.size(); ++p) {
      if (r.instance_id[p] != 0u) continue;
      ++on_character;
      const std::uint8_t* c = &r.color_rgba8[4 * p];
      coloured += std::max({c[0], c[1], c[2]}) - std::min({c[0], c[1], c[2]}) > 24 ? 1 : 0;
    }
    EXPECT_GT(on_character, 500);
    return coloured;
  };
  RenderOptions o = small_options(kCesiumMan);
  const auto on = render_model(o);
  ASSERT_TRUE(on.ok()) << on.status().message();
  o.textures = false;
  const auto off = render_model(o);
  ASSERT_TRUE(off.ok()) << off.status().message();
  EXPECT_GT(coloured_pixels(*on), 200);
  EXPECT_EQ(coloured_pixels(*off), 0);
}

// --- soft shadows and ambient occlusion -------------------------------------------

TEST(RenderCommand, SoftLightingOptionsMapToTheirSettings) {
  const auto d = parse_render_options({"m.glb", "--out", "o"});
  ASSERT_TRUE(d.ok()) << d.status().message();
  EXPECT_EQ(d->light_radius, 0.0f) << "hard point lights by default";
  EXPECT_EQ(d->shadow_samples, 4);
  EXPECT_EQ(d->ao_rays, 0) << "no ambient occlusion by default";
  EXPECT_FALSE(d->ao_radius.has_value()) << "derived from the character's height";

  const auto o = parse_render_options({"m.glb", "--out", "o", "--light-radius", "0.25", "--shadow-samples", "16",
                                       "--ao-rays", "8", "--ao-radius=0.75"});
  ASSERT_TRUE(o.ok()) << o.status().message();
  EXPECT_EQ(o->light_radius, 0.25f);
  EXPECT_EQ(o->shadow_samples, 16);
  EXPECT_EQ(o->ao_rays, 8);
  ASSERT_TRUE(o->ao_radius.has_value());
  EXPECT_EQ(*o->ao_radius, 0.75f);

  // The extremes the renderer takes; a radius of 0 is a hard light, also
  // beside directional lights alone, and a radius applies where one point
  // light is among them.
  const auto extremes = parse_render_options({"m.glb", "--out", "o", "--shadow-samples", "256", "--ao-rays", "256"});
  ASSERT_TRUE(extremes.ok()) << extremes.status().message();
  EXPECT_EQ(extremes->shadow_samples, rt::kMaxSamples);
  EXPECT_EQ(extremes->ao_rays, rt::kMaxSamples);
  EXPECT_TRUE(parse_render_options({"m.glb", "--out", "o", "--light", "dir:0,1,0", "--light-radius", "0"}).ok());
  EXPECT_TRUE(parse_render_options(
                  {"m.glb", "--out", "o", "--light", "dir:0,1,0", "--light", "1,2,3", "--light-radius", "0.5"})
                  .ok());
}

// A sphere light of the suggested radius changes the picture (the shadow's
// edge becomes a penumbra) and takes --shadow-samples rays per lit hit;
// ambient occlusion only ever darkens (it scales the ambient term), does so
// in places, and reaches the character's half height by default.
TEST(RenderCommand, ASphereLightSoftensTheShadowAndAmbientOcclusionDarkens) {
  const auto model = import_gltf(kCesiumMan);
  ASSERT_TRUE(model.ok()) << model.status().message();
  const Aabb rest = character::rest_bounds(*model);

  RenderOptions o = small_options(kCesiumMan);
  const auto hard = render_model(o);
  ASSERT_TRUE(hard.ok()) << hard.status().message();
  o.light_radius = character::suggested_light_radius(rest);
  const auto soft = render_model(o);
  ASSERT_TRUE(soft.ok()) << soft.status().message();
  ASSERT_EQ(soft->lights.size(), 1u);
  EXPECT_EQ(soft->lights[0].radius, o.light_radius);
  std::size_t differ = 0;
  for (std::size_t i = 0; i < hard->color_rgba8.size(); ++i) differ += hard->color_rgba8[i] != soft->color_rgba8[i];
  EXPECT_GT(differ, 30u) << "a sphere light's image equals the point light's";
  EXPECT_EQ(hard->stats.ao_rays, 0u);
  EXPECT_GT(hard->stats.shadow_rays, 0u);
  EXPECT_GT(soft->stats.shadow_rays, 3 * hard->stats.shadow_rays) << "4 samples per lit hit";
  EXPECT_LE(soft->stats.shadow_rays, 4 * hard->stats.primary_rays);

  o.light_radius = 0.0f;
  o.ao_rays = 8;
  const auto occluded = render_model(o);
  ASSERT_TRUE(occluded.ok()) << occluded.status().message();
  EXPECT_FLOAT_EQ(occluded->ao_radius, 0.5f * character::character_height(rest));
  std::size_t darker = 0, brighter = 0;
  for (std::size_t i = 0; i < hard->color_rgba8.size(); ++i) {
    if (i % 4 == 3) continue;  // alpha
    darker += occluded->color_rgba8[i] < hard->color_rgba8[i];
    brighter += occluded->color_rgba8[i] > hard->color_rgba8[i];
  }
  EXPECT_GT(darker, 100u);
  EXPECT_EQ(brighter, 0u);
  EXPECT_GT(occluded->stats.ao_rays, 0u);
  EXPECT_LE(occluded->stats.ao_rays, 8 * occluded->stats.primary_rays);
  EXPECT_EQ(occluded->stats.ao_work.rays, occluded->stats.ao_rays);
  const nlohmann::json stats = nlohmann::json::parse(occluded->stats_json);
  EXPECT_EQ(stats["rays"]["ao"], occluded->stats.ao_rays);
  EXPECT_EQ(stats["lighting"]["ao_rays"], 8);
  EXPECT_FLOAT_EQ(stats["lighting"]["ao_radius"].get<float>(), occluded->ao_radius);
  EXPECT_TRUE(stats["phases"].contains("trace ao"));
  EXPECT_FALSE(nlohmann::json::parse(hard->stats_json)["phases"].contains("trace ao"));
}

// The summary names the lighting and each kind of ray's count and time.
TEST(RenderCommand, SummaryPrintsTheShadowAndAmbientOcclusionRays) {
  const std::string dir = fresh_dir("soft_summary");
  std::ostringstream out, err;
  const int code = run_render({kCesiumMan, "--out", dir, "--size", "48x48", "--threads", "2", "--light-radius",
                               "0.2", "--shadow-samples", "2", "--ao-rays", "3", "--ao-radius", "0.4"},
                              out, err);
  ASSERT_EQ(code, 0) << err.str();
  const std::string text = out.str();
  for (const char* line : {"soft shadows: point lights of radius 0.20, 2 shadow samples per hit\n",
                           "ambient occlusion: 3 rays per hit, radius 0.40\n", "rays (last frame): 2304 primary in ",
                           " ambient occlusion in ", "  ambient occlusion work per ray: ", "  trace ao "}) {
    EXPECT_NE(text.find(line), std::string::npos) << "no '" << line << "' in:\n" << text;
  }
}

#if SINEW_HAVE_CAL3D
// Cally's skeleton and meshes (paths made absolute) under a .cfg of our own
// with `scale=` first.
std::string cally_at_scale(const std::string& dir, const std::string& scale) {
  std::ifstream in(kCally);
  std::stringstream text;
  text << in.rdbuf();
  const Cal3dConfig cally = parse_cal3d_config(text.str(), kCally).value();
  const std::string folder = std::filesystem::path(kCally).parent_path().string() + "/";
  std::string cfg = "scale=" + scale + "\nskeleton=" + folder + cally.skeleton + "\n";
  for (const std::string& mesh : cally.meshes) cfg += "mesh=" + folder + mesh + "\n";
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/scaled.cfg";
  std::ofstream(path) << cfg;
  return path;
}

// A .cfg scale of 1e-10 rendered an image without the character. Scales
// outside what the tracer frames are refused naming the limit; at the
// smallest one it takes, Cally fills the picture as at scale 1.
TEST(RenderCommand, Cal3dScalesTheTracerCannotFrameAreRefused) {
  const std::string dir = fresh_dir("cal3d_scale");
  for (const std::string scale : {"1e-10", "1e-7", "1e7"}) {
    const auto refused = render_model(small_options(cally_at_scale(dir, scale)));
    ASSERT_FALSE(refused.ok()) << scale;
    EXPECT_EQ(refused.status().field(), "line 1: scale") << refused.status().message();
    EXPECT_EQ(refused.status().value(), scale) << refused.status().message();
    EXPECT_NE(refused.status().message().find("[1e-06, 1e+06]"), std::string::npos) << refused.status().message();
  }
  auto character_pixels = [&](const std::string& scale) {
    RenderOptions o = small_options(cally_at_scale(dir, scale));
    o.ground = false;
    const auto outputs = render_model(o);
    EXPECT_TRUE(outputs.ok()) << scale << ": " << outputs.status().message();
    return outputs.ok() ? std::count(outputs->instance_id.begin(), outputs->instance_id.end(), 0u) : 0;
  };
  const auto at_one = character_pixels("1");
  EXPECT_GT(at_one, 96 * 96 / 20);
  const auto smallest = character_pixels("1e-6");
  EXPECT_GT(smallest, at_one / 2);
  const auto largest = character_pixels("1e6");
  EXPECT_GT(largest, at_one / 2);
}
#endif

// A glTF whose clips lasted 10,000 s ran `render` past a minute and took
// `bake` 99 s: every 1/30 s of them was sampled. Render now bakes only the
// pose it draws; the bake refuses such a clip for the every-1/30-s pose
// space in one line naming the clip, its length and the limit.
TEST(RenderCommand, ALongClipCostsRenderOnePoseAndIsRefusedByTheBake) {
  auto model = import_gltf(kCesiumMan);
  ASSERT_TRUE(model.ok()) << model.status().message();
  anim::RawClip raw;
  raw.name = "long";
  anim::JointTracks& track = raw.tracks.emplace_back();
  track.joint = 1;
  track.rotation.times = {0.0f, 10'000.0f};
  track.rotation.values = {Quat(1.0f, 0.0f, 0.0f, 0.0f), glm::angleAxis(1.0f, Vec3(1.0f, 0.0f, 0.0f))};
  model->clips.push_back(anim::Clip::build(std::move(raw), model->skeleton, "test").value());

  const std::string dir = fresh_dir("long_clip");
  std::filesystem::create_directories(dir);
  character::PackContents contents;
  contents.model = &*model;
  const auto bytes = character::serialize_pack(contents);
  ASSERT_TRUE(bytes.ok()) << bytes.status().message();
  const std::string pack = dir + "/long.pack";  // model only: render bakes it in memory
  std::ofstream(pack, std::ios::binary).write(reinterpret_cast<const char*>(bytes->data()),
                                              static_cast<std::streamsize>(bytes->size()));
  RenderOptions o;
  o.model_path = pack;
  o.clip = "long";
  o.time_seconds = 5'000.0;
  o.width = o.height = 32;
  o.threads = 2;
  const auto rendered = render_model(o);
  ASSERT_TRUE(rendered.ok()) << rendered.status().message();
  EXPECT_EQ(rendered->stats.pose_samples, 1u);

  JobSystem jobs(1);
  const auto baked = character::bake_in_memory(*model, character::BakeRequest{}, jobs);
  ASSERT_FALSE(baked.ok());
  EXPECT_EQ(baked.status().code(), ErrorCode::kLimitExceeded);
  EXPECT_EQ(baked.status().message(),
            kCesiumMan + ": pose_space.clips = long: lasts 10000 s: sampling every 1/30 s takes clips of up to "
                         "600 s (anim::kMaxClipSecondsEveryFrame; or sample N poses of it)");
  // N poses of it are fine, whatever its length.
  character::BakeRequest some;
  some.pose_space.clips = {"long"};
  some.pose_space.samples = 8;
  const auto sampled = character::bake_in_memory(*model, some, jobs);
  ASSERT_TRUE(sampled.ok()) << sampled.status().message();
  EXPECT_EQ(sampled->fuzzy.stats.sample_count, 8u);
}

TEST(RenderCommand, UpAxisIsTheLargerOfYAndZ) {
  EXPECT_EQ(character::up_axis_of(Aabb{Vec3(0.0f), Vec3(5.0f, 2.0f, 1.0f)}), 1);
  EXPECT_EQ(character::up_axis_of(Aabb{Vec3(0.0f), Vec3(5.0f, 1.0f, 2.0f)}), 2);
  const rt::StaticMeshDesc ground = character::ground_plane_for(Aabb{Vec3(-1.0f, -0.5f, 0.0f), Vec3(1.0f, 0.5f, 3.0f)}, 1);
  ASSERT_EQ(ground.triangles.size(), 2u);
  for (const Vec3& p : ground.positions) EXPECT_EQ(p.z, 0.0f);  // Z-up: under the box's lowest z
}

// --- layouts -------------------------------------------------------------------

// Rest bounds standing for a Z-up model (2 tall, largest extent 2) and a
// Y-up one (1.8 tall, largest extent 1.8).
const Aabb kZUpRest{Vec3(-0.5f, -0.25f, 0.0f), Vec3(0.5f, 0.25f, 2.0f)};
const Aabb kYUpRest{Vec3(-0.4f, 0.0f, -0.2f), Vec3(0.4f, 1.8f, 0.2f)};

struct Cell {
  int column, row;
};
// By hand: the grid's (column, row) of each copy for N = 1, 2, 5, 9
// (ceil(sqrt(N)) = 1, 2, 3, 3 columns).
const std::vector<std::pair<int, std::vector<Cell>>> kGridCells = {
    {1, {{0, 0}}},
    {2, {{0, 0}, {1, 0}}},
    {5, {{0, 0}, {1, 0}, {2, 0}, {0, 1}, {1, 1}}},
    {9, {{0, 0}, {1, 0}, {2, 0}, {0, 1}, {1, 1}, {2, 1}, {0, 2}, {1, 2}, {2, 2}}},
};

TEST(Layouts, GridPlacementsAndTimeOffsetsAreTheIssuesByHand) {
  struct Case {
    const char* name;
    Aabb rest;
    float spacing;  // 1.2 x the largest rest extent
    Vec3 away;      // the rows' direction, away from the default camera
  };
  const Case models[] = {{"Z-up", kZUpRest, 1.2f * 2.0f, Vec3(0.0f, 1.0f, 0.0f)},
                          {"Y-up", kYUpRest, 1.2f * 1.8f, Vec3(0.0f, 0.0f, -1.0f)}};
  for (const Case& m : models) {
    for (const auto& [n, cells] : kGridCells) {
      SCOPED_TRACE(std::string(m.name) + ", N = " + std::to_string(n));
      ASSERT_EQ(cells.size(), static_cast<std::size_t>(n));
      EXPECT_EQ(character::layout_columns(n, character::Layout::kGrid), n == 1 ? 1 : n == 2 ? 2 : 3);
      EXPECT_EQ(character::layout_columns(n, character::Layout::kRow), n);
      for (int i = 0; i < n; ++i) {
        const Vec3 expected = static_cast<float>(cells[static_cast<std::size_t>(i)].column) * m.spacing *
                                  Vec3(1.0f, 0.0f, 0.0f) +
                              static_cast<float>(cells[static_cast<std::size_t>(i)].row) * m.spacing * m.away;
        const Affine3 grid = character::instance_placement(m.rest, i, n, character::Layout::kGrid);
        for (int a = 0; a < 3; ++a) EXPECT_FLOAT_EQ(grid.translation_part()[a], expected[a]) << "copy " << i;
        // Placements move and never turn.
        for (int r = 0; r < 3; ++r) {
          for (int c = 0; c < 3; ++c) EXPECT_EQ(grid(r, c), r == c ? 1.0f : 0.0f);
        }
        // The row: copy i at i x spacing along +X, as ever.
        const Vec3 row = character::instance_placement(m.rest, i, n, character::Layout::kRow).translation_part();
        EXPECT_FLOAT_EQ(row.x, static_cast<float>(i) * m.spacing);
        EXPECT_EQ(row.y, 0.0f);
        EXPECT_EQ(row.z, 0.0f);
        EXPECT_DOUBLE_EQ(character::instance_time_offset(i), 0.37 * i);
      }
    }
  }
  // More columns as the square grows.
  EXPECT_EQ(character::layout_columns(10, character::Layout::kGrid), 4);
  EXPECT_EQ(character::layout_columns(16, character::Layout::kGrid), 4);
  EXPECT_EQ(character::layout_columns(17, character::Layout::kGrid), 5);
  EXPECT_EQ(character::layout_columns(256, character::Layout::kGrid), 16);
}

TEST(Layouts, TheGroundCoversTheLayoutAndReachesFiftyHeightsBeyondIt) {
  for (const Aabb& rest : {kZUpRest, kYUpRest}) {
    const int up = character::up_axis_of(rest);
    const int a = (up + 1) % 3, b = (up + 2) % 3;
    const float height = rest.extent()[up];
    for (const character::Layout layout : {character::Layout::kRow, character::Layout::kGrid}) {
      for (const int n : {1, 2, 5, 9, 16}) {
        SCOPED_TRACE("up " + std::to_string(up) + ", layout " + std::to_string(static_cast<int>(layout)) + ", N = " +
                     std::to_string(n));
        const rt::StaticMeshDesc ground = character::ground_plane_for(rest, n, layout);
        ASSERT_EQ(ground.positions.size(), 4u);
        ASSERT_EQ(ground.triangles.size(), 2u);
        Aabb quad;
        for (const Vec3& p : ground.positions) {
          EXPECT_EQ(p[up], rest.lower[up]);  // under the feet
          quad.extend(p);
        }
        // Every copy's rest box, placed, within the quad.
        Aabb placed;
        for (int i = 0; i < n; ++i) {
          const Vec3 t = character::instance_placement(rest, i, n, layout).translation_part();
          placed.extend(rest.lower + t);
          placed.extend(rest.upper + t);
        }
        for (const int axis : {a, b}) {
          EXPECT_LE(quad.lower[axis], placed.lower[axis]);
          EXPECT_GE(quad.upper[axis], placed.upper[axis]);
          // Centred on the layout, reaching 50 heights plus half its
          // diagonal along the ground.
          const float reach = 50.0f * height + 0.5f * std::hypot(placed.extent()[a], placed.extent()[b]);
          EXPECT_NEAR(0.5f * (quad.lower[axis] + quad.upper[axis]), placed.center()[axis], 1e-4f);
          EXPECT_NEAR(0.5f * quad.extent()[axis], reach, 1e-4f * reach);
        }
      }
    }
  }
}

// Every copy of a grid is in the picture the default camera frames, on a
// Y-up (CesiumMan) and a Z-up (Cally) model, placed as the grid says.
void expect_grid_shows_every_copy(const std::string& path, int n) {
  RenderOptions o = small_options(path);
  o.instances = n;
  o.layout = character::Layout::kGrid;
  o.width = 160;
  o.height = 120;
  const auto outputs = render_model(o);
  ASSERT_TRUE(outputs.ok()) << outputs.status().message();
  EXPECT_EQ(outputs->ground_instance_id, static_cast<std::uint32_t>(n));
  std::vector<std::size_t> pixels(static_cast<std::size_t>(n) + 1, 0);
  for (const std::uint32_t id : outputs->instance_id) {
    if (id != kInvalidId) ++pixels.at(id);
  }
  for (int i = 0; i <= n; ++i) EXPECT_GT(pixels[static_cast<std::size_t>(i)], 10u) << "instance " << i;
  // The placements, by hand from the rest bounds.
  const auto model = import_any(path);
  ASSERT_TRUE(model.ok()) << model.status().message();
  const Aabb rest = character::rest_bounds(*model);
  const Vec3 e = rest.extent();
  const float spacing = 1.2f * std::max({e.x, e.y, e.z});
  const bool z_up = e.z > e.y;
  int cols = 1;
  while (cols * cols < n) ++cols;
  ASSERT_EQ(outputs->instance_placements.size(), static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const float column = static_cast<float>(i % cols) * spacing;
    const float row = static_cast<float>(i / cols) * spacing;
    const Vec3 expected = z_up ? Vec3(column, row, 0.0f) : Vec3(column, 0.0f, -row);
    const Vec3 t = outputs->instance_placements[static_cast<std::size_t>(i)].translation_part();
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(t[a], expected[a], 1e-5f * spacing) << "copy " << i;
  }
  const auto stats = nlohmann::json::parse(outputs->stats_json);
  EXPECT_EQ(stats["layout"], "grid");
}

TEST(RenderCommand, GridLayoutShowsEveryCopyCesiumMan) { expect_grid_shows_every_copy(kCesiumMan, 5); }

#if SINEW_HAVE_CAL3D
TEST(RenderCommand, GridLayoutShowsEveryCopyCally) { expect_grid_shows_every_copy(kCally, 9); }
#endif

TEST(RenderCommand, LayoutIsRowOrGrid) {
  EXPECT_EQ(parse_render_options({"m.glb", "--out", "o"})->layout, character::Layout::kRow);
  EXPECT_EQ(parse_render_options({"m.glb", "--out", "o", "--layout", "grid"})->layout, character::Layout::kGrid);
  EXPECT_EQ(parse_render_options({"m.glb", "--out", "o", "--layout=row"})->layout, character::Layout::kRow);
  const auto bad = parse_render_options({"m.glb", "--out", "o", "--layout", "ring"});
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("--layout"), std::string::npos) << bad.status().message();
  EXPECT_NE(bad.status().message().find("ring"), std::string::npos) << bad.status().message();
}

// --- errors --------------------------------------------------------------------

struct RunResult {
  int code = 0;
  std::string out;
  std::string err;
};

RunResult run(std::vector<std::string> args) {
  std::ostringstream out, err;
  RunResult r;
  r.code = run_render(args, out, err);
  r.out = out.str();
  r.err = err.str();
  return r;
}

TEST(RenderCommand, UsageErrorsNameTheFlagAndValue) {
  const std::string dir = fresh_dir("usage");
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::vector<Case> cases = {
      {{kCesiumMan, "--out", dir, "--bogus", "1"}, "option = --bogus: unknown option"},
      {{kCesiumMan, "--out", dir, "--size", "0x5"}, "--size = 0x5: expected WxH"},
      {{kCesiumMan, "--out", dir, "--size", "64"}, "--size = 64: expected WxH"},
      {{kCesiumMan, "--out", dir, "--camera", "0,1,4,0,1,0,0,1,0"}, "--camera = 0,1,4,0,1,0,0,1,0: expected 10"},
      {{kCesiumMan, "--out", dir, "--camera", "0,1,4,0,1,0,0,1,0,180"}, "--camera = 0,1,4,0,1,0,0,1,0,180: "},
      {{kCesiumMan, "--out", dir, "--shadows", "maybe"}, "--shadows = maybe: expected one of on|off"},
      {{kCesiumMan, "--out", dir, "--frames", "0"}, "--frames = 0: expected an integer from 1"},
      {{kCesiumMan, "--out", dir, "--threads", "two"}, "--threads = two: expected an integer"},
      {{kCesiumMan, "--out", dir, "--time", "nan"}, "--time = nan: expected a number"},
      {{kCesiumMan, "--out", dir, "--light", "1,2"}, "--light = 1,2: expected 3"},
      {{kCesiumMan, "--out", dir, "--light", "sun:1,2,3"}, "--light = sun:1,2,3: expected X,Y,Z, point:X,Y,Z or dir"},
      {{kCesiumMan, "--out", dir, "--light", "dir:0,0,0"}, "--light = dir:0,0,0: a directional light needs a non-zero"},
      {{kCesiumMan, "--out", dir, "--light", "point:1,2,3:1,-1,0"}, "--light = point:1,2,3:1,-1,0: a light's colour"},
      {{kCesiumMan, "--out", dir, "--light", "point:1,2,3:"}, "--light = point:1,2,3:: expected R,G,B"},
      {{kCesiumMan, "--out", dir, "--light", "1,2,3", "--light", "1,2,3", "--light", "1,2,3", "--light", "1,2,3",
        "--light", "1,2,3", "--light", "1,2,3", "--light", "1,2,3", "--light", "1,2,3", "--light", "4,5,6"},
       "--light = 4,5,6: at most 8 lights"},
      {{kCesiumMan, "--out", dir, "--light-radius", "-1"}, "--light-radius = -1: expected a number from 0 to"},
      {{kCesiumMan, "--out", dir, "--light-radius", "nan"}, "--light-radius = nan: expected a number"},
      {{kCesiumMan, "--out", dir, "--light-radius", "0.5", "--light", "dir:0,1,0"},
       "--light-radius = 0.5: applies to point lights, and every --light is directional"},
      {{kCesiumMan, "--out", dir, "--shadow-samples", "0"}, "--shadow-samples = 0: expected an integer from 1 to 256"},
      {{kCesiumMan, "--out", dir, "--shadow-samples", "257"}, "--shadow-samples = 257: expected an integer from 1"},
      {{kCesiumMan, "--out", dir, "--ao-rays", "-1"}, "--ao-rays = -1: expected an integer from 0 to 256"},
      {{kCesiumMan, "--out", dir, "--ao-rays", "four"}, "--ao-rays = four: expected an integer"},
      {{kCesiumMan, "--out", dir, "--ao-radius", "0"}, "--ao-radius = 0: expected a length above 0"},
      {{kCesiumMan, "--out", dir, "--ao-radius", "inf"}, "--ao-radius = inf: expected a number"},
      {{kCesiumMan, "--out", dir, "--pose-space", "limits"}, "--pose-space = limits: needs --limits"},
      {{kCesiumMan, "--out", dir, "--pose-space", "clip"}, "--pose-space = clip: expected"},
      {{kCesiumMan, "--out", dir, "--pose-space", "arbitrary", "--clips", "a"}, "--clips = a: applies to"},
      {{kCesiumMan, "--out", dir, "--clip"}, "--clip: missing value"},
      {{kCesiumMan}, "--out: missing"},
      {{"--out", dir}, "MODEL: missing"},
      {{kCesiumMan, "extra", "--out", dir}, "argument = extra: unexpected"},
  };
  for (const Case& c : cases) {
    const RunResult r = run(c.args);
    EXPECT_EQ(r.code, 2) << c.message;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << "expected '" << c.message << "' in: " << r.err;
    EXPECT_EQ(r.err.rfind("sinew-editor render: ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
  EXPECT_FALSE(std::filesystem::exists(dir)) << "nothing runs on a usage error";
}

TEST(RenderCommand, UserErrorsAreOneClearLine) {
  const std::string dir = fresh_dir("user");
  const std::string missing = dir + "-nope/CesiumMan.glb";
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::vector<Case> cases = {
      {{missing, "--out", dir}, "sinew-editor: " + missing + ": no such file"},
      {{kCesiumMan, "--out", dir, "--clip", "nope"},
       "sinew-editor: " + kCesiumMan + ": clip = 'nope': no such clip (clips: animation_0)"},
      {{kCesiumMan, "--out", dir, "--clip", "#1"}, "clip = '#1': no such clip"},
      {{"model.pack", "--out", dir}, "sinew-editor: model.pack: no such file"},
      {{"model.obj", "--out", dir}, "model.obj: extension = .obj: unsupported model format"},
      {{kCesiumMan, "--out", dir, "--pose-space", "limits", "--limits", dir + "-nope.json"}, dir + "-nope.json"},
  };
  for (const Case& c : cases) {
    const RunResult r = run(c.args);
    EXPECT_EQ(r.code, 1) << c.message;
    EXPECT_EQ(r.err.rfind(c.message, 0) == 0 || r.err.find(c.message) != std::string::npos, true)
        << "expected '" << c.message << "' in: " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  EXPECT_FALSE(std::filesystem::exists(dir + "/color.png"));
}

TEST(RenderCommand, HelpPrintsUsageAndSucceeds) {
  const RunResult r = run({"--help"});
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(r.out.rfind("usage: sinew-editor render [OPTIONS] [MODEL]", 0), 0u) << r.out;
  EXPECT_NE(r.out.find("--triangle-test fast|watertight"), std::string::npos);
  EXPECT_TRUE(r.err.empty());
}

TEST(RenderCommand, OptionsMapToTheirSettings) {
  const auto o = parse_render_options({"m.glb", "--out=o", "--size", "64x32", "--pose-space", "clip:walk",
                                       "--samples", "0", "--triangle-test", "watertight", "--bone-boxes", "cheap",
                                       "--fallback", "off", "--shadows", "off", "--camera",
                                       "1,2,3,0,0,0,0,0,1,30", "--light", "4,5,6", "--instances", "3",
                                       "--time", "1.5"});
  ASSERT_TRUE(o.ok()) << o.status().message();
  EXPECT_EQ(o->model_path, "m.glb");
  EXPECT_EQ(o->out_dir, "o");
  EXPECT_EQ(o->width, 64);
  EXPECT_EQ(o->height, 32);
  EXPECT_EQ(o->pose_space->mode, anim::PoseSpaceMode::kClip);
  EXPECT_EQ(o->pose_space->clips, std::vector<std::string>{"walk"});
  EXPECT_EQ(o->triangle_test, rt::TriangleTest::kWatertight);
  EXPECT_EQ(o->bone_boxes, rt::BoneBoxMode::kCheap);
  EXPECT_FALSE(o->fallback);
  EXPECT_FALSE(o->shadows);
  ASSERT_TRUE(o->camera.has_value());
  EXPECT_EQ(o->camera->eye, Vec3(1.0f, 2.0f, 3.0f));
  EXPECT_EQ(o->camera->up, Vec3(0.0f, 0.0f, 1.0f));
  EXPECT_EQ(o->camera->fovy_degrees, 30.0f);
  ASSERT_EQ(o->lights.size(), 1u);
  EXPECT_EQ(o->lights[0].kind, rt::Light::Kind::kPoint);
  EXPECT_EQ(o->lights[0].position, Vec3(4.0f, 5.0f, 6.0f));
  EXPECT_EQ(o->lights[0].color, Vec3(1.0f));
  EXPECT_EQ(o->instances, 3);
  EXPECT_EQ(o->time_seconds, 1.5);

  const auto d = parse_render_options({"m.glb", "--out", "o"});
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d->width, 512);
  EXPECT_EQ(d->height, 512);
  EXPECT_TRUE(d->shadows);
  EXPECT_TRUE(d->fallback);
  EXPECT_EQ(d->frames, 1);
  EXPECT_EQ(d->instances, 1);
  EXPECT_EQ(d->threads, 0);
  EXPECT_FALSE(d->camera.has_value());
  EXPECT_FALSE(d->pose_space.has_value()) << "an in-memory bake samples only the rendered poses";
  const auto samples_only = parse_render_options({"m.glb", "--out", "o", "--samples", "7"});
  ASSERT_TRUE(samples_only.ok());
  EXPECT_EQ(samples_only->pose_space->mode, character::default_pose_space().mode);
  EXPECT_EQ(samples_only->pose_space->every_frame_30hz, character::default_pose_space().every_frame_30hz);
  EXPECT_EQ(samples_only->pose_space->samples, 7);

  EXPECT_TRUE(d->lights.empty());

  // Lights of both kinds, in the order given, each with its colour.
  const auto lit = parse_render_options({"m.glb", "--out", "o", "--light", "point:-2,5,3:0.8,0.5,0.25", "--light",
                                         "dir:0.5,1,-0.2", "--light=1,2,3:0,0,1"});
  ASSERT_TRUE(lit.ok()) << lit.status().message();
  ASSERT_EQ(lit->lights.size(), 3u);
  EXPECT_EQ(lit->lights[0].kind, rt::Light::Kind::kPoint);
  EXPECT_EQ(lit->lights[0].position, Vec3(-2.0f, 5.0f, 3.0f));
  EXPECT_EQ(lit->lights[0].color, Vec3(0.8f, 0.5f, 0.25f));
  EXPECT_EQ(lit->lights[1].kind, rt::Light::Kind::kDirectional);
  EXPECT_EQ(lit->lights[1].direction, Vec3(0.5f, 1.0f, -0.2f));
  EXPECT_EQ(lit->lights[1].color, Vec3(1.0f));
  EXPECT_EQ(lit->lights[2].position, Vec3(1.0f, 2.0f, 3.0f));
  EXPECT_EQ(lit->lights[2].color, Vec3(0.0f, 0.0f, 1.0f));

  const auto r = parse_render_options({"m.glb", "--out", "o", "--pose-space", "arbitrary", "--samples", "50",
                                       "--seed", "18446744073709551615"});
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->pose_space->mode, anim::PoseSpaceMode::kArbitrary);
  EXPECT_EQ(r->pose_space->samples, 50);
  EXPECT_EQ(r->pose_space->seed, 18446744073709551615ull);

  // The glTF import limits, each from its option; 0 is refused naming it.
  const auto limits = parse_render_options({"m.glb", "--out", "o", "--max-triangles", "7", "--max-clips", "8",
                                            "--max-keys", "9", "--max-nodes", "10", "--max-bytes", "11"});
  ASSERT_TRUE(limits.ok()) << limits.status().message();
  EXPECT_EQ(limits->gltf.limits.max_triangles, 7u);
  EXPECT_EQ(limits->gltf.limits.max_clips, 8u);
  EXPECT_EQ(limits->gltf.limits.max_keys, 9u);
  EXPECT_EQ(limits->gltf.limits.max_nodes, 10u);
  EXPECT_EQ(limits->gltf.limits.max_bytes, 11u);
  EXPECT_EQ(d->gltf.limits.max_nodes, ImportLimits{}.max_nodes);
  EXPECT_EQ(d->gltf.limits.max_bytes, ImportLimits{}.max_bytes);
  const auto zero = parse_render_options({"m.glb", "--out", "o", "--max-bytes", "0"});
  ASSERT_FALSE(zero.ok());
  EXPECT_NE(zero.status().message().find("--max-bytes = 0"), std::string::npos) << zero.status().message();
}

TEST(OptionValues, ParseTypedValuesAndRejectBadOnes) {
  using namespace sinew::cli;
  const auto f = parse_floats("--v", "1,-2.5,3e2", 3);
  ASSERT_TRUE(f.ok());
  EXPECT_EQ(*f, (std::vector<float>{1.0f, -2.5f, 300.0f}));
  EXPECT_FALSE(parse_floats("--v", "1,,3", 3).ok());
  EXPECT_FALSE(parse_floats("--v", "1,2,inf", 3).ok());
  EXPECT_FALSE(parse_floats("--v", "1,2,3,", 3).ok());
  const auto s = parse_size("--size", "640x480", 1000);
  ASSERT_TRUE(s.ok());
  EXPECT_EQ(s->width, 640);
  EXPECT_EQ(s->height, 480);
  for (const char* bad : {"0x5", "5x0", "x5", "5x", "1001x5", "-5x5", "5x5x5", "5 x5"}) {
    const auto e = parse_size("--size", bad, 1000);
    ASSERT_FALSE(e.ok()) << bad;
    EXPECT_EQ(e.status().field(), "--size");
    EXPECT_EQ(e.status().value(), bad);
  }
  EXPECT_EQ(*parse_int("--n", "-7", -10, 10), -7);
  EXPECT_FALSE(parse_int("--n", "11", -10, 10).ok());
  EXPECT_FALSE(parse_int("--n", "1.5", -10, 10).ok());
  EXPECT_EQ(*parse_double("--t", "0.25", 0.0, 1.0), 0.25);
  EXPECT_FALSE(parse_double("--t", "1.5", 0.0, 1.0).ok());
  EXPECT_EQ(*parse_choice("--c", "b", {"a", "b"}), 1);
  EXPECT_EQ(parse_choice("--c", "z", {"a", "b"}).status().message(), "--c = z: expected one of a|b");
  EXPECT_EQ(*parse_list("--l", "a,b"), (std::vector<std::string>{"a", "b"}));
  EXPECT_FALSE(parse_list("--l", "a,,b").ok());

}

// The convention every program shares (runtime/cli/command_line.h).
TEST(CommandLine, TakesBothFlagFormsAndNamesWhatIsWrong) {
  const auto parse = [](const std::vector<std::string>& args, std::string* x_out = nullptr) {
    cli::CommandLine line("tool", "what it does");
    const auto& positionals = line.positionals("FILE", "a file", 1);
    const auto& x = line.option("--x", "N", "a value");
    const bool& on = line.flag("--on", "a switch");
    auto result = line.parse(args);
    if (result.ok() && x_out != nullptr) *x_out = x.value_or("") + (on ? "+on" : "") + "|" +
                                                  (positionals.empty() ? "" : positionals.front());
    return result;
  };
  for (const std::vector<std::string>& form :
       {std::vector<std::string>{"pos", "--x=1", "--on"}, std::vector<std::string>{"--x", "1", "pos", "--on"}}) {
    std::string seen;
    const auto r = parse(form, &seen);
    ASSERT_TRUE(r.ok()) << r.status().message();
    EXPECT_EQ(*r, cli::ParseResult::kRun);
    EXPECT_EQ(seen, "1+on|pos");
  }
  std::string seen;
  ASSERT_TRUE(parse({"--", "--not-a-flag"}, &seen).ok());
  EXPECT_EQ(seen, "|--not-a-flag");
  EXPECT_EQ(*parse({"--help"}), cli::ParseResult::kHelp);
  EXPECT_EQ(*parse({"-h", "--bogus"}), cli::ParseResult::kHelp);
  EXPECT_EQ(parse({"--x", "1", "--x", "2"}).status().message(), "--x: given more than once");
  EXPECT_EQ(parse({"--y"}).status().message(), "option = --y: unknown option (see --help)");
  EXPECT_EQ(parse({"--x"}).status().message(), "--x: missing value");
  EXPECT_EQ(parse({"a", "b"}).status().message(), "argument = b: unexpected argument (at most 1)");

  cli::CommandLine line("tool", "what it does");
  line.option("--x", "N", "a value");
  const std::string help = line.help();
  EXPECT_EQ(help.rfind("usage: tool [OPTIONS]", 0), 0u) << help;
  EXPECT_NE(help.find("--x N"), std::string::npos) << help;
  EXPECT_NE(help.find("what it does"), std::string::npos) << help;
}

TEST(CommandLine, ACommandsArgumentsNeverStartAnotherCommand) {
  cli::CommandLine line("tool", "");
  line.command("report", "runs the others");
  line.command("tradeoff", "one of them");
  const auto parsed = line.parse({"report", "--sections", "tradeoff", "--quick"});
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  EXPECT_EQ(line.chosen_command(), "report");
  EXPECT_EQ(line.command_arguments(), (std::vector<std::string>{"--sections", "tradeoff", "--quick"}));
}

TEST(CommandLine, UsageErrorsAreOneLineAndExitCode2) {
  cli::CommandLine line("tool", "");
  std::ostringstream out, err;
  const auto done = cli::help_or_usage_error(line, line.parse({"--bogus"}), out, err);
  ASSERT_TRUE(done.has_value());
  EXPECT_EQ(*done, 2);
  EXPECT_EQ(err.str(), "tool: option = --bogus: unknown option (see --help)\n");
  EXPECT_TRUE(out.str().empty());
  std::ostringstream help_out, help_err;
  EXPECT_EQ(cli::help_or_usage_error(line, line.parse({"--help"}), help_out, help_err), 0);
  EXPECT_EQ(help_out.str(), line.help());
}

}  // namespace
}  // namespace sinew::editor
