// The TEXR section: textures survive a pack round trip texel for texel, a
// pack without textures has no TEXR (and loads as before), and damaged
// texture data is refused naming the section and field, before anything
// is allocated from a corrupt count.
#include <gtest/gtest.h>

#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "character/pack.h"
#include "character/pack_textures.h"
#include "content/mannequin/mannequin.h"
#include "runtime/pack/pack_reader.h"
#include "tests/support/repack.h"

namespace sinew::character {
namespace {

// The mannequin with uvs and two textured materials of three (one
// texture shared), so the per-material indices matter.
Model textured_model() {
  Model m = content::make_mannequin().value();
  for (const Vec3& p : m.mesh.positions) m.mesh.uvs.emplace_back(p.x, p.y);
  const std::size_t materials = m.mesh.material_colors.size();
  EXPECT_GE(materials, 3u);
  m.mesh.material_texture.assign(materials, kNoTexture);
  m.mesh.material_texture[0] = 1;
  m.mesh.material_texture[2] = 0;
  std::vector<float> a, b;
  for (int i = 0; i < 5 * 3; ++i) a.insert(a.end(), {0.1f * static_cast<float>(i % 7), 0.5f, 1.0f, 1.0f});
  for (int i = 0; i < 2 * 2; ++i) b.insert(b.end(), {0.0f, 0.25f * static_cast<float>(i), 0.3f, 0.5f});
  m.mesh.textures.push_back(make_texture("a.png", 5, 3, a, TextureWrap::kClamp, TextureWrap::kMirror).value());
  m.mesh.textures.push_back(make_texture("b.tga", 2, 2, b, TextureWrap::kRepeat, TextureWrap::kRepeat).value());
  return m;
}

std::vector<std::byte> pack_of(const Model& m) {
  PackContents contents;
  contents.model = &m;
  return serialize_pack(contents).value();
}

TEST(PackTextures, TexturesRoundTripTexelForTexel) {
  const Model m = textured_model();
  const std::vector<std::byte> bytes = pack_of(m);
  const auto pack = Pack::from_bytes(bytes, "t.pack");
  ASSERT_TRUE(pack.ok()) << pack.status().message();
  const SkinnedMesh& got = pack->model().mesh;
  EXPECT_EQ(got.material_texture, m.mesh.material_texture);
  ASSERT_EQ(got.textures.size(), 2u);
  for (std::size_t t = 0; t < 2; ++t) {
    const Texture& want = m.mesh.textures[t];
    EXPECT_EQ(got.textures[t].name, want.name);
    EXPECT_EQ(got.textures[t].wrap_u, want.wrap_u);
    EXPECT_EQ(got.textures[t].wrap_v, want.wrap_v);
    ASSERT_EQ(got.textures[t].levels.size(), want.levels.size());
    for (std::size_t l = 0; l < want.levels.size(); ++l) {
      EXPECT_EQ(got.textures[t].levels[l].width, want.levels[l].width);
      EXPECT_EQ(got.textures[t].levels[l].height, want.levels[l].height);
      EXPECT_EQ(got.textures[t].levels[l].texels, want.levels[l].texels);
    }
  }
}

TEST(PackTextures, APackWithoutTexturesHasNoTextureSection) {
  Model m = textured_model();
  m.mesh.material_texture.clear();
  m.mesh.textures.clear();
  const std::vector<std::byte> bytes = pack_of(m);
  const auto reader = PackReader::from_bytes(bytes, "plain.pack");
  ASSERT_TRUE(reader.ok());
  EXPECT_FALSE(reader->contains(kTexturesSection));
  const auto pack = Pack::from_bytes(bytes, "plain.pack");
  ASSERT_TRUE(pack.ok());
  EXPECT_TRUE(pack->model().mesh.textures.empty());
}

// The offset of the first texture's first level's width in TEXR: after the
// material count and indices, the texture count, the name "a.png", the two
// wrap bytes, the reserved u16 and the level count.
std::size_t first_width_offset(std::size_t materials) { return 4 + 4 * materials + 4 + (4 + 5) + 2 + 2 + 4; }

TEST(PackTextures, DamagedTextureDataIsRefusedNamingTheField) {
  const Model m = textured_model();
  const std::vector<std::byte> bytes = pack_of(m);
  const std::size_t materials = m.mesh.material_colors.size();
  struct Damage {
    std::function<void(std::vector<std::byte>&)> mutate;
    std::string field;
  };
  const auto put_u32 = [](std::vector<std::byte>& p, std::size_t at, std::uint32_t v) {
    std::memcpy(p.data() + at, &v, 4);
  };
  const std::vector<Damage> damages = {
      {[&](auto& p) { put_u32(p, 0, static_cast<std::uint32_t>(materials + 1)); }, "TEXR.material_count"},
      {[&](auto& p) { put_u32(p, 4, 7); }, "TEXR.material_texture[0]"},
      {[&](auto& p) { put_u32(p, 4 + 4 * materials, 0xFFFFFFF0u); }, "TEXR.texture_count"},
      {[&](auto& p) { put_u32(p, first_width_offset(materials), 4); }, "TEXR.textures[0].levels[1].width"},
      {[&](auto& p) { put_u32(p, first_width_offset(materials), 0x40000000u); }, "TEXR.textures[0].levels[0].width"},
      {[&](auto& p) { put_u32(p, first_width_offset(materials) - 4, 1000); }, "TEXR.textures[0].level_count"},
      {[&](auto& p) { p[4 + 4 * materials + 4 + 9] = std::byte{9}; }, "TEXR.textures[0].wrap"},
      {[&](auto& p) { p.pop_back(); }, "TEXR.textures[1].levels[1].texels"},
      {[&](auto& p) { p.push_back(std::byte{0}); }, "TEXR"},
  };
  for (const Damage& d : damages) {
    SCOPED_TRACE(d.field);
    const std::vector<std::byte> damaged = testing_support::repack_section(bytes, kTexturesSection, d.mutate);
    const auto pack = Pack::from_bytes(damaged, "t.pack");
    ASSERT_FALSE(pack.ok());
    EXPECT_NE(pack.status().message().find(d.field), std::string::npos) << pack.status().message();
  }
  // A texture section of another version is named, not misread.
  const std::vector<std::byte> later =
      testing_support::repack_section(bytes, kTexturesSection, [](auto&) {}, kTexturesVersion + 1);
  const auto refused = Pack::from_bytes(later, "t.pack");
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), ErrorCode::kUnsupportedVersion);
}

}  // namespace
}  // namespace sinew::character
