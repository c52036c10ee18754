#include "tests/bench/query_bench.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "character/bake.h"
#include "character/framing.h"
#include "runtime/jobs/job_system.h"
#include "runtime/timing/phase_timers.h"
#include "runtime/timing/stopwatch.h"
#include "sinew/world.h"
#include "tests/bench/api_character.h"
#include "tests/bench/bench_options.h"
#include "tests/bench/bench_record.h"
#include "tests/bench/bench_support.h"
#include "tests/bench/crowd_rays.h"
#include "tests/bench/crowd_reference.h"
#include "tests/bench/hit_comparison.h"
#ifdef SINEW_HAVE_EMBREE
#include "tests/bench/embree_crowd.h"
#endif

namespace sinew::bench {
namespace {

constexpr double kTickSeconds = 1.0 / 30.0;

// --- options -------------------------------------------------------------------

struct Options {
  std::string model = "cally";
  std::string clip = "walk";
  int instances = 256;
  int rays = 10000;
  int ticks = 30;
  int threads = 2;
  int seed = 1;
  int check_every = 1;  // brute-force every Nth ray of every tick
  std::string shared = SINEW_SHARED_DIR;
  std::string json_path;
  bool help = false;
};

std::vector<BenchFlag> flags() {
  return {
      {"--model", "M", "cally (default), mannequin, or a .gltf/.glb/.cfg/.pack path"},
      {"--clip", "NAME", "the clip every instance plays (default walk)"},
      {"--instances", "N", "characters in the grid layout (default 256)"},
      {"--rays", "N", "random rays a tick (default 10000)"},
      {"--ticks", "N", "ticks of 1/30 s (default 30; the first one builds and is not timed)"},
      threads_flag("2"),
      {"--seed", "S", "seed of the rays (default 1)"},
      {"--check-every", "N", "compare every Nth ray of every tick with brute force (default 1: all)"},
      shared_flag(),
      json_flag(),
  };
}

const char* const kDescription = "gameplay queries in a crowd: World::intersect against Embree refit and rebuild\n";

Status read_options(const BenchArgs& parsed, Options& o) {
  SINEW_RETURN_IF_ERROR(parsed.read("--model", o.model));
  SINEW_RETURN_IF_ERROR(parsed.read("--clip", o.clip));
  SINEW_RETURN_IF_ERROR(parsed.read("--instances", 1, 4096, o.instances));
  SINEW_RETURN_IF_ERROR(parsed.read("--rays", 1, 10000000, o.rays));
  SINEW_RETURN_IF_ERROR(parsed.read("--ticks", 1, 100000, o.ticks));
  SINEW_RETURN_IF_ERROR(parsed.read_threads(o.threads));
  SINEW_RETURN_IF_ERROR(parsed.read("--seed", 0, 2147483647, o.seed));
  SINEW_RETURN_IF_ERROR(parsed.read("--check-every", 1, 10000000, o.check_every));
  SINEW_RETURN_IF_ERROR(parsed.read("--shared", o.shared));
  SINEW_RETURN_IF_ERROR(parsed.read("--json", o.json_path));
  return {};
}

// --- the crowd -----------------------------------------------------------------

// What both contenders are given each tick: every instance's skinning
// matrices (bind pose -> world), in both vocabularies. Computing them is
// the host's animation, timed apart and charged to neither.
struct CrowdPose {
  std::vector<std::vector<Affine3>> bones;          // per instance
  std::vector<std::vector<api::Matrix3x4>> matrices;  // the same, as World::set_bone_matrices takes them
};

api::Matrix3x4 to_api(const Affine3& a) {
  api::Matrix3x4 m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) m.m[r][c] = a(r, c);
  }
  return m;
}

api::Ray to_api(const Ray& ray) {
  api::Ray r;
  r.origin = {ray.origin.x, ray.origin.y, ray.origin.z};
  r.direction = {ray.direction.x, ray.direction.y, ray.direction.z};
  r.t_min = ray.t_min;
  r.t_max = ray.t_max;
  return r;
}

Hit from_api(const api::RayHit& h) {
  if (!h.hit()) return {};
  return Hit{h.t, h.u, h.v, h.triangle, h.instance};
}

// Instance i plays `clip` from its grid offset on (character/framing.h),
// `tick` ticks in, placed by `placements[i]`.
Status pose_crowd(const character::Model& model, const anim::Clip& clip, int tick,
                  const std::vector<Affine3>& placements, CrowdPose& pose) {
  pose.bones.resize(placements.size());
  pose.matrices.resize(placements.size());
  for (std::size_t i = 0; i < placements.size(); ++i) {
    const double t = tick * kTickSeconds + character::instance_time_offset(static_cast<int>(i));
    SINEW_ASSIGN_OR_RETURN(pose.bones[i], character::clip_skinning(model, clip, t, placements[i]));
    pose.matrices[i].resize(pose.bones[i].size());
    std::transform(pose.bones[i].begin(), pose.bones[i].end(), pose.matrices[i].begin(),
                   [](const Affine3& a) { return to_api(a); });
  }
  return {};
}

// Where a ray aims, from one random draw: seven rays in eight at the centre
// of a random triangle of a random character as posed (a body aimed at),
// the eighth at a random point of the crowd's box, which often misses
// everything, so misses are checked too.
Vec3 aim_point(std::uint64_t draw, const CrowdReference& reference, const std::vector<api::InstanceId>& ids,
               std::size_t triangles, const Aabb& crowd_box) {
  if (draw % 8 == 0) {
    const auto fraction = [&](int shift) { return static_cast<float>((draw >> shift) & 0xFFFFu) / 65536.0f; };
    return crowd_box.lower + Vec3(fraction(16), fraction(32), fraction(48)) * (crowd_box.upper - crowd_box.lower);
  }
  draw /= 8;
  const api::InstanceId instance = ids[static_cast<std::size_t>(draw % ids.size())];
  const auto triangle = static_cast<std::uint32_t>((draw / ids.size()) % triangles);
  const std::array<Vec3, 3> corners = *reference.corners(instance, triangle);
  return (corners[0] + corners[1] + corners[2]) / 3.0f;
}

// --- contenders ----------------------------------------------------------------

// One contender's answers and checks over the run.
struct Contender {
  std::string name;
  std::string key;  // the JSON's: "sinew", "embree_refit", "embree_rebuild_low"
  PhaseTimers timers;  // Sinew: "bones", "query", "total"; Embree: "skin", "build", "trace", "total"
  std::vector<Hit> hits;  // this tick's
  std::uint64_t checked = 0, mismatched = 0, grazes = 0;
  std::uint64_t hit_rays = 0;  // over the checked ticks' rays
};

double median_of(const PhaseTimers& timers, std::string_view name) {
  for (const PhaseSummary& s : timers.summarize()) {
    if (s.name == name) return s.median_ms;
  }
  return 0.0;
}

// Sinew's tick: the new matrices handed to the World, then one batch
// query (which skins, boxes and builds the top level over the instances
// the rays reach, then traces).
Status sinew_tick(api::World& world, const std::vector<api::InstanceId>& ids, const CrowdPose& pose,
                  const std::vector<api::Ray>& rays, std::vector<api::RayHit>& answers, Contender& c, bool timed) {
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < ids.size(); ++i) {
    SINEW_RETURN_IF_ERROR(
        status_from_api(world.set_bone_matrices(ids[i], pose.matrices[i]), "World::set_bone_matrices"));
  }
  const double bones_ms = ms_since(start);
  const auto query_start = std::chrono::steady_clock::now();
  SINEW_RETURN_IF_ERROR(status_from_api(world.intersect(rays, answers), "World::intersect"));
  const double query_ms = ms_since(query_start);
  if (timed) {
    c.timers.record("bones", bones_ms);
    c.timers.record("query", query_ms);
    c.timers.record("total", bones_ms + query_ms);
  }
  c.hits.resize(answers.size());
  std::transform(answers.begin(), answers.end(), c.hits.begin(), from_api);
  return {};
}

#ifdef SINEW_HAVE_EMBREE
Status embree_tick(EmbreeCrowd& crowd, const CrowdPose& pose, const std::vector<Ray>& rays, JobSystem& jobs,
                   Contender& c, bool timed) {
  SINEW_ASSIGN_OR_RETURN(const EmbreeCrowdUpdate update, crowd.update(pose.bones, jobs));
  c.hits.resize(rays.size());
  const auto trace_start = std::chrono::steady_clock::now();
  crowd.trace(rays, c.hits);
  const double trace_ms = ms_since(trace_start);
  if (timed) {
    c.timers.record("skin", update.skin_ms);
    c.timers.record("build", update.build_ms);
    c.timers.record("trace", trace_ms);
    c.timers.record("total", update.skin_ms + update.build_ms + trace_ms);
  }
  return {};
}
#endif

// Every `every`-th ray of the tick against brute force, for each
// contender (the reference's rays in parallel: it is the slow part).
void check_tick(const CrowdReference& reference, int tick, const std::vector<Ray>& rays, int every, JobSystem& jobs,
                std::vector<Contender>& contenders) {
  const std::size_t step = static_cast<std::size_t>(every);
  std::vector<std::size_t> sampled;
  for (std::size_t r = 0; r < rays.size(); r += step) sampled.push_back(r);
  std::vector<Hit> ref(sampled.size());
  jobs.parallel_for(0, sampled.size(), 16, [&](Range range) {
    for (std::size_t k = range.begin; k < range.end; ++k) ref[k] = reference.nearest(rays[sampled[k]]);
  });
  const auto corners_of = [&](std::uint32_t instance, std::uint32_t triangle) {
    return reference.corners(instance, triangle);
  };
  for (Contender& c : contenders) {
    for (std::size_t k = 0; k < sampled.size(); ++k) {
      const Hit& ours = c.hits[sampled[k]];
      ++c.checked;
      if (ours.valid()) ++c.hit_rays;
      switch (compare_nearest_hits(ours, ref[k], rays[sampled[k]], corners_of)) {
        case HitVerdict::kSame: break;
        case HitVerdict::kGraze: ++c.grazes; break;
        case HitVerdict::kDifferent:
          if (c.mismatched++ < 5) {  // the first few, so a failure says where to look
            std::printf("  MISMATCH %s, tick %d, ray %zu: %s t %.6g instance %u triangle %u, brute force %s t %.6g "
                        "instance %u triangle %u\n",
                        c.name.c_str(), tick, sampled[k], ours.valid() ? "hit" : "miss", static_cast<double>(ours.t),
                        ours.instance_id, ours.triangle_id, ref[k].valid() ? "hit" : "miss",
                        static_cast<double>(ref[k].t), ref[k].instance_id, ref[k].triangle_id);
          }
          break;
      }
    }
  }
}

// --- report --------------------------------------------------------------------

struct RunSummary {
  double animate_ms = 0.0;  // the shared host animation, median
  std::size_t best_embree = 0;  // index into the contenders; 0 when none (Sinew is 0)
};

double mrays_per_s(int rays, double ms) { return ms > 0.0 ? rays / (ms * 1e3) : 0.0; }

void print_table(const Options& o, const std::vector<Contender>& contenders, const RunSummary& s) {
  const double sinew_total = median_of(contenders[0].timers, "total");
  std::printf("\n| contender | update ms | trace ms | total ms | Mrays/s | this / Sinew |\n"
              "|---|---:|---:|---:|---:|---:|\n");
  for (std::size_t i = 0; i < contenders.size(); ++i) {
    const Contender& c = contenders[i];
    const bool sinew = i == 0;
    const double update = sinew ? median_of(c.timers, "bones")
                                : median_of(c.timers, "skin") + median_of(c.timers, "build");
    const double trace = sinew ? median_of(c.timers, "query") : median_of(c.timers, "trace");
    const double total = median_of(c.timers, "total");
    std::printf("| %s%s | %.3f | %.3f | %.3f | %.2f | %.2f |\n", c.name.c_str(),
                i == s.best_embree && !sinew ? " (best Embree)" : "", update, trace, total,
                mrays_per_s(o.rays, total), sinew_total > 0.0 ? total / sinew_total : 0.0);
  }
  for (std::size_t i = 1; i < contenders.size(); ++i) {
    const Contender& c = contenders[i];
    std::printf("  %s: skin %.3f ms + %s %.3f ms, trace %.3f ms\n", c.name.c_str(), median_of(c.timers, "skin"),
                c.key == "embree_refit" ? "refit" : "rebuild", median_of(c.timers, "build"),
                median_of(c.timers, "trace"));
  }
  if (s.best_embree > 0) {
    const double best = median_of(contenders[s.best_embree].timers, "total");
    std::printf("  Sinew / best Embree per tick: %.3f (%s)\n", best > 0.0 ? sinew_total / best : 0.0,
                contenders[s.best_embree].name.c_str());
  }
  std::printf("  host animation (shared, charged to neither): %.3f ms a tick\n", s.animate_ms);
  std::printf("\n  Medians over ticks 2..%d (the first builds Embree's BVHs and is not timed). Sinew: update = the\n"
              "  skinning matrices handed over (World::set_bone_matrices); trace = one World::intersect over the\n"
              "  batch, which skins, boxes and builds the top level over the instances the rays reach, then traces,\n"
              "  on the calling thread. Embree: update = every vertex skinned (Sinew's kernel, %d threads) + vertex\n"
              "  upload + rtcCommitScene; trace = rtcIntersect1 per ray on the calling thread.\n",
              o.ticks, o.threads);
}

Json contender_json(const Options& o, const Contender& c, bool best) {
  Json entry = {{"name", c.name},
                {"key", c.key},
                {"brute_force",
                 {{"passed", c.mismatched == 0}, {"checked", c.checked}, {"mismatched", c.mismatched},
                  {"edge_grazes", c.grazes}}},
                {"checked_hit_fraction", c.checked > 0 ? static_cast<double>(c.hit_rays) / c.checked : 0.0},
                {"phases", Json::parse(c.timers.json(), nullptr, false)}};
  Json medians = Json::object();
  for (const PhaseSummary& p : c.timers.summarize()) medians[p.name] = p.median_ms;
  entry["median_ms"] = medians;
  entry["mrays_per_s"] = mrays_per_s(o.rays, median_of(c.timers, "total"));
  if (best) entry["best_embree"] = true;
  return entry;
}

// --- the run -------------------------------------------------------------------

Status run(const Options& o, const character::Model& model, BenchRecord& record) {
  SINEW_ASSIGN_OR_RETURN(const std::size_t clip_index, find_clip(model, o.model, o.clip));
  const anim::Clip& clip = model.clips[clip_index];
  JobSystem jobs(o.threads);
  std::fprintf(stderr, "baking %s...\n", o.model.c_str());
  SINEW_ASSIGN_OR_RETURN(const std::unique_ptr<ApiCharacter> character, ApiCharacter::bake(model, o.model, jobs));

  // The grid layout, as sinew-editor render --layout grid places it.
  const Aabb rest = character::rest_bounds(model);
  std::vector<Affine3> placements;
  for (int i = 0; i < o.instances; ++i) {
    placements.push_back(character::instance_placement(rest, i, o.instances, character::Layout::kGrid));
  }
  auto created = api::World::create();
  if (!created.ok()) return status_from_api(created.error(), "World::create");
  api::World world = std::move(created).value();
  std::vector<api::InstanceId> ids;
  api::InstanceDesc desc;
  desc.driver = api::Driver::kHost;
  for (int i = 0; i < o.instances; ++i) {
    auto id = world.add_instance(character->character(), desc);
    if (!id.ok()) return status_from_api(id.error(), "World::add_instance");
    ids.push_back(id.value());
  }

  std::vector<Contender> contenders;
  contenders.emplace_back();
  contenders.back().name = "sinew World::intersect";
  contenders.back().key = "sinew";
#ifdef SINEW_HAVE_EMBREE
  std::vector<std::unique_ptr<EmbreeCrowd>> embree;
  for (const EmbreeMode mode : {EmbreeMode::kRefit, EmbreeMode::kRebuildLow}) {
    SINEW_ASSIGN_OR_RETURN(std::unique_ptr<EmbreeCrowd> crowd,
                           EmbreeCrowd::create(mode, jobs.thread_count(), model.mesh, ids));
    embree.push_back(std::move(crowd));
    const bool refit = mode == EmbreeMode::kRefit;
    contenders.emplace_back();
    contenders.back().name = refit ? "embree refit + rtcIntersect1" : "embree LOW rebuild + rtcIntersect1";
    contenders.back().key = refit ? "embree_refit" : "embree_rebuild_low";
  }
#else
  record.note("Embree not found: its rows are skipped");
#endif

  const Aabb crowd_box = character::layout_bounds(rest, o.instances, character::Layout::kGrid);
  CrowdRays generator(crowd_box, static_cast<std::uint64_t>(o.seed));
  CrowdReference reference(model.mesh, ids);
  CrowdPose pose;
  PhaseTimers shared;
  std::vector<api::Ray> api_rays(static_cast<std::size_t>(o.rays));
  std::vector<api::RayHit> answers(api_rays.size());
  for (int tick = 0; tick < o.ticks; ++tick) {
    const bool timed = tick > 0 || o.ticks == 1;
    const auto animate_start = std::chrono::steady_clock::now();
    SINEW_RETURN_IF_ERROR(pose_crowd(model, clip, tick, placements, pose));
    if (timed) shared.record("animate", ms_since(animate_start));
    // The reference is posed first (untimed): the rays aim at its triangles.
    for (std::size_t i = 0; i < ids.size(); ++i) reference.pose(i, pose.bones[i]);
    const std::vector<Ray> rays = generator.next(api_rays.size(), [&](std::uint64_t draw) {
      return aim_point(draw, reference, ids, model.mesh.triangle_count(), crowd_box);
    });
    std::transform(rays.begin(), rays.end(), api_rays.begin(), [](const Ray& r) { return to_api(r); });
    // The contenders take turns going first, so none always runs on caches
    // the other warmed.
    for (std::size_t k = 0; k < contenders.size(); ++k) {
      const std::size_t which = (k + static_cast<std::size_t>(tick)) % contenders.size();
      if (which == 0) {
        SINEW_RETURN_IF_ERROR(sinew_tick(world, ids, pose, api_rays, answers, contenders[0], timed));
      }
#ifdef SINEW_HAVE_EMBREE
      if (which > 0) SINEW_RETURN_IF_ERROR(embree_tick(*embree[which - 1], pose, rays, jobs, contenders[which], timed));
#endif
    }
    check_tick(reference, tick, rays, o.check_every, jobs, contenders);
  }

  RunSummary summary;
  summary.animate_ms = median_of(shared, "animate");
  for (std::size_t i = 1; i < contenders.size(); ++i) {
    if (summary.best_embree == 0 ||
        median_of(contenders[i].timers, "total") < median_of(contenders[summary.best_embree].timers, "total")) {
      summary.best_embree = i;
    }
  }
  print_table(o, contenders, summary);
  if (o.check_every == 1) {
    std::printf("\n  brute force: every ray of every tick (%llu in all):\n",
                static_cast<unsigned long long>(contenders[0].checked));
  } else {
    std::printf("\n  brute force: every %dth ray of every tick (%llu in all):\n", o.check_every,
                static_cast<unsigned long long>(contenders[0].checked));
  }
  for (const Contender& c : contenders) {
    std::printf("  %s: %s, %llu checked, %llu mismatched, %llu edge grazes, %.0f%% of them hit\n", c.name.c_str(),
                c.mismatched == 0 ? "passed" : "FAILED", static_cast<unsigned long long>(c.checked),
                static_cast<unsigned long long>(c.mismatched), static_cast<unsigned long long>(c.grazes),
                c.checked > 0 ? 100.0 * static_cast<double>(c.hit_rays) / static_cast<double>(c.checked) : 0.0);
    if (c.mismatched > 0) record.mark_failed();
  }

  Json& doc = record.doc();
  doc["triangles_per_instance"] = model.mesh.triangle_count();
  doc["vertices_per_instance"] = model.mesh.vertex_count();
  doc["animate_ms"] = summary.animate_ms;
  doc["contenders"] = Json::array();
  for (std::size_t i = 0; i < contenders.size(); ++i) {
    doc["contenders"].push_back(contender_json(o, contenders[i], i > 0 && i == summary.best_embree));
  }
  if (summary.best_embree > 0) {
    const double best = median_of(contenders[summary.best_embree].timers, "total");
    doc["best_embree"] = contenders[summary.best_embree].key;
    doc["sinew_over_best_embree"] = best > 0.0 ? median_of(contenders[0].timers, "total") / best : 0.0;
  }
  return {};
}

}  // namespace

int run_query_bench(const std::vector<std::string>& args, const std::string& command_line) {
  BenchArgs bench_args("queries", kDescription, flags());
  const auto parsed = parse_bench_options(bench_args, args, read_options);
  if (const std::optional<int> done = usage_exit(bench_args, parsed)) return *done;
  const Options& o = *parsed;
  BenchRecord record("queries", command_line, o.threads);
  std::printf("  model %s, clip %s, %d instances in a grid, %d rays a tick, %d ticks of 1/30 s, seed %d\n",
              o.model.c_str(), o.clip.c_str(), o.instances, o.rays, o.ticks, o.seed);
  std::fflush(stdout);
  record.doc().update(Json{{"model", o.model},
                           {"clip", o.clip},
                           {"instances", o.instances},
                           {"layout", "grid"},
                           {"rays", o.rays},
                           {"ticks", o.ticks},
                           {"seed", o.seed},
                           {"check_every", o.check_every}});
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
  std::printf("  load at the end: %s (1, 5, 15 min)\n", load_average().c_str());
  return record.finish(o.json_path);
}

}  // namespace sinew::bench
