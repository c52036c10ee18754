#include "tests/bench/readme_headline.h"

#include <cmath>
#include <cstdio>

namespace sinew::bench {
namespace {

using Json = nlohmann::ordered_json;

std::string fixed(double value, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}

// 855552 -> "855,552".
std::string thousands(long long n) {
  std::string digits = std::to_string(n), out;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return out;
}

double number(const Json& j, const char* key) {
  return j.contains(key) && j[key].is_number() ? j[key].get<double>() : std::nan("");
}

// The configuration the headline quotes: the first clip at the most threads.
const Json* headline_configuration(const Json& run) {
  if (!run.contains("configurations") || !run["configurations"].is_array()) return nullptr;
  const Json& configs = run["configurations"];
  if (configs.empty()) return nullptr;
  const std::string clip = configs[0].value("clip", "");
  const Json* chosen = nullptr;
  for (const Json& c : configs) {
    if (c.value("clip", "") != clip) continue;
    if (chosen == nullptr || c.value("threads", 0) > chosen->value("threads", 0)) chosen = &c;
  }
  return chosen;
}

std::string row(const Json& run) {
  const Json* config = headline_configuration(run);
  if (config == nullptr || !config->contains("best_embree") || !(*config)["best_embree"].is_object()) return "";
  const Json& best = (*config)["best_embree"];
  const double sinew_ms = number(best, "sinew_total_ms"), embree_ms = number(best, "total_ms");
  const double sinew_trace = number(best, "sinew_trace_ms"), embree_trace = number(best, "trace_ms");
  if (!(sinew_ms > 0.0 && embree_ms > 0.0 && sinew_trace > 0.0 && embree_trace > 0.0)) return "";
  const int threads = config->value("threads", 0);
  const Json size = run.value("size", Json::array());
  const std::string pixels =
      size.size() == 2 ? std::to_string(size[0].get<int>()) + "×" + std::to_string(size[1].get<int>()) : "?";
  const int subdivisions = run.value("subdivide", 0);
  const std::string model = run.value("model", std::string("?")) +
                            (subdivisions > 0 ? " subdivided " + std::to_string(subdivisions) + "×" : "");
  const std::string scene = model + " (" +
                            thousands(static_cast<long long>(number(run, "triangles"))) + " triangles), " +
                            config->value("clip", std::string("?")) + ", " + pixels + ", shadows, " +
                            std::to_string(threads) + (threads == 1 ? " thread" : " threads");
  const std::string cpu = run.value("cpu", std::string("?")) + ", " + run.value("isa", std::string("?")) + " build";
  return "| " + scene + " | " + fixed(sinew_ms, 1) + " | " + best.value("label", std::string("?")) + " | " +
         fixed(embree_ms, 1) + " | **" + fixed(embree_ms / sinew_ms, 2) + "×** | " +
         fixed(embree_trace / sinew_trace, 2) + "× | " + cpu + " | " + run.value("date", std::string("?")).substr(0, 10) +
         " |\n";
}

}  // namespace

std::string headline_table(const Json* small, const Json* large) {
  std::string rows;
  if (small != nullptr) rows += row(*small);
  if (large != nullptr) rows += row(*large);
  if (rows.empty()) return "";
  return "| scene | Sinew, ms a frame | Embree 3, best mode | Embree, ms a frame | Sinew's speed-up | "
         "trace only | CPU | measured |\n|---|---:|---|---:|---:|---:|---|---|\n" +
         rows;
}

std::optional<std::string> replace_headline(const std::string& text, const std::string& table) {
  const std::size_t begin = text.find(kHeadlineBegin);
  if (begin == std::string::npos) return std::nullopt;
  const std::size_t body = begin + std::string(kHeadlineBegin).size();
  const std::size_t end = text.find(kHeadlineEnd, body);
  if (end == std::string::npos) return std::nullopt;
  return text.substr(0, body) + "\n" + table + text.substr(end);
}

}  // namespace sinew::bench
