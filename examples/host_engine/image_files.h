// Writing the frame's images: binary PPM (colour) and PFM (float depth), two
// formats simple enough to write in a few lines and read in any image tool.
#pragma once

#include <string>

#include "host_raster.h"

namespace host {

// RGBA8 rows (top to bottom) as a binary P6 PPM, alpha dropped.
bool write_ppm(const std::string& path, const Image& rgba8);
// One float per pixel as a greyscale PFM ("Pf", little-endian scale -1.0,
// rows bottom to top as the format requires); +inf stays +inf.
bool write_pfm(const std::string& path, const Image& depth);

}  // namespace host
