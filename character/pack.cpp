#include "character/pack.h"

#include <cmath>
#include <cstddef>
#include <cstring>
#include <utility>

#include "character/framing.h"
#include "character/pack_textures.h"
#include "character/renderable.h"
#include "raytrace/bake/fuzzy_bake.h"
#include "runtime/mesh/mesh_checks.h"
#include "runtime/pack/pack_writer.h"
#include "runtime/pack/section_codec.h"

namespace sinew::character {
namespace {

// Section ids and the payload versions this build writes and reads.
constexpr SectionId kSkeleton = make_section_id("SKEL");
constexpr SectionId kMesh = make_section_id("MESH");
constexpr SectionId kClips = make_section_id("CLIP");
constexpr SectionId kLimits = make_section_id("LIMT");
constexpr SectionId kPoseSpace = make_section_id("POSE");
constexpr SectionId kProvenance = make_section_id("PROV");
// Optional: packs written before it compute their framing on load.
constexpr SectionId kFraming = make_section_id("FRAM");
constexpr SectionId kFuzzyHeader = make_section_id("FZHD");
constexpr SectionId kTriangleBone = make_section_id("FTBN");
constexpr SectionId kBoneTrees = make_section_id("FBTR");
constexpr SectionId kNodes = make_section_id("FNOD");
constexpr SectionId kItems = make_section_id("FITM");
// BVH bone trees (FuzzyBakeOptions::bone_trees = kBvh): their nodes in FBVN
// instead of FNOD, which such a pack does not write; its FITM (each
// triangle once per tree) is version kBvhTreesVersion, so a reader that
// predates BVHs refuses it by version rather than reading BVH items as
// kd-tree leaves.
constexpr SectionId kBvhNodes = make_section_id("FBVN");
constexpr SectionId kVertexCheckBegin = make_section_id("FVCB");
constexpr SectionId kVertexChecks = make_section_id("FVCK");
constexpr SectionId kTriangleChecks = make_section_id("FTCK");
// Pose-space clusters (FuzzyBakeOptions::pose_clusters), written only by a
// bake that clustered: a pack without them has none of these sections and
// is byte for byte what it was before they existed. The clusters' trees
// follow the bones' in FNOD and FITM, which such a pack writes as version
// kClusteredTreesVersion: a reader that predates clusters refuses it as a
// version it does not read, rather than finding nodes no bone tree covers.
constexpr SectionId kClusterHeader = make_section_id("FCHD");
constexpr SectionId kBoneClusterBegin = make_section_id("FCLB");
constexpr SectionId kClusters = make_section_id("FCLS");
constexpr SectionId kCheckRank = make_section_id("FCKR");
constexpr SectionId kClusterBoxes = make_section_id("FCLX");
constexpr SectionId kFeatureBoneBegin = make_section_id("FFBB");
constexpr SectionId kFeatureBones = make_section_id("FFBN");
constexpr SectionId kClusterCentres = make_section_id("FCCN");
// Every cluster section but the header, which says the others are there.
constexpr SectionId kClusterArrays[] = {kBoneClusterBegin, kClusters,     kCheckRank,     kClusterBoxes,
                                        kFeatureBoneBegin, kFeatureBones, kClusterCentres};
constexpr std::uint32_t kSectionVersion = 1;
// FNOD and FITM of a pack with clusters: the bones' trees, then the clusters'.
constexpr std::uint32_t kClusteredTreesVersion = 2;
// FITM of a pack with BVH bone trees (FBVN), with or without clusters.
constexpr std::uint32_t kBvhTreesVersion = 3;
// LIMT version 1 held the limits as JSON text; version 2 is binary, so
// loading a pack parses no JSON (JSON stays the editor's authoring format).
constexpr std::uint32_t kLimitsVersion = 2;

// Counts a pack may declare: beyond them a file is refused before any
// allocation (a corrupt count must not exhaust memory).
constexpr std::uint32_t kMaxClips = 65536;
constexpr std::uint32_t kMaxMaterials = 65536;


// --- encoding ------------------------------------------------------------------

std::vector<std::byte> encode_skeleton(const anim::Skeleton& skeleton) {
  SectionEncoder e;
  e.put(static_cast<std::uint32_t>(skeleton.joint_count()));
  for (std::size_t j = 0; j < skeleton.joint_count(); ++j) {
    e.put_string(skeleton.names()[j]);
    e.put(static_cast<std::int32_t>(skeleton.parents()[j]));
    const anim::JointTransform& rest = skeleton.rest_pose()[j];
    e.put(rest.translation);
    e.put(rest.rotation);
    e.put(rest.scale);
    e.put(skeleton.inverse_bind()[j]);
  }
  return std::move(e.bytes());
}

std::vector<std::byte> encode_mesh(const Model& model) {
  const SkinnedMesh& m = model.mesh;
  SectionEncoder e;
  e.put(static_cast<std::uint32_t>(m.vertex_count()));
  e.put(static_cast<std::uint32_t>(m.triangle_count()));
  e.put(static_cast<std::uint32_t>(m.material_colors.size()));
  e.put(static_cast<std::uint8_t>(!m.normals.empty()));
  e.put(static_cast<std::uint8_t>(!m.uvs.empty()));
  e.put(static_cast<std::uint8_t>(!m.triangle_material.empty()));
  e.put(static_cast<std::uint8_t>(!model.material_names.empty()));
  e.put_array<Vec3>(m.positions);
  e.put_array<Vec3>(m.normals);
  e.put_array<Vec2>(m.uvs);
  e.put_array<std::array<std::uint16_t, kMaxInfluences>>(m.joints);
  e.put_array<std::array<float, kMaxInfluences>>(m.weights);
  e.put_array<std::array<std::uint32_t, 3>>(m.triangles);
  e.put_array<std::uint32_t>(m.triangle_material);
  e.put_array<Vec3>(m.material_colors);
  for (const std::string& name : model.material_names) e.put_string(name);
  return std::move(e.bytes());
}

template <typename T>
void encode_track(SectionEncoder& e, const anim::Track<T>& track) {
  e.put(static_cast<std::uint8_t>(track.interpolation));
  e.put(static_cast<std::uint32_t>(track.times.size()));
  e.put(static_cast<std::uint32_t>(track.values.size()));
  e.put_array<float>(track.times);
  e.put_array<T>(track.values);
}

std::vector<std::byte> encode_clips(std::span<const anim::Clip> clips) {
  SectionEncoder e;
  e.put(static_cast<std::uint32_t>(clips.size()));
  for (const anim::Clip& clip : clips) {
    e.put_string(clip.name());
    e.put(static_cast<std::uint32_t>(clip.tracks().size()));
    for (const anim::JointTracks& jt : clip.tracks()) {
      e.put(static_cast<std::int32_t>(jt.joint));
      encode_track(e, jt.translation);
      encode_track(e, jt.rotation);
      encode_track(e, jt.scale);
    }
  }
  return std::move(e.bytes());
}

std::vector<std::byte> encode_pose_space(const PoseSpaceRecord& r) {
  SectionEncoder e;
  e.put(static_cast<std::uint8_t>(r.desc.mode));
  e.put(static_cast<std::uint8_t>(r.desc.every_frame_30hz));
  e.put(static_cast<std::uint8_t>(r.candidates));
  e.put(std::uint8_t{0});
  e.put(static_cast<std::int32_t>(r.desc.samples));
  e.put(static_cast<std::uint64_t>(r.desc.seed));
  e.put(r.padding);
  e.put(static_cast<std::uint32_t>(r.desc.clips.size()));
  for (const std::string& name : r.desc.clips) e.put_string(name);
  return std::move(e.bytes());
}

// Per joint: kind, Euler order, two reserved bytes, then every field of
// both limit forms (the unused one as its defaults), 56 bytes a joint.
std::vector<std::byte> encode_limits(std::span<const anim::JointLimit> limits) {
  SectionEncoder e;
  e.put(static_cast<std::uint32_t>(limits.size()));
  for (const anim::JointLimit& l : limits) {
    e.put(static_cast<std::uint8_t>(l.kind));
    e.put(static_cast<std::uint8_t>(l.euler.order));
    e.put(std::uint16_t{0});
    for (const Vec3& v : {l.euler.min, l.euler.max, l.swing_twist.twist_axis}) {
      for (int a = 0; a < 3; ++a) e.put(v[a]);
    }
    e.put(l.swing_twist.swing_max_1);
    e.put(l.swing_twist.swing_max_2);
    e.put(l.swing_twist.twist_min);
    e.put(l.swing_twist.twist_max);
  }
  return std::move(e.bytes());
}

std::vector<std::byte> encode_provenance(const Provenance& p) {
  SectionEncoder e;
  e.put_string(p.source_name);
  e.put(p.source_hash);
  e.put_string(p.tool_version);
  e.put(p.bake_unix_time);
  e.put(p.pose_sampling_ms);
  e.put(p.sampling_ms);
  e.put(p.assignment_ms);
  e.put(p.build_ms);
  return std::move(e.bytes());
}

// FRAM: u8 up axis (1 or 2), three zero bytes, the rest bounds' lower and
// upper corners (f32[3] each): 28 bytes.
std::vector<std::byte> encode_framing(const PackFraming& f) {
  SectionEncoder e;
  e.put(static_cast<std::uint8_t>(f.up_axis));
  for (int i = 0; i < 3; ++i) e.put(std::uint8_t{0});
  for (int a = 0; a < 3; ++a) e.put(f.rest_bounds.lower[a]);
  for (int a = 0; a < 3; ++a) e.put(f.rest_bounds.upper[a]);
  return std::move(e.bytes());
}

// The fuzzy header: counts and the bake's quality figures (timings live in
// the provenance, so that they can be zeroed for reproducible bakes).
struct FuzzyHeader {
  std::uint32_t bone_count;
  std::uint32_t sample_count;
  std::uint32_t vertex_count;
  std::uint32_t triangle_count;
  std::uint32_t node_count;
  std::int32_t max_depth;
  std::uint8_t candidates;
  std::uint8_t merge_rigid_bones;  // 0 or 1; 0 in packs from before the option (then merged_bones is 0)
  std::uint16_t merged_bones;      // bones that stood for their parent (FuzzyBakeStats::merged_bones)
  std::uint8_t reserved[4];
  double fuzzy_area;
  double rest_area;
  double mean_items_per_leaf;
};
static_assert(sizeof(FuzzyHeader) == 56 && std::is_trivially_copyable_v<FuzzyHeader>);

// The cluster header (FCHD): the scalars of the cluster data and the
// clustering's figures. clustering_ms is a timing and, like the other
// timings, stays out of the fuzzy sections; it is not stored at all, since
// the provenance (PROV) has no room for it without changing every pack's
// bytes, so a loaded pack reports 0.
struct ClusterHeader {
  float feature_translation_scale;  // FuzzyCharacterData::feature_translation_scale, finite and > 0
  std::uint32_t clusters_per_bone;  // FuzzyBakeOptions::pose_clusters, 1 to rt::kMaxPoseClusters
  std::uint32_t cluster_count;      // FCLS entries
  std::uint8_t reserved[4];         // zero
  double cluster_fuzzy_area;        // FuzzyBakeStats::cluster_fuzzy_area
};
static_assert(sizeof(ClusterHeader) == 24 && std::is_trivially_copyable_v<ClusterHeader>);
static_assert(offsetof(ClusterHeader, clusters_per_bone) == 4 && offsetof(ClusterHeader, cluster_count) == 8 &&
              offsetof(ClusterHeader, reserved) == 12 && offsetof(ClusterHeader, cluster_fuzzy_area) == 16,
              "no padding: every byte of FCHD is a named field");

template <typename T>
std::span<const std::byte> bytes_of(std::span<const T> values) {
  return std::as_bytes(values);
}

// --- decoding ------------------------------------------------------------------

// An error of a validating builder run over a section's contents, named as
// the section's own are: "x.pack: SKEL.joints[3].rest = ..." (the builders
// name no file; the pack path used to run into the section's name).
Status in_section(const SectionDecoder& d, const Status& s, const std::string& prefix = "") {
  const std::string field = prefix + std::string(s.field());
  return make_error(s.code(), d.pack(), field.empty() ? d.section() : d.section() + "." + field, s.value(), s.detail());
}

Expected<anim::Skeleton> decode_skeleton(SectionDecoder& d) {
  std::uint32_t count = 0;
  SINEW_RETURN_IF_ERROR(d.get(count, "joint_count"));
  if (count > anim::kMaxJoints) {
    return d.error("joint_count", std::to_string(count), "more than " + std::to_string(anim::kMaxJoints) + " joints",
                   ErrorCode::kLimitExceeded);
  }
  anim::RawSkeleton raw;
  raw.joints.resize(count);
  for (std::uint32_t j = 0; j < count; ++j) {
    const std::string f = "joints[" + std::to_string(j) + "]";
    anim::RawJoint& joint = raw.joints[j];
    std::int32_t parent = 0;
    SINEW_RETURN_IF_ERROR(d.get_string(joint.name, f + ".name"));
    SINEW_RETURN_IF_ERROR(d.get(parent, f + ".parent"));
    // Stored parent-first: a loaded skeleton keeps the indices the mesh,
    // the clips and the fuzzy data refer to.
    if (parent < anim::kNoParent || parent >= static_cast<std::int32_t>(j)) {
      return d.error(f + ".parent", std::to_string(parent), "not an earlier joint (joints are stored parent first)",
                     ErrorCode::kOutOfBounds);
    }
    joint.parent = parent;
    SINEW_RETURN_IF_ERROR(d.get(joint.rest.translation, f + ".translation"));
    SINEW_RETURN_IF_ERROR(d.get(joint.rest.rotation, f + ".rotation"));
    SINEW_RETURN_IF_ERROR(d.get(joint.rest.scale, f + ".scale"));
    SINEW_RETURN_IF_ERROR(d.get(joint.inverse_bind, f + ".inverse_bind"));
  }
  SINEW_RETURN_IF_ERROR(d.finish());
  // Parent-first input keeps its order exactly (Skeleton::build).
  auto skeleton = anim::Skeleton::build(raw, "");
  if (!skeleton.ok()) return in_section(d, skeleton.status());
  return std::move(*skeleton);
}

Status decode_mesh(SectionDecoder& d, std::size_t joint_count, Model& model) {
  SkinnedMesh& m = model.mesh;
  std::uint32_t vertices = 0, triangles = 0, materials = 0;
  std::uint8_t has_normals = 0, has_uvs = 0, has_triangle_material = 0, has_names = 0;
  SINEW_RETURN_IF_ERROR(d.get(vertices, "vertex_count"));
  SINEW_RETURN_IF_ERROR(d.get(triangles, "triangle_count"));
  SINEW_RETURN_IF_ERROR(d.get(materials, "material_count"));
  SINEW_RETURN_IF_ERROR(d.get(has_normals, "has_normals"));
  SINEW_RETURN_IF_ERROR(d.get(has_uvs, "has_uvs"));
  SINEW_RETURN_IF_ERROR(d.get(has_triangle_material, "has_triangle_material"));
  SINEW_RETURN_IF_ERROR(d.get(has_names, "has_material_names"));
  if (materials > kMaxMaterials) {
    return d.error("material_count", std::to_string(materials), "more than " + std::to_string(kMaxMaterials),
                   ErrorCode::kLimitExceeded);
  }
  SINEW_RETURN_IF_ERROR(d.get_array(vertices, m.positions, "positions"));
  SINEW_RETURN_IF_ERROR(d.get_array(has_normals ? vertices : 0u, m.normals, "normals"));
  SINEW_RETURN_IF_ERROR(d.get_array(has_uvs ? vertices : 0u, m.uvs, "uvs"));
  SINEW_RETURN_IF_ERROR(d.get_array(vertices, m.joints, "joints"));
  SINEW_RETURN_IF_ERROR(d.get_array(vertices, m.weights, "weights"));
  SINEW_RETURN_IF_ERROR(d.get_array(triangles, m.triangles, "triangles"));
  SINEW_RETURN_IF_ERROR(d.get_array(has_triangle_material ? triangles : 0u, m.triangle_material, "triangle_material"));
  SINEW_RETURN_IF_ERROR(d.get_array(materials, m.material_colors, "material_colors"));
  model.material_names.assign(has_names ? materials : 0u, std::string());
  for (std::size_t i = 0; i < model.material_names.size(); ++i) {
    SINEW_RETURN_IF_ERROR(d.get_string(model.material_names[i], "material_names[" + std::to_string(i) + "]"));
  }
  SINEW_RETURN_IF_ERROR(d.finish());

  SINEW_RETURN_IF_ERROR(check_skinned_mesh(MeshOrigin{d.pack(), "MESH."}, m, joint_count));
  // Packs store weights the importers normalised; a row that is all zero
  // or far from 1 collapses its vertex (toward the origin) when skinned.
  return check_skin_weight_sums(m, d.pack(), "MESH.");
}

template <typename T>
Status decode_track(SectionDecoder& d, const std::string& field, anim::Track<T>& track) {
  std::uint8_t interpolation = 0;
  std::uint32_t keys = 0, values = 0;
  SINEW_RETURN_IF_ERROR(d.get(interpolation, field + ".interpolation"));
  if (interpolation > static_cast<std::uint8_t>(anim::Interpolation::kCubicSpline)) {
    return d.error(field + ".interpolation", std::to_string(interpolation), "unknown interpolation");
  }
  track.interpolation = static_cast<anim::Interpolation>(interpolation);
  SINEW_RETURN_IF_ERROR(d.get(keys, field + ".key_count"));
  SINEW_RETURN_IF_ERROR(d.get(values, field + ".value_count"));
  SINEW_RETURN_IF_ERROR(d.get_array(keys, track.times, field + ".times"));
  SINEW_RETURN_IF_ERROR(d.get_array(values, track.values, field + ".values"));
  return {};  // Clip::build checks times, counts and values
}

Expected<std::vector<anim::Clip>> decode_clips(SectionDecoder& d, const anim::Skeleton& skeleton) {
  std::uint32_t count = 0;
  SINEW_RETURN_IF_ERROR(d.get(count, "clip_count"));
  if (count > kMaxClips) {
    return d.error("clip_count", std::to_string(count), "more than " + std::to_string(kMaxClips),
                   ErrorCode::kLimitExceeded);
  }
  std::vector<anim::Clip> clips;
  for (std::uint32_t c = 0; c < count; ++c) {
    const std::string f = "clips[" + std::to_string(c) + "]";
    anim::RawClip raw;
    std::uint32_t tracks = 0;
    SINEW_RETURN_IF_ERROR(d.get_string(raw.name, f + ".name"));
    SINEW_RETURN_IF_ERROR(d.get(tracks, f + ".track_count"));
    if (tracks > skeleton.joint_count()) {
      return d.error(f + ".track_count", std::to_string(tracks), "more tracks than joints", ErrorCode::kOutOfBounds);
    }
    raw.tracks.resize(tracks);
    for (std::uint32_t t = 0; t < tracks; ++t) {
      const std::string tf = f + ".tracks[" + std::to_string(t) + "]";
      std::int32_t joint = 0;
      SINEW_RETURN_IF_ERROR(d.get(joint, tf + ".joint"));
      raw.tracks[t].joint = joint;
      SINEW_RETURN_IF_ERROR(decode_track(d, tf + ".translation", raw.tracks[t].translation));
      SINEW_RETURN_IF_ERROR(decode_track(d, tf + ".rotation", raw.tracks[t].rotation));
      SINEW_RETURN_IF_ERROR(decode_track(d, tf + ".scale", raw.tracks[t].scale));
    }
    auto clip = anim::Clip::build(std::move(raw), skeleton, "");
    if (!clip.ok()) return in_section(d, clip.status(), f + ".");
    clips.push_back(std::move(*clip));
  }
  SINEW_RETURN_IF_ERROR(d.finish());
  return clips;
}

Expected<PoseSpaceRecord> decode_pose_space(SectionDecoder& d) {
  PoseSpaceRecord r;
  std::uint8_t mode = 0, every_frame = 0, candidates = 0, reserved = 0;
  std::int32_t samples = 0;
  std::uint64_t seed = 0;
  std::uint32_t clip_names = 0;
  SINEW_RETURN_IF_ERROR(d.get(mode, "mode"));
  SINEW_RETURN_IF_ERROR(d.get(every_frame, "every_frame_30hz"));
  SINEW_RETURN_IF_ERROR(d.get(candidates, "candidates"));
  SINEW_RETURN_IF_ERROR(d.get(reserved, "reserved"));
  SINEW_RETURN_IF_ERROR(d.get(samples, "samples"));
  SINEW_RETURN_IF_ERROR(d.get(seed, "seed"));
  SINEW_RETURN_IF_ERROR(d.get(r.padding, "padding"));
  SINEW_RETURN_IF_ERROR(d.get(clip_names, "clip_count"));
  if (mode > static_cast<std::uint8_t>(anim::PoseSpaceMode::kClip)) {
    return d.error("mode", std::to_string(mode), "unknown pose-space mode");
  }
  if (every_frame > 1 || reserved != 0) return d.error("every_frame_30hz", std::to_string(every_frame), "not 0 or 1");
  if (candidates > static_cast<std::uint8_t>(rt::CandidateBones::kInfluencing)) {
    return d.error("candidates", std::to_string(candidates), "unknown candidate-bone mode");
  }
  if (samples < 0 || samples > anim::kMaxPoseSamples) {
    return d.error("samples", std::to_string(samples), "outside [0, " + std::to_string(anim::kMaxPoseSamples) + "]");
  }
  if (!std::isfinite(r.padding) || r.padding < 0.0f) return d.error("padding", std::to_string(r.padding), "not >= 0");
  if (clip_names > kMaxClips) {
    return d.error("clip_count", std::to_string(clip_names), "more than " + std::to_string(kMaxClips),
                   ErrorCode::kLimitExceeded);
  }
  r.desc.mode = static_cast<anim::PoseSpaceMode>(mode);
  r.desc.every_frame_30hz = every_frame != 0;
  r.candidates = static_cast<rt::CandidateBones>(candidates);
  r.desc.samples = samples;
  r.desc.seed = seed;
  r.desc.clips.resize(clip_names);
  for (std::size_t i = 0; i < clip_names; ++i) {
    SINEW_RETURN_IF_ERROR(d.get_string(r.desc.clips[i], "clips[" + std::to_string(i) + "]"));
  }
  SINEW_RETURN_IF_ERROR(d.finish());
  return r;
}

Expected<anim::JointLimits> decode_limits(SectionDecoder& d, const anim::Skeleton& skeleton) {
  std::uint32_t count = 0;
  SINEW_RETURN_IF_ERROR(d.get(count, "joint_count"));
  if (count != skeleton.joint_count()) {
    return d.error("joint_count", std::to_string(count),
                   "differs from the skeleton's " + std::to_string(skeleton.joint_count()) + " joints");
  }
  anim::JointLimits limits(count);
  for (std::uint32_t j = 0; j < count; ++j) {
    const std::string f = "joints[" + std::to_string(j) + "]";
    anim::JointLimit& l = limits[j];
    std::uint8_t kind = 0, order = 0;
    std::uint16_t reserved = 0;
    SINEW_RETURN_IF_ERROR(d.get(kind, f + ".kind"));
    SINEW_RETURN_IF_ERROR(d.get(order, f + ".euler.order"));
    SINEW_RETURN_IF_ERROR(d.get(reserved, f + ".reserved"));
    if (kind > static_cast<std::uint8_t>(anim::LimitKind::kSwingTwist)) {
      return d.error(f + ".kind", std::to_string(kind), "unknown limit kind (0 free, 1 Euler, 2 swing-twist)");
    }
    if (order > static_cast<std::uint8_t>(anim::RotationOrder::kZYX)) {
      return d.error(f + ".euler.order", std::to_string(order), "unknown rotation order (0 to 5)");
    }
    if (reserved != 0) return d.error(f + ".reserved", std::to_string(reserved), "not 0");
    l.kind = static_cast<anim::LimitKind>(kind);
    l.euler.order = static_cast<anim::RotationOrder>(order);
    Vec3* const vectors[3] = {&l.euler.min, &l.euler.max, &l.swing_twist.twist_axis};
    const char* const names[3] = {".euler.min", ".euler.max", ".swing_twist.twist_axis"};
    for (int v = 0; v < 3; ++v) {
      for (int a = 0; a < 3; ++a) SINEW_RETURN_IF_ERROR(d.get((*vectors[v])[a], f + names[v]));
    }
    SINEW_RETURN_IF_ERROR(d.get(l.swing_twist.swing_max_1, f + ".swing_twist.swing_max_1"));
    SINEW_RETURN_IF_ERROR(d.get(l.swing_twist.swing_max_2, f + ".swing_twist.swing_max_2"));
    SINEW_RETURN_IF_ERROR(d.get(l.swing_twist.twist_min, f + ".swing_twist.twist_min"));
    SINEW_RETURN_IF_ERROR(d.get(l.swing_twist.twist_max, f + ".swing_twist.twist_max"));
  }
  SINEW_RETURN_IF_ERROR(d.finish());
  // Ranges, finiteness and unit axes, as for limits read from JSON.
  if (Status s = anim::validate_joint_limits(limits, ""); !s.ok()) return in_section(d, s);
  return limits;
}

Expected<Provenance> decode_provenance(SectionDecoder& d) {
  Provenance p;
  SINEW_RETURN_IF_ERROR(d.get_string(p.source_name, "source_name"));
  SINEW_RETURN_IF_ERROR(d.get(p.source_hash, "source_hash"));
  SINEW_RETURN_IF_ERROR(d.get_string(p.tool_version, "tool_version"));
  SINEW_RETURN_IF_ERROR(d.get(p.bake_unix_time, "bake_unix_time"));
  SINEW_RETURN_IF_ERROR(d.get(p.pose_sampling_ms, "pose_sampling_ms"));
  SINEW_RETURN_IF_ERROR(d.get(p.sampling_ms, "sampling_ms"));
  SINEW_RETURN_IF_ERROR(d.get(p.assignment_ms, "assignment_ms"));
  SINEW_RETURN_IF_ERROR(d.get(p.build_ms, "build_ms"));
  SINEW_RETURN_IF_ERROR(d.finish());
  return p;
}

Expected<PackFraming> decode_framing(SectionDecoder& d) {
  PackFraming f;
  std::uint8_t up = 0;
  SINEW_RETURN_IF_ERROR(d.get(up, "up_axis"));
  for (int i = 0; i < 3; ++i) {
    std::uint8_t reserved = 0;
    SINEW_RETURN_IF_ERROR(d.get(reserved, "reserved"));
    if (reserved != 0) return d.error("reserved", std::to_string(reserved), "not 0");
  }
  Vec3 lower, upper;
  for (int a = 0; a < 3; ++a) SINEW_RETURN_IF_ERROR(d.get(lower[a], "rest_bounds.lower"));
  for (int a = 0; a < 3; ++a) SINEW_RETURN_IF_ERROR(d.get(upper[a], "rest_bounds.upper"));
  SINEW_RETURN_IF_ERROR(d.finish());
  if (up != 1 && up != 2) return d.error("up_axis", std::to_string(up), "not 1 (+Y) or 2 (+Z)");
  static const char* const kAxis[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    for (const auto& [v, name] : {std::pair{lower[a], "lower"}, std::pair{upper[a], "upper"}}) {
      if (!std::isfinite(v) || static_cast<double>(std::abs(v)) > kMaxCoordinate) {
        return d.error(std::string("rest_bounds.") + name + "." + kAxis[a], std::to_string(v),
                       "not finite or beyond the largest coordinate a pack holds (1e9)");
      }
    }
    if (lower[a] > upper[a]) {
      return d.error(std::string("rest_bounds.lower.") + kAxis[a], std::to_string(lower[a]),
                     "above the upper bound " + std::to_string(upper[a]));
    }
  }
  f.up_axis = up;
  f.rest_bounds = Aabb{lower, upper};
  return f;
}

// A section viewed in place as T; a missing section is an error naming it.
template <typename T>
Expected<std::span<const T>> view_section(const PackReader& reader, SectionId id) {
  auto view = reader.section_as<T>(id);
  if (!view.ok()) return view.status();
  return *view;
}

Status check_version(const PackReader& reader, SectionId id, std::uint32_t version = kSectionVersion,
                     std::string_view why = "") {
  const SectionInfo* info = reader.find(id);
  if (info == nullptr) {
    return make_error(ErrorCode::kNotFound, reader.name(), section_id_name(id), "", "section missing");
  }
  if (info->version != version) {
    return make_error(ErrorCode::kUnsupportedVersion, reader.name(), section_id_name(id) + ".version",
                      std::to_string(info->version),
                      "this build reads version " + std::to_string(version) + (why.empty() ? "" : " ") +
                          std::string(why));
  }
  return {};
}

SectionDecoder decoder(const PackReader& reader, SectionId id) {
  return SectionDecoder(reader.section_bytes(*reader.find(id)), reader.name(), id);
}

}  // namespace

Expected<PackFraming> framing_of(const Model& model) {
  PackFraming f;
  f.rest_bounds = rest_bounds(model);
  if (f.rest_bounds.is_empty()) {
    return make_error(ErrorCode::kInvalidData, model.source, "rest_bounds", "empty",
                      "the rest pose cannot be computed or skins no vertex");
  }
  f.up_axis = up_axis_of(f.rest_bounds);
  return f;
}

bool is_pack_path(const std::string& path) {
  return path.size() >= 5 && path.compare(path.size() - 5, 5, ".pack") == 0;
}

namespace {

Expected<PackWriter> character_pack_writer(const PackContents& c) {
  if (c.model == nullptr) return invalid_argument("contents.model", "null", "a pack needs a model");
  PackWriter w;
  SINEW_RETURN_IF_ERROR(w.add_section(kSkeleton, kSectionVersion, encode_skeleton(c.model->skeleton)));
  SINEW_RETURN_IF_ERROR(w.add_section(kMesh, kSectionVersion, encode_mesh(*c.model)));
  if (has_textures(c.model->mesh)) {
    SINEW_RETURN_IF_ERROR(w.add_section(kTexturesSection, kTexturesVersion, encode_textures(c.model->mesh)));
  }
  SINEW_RETURN_IF_ERROR(w.add_section(kClips, kSectionVersion, encode_clips(c.model->clips)));
  if (!c.limits.empty()) {
    if (c.limits.size() != c.model->skeleton.joint_count()) {
      return invalid_argument("contents.limits", std::to_string(c.limits.size()) + " joints",
                              "the skeleton has " + std::to_string(c.model->skeleton.joint_count()));
    }
    SINEW_RETURN_IF_ERROR(w.add_section(kLimits, kLimitsVersion, encode_limits(c.limits)));
  }
  SINEW_RETURN_IF_ERROR(w.add_section(kPoseSpace, kSectionVersion, encode_pose_space(c.pose_space)));
  SINEW_RETURN_IF_ERROR(w.add_section(kProvenance, kSectionVersion, encode_provenance(c.provenance)));
  PackFraming framing;
  if (c.framing) {
    framing = *c.framing;
  } else {
    SINEW_ASSIGN_OR_RETURN(framing, framing_of(*c.model));
  }
  SINEW_RETURN_IF_ERROR(w.add_section(kFraming, kSectionVersion, encode_framing(framing)));
  if (c.fuzzy != nullptr) {
    const rt::FuzzyCharacterData& f = *c.fuzzy;
    FuzzyHeader h{};
    h.bone_count = f.bone_count;
    h.sample_count = f.stats.sample_count;
    h.vertex_count = f.stats.vertex_count;
    h.triangle_count = f.stats.triangle_count;
    h.node_count = f.stats.node_count;
    h.max_depth = f.stats.max_depth;
    h.candidates = static_cast<std::uint8_t>(f.stats.candidates);
    h.merge_rigid_bones = f.stats.merge_rigid_bones ? 1 : 0;
    h.merged_bones = static_cast<std::uint16_t>(f.stats.merged_bones);
    h.fuzzy_area = f.stats.fuzzy_area;
    h.rest_area = f.stats.rest_area;
    h.mean_items_per_leaf = f.stats.mean_items_per_leaf;
    SINEW_RETURN_IF_ERROR(w.add_section(kFuzzyHeader, kSectionVersion, std::as_bytes(std::span(&h, 1))));
    SINEW_RETURN_IF_ERROR(w.add_section(kTriangleBone, kSectionVersion, bytes_of<std::uint16_t>(f.triangle_bone)));
    SINEW_RETURN_IF_ERROR(w.add_section(kBoneTrees, kSectionVersion, bytes_of<rt::BoneTree>(f.bone_trees)));
    if (f.tree_kind == rt::BoneTreeKind::kBvh) {
      SINEW_RETURN_IF_ERROR(w.add_section(kBvhNodes, kSectionVersion, bytes_of<rt::BvhNode>(f.bvh_nodes)));
      SINEW_RETURN_IF_ERROR(w.add_section(kItems, kBvhTreesVersion, bytes_of<std::uint32_t>(f.items)));
    } else {
      const std::uint32_t trees_version = f.bone_cluster_begin.empty() ? kSectionVersion : kClusteredTreesVersion;
      SINEW_RETURN_IF_ERROR(w.add_section(kNodes, trees_version, bytes_of<rt::KdNode>(f.nodes)));
      SINEW_RETURN_IF_ERROR(w.add_section(kItems, trees_version, bytes_of<std::uint32_t>(f.items)));
    }
    SINEW_RETURN_IF_ERROR(
        w.add_section(kVertexCheckBegin, kSectionVersion, bytes_of<std::uint32_t>(f.vertex_check_begin)));
    SINEW_RETURN_IF_ERROR(w.add_section(kVertexChecks, kSectionVersion, bytes_of<rt::VertexCheck>(f.vertex_checks)));
    SINEW_RETURN_IF_ERROR(w.add_section(kTriangleChecks, kSectionVersion,
                                        bytes_of<std::array<std::uint32_t, 3>>(f.triangle_checks)));
    // A clustering bake always has the per-bone offsets, even when no bone
    // got clusters (then FCLS, FCLX and FCCN are empty).
    if (!f.bone_cluster_begin.empty()) {
      ClusterHeader ch{};
      ch.feature_translation_scale = f.feature_translation_scale;
      ch.clusters_per_bone = f.stats.clusters_per_bone;
      ch.cluster_count = static_cast<std::uint32_t>(f.clusters.size());
      ch.cluster_fuzzy_area = f.stats.cluster_fuzzy_area;
      SINEW_RETURN_IF_ERROR(w.add_section(kClusterHeader, kSectionVersion, std::as_bytes(std::span(&ch, 1))));
      SINEW_RETURN_IF_ERROR(
          w.add_section(kBoneClusterBegin, kSectionVersion, bytes_of<std::uint32_t>(f.bone_cluster_begin)));
      SINEW_RETURN_IF_ERROR(w.add_section(kClusters, kSectionVersion, bytes_of<rt::BoneCluster>(f.clusters)));
      SINEW_RETURN_IF_ERROR(w.add_section(kCheckRank, kSectionVersion, bytes_of<std::uint32_t>(f.check_rank)));
      SINEW_RETURN_IF_ERROR(w.add_section(kClusterBoxes, kSectionVersion, bytes_of<Aabb>(f.cluster_boxes)));
      SINEW_RETURN_IF_ERROR(
          w.add_section(kFeatureBoneBegin, kSectionVersion, bytes_of<std::uint32_t>(f.feature_bone_begin)));
      SINEW_RETURN_IF_ERROR(w.add_section(kFeatureBones, kSectionVersion, bytes_of<std::uint16_t>(f.feature_bones)));
      SINEW_RETURN_IF_ERROR(w.add_section(kClusterCentres, kSectionVersion, bytes_of<float>(f.cluster_centres)));
    }
  }
  return w;
}

}  // namespace

Expected<std::vector<std::byte>> serialize_pack(const PackContents& contents) {
  SINEW_ASSIGN_OR_RETURN(const PackWriter writer, character_pack_writer(contents));
  return writer.serialize();
}

Status write_pack(const std::string& path, const PackContents& contents, const std::function<bool()>& cancelled) {
  SINEW_ASSIGN_OR_RETURN(const PackWriter writer, character_pack_writer(contents));
  return writer.write(path, [&cancelled](const std::string& written) -> Status {
    auto loaded = Pack::open(written);
    if (!loaded.ok()) {
      return make_error(loaded.status().code(), "", "", "",
                        "the written pack does not load, so nothing was replaced: " + loaded.status().message());
    }
    if (cancelled && cancelled()) {
      return make_error(ErrorCode::kCancelled, "", "", "", "interrupted while writing, so nothing was replaced");
    }
    return {};
  });
}

Expected<Pack> Pack::open(const std::string& path) {
  SINEW_ASSIGN_OR_RETURN(PackReader reader, PackReader::open(path));
  return load(std::move(reader));
}

Expected<Pack> Pack::from_bytes(std::span<const std::byte> bytes, const std::string& name) {
  SINEW_ASSIGN_OR_RETURN(PackReader reader, PackReader::from_bytes(bytes, name));
  return load(std::move(reader));
}

Expected<Pack> Pack::load(PackReader reader) {
  Pack pack(std::move(reader));
  const PackReader& r = pack.reader_;
  for (SectionId id : {kSkeleton, kMesh, kClips, kPoseSpace, kProvenance}) SINEW_RETURN_IF_ERROR(check_version(r, id));
  pack.model_.source = r.name();
  {
    SectionDecoder d = decoder(r, kSkeleton);
    SINEW_ASSIGN_OR_RETURN(pack.model_.skeleton, decode_skeleton(d));
  }
  {
    SectionDecoder d = decoder(r, kMesh);
    SINEW_RETURN_IF_ERROR(decode_mesh(d, pack.model_.skeleton.joint_count(), pack.model_));
  }
  if (r.contains(kTexturesSection)) {
    SINEW_RETURN_IF_ERROR(check_version(r, kTexturesSection, kTexturesVersion));
    SectionDecoder d = decoder(r, kTexturesSection);
    SINEW_RETURN_IF_ERROR(decode_textures(d, pack.model_.mesh));
  }
  {
    SectionDecoder d = decoder(r, kClips);
    SINEW_ASSIGN_OR_RETURN(pack.model_.clips, decode_clips(d, pack.model_.skeleton));
  }
  // What every consumer needs to frame and trace it, checked once here.
  SINEW_RETURN_IF_ERROR(check_renderable(pack.model_, r.name(), kPackFields));
  if (const SectionInfo* limits = r.find(kLimits)) {
    if (limits->version != kLimitsVersion) {
      return make_error(ErrorCode::kUnsupportedVersion, r.name(), "LIMT.version", std::to_string(limits->version),
                        limits->version == 1 ? "joint limits as JSON text, which this build no longer reads: "
                                               "re-bake the pack with this sinew-editor"
                                             : "this build reads version " + std::to_string(kLimitsVersion));
    }
    SectionDecoder d = decoder(r, kLimits);
    SINEW_ASSIGN_OR_RETURN(pack.limits_, decode_limits(d, pack.model_.skeleton));
  }
  {
    SectionDecoder d = decoder(r, kPoseSpace);
    SINEW_ASSIGN_OR_RETURN(pack.pose_space_, decode_pose_space(d));
  }
  {
    SectionDecoder d = decoder(r, kProvenance);
    SINEW_ASSIGN_OR_RETURN(pack.provenance_, decode_provenance(d));
  }
  if (r.contains(kFraming)) {
    SINEW_RETURN_IF_ERROR(check_version(r, kFraming));
    SectionDecoder d = decoder(r, kFraming);
    SINEW_ASSIGN_OR_RETURN(pack.framing_, decode_framing(d));
    pack.framing_stored_ = true;
  } else {
    auto computed = framing_of(pack.model_);
    if (!computed.ok()) return make_error(computed.status().code(), r.name(), "FRAM", "", computed.status().detail());
    pack.framing_ = *computed;
  }
  // Cluster sections refine the fuzzy data: without its header, or without
  // the fuzzy data itself, they mean nothing, and ignoring them would hide a
  // damaged pack.
  const bool has_cluster_header = r.contains(kClusterHeader);
  for (SectionId id : kClusterArrays) {
    if (r.contains(id) && !has_cluster_header) {
      return make_error(ErrorCode::kNotFound, r.name(), section_id_name(kClusterHeader), "",
                        "section missing: the pack has the cluster section " + section_id_name(id) +
                            " but not the cluster header");
    }
  }
  if (has_cluster_header && !r.contains(kFuzzyHeader)) {
    return make_error(ErrorCode::kNotFound, r.name(), section_id_name(kFuzzyHeader), "",
                      "section missing: the pack has cluster sections (FCHD) but no fuzzy data");
  }
  if (!r.contains(kFuzzyHeader)) return pack;

  for (SectionId id : {kFuzzyHeader, kTriangleBone, kBoneTrees, kVertexCheckBegin, kVertexChecks, kTriangleChecks}) {
    SINEW_RETURN_IF_ERROR(check_version(r, id));
  }
  const bool has_bvhs = r.contains(kBvhNodes);
  if (has_bvhs) {
    if (r.contains(kNodes)) {
      return make_error(ErrorCode::kInvalidData, r.name(), section_id_name(kNodes), "",
                        "a pack with BVH bone trees (FBVN) has no kd-tree nodes");
    }
    SINEW_RETURN_IF_ERROR(check_version(r, kBvhNodes));
    SINEW_RETURN_IF_ERROR(check_version(r, kItems, kBvhTreesVersion, "in a pack with BVH bone trees (FBVN)"));
  } else {
    for (SectionId id : {kNodes, kItems}) {
      SINEW_RETURN_IF_ERROR(has_cluster_header
                                ? check_version(r, id, kClusteredTreesVersion, "in a pack with clusters (FCHD)")
                                : check_version(r, id, kSectionVersion, "in a pack without clusters (no FCHD)"));
    }
  }
  FuzzyHeader h{};
  {
    SectionDecoder d = decoder(r, kFuzzyHeader);
    SINEW_RETURN_IF_ERROR(d.get(h, "header"));
    SINEW_RETURN_IF_ERROR(d.finish());
  }
  if (h.bone_count != pack.model_.skeleton.joint_count()) {
    return make_error(ErrorCode::kInvalidData, r.name(), "FZHD.bone_count", std::to_string(h.bone_count),
                      "differs from the skeleton's " + std::to_string(pack.model_.skeleton.joint_count()) + " joints");
  }
  // The counts are only reported (stats), never used to size anything, but
  // a header that disagrees with the mesh is a corrupt pack, not a statistic.
  if (h.vertex_count != pack.model_.mesh.vertex_count()) {
    return make_error(ErrorCode::kInvalidData, r.name(), "FZHD.vertex_count", std::to_string(h.vertex_count),
                      "differs from the mesh's " + std::to_string(pack.model_.mesh.vertex_count()) + " vertices");
  }
  if (h.triangle_count != pack.model_.mesh.triangle_count()) {
    return make_error(ErrorCode::kInvalidData, r.name(), "FZHD.triangle_count", std::to_string(h.triangle_count),
                      "differs from the mesh's " + std::to_string(pack.model_.mesh.triangle_count()) + " triangles");
  }
  if (h.candidates > static_cast<std::uint8_t>(rt::CandidateBones::kInfluencing)) {
    return make_error(ErrorCode::kInvalidData, r.name(), "FZHD.candidates", std::to_string(h.candidates),
                      "unknown candidate-bone mode");
  }
  if (h.merge_rigid_bones > 1) {
    return make_error(ErrorCode::kInvalidData, r.name(), "FZHD.merge_rigid_bones", std::to_string(h.merge_rigid_bones),
                      "not 0 or 1");
  }
  if (h.merged_bones > (h.merge_rigid_bones ? h.bone_count : 0u)) {
    return make_error(ErrorCode::kInvalidData, r.name(), "FZHD.merged_bones", std::to_string(h.merged_bones),
                      h.merge_rigid_bones ? "more than the bones" : "not 0 in a bake that merged no bones");
  }
  for (const std::uint8_t byte : h.reserved) {
    if (byte != 0) {
      return make_error(ErrorCode::kInvalidData, r.name(), "FZHD.reserved", std::to_string(byte), "not 0");
    }
  }
  rt::FuzzyCharacterView& v = pack.fuzzy_;
  v.bone_count = h.bone_count;
  SINEW_ASSIGN_OR_RETURN(v.triangle_bone, view_section<std::uint16_t>(r, kTriangleBone));
  SINEW_ASSIGN_OR_RETURN(v.bone_trees, view_section<rt::BoneTree>(r, kBoneTrees));
  if (has_bvhs) {
    v.tree_kind = rt::BoneTreeKind::kBvh;
    SINEW_ASSIGN_OR_RETURN(v.bvh_nodes, view_section<rt::BvhNode>(r, kBvhNodes));
  } else {
    SINEW_ASSIGN_OR_RETURN(v.nodes, view_section<rt::KdNode>(r, kNodes));
  }
  SINEW_ASSIGN_OR_RETURN(v.items, view_section<std::uint32_t>(r, kItems));
  SINEW_ASSIGN_OR_RETURN(v.vertex_check_begin, view_section<std::uint32_t>(r, kVertexCheckBegin));
  SINEW_ASSIGN_OR_RETURN(v.vertex_checks, view_section<rt::VertexCheck>(r, kVertexChecks));
  using Corners = std::array<std::uint32_t, 3>;
  SINEW_ASSIGN_OR_RETURN(v.triangle_checks, view_section<Corners>(r, kTriangleChecks));
  ClusterHeader ch{};
  if (has_cluster_header) {
    SINEW_RETURN_IF_ERROR(check_version(r, kClusterHeader));
    for (SectionId id : kClusterArrays) SINEW_RETURN_IF_ERROR(check_version(r, id));
    {
      SectionDecoder d = decoder(r, kClusterHeader);
      SINEW_RETURN_IF_ERROR(d.get(ch, "header"));
      SINEW_RETURN_IF_ERROR(d.finish());
    }
    // The scale divides every frame's feature (pose_clusters.h): the
    // validation below checks it too, but a header field is reported as one.
    if (!(std::isfinite(ch.feature_translation_scale) && ch.feature_translation_scale > 0.0f)) {
      return make_error(ErrorCode::kInvalidData, r.name(), "FCHD.feature_translation_scale",
                        std::to_string(ch.feature_translation_scale), "not finite and positive");
    }
    if (ch.clusters_per_bone == 0 || ch.clusters_per_bone > rt::kMaxPoseClusters) {
      return make_error(ErrorCode::kInvalidData, r.name(), "FCHD.clusters_per_bone",
                        std::to_string(ch.clusters_per_bone),
                        "outside [1, " + std::to_string(rt::kMaxPoseClusters) + "] (rt::kMaxPoseClusters)");
    }
    if (!(std::isfinite(ch.cluster_fuzzy_area) && ch.cluster_fuzzy_area >= 0.0)) {
      return make_error(ErrorCode::kInvalidData, r.name(), "FCHD.cluster_fuzzy_area",
                        std::to_string(ch.cluster_fuzzy_area), "not finite and >= 0");
    }
    for (const std::uint8_t byte : ch.reserved) {
      if (byte != 0) {
        return make_error(ErrorCode::kInvalidData, r.name(), "FCHD.reserved", std::to_string(byte), "not 0");
      }
    }
    SINEW_ASSIGN_OR_RETURN(v.bone_cluster_begin, view_section<std::uint32_t>(r, kBoneClusterBegin));
    SINEW_ASSIGN_OR_RETURN(v.clusters, view_section<rt::BoneCluster>(r, kClusters));
    SINEW_ASSIGN_OR_RETURN(v.check_rank, view_section<std::uint32_t>(r, kCheckRank));
    SINEW_ASSIGN_OR_RETURN(v.cluster_boxes, view_section<Aabb>(r, kClusterBoxes));
    SINEW_ASSIGN_OR_RETURN(v.feature_bone_begin, view_section<std::uint32_t>(r, kFeatureBoneBegin));
    SINEW_ASSIGN_OR_RETURN(v.feature_bones, view_section<std::uint16_t>(r, kFeatureBones));
    SINEW_ASSIGN_OR_RETURN(v.cluster_centres, view_section<float>(r, kClusterCentres));
    v.feature_translation_scale = ch.feature_translation_scale;
    if (ch.cluster_count != v.clusters.size()) {
      return make_error(ErrorCode::kInvalidData, r.name(), "FCHD.cluster_count", std::to_string(ch.cluster_count),
                        "differs from the " + std::to_string(v.clusters.size()) + " clusters of FCLS");
    }
    // The validation checks the cluster arrays only when one of them has
    // entries; a clustering bake always has the per-bone offsets.
    if (v.bone_cluster_begin.size() != std::size_t{v.bone_count} + 1) {
      return make_error(ErrorCode::kInvalidData, r.name(), "FCLB.size",
                        std::to_string(v.bone_cluster_begin.size()) + " offsets",
                        "expected one per bone + 1 (" + std::to_string(std::size_t{v.bone_count} + 1) + ")");
    }
  }
  if (Status s = rt::validate_fuzzy_character(pack.model_.mesh, v); !s.ok()) {
    return make_error(s.code(), r.name(), "fuzzy " + std::string(s.field()), s.value(), s.detail());
  }
  if (has_cluster_header) {
    // The offsets are validated now: no bone has more clusters than the bake asked for.
    for (std::uint32_t b = 0; b < v.bone_count; ++b) {
      const std::uint32_t count = v.bone_cluster_begin[b + 1] - v.bone_cluster_begin[b];
      if (count > ch.clusters_per_bone) {
        return make_error(ErrorCode::kInvalidData, r.name(), "FCLB[" + std::to_string(b) + "]",
                          std::to_string(count) + " clusters",
                          "more than FCHD.clusters_per_bone (" + std::to_string(ch.clusters_per_bone) + ")");
      }
    }
  }
  rt::FuzzyBakeStats& st = pack.stats_;
  st.sample_count = h.sample_count;
  st.vertex_count = h.vertex_count;
  st.triangle_count = h.triangle_count;
  st.bone_count = h.bone_count;
  st.candidates = static_cast<rt::CandidateBones>(h.candidates);
  st.merge_rigid_bones = h.merge_rigid_bones != 0;
  st.merged_bones = h.merged_bones;
  st.fuzzy_area = h.fuzzy_area;
  st.rest_area = h.rest_area;
  st.mean_items_per_leaf = h.mean_items_per_leaf;
  st.max_depth = h.max_depth;
  st.node_count = h.node_count;
  st.sampling_ms = pack.provenance_.sampling_ms;
  st.assignment_ms = pack.provenance_.assignment_ms;
  st.build_ms = pack.provenance_.build_ms;
  if (has_cluster_header) {
    st.clusters_per_bone = ch.clusters_per_bone;
    st.cluster_count = ch.cluster_count;
    st.cluster_fuzzy_area = ch.cluster_fuzzy_area;
  }
  pack.has_fuzzy_ = true;
  return pack;
}

}  // namespace sinew::character
