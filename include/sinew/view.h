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
  enum class Kind : std::uint8_t { kPoint, kDirectional };
  Kind kind = Kind::kPoint;
  Float3 position{4.0f, 8.0f, 6.0f};   // kPoint
  Float3 direction{0.4f, 1.0f, 0.6f};  // kDirectional: towards the light
  Float3 color{1.0f, 1.0f, 1.0f};      // linear RGB, no distance falloff
};

}  // namespace sinew::api
