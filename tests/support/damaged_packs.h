// Re-sealed packs with random damage: the corruption suite's random cases
// (tests/character/pack_test.cpp), shared with the consumer-agreement test
// (tests/character/pack_agreement_test.cpp) so both walk the same packs.
#pragma once

#include <cstddef>
#include <cstdint>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "runtime/pack/pack_reader.h"
#include "tests/support/repack.h"

namespace sinew::testing_support {

struct DamagedPack {
  std::string what;  // "<section> trial <k>"
  std::vector<std::byte> bytes;
};

// For every non-empty section of `pristine`, `trials` copies with three
// random bytes of that section's payload overwritten (seeded), each
// re-sealed so that its checksums pass.
inline std::vector<DamagedPack> randomly_damaged_packs(std::span<const std::byte> pristine, int trials,
                                                       std::uint32_t seed) {
  std::vector<DamagedPack> packs;
  auto reader = PackReader::from_bytes(pristine, "pristine");
  if (!reader.ok()) return packs;
  std::mt19937 random(seed);
  for (const SectionInfo& s : reader->sections()) {
    if (s.size == 0) continue;
    for (int trial = 0; trial < trials; ++trial) {
      packs.push_back({section_id_name(s.id) + " trial " + std::to_string(trial),
                       repack_section(pristine, s.id, [&](std::vector<std::byte>& p) {
                         for (int k = 0; k < 3; ++k) p[random() % p.size()] = static_cast<std::byte>(random() & 0xffu);
                       })});
    }
  }
  return packs;
}

}  // namespace sinew::testing_support
