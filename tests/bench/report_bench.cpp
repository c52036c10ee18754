#include "tests/bench/report_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "runtime/cli/option_values.h"
#include "runtime/cpu/cpu_features.h"
#include "runtime/jobs/job_system.h"
#include "tests/bench/bench_options.h"
#include "tests/bench/bench_support.h"
#include "tests/bench/demo_bench.h"
#include "tests/bench/embree_bench.h"
#include "tests/bench/paper_bench.h"
#include "tests/bench/readme_headline.h"
#include "tests/bench/raytrace_bench.h"
#include "tests/bench/report_plots.h"
#include "tests/bench/structures_bench.h"
#include "tests/bench/tradeoff_bench.h"

namespace sinew::bench {
namespace {

using Json = nlohmann::ordered_json;
namespace fs = std::filesystem;

// --- options -------------------------------------------------------------------

const std::vector<std::string> kAllSections = {"paper", "embree", "structures", "demo", "tradeoff", "scaling"};

struct Options {
  bool quick = false;
  bool help = false;
  std::string out_dir;  // empty: docs/ (full) or build/report-quick/ (quick)
  std::vector<std::string> sections = kAllSections;
  std::string shared = SINEW_SHARED_DIR;
};

std::vector<BenchFlag> bench_flags() {
  return {
      {"--quick", "", "a smoke run under 5 minutes on 2 cores (default --out build/report-quick)"},
      {"--out", "DIR", "where BENCHMARKS.md, img/ and bench-data/ go (default: the source tree's docs/)"},
      {"--sections", "LIST",
       "paper,embree,structures,demo,tradeoff,scaling (default all); the other sections\n"
       "are kept from the last report written to the same --out"},
      shared_flag(),
  };
}

const char* const kDescription = "every benchmark section; writes docs/BENCHMARKS.md\n";

Status read_options(const BenchArgs& parsed, Options& o) {
  namespace cli = sinew::cli;
  o.quick = parsed.has("--quick");
  SINEW_RETURN_IF_ERROR(parsed.read("--out", o.out_dir));
  SINEW_RETURN_IF_ERROR(parsed.read("--shared", o.shared));
  if (const auto text = parsed.value("--sections")) {
    SINEW_ASSIGN_OR_RETURN(o.sections, cli::parse_list("--sections", *text));
    for (const std::string& s : o.sections) {
      if (std::find(kAllSections.begin(), kAllSections.end(), s) == kAllSections.end()) {
        return invalid_argument("--sections", s, "unknown section (expected paper, embree, structures, demo, tradeoff or scaling)");
      }
    }
  }
  if (o.out_dir.empty()) {
    o.out_dir = o.quick ? std::string(SINEW_SOURCE_DIR) + "/build/report-quick" : std::string(SINEW_SOURCE_DIR) + "/docs";
  }
  return {};
}

bool wanted(const Options& o, const std::string& section) {
  return std::find(o.sections.begin(), o.sections.end(), section) != o.sections.end();
}

// --- running the benchmarks ------------------------------------------------------

using BenchFunction = std::function<int(const std::vector<std::string>&, const std::string&)>;

// One benchmark invocation: what ran, how it ended, where its JSON is.
struct Run {
  std::string key;      // names the JSON (and Markdown) files
  std::string command;  // as a user would type it from the source tree
  std::string json_path;
  std::string markdown_path;  // empty when the benchmark writes none
  int exit_code = 0;
  double seconds = 0.0;
  std::string date;    // when it started
  std::string commit;  // what it measured
  bool kept = false;   // taken from an earlier report (its section was not rerun)
  Json json;           // null when the file is missing or unreadable
};

// The report section a run belongs to (what --sections names).
std::string section_of(const std::string& key) {
  if (key.rfind("embree", 0) == 0) return "embree";
  if (key.rfind("scaling", 0) == 0) return "scaling";
  return key;
}

std::string join_args(const std::vector<std::string>& args) {
  std::string out;
  for (const std::string& a : args) out += (out.empty() ? "" : " ") + a;
  return out;
}

Json read_json(const std::string& path) {
  std::ifstream in(path);
  if (!in) return Json();
  Json doc = Json::parse(in, nullptr, false);
  return doc.is_discarded() ? Json() : doc;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

Run run_bench(const std::string& bench, const std::string& key, std::vector<std::string> args, bool markdown,
              const std::string& data_dir, const BenchFunction& fn) {
  Run r;
  r.key = key;
  r.json_path = data_dir + "/" + key + ".json";
  // The command as printed leaves out where the report keeps its files.
  r.command = "build/release/tests/bench/sinew-bench " + bench + (args.empty() ? "" : " " + join_args(args));
  args.push_back("--json");
  args.push_back(r.json_path);
  if (markdown) {
    r.markdown_path = data_dir + "/" + key + ".md";
    args.push_back("--markdown");
    args.push_back(r.markdown_path);
  }
  r.date = utc_date();
  r.commit = git_commit();
  std::fprintf(stderr, "sinew-bench report: running %s\n", r.command.c_str());
  std::fflush(stdout);
  const auto start = std::chrono::steady_clock::now();
  r.exit_code = fn(args, "sinew-bench " + bench + " " + join_args(args));
  std::fflush(stdout);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.json = read_json(r.json_path);
  std::fprintf(stderr, "sinew-bench report: %s finished in %.0f s (exit code %d)\n", key.c_str(), r.seconds,
               r.exit_code);
  return r;
}

// --- Markdown helpers ------------------------------------------------------------

// A benchmark's own Markdown section, its commands' paths made relative to
// the source tree (the report's readers do not share this machine's paths).
std::string pasted_markdown(const Run& r) {
  std::string text = read_text(r.markdown_path);
  const std::string root = std::string(SINEW_SOURCE_DIR) + "/";
  for (std::size_t at = text.find(root); at != std::string::npos; at = text.find(root, at)) text.erase(at, root.size());
  return text;
}

std::string format(const char* pattern, ...) __attribute__((format(printf, 1, 2)));
std::string format(const char* pattern, ...) {
  char text[512];
  va_list list;
  va_start(list, pattern);
  std::vsnprintf(text, sizeof text, pattern, list);
  va_end(list);
  return text;
}

double number(const Json& j, const char* key, double fallback = std::nan("")) {
  if (!j.is_object() || !j.contains(key) || !j[key].is_number()) return fallback;
  return j[key].get<double>();
}

// The median of a phase in a PhaseTimers JSON object, NaN when absent.
double phase_ms(const Json& phases, const char* name) {
  if (!phases.is_object() || !phases.contains(name)) return std::nan("");
  return number(phases[name], "median_ms");
}

// A number with `decimals` digits after the point, "–" when missing.
std::string cell(double v, int decimals = 2) {
  return std::isfinite(v) ? format("%.*f", decimals, v) : std::string("–");
}

// Two significant digits, for fractions that span decades.
std::string cell_g(double v) {
  return std::isfinite(v) ? format("%.2g", v) : std::string("–");
}

std::string ratio_cell(double a, double b) {
  return std::isfinite(a) && std::isfinite(b) && b > 0.0 ? format("%.2f", a / b) : std::string("–");
}

std::string thousands(double v) {
  if (!std::isfinite(v)) return "–";
  std::string digits = std::to_string(static_cast<long long>(std::llround(v)));
  for (int i = static_cast<int>(digits.size()) - 3; i > 0; i -= 3) digits.insert(static_cast<std::size_t>(i), ",");
  return digits;
}

std::string failure_line(const Run& r) {
  return r.exit_code == 0 ? std::string()
                          : format("\n**This benchmark ended with exit code %d**: a model failed to load, a "
                                   "configuration failed its brute-force check (and is left out), or a file could "
                                   "not be written; its log is the report's standard output.\n",
                                   r.exit_code);
}

// --- the peer comparison (Embree) ------------------------------------------------

const Json* contender(const Json& config, const std::string& name) {
  if (!config.contains("contenders")) return nullptr;
  for (const Json& c : config["contenders"]) {
    if (c.value("name", "") == name) return &c;
  }
  return nullptr;
}

// Whether the run measured every Embree (mode, width) pair and named each
// mode's best width (sinew-bench embree since its --embree-widths); earlier
// runs have one Embree row per mode, at a width they did not record.
bool has_embree_widths(const Json& config) { return config.contains("best_embree_by_mode"); }

// The rows the report's table shows: Sinew, each Embree mode at its best
// width, the exact kd-tree, and every row that failed its brute-force
// check. Earlier runs: all their rows.
std::vector<const Json*> embree_table_rows(const Json& config) {
  std::vector<const Json*> rows;
  if (!config.contains("contenders")) return rows;
  const bool widths = has_embree_widths(config);
  for (const Json& c : config["contenders"]) {
    const bool failed = !c["brute_force"].value("passed", false);
    const bool embree = c.value("kind", "") == "embree";
    if (!widths || !embree || failed) {
      rows.push_back(&c);
      continue;
    }
    for (const Json& best : config["best_embree_by_mode"]) {
      if (best.value("name", "") == c.value("name", "")) rows.push_back(&c);
    }
  }
  return rows;
}

// "LOW rebuild: rtcIntersect1 237.7, rtcIntersect4 201.3; refit: ...": every
// width's median total, mode by mode as the run listed them.
std::string embree_widths_line(const Json& config) {
  std::string line, mode;
  if (!config.contains("contenders")) return line;
  for (const Json& c : config["contenders"]) {
    if (c.value("kind", "") != "embree") continue;
    const std::string total = c.contains("phases") ? cell(phase_ms(c["phases"], "total"), 1) : std::string("FAILED");
    if (c.value("mode_name", "") != mode) {
      mode = c.value("mode_name", "?");
      line += (line.empty() ? "" : "; ") + mode + ":";
    } else {
      line += ",";
    }
    line += " " + c.value("width_name", "?") + " " + total;
  }
  return line;
}

// Sinew against the run's fastest Embree row, as sinew-bench embree prints it.
std::string embree_best_line(const Json& config) {
  const Json& best = config["best_embree"];
  if (!best.is_object()) return "No Embree row passed its brute-force check.\n";
  std::string md = format("Best Embree: **%s**, total %s ms (%s fps), trace %s ms", best.value("label", "?").c_str(),
                          cell(number(best, "total_ms"), 1).c_str(), cell(number(best, "fps")).c_str(),
                          cell(number(best, "trace_ms"), 1).c_str());
  if (!best.contains("sinew_total_ms")) return md + "; Sinew failed its brute-force check.\n";
  return md + format("; Sinew total %s ms (%s fps), trace %s ms; Sinew ÷ best: total %s, trace %s.\n",
                     cell(number(best, "sinew_total_ms"), 1).c_str(), cell(number(best, "sinew_fps")).c_str(),
                     cell(number(best, "sinew_trace_ms"), 1).c_str(),
                     cell(number(best, "sinew_over_best_total")).c_str(),
                     cell(number(best, "sinew_over_best_trace")).c_str());
}

std::string embree_markdown(const Run& r) {
  std::string md;
  const Json& doc = r.json;
  md += format("\nModel %s (%s triangles, %d subdivision levels), %s instance, %d×%d, %d frames per clip at "
               "30 fps.\n\n",
               doc.value("model", "?").c_str(), thousands(number(doc, "triangles")).c_str(),
               doc.value("subdivide", 0), thousands(number(doc, "instances")).c_str(),
               doc.contains("size") ? doc["size"][0].get<int>() : 0, doc.contains("size") ? doc["size"][1].get<int>() : 0,
               doc.value("frames", 0));
  if (doc.value("pose_clusters", 0u) > 0) {
    md += format("Sinew's bone trees: up to %u pose-space clusters a bone, %u in all (the default from 25,000 "
                 "triangles; RAYTRACE.md, \"Pose-space clusters\").\n\n",
                 doc.value("clusters_per_bone", 0u), doc.value("pose_clusters", 0u));
  }
  md += "```sh\n" + r.command + "\n```\n";
  if (!doc.value("embree", false)) md += "\nEmbree was not found when this was built: only Sinew and the exact kd-tree ran.\n";
  bool widths = false;
  for (const Json& config : doc.value("configurations", Json::array())) {
    widths = widths || has_embree_widths(config);
    const Json& shared = config["shared"];
    md += format("\n%s, %d thread%s (shared per frame: animation %s ms, skinning %s ms):\n\n",
                 config.value("clip", "?").c_str(), config.value("threads", 0), config.value("threads", 0) == 1 ? "" : "s",
                 cell(phase_ms(shared, "animation"), 3).c_str(), cell(phase_ms(shared, "skinning"), 3).c_str());
    md += "| contender | build ms | primary ms | shadow ms | trace ms | shade ms | total ms | Sinew ÷ this: build | "
          "trace | total | brute force (first frame) |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n";
    const Json* sinew = contender(config, kSinewContender);
    const Json sinew_phases = sinew && sinew->contains("phases") ? (*sinew)["phases"] : Json();
    for (const Json* row : embree_table_rows(config)) {
      const Json& c = *row;
      const Json& gate = c["brute_force"];
      if (!gate.value("passed", false)) {
        md += format("| %s | FAILED brute-force check: %s of %s sampled pixels differ; not reported | | | | | | | | | "
                     "FAILED |\n",
                     c.value("name", "?").c_str(), thousands(number(gate, "mismatched")).c_str(),
                     thousands(number(gate, "checked")).c_str());
        continue;
      }
      const Json& p = c["phases"];
      const std::string name = c.value("name", "?") + (c.value("best_embree", false) ? " (best Embree)" : "");
      md += format("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s px, %s grazes |\n", name.c_str(),
                   cell(phase_ms(p, "build"), 3).c_str(), cell(phase_ms(p, "trace primary"), 1).c_str(),
                   cell(phase_ms(p, "trace shadow"), 1).c_str(), cell(phase_ms(p, "trace"), 1).c_str(),
                   cell(phase_ms(p, "shade"), 1).c_str(), cell(phase_ms(p, "total"), 1).c_str(),
                   ratio_cell(phase_ms(sinew_phases, "build"), phase_ms(p, "build")).c_str(),
                   ratio_cell(phase_ms(sinew_phases, "trace"), phase_ms(p, "trace")).c_str(),
                   ratio_cell(phase_ms(sinew_phases, "total"), phase_ms(p, "total")).c_str(),
                   thousands(number(gate, "checked")).c_str(), thousands(number(gate, "edge_grazes")).c_str());
    }
    if (has_embree_widths(config) && doc.value("embree", false)) {
      md += "\nEmbree total ms at each width: " + embree_widths_line(config) + ".\n\n" + embree_best_line(config);
    }
  }
  md += "\n*build*: Sinew = bone boxes + fallback + top level; Embree = vertex upload + `rtcCommitScene`; exact = "
        "merge + SAH kd build + top level. *trace* = primary + shadow rays; *total* = skinning (shared) + build + "
        "trace + shade; medians over the frames. Ratios below 1: Sinew is faster. Sinew traces " +
        packet_words() + " that walk each tree once, after a tile cull of the top level; tiles that reach only a "
        "few static triangles test them directly. ";
  md += widths ? "Embree ran every mode at every width — single rays (`rtcIntersect1`/`rtcOccluded1`) and 4-, 8- "
                 "and 16-wide packets (`rtcIntersectN`/`rtcOccludedN` with `RTC_INTERSECT_CONTEXT_FLAG_COHERENT`); "
                 "each mode is shown at its fastest width, named in its row, and the fastest row of all is marked "
                 "*best Embree*. "
               : "Embree's ray width was not recorded by this run (one row per mode). ";
  md += "Camera, shading and threads are shared code.\n";
  return md + failure_line(r);
}

// --- scaling -----------------------------------------------------------------------

const Json* first_model(const Run& r) {
  if (!r.json.contains("models") || r.json["models"].empty()) return nullptr;
  return &r.json["models"][0];
}

std::string scaling_instances_markdown(const Run& r) {
  std::string md = "\n```sh\n" + r.command + "\n```\n\n";
  const Json* model = first_model(r);
  if (!model) return md + "No results (see the log).\n" + failure_line(r);
  md += format("%s: %s triangles per instance, %s bones; %d×%d, walk clip, shadows on.\n\n",
               model->value("name", "?").c_str(), thousands(number(*model, "triangles")).c_str(),
               thousands(number(*model, "bones")).c_str(), r.json["size"][0].get<int>(), r.json["size"][1].get<int>());
  md += "| instances | triangles | threads | per-frame work ms (skin + boxes + top level) | trace ms | shade ms | total "
        "ms | fps | M rays/s | fuzzy ÷ exact trace |\n|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const Json& run : model->value("runs", Json::array())) {
    const Json& p = run["phases"];
    const double per_frame = phase_ms(p, "skinning") + phase_ms(p, "boxes") + phase_ms(p, "top level + fallback");
    md += format("| %d | %s | %d | %s | %s | %s | %s | %s | %s | %s |\n", run.value("instances", 0),
                 thousands(number(*model, "triangles") * run.value("instances", 0)).c_str(), run.value("threads", 0),
                 cell(per_frame).c_str(),
                 cell(phase_ms(p, "trace primary") + phase_ms(p, "trace shadow"), 1).c_str(),
                 cell(phase_ms(p, "shade"), 1).c_str(), cell(phase_ms(p, "total"), 1).c_str(),
                 cell(number(run, "fps")).c_str(), cell(number(run, "mrays_per_s"), 1).c_str(),
                 cell(number(run["exact"], "fuzzy_over_exact")).c_str());
  }
  return md + failure_line(r);
}

std::string scaling_sizes_markdown(const std::vector<Run>& runs) {
  std::string md = "\n```sh\n";
  for (const Run& r : runs) md += r.command + "\n";
  md += "```\n\n| image | pixels | threads | trace ms | shade ms | total ms | fps | ns per pixel and thread |\n"
        "|---|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const Run& r : runs) {
    const Json* model = first_model(r);
    if (!model) {
      md += "| " + r.key + " | no results | | | | | | |\n";
      continue;
    }
    const int w = r.json["size"][0].get<int>(), h = r.json["size"][1].get<int>();
    const double pixels = static_cast<double>(w) * h;
    for (const Json& run : model->value("runs", Json::array())) {
      const Json& p = run["phases"];
      const double total = phase_ms(p, "total");
      md += format("| %d×%d | %s | %d | %s | %s | %s | %s | %s |\n", w, h, thousands(pixels).c_str(),
                   run.value("threads", 0), cell(phase_ms(p, "trace primary") + phase_ms(p, "trace shadow"), 1).c_str(),
                   cell(phase_ms(p, "shade"), 1).c_str(), cell(total, 1).c_str(), cell(number(run, "fps")).c_str(),
                   cell(total * 1e6 * run.value("threads", 1) / pixels, 0).c_str());
    }
  }
  for (const Run& r : runs) md += failure_line(r);
  return md;
}

// --- headlines -----------------------------------------------------------------------

// Points into the run's JSON (not into a copy: value() returns one).
const Json* table2_row(const Run* paper, int level) {
  if (!paper || !paper->json.contains("table2") || !paper->json["table2"].contains("rows")) return nullptr;
  for (const Json& row : paper->json["table2"]["rows"]) {
    if (row.contains("level") && row["level"].is_number_integer() && row["level"].get<int>() == level &&
        !row.value("interpolated", false)) {
      return &row;
    }
  }
  return nullptr;
}

double table2_fps(const Json& row, const char* threads, const char* kind) {
  if (!row.contains("fps") || !row["fps"].contains(threads)) return std::nan("");
  return number(row["fps"][threads], kind);
}

// Sinew's total over the named contender's, for one configuration.
double total_ratio(const Json& config, const std::string& other) {
  const Json* s = contender(config, kSinewContender);
  const Json* o = contender(config, other);
  if (!s || !o || !s->contains("phases") || !o->contains("phases")) return std::nan("");
  return phase_ms((*s)["phases"], "total") / phase_ms((*o)["phases"], "total");
}

double trace_ratio(const Json& config, const std::string& other) {
  const Json* s = contender(config, kSinewContender);
  const Json* o = contender(config, other);
  if (!s || !o || !s->contains("phases") || !o->contains("phases")) return std::nan("");
  return phase_ms((*s)["phases"], "trace") / phase_ms((*o)["phases"], "trace");
}

// "LOW rebuild 0.95 (rtcIntersect8), refit ...": Sinew ÷ each mode at its
// best width.
std::string best_by_mode_ratios(const Json& config) {
  std::string text;
  for (const Json& best : config["best_embree_by_mode"]) {
    text += (text.empty() ? "" : ", ") +
            format("%s %s (%s)", best.value("mode_name", "?").c_str(),
                   cell(number(best, "sinew_over_best_total")).c_str(), best.value("width_name", "?").c_str());
  }
  return text.empty() ? "no Embree row passed its brute-force check" : text;
}

// "Sinew's update 2.7 ms ÷ Embree refit's build 13.3 ms = 0.20": Sinew's
// per-frame update (the shared skinning, which carries its escape check
// and bone boxes, plus Sinew's build) over the build of the refit row at
// its best width. Empty when the run has no refit row.
std::string update_over_refit(const Json& config) {
  const Json* s = contender(config, kSinewContender);
  if (s == nullptr || !s->contains("phases") || !config.contains("shared")) return "";
  for (const Json& best : config.value("best_embree_by_mode", Json::array())) {
    if (best.value("mode_name", "") != "refit") continue;
    const Json* refit = contender(config, best.value("name", ""));
    if (refit == nullptr || !refit->contains("phases")) return "";
    const double update = phase_ms(config["shared"], "skinning") + phase_ms((*s)["phases"], "build");
    const double build = phase_ms((*refit)["phases"], "build");
    return format("; Sinew's update (skinning + build) %s ms ÷ Embree refit's build %s ms = %s", cell(update).c_str(),
                  cell(build).c_str(), cell(update / build).c_str());
  }
  return "";
}

std::string embree_headline(const Run& r, const char* label) {
  std::string md;
  for (const Json& config : r.json.value("configurations", Json::array())) {
    const std::string where = format("%s, %s, %d thread%s", label, config.value("clip", "?").c_str(),
                                     config.value("threads", 0), config.value("threads", 0) == 1 ? "" : "s");
    const std::string exact = cell(trace_ratio(config, "exact SAH kd rebuild"));
    if (!has_embree_widths(config)) {  // an earlier run: one row per mode
      md += format("- Sinew ÷ Embree, total frame time, %s: LOW rebuild %s, refit %s, MEDIUM rebuild %s; fuzzy ÷ "
                   "exact kd-tree trace time %s.\n",
                   where.c_str(), cell(total_ratio(config, "embree LOW rebuild")).c_str(),
                   cell(total_ratio(config, "embree refit")).c_str(),
                   cell(total_ratio(config, "embree MEDIUM rebuild")).c_str(), exact.c_str());
      continue;
    }
    if (!r.json.value("embree", false)) {
      md += format("- Embree was not found (%s); fuzzy ÷ exact kd-tree trace time %s.\n", where.c_str(),
                   exact.c_str());
      continue;
    }
    const Json& best = config["best_embree"];
    const std::string overall =
        best.is_object() ? format("against the best Embree row (%s) total frame time %s, trace %s",
                                  best.value("label", "?").c_str(), cell(number(best, "sinew_over_best_total")).c_str(),
                                  cell(number(best, "sinew_over_best_trace")).c_str())
                         : std::string("no Embree row passed its brute-force check");
    md += format("- Sinew ÷ Embree, %s: %s; each mode at its best width, total: %s; fuzzy ÷ exact kd-tree trace "
                 "time %s%s.\n",
                 where.c_str(), overall.c_str(), best_by_mode_ratios(config).c_str(), exact.c_str(),
                 update_over_refit(config).c_str());
  }
  return md;
}

// The demo run's entry for `characters`, or null.
const Json* demo_count(const Run* demo, int characters) {
  if (demo == nullptr || !demo->json.contains("counts")) return nullptr;
  for (const Json& c : demo->json["counts"]) {
    if (number(c, "characters") == characters) return &c;
  }
  return nullptr;
}

std::string headlines(const Run* paper, const Run* embree_small, const Run* embree_large, const Run* demo,
                      const Run* tradeoff) {
  std::string md = "## Headlines\n\n";
  if (const Json* row = table2_row(paper, 0)) {
    md += format("- Cally, %s triangles, 1024×1024, primary rays only: **%s fps on 1 thread** (%s on 2); the paper: "
                 "9.5 fps on one 2.4 GHz Opteron core (2006). With shadows: %s fps on 1 thread, %s on 2.\n",
                 thousands(number(*row, "triangles")).c_str(), cell(table2_fps(*row, "1", "primary")).c_str(),
                 cell(table2_fps(*row, "2", "primary")).c_str(), cell(table2_fps(*row, "1", "primary_shadows")).c_str(),
                 cell(table2_fps(*row, "2", "primary_shadows")).c_str());
  }
  if (embree_small) md += embree_headline(*embree_small, "Cally");
  if (embree_large) {
    md += embree_headline(*embree_large,
                          format("Cally subdivided (%s triangles)", thousands(number(embree_large->json, "triangles")).c_str())
                              .c_str());
  }
  if (const Json* six = demo_count(demo, 6)) {
    const Json size = demo->json.value("size", Json::array());
    const std::string pixels = size.size() == 2 ? format("%d×%d", size[0].get<int>(), size[1].get<int>()) : "?";
    const double threads = number(demo->json, "threads");
    md += format("- The game demo, 6 characters with shadows, %s, %s thread%s: **%s fps** (%s ms a frame).\n",
                 pixels.c_str(), cell(threads, 0).c_str(), threads == 1.0 ? "" : "s", cell(number(*six, "fps"), 1).c_str(),
                 cell(number(*six, "frame_ms"), 1).c_str());
  }
  if (tradeoff && tradeoff->json.contains("knee")) {
    for (const Json& k : tradeoff->json["knee"]) {
      md += format("- Knee of the speed/accuracy curve, %s pose space: %s samples (%s fps, hole fraction %s).\n",
                   k.value("mode", "?").c_str(), thousands(number(k, "samples")).c_str(), cell(number(k, "fps")).c_str(),
                   cell_g(number(k, "hole_fraction")).c_str());
    }
  }
  return md + "\n";
}

// The game demo's frame per character count: fps and the phases that
// make it (the demo's own session: its arena, characters and camera).
std::string demo_markdown(const Run& r) {
  std::string md = "## The game demo\n\n";
  md += "The demo's own session (`game_demo/`: the arena, the procedural mannequins walking a scripted path, the "
        "follow camera, one point light with shadow rays), timed frame by frame; fps = 1000 / the sum of the phases' "
        "per-frame medians. Command: `" + r.command + "`.\n\n";
  if (!r.json.contains("counts") || r.json["counts"].empty()) return md + failure_line(r) + "\n";
  md += "| characters | fps | frame ms | trace primary ms | trace shadow ms | shade ms | skinning ms | top level ms |\n"
        "|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const Json& c : r.json["counts"]) {
    const Json phases = c.value("phases_ms", Json::object());
    md += format("| %s | %s | %s | %s | %s | %s | %s | %s |\n", cell(number(c, "characters"), 0).c_str(),
                 cell(number(c, "fps"), 1).c_str(), cell(number(c, "frame_ms")).c_str(),
                 cell(number(phases, "trace primary")).c_str(), cell(number(phases, "trace shadow")).c_str(),
                 cell(number(phases, "shade")).c_str(), cell(number(phases, "skinning")).c_str(),
                 cell(number(phases, "top level")).c_str());
  }
  return md + failure_line(r) + "\n";
}

// --- the document ------------------------------------------------------------------------

struct Report {
  std::vector<Run> runs;
  const Run* find(const std::string& key) const {
    for (const Run& r : runs) {
      if (r.key == key) return &r;
    }
    return nullptr;
  }
};

std::string document(const Options& o, const Report& report, const std::string& date, const std::string& cpu,
                     const std::string& load_start, const std::string& load_end, double minutes,
                     const PlotResult& plots) {
  std::string md = "# Benchmarks\n\n";
  md += "<!-- Written by `sinew-bench report` (tests/bench/report_bench.cpp). Do not edit by hand: rerun it. -->\n\n";
  md += format("Measured %s on %s (%d hardware threads), build baseline %s, commit `%s`; %s mode, %.1f minutes in "
               "all; load average %s at the start, %s at the end (1, 5, 15 min). Each benchmark checks the first "
               "frame of every configuration against brute-force ray casting and leaves out any that disagrees.\n\n",
               date.c_str(), cpu.c_str(), JobSystem::hardware_threads(), std::string(build_isa()).c_str(),
               git_commit().c_str(), o.quick ? "quick" : "full", minutes, load_start.c_str(), load_end.c_str());
  std::string kept;
  for (const Run& r : report.runs) {
    if (r.kept && kept.find(section_of(r.key)) == std::string::npos) {
      kept += (kept.empty() ? "" : ", ") + section_of(r.key);
    }
  }
  if (!kept.empty()) {
    md += "Only some sections were measured by this run. Kept from an earlier run of the report: **" + kept +
          "** (`--sections` reruns the named sections and keeps the others; the last table gives each "
          "benchmark's date and commit).\n\n";
  }
  md += "Reproduce (the release preset; Embree 3 optional):\n\n```sh\n./sinew build release\n" +
        std::string("build/release/tests/bench/sinew-bench report") + (o.quick ? " --quick" : "") +
        "\n```\n\nThe raw numbers are in `bench-data/*.json` beside this file; each section names the command that "
        "measured it. `sinew-bench animation` and `sinew-bench bake` measure the animation (against Cal3D) and "
        "the bake (its candidate bones and memory bound) on their own.\n\n";
  md += headlines(report.find("paper"), report.find("embree"), report.find("embree-large"), report.find("demo"),
                  report.find("tradeoff"));

  if (const Run* paper = report.find("paper")) {
    md += pasted_markdown(*paper);
    md += failure_line(*paper);
    if (!plots.fps_vs_triangles.empty()) md += "\n![fps vs triangles, Sinew and the paper](" + plots.fps_vs_triangles + ")\n";
    md += "\n";
  }
  const Run* embree_small = report.find("embree");
  const Run* embree_large = report.find("embree-large");
  if (embree_small || embree_large) {
    md += "## The peer: Embree 3, and an exact kd-tree rebuilt per frame\n\n"
          "The same skinned triangles every frame (Sinew's skinning), the same camera rays, shadow rays and shading, "
          "traced by Sinew's fuzzy kd-trees, by Embree 3 rebuilt per frame at LOW and MEDIUM quality and refitted "
          "per frame (each at every ray width: single rays and 4-, 8- and 16-wide packets), and by an exact SAH "
          "kd-tree of Sinew's rebuilt per frame; the contenders take turns frame by "
          "frame so machine noise hits them alike.\n";
    if (embree_small) md += embree_markdown(*embree_small);
    if (embree_large) md += embree_markdown(*embree_large);
    if (!plots.embree.empty()) md += "\n![frame time per contender](" + plots.embree + ")\n";
    md += "\n";
  }
  if (const Run* demo = report.find("demo")) md += demo_markdown(*demo);
  if (const Run* structures = report.find("structures")) {
    md += pasted_markdown(*structures);
    md += failure_line(*structures);
    md += "\n";
  }
  if (const Run* trade = report.find("tradeoff")) {
    md += pasted_markdown(*trade);
    md += failure_line(*trade);
    if (!plots.tradeoff.empty()) {
      md += "\n![left: triangle tests and node visits per ray against holes, each sample count labelled with its "
            "fps, each mode's Pareto front; right: the same work against pack size for each pose-space cluster "
            "count K](" +
            plots.tradeoff + ")\n";
    }
    md += "\n";
  }
  const Run* instances = report.find("scaling-instances");
  std::vector<Run> sizes;
  for (const Run& r : report.runs) {
    if (r.key.rfind("scaling-size-", 0) == 0) sizes.push_back(r);
  }
  if (instances || !sizes.empty()) {
    md += "## Scaling\n\nFrames per second against the number of character instances, the image size and the "
          "threads (this machine has " +
          std::to_string(JobSystem::hardware_threads()) +
          "; a 16-core run is reported separately when one was at hand). Instances stand in a row on the ground, "
          "each a little later in the walk cycle.\n";
    if (instances) md += "\n### Instances\n" + scaling_instances_markdown(*instances);
    if (!sizes.empty()) md += "\n### Image size (one Cally)\n" + scaling_sizes_markdown(sizes);
    if (!plots.scaling.empty()) md += "\n![scaling](" + plots.scaling + ")\n";
    md += "\n";
  }
  md += "## When and how long each benchmark ran\n\n| benchmark | command | measured | commit | minutes | exit code |\n"
        "|---|---|---|---|---:|---:|\n";
  for (const Run& r : report.runs) {
    md += format("| %s | `%s` | %s%s | `%s` | %.1f | %d |\n", r.key.c_str(), r.command.c_str(), r.date.c_str(),
                 r.kept ? " (kept)" : "", r.commit.c_str(), r.seconds / 60.0, r.exit_code);
  }
  if (!plots.note.empty()) md += "\n" + plots.note + "\n";
  return md;
}

// --- the runs' manifest: rerunning some sections keeps the others -----------------

constexpr const char* kManifest = "report-runs.json";

std::string file_name(const std::string& path) { return path.empty() ? "" : fs::path(path).filename().string(); }

Json manifest(const Report& report) {
  Json runs = Json::array();
  for (const Run& r : report.runs) {
    runs.push_back({{"key", r.key},
                    {"command", r.command},
                    {"json", file_name(r.json_path)},
                    {"markdown", file_name(r.markdown_path)},
                    {"exit_code", r.exit_code},
                    {"seconds", r.seconds},
                    {"date", r.date},
                    {"commit", r.commit}});
  }
  return runs;
}

// The earlier report's runs of the sections not rerun now, read back from
// its manifest and JSON (a run whose files are gone is left out).
std::vector<Run> kept_runs(const Options& o, const std::string& data_dir) {
  std::vector<Run> kept;
  const Json manifest = read_json(data_dir + "/" + kManifest);
  if (!manifest.is_array()) return kept;
  for (const Json& entry : manifest) {
    const std::string key = entry.value("key", "");
    if (key.empty() || wanted(o, section_of(key))) continue;
    Run r;
    r.key = key;
    r.command = entry.value("command", "");
    r.json_path = data_dir + "/" + entry.value("json", "");
    const std::string markdown = entry.value("markdown", "");
    if (!markdown.empty()) r.markdown_path = data_dir + "/" + markdown;
    r.exit_code = entry.value("exit_code", 0);
    r.seconds = entry.value("seconds", 0.0);
    r.date = entry.value("date", "");
    r.commit = entry.value("commit", "");
    r.kept = true;
    r.json = read_json(r.json_path);
    if (!r.json.is_null()) kept.push_back(std::move(r));
  }
  return kept;
}

// Report order: the sections as kAllSections lists them, runs within a
// section in the order they ran.
void sort_runs(std::vector<Run>& runs) {
  const auto rank = [](const Run& r) {
    return std::find(kAllSections.begin(), kAllSections.end(), section_of(r.key)) - kAllSections.begin();
  };
  std::stable_sort(runs.begin(), runs.end(), [&](const Run& a, const Run& b) { return rank(a) < rank(b); });
}

// The benchmarks the report runs, with their full and quick arguments.
void run_all(const Options& o, const std::string& data_dir, Report& report) {
  std::vector<std::string> common;
  if (o.shared != SINEW_SHARED_DIR) common = {"--shared", o.shared};
  const auto with_common = [&](std::vector<std::string> args) {
    args.insert(args.end(), common.begin(), common.end());
    return args;
  };
  if (wanted(o, "paper")) {
    report.runs.push_back(run_bench("paper", "paper", with_common(o.quick ? std::vector<std::string>{"--quick"}
                                                                           : std::vector<std::string>{}),
                                    true, data_dir, run_paper_bench));
  }
  if (wanted(o, "embree")) {
    const std::vector<std::string> small =
        o.quick ? std::vector<std::string>{"--clips", "walk,tornado_kick", "--frames", "20", "--size", "256x256",
                                           "--threads", "1"}
                : std::vector<std::string>{"--clips", "walk,tornado_kick", "--frames", "120", "--threads", "1,2"};
    report.runs.push_back(run_bench("embree", "embree", with_common(small), false, data_dir, run_embree_bench));
    // The largest mesh of Table 2: few frames, as its exact kd-tree alone
    // takes seconds to build.
    const std::vector<std::string> large =
        o.quick ? std::vector<std::string>{"--subdivide", "2", "--clips", "walk", "--frames", "3", "--size", "256x256",
                                           "--threads", "1"}
                : std::vector<std::string>{"--subdivide", "4", "--clips", "walk", "--frames", "8", "--threads", "1,2"};
    report.runs.push_back(run_bench("embree", "embree-large", with_common(large), false, data_dir, run_embree_bench));
  }
  if (wanted(o, "structures")) {
    report.runs.push_back(run_bench("structures", "structures",
                                    with_common(o.quick ? std::vector<std::string>{"--quick"} : std::vector<std::string>{}),
                                    true, data_dir, run_structures_bench));
  }
  if (wanted(o, "demo")) {
    // The demo takes no --shared: its characters are procedural.
    const std::vector<std::string> demo =
        o.quick ? std::vector<std::string>{"--characters", "6", "--frames", "5", "--size", "256x256", "--threads", "1"}
                : std::vector<std::string>{"--characters", "1,6,12", "--frames", "60", "--threads", "2"};
    report.runs.push_back(run_bench("demo", "demo", demo, false, data_dir, run_demo_bench));
  }
  if (wanted(o, "tradeoff")) {
    report.runs.push_back(run_bench("tradeoff", "tradeoff",
                                    with_common(o.quick ? std::vector<std::string>{"--quick"} : std::vector<std::string>{}),
                                    true, data_dir, run_tradeoff_bench));
  }
  if (wanted(o, "scaling")) {
    const std::vector<std::string> instances =
        o.quick ? std::vector<std::string>{"--models", "cally", "--instances", "1,4,16", "--threads", "1,2", "--frames",
                                           "2", "--size", "256x256"}
                : std::vector<std::string>{"--models", "cally", "--instances", "1,2,4,8,16,32", "--threads", "1,2",
                                           "--frames", "5"};
    report.runs.push_back(
        run_bench("raytrace", "scaling-instances", with_common(instances), false, data_dir, run_raytrace_bench));
    const std::vector<int> sides = o.quick ? std::vector<int>{256, 512} : std::vector<int>{256, 512, 1024, 2048};
    for (int side : sides) {
      const std::string size = std::to_string(side) + "x" + std::to_string(side);
      report.runs.push_back(run_bench("raytrace", "scaling-size-" + std::to_string(side),
                                      with_common({"--models", "cally", "--instances", "1", "--threads", "1,2",
                                                   "--frames", o.quick ? "2" : "5", "--size", size}),
                                      false, data_dir, run_raytrace_bench));
    }
  }
}

// The README's headline table (tests/bench/readme_headline.h), from the
// runs this report shows; only for the report in the source tree's docs/.
bool write_readme_headline(const Report& report) {
  const std::string path = std::string(SINEW_SOURCE_DIR) + "/README.md";
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  const Run* small = report.find("embree");
  const Run* large = report.find("embree-large");
  const std::string table = headline_table(small ? &small->json : nullptr, large ? &large->json : nullptr);
  const std::optional<std::string> updated = replace_headline(text.str(), table);
  if (!in || !updated) {
    std::fprintf(stderr, "sinew-bench report: %s: no headline table markers (%s ... %s) to write between\n",
                 path.c_str(), kHeadlineBegin, kHeadlineEnd);
    return false;
  }
  if (!write_output("report", "README headline", path, *updated)) return false;
  std::printf("sinew-bench report: wrote the headline table of %s\n", path.c_str());
  return true;
}

}  // namespace

int run_report_bench(const std::vector<std::string>& args, const std::string& command_line) {
  BenchArgs bench_args("report", kDescription, bench_flags());
  const auto parsed = parse_bench_options(bench_args, args, read_options);
  if (const std::optional<int> done = usage_exit(bench_args, parsed)) return *done;
  const Options& o = *parsed;
  const std::string data_dir = o.out_dir + "/bench-data";
  const std::string image_dir = o.out_dir + "/img";
  std::error_code ec;
  fs::create_directories(data_dir, ec);
  if (!ec) fs::create_directories(image_dir, ec);
  if (ec) {
    std::fprintf(stderr, "sinew-bench report: cannot create %s: %s\n", data_dir.c_str(), ec.message().c_str());
    return 1;
  }
  const std::string cpu = cpu_model();
  const std::string date = utc_date();
  const std::string load_start = load_average();
  print_bench_header("report", command_line, "per benchmark", cpu, date);
  const auto start = std::chrono::steady_clock::now();

  Report report;
  report.runs = kept_runs(o, data_dir);
  run_all(o, data_dir, report);
  sort_runs(report.runs);
  if (!write_output("report", "manifest", data_dir + "/" + kManifest, manifest(report).dump(2) + "\n")) return 1;

  const double minutes = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / 60.0;
  PlotInputs inputs;
  for (const Run& r : report.runs) inputs.json[r.key] = &r.json;
  const PlotResult plots = make_plots(inputs, image_dir, data_dir, "img");
  const std::string path = o.out_dir + "/BENCHMARKS.md";
  std::ofstream out(path);
  out << document(o, report, date, cpu, load_start, load_average(), minutes, plots);
  out.close();
  if (!out) {
    std::fprintf(stderr, "sinew-bench report: cannot write %s\n", path.c_str());
    return 1;
  }
  std::printf("\nsinew-bench report: wrote %s (%.1f minutes)\n", path.c_str(), minutes);
  if (o.out_dir == std::string(SINEW_SOURCE_DIR) + "/docs" && !write_readme_headline(report)) return 1;
  int exit_code = plots.failed ? 1 : 0;
  for (const Run& r : report.runs) {
    if (r.exit_code != 0) exit_code = 1;
  }
  return exit_code;
}

}  // namespace sinew::bench
