// The world a ray-trace pass renders: instances of characters, each driven
// either by Sinew's own animation mixer (Cal3D semantics: blended cycles,
// one-shot actions with fades) or by the host's animation system, which
// hands over one 3x4 skinning matrix per bone each frame; plus optional
// static geometry (a level, a ground) in world space.
//
// A World is not thread-safe: drive it from one thread, between passes. The
// pass itself runs its work on many threads (sinew/pass.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
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

enum class TriangleTest : std::uint8_t {
  kFast,        // Möller–Trumbore, no per-triangle precomputation: fastest
  kWatertight,  // Woop, Benthin and Wald 2013: no ray leaks between adjacent triangles
};

// Every mask bit set: the default of instances, static meshes and rays.
inline constexpr std::uint32_t kAllMaskBits = 0xFFFFFFFFu;

// A ray for World's queries: the points origin + t direction with
// t_min <= t < t_max (the direction need not be unit length: t is in its
// units). The query skips every instance and static mesh whose mask shares
// no bit with the ray's (InstanceDesc::mask, World::set_mask).
struct Ray {
  Float3 origin;
  Float3 direction{0.0f, 0.0f, 1.0f};
  float t_min = 0.0f;
  float t_max = std::numeric_limits<float>::infinity();
  std::uint32_t mask = kAllMaskBits;
};

// The nearest hit of a ray, or a miss (instance, triangle and material
// kNoHit, t infinite, the rest zero). The hit point is origin + t direction
// = (1 - u - v) p0 + u p1 + v p2 on the triangle's corners (as posed, in
// world space).
struct RayHit {
  float t = std::numeric_limits<float>::infinity();
  float u = 0.0f;
  float v = 0.0f;
  InstanceId instance = kNoHit;
  std::uint32_t triangle = kNoHit;  // the character's (or static mesh's) triangle
  // The posed triangle's unit normal in world space, normalize((p1 - p0) x
  // (p2 - p0)): its front side, the one from which p0, p1, p2 run
  // counter-clockwise, whichever side the ray came from (the ray hit the
  // front when dot(geometric_normal, direction) < 0). Not interpolated.
  Float3 geometric_normal;
  // The mesh's texture coordinates at the hit, (1 - u - v) uv0 + u uv1 +
  // v uv2 ((0, 0) when the mesh has none, as static meshes).
  Float2 uv;
  // The triangle's material: an index into the character's materials
  // (kNoHit for a character without materials; a static mesh's one colour
  // is material 0), as the pass's material_id output gives it.
  std::uint32_t material = kNoHit;
  bool hit() const noexcept { return instance != kNoHit; }
};

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
  // Mixer-driven: advance(dt) moves this instance's mixer by
  // playback_speed * dt (cycles, fades and actions alike): 2 plays at double
  // speed, 0 holds the pose. Finite and >= 0 (kInvalidArgument otherwise).
  float playback_speed = 1.0f;
  // Queries skip the instance when (mask & Ray::mask) == 0: give each
  // group of instances (players, the ground, debris) a bit, and a ray the
  // bits it may hit. World::set_mask changes it. The pass's camera and
  // shadow rays test it against PassInputs::camera_ray_mask and
  // shadow_ray_mask.
  std::uint32_t mask = kAllMaskBits;
};

// A static triangle mesh in world space; copied, its kd-tree built once.
struct StaticMeshDesc {
  std::span<const Float3> positions;
  std::span<const std::uint32_t> indices;  // three per triangle
  Float3 color{0.6f, 0.6f, 0.6f};          // linear RGB albedo
  std::uint32_t mask = kAllMaskBits;       // as InstanceDesc::mask
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
  // Advances every mixer-driven instance's mixer by dt seconds (times its
  // playback speed) and poses it. Errors: kInvalidArgument (dt negative or
  // not finite, or dt times an instance's speed not finite: nothing moves).
  Status advance(float dt_seconds) noexcept;

  // Each mixer-driven instance's own clock, so a crowd on one clip need not
  // walk in lockstep. set_playback_speed: InstanceDesc::playback_speed,
  // changed. offset_time: moves this instance alone `seconds` ahead now
  // (its speed not applied), so it poses exactly as one that advance() had
  // moved `seconds` further; call it after play_cycle, since an idle mixer
  // has no clock to move. set_time_factor: Cal3D's CalMixer::setTimeFactor,
  // the clock of the synchronised cycles runs at `factor` (negative:
  // backwards) while fades, actions and desynchronised cycles keep real
  // time; default 1. Errors: kNotFound (no such instance), kInvalidArgument
  // (a host-driven instance; a negative or non-finite speed or seconds; a
  // non-finite factor), nothing changed.
  Status set_playback_speed(InstanceId instance, float speed) noexcept;
  Status offset_time(InstanceId instance, float seconds) noexcept;
  Status set_time_factor(InstanceId instance, float factor) noexcept;

  // Bone `bone`'s world transform as posed now, bone space -> world (its
  // last column is the joint's position): where to attach a sword to a hand
  // or a camera to a head. Mixer-driven: the placement times the joint's
  // model-space transform; host-driven: the skinning matrix set times
  // Character::bind_pose(bone). Errors: kNotFound (no such character
  // instance, or a static mesh), kInvalidArgument (a bone past the end).
  Result<Matrix3x4> bone_transform(InstanceId instance, std::size_t bone) const noexcept;

  // Removes a character instance or a static mesh (a host despawning it):
  // it leaves the next pass and query, and its per-frame memory is freed.
  // Its id is never given again, so a stale id fails with kNotFound instead
  // of reaching a newer instance. Errors: kNotFound (never added, or removed
  // already).
  Status remove(InstanceId instance) noexcept;

  // The mask bits of a character instance or a static mesh (InstanceDesc::
  // mask): the next query sees them; nothing is prepared again. Errors:
  // kNotFound (never added, or removed).
  Status set_mask(InstanceId instance, std::uint32_t mask) noexcept;

  // Characters and static meshes in the world (removed ones not counted).
  std::size_t instance_count() const noexcept;

  // Ray queries on the world as posed now (picking, hit tests, gameplay
  // rays), exact like the pass's images: triangles outside the baked pose
  // space included. Poses set since the last pass or query are first
  // skinned and their trees' boxes and top level rebuilt (as a pass's
  // prepare, on the calling thread: fractions of a millisecond per
  // character), so query between passes, as for every other World call.
  // The batch forms answer rays[i] in hits[i] (or blocked[i]: 1 when
  // something lies on the ray, else 0), on the calling thread.
  // Errors: kInvalidArgument (a non-finite origin or direction, a zero
  // direction, a NaN or negative t_min, t_max below t_min; spans of
  // different sizes), naming the ray; nothing is written then.
  Result<RayHit> intersect(const Ray& ray, TriangleTest test = TriangleTest::kFast) noexcept;
  Status intersect(std::span<const Ray> rays, std::span<RayHit> hits,
                   TriangleTest test = TriangleTest::kFast) noexcept;
  // Whether anything lies on the ray (any hit: cheaper than the nearest).
  Result<bool> occluded(const Ray& ray, TriangleTest test = TriangleTest::kFast) noexcept;
  Status occluded(std::span<const Ray> rays, std::span<std::uint8_t> blocked,
                  TriangleTest test = TriangleTest::kFast) noexcept;

  struct Impl;

 private:
  friend class RayTracePass;
  Impl& impl() noexcept { return *impl_; }
  explicit World(std::unique_ptr<Impl> impl) noexcept;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sinew::api
