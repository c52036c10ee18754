// Mailboxes: per object visit, the leaf items already tested. A triangle
// whose fuzzy box straddles kd splits is listed in several leaves, and a ray
// reaches it through each; testing it again costs time, never a hit (a
// triangle must beat the best t strictly). Both kinds are direct-mapped on
// the id's low bits, which neighbouring items of a leaf differ in; an
// evicted item is tested again with the same answers.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "runtime/math/ray.h"

namespace sinew::rt {

// Items tested by the whole query: a single ray, or a packet whose test of
// an item does not depend on the leaf it is listed in (under group frusta).
// A key holds the visit's epoch above the id, so reset() is a count, not a
// fill per object visit; the slots are cleared only when the epoch wraps
// (every 2^32 visits: key 0 never matches a key formed after it).
template <std::size_t kSlots>
class ItemMailbox {
  static_assert((kSlots & (kSlots - 1)) == 0, "a power of two");

 public:
  void reset() {
    if (++epoch_ == 0) {
      keys_.fill(0);
      epoch_ = 1;
    }
  }
  // True the first time `id` is seen since reset (or since its eviction).
  bool first_visit(std::uint32_t id) {
    const std::uint64_t key = std::uint64_t{epoch_} << 32 | id;
    std::uint64_t& slot = keys_[id & (kSlots - 1)];
    if (slot == key) return false;
    slot = key;
    return true;
  }

 private:
  std::array<std::uint64_t, kSlots> keys_{};
  std::uint32_t epoch_ = 1;
};

// Items tested lane by lane: which lanes of each group of a packet have
// tested an item (a packet without frusta tests a leaf with the lanes that
// reach it, so a later leaf may bring others), for packets of up to kGroups
// groups.
template <std::uint32_t kGroups>
class LaneMailbox {
 public:
  void reset() { keys_.fill(kInvalidId); }
  // Of `lanes` of group g, those that have not tested `id` yet (marking them).
  std::uint32_t untested(std::uint32_t id, int g, std::uint32_t lanes) {
    const std::uint32_t key = id * kGroups + static_cast<std::uint32_t>(g);
    const std::size_t slot = (id * 7u + static_cast<std::uint32_t>(g)) & (keys_.size() - 1);
    if (keys_[slot] != key) {
      keys_[slot] = key;
      lanes_[slot] = static_cast<std::uint8_t>(lanes);
      return lanes;
    }
    const std::uint32_t fresh = lanes & ~std::uint32_t{lanes_[slot]};
    lanes_[slot] = static_cast<std::uint8_t>(lanes_[slot] | lanes);
    return fresh;
  }

 private:
  std::array<std::uint32_t, 256> keys_{};
  std::array<std::uint8_t, 256> lanes_{};
};

}  // namespace sinew::rt
