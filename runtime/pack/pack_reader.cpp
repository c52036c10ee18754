#include "runtime/pack/pack_reader.h"

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string_view>
#include <utility>

#include "runtime/pack/checksum.h"

namespace sinew {
namespace {

constexpr std::uint64_t kU64Max = std::numeric_limits<std::uint64_t>::max();

// Overflow-safe arithmetic for untrusted offsets and sizes.
bool checked_add(std::uint64_t a, std::uint64_t b, std::uint64_t* out) {
  if (b > kU64Max - a) return false;
  *out = a + b;
  return true;
}

std::string dec(std::uint64_t value) { return std::to_string(value); }

std::string hex(std::uint64_t value, int digits) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "0x%0*" PRIx64, digits, value);
  return buf;
}

std::string hex64(std::uint64_t value) { return hex(value, 16); }

std::string quoted_id(SectionId id) { return "'" + section_id_name(id) + "'"; }

std::string range(std::uint64_t begin, std::uint64_t end) {
  return "[" + dec(begin) + ", " + dec(end) + ")";
}

// The magic as a C-like string literal, so garbage stays one readable line.
std::string printable_magic(const char (&magic)[8]) {
  std::string out = "\"";
  for (char ch : magic) {
    const auto c = static_cast<unsigned char>(ch);
    if (c >= 0x20 && c <= 0x7e && c != '"' && c != '\\') {
      out += static_cast<char>(c);
    } else {
      out += "\\x" + hex(c, 2).substr(2);
    }
  }
  return out + "\"";
}

std::string section_field(std::size_t index, std::string_view field) {
  return "section[" + std::to_string(index) + "]." + std::string(field);
}

// Offset of the first non-zero byte in `bytes`, or bytes.size().
std::size_t first_nonzero(std::span<const std::byte> bytes) {
  const auto it = std::find_if(bytes.begin(), bytes.end(),
                               [](std::byte b) { return b != std::byte{0}; });
  return static_cast<std::size_t>(it - bytes.begin());
}

}  // namespace

Expected<PackReader> PackReader::open(const std::string& path) {
  SINEW_ASSIGN_OR_RETURN(MappedFile file, MappedFile::open(path));
  SINEW_ASSIGN_OR_RETURN(PackReader reader, parse(file.bytes(), path));
  // Moving the MappedFile keeps its address, so reader.bytes_ stays valid.
  reader.file_.emplace(std::move(file));
  return reader;
}

Expected<PackReader> PackReader::from_bytes(std::span<const std::byte> bytes, std::string name) {
  return parse(bytes, std::move(name));
}

// The checks run in the order docs/PACK_FORMAT.md documents; each one only
// relies on facts the earlier ones established, and no byte is read before
// the check that proves it lies inside `bytes`.
Expected<PackReader> PackReader::parse(std::span<const std::byte> bytes, std::string name) {
  const auto fail = [&name](ErrorCode code, std::string_view field, std::string_view value,
                            std::string_view detail) {
    return make_error(code, name, field, value, detail);
  };
  static_assert(sizeof(std::size_t) >= sizeof(std::uint64_t),
                "pack offsets are 64-bit; a 32-bit size_t would need extra range checks");
  const std::uint64_t actual_size = bytes.size();

  // --- header ---------------------------------------------------------------
  if (actual_size < kHeaderSize) {
    return fail(ErrorCode::kTruncated, "header", dec(actual_size) + " bytes",
                "the file is shorter than the " + dec(kHeaderSize) + "-byte pack header");
  }
  const PackHeader header = load_pack_header(bytes.first<kHeaderSize>());

  if (std::memcmp(header.magic, kPackMagic, sizeof kPackMagic) != 0) {
    return fail(ErrorCode::kBadMagic, "header.magic", printable_magic(header.magic),
                "not a Sinew content pack (expected \"SINEWPK\\x00\")");
  }
  if (header.endian_tag == kEndianTagSwapped) {
    return fail(ErrorCode::kUnsupportedVersion, "header.endian_tag", hex(header.endian_tag, 8),
                "the pack was written big-endian; Sinew packs are little-endian");
  }
  if (header.endian_tag != kEndianTag) {
    return fail(ErrorCode::kBadMagic, "header.endian_tag", hex(header.endian_tag, 8),
                "expected " + hex(kEndianTag, 8));
  }
  // The version is checked before the header checksum: magic, endian tag and
  // version are the prefix every major version keeps, while a newer major may
  // checksum its header differently. "Version 2.0" is the useful message then.
  if (header.version_major != kPackVersionMajor) {
    return fail(ErrorCode::kUnsupportedVersion, "header.version",
                dec(header.version_major) + "." + dec(header.version_minor),
                "this build reads format " + dec(kPackVersionMajor) + ".x packs");
  }
  const std::uint64_t header_sum = pack_header_checksum(header);
  if (header.header_checksum != header_sum) {
    return fail(ErrorCode::kChecksumMismatch, "header.header_checksum",
                hex64(header.header_checksum), "the header hashes to " + hex64(header_sum));
  }
  if (header.header_size != kHeaderSize) {
    return fail(ErrorCode::kInvalidData, "header.header_size", dec(header.header_size),
                "format 1.x headers are " + dec(kHeaderSize) + " bytes");
  }
  if (header.reserved != 0) {
    return fail(ErrorCode::kInvalidData, "header.reserved", hex64(header.reserved),
                "reserved bytes must be zero");
  }
  if (header.file_size > actual_size) {
    return fail(ErrorCode::kTruncated, "header.file_size", dec(header.file_size),
                "the file has only " + dec(actual_size) + " bytes");
  }
  if (header.file_size < actual_size) {
    return fail(ErrorCode::kInvalidData, "header.file_size", dec(header.file_size),
                "the file has " + dec(actual_size - header.file_size) +
                    " trailing bytes after the declared end (" + dec(actual_size) +
                    " bytes in all)");
  }
  // After the two checks above, so that a small file claiming a huge size
  // still reads as truncated; here the file really is that large.
  if (actual_size > kMaxPackBytes) {
    return fail(ErrorCode::kLimitExceeded, "header.file_size", dec(actual_size),
                "larger than the " + dec(kMaxPackBytes >> 30) + " GiB a pack may be");
  }
  const std::uint64_t file_size = actual_size;

  // --- section table ----------------------------------------------------------
  if (header.section_count > kMaxSections) {
    return fail(ErrorCode::kLimitExceeded, "header.section_count", dec(header.section_count),
                "more than the " + dec(kMaxSections) + " sections a pack may hold");
  }
  if (header.table_offset < kHeaderSize) {
    return fail(ErrorCode::kOverlap, "header.table_offset", dec(header.table_offset),
                "the section table overlaps the header " + range(0, kHeaderSize));
  }
  if (header.table_offset % kSectionAlignment != 0) {
    return fail(ErrorCode::kMisaligned, "header.table_offset", dec(header.table_offset),
                "not a multiple of " + dec(kSectionAlignment));
  }
  // section_count <= kMaxSections, so the product cannot overflow.
  const std::uint64_t table_size = std::uint64_t{header.section_count} * kSectionEntrySize;
  std::uint64_t table_end = 0;
  if (!checked_add(header.table_offset, table_size, &table_end) || table_end > file_size) {
    return fail(ErrorCode::kOutOfBounds, "header.table_offset", dec(header.table_offset),
                "a table of " + dec(header.section_count) + " entries (" + dec(table_size) +
                    " bytes) there ends past the end of the file (" + dec(file_size) + " bytes)");
  }
  const auto table = bytes.subspan(static_cast<std::size_t>(header.table_offset),
                                   static_cast<std::size_t>(table_size));
  const std::uint64_t table_sum = checksum64(table);
  if (header.table_checksum != table_sum) {
    return fail(ErrorCode::kChecksumMismatch, "header.table_checksum",
                hex64(header.table_checksum), "the section table hashes to " + hex64(table_sum));
  }

  // --- each section on its own ------------------------------------------------
  PackReader reader;
  reader.sections_.reserve(header.section_count);
  for (std::size_t i = 0; i < header.section_count; ++i) {
    const SectionEntry entry =
        load_section_entry(table.subspan(i * kSectionEntrySize).first<kSectionEntrySize>());
    const SectionId id{entry.id};
    if (entry.alignment != kSectionAlignment) {
      return fail(ErrorCode::kMisaligned, section_field(i, "alignment"), dec(entry.alignment),
                  "format 1.x sections are " + dec(kSectionAlignment) + "-byte aligned");
    }
    if (entry.offset % kSectionAlignment != 0) {
      return fail(ErrorCode::kMisaligned, section_field(i, "offset"), dec(entry.offset),
                  "not a multiple of the section alignment " + dec(kSectionAlignment));
    }
    if (entry.flags != 0) {
      return fail(ErrorCode::kInvalidData, section_field(i, "flags"), hex(entry.flags, 8),
                  "no section flags are defined in format 1.x");
    }
    if (entry.reserved != 0) {
      return fail(ErrorCode::kInvalidData, section_field(i, "reserved"), hex64(entry.reserved),
                  "reserved bytes must be zero");
    }
    if (entry.offset > file_size) {
      return fail(ErrorCode::kOutOfBounds, section_field(i, "offset"), dec(entry.offset),
                  "section " + quoted_id(id) + " starts past the end of the file (" +
                      dec(file_size) + " bytes)");
    }
    std::uint64_t end = 0;
    if (!checked_add(entry.offset, entry.size, &end) || end > file_size) {
      return fail(ErrorCode::kOutOfBounds, section_field(i, "size"), dec(entry.size),
                  "section " + quoted_id(id) + " at offset " + dec(entry.offset) +
                      " ends past the end of the file (" + dec(file_size) + " bytes)");
    }
    if (entry.offset < table_end) {
      std::string where;
      if (entry.offset < kHeaderSize) {
        where = "overlaps the header " + range(0, kHeaderSize);
      } else if (end > header.table_offset) {
        where = "overlaps the section table " + range(header.table_offset, table_end);
      } else {
        where = "lies before the section table; sections must follow it";
      }
      return fail(ErrorCode::kOverlap, section_field(i, "offset"), dec(entry.offset),
                  "section " + quoted_id(id) + " " + range(entry.offset, end) + " " + where);
    }
    reader.sections_.push_back(
        SectionInfo{id, entry.version, entry.offset, entry.size, entry.checksum});
  }
  const auto& sections = reader.sections_;
  const std::size_t count = sections.size();

  // --- unique ids ---------------------------------------------------------------
  auto& by_id = reader.by_id_;
  by_id.resize(count);
  for (std::size_t i = 0; i < count; ++i) by_id[i] = static_cast<std::uint32_t>(i);
  std::stable_sort(by_id.begin(), by_id.end(), [&sections](std::uint32_t a, std::uint32_t b) {
    return sections[a].id < sections[b].id;
  });
  // Report the duplicate with the smallest table index, whatever the ids.
  std::size_t dup = count;
  std::size_t dup_of = count;
  for (std::size_t k = 1; k < count; ++k) {
    if (sections[by_id[k]].id == sections[by_id[k - 1]].id && by_id[k] < dup) {
      dup = by_id[k];
      dup_of = by_id[k - 1];
    }
  }
  if (dup != count) {
    // Within a run of equal ids the stable sort keeps table order, so the
    // entry before the duplicate is an earlier section with the same id.
    return fail(ErrorCode::kDuplicate, section_field(dup, "id"), quoted_id(sections[dup].id),
                "the same id as section[" + dec(dup_of) + "]");
  }

  // --- sections pairwise disjoint ---------------------------------------------------
  std::vector<std::uint32_t> by_offset(count);
  for (std::size_t i = 0; i < count; ++i) by_offset[i] = static_cast<std::uint32_t>(i);
  std::sort(by_offset.begin(), by_offset.end(), [&sections](std::uint32_t a, std::uint32_t b) {
    return sections[a].offset != sections[b].offset ? sections[a].offset < sections[b].offset
                                                    : a < b;
  });
  // Empty sections occupy no bytes and overlap nothing.
  std::uint64_t covered_end = table_end;
  std::size_t covered_by = count;  // the section reaching covered_end, if any
  for (std::uint32_t i : by_offset) {
    const SectionInfo& s = sections[i];
    if (s.size == 0) continue;
    if (s.offset < covered_end && covered_by != count) {
      const SectionInfo& other = sections[covered_by];
      return fail(ErrorCode::kOverlap, section_field(i, "offset"), dec(s.offset),
                  "section " + quoted_id(s.id) + " " + range(s.offset, s.offset + s.size) +
                      " overlaps section[" + dec(covered_by) + "] " + quoted_id(other.id) + " " +
                      range(other.offset, other.offset + other.size));
    }
    if (s.offset + s.size > covered_end) {
      covered_end = s.offset + s.size;
      covered_by = i;
    }
  }

  // --- padding is zero ------------------------------------------------------------
  // Every byte outside the header, the table and the payloads; with this,
  // checksums plus zero padding cover the whole file.
  const auto check_zero = [&](std::uint64_t begin, std::uint64_t end) -> Status {
    if (begin >= end) return Status{};
    const auto gap = bytes.subspan(static_cast<std::size_t>(begin),
                                   static_cast<std::size_t>(end - begin));
    const std::size_t at = first_nonzero(gap);
    if (at == gap.size()) return Status{};
    return fail(ErrorCode::kInvalidData, "padding at offset " + dec(begin + at),
                hex(std::to_integer<unsigned>(gap[at]), 2),
                "bytes between the header, the table and the sections must be zero");
  };
  SINEW_RETURN_IF_ERROR(check_zero(kHeaderSize, header.table_offset));
  std::uint64_t cursor = table_end;
  for (std::uint32_t i : by_offset) {
    const SectionInfo& s = sections[i];
    SINEW_RETURN_IF_ERROR(check_zero(cursor, s.offset));
    cursor = std::max(cursor, s.offset + s.size);
  }
  SINEW_RETURN_IF_ERROR(check_zero(cursor, file_size));

  // --- payload checksums (last: the only check that reads every byte) -----------
  for (std::size_t i = 0; i < count; ++i) {
    const SectionInfo& s = sections[i];
    const std::uint64_t sum = checksum64(
        bytes.subspan(static_cast<std::size_t>(s.offset), static_cast<std::size_t>(s.size)));
    if (sum != s.checksum) {
      return fail(ErrorCode::kChecksumMismatch, section_field(i, "checksum"), hex64(s.checksum),
                  "the payload of section " + quoted_id(s.id) + " hashes to " + hex64(sum));
    }
  }

  reader.bytes_ = bytes;
  reader.name_ = std::move(name);
  reader.version_ = PackVersion{header.version_major, header.version_minor};
  return reader;
}

Expected<SectionInfo> PackReader::section_info(std::size_t index) const {
  if (index >= sections_.size()) {
    return make_error(ErrorCode::kOutOfBounds, name_, "section index", dec(index),
                      "the pack has " + dec(sections_.size()) + " sections");
  }
  return sections_[index];
}

const SectionInfo* PackReader::find(SectionId id) const {
  const auto it = std::lower_bound(
      by_id_.begin(), by_id_.end(), id,
      [this](std::uint32_t index, SectionId key) { return sections_[index].id < key; });
  if (it == by_id_.end() || sections_[*it].id != id) return nullptr;
  return &sections_[*it];
}

Expected<std::span<const std::byte>> PackReader::section_bytes(SectionId id) const {
  const SectionInfo* info = find(id);
  if (info == nullptr) {
    return make_error(ErrorCode::kNotFound, name_, "section", quoted_id(id),
                      "the pack has no section with this id");
  }
  return section_bytes(*info);
}

std::span<const std::byte> PackReader::section_bytes(const SectionInfo& info) const {
  // Validated at open: offset + size <= bytes_.size().
  return bytes_.subspan(static_cast<std::size_t>(info.offset), static_cast<std::size_t>(info.size));
}

Status PackReader::misaligned_view_error(SectionId id, std::size_t size, std::size_t type_size,
                                         std::size_t type_align, bool size_ok) const {
  const SectionInfo* info = find(id);
  const std::size_t index = info != nullptr ? static_cast<std::size_t>(info - sections_.data()) : 0;
  if (!size_ok) {
    return make_error(ErrorCode::kInvalidData, name_, section_field(index, "size"), dec(size),
                      "section " + quoted_id(id) + " is not a whole number of " +
                          dec(type_size) + "-byte elements");
  }
  return make_error(ErrorCode::kMisaligned, name_, section_field(index, "offset"),
                    info != nullptr ? dec(info->offset) : "?",
                    "the payload of section " + quoted_id(id) + " is not " + dec(type_align) +
                        "-byte aligned in memory (was the buffer given to from_bytes aligned?)");
}

}  // namespace sinew
