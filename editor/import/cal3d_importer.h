// Cal3D importer: reads a Cal3D model (.cfg + .csf/.cmf/.caf/.xrf, or the
// XML variants .xsf/.xmf/.xaf/.xrf) through the Cal3D library itself, so the
// file parsing is Cal3D's and only the conversion to Sinew's types is ours.
//
// Conventions (docs/ANIMATION.md, "Importers"), pinned by tests/editor/cal3d_import_test:
// * Units: the .cfg `scale=` is applied with CalCoreModel::scale() after
//   everything is loaded, so positions, bone translations and keyframe
//   translations are in the file's units times that scale — exactly what the
//   Cal3D library itself renders for that model.
// * Rotations: a CalQuaternion q rotates vectors as the conjugate of the
//   glm quaternion with the same components (Cal3D's `v *= q` computes
//   q^-1 v q), so every quaternion is imported as glm::quat(w, -x, -y, -z).
//   With that mapping Cal3D's `child *= parent` becomes parent * child.
// * Times: keyframe times in seconds are kept. Cal3D loops a cycle at
//   CalCoreAnimation::getDuration() (the header's duration, in the test
//   content one frame past the last key: walk's keys end at 1.0 s, its
//   duration is 1.0333 s), and CalMixer::blendCycle appends to every track
//   ending earlier a key at the duration with the first key's value, so the
//   last frame blends back into the first. The importer appends the same
//   key: the clip's duration (Sinew: the last key time) equals Cal3D's and
//   looping matches Cal3D's cycles. Not reproduced, both outside what the
//   test content uses: the Debian Cal3D 0.11 extrapolates the first / last
//   key interval when sampled outside the keys (a non-cycle action past its
//   last key, a track whose first key is after 0); Sinew holds the end keys
//   (newer Cal3D does too). A header duration shorter than the last key is
//   kept as the last key (Cal3D would wrap before it). Keys with equal
//   times are collapsed to the last of them, the key Cal3D samples at and
//   after that time.
// * Triangle order: meshes in .cfg order, then submeshes and faces in file
//   order. Vertices: per submesh, as stored, in the same order.
// * Materials: a submesh's material thread id indexes the .cfg's material
//   lines in order (the convention of Cal3D's own demos, which create one
//   thread per material with thread id == material id); a submesh whose id
//   names no loaded material gets an extra white material "default".
//   Diffuse bytes are divided by 255 with no sRGB decoding.
// * Robustness: Cal3D 0.11 trusts its input (unchecked counts, reads past
//   the end, an unchecked face index in its own loader), so binary
//   .csf/.cmf/.caf files are walked and checked before Cal3D sees them;
//   XML materials (.xrf) must have exactly the form Cal3D writes (its XML
//   loader dereferences missing attributes and texts); other XML files and
//   binary .crf materials are left to Cal3D's own checks. Exceptions from
//   Cal3D (std::bad_alloc) become errors naming the file being loaded.
// * Influences: the 8 largest weights, renormalised to sum 1 (Cal3D does not
//   renormalise; the test content's weights already sum to 1). A vertex
//   with no positive weight is an error: Cal3D would leave it unskinned,
//   which Sinew's SkinnedMesh cannot express.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "character/model.h"
#include "runtime/core/expected.h"

namespace sinew::editor {

// The range of a .cfg's scale= the tracer handles: the default camera
// frames a character of at least a millionth of a unit (a Cal3D model is
// tens of units tall), and a million times keeps Cally's hundred-odd units
// far inside character::kMaxCoordinate. A scale of 1e-10 used to render an
// image without the character.
inline constexpr float kMinCal3dScale = 1e-6f;
inline constexpr float kMaxCal3dScale = 1e6f;

// The parts of a Cal3D .cfg the importer uses. Paths are as written in the
// file (relative to the .cfg's folder unless absolute).
struct Cal3dConfig {
  float scale = 1.0f;
  std::string skeleton;
  std::vector<std::string> meshes;
  std::vector<std::string> animations;
  std::vector<std::string> materials;
};

// Parses .cfg text: `key=value` lines, `#` comments, blank lines; keys and
// values are trimmed; unknown keys are ignored. Errors (naming `source` and
// the line): a non-blank line without '=', an empty value, a scale that is
// not a finite number in [kMinCal3dScale, kMaxCal3dScale], a second
// skeleton line, no skeleton line.
Expected<Cal3dConfig> parse_cal3d_config(std::string_view text, std::string_view source);

// Imports the model of `cfg_path`: its skeleton and meshes, the animations
// it lists and also every `<model>_*.caf` / `<model>_*.xaf` next to it
// (<model> = the .cfg's stem), the listed ones first in .cfg order, then the
// others sorted by file name. Clip names are the file stem without the
// `<model>_` prefix. A file listed twice is one clip; two listed files with
// one clip name are a kDuplicate error; a file found beside the .cfg whose
// clip name is taken (cally_walk.xaf next to cally_walk.caf) is skipped.
// Errors name the file: kNotFound (missing file), kInvalidData /
// kBadMagic / kUnsupportedVersion / kTruncated (what Cal3D reported, or what
// the conversion found: bone ids out of range, non-finite values, vertices
// without influences), plus the errors of Skeleton::build and Clip::build.
Expected<character::Model> import_cal3d(const std::string& cfg_path);

}  // namespace sinew::editor
