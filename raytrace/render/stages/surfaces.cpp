#include "raytrace/render/stages/tile_stages.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "raytrace/render/stages/stage_support.h"
#include "raytrace/traverse/traversal_shared.h"
#include "runtime/image/texture_sample.h"

namespace sinew::rt {

using namespace stages;

namespace {

// What shading reads of the mesh behind one hit instance.
struct MeshRefs {
  std::span<const std::array<std::uint32_t, 3>> triangles;
  std::span<const Vec3> positions;  // world space (skinned for characters)
  std::span<const Vec3> normals;    // empty: none
  std::span<const std::uint32_t> triangle_material;
  std::span<const Vec3> material_colors;
  std::span<const Vec2> uvs;                       // empty: none
  std::span<const std::uint32_t> material_texture;  // empty: no material has a texture
  std::span<const Texture> textures;
  bool is_static = false;

  // Material `m`'s texture, or null.
  const Texture* texture_of(std::uint32_t m) const {
    if (m >= material_texture.size() || material_texture[m] == kNoTexture) return nullptr;
    return &textures[material_texture[m]];
  }
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
    r.uvs = mesh.uvs;
    r.material_texture = mesh.material_texture;
    r.textures = mesh.textures;
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

// What texturing and the hit-attribute outputs need of each lane: its
// material, its texture (textured lanes), and its triangle's corner uvs
// (textured lanes, and every lane on a mesh with uvs when `all_uvs`).
struct LaneMaterials {
  bool all_uvs = false;
  const Texture* texture[kBlockLanes] = {};
  std::uint32_t material[kBlockLanes] = {};
  alignas(32) float uv[3][2][kBlockLanes] = {};  // [corner][axis][lane]
  std::uint32_t textured = 0;                    // bit l: lane l's material has a texture
  std::uint32_t with_uvs = 0;                    // bit l: uv[..][..][l] holds lane l's corners

  void clear() { textured = with_uvs = 0; }

  void set(const MeshRefs& mesh, std::uint32_t tri, std::uint32_t m, std::uint32_t which) {
    const Texture* map = mesh.texture_of(m);
    if (map != nullptr) textured |= which;
    const bool uvs = (map != nullptr || all_uvs) && !mesh.uvs.empty();
    if (uvs) with_uvs |= which;
    if (map == nullptr && !all_uvs) return;
    const auto& corners = mesh.triangles[tri];
    for (std::uint32_t left = which; left != 0; left &= left - 1) {
      const int lane = std::countr_zero(left);
      texture[lane] = map;
      material[lane] = m < mesh.material_colors.size() ? m : kInvalidId;
      if (!uvs) continue;
      for (int i = 0; i < 3; ++i) {
        const Vec2& c = mesh.uvs[corners[static_cast<std::size_t>(i)]];
        uv[i][0][lane] = c.x;
        uv[i][1][lane] = c.y;
      }
    }
  }
};

// Each lane's corners, corner normals and albedo (lanes without a hit get a
// harmless unit triangle), and their materials (LaneMaterials). Returns
// true when every lane hit one triangle, loaded once and broadcast.
bool gather_lanes(const Scene& scene, const TileScratch& s, std::size_t k0, std::uint32_t hits,
                  const Vec3& default_albedo, float (&p)[3][3][8], float (&n)[3][3][8], float (&albedo)[3][8],
                  std::uint32_t& with_normals, std::uint32_t& on_character, LaneMaterials& materials) {
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
    materials.set(mesh, tri, m, 0xFFu);
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
    materials.set(mesh, tri, m, same);
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

// Each lane's uv: its triangle's corner uvs blended with the hit's
// barycentrics (lanes without uvs get 0).
struct LaneUvs {
  Float8 x, y;
};
LaneUvs lane_uvs(const LaneMaterials& materials, Float8 u, Float8 v, Float8 w) {
  const auto corner = [&](int i, int a) { return Float8::load(materials.uv[i][a]); };
  const Mask8 with = Mask8::from_bits(materials.with_uvs);
  return {select(with, (w * corner(0, 0) + u * corner(1, 0)) + v * corner(2, 0), Float8(0.0f)),
          select(with, (w * corner(0, 1) + u * corner(1, 1)) + v * corner(2, 1), Float8(0.0f))};
}

// The albedo of the textured lanes of `lanes` times their texture's linear
// RGB at the hit's uv, from the level the pixel's footprint asks for
// (texture_level): the pixel cone's width at distance t, stretched by the
// surface's tilt to the ray (at most 16x, grazing), over the triangle's
// uv-to-world area ratio. The other lanes keep `albedo`. Lanes are sampled
// one by one: their textures, levels and texel addresses differ, and the
// blend is twelve multiply-adds.
Vec3x8 textured_albedo(const LaneMaterials& materials, std::uint32_t lanes, const LaneUvs& uv, const Vec3x8& p0,
                       const Vec3x8& p1, const Vec3x8& p2, const Vec3x8& geometric, const Vec3x8& dir, Float8 t,
                       float pixel_spread, const Vec3x8& albedo) {
  const auto corner = [&](int i, int a) { return Float8::load(materials.uv[i][a]); };
  const Float8 e1x = corner(1, 0) - corner(0, 0), e1y = corner(1, 1) - corner(0, 1);
  const Float8 e2x = corner(2, 0) - corner(0, 0), e2y = corner(2, 1) - corner(0, 1);
  const Float8 uv_area2 = abs(e1x * e2y - e1y * e2x);
  const Vec3x8 normal = cross(p1 - p0, p2 - p0);
  const Float8 world_area2 = sqrt(dot(normal, normal));
  const Float8 cosine = max(abs(dot(geometric, dir)), Float8(1.0f / 16.0f));
  const Float8 width = Float8(pixel_spread) * t / cosine;
  alignas(32) float x[kBlockLanes], y[kBlockLanes], footprint[kBlockLanes];
  uv.x.store(x);
  uv.y.store(y);
  (uv_area2 / world_area2 * (width * width)).store(footprint);
  alignas(32) float rgb[3][kBlockLanes];
  for (int a = 0; a < 3; ++a) Float8(1.0f).store(rgb[a]);
  for (std::uint32_t left = lanes; left != 0; left &= left - 1) {
    const int lane = std::countr_zero(left);
    const Texture& texture = *materials.texture[lane];
    const Vec3 c = sample_bilinear(texture, texture_level(texture, footprint[lane]), Vec2(x[lane], y[lane]));
    for (int a = 0; a < 3; ++a) rgb[a][lane] = c[a];
  }
  return {albedo.x * Float8::load(rgb[0]), albedo.y * Float8::load(rgb[1]), albedo.z * Float8::load(rgb[2])};
}

}  // namespace

SurfaceSettings surface_settings(const RenderSettings& settings, const PinholeCamera& camera,
                                 const OutputPlanes& out) {
  return {settings.default_albedo, camera.pixel_spread(), settings.textures, out.want_hit_attributes()};
}

float top_level_magnitude(const Scene& scene) {
  const float magnitude = detail::max_abs(scene.top_level().bounds());
  return std::isfinite(magnitude) ? magnitude : 0.0f;
}

void reconstruct_surfaces(const Scene& scene, const SurfaceSettings& settings, TileScratch& s) {
  s.scene_magnitude = top_level_magnitude(scene);
  const Vec3& default_albedo = settings.default_albedo;
  const std::size_t blocks = s.lanes / kBlockLanes;
  // Each lane's corners, corner normals and albedo (lanes without a hit
  // repeat a harmless unit triangle). A whole block on the triangle of the
  // last uniform block (a ground's blocks, mostly) keeps them, and the
  // normal, as they are.
  alignas(32) float p[3][3][8] = {};  // [corner][axis][lane]
  alignas(32) float n[3][3][8] = {};
  alignas(32) float albedo[3][8] = {};
  std::uint32_t with_normals = 0, on_character = 0;
  LaneMaterials materials;
  materials.all_uvs = settings.hit_attributes;
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
      materials.clear();
      // Lane by lane: AVX2 gathers measured slower here (Zen 4).
      uniform =
          gather_lanes(scene, s, k0, hits, default_albedo, p, n, albedo, with_normals, on_character, materials);
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
    const Vec3x8 dir = load3(s.dir_x, s.dir_y, s.dir_z, k0);
    Vec3x8 block_albedo{Float8::load(albedo[0]), Float8::load(albedo[1]), Float8::load(albedo[2])};
    const std::uint32_t textured = settings.textures ? materials.textured & hits : 0u;
    if (textured != 0 || settings.hit_attributes) {
      const LaneUvs uv = lane_uvs(materials, u, v, w);
      if (textured != 0) {
        block_albedo = textured_albedo(materials, textured, uv, p0, p1, p2, geometric, dir, Float8::load(&s.t[k0]),
                                       settings.pixel_spread, block_albedo);
      }
      if (settings.hit_attributes) {
        uv.x.store(&s.uv_x[k0]);
        uv.y.store(&s.uv_y[k0]);
        std::memcpy(&s.material[k0], materials.material, sizeof materials.material);
      }
    }
    // Both normals onto the camera's side of the surface.
    const Mask8 back = dot(geometric, dir) > Float8(0.0f);
    geometric = select(back, Vec3x8{-geometric.x, -geometric.y, -geometric.z}, geometric);
    const Mask8 flip = dot(shading, geometric) < Float8(0.0f);
    shading = select(flip, Vec3x8{-shading.x, -shading.y, -shading.z}, shading);
    store3(position, s.px, s.py, s.pz, k0);
    store3(geometric, s.gx, s.gy, s.gz, k0);
    store3(shading, s.nx, s.ny, s.nz, k0);
    block_albedo.x.store(&s.ar[k0]);
    block_albedo.y.store(&s.ag[k0]);
    block_albedo.z.store(&s.ab[k0]);
    (Float8(gamma(7)) * magnitude).store(&s.error[k0]);
  }
}

}  // namespace sinew::rt
