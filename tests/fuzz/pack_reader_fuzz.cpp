// libFuzzer target for the content-pack reader (docs/PACK_FORMAT.md, "Running
// the pack fuzzer").
//
// Each input is tried twice: as is, and "re-sealed" — file_size and all
// checksums recomputed wherever the structure lets us find what they cover.
// Random mutations almost never keep a 64-bit checksum right, so without the
// second pass the fuzzer would only ever exercise the checks before the
// header checksum; with it, every structural check (bounds, overflow,
// overlap, duplicates, padding) sees arbitrary values.
//
// Beyond ASan/UBSan findings, the harness traps on broken contracts: an
// accepted pack whose sections lie outside the input, a section that cannot
// be found by its own id, or an error without a code, field or value.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "runtime/pack/checksum.h"
#include "runtime/pack/pack_format.h"
#include "runtime/pack/pack_reader.h"

namespace {

using sinew::ErrorCode;
using sinew::PackReader;

void require(bool condition) {
  if (!condition) __builtin_trap();
}

// Makes the checksums and file_size agree with the bytes, so the reader's
// structural checks get to judge the rest. Reads only what it has proved to
// be inside `bytes` (the harness must not be the thing that overflows).
void reseal(std::vector<std::byte>& bytes) {
  using namespace sinew;
  if (bytes.size() < kHeaderSize) return;
  const auto all = std::span(bytes);
  PackHeader header = load_pack_header(all.first<kHeaderSize>());
  header.file_size = bytes.size();
  const std::uint64_t size = bytes.size();
  const std::uint64_t table_size = std::uint64_t{header.section_count} * kSectionEntrySize;
  if (header.section_count <= kMaxSections && header.table_offset <= size &&
      table_size <= size - header.table_offset) {
    for (std::uint64_t i = 0; i < header.section_count; ++i) {
      const auto raw = all.subspan(header.table_offset + i * kSectionEntrySize)
                           .first<kSectionEntrySize>();
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

// Opens `bytes` and, when they are accepted, reads everything a loader could.
void exercise(std::span<const std::byte> bytes) {
  auto reader = PackReader::from_bytes(bytes, "fuzz.pack");
  if (!reader.ok()) {
    const sinew::Status& status = reader.status();
    require(status.code() != ErrorCode::kOk && status.code() != ErrorCode::kInternal);
    require(!status.field().empty() && !status.value().empty());
    return;
  }
  const auto whole = reader->bytes();
  require(whole.data() == bytes.data() && whole.size() == bytes.size());
  std::uint64_t sum = 0;
  for (const sinew::SectionInfo& info : reader->sections()) {
    require(info.offset % sinew::kSectionAlignment == 0);
    require(info.offset <= whole.size() && info.size <= whole.size() - info.offset);
    require(reader->find(info.id) == &info);
    auto payload = reader->section_bytes(info.id);
    require(payload.ok());
    for (std::byte b : *payload) sum += std::to_integer<unsigned>(b);
    auto words = reader->section_as<std::uint32_t>(info.id);
    if (words.ok()) {
      for (std::uint32_t w : *words) sum += w;
    } else {
      require(words.status().code() == ErrorCode::kInvalidData ||
              words.status().code() == ErrorCode::kMisaligned);
    }
  }
  // Keep the reads from being optimised away.
  volatile std::uint64_t sink = sum;
  (void)sink;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // libFuzzer's buffer is a fresh heap allocation of exactly `size` bytes, so
  // ASan catches any read past the end of the input.
  const auto bytes = std::as_bytes(std::span(data, size));
  exercise(bytes);

  if (size >= sinew::kHeaderSize) {
    std::vector<std::byte> sealed(bytes.begin(), bytes.end());
    reseal(sealed);
    exercise(sealed);
  }
  return 0;
}
