#include "editor/import/cal3d_importer.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <fstream>
#include <list>
#include <memory>
#include <new>
#include <set>
#include <sstream>
#include <utility>

#include <cal3d/cal3d.h>
#include <cal3d/corekeyframe.h>
#include <cal3d/coretrack.h>

namespace sinew::editor {
namespace {

namespace fs = std::filesystem;

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

bool finite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// See the header: Cal3D's quaternions rotate as the conjugate of glm's.
Quat to_quat(const CalQuaternion& q) { return Quat(q.w, -q.x, -q.y, -q.z); }
Vec3 to_vec3(const CalVector& v) { return Vec3(v.x, v.y, v.z); }

// Cal3D reports failures through a global "last error"; turn it into a
// Status naming our file (Cal3D's own file/line is its source file, useless
// to a user, so it is left out).
Status cal3d_error(const std::string& file, std::string_view what) {
  const CalError::Code code = CalError::getLastErrorCode();
  ErrorCode ours = ErrorCode::kInvalidData;
  switch (code) {
    case CalError::FILE_NOT_FOUND: ours = ErrorCode::kNotFound; break;
    case CalError::INVALID_FILE_FORMAT: ours = ErrorCode::kBadMagic; break;
    case CalError::INCOMPATIBLE_FILE_VERSION: ours = ErrorCode::kUnsupportedVersion; break;
    case CalError::MEMORY_ALLOCATION_FAILED: ours = ErrorCode::kLimitExceeded; break;
    default: break;
  }
  std::string detail = "Cal3D could not load the " + std::string(what) + ": " +
                       CalError::getErrorDescription(code);
  if (!CalError::getLastErrorText().empty()) detail += " (" + CalError::getLastErrorText() + ")";
  return make_error(ours, file, "", "", detail);
}

// Cal3D's loaders open files themselves; checking first gives a clear
// kNotFound instead of Cal3D's generic message, and keeps directories
// (which some loaders would "read" as empty) out.
Status check_file(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) {
    return make_error(ErrorCode::kNotFound, path, "", "", "no such file");
  }
  return {};
}

Status validate_binary(const std::string& path);

// Before each Cal3D load: the file exists and, if binary, is well formed.
// `current` records it, so an exception from inside Cal3D names the file.
Status check_cal3d_file(const std::string& path, std::string& current) {
  current = path;
  SINEW_RETURN_IF_ERROR(check_file(path));
  return validate_binary(path);
}

std::string join(const fs::path& folder, const std::string& name) {
  const fs::path p(name);
  return (p.is_absolute() ? p : folder / p).lexically_normal().string();
}

struct ClipFile {
  std::string path;
  std::string name;
};

// The .cfg's animations first, then every <model>_*.caf/.xaf beside it.
Expected<std::vector<ClipFile>> clip_files(const Cal3dConfig& cfg, const fs::path& folder,
                                           const std::string& model, const std::string& cfg_path) {
  std::vector<ClipFile> out;
  std::set<std::string> paths;
  std::set<std::string> names;
  const std::string prefix = model + "_";
  auto clip_name = [&](const std::string& path) {
    std::string stem = fs::path(path).stem().string();
    if (stem.size() > prefix.size() && stem.compare(0, prefix.size(), prefix) == 0) {
      stem.erase(0, prefix.size());
    }
    return stem;
  };
  // Returns false when another file already has this clip name.
  auto add = [&](const std::string& path) {
    if (paths.count(path) != 0) return true;  // listed twice: one clip
    std::string name = clip_name(path);
    if (names.count(name) != 0) return false;
    paths.insert(path);
    names.insert(name);
    out.push_back({path, std::move(name)});
    return true;
  };
  for (const std::string& a : cfg.animations) {
    const std::string path = join(folder, a);
    // Two listed files, one name: clips are looked up by name, so refuse.
    if (!add(path)) {
      return make_error(ErrorCode::kDuplicate, cfg_path, "animation", a,
                        "another listed animation already has the clip name '" + clip_name(path) + "'");
    }
  }

  std::vector<std::string> extra;
  std::error_code ec;
  for (fs::directory_iterator it(folder.empty() ? fs::path(".") : folder, ec), end;
       !ec && it != end; it.increment(ec)) {
    const std::string file = it->path().filename().string();
    const std::string ext = lower(it->path().extension().string());
    if ((ext == ".caf" || ext == ".xaf") && file.size() > prefix.size() + ext.size() &&
        file.compare(0, prefix.size(), prefix) == 0 && it->is_regular_file(ec)) {
      extra.push_back(join(folder, file));
    }
  }
  // Directory order is unspecified; sorting makes clip indices ("#3") stable.
  // .caf sorts before .xaf, so the binary file wins a name clash; an extra
  // file whose name is taken is skipped (it was not asked for).
  std::sort(extra.begin(), extra.end());
  for (const std::string& e : extra) add(e);
  return out;
}

// ---------------------------------------------------------------------------
// Structural check of Cal3D's binary files before Cal3D reads them.
//
// Cal3D 0.11's binary loader trusts the file: it reserves memory from counts
// it has not checked against the file size, reads on after a short read
// (leaving counts uninitialised), and CalLoader::loadCoreSubmesh indexes the
// vertex array with the first face's ids unchecked. So each .csf/.cmf/.caf
// is walked here first, with every count checked against the bytes left and
// face ids against the vertex count. The layout (identical in file versions
// 700 and 910, the ones in the test content) is: magic[4], int version, then
//   .csf: int boneCount; per bone: string name, float[3] t, float[4] r,
//         float[3] t_bs, float[4] r_bs, int parent, int childCount, int[childCount]
//   .cmf: int submeshCount; per submesh: int material, vertexCount, faceCount,
//         lodCount, springCount, texCoordCount; per vertex: float[6], int[2],
//         float[2*texCoordCount], int influenceCount, {int bone, float w}[...],
//         float physical weight if springCount > 0; springs {int[2], float[2]};
//         faces int[3]
//   .caf: float duration, int trackCount; per track: int bone, int keyCount,
//         {float time, float[3] t, float[4] r}[keyCount]
// (string = int length + length bytes; integers and floats little-endian).
// Trailing bytes are allowed, as Cal3D allows them. Files with another magic
// (XML variants, binary .crf materials) are left to Cal3D.
class ByteWalker {
 public:
  ByteWalker(const std::string& bytes, const std::string& file) : bytes_(bytes), file_(file) {}

  std::size_t left() const { return bytes_.size() - pos_; }

  Status skip(std::size_t n, std::string_view field) {
    if (n > left()) {
      return make_error(ErrorCode::kTruncated, file_, field, std::to_string(pos_),
                        "file ends after " + std::to_string(bytes_.size()) + " bytes, " +
                            std::to_string(n) + " more needed");
    }
    pos_ += n;
    return {};
  }

  Status i32(std::int32_t& out, std::string_view field) {
    const std::size_t at = pos_;
    SINEW_RETURN_IF_ERROR(skip(4, field));
    std::uint32_t u = 0;
    for (int i = 3; i >= 0; --i) u = (u << 8) | static_cast<unsigned char>(bytes_[at + static_cast<std::size_t>(i)]);
    out = static_cast<std::int32_t>(u);
    return {};
  }

  // A count whose records (each at least `min_record` bytes) must fit in
  // what is left of the file.
  Status count(std::int32_t& out, std::size_t min_record, const std::string& field) {
    SINEW_RETURN_IF_ERROR(i32(out, field));
    if (out < 0) {
      return make_error(ErrorCode::kInvalidData, file_, field, std::to_string(out), "negative count");
    }
    if (min_record != 0 && static_cast<std::size_t>(out) > left() / min_record) {
      return make_error(ErrorCode::kTruncated, file_, field, std::to_string(out),
                        "needs at least " + std::to_string(static_cast<std::size_t>(out) * min_record) +
                            " bytes, " + std::to_string(left()) + " left in the file");
    }
    return {};
  }

  Status string(const std::string& field) {
    std::int32_t len = 0;
    SINEW_RETURN_IF_ERROR(count(len, 1, field + ".length"));
    return skip(static_cast<std::size_t>(len), field);
  }

 private:
  const std::string& bytes_;
  const std::string& file_;
  std::size_t pos_ = 0;
};

Status walk_skeleton(ByteWalker& w) {
  std::int32_t bones = 0;
  // name length + 14 floats + parent + child count.
  SINEW_RETURN_IF_ERROR(w.count(bones, 4 + 14 * 4 + 8, "boneCount"));
  for (std::int32_t b = 0; b < bones; ++b) {
    const std::string f = "bone[" + std::to_string(b) + "]";
    SINEW_RETURN_IF_ERROR(w.string(f + ".name"));
    SINEW_RETURN_IF_ERROR(w.skip(14 * 4 + 4, f));
    std::int32_t children = 0;
    SINEW_RETURN_IF_ERROR(w.count(children, 4, f + ".childCount"));
    SINEW_RETURN_IF_ERROR(w.skip(static_cast<std::size_t>(children) * 4, f + ".children"));
  }
  return {};
}

Status walk_mesh(ByteWalker& w) {
  std::int32_t submeshes = 0;
  SINEW_RETURN_IF_ERROR(w.count(submeshes, 6 * 4, "submeshCount"));
  for (std::int32_t s = 0; s < submeshes; ++s) {
    const std::string f = "submesh[" + std::to_string(s) + "]";
    std::int32_t material = 0, vertices = 0, faces = 0, lods = 0, springs = 0, uv_sets = 0;
    SINEW_RETURN_IF_ERROR(w.i32(material, f + ".material"));
    SINEW_RETURN_IF_ERROR(w.count(vertices, 8 * 4 + 4, f + ".vertexCount"));
    SINEW_RETURN_IF_ERROR(w.count(faces, 3 * 4, f + ".faceCount"));
    SINEW_RETURN_IF_ERROR(w.i32(lods, f + ".lodCount"));
    SINEW_RETURN_IF_ERROR(w.count(springs, 4 * 4, f + ".springCount"));
    SINEW_RETURN_IF_ERROR(w.count(uv_sets, 8, f + ".textureCoordinateCount"));
    const std::size_t per_vertex = 8 * 4 + static_cast<std::size_t>(uv_sets) * 8 + 4;
    if (static_cast<std::size_t>(vertices) > w.left() / per_vertex) {
      return make_error(ErrorCode::kTruncated, "", f + ".vertexCount", std::to_string(vertices),
                        "more vertices than the file has bytes for");
    }
    for (std::int32_t v = 0; v < vertices; ++v) {
      const std::string vf = f + ".vertex[" + std::to_string(v) + "]";
      SINEW_RETURN_IF_ERROR(w.skip(8 * 4 + static_cast<std::size_t>(uv_sets) * 8, vf));
      std::int32_t influences = 0;
      SINEW_RETURN_IF_ERROR(w.count(influences, 8, vf + ".influenceCount"));
      SINEW_RETURN_IF_ERROR(w.skip(static_cast<std::size_t>(influences) * 8, vf + ".influences"));
      if (springs > 0) SINEW_RETURN_IF_ERROR(w.skip(4, vf + ".physicalWeight"));
    }
    for (std::int32_t k = 0; k < springs; ++k) {
      const std::string sf = f + ".spring[" + std::to_string(k) + "]";
      for (int c = 0; c < 2; ++c) {
        std::int32_t id = 0;
        SINEW_RETURN_IF_ERROR(w.i32(id, sf + ".vertex"));
        if (id < 0 || id >= vertices) {
          return make_error(ErrorCode::kOutOfBounds, "", sf + ".vertex[" + std::to_string(c) + "]",
                            std::to_string(id), "past the submesh's " + std::to_string(vertices) + " vertices");
        }
      }
      SINEW_RETURN_IF_ERROR(w.skip(8, sf));
    }
    for (std::int32_t t = 0; t < faces; ++t) {
      for (int c = 0; c < 3; ++c) {
        const std::string ff = f + ".face[" + std::to_string(t) + "].vertex[" + std::to_string(c) + "]";
        std::int32_t id = 0;
        SINEW_RETURN_IF_ERROR(w.i32(id, ff));
        if (id < 0 || id >= vertices) {
          return make_error(ErrorCode::kOutOfBounds, "", ff, std::to_string(id),
                            "past the submesh's " + std::to_string(vertices) + " vertices");
        }
      }
    }
  }
  return {};
}

Status walk_animation(ByteWalker& w) {
  SINEW_RETURN_IF_ERROR(w.skip(4, "duration"));
  std::int32_t tracks = 0;
  SINEW_RETURN_IF_ERROR(w.count(tracks, 8, "trackCount"));
  for (std::int32_t t = 0; t < tracks; ++t) {
    const std::string f = "track[" + std::to_string(t) + "]";
    std::int32_t bone = 0, keys = 0;
    SINEW_RETURN_IF_ERROR(w.i32(bone, f + ".bone"));
    SINEW_RETURN_IF_ERROR(w.count(keys, 8 * 4, f + ".keyframeCount"));
    // Cal3D rejects it too, but leaks the track doing so.
    if (keys == 0) {
      return make_error(ErrorCode::kInvalidData, "", f + ".keyframeCount", "0", "a track needs a key");
    }
    SINEW_RETURN_IF_ERROR(w.skip(static_cast<std::size_t>(keys) * 8 * 4, f + ".keyframes"));
  }
  return {};
}

// Far beyond any character file; keeps a stray huge file from being read
// into memory whole.
constexpr std::uintmax_t kMaxCal3dFileBytes = 512u << 20;

Status validate_binary(const std::string& path) {
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) return make_error(ErrorCode::kIoError, path, "", "", ec.message());
  if (size > kMaxCal3dFileBytes) {
    return make_error(ErrorCode::kLimitExceeded, path, "size", std::to_string(size),
                      "larger than any Cal3D character file Sinew accepts");
  }
  std::ifstream in(path, std::ios::binary);
  std::string bytes(static_cast<std::size_t>(size), '\0');
  if (!in || !in.read(bytes.data(), static_cast<std::streamsize>(size))) {
    return make_error(ErrorCode::kIoError, path, "", "", "read failed");
  }
  const std::string_view magic(bytes.data(), std::min<std::size_t>(bytes.size(), 4));
  using Walk = Status (*)(ByteWalker&);
  Walk walk = nullptr;
  if (magic == std::string_view("CSF\0", 4)) walk = walk_skeleton;
  if (magic == std::string_view("CMF\0", 4)) walk = walk_mesh;
  if (magic == std::string_view("CAF\0", 4)) walk = walk_animation;
  if (bytes.size() < 4) {
    return make_error(ErrorCode::kTruncated, path, "magic", std::to_string(bytes.size()) + " bytes",
                      "too short for a Cal3D file");
  }
  if (walk == nullptr) return {};  // XML or material: Cal3D checks those
  ByteWalker w(bytes, path);
  SINEW_RETURN_IF_ERROR(w.skip(4, "magic"));
  std::int32_t version = 0;
  SINEW_RETURN_IF_ERROR(w.i32(version, "version"));
  return walk(w).with_file(path);
}

Expected<anim::Skeleton> convert_skeleton(CalCoreSkeleton& core, const std::string& file,
                                          std::vector<int>& raw_to_sorted) {
  std::vector<CalCoreBone*>& bones = core.getVectorCoreBone();
  if (bones.size() > anim::kMaxJoints) {
    return make_error(ErrorCode::kLimitExceeded, file, "bones", std::to_string(bones.size()),
                      "more bones than Sinew supports (" + std::to_string(anim::kMaxJoints) + ")");
  }
  anim::RawSkeleton raw;
  raw.joints.resize(bones.size());
  for (std::size_t i = 0; i < bones.size(); ++i) {
    CalCoreBone* b = bones[i];
    const std::string field = "bone[" + std::to_string(i) + "]";
    if (b == nullptr) return make_error(ErrorCode::kInvalidData, file, field, "", "missing bone");
    anim::RawJoint& j = raw.joints[i];
    j.name = b->getName();
    const int parent = b->getParentId();
    // Cal3D writes -1 for roots; anything else negative is corrupt, and
    // Skeleton::build reports indices past the end.
    if (parent < -1) {
      return make_error(ErrorCode::kOutOfBounds, file, field + ".parent", std::to_string(parent),
                        "negative parent id");
    }
    j.parent = parent < 0 ? anim::kNoParent : parent;
    j.rest.translation = to_vec3(b->getTranslation());
    j.rest.rotation = to_quat(b->getRotation());
    // Bone space maps model space to the bone: p_bone = R_bs p + t_bs.
    j.inverse_bind = Affine3::from_trs(to_vec3(b->getTranslationBoneSpace()),
                                       to_quat(b->getRotationBoneSpace()), Vec3(1.0f));
    if (!finite(j.rest.translation) || !finite(to_vec3(b->getTranslationBoneSpace()))) {
      return make_error(ErrorCode::kInvalidData, file, field + ".translation", "",
                        "non-finite translation");
    }
  }
  return anim::Skeleton::build(raw, file, &raw_to_sorted);
}

struct MeshContext {
  SkinnedMesh* mesh = nullptr;
  const std::vector<int>* raw_to_sorted = nullptr;
  std::size_t material_count = 0;   // materials loaded from the .cfg
  bool uses_default_material = false;
};

Status convert_mesh(CalCoreMesh& core, const std::string& file, MeshContext& ctx) {
  SkinnedMesh& m = *ctx.mesh;
  const std::vector<int>& remap = *ctx.raw_to_sorted;
  std::vector<CalCoreSubmesh*>& submeshes = core.getVectorCoreSubmesh();
  for (std::size_t s = 0; s < submeshes.size(); ++s) {
    CalCoreSubmesh* sub = submeshes[s];
    const std::string sfield = "submesh[" + std::to_string(s) + "]";
    if (sub == nullptr) return make_error(ErrorCode::kInvalidData, file, sfield, "", "missing");
    std::vector<CalCoreSubmesh::Vertex>& verts = sub->getVectorVertex();
    std::vector<CalCoreSubmesh::Face>& faces = sub->getVectorFace();
    std::vector<std::vector<CalCoreSubmesh::TextureCoordinate>>& uv_sets =
        sub->getVectorVectorTextureCoordinate();
    const std::size_t base = m.positions.size();
    if (base + verts.size() > UINT32_MAX) {
      return make_error(ErrorCode::kLimitExceeded, file, sfield + ".vertices",
                        std::to_string(verts.size()), "too many vertices");
    }
    // UVs: each submesh's first set. Once any submesh has UVs, vertices of
    // submeshes without them get (0,0), so the arrays stay parallel.
    const bool has_uv = !uv_sets.empty() && uv_sets[0].size() == verts.size();
    if (has_uv && m.uvs.size() < base) m.uvs.resize(base, Vec2(0.0f));

    for (std::size_t v = 0; v < verts.size(); ++v) {
      const CalCoreSubmesh::Vertex& cv = verts[v];
      const std::string vfield = sfield + ".vertex[" + std::to_string(v) + "]";
      const Vec3 p = to_vec3(cv.position);
      Vec3 n = to_vec3(cv.normal);
      if (!finite(p) || !finite(n)) {
        return make_error(ErrorCode::kInvalidData, file, vfield, "", "non-finite position or normal");
      }
      const float len = glm::length(n);
      // A zero normal cannot be made unit; any unit vector keeps the
      // SkinnedMesh invariant and the vertex is degenerate for shading anyway.
      n = len > 0.0f ? n / len : Vec3(0.0f, 0.0f, 1.0f);
      m.positions.push_back(p);
      m.normals.push_back(n);
      if (has_uv) {
        m.uvs.emplace_back(uv_sets[0][v].u, uv_sets[0][v].v);
      } else if (!m.uvs.empty()) {
        m.uvs.emplace_back(0.0f, 0.0f);
      }

      // Influences: keep the kMaxInfluences largest, renormalised.
      std::vector<std::pair<float, int>> infl;
      infl.reserve(cv.vectorInfluence.size());
      for (std::size_t k = 0; k < cv.vectorInfluence.size(); ++k) {
        const CalCoreSubmesh::Influence& in = cv.vectorInfluence[k];
        const std::string ifield = vfield + ".influence[" + std::to_string(k) + "]";
        if (in.boneId < 0 || static_cast<std::size_t>(in.boneId) >= remap.size()) {
          return make_error(ErrorCode::kOutOfBounds, file, ifield + ".bone",
                            std::to_string(in.boneId),
                            "no such bone (" + std::to_string(remap.size()) + " bones)");
        }
        if (!std::isfinite(in.weight) || in.weight < 0.0f) {
          return make_error(ErrorCode::kInvalidData, file, ifield + ".weight",
                            std::to_string(in.weight), "weight must be finite and >= 0");
        }
        if (in.weight > 0.0f) infl.emplace_back(in.weight, remap[static_cast<std::size_t>(in.boneId)]);
      }
      // stable_sort keeps file order among equal weights: deterministic.
      std::stable_sort(infl.begin(), infl.end(),
                       [](const auto& a, const auto& b) { return a.first > b.first; });
      if (infl.size() > static_cast<std::size_t>(kMaxInfluences)) infl.resize(kMaxInfluences);
      double sum = 0.0;
      for (const auto& i : infl) sum += static_cast<double>(i.first);
      // Cal3D leaves a vertex without influences in place (model space);
      // Sinew has no "no bone" slot, and binding it to some bone would move
      // it, so such a mesh is rejected rather than silently changed.
      if (infl.empty() || !(sum > 0.0)) {
        return make_error(ErrorCode::kInvalidData, file, vfield + ".influences", "0",
                          "vertex has no bone influence with a positive weight");
      }
      std::array<std::uint16_t, kMaxInfluences> joints{};
      std::array<float, kMaxInfluences> weights{};
      for (std::size_t k = 0; k < infl.size(); ++k) {
        joints[k] = static_cast<std::uint16_t>(infl[k].second);
        weights[k] = static_cast<float>(static_cast<double>(infl[k].first) / sum);
      }
      m.joints.push_back(joints);
      m.weights.push_back(weights);
    }

    int thread = sub->getCoreMaterialThreadId();
    std::uint32_t material = 0;
    if (thread >= 0 && static_cast<std::size_t>(thread) < ctx.material_count) {
      material = static_cast<std::uint32_t>(thread);
    } else {
      material = static_cast<std::uint32_t>(ctx.material_count);  // the white default
      ctx.uses_default_material = true;
    }
    for (std::size_t f = 0; f < faces.size(); ++f) {
      std::array<std::uint32_t, 3> tri{};
      for (int c = 0; c < 3; ++c) {
        const auto id = static_cast<long long>(faces[f].vertexId[c]);
        if (id < 0 || static_cast<std::size_t>(id) >= verts.size()) {
          return make_error(ErrorCode::kOutOfBounds, file,
                            sfield + ".face[" + std::to_string(f) + "].vertex[" +
                                std::to_string(c) + "]",
                            std::to_string(id),
                            "past the submesh's " + std::to_string(verts.size()) + " vertices");
        }
        tri[static_cast<std::size_t>(c)] = static_cast<std::uint32_t>(base + static_cast<std::size_t>(id));
      }
      m.triangles.push_back(tri);
      m.triangle_material.push_back(material);
    }
  }
  return {};
}

Expected<anim::Clip> convert_clip(CalCoreAnimation& core, const std::string& name,
                                  const std::string& file, const anim::Skeleton& skeleton,
                                  const std::vector<int>& remap) {
  anim::RawClip raw;
  raw.name = name;
  const float duration = core.getDuration();
  std::size_t t = 0;
  for (CalCoreTrack* track : core.getListCoreTrack()) {
    const std::string tfield = "track[" + std::to_string(t++) + "]";
    if (track == nullptr) return make_error(ErrorCode::kInvalidData, file, tfield, "", "missing");
    const int bone = track->getCoreBoneId();
    if (bone < 0 || static_cast<std::size_t>(bone) >= remap.size()) {
      return make_error(ErrorCode::kOutOfBounds, file, tfield + ".bone", std::to_string(bone),
                        "no such bone (" + std::to_string(remap.size()) + " bones)");
    }
    anim::JointTracks jt;
    jt.joint = remap[static_cast<std::size_t>(bone)];
    jt.translation.interpolation = anim::Interpolation::kLinear;
    jt.rotation.interpolation = anim::Interpolation::kLinear;
    const int count = track->getCoreKeyframeCount();
    // Cal3D samples nothing sensible from a track without keys; it animates
    // nothing, so it is left out.
    if (count <= 0) continue;
    for (int k = 0; k < count; ++k) {
      CalCoreKeyframe* key = track->getCoreKeyframe(k);
      if (key == nullptr) {
        return make_error(ErrorCode::kInvalidData, file, tfield + ".key[" + std::to_string(k) + "]",
                          "", "missing");
      }
      const float time = key->getTime();
      const Vec3 tr = to_vec3(key->getTranslation());
      const Quat rot = to_quat(key->getRotation());
      // Equal times: Cal3D samples the last of them at and after that time
      // (upper-bound search), so keeping the last reproduces it exactly.
      // Other ordering problems are left for Clip::build to report.
      if (!jt.translation.times.empty() && jt.translation.times.back() == time) {
        jt.translation.values.back() = tr;
        jt.rotation.values.back() = rot;
        continue;
      }
      jt.translation.times.push_back(time);
      jt.translation.values.push_back(tr);
      jt.rotation.times.push_back(time);
      jt.rotation.values.push_back(rot);
    }
    // Cal3D's cycles loop at the header duration, usually one frame past
    // the last key: CalMixer::blendCycle appends to each such track a key at
    // the duration holding the first key's value (Cal3D 0.11, checked by the
    // oracle test), so the last frame blends back into the first. Doing the
    // same makes the clip's duration Cal3D's and its loop seamless.
    if (std::isfinite(duration) && duration > jt.translation.times.back()) {
      jt.translation.times.push_back(duration);
      jt.translation.values.push_back(jt.translation.values.front());
      jt.rotation.times.push_back(duration);
      jt.rotation.values.push_back(jt.rotation.values.front());
    }
    raw.tracks.push_back(std::move(jt));
  }
  return anim::Clip::build(std::move(raw), skeleton, file);
}

// Cal3D 0.11's ~CalCoreAnimation does not delete its tracks (LeakSanitizer
// shows every track and keyframe lost), so the owner frees them; the list is
// emptied, so a Cal3D whose destructor does delete them finds nothing left.
class CoreModelTrackReleaser {
 public:
  explicit CoreModelTrackReleaser(CalCoreModel& core) : core_(core) {}
  CoreModelTrackReleaser(const CoreModelTrackReleaser&) = delete;
  CoreModelTrackReleaser& operator=(const CoreModelTrackReleaser&) = delete;
  ~CoreModelTrackReleaser() {
    for (int i = 0; i < core_.getCoreAnimationCount(); ++i) {
      CalCoreAnimation* anim = core_.getCoreAnimation(i);
      if (anim == nullptr) continue;
      std::list<CalCoreTrack*>& tracks = anim->getListCoreTrack();
      for (CalCoreTrack* track : tracks) {
        if (track == nullptr) continue;
        track->destroy();
        delete track;
      }
      tracks.clear();
    }
  }

 private:
  CalCoreModel& core_;
};

Expected<ImportedModel> import_impl(const std::string& cfg_path, std::string& current) {
  SINEW_RETURN_IF_ERROR(check_file(cfg_path));
  std::ifstream in(cfg_path, std::ios::binary);
  if (!in) return make_error(ErrorCode::kIoError, cfg_path, "", "", "cannot open");
  std::stringstream text;
  text << in.rdbuf();
  if (in.bad()) return make_error(ErrorCode::kIoError, cfg_path, "", "", "read failed");
  SINEW_ASSIGN_OR_RETURN(Cal3dConfig cfg, parse_cal3d_config(text.str(), cfg_path));

  const fs::path folder = fs::path(cfg_path).parent_path();
  const std::string model_name = fs::path(cfg_path).stem().string();

  CalCoreModel core(model_name);
  const CoreModelTrackReleaser release_tracks(core);

  // Skeleton first whatever the .cfg order: meshes and animations refer to it.
  const std::string skeleton_file = join(folder, cfg.skeleton);
  SINEW_RETURN_IF_ERROR(check_cal3d_file(skeleton_file, current));
  if (!core.loadCoreSkeleton(skeleton_file)) return cal3d_error(skeleton_file, "skeleton");
  if (core.getCoreSkeleton() == nullptr) {
    return make_error(ErrorCode::kInvalidData, skeleton_file, "", "", "Cal3D loaded no skeleton");
  }

  std::vector<std::string> mesh_files;
  std::vector<int> mesh_ids;
  for (const std::string& m : cfg.meshes) {
    mesh_files.push_back(join(folder, m));
    SINEW_RETURN_IF_ERROR(check_cal3d_file(mesh_files.back(), current));
    const int id = core.loadCoreMesh(mesh_files.back());
    if (id < 0) return cal3d_error(mesh_files.back(), "mesh");
    mesh_ids.push_back(id);
  }

  std::vector<std::string> material_files;
  std::vector<int> material_ids;
  for (const std::string& m : cfg.materials) {
    material_files.push_back(join(folder, m));
    SINEW_RETURN_IF_ERROR(check_cal3d_file(material_files.back(), current));
    const int id = core.loadCoreMaterial(material_files.back());
    if (id < 0) return cal3d_error(material_files.back(), "material");
    material_ids.push_back(id);
  }

  SINEW_ASSIGN_OR_RETURN(const std::vector<ClipFile> clips,
                         clip_files(cfg, folder, model_name, cfg_path));
  std::vector<int> clip_ids;
  for (const ClipFile& c : clips) {
    SINEW_RETURN_IF_ERROR(check_cal3d_file(c.path, current));
    const int id = core.loadCoreAnimation(c.path);
    if (id < 0) return cal3d_error(c.path, "animation");
    clip_ids.push_back(id);
  }

  current = cfg_path;
  // After loading everything, so meshes, skeleton and keyframes all scale.
  if (cfg.scale != 1.0f) core.scale(cfg.scale);

  ImportedModel out;
  out.source = cfg_path;
  std::vector<int> raw_to_sorted;
  SINEW_ASSIGN_OR_RETURN(out.skeleton,
                         convert_skeleton(*core.getCoreSkeleton(), skeleton_file, raw_to_sorted));

  MeshContext ctx;
  ctx.mesh = &out.mesh;
  ctx.raw_to_sorted = &raw_to_sorted;
  ctx.material_count = material_ids.size();
  for (std::size_t i = 0; i < mesh_ids.size(); ++i) {
    CalCoreMesh* mesh = core.getCoreMesh(mesh_ids[i]);
    if (mesh == nullptr) return make_error(ErrorCode::kInvalidData, mesh_files[i], "", "", "Cal3D loaded no mesh");
    SINEW_RETURN_IF_ERROR(convert_mesh(*mesh, mesh_files[i], ctx));
  }

  for (std::size_t i = 0; i < material_ids.size(); ++i) {
    CalCoreMaterial* mat = core.getCoreMaterial(material_ids[i]);
    Vec3 color(1.0f);
    if (mat != nullptr) {
      const CalCoreMaterial::Color& c = mat->getDiffuseColor();
      // Bytes 0..255 taken as linear: Cal3D's fixed-function demos feed them
      // to glMaterial unconverted.
      color = Vec3(c.red, c.green, c.blue) / 255.0f;
    }
    out.mesh.material_colors.push_back(color);
    out.material_names.push_back(fs::path(material_files[i]).stem().string());
  }
  if (ctx.uses_default_material) {
    out.mesh.material_colors.emplace_back(1.0f);
    out.material_names.emplace_back("default");
  }

  for (std::size_t i = 0; i < clips.size(); ++i) {
    CalCoreAnimation* anim = core.getCoreAnimation(clip_ids[i]);
    if (anim == nullptr) {
      return make_error(ErrorCode::kInvalidData, clips[i].path, "", "", "Cal3D loaded no animation");
    }
    SINEW_ASSIGN_OR_RETURN(anim::Clip clip, convert_clip(*anim, clips[i].name, clips[i].path,
                                                         out.skeleton, raw_to_sorted));
    out.clips.push_back(std::move(clip));
  }
  return out;
}

}  // namespace

Expected<Cal3dConfig> parse_cal3d_config(std::string_view text, std::string_view source) {
  Cal3dConfig cfg;
  bool have_skeleton = false;
  std::size_t line_no = 0;
  while (!text.empty()) {
    const std::size_t eol = text.find('\n');
    std::string_view line = text.substr(0, eol);
    text = eol == std::string_view::npos ? std::string_view() : text.substr(eol + 1);
    ++line_no;
    const std::string field = "line " + std::to_string(line_no);
    line = trim(line);
    if (line.empty() || line.front() == '#') continue;
    const std::size_t eq = line.find('=');
    if (eq == std::string_view::npos) {
      return make_error(ErrorCode::kInvalidData, source, field,
                        std::string(line.substr(0, std::min<std::size_t>(line.size(), 60))),
                        "expected key=value");
    }
    const std::string key = lower(std::string(trim(line.substr(0, eq))));
    const std::string_view value = trim(line.substr(eq + 1));
    const bool known = key == "scale" || key == "skeleton" || key == "mesh" || key == "animation" ||
                       key == "material";
    if (!known) continue;  // other tools' keys (path=, ...) are not errors
    if (value.empty()) {
      return make_error(ErrorCode::kInvalidData, source, field + ": " + key, "", "empty value");
    }
    if (key == "scale") {
      float s = 0.0f;
      const auto [ptr, ec] = std::from_chars(value.data(), value.data() + value.size(), s);
      if (ec != std::errc() || ptr != value.data() + value.size() || !std::isfinite(s) || s <= 0.0f) {
        return make_error(ErrorCode::kInvalidData, source, field + ": scale", std::string(value),
                          "scale must be a finite positive number");
      }
      cfg.scale = s;
    } else if (key == "skeleton") {
      if (have_skeleton) {
        return make_error(ErrorCode::kDuplicate, source, field + ": skeleton", std::string(value),
                          "a model has one skeleton");
      }
      have_skeleton = true;
      cfg.skeleton = std::string(value);
    } else if (key == "mesh") {
      cfg.meshes.emplace_back(value);
    } else if (key == "animation") {
      cfg.animations.emplace_back(value);
    } else {
      cfg.materials.emplace_back(value);
    }
  }
  if (!have_skeleton) {
    return make_error(ErrorCode::kNotFound, source, "skeleton", "", "no skeleton= line");
  }
  return cfg;
}

Expected<ImportedModel> import_cal3d(const std::string& cfg_path) {
  // Cal3D allocates with plain new and std::vector from counts in the file;
  // a corrupt count can throw. Errors are values here, so that ends as one.
  std::string current = cfg_path;
  try {
    return import_impl(cfg_path, current);
  } catch (const std::bad_alloc&) {
    return make_error(ErrorCode::kLimitExceeded, current, "", "",
                      "out of memory while Cal3D loaded the file (corrupt count?)");
  } catch (const std::exception& e) {
    return make_error(ErrorCode::kInvalidData, current, "", "", std::string("Cal3D failed: ") + e.what());
  }
}

}  // namespace sinew::editor
