// The leaf-box cache (raytrace/scene/leaf_boxes.h): a box is computed once a
// frame and slot, read back by later lookups, stale after prepare(); slots
// follow each bone's largest tree; lookups without a slot compute and keep
// nothing; threads looking up the same slots all get the computed boxes.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

#include "raytrace/fuzzy/fuzzy_character.h"
#include "raytrace/scene/leaf_boxes.h"

namespace sinew {
namespace {

// Three bones: bone 0 with a 5-node full tree and clusters of 9 and 3
// nodes, bone 1 without a tree, bone 2 with a 7-node tree and no clusters.
struct Trees {
  std::vector<rt::BoneTree> bones;
  std::vector<rt::BoneCluster> clusters;
  std::vector<std::uint32_t> cluster_begin{0, 2, 2, 2};
  rt::FuzzyCharacterView view;
  Trees() {
    bones.resize(3);
    bones[0].node_count = 5;
    bones[2].node_count = 7;
    clusters.resize(2);
    clusters[0].tree.node_count = 9;
    clusters[1].tree.node_count = 3;
    view.bone_count = 3;
    view.bone_trees = bones;
    view.clusters = clusters;
    view.bone_cluster_begin = cluster_begin;
  }
};

// A box that names its bone, node and frame.
Aabb box_of(std::uint32_t bone, std::uint32_t node, int frame) {
  const Vec3 lower(static_cast<float>(bone), static_cast<float>(node), static_cast<float>(frame));
  return {lower, lower + Vec3(0.5f)};
}

void expect_box(const Aabb& got, const Aabb& want) {
  EXPECT_EQ(got.lower, want.lower);
  EXPECT_EQ(got.upper, want.upper);
}

TEST(LeafBoxes, EachSlotIsComputedOnceAFrameAndStaleAfterPrepare) {
  const Trees trees;
  rt::LeafBoxCache cache;
  cache.prepare(trees.view);
  EXPECT_EQ(cache.slot_count(), 9u + 0u + 7u) << "bone 0's largest tree is its 9-node cluster";
  int computed = 0;
  for (int frame = 1; frame <= 3; ++frame) {
    if (frame > 1) cache.prepare(trees.view);
    for (int pass = 0; pass < 2; ++pass) {
      for (const auto& [bone, node] : {std::pair{0u, 0u}, std::pair{0u, 8u}, std::pair{2u, 6u}}) {
        const Aabb box = cache.get(bone, node, [&] {
          ++computed;
          return box_of(bone, node, frame);
        });
        expect_box(box, box_of(bone, node, frame));
      }
    }
    EXPECT_EQ(computed, 3 * frame) << "frame " << frame << ": one computation per slot, none on the second pass";
  }
}

TEST(LeafBoxes, LookupsWithoutASlotComputeAndKeepNothing) {
  const Trees trees;
  rt::LeafBoxCache cache;
  int computed = 0;
  const auto count = [&] {
    ++computed;
    return box_of(0, 0, 0);
  };
  // Never prepared: no slots at all.
  cache.get(0, 0, count);
  cache.get(0, 0, count);
  EXPECT_EQ(computed, 2);
  EXPECT_EQ(cache.slot_count(), 0u);
  cache.prepare(trees.view);
  computed = 0;
  for (const auto& [bone, node] : {std::pair{0u, 9u}, std::pair{1u, 0u}, std::pair{2u, 7u}, std::pair{3u, 0u}}) {
    cache.get(bone, node, count);
    cache.get(bone, node, count);
  }
  EXPECT_EQ(computed, 8) << "nodes beyond a bone's trees, a bone without one, a bone beyond the character";
}

TEST(LeafBoxes, ThreadsSharingSlotsGetTheComputedBoxes) {
  const Trees trees;
  rt::LeafBoxCache cache;
  std::atomic<int> computed{0};
  std::atomic<int> wrong{0};
  for (int frame = 1; frame <= 20; ++frame) {
    cache.prepare(trees.view);
    const auto work = [&] {
      for (int pass = 0; pass < 50; ++pass) {
        for (std::uint32_t node = 0; node < 9; ++node) {
          for (const std::uint32_t bone : {0u, 2u}) {
            if (bone == 2 && node >= 7) continue;
            const Aabb box = cache.get(bone, node, [&] {
              computed.fetch_add(1, std::memory_order_relaxed);
              return box_of(bone, node, frame);
            });
            const Aabb want = box_of(bone, node, frame);
            if (box.lower != want.lower || box.upper != want.upper) wrong.fetch_add(1, std::memory_order_relaxed);
          }
        }
      }
    };
    std::thread a(work), b(work);
    a.join();
    b.join();
  }
  EXPECT_EQ(wrong.load(), 0);
  // 16 slots a frame, each computed by one thread or by both racing.
  EXPECT_GE(computed.load(), 20 * 16);
  EXPECT_LE(computed.load(), 2 * 20 * 16);
}

}  // namespace
}  // namespace sinew
