#include "raytrace/traverse/large_packet.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "raytrace/cull/grid_frusta.h"
#include "raytrace/cull/group_frusta.h"
#include "raytrace/cull/packet_frusta.h"
#include "raytrace/cull/interval_bound.h"
#include "raytrace/cull/interval_walk.h"
#include "raytrace/cull/ray_bound.h"
#include "raytrace/geometry/triangle_intersect8.h"
#include "raytrace/traverse/leaf_triangles.h"
#include "raytrace/traverse/mailbox.h"
#include "raytrace/traverse/packet_lanes.h"
#include "raytrace/traverse/packet_rays.h"
#include "raytrace/traverse/ray_frames.h"
#include "raytrace/traverse/segment_apex.h"
#include "raytrace/traverse/traversal_shared.h"
#include "runtime/math/float8.h"

namespace sinew::rt {
namespace {

using detail::max_abs;
using packet_lanes::clip_lanes;
using packet_lanes::for_each_bit;
using packet_lanes::Group;
using packet_lanes::PacketRays;
using packet_lanes::SegmentApex;
using packet_lanes::thread_query;
using packet_lanes::kInf;
using packet_lanes::kLanes;
using packet_lanes::VisitGroup;
using packet_lanes::world_eps;

template <TriangleTest kTest, bool kAnyHit>
class LargeQuery : public PacketRays<kTest, kAnyHit> {
  using Rays = PacketRays<kTest, kAnyHit>;
  using Rays::alive_groups_;
  using Rays::common_origin_;
  using Rays::common_origin_at_;
  using Rays::counters_;
  using Rays::group_;
  using Rays::group_limit;
  using Rays::groups_;
  using Rays::limits_lowered_;
  using Rays::live_;
  using Rays::packet_limit;
  using Rays::test_groups;
  using Rays::test_groups_prepared;
  using Rays::visit_;

 public:
  void start(const Scene& scene, const LargePacketRays& rays, PacketHits out) {
    Rays::start(rays, out);
    scene_p_ = &scene;
    grid_ = {rays.grid_columns, rays.grid_forward, rays.grid_right, rays.grid_up};
    group_frusta_ = rays.group_frusta;
    clip_leaf_lanes_ = rays.clip_leaf_lanes;
    segment_apex_found_ = false;
    frusta_.off();
  }

  void run(std::span<const std::uint32_t> objects) {
    if (alive_groups_ == 0 || objects.empty()) return;
    const std::span<const TopLevelObject> all = scene_ref().top_level().objects();
    // The packet's bound in world space and a bound on the slack of every
    // single-ray box clip (traversal_slack_bound, cull/ray_bound.h).
    RangeAccumulator acc;
    Float8 o_mag8(0.0f), d_mag8(0.0f), t_hi8(0.0f);
    for_each_bit(alive_groups_, [&](int g) {
      const Group& gr = group_[g];
      const Mask8 use = Mask8::from_bits(live_[g]);
      const Float8 t_max = Float8::load(gr.t_limit);
      acc.add(gr.origin(), gr.direction(), Float8::load(gr.t_min), t_max, live_[g]);
      o_mag8 = max(o_mag8, select(use, Float8::load(gr.o_mag), Float8(0.0f)));
      d_mag8 = max(d_mag8, select(use, Float8::load(gr.d_mag), Float8(0.0f)));
      t_hi8 = max(t_hi8, select(use, t_max, Float8(0.0f)));
    });
    const RayRanges ranges = acc.ranges();
    const float o_mag = reduce_max(o_mag8), d_mag = reduce_max(d_mag8), t_hi = reduce_max(t_hi8);
    const IntervalBound bound(ranges);
    const float scene_magnitude = max_abs(scene_ref().top_level().bounds());
    const float slack = traversal_slack_bound(o_mag, d_mag, t_hi, scene_magnitude);
    const IntervalBound::Growth grow = bound.grow_for(scene_ref().top_level().bounds(), slack);
    visit_slack_ = slack;
    struct Candidate {
      float entry;
      std::uint32_t object;
    };
    std::array<Candidate, 256> stack_candidates;
    std::vector<Candidate> heap_candidates;
    std::size_t count = 0;
    const auto add = [&](Candidate c) {
      if (count < stack_candidates.size()) {
        stack_candidates[count++] = c;
        return;
      }
      if (heap_candidates.empty()) heap_candidates.assign(stack_candidates.begin(), stack_candidates.end());
      heap_candidates.push_back(c);
      ++count;
    };
    for (const std::uint32_t object : objects) {
      const float e = bound.entry(all[object].box, grow);
      if (e != kInf) add({e != e ? -kInf : e, object});
    }
    Candidate* const begin = heap_candidates.empty() ? stack_candidates.data() : heap_candidates.data();
    segment_apex_found_ = find_segment_apex();
    // Closest hit: front to back, so an object entered after every lane's
    // best hit is skipped. Any hit from one origin or from near one (shadow
    // rays from a point light, an area light's samples): from the light, so
    // a lane blocked on the way retires before it walks the tree it ends
    // in, which costs most.
    if (!kAnyHit || common_origin_ || segment_apex_found_) {
      std::sort(begin, begin + count, [](const Candidate& a, const Candidate& b) {
        return a.entry < b.entry || (a.entry == b.entry && a.object < b.object);
      });
    }
    const bool small_statics_only =
        kTest == TriangleTest::kFast && count > 0 &&
        std::all_of(begin, begin + count,
                    [&](const Candidate& c) { return detail::is_small_static(scene_ref(), all[c.object]); });
    if (small_statics_only) {
      // A ground quad and the like: every triangle against every group, in
      // order, without box clips (the nearest hit is the same).
      for (std::size_t i = 0; i < count && alive_groups_ != 0; ++i) {
        const Scene::StaticMesh& mesh = scene_ref().static_meshes()[all[begin[i].object].index];
        for_each_bit(alive_groups_, [&](int g) {
          visit_[g].leaf_lanes = live_[g];
          counters_.object_visits += static_cast<std::uint64_t>(std::popcount(live_[g]));
        });
        each_triangle(StaticTriangles{mesh}, mesh.desc.triangles.size(), alive_groups_);
      }
      return;
    }
    // The reciprocals for the box clips (correctly rounded, like the single ray's).
    for_each_bit(alive_groups_, [&](int g) {
      Group& gr = group_[g];
      for (int a = 0; a < 3; ++a) (Float8(1.0f) / Float8::load(gr.d[a])).store(gr.inv[a]);
    });
    prepare_frusta();
    for (std::size_t i = 0; i < count; ++i) {
      if (alive_groups_ == 0) return;
      if constexpr (!kAnyHit) {
        if (begin[i].entry > packet_limit(alive_groups_, nullptr)) return;
      }
      visit(all[begin[i].object]);
    }
  }

 private:
  // Whether every live lane starts at t >= 0.
  bool forward() const {
    bool forward = true;
    for_each_bit(alive_groups_, [&](int g) {
      forward = forward && (select(Mask8::from_bits(live_[g]), Float8::load(group_[g].t_min), Float8(0.0f)) >=
                            Float8(0.0f)).bits() == 0xFFu;
    });
    return forward;
  }

  // Any-hit segments from points close together (an area light's
  // samples): their apex, radius and ends (traverse/segment_apex.h). Not
  // for rays from one origin, whose apex is exact.
  bool find_segment_apex() {
    if (!kAnyHit || common_origin_ || !forward()) return false;
    const std::optional<SegmentApex> apex = packet_lanes::find_segment_apex(group_, live_, alive_groups_, segment_ends_);
    if (!apex) return false;
    segment_apex_ = *apex;
    return true;
  }

  // Frusta (cull/packet_frusta.h) for rays from one origin, t >= 0: camera
  // rays and shadow rays from a point light, whose frusta also get a far
  // plane at their ends, and segments from near one (find_segment_apex);
  // other packets go without (frusta_ stays off).
  void prepare_frusta() {
    frusta_.off();
    if (!common_origin_ && !segment_apex_found_) return;
    if (!forward()) return;
    // Shadow packets: the groups' slabs in the packet's basis, cheaper per
    // triangle than their own frusta and built with the packet's bound
    // (docs/RAYTRACE.md, "Shadow slabs"), unless the packet asks for the
    // groups' own (LargePacketRays::group_frusta).
    const bool slabs = kAnyHit && !group_frusta_;
    if (common_origin_) {
      frusta_.start(common_origin_at_, 0.0f, groups_, grid_, slabs, directions(), lanes());
      return;
    }
    frusta_.start(segment_apex_.at, segment_apex_.radius, groups_, grid_, slabs, directions(), lanes());
    // Segments too near their apex build no plane: their packet walks as
    // one without frusta, clipping lanes to cells.
    ensure_frusta(alive_groups_);
    if (!frusta_.culls()) frusta_.off();
  }

  // Group g's directions (from the apex: a segment's far end) and live
  // lanes, as the frusta read them.
  auto directions() const {
    return [this](int g) -> const float (&)[3][kLanes] {
      return segment_apex_found_ ? segment_ends_[static_cast<std::size_t>(g)].q : group_[g].d;
    };
  }
  auto lanes() const {
    return [this](int g) { return live_[g]; };
  }

  // The groups of `groups` whose frustum may reach the box.
  GroupMask frusta_box_reached(const Aabb& box, GroupMask groups) const { return frusta_.box_reached(box, groups); }

  // The frusta of `groups`, built with every other live group's.
  void ensure_frusta(GroupMask groups) {
    if constexpr (!kAnyHit) {
      frusta_.template ensure<false>(groups, alive_groups_, directions(), lanes(), [](int, float*) {});
    } else {
      // A lane's points end at t_max (an infinite one: no far plane);
      // segments' directions are their ends.
      const auto reach = [&](int g, float* out) {
        if (segment_apex_found_) {
          std::fill_n(out, kLanes, 1.0f);
        } else {
          std::copy_n(group_[g].t_limit, kLanes, out);
        }
      };
      frusta_.template ensure<true>(groups, alive_groups_, directions(), lanes(), reach);
    }
  }

  // Enters one object: each group's lanes clipped to its box as the single
  // ray clips them (traverse/traversal.cpp visit).
  void visit(const TopLevelObject& object) {
    GroupMask groups = 0;
    const float box_magnitude = max_abs(object.box);
    // With group frusta, only the groups whose frustum reaches the box
    // grown by every lane's slack clip their lanes to it: most groups of a
    // packet miss most of the objects its bound reaches (a shadow packet's
    // groups enter about one object in three). The others enter nothing.
    GroupMask clipped = alive_groups_;
    if (frusta_.on()) {
      ensure_frusta(alive_groups_);
      const Vec3 s(visit_slack_);
      clipped = frusta_box_reached({object.box.lower - s, object.box.upper + s}, alive_groups_);
      for_each_bit(alive_groups_ & ~clipped, [&](int g) { visit_[g].lanes = visit_[g].leaf_lanes = 0; });
    }
    if (kTest == TriangleTest::kFast && detail::is_small_static(scene_ref(), object)) {
      // A ground quad and the like: its triangles are tested directly, and
      // a lane's clip to their box would only repeat what the triangle
      // tests decide (run()'s short cut for packets of such meshes).
      for_each_bit(clipped, [&](int g) {
        visit_[g].lanes = visit_[g].leaf_lanes = live_[g];
        if (live_[g] != 0) groups |= GroupMask{1} << g;
        counters_.object_visits += static_cast<std::uint64_t>(std::popcount(live_[g]));
      });
      const Scene::StaticMesh& mesh = scene_ref().static_meshes()[object.index];
      if (groups != 0) each_triangle(StaticTriangles{mesh}, mesh.desc.triangles.size(), groups);
      return;
    }
    for_each_bit(clipped, [&](int g) {
      const Group& gr = group_[g];
      VisitGroup& vg = visit_[g];
      Float8 t0 = Float8::load(gr.t_min), t1 = Float8::load(gr.t_limit);
      const Float8 eps = world_eps(gr, box_magnitude, t1);
      const Vec3x8 inv{Float8::load(gr.inv[0]), Float8::load(gr.inv[1]), Float8::load(gr.inv[2])};
      vg.lanes = clip_lanes(object.box, eps, gr.origin(), gr.direction(), inv, live_[g], t0, t1);
      vg.leaf_lanes = vg.lanes;
      t0.store(vg.t0);
      t1.store(vg.t1);
      if (vg.lanes != 0) {
        groups |= GroupMask{1} << g;
        counters_.object_visits += static_cast<std::uint64_t>(std::popcount(vg.lanes));
      }
    });
    if (groups == 0) return;
    if (frusta_.on()) {
      items_seen_.reset();
    } else {
      mailbox_.reset();
    }
    visit_object(scene_ref(), object, *this, groups);
  }

 public:
  // The object kinds' walks (visit_object, traverse/leaf_triangles.h) for
  // the lanes of `groups` that entered the object (visit_[g].lanes).
  void each_triangle(const StaticTriangles& triangles, std::size_t count, GroupMask groups) {
    for (std::uint32_t t = 0; t < count && groups != 0; ++t) {
      const LeafTriangle tri = triangles(t);
      test_groups(groups, *tri.p0, *tri.p1, *tri.p2, tri.triangle, tri.instance);
      groups &= alive_groups_;
    }
  }
  template <class Source>
  void world_tree(const KdTreeView& tree, const Source& triangles, GroupMask groups) {
    const auto leaf = [&](std::uint32_t, std::span<const std::uint32_t> items, GroupMask groups_here) {
      return test_leaf(items, groups_here, triangles);
    };
    visit_world_tree(tree, groups, leaf);
  }
  void bone_tree(const InstanceFrame& frame, std::uint32_t bone, const Scene::Character& character,
                 const SkinnedTriangles& corners, GroupMask groups) {
    const BoneTree& tree = frame.bone_tree(character.fuzzy, bone);
    if (tree.node_count == 0) return;
    // Each group's rays in the bone frame, with each lane's slack there
    // (traverse/ray_frames.h, as the single ray).
    TreeEntry entry;
    for_each_bit(groups, [&](int g) {
      const Group& gr = group_[g];
      const per_lane::FrameRay<Float8> r =
          per_lane::to_bone_frame<Float8>(frame, bone, gr.origin(), gr.direction(), Float8::load(gr.o_mag),
                                       Float8::load(visit_[g].t1), Mask8::from_bits(visit_[g].lanes));
      const Vec3x8& o = r.o;
      const Vec3x8& d = r.d;
      const Float8 eps = r.eps;
      if (frusta_.on()) {
        enter_tree_unclipped(entry, g, o, d, eps);
        return;
      }
      enter_tree(entry, tree.bounds, g, o, d, per_lane::reciprocal<Float8>(d), eps);
    });
    const auto leaf = [&](std::uint32_t node, std::span<const std::uint32_t> triangles, GroupMask groups_here) {
      if (frusta_.on()) {
        // The leaf's triangles as they are this frame (raytrace/scene/leaf_boxes.h):
        // a leaf no frustum reaches costs one box test, not one per triangle.
        ensure_frusta(groups_here & alive_groups_);
        const Aabb box = frame.leaf_boxes.get(bone, node, [&] { return triangles_box(triangles, corners); });
        groups_here = frusta_box_reached(box, groups_here & alive_groups_);
        if (clip_leaf_lanes_) groups_here = clip_to_leaf_box(box, groups_here);
        if (groups_here == 0) return false;
        return test_leaf_in_frusta(triangles, groups_here, corners, character.fuzzy.has_bvhs(), clip_leaf_lanes_);
      }
      return test_leaf(triangles, groups_here, corners, character.fuzzy.has_bvhs());
    };
    if (character.fuzzy.has_bvhs()) {
      walk_tree(character.fuzzy.bvh_view(tree), entry, leaf);
    } else {
      walk_tree(character.fuzzy.tree_view(tree), entry, leaf);
    }
  }

 private:
  // The box of the triangles of `items` (corners(item): a LeafTriangle).
  template <class TriangleSource>
  static Aabb triangles_box(std::span<const std::uint32_t> items, const TriangleSource& corners) {
    Vec3 lo(kInf), hi(-kInf);
    for (const std::uint32_t item : items) {
      const LeafTriangle tri = corners(item);
      lo = min(lo, min(*tri.p0, min(*tri.p1, *tri.p2)));
      hi = max(hi, max(*tri.p0, max(*tri.p1, *tri.p2)));
    }
    return {lo, hi};
  }

  // A leaf's items for the groups reaching it. `corners(item)` gives the
  // item's triangle (LeafTriangle). With group frusta see
  // test_leaf_in_frusta; without, each item (mailboxed by its index) is
  // tested by the groups with lanes in the leaf left to test it. Returns
  // true when every lane is answered (any hit).
  template <class TriangleSource>
  bool test_leaf(std::span<const std::uint32_t> items, GroupMask groups_here, const TriangleSource& corners,
                 bool listed_once = false) {
    if (frusta_.on()) return test_leaf_in_frusta(items, groups_here, corners, listed_once);
    for (const std::uint32_t item : items) {
      GroupMask need = 0;
      for_each_bit(groups_here & alive_groups_, [&](int g) {
        visit_[g].leaf_lanes = mailbox_.untested(item, g, leaf_lanes_[g]) & live_[g];
        if (visit_[g].leaf_lanes != 0) need |= GroupMask{1} << g;
      });
      if (need == 0) continue;
      const LeafTriangle tri = corners(item);
      test_groups(need, *tri.p0, *tri.p1, *tri.p2, tri.triangle, tri.instance);
      // Done only when every group in the tree is (not just this leaf's).
      if (kAnyHit && (tree_groups_ & alive_groups_) == 0) return true;
    }
    return false;
  }

  // test_leaf with group frusta: each item is tested once per object visit
  // (a tree that lists each item once, a BVH, `listed_once`, needs no
  // mailbox for that), by the groups whose frustum it reaches. The items
  // go eight at a time: their corners side by side, culled against each
  // group of the leaf together (reached8) and, for the fast test, their
  // origin terms prepared together (prepare_common_origin8); one triangle
  // at a time was tested against every group of a block of eight, whatever
  // the leaf's groups.
  // `lanes_clipped`: leaf_lanes_ holds each group's lanes that reach the
  // leaf (clip_to_leaf_box); otherwise every lane of a group is tested.
  template <class TriangleSource>
  bool test_leaf_in_frusta(std::span<const std::uint32_t> items, GroupMask groups_here, const TriangleSource& corners,
                           bool listed_once, bool lanes_clipped = false) {
    ensure_frusta(groups_here & alive_groups_);
    std::size_t next = 0;
    while (next < items.size()) {
      const GroupMask here = groups_here & alive_groups_;
      if (here == 0) return false;
      int n = 0;
      for (; next < items.size() && n < kLanes; ++next) {
        const std::uint32_t item = items[next];
        if (!listed_once && !items_seen_.first_visit(item)) continue;
        const LeafTriangle tri = corners(item);
        const Vec3* const p[3] = {tri.p0, tri.p1, tri.p2};
        for (int k = 0; k < 3; ++k) {
          batch_.p[k][0][n] = p[k]->x;
          batch_.p[k][1][n] = p[k]->y;
          batch_.p[k][2][n] = p[k]->z;
        }
        batch_triangle_[n] = tri.triangle;
        batch_instance_[n] = tri.instance;
        ++n;
      }
      if (n == 0) return false;
      const std::uint32_t lanes = (1u << n) - 1u;
      std::uint64_t reach[kLanes];
      if (kAnyHit && std::has_single_bit(here)) {
        // A shadow packet's leaf that one group alone reaches (most leaves
        // on pixel-sized triangles, where the leaf's box picked its
        // groups): the group's frustum test would cost about what its
        // lane test does.
        std::fill(std::begin(reach), std::end(reach), here);
      } else {
        frusta_.reached8(batch_, lanes, here, reach);
      }
      // The fast test's origin terms, once for every group, for rays from one origin.
      const bool prepared = kTest == TriangleTest::kFast && common_origin_;
      if (prepared) prepare_common_origin8(common_origin_at_, batch_.p, prepared_);
      for (int i = 0; i < n; ++i) {
        const GroupMask need = reach[i] & alive_groups_;
        if (need == 0) continue;
        for_each_bit(need, [&](int g) {
          visit_[g].leaf_lanes = visit_[g].lanes & live_[g] & (lanes_clipped ? leaf_lanes_[g] : 0xFFu);
        });
        if (prepared) {
          test_groups_prepared(need, prepared_.at(i), batch_triangle_[i], batch_instance_[i]);
        } else {
          test_groups(need, batch_.corner(0, i), batch_.corner(1, i), batch_.corner(2, i), batch_triangle_[i],
                      batch_instance_[i]);
        }
        // Done only when every group in the tree is (not just this leaf's).
        if (kAnyHit && (tree_groups_ & alive_groups_) == 0) return true;
      }
    }
    return false;
  }

  // A world-space tree below the top level (a static mesh's, the escape
  // fallback's): the world rays with the single ray's slack for the tree.
  template <class LeafFn>
  void visit_world_tree(const KdTreeView& tree, GroupMask groups, LeafFn& leaf) {
    if (tree.empty()) return;
    const float box_magnitude = max_abs(tree.bounds);
    TreeEntry entry;
    for_each_bit(groups, [&](int g) {
      const Group& gr = group_[g];
      const Float8 eps = world_eps(gr, box_magnitude, Float8::load(visit_[g].t1));
      if (frusta_.on()) {
        // The lanes were just clipped to the object's box, which is the
        // tree's (a static mesh's, the fallback's): a second clip would
        // only narrow their passage by the difference in slack.
        enter_tree_unclipped(entry, g, gr.origin(), gr.direction(), eps);
        return;
      }
      const Vec3x8 inv{Float8::load(gr.inv[0]), Float8::load(gr.inv[1]), Float8::load(gr.inv[2])};
      enter_tree(entry, tree.bounds, g, gr.origin(), gr.direction(), inv, eps);
    });
    walk_tree(tree, entry, leaf);
  }


  // The lanes of each group of `groups` whose world ray, over its passage
  // through the object and short of its best hit, meets `box` (a bone-tree
  // leaf's current triangles, raytrace/scene/leaf_boxes.h) grown by the
  // single ray's slack for a world box (world_eps), kept in leaf_lanes_;
  // returns the groups left with lanes. A group's frustum reaching the box
  // says one of its rays may; this says which: a leaf near the ends of
  // thin shadow groups, or behind a closest hit, keeps few of their lanes.
  GroupMask clip_to_leaf_box(const Aabb& box, GroupMask groups) {
    GroupMask kept = 0;
    const float box_magnitude = max_abs(box);
    for_each_bit(groups, [&](int g) {
      const Group& gr = group_[g];
      const VisitGroup& vg = visit_[g];
      Float8 t0 = Float8::load(vg.t0);
      Float8 t1 = min(Float8::load(vg.t1), Float8::load(gr.t_limit));
      const Vec3x8 inv{Float8::load(gr.inv[0]), Float8::load(gr.inv[1]), Float8::load(gr.inv[2])};
      leaf_lanes_[g] = clip_lanes(box, world_eps(gr, box_magnitude, t1), gr.origin(), gr.direction(), inv,
                                  vg.lanes & live_[g], t0, t1);
      if (leaf_lanes_[g] != 0) kept |= GroupMask{1} << g;
    });
    return kept;
  }

  // Entering a tree: the groups' lanes clipped to its root box, their rays
  // in the tree's frame kept for the leaf clips, and the packet's bound.
  struct TreeEntry {
    RangeAccumulator ranges;
    float eps = 0.0f;  // the largest lane slack
    GroupMask groups = 0;
  };

  // Group g's rays o + t d in the tree's frame (reciprocals inv, lane
  // slack eps).
  void enter_tree(TreeEntry& entry, const Aabb& bounds, int g, const Vec3x8& o, const Vec3x8& d,
                  const Vec3x8& inv, Float8 eps) {
    VisitGroup& vg = visit_[g];
    Float8 t0 = Float8::load(vg.t0), t1 = Float8::load(vg.t1);
    vg.lanes = clip_lanes(bounds, eps, o, d, inv, vg.lanes, t0, t1);
    if (vg.lanes == 0) return;
    t0.store(vg.t0);
    t1.store(vg.t1);
    const Float8* const oc[3] = {&o.x, &o.y, &o.z};
    const Float8* const dc[3] = {&d.x, &d.y, &d.z};
    const Float8* const ic[3] = {&inv.x, &inv.y, &inv.z};
    for (int a = 0; a < 3; ++a) {
      oc[a]->store(vg.o[a]);
      dc[a]->store(vg.d[a]);
      ic[a]->store(vg.inv[a]);
    }
    eps.store(vg.lane_eps);
    enter_tree_unclipped(entry, g, o, d, eps);
  }

  // With group frusta no leaf clips a group's lanes (the triangles pick
  // their groups), so the rays need not be clipped to the root box or kept
  // in the tree's frame: they join the packet's bound over their passage
  // through the object, and the walk tests the root box itself.
  void enter_tree_unclipped(TreeEntry& entry, int g, const Vec3x8& o, const Vec3x8& d, Float8 eps) {
    const VisitGroup& vg = visit_[g];
    if (vg.lanes == 0) return;
    const Float8 t0 = Float8::load(vg.t0), t1 = Float8::load(vg.t1);
    entry.ranges.add(o, d, t0, t1, vg.lanes);
    entry.eps = std::max(entry.eps, reduce_max(select(Mask8::from_bits(vg.lanes), eps, Float8(0.0f))));
    entry.groups |= GroupMask{1} << g;
  }

  // The groups of `entry` through a kd-tree or a BVH (cull/interval_walk.h),
  // each reached leaf's lanes picked by visit_leaf.
  template <class Tree, class LeafFn>
  void walk_tree(const Tree& tree, const TreeEntry& entry, LeafFn& leaf) {
    if (entry.groups == 0) return;
    const IntervalBound bound(entry.ranges.ranges());
    tree_groups_ = entry.groups;
    PacketLimit limit(*this, entry.groups, bound);
    interval_walk(tree, bound, bound.grow_for(tree.bounds, entry.eps), limit, leaf_of(entry.groups, leaf),
                  counters_.node_visits);
  }
  template <class LeafFn>
  auto leaf_of(GroupMask groups, LeafFn& leaf) {
    return [this, groups, &leaf](const Aabb& cell, std::uint32_t node, std::span<const std::uint32_t> items) {
      return visit_leaf(cell, node, items, groups, leaf);
    };
  }

  // The packet's limit for pruning a walk's nodes: for any-hit rays the
  // bound's far end; for closest-hit rays the largest of its groups'
  // (group_limit), and a group's changes only when one of its lanes records
  // a hit, so only those groups are looked at again (a closest-hit
  // packet's groups stay alive throughout).
  class PacketLimit {
   public:
    PacketLimit(LargeQuery& q, GroupMask groups, const IntervalBound& bound) : q_(q), groups_(groups), bound_(bound) {
      if constexpr (!kAnyHit) {
        limits_.fill(-kInf);
        for_each_bit(groups_ & q_.alive_groups_, [&](int g) { limits_[g] = q_.group_limit(g, q_.visit_.data()); });
        cached_ = packet_max();
        q_.limits_lowered_ = 0;
      }
    }
    float operator()() {
      if constexpr (kAnyHit) {
        return bound_.t_hi();
      } else {
        if (q_.limits_lowered_ != 0) {
          for_each_bit(q_.limits_lowered_ & groups_ & q_.alive_groups_,
                       [&](int g) { limits_[g] = q_.group_limit(g, q_.visit_.data()); });
          q_.limits_lowered_ = 0;
          cached_ = packet_max();
        }
        return cached_;
      }
    }

   private:
    float packet_max() const {
      Float8 m(-kInf);
      const int blocks = (q_.groups_ + kLanes - 1) / kLanes;
      for (int i = 0; i < blocks; ++i) m = max(m, Float8::load(&limits_[static_cast<std::size_t>(i * kLanes)]));
      return reduce_max(m);
    }
    LargeQuery& q_;
    GroupMask groups_;
    const IntervalBound& bound_;
    alignas(32) std::array<float, kMaxPacketGroups> limits_;
    float cached_ = kInf;
  };

  // A leaf (a kd-tree cell, or a BVH leaf's box: every item's fuzzy box
  // inside it) reached by the packet: without group frusta each group's
  // lanes are clipped to `cell` exactly, as their single rays would be
  // (grown by each lane's own slack); with them each triangle picks its
  // groups itself, more tightly than the cell would. Returns true to stop.
  template <class LeafFn>
  bool visit_leaf(const Aabb& cell, std::uint32_t node, std::span<const std::uint32_t> items, GroupMask groups,
                  LeafFn& leaf) {
    GroupMask reaching = 0;
    if (frusta_.on()) reaching = groups & alive_groups_;
    for_each_bit(frusta_.on() ? GroupMask{0} : groups & alive_groups_, [&](int g) {
      const VisitGroup& vg = visit_[g];
      Float8 t0 = Float8::load(vg.t0), t1 = Float8::load(vg.t1);
      if constexpr (!kAnyHit) t1 = min(t1, Float8::load(group_[g].t_limit));
      leaf_lanes_[g] = clip_lanes(cell, Float8::load(vg.lane_eps), vg.origin(), vg.direction(), vg.inverse(),
                                  vg.lanes & live_[g], t0, t1);
      if (leaf_lanes_[g] != 0) reaching |= GroupMask{1} << g;
    });
    return reaching != 0 && leaf(node, items, reaching);
  }

  const Scene* scene_p_ = nullptr;
  const Scene& scene_ref() const { return *scene_p_; }
  std::array<std::uint32_t, kMaxPacketGroups> leaf_lanes_{};  // per group: the lanes reaching the current leaf
  GroupMask tree_groups_ = 0;  // the groups walking the current tree
  // test_leaf_in_frusta: up to eight of a leaf's triangles, their ids and
  // instances, and their origin terms.
  TriangleLanes8 batch_;
  std::array<std::uint32_t, kLanes> batch_triangle_{};
  std::array<std::uint32_t, kLanes> batch_instance_{};
  CommonOriginLanes8 prepared_;
  LaneMailbox<kMaxPacketGroups> mailbox_;
  ItemMailbox<512> items_seen_;
  PacketFrusta<kMaxPacketGroups> frusta_;  // on: they pick each leaf triangle's groups
  PacketFrusta<kMaxPacketGroups>::Grid grid_;  // LargePacketRays' pixel grid
  float visit_slack_ = 0.0f;       // run(): a bound on every lane's slack in an object's box clip
  // find_segment_apex: whether the packet's segments start near one apex,
  // the apex and its radius, and each group's far ends relative to it.
  bool segment_apex_found_ = false;
  SegmentApex segment_apex_;
  std::array<packet_lanes::SegmentEnds, kMaxPacketGroups> segment_ends_;
  bool group_frusta_ = false;      // LargePacketRays::group_frusta
  bool clip_leaf_lanes_ = false;   // LargePacketRays::clip_leaf_lanes
};

template <TriangleTest kTest, bool kAnyHit>
void run_query(const Scene& scene, const LargePacketRays& rays, std::span<const std::uint32_t> objects, PacketHits out,
               std::uint8_t* blocked, TraversalCounters* counters) {
  LargeQuery<kTest, kAnyHit>& query = thread_query<LargeQuery<kTest, kAnyHit>>();
  query.start(scene, rays, out);
  query.run(objects);
  query.finish(blocked, counters);
}

}  // namespace

void intersect_large_packet(const Scene& scene, const LargePacketRays& rays, TriangleTest test,
                            std::span<const std::uint32_t> objects, PacketHits out, TraversalCounters* counters) {
  if (test == TriangleTest::kWatertight) {
    run_query<TriangleTest::kWatertight, false>(scene, rays, objects, out, nullptr, counters);
  } else {
    run_query<TriangleTest::kFast, false>(scene, rays, objects, out, nullptr, counters);
  }
}

void occluded_large_packet(const Scene& scene, const LargePacketRays& rays, TriangleTest test,
                           std::span<const std::uint32_t> objects, std::uint8_t* blocked,
                           TraversalCounters* counters) {
  const PacketHits none{nullptr, nullptr, nullptr, nullptr, nullptr};
  if (test == TriangleTest::kWatertight) {
    run_query<TriangleTest::kWatertight, true>(scene, rays, objects, none, blocked, counters);
  } else {
    run_query<TriangleTest::kFast, true>(scene, rays, objects, none, blocked, counters);
  }
}

}  // namespace sinew::rt
