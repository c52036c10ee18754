#include "tests/bench/report_plots.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "tests/bench/embree_bench.h"

namespace sinew::bench {
namespace {

using Json = nlohmann::ordered_json;

// Hole fractions of exactly zero cannot sit on a log axis; they are drawn
// here, and the axis label says so.
constexpr double kZeroHoles = 1e-6;

const char* kTerminal = "set terminal pngcairo noenhanced size 960,600 font 'sans,11'\n";

double number(const Json& j, const char* key) {
  if (!j.is_object() || !j.contains(key) || !j[key].is_number()) return std::nan("");
  return j[key].get<double>();
}

// gnuplot reads "NaN" as a missing point.
std::string value(double v) {
  if (!std::isfinite(v)) return "NaN";
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

double phase_ms(const Json& phases, const char* name) {
  if (!phases.is_object() || !phases.contains(name)) return std::nan("");
  return number(phases[name], "median_ms");
}

const Json* input(const PlotInputs& in, const std::string& key) {
  const auto it = in.json.find(key);
  return it == in.json.end() || !it->second || it->second->is_null() ? nullptr : it->second;
}

// Runs one script from the data folder (its paths are relative to it, so
// the scripts can be rerun anywhere); a missing or empty PNG counts as a
// failure. An empty log is removed.
bool draw(const std::string& data_dir, const std::string& script, const std::string& png_path, std::string& note) {
  const std::string log = script + ".log";
  const std::string command = "cd '" + data_dir + "' && gnuplot '" + script + "' > '" + log + "' 2>&1";
  const int rc = std::system(command.c_str());
  std::error_code ec;
  const std::string log_path = data_dir + "/" + log;
  if (rc != 0 || !std::filesystem::is_regular_file(png_path, ec) || std::filesystem::file_size(png_path, ec) == 0) {
    note += "gnuplot failed on " + data_dir + "/" + script + " (see " + log_path + "). ";
    return false;
  }
  if (std::filesystem::file_size(log_path, ec) == 0) std::filesystem::remove(log_path, ec);
  return true;
}

bool write_file(const std::string& path, const std::string& text, std::string& note) {
  std::ofstream out(path);
  out << text;
  out.close();
  if (!out) note += "cannot write " + path + ". ";
  return static_cast<bool>(out);
}

// --- fps against triangles, beside the paper (Table 2) ---------------------------

bool fps_vs_triangles_data(const Json& paper, std::string& data) {
  if (!paper.contains("table2")) return false;
  const Json& t2 = paper["table2"];
  bool any = false;
  for (const Json& row : t2.value("rows", Json::array())) {
    if (row.value("interpolated", false) || !row.contains("fps")) continue;
    const Json& fps = row["fps"];
    const auto at = [&](const char* threads, const char* kind) {
      return fps.contains(threads) ? number(fps[threads], kind) : std::nan("");
    };
    data += value(number(row, "triangles")) + " " + value(at("1", "primary")) + " " +
            value(at("1", "primary_shadows")) + " " + value(at("2", "primary")) + " " +
            value(at("2", "primary_shadows")) + "\n";
    any = true;
  }
  data += "\n\n";
  for (const Json& row : t2.value("paper", Json::array())) {
    data += value(number(row, "triangles")) + " " + value(number(row, "fps")) + "\n";
  }
  return any;
}

std::string fps_vs_triangles_script(const std::string& dat, const std::string& png) {
  return std::string(kTerminal) + "set output '" + png + "'\n" +
         "set title 'Cally at 1024x1024: Sinew and the paper (Table 2)'\n"
         "set logscale xy\nset grid\nset key outside below\n"
         "set xlabel 'triangles (iterative subdivision of Cally)'\nset ylabel 'frames per second'\n"
         "plot '" + dat + "' index 0 using 1:2 with linespoints lw 2 pt 7 title 'Sinew, 1 thread, primary rays', \\\n"
         "     '' index 0 using 1:3 with linespoints lw 2 pt 5 title 'Sinew, 1 thread, primary + shadow rays', \\\n"
         "     '' index 0 using 1:4 with linespoints lw 2 pt 9 title 'Sinew, 2 threads, primary rays', \\\n"
         "     '' index 0 using 1:5 with linespoints lw 2 pt 11 title 'Sinew, 2 threads, primary + shadow rays', \\\n"
         "     '' index 1 using 1:2 with linespoints lw 2 dt 2 pt 6 lc rgb 'black' "
         "title 'paper: one 2.4 GHz Opteron core, primary rays'\n";
}

// --- Sinew against Embree: frame time per contender --------------------------------

std::string short_name(const std::string& name) {
  if (name == kSinewContender) return "Sinew";
  if (name == "exact SAH kd rebuild") return "exact kd";
  // "embree refit rtcIntersect16" -> "Embree refit x16" (the widths' rows).
  static const std::pair<const char*, const char*> kModes[] = {
      {"embree LOW rebuild", "Embree LOW"}, {"embree refit", "Embree refit"}, {"embree MEDIUM rebuild", "Embree MEDIUM"}};
  for (const auto& [long_name, short_label] : kModes) {
    const std::string prefix = long_name;
    if (name.rfind(prefix, 0) != 0) continue;
    const std::string rest = name.substr(prefix.size());
    const std::size_t digits = rest.find_first_of("0123456789");
    return std::string(short_label) + (digits == std::string::npos ? "" : " x" + rest.substr(digits));
  }
  return name;
}

// Whether a contender is drawn: Sinew, the exact kd-tree, and each Embree
// mode at its best width (every width of every mode would be 14 bars a
// group); runs from before the widths draw every row.
bool drawn(const Json& config, const Json& contender) {
  const std::string name = contender.value("name", "");
  if (!config.contains("best_embree_by_mode") || name.rfind("embree", 0) != 0) return true;
  for (const Json& best : config["best_embree_by_mode"]) {
    if (best.value("name", "") == name) return true;
  }
  return false;
}

// One data block per configuration; returns the blocks' titles.
std::vector<std::string> embree_data(const Json& doc, std::string& data) {
  std::vector<std::string> titles;
  for (const Json& config : doc.value("configurations", Json::array())) {
    const double skinning = phase_ms(config["shared"], "skinning");
    std::string block;
    for (const Json& c : config.value("contenders", Json::array())) {
      if (!c.contains("phases") || !drawn(config, c)) continue;  // failed its brute-force check, or not a best width
      const Json& p = c["phases"];
      block += "\"" + short_name(c.value("name", "?")) + "\" " + value(skinning) + " " + value(phase_ms(p, "build")) +
               " " + value(phase_ms(p, "trace primary")) + " " + value(phase_ms(p, "trace shadow")) + " " +
               value(phase_ms(p, "shade")) + "\n";
    }
    if (block.empty()) continue;
    data += block + "\n\n";
    const int threads = config.value("threads", 0);
    // Two lines (gnuplot's "\n" in a double-quoted string): one line per
    // group overlapped its neighbours under four groups of five bars.
    titles.push_back(config.value("clip", "?") + "\\n" + std::to_string(threads) + (threads == 1 ? " thread" : " threads"));
  }
  return titles;
}

std::string embree_panel(const std::string& dat, const std::vector<std::string>& titles, const std::string& title) {
  std::string s = "set title '" + title + "'\nplot ";
  for (std::size_t i = 0; i < titles.size(); ++i) {
    const std::string index = " index " + std::to_string(i);
    const bool first = i == 0;
    s += std::string(first ? "" : ", \\\n     ") + "newhistogram \"" + titles[i] + "\" lt 1, '" + dat + "'" + index +
         " using 2:xtic(1) " + (first ? "title 'skinning'" : "notitle") + ", '' " + index + " using 3 " +
         (first ? "title 'build / refit'" : "notitle") + ", '' " + index + " using 4 " +
         (first ? "title 'primary rays'" : "notitle") + ", '' " + index + " using 5 " +
         (first ? "title 'shadow rays'" : "notitle") + ", '' " + index + " using 6 " +
         (first ? "title 'shading'" : "notitle");
  }
  return s + "\n";
}

// --- the speed/accuracy trade -------------------------------------------------------

// Per mode two blocks: every sample count at padding 0 (holes, work per
// ray, samples, fps), and the mode's Pareto front among them (no other point
// of the mode has fewer holes and no more work, or less work and no more
// holes), sorted by holes.
std::vector<std::string> tradeoff_data(const Json& doc, std::string& data) {
  std::vector<std::string> modes;
  for (const Json& row : doc.value("sweep", Json::array())) {
    const std::string mode = row.value("mode", "?");
    if (std::find(modes.begin(), modes.end(), mode) == modes.end()) modes.push_back(mode);
  }
  struct TradePoint {
    double holes, work, samples, fps;
  };
  std::vector<std::string> drawn;
  for (const std::string& mode : modes) {
    std::vector<TradePoint> points;
    for (const Json& row : doc["sweep"]) {
      if (row.value("mode", "") != mode || number(row, "padding") != 0.0) continue;
      const TradePoint p{std::max(number(row, "hole_fraction"), kZeroHoles), number(row, "work_per_ray"),
                         number(row, "samples"), number(row, "fps")};
      if (std::isfinite(p.holes) && std::isfinite(p.work) && std::isfinite(p.fps)) points.push_back(p);
    }
    if (points.empty()) continue;
    std::vector<TradePoint> front;
    for (const TradePoint& p : points) {
      const bool dominated = std::any_of(points.begin(), points.end(), [&](const TradePoint& q) {
        return q.holes <= p.holes && q.work <= p.work && (q.holes < p.holes || q.work < p.work);
      });
      if (!dominated) front.push_back(p);
    }
    std::sort(front.begin(), front.end(), [](const TradePoint& a, const TradePoint& b) { return a.holes < b.holes; });
    for (const std::vector<TradePoint>* block : {&points, &front}) {
      for (const TradePoint& p : *block) {
        data += value(p.holes) + " " + value(p.work) + " " + value(p.samples) + " " + value(p.fps) + "\n";
      }
      data += "\n\n";
    }
    drawn.push_back(mode);
  }
  return drawn;
}

// The clusters' study: per K its pack size in MB, work per ray, K and fps.
bool cluster_data(const Json& doc, std::string& data, std::string& title) {
  bool any = false;
  for (const Json& row : doc.value("clusters", Json::array())) {
    const double mb = number(row, "pack_bytes") / 1e6;
    const double work = number(row, "work_per_ray");
    if (!std::isfinite(mb) || !std::isfinite(work)) continue;
    data += value(mb) + " " + value(work) + " " + value(number(row, "clusters_per_bone")) + " " +
            value(number(row, "fps")) + "\n";
    any = true;
  }
  char text[160];
  std::snprintf(text, sizeof text, "Pose-space clusters, Cally at %.0f triangles: each point a K, labelled K / fps",
                number(doc, "cluster_triangles"));
  title = text;
  return any;
}

// `cluster_dat` empty: the sweep alone; else a second panel for the
// clusters' study.
std::string tradeoff_script(const std::string& dat, const std::string& png, const std::vector<std::string>& modes,
                            const std::string& cluster_dat = {}, const std::string& cluster_title = {}) {
  std::string s = std::string(cluster_dat.empty() ? kTerminal : "set terminal pngcairo noenhanced size 1600,640 font 'sans,11'\n") +
                  "set output '" + png + "'\n" + (cluster_dat.empty() ? "" : "set multiplot layout 1,2\n") +
                  "set title \"Work against accuracy (padding 0): each point a sample count, labelled samples / fps;\\n"
                  "rings and lines: each mode's Pareto front\"\n"
                  "set logscale x\nset grid\nset key outside below\n"
                  "set xlabel 'fraction of pixels whose hit differs from brute force, fallback off (0 drawn at 1e-6)'\n"
                  "set ylabel 'triangle tests + kd-tree node visits per ray (deterministic)'\nplot ";
  for (std::size_t i = 0; i < modes.size(); ++i) {
    const std::string points = " index " + std::to_string(2 * i);
    const std::string front = " index " + std::to_string(2 * i + 1);
    s += std::string(i == 0 ? "" : ", \\\n     ") + "'" + dat + "'" + front + " using 1:2 with linespoints lw 2 pt 6 ps 2 lc " +
         std::to_string(i + 1) + " title '" + modes[i] + "', ''" + points + " using 1:2 with points pt 7 lc " +
         std::to_string(i + 1) + " notitle, ''" + points +
         " using 1:2:(sprintf('%d / %.0f', $3, $4)) with labels offset char 0.8,0.6 font ',7' notitle";
  }
  s += "\n";
  if (cluster_dat.empty()) return s;
  s += "unset logscale\nset title '" + cluster_title + "'\nset key off\n"
       "set xlabel 'character pack size, MB'\n"
       "set ylabel 'triangle tests + kd-tree node visits per ray (deterministic)'\n"
       "plot '" + cluster_dat + "' using 1:2 with linespoints lw 2 pt 7 lc 1, '' using 1:2:(sprintf('%d / %.0f', $3, $4)) "
       "with labels offset char 0.8,0.6 font ',8'\nunset multiplot\n";
  return s;
}

// --- scaling ------------------------------------------------------------------------

struct Point {
  double x;
  double fps;
};

// Points by thread count, from the raytrace benchmark's runs.
void scaling_points(const Json& doc, bool by_instances, std::map<int, std::vector<Point>>& out) {
  if (!doc.contains("models") || doc["models"].empty()) return;
  const double pixels = doc.contains("size") ? doc["size"][0].get<double>() * doc["size"][1].get<double>() : 0.0;
  for (const Json& run : doc["models"][0].value("runs", Json::array())) {
    const double x = by_instances ? number(run, "instances") : pixels / 1e6;
    out[run.value("threads", 0)].push_back({x, number(run, "fps")});
  }
}

std::vector<int> scaling_data(const std::map<int, std::vector<Point>>& points, std::string& data) {
  std::vector<int> threads;
  for (const auto& [t, list] : points) {
    std::vector<Point> sorted = list;
    std::sort(sorted.begin(), sorted.end(), [](const Point& a, const Point& b) { return a.x < b.x; });
    for (const Point& p : sorted) data += value(p.x) + " " + value(p.fps) + "\n";
    data += "\n\n";
    threads.push_back(t);
  }
  return threads;
}

std::string scaling_panel(const std::string& dat, const std::vector<int>& threads, const std::string& xlabel,
                          const std::string& title) {
  std::string s = "set title '" + title + "'\nset xlabel '" + xlabel + "'\nplot ";
  for (std::size_t i = 0; i < threads.size(); ++i) {
    s += std::string(i == 0 ? "" : ", ") + "'" + dat + "' index " + std::to_string(i) +
         " using 1:2 with linespoints lw 2 pt 7 title '" + std::to_string(threads[i]) +
         (threads[i] == 1 ? " thread'" : " threads'");
  }
  return s + "\n";
}

}  // namespace

PlotResult make_plots(const PlotInputs& inputs, const std::string& image_dir, const std::string& data_dir,
                      const std::string& link_dir) {
  PlotResult result;
  if (std::system("command -v gnuplot > /dev/null 2>&1") != 0) {
    result.note = "Plots skipped: gnuplot was not found (Debian: gnuplot-nox; `./sinew deps` installs it).";
    return result;
  }
  // The scripts name their data and images relative to the data folder.
  std::error_code ec;
  const std::string images_from_data = std::filesystem::relative(image_dir, data_dir, ec).string();
  const auto paths = [&](const std::string& name) {
    return std::array<std::string, 4>{"plot_" + name + ".dat", "plot_" + name + ".gp",
                                      (ec ? image_dir : images_from_data) + "/bench_" + name + ".png",
                                      link_dir + "/bench_" + name + ".png"};
  };
  const auto in_data = [&](const std::string& file) { return data_dir + "/" + file; };
  const auto render = [&](const std::string& name, const std::string& data, const std::string& script,
                          std::string& link) {
    const auto [dat, gp, png, href] = paths(name);
    if (!write_file(in_data(dat), data, result.note) || !write_file(in_data(gp), script, result.note)) {
      result.failed = true;
      return;
    }
    if (draw(data_dir, gp, image_dir + "/bench_" + name + ".png", result.note)) {
      link = href;
    } else {
      result.failed = true;
    }
  };

  if (const Json* paper = input(inputs, "paper")) {
    std::string data;
    if (fps_vs_triangles_data(*paper, data)) {
      const auto [dat, gp, png, href] = paths("fps_vs_triangles");
      render("fps_vs_triangles", data, fps_vs_triangles_script(dat, png), result.fps_vs_triangles);
    }
  }

  {
    const Json* small = input(inputs, "embree");
    const Json* large = input(inputs, "embree-large");
    std::string small_data, large_data;
    const std::vector<std::string> small_titles = small ? embree_data(*small, small_data) : std::vector<std::string>{};
    const std::vector<std::string> large_titles = large ? embree_data(*large, large_data) : std::vector<std::string>{};
    if (!small_titles.empty() || !large_titles.empty()) {
      const auto [dat, gp, png, href] = paths("embree");
      const std::string large_dat = "plot_embree_large.dat";
      std::string script = std::string("set terminal pngcairo noenhanced size 1280,600 font 'sans,11'\nset output '") + png +
                           "'\nset style data histograms\nset style histogram rowstacked\n"
                           "set style fill solid 0.85 border -1\nset boxwidth 0.8\nset grid ytics\n"
                           "set ylabel 'ms per frame (median)'\nset xtics rotate by -40 scale 0 font ',9'\n"
                           "set key top left\nset bmargin 9\n";  // room for the two-line group titles
      const int panels = (small_titles.empty() ? 0 : 1) + (large_titles.empty() ? 0 : 1);
      script += "set multiplot layout 1," + std::to_string(panels) + "\n";
      const auto triangles = [](const Json* doc) {
        char text[64];
        std::snprintf(text, sizeof text, "%.0f", doc ? number(*doc, "triangles") : 0.0);
        return std::string(text);
      };
      if (!small_titles.empty()) script += embree_panel(dat, small_titles, "Cally, " + triangles(small) + " triangles");
      if (!large_titles.empty()) {
        script += embree_panel(large_dat, large_titles, "Cally subdivided, " + triangles(large) + " triangles");
      }
      script += "unset multiplot\n";
      if (!large_titles.empty() && !write_file(in_data(large_dat), large_data, result.note)) result.failed = true;
      render("embree", small_data, script, result.embree);
    }
  }

  if (const Json* trade = input(inputs, "tradeoff")) {
    std::string data;
    const std::vector<std::string> modes = tradeoff_data(*trade, data);
    std::string clusters, cluster_title;
    const bool with_clusters = cluster_data(*trade, clusters, cluster_title);
    if (!modes.empty()) {
      const auto [dat, gp, png, href] = paths("tradeoff");
      const std::string cluster_dat = with_clusters ? "plot_tradeoff_clusters.dat" : "";
      if (with_clusters && !write_file(in_data(cluster_dat), clusters, result.note)) result.failed = true;
      render("tradeoff", data, tradeoff_script(dat, png, modes, cluster_dat, cluster_title), result.tradeoff);
    }
  }

  {
    std::map<int, std::vector<Point>> by_instances, by_pixels;
    for (const auto& [key, doc] : inputs.json) {
      if (!doc || doc->is_null()) continue;
      if (key == "scaling-instances") scaling_points(*doc, true, by_instances);
      if (key.rfind("scaling-size-", 0) == 0) scaling_points(*doc, false, by_pixels);
    }
    std::string instance_data, pixel_data;
    const std::vector<int> instance_threads = scaling_data(by_instances, instance_data);
    const std::vector<int> pixel_threads = scaling_data(by_pixels, pixel_data);
    if (!instance_threads.empty() || !pixel_threads.empty()) {
      const auto [dat, gp, png, href] = paths("scaling");
      const std::string pixel_dat = "plot_scaling_pixels.dat";
      const int panels = (instance_threads.empty() ? 0 : 1) + (pixel_threads.empty() ? 0 : 1);
      std::string script = std::string("set terminal pngcairo noenhanced size 1200,520 font 'sans,11'\nset output '") + png +
                           "'\nset logscale xy\nset grid\nset key top right\nset ylabel 'frames per second'\n"
                           "set multiplot layout 1," +
                           std::to_string(panels) + "\n";
      if (!instance_threads.empty()) {
        script += scaling_panel(dat, instance_threads, "Cally instances", "fps against instances");
      }
      if (!pixel_threads.empty()) {
        script += scaling_panel(pixel_dat, pixel_threads, "megapixels", "fps against image size (one Cally)");
        if (!write_file(in_data(pixel_dat), pixel_data, result.note)) result.failed = true;
      }
      script += "unset multiplot\n";
      render("scaling", instance_data, script, result.scaling);
    }
  }
  return result;
}

}  // namespace sinew::bench
