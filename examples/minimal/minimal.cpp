// The smallest Sinew host (docs/EMBEDDING.md, which quotes the code below):
// load a pack, play its first clip, render one frame, write the colour as a
// PPM.  c++ -std=c++20 minimal.cpp $(pkg-config --cflags --libs sinew) -o minimal
#include <sinew/sinew.h>
#include <cstdio>
#include <fstream>
#include <vector>
namespace api = sinew::api;

int main(int argc, char** argv) {
  if (argc != 3) return std::fprintf(stderr, "usage: minimal PACK OUT.ppm\n"), 2;
  const auto fail = [](const api::Error& e) { return std::fprintf(stderr, "sinew: %s\n", e.message.c_str()), 1; };
  auto character = api::Character::load(argv[1]);
  if (!character) return fail(character.error());
  auto world = api::World::create();
  if (!world) return fail(world.error());
  auto instance = world->add_instance(*character);  // mixer-driven, at the origin
  if (!instance) return fail(instance.error());
  if (auto s = world->play_cycle(*instance, "#0", 1.0f, 0.0f); !s) return fail(s.error());
  if (auto s = world->advance(0.5f); !s) return fail(s.error());  // 0.5 s into the clip

  constexpr int kSize = 256;
  auto pass = api::RayTracePass::create({.width = kSize, .height = kSize, .outputs = api::Output::kColorRgba8});
  if (!pass) return fail(pass.error());
  std::vector<unsigned char> rgba(kSize * kSize * 4);
  api::PassOutputs out;
  out.color_rgba8 = {rgba.data(), kSize * 4};  // the row pitch in bytes
  // The pack's framing: upright and in view whichever axis the model stands along.
  const api::Character::Framing framing = character->framing(1.0f);  // a square image
  api::PassInputs inputs;
  inputs.camera = framing.camera;
  inputs.lights = {&framing.light, 1};
  auto stats = pass->execute(*world, inputs, out);
  if (!stats) return fail(stats.error());
  std::ofstream ppm(argv[2], std::ios::binary);
  ppm << "P6\n" << kSize << ' ' << kSize << "\n255\n";
  for (int i = 0; i < kSize * kSize; ++i) ppm.write(reinterpret_cast<const char*>(&rgba[4 * i]), 3);
  return ppm ? 0 : 1;
}
