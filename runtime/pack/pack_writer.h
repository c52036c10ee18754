// PackWriter: assembles sections in memory and writes a content pack.
//
// The writer owns copies of the payloads it is given (the editor's bake
// produces them and may free its own buffers right after add_section). The
// output is deterministic: the same sections added in the same order give a
// byte-identical pack, laid out header, table, then payloads in insertion
// order, each at the next 64-byte boundary, all gaps zero. No timestamps or
// host details are stored, so bakes are reproducible.
//
// write() goes through AtomicFileWriter: the destination either keeps its old
// contents or holds the complete new pack, never a half-written one.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "runtime/core/expected.h"
#include "runtime/pack/pack_format.h"

namespace sinew {

class PackWriter {
 public:
  // Adds a section after those already added. Errors: kDuplicate when `id`
  // was added before, kLimitExceeded beyond kMaxSections sections. Either
  // way the writer is unchanged.
  Status add_section(SectionId id, std::uint32_t version, std::span<const std::byte> payload);
  // As above, taking the payload without copying it.
  Status add_section(SectionId id, std::uint32_t version, std::vector<std::byte>&& payload);

  std::size_t section_count() const { return sections_.size(); }

  // The whole pack as bytes. kLimitExceeded if it would not fit in memory
  // addressing (a sum of sizes that overflows).
  Expected<std::vector<std::byte>> serialize() const;

  // Writes the pack to `path` atomically, streaming the payloads (the file is
  // never assembled in memory). `verify`, when given, reads the complete
  // temporary file (its path) before it replaces anything; its error
  // aborts the write. Errors: kIoError naming the path, those of
  // serialize(), and verify's, named after `path`.
  Status write(const std::string& path,
               const std::function<Status(const std::string& written)>& verify = {}) const;

 private:
  struct Section {
    SectionId id;
    std::uint32_t version;
    std::uint64_t checksum;
    std::vector<std::byte> payload;
  };
  struct Layout {
    std::vector<std::byte> head;          // header + table + padding up to the first section
    std::vector<std::uint64_t> offsets;   // per section, in insertion order
    std::uint64_t file_size = 0;
  };

  Expected<Layout> layout() const;
  Status check_new_id(SectionId id) const;

  std::vector<Section> sections_;
};

}  // namespace sinew
