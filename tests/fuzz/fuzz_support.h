// Shared helpers of the file-based fuzz targets (gltf_import_fuzz.cpp,
// cal3d_import_fuzz.cpp): the importers read files, so each input is
// written into one scratch folder per fuzzer process first.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "animation/clip.h"
#include "animation/joint_transform.h"
#include "character/model.h"
#include "runtime/core/status.h"

namespace sinew::fuzz {

// A finding: libFuzzer reports the trap with the input that caused it.
inline void require(bool condition) {
  if (!condition) __builtin_trap();
}

// The importers' promise on refusal: a code and a message.
inline void require_clear_error(const Status& status) {
  require(status.code() != ErrorCode::kOk);
  require(!status.message().empty());
}

// The process's scratch folder (unique per process, so parallel fuzzers do
// not share files), removed at exit.
inline const std::filesystem::path& scratch_dir(const char* fuzzer_name) {
  static const std::filesystem::path dir = [fuzzer_name] {
    std::filesystem::path p = std::filesystem::temp_directory_path() /
                              (std::string("sinew-") + fuzzer_name + "-" + std::to_string(::getpid()));
    std::filesystem::remove_all(p);
    std::filesystem::create_directories(p);
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(scratch_dir(nullptr), ec);
    });
    return p;
  }();
  return dir;
}

inline void write_file(const std::filesystem::path& path, const void* data, std::size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
  require(static_cast<bool>(out));
}

// What every importer promises about a model it returns: parallel mesh
// arrays, triangle, joint and material indices in range, and clips that can
// be sampled over the skeleton's rest pose (at start, middle and end).
inline void require_consistent_model(const character::Model& model) {
  const SkinnedMesh& mesh = model.mesh;
  const std::size_t vertices = mesh.vertex_count();
  const std::size_t joints = model.skeleton.joint_count();
  require(joints > 0);
  require(mesh.joints.size() == vertices && mesh.weights.size() == vertices);
  require(mesh.normals.empty() || mesh.normals.size() == vertices);
  require(mesh.uvs.empty() || mesh.uvs.size() == vertices);
  require(mesh.triangle_material.size() == mesh.triangle_count());
  require(model.material_names.size() == mesh.material_colors.size());
  for (const auto& triangle : mesh.triangles) {
    for (std::uint32_t v : triangle) require(v < vertices);
  }
  for (std::uint32_t m : mesh.triangle_material) require(m < mesh.material_colors.size());
  for (const auto& row : mesh.joints) {
    for (std::uint16_t j : row) require(j < joints);
  }
  for (const anim::Clip& clip : model.clips) {
    std::vector<anim::JointTransform> local(model.skeleton.rest_pose().begin(),
                                            model.skeleton.rest_pose().end());
    anim::SamplingCache cache;
    cache.reset(clip);
    for (float t : {0.0f, 0.5f * clip.duration(), clip.duration()}) {
      anim::sample_clip(clip, t, cache, local);
    }
  }
}

}  // namespace sinew::fuzz
