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
#include "tests/fuzz/reseal_pack.h"

namespace {

using sinew::ErrorCode;
using sinew::PackReader;

void require(bool condition) {
  if (!condition) __builtin_trap();
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
    sinew::fuzz::reseal_pack(sealed);
    exercise(sealed);
  }
  return 0;
}
