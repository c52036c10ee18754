// PackReader: validated, zero-copy access to a content pack.
//
// open() / from_bytes() check the whole pack before handing anything out:
// magic, endian tag, version, header and table checksums, the bounds,
// alignment and disjointness of every section, unique ids, zero padding and
// every payload checksum (docs/PACK_FORMAT.md lists the order and the error
// code of each check). A reader that exists is therefore a pack whose every
// byte has been accounted for; the accessors only look things up.
//
// The validation never reads outside the input, whatever it holds: every
// offset and size is checked with overflow-safe arithmetic before the bytes
// it names are touched, and fields are copied out with memcpy. Errors name
// the pack, the field ("section[2].offset") and the bad value.
//
// Ownership: a reader from open() owns its memory mapping; one from
// from_bytes() only views the caller's bytes, which must outlive it. Spans
// returned by the accessors point into that memory (no copy) and are valid as
// long as the reader (or the caller's buffer) is. Moving a reader keeps them
// valid. Thread safety: const methods may be called concurrently.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "runtime/core/expected.h"
#include "runtime/io/mapped_file.h"
#include "runtime/pack/pack_format.h"

namespace sinew {

// A validated table entry.
struct SectionInfo {
  SectionId id{};
  std::uint32_t version = 0;  // the section's own payload version
  std::uint64_t offset = 0;   // from the start of the pack; a multiple of 64
  std::uint64_t size = 0;     // payload bytes
  std::uint64_t checksum = 0;
};

class PackReader {
 public:
  // Maps `path` and validates it. Errors: those of MappedFile::open
  // (kNotFound, kIoError) and every validation error, naming `path`.
  static Expected<PackReader> open(const std::string& path);

  // Validates `bytes` in place without copying; `name` is used in messages.
  static Expected<PackReader> from_bytes(std::span<const std::byte> bytes, std::string name);

  PackReader(PackReader&&) noexcept = default;
  PackReader& operator=(PackReader&&) noexcept = default;
  PackReader(const PackReader&) = delete;
  PackReader& operator=(const PackReader&) = delete;
  ~PackReader() = default;

  // The file's format version (major is always kPackVersionMajor).
  PackVersion version() const { return version_; }
  const std::string& name() const { return name_; }
  // The whole pack, header included.
  std::span<const std::byte> bytes() const { return bytes_; }

  // Sections in table order.
  std::size_t section_count() const { return sections_.size(); }
  std::span<const SectionInfo> sections() const { return sections_; }
  // kOutOfBounds when `index` >= section_count().
  Expected<SectionInfo> section_info(std::size_t index) const;

  // The section with `id`, or nullptr when the pack has none.
  const SectionInfo* find(SectionId id) const;
  bool contains(SectionId id) const { return find(id) != nullptr; }

  // The payload of section `id`. kNotFound names the id ("SKEL").
  Expected<std::span<const std::byte>> section_bytes(SectionId id) const;
  // The payload of a section of this reader (from sections() / find()).
  std::span<const std::byte> section_bytes(const SectionInfo& info) const;

  // The payload of section `id` viewed as an array of T, in place.
  // kNotFound as above; kInvalidData when the size is not a multiple of
  // sizeof(T); kMisaligned when the payload's address is not aligned for T
  // (cannot happen for alignof(T) <= 64 on a pack from open(), whose mapping
  // is page aligned; from_bytes() inherits the caller buffer's alignment).
  // T must be an implicit-lifetime, trivially copyable type such as an
  // integer, a float or a struct of them; the loader that asks for it still
  // validates the values (counts, indices, finite floats).
  template <typename T>
  Expected<std::span<const T>> section_as(SectionId id) const;

 private:
  PackReader() = default;

  static Expected<PackReader> parse(std::span<const std::byte> bytes, std::string name);
  Status misaligned_view_error(SectionId id, std::size_t size, std::size_t type_size,
                               std::size_t type_align, bool size_ok) const;

  std::optional<MappedFile> file_;  // set by open(); bytes_ points into it
  std::span<const std::byte> bytes_;
  std::string name_;
  PackVersion version_;
  std::vector<SectionInfo> sections_;   // table order
  std::vector<std::uint32_t> by_id_;    // indices into sections_, sorted by id
};

template <typename T>
Expected<std::span<const T>> PackReader::section_as(SectionId id) const {
  static_assert(std::is_trivially_copyable_v<T>, "section_as<T> needs a trivially copyable T");
  static_assert(!std::is_reference_v<T> && sizeof(T) > 0);
  SINEW_ASSIGN_OR_RETURN(std::span<const std::byte> raw, section_bytes(id));
  if (raw.empty()) return std::span<const T>();
  const bool size_ok = raw.size() % sizeof(T) == 0;
  const bool align_ok = reinterpret_cast<std::uintptr_t>(raw.data()) % alignof(T) == 0;
  if (!size_ok || !align_ok) {
    return misaligned_view_error(id, raw.size(), sizeof(T), alignof(T), size_ok);
  }
  // The bytes are mapped file data with no C++ objects in them; T is
  // trivially copyable, so treating them as T is how in-place loading works
  // in practice (C++23 would spell this std::start_lifetime_as_array).
  const auto* first = static_cast<const T*>(static_cast<const void*>(raw.data()));
  return std::span<const T>(first, raw.size() / sizeof(T));
}

}  // namespace sinew
