// A real pack with one section's payload rewritten and the container sealed
// again (checksums recomputed): only that section's own decoding and
// validation stand between the damaged bytes and the loader. The corruption
// tests of the character pack build on it.
#pragma once

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "runtime/pack/pack_reader.h"
#include "runtime/pack/pack_writer.h"

namespace sinew::testing_support {

// `pack` with section `id`'s payload replaced by mutate(payload), and its
// payload version by `version` when given.
inline std::vector<std::byte> repack_section(std::span<const std::byte> pack, SectionId id,
                                             const std::function<void(std::vector<std::byte>&)>& mutate,
                                             std::optional<std::uint32_t> version = std::nullopt) {
  auto reader = PackReader::from_bytes(pack, "pristine");
  EXPECT_TRUE(reader.ok());
  if (!reader.ok()) return {};
  PackWriter w;
  for (const SectionInfo& s : reader->sections()) {
    const auto payload = reader->section_bytes(s);
    std::vector<std::byte> copy(payload.begin(), payload.end());
    const bool target = s.id == id;
    if (target) mutate(copy);
    EXPECT_TRUE(w.add_section(s.id, target && version ? *version : s.version, std::move(copy)).ok());
  }
  auto out = w.serialize();
  EXPECT_TRUE(out.ok());
  return out.ok() ? std::move(*out) : std::vector<std::byte>{};
}

}  // namespace sinew::testing_support
