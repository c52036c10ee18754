#include "raytrace/accel/top_level.h"

#include <algorithm>
#include <utility>

namespace sinew::rt {
namespace {

bool same_run(const TopLevelObject& a, const TopLevelObject& b) {
  return a.kind != TopLevelObject::Kind::kStatic && b.kind != TopLevelObject::Kind::kStatic && a.index == b.index;
}

// Grows `run` by both corners of `box` on every axis, so it holds an
// inverted (empty) box's coordinates too.
void grow_run(ObjectRun& run, const Aabb& box) {
  for (int a = 0; a < 3; ++a) {
    run.box.lower[a] = std::min({run.box.lower[a], box.lower[a], box.upper[a]});
    run.box.upper[a] = std::max({run.box.upper[a], box.lower[a], box.upper[a]});
  }
}

}  // namespace

Status TopLevel::build(std::vector<TopLevelObject>&& objects, const KdBuildOptions& options) {
  objects_ = std::move(objects);
  boxes_.clear();
  boxes_.reserve(objects_.size());
  for (const TopLevelObject& object : objects_) boxes_.push_back(object.box);
  runs_.clear();
  for (std::uint32_t i = 0; i < objects_.size(); ++i) {
    if (runs_.empty() || !same_run(objects_[runs_.back().first], objects_[i])) runs_.push_back({i, 0, Aabb::empty()});
    ++runs_.back().count;
    grow_run(runs_.back(), objects_[i].box);
  }
  SINEW_ASSIGN_OR_RETURN(tree_, build_kd_tree(boxes_, options));
  return {};
}

void TopLevel::set_mask(bool static_mesh, std::uint32_t index, std::uint32_t mask) {
  for (const ObjectRun& run : runs_) {
    const TopLevelObject& first = objects_[run.first];
    if ((first.kind == TopLevelObject::Kind::kStatic) != static_mesh || first.index != index) continue;
    for (std::uint32_t i = run.first; i < run.first + run.count; ++i) objects_[i].mask = mask;
  }
}

std::vector<TopLevelObject> TopLevel::take_objects() {
  std::vector<TopLevelObject> out = std::move(objects_);
  out.clear();
  objects_.clear();
  runs_.clear();
  return out;
}

}  // namespace sinew::rt
