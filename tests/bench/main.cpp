// sinew-bench: Sinew's benchmark programs. They print tables; nothing here
// is asserted (tests never time anything).
#include <cstdio>
#include <string>
#include <vector>

#include "runtime/cpu/cpu_features.h"
#include "tests/bench/animation_bench.h"

namespace {

void usage() {
  std::printf(
      "usage: sinew-bench <benchmark> [options]\n"
      "  animation [--frames N] [--shared DIR]   animation + skinning vs the Cal3D library\n");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    usage();
    return 2;
  }
  if (sinew::Status s = sinew::check_cpu_supports_build(); !s.ok()) {
    std::fprintf(stderr, "sinew-bench: %s\n", s.message().c_str());
    return 1;
  }
  const std::string what = argv[1];
  const std::vector<std::string> args(argv + 2, argv + argc);
  if (what == "animation") return sinew::bench::run_animation_bench(args);
  if (what == "--help" || what == "-h" || what == "help") {
    usage();
    return 0;
  }
  std::fprintf(stderr, "sinew-bench: unknown benchmark '%s'\n", what.c_str());
  usage();
  return 2;
}
