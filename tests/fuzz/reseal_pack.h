// Re-sealing a mutated content pack for the fuzzers: file_size and every
// checksum recomputed over the bytes, wherever the (bounds-checked) structure
// lets us find what they cover. Random mutations almost never keep a 64-bit
// checksum right, so without this the fuzzers would only exercise the checks
// in front of the checksums.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "runtime/pack/checksum.h"
#include "runtime/pack/pack_format.h"

namespace sinew::fuzz {

// Reads only what it has proved to be inside `all` (the harness must not be
// the thing that overflows).
inline void reseal_pack(std::span<std::byte> all) {
  if (all.size() < kHeaderSize) return;
  PackHeader header = load_pack_header(all.first<kHeaderSize>());
  const std::uint64_t size = all.size();
  header.file_size = size;
  const std::uint64_t table_size = std::uint64_t{header.section_count} * kSectionEntrySize;
  if (header.section_count <= kMaxSections && header.table_offset <= size &&
      table_size <= size - header.table_offset) {
    for (std::uint64_t i = 0; i < header.section_count; ++i) {
      const auto raw = all.subspan(header.table_offset + i * kSectionEntrySize).first<kSectionEntrySize>();
      SectionEntry entry = load_section_entry(raw);
      if (entry.offset <= size && entry.size <= size - entry.offset) {
        entry.checksum = checksum64(all.subspan(entry.offset, entry.size));
        store_section_entry(entry, raw);
      }
    }
    header.table_checksum = checksum64(all.subspan(header.table_offset, table_size));
  }
  header.header_checksum = pack_header_checksum(header);
  store_pack_header(header, all.first<kHeaderSize>());
}

}  // namespace sinew::fuzz
