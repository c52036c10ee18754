// Soft shadows and ambient occlusion in the demo: the settings, their
// command-line options and the --soft preset, and how a frame's render
// settings take them. Lengths are metres of the demo world, where every
// character stands kCharacterHeight tall.
//
// Off by default: hard shadows from a point light and no ambient
// occlusion, the demo's reference look and frame rate. --soft turns on the
// preset that makes the arena look like a game scene (soft_preset());
// --light-radius, --shadow-samples, --ao-rays and --ao-radius set each
// value alone, over the preset when both are given.
#pragma once

#include <optional>
#include <span>
#include <string>

#include "raytrace/render/render_settings.h"
#include "runtime/cli/command_line.h"
#include "runtime/core/expected.h"

namespace sinew::demo {

// Every character's height in the demo world, in metres (model_to_world).
inline constexpr float kCharacterHeight = 1.8f;

struct SoftLighting {
  float light_radius = 0.0f;  // every point light's sphere radius (m); 0: hard point lights
  int shadow_samples = rt::RenderSettings{}.shadow_samples;  // rays per hit towards each sphere light
  int ao_rays = 0;                                    // ambient occlusion rays per hit; 0: none
  float ao_radius = 0.5f * kCharacterHeight;          // how far they reach (m)

  bool operator==(const SoftLighting&) const = default;
};

// The --soft preset: a sphere light of radius 0.3 x the characters'
// height sampled 4 times per hit, and 4 ambient occlusion rays reaching
// half their height: penumbrae that widen away from the feet, and
// darkened contact under the characters and where the boxes meet the
// floor, at a cost a game budgets for.
SoftLighting soft_preset();

// Writes `soft` into the settings a frame renders with, and its radius
// into each point light among `lights` (directional lights stay as they
// are).
void apply_soft_lighting(const SoftLighting& soft, rt::RenderSettings& settings, std::span<rt::Light> lights);

// The options --soft, --light-radius R, --shadow-samples S, --ao-rays A and
// --ao-radius R, declared on a command line (like every option there, their
// text is read after its parse()).
class SoftLightingFlags {
 public:
  explicit SoftLightingFlags(cli::CommandLine& line);
  // The settings given (the preset first, then each option over it);
  // errors name the option and the value.
  Expected<SoftLighting> parse() const;

 private:
  const bool& soft_;
  const std::optional<std::string>& light_radius_;
  const std::optional<std::string>& shadow_samples_;
  const std::optional<std::string>& ao_rays_;
  const std::optional<std::string>& ao_radius_;
};

}  // namespace sinew::demo
