// Skeleton planning: the node forest with its transforms, which nodes become
// joints (and in what order), their inverse binds, and the anim::Skeleton with
// non-joint ancestors folded in. Separate because the meshes and the clips
// both index joints through its SkeletonPlan and raw_to_sorted.
#pragma once

#include <vector>

#include "editor/import/gltf_transforms.h"

namespace sinew::editor::gltf_detail {

struct NodeGraph {
  std::vector<int> parent;      // -1 for roots
  std::vector<DMat4> local;
  std::vector<Trs> local_trs;
  std::vector<bool> trs_ok;     // local matrix is expressible as TRS
  std::vector<DMat4> global;
};

Expected<NodeGraph> build_graph(const Ctx& c);

struct SkeletonPlan {
  std::vector<int> joint_nodes;     // raw joint -> node (-1: synthetic root)
  std::vector<int> node_to_raw;     // node -> raw joint or -1
  std::vector<Trs> fold;            // per raw joint: parent-side transform
  std::vector<bool> fold_needed;
  std::vector<DMat4> inverse_bind;  // per raw joint
  int static_root = -1;             // raw index of "<static>", or -1
};

// Raw joint of the nearest ancestor-or-self node that is a joint, or -1.
int joint_ancestor(const NodeGraph& g, const SkeletonPlan& plan, int node);

Expected<SkeletonPlan> plan_skeleton(const Ctx& c, const NodeGraph& g);

Expected<anim::Skeleton> build_skeleton(const Ctx& c, const NodeGraph& g, SkeletonPlan& plan,
                                        const std::vector<bool>& animated,
                                        std::vector<int>& raw_to_sorted);

}  // namespace sinew::editor::gltf_detail
