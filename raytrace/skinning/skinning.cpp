// Scalar skinning, path dispatch, chunking and the fused escape check.
//
// Decisions the header leaves open:
// - Both paths blend the matrix first (sum_k w_k B_k) and transform once,
//   which equals sum_k w_k (B_k p) up to rounding and lets the normal reuse
//   the blended 3x3 part.
// - Normals are written only when targets.normals is non-empty AND the mesh
//   has normals; a mesh without normals leaves targets.normals untouched
//   (skipped, not zeroed): there is nothing meaningful to write.
// - The function has no error channel, so mismatched sizes are clamped rather
//   than read or written out of bounds: only the vertices that fit every
//   per-vertex array are skinned, normals only when both normal arrays cover
//   them, and an escape flag is written only where targets.escaped has room
//   (the check is still counted). A check whose bone has no bone_from_world
//   or tolerance entry counts as escaped, the safe answer for the renderer.
// - The escape check runs on the chunk's fresh positions, right after they
//   were written, while they are still in cache: rigid blocks by
//   construction, the others eight vertices at a time (AVX2) or four lanes
//   per check.
#include "raytrace/skinning/skinning.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <vector>

#include "raytrace/skinning/skinning_kernels.h"
#include "runtime/jobs/job_system.h"

#if defined(__SSE2__)
#include <immintrin.h>
#define SINEW_ESCAPE_SSE 1
#else
#define SINEW_ESCAPE_SSE 0
#endif

namespace sinew::rt {

namespace {

static_assert(sizeof(Vec3) == 3 * sizeof(float), "kernels read Vec3 arrays as packed floats");
static_assert(sizeof(Affine3) == detail::kFloatsPerBone * sizeof(float), "kernels read bones as 12 floats");
static_assert(kInfluenceGroupLanes == detail::kAvx2Lanes, "a group of packed influences is one register");

// Large enough to amortise the task overhead.
constexpr std::size_t kChunkVertices = kSkinningChunkVertices;
static_assert(kChunkVertices % detail::kAvx2Lanes == 0);

void skin_vertex_scalar(const detail::SkinningArrays& a, std::size_t v) {
  float m[detail::kFloatsPerBone] = {};
  const std::size_t group = v / detail::kAvx2Lanes;
  const std::size_t lane = v % detail::kAvx2Lanes;
  for (std::size_t slot = a.group_slot_begin[group]; slot < a.group_slot_begin[group + 1]; ++slot) {
    const float w = a.slot_weights[slot * detail::kAvx2Lanes + lane];
    if (w == 0.0f) continue;
    const float* bone = a.bones + detail::kFloatsPerBone * a.slot_joints[slot * detail::kAvx2Lanes + lane];
    for (std::size_t e = 0; e < detail::kFloatsPerBone; ++e) m[e] += w * bone[e];
  }
  const float* p = a.rest_positions + 3 * v;
  float* out = a.positions + 3 * v;
  for (int r = 0; r < 3; ++r) {
    const float* row = m + 4 * r;
    out[r] = row[0] * p[0] + row[1] * p[1] + row[2] * p[2] + row[3];
  }
  if (a.rest_normals == nullptr || a.normals == nullptr) return;
  const float* n = a.rest_normals + 3 * v;
  float* out_n = a.normals + 3 * v;
  for (int r = 0; r < 3; ++r) {
    const float* row = m + 4 * r;
    out_n[r] = row[0] * n[0] + row[1] * n[1] + row[2] * n[2];
  }
}

void skin_range(const detail::SkinningArrays& a, Range r, bool use_avx2) {
  std::size_t v = r.begin;
  if (use_avx2) {
    const std::size_t simd_end = r.begin + (r.size() / detail::kAvx2Lanes) * detail::kAvx2Lanes;
    detail::skin_range_avx2(a, r.begin, simd_end);
    v = simd_end;
  }
  for (; v < r.end; ++v) skin_vertex_scalar(a, v);
}

#if !SINEW_ESCAPE_SSE
// Ordered comparisons are false for NaN, so a non-finite q (a zero-scale
// bone's inverse) is never "inside"; the explicit finiteness test also
// rejects an infinite q against an unbounded box. Bitwise & instead of &&:
// no short-circuit branches to mispredict when outcomes vary.
bool inside_grown_box(const Vec3& q, const Aabb& box, float tolerance) {
  const bool x = (q.x >= box.lower.x - tolerance) & (q.x <= box.upper.x + tolerance);
  const bool y = (q.y >= box.lower.y - tolerance) & (q.y <= box.upper.y + tolerance);
  const bool z = (q.z >= box.lower.z - tolerance) & (q.z <= box.upper.z + tolerance);
  const bool finite = std::isfinite(q.x) & std::isfinite(q.y) & std::isfinite(q.z);
  return x & y & z & finite;
}
#endif

#if SINEW_ESCAPE_SSE
// A bone's world -> bone transform as four columns (x, y, z, translation),
// lane i of each holding row i: a check's bone-frame position is
// ((c0 x + c1 y) + c2 z) + c3, each lane Affine3::transform_point's
// expression in its order, so the same bits as the scalar check.
struct BoneColumns {
  __m128 c[4];
};

std::vector<BoneColumns> bone_columns(const EscapeCheckInput& e) {
  const std::size_t count = std::min(e.bone_from_world.size(), e.tolerance.size());
  const std::span<const Affine3> bones = e.bone_from_world;
  std::vector<BoneColumns> columns(count);
  for (std::size_t b = 0; b < count; ++b) {
    const Affine3& m = bones[b];
    columns[b].c[0] = _mm_setr_ps(m.rows[0].x, m.rows[1].x, m.rows[2].x, 0.0f);
    columns[b].c[1] = _mm_setr_ps(m.rows[0].y, m.rows[1].y, m.rows[2].y, 0.0f);
    columns[b].c[2] = _mm_setr_ps(m.rows[0].z, m.rows[1].z, m.rows[2].z, 0.0f);
    columns[b].c[3] = _mm_setr_ps(m.rows[0].w, m.rows[1].w, m.rows[2].w, 0.0f);
  }
  return columns;
}

#else
struct BoneColumns {};
std::vector<BoneColumns> bone_columns(const EscapeCheckInput&) { return {}; }
#endif

// Asks for the `lines` cache lines 2 KB past `p`.
template <typename T>
void prefetch_ahead([[maybe_unused]] const T* p, [[maybe_unused]] int lines = 1) {
#if SINEW_ESCAPE_SSE
  constexpr std::size_t kAhead = 2048;
  const char* at = reinterpret_cast<const char*>(p) + kAhead;
  for (int i = 0; i < lines; ++i) _mm_prefetch(at + 64 * i, _MM_HINT_T0);
#endif
}

// Per bone: whether its rigid blocks may skip their checks (EscapeCheckInput::
// rigid_blocks): its world -> bone transform and its tolerance are finite.
std::vector<std::uint8_t> rigid_bones_usable(const EscapeCheckInput& e) {
  std::vector<std::uint8_t> usable(e.rigid_blocks.empty() ? 0 : std::min(e.bone_from_world.size(), e.tolerance.size()));
  for (std::size_t b = 0; b < usable.size(); ++b) {
    usable[b] = is_finite(e.bone_from_world[b]) && std::isfinite(e.tolerance[b]) && e.tolerance[b] >= 0.0f;
  }
  return usable;
}

// Whether the 8 positions from v are finite; then their box.
bool finite_block_box(std::span<const Vec3> positions, std::size_t v, bool avx2, float lower[3], float upper[3]) {
  if (avx2) return detail::finite_block_box_avx2(&positions[v].x, lower, upper);
  Aabb box = Aabb::empty();
  for (std::size_t i = 0; i < detail::kAvx2Lanes; ++i) {
    const Vec3& p = positions[v + i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return false;
    box.extend(p);
  }
  for (int a = 0; a < 3; ++a) {
    lower[a] = box.lower[a];
    upper[a] = box.upper[a];
  }
  return true;
}

// What count_escapes reads and writes over one range. Local copies of the
// spans: the byte stores into `escaped` may alias anything, and locals spare
// the reloads of pointers and sizes after each.
struct EscapeArrays {
  std::span<const std::uint32_t> check_begin;
  std::span<const VertexCheck> checks;
  std::span<const Affine3> bone_from_world;
  std::span<const float> tolerance;
  std::size_t bone_limit = 0;  // the bones with both a transform and a tolerance
  // A bone's checks held to its cluster's boxes, when it has one.
  std::span<const Aabb* const> bone_boxes;
  std::span<const std::uint32_t> check_rank;
  std::span<const BoneColumns> columns;  // bone_columns(e), read by the SSE check
  std::span<const Vec3> positions;
  std::span<std::uint8_t> escaped;

  const Aabb& box_of(const VertexCheck& check, std::size_t c) const {
    if (bone_boxes.empty()) return check.box;
    const Aabb* boxes_of_bone = bone_boxes[check.bone];
    const std::uint32_t rank = check_rank[c];
    return boxes_of_bone != nullptr && rank != kSharedCheckBox ? boxes_of_bone[rank] : check.box;
  }
};

EscapeArrays escape_arrays(const EscapeCheckInput& e, std::span<const BoneColumns> columns,
                           std::span<const Vec3> positions, std::span<std::uint8_t> escaped) {
  EscapeArrays a;
  a.check_begin = e.vertex_check_begin;
  a.checks = e.vertex_checks;
  a.bone_from_world = e.bone_from_world;
  a.tolerance = e.tolerance;
  a.bone_limit = std::min(a.bone_from_world.size(), a.tolerance.size());
  a.bone_boxes = e.check_rank.size() >= a.checks.size() && e.bone_boxes.size() >= a.bone_limit
                     ? e.bone_boxes
                     : std::span<const Aabb* const>{};
  a.check_rank = e.check_rank;
  a.columns = columns;
  a.positions = positions;
  a.escaped = escaped;
  return a;
}

// A range's row of bone boxes (EscapeCheckInput::chunk_bone_boxes), null
// when not asked for.
struct BoneBoxRow {
  Aabb* boxes = nullptr;
  std::size_t bones = 0;
#if SINEW_ESCAPE_SSE
  // The box of the current run of checks against one bone, kept in
  // registers and merged into the bone's box when the bone changes: extending
  // the box in memory check after check made each wait for the last one's
  // store. Each side
  // keeps the earlier value on ties and NaNs, as Aabb::extend does, so the
  // boxes have the same bits.
  std::size_t run_bone = bones;  // none yet
  __m128 run_lower = _mm_set1_ps(std::numeric_limits<float>::infinity());
  __m128 run_upper = _mm_set1_ps(-std::numeric_limits<float>::infinity());

  void end_run() {
    if (run_bone >= bones) return;
    alignas(16) float lower[4];
    alignas(16) float upper[4];
    _mm_store_ps(lower, run_lower);
    _mm_store_ps(upper, run_upper);
    boxes[run_bone].extend(Aabb{Vec3(lower[0], lower[1], lower[2]), Vec3(upper[0], upper[1], upper[2])});
    run_bone = bones;
    run_lower = _mm_set1_ps(std::numeric_limits<float>::infinity());
    run_upper = _mm_set1_ps(-std::numeric_limits<float>::infinity());
  }
  // Grows `bone`'s run by the box [lower, upper] (x, y, z, 0 each).
  // min_ps(a, b) is a < b ? a : b: the run's side stays on ties and NaNs.
  void extend_run(std::size_t bone, __m128 lower, __m128 upper) {
    if (bone != run_bone) {
      end_run();
      run_bone = bone;
    }
    run_lower = _mm_min_ps(lower, run_lower);
    run_upper = _mm_max_ps(upper, run_upper);
  }
#endif
};

// The row of range `r`, emptied, when asked for and sized as documented.
BoneBoxRow bone_box_row(const EscapeCheckInput& e, Range r) {
  const std::size_t bones = e.bone_from_world.size();
  const std::size_t row = r.begin / kChunkVertices;
  Aabb* const boxes = e.chunk_bone_boxes.size() >= (row + 1) * bones && bones > 0
                          ? e.chunk_bone_boxes.data() + row * bones
                          : nullptr;
  if (boxes != nullptr) std::fill(boxes, boxes + bones, Aabb::empty());
  return BoneBoxRow{boxes, bones};
}

// Vertex v's checks one by one (a vertex no block check took): their flags
// written, its position grown into their bones' boxes; returns how many
// escaped. Inlined into count_escapes's loop, where the row's run stays in
// registers from vertex to vertex.
[[gnu::always_inline]] inline std::size_t check_vertex(const EscapeArrays& a, BoneBoxRow& row, std::size_t v) {
  const std::size_t first = std::min<std::size_t>(a.check_begin[v], a.checks.size());
  const std::size_t last = std::min<std::size_t>(a.check_begin[v + 1], a.checks.size());
  const Vec3 world = a.positions[v];
#if SINEW_ESCAPE_SSE
  // Four lanes per check (x, y, z and a spare), about a quarter of the
  // scalar check's instructions: the check is per vertex and per bone, and
  // at 855,552 triangles it was as long as the skinning itself.
  const __m128 x = _mm_set1_ps(world.x), y = _mm_set1_ps(world.y), z = _mm_set1_ps(world.z);
  const auto inside = [&](const VertexCheck& check, const Aabb& box) {
    const BoneColumns& m = a.columns[check.bone];
    const __m128 q =
        _mm_add_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(m.c[0], x), _mm_mul_ps(m.c[1], y)), _mm_mul_ps(m.c[2], z)),
                   m.c[3]);
    const __m128 tol = _mm_set1_ps(a.tolerance[check.bone]);
    // The box's lower corner, and its upper one read from lower.z on (in
    // bounds), moved down a lane.
    const __m128 lower = _mm_loadu_ps(&box.lower.x);
    const __m128 from_z = _mm_loadu_ps(&box.lower.z);
    const __m128 upper = _mm_shuffle_ps(from_z, from_z, _MM_SHUFFLE(3, 3, 2, 1));
    const __m128 in = _mm_and_ps(
        _mm_and_ps(_mm_cmpge_ps(q, _mm_sub_ps(lower, tol)), _mm_cmple_ps(q, _mm_add_ps(upper, tol))),
        _mm_cmpeq_ps(_mm_sub_ps(q, q), _mm_setzero_ps()));
    return (_mm_movemask_ps(in) & 7) == 7;
  };
#else
  const auto inside = [&](const VertexCheck& check, const Aabb& box) {
    return inside_grown_box(a.bone_from_world[check.bone].transform_point(world), box, a.tolerance[check.bone]);
  };
#endif
#if SINEW_ESCAPE_SSE
  const __m128 point = _mm_setr_ps(world.x, world.y, world.z, 0.0f);
  const auto extend_box = [&](std::size_t bone) { row.extend_run(bone, point, point); };
#else
  const auto extend_box = [&](std::size_t bone) { row.boxes[bone].extend(world); };
#endif
  std::size_t count = 0;
  for (std::size_t c = first; c < last; ++c) {
    const VertexCheck& check = a.checks[c];
    if (row.boxes != nullptr && check.bone < row.bones) extend_box(check.bone);
    // A check naming a bone without a transform or tolerance escapes.
    const bool out = check.bone >= a.bone_limit || !inside(check, a.box_of(check, c));
    count += static_cast<std::size_t>(out);
    if (c < a.escaped.size()) a.escaped[c] = static_cast<std::uint8_t>(out);
  }
  return count;
}

// `columns`: bone_columns(e); `rigid_usable`: rigid_bones_usable(e);
// `blocks`: whether the AVX2 block check may run.
std::size_t count_escapes(const EscapeCheckInput& e, std::span<const BoneColumns> columns,
                          std::span<const std::uint8_t> rigid_usable, std::span<const Vec3> positions,
                          std::span<std::uint8_t> escaped, Range r, bool blocks) {
  const EscapeArrays a = escape_arrays(e, columns, positions, escaped);
  const std::size_t end = std::min(r.end, a.check_begin.empty() ? 0 : a.check_begin.size() - 1);
  BoneBoxRow row = bone_box_row(e, r);

  std::size_t count = 0;
  constexpr std::size_t kBlock = detail::kAvx2Lanes;
  static_assert(kBlock == kRigidBlockVertices);
  // A checked block's flags (bit i: check c0 + i escaped) and its positions'
  // box, grown into its bone's.
  const auto finish_block = [&](std::size_t c0, std::uint32_t flags, std::uint32_t bone, const float lower[3],
                                const float upper[3]) {
    for (std::size_t i = 0; i < kBlock; ++i) {
      const std::uint8_t out = static_cast<std::uint8_t>((flags >> i) & 1u);
      count += out;
      if (c0 + i < a.escaped.size()) a.escaped[c0 + i] = out;
    }
    if (row.boxes == nullptr) return;
#if SINEW_ESCAPE_SSE
    row.extend_run(bone, _mm_setr_ps(lower[0], lower[1], lower[2], 0.0f),
                   _mm_setr_ps(upper[0], upper[1], upper[2], 0.0f));
#else
    row.boxes[bone].extend(Aabb{Vec3(lower[0], lower[1], lower[2]), Vec3(upper[0], upper[1], upper[2])});
#endif
  };
  // A block whose checks hold by construction (rigid_checks.h): only its
  // positions' finiteness and box are computed, its flags are 0. Its bone's
  // checks read nothing of the check arrays but the first begin and the
  // one past the block's end.
  const std::span<const std::uint16_t> rigid = e.rigid_blocks;
  const auto rigid_block = [&](std::size_t v) -> bool {
    const std::size_t block = v / kBlock;
    if (block >= rigid.size()) return false;
    const std::uint16_t bone = rigid[block];
    if (bone >= rigid_usable.size() || !rigid_usable[bone]) return false;
    const std::size_t c0 = a.check_begin[v];
    if (a.check_begin[v + kBlock] != c0 + kBlock || c0 + kBlock > a.checks.size()) return false;
    float lower[3];
    float upper[3];
    if (!finite_block_box(a.positions, v, blocks, lower, upper)) return false;
    finish_block(c0, 0, bone, lower, upper);
    return true;
  };
  // Eight vertices with one check each, all against one bone, are checked
  // eight at a time (the AVX2 block check: most blocks of a fine mesh);
  // other blocks, and blocks with a position that is not finite, go
  // check by check (check_vertex).
  const auto check_block = [&](std::size_t v) -> bool {
    const std::size_t c0 = a.check_begin[v];
    if (c0 + kBlock > a.checks.size()) return false;
    const std::uint32_t bone = a.checks[c0].bone;
    if (bone >= a.bone_limit) return false;
    // The arrays this reads stream in vertex order but each address waits
    // for the load before it (begin, check, rank, cluster box), so they are
    // prefetched 2 KB ahead.
    prefetch_ahead(a.check_begin.data() + v);
    prefetch_ahead(a.checks.data() + c0, 4);
    if (!a.bone_boxes.empty() && a.bone_boxes[bone] != nullptr) {
      prefetch_ahead(a.check_rank.data() + c0);
      const std::uint32_t rank = a.check_rank[c0];
      if (rank != kSharedCheckBox) prefetch_ahead(a.bone_boxes[bone] + rank, 3);
    }
    const float* lane_boxes[kBlock];
    for (std::size_t i = 0; i < kBlock; ++i) {
      if (a.check_begin[v + i + 1] != c0 + i + 1 || a.checks[c0 + i].bone != bone) return false;
      lane_boxes[i] = &a.box_of(a.checks[c0 + i], c0 + i).lower.x;
    }
    float lower[3];
    float upper[3];
    const std::uint32_t result = detail::escape_block_avx2(&a.positions[v].x, &a.bone_from_world[bone].rows[0].x,
                                                           a.tolerance[bone], lane_boxes, lower, upper);
    if ((result & detail::kEscapeBlockFinite) == 0) return false;
    finish_block(c0, result & 0xFFu, bone, lower, upper);
    return true;
  };
  for (std::size_t v = r.begin; v < end; ++v) {
    if (v % kBlock == 0 && v + kBlock <= end && (rigid_block(v) || (blocks && check_block(v)))) {
      v += kBlock - 1;
      continue;
    }
    count += check_vertex(a, row, v);
  }
#if SINEW_ESCAPE_SSE
  row.end_run();
#endif
  return count;
}

std::size_t skinnable_vertex_count(const SkinnedMesh& mesh, const PackedInfluences& influences,
                                   const SkinningTargets& targets) {
  return std::min({mesh.positions.size(), influences.vertex_count,
                   influences.group_count() * kInfluenceGroupLanes, targets.positions.size()});
}

detail::SkinningArrays flat_arrays(const SkinnedMesh& mesh, const PackedInfluences& influences,
                                   std::span<const Affine3> bones, const SkinningTargets& targets,
                                   std::size_t vertex_count) {
  detail::SkinningArrays a;
  a.rest_positions = reinterpret_cast<const float*>(mesh.positions.data());
  a.group_slot_begin = influences.group_slot_begin.data();
  a.slot_joints = influences.joints.data();
  a.slot_weights = influences.weights.data();
  static_assert(kNoGroupBone == 0xFFFF, "the kernels see group_bone as raw 16-bit values (skinning_kernels.h)");
  a.group_bone = influences.group_bone.size() >= influences.group_count() ? influences.group_bone.data() : nullptr;
  a.bones = reinterpret_cast<const float*>(bones.data());
  a.positions = reinterpret_cast<float*>(targets.positions.data());
  const bool normals = mesh.normals.size() >= vertex_count && targets.normals.size() >= vertex_count &&
                       !mesh.normals.empty() && !targets.normals.empty();
  if (normals) {
    a.rest_normals = reinterpret_cast<const float*>(mesh.normals.data());
    a.normals = reinterpret_cast<float*>(targets.normals.data());
  }
  return a;
}

}  // namespace

bool avx2_skinning_available() {
#if defined(__x86_64__) || defined(__i386__)
  static const bool available = detail::avx2_kernel_compiled() && __builtin_cpu_supports("avx2") &&
                                __builtin_cpu_supports("fma");
  return available;
#else
  return false;
#endif
}

SkinningResult skin_vertices(const SkinnedMesh& mesh, std::span<const Affine3> bones,
                             const SkinningTargets& targets, const EscapeCheckInput* escape,
                             JobSystem* jobs, SkinningPath path) {
  return skin_vertices(mesh, pack_influences(mesh), bones, targets, escape, jobs, path);
}

SkinningResult skin_vertices(const SkinnedMesh& mesh, const PackedInfluences& influences,
                             std::span<const Affine3> bones, const SkinningTargets& targets,
                             const EscapeCheckInput* escape, JobSystem* jobs, SkinningPath path) {
  SkinningResult result;
  const bool use_avx2 = path != SkinningPath::kScalar && avx2_skinning_available();
  result.path_used = use_avx2 ? SkinningPath::kAvx2 : SkinningPath::kScalar;

  const std::size_t vertex_count = skinnable_vertex_count(mesh, influences, targets);
  if (vertex_count == 0) return result;
  const detail::SkinningArrays arrays = flat_arrays(mesh, influences, bones, targets, vertex_count);
  const std::span<const Vec3> positions = targets.positions;

  // One escape count per chunk, summed in chunk order afterwards: no atomics
  // in the loop and the same total whatever the thread count.
  const std::size_t chunk_count = (vertex_count + kChunkVertices - 1) / kChunkVertices;
  std::vector<std::size_t> chunk_escapes(escape != nullptr ? chunk_count : 0, 0);
  const std::vector<BoneColumns> columns = escape != nullptr ? bone_columns(*escape) : std::vector<BoneColumns>{};
  const std::vector<std::uint8_t> rigid_usable =
      escape != nullptr ? rigid_bones_usable(*escape) : std::vector<std::uint8_t>{};

  const auto run_chunk = [&](Range r) {
    skin_range(arrays, r, use_avx2);
    if (escape != nullptr) {
      chunk_escapes[r.begin / kChunkVertices] =
          count_escapes(*escape, columns, rigid_usable, positions, targets.escaped, r, use_avx2);
    }
  };
  if (jobs != nullptr) {
    jobs->parallel_for(0, vertex_count, kChunkVertices, run_chunk);
  } else {
    for (std::size_t begin = 0; begin < vertex_count; begin += kChunkVertices) {
      run_chunk(Range{begin, std::min(vertex_count, begin + kChunkVertices)});
    }
  }
  result.escaped_checks = std::accumulate(chunk_escapes.begin(), chunk_escapes.end(), std::size_t{0});
  return result;
}

std::size_t check_escapes(const EscapeCheckInput& escape, std::span<const Vec3> positions,
                          std::span<std::uint8_t> escaped, JobSystem* jobs) {
  const std::size_t vertex_count =
      std::min(positions.size(), escape.vertex_check_begin.empty() ? 0 : escape.vertex_check_begin.size() - 1);
  const std::size_t chunk_count = (vertex_count + kChunkVertices - 1) / kChunkVertices;
  std::vector<std::size_t> chunk_escapes(chunk_count, 0);
  const std::vector<BoneColumns> columns = bone_columns(escape);
  const std::vector<std::uint8_t> rigid_usable = rigid_bones_usable(escape);
  const bool blocks = avx2_skinning_available();
  const auto run_chunk = [&](Range r) {
    chunk_escapes[r.begin / kChunkVertices] =
        count_escapes(escape, columns, rigid_usable, positions, escaped, r, blocks);
  };
  if (jobs != nullptr) {
    jobs->parallel_for(0, vertex_count, kChunkVertices, run_chunk);
  } else {
    for (std::size_t begin = 0; begin < vertex_count; begin += kChunkVertices) {
      run_chunk(Range{begin, std::min(vertex_count, begin + kChunkVertices)});
    }
  }
  return std::accumulate(chunk_escapes.begin(), chunk_escapes.end(), std::size_t{0});
}

}  // namespace sinew::rt
