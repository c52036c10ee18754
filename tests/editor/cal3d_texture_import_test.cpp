// Cal3D material maps: Paladin's first <MAP> of each material becomes its
// texture, one per distinct file, each the size its TGA header gives and
// its top-left texel the one the file stores (bottom-up rows, BGR) decoded
// here by hand; Hero's maps are missing beside it, which is one warning
// per material naming the file, and the import goes on.
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "editor/import/cal3d_importer.h"
#include "runtime/image/texture.h"

namespace sinew::editor {
namespace {

const std::string kContent = std::string(SINEW_SHARED_DIR) + "/content/cal3d/";

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Each material line of the .cfg, in order: the first <MAP> of its file.
std::vector<std::string> first_maps(const std::string& folder, const std::string& cfg) {
  std::vector<std::string> maps;
  const std::string text = read_text(folder + cfg);
  const std::regex material("material=(\\S+)"), map("<MAP>([^<]+)</MAP>");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), material); it != std::sregex_iterator(); ++it) {
    const std::string xrf = read_text(folder + (*it)[1].str());
    std::smatch m;
    maps.push_back(std::regex_search(xrf, m, map) ? m[1].str() : "");
  }
  return maps;
}

TEST(Cal3dTextures, PaladinsMaterialsCarryTheirFirstMapsTexelForTexel) {
  const std::string folder = kContent + "paladin/";
  const auto m = import_cal3d(folder + "paladin.cfg");
  ASSERT_TRUE(m.ok()) << m.status().message();
  for (const std::string& w : m->warnings) EXPECT_EQ(w.find("map"), std::string::npos) << w;
  const std::vector<std::string> maps = first_maps(folder, "paladin.cfg");
  ASSERT_EQ(maps.size(), 19u);
  ASSERT_EQ(m->mesh.material_texture.size(), m->mesh.material_colors.size());
  std::set<std::string> distinct;
  for (std::size_t i = 0; i < maps.size(); ++i) {
    SCOPED_TRACE(maps[i]);
    ASSERT_NE(maps[i], "");
    distinct.insert(maps[i]);
    const std::uint32_t t = m->mesh.material_texture[i];
    ASSERT_LT(t, m->mesh.textures.size());
    const Texture& texture = m->mesh.textures[t];
    EXPECT_EQ(texture.name, maps[i]);
    // An uncompressed 24-bit TGA: width and height at bytes 12 and 14,
    // then rows of BGR from the bottom up (descriptor 0).
    const std::string tga = read_text(folder + maps[i]);
    ASSERT_EQ(tga[2], 2);
    ASSERT_EQ(tga[17], 0);
    const auto u16 = [&](std::size_t at) {
      return static_cast<std::uint32_t>(static_cast<unsigned char>(tga[at]) |
                                        static_cast<unsigned char>(tga[at + 1]) << 8);
    };
    const std::uint32_t w = u16(12), h = u16(14);
    ASSERT_EQ(texture.levels[0].width, w);
    ASSERT_EQ(texture.levels[0].height, h);
    for (const std::uint32_t x : {0u, w / 3, w - 1}) {
      for (const std::uint32_t y : {0u, h / 2, h - 1}) {
        const std::size_t at = 18 + 3 * (static_cast<std::size_t>(h - 1 - y) * w + x);
        for (int c = 0; c < 3; ++c) {
          const float byte = static_cast<unsigned char>(tga[at + static_cast<std::size_t>(2 - c)]);
          EXPECT_NEAR(texture.levels[0].texels[static_cast<std::size_t>(y) * w + x][static_cast<std::size_t>(c)] /
                          65535.0f,
                      srgb_to_linear(byte / 255.0f), 1.0f / 65535.0f)
              << "texel " << x << "," << y << " channel " << c;
        }
      }
    }
  }
  EXPECT_EQ(m->mesh.textures.size(), distinct.size());
}

TEST(Cal3dTextures, MissingMapsAreOneWarningEachAndTheMaterialsKeepTheirColours) {
  const auto m = import_cal3d(kContent + "hero/hero.cfg");
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_TRUE(m->mesh.textures.empty());
  EXPECT_TRUE(m->mesh.material_texture.empty());
  int warned = 0;
  for (const std::string& w : m->warnings) {
    if (w.find("hero_head2.tga") != std::string::npos || w.find("hero_body.tga") != std::string::npos) {
      EXPECT_NE(w.find("no such file"), std::string::npos) << w;
      EXPECT_NE(w.find("colour is used"), std::string::npos) << w;
      ++warned;
    }
  }
  EXPECT_EQ(warned, 2);
}

}  // namespace
}  // namespace sinew::editor
