#include "raytrace/scene/top_level.h"

#include <utility>

namespace sinew::rt {

Status TopLevel::build(std::vector<TopLevelObject>&& objects, const KdBuildOptions& options) {
  objects_ = std::move(objects);
  boxes_.clear();
  boxes_.reserve(objects_.size());
  for (const TopLevelObject& object : objects_) boxes_.push_back(object.box);
  SINEW_ASSIGN_OR_RETURN(tree_, build_kd_tree(boxes_, options));
  return {};
}

std::vector<TopLevelObject> TopLevel::take_objects() {
  std::vector<TopLevelObject> out = std::move(objects_);
  out.clear();
  objects_.clear();
  return out;
}

}  // namespace sinew::rt
