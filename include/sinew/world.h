// The world a ray-trace pass renders: instances of characters, each driven
// either by Sinew's own animation mixer (Cal3D semantics: blended cycles,
// one-shot actions with fades) or by the host's animation system, which
// hands over one 3x4 skinning matrix per bone each frame; plus optional
// static geometry (a level, a ground) in world space.
//
// A World is not thread-safe: drive it from one thread, between passes. The
// pass itself runs its work on many threads (sinew/pass.h).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string_view>

#include "sinew/character.h"
#include "sinew/export.h"
#include "sinew/math.h"
#include "sinew/result.h"

namespace sinew::api {

// Instance and static-mesh ids share one numbering: the values of the
// pass's instance-id output.
using InstanceId = std::uint32_t;
inline constexpr std::uint32_t kNoHit = 0xFFFFFFFFu;  // id outputs on a miss

enum class Driver : std::uint8_t {
  kMixer,  // World::play_cycle / play_action / advance pose it
  kHost,   // the host calls World::set_bone_matrices every frame it moves
};

struct InstanceDesc {
  Driver driver = Driver::kMixer;
  // Mixer-driven: model -> world placement (set_transform changes it).
  // Host-driven instances ignore it: their matrices already go to world.
  Matrix3x4 transform = Matrix3x4::identity();
  // Mixer-driven: clamp each pose to the pack's joint limits (when it has
  // any) before skinning.
  bool apply_joint_limits = false;
};

// A static triangle mesh in world space; copied, its kd-tree built once.
struct StaticMeshDesc {
  std::span<const Float3> positions;
  std::span<const std::uint32_t> indices;  // three per triangle
  Float3 color{0.6f, 0.6f, 0.6f};          // linear RGB albedo
};

class SINEW_API World {
 public:
  // Errors: kOutOfMemory.
  static Result<World> create() noexcept;
  ~World();
  World(World&&) noexcept;
  World& operator=(World&&) noexcept;
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  // An instance of `character`, at its bind pose until posed. Errors:
  // kInvalidArgument (non-finite transform), kLimitExceeded (2^24 instances).
  Result<InstanceId> add_instance(const Character& character, const InstanceDesc& desc = {}) noexcept;
  // Errors: kInvalidArgument (index count not a multiple of 3, an index
  // past the positions, non-finite positions, no triangles).
  Result<InstanceId> add_static_mesh(const StaticMeshDesc& mesh) noexcept;

  // Host-driven instances: this frame's skinning matrices (bind pose ->
  // world), one per bone in Character::bone_name order; copied. Identity
  // matrices show the mesh as stored in the pack (its bind pose), which can
  // differ from the skeleton's rest pose a mixer-driven instance starts in
  // (glTF files whose root node turns the skeleton, say). Errors:
  // kNotFound (no such instance), kInvalidArgument (a mixer-driven
  // instance, the wrong count, a non-finite matrix — nothing is changed).
  Status set_bone_matrices(InstanceId instance, std::span<const Matrix3x4> skinning) noexcept;

  // Mixer-driven instances. Clips by name or "#<index>". A cycle started on
  // an idle mixer starts its clock at once: the next advance(dt) plays it dt
  // seconds in (Cal3D's own mixer would spend that first update starting
  // the clock). Errors: kNotFound (instance or clip), kInvalidArgument (a
  // host-driven instance, negative or non-finite weights and times).
  Status set_transform(InstanceId instance, const Matrix3x4& model_to_world) noexcept;
  Status play_cycle(InstanceId instance, std::string_view clip, float weight, float fade_seconds) noexcept;
  Status stop_cycle(InstanceId instance, std::string_view clip, float fade_seconds) noexcept;
  Status play_action(InstanceId instance, std::string_view clip, float fade_in_seconds,
                     float fade_out_seconds) noexcept;
  // Poses the instance at `seconds` of one clip alone (looping), bypassing
  // and resetting its mixer: scrubbing, thumbnails, tests.
  Status pose_at(InstanceId instance, std::string_view clip, double seconds) noexcept;
  // Advances every mixer-driven instance's mixer by dt seconds and poses it.
  Status advance(float dt_seconds) noexcept;

  std::size_t instance_count() const noexcept;  // characters and static meshes

  struct Impl;

 private:
  friend class RayTracePass;
  Impl& impl() noexcept { return *impl_; }
  explicit World(std::unique_ptr<Impl> impl) noexcept;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sinew::api
