#include "content/mannequin/mannequin.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <initializer_list>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "runtime/core/status.h"

namespace sinew::content {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;
constexpr const char* kSourceName = "mannequin";
// Every length below is for a 1.8 m figure and scaled by height / 1.8.
constexpr float kDesignHeight = 1.8f;
constexpr float kKeyRate = 15.0f;  // keys per second

float deg(float d) { return d * kPi / 180.0f; }

float smoothstep01(float x) {
  const float t = std::clamp(x, 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

// ---------------------------------------------------------------- skeleton

struct JointDef {
  const char* name;
  const char* parent;  // nullptr for the root
  Vec3 position;       // model space at design height
};

// T-pose, facing +Z, left = +X.
const std::array<JointDef, 21> kJoints{{
    {"pelvis", nullptr, {0.0f, 0.95f, 0.0f}},
    {"spine", "pelvis", {0.0f, 1.08f, 0.0f}},
    {"chest", "spine", {0.0f, 1.26f, 0.0f}},
    {"neck", "chest", {0.0f, 1.50f, 0.0f}},
    {"head", "neck", {0.0f, 1.58f, 0.0f}},
    {"clavicle_l", "chest", {0.02f, 1.45f, 0.0f}},
    {"upperarm_l", "clavicle_l", {0.17f, 1.45f, 0.0f}},
    {"lowerarm_l", "upperarm_l", {0.45f, 1.45f, 0.0f}},
    {"hand_l", "lowerarm_l", {0.71f, 1.45f, 0.0f}},
    {"clavicle_r", "chest", {-0.02f, 1.45f, 0.0f}},
    {"upperarm_r", "clavicle_r", {-0.17f, 1.45f, 0.0f}},
    {"lowerarm_r", "upperarm_r", {-0.45f, 1.45f, 0.0f}},
    {"hand_r", "lowerarm_r", {-0.71f, 1.45f, 0.0f}},
    {"thigh_l", "pelvis", {0.10f, 0.92f, 0.0f}},
    {"calf_l", "thigh_l", {0.10f, 0.50f, 0.0f}},
    {"foot_l", "calf_l", {0.10f, 0.08f, 0.0f}},
    {"toe_l", "foot_l", {0.10f, 0.03f, 0.13f}},
    {"thigh_r", "pelvis", {-0.10f, 0.92f, 0.0f}},
    {"calf_r", "thigh_r", {-0.10f, 0.50f, 0.0f}},
    {"foot_r", "calf_r", {-0.10f, 0.08f, 0.0f}},
    {"toe_r", "foot_r", {-0.10f, 0.03f, 0.13f}},
}};

int def_index(const char* name) {
  for (std::size_t i = 0; i < kJoints.size(); ++i) {
    if (std::string_view(kJoints[i].name) == name) return static_cast<int>(i);
  }
  return anim::kNoParent;
}

Expected<anim::Skeleton> build_skeleton(float scale) {
  anim::RawSkeleton raw;
  for (const JointDef& def : kJoints) {
    anim::RawJoint joint;
    joint.name = def.name;
    const Vec3 position = def.position * scale;
    Vec3 parent_position(0.0f);
    if (def.parent != nullptr) {
      joint.parent = def_index(def.parent);
      parent_position = kJoints[static_cast<std::size_t>(joint.parent)].position * scale;
    }
    joint.rest.translation = position - parent_position;
    joint.inverse_bind = Affine3::translation(-position);
    raw.joints.push_back(std::move(joint));
  }
  return anim::Skeleton::build(raw, kSourceName);
}

// -------------------------------------------------------------------- mesh

struct Influence {
  int joint = 0;
  float weight = 0.0f;
};
using Weights = std::array<Influence, 2>;

// A chain of bones along a tube's axis: bone k owns t >= starts[k] (until the
// next start); within `blend[k]` of starts[k] the ring blends bones k-1 and
// k, so the skin stretches smoothly over the joint instead of creasing.
struct BoneChain {
  std::vector<int> joints;
  std::vector<float> starts;  // starts[0] is ignored
  std::vector<float> blend;   // half-widths, blend[0] ignored

  Weights weights_at(float t) const {
    std::size_t k = 0;
    while (k + 1 < joints.size() && t >= starts[k + 1]) ++k;
    // Blend with the nearer neighbour boundary, if any is close.
    if (k + 1 < joints.size() && t > starts[k + 1] - blend[k + 1]) {
      const float w = smoothstep01((t - (starts[k + 1] - blend[k + 1])) / (2.0f * blend[k + 1]));
      return {{{joints[k], 1.0f - w}, {joints[k + 1], w}}};
    }
    if (k > 0 && t < starts[k] + blend[k]) {
      const float w = smoothstep01((t - (starts[k] - blend[k])) / (2.0f * blend[k]));
      return {{{joints[k - 1], 1.0f - w}, {joints[k], w}}};
    }
    return {{{joints[k], 1.0f}, {joints[k], 0.0f}}};
  }
};

// Cross-section at a point of the axis: half-extents along u and v and an
// offset of the centre along v (the feet sit on the floor, not on their axis).
struct Station {
  float t;
  float ru;
  float rv;
  float offset_v = 0.0f;
};

struct Material {
  float until_t;  // this material up to (and excluding) t, in axis order
  std::uint32_t index;
};

struct TubeSpec {
  Vec3 origin;  // the axis passes through origin + t * axis
  Vec3 axis;    // unit
  Vec3 u;       // unit, perpendicular to axis; v = axis x u
  std::vector<Station> stations;  // increasing t, at least two
  float cap_start = 0.0f;         // depth of the end caps along the axis
  float cap_end = 0.0f;
  int segments = 12;  // vertices per ring, a multiple of 4
  int body_rings = 10;
  int cap_rings = 2;
  BoneChain bones;
  std::vector<Material> materials;  // increasing until_t; last one covers the rest
};

Station profile_at(const std::vector<Station>& s, float t) {
  if (t <= s.front().t) return s.front();
  if (t >= s.back().t) return s.back();
  std::size_t i = 0;
  while (s[i + 1].t < t) ++i;
  // Cosine easing between stations gives a rounded silhouette rather than
  // visible kinks at each station.
  const float x = (t - s[i].t) / (s[i + 1].t - s[i].t);
  const float w = 0.5f - 0.5f * std::cos(x * kPi);
  return {t, s[i].ru + (s[i + 1].ru - s[i].ru) * w, s[i].rv + (s[i + 1].rv - s[i].rv) * w,
          s[i].offset_v + (s[i + 1].offset_v - s[i].offset_v) * w};
}

std::uint32_t material_at(const std::vector<Material>& m, float t) {
  for (const Material& entry : m) {
    if (t < entry.until_t) return entry.index;
  }
  return m.back().index;
}

class MeshBuilder {
 public:
  explicit MeshBuilder(SkinnedMesh& mesh) : _mesh(mesh) {}

  // Rings from the start pole to the end pole; triangles wound so that
  // (b - a) x (c - a) points away from the axis.
  void add_tube(const TubeSpec& spec) {
    const Vec3 v = glm::cross(spec.axis, spec.u);
    const Station first = spec.stations.front();
    const Station last = spec.stations.back();

    struct Ring {
      float t;  // axis position of the ring (for weights and materials)
      Station shape;
      float scale;  // radial scale (caps shrink towards the pole)
      float weight_t;
    };
    std::vector<Ring> rings;
    const int caps = spec.cap_rings;
    for (int k = caps; k >= 1; --k) {
      const float phi = static_cast<float>(k) * (kPi / 2.0f) / static_cast<float>(caps + 1);
      rings.push_back({first.t - spec.cap_start * std::sin(phi), first, std::cos(phi), first.t});
    }
    for (int i = 0; i < spec.body_rings; ++i) {
      const float t = first.t + (last.t - first.t) * static_cast<float>(i) /
                                    static_cast<float>(spec.body_rings - 1);
      rings.push_back({t, profile_at(spec.stations, t), 1.0f, t});
    }
    for (int k = 1; k <= caps; ++k) {
      const float phi = static_cast<float>(k) * (kPi / 2.0f) / static_cast<float>(caps + 1);
      rings.push_back({last.t + spec.cap_end * std::sin(phi), last, std::cos(phi), last.t});
    }

    const auto point = [&](float t, const Station& s, float scale, float angle) {
      return spec.origin + spec.axis * t + v * s.offset_v +
             spec.u * (s.ru * scale * std::cos(angle)) + v * (s.rv * scale * std::sin(angle));
    };

    const auto n = static_cast<std::uint32_t>(spec.segments);
    const auto start_pole = add_vertex(point(first.t - spec.cap_start, first, 0.0f, 0.0f),
                                       spec.bones.weights_at(first.t));
    const auto ring_base = static_cast<std::uint32_t>(_mesh.positions.size());
    for (const Ring& ring : rings) {
      const Weights w = spec.bones.weights_at(ring.weight_t);
      for (std::uint32_t j = 0; j < n; ++j) {
        const float angle = 2.0f * kPi * static_cast<float>(j) / static_cast<float>(n);
        add_vertex(point(ring.t, ring.shape, ring.scale, angle), w);
      }
    }
    const auto end_pole =
        add_vertex(point(last.t + spec.cap_end, last, 0.0f, 0.0f), spec.bones.weights_at(last.t));

    const auto ring_count = static_cast<std::uint32_t>(rings.size());
    const auto at = [&](std::uint32_t ring, std::uint32_t j) { return ring_base + ring * n + j % n; };
    for (std::uint32_t j = 0; j < n; ++j) {
      add_triangle(start_pole, at(0, j + 1), at(0, j), material_at(spec.materials, rings[0].t));
    }
    for (std::uint32_t r = 0; r + 1 < ring_count; ++r) {
      const std::uint32_t m =
          material_at(spec.materials, 0.5f * (rings[r].t + rings[r + 1].t));
      for (std::uint32_t j = 0; j < n; ++j) {
        add_triangle(at(r, j), at(r, j + 1), at(r + 1, j + 1), m);
        add_triangle(at(r, j), at(r + 1, j + 1), at(r + 1, j), m);
      }
    }
    for (std::uint32_t j = 0; j < n; ++j) {
      add_triangle(at(ring_count - 1, j), at(ring_count - 1, j + 1), end_pole,
                   material_at(spec.materials, rings.back().t));
    }
  }

  // Area-weighted face normals averaged per vertex: tubes share no
  // vertices, so this is the smooth normal of each closed part.
  void compute_normals() {
    _mesh.normals.assign(_mesh.positions.size(), Vec3(0.0f));
    for (const auto& tri : _mesh.triangles) {
      const Vec3& a = _mesh.positions[tri[0]];
      const Vec3 face = glm::cross(_mesh.positions[tri[1]] - a, _mesh.positions[tri[2]] - a);
      for (const std::uint32_t i : tri) _mesh.normals[i] += face;
    }
    for (Vec3& normal : _mesh.normals) normal = glm::normalize(normal);
  }

 private:
  std::uint32_t add_vertex(const Vec3& p, const Weights& w) {
    _mesh.positions.push_back(p);
    std::array<std::uint16_t, kMaxInfluences> joints{};
    std::array<float, kMaxInfluences> weights{};
    std::size_t slot = 0;
    for (const Influence& influence : w) {
      if (influence.weight <= 0.0f) continue;
      joints[slot] = static_cast<std::uint16_t>(influence.joint);
      weights[slot] = influence.weight;
      ++slot;
    }
    // The two blend weights are 1 - w and w; renormalising removes the last
    // rounding so each row sums to 1 as exactly as floats allow.
    float sum = 0.0f;
    for (const float x : weights) sum += x;
    for (float& x : weights) x /= sum;
    _mesh.joints.push_back(joints);
    _mesh.weights.push_back(weights);
    return static_cast<std::uint32_t>(_mesh.positions.size() - 1);
  }

  void add_triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t material) {
    _mesh.triangles.push_back({a, b, c});
    _mesh.triangle_material.push_back(material);
  }

  SkinnedMesh& _mesh;
};

enum MaterialIndex : std::uint32_t { kSkin = 0, kShirt = 1, kTrousers = 2, kShoes = 3 };

void build_mesh(const anim::Skeleton& skeleton, float s, int detail, SkinnedMesh& mesh) {
  const auto j = [&](const char* name) { return *skeleton.find(name); };
  mesh.material_colors = {Vec3(0.80f, 0.60f, 0.48f), Vec3(0.20f, 0.35f, 0.65f),
                          Vec3(0.22f, 0.22f, 0.25f), Vec3(0.35f, 0.20f, 0.10f)};
  MeshBuilder builder(mesh);
  const auto scaled = [s](std::vector<Station> stations) {
    for (Station& st : stations) {
      st.t *= s;
      st.ru *= s;
      st.rv *= s;
      st.offset_v *= s;
    }
    return stations;
  };
  const auto scaled_chain = [s](BoneChain chain) {
    for (float& x : chain.starts) x *= s;
    for (float& x : chain.blend) x *= s;
    return chain;
  };
  const auto scaled_materials = [s](std::vector<Material> m) {
    for (Material& x : m) x.until_t *= s;
    return m;
  };

  // Torso, neck and head: one tube up the Y axis (u = X across the
  // shoulders, v = -Z through the chest).
  {
    TubeSpec torso;
    torso.origin = Vec3(0.0f);
    torso.axis = Vec3(0, 1, 0);
    torso.u = Vec3(1, 0, 0);
    torso.stations = scaled({{0.82f, 0.15f, 0.11f},
                             {0.95f, 0.17f, 0.12f},
                             {1.08f, 0.15f, 0.11f},
                             {1.26f, 0.17f, 0.12f},
                             {1.40f, 0.19f, 0.12f},
                             {1.47f, 0.15f, 0.10f},
                             {1.52f, 0.055f, 0.055f},
                             {1.58f, 0.06f, 0.065f},
                             {1.63f, 0.09f, 0.10f},
                             {1.70f, 0.10f, 0.11f},
                             {1.76f, 0.085f, 0.095f}});
    torso.cap_start = 0.06f * s;
    torso.cap_end = 0.04f * s;
    torso.segments = 20 * detail;
    torso.body_rings = 24 * detail;
    torso.cap_rings = 2 * detail;
    torso.bones = scaled_chain({{j("pelvis"), j("spine"), j("chest"), j("neck"), j("head")},
                                {0.0f, 1.08f, 1.26f, 1.50f, 1.58f},
                                {0.0f, 0.06f, 0.06f, 0.03f, 0.03f}});
    torso.materials = scaled_materials({{1.02f, kTrousers}, {1.495f, kShirt}, {9.0f, kSkin}});
    builder.add_tube(torso);
  }

  // Arms along +-X; the flat hand is thinner along Y (v) than along Z (u).
  for (const int side : {1, -1}) {
    const char* suffix = side > 0 ? "_l" : "_r";
    const auto sj = [&](const char* base) { return j((std::string(base) + suffix).c_str()); };
    TubeSpec arm;
    arm.origin = Vec3(0.0f, 1.45f * s, 0.0f);
    arm.axis = Vec3(static_cast<float>(side), 0, 0);
    arm.u = Vec3(0, 0, 1);
    arm.stations = scaled({{0.10f, 0.055f, 0.055f},
                           {0.17f, 0.055f, 0.055f},
                           {0.30f, 0.048f, 0.048f},
                           {0.45f, 0.038f, 0.038f},
                           {0.60f, 0.032f, 0.030f},
                           {0.70f, 0.028f, 0.024f},
                           {0.78f, 0.045f, 0.018f},
                           {0.86f, 0.040f, 0.015f}});
    arm.cap_start = 0.04f * s;
    arm.cap_end = 0.03f * s;
    arm.segments = 12 * detail;
    arm.body_rings = 14 * detail;
    arm.cap_rings = 2 * detail;
    arm.bones = scaled_chain({{sj("clavicle"), sj("upperarm"), sj("lowerarm"), sj("hand")},
                              {0.0f, 0.17f, 0.45f, 0.71f},
                              {0.0f, 0.05f, 0.05f, 0.03f}});
    arm.materials = scaled_materials({{0.55f, kShirt}, {9.0f, kSkin}});
    builder.add_tube(arm);
  }

  // Legs down -Y from inside the pelvis to inside the foot.
  for (const int side : {1, -1}) {
    const char* suffix = side > 0 ? "_l" : "_r";
    const auto sj = [&](const char* base) { return j((std::string(base) + suffix).c_str()); };
    TubeSpec leg;
    leg.origin = Vec3(0.10f * s * static_cast<float>(side), 0.0f, 0.0f);
    leg.axis = Vec3(0, -1, 0);
    leg.u = Vec3(1, 0, 0);
    // t = -y, so stations run from the hip (t = -0.98) down to the ankle.
    leg.stations = scaled({{-0.98f, 0.085f, 0.085f},
                           {-0.95f, 0.085f, 0.085f},
                           {-0.80f, 0.075f, 0.075f},
                           {-0.60f, 0.055f, 0.055f},
                           {-0.50f, 0.048f, 0.048f},
                           {-0.38f, 0.052f, 0.052f},
                           {-0.20f, 0.038f, 0.038f},
                           {-0.10f, 0.035f, 0.035f}});
    leg.cap_start = 0.05f * s;
    leg.cap_end = 0.03f * s;
    leg.segments = 12 * detail;
    leg.body_rings = 14 * detail;
    leg.cap_rings = 2 * detail;
    leg.bones = scaled_chain({{j("pelvis"), sj("thigh"), sj("calf"), sj("foot")},
                              {0.0f, -0.96f, -0.50f, -0.08f},
                              {0.0f, 0.05f, 0.05f, 0.04f}});
    leg.materials = {{9.0f, kTrousers}};
    builder.add_tube(leg);
  }

  // Feet along +Z, flattened, resting on the floor (offset along v = +Y).
  for (const int side : {1, -1}) {
    const char* suffix = side > 0 ? "_l" : "_r";
    const auto sj = [&](const char* base) { return j((std::string(base) + suffix).c_str()); };
    TubeSpec foot;
    foot.origin = Vec3(0.10f * s * static_cast<float>(side), 0.0f, 0.0f);
    foot.axis = Vec3(0, 0, 1);
    foot.u = Vec3(1, 0, 0);
    foot.stations = scaled({{-0.03f, 0.040f, 0.045f, 0.045f},
                            {0.05f, 0.045f, 0.045f, 0.045f},
                            {0.13f, 0.045f, 0.030f, 0.030f},
                            {0.20f, 0.040f, 0.025f, 0.025f}});
    foot.cap_start = 0.03f * s;
    foot.cap_end = 0.03f * s;
    foot.segments = 12 * detail;
    foot.body_rings = 6 * detail;
    foot.cap_rings = 2 * detail;
    foot.bones = scaled_chain({{sj("foot"), sj("toe")}, {0.0f, 0.13f}, {0.0f, 0.03f}});
    foot.materials = {{9.0f, kShoes}};
    builder.add_tube(foot);
  }
  builder.compute_normals();
}

// ------------------------------------------------------------------- clips

Quat axis_angle(float radians, const Vec3& axis) { return glm::angleAxis(radians, axis); }
Quat rot_x(float radians) { return axis_angle(radians, Vec3(1, 0, 0)); }
Quat rot_y(float radians) { return axis_angle(radians, Vec3(0, 1, 0)); }
Quat rot_z(float radians) { return axis_angle(radians, Vec3(0, 0, 1)); }
// Matches RotationOrder::kXYZ: delta = Rx * Ry * Rz.
Quat euler_xyz(float x, float y, float z) { return rot_x(x) * rot_y(y) * rot_z(z); }

// Samples functions of time into linear key tracks at kKeyRate. Loop clips
// copy their first key onto the last so playback wraps without a pop.
class ClipBuilder {
 public:
  ClipBuilder(const anim::Skeleton& skeleton, std::string name, float duration, bool loop)
      : _skeleton(skeleton), _duration(duration), _loop(loop) {
    _raw.name = std::move(name);
    _intervals = std::max(1, static_cast<int>(std::lround(duration * kKeyRate)));
  }

  void rotation(const char* joint, const std::function<Quat(float)>& f) {
    anim::JointTracks& tracks = track_for(joint);
    tracks.rotation.interpolation = anim::Interpolation::kLinear;
    for (int k = 0; k <= _intervals; ++k) {
      const float t = time_of(k);
      tracks.rotation.times.push_back(t);
      tracks.rotation.values.push_back(_loop && k == _intervals ? tracks.rotation.values.front()
                                                                 : glm::normalize(f(t)));
    }
  }

  // An offset added to the joint's rest translation.
  void translation(const char* joint, const std::function<Vec3(float)>& f) {
    anim::JointTracks& tracks = track_for(joint);
    const Vec3 rest = _skeleton.rest_pose()[static_cast<std::size_t>(tracks.joint)].translation;
    tracks.translation.interpolation = anim::Interpolation::kLinear;
    for (int k = 0; k <= _intervals; ++k) {
      const float t = time_of(k);
      tracks.translation.times.push_back(t);
      tracks.translation.values.push_back(
          _loop && k == _intervals ? tracks.translation.values.front() : rest + f(t));
    }
  }

  Expected<anim::Clip> build() { return anim::Clip::build(std::move(_raw), _skeleton, kSourceName); }

 private:
  float time_of(int k) const {
    return _duration * static_cast<float>(k) / static_cast<float>(_intervals);
  }

  anim::JointTracks& track_for(const char* joint) {
    const int index = *_skeleton.find(joint);
    for (anim::JointTracks& t : _raw.tracks) {
      if (t.joint == index) return t;
    }
    _raw.tracks.push_back({});
    _raw.tracks.back().joint = index;
    return _raw.tracks.back();
  }

  const anim::Skeleton& _skeleton;
  anim::RawClip _raw;
  float _duration;
  bool _loop;
  int _intervals = 1;
};

// Arms hang from the T-pose by rotating the upper arm about Z; `forward`
// then swings the hanging arm towards +Z about the shoulder's X axis.
// side = +1 for the left arm (+X), -1 for the right.
Quat hanging_arm(float side, float down_deg, float forward_deg) {
  return rot_x(-deg(forward_deg)) * rot_z(-side * deg(down_deg));
}
// Elbow flexion brings the forearm forward: about local Y, sign by side.
Quat elbow(float side, float flex_deg) { return rot_y(-side * deg(flex_deg)); }
// Thigh: positive swings the leg forward. Knee: positive flexes backwards.
Quat thigh(float forward_deg) { return rot_x(-deg(forward_deg)); }
Quat knee(float flex_deg) { return rot_x(deg(flex_deg)); }

// Locomotion cycle shared by walk and run, parameterised by amplitudes.
struct GaitParams {
  float duration;
  float thigh_swing;    // degrees either side
  float knee_base;      // degrees of flexion at stance
  float knee_swing;     // extra flexion during the swing phase
  float ankle_swing;    // degrees
  float arm_down;       // upper arm angle below horizontal
  float arm_swing;      // degrees either side
  float elbow_base;     // degrees
  float elbow_swing;    // extra flexion when the arm is forward
  float spine_lean;     // forward lean, degrees
  float chest_twist;    // degrees either side (counter-rotation)
  float pelvis_twist;   // degrees either side
  float bob;            // metres of vertical pelvis motion
};

Expected<anim::Clip> make_gait(const anim::Skeleton& sk, const char* name, const GaitParams& p,
                               float scale) {
  ClipBuilder b(sk, name, p.duration, true);
  const float w = 2.0f * kPi / p.duration;
  // Left leg forward when sin(phase) > 0; the swing (lifted) phase of a leg
  // is when it is moving forward, i.e. cos(phase) > 0 for the left leg.
  const auto leg = [&](float sign) {
    return [&p, w, sign](float t) { return thigh(sign * p.thigh_swing * std::sin(w * t)); };
  };
  const auto knee_of = [&](float sign) {
    return [&p, w, sign](float t) {
      const float lift = std::max(0.0f, sign * std::cos(w * t));
      return knee(p.knee_base + p.knee_swing * lift * lift);
    };
  };
  const auto ankle_of = [&](float sign) {
    return [&p, w, sign](float t) {
      return euler_xyz(deg(p.ankle_swing) * sign * std::cos(w * t), 0.0f, 0.0f);
    };
  };
  b.rotation("thigh_l", leg(1.0f));
  b.rotation("thigh_r", leg(-1.0f));
  b.rotation("calf_l", knee_of(1.0f));
  b.rotation("calf_r", knee_of(-1.0f));
  b.rotation("foot_l", ankle_of(1.0f));
  b.rotation("foot_r", ankle_of(-1.0f));
  // Arms swing opposite to the legs on their side.
  for (const float side : {1.0f, -1.0f}) {
    const char* upper = side > 0 ? "upperarm_l" : "upperarm_r";
    const char* lower = side > 0 ? "lowerarm_l" : "lowerarm_r";
    b.rotation(upper, [&p, w, side](float t) {
      return hanging_arm(side, p.arm_down, -side * p.arm_swing * std::sin(w * t));
    });
    b.rotation(lower, [&p, w, side](float t) {
      const float forward = std::max(0.0f, -side * std::sin(w * t));
      return elbow(side, p.elbow_base + p.elbow_swing * forward);
    });
  }
  b.rotation("pelvis", [&p, w](float t) { return rot_y(deg(p.pelvis_twist) * std::sin(w * t)); });
  b.rotation("spine", [&p](float) { return euler_xyz(deg(p.spine_lean), 0.0f, 0.0f); });
  b.rotation("chest", [&p, w](float t) {
    return euler_xyz(0.0f, -deg(p.chest_twist) * std::sin(w * t), 0.0f);
  });
  // The pelvis is lowest when the legs are furthest apart (twice per cycle).
  b.translation("pelvis", [&p, w, scale](float t) {
    return Vec3(0.0f, -p.bob * scale * (0.5f - 0.5f * std::cos(2.0f * w * t)), 0.0f);
  });
  return b.build();
}

Expected<anim::Clip> make_idle(const anim::Skeleton& sk) {
  constexpr float kDuration = 3.0f;
  ClipBuilder b(sk, "idle", kDuration, true);
  const float w = 2.0f * kPi / kDuration;
  // Breathing lifts the chest; a slow sway shifts weight side to side.
  b.rotation("spine", [w](float t) { return euler_xyz(0.0f, 0.0f, deg(1.5f) * std::sin(w * t)); });
  b.rotation("chest", [w](float t) {
    return euler_xyz(-deg(2.0f) * std::sin(2.0f * w * t), 0.0f, -deg(1.0f) * std::sin(w * t));
  });
  b.rotation("neck", [w](float t) { return euler_xyz(deg(2.0f) * std::sin(w * t + 1.0f), 0.0f, 0.0f); });
  b.rotation("head", [w](float t) { return euler_xyz(0.0f, deg(6.0f) * std::sin(w * t), 0.0f); });
  for (const float side : {1.0f, -1.0f}) {
    const bool left = side > 0;
    b.rotation(left ? "clavicle_l" : "clavicle_r",
               [w, side](float t) { return euler_xyz(0.0f, 0.0f, side * deg(1.5f) * std::sin(2.0f * w * t)); });
    b.rotation(left ? "upperarm_l" : "upperarm_r",
               [w, side](float t) { return hanging_arm(side, 75.0f, 3.0f * std::sin(w * t)); });
    b.rotation(left ? "lowerarm_l" : "lowerarm_r",
               [w, side](float t) { return elbow(side, 12.0f + 3.0f * std::sin(w * t)); });
    b.rotation(left ? "thigh_l" : "thigh_r", [w, side](float t) {
      return thigh(0.0f) * rot_z(side * deg(1.5f) * std::sin(w * t));
    });
  }
  return b.build();
}

// One-shot envelope: 0 before t0, eases to 1 by t1, holds, eases back to 0
// between t2 and t3.
float envelope(float t, float t0, float t1, float t2, float t3) {
  if (t <= t1) return smoothstep01((t - t0) / (t1 - t0));
  if (t <= t2) return 1.0f;
  return 1.0f - smoothstep01((t - t2) / (t3 - t2));
}

Expected<anim::Clip> make_wave(const anim::Skeleton& sk) {
  constexpr float kDuration = 2.6f;
  ClipBuilder b(sk, "wave", kDuration, false);
  const auto up = [](float t) { return envelope(t, 0.0f, 0.5f, 2.1f, 2.6f); };
  // The right upper arm lifts a little above horizontal and twists 75
  // degrees about its own axis, so the elbow hinge bends the forearm up;
  // waving swings the forearm about that hinge.
  b.rotation("clavicle_r", [up](float t) { return euler_xyz(0.0f, 0.0f, -deg(8.0f) * up(t)); });
  b.rotation("upperarm_r", [up](float t) {
    const float e = up(t);
    return rot_z(-deg(15.0f) * e) * rot_x(-deg(75.0f) * e);
  });
  b.rotation("lowerarm_r", [up](float t) {
    const float e = up(t);
    const float wave = t > 0.5f && t < 2.1f ? std::sin((t - 0.5f) * 2.0f * kPi * 1.875f) : 0.0f;
    return elbow(-1.0f, e * (95.0f + 25.0f * wave));
  });
  b.rotation("hand_r", [up](float t) {
    const float wave = t > 0.5f && t < 2.1f ? std::sin((t - 0.5f) * 2.0f * kPi * 1.875f) : 0.0f;
    return euler_xyz(0.0f, deg(15.0f) * wave * up(t), 0.0f);
  });
  b.rotation("chest", [up](float t) { return euler_xyz(0.0f, 0.0f, deg(4.0f) * up(t)); });
  b.rotation("head", [up](float t) { return euler_xyz(deg(5.0f) * up(t), -deg(15.0f) * up(t), 0.0f); });
  return b.build();
}

Expected<anim::Clip> make_kick(const anim::Skeleton& sk) {
  constexpr float kDuration = 1.2f;
  ClipBuilder b(sk, "kick", kDuration, false);
  // Wind-up (thigh back, knee bent), strike (thigh up, knee straight), hold,
  // recover to the rest pose.
  const auto piecewise = [](float t, std::initializer_list<std::pair<float, float>> keys) {
    const auto* prev = keys.begin();
    if (t <= prev->first) return prev->second;
    for (const auto* k = keys.begin() + 1; k != keys.end(); ++k) {
      if (t <= k->first) {
        const float x = smoothstep01((t - prev->first) / (k->first - prev->first));
        return prev->second + (k->second - prev->second) * x;
      }
      prev = k;
    }
    return prev->second;
  };
  b.rotation("thigh_r", [piecewise](float t) {
    return thigh(piecewise(t, {{0.0f, 0.0f}, {0.35f, -20.0f}, {0.6f, 75.0f}, {0.75f, 70.0f}, {1.2f, 0.0f}}));
  });
  b.rotation("calf_r", [piecewise](float t) {
    return knee(piecewise(t, {{0.0f, 0.0f}, {0.35f, 80.0f}, {0.6f, 5.0f}, {0.75f, 10.0f}, {1.2f, 0.0f}}));
  });
  b.rotation("foot_r", [piecewise](float t) {
    return euler_xyz(deg(piecewise(t, {{0.0f, 0.0f}, {0.35f, 15.0f}, {0.6f, 25.0f}, {1.2f, 0.0f}})), 0.0f, 0.0f);
  });
  b.rotation("spine", [piecewise](float t) {
    return euler_xyz(deg(piecewise(t, {{0.0f, 0.0f}, {0.35f, 5.0f}, {0.6f, -12.0f}, {0.75f, -12.0f}, {1.2f, 0.0f}})),
                     0.0f, 0.0f);
  });
  for (const float side : {1.0f, -1.0f}) {
    b.rotation(side > 0 ? "upperarm_l" : "upperarm_r", [piecewise, side](float t) {
      return hanging_arm(side, piecewise(t, {{0.0f, 0.0f}, {0.35f, 45.0f}, {0.75f, 45.0f}, {1.2f, 0.0f}}), 0.0f);
    });
  }
  return b.build();
}

}  // namespace

Expected<character::Model> make_mannequin(const MannequinOptions& options) {
  if (options.detail < 1 || options.detail > 16) {
    return invalid_argument("detail", std::to_string(options.detail), "must be in [1, 16]");
  }
  if (!std::isfinite(options.height) || options.height <= 0.0f) {
    return invalid_argument("height", std::to_string(options.height),
                            "must be a finite positive number of metres");
  }
  const float scale = options.height / kDesignHeight;
  character::Model model;
  model.source = kSourceName;
  SINEW_ASSIGN_OR_RETURN(model.skeleton, build_skeleton(scale));
  build_mesh(model.skeleton, scale, options.detail, model.mesh);
  model.material_names = {"skin", "shirt", "trousers", "shoes"};

  const GaitParams walk{1.0f, 25.0f, 5.0f, 45.0f, 12.0f, 75.0f, 20.0f, 10.0f, 15.0f,
                        3.0f, 5.0f, 5.0f, 0.03f};
  const GaitParams run{0.7f, 40.0f, 15.0f, 80.0f, 20.0f, 70.0f, 35.0f, 75.0f, 20.0f,
                       10.0f, 10.0f, 8.0f, 0.06f};
  SINEW_ASSIGN_OR_RETURN(anim::Clip idle, make_idle(model.skeleton));
  SINEW_ASSIGN_OR_RETURN(anim::Clip walk_clip, make_gait(model.skeleton, "walk", walk, scale));
  SINEW_ASSIGN_OR_RETURN(anim::Clip run_clip, make_gait(model.skeleton, "run", run, scale));
  SINEW_ASSIGN_OR_RETURN(anim::Clip wave, make_wave(model.skeleton));
  SINEW_ASSIGN_OR_RETURN(anim::Clip kick, make_kick(model.skeleton));
  model.clips = {std::move(idle), std::move(walk_clip), std::move(run_clip), std::move(wave),
                 std::move(kick)};
  return model;
}

anim::JointLimits mannequin_joint_limits(const anim::Skeleton& skeleton) {
  anim::JointLimits limits(skeleton.joint_count());
  const auto euler = [&](const std::string& name, Vec3 min_deg, Vec3 max_deg) {
    const auto index = skeleton.find(name);
    if (!index) return;
    anim::JointLimit& l = limits[static_cast<std::size_t>(*index)];
    l.kind = anim::LimitKind::kEuler;
    l.euler.order = anim::RotationOrder::kXYZ;
    l.euler.min = min_deg * (kPi / 180.0f);
    l.euler.max = max_deg * (kPi / 180.0f);
  };
  const auto cone = [&](const std::string& name, Vec3 axis, float swing_deg, float twist_min_deg,
                        float twist_max_deg) {
    const auto index = skeleton.find(name);
    if (!index) return;
    anim::JointLimit& l = limits[static_cast<std::size_t>(*index)];
    l.kind = anim::LimitKind::kSwingTwist;
    l.swing_twist.twist_axis = axis;
    l.swing_twist.swing_max_1 = deg(swing_deg);
    l.swing_twist.swing_max_2 = deg(swing_deg);
    l.swing_twist.twist_min = deg(twist_min_deg);
    l.swing_twist.twist_max = deg(twist_max_deg);
  };
  // Spine and head: x = forward/back bend, y = twist, z = side bend.
  euler("spine", {-25, -30, -25}, {40, 30, 25});
  euler("chest", {-20, -25, -20}, {30, 25, 20});
  euler("neck", {-40, -50, -30}, {40, 50, 30});
  euler("head", {-40, -60, -35}, {40, 60, 35});
  for (const float side : {1.0f, -1.0f}) {
    const std::string s = side > 0 ? "_l" : "_r";
    euler("clavicle" + s, {-10, -15, -20}, {10, 15, 20});
    // Shoulders: a wide cone around the arm's axis; the twist range admits
    // the 75-degree twist of the wave.
    cone("upperarm" + s, Vec3(side, 0, 0), 110.0f, -90.0f, 90.0f);
    // Elbows hinge about Y only (a few degrees of slack on the other axes);
    // flexion is -Y on the left arm and +Y on the right.
    if (side > 0) {
      euler("lowerarm" + s, {-3, -150, -3}, {3, 2, 3});
    } else {
      euler("lowerarm" + s, {-3, -2, -3}, {3, 150, 3});
    }
    euler("hand" + s, {-45, -60, -70}, {45, 60, 70});
    cone("thigh" + s, Vec3(0, -1, 0), 100.0f, -45.0f, 45.0f);
    // Knees hinge about X: positive bends the calf backwards.
    euler("calf" + s, {-2, -3, -3}, {150, 3, 3});
    euler("foot" + s, {-45, -20, -25}, {30, 20, 25});
    euler("toe" + s, {-50, -5, -5}, {30, 5, 5});
  }
  return limits;
}

}  // namespace sinew::content
