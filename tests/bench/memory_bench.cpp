#include "tests/bench/memory_bench.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "character/framing.h"
#include "raytrace/scene/frame_state.h"
#include "runtime/jobs/job_system.h"
#include "sinew/pass.h"
#include "sinew/world.h"
#include "tests/bench/api_character.h"
#include "tests/bench/bench_options.h"
#include "tests/bench/bench_record.h"
#include "tests/bench/bench_support.h"
#include "tests/bench/process_memory.h"

namespace sinew::bench {
namespace {

// What each instance may cost beyond its skinned vertices: its pose and its
// share of the top level.
constexpr std::int64_t kAllowanceKib = 4;
// Frames animated and rendered after each step, so buffers a frame grows
// on first use are in the reading.
constexpr int kFramesPerStep = 2;

struct Options {
  std::string model = "cally";
  std::string clip = "walk";
  std::vector<int> instances{1, 2, 4, 8, 16, 32, 64, 128, 256};
  int width = 64;
  int height = 64;
  int threads = 2;
  std::string shared = SINEW_SHARED_DIR;
  std::string json_path;
  bool help = false;
};

std::vector<BenchFlag> flags() {
  return {
      {"--model", "M", "cally (default), mannequin, or a .gltf/.glb/.cfg/.pack path"},
      {"--clip", "NAME", "the clip every instance plays (default walk)"},
      {"--instances", "LIST", "instance counts to read the resident set at, rising (default 1,2,4,...,256)"},
      size_flag("64x64"),
      threads_flag("2"),
      shared_flag(),
      json_flag(),
  };
}

const char* const kDescription = "resident memory per added character instance against its skinned vertices\n";

Status read_options(const BenchArgs& parsed, Options& o) {
  SINEW_RETURN_IF_ERROR(parsed.read("--model", o.model));
  SINEW_RETURN_IF_ERROR(parsed.read("--clip", o.clip));
  SINEW_RETURN_IF_ERROR(parsed.read("--instances", 1, 4096, o.instances));
  if (!std::is_sorted(o.instances.begin(), o.instances.end()) ||
      std::adjacent_find(o.instances.begin(), o.instances.end()) != o.instances.end()) {
    return invalid_argument("--instances", join_ints(o.instances), "expected rising counts");
  }
  SINEW_RETURN_IF_ERROR(parsed.read_size(4096, o.width, o.height));
  SINEW_RETURN_IF_ERROR(parsed.read_threads(o.threads));
  SINEW_RETURN_IF_ERROR(parsed.read("--shared", o.shared));
  SINEW_RETURN_IF_ERROR(parsed.read("--json", o.json_path));
  return {};
}

api::Float3 to_api(const Vec3& v) { return {v.x, v.y, v.z}; }

api::Matrix3x4 to_api(const Affine3& a) {
  api::Matrix3x4 m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) m.m[r][c] = a(r, c);
  }
  return m;
}

struct Step {
  int instances = 0;
  ProcessMemory memory;
  // Since the step before (0 for the first): the growth of each reading
  // over the instances added.
  double resident_kib_per_added = 0.0;
  double heap_kib_per_added = 0.0;
};

// The bytes each instance keeps per vertex of its character when a pass
// shades it: the skinned world positions and normals (InstanceFrame).
constexpr std::size_t kSkinnedVertexBytes = sizeof(decltype(rt::InstanceFrame::positions)::value_type) +
                                            sizeof(decltype(rt::InstanceFrame::normals)::value_type);

Status run(const Options& o, const character::Model& model, BenchRecord& record) {
  SINEW_RETURN_IF_ERROR(status_of(find_clip(model, o.model, o.clip)));
  JobSystem jobs(o.threads);
  std::fprintf(stderr, "baking %s...\n", o.model.c_str());
  SINEW_ASSIGN_OR_RETURN(const std::unique_ptr<ApiCharacter> character, ApiCharacter::bake(model, o.model, jobs));
  const int most = o.instances.back();

  // The grid of the largest count from the start, so an instance never
  // moves as more join it; the camera frames all of them, so none is
  // culled and every one keeps its skinned vertices.
  const Aabb rest = character::rest_bounds(model);
  const int up = character::up_axis_of(rest);
  const Aabb box = character::layout_bounds(rest, most, character::Layout::kGrid);
  const rt::CameraDesc view = character::default_camera(box, up, o.width, o.height);
  api::PassInputs inputs;
  inputs.camera = {to_api(view.eye), to_api(view.target), to_api(view.up), view.fovy_degrees};
  api::Light light;
  light.position = to_api(character::default_light(box, up));
  inputs.lights = {&light, 1};

  auto created = api::World::create();
  if (!created.ok()) return status_from_api(created.error(), "World::create");
  api::World world = std::move(created).value();
  api::PassDesc desc;
  desc.width = o.width;
  desc.height = o.height;
  desc.threads = o.threads;
  auto pass = api::RayTracePass::create(desc);
  if (!pass.ok()) return status_from_api(pass.error(), "RayTracePass::create");
  std::vector<std::uint8_t> rgba(static_cast<std::size_t>(o.width) * static_cast<std::size_t>(o.height) * 4);
  api::PassOutputs outputs;
  outputs.color_rgba8 = {rgba.data(), 0};

  std::vector<Step> steps;
  int added = 0;
  for (const int count : o.instances) {
    for (; added < count; ++added) {
      api::InstanceDesc instance;
      instance.transform = to_api(character::instance_placement(rest, added, most, character::Layout::kGrid));
      auto id = world.add_instance(character->character(), instance);
      if (!id.ok()) return status_from_api(id.error(), "World::add_instance");
      SINEW_RETURN_IF_ERROR(status_from_api(world.play_cycle(*id, o.clip, 1.0f, 0.0f), "World::play_cycle"));
      SINEW_RETURN_IF_ERROR(status_from_api(
          world.offset_time(*id, static_cast<float>(character::instance_time_offset(added))), "World::offset_time"));
    }
    for (int f = 0; f < kFramesPerStep; ++f) {
      SINEW_RETURN_IF_ERROR(status_from_api(world.advance(1.0f / 30.0f), "World::advance"));
      const auto stats = pass->execute(world, inputs, outputs);
      if (!stats.ok()) return status_from_api(stats.error(), "RayTracePass::execute");
    }
    const std::optional<ProcessMemory> memory = read_process_memory();
    if (!memory) {
      return make_error(ErrorCode::kNotFound, "/proc/self/status", "VmRSS", "",
                        "no such line: the resident set cannot be read here");
    }
    Step step{count, *memory, 0.0, 0.0};
    if (!steps.empty()) {
      const Step& before = steps.back();
      const double added_now = count - before.instances;
      step.resident_kib_per_added =
          static_cast<double>(memory->resident_kib - before.memory.resident_kib) / added_now;
      step.heap_kib_per_added =
          static_cast<double>(memory->heap_in_use_kib - before.memory.heap_in_use_kib) / added_now;
    }
    steps.push_back(step);
  }

  const double vertex_kib = static_cast<double>(model.mesh.vertex_count() * kSkinnedVertexBytes) / 1024.0;
  const double target_kib = vertex_kib + static_cast<double>(kAllowanceKib);
  std::printf("\n  %zu vertices x %zu bytes (skinned positions and normals) = %.1f KiB a skinned instance;\n"
              "  target per added instance: that + %lld KiB = %.1f KiB\n",
              model.mesh.vertex_count(), kSkinnedVertexBytes, vertex_kib, static_cast<long long>(kAllowanceKib),
              target_kib);
  std::printf("\n| instances | resident set KiB | heap in use KiB | resident KiB per added instance |"
              " heap KiB per added instance | within target |\n|---:|---:|---:|---:|---:|---|\n");
  Json rows = Json::array();
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const Step& s = steps[i];
    const auto resident = static_cast<long long>(s.memory.resident_kib);
    const auto heap = static_cast<long long>(s.memory.heap_in_use_kib);
    Json row = {{"instances", s.instances}, {"resident_set_kib", resident}, {"heap_in_use_kib", heap}};
    if (i == 0) {
      std::printf("| %d | %lld | %lld | | | |\n", s.instances, resident, heap);
    } else {
      const bool within = std::max(s.resident_kib_per_added, s.heap_kib_per_added) <= target_kib;
      std::printf("| %d | %lld | %lld | %.1f | %.1f | %s |\n", s.instances, resident, heap, s.resident_kib_per_added,
                  s.heap_kib_per_added, within ? "yes" : "no");
      row["resident_kib_per_added_instance"] = s.resident_kib_per_added;
      row["heap_kib_per_added_instance"] = s.heap_kib_per_added;
      row["within_target"] = within;
    }
    rows.push_back(row);
  }
  std::printf("\n  Each step adds instances (grid layout, clip %s, own time offsets), animates and renders %d\n"
              "  frames of %dx%d with shadows, returns the heap's free pages (malloc_trim), then reads VmRSS and\n"
              "  the heap in use (mallinfo2); per added instance = the growth since the step before over the\n"
              "  instances added. The resident set grows by whole pages, so small steps are coarse; the heap\n"
              "  in use counts bytes. Within target: both at most the target.\n",
              o.clip.c_str(), kFramesPerStep, o.width, o.height);
  Json& doc = record.doc();
  doc["vertices"] = model.mesh.vertex_count();
  doc["skinned_vertex_bytes"] = kSkinnedVertexBytes;
  doc["skinned_instance_kib"] = vertex_kib;
  doc["target_kib_per_instance"] = target_kib;
  doc["steps"] = std::move(rows);
  return {};
}

}  // namespace

int run_memory_bench(const std::vector<std::string>& args, const std::string& command_line) {
  BenchArgs bench_args("memory", kDescription, flags());
  const auto parsed = parse_bench_options(bench_args, args, read_options);
  if (const std::optional<int> done = usage_exit(bench_args, parsed)) return *done;
  const Options& o = *parsed;
  BenchRecord record("memory", command_line, o.threads);
  std::printf("  model %s, clip %s, instances %s, %dx%d frames\n", o.model.c_str(), o.clip.c_str(),
              join_ints(o.instances).c_str(), o.width, o.height);
  record.doc().update(Json{{"model", o.model},
                           {"clip", o.clip},
                           {"instances", o.instances},
                           {"layout", "grid"},
                           {"size", {o.width, o.height}}});
  std::string note;
  auto loaded = load_model_or_path(o.model, o.shared, note);
  if (!loaded.ok()) {
    record.fail("", loaded.status());
    return record.exit_code();
  }
  if (!loaded->has_value()) {
    record.note(note);
    return record.finish(o.json_path);
  }
  if (const Status s = run(o, **loaded, record); !s.ok()) record.fail("", s);
  return record.finish(o.json_path);
}

}  // namespace sinew::bench
