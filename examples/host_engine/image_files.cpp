#include "image_files.h"

#include <bit>
#include <fstream>
#include <vector>

namespace host {

bool write_ppm(const std::string& path, const Image& rgba8) {
  std::ofstream file(path, std::ios::binary);
  file << "P6\n" << rgba8.width() << ' ' << rgba8.height() << "\n255\n";
  std::vector<char> rgb(static_cast<std::size_t>(rgba8.width()) * 3);
  for (int y = 0; y < rgba8.height(); ++y) {
    const std::uint8_t* row = rgba8.row<std::uint8_t>(y);
    for (int x = 0; x < rgba8.width(); ++x) {
      for (int c = 0; c < 3; ++c) rgb[static_cast<std::size_t>(3 * x + c)] = static_cast<char>(row[4 * x + c]);
    }
    file.write(rgb.data(), static_cast<std::streamsize>(rgb.size()));
  }
  return static_cast<bool>(file.flush());
}

bool write_pfm(const std::string& path, const Image& depth) {
  static_assert(std::endian::native == std::endian::little, "the PFM writer assumes a little-endian host");
  std::ofstream file(path, std::ios::binary);
  file << "Pf\n" << depth.width() << ' ' << depth.height() << "\n-1.0\n";
  for (int y = depth.height() - 1; y >= 0; --y) {
    file.write(reinterpret_cast<const char*>(depth.row<float>(y)),
               static_cast<std::streamsize>(sizeof(float) * static_cast<std::size_t>(depth.width())));
  }
  return static_cast<bool>(file.flush());
}

}  // namespace host
