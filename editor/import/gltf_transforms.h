// TRS decomposition: a node's local transform as translation, rotation and
// scale (its TRS properties, or its matrix split), similarity tests, and the
// folding of a constant parent-side similarity into a child's TRS. Separate:
// pure transform arithmetic, shared by the skeleton's rest poses and the clips.
#pragma once

#include <cstddef>

#include "editor/import/gltf_context.h"

namespace sinew::editor::gltf_detail {

using DMat4 = glm::dmat4;
using DVec3 = glm::dvec3;
using DQuat = glm::dquat;

struct Trs {
  DVec3 t{0.0};
  DQuat r{1.0, 0.0, 0.0, 0.0};
  DVec3 s{1.0};

  DMat4 matrix() const {
    DMat4 m = glm::mat4_cast(r);
    m[0] *= s.x;
    m[1] *= s.y;
    m[2] *= s.z;
    m[3] = glm::dvec4(t, 1.0);
    return m;
  }
};

double max_abs_diff(const DMat4& a, const DMat4& b);

// Splits an affine matrix into TRS. Returns false for
// matrices TRS cannot express: shear, zero scale, a projective row.
bool decompose(const DMat4& m, Trs& out);

bool is_similarity(const Trs& p);

bool is_identity(const DMat4& m);

// Node `i`'s local TRS (from TRS properties, or its matrix decomposed).
Status node_local(const Ctx& c, std::size_t i, DMat4& matrix, Trs& trs, bool& trs_ok);

Affine3 to_affine(const DMat4& m);

// Folds a constant parent-side similarity `p` into a child's TRS value.
inline DVec3 fold_translation(const Trs& p, const DVec3& t) { return p.t + p.s.x * (p.r * t); }
inline DQuat fold_rotation(const Trs& p, const DQuat& r) { return p.r * r; }
inline DVec3 fold_scale(const Trs& p, const DVec3& s) { return p.s.x * s; }

}  // namespace sinew::editor::gltf_detail
