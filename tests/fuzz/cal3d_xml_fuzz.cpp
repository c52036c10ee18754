// libFuzzer target for Cal3D's XML formats: the importer's structural checks
// (editor/import/cal3d_xml_check.h), then Cal3D's own XML loaders.
//
// The first input byte (modulo 3) picks which file of a model is fuzzed:
//   0: skeleton.xsf   1: mesh.xmf   2: anim.xaf
// and the rest of the input is that file's text. The other two are Cally's
// skeleton, neck mesh and wave clip, written as XML by Cal3D's own saver
// when the fuzzer starts (from the binary files in SINEW_SHARED_DIR, so no
// third-party bytes are committed), and a fixed model.cfg lists all three.
// The same three files behind their selector bytes are written as seeds
// into the generated seed folder (SINEW_FUZZ_GENERATED_SEEDS) when it is
// empty; corpus/cal3d_xml/ holds the project's own small skeleton.
//
// A finding: any sanitizer report, leak, trap, time-out or OOM; a refusal
// without an error code or message; or an imported model that breaks the
// invariants of require_consistent_model.
#include <cal3d/cal3d.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "editor/import/cal3d_importer.h"
#include "tests/fuzz/fuzz_support.h"
#include "tests/support/cal3d_support.h"

namespace {

constexpr std::array<const char*, 3> kFiles{"skeleton.xsf", "mesh.xmf", "anim.xaf"};

constexpr const char* kConfig =
    "skeleton=skeleton.xsf\n"
    "mesh=mesh.xmf\n"
    "animation=anim.xaf\n";

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Cally's three files as XML, saved once by Cal3D.
const std::array<std::string, 3>& companions() {
  static const std::array<std::string, 3> files = [] {
    const std::string cally = std::string(SINEW_SHARED_DIR) + "/content/cal3d/cally/";
    const auto& dir = sinew::fuzz::scratch_dir("cal3d_xml");
    CalCoreModel core("cally");
    const bool loaded = core.loadCoreSkeleton(cally + "cally.csf") && core.loadCoreMesh(cally + "cally_neck.cmf") >= 0 &&
                        core.loadCoreAnimation(cally + "cally_wave.caf") >= 0;
    const bool saved = loaded && CalSaver::saveCoreSkeleton((dir / "cally.xsf").string(), core.getCoreSkeleton()) &&
                       CalSaver::saveCoreMesh((dir / "cally.xmf").string(), core.getCoreMesh(0)) &&
                       CalSaver::saveCoreAnimation((dir / "cally.xaf").string(), core.getCoreAnimation(0));
    sinew::testing_support::free_cal3d_animation_tracks(core);
    if (!saved) {
      std::fprintf(stderr, "cal3d_xml_fuzz: cannot write Cally as XML from %s (the shared content)\n", cally.c_str());
      __builtin_trap();
    }
    return std::array<std::string, 3>{read_file(dir / "cally.xsf"), read_file(dir / "cally.xmf"),
                                      read_file(dir / "cally.xaf")};
  }();
  return files;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const std::filesystem::path seeds(SINEW_FUZZ_GENERATED_SEEDS);
  std::error_code ec;
  if (std::filesystem::is_directory(seeds, ec) && std::filesystem::is_empty(seeds, ec)) {
    for (std::size_t i = 0; i < kFiles.size(); ++i) {
      const std::string seed = static_cast<char>(i) + companions()[i];
      sinew::fuzz::write_file(seeds / (std::string("cally-") + kFiles[i]), seed.data(), seed.size());
    }
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sinew;
  if (size == 0) return 0;
  const std::size_t fuzzed = data[0] % kFiles.size();
  const auto& dir = fuzz::scratch_dir("cal3d_xml");
  fuzz::write_file(dir / "model.cfg", kConfig, std::char_traits<char>::length(kConfig));
  for (std::size_t i = 0; i < kFiles.size(); ++i) {
    if (i == fuzzed) {
      fuzz::write_file(dir / kFiles[i], data + 1, size - 1);
    } else {
      fuzz::write_file(dir / kFiles[i], companions()[i].data(), companions()[i].size());
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
