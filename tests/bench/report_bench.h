// sinew-bench report: one command that measures everything docs/BENCHMARKS.md reports
// for and writes it down. It runs, in one process and one after another,
// the paper tables (`paper`), the peer comparison (`embree`, on Cally and
// on Cally's largest subdivision), the speed/accuracy trade (`tradeoff`) and
// the scaling runs (`raytrace` over instance counts and image sizes), each
// writing JSON into a work folder; then it writes BENCHMARKS.md (tables,
// machine, date, commit, the exact commands) and PNG plots made by gnuplot.
//
// Full mode writes docs/BENCHMARKS.md and docs/img/bench_*.png of the source
// tree; --quick (under 5 minutes on 2 cores: smaller images, fewer frames,
// levels and samples) writes into build/report-quick/ unless --out says
// otherwise, so a smoke run never overwrites the measured report.
#pragma once

#include <string>
#include <vector>

namespace sinew::bench {

// `args` are the arguments after "report". Returns 0, 1 (a benchmark failed
// or refused a configuration, or a file could not be written) or 2 (usage).
int run_report_bench(const std::vector<std::string>& args, const std::string& command_line);

}  // namespace sinew::bench
