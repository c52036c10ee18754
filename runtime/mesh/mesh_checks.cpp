#include "runtime/mesh/mesh_checks.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "runtime/core/format_number.h"

namespace sinew {
namespace {

bool finite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool finite(const Vec2& v) { return std::isfinite(v.x) && std::isfinite(v.y); }

std::string text(const Vec3& v) { return format_number(v.x) + " " + format_number(v.y) + " " + format_number(v.z); }
std::string text(const Vec2& v) { return format_number(v.x) + " " + format_number(v.y); }

class Reporter {
 public:
  explicit Reporter(const MeshOrigin& origin) : origin_(origin) {}

  Status error(std::string_view array, std::string_view indices, std::string_view value,
               std::string_view detail) const {
    std::string field(origin_.field_prefix);
    field += array;
    field += indices;
    return make_error(ErrorCode::kInvalidData, origin_.file, field, value, detail);
  }
  Status count(std::string_view array, std::size_t size, std::string_view expected) const {
    return error(array, "", std::to_string(size) + " entries", expected);
  }

 private:
  const MeshOrigin& origin_;
};

std::string at(std::size_t i) { return "[" + std::to_string(i) + "]"; }
std::string at(std::size_t i, std::size_t k) { return at(i) + at(k); }

template <typename T>
Status check_finite(const Reporter& report, std::string_view array, std::span<const T> values) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!finite(values[i])) return report.error(array, at(i), text(values[i]), "not finite");
  }
  return {};
}

}  // namespace

Status check_triangle_mesh(const MeshOrigin& origin, std::span<const Vec3> positions,
                           std::span<const std::array<std::uint32_t, 3>> triangles,
                           std::span<const std::uint32_t> triangle_material, std::span<const Vec3> material_colors) {
  const Reporter report(origin);
  SINEW_RETURN_IF_ERROR(check_finite(report, "positions", positions));
  SINEW_RETURN_IF_ERROR(check_finite(report, "material_colors", material_colors));
  if (!triangle_material.empty() && triangle_material.size() != triangles.size()) {
    return report.count("triangle_material", triangle_material.size(),
                        "expected none or one per triangle (" + std::to_string(triangles.size()) + ")");
  }
  const std::size_t materials = std::max<std::size_t>(material_colors.size(), 1);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    for (std::size_t i = 0; i < 3; ++i) {
      if (triangles[t][i] >= positions.size()) {
        return report.error("triangles", at(t, i), std::to_string(triangles[t][i]),
                            "not below the vertex count (" + std::to_string(positions.size()) + ")");
      }
    }
    if (!triangle_material.empty() && triangle_material[t] >= materials) {
      return report.error("triangle_material", at(t), std::to_string(triangle_material[t]),
                          "no such material (" + std::to_string(material_colors.size()) + " materials)");
    }
  }
  return {};
}

Status check_skinned_mesh(const MeshOrigin& origin, const SkinnedMesh& mesh, std::size_t joint_count) {
  const Reporter report(origin);
  const std::size_t n = mesh.vertex_count();
  const std::string one_per_position = "one per position (" + std::to_string(n) + ")";
  if (mesh.joints.size() != n) return report.count("joints", mesh.joints.size(), "expected " + one_per_position);
  if (mesh.weights.size() != n) return report.count("weights", mesh.weights.size(), "expected " + one_per_position);
  if (!mesh.normals.empty() && mesh.normals.size() != n) {
    return report.count("normals", mesh.normals.size(), "expected none or " + one_per_position);
  }
  if (!mesh.uvs.empty() && mesh.uvs.size() != n) {
    return report.count("uvs", mesh.uvs.size(), "expected none or " + one_per_position);
  }
  SINEW_RETURN_IF_ERROR(check_finite(report, "normals", std::span<const Vec3>(mesh.normals)));
  SINEW_RETURN_IF_ERROR(check_finite(report, "uvs", std::span<const Vec2>(mesh.uvs)));
  for (std::size_t v = 0; v < n; ++v) {
    for (std::size_t k = 0; k < static_cast<std::size_t>(kMaxInfluences); ++k) {
      if (mesh.joints[v][k] >= joint_count) {
        return report.error("joints", at(v, k), std::to_string(mesh.joints[v][k]),
                            "not below the joint count (" + std::to_string(joint_count) + ")");
      }
      const float w = mesh.weights[v][k];
      if (!std::isfinite(w) || w < 0.0f) {
        return report.error("weights", at(v, k), format_number(w), "not a finite weight >= 0");
      }
    }
  }
  SINEW_RETURN_IF_ERROR(check_material_textures(origin, mesh));
  return check_triangle_mesh(origin, mesh.positions, mesh.triangles, mesh.triangle_material, mesh.material_colors);
}

Status check_material_textures(const MeshOrigin& origin, const SkinnedMesh& mesh) {
  const Reporter report(origin);
  if (!mesh.material_texture.empty() && mesh.material_texture.size() != mesh.material_colors.size()) {
    return report.count("material_texture", mesh.material_texture.size(),
                        "expected none or one per material (" + std::to_string(mesh.material_colors.size()) + ")");
  }
  for (std::size_t m = 0; m < mesh.material_texture.size(); ++m) {
    const std::uint32_t texture = mesh.material_texture[m];
    if (texture == kNoTexture) continue;
    if (texture >= mesh.textures.size()) {
      return report.error("material_texture", at(m), std::to_string(texture),
                          "no such texture (" + std::to_string(mesh.textures.size()) + " textures)");
    }
    if (mesh.uvs.empty()) {
      return report.error("material_texture", at(m), std::to_string(texture), "a texture needs the mesh's uvs");
    }
  }
  for (std::size_t t = 0; t < mesh.textures.size(); ++t) {
    const std::string field = std::string(origin.field_prefix) + "textures" + at(t);
    SINEW_RETURN_IF_ERROR(check_texture(mesh.textures[t], origin.file, field));
  }
  return {};
}

}  // namespace sinew
