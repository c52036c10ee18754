// Encoding and decoding of a section's payload: little-endian scalars,
// length-prefixed strings and counted arrays, appended in order. Loaders
// decode with SectionDecoder, which never reads past the payload and names
// the pack, the section and the field in every error:
//
//   cally.pack: MESH.positions: count 4294967295 x 12 bytes: past the end of the section (1 024 bytes left)
//
// Only little-endian hosts are supported (the pack format is little-endian
// and payload arrays are copied or viewed as they lie).
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "runtime/core/expected.h"
#include "runtime/pack/pack_format.h"

namespace sinew {

static_assert(std::endian::native == std::endian::little, "content packs are read on little-endian hosts only");

// A string in a section: u32 byte length, then the bytes (no terminator).
inline constexpr std::uint32_t kMaxSectionString = 1u << 20;

class SectionEncoder {
 public:
  template <typename T>
  void put(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* p = reinterpret_cast<const std::byte*>(&value);
    bytes_.insert(bytes_.end(), p, p + sizeof(T));
  }
  void put_string(const std::string& text);
  // The elements only; the caller writes the count where the format has it.
  template <typename T>
  void put_array(std::span<const T> values) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* p = reinterpret_cast<const std::byte*>(values.data());
    bytes_.insert(bytes_.end(), p, p + values.size_bytes());
  }

  std::vector<std::byte>& bytes() { return bytes_; }

 private:
  std::vector<std::byte> bytes_;
};

class SectionDecoder {
 public:
  SectionDecoder(std::span<const std::byte> payload, std::string pack, SectionId section)
      : bytes_(payload), pack_(std::move(pack)), section_(section_id_name(section)) {}

  template <typename T>
  Status get(T& out, std::string_view field) {
    static_assert(std::is_trivially_copyable_v<T>);
    SINEW_RETURN_IF_ERROR(need(sizeof(T), 1, field));
    std::memcpy(&out, bytes_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return {};
  }
  Status get_string(std::string& out, std::string_view field);
  // `count` elements into `out` (resized); checked against the bytes left
  // before anything is allocated, so a corrupt count cannot exhaust memory.
  template <typename T>
  Status get_array(std::uint64_t count, std::vector<T>& out, std::string_view field) {
    static_assert(std::is_trivially_copyable_v<T>);
    SINEW_RETURN_IF_ERROR(need(sizeof(T), count, field));
    out.resize(static_cast<std::size_t>(count));
    if (count > 0) std::memcpy(out.data(), bytes_.data() + pos_, static_cast<std::size_t>(count) * sizeof(T));
    pos_ += static_cast<std::size_t>(count) * sizeof(T);
    return {};
  }
  // Everything decoded: trailing bytes are an error (kInvalidData).
  Status finish() const;

  // An error about this section's `field` (kInvalidData unless given).
  Status error(std::string_view field, std::string_view value, std::string_view detail,
               ErrorCode code = ErrorCode::kInvalidData) const;
  const std::string& pack() const { return pack_; }
  const std::string& section() const { return section_; }

 private:
  Status need(std::size_t element_size, std::uint64_t count, std::string_view field) const;

  std::span<const std::byte> bytes_;
  std::size_t pos_ = 0;
  std::string pack_;
  std::string section_;
};

}  // namespace sinew
