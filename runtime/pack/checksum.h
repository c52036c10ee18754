// Checksums used by the content pack: XXH3_64 (seed 0) from the system
// libxxhash. The algorithm is part of the on-disk format: changing it (or the
// seed) is a major format version bump (runtime/pack/pack_format.h).
//
// xxhash.h stays out of this header so that only checksum.cpp depends on it
// and the library's link to libxxhash can remain private.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "runtime/pack/pack_format.h"

namespace sinew {

// XXH3_64 of `bytes` with seed 0. Any span is fine, including an empty one.
std::uint64_t checksum64(std::span<const std::byte> bytes);

// The value PackHeader::header_checksum must hold: checksum64 of the 64
// header bytes with the header_checksum field set to zero.
std::uint64_t pack_header_checksum(const PackHeader& header);

}  // namespace sinew
