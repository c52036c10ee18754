// A character's content pack (docs/PACK_FORMAT.md, "Character sections"):
// skeleton, skinned mesh, clips, joint limits, the pose space it was baked
// over, provenance, and the fuzzy kd-trees of the bake.
//
// Loading copies the small, editable parts (skeleton, mesh, clips, limits)
// into their usual types and leaves the fuzzy data where it lies: the
// FuzzyCharacterView of a Pack points into the mapped file, so a
// 300k-triangle pack loads in milliseconds and renders bit-identically to
// the in-memory bake it was written from. Every section is decoded with
// bounds checks and validated (indices, counts, finite values, kd-tree
// links and depth) before anything is handed out: a pack that loads is safe
// to render, whatever bytes it was made of.
//
// A pack without fuzzy sections is a model only (`sinew-editor subdivide`
// writes those); `bake` accepts it as its MODEL.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "animation/joint_limits.h"
#include "animation/pose_space.h"
#include "character/model.h"
#include "raytrace/fuzzy/fuzzy_character.h"
#include "runtime/core/expected.h"
#include "runtime/math/aabb.h"
#include "runtime/pack/pack_reader.h"

namespace sinew::character {

// How the fuzzy boxes were sampled: enough to repeat the bake.
struct PoseSpaceRecord {
  anim::PoseSpaceDesc desc;
  float padding = 0.0f;  // FuzzyBakeOptions::padding
  rt::CandidateBones candidates = rt::CandidateBones::kAll;
};

struct Provenance {
  std::string source_name;        // the model file's name (no folders)
  std::uint64_t source_hash = 0;  // XXH3-64 of its bytes (0 for a procedural model)
  std::string tool_version;       // "sinew-editor 0.1.0"
  std::int64_t bake_unix_time = 0;  // seconds since 1970 UTC; SOURCE_DATE_EPOCH when set
  double pose_sampling_ms = 0.0;  // 0 in reproducible bakes (SOURCE_DATE_EPOCH set)
  double sampling_ms = 0.0;
  double assignment_ms = 0.0;
  double build_ms = 0.0;
};

// How a character stands (the FRAM section): the axis it stands along and
// its bounds at the skeleton's rest pose, skinned, in model space: the
// convention the mixer poses it in. Not the mesh as stored (its bind pose),
// which an importer may keep in another orientation (CesiumMan's mesh is
// Z-up, its posed skeleton Y-up).
struct PackFraming {
  Aabb rest_bounds;  // never empty in a pack that loads
  int up_axis = 1;   // 1 (+Y) or 2 (+Z)
};
// The framing computed from the model (character/framing.h: rest_bounds,
// up_axis_of). Errors: a rest pose that cannot be computed or bounds nothing.
Expected<PackFraming> framing_of(const Model& model);

// What goes into a pack. `fuzzy` null: a model-only pack.
struct PackContents {
  const Model* model = nullptr;
  std::span<const anim::JointLimit> limits;  // empty: none stored
  const rt::FuzzyCharacterData* fuzzy = nullptr;
  PoseSpaceRecord pose_space;
  Provenance provenance;
  // Written as FRAM; empty: framing_of(*model).
  std::optional<PackFraming> framing;
};

// The pack's bytes: the same contents give the same bytes.
Expected<std::vector<std::byte>> serialize_pack(const PackContents& contents);
// Written atomically: `path` keeps its old contents unless the whole new
// pack is in place, and the new pack replaces it only after it loaded and
// validated (Pack::open) from the written bytes: a pack that
// would not load is never left behind. `cancelled`, when given, is asked
// after that check: true (a signal arrived while writing) discards the
// written file and returns kCancelled, `path` untouched.
Status write_pack(const std::string& path, const PackContents& contents,
                  const std::function<bool()>& cancelled = {});

class Pack {
 public:
  // Maps and validates a pack file. Errors name the file, the section and
  // the field (`cally.pack: MESH.triangles[12]: index 9999 ...`).
  static Expected<Pack> open(const std::string& path);
  // The same over bytes the caller keeps alive (tests, fuzzing).
  static Expected<Pack> from_bytes(std::span<const std::byte> bytes, const std::string& name);

  const Model& model() const { return model_; }
  std::span<const anim::JointLimit> limits() const { return limits_; }
  bool has_fuzzy() const { return has_fuzzy_; }
  // Spans into the pack (valid while this object lives; moving keeps them valid).
  const rt::FuzzyCharacterView& fuzzy() const { return fuzzy_; }
  const rt::FuzzyBakeStats& fuzzy_stats() const { return stats_; }
  const PoseSpaceRecord& pose_space() const { return pose_space_; }
  const Provenance& provenance() const { return provenance_; }
  // FRAM's framing, or, in a pack written before the section, framing_of
  // the loaded model (framing_stored() false).
  const PackFraming& framing() const { return framing_; }
  bool framing_stored() const { return framing_stored_; }
  const PackReader& reader() const { return reader_; }

  Pack(Pack&&) noexcept = default;
  Pack& operator=(Pack&&) noexcept = default;

 private:
  explicit Pack(PackReader reader) : reader_(std::move(reader)) {}
  static Expected<Pack> load(PackReader reader);

  PackReader reader_;
  Model model_;
  anim::JointLimits limits_;
  bool has_fuzzy_ = false;
  rt::FuzzyCharacterView fuzzy_;
  rt::FuzzyBakeStats stats_;
  PoseSpaceRecord pose_space_;
  Provenance provenance_;
  PackFraming framing_;
  bool framing_stored_ = false;
};

// True when `path` names a content pack by its extension (".pack").
bool is_pack_path(const std::string& path);

}  // namespace sinew::character
