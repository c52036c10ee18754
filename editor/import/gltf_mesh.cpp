// Meshes (gltf_mesh.h): a primitive's attributes decoded and checked,
// transformed to the bind pose, and its triangles and normals appended.
#include "editor/import/gltf_mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <string>

#include <glm/gtc/matrix_inverse.hpp>

#include "editor/import/gltf_accessors.h"

namespace sinew::editor::gltf_detail {
namespace {

constexpr std::initializer_list<int> kWeightComponentTypes = {
    TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
    TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT};

}  // namespace

Status add_primitive(const Ctx& c, const NodeGraph& g, const SkeletonPlan& plan,
                     const std::vector<int>& raw_to_sorted, std::size_t node_index,
                     std::size_t mesh_index, std::size_t prim_index, std::uint32_t material,
                     MeshBuilder& b) {
  const tinygltf::Node& node = c.model.nodes[node_index];
  const tinygltf::Primitive& prim = c.model.meshes[mesh_index].primitives[prim_index];
  const std::string pfield = idx(idx("meshes", mesh_index) + ".primitives", prim_index);
  const int mode = prim.mode == -1 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
  if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN) {
    return c.error(ErrorCode::kInvalidData, pfield + ".mode", std::to_string(prim.mode),
                   "only triangle primitives are supported: TRIANGLES (4), TRIANGLE_STRIP (5), TRIANGLE_FAN (6)");
  }
  const std::string afield = pfield + ".attributes";
  const int pos_acc = attribute(prim, "POSITION");
  if (pos_acc < 0) {
    return c.error(ErrorCode::kNotFound, afield + ".POSITION", "", "primitive has no positions");
  }
  SINEW_ASSIGN_OR_RETURN(AccessorData pos,
                         read_accessor(c, pos_acc, afield + ".POSITION", {TINYGLTF_TYPE_VEC3},
                                       {TINYGLTF_COMPONENT_TYPE_FLOAT}));
  const std::size_t vcount = pos.count;
  const std::size_t base = b.mesh.positions.size();
  if (vcount > kMaxElements || base + vcount > std::numeric_limits<std::uint32_t>::max() / 2) {
    return c.error(ErrorCode::kLimitExceeded, afield + ".POSITION", std::to_string(vcount),
                   "too many vertices");
  }
  auto counted = [&](int acc, const char* name, AccessorData& out,
                     std::initializer_list<int> types,
                     std::initializer_list<int> ctypes) -> Status {
    SINEW_ASSIGN_OR_RETURN(out, read_accessor(c, acc, afield + "." + name, types, ctypes));
    if (out.count != vcount) {
      return c.error(ErrorCode::kInvalidData, afield + "." + name, std::to_string(out.count),
                     "count differs from POSITION's " + std::to_string(vcount));
    }
    return {};
  };

  // Where the vertices go: skinned nodes ignore their own transform (spec),
  // rigid ones are baked into the bind pose of the joint that carries them.
  const bool skinned = node.skin >= 0;
  DMat4 bind(1.0);
  int rigid_raw = -1;
  if (!skinned) {
    rigid_raw = joint_ancestor(g, plan, static_cast<int>(node_index));
    if (rigid_raw == -1) {
      rigid_raw = plan.static_root;
      bind = g.global[node_index];
    } else {
      const int jnode = plan.joint_nodes[static_cast<std::size_t>(rigid_raw)];
      bind = glm::inverse(plan.inverse_bind[static_cast<std::size_t>(rigid_raw)]) *
             glm::inverse(g.global[static_cast<std::size_t>(jnode)]) * g.global[node_index];
    }
    for (int col = 0; col < 4; ++col) {
      for (int row = 0; row < 4; ++row) {
        if (!std::isfinite(bind[col][row])) {
          return c.error(ErrorCode::kInvalidData, idx("nodes", node_index), "",
                         "rigid mesh's bind transform is singular (zero scale?)");
        }
      }
    }
  }
  const glm::dmat3 normal_matrix = glm::inverseTranspose(glm::dmat3(bind));

  std::vector<Vec3> positions(vcount);
  for (std::size_t v = 0; v < vcount; ++v) {
    const glm::dvec4 p = bind * glm::dvec4(pos.at(v, 0), pos.at(v, 1), pos.at(v, 2), 1.0);
    positions[v] = Vec3(DVec3(p));
  }

  std::vector<Vec3> normals;
  const int nrm_acc = attribute(prim, "NORMAL");
  if (nrm_acc >= 0) {
    AccessorData nrm;
    SINEW_RETURN_IF_ERROR(
        counted(nrm_acc, "NORMAL", nrm, {TINYGLTF_TYPE_VEC3}, {TINYGLTF_COMPONENT_TYPE_FLOAT}));
    normals.resize(vcount);
    for (std::size_t v = 0; v < vcount; ++v) {
      const DVec3 n = normal_matrix * DVec3(nrm.at(v, 0), nrm.at(v, 1), nrm.at(v, 2));
      const double len = glm::length(n);
      // Zero normals (seen in the wild) are replaced by computed ones below.
      normals[v] = len > 1e-12 ? Vec3(n / len) : Vec3(0.0f);
    }
  }

  // The set the material's base colour texture reads (TEXCOORD_0 without one).
  std::vector<Vec2> uvs;
  int uv_set = 0;
  if (material < c.model.materials.size()) {
    const int set = c.model.materials[material].pbrMetallicRoughness.baseColorTexture.texCoord;
    if (set > 0 && set < 16) uv_set = set;
  }
  const std::string uv_name = "TEXCOORD_" + std::to_string(uv_set);
  const int uv_acc = attribute(prim, uv_name.c_str());
  if (uv_acc >= 0) {
    AccessorData uv;
    SINEW_RETURN_IF_ERROR(counted(uv_acc, uv_name.c_str(), uv, {TINYGLTF_TYPE_VEC2},
                                  kWeightComponentTypes));
    uvs.resize(vcount);
    for (std::size_t v = 0; v < vcount; ++v) {
      uvs[v] = Vec2(static_cast<float>(uv.at(v, 0)), static_cast<float>(uv.at(v, 1)));
    }
  }

  std::vector<std::array<std::uint16_t, kMaxInfluences>> joints(vcount);
  std::vector<std::array<float, kMaxInfluences>> weights(vcount);
  for (auto& w : weights) w.fill(0.0f);
  for (auto& j : joints) j.fill(0);
  if (skinned) {
    const tinygltf::Skin& skin = c.model.skins[static_cast<std::size_t>(node.skin)];
    if (attribute(prim, "JOINTS_2") >= 0 || attribute(prim, "WEIGHTS_2") >= 0) {
      return c.error(ErrorCode::kLimitExceeded, afield + ".JOINTS_2", "",
                     "more than 8 influences per vertex");
    }
    bool any_set = false;
    for (int set = 0; set < 2; ++set) {
      const std::string jname = "JOINTS_" + std::to_string(set);
      const std::string wname = "WEIGHTS_" + std::to_string(set);
      const int jacc = attribute(prim, jname.c_str());
      const int wacc = attribute(prim, wname.c_str());
      if (jacc < 0 && wacc < 0) continue;
      if (jacc < 0 || wacc < 0) {
        return c.error(ErrorCode::kNotFound, afield + "." + (jacc < 0 ? jname : wname), "",
                       "JOINTS_n and WEIGHTS_n come in pairs");
      }
      any_set = true;
      AccessorData jd, wd;
      SINEW_RETURN_IF_ERROR(counted(jacc, jname.c_str(), jd, {TINYGLTF_TYPE_VEC4},
                                    {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                                     TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT}));
      SINEW_RETURN_IF_ERROR(
          counted(wacc, wname.c_str(), wd, {TINYGLTF_TYPE_VEC4}, kWeightComponentTypes));
      for (std::size_t v = 0; v < vcount; ++v) {
        for (int k = 0; k < 4; ++k) {
          const std::size_t slot = static_cast<std::size_t>(set * 4 + k);
          const double w = wd.at(v, k);
          const double j = jd.at(v, k);
          if (w < 0.0) {
            return c.error(ErrorCode::kInvalidData, idx(afield + "." + wname, v), num(w),
                           "negative weight");
          }
          if (j >= static_cast<double>(skin.joints.size())) {
            if (w == 0.0) continue;  // unused padding slot: leave joint 0
            return c.error(ErrorCode::kOutOfBounds, idx(afield + "." + jname, v), num(j),
                           "joint index past the skin's " + std::to_string(skin.joints.size()) +
                               " joints (" + idx("skins", static_cast<std::size_t>(node.skin)) +
                               ")");
          }
          const int jnode = skin.joints[static_cast<std::size_t>(j)];
          const int raw = plan.node_to_raw[static_cast<std::size_t>(jnode)];
          joints[v][slot] = static_cast<std::uint16_t>(raw_to_sorted[static_cast<std::size_t>(raw)]);
          weights[v][slot] = static_cast<float>(w);
        }
      }
    }
    if (!any_set) {
      return c.error(ErrorCode::kNotFound, afield + ".JOINTS_0", "",
                     "primitive of a skinned node has no JOINTS_0/WEIGHTS_0");
    }
    for (std::size_t v = 0; v < vcount; ++v) {
      double sum = 0.0;
      for (const float w : weights[v]) sum += static_cast<double>(w);
      if (!(sum > 0.0)) {
        return c.error(ErrorCode::kInvalidData, idx(afield + ".WEIGHTS_0", v), "0",
                       "the vertex's weights are all zero");
      }
    }
  } else {
    const std::uint16_t j = static_cast<std::uint16_t>(raw_to_sorted[static_cast<std::size_t>(rigid_raw)]);
    for (std::size_t v = 0; v < vcount; ++v) {
      joints[v][0] = j;
      weights[v][0] = 1.0f;
    }
  }

  // The vertex sequence: the indices, or 0, 1, 2, ... without them.
  std::vector<std::uint32_t> sequence;
  if (prim.indices >= 0) {
    SINEW_ASSIGN_OR_RETURN(AccessorData ind,
                           read_accessor(c, prim.indices, pfield + ".indices",
                                         {TINYGLTF_TYPE_SCALAR},
                                         {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                                          TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                                          TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT}));
    sequence.resize(ind.count);
    for (std::size_t i = 0; i < ind.count; ++i) {
      const double v = ind.at(i, 0);
      if (v >= static_cast<double>(vcount)) {
        return c.error(ErrorCode::kOutOfBounds, idx(pfield + ".indices", i), num(v),
                       "vertex index past the primitive's " + std::to_string(vcount) +
                           " vertices");
      }
      sequence[i] = static_cast<std::uint32_t>(v);
    }
  } else {
    sequence.resize(vcount);
    for (std::size_t i = 0; i < vcount; ++i) sequence[i] = static_cast<std::uint32_t>(i);
  }
  const std::string count_field = prim.indices >= 0 ? pfield + ".indices" : afield + ".POSITION";
  // Triangles in the spec's order (glTF 2.0, 3.7.2.1): strips alternate
  // their winding so that every triangle faces the same way, fans share the
  // first vertex.
  std::vector<std::array<std::uint32_t, 3>> tris;
  const std::size_t count = sequence.size();
  if (mode == TINYGLTF_MODE_TRIANGLES) {
    if (count % 3 != 0) {
      return c.error(ErrorCode::kInvalidData, count_field, std::to_string(count),
                     prim.indices >= 0 ? "index count is not a multiple of 3"
                                       : "non-indexed primitive whose vertex count is not a multiple of 3");
    }
    tris.resize(count / 3);
    for (std::size_t i = 0; i < count; ++i) tris[i / 3][i % 3] = sequence[i];
  } else {
    if (count < 3) {
      return c.error(ErrorCode::kInvalidData, count_field, std::to_string(count),
                     std::string(mode == TINYGLTF_MODE_TRIANGLE_STRIP ? "a triangle strip" : "a triangle fan") +
                         " needs at least 3 vertices");
    }
    tris.resize(count - 2);
    for (std::size_t i = 0; i + 2 < count; ++i) {
      if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
        tris[i] = {sequence[i], sequence[i + 1 + i % 2], sequence[i + 2 - i % 2]};
      } else {
        tris[i] = {sequence[i + 1], sequence[i + 2], sequence[0]};
      }
    }
  }

  // Computed normals: area-weighted face normals, for missing or zero ones.
  const bool need_normals =
      normals.empty() ||
      std::any_of(normals.begin(), normals.end(), [](const Vec3& n) { return n == Vec3(0.0f); });
  if (need_normals) {
    std::vector<DVec3> acc(vcount, DVec3(0.0));
    for (const auto& t : tris) {
      const DVec3 a(positions[t[0]]), bb(positions[t[1]]), cc(positions[t[2]]);
      const DVec3 n = glm::cross(bb - a, cc - a);
      for (const std::uint32_t v : t) acc[v] += n;
    }
    if (normals.empty()) normals.assign(vcount, Vec3(0.0f));
    for (std::size_t v = 0; v < vcount; ++v) {
      if (normals[v] != Vec3(0.0f)) continue;
      const double len = glm::length(acc[v]);
      normals[v] = len > 0.0 ? Vec3(acc[v] / len) : Vec3(0.0f, 0.0f, 1.0f);
    }
  }

  SkinnedMesh& m = b.mesh;
  if (!uvs.empty() && !b.any_uvs) {
    m.uvs.assign(base, Vec2(0.0f));  // earlier primitives had none
    b.any_uvs = true;
  }
  if (b.any_uvs && uvs.empty()) uvs.assign(vcount, Vec2(0.0f));
  m.positions.insert(m.positions.end(), positions.begin(), positions.end());
  m.normals.insert(m.normals.end(), normals.begin(), normals.end());
  m.uvs.insert(m.uvs.end(), uvs.begin(), uvs.end());
  m.joints.insert(m.joints.end(), joints.begin(), joints.end());
  m.weights.insert(m.weights.end(), weights.begin(), weights.end());
  const std::uint32_t ubase = static_cast<std::uint32_t>(base);
  for (const auto& t : tris) {
    m.triangles.push_back({t[0] + ubase, t[1] + ubase, t[2] + ubase});
    m.triangle_material.push_back(material);
  }
  return {};
}

}  // namespace sinew::editor::gltf_detail
