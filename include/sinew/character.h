// A character: the immutable core data a content pack holds — skeleton,
// skinned mesh, clips, joint limits and the fuzzy kd-trees baked over its
// pose space (`sinew-editor bake`). Like Cal3D's CoreModel it is shared: a
// Character is a cheap handle, and every instance made from it (World) uses
// the same trees, mapped from the file in place, never copied.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "sinew/export.h"
#include "sinew/math.h"
#include "sinew/result.h"
#include "sinew/view.h"

namespace sinew::api {

class SINEW_API Character {
 public:
  // Maps and fully validates a baked pack: a pack that loads is safe to
  // render, whatever its bytes. Errors: kNotFound, kIoError, kCorruptData
  // (naming the section and field), kUnsupported (another major format
  // version, or a model-only pack without fuzzy trees).
  static Result<Character> load(std::string_view path) noexcept;
  // The same over bytes the caller keeps alive as long as any handle or
  // instance of the character lives. `name` appears in error messages.
  static Result<Character> from_memory(std::span<const std::byte> bytes, std::string_view name) noexcept;

  // Bones in the pack's order: the order of the skinning matrices a host
  // hands to World::set_bone_matrices.
  std::size_t bone_count() const noexcept;
  std::string_view bone_name(std::size_t bone) const noexcept;  // "" past the end
  // The index of the bone called `name`. Errors: kNotFound.
  Result<std::size_t> find_bone(std::string_view name) const noexcept;
  // The bone's bind pose: bone space -> model space. A host's skinning
  // matrix for the bone is (bone -> world now) * inverse(bind_pose).
  Matrix3x4 bind_pose(std::size_t bone) const noexcept;  // identity past the end
  int bone_parent(std::size_t bone) const noexcept;      // -1 for a root or past the end

  std::size_t clip_count() const noexcept;
  std::string_view clip_name(std::size_t clip) const noexcept;  // "" past the end
  float clip_duration(std::size_t clip) const noexcept;         // seconds; 0 past the end

  // Materials in the pack's order: the pass's material_id output and
  // RayHit::material index them.
  std::size_t material_count() const noexcept;
  std::string_view material_name(std::size_t material) const noexcept;  // "" past the end or unnamed
  bool material_has_texture(std::size_t material) const noexcept;        // false past the end

  // The mesh as stored (its bind pose), in model space: for framing a
  // camera, culling, or putting a ground under it.
  struct Bounds {
    Float3 min;
    Float3 max;
  };
  Bounds bind_bounds() const noexcept;

  // How the character stands and how to look at it, in the convention the
  // mixer poses it in (World::play_cycle and friends; model space, before
  // the instance's placement). Unlike bind_bounds, which is the mesh as
  // stored and may lie in another orientation (CesiumMan's mesh is Z-up
  // while its posed skeleton is Y-up), these are the character skinned at
  // its skeleton's rest pose. The pack records them (its FRAM section);
  // packs baked before it get them computed on load.
  struct Framing {
    int up_axis = 1;     // 1: it stands along +Y; 2: along +Z (Cal3D characters usually); camera.up is that axis
    Bounds rest_bounds;  // the rest pose's bounds
    // Looks at the rest bounds' centre from the front, a little above,
    // from far enough that their bounding sphere fits an image `aspect`
    // (width / height) times as wide as high, with the up axis up; fovy 40.
    Camera camera;
    Light light;  // a white point light above, in front of and right of the character
  };
  Framing framing(float aspect = 1.0f) const noexcept;

  std::size_t vertex_count() const noexcept;
  std::size_t triangle_count() const noexcept;
  // What the trees were baked over, e.g. "clips (566 samples)". Poses
  // outside it still render correctly through the fallback, at a cost.
  std::string pose_space() const;
  std::string_view source_name() const noexcept;  // the pack's name or path

  struct Impl;

 private:
  friend struct CharacterFactory;
  explicit Character(std::shared_ptr<const Impl> impl) : impl_(std::move(impl)) {}
  std::shared_ptr<const Impl> impl_;
};

}  // namespace sinew::api
