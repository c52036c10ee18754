// On-disk layout of a Sinew content pack (docs/PACK_FORMAT.md is the prose
// version of this file; keep the two in step).
//
//     [0, 64)                    PackHeader
//     [table_offset, +n * 48)    SectionEntry[section_count]
//     zero padding to 64
//     section payloads, each at a 64-byte aligned offset, zero padding between
//
// Every byte of a valid pack is covered by a check: the header and the table
// by their own checksums, each payload by its entry's checksum, and every
// byte in between (padding) must be zero. A single flipped byte anywhere is
// therefore always reported.
//
// All integers are little-endian. Fields are read with memcpy from the raw
// bytes into these structs (never by casting a pointer into the file), so the
// reader works on any input alignment. Payloads themselves are used in place
// as spans of host types, which is why a big-endian host is refused at
// compile time rather than silently misreading data.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <type_traits>

namespace sinew {

static_assert(std::endian::native == std::endian::little,
              "packs are little-endian and used in place: big-endian hosts are unsupported");

// A section's type tag: four ASCII characters stored in file order, so the
// bytes "SKEL" in a hex dump are the id make_section_id("SKEL").
enum class SectionId : std::uint32_t {};

constexpr SectionId make_section_id(const char (&fourcc)[5]) {
  std::uint32_t value = 0;
  for (int i = 3; i >= 0; --i) {
    value = value << 8 | static_cast<unsigned char>(fourcc[i]);
  }
  return static_cast<SectionId>(value);
}

// "SKEL" when all four bytes are printable ASCII, "0x0000002a" otherwise, so
// error messages stay readable for corrupted ids.
inline std::string section_id_name(SectionId id) {
  const auto value = static_cast<std::uint32_t>(id);
  std::string text;
  for (int i = 0; i < 4; ++i) {
    const auto c = static_cast<unsigned char>((value >> (8 * i)) & 0xffu);
    if (c < 0x20 || c > 0x7e) {
      static constexpr char kHex[] = "0123456789abcdef";
      std::string hex = "0x";
      for (int shift = 28; shift >= 0; shift -= 4) hex += kHex[(value >> shift) & 0xfu];
      return hex;
    }
    text += static_cast<char>(c);
  }
  return text;
}

// Format version. A reader accepts every pack with its own major version,
// whatever the minor: minor bumps only add new section ids or new per-section
// payload versions (each entry carries its own), which an older reader can
// ignore. Anything that changes the header, the table entries, the meaning of
// flags or reserved fields, or the checksum algorithm is a major bump.
inline constexpr std::uint16_t kPackVersionMajor = 1;
inline constexpr std::uint16_t kPackVersionMinor = 0;

inline constexpr char kPackMagic[8] = {'S', 'I', 'N', 'E', 'W', 'P', 'K', '\0'};
// Written as the integer 0x01020304; a pack produced by a writer that stored
// integers big-endian reads back as 0x04030201.
inline constexpr std::uint32_t kEndianTag = 0x01020304u;
inline constexpr std::uint32_t kEndianTagSwapped = 0x04030201u;

inline constexpr std::size_t kHeaderSize = 64;
inline constexpr std::size_t kSectionEntrySize = 48;
// Every section payload (and the section table) starts at a multiple of this
// offset from the start of the file: enough for any SIMD type and a cache line.
inline constexpr std::uint32_t kSectionAlignment = 64;
// A sanity cap, far above what a character needs (a dozen sections), that
// bounds the work and memory the reader spends on the table before it trusts it.
inline constexpr std::uint32_t kMaxSections = 4096;
// The largest pack a reader accepts (64 GiB): thousands of times a
// subdivided character, and small enough that validating it (every byte is
// checksummed or checked to be zero padding) ends in bounded time. A larger
// file is refused from its header, before the table or any payload is read.
inline constexpr std::uint64_t kMaxPackBytes = std::uint64_t{1} << 36;

struct PackVersion {
  std::uint16_t major = 0;
  std::uint16_t minor = 0;
  friend constexpr bool operator==(PackVersion, PackVersion) = default;
};

// The 64-byte header at offset 0.
struct PackHeader {
  char magic[8];                 // kPackMagic
  std::uint32_t endian_tag;      // kEndianTag
  std::uint16_t version_major;   // kPackVersionMajor
  std::uint16_t version_minor;   // any value is accepted
  std::uint32_t header_size;     // kHeaderSize
  std::uint32_t section_count;   // <= kMaxSections
  std::uint64_t file_size;       // exact size of the file in bytes
  std::uint64_t table_offset;    // 64-aligned, >= kHeaderSize
  std::uint64_t table_checksum;  // XXH3_64 (seed 0) of the section_count entries
  std::uint64_t header_checksum; // XXH3_64 (seed 0) of these 64 bytes with this field zero
  std::uint64_t reserved;        // must be zero
};

// One entry of the section table.
struct SectionEntry {
  std::uint32_t id;         // SectionId; unique within the pack
  std::uint32_t version;    // payload format version, owned by the section's loader
  std::uint64_t offset;     // from the start of the file; multiple of `alignment`
  std::uint64_t size;       // payload bytes; may be zero
  std::uint32_t alignment;  // kSectionAlignment
  std::uint32_t flags;      // no flags are defined in 1.x: must be zero
  std::uint64_t checksum;   // XXH3_64 (seed 0) of the payload
  std::uint64_t reserved;   // must be zero
};

static_assert(sizeof(PackHeader) == kHeaderSize);
static_assert(sizeof(SectionEntry) == kSectionEntrySize);
static_assert(std::is_trivially_copyable_v<PackHeader> && std::is_standard_layout_v<PackHeader>);
static_assert(std::is_trivially_copyable_v<SectionEntry> &&
              std::is_standard_layout_v<SectionEntry>);
// No hidden padding: every byte of the structs is a named field, so a memcpy
// round trip is exact and checksums are well defined.
static_assert(std::has_unique_object_representations_v<PackHeader>);
static_assert(std::has_unique_object_representations_v<SectionEntry>);
static_assert(offsetof(PackHeader, endian_tag) == 8);
static_assert(offsetof(PackHeader, version_major) == 12);
static_assert(offsetof(PackHeader, version_minor) == 14);
static_assert(offsetof(PackHeader, header_size) == 16);
static_assert(offsetof(PackHeader, section_count) == 20);
static_assert(offsetof(PackHeader, file_size) == 24);
static_assert(offsetof(PackHeader, table_offset) == 32);
static_assert(offsetof(PackHeader, table_checksum) == 40);
static_assert(offsetof(PackHeader, header_checksum) == 48);
static_assert(offsetof(PackHeader, reserved) == 56);
static_assert(offsetof(SectionEntry, version) == 4);
static_assert(offsetof(SectionEntry, offset) == 8);
static_assert(offsetof(SectionEntry, size) == 16);
static_assert(offsetof(SectionEntry, alignment) == 24);
static_assert(offsetof(SectionEntry, flags) == 28);
static_assert(offsetof(SectionEntry, checksum) == 32);
static_assert(offsetof(SectionEntry, reserved) == 40);

// Raw (unvalidated) decoding and encoding. The fixed-extent spans make the
// caller prove the bytes exist; nothing here checks the values.
inline PackHeader load_pack_header(std::span<const std::byte, kHeaderSize> bytes) {
  PackHeader header;
  std::memcpy(&header, bytes.data(), kHeaderSize);
  return header;
}

inline void store_pack_header(const PackHeader& header, std::span<std::byte, kHeaderSize> out) {
  std::memcpy(out.data(), &header, kHeaderSize);
}

inline SectionEntry load_section_entry(std::span<const std::byte, kSectionEntrySize> bytes) {
  SectionEntry entry;
  std::memcpy(&entry, bytes.data(), kSectionEntrySize);
  return entry;
}

inline void store_section_entry(const SectionEntry& entry,
                                std::span<std::byte, kSectionEntrySize> out) {
  std::memcpy(out.data(), &entry, kSectionEntrySize);
}

}  // namespace sinew
