#include "runtime/pack/pack_writer.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <limits>
#include <utility>

#include "runtime/io/atomic_file.h"
#include "runtime/pack/checksum.h"

namespace sinew {
namespace {

constexpr std::uint64_t kU64Max = std::numeric_limits<std::uint64_t>::max();
constexpr std::array<std::byte, kSectionAlignment> kZeros{};

bool checked_add(std::uint64_t a, std::uint64_t b, std::uint64_t* out) {
  if (b > kU64Max - a) return false;
  *out = a + b;
  return true;
}

bool checked_align_up(std::uint64_t value, std::uint64_t* out) {
  std::uint64_t bumped = 0;
  if (!checked_add(value, kSectionAlignment - 1, &bumped)) return false;
  *out = bumped / kSectionAlignment * kSectionAlignment;
  return true;
}

Status too_large(std::string_view what) {
  return make_error(ErrorCode::kLimitExceeded, "", "pack size", "",
                    std::string(what) + " does not fit in 64-bit offsets");
}

}  // namespace

Status PackWriter::check_new_id(SectionId id) const {
  for (const Section& s : sections_) {
    if (s.id == id) {
      return make_error(ErrorCode::kDuplicate, "", "section", "'" + section_id_name(id) + "'",
                        "a section with this id was already added");
    }
  }
  if (sections_.size() >= kMaxSections) {
    return make_error(ErrorCode::kLimitExceeded, "", "section count",
                      std::to_string(sections_.size() + 1),
                      "a pack holds at most " + std::to_string(kMaxSections) + " sections");
  }
  return Status{};
}

Status PackWriter::add_section(SectionId id, std::uint32_t version,
                               std::span<const std::byte> payload) {
  SINEW_RETURN_IF_ERROR(check_new_id(id));
  return add_section(id, version, std::vector<std::byte>(payload.begin(), payload.end()));
}

Status PackWriter::add_section(SectionId id, std::uint32_t version,
                               std::vector<std::byte>&& payload) {
  SINEW_RETURN_IF_ERROR(check_new_id(id));
  const std::uint64_t sum = checksum64(payload);
  sections_.push_back(Section{id, version, sum, std::move(payload)});
  return Status{};
}

Expected<PackWriter::Layout> PackWriter::layout() const {
  Layout out;
  const std::uint64_t table_offset = kHeaderSize;
  const std::uint64_t table_size = sections_.size() * std::uint64_t{kSectionEntrySize};
  std::uint64_t cursor = table_offset + table_size;  // count <= kMaxSections: no overflow
  if (!checked_align_up(cursor, &cursor)) return too_large("the section table");
  const std::uint64_t head_size = cursor;

  out.offsets.reserve(sections_.size());
  for (const Section& s : sections_) {
    std::uint64_t offset = 0;
    if (!checked_align_up(cursor, &offset) || !checked_add(offset, s.payload.size(), &cursor)) {
      return too_large("the sections");
    }
    out.offsets.push_back(offset);
  }
  out.file_size = cursor;

  std::vector<std::byte> table(static_cast<std::size_t>(table_size));
  for (std::size_t i = 0; i < sections_.size(); ++i) {
    const Section& s = sections_[i];
    SectionEntry entry{};
    entry.id = static_cast<std::uint32_t>(s.id);
    entry.version = s.version;
    entry.offset = out.offsets[i];
    entry.size = s.payload.size();
    entry.alignment = kSectionAlignment;
    entry.flags = 0;
    entry.checksum = s.checksum;
    entry.reserved = 0;
    store_section_entry(entry, std::span(table).subspan(i * kSectionEntrySize)
                                   .first<kSectionEntrySize>());
  }

  PackHeader header{};
  std::memcpy(header.magic, kPackMagic, sizeof kPackMagic);
  header.endian_tag = kEndianTag;
  header.version_major = kPackVersionMajor;
  header.version_minor = kPackVersionMinor;
  header.header_size = kHeaderSize;
  header.section_count = static_cast<std::uint32_t>(sections_.size());
  header.file_size = out.file_size;
  header.table_offset = table_offset;
  header.table_checksum = checksum64(table);
  header.reserved = 0;
  header.header_checksum = pack_header_checksum(header);

  out.head.assign(static_cast<std::size_t>(head_size), std::byte{0});
  store_pack_header(header, std::span(out.head).first<kHeaderSize>());
  std::copy(table.begin(), table.end(), out.head.begin() + kHeaderSize);
  return out;
}

Expected<std::vector<std::byte>> PackWriter::serialize() const {
  SINEW_ASSIGN_OR_RETURN(Layout layout, this->layout());
  if (layout.file_size > std::vector<std::byte>().max_size()) {
    return too_large("the pack");
  }
  std::vector<std::byte> out(static_cast<std::size_t>(layout.file_size), std::byte{0});
  std::copy(layout.head.begin(), layout.head.end(), out.begin());
  for (std::size_t i = 0; i < sections_.size(); ++i) {
    const auto& payload = sections_[i].payload;
    std::copy(payload.begin(), payload.end(),
              out.begin() + static_cast<std::ptrdiff_t>(layout.offsets[i]));
  }
  return out;
}

Status PackWriter::write(const std::string& path,
                         const std::function<Status(const std::string& written)>& verify) const {
  auto named = [&path](Status status) { return status.with_file(path); };
  auto layout = this->layout();
  if (!layout.ok()) return named(layout.status());
  auto writer = AtomicFileWriter::create(path);
  if (!writer.ok()) return named(writer.status());

  // Padding is at most 63 bytes at a time, written from a static zero block.
  std::uint64_t written = 0;
  const auto pad_to = [&](std::uint64_t offset) -> Status {
    const auto gap = static_cast<std::size_t>(offset - written);
    SINEW_RETURN_IF_ERROR(writer->write(std::span(kZeros).first(gap)));
    written = offset;
    return Status{};
  };
  SINEW_RETURN_IF_ERROR(named(writer->write(layout->head)));
  written = layout->head.size();
  for (std::size_t i = 0; i < sections_.size(); ++i) {
    SINEW_RETURN_IF_ERROR(named(pad_to(layout->offsets[i])));
    SINEW_RETURN_IF_ERROR(named(writer->write(sections_[i].payload)));
    written += sections_[i].payload.size();
  }
  SINEW_RETURN_IF_ERROR(named(pad_to(layout->file_size)));
  if (verify) {
    if (Status s = verify(writer->temp_path()); !s.ok()) {
      writer->discard();
      return named(s);
    }
  }
  return named(writer->commit());
}

}  // namespace sinew
