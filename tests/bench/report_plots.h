// The report's plots: gnuplot (Debian's gnuplot-nox, pngcairo terminal)
// draws them from data files written next to the benchmarks' JSON, so the
// numbers in a picture are the numbers in the tables, and anyone can rerun
// the script (bench-data/plot_*.gp) or restyle it.
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <string>

namespace sinew::bench {

struct PlotInputs {
  // By the report's run key: "paper", "embree", "embree-large", "tradeoff",
  // "scaling-instances", "scaling-size-<side>". Absent keys skip their plot.
  std::map<std::string, const nlohmann::ordered_json*> json;
};

struct PlotResult {
  // Links to the PNGs, relative to the report ("img/bench_*.png"); empty
  // when that plot had no data or could not be drawn.
  std::string fps_vs_triangles;
  std::string embree;
  std::string tradeoff;
  std::string scaling;
  std::string note;     // why plots are missing, for the report
  bool failed = false;  // gnuplot ran and failed
};

// Writes PNGs into `image_dir` (linked as `link_dir`/name) and the data and
// scripts into `data_dir`.
PlotResult make_plots(const PlotInputs& inputs, const std::string& image_dir, const std::string& data_dir,
                      const std::string& link_dir);

}  // namespace sinew::bench
