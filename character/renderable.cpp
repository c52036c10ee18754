#include "character/renderable.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace sinew::character {
namespace {

// Past this a bound is as good as infinite; capping keeps 0 * bound at 0.
constexpr double kSaturated = 1e300;

double max_abs(const Vec3& v) {
  return std::max({std::fabs(static_cast<double>(v.x)), std::fabs(static_cast<double>(v.y)),
                   std::fabs(static_cast<double>(v.z))});
}

double length(const Vec3& v) {
  const double x = static_cast<double>(v.x), y = static_cast<double>(v.y), z = static_cast<double>(v.z);
  return std::sqrt(x * x + y * y + z * z);
}

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

std::string limit_text() { return "past the limit " + number(kMaxCoordinate) + " (character::kMaxCoordinate)"; }

Status past_limit(std::string_view file, const std::string& field, const std::string& value, std::string_view what) {
  return make_error(ErrorCode::kInvalidData, file, field, value,
                    std::string(what) + " " + limit_text() + " that every consumer can frame and trace");
}

std::string joint_field(const ModelFields& fields, std::size_t j) {
  return std::string(fields.skeleton) + "joints[" + std::to_string(j) + "]";
}

// The largest `norm` a vector track can take between its keys: the keys
// themselves, and for a cubic spline the tangents' pull, at most 4/27 of
// each tangent times its interval (the Hermite basis), from both ends.
// Every stored value (tangents included) must lie within the limit.
Status track_reach(const anim::Track<Vec3>& track, double (*norm)(const Vec3&), std::string_view file,
                   const std::string& field, double& reach) {
  const bool cubic = track.interpolation == anim::Interpolation::kCubicSpline;
  double longest_interval = 0.0;
  for (std::size_t k = 1; k < track.times.size(); ++k) {
    longest_interval = std::max(longest_interval, static_cast<double>(track.times[k]) - static_cast<double>(track.times[k - 1]));
  }
  double values = 0.0, tangents = 0.0;
  for (std::size_t i = 0; i < track.values.size(); ++i) {
    const Vec3& v = track.values[i];
    if (max_abs(v) > kMaxCoordinate) {
      return past_limit(file, field + ".values[" + std::to_string(i) + "]", number(max_abs(v)), "a component");
    }
    const bool tangent = cubic && i % 3 != 1;
    (tangent ? tangents : values) = std::max(tangent ? tangents : values, norm(v));
  }
  reach = std::max(reach, values + 2.0 * (4.0 / 27.0) * longest_interval * tangents);
  return {};
}

struct JointReach {
  double scale = 0.0;        // the largest scale (operator norm of R S) the joint's local transform takes
  double translation = 0.0;  // the longest local translation
};

Status stored_values(const Model& model, std::string_view file, const ModelFields& fields,
                     std::vector<JointReach>& reach) {
  const auto rest = model.skeleton.rest_pose();
  const auto inverse_bind = model.skeleton.inverse_bind();
  for (std::size_t j = 0; j < rest.size(); ++j) {
    const std::string f = joint_field(fields, j);
    if (max_abs(rest[j].translation) > kMaxCoordinate) {
      return past_limit(file, f + ".translation", number(max_abs(rest[j].translation)), "a component");
    }
    if (max_abs(rest[j].scale) > kMaxCoordinate) {
      return past_limit(file, f + ".scale", number(max_abs(rest[j].scale)), "a component");
    }
    for (const Vec4& row : inverse_bind[j].rows) {
      for (int c = 0; c < 4; ++c) {
        if (std::fabs(static_cast<double>(row[c])) > kMaxCoordinate) {
          return past_limit(file, f + ".inverse_bind", number(static_cast<double>(row[c])), "an entry");
        }
      }
    }
    reach[j].scale = max_abs(rest[j].scale);
    reach[j].translation = length(rest[j].translation);
  }
  const auto& positions = model.mesh.positions;
  for (std::size_t v = 0; v < positions.size(); ++v) {
    if (max_abs(positions[v]) > kMaxCoordinate) {
      return past_limit(file, std::string(fields.mesh) + "positions[" + std::to_string(v) + "]",
                        number(max_abs(positions[v])), "a coordinate");
    }
  }
  for (std::size_t c = 0; c < model.clips.size(); ++c) {
    const auto tracks = model.clips[c].tracks();
    for (std::size_t t = 0; t < tracks.size(); ++t) {
      const std::string f =
          std::string(fields.clips) + "[" + std::to_string(c) + "].tracks[" + std::to_string(t) + "]";
      JointReach& r = reach[static_cast<std::size_t>(tracks[t].joint)];
      SINEW_RETURN_IF_ERROR(track_reach(tracks[t].translation, length, file, f + ".translation", r.translation));
      SINEW_RETURN_IF_ERROR(track_reach(tracks[t].scale, max_abs, file, f + ".scale", r.scale));
    }
  }
  return {};
}

// Bounds of a matrix's linear part (Frobenius, >= the operator norm) and
// its translation.
double linear_norm(const Affine3& m) {
  double sum = 0.0;
  for (const Vec4& row : m.rows) {
    for (int c = 0; c < 3; ++c) sum += static_cast<double>(row[c]) * static_cast<double>(row[c]);
  }
  return std::sqrt(sum);
}

}  // namespace

Status check_renderable(const Model& model, std::string_view file, const ModelFields& fields) {
  if (model.mesh.triangle_count() == 0) {
    return make_error(ErrorCode::kInvalidData, file, std::string(fields.mesh) + "triangle_count", "0",
                      "the model has no triangles: nothing to frame or trace");
  }
  const std::size_t joints = model.skeleton.joint_count();
  std::vector<JointReach> local(joints);
  SINEW_RETURN_IF_ERROR(stored_values(model, file, fields, local));

  // Along each chain (parents come first): model-space scale and reach,
  // then the skinning matrix's (model * inverse bind).
  const auto parents = model.skeleton.parents();
  const auto inverse_bind = model.skeleton.inverse_bind();
  std::vector<double> skin_scale(joints), skin_offset(joints);
  std::vector<double> scale(joints), offset(joints);
  for (std::size_t j = 0; j < joints; ++j) {
    const int p = parents[j];
    const double parent_scale = p < 0 ? 1.0 : scale[static_cast<std::size_t>(p)];
    const double parent_offset = p < 0 ? 0.0 : offset[static_cast<std::size_t>(p)];
    scale[j] = std::min(parent_scale * local[j].scale, kSaturated);
    offset[j] = std::min(parent_offset + parent_scale * local[j].translation, kSaturated);
    skin_scale[j] = std::min(scale[j] * linear_norm(inverse_bind[j]), kSaturated);
    skin_offset[j] = std::min(scale[j] * length(inverse_bind[j].translation_part()) + offset[j], kSaturated);
    const double worst = std::max({scale[j], offset[j], skin_scale[j], skin_offset[j]});
    if (worst > kMaxCoordinate) {
      return past_limit(file, joint_field(fields, j), "reach " + number(worst),
                        "its chain's scales multiplied and translations added up (rest pose and clip keys) reach");
    }
  }
  const SkinnedMesh& mesh = model.mesh;
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    const double radius = length(mesh.positions[v]);
    for (int k = 0; k < kMaxInfluences; ++k) {
      if (!(mesh.weights[v][k] > 0.0f)) continue;
      const std::size_t j = mesh.joints[v][k];
      if (j >= joints) continue;  // refused by the mesh checks, which come first
      const double reach = skin_scale[j] * radius + skin_offset[j];
      if (reach > kMaxCoordinate) {
        return past_limit(file, joint_field(fields, j), "reach " + number(reach),
                          "a pose can carry vertex " + std::to_string(v) + " this far from the origin,");
      }
    }
  }
  return {};
}

}  // namespace sinew::character
