// glTF base colour textures: a synthetic skinned triangle whose texture is
// a PNG in a data URI (the texels against the sRGB bytes written, the
// sampler's wrap modes, the texCoord set the material names), a broken
// image (a warning naming the material, the import goes on), and
// CesiumMan's embedded JPEG against OpenImageIO's own 8-bit read of the
// same bytes.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "editor/import/gltf_importer.h"
#include "runtime/image/image_io.h"
#include "runtime/image/texture.h"

namespace sinew::editor {
namespace {

namespace fs = std::filesystem;

std::string base64(const std::vector<unsigned char>& bytes) {
  static const char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
    std::uint32_t group = 0;
    for (std::size_t k = 0; k < 3; ++k) group = group << 8 | (k < n ? std::uint32_t{bytes[i + k]} : 0u);
    for (std::size_t k = 0; k < 4; ++k) out += k <= n ? kDigits[(group >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

std::vector<unsigned char> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

template <typename T>
void put(std::vector<unsigned char>& b, std::size_t at, T v) {
  std::memcpy(b.data() + at, &v, sizeof v);
}

class GltfTextures : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("sinew_gltf_texture_test_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::create_directories(dir_);
    // A 4x2 RGB image, every byte different.
    for (int i = 0; i < 4 * 2 * 3; ++i) pixels_.push_back(static_cast<std::uint8_t>(11 * i + 7));
    ASSERT_TRUE(write_png((dir_ / "skin.png").string(), 4, 2, 3, pixels_).ok());
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  // One skinned triangle with two uv sets; its material's texture reads set
  // `tex_coord` of image `image_uri`.
  std::string write(int tex_coord, const std::string& image_uri) {
    std::vector<unsigned char> bin(144, 0);
    const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    for (int i = 0; i < 9; ++i) put(bin, static_cast<std::size_t>(4 * i), pos[i]);
    for (int v = 0; v < 3; ++v) put(bin, static_cast<std::size_t>(48 + 16 * v), 1.0f);  // weight 1 on joint 0
    const float uv0[6] = {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f}, uv1[6] = {-1.5f, 2.5f, 0.75f, 0.25f, 3.0f, -2.0f};
    for (int i = 0; i < 6; ++i) {
      put(bin, static_cast<std::size_t>(96 + 4 * i), uv0[i]);
      put(bin, static_cast<std::size_t>(120 + 4 * i), uv1[i]);
    }
    nlohmann::json j = {
        {"asset", {{"version", "2.0"}}},
        {"scene", 0},
        {"scenes", {{{"nodes", {0, 1}}}}},
        {"nodes", {{{"mesh", 0}, {"skin", 0}}, {{"name", "root"}}}},
        {"skins", {{{"joints", {1}}}}},
        {"meshes",
         {{{"primitives",
            {{{"attributes", {{"POSITION", 0}, {"JOINTS_0", 1}, {"WEIGHTS_0", 2}, {"TEXCOORD_0", 3}, {"TEXCOORD_1", 4}}},
              {"material", 0}}}}}}},
        {"materials",
         {{{"name", "skin"},
           {"pbrMetallicRoughness",
            {{"baseColorFactor", {1.0, 0.5, 1.0, 1.0}}, {"baseColorTexture", {{"index", 0}, {"texCoord", tex_coord}}}}}}}},
        {"textures", {{{"sampler", 0}, {"source", 0}}}},
        {"samplers", {{{"wrapS", 33071}, {"wrapT", 33648}}}},
        {"images", {{{"uri", image_uri}}}},
        {"buffers", {{{"uri", "data:application/octet-stream;base64," + base64(bin)}, {"byteLength", 144}}}},
        {"bufferViews", {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 144}}}},
        {"accessors",
         {{{"bufferView", 0}, {"byteOffset", 0}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"},
           {"min", {0, 0, 0}}, {"max", {1, 1, 0}}},
          {{"bufferView", 0}, {"byteOffset", 36}, {"componentType", 5121}, {"count", 3}, {"type", "VEC4"}},
          {{"bufferView", 0}, {"byteOffset", 48}, {"componentType", 5126}, {"count", 3}, {"type", "VEC4"}},
          {{"bufferView", 0}, {"byteOffset", 96}, {"componentType", 5126}, {"count", 3}, {"type", "VEC2"}},
          {{"bufferView", 0}, {"byteOffset", 120}, {"componentType", 5126}, {"count", 3}, {"type", "VEC2"}}}},
    };
    const std::string path = (dir_ / "triangle.gltf").string();
    std::ofstream(path) << j.dump();
    return path;
  }

  std::string png_data_uri() { return "data:image/png;base64," + base64(read_bytes((dir_ / "skin.png").string())); }

  fs::path dir_;
  std::vector<std::uint8_t> pixels_;
};

TEST_F(GltfTextures, AnEmbeddedPngBecomesTheMaterialsLinearTextureWithItsSamplersWrapModes) {
  const auto m = import_gltf(write(0, png_data_uri()));
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_TRUE(m->warnings.empty()) << m->warnings.front();
  ASSERT_EQ(m->mesh.textures.size(), 1u);
  ASSERT_EQ(m->mesh.material_texture, std::vector<std::uint32_t>{0});
  EXPECT_EQ(m->mesh.material_colors[0], Vec3(1.0f, 0.5f, 1.0f));  // the factor multiplies the texture
  const Texture& t = m->mesh.textures[0];
  EXPECT_EQ(t.wrap_u, TextureWrap::kClamp);   // 33071 CLAMP_TO_EDGE
  EXPECT_EQ(t.wrap_v, TextureWrap::kMirror);  // 33648 MIRRORED_REPEAT
  ASSERT_EQ(t.levels[0].width, 4u);
  ASSERT_EQ(t.levels[0].height, 2u);
  EXPECT_EQ(t.levels.size(), 3u);  // 4x2, 2x1, 1x1
  for (std::size_t p = 0; p < 8; ++p) {
    for (std::size_t c = 0; c < 3; ++c) {
      const float want = srgb_to_linear(static_cast<float>(pixels_[3 * p + c]) / 255.0f);
      EXPECT_NEAR(t.levels[0].texels[p][c] / 65535.0f, want, 1.0f / 65535.0f) << "texel " << p;
    }
  }
  EXPECT_EQ(m->mesh.uvs[1], Vec2(0.3f, 0.4f));
}

TEST_F(GltfTextures, TheUvsAreTheSetTheMaterialsTextureNames) {
  const auto m = import_gltf(write(1, "skin.png"));  // a file beside the asset, this time
  ASSERT_TRUE(m.ok()) << m.status().message();
  ASSERT_EQ(m->mesh.textures.size(), 1u);
  ASSERT_EQ(m->mesh.uvs.size(), 3u);
  EXPECT_EQ(m->mesh.uvs[0], Vec2(-1.5f, 2.5f));
  EXPECT_EQ(m->mesh.uvs[2], Vec2(3.0f, -2.0f));
}

TEST_F(GltfTextures, AnImageThatCannotBeReadIsAWarningAndTheMaterialKeepsItsColour) {
  // (A file outside the asset's folder is refused outright, as buffers
  // are: the sandbox's tests cover that.)
  for (const std::string& uri : {std::string("missing.png"), std::string("data:image/png;base64,AAAAAAAA")}) {
    SCOPED_TRACE(uri);
    const auto m = import_gltf(write(0, uri));
    ASSERT_TRUE(m.ok()) << m.status().message();
    EXPECT_TRUE(m->mesh.textures.empty());
    EXPECT_TRUE(m->mesh.material_texture.empty());
    ASSERT_EQ(m->warnings.size(), 1u);
    EXPECT_NE(m->warnings[0].find("material 'skin'"), std::string::npos) << m->warnings[0];
    EXPECT_NE(m->warnings[0].find("images[0]"), std::string::npos) << m->warnings[0];
    EXPECT_NE(m->warnings[0].find("colour is used"), std::string::npos) << m->warnings[0];
  }
}

TEST(GltfTexturesShared, CesiumMansEmbeddedJpegMatchesOpenImageIosOwnRead) {
  const std::string path = std::string(SINEW_SHARED_DIR) + "/content/gltf/CesiumMan/CesiumMan.glb";
  const auto m = import_gltf(path);
  ASSERT_TRUE(m.ok()) << m.status().message();
  ASSERT_EQ(m->mesh.textures.size(), 1u);
  ASSERT_EQ(m->mesh.material_texture, std::vector<std::uint32_t>{0});
  // The JPEG's bytes, from the .glb by hand: images[0]'s buffer view in the
  // BIN chunk.
  const std::vector<unsigned char> glb = read_bytes(path);
  std::uint32_t json_length = 0;
  std::memcpy(&json_length, glb.data() + 12, 4);
  const auto json = nlohmann::json::parse(glb.begin() + 20, glb.begin() + 20 + json_length);
  const auto& view = json["bufferViews"][json["images"][0]["bufferView"].get<std::size_t>()];
  const std::size_t bin = 20 + json_length + 8;
  const std::size_t offset = bin + view.value("byteOffset", std::size_t{0});
  const std::string jpeg_path = (fs::temp_directory_path() / "sinew_cesium_man_texture.jpg").string();
  std::ofstream(jpeg_path, std::ios::binary)
      .write(reinterpret_cast<const char*>(glb.data() + offset), view["byteLength"].get<std::streamsize>());
  auto in = OIIO::ImageInput::open(jpeg_path);
  ASSERT_TRUE(in);
  const OIIO::ImageSpec spec = in->spec();
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(spec.width * spec.height * spec.nchannels));
  ASSERT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, bytes.data()));
  in->close();
  fs::remove(jpeg_path);
  const TextureLevel& level = m->mesh.textures[0].levels[0];
  ASSERT_EQ(level.width, static_cast<std::uint32_t>(spec.width));
  ASSERT_EQ(level.height, static_cast<std::uint32_t>(spec.height));
  double worst = 0.0;
  for (std::size_t p = 0; p < level.texels.size(); p += 97) {
    for (std::size_t c = 0; c < 3; ++c) {
      const double want = srgb_to_linear(bytes[p * static_cast<std::size_t>(spec.nchannels) + c] / 255.0f);
      worst = std::max(worst, std::fabs(static_cast<double>(level.texels[p][c]) / 65535.0 - want));
    }
  }
  EXPECT_LT(worst, 1.5 / 65535.0);
}

}  // namespace
}  // namespace sinew::editor
