#include "raytrace/traverse/traversal.h"

#include "raytrace/traverse/leaf_triangles.h"
#include "raytrace/traverse/mailbox.h"
#include "raytrace/traverse/ray_frames.h"
#include "raytrace/traverse/traversal_shared.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>

namespace sinew::rt {
namespace {

using detail::max_abs;
using detail::valid_ray;

constexpr float kInf = std::numeric_limits<float>::infinity();

// The shared box clip (traverse/ray_frames.h) for one ray.
bool clip_to_box(const Aabb& box, float eps, const Vec3& o, const Vec3& d, const Vec3& inv, float& t0, float& t1) {
  return per_lane::clip_to_box<float>(box, eps, o, d, inv, t0, t1);
}

struct StackEntry {
  std::uint32_t node;
  float t0;
  float t1;
};

// Front-to-back traversal of one kd-tree over [t0, t1] with split planes
// thickened by `eps`: a child is entered whenever the ray passes within eps
// of its cell. Cells whose entry lies beyond `t_limit` (the best hit so far,
// read on every pop) are pruned. `leaf` returns true to stop (any hit).
template <class LeafFn>
bool traverse_tree(const KdTreeView& tree, const Vec3& o, const Vec3& d, const Vec3& inv, float eps, float t0,
                   float t1, const float& t_limit, std::uint64_t& visits, LeafFn&& leaf) {
  std::array<StackEntry, kMaxTraversalDepth + 2> stack;
  std::size_t top = 0;
  std::uint32_t index = 0;
  for (;;) {
    ++visits;
    const KdNode node = tree.nodes[index];
    if (!node.is_leaf()) {
      const int a = node.axis();
      const float split = node.split();
      const float oa = o[a];
      const float da = d[a];
      const float below_edge = split + eps;  // the below cell, thickened, reaches up to here
      const float above_edge = split - eps;  // the above cell, thickened, starts here
      float b0 = t0, b1 = t1, a0 = t0, a1 = t1;
      bool below_first = true;
      if (da > 0.0f) {
        b1 = std::min(t1, (below_edge - oa) * inv[a]);
        a0 = std::max(t0, (above_edge - oa) * inv[a]);
      } else if (da < 0.0f) {
        b0 = std::max(t0, (below_edge - oa) * inv[a]);
        a1 = std::min(t1, (above_edge - oa) * inv[a]);
        below_first = false;
      } else {
        if (!(oa <= below_edge)) b1 = -kInf;
        if (!(oa >= above_edge)) a1 = -kInf;
      }
      const std::uint32_t below = index + 1;
      const std::uint32_t above = node.above_child();
      const StackEntry first = below_first ? StackEntry{below, b0, b1} : StackEntry{above, a0, a1};
      const StackEntry second = below_first ? StackEntry{above, a0, a1} : StackEntry{below, b0, b1};
      const bool first_ok = first.t0 <= first.t1;
      const bool second_ok = second.t0 <= second.t1 && second.t0 <= t_limit;
      if (first_ok) {
        if (second_ok) stack[top++] = second;
        index = first.node;
        t0 = first.t0;
        t1 = first.t1;
        continue;
      }
      if (second_ok) {
        index = second.node;
        t0 = second.t0;
        t1 = second.t1;
        continue;
      }
    } else if (node.item_count() > 0) {
      if (leaf(tree.items.subspan(node.first_item(), node.item_count()))) return true;
    }
    for (;;) {
      if (top == 0) return false;
      const StackEntry& entry = stack[--top];
      if (entry.t0 <= t_limit) {
        index = entry.node;
        t0 = entry.t0;
        t1 = std::min(entry.t1, t_limit);
        break;
      }
    }
  }
}

// Front-to-back walk of one BVH over [t0, t1] with every node box grown by
// `eps` (the kd walk's thickened planes, for boxes): a child is entered
// whenever the ray passes within eps of its box, the nearer entry first;
// nodes whose entry lies beyond `t_limit` (read on every pop) are pruned.
// The caller has clipped [t0, t1] to the root's box. `leaf` returns true to
// stop (any hit).
template <class LeafFn>
bool traverse_bvh(const BvhView& tree, const Vec3& o, const Vec3& d, const Vec3& inv, float eps, float t0, float t1,
                  const float& t_limit, std::uint64_t& visits, LeafFn&& leaf) {
  struct Pending {
    std::uint32_t node;
    float t;
  };
  std::array<Pending, kMaxTraversalDepth + 2> stack;
  std::size_t top = 0;
  std::uint32_t index = 0;
  for (;;) {
    ++visits;
    const BvhNode& node = tree.nodes[index];
    if (node.is_leaf()) {
      if (leaf(tree.items.subspan(node.first, node.count))) return true;
    } else {
      float a0 = t0, a1 = std::min(t1, t_limit), b0 = t0, b1 = a1;
      const bool a = clip_to_box(tree.nodes[node.first].box, eps, o, d, inv, a0, a1);
      const bool b = clip_to_box(tree.nodes[node.first + 1].box, eps, o, d, inv, b0, b1);
      if (a && b) {
        const bool a_first = a0 <= b0;
        stack[top++] = a_first ? Pending{node.first + 1, b0} : Pending{node.first, a0};
        index = a_first ? node.first : node.first + 1;
        continue;
      }
      if (a || b) {
        index = a ? node.first : node.first + 1;
        continue;
      }
    }
    for (;;) {
      if (top == 0) return false;
      const Pending& entry = stack[--top];
      if (entry.t <= t_limit) {
        index = entry.node;
        break;
      }
    }
  }
}

// One query: the world ray, its per-ray triangle-test data, and the best hit
// (closest-hit) or the first hit (any-hit).
template <TriangleTest kTest, bool kAnyHit>
class Query {
 public:
  Query(const Scene& scene, const Ray& ray, std::uint32_t ray_mask)
      : scene_(scene),
        ray_(ray),
        ray_mask_(ray_mask),
        inv_dir_(1.0f / ray.direction.x, 1.0f / ray.direction.y, 1.0f / ray.direction.z),
        origin_magnitude_(max_abs(ray.origin)),
        direction_magnitude_(max_abs(ray.direction)),
        t_limit_(ray.t_max) {
    if constexpr (kTest == TriangleTest::kWatertight) watertight_ = prepare_watertight(ray);
  }

  bool run() {
    const KdTreeView top = scene_.top_level().view();
    if (top.empty()) return false;
    float t0 = ray_.t_min;
    float t1 = ray_.t_max;
    if (!clip_to_box(top.bounds, world_eps(top.bounds, 0.0f), ray_.origin, ray_.direction, inv_dir_, t0, t1)) {
      return false;
    }
    const float eps = world_eps(top.bounds, t1);
    return traverse_tree(top, ray_.origin, ray_.direction, inv_dir_, eps, t0, t1, t_limit_, counters_.node_visits,
                         [this](std::span<const std::uint32_t> objects) {
                           const std::span<const TopLevelObject> all = scene_.top_level().objects();
                           for (const std::uint32_t object : objects) {
                             if ((all[object].mask & ray_mask_) == 0) continue;  // masked out: never entered
                             if (already_visited(object)) continue;
                             if (visit(all[object])) return true;
                           }
                           return false;
                         });
  }

  const Hit& hit() const { return best_; }
  const TraversalCounters& counters() const { return counters_; }

 private:
  // The slack of a world-space box (traverse/ray_frames.h world_slack).
  float world_eps(const Aabb& box, float t_end) const {
    return per_lane::world_slack<float>(origin_magnitude_, direction_magnitude_, max_abs(box), t_end);
  }

  // Objects overlap several top-level leaves; each is traversed once, over
  // the whole ray, so later leaves skip it. Past the list's capacity an
  // object may be traversed again, which costs time but not correctness.
  bool already_visited(std::uint32_t object) {
    for (std::size_t i = 0; i < visited_count_; ++i) {
      if (visited_[i] == object) return true;
    }
    if (visited_count_ < visited_.size()) visited_[visited_count_++] = object;
    return false;
  }

  bool visit(const TopLevelObject& object) {
    float t0 = ray_.t_min;
    float t1 = t_limit_;
    if (!clip_to_box(object.box, world_eps(object.box, t1), ray_.origin, ray_.direction, inv_dir_, t0, t1)) {
      return false;
    }
    ++counters_.object_visits;
    mailbox_.reset();
    return visit_object(scene_, object, *this, t0, t1);
  }

 public:
  // The object kinds' walks (visit_object, traverse/leaf_triangles.h) over
  // the ray's passage [t0, t1] through the object's box.
  bool bone_tree(const InstanceFrame& frame, std::uint32_t bone, const Scene::Character& character,
                 const SkinnedTriangles& triangles, float t0, float t1) {
    const BoneTree& tree = frame.bone_tree(character.fuzzy, bone);
    // The ray and its slack in the bone frame (traverse/ray_frames.h).
    const per_lane::FrameRay<float> r =
        per_lane::to_bone_frame<float>(frame, bone, ray_.origin, ray_.direction, origin_magnitude_, t1);
    const Vec3& o = r.o;
    const Vec3& d = r.d;
    const float eps = r.eps;
    const Vec3 inv = per_lane::reciprocal<float>(d);
    if (!clip_to_box(tree.bounds, eps, o, d, inv, t0, t1)) return false;
    if (character.fuzzy.has_bvhs()) {
      return traverse_bvh(character.fuzzy.bvh_view(tree), o, d, inv, eps, t0, t1, t_limit_, counters_.node_visits,
                          leaf_of(triangles));
    }
    return traverse_tree(character.fuzzy.tree_view(tree), o, d, inv, eps, t0, t1, t_limit_, counters_.node_visits,
                         leaf_of(triangles));
  }
  template <class Source>
  bool world_tree(const KdTreeView& tree, const Source& triangles, float t0, float t1) {
    const float eps = world_eps(tree.bounds, t1);
    return traverse_tree(tree, ray_.origin, ray_.direction, inv_dir_, eps, t0, t1, t_limit_, counters_.node_visits,
                         leaf_of(triangles));
  }
  bool each_triangle(const StaticTriangles& triangles, std::size_t count, float, float) {
    for (std::uint32_t t = 0; t < count; ++t) {
      if (test(triangles(t))) return true;
    }
    return false;
  }

 private:
  // A leaf's test: each item's triangle (from `source`, traverse/
  // leaf_triangles.h) once per object visit; true when the query is answered.
  template <class Source>
  auto leaf_of(const Source& source) {
    return [this, source](std::span<const std::uint32_t> items) {
      for (const std::uint32_t item : items) {
        if (!mailbox_.first_visit(item)) continue;
        if (test(source(item))) return true;
      }
      return false;
    };
  }

  // Tests one world-space triangle; records a nearer hit. Returns true when
  // the query is answered (any-hit found something).
  bool test(const LeafTriangle& tri) {
    const Vec3& p0 = *tri.p0;
    const Vec3& p1 = *tri.p1;
    const Vec3& p2 = *tri.p2;
    ++counters_.triangle_tests;
    TriangleHit h;
    bool hit_found;
    if constexpr (kTest == TriangleTest::kWatertight) {
      hit_found = intersect_triangle_watertight(watertight_, ray_, t_limit_, p0, p1, p2, h);
    } else {
      hit_found = intersect_triangle_fast(ray_, t_limit_, p0, p1, p2, h);
    }
    if (!hit_found) return false;
    best_ = Hit{h.t, h.u, h.v, tri.triangle, tri.instance};
    if constexpr (kAnyHit) return true;
    t_limit_ = h.t;
    return false;
  }

  const Scene& scene_;
  Ray ray_;
  std::uint32_t ray_mask_;
  Vec3 inv_dir_;
  float origin_magnitude_;
  float direction_magnitude_;
  float t_limit_;
  WatertightRay watertight_;
  Hit best_;
  ItemMailbox<16> mailbox_;
  std::array<std::uint32_t, 32> visited_;  // the first visited_count_ are set
  std::size_t visited_count_ = 0;
  TraversalCounters counters_;
};


template <TriangleTest kTest, bool kAnyHit>
Hit run_query(const Scene& scene, const Ray& ray, std::uint32_t ray_mask, TraversalCounters* counters) {
  Query<kTest, kAnyHit> query(scene, ray, ray_mask);
  query.run();
  if (counters) *counters += query.counters().for_rays(1);
  return query.hit();
}

}  // namespace

Hit intersect(const Scene& scene, const Ray& ray, std::uint32_t ray_mask, TriangleTest test,
              TraversalCounters* counters) {
  if (!valid_ray(ray)) return {};
  return test == TriangleTest::kWatertight
             ? run_query<TriangleTest::kWatertight, false>(scene, ray, ray_mask, counters)
             : run_query<TriangleTest::kFast, false>(scene, ray, ray_mask, counters);
}

bool occluded(const Scene& scene, const Ray& ray, std::uint32_t ray_mask, TriangleTest test,
              TraversalCounters* counters) {
  if (!valid_ray(ray)) return false;
  const Hit hit = test == TriangleTest::kWatertight
                      ? run_query<TriangleTest::kWatertight, true>(scene, ray, ray_mask, counters)
                      : run_query<TriangleTest::kFast, true>(scene, ray, ray_mask, counters);
  return hit.valid();
}

Hit intersect(const Scene& scene, const Ray& ray, TriangleTest test, TraversalCounters* counters) {
  return intersect(scene, ray, kAllMaskBits, test, counters);
}

bool occluded(const Scene& scene, const Ray& ray, TriangleTest test, TraversalCounters* counters) {
  return occluded(scene, ray, kAllMaskBits, test, counters);
}

}  // namespace sinew::rt
