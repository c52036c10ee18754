// The smallest Sinew host: load a pack, play its first clip, render one
// frame, write the colour as a PPM.   usage: minimal PACK OUT.ppm
//
//   c++ -std=c++20 minimal.cpp $(pkg-config --cflags --libs sinew) -o minimal
// (the source before the libraries: GCC links with --as-needed on Debian and
// Ubuntu, which drops a library named before the code that uses it).
#include <cstdio>
#include <fstream>
#include <vector>

#include <sinew/sinew.h>

namespace api = sinew::api;

static int fail(const api::Error& error) {
  std::fprintf(stderr, "sinew: %s\n", error.message.c_str());
  return 1;
}

int main(int argc, char** argv) {
  if (argc != 3) return std::fprintf(stderr, "usage: minimal PACK OUT.ppm\n"), 2;
  auto character = api::Character::load(argv[1]);
  if (!character) return fail(character.error());
  auto world = api::World::create();
  if (!world) return fail(world.error());
  auto instance = world->add_instance(*character);
  if (!instance) return fail(instance.error());
  if (auto s = world->play_cycle(*instance, "#0", 1.0f, 0.0f); !s) return fail(s.error());
  if (auto s = world->advance(0.5f); !s) return fail(s.error());  // 0.5 s into the clip

  constexpr int kSize = 256;
  auto pass = api::RayTracePass::create({.width = kSize, .height = kSize,
                                         .outputs = api::Output::kColorRgba8 | api::Output::kDepth});
  if (!pass) return fail(pass.error());
  std::vector<unsigned char> color(kSize * kSize * 4);
  std::vector<float> depth(kSize * kSize);
  api::PassOutputs out;
  out.color_rgba8 = {color.data(), 0};  // pitch 0: tightly packed rows
  out.depth = {depth.data(), 0};
  const api::Light light;  // a white point light above and in front
  api::PassInputs inputs;  // the default camera looks at a Y-up figure 1 unit up
  inputs.lights = {&light, 1};
  auto stats = pass->execute(*world, inputs, out);
  if (!stats) return fail(stats.error());

  std::ofstream ppm(argv[2], std::ios::binary);
  ppm << "P6\n" << kSize << ' ' << kSize << "\n255\n";
  for (int i = 0; i < kSize * kSize; ++i) ppm.write(reinterpret_cast<const char*>(&color[4 * i]), 3);
  if (!ppm.flush()) return std::fprintf(stderr, "cannot write %s\n", argv[2]), 1;
  std::printf("traced %llu rays in %.2f ms\n", static_cast<unsigned long long>(stats->primary_rays + stats->shadow_rays),
              stats->prepare_ms + stats->trace_ms + stats->shade_ms);
  return 0;
}
