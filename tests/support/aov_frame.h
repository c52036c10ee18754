// Every output (AOV) of one rendered frame, packed rows, owned by the test:
// the renderer's FrameBuffers over them, and a poison fill so a pixel the
// renderer forgot to write shows up as a failure.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include "raytrace/render/renderer.h"
#include "runtime/math/types.h"

namespace sinew::testing_support {

struct AovFrame {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba8;
  std::vector<float> rgba32f;
  std::vector<float> depth;
  std::vector<Vec3> normal;
  std::vector<std::uint32_t> instance_id;
  std::vector<std::uint32_t> triangle_id;
  std::vector<Vec2> uv;
  std::vector<Vec2> barycentric;
  std::vector<std::uint32_t> material_id;

  AovFrame(int w, int h)
      : width(w),
        height(h),
        rgba8(4 * pixels()),
        rgba32f(4 * pixels()),
        depth(pixels()),
        normal(pixels()),
        instance_id(pixels()),
        triangle_id(pixels()),
        uv(pixels()),
        barycentric(pixels()),
        material_id(pixels()) {}

  std::size_t pixels() const { return static_cast<std::size_t>(width) * static_cast<std::size_t>(height); }

  // NaN floats, a marker id, a marker colour byte.
  void poison() {
    constexpr float nan = std::numeric_limits<float>::quiet_NaN();
    std::fill(rgba8.begin(), rgba8.end(), std::uint8_t{7});
    std::fill(rgba32f.begin(), rgba32f.end(), nan);
    std::fill(depth.begin(), depth.end(), nan);
    std::fill(normal.begin(), normal.end(), Vec3(nan));
    std::fill(instance_id.begin(), instance_id.end(), 0xDEADBEEFu);
    std::fill(triangle_id.begin(), triangle_id.end(), 0xDEADBEEFu);
    std::fill(uv.begin(), uv.end(), Vec2(nan));
    std::fill(barycentric.begin(), barycentric.end(), Vec2(nan));
    std::fill(material_id.begin(), material_id.end(), 0xDEADBEEFu);
  }

  rt::FrameBuffers buffers() {
    rt::FrameBuffers b;
    b.width = width;
    b.height = height;
    b.color_rgba8 = rgba8;
    b.color_rgba32f = rgba32f;
    b.depth = depth;
    b.normal = normal;
    b.instance_id = instance_id;
    b.triangle_id = triangle_id;
    b.uv = uv;
    b.barycentric = barycentric;
    b.material_id = material_id;
    return b;
  }
};

}  // namespace sinew::testing_support
