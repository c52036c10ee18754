// Skeleton planning (gltf_skeleton.h): the node graph, the joint plan from
// the skins, and the skeleton's rest poses and inverse binds.
#include "editor/import/gltf_skeleton.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include "editor/import/gltf_accessors.h"

namespace sinew::editor::gltf_detail {
namespace {

constexpr const char* kStaticRootName = "<static>";

Expected<std::vector<DMat4>> read_inverse_binds(const Ctx& c, std::size_t skin_index) {
  const tinygltf::Skin& skin = c.model.skins[skin_index];
  const std::string field = idx("skins", skin_index);
  std::vector<DMat4> out(skin.joints.size(), DMat4(1.0));
  if (skin.inverseBindMatrices < 0) return out;
  SINEW_ASSIGN_OR_RETURN(AccessorData d,
                         read_accessor(c, skin.inverseBindMatrices, field + ".inverseBindMatrices",
                                       {TINYGLTF_TYPE_MAT4}, {TINYGLTF_COMPONENT_TYPE_FLOAT}));
  if (d.count < skin.joints.size()) {
    return c.error(ErrorCode::kTruncated, field + ".inverseBindMatrices", std::to_string(d.count),
                   "fewer matrices than the skin's " + std::to_string(skin.joints.size()) +
                       " joints");
  }
  for (std::size_t j = 0; j < out.size(); ++j) {
    for (int k = 0; k < 16; ++k) out[j][k / 4][k % 4] = d.at(j, k);
  }
  return out;
}

}  // namespace

Expected<NodeGraph> build_graph(const Ctx& c) {
  const auto& nodes = c.model.nodes;
  const std::size_t n = nodes.size();
  if (n > c.limits.max_nodes) return c.limit("nodes", n, "nodes", c.limits.max_nodes, "--max-nodes");
  NodeGraph g;
  g.parent.assign(n, -1);
  g.local.assign(n, DMat4(1.0));
  g.local_trs.assign(n, Trs{});
  g.trs_ok.assign(n, true);
  g.global.assign(n, DMat4(1.0));
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t k = 0; k < nodes[i].children.size(); ++k) {
      const int child = nodes[i].children[k];
      const std::string field = idx(idx("nodes", i) + ".children", k);
      if (child < 0 || static_cast<std::size_t>(child) >= n) {
        return c.error(ErrorCode::kOutOfBounds, field, std::to_string(child), "no such node");
      }
      if (static_cast<std::size_t>(child) == i) {
        return c.error(ErrorCode::kInvalidData, field, std::to_string(child),
                       "a node cannot be its own child (cycle)");
      }
      if (g.parent[static_cast<std::size_t>(child)] != -1) {
        return c.error(ErrorCode::kInvalidData, field, std::to_string(child),
                       "node already has parent " +
                           std::to_string(g.parent[static_cast<std::size_t>(child)]) +
                           " (the node hierarchy must be a forest)");
      }
      g.parent[static_cast<std::size_t>(child)] = static_cast<int>(i);
    }
    bool trs_ok = true;
    SINEW_RETURN_IF_ERROR(node_local(c, i, g.local[i], g.local_trs[i], trs_ok));
    g.trs_ok[i] = trs_ok;
  }
  // Globals top-down from each root, iteratively (hierarchies can be deep).
  // With one parent per node this reaches each node at most once, and every
  // node it does not reach has no root above it: it sits on a cycle or
  // below one. Linear in the nodes (walking each node up to its root was
  // quadratic on long chains).
  std::vector<std::size_t> stack;
  std::vector<bool> reached(n, false);
  for (std::size_t i = 0; i < n; ++i) {
    if (g.parent[i] != -1) continue;
    g.global[i] = g.local[i];
    reached[i] = true;
    stack.push_back(i);
    while (!stack.empty()) {
      const std::size_t cur = stack.back();
      stack.pop_back();
      for (const int child : nodes[cur].children) {
        const std::size_t ch = static_cast<std::size_t>(child);
        g.global[ch] = g.global[cur] * g.local[ch];
        reached[ch] = true;
        stack.push_back(ch);
      }
    }
  }
  const auto unreached = std::find(reached.begin(), reached.end(), false);
  if (unreached != reached.end()) {
    // Up from there, the first node met twice is on the cycle.
    std::vector<bool> seen(n, false);
    std::size_t at = static_cast<std::size_t>(unreached - reached.begin());
    while (!seen[at]) {
      seen[at] = true;
      at = static_cast<std::size_t>(g.parent[at]);
    }
    return c.error(ErrorCode::kInvalidData, idx("nodes", at) + ".children", "",
                   "the node hierarchy has a cycle through this node");
  }
  return g;
}

int joint_ancestor(const NodeGraph& g, const SkeletonPlan& plan, int node) {
  std::size_t guard = 0;
  while (node != -1 && guard++ <= g.parent.size()) {
    const int raw = plan.node_to_raw[static_cast<std::size_t>(node)];
    if (raw != -1) return raw;
    node = g.parent[static_cast<std::size_t>(node)];
  }
  return -1;
}

Expected<SkeletonPlan> plan_skeleton(const Ctx& c, const NodeGraph& g) {
  const auto& nodes = c.model.nodes;
  SkeletonPlan plan;
  plan.node_to_raw.assign(nodes.size(), -1);

  std::vector<bool> skin_used(c.model.skins.size(), false);
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const int mesh = nodes[i].mesh;
    const int skin = nodes[i].skin;
    if (mesh < -1 || mesh >= static_cast<int>(c.model.meshes.size())) {
      return c.error(ErrorCode::kOutOfBounds, idx("nodes", i) + ".mesh", std::to_string(mesh),
                     "no such mesh");
    }
    if (skin < -1 || skin >= static_cast<int>(c.model.skins.size())) {
      return c.error(ErrorCode::kOutOfBounds, idx("nodes", i) + ".skin", std::to_string(skin),
                     "no such skin");
    }
    if (mesh >= 0 && skin >= 0) skin_used[static_cast<std::size_t>(skin)] = true;
  }

  for (std::size_t s = 0; s < c.model.skins.size(); ++s) {
    if (!skin_used[s]) continue;
    const tinygltf::Skin& skin = c.model.skins[s];
    const std::string field = idx("skins", s);
    if (skin.joints.empty()) {
      return c.error(ErrorCode::kInvalidData, field + ".joints", "[]", "a skin needs joints");
    }
    if (skin.skeleton < -1 || skin.skeleton >= static_cast<int>(nodes.size())) {
      return c.error(ErrorCode::kOutOfBounds, field + ".skeleton", std::to_string(skin.skeleton),
                     "no such node");
    }
    SINEW_ASSIGN_OR_RETURN(std::vector<DMat4> ibm, read_inverse_binds(c, s));
    for (std::size_t j = 0; j < skin.joints.size(); ++j) {
      const int node = skin.joints[j];
      const std::string jfield = idx(field + ".joints", j);
      if (node < 0 || static_cast<std::size_t>(node) >= nodes.size()) {
        return c.error(ErrorCode::kOutOfBounds, jfield, std::to_string(node), "no such node");
      }
      int& raw = plan.node_to_raw[static_cast<std::size_t>(node)];
      if (raw != -1) {
        // Shared between skins (or listed twice): one joint needs one bind.
        const DMat4& prev = plan.inverse_bind[static_cast<std::size_t>(raw)];
        double scale = 1.0;
        for (int col = 0; col < 4; ++col) {
          for (int row = 0; row < 4; ++row) scale = std::max(scale, std::abs(prev[col][row]));
        }
        if (max_abs_diff(prev, ibm[j]) > 1e-5 * scale) {
          return c.error(ErrorCode::kInvalidData, idx(field + ".inverseBindMatrices", j),
                         std::to_string(node),
                         "node is a joint of several skins with different inverse bind "
                         "matrices; Sinew needs one bind pose per joint");
        }
        continue;
      }
      raw = static_cast<int>(plan.joint_nodes.size());
      plan.joint_nodes.push_back(node);
      plan.inverse_bind.push_back(ibm[j]);
    }
  }
  if (plan.joint_nodes.size() > anim::kMaxJoints) {
    return c.error(ErrorCode::kLimitExceeded, "skins", std::to_string(plan.joint_nodes.size()),
                   "more joints than Sinew supports");
  }
  // Rigid meshes outside every joint's subtree hang off a synthetic root.
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    if (nodes[i].mesh >= 0 && nodes[i].skin < 0 &&
        joint_ancestor(g, plan, static_cast<int>(i)) == -1) {
      plan.static_root = static_cast<int>(plan.joint_nodes.size());
      plan.joint_nodes.push_back(-1);
      plan.inverse_bind.push_back(DMat4(1.0));
      break;
    }
  }
  return plan;
}

Expected<anim::Skeleton> build_skeleton(const Ctx& c, const NodeGraph& g, SkeletonPlan& plan,
                                        const std::vector<bool>& animated,
                                        std::vector<int>& raw_to_sorted) {
  anim::RawSkeleton raw;
  raw.joints.resize(plan.joint_nodes.size());
  plan.fold.assign(plan.joint_nodes.size(), Trs{});
  plan.fold_needed.assign(plan.joint_nodes.size(), false);
  std::set<std::string> used_names;
  for (std::size_t r = 0; r < plan.joint_nodes.size(); ++r) {
    anim::RawJoint& joint = raw.joints[r];
    joint.inverse_bind = to_affine(plan.inverse_bind[r]);
    const int node = plan.joint_nodes[r];
    if (node == -1) {
      joint.name = kStaticRootName;
      continue;
    }
    const std::size_t un = static_cast<std::size_t>(node);
    const std::string field = idx("nodes", un);
    // Skeleton names must be unique and findable; glTF names need be neither.
    joint.name = c.model.nodes[un].name.empty() ? "node_" + std::to_string(un)
                                                : c.model.nodes[un].name;
    if (!used_names.insert(joint.name).second) {
      joint.name += "_node" + std::to_string(un);
    }
    const int direct = g.parent[un];
    const int parent_raw = direct == -1 ? -1 : joint_ancestor(g, plan, direct);
    joint.parent = parent_raw == -1 ? anim::kNoParent : parent_raw;

    // P maps the direct parent's space to the parent joint's (or model) space.
    DMat4 p(1.0);
    if (direct != -1) {
      p = g.global[static_cast<std::size_t>(direct)];
      if (parent_raw != -1) {
        const int pnode = plan.joint_nodes[static_cast<std::size_t>(parent_raw)];
        p = glm::inverse(g.global[static_cast<std::size_t>(pnode)]) * p;
      }
    }
    Trs rest;
    Trs pt;
    const bool fold = !is_identity(p);
    if (!fold) {
      if (!g.trs_ok[un]) {
        return c.error(ErrorCode::kInvalidData, field + ".matrix", "",
                       "joint matrix is not expressible as translation, rotation and scale");
      }
      rest = g.local_trs[un];
    } else if (decompose(p, pt) && is_similarity(pt) && g.trs_ok[un]) {
      const Trs& l = g.local_trs[un];
      rest = Trs{fold_translation(pt, l.t), fold_rotation(pt, l.r), fold_scale(pt, l.s)};
      plan.fold[r] = pt;
      plan.fold_needed[r] = true;
    } else {
      if (animated[un]) {
        return c.error(ErrorCode::kInvalidData, field, joint.name,
                       "animated joint under non-joint nodes whose transform is not a "
                       "similarity (non-uniform scale or shear) cannot be folded");
      }
      if (!decompose(p * g.local[un], rest)) {
        return c.error(ErrorCode::kInvalidData, field, joint.name,
                       "joint transform (with its non-joint ancestors) has shear or zero scale");
      }
    }
    joint.rest.translation = Vec3(rest.t);
    joint.rest.rotation = Quat(rest.r);
    joint.rest.scale = Vec3(rest.s);
  }
  return anim::Skeleton::build(raw, c.file, &raw_to_sorted);
}

}  // namespace sinew::editor::gltf_detail
