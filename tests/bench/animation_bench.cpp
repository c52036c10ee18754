#include "tests/bench/animation_bench.h"

#include <cal3d/cal3d.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>

#include "animation/blend.h"
#include "animation/mixer.h"
#include "animation/pose.h"
#include "animation/reference_skinning.h"
#include "content/mannequin/mannequin.h"
#include "editor/import/cal3d_importer.h"
#include "runtime/cli/option_values.h"
#include "runtime/timing/phase_timers.h"
#include "runtime/timing/stopwatch.h"
#include "tests/bench/bench_options.h"
#include "tests/support/cal3d_support.h"

namespace sinew::bench {
namespace {

using Clock = std::chrono::steady_clock;


// Per-instance state on our side: what a game holds per character.
struct OurInstance {
  explicit OurInstance(const character::Model& m)
      : mixer(m.clips),
        caches(m.clips.size()),
        local(m.skeleton.joint_count()),
        model(m.skeleton.joint_count()),
        skin(m.skeleton.joint_count()),
        positions(m.mesh.vertex_count()) {}
  anim::Mixer mixer;
  std::vector<anim::SamplingCache> caches;
  anim::BlendScratch scratch;
  std::vector<anim::JointTransform> local;
  std::vector<Affine3> model;
  std::vector<Affine3> skin;
  std::vector<Vec3> positions;
};

struct Row {
  std::string model;
  int instances = 0;
  double ours_anim_us = 0.0;   // per instance per frame
  double ours_skin_mvps = 0.0;
  std::optional<double> cal_anim_us;
  std::optional<double> cal_skin_mvps;
};

Row bench_ours(const std::string& name, const character::Model& m, int instances, int frames,
               int walk_clip) {
  std::vector<std::unique_ptr<OurInstance>> pool;
  for (int i = 0; i < instances; ++i) {
    pool.push_back(std::make_unique<OurInstance>(m));
    (void)pool.back()->mixer.blend_cycle(walk_clip, 1.0f, 0.0f);
    pool.back()->mixer.update(0.013f * static_cast<float>(i));  // desynchronise instances
  }
  PhaseTimers timers;
  for (int f = 0; f < frames; ++f) {
    auto start = Clock::now();
    for (auto& inst : pool) {
      inst->mixer.update(1.0f / 30.0f);
      (void)anim::evaluate_layers(m.skeleton, m.clips, inst->mixer.layers(), inst->caches,
                                  inst->local, &inst->scratch);
      (void)anim::local_to_model(m.skeleton, inst->local, inst->model);
      (void)anim::skinning_matrices(m.skeleton, inst->model, Affine3::identity(), inst->skin);
    }
    timers.record("animation", ms_since(start));
    start = Clock::now();
    for (auto& inst : pool) (void)anim::skin_reference(m.mesh, inst->skin, inst->positions, {});
    timers.record("skinning", ms_since(start));
  }
  const auto s = timers.summarize();
  Row row;
  row.model = name;
  row.instances = instances;
  row.ours_anim_us = s[0].median_ms * 1000.0 / instances;
  row.ours_skin_mvps = double(m.mesh.vertex_count()) * instances / (s[1].median_ms * 1e-3) / 1e6;
  return row;
}

// Cal3D's side: its own core model of Cally, instances as CalModels.
void bench_cal3d(const std::string& dir, int instances, int frames, Row& row) {
  CalCoreModel core("bench");
  if (!core.loadCoreSkeleton(dir + "/cally.csf")) return;
  std::vector<int> meshes;
  for (const char* mesh : {"calf_left", "calf_right", "chest", "foot_left", "foot_right",
                           "hand_left", "hand_right", "head", "lowerarm_left", "lowerarm_right",
                           "neck", "pelvis", "ponytail", "thigh_left", "thigh_right",
                           "upperarm_left", "upperarm_right"}) {
    const int id = core.loadCoreMesh(dir + "/cally_" + mesh + ".cmf");
    if (id < 0) return;
    meshes.push_back(id);
  }
  const int walk = core.loadCoreAnimation(dir + "/cally_walk.caf");
  if (walk < 0) return;
  {
    std::vector<std::unique_ptr<CalModel>> pool;
    int vertex_count = 0;
    for (int i = 0; i < instances; ++i) {
      auto model = std::make_unique<CalModel>(&core);
      for (int id : meshes) model->attachMesh(id);
      model->disableInternalData();
      model->getMixer()->blendCycle(walk, 1.0f, 0.0f);
      model->getMixer()->updateAnimation(0.013f * static_cast<float>(i));
      pool.push_back(std::move(model));
    }
    for (int id : meshes) {
      for (CalSubmesh* sub : pool[0]->getMesh(id)->getVectorSubmesh()) vertex_count += sub->getVertexCount();
    }
    std::vector<float> buffer(static_cast<std::size_t>(vertex_count) * 3);
    PhaseTimers timers;
    for (int f = 0; f < frames; ++f) {
      auto start = Clock::now();
      for (auto& model : pool) {
        model->getMixer()->updateAnimation(1.0f / 30.0f);
        model->getMixer()->updateSkeleton();
      }
      timers.record("animation", ms_since(start));
      start = Clock::now();
      for (auto& model : pool) {
        float* out = buffer.data();
        for (int id : meshes) {
          for (CalSubmesh* sub : model->getMesh(id)->getVectorSubmesh()) {
            out += 3 * model->getPhysique()->calculateVertices(sub, out);
          }
        }
      }
      timers.record("skinning", ms_since(start));
    }
    const auto s = timers.summarize();
    row.cal_anim_us = s[0].median_ms * 1000.0 / instances;
    row.cal_skin_mvps = double(vertex_count) * instances / (s[1].median_ms * 1e-3) / 1e6;
  }
  testing_support::free_cal3d_animation_tracks(core);
}

struct AnimationBenchOptions {
  int frames = 60;
  std::string shared = SINEW_SHARED_DIR;
  bool help = false;
};

int walk_index(const character::Model& m) {
  for (std::size_t i = 0; i < m.clips.size(); ++i) {
    if (m.clips[i].name() == "walk") return static_cast<int>(i);
  }
  return 0;
}

}  // namespace

int run_animation_bench(const std::vector<std::string>& args) {
  BenchArgs options("animation", "Animation + skinning vs the Cal3D library.\n",
                    {frames_flag("frames per character (default 60)"), shared_flag()});
  const auto parsed = [&]() -> Expected<AnimationBenchOptions> {
    SINEW_ASSIGN_OR_RETURN(const cli::ParseResult result, options.parse(args));
    AnimationBenchOptions o;
    o.help = result == cli::ParseResult::kHelp;
    if (const auto text = options.value("--frames")) {
      SINEW_ASSIGN_OR_RETURN(const std::int64_t n, cli::parse_int("--frames", *text, 1, 1000000));
      o.frames = static_cast<int>(n);
    }
    if (const auto text = options.value("--shared")) o.shared = *text;
    return o;
  }();
  if (const std::optional<int> done = usage_exit(options, parsed)) return *done;
  const int frames = parsed->frames;
  const std::string& shared = parsed->shared;
  const std::string cally_dir = shared + "/content/cal3d/cally";
  auto cally = editor::import_cal3d(cally_dir + "/cally.cfg");
  if (!cally.ok()) {
    std::fprintf(stderr, "sinew-bench: %s\n", cally.status().message().c_str());
    return 1;
  }
  auto mannequin = content::make_mannequin();
  if (!mannequin.ok()) {
    std::fprintf(stderr, "sinew-bench: %s\n", mannequin.status().message().c_str());
    return 1;
  }

  std::vector<Row> rows;
  for (int n : {1, 10, 100}) {
    Row row = bench_ours("cally", *cally, n, frames, walk_index(*cally));
    bench_cal3d(cally_dir, n, frames, row);
    rows.push_back(row);
  }
  for (int n : {1, 10, 100}) rows.push_back(bench_ours("mannequin", *mannequin, n, frames, walk_index(*mannequin)));

  std::printf("animation: walk cycle, %d frames at 30 Hz, 1 thread; medians per frame\n", frames);
  std::printf("  animation = mixer update + sample/blend + local-to-model + skinning matrices\n");
  std::printf("  skinning  = Sinew's reference LBS (double precision; the SIMD kernel is raytrace's)\n");
  std::printf("              vs Cal3D CalPhysique::calculateVertices (positions only)\n\n");
  std::printf("%-10s %9s %14s %14s %10s %14s %14s\n", "model", "instances", "sinew us/inst",
              "cal3d us/inst", "ratio", "sinew Mvert/s", "cal3d Mvert/s");
  for (const Row& r : rows) {
    char cal_anim[32] = "n/a", ratio[32] = "n/a", cal_skin[32] = "n/a";
    if (r.cal_anim_us) {
      std::snprintf(cal_anim, sizeof cal_anim, "%.2f", *r.cal_anim_us);
      std::snprintf(ratio, sizeof ratio, "%.2f", *r.cal_anim_us / r.ours_anim_us);
      std::snprintf(cal_skin, sizeof cal_skin, "%.1f", *r.cal_skin_mvps);
    }
    std::printf("%-10s %9d %14.2f %14s %10s %14.1f %14s\n", r.model.c_str(), r.instances,
                r.ours_anim_us, cal_anim, ratio, r.ours_skin_mvps, cal_skin);
  }
  std::printf("\nratio = Cal3D time / Sinew time (above 1: Sinew is faster). The mannequin has no\n"
              "Cal3D files, so its Cal3D columns are n/a.\n");
  return 0;
}

}  // namespace sinew::bench
