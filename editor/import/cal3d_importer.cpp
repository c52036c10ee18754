// The Cal3D import in order (cal3d_importer.h says what becomes of a model):
// the .cfg and the files it names (cal3d_files.h), each checked before Cal3D
// loads it (cal3d_validate.h), then converted (cal3d_convert.h); Cal3D's
// errors and exceptions become Statuses naming the file.
#include "editor/import/cal3d_convert.h"
#include "editor/import/cal3d_files.h"
#include "editor/import/cal3d_importer.h"
#include "editor/import/cal3d_validate.h"
#include "editor/import/material_maps.h"
#include "runtime/io/regular_file.h"

#include <exception>
#include <filesystem>
#include <fstream>
#include <list>
#include <new>
#include <sstream>
#include <string_view>
#include <utility>
#include <vector>

#include <cal3d/cal3d.h>
#include <cal3d/coretrack.h>

namespace sinew::editor {
namespace {

namespace fs = std::filesystem;

using cal3d_detail::clip_files;
using cal3d_detail::ClipFile;
using cal3d_detail::convert_clip;
using cal3d_detail::convert_mesh;
using cal3d_detail::convert_skeleton;
using cal3d_detail::join;
using cal3d_detail::MeshContext;
using cal3d_detail::validate_binary;

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
Status check_file(const std::string& path) { return check_regular_file(path); }

// Before each Cal3D load: the file exists and, if binary, is well formed.
// `current` records it, so an exception from inside Cal3D names the file.
Status check_cal3d_file(const std::string& path, std::string& current) {
  current = path;
  SINEW_RETURN_IF_ERROR(check_file(path));
  return validate_binary(path);
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

Expected<character::Model> import_impl(const std::string& cfg_path, std::string& current) {
  SINEW_RETURN_IF_ERROR(check_file(cfg_path));
  std::ifstream in(cfg_path, std::ios::binary);
  if (!in) return make_error(ErrorCode::kIoError, cfg_path, "", "", "cannot open");
  std::stringstream text;
  text << in.rdbuf();
  if (in.bad()) return make_error(ErrorCode::kIoError, cfg_path, "", "", "read failed");
  SINEW_ASSIGN_OR_RETURN(Cal3dConfig cfg, parse_cal3d_config(text.str(), cfg_path));

  // A .cfg reached through a symbolic link names its files relative to the
  // file it links to, beside which they lie, not relative to the link.
  std::error_code link_error;
  const fs::path target =
      fs::is_symlink(cfg_path, link_error) ? fs::canonical(cfg_path, link_error) : fs::path(cfg_path);
  const fs::path cfg_file = link_error ? fs::path(cfg_path) : target;
  const fs::path folder = cfg_file.parent_path();
  const std::string model_name = cfg_file.stem().string();

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

  character::Model out;
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

  std::vector<std::string> maps(material_ids.size());  // each material's first map: its diffuse texture
  for (std::size_t i = 0; i < material_ids.size(); ++i) {
    CalCoreMaterial* mat = core.getCoreMaterial(material_ids[i]);
    Vec3 color(1.0f);
    if (mat != nullptr && mat->getMapCount() > 0) maps[i] = mat->getMapFilename(0);
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
  load_material_maps(maps, out.material_names, folder.string(), out.mesh, out.warnings);

  for (std::size_t i = 0; i < clips.size(); ++i) {
    CalCoreAnimation* anim = core.getCoreAnimation(clip_ids[i]);
    if (anim == nullptr) {
      return make_error(ErrorCode::kInvalidData, clips[i].path, "", "", "Cal3D loaded no animation");
    }
    SINEW_ASSIGN_OR_RETURN(anim::Clip clip, convert_clip(*anim, clips[i].name, clips[i].path,
                                                         out.skeleton, raw_to_sorted));
    out.clips.push_back(std::move(clip));
  }
  SINEW_RETURN_IF_ERROR(character::normalize_skin_weights(out));
  return out;
}

}  // namespace

Expected<character::Model> import_cal3d(const std::string& cfg_path) {
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
