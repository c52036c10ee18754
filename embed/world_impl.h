// World's state: the ray tracer's Scene plus, per instance, who drives it
// and (for the mixer) its animation state.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "animation/blend.h"
#include "animation/clip.h"
#include "animation/mixer.h"
#include "embed/character_impl.h"
#include "raytrace/scene/scene.h"
#include "runtime/jobs/job_system.h"
#include "runtime/math/affine.h"
#include "sinew/world.h"

namespace sinew::api {

struct World::Impl {
  struct Instance {
    bool removed = false;  // World::remove: its id is never given again
    bool is_static = false;
    std::shared_ptr<const Character::Impl> core;  // null for static meshes
    Driver driver = Driver::kMixer;
    Affine3 transform = Affine3::identity();
    bool limits = false;
    // Mixer-driven only.
    float speed = 1.0f;  // advance(dt) moves the mixer by speed * dt
    std::unique_ptr<anim::Mixer> mixer;
    std::vector<anim::SamplingCache> caches;
    std::vector<anim::JointTransform> local;
    std::vector<Affine3> model_pose;
    std::vector<Affine3> skin;
    anim::BlendScratch scratch;
  };

  // Declared before the scene: the scene points into these cores' meshes
  // and trees, so it must go first.
  std::vector<std::shared_ptr<const Character::Impl>> cores;  // by scene character index
  rt::Scene scene;
  std::vector<Instance> instances;  // by InstanceId (the scene's numbering)

  // What the scene's frame state (skinned positions, boxes, top level) was
  // last prepared from: queries prepare it again when anything moved since,
  // or when the last prepare left escaped triangles out (a pass without
  // the fallback).
  std::uint64_t changes = 1;           // bumped by every change to an instance
  std::uint64_t prepared_changes = 0;  // `changes` at the last prepare
  bool prepared_exact = false;
  // A batch of queries skins only the instances its rays reach (lazy
  // skinning); these are its rays, kept for the next batch's allocation.
  bool lazy_query_skinning = true;
  std::vector<sinew::Ray> query_rays;         // that prepare routed escaped triangles
  std::unique_ptr<JobSystem> query_jobs;  // one thread, made by the first query that prepares
  void changed() { ++changes; }
};

namespace detail {

// The character instance `id` (not removed, not a static mesh); `call`
// names the API call in the kNotFound error.
Result<World::Impl::Instance*> find_character(World::Impl& world, InstanceId id, const char* call);
// The same, and driven by `wanted` (kInvalidArgument otherwise).
Result<World::Impl::Instance*> find_instance(World::Impl& world, InstanceId id, Driver wanted, const char* call);
// Evaluates the mixer's layers and poses the instance in the scene.
Status pose_from_mixer(World::Impl& world, InstanceId id);

}  // namespace detail
}  // namespace sinew::api
