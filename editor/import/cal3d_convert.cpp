// Conversion (cal3d_convert.h): bones, submeshes (vertices, influences,
// faces, materials) and keyframe tracks, each value checked on the way.
#include "editor/import/cal3d_convert.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>

#include <cal3d/corekeyframe.h>
#include <cal3d/coretrack.h>

namespace sinew::editor::cal3d_detail {
namespace {

bool finite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// See cal3d_importer.h: Cal3D's quaternions rotate as the conjugate of glm's.
Quat to_quat(const CalQuaternion& q) { return Quat(q.w, -q.x, -q.y, -q.z); }
Vec3 to_vec3(const CalVector& v) { return Vec3(v.x, v.y, v.z); }

}  // namespace

Expected<anim::Skeleton> convert_skeleton(CalCoreSkeleton& core, const std::string& file,
                                          std::vector<int>& raw_to_sorted) {
  std::vector<CalCoreBone*>& bones = core.getVectorCoreBone();
  if (bones.size() > anim::kMaxJoints) {
    return make_error(ErrorCode::kLimitExceeded, file, "bones", std::to_string(bones.size()),
                      "more bones than Sinew supports (" + std::to_string(anim::kMaxJoints) + ")");
  }
  anim::RawSkeleton raw;
  raw.joints.resize(bones.size());
  for (std::size_t i = 0; i < bones.size(); ++i) {
    CalCoreBone* b = bones[i];
    const std::string field = "bone[" + std::to_string(i) + "]";
    if (b == nullptr) return make_error(ErrorCode::kInvalidData, file, field, "", "missing bone");
    anim::RawJoint& j = raw.joints[i];
    j.name = b->getName();
    const int parent = b->getParentId();
    // Cal3D writes -1 for roots; anything else negative is corrupt, and
    // Skeleton::build reports indices past the end.
    if (parent < -1) {
      return make_error(ErrorCode::kOutOfBounds, file, field + ".parent", std::to_string(parent),
                        "negative parent id");
    }
    j.parent = parent < 0 ? anim::kNoParent : parent;
    j.rest.translation = to_vec3(b->getTranslation());
    j.rest.rotation = to_quat(b->getRotation());
    // Bone space maps model space to the bone: p_bone = R_bs p + t_bs.
    j.inverse_bind = Affine3::from_trs(to_vec3(b->getTranslationBoneSpace()),
                                       to_quat(b->getRotationBoneSpace()), Vec3(1.0f));
    if (!finite(j.rest.translation) || !finite(to_vec3(b->getTranslationBoneSpace()))) {
      return make_error(ErrorCode::kInvalidData, file, field + ".translation", "",
                        "non-finite translation");
    }
  }
  return anim::Skeleton::build(raw, file, &raw_to_sorted);
}

Status convert_mesh(CalCoreMesh& core, const std::string& file, MeshContext& ctx) {
  SkinnedMesh& m = *ctx.mesh;
  const std::vector<int>& remap = *ctx.raw_to_sorted;
  std::vector<CalCoreSubmesh*>& submeshes = core.getVectorCoreSubmesh();
  for (std::size_t s = 0; s < submeshes.size(); ++s) {
    CalCoreSubmesh* sub = submeshes[s];
    const std::string sfield = "submesh[" + std::to_string(s) + "]";
    if (sub == nullptr) return make_error(ErrorCode::kInvalidData, file, sfield, "", "missing");
    std::vector<CalCoreSubmesh::Vertex>& verts = sub->getVectorVertex();
    std::vector<CalCoreSubmesh::Face>& faces = sub->getVectorFace();
    std::vector<std::vector<CalCoreSubmesh::TextureCoordinate>>& uv_sets =
        sub->getVectorVectorTextureCoordinate();
    const std::size_t base = m.positions.size();
    if (base + verts.size() > UINT32_MAX) {
      return make_error(ErrorCode::kLimitExceeded, file, sfield + ".vertices",
                        std::to_string(verts.size()), "too many vertices");
    }
    // UVs: each submesh's first set. Once any submesh has UVs, vertices of
    // submeshes without them get (0,0), so the arrays stay parallel.
    const bool has_uv = !uv_sets.empty() && uv_sets[0].size() == verts.size();
    if (has_uv && m.uvs.size() < base) m.uvs.resize(base, Vec2(0.0f));

    for (std::size_t v = 0; v < verts.size(); ++v) {
      const CalCoreSubmesh::Vertex& cv = verts[v];
      const std::string vfield = sfield + ".vertex[" + std::to_string(v) + "]";
      const Vec3 p = to_vec3(cv.position);
      Vec3 n = to_vec3(cv.normal);
      if (!finite(p) || !finite(n)) {
        return make_error(ErrorCode::kInvalidData, file, vfield, "", "non-finite position or normal");
      }
      const float len = glm::length(n);
      // A zero normal cannot be made unit; any unit vector keeps the
      // SkinnedMesh invariant and the vertex is degenerate for shading anyway.
      n = len > 0.0f ? n / len : Vec3(0.0f, 0.0f, 1.0f);
      m.positions.push_back(p);
      m.normals.push_back(n);
      if (has_uv) {
        m.uvs.emplace_back(uv_sets[0][v].u, uv_sets[0][v].v);
      } else if (!m.uvs.empty()) {
        m.uvs.emplace_back(0.0f, 0.0f);
      }

      // Influences: keep the kMaxInfluences largest, renormalised.
      std::vector<std::pair<float, int>> infl;
      infl.reserve(cv.vectorInfluence.size());
      for (std::size_t k = 0; k < cv.vectorInfluence.size(); ++k) {
        const CalCoreSubmesh::Influence& in = cv.vectorInfluence[k];
        const std::string ifield = vfield + ".influence[" + std::to_string(k) + "]";
        if (in.boneId < 0 || static_cast<std::size_t>(in.boneId) >= remap.size()) {
          return make_error(ErrorCode::kOutOfBounds, file, ifield + ".bone",
                            std::to_string(in.boneId),
                            "no such bone (" + std::to_string(remap.size()) + " bones)");
        }
        if (!std::isfinite(in.weight) || in.weight < 0.0f) {
          return make_error(ErrorCode::kInvalidData, file, ifield + ".weight",
                            std::to_string(in.weight), "weight must be finite and >= 0");
        }
        if (in.weight > 0.0f) infl.emplace_back(in.weight, remap[static_cast<std::size_t>(in.boneId)]);
      }
      // stable_sort keeps file order among equal weights: deterministic.
      std::stable_sort(infl.begin(), infl.end(),
                       [](const auto& a, const auto& b) { return a.first > b.first; });
      if (infl.size() > static_cast<std::size_t>(kMaxInfluences)) infl.resize(kMaxInfluences);
      double sum = 0.0;
      for (const auto& i : infl) sum += static_cast<double>(i.first);
      // Cal3D leaves a vertex without influences in place (model space);
      // Sinew has no "no bone" slot, and binding it to some bone would move
      // it, so such a mesh is rejected rather than silently changed.
      if (infl.empty() || !(sum > 0.0)) {
        return make_error(ErrorCode::kInvalidData, file, vfield + ".influences", "0",
                          "vertex has no bone influence with a positive weight");
      }
      std::array<std::uint16_t, kMaxInfluences> joints{};
      std::array<float, kMaxInfluences> weights{};
      for (std::size_t k = 0; k < infl.size(); ++k) {
        joints[k] = static_cast<std::uint16_t>(infl[k].second);
        weights[k] = infl[k].first;  // renormalised with every importer's rule below
      }
      m.joints.push_back(joints);
      m.weights.push_back(weights);
    }

    int thread = sub->getCoreMaterialThreadId();
    std::uint32_t material = 0;
    if (thread >= 0 && static_cast<std::size_t>(thread) < ctx.material_count) {
      material = static_cast<std::uint32_t>(thread);
    } else {
      material = static_cast<std::uint32_t>(ctx.material_count);  // the white default
      ctx.uses_default_material = true;
    }
    for (std::size_t f = 0; f < faces.size(); ++f) {
      std::array<std::uint32_t, 3> tri{};
      for (int c = 0; c < 3; ++c) {
        const auto id = static_cast<long long>(faces[f].vertexId[c]);
        if (id < 0 || static_cast<std::size_t>(id) >= verts.size()) {
          return make_error(ErrorCode::kOutOfBounds, file,
                            sfield + ".face[" + std::to_string(f) + "].vertex[" +
                                std::to_string(c) + "]",
                            std::to_string(id),
                            "past the submesh's " + std::to_string(verts.size()) + " vertices");
        }
        tri[static_cast<std::size_t>(c)] = static_cast<std::uint32_t>(base + static_cast<std::size_t>(id));
      }
      m.triangles.push_back(tri);
      m.triangle_material.push_back(material);
    }
  }
  return {};
}

Expected<anim::Clip> convert_clip(CalCoreAnimation& core, const std::string& name,
                                  const std::string& file, const anim::Skeleton& skeleton,
                                  const std::vector<int>& remap) {
  anim::RawClip raw;
  raw.name = name;
  const float duration = core.getDuration();
  std::size_t t = 0;
  for (CalCoreTrack* track : core.getListCoreTrack()) {
    const std::string tfield = "track[" + std::to_string(t++) + "]";
    if (track == nullptr) return make_error(ErrorCode::kInvalidData, file, tfield, "", "missing");
    const int bone = track->getCoreBoneId();
    if (bone < 0 || static_cast<std::size_t>(bone) >= remap.size()) {
      return make_error(ErrorCode::kOutOfBounds, file, tfield + ".bone", std::to_string(bone),
                        "no such bone (" + std::to_string(remap.size()) + " bones)");
    }
    anim::JointTracks jt;
    jt.joint = remap[static_cast<std::size_t>(bone)];
    jt.translation.interpolation = anim::Interpolation::kLinear;
    jt.rotation.interpolation = anim::Interpolation::kLinear;
    const int count = track->getCoreKeyframeCount();
    // Cal3D samples nothing sensible from a track without keys; it animates
    // nothing, so it is left out.
    if (count <= 0) continue;
    for (int k = 0; k < count; ++k) {
      CalCoreKeyframe* key = track->getCoreKeyframe(k);
      if (key == nullptr) {
        return make_error(ErrorCode::kInvalidData, file, tfield + ".key[" + std::to_string(k) + "]",
                          "", "missing");
      }
      const float time = key->getTime();
      const Vec3 tr = to_vec3(key->getTranslation());
      const Quat rot = to_quat(key->getRotation());
      // Equal times: Cal3D samples the last of them at and after that time
      // (upper-bound search), so keeping the last reproduces it exactly.
      // Other ordering problems are left for Clip::build to report.
      if (!jt.translation.times.empty() && jt.translation.times.back() == time) {
        jt.translation.values.back() = tr;
        jt.rotation.values.back() = rot;
        continue;
      }
      jt.translation.times.push_back(time);
      jt.translation.values.push_back(tr);
      jt.rotation.times.push_back(time);
      jt.rotation.values.push_back(rot);
    }
    // Cal3D's cycles loop at the header duration, usually one frame past
    // the last key: CalMixer::blendCycle appends to each such track a key at
    // the duration holding the first key's value (Cal3D 0.11, checked by the
    // oracle test), so the last frame blends back into the first. Doing the
    // same makes the clip's duration Cal3D's and its loop seamless.
    if (std::isfinite(duration) && duration > jt.translation.times.back()) {
      jt.translation.times.push_back(duration);
      jt.translation.values.push_back(jt.translation.values.front());
      jt.rotation.times.push_back(duration);
      jt.rotation.values.push_back(jt.rotation.values.front());
    }
    raw.tracks.push_back(std::move(jt));
  }
  return anim::Clip::build(std::move(raw), skeleton, file);
}

}  // namespace sinew::editor::cal3d_detail
