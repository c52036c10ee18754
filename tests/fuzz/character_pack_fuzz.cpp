// libFuzzer target for character content packs (character/pack.h):
// load, validate and, when the pack loads, render a tiny image from it.
//
// The contract under test is the loader's promise: "a pack that loads is
// safe to render, whatever bytes it was made of". So an input that loads is
// put in a Scene, posed by its first clip, skinned and ray traced (16x16,
// colour + triangle ids, with shadows); any ASan/UBSan report, leak or trap
// anywhere on that path is a finding. Errors are not: a damaged pack may be
// refused at any step (a clip that cannot be evaluated, a pose so huge or
// non-finite that no camera frames it), and then the input simply ends.
//
// Checksums: the pack container checksums its header, its table and every
// section (XXH3-64), so almost every mutation libFuzzer makes would be
// refused before any section decoder runs. Every input is therefore
// "re-sealed" first: file_size and all checksums are recomputed over the
// mutated bytes, wherever the (bounds-checked) structure lets us find what
// they cover. The seeds stay plain, valid packs (corpus/character_pack/,
// written by sinew_make_character_pack_seeds), and mutations reach the
// skeleton, mesh, clip, limit, pose-space, provenance and fuzzy-tree
// decoders and validators. The container's own checksum checks are the
// pack_reader fuzzer's business.
//
// Half of the mutations are structural (pack_mutator.h: sections zeroed,
// swapped, shifted, cut short or copied over each other), the rest are
// libFuzzer's byte mutations; both are re-sealed.
//
// The harness traps (a finding) when a refused pack's error has no code or
// no message, or when a rendered pixel names a triangle the mesh does not
// have. Field and value may legitimately be empty ("MESH: section missing"
// has no value).
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <new>
#include <span>
#include <vector>

#include "character/bake.h"
#include "character/framing.h"
#include "character/pack.h"
#include "raytrace/camera/camera.h"
#include "raytrace/render/renderer.h"
#include "raytrace/scene/scene.h"
#include "runtime/jobs/job_system.h"
#include "runtime/pack/checksum.h"
#include "runtime/pack/pack_format.h"
#include "tests/fuzz/pack_mutator.h"
#include "tests/fuzz/reseal_pack.h"

extern "C" std::size_t LLVMFuzzerMutate(std::uint8_t* data, std::size_t size, std::size_t max_size);

extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size, std::size_t max_size,
                                              unsigned int seed) {
  if (seed % 2 == 0 &&
      sinew::fuzz::mutate_pack_structure(std::span(reinterpret_cast<std::byte*>(data), size), seed / 2)) {
    return size;
  }
  return LLVMFuzzerMutate(data, size, max_size);
}

namespace {

using namespace sinew;

constexpr int kImageSize = 16;
// Bigger meshes are still loaded and validated, only not rendered: skinning
// and tracing them would cut the executions per second for little new
// coverage.
constexpr std::size_t kMaxRenderedTriangles = 20000;
// section_as<T> refuses misaligned payloads; sections are 64-aligned in the
// file, so the file itself must be too.
constexpr std::size_t kBufferAlignment = 64;

void require(bool condition) {
  if (!condition) __builtin_trap();
}

struct AlignedFree {
  void operator()(std::byte* p) const { ::operator delete[](p, std::align_val_t{kBufferAlignment}); }
};

// The input copied into a 64-byte aligned buffer of exactly its size (so ASan
// still sees any read past the end).
class AlignedBytes {
 public:
  explicit AlignedBytes(std::span<const std::uint8_t> input)
      : size_(input.size()),
        data_(static_cast<std::byte*>(
            ::operator new[](input.empty() ? 1 : input.size(), std::align_val_t{kBufferAlignment}))) {
    if (!input.empty()) std::memcpy(data_.get(), input.data(), input.size());
  }
  std::span<std::byte> span() { return {data_.get(), size_}; }

 private:
  std::size_t size_;
  std::unique_ptr<std::byte[], AlignedFree> data_;
};

JobSystem& serial_jobs() {
  // One thread: deterministic, and no worker threads for libFuzzer to juggle.
  static JobSystem jobs(1);
  return jobs;
}

// Renders the loaded pack's character; returns early on any refused step.
void render(const character::Pack& pack) {
  const character::Model& model = pack.model();
  if (model.mesh.triangle_count() > kMaxRenderedTriangles) return;
  JobSystem& jobs = serial_jobs();

  rt::Scene scene;
  auto character = scene.add_character(model.mesh, pack.fuzzy());
  if (!character.ok()) return;
  auto instance = scene.add_instance(*character);
  if (!instance.ok()) return;
  if (!model.clips.empty()) {
    auto skinning = character::clip_skinning(model, model.clips.front(), 0.25);
    if (!skinning.ok()) return;
    if (!scene.set_bones(*instance, *skinning).ok()) return;
  }
  if (!scene.prepare_frame(rt::FrameOptions{}, jobs).ok()) return;

  const Aabb posed = character::posed_bounds(scene);
  const int up = character::up_axis_of(character::rest_bounds(model));
  // A huge or non-finite pose gives no camera: refused, not a bug.
  auto camera = rt::PinholeCamera::create(character::default_camera(posed, up, kImageSize, kImageSize),
                                          kImageSize, kImageSize);
  if (!camera.ok()) return;

  std::vector<std::uint8_t> rgba(kImageSize * kImageSize * 4);
  std::vector<std::uint32_t> triangles(kImageSize * kImageSize);
  rt::FrameBuffers buffers;
  buffers.width = kImageSize;
  buffers.height = kImageSize;
  buffers.color_rgba8 = rgba;
  buffers.triangle_id = triangles;
  rt::RenderSettings settings;
  settings.shadows = true;
  settings.light.position = character::default_light(posed, up);
  auto stats = rt::Renderer().render(scene, *camera, settings, buffers, jobs);
  if (!stats.ok()) return;

  // A hit names a triangle of the mesh (one instance, no ground).
  for (std::uint32_t id : triangles) {
    require(id == 0xFFFFFFFFu || id < model.mesh.triangle_count());
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  AlignedBytes bytes(std::span(data, size));
  sinew::fuzz::reseal_pack(bytes.span());

  auto pack = character::Pack::from_bytes(bytes.span(), "fuzz.pack");
  if (!pack.ok()) {
    const Status& status = pack.status();
    require(status.code() != ErrorCode::kOk);
    require(!status.message().empty());
    return 0;
  }
  if (pack->has_fuzzy()) render(*pack);
  return 0;
}
