#include "animation/skeleton.h"

#include <cmath>
#include <unordered_map>

namespace sinew::anim {
namespace {

bool finite3(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

std::string joint_field(std::size_t i, std::string_view what) {
  return "joints[" + std::to_string(i) + "]." + std::string(what);
}

}  // namespace

Expected<Skeleton> Skeleton::build(const RawSkeleton& raw, std::string_view source,
                                   std::vector<int>* raw_to_sorted) {
  const std::size_t n = raw.joints.size();
  if (n > kMaxJoints) {
    return make_error(ErrorCode::kLimitExceeded, source, "joint count", std::to_string(n),
                      "more than " + std::to_string(kMaxJoints) + " joints");
  }
  // Validate each joint on its own first.
  std::unordered_map<std::string_view, std::size_t> by_name;
  for (std::size_t i = 0; i < n; ++i) {
    const RawJoint& j = raw.joints[i];
    if (j.parent != kNoParent && (j.parent < 0 || static_cast<std::size_t>(j.parent) >= n)) {
      return make_error(ErrorCode::kOutOfBounds, source, joint_field(i, "parent"),
                        std::to_string(j.parent), "not a joint index (joint count " + std::to_string(n) + ")");
    }
    if (static_cast<std::size_t>(j.parent) == i) {
      return make_error(ErrorCode::kInvalidData, source, joint_field(i, "parent"),
                        std::to_string(j.parent), "a joint cannot be its own parent");
    }
    const Quat& q = j.rest.rotation;
    const float qlen = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
    if (!finite3(j.rest.translation) || !finite3(j.rest.scale) || !std::isfinite(qlen)) {
      return make_error(ErrorCode::kInvalidData, source, joint_field(i, "rest"), j.name,
                        "non-finite rest transform");
    }
    if (qlen < 1e-6f) {
      return make_error(ErrorCode::kInvalidData, source, joint_field(i, "rest.rotation"), "0",
                        "zero-length rotation quaternion");
    }
    if (!is_finite(j.inverse_bind)) {
      return make_error(ErrorCode::kInvalidData, source, joint_field(i, "inverse_bind"), j.name,
                        "non-finite inverse bind matrix");
    }
    if (!j.name.empty()) {
      auto [it, inserted] = by_name.emplace(j.name, i);
      if (!inserted) {
        return make_error(ErrorCode::kDuplicate, source, joint_field(i, "name"), j.name,
                          "same name as joint " + std::to_string(it->second));
      }
    }
  }

  // Topological order by depth-first emission from the roots, children in
  // their raw order, so an already sorted skeleton keeps its order exactly.
  std::vector<std::vector<int>> children(n);
  std::vector<int> roots;
  for (std::size_t i = 0; i < n; ++i) {
    const int p = raw.joints[i].parent;
    (p == kNoParent ? roots : children[static_cast<std::size_t>(p)]).push_back(static_cast<int>(i));
  }
  std::vector<int> order;
  order.reserve(n);
  std::vector<int> stack;
  for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.push_back(*it);
  while (!stack.empty()) {
    const int j = stack.back();
    stack.pop_back();
    order.push_back(j);
    const auto& c = children[static_cast<std::size_t>(j)];
    for (auto it = c.rbegin(); it != c.rend(); ++it) stack.push_back(*it);
  }
  if (order.size() != n) {
    // Joints never reached from a root sit on a parent cycle.
    std::vector<bool> seen(n, false);
    for (int j : order) seen[static_cast<std::size_t>(j)] = true;
    std::size_t first = 0;
    while (seen[first]) ++first;
    return make_error(ErrorCode::kInvalidData, source, joint_field(first, "parent"),
                      std::to_string(raw.joints[first].parent), "the joint hierarchy has a cycle");
  }
  // An already topological input keeps its order (glTF files usually are).
  bool sorted_already = true;
  for (std::size_t i = 0; i < n; ++i) {
    const int p = raw.joints[i].parent;
    if (p != kNoParent && static_cast<std::size_t>(p) >= i) sorted_already = false;
  }
  if (sorted_already) {
    for (std::size_t i = 0; i < n; ++i) order[i] = static_cast<int>(i);
  }

  std::vector<int> remap(n);
  for (std::size_t k = 0; k < n; ++k) remap[static_cast<std::size_t>(order[k])] = static_cast<int>(k);

  Skeleton s;
  s.parents_.resize(n);
  s.rest_.resize(n);
  s.inverse_bind_.resize(n);
  s.names_.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const RawJoint& j = raw.joints[static_cast<std::size_t>(order[k])];
    s.parents_[k] = j.parent == kNoParent ? kNoParent : remap[static_cast<std::size_t>(j.parent)];
    s.rest_[k] = j.rest;
    s.rest_[k].rotation = unit_rotation(j.rest.rotation);
    s.inverse_bind_[k] = j.inverse_bind;
    s.names_[k] = j.name;
  }
  if (raw_to_sorted != nullptr) *raw_to_sorted = std::move(remap);
  return s;
}

std::optional<int> Skeleton::find(std::string_view name) const {
  for (std::size_t i = 0; i < names_.size(); ++i) {
    if (names_[i] == name) return static_cast<int>(i);
  }
  return std::nullopt;
}

}  // namespace sinew::anim
