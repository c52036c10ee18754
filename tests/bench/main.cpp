// sinew-bench: Sinew's benchmark programs. They print tables; nothing here
// is asserted (tests never time anything).
#include <cstdio>
#include <string>
#include <vector>

#include "runtime/cpu/cpu_features.h"
#include "tests/bench/animation_bench.h"
#include "tests/bench/bake_bench.h"
#include "tests/bench/demo_bench.h"
#include "tests/bench/embree_bench.h"
#include "tests/bench/paper_bench.h"
#include "tests/bench/raytrace_bench.h"
#include "tests/bench/report_bench.h"
#include "tests/bench/tradeoff_bench.h"

namespace {

void usage() {
  std::printf(
      "usage: sinew-bench <benchmark> [options]\n"
      "  animation [--frames N] [--shared DIR]   animation + skinning vs the Cal3D library\n"
      "  bake [--models LIST] [--shared DIR] [--threads N] [--large on|off] [--json FILE]\n"
      "           fuzzy bake cost per candidate-bone mode, its trace effect, and its memory bound\n"
      "  demo [--characters LIST] [--size WxH] [--threads N] [--frames N] [--warmup N]\n"
      "           [--shadows on|off] [--model PATH] [--json FILE]   the game demo's fps and phases\n"
      "  embree [--quick] [--model NAME|PATH] [--subdivide L] [--instances N] [--frames N] [--clips LIST]\n"
      "           [--size WxH] [--threads LIST] [--json FILE]   Sinew vs Embree 3 (rebuild LOW/MEDIUM, refit) vs exact kd\n"
      "  paper [--quick] [--tables 1,2] [--levels LIST] [--threads LIST] [--frames N] [--size WxH]\n"
      "           [--samples N] [--json FILE] [--markdown FILE]   the paper's Tables 1 and 2 on Cally\n"
      "  report [--quick] [--out DIR] [--sections LIST]   every issue-7 benchmark; writes docs/BENCHMARKS.md\n"
      "  tradeoff [--quick] [--model NAME] [--samples LIST] [--modes LIST] [--padding LIST] [--held-out N]\n"
      "           [--json FILE] [--markdown FILE]   speed against accuracy: samples, pose spaces, padding,\n"
      "           held-out escapes and holes, fallback cost, fast vs watertight, exact vs cheap boxes\n"
      "  raytrace [--size WxH] [--frames N] [--threads LIST] [--models LIST] [--instances LIST]\n"
      "           [--shared DIR] [--triangle-test fast|watertight] [--bone-boxes exact|cheap]\n"
      "           [--json FILE]   ray tracer frame phases, and fuzzy vs exact kd-tree trace time\n"
      "Run `sinew-bench <benchmark> --help` for a benchmark's options.\n");
}

// The command as typed (arguments with spaces quoted), so a printed table
// says how to reproduce it.
std::string command_line(int argc, char** argv) {
  std::string line;
  for (int i = 0; i < argc; ++i) {
    const std::string arg = argv[i];
    if (!line.empty()) line += ' ';
    line += arg.find_first_of(" \t") == std::string::npos ? arg : "'" + arg + "'";
  }
  return line;
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
  if (what == "bake") return sinew::bench::run_bake_bench(args, command_line(argc, argv));
  if (what == "demo") return sinew::bench::run_demo_bench(args, command_line(argc, argv));
  if (what == "embree") return sinew::bench::run_embree_bench(args, command_line(argc, argv));
  if (what == "paper") return sinew::bench::run_paper_bench(args, command_line(argc, argv));
  if (what == "raytrace") return sinew::bench::run_raytrace_bench(args, command_line(argc, argv));
  if (what == "report") return sinew::bench::run_report_bench(args, command_line(argc, argv));
  if (what == "tradeoff") return sinew::bench::run_tradeoff_bench(args, command_line(argc, argv));
  if (what == "--help" || what == "-h" || what == "help") {
    usage();
    return 0;
  }
  std::fprintf(stderr, "sinew-bench: unknown benchmark '%s'\n", what.c_str());
  usage();
  return 2;
}
