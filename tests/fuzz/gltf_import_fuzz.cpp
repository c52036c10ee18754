// libFuzzer target for the glTF importer (editor/import/gltf_importer.h):
// both .glb and .gltf, since import_gltf picks the parser by the file's
// magic ("glTF" = binary), not by its name. Each input is written as-is to
// <scratch>/model.gltf and imported; so a seed is simply a glTF file and a
// crash input can be loaded with `sinew-editor` directly.
//
// External resources: the scratch folder holds nothing but the model, so a
// buffer "uri" naming a file must fail cleanly (kInvalidData naming the
// file), as must data: URIs that do not decode; the seeds therefore embed
// their buffers (base64 data URIs in .gltf, the BIN chunk in .glb; written by
// make_gltf_seeds.py). Images are never decoded (the importer skips them).
//
// Mutations: half of them are structural (tests/fuzz/gltf_mutator.h: the
// parsed document's elements duplicated, repeated, deleted, swapped and
// renumbered, nodes chained and looped, extras nested deeply), the rest are
// libFuzzer's byte mutations with gltf_import.dict.
//
// A finding: any sanitizer report, leak, trap, time-out or OOM; a refusal
// without an error code or message; or an imported model whose mesh or
// skeleton breaks the character::Model invariants checked below.
#include <cstddef>
#include <cstdint>

#include <cstring>
#include <string>

#include "editor/import/gltf_importer.h"
#include "tests/fuzz/fuzz_support.h"
#include "tests/fuzz/gltf_mutator.h"

extern "C" std::size_t LLVMFuzzerMutate(std::uint8_t* data, std::size_t size, std::size_t max_size);

extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size, std::size_t max_size,
                                              unsigned int seed) {
  if (seed % 2 == 0) {
    const std::string mutated = sinew::fuzz::mutate_gltf(data, size, max_size, seed / 2);
    if (!mutated.empty()) {
      std::memcpy(data, mutated.data(), mutated.size());
      return mutated.size();
    }
  }
  return LLVMFuzzerMutate(data, size, max_size);
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sinew;
  const auto path = fuzz::scratch_dir("gltf_import") / "model.gltf";
  fuzz::write_file(path, data, size);

  auto model = editor::import_gltf(path.string());
  if (!model.ok()) {
    fuzz::require_clear_error(model.status());
    return 0;
  }
  fuzz::require_consistent_model(*model);
  return 0;
}
