// The one check that a character can be framed and traced: what
// `sinew-editor validate`, `render`, the demo and libsinew all accept,
// because every one of them reaches a model through it (Pack::open and
// bake_in_memory call it; docs/ROBUSTNESS.md, "One validation").
//
// Decoding already refuses what is malformed (NaN, indices out of range,
// weights that do not sum to 1). This refuses what is well formed but out
// of reach of the tracer:
//
// * a model with no triangles (nothing to frame or trace);
// * a value stored past kMaxCoordinate: a vertex coordinate, a joint's rest
//   translation, scale or inverse-bind entry, a clip key's translation or
//   scale (cubic-spline tangents included);
// * a model whose poses can carry a vertex past kMaxCoordinate. The reach
//   is bounded from the stored values without sampling anything: along
//   each joint's chain the largest scale of its rest pose and of every
//   clip's keys multiplies, and translations add up, so the bound holds
//   for every clip time, every blend and every rotation (joint limits and
//   pose spaces only rotate). It costs one pass over the joints, the keys
//   and the vertices.
//
// The limit leaves the framing (camera, light and a ground reaching ten
// times past the character) and the tracer's products of three coordinates
// far inside float's range.
#pragma once

#include <string_view>

#include "character/model.h"
#include "runtime/core/status.h"

namespace sinew::character {

// No vertex of any pose may lie farther than this from the model's origin
// on any axis (in the model's own units).
inline constexpr double kMaxCoordinate = 1e9;

// Where each part of the model is named in messages: the field prefixes of
// its skeleton, mesh and clips (a pack names its sections, "SKEL.").
struct ModelFields {
  std::string_view skeleton = "skeleton.";
  std::string_view mesh = "mesh.";
  std::string_view clips = "clips";
};
inline constexpr ModelFields kPackFields{"SKEL.", "MESH.", "CLIP.clips"};

// kInvalidData naming `file`, the field and its value, and the limit when
// one is passed.
Status check_renderable(const Model& model, std::string_view file, const ModelFields& fields = {});

}  // namespace sinew::character
