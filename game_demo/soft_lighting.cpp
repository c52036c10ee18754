#include "game_demo/soft_lighting.h"

#include <cstdint>

#include "runtime/cli/option_values.h"

namespace sinew::demo {
namespace {

// The longest light radius and occlusion reach taken: far past the arena,
// so any larger value is a typing slip.
constexpr double kMaxLengthMetres = 1000.0;

}  // namespace

SoftLighting soft_preset() {
  SoftLighting soft;
  soft.light_radius = 0.3f * kCharacterHeight;
  soft.shadow_samples = 4;
  soft.ao_rays = 4;
  soft.ao_radius = 0.5f * kCharacterHeight;
  return soft;
}

void apply_soft_lighting(const SoftLighting& soft, rt::RenderSettings& settings, std::span<rt::Light> lights) {
  settings.shadow_samples = soft.shadow_samples;
  settings.ao_rays = soft.ao_rays;
  settings.ao_radius = soft.ao_radius;
  for (rt::Light& light : lights) {
    if (light.kind == rt::Light::Kind::kPoint) light.radius = soft.light_radius;
  }
}

SoftLightingFlags::SoftLightingFlags(cli::CommandLine& line)
    : soft_(line.flag("--soft", "soft shadows and ambient occlusion: a sphere light of radius 0.54 m,\n"
                                "4 shadow samples, 4 ambient occlusion rays of 0.9 m (default off)")),
      light_radius_(line.option("--light-radius", "R",
                                "point lights become spheres of radius R m with soft shadows\n"
                                "(0-1000; default 0: hard, 0.54 with --soft)")),
      shadow_samples_(
          line.option("--shadow-samples", "S", "shadow rays per hit towards each sphere light (1-256, default 4)")),
      ao_rays_(
          line.option("--ao-rays", "A", "ambient occlusion rays per hit (0-256; default 0: none, 4 with --soft)")),
      ao_radius_(line.option("--ao-radius", "R",
                             "how far ambient occlusion rays reach, in m (default 0.9: half a\n"
                             "character's height)")) {}

Expected<SoftLighting> SoftLightingFlags::parse() const {
  SoftLighting soft = soft_ ? soft_preset() : SoftLighting{};
  if (light_radius_) {
    SINEW_ASSIGN_OR_RETURN(const double r, cli::parse_double("--light-radius", *light_radius_, 0.0, kMaxLengthMetres));
    soft.light_radius = static_cast<float>(r);
  }
  if (shadow_samples_) {
    SINEW_ASSIGN_OR_RETURN(const std::int64_t n,
                           cli::parse_int("--shadow-samples", *shadow_samples_, 1, rt::kMaxSamples));
    soft.shadow_samples = static_cast<int>(n);
  }
  if (ao_rays_) {
    SINEW_ASSIGN_OR_RETURN(const std::int64_t n, cli::parse_int("--ao-rays", *ao_rays_, 0, rt::kMaxSamples));
    soft.ao_rays = static_cast<int>(n);
  }
  if (ao_radius_) {
    SINEW_ASSIGN_OR_RETURN(const double r, cli::parse_double("--ao-radius", *ao_radius_, 0.0, kMaxLengthMetres));
    // A ray of length 0 finds nothing, and the renderer refuses it.
    if (!(r > 0.0)) return invalid_argument("--ao-radius", *ao_radius_, "expected a length above 0");
    soft.ao_radius = static_cast<float>(r);
  }
  return soft;
}

}  // namespace sinew::demo
