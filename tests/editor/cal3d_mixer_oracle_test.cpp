// The mixer against the Cal3D library: two blended cycles with fades plus an
// action with fade-in and fade-out, driven by the same update steps on both
// sides, compared bone by bone and vertex by vertex on Cally (the blending
// oracle of docs/ANIMATION.md, "Tests"), and the same on Paladin at its .cfg
// scale of 0.5. The same again with the mixer's time factor (Cal3D's
// CalMixer::setTimeFactor) changed mid-script: faster, backwards, back to 1.
// Complements the single-clip oracle in cal3d_import_test.cpp.
#include <gtest/gtest.h>

#include <cal3d/cal3d.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "animation/blend.h"
#include "animation/mixer.h"
#include "animation/pose.h"
#include "animation/reference_skinning.h"
#include "editor/import/cal3d_importer.h"
#include "tests/support/cal3d_support.h"

namespace sinew::editor {
namespace {

std::string model_file(const std::string& model, const std::string& file) {
  return std::string(SINEW_SHARED_DIR) + "/content/cal3d/" + model + "/" + file;
}

// Cal3D's side: its own core model from the same files.
struct CalSide {
  CalCoreModel core{"oracle"};
  std::vector<int> mesh_ids;
  ~CalSide() { testing_support::free_cal3d_animation_tracks(core); }
};

struct Errors {
  double joint = 0.0;
  double vertex = 0.0;
  int samples = 0;
};

int clip_index(const character::Model& model, const std::string& name) {
  for (std::size_t i = 0; i < model.clips.size(); ++i) {
    if (model.clips[i].name() == name) return static_cast<int>(i);
  }
  return -1;
}

void run_mixer_oracle(const std::string& name, bool time_factor = false) {
  auto ours = import_cal3d(model_file(name, name + ".cfg"));
  ASSERT_TRUE(ours.ok()) << ours.status().message();

  // Cal3D's own model from the file names the .cfg lists, at the .cfg scale.
  std::ifstream in(model_file(name, name + ".cfg"));
  std::stringstream text;
  text << in.rdbuf();
  auto cfg = parse_cal3d_config(text.str(), name + ".cfg");
  ASSERT_TRUE(cfg.ok()) << cfg.status().message();
  CalSide cal3d;
  ASSERT_TRUE(cal3d.core.loadCoreSkeleton(model_file(name, cfg->skeleton)));
  for (const std::string& mesh : cfg->meshes) {
    const int id = cal3d.core.loadCoreMesh(model_file(name, mesh));
    ASSERT_GE(id, 0) << mesh;
    cal3d.mesh_ids.push_back(id);
  }
  if (cfg->scale != 1.0f) cal3d.core.scale(cfg->scale);  // skeleton and meshes
  auto load_clip = [&](const char* clip) {
    const int id = cal3d.core.loadCoreAnimation(model_file(name, name + "_" + clip + ".caf"));
    // CalCoreModel::scale scaled what was loaded before: scale the clip too.
    if (id >= 0 && cfg->scale != 1.0f) cal3d.core.getCoreAnimation(id)->scale(cfg->scale);
    return id;
  };
  const int cal_walk = load_clip("walk");
  const int cal_jog = load_clip("jog");
  const int cal_wave = load_clip("wave");
  ASSERT_GE(cal_walk, 0);
  ASSERT_GE(cal_jog, 0);
  ASSERT_GE(cal_wave, 0);

  CalModel cal(&cal3d.core);
  for (int id : cal3d.mesh_ids) ASSERT_TRUE(cal.attachMesh(id));
  cal.disableInternalData();  // skin every vertex; springs never run
  CalMixer* cal_mixer = cal.getMixer();
  // Cal3D appends a loop-closing key to a clip the first time it is blended
  // as a cycle; our importer appends it to every clip. Blend the action's
  // clip once and clear it so both sides sample the same keys.
  ASSERT_TRUE(cal_mixer->blendCycle(cal_wave, 1.0f, 0.0f));
  ASSERT_TRUE(cal_mixer->clearCycle(cal_wave, 0.0f));
  cal_mixer->updateAnimation(0.0f);

  const int walk = clip_index(*ours, "walk");
  const int jog = clip_index(*ours, "jog");
  const int wave = clip_index(*ours, "wave");
  ASSERT_GE(walk, 0);
  ASSERT_GE(jog, 0);
  ASSERT_GE(wave, 0);
  anim::Mixer mixer(ours->clips);

  // The script, applied to both sides: walk fades in, jog joins at 0.4
  // weight, the wave action fades in and out on top, walk is cleared late.
  struct Command {
    int step;
    void (*apply)(CalMixer&, anim::Mixer&, const int*, const int*);
  };
  const int cal_ids[3] = {cal_walk, cal_jog, cal_wave};
  const int our_ids[3] = {walk, jog, wave};
  std::vector<Command> script = {
      {0, [](CalMixer& c, anim::Mixer& m, const int* ci, const int* oi) {
         c.blendCycle(ci[0], 1.0f, 0.3f);
         ASSERT_TRUE(m.blend_cycle(oi[0], 1.0f, 0.3f).ok());
       }},
      {5, [](CalMixer& c, anim::Mixer& m, const int* ci, const int* oi) {
         c.blendCycle(ci[1], 0.4f, 0.5f);
         ASSERT_TRUE(m.blend_cycle(oi[1], 0.4f, 0.5f).ok());
       }},
      {12, [](CalMixer& c, anim::Mixer& m, const int* ci, const int* oi) {
         c.executeAction(ci[2], 0.4f, 0.6f, 0.8f, false);
         ASSERT_TRUE(m.execute_action(oi[2], 0.4f, 0.6f, 0.8f, false).ok());
       }},
      {90, [](CalMixer& c, anim::Mixer& m, const int* ci, const int* oi) {
         c.clearCycle(ci[0], 0.5f);
         ASSERT_TRUE(m.clear_cycle(oi[0], 0.5f).ok());
       }},
  };
  if (time_factor) {
    // Back to 1 before walk is cleared at step 90: with the clock running
    // backwards there, it sits past the shortened period for one frame, and
    // that frame differs from Cal3D's (docs/ANIMATION.md, "Mixer").
    script.push_back({30, [](CalMixer& c, anim::Mixer& m, const int*, const int*) {
                        c.setTimeFactor(1.6f);
                        ASSERT_TRUE(m.set_time_factor(1.6f).ok());
                      }});
    script.push_back({55, [](CalMixer& c, anim::Mixer& m, const int*, const int*) {
                        c.setTimeFactor(-0.7f);
                        ASSERT_TRUE(m.set_time_factor(-0.7f).ok());
                      }});
    script.push_back({80, [](CalMixer& c, anim::Mixer& m, const int*, const int*) {
                        c.setTimeFactor(1.0f);
                        ASSERT_TRUE(m.set_time_factor(1.0f).ok());
                      }});
  }

  const anim::Skeleton& skel = ours->skeleton;
  std::vector<anim::JointTransform> local(skel.joint_count());
  std::vector<Affine3> model_m(skel.joint_count()), skin(skel.joint_count());
  std::vector<Vec3> positions(ours->mesh.vertex_count());
  std::vector<anim::SamplingCache> caches(ours->clips.size());
  anim::BlendScratch scratch;
  const double diag = testing_support::bbox_diagonal(ours->mesh);
  std::vector<CalBone*>& bones = cal.getSkeleton()->getVectorBone();
  ASSERT_EQ(bones.size(), skel.joint_count());

  Errors err;
  const float dt = 1.0f / 30.0f;
  for (int step = 0; step < 120; ++step) {
    for (const Command& c : script) {
      if (c.step == step) c.apply(*cal_mixer, mixer, cal_ids, our_ids);
    }
    cal_mixer->updateAnimation(dt);
    cal_mixer->updateSkeleton();
    mixer.update(dt);
    ASSERT_TRUE(anim::evaluate_layers(skel, ours->clips, mixer.layers(), caches, local, &scratch).ok());
    ASSERT_TRUE(anim::local_to_model(skel, local, model_m).ok());
    ASSERT_TRUE(anim::skinning_matrices(skel, model_m, Affine3::identity(), skin).ok());
    ASSERT_TRUE(anim::skin_reference(ours->mesh, skin, positions, {}).ok());

    for (CalBone* bone : bones) {
      const auto j = skel.find(bone->getCoreBone()->getName());
      ASSERT_TRUE(j.has_value());
      const CalVector& t = bone->getTranslationAbsolute();
      const Vec3 d = model_m[static_cast<std::size_t>(*j)].translation_part() - Vec3(t.x, t.y, t.z);
      err.joint = std::max(err.joint, static_cast<double>(glm::length(d)) / diag);
    }
    const auto vertex_error =
        testing_support::max_vertex_error_vs_cal3d(cal, cal3d.mesh_ids, positions, diag);
    ASSERT_TRUE(vertex_error.has_value()) << "vertex counts differ from Cal3D's";
    err.vertex = std::max(err.vertex, *vertex_error);
    ++err.samples;
  }
  std::printf("[mixer oracle] %s walk+jog+wave%s, %d frames: joint %.3g, vertex %.3g (of bbox diagonal)\n",
              name.c_str(), time_factor ? " with time factors" : "", err.samples, err.joint, err.vertex);
  EXPECT_LT(err.joint, 1e-4);
  EXPECT_LT(err.vertex, 1e-4);
}

TEST(Cal3dMixerOracle, CallyTwoCyclesAndAnActionMatchCal3d) { run_mixer_oracle("cally"); }

TEST(Cal3dMixerOracle, PaladinTwoCyclesAndAnActionMatchCal3d) { run_mixer_oracle("paladin"); }

TEST(Cal3dMixerOracle, CallyTimeFactorsMatchCal3d) { run_mixer_oracle("cally", /*time_factor=*/true); }

}  // namespace
}  // namespace sinew::editor
