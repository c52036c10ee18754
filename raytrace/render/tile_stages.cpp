#include "raytrace/render/tile_stages.h"

#if defined(__AVX2__)
#include <immintrin.h>
#endif

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "raytrace/render/large_packet.h"
#include "raytrace/render/static_tiles.h"
#include "raytrace/render/packet_traversal.h"
#include "raytrace/render/ray_bound.h"
#include "raytrace/render/srgb.h"
#include "raytrace/render/srgb_encode.h"
#include "raytrace/render/traversal.h"
#include "raytrace/render/traversal_shared.h"
#include "runtime/math/float8.h"

namespace sinew::rt {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// pbrt's gamma(n): a bound on n successive float roundings.
constexpr float gamma(int n) {
  constexpr float u = std::numeric_limits<float>::epsilon() * 0.5f;
  return (static_cast<float>(n) * u) / (1.0f - static_cast<float>(n) * u);
}

// Eight RGBA8 pixels, R in the low byte, alpha 255.
[[gnu::always_inline]] inline void srgb_pixels(const Vec3x8& linear, std::uint32_t* out) {
#if SINEW_FLOAT8_AVX2
  const auto bytes = [](Float8 x) { return _mm256_cvttps_epi32(srgb_steps(x).v); };
  const __m256i rgba = _mm256_or_si256(
      _mm256_or_si256(bytes(linear.x), _mm256_slli_epi32(bytes(linear.y), 8)),
      _mm256_or_si256(_mm256_slli_epi32(bytes(linear.z), 16), _mm256_set1_epi32(static_cast<int>(0xFF000000u))));
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(out), rgba);
#else
  alignas(32) std::int32_t r[8], g[8], b[8];
  store_truncated(srgb_steps(linear.x), r);
  store_truncated(srgb_steps(linear.y), g);
  store_truncated(srgb_steps(linear.z), b);
  for (int i = 0; i < 8; ++i) {
    out[i] = static_cast<std::uint32_t>(r[i]) | static_cast<std::uint32_t>(g[i]) << 8 |
             static_cast<std::uint32_t>(b[i]) << 16 | 0xFF000000u;
  }
#endif
}

// Bit i: bit l of lit[i], for eight bytes (each lane's bit gathered into
// the top byte by one multiply: no two partial products overlap).
std::uint32_t lane_bits(const std::uint8_t* lit, int l) {
  std::uint64_t word;
  std::memcpy(&word, lit, sizeof word);
  return static_cast<std::uint32_t>((((word >> l) & 0x0101010101010101ull) * 0x0102040810204080ull) >> 56);
}

// The next float from x away from zero offsets: towards +inf where
// offset > 0, towards -inf where offset < 0, x itself where offset is 0 or
// x is not finite (offset_origin's next_float step, eight lanes).
Float8 step_away(Float8 x, Float8 offset) {
#if SINEW_FLOAT8_AVX2
  const __m256i bits = _mm256_castps_si256(x.v);
  const Mask8 up = offset > Float8(0.0f);
  const Mask8 down = offset < Float8(0.0f);
  const Mask8 positive = x > Float8(0.0f);
  // (x > 0) == up: one ulp up in magnitude, else down.
  const __m256 grow = _mm256_xor_ps(_mm256_xor_ps(positive.m, up.m), _mm256_castsi256_ps(_mm256_set1_epi32(-1)));
  const __m256i delta = _mm256_blendv_epi8(_mm256_set1_epi32(-1), _mm256_set1_epi32(1), _mm256_castps_si256(grow));
  Float8 stepped{_mm256_castsi256_ps(_mm256_add_epi32(bits, delta))};
  const Float8 denorm = std::numeric_limits<float>::denorm_min();
  stepped = select(x == Float8(0.0f), select(up, denorm, -denorm), stepped);
  return select((up | down) & is_finite(x), stepped, x);
#else
  return Float8::map([&](int i) {
    const float v = x.v[i];
    const float o = offset.v[i];
    if (o == 0.0f || !std::isfinite(v)) return v;
    const bool up = o > 0.0f;
    if (v == 0.0f) return up ? std::numeric_limits<float>::denorm_min() : -std::numeric_limits<float>::denorm_min();
    std::uint32_t b = std::bit_cast<std::uint32_t>(v);
    b = (v > 0.0f) == up ? b + 1 : b - 1;
    return std::bit_cast<float>(b);
  });
#endif
}

Vec3x8 load3(const std::vector<float>& x, const std::vector<float>& y, const std::vector<float>& z, std::size_t k) {
  return {Float8::load(&x[k]), Float8::load(&y[k]), Float8::load(&z[k])};
}
void store3(const Vec3x8& v, std::vector<float>& x, std::vector<float>& y, std::vector<float>& z, std::size_t k) {
  v.x.store(&x[k]);
  v.y.store(&y[k]);
  v.z.store(&z[k]);
}

// Per-thread lists of the objects a tile's and a packet's rays may enter.
struct CullLists {
  std::vector<std::uint32_t> tile;
  std::vector<std::uint32_t> packet;
};
CullLists& cull_lists() {
  thread_local CullLists lists;
  return lists;
}

// What shading reads of the mesh behind one hit instance.
struct MeshRefs {
  std::span<const std::array<std::uint32_t, 3>> triangles;
  std::span<const Vec3> positions;  // world space (skinned for characters)
  std::span<const Vec3> normals;    // empty: none
  std::span<const std::uint32_t> triangle_material;
  std::span<const Vec3> material_colors;
  bool is_static = false;
};

MeshRefs mesh_refs(const Scene& scene, const Scene::ObjectSlot& slot) {
  MeshRefs r;
  if (slot.kind == Scene::ObjectKind::kCharacter) {
    const InstanceFrame& frame = scene.instances()[slot.index];
    const SkinnedMesh& mesh = *scene.characters()[frame.character].mesh;
    r.triangles = mesh.triangles;
    r.positions = frame.positions;
    r.normals = frame.normals;
    r.triangle_material = mesh.triangle_material;
    r.material_colors = mesh.material_colors;
  } else {
    const StaticMeshDesc& mesh = scene.static_meshes()[slot.index].desc;
    r.triangles = mesh.triangles;
    r.positions = mesh.positions;
    r.triangle_material = mesh.triangle_material;
    r.material_colors = mesh.material_colors;
    r.is_static = true;
  }
  return r;
}

// Each lane's corners, corner normals and albedo (lanes without a hit get a
// harmless unit triangle). Returns true when every lane hit one triangle,
// loaded once and broadcast.
bool gather_lanes(const Scene& scene, const TileScratch& s, std::size_t k0, std::uint32_t hits,
                  const Vec3& default_albedo, float (&p)[3][3][8], float (&n)[3][3][8], float (&albedo)[3][8],
                  std::uint32_t& with_normals, std::uint32_t& on_character) {
  const std::span<const Scene::ObjectSlot> slots = scene.object_slots();
  // One triangle under the whole block (most blocks of a ground or of a
  // close-up): load it once and broadcast it.
  if (hits == 0xFFu && (lanes_equal(&s.triangle[k0], s.triangle[k0]) & lanes_equal(&s.instance[k0], s.instance[k0])) ==
                           0xFFu) {
    const std::size_t k = k0;
    const MeshRefs mesh = mesh_refs(scene, slots[s.instance[k]]);
    const std::uint32_t tri = s.triangle[k];
    const auto& v = mesh.triangles[tri];
    const bool normals = !mesh.normals.empty();
    for (int i = 0; i < 3; ++i) {
      const Vec3& c = mesh.positions[v[static_cast<std::size_t>(i)]];
      const Vec3 nn = normals ? mesh.normals[v[static_cast<std::size_t>(i)]] : Vec3(0.0f);
      for (int a = 0; a < 3; ++a) {
        Float8(c[a]).store(p[i][a]);
        Float8(nn[a]).store(n[i][a]);
      }
    }
    if (normals) with_normals = 0xFFu;
    if (!mesh.is_static) on_character = 0xFFu;
    const std::uint32_t m = tri < mesh.triangle_material.size() ? mesh.triangle_material[tri]
                            : mesh.is_static                     ? 0u
                                                                 : kInvalidId;
    const Vec3 color = m < mesh.material_colors.size() ? mesh.material_colors[m] : default_albedo;
    for (int a = 0; a < 3; ++a) Float8(color[a]).store(albedo[a]);
    return true;
  }
  // Triangle by triangle: a block's lanes mostly hit one to three, so each
  // distinct triangle's corners, normals and colour are loaded once and
  // blended into its lanes (lane by lane cost eight scalar stores of
  // each). Lanes without a hit keep a harmless unit triangle.
  Float8 pc[3][3], nc[3][3], color[3];
  for (int i = 0; i < 3; ++i) {
    for (int a = 0; a < 3; ++a) {
      pc[i][a] = Float8(i == a + 1 ? 1.0f : 0.0f);
      nc[i][a] = Float8(0.0f);
    }
  }
  for (int a = 0; a < 3; ++a) color[a] = Float8(default_albedo[a]);
  for (std::uint32_t left = hits; left != 0;) {
    const std::size_t k = k0 + static_cast<std::size_t>(std::countr_zero(left));
    const std::uint32_t tri = s.triangle[k], instance = s.instance[k];
    const std::uint32_t same = lanes_equal(&s.triangle[k0], tri) & lanes_equal(&s.instance[k0], instance) & left;
    left &= ~same;
    const Mask8 use = Mask8::from_bits(same);
    const MeshRefs mesh = mesh_refs(scene, slots[instance]);
    const auto& v = mesh.triangles[tri];
    if (!mesh.is_static) on_character |= same;
    for (int i = 0; i < 3; ++i) {
      const Vec3& c = mesh.positions[v[static_cast<std::size_t>(i)]];
      for (int a = 0; a < 3; ++a) pc[i][a] = select(use, Float8(c[a]), pc[i][a]);
    }
    if (!mesh.normals.empty()) {
      for (int i = 0; i < 3; ++i) {
        const Vec3& nn = mesh.normals[v[static_cast<std::size_t>(i)]];
        for (int a = 0; a < 3; ++a) nc[i][a] = select(use, Float8(nn[a]), nc[i][a]);
      }
      with_normals |= same;
    }
    // Characters without per-triangle materials use the default albedo;
    // static meshes without them use material 0.
    const std::uint32_t m = tri < mesh.triangle_material.size() ? mesh.triangle_material[tri]
                            : mesh.is_static                     ? 0u
                                                                 : kInvalidId;
    if (m < mesh.material_colors.size()) {
      for (int a = 0; a < 3; ++a) color[a] = select(use, Float8(mesh.material_colors[m][a]), color[a]);
    }
  }
  for (int i = 0; i < 3; ++i) {
    for (int a = 0; a < 3; ++a) {
      pc[i][a].store(p[i][a]);
      nc[i][a].store(n[i][a]);
    }
  }
  for (int a = 0; a < 3; ++a) color[a].store(albedo[a]);
  return false;
}

// Of the tile's objects, those `packet` may enter, into lists.packet. With
// one object for the whole tile the packet's own cull could only drop it,
// which the object's box clip does as cheaply.
void cull_for_packet(const Scene& scene, const RayPacket& packet, CullLists& lists) {
  lists.packet.clear();
  if (lists.tile.size() == 1) {
    lists.packet.push_back(lists.tile[0]);
    return;
  }
  const float* const o[3] = {packet.ox, packet.oy, packet.oz};
  const float* const d[3] = {packet.dx, packet.dy, packet.dz};
  cull_objects_for_packet(scene, o, d, packet.t_min, packet.t_max, packet.active, lists.tile, lists.packet);
}

// A packet query's work added to the tile's (rays are counted by the caller).
void add_work(TraversalCounters& into, const TraversalCounters& from) {
  into.node_visits += from.node_visits;
  into.object_visits += from.object_visits;
  into.triangle_tests += from.triangle_tests;
}

void set_miss(TileScratch& s, std::size_t k) {
  s.t[k] = kInf;
  s.u[k] = 0.0f;
  s.v[k] = 0.0f;
  s.triangle[k] = kInvalidId;
  s.instance[k] = kInvalidId;
}

}  // namespace

TileCone camera_tile_cone(const PinholeCamera& camera, const Tile& tile) {
  const float x0 = static_cast<float>(tile.x0) + 0.5f, x1 = static_cast<float>(tile.x1) - 0.5f;
  const float y0 = static_cast<float>(tile.y0) + 0.5f, y1 = static_cast<float>(tile.y1) - 0.5f;
  alignas(32) const float xs[8] = {x0, x1, x0, x1, x0, x1, x0, x1};
  alignas(32) const float ys[8] = {y0, y0, y1, y1, y0, y0, y1, y1};
  alignas(32) float q[3][8];
  const Vec3x8 d = camera.directions_at(Float8::load(xs), Float8::load(ys));
  d.x.store(q[0]);
  d.y.store(q[1]);
  d.z.store(q[2]);
  Vec3 corners[4];
  for (int i = 0; i < 4; ++i) corners[i] = Vec3(q[0][i], q[1][i], q[2][i]);
  return TileCone(camera.eye(), corners, 4);
}

TileCone shadow_tile_cone(const TileScratch& s) {
  if (!s.shadows_from_point || !(s.shadow_ends.lower.x <= s.shadow_ends.upper.x)) return {};
  Vec3 corners[8];
  for (int corner = 0; corner < 8; ++corner) {
    for (int a = 0; a < 3; ++a) {
      const float end = (corner >> a & 1) ? s.shadow_ends.upper[a] : s.shadow_ends.lower[a];
      corners[corner][a] = end - s.shadow_origin[a];
    }
  }
  return TileCone(s.shadow_origin, corners, 8);
}

void TileScratch::prepare(const Tile& area, int region_blocks_x, int region_blocks_y) {
  tile = area;
  shadow_placed = 0;
  shadows_compacted = true;
  shadow_count = 0;
  shadow_region_begin.clear();
  shadows_from_point = false;
  shadows_aimed_only = false;
  const int width = area.x1 - area.x0, height = area.y1 - area.y0;
  const int rx = std::max(1, region_blocks_x), ry = std::max(1, region_blocks_y);
  if (width == layout_width_ && height == layout_height_ && rx == layout_region_x_ && ry == layout_region_y_) {
    std::fill_n(block_hits.begin(), blocks(), std::uint8_t{0});
    std::fill_n(block_on_character.begin(), blocks(), std::uint8_t{0});
    return;
  }
  layout_width_ = width;
  layout_height_ = height;
  layout_region_x_ = rx;
  layout_region_y_ = ry;
  blocks_x = (width + kBlockWidth - 1) / kBlockWidth;
  blocks_y = (height + kBlockHeight - 1) / kBlockHeight;
  const std::size_t blocks = static_cast<std::size_t>(blocks_x) * static_cast<std::size_t>(blocks_y);
  lanes = blocks * kBlockLanes;
  if (block_pixels.size() < blocks) {
    block_pixels.resize(blocks);
    block_hits.resize(blocks);
    block_on_character.resize(blocks);
    shadow_lanes.resize(blocks);
    block_dx.resize(blocks);
    block_dy.resize(blocks);
  }
  // One spare group: a region's shadow rays start anywhere in the compacted
  // arrays and are read a whole group at a time, and the sRGB encoding
  // reads and writes pairs of blocks.
  static_assert(kSrgbEncodeLanes == 2 * kBlockLanes);
  const std::size_t arrays = lanes + kBlockLanes;
  if (capacity_ < arrays) {
    for (std::vector<float>* a : {&dir_x, &dir_y, &dir_z, &t, &u, &v, &px, &py, &pz, &gx, &gy, &gz, &nx, &ny,
                                  &nz, &ar, &ag, &ab, &error, &so_x, &so_y, &so_z, &sd_x, &sd_y, &sd_z, &s_tmax,
                                  &shadow_lane_x, &shadow_lane_y, &shadow_lane_z, &shadow_push_x,
                                  &shadow_push_y, &shadow_push_z, &lr, &lg, &lb}) {
      a->resize(arrays);
    }
    triangle.resize(arrays);
    instance.resize(arrays);
    rgba8.resize(arrays);
    lit.resize(arrays);
    shadow_pixel.resize(arrays);
    capacity_ = arrays;
  }
  region_begin.clear();
  std::size_t b = 0;
  for (int y0 = 0; y0 < blocks_y; y0 += ry) {
    for (int x0 = 0; x0 < blocks_x; x0 += rx) {
      region_begin.push_back(static_cast<std::uint32_t>(b));
      for (int y = y0; y < std::min(blocks_y, y0 + ry); ++y) {
        for (int x = x0; x < std::min(blocks_x, x0 + rx); ++x, ++b) {
          const int dx = x * kBlockWidth;
          const int dy = y * kBlockHeight;
          block_dx[b] = dx;
          block_dy[b] = dy;
          const int w = std::min(kBlockWidth, width - dx);
          const int h = std::min(kBlockHeight, height - dy);
          const std::uint32_t row = (1u << w) - 1u;
          block_pixels[b] = static_cast<std::uint8_t>(h == 2 ? row | (row << kBlockWidth) : row);
          block_hits[b] = 0;
          block_on_character[b] = 0;
        }
      }
    }
  }
  region_begin.push_back(static_cast<std::uint32_t>(b));
}

void generate_camera_rays(const PinholeCamera& camera, TileScratch& s) {
  // Each column's and each row's offset once per tile (pixel centres,
  // integer + 0.5, exact in float, as PinholeCamera::ray), out to the
  // blocks' edges.
  thread_local std::vector<float> columns, rows;
  columns.resize(static_cast<std::size_t>(s.blocks_x) * kBlockWidth);
  rows.resize(static_cast<std::size_t>(s.blocks_y) * kBlockHeight);
  for (std::size_t i = 0; i < columns.size(); ++i) {
    columns[i] = camera.right_offset(static_cast<float>(s.tile.x0 + static_cast<int>(i)) + 0.5f);
  }
  for (std::size_t i = 0; i < rows.size(); ++i) {
    rows[i] = camera.up_offset(static_cast<float>(s.tile.y0 + static_cast<int>(i)) + 0.5f);
  }
  for (std::size_t b = 0; b < s.blocks(); ++b) {
    // Lane i sits at (i % 4, i / 4) in its block.
    const float* const a = &columns[static_cast<std::size_t>(s.block_dx[b])];
    const float* const r = &rows[static_cast<std::size_t>(s.block_dy[b])];
#if SINEW_FLOAT8_AVX2
    const Float8 right{_mm256_broadcast_ps(reinterpret_cast<const __m128*>(a))};
    const Float8 up{_mm256_insertf128_ps(_mm256_set1_ps(r[0]), _mm_set1_ps(r[1]), 1)};
#else
    const Float8 right = Float8::map([&](int i) { return a[i % kBlockWidth]; });
    const Float8 up = Float8::map([&](int i) { return r[i / kBlockWidth]; });
#endif
    store3(camera.directions_from(right, up), s.dir_x, s.dir_y, s.dir_z, b * kBlockLanes);
  }
}

namespace {

// Ray arrays every large packet of primary rays shares: the eye, t in [0, inf).
struct PrimaryLanes {
  alignas(32) float o[3][kMaxPacketGroups * kBlockLanes];
  alignas(32) float t_min[kMaxPacketGroups * kBlockLanes];
  alignas(32) float t_max[kMaxPacketGroups * kBlockLanes];
  Vec3 eye{std::numeric_limits<float>::quiet_NaN()};
  PrimaryLanes() {
    std::fill(std::begin(t_min), std::end(t_min), 0.0f);
    std::fill(std::begin(t_max), std::end(t_max), kInf);
  }
  void set_eye(const Vec3& e) {
    if (e.x == eye.x && e.y == eye.y && e.z == eye.z) return;
    eye = e;
    for (int a = 0; a < 3; ++a) std::fill(std::begin(o[a]), std::end(o[a]), e[a]);
  }
};

// One large packet per region: its blocks are consecutive in `s`.
void trace_primary_large(const Scene& scene, const PinholeCamera& camera, TriangleTest test,
                         const std::vector<std::uint32_t>& objects, TileScratch& s, TraversalCounters& counters) {
  thread_local PrimaryLanes shared;
  shared.set_eye(camera.eye());
  for (std::size_t r = 0; r < s.regions(); ++r) {
    const std::size_t b0 = s.region_begin[r], b1 = s.region_begin[r + 1];
    const std::size_t k0 = b0 * kBlockLanes;
    for (std::size_t b = b0; b < b1; ++b) counters.rays += static_cast<std::uint64_t>(std::popcount(s.block_pixels[b]));
    if (objects.empty()) {
      for (std::size_t k = k0; k < b1 * kBlockLanes; ++k) set_miss(s, k);
      for (std::size_t b = b0; b < b1; ++b) s.block_hits[b] = 0;
      continue;
    }
    LargePacketRays rays;
    rays.groups = static_cast<int>(b1 - b0);
    for (int a = 0; a < 3; ++a) rays.o[a] = shared.o[a];
    rays.d[0] = &s.dir_x[k0];
    rays.d[1] = &s.dir_y[k0];
    rays.d[2] = &s.dir_z[k0];
    rays.t_min = shared.t_min;
    rays.t_max = shared.t_max;
    rays.active = &s.block_pixels[b0];
    rays.grid_columns = static_cast<int>(s.region_columns(r));
    rays.grid_forward = camera.forward();
    rays.grid_right = camera.right();
    rays.grid_up = camera.up();
    rays.clip_leaf_lanes = s.clip_leaf_lanes;
    TraversalCounters work;
    intersect_large_packet(scene, rays, test, objects,
                           PacketHits{&s.t[k0], &s.u[k0], &s.v[k0], &s.triangle[k0], &s.instance[k0]}, &work);
    add_work(counters, work);
    for (std::size_t b = b0; b < b1; ++b) {
      std::uint32_t hit_bits = 0;
      for (int lane = 0; lane < kBlockLanes; ++lane) {
        hit_bits |= s.triangle[b * kBlockLanes + static_cast<std::size_t>(lane)] != kInvalidId ? (1u << lane) : 0u;
      }
      s.block_hits[b] = static_cast<std::uint8_t>(hit_bits & s.block_pixels[b]);
    }
  }
}

// One large packet per region's run of shadow rays.
std::uint64_t trace_shadow_large(const Scene& scene, TriangleTest test, const std::vector<std::uint32_t>& objects,
                                 int l, TileScratch& s, TraversalCounters& counters) {
  static const std::vector<float> zeros(kMaxPacketGroups * kBlockLanes, 0.0f);
  const std::uint8_t dark = static_cast<std::uint8_t>(~(1u << l));
  std::uint64_t blocked_count = 0;
  std::array<std::uint8_t, kMaxPacketGroups> active{}, blocked{};
  for (std::size_t r = 0; r + 1 < s.shadow_region_begin.size(); ++r) {
    const std::size_t i0 = s.shadow_region_begin[r], i1 = s.shadow_region_begin[r + 1];
    counters.rays += i1 - i0;
    if (objects.empty()) continue;
    for (std::size_t i = i0; i < i1; i += kBlockLanes) {
      const std::size_t n = std::min<std::size_t>(kBlockLanes, i1 - i);
      const std::size_t g = (i - i0) / kBlockLanes;
      active[g] = static_cast<std::uint8_t>((1u << n) - 1u);
    }
    LargePacketRays rays;
    rays.groups = static_cast<int>((i1 - i0 + kBlockLanes - 1) / kBlockLanes);
    rays.o[0] = &s.so_x[i0];
    rays.o[1] = &s.so_y[i0];
    rays.o[2] = &s.so_z[i0];
    rays.d[0] = &s.sd_x[i0];
    rays.d[1] = &s.sd_y[i0];
    rays.d[2] = &s.sd_z[i0];
    rays.t_min = zeros.data();
    rays.t_max = &s.s_tmax[i0];
    rays.active = active.data();
    rays.group_frusta = s.shadow_group_frusta;
    rays.clip_leaf_lanes = s.clip_leaf_lanes;
    TraversalCounters work;
    occluded_large_packet(scene, rays, test, objects, blocked.data(), &work);
    add_work(counters, work);
    for (int g = 0; g < rays.groups; ++g) {
      for (std::uint32_t m = blocked[static_cast<std::size_t>(g)] & active[static_cast<std::size_t>(g)]; m != 0;
           m &= m - 1) {
        const std::size_t i = i0 + static_cast<std::size_t>(g) * kBlockLanes + static_cast<std::size_t>(std::countr_zero(m));
        s.lit[s.shadow_pixel[i]] &= dark;
        ++blocked_count;
      }
    }
  }
  return blocked_count;
}

}  // namespace

bool valid_packet_rays(int packet_rays) {
  return packet_rays == 1 || packet_rays == 8 || packet_rays == 64 || packet_rays == 256 || packet_rays == 512;
}

void packet_region_blocks(int packet_rays, int& blocks_x, int& blocks_y) {
  // Regions of 4x2-pixel blocks: 8x8 pixels are 2x4 blocks, 16x16 are 4x8,
  // 32x16 are 8x8 (the grid's most, render/grid_frusta.h).
  blocks_x = blocks_y = 1;
  if (packet_rays == 64) {
    blocks_x = 2;
    blocks_y = 4;
  } else if (packet_rays == 256) {
    blocks_x = 4;
    blocks_y = 8;
  } else if (packet_rays == 512) {
    blocks_x = 8;
    blocks_y = 8;
  }
}

void trace_primary(const Scene& scene, const PinholeCamera& camera, TriangleTest test, int packet_rays,
                   TileScratch& s, TraversalCounters& counters) {
  const std::size_t blocks = s.lanes / kBlockLanes;
  const Vec3 eye = camera.eye();
  if (packet_rays <= 1) {
    for (std::size_t b = 0; b < blocks; ++b) {
      std::uint32_t hits = 0;
      for (int lane = 0; lane < kBlockLanes; ++lane) {
        const std::size_t k = b * kBlockLanes + static_cast<std::size_t>(lane);
        if (!(s.block_pixels[b] >> lane & 1u)) {
          set_miss(s, k);
          continue;
        }
        Ray ray;
        ray.origin = eye;
        ray.direction = Vec3(s.dir_x[k], s.dir_y[k], s.dir_z[k]);
        const Hit hit = intersect(scene, ray, test, &counters);
        s.t[k] = hit.t;
        s.u[k] = hit.u;
        s.v[k] = hit.v;
        s.triangle[k] = hit.triangle_id;
        s.instance[k] = hit.instance_id;
        hits |= hit.valid() ? (1u << lane) : 0u;
      }
      s.block_hits[b] = static_cast<std::uint8_t>(hits);
    }
    return;
  }
  // One bound over the whole tile picks the objects any of its rays may
  // enter; each packet then keeps those of its own rays.
  CullLists& lists = cull_lists();
  lists.tile.clear();
  RayBound tile_bound;
  const float* const dirs[3] = {s.dir_x.data(), s.dir_y.data(), s.dir_z.data()};
  tile_bound.add_groups(eye, dirs, 0.0f, kInf, std::span<const std::uint8_t>(s.block_pixels.data(), blocks));
  cull_objects(scene, tile_bound, lists.tile);
  thread_local StaticTile statics;
  if (gather_static_tile(scene, test, tile_bound, 0.0f, lists.tile, statics, camera_tile_cone(camera, s.tile))) {
    for (std::size_t b = 0; b < blocks; ++b) counters.rays += static_cast<std::uint64_t>(std::popcount(s.block_pixels[b]));
    intersect_static_tile(statics, eye, s, counters);
    return;
  }
  if (packet_rays > kPacketSize) {
    trace_primary_large(scene, camera, test, lists.tile, s, counters);
    return;
  }
  RayPacket packet;
  for (int lane = 0; lane < kPacketSize; ++lane) {
    packet.ox[lane] = eye.x;
    packet.oy[lane] = eye.y;
    packet.oz[lane] = eye.z;
    packet.t_min[lane] = 0.0f;
    packet.t_max[lane] = kInf;
  }
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::size_t k0 = b * kBlockLanes;
    const std::uint32_t pixels = s.block_pixels[b];
    counters.rays += static_cast<std::uint64_t>(std::popcount(pixels));
    s.block_hits[b] = 0;
    std::memcpy(packet.dx, &s.dir_x[k0], sizeof(packet.dx));
    std::memcpy(packet.dy, &s.dir_y[k0], sizeof(packet.dy));
    std::memcpy(packet.dz, &s.dir_z[k0], sizeof(packet.dz));
    packet.active = static_cast<std::uint8_t>(pixels);
    if (!lists.tile.empty()) cull_for_packet(scene, packet, lists);
    if (lists.tile.empty() || lists.packet.empty()) {
      for (int lane = 0; lane < kBlockLanes; ++lane) set_miss(s, k0 + static_cast<std::size_t>(lane));
      continue;
    }
    const ObjectFilter filter{lists.packet};
    TraversalCounters work;
    const PacketHits direct{&s.t[k0], &s.u[k0], &s.v[k0], &s.triangle[k0], &s.instance[k0]};
    if (!intersect_packet_small_statics(scene, packet, test, filter, direct, &work)) {
      Hit hits[kPacketSize];
      intersect_packet(scene, packet, test, hits, &work, &filter);
      for (int lane = 0; lane < kPacketSize; ++lane) {
        const std::size_t k = k0 + static_cast<std::size_t>(lane);
        s.t[k] = hits[lane].t;
        s.u[k] = hits[lane].u;
        s.v[k] = hits[lane].v;
        s.triangle[k] = hits[lane].triangle_id;
        s.instance[k] = hits[lane].instance_id;
      }
    }
    add_work(counters, work);
    std::uint32_t hit_bits = 0;
    for (int lane = 0; lane < kPacketSize; ++lane) {
      hit_bits |= s.triangle[k0 + static_cast<std::size_t>(lane)] != kInvalidId ? (1u << lane) : 0u;
    }
    s.block_hits[b] = static_cast<std::uint8_t>(hit_bits & pixels);
  }
}

void reconstruct_surfaces(const Scene& scene, const Vec3& default_albedo, TileScratch& s) {
  const std::size_t blocks = s.lanes / kBlockLanes;
  // Each lane's corners, corner normals and albedo (lanes without a hit
  // repeat a harmless unit triangle). A whole block on the triangle of the
  // last uniform block (a ground's blocks, mostly) keeps them, and the
  // normal, as they are.
  alignas(32) float p[3][3][8] = {};  // [corner][axis][lane]
  alignas(32) float n[3][3][8] = {};
  alignas(32) float albedo[3][8] = {};
  std::uint32_t with_normals = 0, on_character = 0;
  std::uint32_t kept_triangle = kInvalidId, kept_instance = kInvalidId;
  Vec3x8 kept_geometric{};
  Float8 kept_magnitude(0.0f);  // the corners' largest coordinate, with them
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::uint32_t hits = s.block_hits[b];
    s.block_on_character[b] = 0;
    if (hits == 0) continue;
    const std::size_t k0 = b * kBlockLanes;
    const bool kept = hits == 0xFFu && kept_triangle != kInvalidId &&
                      (lanes_equal(&s.triangle[k0], kept_triangle) & lanes_equal(&s.instance[k0], kept_instance)) == 0xFFu;
    bool uniform = kept;
    if (!kept) {
      kept_triangle = kInvalidId;  // the arrays are about to change
      with_normals = on_character = 0;
      // Lane by lane: AVX2 gathers measured slower here (Zen 4).
      uniform = gather_lanes(scene, s, k0, hits, default_albedo, p, n, albedo, with_normals, on_character);
    }
    s.block_on_character[b] = static_cast<std::uint8_t>(on_character & hits);
    // surface_at's arithmetic, eight lanes at once.
    const auto corner = [&](const float (&c)[3][3][8], int i) {
      return Vec3x8{Float8::load(c[i][0]), Float8::load(c[i][1]), Float8::load(c[i][2])};
    };
    const Vec3x8 p0 = corner(p, 0), p1 = corner(p, 1), p2 = corner(p, 2);
    const Float8 u = Float8::load(&s.u[k0]);
    const Float8 v = Float8::load(&s.v[k0]);
    const Float8 w = Float8(1.0f) - u - v;
    const Vec3x8 position = (w * p0 + u * p1) + v * p2;
    Float8 magnitude = kept_magnitude;
    if (!kept) {
      magnitude = abs(p0.x);
      for (const Vec3x8* c : {&p0, &p1, &p2}) {
        magnitude = max(magnitude, max(max(abs(c->x), abs(c->y)), abs(c->z)));
      }
    }
    Vec3x8 geometric;
    if (kept) {
      geometric = kept_geometric;
    } else if (uniform) {
      // One triangle: its normal once, with the lanes' very expressions.
      const Vec3 q0(p[0][0][0], p[0][1][0], p[0][2][0]), q1(p[1][0][0], p[1][1][0], p[1][2][0]),
          q2(p[2][0][0], p[2][1][0], p[2][2][0]);
      const Vec3 a = q1 - q0, c = q2 - q0;
      const Vec3 cross_n(a.y * c.z - c.y * a.z, a.z * c.x - c.z * a.x, a.x * c.y - c.x * a.y);
      const float length = std::sqrt(cross_n.x * cross_n.x + cross_n.y * cross_n.y + cross_n.z * cross_n.z);
      const bool usable = length > 0.0f && std::isfinite(length);
      const Vec3 g = usable ? Vec3(cross_n.x / length, cross_n.y / length, cross_n.z / length) : Vec3(0, 0, 1);
      geometric = Vec3x8{Float8(g.x), Float8(g.y), Float8(g.z)};
      kept_triangle = s.triangle[k0];  // gather_lanes is uniform only for whole blocks
      kept_instance = s.instance[k0];
      kept_geometric = geometric;
      kept_magnitude = magnitude;
    } else {
      const Vec3x8 cross_n = cross(p1 - p0, p2 - p0);
      const Float8 length = sqrt(dot(cross_n, cross_n));
      const Mask8 usable = (length > Float8(0.0f)) & is_finite(length);
      geometric = select(usable, Vec3x8{cross_n.x / length, cross_n.y / length, cross_n.z / length},
                         Vec3x8{Float8(0.0f), Float8(0.0f), Float8(1.0f)});
    }
    Vec3x8 shading = geometric;
    if (with_normals != 0) {
      const Vec3x8 shading_sum = (w * corner(n, 0) + u * corner(n, 1)) + v * corner(n, 2);
      const Float8 shading_length =
          select(Mask8::from_bits(with_normals), sqrt(dot(shading_sum, shading_sum)), Float8(0.0f));
      const Mask8 shading_usable = (shading_length > Float8(0.0f)) & is_finite(shading_length);
      shading = select(shading_usable,
                       Vec3x8{shading_sum.x / shading_length, shading_sum.y / shading_length,
                              shading_sum.z / shading_length},
                       geometric);
    }
    // Both normals onto the camera's side of the surface.
    const Vec3x8 dir = load3(s.dir_x, s.dir_y, s.dir_z, k0);
    const Mask8 back = dot(geometric, dir) > Float8(0.0f);
    geometric = select(back, Vec3x8{-geometric.x, -geometric.y, -geometric.z}, geometric);
    const Mask8 flip = dot(shading, geometric) < Float8(0.0f);
    shading = select(flip, Vec3x8{-shading.x, -shading.y, -shading.z}, shading);
    store3(position, s.px, s.py, s.pz, k0);
    store3(geometric, s.gx, s.gy, s.gz, k0);
    store3(shading, s.nx, s.ny, s.nz, k0);
    Float8::load(albedo[0]).store(&s.ar[k0]);
    Float8::load(albedo[1]).store(&s.ag[k0]);
    Float8::load(albedo[2]).store(&s.ab[k0]);
    (Float8(gamma(7)) * magnitude).store(&s.error[k0]);
  }
}

namespace {

// One light's terms for placing shadow rays, eight lanes at a time.
struct ShadowLight {
  bool point;
  Vec3x8 at, direction;
  float magnitude;
  std::uint8_t dark;  // clears the light's bit of s.lit

  ShadowLight(bool is_point, const Vec3& position, const Vec3& dir, int l)
      : point(is_point), at{Float8(position.x), Float8(position.y), Float8(position.z)},
        direction{Float8(dir.x), Float8(dir.y), Float8(dir.z)}, magnitude(detail::max_abs(position)),
        dark(static_cast<std::uint8_t>(~(1u << l))) {}

  Vec3x8 to_light(const Vec3x8& position) const { return point ? at - position : direction; }

  // The hits of block b whose surface faces the light; the others lose the
  // light's bit of s.lit (no ray needed).
  std::uint32_t facing(TileScratch& s, std::size_t b) const {
    const std::uint32_t lanes = s.block_hits[b];
    if (lanes == 0) return 0;
    const std::size_t k0 = b * kBlockLanes;
    const Vec3x8 to = to_light(load3(s.px, s.py, s.pz, k0));
    const std::uint32_t toward = (dot(load3(s.gx, s.gy, s.gz, k0), to) > Float8(0.0f)).bits() & lanes;
    for (std::uint32_t away = lanes & ~toward; away != 0; away &= away - 1) {
      s.lit[k0 + static_cast<std::size_t>(std::countr_zero(away))] &= dark;
    }
    return toward;
  }

  // offset_origin's push of block b's hits along the camera-facing normal,
  // by the rounding bound (for a point light shadow_ray_from_light's wider
  // one): the offset, and the moved points.
  Vec3x8 offset(const TileScratch& s, std::size_t k0) const {
    const Vec3x8 position = load3(s.px, s.py, s.pz, k0);
    const Vec3x8 facing = load3(s.gx, s.gy, s.gz, k0);
    Float8 e = Float8::load(&s.error[k0]);
    if (point) {
      const Vec3x8 to = to_light(position);
      const Float8 reach = Float8(magnitude) + Float8(2.0f) * max(max(abs(to.x), abs(to.y)), abs(to.z));
      e = e + Float8(gamma(32)) * reach;
    }
    const Float8 distance = abs(facing.x) * e + abs(facing.y) * e + abs(facing.z) * e;
    return distance * facing;
  }

  // Block b's rays: the moved points one float further on every axis they
  // moved; a point light's run from the light to them.
  void place(TileScratch& s, std::size_t b) const {
    const std::size_t k0 = b * kBlockLanes;
    const Vec3x8 push = offset(s, k0);
    place_moved(s, k0, load3(s.px, s.py, s.pz, k0) + push, push);
  }
  void place_moved(TileScratch& s, std::size_t k0, const Vec3x8& moved, const Vec3x8& push) const {
    const Vec3x8 end{step_away(moved.x, push.x), step_away(moved.y, push.y), step_away(moved.z, push.z)};
    store3(point ? end - at : end, s.shadow_lane_x, s.shadow_lane_y, s.shadow_lane_z, k0);
  }
};

void start_shadow_rays(const Light& light, TileScratch& s) {
  s.shadow_placed = 0;
  s.shadows_compacted = false;
  s.shadow_count = 0;
  s.shadow_region_begin.clear();
  s.shadows_from_point = light.kind == Light::Kind::kPoint;
  s.shadow_origin = light.position;
  s.shadow_direction = light.direction;
  s.shadow_ends = Aabb::empty();  // only aiming bounds the ends
}

}  // namespace

void aim_shadow_rays(const Light& light, int l, TileScratch& s) {
  start_shadow_rays(light, s);
  s.shadows_aimed_only = true;
  const ShadowLight to(s.shadows_from_point, light.position, light.direction, l);
  Vec3x8 lo{Float8(kInf), Float8(kInf), Float8(kInf)}, hi{Float8(-kInf), Float8(-kInf), Float8(-kInf)};
  for (std::size_t b = 0; b < s.blocks(); ++b) {
    const std::uint32_t toward = to.facing(s, b);
    s.shadow_lanes[b] = static_cast<std::uint8_t>(toward);
    if (toward == 0) continue;
    // The moved points of place(), bit for bit (the last step, one float
    // on, is left to the bound's growth), kept with their push for
    // offset_shadow_rays.
    const std::size_t k0 = b * kBlockLanes;
    const Vec3x8 push = to.offset(s, k0);
    const Vec3x8 moved = load3(s.px, s.py, s.pz, k0) + push;
    store3(moved, s.shadow_lane_x, s.shadow_lane_y, s.shadow_lane_z, k0);
    store3(push, s.shadow_push_x, s.shadow_push_y, s.shadow_push_z, k0);
    const Mask8 m = Mask8::from_bits(toward);
    lo = select(m, Vec3x8{min(lo.x, moved.x), min(lo.y, moved.y), min(lo.z, moved.z)}, lo);
    hi = select(m, Vec3x8{max(hi.x, moved.x), max(hi.y, moved.y), max(hi.z, moved.z)}, hi);
    s.shadow_placed += static_cast<std::size_t>(std::popcount(toward));
  }
  if (s.shadow_placed == 0) return;
  // A ray ends one float on from its moved point (at most 2^-22 of the
  // coordinate, or a denormal step from zero): growing the box by 2^-21 of
  // the coordinates and the smallest normal float holds every end and its
  // rounding, and keeps the box on the light's side of a receiver the
  // offset cleared by far more.
  const Vec3 low(reduce_min(lo.x), reduce_min(lo.y), reduce_min(lo.z));
  const Vec3 high(reduce_max(hi.x), reduce_max(hi.y), reduce_max(hi.z));
  const float magnitude = std::max(detail::max_abs(low), detail::max_abs(high));
  const float grow = 0x1.0p-21f * magnitude + std::numeric_limits<float>::min();
  s.shadow_ends = {low - Vec3(grow), high + Vec3(grow)};
}

void offset_shadow_rays(TileScratch& s) {
  if (!s.shadows_aimed_only) return;
  s.shadows_aimed_only = false;
  const ShadowLight to(s.shadows_from_point, s.shadow_origin, s.shadow_direction, 0);
  for (std::size_t b = 0; b < s.blocks(); ++b) {
    if (s.shadow_lanes[b] == 0) continue;
    const std::size_t k0 = b * kBlockLanes;
    to.place_moved(s, k0, load3(s.shadow_lane_x, s.shadow_lane_y, s.shadow_lane_z, k0),
                   load3(s.shadow_push_x, s.shadow_push_y, s.shadow_push_z, k0));
  }
}

void place_shadow_rays(const Light& light, int l, TileScratch& s) {
  // In one pass, without the bound aiming makes: for tracers that take
  // every ray (the Embree peer of the benchmarks).
  start_shadow_rays(light, s);
  s.shadows_aimed_only = false;
  const ShadowLight to(s.shadows_from_point, light.position, light.direction, l);
  for (std::size_t b = 0; b < s.blocks(); ++b) {
    const std::uint32_t toward = to.facing(s, b);
    s.shadow_lanes[b] = static_cast<std::uint8_t>(toward);
    if (toward == 0) continue;
    to.place(s, b);
    s.shadow_placed += static_cast<std::size_t>(std::popcount(toward));
  }
}

namespace {

// Fine geometry's shadow packets: 8x8 pixels. Measured against 4x4 and
// 8x4 (and the whole 16x16 region) at 213,888 and 855,552 triangles
// (docs/RAYTRACE.md, "Shadow packets on fine meshes").
constexpr std::size_t kSplitBlocksX = 2;
constexpr std::size_t kSplitBlocksY = 4;
// Triangles this many pixels across or smaller count as fine: at least two
// in three neighbouring character pixels lie on different triangles.
constexpr double kFineTrianglePixels = 1.5;

// Whether the region's character hits lie on triangles about
// kFineTrianglePixels across or smaller: the share of neighbouring
// character pixels (within a block, across and down) on different
// triangles.
bool fine_geometry(const TileScratch& s, std::size_t b0, std::size_t b1) {
  // Per block, bit i of `across` for the pair (i, i + 1) of a row (bits 0-2
  // the top row, 4-6 the bottom one), bit i of `down` for (i, i + 4); a
  // pair counts when both its pixels are on a character. Without branches:
  // scalar pair by pair this was 4% of the shadow rays' time at 3,342
  // triangles, where no region splits.
  int pairs = 0, changes = 0;
  for (std::size_t b = b0; b < b1; ++b) {
    const unsigned on = s.block_on_character[b];
    if (on == 0) continue;
    const std::uint32_t* tri = s.triangle.data() + b * kBlockLanes;
    const std::uint32_t* inst = s.instance.data() + b * kBlockLanes;
    const auto same = [&](int i, int j) {
      return static_cast<unsigned>(tri[i] == tri[j]) & static_cast<unsigned>(inst[i] == inst[j]);
    };
    const unsigned same_across = same(0, 1) | same(1, 2) << 1 | same(2, 3) << 2 | same(4, 5) << 4 |
                                 same(5, 6) << 5 | same(6, 7) << 6;
    const unsigned same_down = same(0, 4) | same(1, 5) << 1 | same(2, 6) << 2 | same(3, 7) << 3;
    const unsigned across = on & (on >> 1) & 0x77u;
    const unsigned down = on & (on >> 4) & 0x0Fu;
    pairs += std::popcount(across) + std::popcount(down);
    changes += std::popcount(across & ~same_across) + std::popcount(down & ~same_down);
  }
  return pairs > 0 && static_cast<double>(changes) * kFineTrianglePixels >= static_cast<double>(pairs);
}

}  // namespace

void compact_shadow_rays(TileScratch& s) {
  if (s.shadows_compacted) return;
  s.shadows_compacted = true;
  const bool point = s.shadows_from_point;
  const Vec3x8 light_at{Float8(s.shadow_origin.x), Float8(s.shadow_origin.y), Float8(s.shadow_origin.z)};
  const Vec3x8 light_dir{Float8(s.shadow_direction.x), Float8(s.shadow_direction.y), Float8(s.shadow_direction.z)};
  s.shadow_count = 0;
  s.shadow_region_begin.clear();
  // The rays of block b's lanes of `lanes`, compacted eight lanes at a time
  // (the arrays have a spare group).
  const auto add_block = [&](std::size_t b, std::uint32_t lanes) {
    const std::size_t k0 = b * kBlockLanes;
    const Vec3x8 placed = load3(s.shadow_lane_x, s.shadow_lane_y, s.shadow_lane_z, k0);
    const Vec3x8 origin = point ? light_at : placed;
    const Vec3x8 direction = point ? placed : light_dir;
    const std::size_t i = s.shadow_count;
    compress_store(&s.so_x[i], origin.x, lanes);
    compress_store(&s.so_y[i], origin.y, lanes);
    compress_store(&s.so_z[i], origin.z, lanes);
    compress_store(&s.sd_x[i], direction.x, lanes);
    compress_store(&s.sd_y[i], direction.y, lanes);
    compress_store(&s.sd_z[i], direction.z, lanes);
    Float8(point ? 1.0f : kInf).store(&s.s_tmax[i]);
    compress_store_lane_indices(&s.shadow_pixel[i], static_cast<std::uint32_t>(k0), lanes);
    s.shadow_count += static_cast<std::size_t>(std::popcount(lanes));
  };
  // Per region, the rays from characters and those from static meshes make
  // two runs (two packets): a silhouette region's rays end at two depths,
  // and one packet over both would reach every object between them.
  const auto close_run = [&] {
    if (s.shadow_region_begin.empty() || s.shadow_region_begin.back() != s.shadow_count) {
      s.shadow_region_begin.push_back(static_cast<std::uint32_t>(s.shadow_count));
    }
  };
  // The rays of the region's blocks [b0, b1) (`columns` to a row) whose
  // lanes `lanes_of(b)` gives, in packets of square x square_rows blocks.
  const auto add_squares = [&](std::size_t b0, std::size_t b1, std::size_t columns, std::size_t square,
                               std::size_t square_rows, auto&& lanes_of) {
    const std::size_t rows = columns == 0 ? 0 : (b1 - b0 + columns - 1) / columns;
    for (std::size_t sy = 0; sy < rows; sy += square_rows) {
      for (std::size_t sx = 0; sx < columns; sx += square) {
        for (std::size_t y = sy; y < std::min(rows, sy + square_rows); ++y) {
          for (std::size_t x = sx; x < std::min(columns, sx + square); ++x) {
            const std::size_t b = b0 + y * columns + x;
            if (b >= b1) continue;
            const std::uint32_t lanes = lanes_of(b);
            if (lanes != 0) add_block(b, lanes);
          }
        }
        close_run();
      }
    }
  };
  s.shadow_region_begin.push_back(0);
  for (std::size_t r = 0; r < s.regions(); ++r) {
    const std::size_t b0 = s.region_begin[r], b1 = s.region_begin[r + 1];
    std::uint32_t statics = 0;
    for (std::size_t b = b0; b < b1; ++b) statics |= s.shadow_lanes[b] & ~s.block_on_character[b];
    // The character rays in packets of the whole region, or on pixel-sized
    // triangles of 8x8-pixel squares. A large packet's rays all end on the
    // surface, so its leaves near the surface are reached by every group,
    // and there a finer mesh means more triangles per group: at 855,552
    // triangles 8x8-pixel packets take 25 triangle tests a shadow ray where
    // 16x16 take 37.
    const std::size_t columns = s.region_columns(r);
    const bool splittable = s.split_fine_shadows && columns > kSplitBlocksX;
    const std::size_t rows = columns == 0 ? 0 : (b1 - b0 + columns - 1) / columns;
    const bool split = splittable && fine_geometry(s, b0, b1);
    add_squares(b0, b1, columns, split ? kSplitBlocksX : columns, split ? kSplitBlocksY : rows,
                [&](std::size_t b) { return s.block_on_character[b] & s.shadow_lanes[b]; });
    if (statics == 0) continue;
    // The static meshes' rays (a ground's) pass the characters away from
    // their ends: 8x8-pixel squares pay where the characters' triangles are
    // about a pixel (TileScratch::split_static_shadows), and cost more
    // where they are larger (docs/RAYTRACE.md, "Shadow packets on fine
    // meshes").
    const bool split_statics = splittable && s.split_static_shadows;
    add_squares(b0, b1, columns, split_statics ? kSplitBlocksX : columns, split_statics ? kSplitBlocksY : rows,
                [&](std::size_t b) { return s.shadow_lanes[b] & ~s.block_on_character[b]; });
  }
  // No ray at all: no run.
  if (s.shadow_count == 0) s.shadow_region_begin.clear();
}

void make_shadow_rays(const Light& light, int l, TileScratch& s) {
  place_shadow_rays(light, l, s);
  compact_shadow_rays(s);
}

std::uint64_t trace_shadow_rays(const Scene& scene, TriangleTest test, int packet_rays, int l, TileScratch& s,
                                TraversalCounters& counters) {
  const std::uint8_t dark = static_cast<std::uint8_t>(~(1u << l));
  std::uint64_t blocked_count = 0;
  const auto block = [&](std::size_t i) {
    s.lit[s.shadow_pixel[i]] &= dark;
    ++blocked_count;
  };
  if (packet_rays <= 1) {
    offset_shadow_rays(s);
    compact_shadow_rays(s);
    for (std::size_t i = 0; i < s.shadow_count; ++i) {
      if (occluded(scene, s.shadow_ray(i), test, &counters)) block(i);
    }
    return blocked_count;
  }
  if (s.shadow_placed == 0) return 0;
  static const float kZeros[kPacketSize] = {};
  CullLists& lists = cull_lists();
  lists.tile.clear();
  RayBound tile_bound;
  if (s.shadows_aimed_only) {
    // Every ray the ends' box allows, as one bound: from the light to the
    // box, or from the box along the light. Per axis that is the same
    // range of directions (or origins) as the placed rays' own (the box's
    // faces are their extreme ends, grown, and rounded differences keep
    // their order), so the rays are placed only when it reaches an object:
    // a tile in the open places none.
    alignas(32) float o[3][kPacketSize] = {}, d[3][kPacketSize] = {};
    alignas(32) float t_min[kPacketSize] = {}, t_max[kPacketSize] = {};
    const Vec3 corners[2] = {s.shadow_ends.lower, s.shadow_ends.upper};
    for (int c = 0; c < 2; ++c) {
      for (int a = 0; a < 3; ++a) {
        o[a][c] = s.shadows_from_point ? s.shadow_origin[a] : corners[c][a];
        d[a][c] = s.shadows_from_point ? corners[c][a] - s.shadow_origin[a] : s.shadow_direction[a];
      }
      t_max[c] = s.shadows_from_point ? 1.0f : kInf;
    }
    const float* const origins[3] = {o[0], o[1], o[2]};
    const float* const directions[3] = {d[0], d[1], d[2]};
    tile_bound.add_lanes(origins, directions, t_min, t_max, 0b11u);
  } else {
    // The tile's rays bounded as placed, lane by lane (the same rays, so
    // the same bound as over the compacted ones).
    const float* const placed[3] = {s.shadow_lane_x.data(), s.shadow_lane_y.data(), s.shadow_lane_z.data()};
    if (s.shadows_from_point) {
      tile_bound.add_groups(s.shadow_origin, placed, 0.0f, 1.0f, std::span(s.shadow_lanes.data(), s.blocks()));
    } else {
      alignas(32) float d[3][kPacketSize], t_max[kPacketSize];
      for (int lane = 0; lane < kPacketSize; ++lane) {
        for (int a = 0; a < 3; ++a) d[a][lane] = s.shadow_direction[a];
        t_max[lane] = kInf;
      }
      const float* const directions[3] = {d[0], d[1], d[2]};
      for (std::size_t b = 0; b < s.blocks(); ++b) {
        if (s.shadow_lanes[b] == 0) continue;
        const std::size_t k0 = b * kBlockLanes;
        const float* const o[3] = {placed[0] + k0, placed[1] + k0, placed[2] + k0};
        tile_bound.add_lanes(o, directions, kZeros, t_max, s.shadow_lanes[b]);
      }
    }
  }
  // A tile whose rays can reach nothing (a ground in the open, mostly)
  // places and compacts none.
  cull_objects(scene, tile_bound, lists.tile);
  if (lists.tile.empty()) {
    counters.rays += s.shadow_placed;
    return 0;
  }
  offset_shadow_rays(s);
  compact_shadow_rays(s);
  // Pad a group past the last ray (inactive lanes, but the arithmetic
  // reads them; a large packet's groups start anywhere).
  const std::size_t padded = (s.shadow_count + kPacketSize - 1) / kPacketSize * kPacketSize;
  for (std::size_t i = s.shadow_count; i < s.shadow_count + kPacketSize; ++i) {
    s.so_x[i] = s.so_y[i] = s.so_z[i] = 0.0f;
    s.sd_x[i] = s.sd_y[i] = 0.0f;
    s.sd_z[i] = 1.0f;
    s.s_tmax[i] = 1.0f;
  }
  thread_local StaticTile statics;
  if (gather_static_tile(scene, test, tile_bound, 0.0f, lists.tile, statics, shadow_tile_cone(s))) {
    counters.rays += s.shadow_count;
    return occluded_static_tile(statics, l, s, counters);
  }
  if (packet_rays > kPacketSize) return trace_shadow_large(scene, test, lists.tile, l, s, counters);
  RayPacket packet;
  std::memcpy(packet.t_min, kZeros, sizeof(packet.t_min));
  for (std::size_t i = 0; i < padded; i += kPacketSize) {
    const std::size_t n = std::min<std::size_t>(kPacketSize, s.shadow_count - i);
    counters.rays += n;
    if (lists.tile.empty()) continue;
    std::memcpy(packet.ox, &s.so_x[i], sizeof(packet.ox));
    std::memcpy(packet.oy, &s.so_y[i], sizeof(packet.oy));
    std::memcpy(packet.oz, &s.so_z[i], sizeof(packet.oz));
    std::memcpy(packet.dx, &s.sd_x[i], sizeof(packet.dx));
    std::memcpy(packet.dy, &s.sd_y[i], sizeof(packet.dy));
    std::memcpy(packet.dz, &s.sd_z[i], sizeof(packet.dz));
    std::memcpy(packet.t_max, &s.s_tmax[i], sizeof(packet.t_max));
    packet.active = static_cast<std::uint8_t>((1u << n) - 1u);
    cull_for_packet(scene, packet, lists);
    if (lists.packet.empty()) continue;
    const ObjectFilter filter{lists.packet};
    TraversalCounters work;
    const int small = occluded_packet_small_statics(scene, packet, test, filter, &work);
    const std::uint32_t blocked =
        small >= 0 ? static_cast<std::uint32_t>(small) : occluded_packet(scene, packet, test, &work, &filter);
    add_work(counters, work);
    for (std::uint32_t m = blocked & packet.active; m != 0; m &= m - 1) {
      block(i + static_cast<std::size_t>(std::countr_zero(m)));
    }
  }
  return blocked_count;
}

namespace {

// A light's terms for the shading, eight lanes wide, made once per tile.
struct LightTerms {
  bool point;
  Vec3x8 at;  // the position (point) or the direction (directional)
  Vec3x8 color;
};

// The terms of `lights` (at most kMaxLights), in their order.
struct ShadingLights {
  std::array<LightTerms, kMaxLights> terms;
  std::size_t count = 0;
  explicit ShadingLights(std::span<const Light> lights) : count(std::min(lights.size(), kMaxLights)) {
    for (std::size_t l = 0; l < count; ++l) {
      const Light& light = lights[l];
      const bool point = light.kind == Light::Kind::kPoint;
      const Vec3 at = point ? light.position : light.direction;
      terms[l] = {point, {Float8(at.x), Float8(at.y), Float8(at.z)},
                  {Float8(light.color.x), Float8(light.color.y), Float8(light.color.z)}};
    }
  }
  std::span<const LightTerms> span() const { return {terms.data(), count}; }
};

// The linear colour of block b's hits: ambient plus each light's N·L where
// it is unblocked, times the albedo.
Vec3x8 block_color(const RenderSettings& settings, std::span<const LightTerms> lights, const TileScratch& s,
                   std::size_t b, std::uint32_t hits) {
  const std::size_t k0 = b * kBlockLanes;
  const Vec3x8 position = load3(s.px, s.py, s.pz, k0);
  const Vec3x8 n = load3(s.nx, s.ny, s.nz, k0);
  Vec3x8 radiance{Float8(settings.ambient.x), Float8(settings.ambient.y), Float8(settings.ambient.z)};
  for (std::size_t l = 0; l < lights.size(); ++l) {
    const std::uint32_t lit_bits = lane_bits(&s.lit[k0], static_cast<int>(l)) & hits;
    if (lit_bits == 0) continue;
    const LightTerms& light = lights[l];
    const Vec3x8 to_light = light.point ? light.at - position : light.at;
    const Float8 cosine = select(Mask8::from_bits(lit_bits),
                                 max(dot(n, to_light) / sqrt(dot(to_light, to_light)), Float8(0.0f)), Float8(0.0f));
    radiance = radiance + Vec3x8{light.color.x * cosine, light.color.y * cosine, light.color.z * cosine};
  }
  return {Float8::load(&s.ar[k0]) * radiance.x, Float8::load(&s.ag[k0]) * radiance.y,
          Float8::load(&s.ab[k0]) * radiance.z};
}

// Colour alone, the output a game asks for, in three passes: the blocks'
// linear colours, their sRGB bytes sixteen lanes at a time where the CPU
// has AVX-512 (render/srgb_encode.h), and the rows. The plane's base and
// pitch sit in locals: stores through a plane's bytes could otherwise alias
// every field the loop reads, and each would be loaded again after every
// store.
void shade_rgba8_only(const RenderSettings& settings, std::span<const Light> lights,
                      const OutputPlane<std::uint8_t>& plane, TileScratch& s) {
  const ShadingLights terms(lights);
  const std::span<const LightTerms> shading_lights = terms.span();
  std::byte* const base = plane.base;
  const std::size_t pitch = plane.pitch;
  const int x0 = plane.x0, y0 = plane.y0;
  std::uint32_t background;
  const std::array<std::uint8_t, 4> background_bytes = {srgb_byte(settings.background.x),
                                                         srgb_byte(settings.background.y),
                                                         srgb_byte(settings.background.z), 255};
  std::memcpy(&background, background_bytes.data(), 4);
  std::uint32_t background_row[kBlockWidth];
  for (std::uint32_t& pixel : background_row) pixel = background;
  const std::size_t blocks = s.lanes / kBlockLanes;
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::uint32_t hits = s.block_hits[b];
    if (hits == 0) continue;
    const Vec3x8 color = block_color(settings, shading_lights, s, b, hits);
    const std::size_t k0 = b * kBlockLanes;
    color.x.store(&s.lr[k0]);
    color.y.store(&s.lg[k0]);
    color.z.store(&s.lb[k0]);
  }
  // Encoded a pair of blocks at a time, in runs of pairs with a hit (the
  // lanes without one encode what they held, and are not written).
  const std::size_t pairs = (blocks + 1) / 2;
  std::size_t run = 0;
  for (std::size_t pair = 0; pair <= pairs; ++pair) {
    if (pair < pairs) {
      const std::size_t b = 2 * pair;
      if ((s.block_hits[b] | (b + 1 < blocks ? s.block_hits[b + 1] : 0u)) != 0) continue;
    }
    if (pair > run) {
      const std::size_t k = run * kSrgbEncodeLanes;
      srgb_encode(&s.lr[k], &s.lg[k], &s.lb[k], &s.rgba8[k], (pair - run) * kSrgbEncodeLanes);
    }
    run = pair + 1;
  }
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::uint32_t pixels = s.block_pixels[b];
    const std::uint32_t hits = s.block_hits[b];
    const std::uint32_t* const rgba = &s.rgba8[b * kBlockLanes];
    std::byte* const row0 = base + static_cast<std::size_t>(s.block_y0(b) - y0) * pitch +
                            static_cast<std::size_t>(s.block_x0(b) - x0) * 4;
    if (pixels == 0xFFu && (hits == 0xFFu || hits == 0u)) {
      const std::uint32_t* const source = hits != 0 ? rgba : nullptr;
      for (int row = 0; row < kBlockHeight; ++row) {
        std::memcpy(row0 + static_cast<std::size_t>(row) * pitch,
                    source ? source + row * kBlockWidth : background_row, sizeof(background_row));
      }
      continue;
    }
    for (std::uint32_t m = pixels; m != 0; m &= m - 1) {
      const int lane = std::countr_zero(m);
      std::byte* const pixel = row0 + static_cast<std::size_t>(lane / kBlockWidth) * pitch +
                               static_cast<std::size_t>(lane % kBlockWidth) * 4;
      std::memcpy(pixel, hits >> lane & 1u ? &rgba[lane] : &background, 4);
    }
  }
}

}  // namespace

void shade_and_write(const RenderSettings& settings, std::span<const Light> lights, const OutputPlanes& host,
                     TileScratch& s) {
  // Written to the tile's staging planes, stored to the host's at the end.
  const OutputPlanes& out = s.staging.stage(host, s.tile);
  if (host.rgba8.wanted() && !host.rgba32f.wanted() && !host.depth.wanted() && !host.normal.wanted() &&
      !host.triangle.wanted() && !host.instance.wanted()) {
    shade_rgba8_only(settings, lights, out.rgba8, s);
    s.staging.flush(host);
    return;
  }
  const std::size_t blocks = s.lanes / kBlockLanes;
  const bool want_color = out.want_color();
  const ShadingLights shading_lights(lights);
  const std::array<std::uint8_t, 4> background_bytes = {srgb_byte(settings.background.x),
                                                         srgb_byte(settings.background.y),
                                                         srgb_byte(settings.background.z), 255};
  // A row of a block that missed, whole.
  std::uint32_t background_row[kBlockWidth];
  for (std::uint32_t& pixel : background_row) std::memcpy(&pixel, background_bytes.data(), 4);
  static constexpr float kMissDepths[kBlockWidth] = {kInf, kInf, kInf, kInf};
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::size_t k0 = b * kBlockLanes;
    const std::uint32_t pixels = s.block_pixels[b];
    const std::uint32_t hits = s.block_hits[b];
    // Filled below for blocks with hits, each only when its output is
    // wanted, and read only then (so not zeroed per block).
    alignas(32) float depth[8], linear[3][8];
    alignas(32) std::uint32_t pixels_rgba8[8];
    if (hits != 0) {
      if (out.depth.wanted()) {
        const Vec3x8 dir = load3(s.dir_x, s.dir_y, s.dir_z, k0);
        (Float8::load(&s.t[k0]) * sqrt(dot(dir, dir))).store(depth);
      }
      if (want_color) {
        const Vec3x8 color = block_color(settings, shading_lights.span(), s, b, hits);
        color.x.store(linear[0]);
        color.y.store(linear[1]);
        color.z.store(linear[2]);
        if (out.rgba8.wanted()) srgb_pixels(color, pixels_rgba8);
      }
    }
    const int bx = s.block_x0(b);
    const int by = s.block_y0(b);
    if (pixels == 0xFFu && (hits == 0xFFu || hits == 0u)) {
      // A whole block of one kind: each output's two rows of four pixels
      // are contiguous.
      for (int row = 0; row < kBlockHeight; ++row) {
        const std::size_t k = k0 + static_cast<std::size_t>(row * kBlockWidth);
        const int y = by + row;
        if (out.triangle.wanted()) std::memcpy(out.triangle.at(bx, y), &s.triangle[k], 4 * sizeof(std::uint32_t));
        if (out.instance.wanted()) std::memcpy(out.instance.at(bx, y), &s.instance[k], 4 * sizeof(std::uint32_t));
        if (hits == 0u) {
          if (out.depth.wanted()) std::memcpy(out.depth.at(bx, y), kMissDepths, sizeof(kMissDepths));
          if (out.rgba8.wanted()) std::memcpy(out.rgba8.at(bx, y), background_row, sizeof(background_row));
          for (int i = 0; i < kBlockWidth; ++i) {
            if (out.normal.wanted()) out.normal.at(bx, y)[i] = Vec3(0.0f);
            if (out.rgba32f.wanted()) {
              float* rgba = out.rgba32f.at(bx + i, y);
              for (int c = 0; c < 3; ++c) rgba[c] = settings.background[c];
              rgba[3] = 1.0f;
            }
          }
          continue;
        }
        const int l0 = row * kBlockWidth;
        if (out.depth.wanted()) std::memcpy(out.depth.at(bx, y), &depth[l0], 4 * sizeof(float));
        if (out.normal.wanted()) {
          for (int i = 0; i < kBlockWidth; ++i) out.normal.at(bx, y)[i] = Vec3(s.nx[k + i], s.ny[k + i], s.nz[k + i]);
        }
        if (out.rgba8.wanted()) std::memcpy(out.rgba8.at(bx, y), &pixels_rgba8[l0], 4 * sizeof(std::uint32_t));
        if (out.rgba32f.wanted()) {
          float* rgba = out.rgba32f.at(bx, y);
          for (int i = 0; i < kBlockWidth; ++i) {
            for (int c = 0; c < 3; ++c) rgba[4 * i + c] = linear[c][l0 + i];
            rgba[4 * i + 3] = 1.0f;
          }
        }
      }
      continue;
    }
    for (std::uint32_t m = pixels; m != 0; m &= m - 1) {
      const int lane = std::countr_zero(m);
      const std::size_t k = k0 + static_cast<std::size_t>(lane);
      const int x = bx + lane % kBlockWidth;
      const int y = by + lane / kBlockWidth;
      if (out.triangle.wanted()) *out.triangle.at(x, y) = s.triangle[k];
      if (out.instance.wanted()) *out.instance.at(x, y) = s.instance[k];
      if (!(hits >> lane & 1u)) {
        if (out.depth.wanted()) *out.depth.at(x, y) = kInf;
        if (out.normal.wanted()) *out.normal.at(x, y) = Vec3(0.0f);
        if (out.rgba32f.wanted()) {
          float* rgba = out.rgba32f.at(x, y);
          for (int c = 0; c < 3; ++c) rgba[c] = settings.background[c];
          rgba[3] = 1.0f;
        }
        if (out.rgba8.wanted()) std::memcpy(out.rgba8.at(x, y), background_bytes.data(), 4);
        continue;
      }
      if (out.depth.wanted()) *out.depth.at(x, y) = depth[lane];
      if (out.normal.wanted()) *out.normal.at(x, y) = Vec3(s.nx[k], s.ny[k], s.nz[k]);
      if (out.rgba32f.wanted()) {
        float* rgba = out.rgba32f.at(x, y);
        for (int c = 0; c < 3; ++c) rgba[c] = linear[c][lane];
        rgba[3] = 1.0f;
      }
      if (out.rgba8.wanted()) std::memcpy(out.rgba8.at(x, y), &pixels_rgba8[lane], 4);
    }
  }
  s.staging.flush(host);
}

}  // namespace sinew::rt
