// How a frame is seen and lit: the pass's camera and lights
// (sinew/pass.h), and what a character suggests for them
// (Character::framing, sinew/character.h).
#pragma once

#include <cstdint>

#include "sinew/math.h"

namespace sinew::api {

struct Camera {  // a pinhole camera; y = 0 is the image's top row
  Float3 eye{0.0f, 1.0f, 4.0f};
  Float3 target{0.0f, 1.0f, 0.0f};
  Float3 up{0.0f, 1.0f, 0.0f};
  float fovy_degrees = 45.0f;
};

struct Light {
  enum class Kind : std::uint8_t { kPoint, kDirectional, kRect };
  Kind kind = Kind::kPoint;
  Float3 position{4.0f, 8.0f, 6.0f};   // kPoint, kRect: the centre
  Float3 direction{0.4f, 1.0f, 0.6f};  // kDirectional: towards the light
  Float3 color{1.0f, 1.0f, 1.0f};      // linear RGB, no distance falloff
  // The light's size. A light of size 0 is hard: one shadow ray per hit.
  // An area light casts PassInputs::shadow_samples rays per hit towards
  // stratified points on it, and its shadow is the fraction that arrive: a
  // soft shadow whose penumbra widens with the size (docs/EMBEDDING.md, "Soft
  // shadows and ambient occlusion").
  float radius = 0.0f;          // kPoint: a sphere light's radius (world units)
  float angular_radius = 0.0f;  // kDirectional: the sun's half angle (radians, below 1.5)
  // kRect: the rectangle's two full edges (it spans position +- edge / 2 in
  // each); it lights both of its sides. Always an area light.
  Float3 edge_u{0.0f, 0.0f, 0.0f};
  Float3 edge_v{0.0f, 0.0f, 0.0f};
};

}  // namespace sinew::api
