// sinew-bench: Sinew's benchmark programs. They print tables; nothing here
// is asserted (tests never time anything).
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "runtime/cli/command_line.h"
#include "runtime/cpu/cpu_features.h"
#include "tests/bench/animation_bench.h"
#include "tests/bench/bake_bench.h"
#include "tests/bench/demo_bench.h"
#include "tests/bench/embree_bench.h"
#include "tests/bench/memory_bench.h"
#include "tests/bench/paper_bench.h"
#include "tests/bench/query_bench.h"
#include "tests/bench/raytrace_bench.h"
#include "tests/bench/report_bench.h"
#include "tests/bench/structures_bench.h"
#include "tests/bench/tradeoff_bench.h"

namespace {

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
  sinew::cli::CommandLine line("sinew-bench", "Sinew's benchmark programs: they print tables (nothing here is asserted).\n");
  line.command("animation", "animation + skinning vs the Cal3D library");
  line.command("bake", "fuzzy bake cost per candidate-bone mode, its trace effect, and its memory bound");
  line.command("demo", "the game demo's fps and phases");
  line.command("embree", "Sinew vs Embree 3 (rebuild LOW/MEDIUM, refit) vs exact kd");
  line.command("memory", "resident memory per added character instance against its skinned vertices");
  line.command("paper", "the paper's Tables 1 and 2 on Cally");
  line.command("queries", "gameplay queries in a crowd: World::intersect against Embree refit and rebuild");
  line.command("raytrace", "ray tracer frame phases, and fuzzy vs exact kd-tree trace time");
  line.command("report", "every benchmark section; writes docs/BENCHMARKS.md");
  line.command("structures", "the paper's one tree a bone against pose-space clusters, per model and mesh size");
  line.command("tradeoff",
               "speed against accuracy: samples, pose spaces, padding, held-out escapes and holes,\n"
               "fallback cost, fast vs watertight, exact vs cheap boxes");
  line.footer("Run `sinew-bench BENCHMARK --help` for a benchmark's options. --threads N means worker\n"
              "threads everywhere, 0 = all cores.\n");
  if (const auto done = sinew::cli::help_or_usage_error(line, line.parse({argv + 1, argv + argc}), std::cout,
                                                       std::cerr)) {
    return *done;
  }
  const std::string& what = line.chosen_command();
  if (what.empty()) {
    return sinew::cli::usage_error("sinew-bench", sinew::invalid_argument("BENCHMARK", "", "missing (see --help)"),
                                   std::cerr);
  }
  if (sinew::Status s = sinew::check_cpu_supports_build(); !s.ok()) {
    std::fprintf(stderr, "sinew-bench: %s\n", s.message().c_str());
    return 1;
  }
  const std::vector<std::string>& args = line.command_arguments();
  if (what == "animation") return sinew::bench::run_animation_bench(args);
  if (what == "bake") return sinew::bench::run_bake_bench(args, command_line(argc, argv));
  if (what == "demo") return sinew::bench::run_demo_bench(args, command_line(argc, argv));
  if (what == "embree") return sinew::bench::run_embree_bench(args, command_line(argc, argv));
  if (what == "memory") return sinew::bench::run_memory_bench(args, command_line(argc, argv));
  if (what == "paper") return sinew::bench::run_paper_bench(args, command_line(argc, argv));
  if (what == "queries") return sinew::bench::run_query_bench(args, command_line(argc, argv));
  if (what == "raytrace") return sinew::bench::run_raytrace_bench(args, command_line(argc, argv));
  if (what == "report") return sinew::bench::run_report_bench(args, command_line(argc, argv));
  if (what == "structures") return sinew::bench::run_structures_bench(args, command_line(argc, argv));
  return sinew::bench::run_tradeoff_bench(args, command_line(argc, argv));
}
