// libFuzzer target for the Cal3D importer (editor/import/cal3d_importer.h).
//
// The importer reads a .cfg and the files it lists, so every input is
// written into a scratch folder as ONE of the model's files, chosen by the
// input's first byte (modulo 4):
//   0: skeleton.csf   1: mesh.cmf   2: anim.caf   3: material.xrf (XML)
// and the rest of the input is that file's bytes. The other three files are
// Cally's own (cally.csf, cally_neck.cmf, cally_idle.caf, cally_skin.xrf from
// the shared content folder, SINEW_SHARED_DIR), and a fixed model.cfg lists
// all four. So a fuzzed mesh is bound to a real skeleton, a fuzzed
// animation drives a real skeleton, and so on. Seeds (corpus/cal3d_import/,
// written by make_import_seeds.py) are Cally's and the skeleton model's
// files behind their selector byte.
//
// Binary .csf/.cmf/.caf are pre-validated by the importer before Cal3D reads
// them; the XML material goes to Cal3D's own parser, so a crash there is a
// finding for the importer too (it must refuse what Cal3D cannot take).
// A finding: any sanitizer report, leak, trap, time-out or OOM; a refusal
// without an error code or message; or an imported model that breaks the
// invariants of require_consistent_model.
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>

#include "editor/import/cal3d_importer.h"
#include "tests/fuzz/fuzz_support.h"

namespace {

struct ModelFile {
  const char* scratch_name;  // as model.cfg lists it
  const char* cally_name;    // the companion used when this file is not fuzzed
};

constexpr std::array<ModelFile, 4> kFiles{{
    {"skeleton.csf", "cally.csf"},
    {"mesh.cmf", "cally_neck.cmf"},
    {"anim.caf", "cally_idle.caf"},
    {"material.xrf", "cally_skin.xrf"},
}};

constexpr const char* kConfig =
    "scale=1.0\n"
    "skeleton=skeleton.csf\n"
    "mesh=mesh.cmf\n"
    "animation=anim.caf\n"
    "material=material.xrf\n";

std::string read_companion(const char* name) {
  const std::string path = std::string(SINEW_SHARED_DIR) + "/content/cal3d/cally/" + name;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    std::fprintf(stderr, "cal3d_import_fuzz: cannot read %s (the shared content)\n", path.c_str());
    __builtin_trap();
  }
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

const std::array<std::string, 4>& companions() {
  static const std::array<std::string, 4> files = [] {
    std::array<std::string, 4> out;
    for (std::size_t i = 0; i < kFiles.size(); ++i) out[i] = read_companion(kFiles[i].cally_name);
    return out;
  }();
  return files;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sinew;
  if (size == 0) return 0;
  const std::size_t fuzzed = data[0] % kFiles.size();
  const auto& dir = fuzz::scratch_dir("cal3d_import");
  fuzz::write_file(dir / "model.cfg", kConfig, std::char_traits<char>::length(kConfig));
  for (std::size_t i = 0; i < kFiles.size(); ++i) {
    if (i == fuzzed) {
      fuzz::write_file(dir / kFiles[i].scratch_name, data + 1, size - 1);
    } else {
      fuzz::write_file(dir / kFiles[i].scratch_name, companions()[i].data(), companions()[i].size());
    }
  }

  auto model = editor::import_cal3d((dir / "model.cfg").string());
  if (!model.ok()) {
    fuzz::require_clear_error(model.status());
    return 0;
  }
  fuzz::require_consistent_model(*model);
  return 0;
}
