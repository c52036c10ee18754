// A model baked in memory and loaded through the public API, for the
// benchmarks that drive Sinew as a host engine does (sinew/world.h): the
// in-memory bake is serialised as a character pack and handed to
// api::Character::from_memory, so the World sees exactly what a pack file
// would give it, without a file on disk.
//
// Ownership: the object owns the pack's bytes, which the Character (and
// every World instance made from it) points into; it must outlive them.
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "character/bake.h"
#include "character/model.h"
#include "character/pack.h"
#include "runtime/core/expected.h"
#include "runtime/jobs/job_system.h"
#include "sinew/character.h"
#include "sinew/result.h"

namespace sinew::bench {

// An API error as the benchmarks' Status, its message kept; `what` names
// the call that failed ("World::intersect").
inline Status status_from_api(const api::Error& error, const std::string& what) {
  return make_error(ErrorCode::kInternal, "", what, "", error.message);
}
inline Status status_from_api(const api::Status& status, const std::string& what) {
  return status.ok() ? Status{} : status_from_api(status.error(), what);
}

class ApiCharacter {
 public:
  // Bakes `model` over the default pose space (every clip) on `jobs` and
  // loads the resulting pack. `name` appears in the Character's errors.
  // Errors: the bake's, the pack writer's, or the API's load error.
  static Expected<std::unique_ptr<ApiCharacter>> bake(const character::Model& model, const std::string& name,
                                                      JobSystem& jobs) {
    SINEW_ASSIGN_OR_RETURN(const character::InMemoryBake baked,
                           character::bake_in_memory(model, character::BakeRequest{}, jobs));
    character::PackContents contents;
    contents.model = &model;
    contents.fuzzy = &baked.fuzzy;
    contents.pose_space.desc = character::default_pose_space();
    contents.provenance.source_name = name;
    contents.provenance.tool_version = "sinew-bench";
    auto result = std::unique_ptr<ApiCharacter>(new ApiCharacter());
    SINEW_ASSIGN_OR_RETURN(result->bytes_, character::serialize_pack(contents));
    auto loaded = api::Character::from_memory(result->bytes_, name);
    if (!loaded.ok()) return status_from_api(loaded.error(), "Character::from_memory");
    result->character_.emplace(std::move(loaded).value());
    return result;
  }

  const api::Character& character() const { return *character_; }
  std::size_t pack_bytes() const { return bytes_.size(); }

 private:
  ApiCharacter() = default;
  std::vector<std::byte> bytes_;
  std::optional<api::Character> character_;
};

}  // namespace sinew::bench
