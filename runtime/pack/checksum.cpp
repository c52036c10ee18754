#include "runtime/pack/checksum.h"

#include <xxhash.h>

#include <array>

namespace sinew {

std::uint64_t checksum64(std::span<const std::byte> bytes) {
  // xxHash accepts a null pointer only together with length 0; an empty span
  // may carry either, so give it a valid address regardless.
  static constexpr std::byte kEmpty{};
  const void* data = bytes.empty() ? static_cast<const void*>(&kEmpty) : bytes.data();
  return XXH3_64bits(data, bytes.size());
}

std::uint64_t pack_header_checksum(const PackHeader& header) {
  PackHeader copy = header;
  copy.header_checksum = 0;
  std::array<std::byte, kHeaderSize> raw{};
  store_pack_header(copy, raw);
  return checksum64(raw);
}

}  // namespace sinew
