// The HUD's soft-lighting toggles (HudControls): they start as the session
// renders, a toggle turned on starts at the --soft preset's values, and a
// toggle turned off keeps its values for when it comes back on.
#include <gtest/gtest.h>

#include "game_demo/hud.h"
#include "game_demo/soft_lighting.h"

namespace sinew::demo {
namespace {

TEST(HudSoftLighting, TogglesStartAsTheSessionRendersAndTurnOnAtThePreset) {
  HudControls controls;
  controls.take(SoftLighting{});
  EXPECT_FALSE(controls.soft_shadows);
  EXPECT_FALSE(controls.ambient_occlusion);
  EXPECT_EQ(controls.soft_lighting(), SoftLighting{}) << "off renders as the default";

  controls.soft_shadows = true;
  controls.ambient_occlusion = true;
  EXPECT_EQ(controls.soft_lighting(), soft_preset());
}

TEST(HudSoftLighting, ATogglesValuesStayWhileItIsOff) {
  SoftLighting given;
  given.light_radius = 0.25f;
  given.shadow_samples = 8;
  given.ao_rays = 2;
  given.ao_radius = 1.5f;
  HudControls controls;
  controls.take(given);
  EXPECT_TRUE(controls.soft_shadows);
  EXPECT_TRUE(controls.ambient_occlusion);
  EXPECT_EQ(controls.soft_lighting(), given);

  controls.soft_shadows = false;
  controls.ambient_occlusion = false;
  const SoftLighting off = controls.soft_lighting();
  EXPECT_EQ(off.light_radius, 0.0f);
  EXPECT_EQ(off.ao_rays, 0);
  controls.soft_shadows = true;
  controls.ambient_occlusion = true;
  EXPECT_EQ(controls.soft_lighting(), given);
}

}  // namespace
}  // namespace sinew::demo
