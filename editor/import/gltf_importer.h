// glTF 2.0 importer (.gltf with external or embedded buffers, and .glb),
// built on tinygltf for parsing; everything past the JSON (accessor decoding,
// bounds, skins, node folding) is checked here so bad files give a Status.
//
// What becomes of a glTF file:
//
// * Skeleton. The joints are the union of the `joints` of every skin that a
//   mesh node uses, in skin order then joint order. A joint's parent is its
//   nearest ancestor node that is also a joint. Non-joint nodes between two
//   joints, and above a root joint (e.g. an "Armature" or Z-up node), are
//   folded into the child joint's rest transform and into its animation
//   tracks, so model-space joint transforms equal the glTF global transforms.
//   Folding an animated joint needs the folded transform to be a similarity
//   (translation, rotation, uniform scale); otherwise the import fails.
//   A node listed by two skins must have the same inverseBindMatrix in both
//   (otherwise the import fails). An absent inverseBindMatrices accessor
//   means identity. The skin's `skeleton` property is validated but not
//   needed: global transforms always come from the full node hierarchy.
// * Mesh. Every node with a mesh instantiates it; triangles come in mesh
//   array order, then per mesh its instancing nodes in node order, then
//   primitives in order, then triangles in index order (non-indexed
//   primitives use 0,1,2,...; strips and fans become the spec's triangles,
//   points and lines are refused). Meshes no node uses are skipped. Skinned mesh
//   nodes follow the spec: their own transform is ignored, vertices are bind
//   positions. Meshes on nodes without a skin are rigid: they are bound with
//   weight 1 to their nearest joint ancestor (or self), or, if none, to a
//   synthetic root joint "<static>" with identity transforms (added only
//   when needed, so a model without skins imports as one root joint).
//   JOINTS_0/WEIGHTS_0 and JOINTS_1/WEIGHTS_1 give up to 8 influences;
//   weights are renormalised to sum 1. A joint index past the skin's joint
//   list is an error when its weight is non-zero and is cleared to joint 0
//   when its weight is zero (some exporters pad unused slots that way).
//   Missing normals are computed (area-weighted); texture coordinates are
//   optional, read from the set the material's base colour texture names
//   (TEXCOORD_0 without one).
// * Materials. Every glTF material in array order, its colour the
//   baseColorFactor rgb (white by default) and its colour map the
//   baseColorTexture's image with its sampler's wrap modes (gltf_textures.h;
//   one that cannot be read is a warning); primitives without a material
//   use an extra "<default>" white material appended at the end.
// * Clips. One per animation, named by `name` or "animation_<index>".
//   Translation, rotation and scale channels on joints become tracks with
//   STEP / LINEAR / CUBICSPLINE interpolation; `weights` channels (morph
//   targets) and channels on non-joint nodes are ignored.
// * Limits (kLimitExceeded, naming the accessor's count): at most 2^25
//   values per accessor, and an accessor without a bufferView (zeros plus
//   sparse values) at most as many elements as the file's buffers have
//   bytes, so that memory stays proportional to the file's size.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "character/model.h"
#include "runtime/core/expected.h"

namespace sinew::editor {

// Loads `path` (.gltf or .glb, decided by the file's magic, not its name).
// Every failure is a Status naming the file and the offending field, e.g.
// "m.gltf: meshes[0].primitives[1].attributes.WEIGHTS_0[17] = 0: the
// vertex's weights are all zero".
//
// External buffers and images are read only from the file's own folder and
// `asset_roots` (relative references; data: URIs are always fine): a URI
// of "../../etc/passwd" or "/etc/passwd" is refused before anything is read.
// Resource limits, each named (with the option that raises it) when hit:
// a 290 KB file instancing one mesh from 5,000 nodes is 23 M triangles.
// (Joints have no import limit of their own: a skeleton holds at most
// anim::kMaxJoints, and more are refused as beyond its capacity.)
struct ImportLimits {
  std::size_t max_triangles = std::size_t{1} << 22;  // 4,194,304, over all mesh instances
  std::size_t max_clips = 1024;                      // animations
  std::size_t max_keys = std::size_t{1} << 24;       // keys over all channels (16,777,216)
  std::size_t max_nodes = std::size_t{1} << 20;      // 1,048,576 nodes
  std::size_t max_bytes = std::size_t{1} << 30;      // 1 GiB read: the file and its external buffers
};
struct GltfImportOptions {
  std::vector<std::string> asset_roots;  // more folders external files may come from
  ImportLimits limits;
};
Expected<character::Model> import_gltf(const std::string& path, const GltfImportOptions& options = {});

}  // namespace sinew::editor
