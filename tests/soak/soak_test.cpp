// The soak test (docs/ROBUSTNESS.md, "The soak test"): the demo's world run for a long time
// (20,000 frames by default; SINEW_SOAK_FRAMES overrides, SINEW_SOAK_SEED
// picks the seed) with random player input, random camera moves and random
// clip switches, rendered with every AOV at a small size. It checks that
//  * memory stays flat: RSS at the end within kMaxRssGrowth of RSS after the
//    warm-up (skipped under AddressSanitizer, whose quarantine grows RSS),
//  * poses inside the baked pose space never escape their fuzzy boxes,
//  * every AOV pixel is written, finite and self-consistent, every frame,
// and prints one summary line (frames, time, RSS, escapes, seed).
//
// The scene: the mannequin baked exactly as the demo bakes it (every clip at
// its key times and every 1/30 s, no padding), the demo's arena, the six
// World characters (NPC wandering, actions, the randomly driven player) plus
// three more instances of the same character:
//  * a "switcher" whose own mixer gets random clip switches (cycles blended
//    in and cleared, actions fired, locked and removed, sync toggled);
//  * two "probes" posed exactly at pose-space samples (a random clip, a
//    random sample time, then the next samples), switching clips at random.
// Blends of cycles, actions over cycles and the times between samples may
// legitimately leave the sampled pose space, so escapes of the World
// characters and the switcher are counted and printed, not failed on; the
// probes' poses are inside the space by construction, so any escape of
// theirs fails the test.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "animation/blend.h"
#include "animation/mixer.h"
#include "animation/pose.h"
#include "animation/pose_space.h"
#include "character/bake.h"
#include "content/mannequin/mannequin.h"
#include "game_demo/arena.h"
#include "game_demo/demo_session.h"
#include "game_demo/world.h"
#include "raytrace/camera/camera.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "runtime/jobs/job_system.h"
#include "runtime/math/ray.h"
#include "tests/support/aov_frame.h"

#if defined(__SANITIZE_ADDRESS__)
#define SINEW_SOAK_UNDER_ASAN 1
#else
#define SINEW_SOAK_UNDER_ASAN 0
#endif

namespace sinew::demo {
namespace {

constexpr int kDefaultFrames = 20'000;
constexpr std::uint32_t kDefaultSeed = 20261122u;
constexpr int kWorldCharacters = 6;
constexpr int kProbes = 2;
constexpr int kObstacles = 8;  // as many as the demo
constexpr int kImageSize = 96;
constexpr float kFrameStep = 1.0f / 30.0f;
constexpr float kPi = std::numbers::pi_v<float>;
// Memory must not grow by more than this between the end of the warm-up and
// the end of the run. Every per-frame buffer is sized once or reused, so the
// only legitimate growth is a vector that meets a new high-water mark (the
// fallback tree over the largest escape seen so far: tens of KB) plus
// allocator noise; a leak of even 300 bytes a frame over 19,000 frames
// (5.4 MB) would exceed it.
constexpr long kMaxRssGrowthBytes = 5L << 20;

// [0, 1) from the generator's top 24 bits (exact in a float).
float unit_float(std::mt19937& rng) { return static_cast<float>(rng() >> 8) * (1.0f / 16777216.0f); }
float in_range(std::mt19937& rng, float lo, float hi) { return lo + (hi - lo) * unit_float(rng); }
bool chance(std::mt19937& rng, float p) { return unit_float(rng) < p; }
int pick(std::mt19937& rng, int n) { return std::min(n - 1, static_cast<int>(unit_float(rng) * static_cast<float>(n))); }

long resident_bytes() {
  std::ifstream statm("/proc/self/statm");
  long size_pages = 0, resident_pages = 0;
  statm >> size_pages >> resident_pages;
  return resident_pages * sysconf(_SC_PAGESIZE);
}

// User + system CPU seconds of the process: the machine may be shared, so
// wall time alone says little about the cost.
double cpu_seconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  auto seconds = [](const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec); };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

double mib(long bytes) { return static_cast<double>(bytes) / (1024.0 * 1024.0); }

template <class T>
T env_or(const char* name, T fallback) {
  const char* text = std::getenv(name);
  if (text == nullptr || *text == '\0') return fallback;
  char* end = nullptr;
  const long long value = std::strtoll(text, &end, 10);
  if (*end != '\0' || value <= 0) {
    ADD_FAILURE() << name << "='" << text << "' is not a positive integer";
    return fallback;
  }
  return static_cast<T>(value);
}

Affine3 placement(const Vec3& position, float heading, const Affine3& model_to_world_matrix) {
  return Affine3::translation(position) *
         Affine3::from_trs(Vec3(0.0f), glm::angleAxis(heading, Vec3(0.0f, 1.0f, 0.0f)), Vec3(1.0f)) *
         model_to_world_matrix;
}

// Player keys held for a random while, edges (action, Tab) now and then.
class RandomPlayer {
 public:
  PlayerInput next(std::mt19937& rng) {
    if (--hold_ <= 0) {
      hold_ = 1 + pick(rng, 90);
      held_.forward = chance(rng, 0.3f) ? 0.0f : in_range(rng, -1.0f, 1.0f);
      held_.right = chance(rng, 0.5f) ? 0.0f : in_range(rng, -1.0f, 1.0f);
      held_.run = chance(rng, 0.3f);
    }
    PlayerInput input = held_;
    input.action = chance(rng, 1.0f / 60.0f);
    input.next_character = chance(rng, 1.0f / 400.0f);
    return input;
  }

 private:
  int hold_ = 0;
  PlayerInput held_;
};

// The follow camera drifting, jumping now and then, and sometimes a free
// camera anywhere over the arena looking anywhere (not straight up or down).
class RandomCamera {
 public:
  rt::CameraDesc next(std::mt19937& rng, const Vec3& player) {
    if (chance(rng, 0.01f)) {
      follow_.yaw = in_range(rng, -kPi, kPi);
      follow_.pitch = in_range(rng, -0.3f, 1.4f);
      follow_.distance = in_range(rng, 0.5f, 25.0f);
      follow_.fovy_degrees = in_range(rng, 15.0f, 120.0f);
    } else {
      follow_.yaw = std::remainder(follow_.yaw + in_range(rng, -0.05f, 0.05f), 2.0f * kPi);
      follow_.pitch = std::clamp(follow_.pitch + in_range(rng, -0.02f, 0.02f), -0.3f, 1.4f);
      follow_.distance = std::clamp(follow_.distance + in_range(rng, -0.1f, 0.1f), 0.5f, 25.0f);
    }
    if (free_frames_ > 0 || chance(rng, 0.005f)) {
      if (free_frames_ <= 0) {
        free_frames_ = 1 + pick(rng, 60);
        free_.eye = Vec3(in_range(rng, -16.0f, 16.0f), in_range(rng, 0.05f, 8.0f), in_range(rng, -16.0f, 16.0f));
        const float yaw = in_range(rng, -kPi, kPi), pitch = in_range(rng, -1.3f, 1.3f);
        free_.target = free_.eye + Vec3(std::sin(yaw) * std::cos(pitch), std::sin(pitch), std::cos(yaw) * std::cos(pitch));
        free_.fovy_degrees = in_range(rng, 15.0f, 120.0f);
      }
      --free_frames_;
      return free_;
    }
    return follow_camera_desc(follow_, player);
  }
  float yaw() const { return follow_.yaw; }

 private:
  FollowCamera follow_;
  rt::CameraDesc free_;
  int free_frames_ = 0;
};

// An extra instance posed by its own skeleton evaluation.
struct Puppet {
  std::vector<anim::JointTransform> local;
  std::vector<Affine3> model_pose;
  std::vector<Affine3> skin;
  std::vector<anim::SamplingCache> caches;
  anim::BlendScratch scratch;
  std::uint32_t instance = 0;

  Puppet(const character::Model& model, std::uint32_t id)
      : local(model.skeleton.joint_count()),
        model_pose(model.skeleton.joint_count()),
        skin(model.skeleton.joint_count()),
        caches(model.clips.size()),
        instance(id) {
    for (std::size_t k = 0; k < model.clips.size(); ++k) caches[k].reset(model.clips[k]);
  }

  Status finish(const character::Model& model, const Affine3& world) {
    SINEW_RETURN_IF_ERROR(anim::local_to_model(model.skeleton, local, model_pose));
    return anim::skinning_matrices(model.skeleton, model_pose, world, skin);
  }
};

// Random clip switches on a mixer of its own: any clip as a cycle or an
// action, with random weights and fades. The state stays bounded (at most a
// few actions, cycles cleared when many pile up) so its memory is flat by
// design and any growth is the library's.
void switch_clips_at_random(anim::Mixer& mixer, int clips, std::mt19937& rng, std::uint64_t& switches) {
  if (!chance(rng, 1.0f / 15.0f)) return;
  ++switches;
  const int clip = pick(rng, clips);
  switch (pick(rng, 6)) {
    case 0:
    case 1: (void)mixer.blend_cycle(clip, in_range(rng, 0.0f, 1.0f), in_range(rng, 0.0f, 0.6f)); break;
    case 2: (void)mixer.clear_cycle(clip, in_range(rng, 0.0f, 0.6f)); break;
    case 3:
      (void)mixer.execute_action(clip, in_range(rng, 0.0f, 0.4f), in_range(rng, 0.0f, 0.4f),
                                 in_range(rng, 0.1f, 1.0f), chance(rng, 0.2f));
      break;
    case 4: (void)mixer.remove_action(clip); break;  // kNotFound when none runs: fine
    default: mixer.set_synchronized_cycles(chance(rng, 0.5f)); break;
  }
  // Locked actions stay until removed; keep the puppet's state bounded.
  for (int c = 0; c < clips && mixer.action_count() > 4; ++c) (void)mixer.remove_action(c);
  if (mixer.cycle_count() > 8) {
    for (int c = 0; c < clips; ++c) (void)mixer.clear_cycle(c, 0.0f);
  }
}

// A probe: one clip alone over the rest pose at one of the bake's own
// sample times, exactly as the bake's pose space visits it.
struct Probe {
  int clip = 0;
  std::size_t sample = 0;
};

void advance_probe(Probe& probe, const std::vector<std::vector<float>>& sample_times, std::mt19937& rng) {
  if (chance(rng, 0.05f)) {
    probe.clip = pick(rng, static_cast<int>(sample_times.size()));
    probe.sample = static_cast<std::size_t>(pick(rng, static_cast<int>(sample_times[static_cast<std::size_t>(probe.clip)].size())));
  } else {
    probe.sample = (probe.sample + 1) % sample_times[static_cast<std::size_t>(probe.clip)].size();
  }
}

using Aovs = testing_support::AovFrame;

bool finite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Empty when every pixel is consistent; otherwise what is wrong with the
// first bad pixel. A pixel is a hit in every AOV or a miss in every AOV.
// (The shading normal is only flipped to the geometric normal's side, so at
// silhouettes it may point slightly away from the camera: not checked.)
std::string check_aovs(const Aovs& aovs, const rt::Scene& scene, int width, const rt::RenderSettings& settings) {
  for (std::size_t i = 0; i < aovs.depth.size(); ++i) {
    const int x = static_cast<int>(i) % width, y = static_cast<int>(i) / width;
    std::ostringstream where;
    where << "pixel (" << x << ", " << y << "): ";
    for (int c = 0; c < 4; ++c) {
      const float v = aovs.rgba32f[4 * i + static_cast<std::size_t>(c)];
      if (!std::isfinite(v) || v < 0.0f) return where.str() + "colour channel " + std::to_string(c) + " = " + std::to_string(v);
    }
    if (aovs.rgba32f[4 * i + 3] != 1.0f || aovs.rgba8[4 * i + 3] != 255) return where.str() + "alpha is not opaque";
    const float depth = aovs.depth[i];
    const Vec3 n = aovs.normal[i];
    const std::uint32_t instance = aovs.instance_id[i], triangle = aovs.triangle_id[i];
    if (!finite(n)) return where.str() + "non-finite normal";
    if (std::isnan(depth)) return where.str() + "depth is NaN (or never written)";
    const bool miss = depth == std::numeric_limits<float>::infinity();
    if (miss) {
      if (instance != kInvalidId || triangle != kInvalidId) return where.str() + "a miss with an id";
      if (n != Vec3(0.0f)) return where.str() + "a miss with a non-zero normal";
      for (int c = 0; c < 3; ++c) {
        if (aovs.rgba32f[4 * i + static_cast<std::size_t>(c)] != settings.background[c]) {
          return where.str() + "a miss that is not the background colour";
        }
      }
      continue;
    }
    if (!std::isfinite(depth) || depth < 0.0f) return where.str() + "depth " + std::to_string(depth);
    if (instance >= scene.object_slots().size()) return where.str() + "instance id " + std::to_string(instance);
    const rt::Scene::ObjectSlot slot = scene.object_slots()[instance];
    const std::size_t triangles =
        slot.kind == rt::Scene::ObjectKind::kStatic
            ? scene.static_meshes()[slot.index].desc.triangles.size()
            : scene.characters()[scene.instances()[slot.index].character].mesh->triangle_count();
    if (triangle >= triangles) {
      return where.str() + "triangle id " + std::to_string(triangle) + " of instance " + std::to_string(instance) +
             " with " + std::to_string(triangles) + " triangles";
    }
    if (std::abs(glm::length(n) - 1.0f) > 1e-3f) return where.str() + "normal not unit: " + std::to_string(glm::length(n));
  }
  return {};
}

struct EscapeTally {
  std::uint64_t checks = 0;
  std::uint64_t triangles = 0;
  std::uint64_t frames = 0;  // frames with at least one escaped check
  std::size_t max_checks = 0;
  void add(std::size_t frame_checks, std::size_t frame_triangles) {
    checks += frame_checks;
    triangles += frame_triangles;
    frames += frame_checks > 0 ? 1 : 0;
    max_checks = std::max(max_checks, frame_checks);
  }
  std::string text() const {
    return std::to_string(checks) + " checks / " + std::to_string(triangles) + " triangles in " +
           std::to_string(frames) + " frames (max " + std::to_string(max_checks) + "/frame)";
  }
};

TEST(Soak, LongRandomRunKeepsMemoryFlatPoseSpaceInsideAndAovsClean) {
  const int frames = env_or<int>("SINEW_SOAK_FRAMES", kDefaultFrames);
  const std::uint32_t seed = env_or<std::uint32_t>("SINEW_SOAK_SEED", kDefaultSeed);
  // RSS is read after the warm-up frame, half way and at the end.
  const int warm_frame = std::max(1, std::min(1000, frames / 10));
  const int middle_frame = frames / 2;
  std::mt19937 rng(seed);
  JobSystem jobs(0);

  const long rss_start = resident_bytes();
  auto made = content::make_mannequin();
  ASSERT_TRUE(made.ok()) << made.status().message();
  const character::Model& model = *made;
  const Affine3 to_world = model_to_world(model);
  // The demo's bake: every clip at its key times and every 1/30 s.
  const character::BakeRequest request;
  auto bake = character::bake_in_memory(model, request, jobs);
  ASSERT_TRUE(bake.ok()) << bake.status().message();
  ASSERT_EQ(request.pose_space.mode, anim::PoseSpaceMode::kClips);
  ASSERT_TRUE(request.pose_space.every_frame_30hz);
  std::vector<std::vector<float>> sample_times;
  for (const anim::Clip& clip : model.clips) sample_times.push_back(anim::clip_sample_times(clip, true));

  const Arena arena = Arena::generate(seed, kObstacles);
  WorldOptions world_options;
  world_options.characters = kWorldCharacters;
  world_options.seed = seed;
  world_options.arena_half_size = arena.walk_half_size;
  world_options.obstacles = arena.obstacles;
  world_options.model_to_world = to_world;
  auto created = World::create(model, world_options);
  ASSERT_TRUE(created.ok()) << created.status().message();
  World& world = *created;

  rt::Scene scene;
  auto character = scene.add_character(model.mesh, bake->fuzzy.view());
  ASSERT_TRUE(character.ok()) << character.status().message();
  for (const rt::StaticMeshDesc& mesh : arena.static_meshes()) ASSERT_TRUE(scene.add_static_mesh(mesh).ok());
  std::vector<std::uint32_t> world_instances;
  std::vector<Puppet> puppets;  // [0] the switcher, then the probes
  for (int i = 0; i < kWorldCharacters + 1 + kProbes; ++i) {
    auto instance = scene.add_instance(*character);
    ASSERT_TRUE(instance.ok()) << instance.status().message();
    if (i < kWorldCharacters) {
      world_instances.push_back(*instance);
    } else {
      puppets.emplace_back(model, *instance);
    }
  }
  anim::Mixer switcher(model.clips);
  ASSERT_TRUE(switcher.blend_cycle(0, 1.0f, 0.0f).ok());
  std::array<Probe, kProbes> probes{};

  rt::RenderSettings settings;
  settings.light.kind = rt::Light::Kind::kPoint;
  settings.light.position = arena.light_position;
  settings.background = Vec3(0.30f, 0.38f, 0.50f);
  rt::Renderer renderer;
  Aovs aovs(kImageSize, kImageSize);
  RandomPlayer player;
  RandomCamera camera;

  // World characters posed by one clip alone (one layer: a single cycle,
  // no action), i.e. a clip between its sample times.
  EscapeTally single_clip_escapes;
  std::uint64_t single_clip_poses = 0;
  EscapeTally world_escapes, switcher_escapes, probe_escapes, total_escapes;
  std::string first_probe_escape, aov_failure;
  std::uint64_t clip_switches = 0, primary_hits = 0;
  long rss_warm = 0, rss_middle = 0;
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = cpu_seconds();
  int frame = 0;
  for (; frame < frames; ++frame) {
    // Mostly 30 fps; now and then a short, long or empty step.
    const float dt = chance(rng, 0.05f) ? in_range(rng, 0.0f, 0.3f) : kFrameStep;
    PlayerInput input = player.next(rng);
    input.camera_yaw = camera.yaw();
    world.step(dt, input);
    for (int i = 0; i < kWorldCharacters; ++i) {
      ASSERT_TRUE(scene.set_bones(world_instances[static_cast<std::size_t>(i)], world.skinning(i)).ok());
    }
    // The extra instances stand around the player so the camera sees them.
    const CharacterState& lead = world.character(world.player());
    auto beside_player = [&](int k) {
      const float angle = lead.heading + 0.9f * static_cast<float>(k + 1);
      return lead.position + 1.6f * Vec3(std::sin(angle), 0.0f, std::cos(angle));
    };

    switch_clips_at_random(switcher, static_cast<int>(model.clips.size()), rng, clip_switches);
    switcher.update(dt);
    Puppet& s = puppets[0];
    ASSERT_TRUE(anim::evaluate_layers(model.skeleton, model.clips, switcher.layers(), s.caches, s.local, &s.scratch).ok());
    ASSERT_TRUE(s.finish(model, placement(beside_player(0), lead.heading, to_world)).ok());
    ASSERT_TRUE(scene.set_bones(s.instance, s.skin).ok());
    for (int k = 0; k < kProbes; ++k) {
      Probe& probe = probes[static_cast<std::size_t>(k)];
      advance_probe(probe, sample_times, rng);
      Puppet& p = puppets[static_cast<std::size_t>(1 + k)];
      const auto clip = static_cast<std::size_t>(probe.clip);
      ASSERT_TRUE(anim::rest_pose(model.skeleton, p.local).ok());
      anim::sample_clip(model.clips[clip], sample_times[clip][probe.sample], p.caches[clip], p.local);
      ASSERT_TRUE(p.finish(model, placement(beside_player(1 + k), in_range(rng, -kPi, kPi), to_world)).ok());
      ASSERT_TRUE(scene.set_bones(p.instance, p.skin).ok());
    }

    auto stats = scene.prepare_frame(rt::FrameOptions{}, jobs);
    ASSERT_TRUE(stats.ok()) << stats.status().message();
    ASSERT_EQ(stats->singular_bones, 0u) << "frame " << frame;
    total_escapes.add(stats->escaped_checks, stats->escaped_triangles);
    auto tally = [&](std::uint32_t instance, EscapeTally& into) {
      const rt::InstanceFrame& f = scene.instances()[scene.object_slots()[instance].index];
      into.add(f.escaped_checks, f.escaped_triangles.size());
      return &f;
    };
    for (int i = 0; i < kWorldCharacters; ++i) {
      const rt::InstanceFrame* f = tally(world_instances[static_cast<std::size_t>(i)], world_escapes);
      if (world.mixer(i).layers().size() == 1) {
        ++single_clip_poses;
        single_clip_escapes.add(f->escaped_checks, f->escaped_triangles.size());
      }
    }
    tally(puppets[0].instance, switcher_escapes);
    for (int k = 0; k < kProbes; ++k) {
      const std::size_t escaped = tally(puppets[static_cast<std::size_t>(1 + k)].instance, probe_escapes)->escaped_checks;
      if (escaped > 0 && first_probe_escape.empty()) {
        const Probe& probe = probes[static_cast<std::size_t>(k)];
        const auto clip = static_cast<std::size_t>(probe.clip);
        first_probe_escape = "frame " + std::to_string(frame) + ": probe " + std::to_string(k) + ", clip '" +
                             model.clips[clip].name() + "' at sample time " +
                             std::to_string(sample_times[clip][probe.sample]) + ": " + std::to_string(escaped) +
                             " escaped checks";
      }
    }

    auto cam = rt::PinholeCamera::create(camera.next(rng, lead.position), kImageSize, kImageSize);
    ASSERT_TRUE(cam.ok()) << "frame " << frame << ": " << cam.status().message();
    aovs.poison();
    auto rendered = renderer.render(scene, *cam, settings, aovs.buffers(), jobs);
    ASSERT_TRUE(rendered.ok()) << rendered.status().message();
    primary_hits += rendered->primary_hits;
    aov_failure = check_aovs(aovs, scene, kImageSize, settings);
    if (!aov_failure.empty()) {
      aov_failure = "frame " + std::to_string(frame) + ", " + aov_failure;
      break;
    }

    if (frame + 1 == warm_frame) rss_warm = resident_bytes();
    if (frame + 1 == middle_frame) rss_middle = resident_bytes();
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double cpu = cpu_seconds() - cpu_start;
  const long rss_end = resident_bytes();

  std::printf(
      "soak: seed %u, %d frames of %d (%dx%d, %d instances, %u threads) in %.1f s (%.2f ms/frame; CPU %.1f s, %.2f ms/frame); RSS MiB: "
      "start %.1f, after frame %d %.1f, middle %.1f, end %.1f (end - warm-up %+.2f); clip switches %llu, "
      "actions %llu, primary hits %llu\n"
      "soak: escapes (vertex-bone checks outside their fuzzy boxes / triangles to the fallback): all %s; world "
      "characters %s (of which in %llu single-clip poses: %s); switcher %s; pose-space probes %s\n",
      seed, frame, frames, kImageSize, kImageSize, kWorldCharacters + 1 + kProbes,
      static_cast<unsigned>(jobs.thread_count()), seconds, 1000.0 * seconds / std::max(frame, 1), cpu, 1000.0 * cpu / std::max(frame, 1), mib(rss_start),
      warm_frame, mib(rss_warm), mib(rss_middle), mib(rss_end), mib(rss_end - rss_warm),
      static_cast<unsigned long long>(clip_switches), static_cast<unsigned long long>(world.actions_started()),
      static_cast<unsigned long long>(primary_hits), total_escapes.text().c_str(), world_escapes.text().c_str(),
      static_cast<unsigned long long>(single_clip_poses), single_clip_escapes.text().c_str(),
      switcher_escapes.text().c_str(), probe_escapes.text().c_str());
  std::fflush(stdout);

  EXPECT_TRUE(aov_failure.empty()) << aov_failure;
  EXPECT_EQ(probe_escapes.checks, 0u) << "a pose of the baked pose space escaped; first: " << first_probe_escape;
  EXPECT_GT(primary_hits, 0u);
  EXPECT_GT(world.actions_started(), 0u);
  if (!SINEW_SOAK_UNDER_ASAN) {
    EXPECT_LT(rss_end - rss_warm, kMaxRssGrowthBytes)
        << "memory grew from " << mib(rss_warm) << " MiB after frame " << warm_frame << " to " << mib(rss_end)
        << " MiB at the end";
  }
}

}  // namespace
}  // namespace sinew::demo
