#include "editor/gui/overlays.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace sinew::editor::gui {

std::string_view overlay_name(Overlay overlay) {
  switch (overlay) {
    case Overlay::kNone: return "none";
    case Overlay::kBoxes: return "boxes";
    case Overlay::kHeat: return "heat";
    case Overlay::kEscapes: return "escapes";
  }
  return "none";
}

Expected<Overlay> parse_overlay(std::string_view name) {
  for (Overlay o : {Overlay::kNone, Overlay::kBoxes, Overlay::kHeat, Overlay::kEscapes}) {
    if (overlay_name(o) == name) return o;
  }
  return invalid_argument("--overlay", std::string(name), "expected none, boxes, heat or escapes");
}

Projection::Projection(const rt::CameraDesc& desc, int width, int height)
    : eye_(desc.eye),
      width_(static_cast<float>(width)),
      height_(static_cast<float>(height)) {
  forward_ = glm::normalize(desc.target - desc.eye);
  right_ = glm::normalize(glm::cross(forward_, desc.up));
  up_ = glm::cross(right_, forward_);
  tan_half_fovy_ = std::tan(glm::radians(desc.fovy_degrees) * 0.5f);
  aspect_ = width_ / height_;
  // Near enough to keep everything the user looks at, far enough that a
  // point just past the plane does not project to a huge coordinate.
  near_ = 1e-3f * glm::length(desc.target - desc.eye);
}

float Projection::depth(const Vec3& world) const { return glm::dot(world - eye_, forward_); }

Vec2 Projection::to_pixel(const Vec3& world) const {
  const Vec3 d = world - eye_;
  const float z = glm::dot(d, forward_);
  const float sx = glm::dot(d, right_) / (z * tan_half_fovy_ * aspect_);
  const float sy = glm::dot(d, up_) / (z * tan_half_fovy_);
  return {(sx + 1.0f) * 0.5f * width_, (1.0f - sy) * 0.5f * height_};
}

namespace {

void put_pixel(const ImageRef& image, int x, int y, const std::uint8_t (&color)[3]) {
  if (x < 0 || y < 0 || x >= image.width || y >= image.height) return;
  const std::size_t i = 4 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) +
                             static_cast<std::size_t>(x));
  image.rgba[i] = color[0];
  image.rgba[i + 1] = color[1];
  image.rgba[i + 2] = color[2];
  image.rgba[i + 3] = 255;
}

// Liang-Barsky clip of p + t (q - p), t in [0, 1], to [lo, hi] on both axes.
bool clip_to_rect(Vec2& p, Vec2& q, const Vec2& lo, const Vec2& hi) {
  float t0 = 0.0f;
  float t1 = 1.0f;
  const Vec2 d = q - p;
  const float pk[4] = {-d.x, d.x, -d.y, d.y};
  const float qk[4] = {p.x - lo.x, hi.x - p.x, p.y - lo.y, hi.y - p.y};
  for (int k = 0; k < 4; ++k) {
    if (pk[k] == 0.0f) {
      if (qk[k] < 0.0f) return false;
      continue;
    }
    const float t = qk[k] / pk[k];
    if (pk[k] < 0.0f) {
      t0 = std::max(t0, t);
    } else {
      t1 = std::min(t1, t);
    }
    if (t0 > t1) return false;
  }
  const Vec2 start = p + t0 * d;
  q = p + t1 * d;
  p = start;
  return true;
}

}  // namespace

void draw_segment(const ImageRef& image, const Projection& projection, const Vec3& a, const Vec3& b,
                  const std::uint8_t (&color)[3]) {
  Vec3 pa = a;
  Vec3 pb = b;
  const float da = projection.depth(pa);
  const float db = projection.depth(pb);
  const float near = projection.near_depth();
  if (!(da >= near) && !(db >= near)) return;  // both behind (or NaN)
  if (da < near) pa = pa + (near - da) / (db - da) * (pb - pa);
  if (db < near) pb = pb + (near - db) / (da - db) * (pa - pb);
  Vec2 p = projection.to_pixel(pa);
  Vec2 q = projection.to_pixel(pb);
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(q.x) || !std::isfinite(q.y)) return;
  const Vec2 lo(0.0f);
  const Vec2 hi(static_cast<float>(image.width) - 0.001f, static_cast<float>(image.height) - 0.001f);
  if (!clip_to_rect(p, q, lo, hi)) return;
  const float steps = std::ceil(std::max(std::abs(q.x - p.x), std::abs(q.y - p.y)));
  const int n = static_cast<int>(steps);
  for (int i = 0; i <= n; ++i) {
    const float t = n == 0 ? 0.0f : static_cast<float>(i) / steps;
    const Vec2 s = p + t * (q - p);
    put_pixel(image, static_cast<int>(s.x), static_cast<int>(s.y), color);
  }
}

void draw_box(const ImageRef& image, const Projection& projection, const Aabb& box, const Affine3& bone_to_world,
              const std::uint8_t (&color)[3]) {
  if (box.is_empty()) return;
  Vec3 corners[8];
  for (int c = 0; c < 8; ++c) {
    const Vec3 local((c & 1) ? box.upper.x : box.lower.x, (c & 2) ? box.upper.y : box.lower.y,
                     (c & 4) ? box.upper.z : box.lower.z);
    corners[c] = bone_to_world.transform_point(local);
  }
  // Edges join corners differing in exactly one bit.
  for (int c = 0; c < 8; ++c) {
    for (int bit = 1; bit < 8; bit <<= 1) {
      if ((c & bit) == 0) draw_segment(image, projection, corners[c], corners[c | bit], color);
    }
  }
}

std::vector<Aabb> leaf_cells(const rt::KdTreeView& tree) {
  std::vector<Aabb> cells;
  if (tree.empty()) return cells;
  struct Entry {
    std::uint32_t node;
    Aabb cell;
  };
  std::vector<Entry> stack{{0, tree.bounds}};
  while (!stack.empty()) {
    const Entry e = stack.back();
    stack.pop_back();
    if (e.node >= tree.nodes.size()) continue;  // validated trees never get here
    const rt::KdNode& node = tree.nodes[e.node];
    if (node.is_leaf()) {
      if (node.item_count() > 0) cells.push_back(e.cell);
      continue;
    }
    const int axis = node.axis();
    Aabb below = e.cell;
    Aabb above = e.cell;
    below.upper[axis] = std::min(below.upper[axis], node.split());
    above.lower[axis] = std::max(above.lower[axis], node.split());
    stack.push_back({e.node + 1, below});
    stack.push_back({node.above_child(), above});
  }
  return cells;
}

std::vector<Aabb> bvh_leaf_boxes(const rt::BvhView& tree) {
  std::vector<Aabb> boxes;
  for (const rt::BvhNode& node : tree.nodes) {
    if (node.is_leaf()) boxes.push_back(node.box);
  }
  return boxes;
}

std::vector<std::uint32_t> leaf_heat(const rt::FuzzyCharacterView& fuzzy, std::size_t triangle_count) {
  std::vector<std::uint32_t> heat(triangle_count, 0);
  if (fuzzy.has_bvhs()) {
    for (const rt::BoneTree& bt : fuzzy.bone_trees) {
      const rt::BvhView tree = fuzzy.bvh_view(bt);
      for (const rt::BvhNode& node : tree.nodes) {
        if (!node.is_leaf()) continue;
        for (std::uint32_t i = node.first; i < node.first + node.count && i < tree.items.size(); ++i) {
          if (tree.items[i] < heat.size()) heat[tree.items[i]] = node.count;
        }
      }
    }
    return heat;
  }
  for (std::uint32_t b = 0; b < fuzzy.bone_trees.size(); ++b) {
    const rt::KdTreeView tree = fuzzy.bone_tree(b);
    for (const rt::KdNode& node : tree.nodes) {
      if (!node.is_leaf()) continue;
      const std::uint32_t first = node.first_item();
      const std::uint32_t count = node.item_count();
      for (std::uint32_t i = first; i < first + count && i < tree.items.size(); ++i) {
        const std::uint32_t triangle = tree.items[i];
        if (triangle < heat.size()) heat[triangle] = std::max(heat[triangle], count);
      }
    }
  }
  return heat;
}

void draw_bone_boxes(const ImageRef& image, const Projection& projection, const rt::FuzzyCharacterView& fuzzy,
                     std::uint32_t bone, const Affine3& skinning) {
  if (bone >= fuzzy.bone_trees.size()) return;
  const std::vector<Aabb> cells = fuzzy.has_bvhs() ? bvh_leaf_boxes(fuzzy.bvh_view(fuzzy.bone_trees[bone]))
                                                   : leaf_cells(fuzzy.bone_tree(bone));
  for (const Aabb& cell : cells) draw_box(image, projection, cell, skinning, kLeafBoxColor);
  // The root box last so that it stays visible where the cells touch it.
  draw_box(image, projection, fuzzy.bone_trees[bone].bounds, skinning, kRootBoxColor);
}

namespace {

// Blue (cold) -> green -> red (hot), t in [0, 1].
Vec3 heat_color(float t) {
  const float r = std::clamp(2.0f * t - 1.0f, 0.0f, 1.0f);
  const float b = std::clamp(1.0f - 2.0f * t, 0.0f, 1.0f);
  const float g = 1.0f - r - b;
  return {r, g, b};
}

}  // namespace

void apply_heat(const ImageRef& image, std::span<const std::uint32_t> triangle_id,
                std::span<const std::uint32_t> instance_id, std::uint32_t instance,
                std::span<const std::uint32_t> heat) {
  std::uint32_t hottest = 1;
  for (std::uint32_t h : heat) hottest = std::max(hottest, h);
  // Logarithmic: leaf sizes span a few orders of magnitude.
  const float scale = 1.0f / std::log(1.0f + static_cast<float>(hottest));
  const std::size_t pixels = std::min(triangle_id.size(), instance_id.size());
  for (std::size_t p = 0; p < pixels; ++p) {
    if (instance_id[p] != instance || triangle_id[p] >= heat.size()) continue;
    const float t = std::log(1.0f + static_cast<float>(heat[triangle_id[p]])) * scale;
    const Vec3 tint = heat_color(t);
    for (int c = 0; c < 3; ++c) {
      // Keep a third of the shading so the shape stays readable.
      const float shaded = static_cast<float>(image.rgba[4 * p + static_cast<std::size_t>(c)]) / 255.0f;
      const float v = 0.35f * shaded + 0.65f * tint[c];
      image.rgba[4 * p + static_cast<std::size_t>(c)] = static_cast<std::uint8_t>(std::lround(v * 255.0f));
    }
  }
}

std::size_t apply_escapes(const ImageRef& image, std::span<const std::uint32_t> triangle_id,
                          std::span<const std::uint32_t> instance_id, std::uint32_t instance,
                          std::span<const std::uint32_t> escaped, std::size_t triangle_count) {
  if (escaped.empty()) return 0;
  std::vector<std::uint8_t> is_escaped(triangle_count, 0);
  for (std::uint32_t t : escaped) {
    if (t < triangle_count) is_escaped[t] = 1;
  }
  std::size_t painted = 0;
  const std::size_t pixels = std::min(triangle_id.size(), instance_id.size());
  for (std::size_t p = 0; p < pixels; ++p) {
    if (instance_id[p] != instance || triangle_id[p] >= triangle_count || !is_escaped[triangle_id[p]]) continue;
    const int x = static_cast<int>(p % static_cast<std::size_t>(image.width));
    const int y = static_cast<int>(p / static_cast<std::size_t>(image.width));
    put_pixel(image, x, y, kEscapeColor);
    ++painted;
  }
  return painted;
}

}  // namespace sinew::editor::gui
