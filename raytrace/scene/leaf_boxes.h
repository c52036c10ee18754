// The world boxes of an instance's bone-tree leaves in the current pose,
// each computed the first time a packet reaches its leaf in a frame and
// kept for the frame's other packets (docs/RAYTRACE.md, "Leaf boxes").
//
// A fuzzy leaf's box holds its triangles in every sampled pose; at 855,552
// triangles on Cally the triangles of two leaves in five lie wholly outside
// a packet's frusta that reach the leaf's fuzzy box. The box of the current
// triangles settles such a leaf with one test instead of a gather and a
// frustum test per triangle, and a frame computes each leaf's box at most
// once per thread racing for it: nothing is refitted before the first ray,
// and leaves no packet reaches cost nothing.
//
// Slots: per bone, as many as the largest of its trees (its full tree and
// its pose-space clusters' trees) has nodes, so bone b's node n of the tree
// it uses this frame has slot offset(b) + n. A slot's stamp says in which
// frame its box was written; prepare() starts a new frame.
//
// Threads: any number may look up and fill slots at once. A slot's corners
// are written (relaxed) before its stamp (release); a reader that sees this
// frame's stamp (acquire) sees the corners. Two threads filling one slot
// write the same box.
#pragma once

#include <atomic>
#include <cstdint>
#include <vector>

#include "raytrace/fuzzy/fuzzy_character.h"
#include "runtime/math/aabb.h"

namespace sinew::rt {

class LeafBoxCache {
 public:
  // Sizes the slots for `fuzzy`'s trees on first use (or when the character
  // changes shape) and starts a new frame: every slot's box is stale.
  void prepare(const FuzzyCharacterView& fuzzy) {
    if (offsets_.size() != fuzzy.bone_count + std::size_t{1}) {
      offsets_.assign(fuzzy.bone_count + std::size_t{1}, 0);
      std::size_t total = 0;
      for (std::uint32_t b = 0; b < fuzzy.bone_count; ++b) {
        std::uint32_t most = fuzzy.bone_trees[b].node_count;
        for (const BoneCluster& cluster : fuzzy.bone_clusters(b)) most = std::max(most, cluster.tree.node_count);
        offsets_[b] = static_cast<std::uint32_t>(total);
        total += most;
      }
      offsets_[fuzzy.bone_count] = static_cast<std::uint32_t>(total);
      slots_.assign(total, Slot{});
      frame_ = 0;
    }
    ++frame_;
    if (frame_ == 0) {
      // 2^32 frames on: every stamp could look current again.
      for (Slot& slot : slots_) slot.stamp = 0;
      frame_ = 1;
    }
  }

  // The box of bone `bone`'s node `node` this frame: the stored one, or
  // compute() (an Aabb) stored for the frame's other packets. Without a
  // slot (never prepared, or a node beyond the bone's trees) compute()'s
  // box is returned and not kept.
  template <class Compute>
  Aabb get(std::uint32_t bone, std::uint32_t node, Compute&& compute) const {
    if (bone + std::size_t{1} >= offsets_.size() || node >= offsets_[bone + 1] - offsets_[bone]) return compute();
    Slot& slot = slots_[offsets_[bone] + static_cast<std::size_t>(node)];
    std::atomic_ref<std::uint32_t> stamp(slot.stamp);
    if (stamp.load(std::memory_order_acquire) == frame_) {
      Aabb box;
      for (int a = 0; a < 3; ++a) {
        box.lower[a] = std::atomic_ref<float>(slot.lower[a]).load(std::memory_order_relaxed);
        box.upper[a] = std::atomic_ref<float>(slot.upper[a]).load(std::memory_order_relaxed);
      }
      return box;
    }
    const Aabb box = compute();
    for (int a = 0; a < 3; ++a) {
      std::atomic_ref<float>(slot.lower[a]).store(box.lower[a], std::memory_order_relaxed);
      std::atomic_ref<float>(slot.upper[a]).store(box.upper[a], std::memory_order_relaxed);
    }
    stamp.store(frame_, std::memory_order_release);
    return box;
  }

  std::size_t slot_count() const { return slots_.size(); }
  std::size_t bytes() const { return slots_.size() * sizeof(Slot) + offsets_.size() * sizeof(std::uint32_t); }

 private:
  struct alignas(32) Slot {
    float lower[3] = {0.0f, 0.0f, 0.0f};
    float upper[3] = {0.0f, 0.0f, 0.0f};
    std::uint32_t stamp = 0;  // the frame the box was written in (0: never)
  };
  std::vector<std::uint32_t> offsets_;  // per bone, then the total
  mutable std::vector<Slot> slots_;
  std::uint32_t frame_ = 0;
};

}  // namespace sinew::rt
