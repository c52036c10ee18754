// Structural mutations of a content pack for the character-pack fuzzer
// (character_pack_fuzz.cpp), applied before re-sealing (reseal_pack.h) so
// the section decoders and validators see well-formed containers with
// wrong contents: a section's payload zeroed, two sections' ids or places
// swapped, a section shifted or cut short, one section's bytes copied over
// another's. The classes of hostile input in docs/ROBUSTNESS.md ("Hostile
// input") are what it aims at: all-zero and swapped-but-sealed sections.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <random>
#include <span>
#include <utility>
#include <vector>

#include "runtime/pack/pack_format.h"

namespace sinew::fuzz {

// Mutates `all` in place; false when it holds no readable section table.
// Reads only what it has proved to be inside `all`.
inline bool mutate_pack_structure(std::span<std::byte> all, unsigned int seed) {
  if (all.size() < kHeaderSize) return false;
  const PackHeader header = load_pack_header(all.first<kHeaderSize>());
  const std::uint64_t size = all.size();
  const std::uint64_t table_size = std::uint64_t{header.section_count} * kSectionEntrySize;
  if (header.section_count == 0 || header.section_count > kMaxSections || header.table_offset > size ||
      table_size > size - header.table_offset) {
    return false;
  }
  const auto raw = [&](std::uint64_t i) {
    return all.subspan(header.table_offset + i * kSectionEntrySize).first<kSectionEntrySize>();
  };
  std::vector<SectionEntry> entries;
  for (std::uint64_t i = 0; i < header.section_count; ++i) entries.push_back(load_section_entry(raw(i)));
  const auto inside = [&](const SectionEntry& e) { return e.offset <= size && e.size <= size - e.offset; };
  std::mt19937 g(seed);
  const std::size_t a = g() % entries.size(), b = g() % entries.size();
  SectionEntry& ea = entries[a];
  SectionEntry& eb = entries[b];
  switch (g() % 6) {
    case 0:  // a payload zeroed
      if (!inside(ea)) return false;
      std::memset(all.data() + ea.offset, 0, ea.size);
      return true;
    case 1:  // ids swapped: each payload decoded as the other's section
      std::swap(ea.id, eb.id);
      std::swap(ea.version, eb.version);
      break;
    case 2:  // places swapped
      std::swap(ea.offset, eb.offset);
      std::swap(ea.size, eb.size);
      break;
    case 3: {  // shifted by whole alignment steps, either way
      // Unsigned and range-checked: a mutated table may hold any offset,
      // up to 2^64 - 1, so signed arithmetic here could overflow.
      const unsigned int pick = g() % 9;
      if (pick == 4) return false;
      const std::uint64_t step = std::uint64_t{pick < 4 ? 4u - pick : pick - 4u} * kSectionAlignment;
      if (pick < 4) {
        if (ea.offset < step) return false;
        ea.offset -= step;
      } else {
        if (ea.offset > UINT64_MAX - step) return false;
        ea.offset += step;
      }
      break;
    }
    case 4:  // cut short
      if (ea.size == 0) return false;
      ea.size = (g() % ea.size) / 4 * 4;
      break;
    default:  // one payload's bytes over another's
      if (a == b || !inside(ea) || !inside(eb)) return false;
      std::memmove(all.data() + eb.offset, all.data() + ea.offset, std::min(ea.size, eb.size));
      return true;
  }
  store_section_entry(ea, raw(a));
  store_section_entry(eb, raw(b));
  return true;
}

}  // namespace sinew::fuzz
