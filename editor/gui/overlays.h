// Editor overlays drawn into the ray-traced image on the CPU, after the
// render and before the frame is shown, so a screenshot holds exactly what
// the user saw and the overlays need no GL.
//
//  * boxes: the chosen bone's fuzzy root box (yellow) and the cells of its
//    kd-tree's non-empty leaves (green), carried from the bone's frame to
//    the world by the bone's skinning matrix. Leaf cells rather than each
//    triangle's fuzzy box: the cells are what traversal actually visits, and
//    there are far fewer of them, so the wireframe stays readable.
//  * heat: every pixel of the character is tinted by the item count of the
//    most crowded kd leaf its triangle sits in (blue: few, red: many).
//  * escapes: pixels whose triangle left its fuzzy box this frame are red.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "raytrace/camera/camera.h"
#include "raytrace/fuzzy/fuzzy_character.h"
#include "runtime/core/expected.h"
#include "runtime/math/affine.h"
#include "runtime/math/types.h"

namespace sinew::editor::gui {

enum class Overlay : std::uint8_t { kNone, kBoxes, kHeat, kEscapes };

std::string_view overlay_name(Overlay overlay);  // "none", "boxes", "heat", "escapes"
Expected<Overlay> parse_overlay(std::string_view name);

// Colours the overlays write (RGB, alpha 255), exposed for tests.
inline constexpr std::uint8_t kRootBoxColor[3] = {255, 255, 0};
inline constexpr std::uint8_t kLeafBoxColor[3] = {0, 255, 0};
inline constexpr std::uint8_t kEscapeColor[3] = {255, 0, 0};

// World -> pixel projection of a CameraDesc with the PinholeCamera convention
// (camera.h): pixel corners at integers, y = 0 on top.
class Projection {
 public:
  Projection(const rt::CameraDesc& desc, int width, int height);
  // Camera-space depth along the forward axis (positive in front).
  float depth(const Vec3& world) const;
  // The pixel position of a point in front of the eye (depth > 0).
  Vec2 to_pixel(const Vec3& world) const;
  float near_depth() const { return near_; }

 private:
  Vec3 eye_{0.0f};
  Vec3 forward_{0.0f};
  Vec3 right_{0.0f};
  Vec3 up_{0.0f};
  float tan_half_fovy_ = 1.0f;
  float aspect_ = 1.0f;
  float width_ = 1.0f;
  float height_ = 1.0f;
  float near_ = 1e-3f;
};

// An RGBA8 image being drawn on (row 0 on top).
struct ImageRef {
  int width = 0;
  int height = 0;
  std::span<std::uint8_t> rgba;
};

// Draws the world-space segment a-b, clipped against the near plane (parts
// behind the eye are dropped) and the image borders.
void draw_segment(const ImageRef& image, const Projection& projection, const Vec3& a, const Vec3& b,
                  const std::uint8_t (&color)[3]);

// Draws the 12 edges of `box` (in a bone's frame) carried to the world by
// `bone_to_world`. Empty boxes draw nothing.
void draw_box(const ImageRef& image, const Projection& projection, const Aabb& box, const Affine3& bone_to_world,
              const std::uint8_t (&color)[3]);

// The cells of a tree's non-empty leaves (the root cell split down each
// path), in the tree's frame.
std::vector<Aabb> leaf_cells(const rt::KdTreeView& tree);

// A BVH bone tree's leaf boxes (each holds its triangles' fuzzy boxes).
std::vector<Aabb> bvh_leaf_boxes(const rt::BvhView& tree);

// Per triangle: the largest item count among the leaves listing it (0 for
// triangles in no leaf), from one walk over every bone tree.
std::vector<std::uint32_t> leaf_heat(const rt::FuzzyCharacterView& fuzzy, std::size_t triangle_count);

// The boxes overlay for `bone` (root box, then leaf cells).
void draw_bone_boxes(const ImageRef& image, const Projection& projection, const rt::FuzzyCharacterView& fuzzy,
                     std::uint32_t bone, const Affine3& skinning);

// Tints pixels of `instance` by their triangle's heat (others untouched).
void apply_heat(const ImageRef& image, std::span<const std::uint32_t> triangle_id,
                std::span<const std::uint32_t> instance_id, std::uint32_t instance,
                std::span<const std::uint32_t> heat);

// Paints pixels of `instance` whose triangle is in `escaped` (any order).
// Returns the number of pixels painted.
std::size_t apply_escapes(const ImageRef& image, std::span<const std::uint32_t> triangle_id,
                          std::span<const std::uint32_t> instance_id, std::uint32_t instance,
                          std::span<const std::uint32_t> escaped, std::size_t triangle_count);

}  // namespace sinew::editor::gui
