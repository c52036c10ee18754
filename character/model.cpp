#include "character/model.h"

#include <charconv>
#include <cmath>
#include <cstdio>

#include "runtime/core/format_number.h"

namespace sinew::character {
namespace {

std::string weight_field(std::size_t v) { return "weights[" + std::to_string(v) + "]"; }

// A sum of float weights to six digits: the float rounding of each weight
// (1.02 summed as 1.01999998) says nothing to the reader.
std::string sum_text(double sum) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", sum);
  return text;
}


}  // namespace

const anim::Clip* Model::find_clip(const std::string& name) const {
  if (!name.empty() && name[0] == '#') {
    std::size_t index = 0;
    const char* first = name.data() + 1;
    const char* last = name.data() + name.size();
    const auto [end, ec] = std::from_chars(first, last, index);
    if (ec != std::errc() || end != last || index >= clips.size()) return nullptr;
    return &clips[index];
  }
  for (const anim::Clip& c : clips) {
    if (c.name() == name) return &c;
  }
  return nullptr;
}

Status normalize_skin_weights(SkinnedMesh& mesh, std::string_view source, std::vector<std::string>& warnings) {
  if (mesh.weights.size() != mesh.vertex_count()) {
    return make_error(ErrorCode::kInvalidData, source, "weights", std::to_string(mesh.weights.size()) + " rows",
                      "expected one row per vertex (" + std::to_string(mesh.vertex_count()) + ")");
  }
  std::size_t off_rows = 0;
  std::size_t first_off = 0;
  double first_off_sum = 0.0;
  for (std::size_t v = 0; v < mesh.weights.size(); ++v) {
    auto& row = mesh.weights[v];
    double sum = 0.0;
    for (std::size_t k = 0; k < row.size(); ++k) {
      const float w = row[k];
      if (!std::isfinite(w) || w < 0.0f) {
        return make_error(ErrorCode::kInvalidData, source, weight_field(v) + "[" + std::to_string(k) + "]",
                          std::to_string(w), "a skin weight must be finite and >= 0");
      }
      sum += static_cast<double>(w);
    }
    if (!(sum > 0.0)) {
      return make_error(ErrorCode::kInvalidData, source, weight_field(v), "0",
                        "the vertex's weights are all zero: it belongs to no bone");
    }
    if (sum == 1.0) continue;  // keeps the bits of already normalised rows
    if (std::fabs(sum - 1.0) > kSkinWeightSumTolerance && off_rows++ == 0) {
      first_off = v;
      first_off_sum = sum;
    }
    for (float& w : row) w = static_cast<float>(static_cast<double>(w) / sum);
  }
  if (off_rows > 0) {
    warnings.push_back(std::string(source) + ": " + weight_field(first_off) + ": skin weights sum to " +
                       format_number(first_off_sum) + ", not 1; renormalised (" + std::to_string(off_rows) +
                       " of " + std::to_string(mesh.weights.size()) + " vertices)");
  }
  return {};
}

Status check_skin_weight_sums(const SkinnedMesh& mesh, std::string_view file, std::string_view field_prefix) {
  for (std::size_t v = 0; v < mesh.weights.size(); ++v) {
    double sum = 0.0;
    for (const float w : mesh.weights[v]) sum += static_cast<double>(w);
    if (!(sum > 0.0)) {
      return make_error(ErrorCode::kInvalidData, file, std::string(field_prefix) + weight_field(v), "0",
                        "the vertex's skin weights are all zero: it belongs to no bone");
    }
    if (std::fabs(sum - 1.0) > kSkinWeightSumTolerance) {
      return make_error(ErrorCode::kInvalidData, file, std::string(field_prefix) + weight_field(v),
                        "sum " + sum_text(sum),
                        "skin weights must sum to 1 (within " + format_number(kSkinWeightSumTolerance) + ")");
    }
  }
  return {};
}

}  // namespace sinew::character
