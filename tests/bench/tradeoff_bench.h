// sinew-bench tradeoff: the speed/accuracy trade of the bake's options
// measured side by side (docs/DESIGN.md section 5): pose-space mode, sample count
// and padding against bake time, pack size, fuzzy area, fps, escapes and
// holes on held-out poses; plus the fast vs watertight triangle test (fps
// and leaked rays on a crack test) and exact vs cheap bone boxes.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace sinew::bench {

int run_tradeoff_bench(const std::vector<std::string>& args, const std::string& command_line);

// --- pieces exposed for tests ----------------------------------------------------

// One point of the sweep as the knee rule sees it.
struct KneePoint {
  std::string mode;
  int samples_used = 0;
  double padding = 0.0;
  double fps = 0.0;
  double hole_fraction = 0.0;
};

// The knee of one mode's curve: the smallest sample count (samples_used)
// whose hole fraction at the smallest padding measured is below
// `threshold`. Empty when no point of that mode gets there.
std::optional<KneePoint> find_knee(const std::vector<KneePoint>& points, const std::string& mode,
                                   double threshold);

// The crack test: rays aimed at the shared edges and vertices of a closed
// icosphere (every edge shared by two triangles), each stopped just past
// its target, so a ray that finds no triangle there slipped through a
// crack. `subdivisions` refines the 20-triangle icosahedron.
struct CrackResult {
  std::uint64_t rays = 0;
  std::uint64_t leaked = 0;
};
CrackResult crack_test(bool watertight, int subdivisions, std::uint64_t seed);

}  // namespace sinew::bench
