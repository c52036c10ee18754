#include "character/pack_textures.h"

#include <cstring>
#include <string>

#include "runtime/mesh/mesh_checks.h"

namespace sinew::character {
namespace {

// A full chain of a kMaxTextureSide-sided texture has 15 levels.
constexpr std::uint32_t kMaxLevels = 32;
constexpr std::uint32_t kMaxTextures = 65536;

}  // namespace

bool has_textures(const SkinnedMesh& mesh) {
  for (const std::uint32_t t : mesh.material_texture) {
    if (t != kNoTexture) return true;
  }
  return false;
}

namespace {

// The section's bytes are sized once and filled in place: the texels are
// nearly all of them.
class Filler {
 public:
  explicit Filler(std::size_t size) : bytes_(size) {}
  template <typename T>
  void put(const T& value) {
    put_bytes(&value, sizeof value);
  }
  template <typename T>
  void put_array(const std::vector<T>& values) {
    put_bytes(values.data(), values.size() * sizeof(T));
  }
  void put_string(const std::string& text) {
    put(static_cast<std::uint32_t>(text.size()));
    put_bytes(text.data(), text.size());
  }
  std::vector<std::byte> done() { return std::move(bytes_); }

 private:
  void put_bytes(const void* data, std::size_t size) {
    std::byte* const to = bytes_.data();
    if (size == 0 || to == nullptr) return;
    std::memcpy(to + at_, data, size);
    at_ += size;
  }
  std::vector<std::byte> bytes_;
  std::size_t at_ = 0;
};

}  // namespace

std::vector<std::byte> encode_textures(const SkinnedMesh& mesh) {
  std::size_t size = 4 + 4 * mesh.material_texture.size() + 4;
  for (const Texture& texture : mesh.textures) {
    size += 4 + texture.name.size() + 4 + 4;
    for (const TextureLevel& level : texture.levels) size += 8 + level.texels.size() * sizeof(Texel16);
  }
  Filler e(size);
  e.put(static_cast<std::uint32_t>(mesh.material_texture.size()));
  e.put_array(mesh.material_texture);
  e.put(static_cast<std::uint32_t>(mesh.textures.size()));
  for (const Texture& texture : mesh.textures) {
    e.put_string(texture.name);
    e.put(static_cast<std::uint8_t>(texture.wrap_u));
    e.put(static_cast<std::uint8_t>(texture.wrap_v));
    e.put(std::uint16_t{0});
    e.put(static_cast<std::uint32_t>(texture.levels.size()));
    for (const TextureLevel& level : texture.levels) {
      e.put(level.width);
      e.put(level.height);
      e.put_array(level.texels);
    }
  }
  return e.done();
}

Status decode_textures(SectionDecoder& d, SkinnedMesh& mesh) {
  std::uint32_t materials = 0, textures = 0;
  SINEW_RETURN_IF_ERROR(d.get(materials, "material_count"));
  if (materials != mesh.material_colors.size()) {
    return d.error("material_count", std::to_string(materials),
                   "differs from MESH's " + std::to_string(mesh.material_colors.size()) + " materials",
                   ErrorCode::kInvalidData);
  }
  SINEW_RETURN_IF_ERROR(d.get_array(materials, mesh.material_texture, "material_texture"));
  SINEW_RETURN_IF_ERROR(d.get(textures, "texture_count"));
  if (textures > kMaxTextures) {
    return d.error("texture_count", std::to_string(textures), "more than " + std::to_string(kMaxTextures),
                   ErrorCode::kLimitExceeded);
  }
  mesh.textures.clear();
  for (std::uint32_t t = 0; t < textures; ++t) {
    const std::string f = "textures[" + std::to_string(t) + "]";
    Texture& texture = mesh.textures.emplace_back();
    std::uint8_t wrap_u = 0, wrap_v = 0;
    std::uint16_t reserved = 0;
    std::uint32_t levels = 0;
    SINEW_RETURN_IF_ERROR(d.get_string(texture.name, f + ".name"));
    SINEW_RETURN_IF_ERROR(d.get(wrap_u, f + ".wrap_u"));
    SINEW_RETURN_IF_ERROR(d.get(wrap_v, f + ".wrap_v"));
    SINEW_RETURN_IF_ERROR(d.get(reserved, f + ".reserved"));
    if (reserved != 0) return d.error(f + ".reserved", std::to_string(reserved), "not 0", ErrorCode::kInvalidData);
    texture.wrap_u = static_cast<TextureWrap>(wrap_u);
    texture.wrap_v = static_cast<TextureWrap>(wrap_v);
    SINEW_RETURN_IF_ERROR(d.get(levels, f + ".level_count"));
    if (levels == 0 || levels > kMaxLevels) {
      return d.error(f + ".level_count", std::to_string(levels), "not 1 to " + std::to_string(kMaxLevels),
                     ErrorCode::kInvalidData);
    }
    texture.levels.resize(levels);
    for (std::uint32_t l = 0; l < levels; ++l) {
      const std::string lf = f + ".levels[" + std::to_string(l) + "]";
      TextureLevel& level = texture.levels[l];
      SINEW_RETURN_IF_ERROR(d.get(level.width, lf + ".width"));
      SINEW_RETURN_IF_ERROR(d.get(level.height, lf + ".height"));
      // Bounded before the product sizes a read (check_texture says more below).
      if (level.width == 0 || level.width > kMaxTextureSide || level.height == 0 ||
          level.height > kMaxTextureSide) {
        return d.error(lf + ".width", std::to_string(level.width) + "x" + std::to_string(level.height),
                       "each side must be 1 to " + std::to_string(kMaxTextureSide), ErrorCode::kInvalidData);
      }
      SINEW_RETURN_IF_ERROR(
          d.get_array(static_cast<std::uint64_t>(level.width) * level.height, level.texels, lf + ".texels"));
    }
  }
  SINEW_RETURN_IF_ERROR(d.finish());
  return check_material_textures(MeshOrigin{d.pack(), "TEXR."}, mesh);
}

}  // namespace sinew::character
