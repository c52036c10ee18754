// Model: what every importer produces (docs/ANIMATION.md, "Importers"), in
// Sinew's own types. Importers are the only code that knows file formats
// other than the content pack.
//
// Triangle order is part of the contract (the ray tracer reports triangle
// ids in it): Cal3D — meshes in .cfg order, then submeshes and faces in file
// order; glTF — meshes in array order, primitives in order, triangles in
// index order. Positions stay in the file's units after the file's own scale;
// nothing is re-oriented (glTF is Y-up, Cal3D models usually Z-up).
//
// Skin weights (the rule every importer follows, through
// normalize_skin_weights): each vertex's weights must be finite and >= 0
// with a positive sum; rows that do not sum to 1 are divided by their sum.
// Rows off by more than kSkinWeightSumTolerance (a file that meant
// something else, e.g. weights summing to 0.5 or 2) are also reported in
// Model::warnings, so the caller can show them; rounding-level
// differences (8-bit glTF weights) are renormalised silently.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "animation/clip.h"
#include "animation/skeleton.h"
#include "runtime/core/status.h"
#include "runtime/mesh/skinned_mesh.h"

namespace sinew::character {

struct Model {
  std::string source;  // the file it came from
  anim::Skeleton skeleton;
  SkinnedMesh mesh;  // joint indices refer to skeleton's (sorted) joint order
  std::vector<anim::Clip> clips;
  std::vector<std::string> material_names;  // parallel to mesh.material_colors
  // Things the import changed or doubted but accepted (one line each, naming
  // the file and the field), e.g. renormalised skin weights.
  std::vector<std::string> warnings;

  // The clip called `name`, or "#<index>" for the index-th clip.
  const anim::Clip* find_clip(const std::string& name) const;
};

// |sum - 1| above this is worth a warning: 4 influences quantised to 8 bits
// are off by at most 4 / 510 < 0.01.
inline constexpr double kSkinWeightSumTolerance = 0.01;

// Divides every vertex's weights by their sum (in double), appending one
// summary line to `warnings` when any row was off by more than
// kSkinWeightSumTolerance. Errors (kInvalidData, naming `source` and
// "weights[v][k]" or "weights[v]"): a weight that is negative or not finite,
// a row whose sum is 0, or a weights array of the wrong length.
Status normalize_skin_weights(SkinnedMesh& mesh, std::string_view source, std::vector<std::string>& warnings);

// For weights already normalised (a pack's mesh, written after
// normalize_skin_weights): kInvalidData naming `file`, `field_prefix` +
// "weights[v]" and the row's sum when a vertex's weights are all zero or sum
// to more than kSkinWeightSumTolerance away from 1. Each weight is assumed
// finite and >= 0 (check_skinned_mesh).
Status check_skin_weight_sums(const SkinnedMesh& mesh, std::string_view file, std::string_view field_prefix);

// The same for a whole model, warnings going to model.warnings.
inline Status normalize_skin_weights(Model& model) {
  return normalize_skin_weights(model.mesh, model.source, model.warnings);
}

}  // namespace sinew::character
