// Iterative subdivision of a skinned mesh, the paper's way to make 10k ...
// 271k-triangle variants of one character (Günther et al. 2006, Table 2).
//
// Each level splits every triangle into four at its edge midpoints. An edge
// shared by two triangles gets one midpoint vertex, so the result has no
// cracks; a midpoint's attributes are the average of the edge's two
// endpoints: position, normal (renormalised), uv, and skin weights (the
// union of both endpoints' influences, each weighted 1/2, the heaviest
// kMaxInfluences kept and renormalised to sum to 1). Positions are only
// interpolated (no smoothing), so the bind-pose surface is the original one.
// Posed, it is not quite: with linear blend skinning a midpoint whose
// endpoints have different weights does not skin to the midpoint of their
// skinned positions (measured at level 1: up to 1.5 cm on the 1.8 m
// mannequin). The result is a new, finer character, not a re-tessellation
// of the old one's every pose.
//
// Order, part of the contract (triangle ids are reported in it): the
// original vertices keep their indices; midpoints follow in the order their
// edges are first met walking triangles in order, edges (v0,v1), (v1,v2),
// (v2,v0). Triangle t becomes triangles 4t .. 4t+3: the corners at v0, v1,
// v2, then the middle one, all with the winding of t and t's material.
#pragma once

#include "character/model.h"
#include "runtime/core/expected.h"

namespace sinew::editor {

inline constexpr int kMaxSubdivisionLevels = 8;

// `levels` subdivisions of `model`'s mesh (skeleton, clips and materials are
// copied unchanged; for levels > 0 `source` gets " (subdivided N)"
// appended; level 0 is an identical copy). Errors:
// kInvalidArgument for levels outside [0, kMaxSubdivisionLevels];
// kLimitExceeded when the result would exceed 2^31 triangles or vertices;
// kInvalidData naming the triangle whose vertex index is out of range, or
// the per-vertex or per-triangle array whose length is wrong.
Expected<character::Model> subdivide(const character::Model& model, int levels);

}  // namespace sinew::editor
