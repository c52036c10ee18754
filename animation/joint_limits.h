// Joint limits: the allowed range of each joint's rotation, used to keep
// animated poses plausible and to define the "joint limits" pose space the
// bake samples (paper section 3.3, Table 1).
//
// A limit constrains the rotation RELATIVE TO THE JOINT'S REST ROTATION:
// with local = rest * delta, the limit applies to delta, so an all-zero
// range pins a joint to its rest pose. Angles are radians.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "animation/joint_transform.h"
#include "runtime/core/expected.h"
#include "runtime/math/types.h"

namespace sinew::anim {

class Skeleton;

// The order in which Euler rotations are applied: kXYZ means
// delta = Rx(x) * Ry(y) * Rz(z) (intrinsic x, then y, then z).
enum class RotationOrder : std::uint8_t { kXYZ, kXZY, kYXZ, kYZX, kZXY, kZYX };

struct EulerLimit {
  RotationOrder order = RotationOrder::kXYZ;
  Vec3 min{0.0f};  // per-axis lower bounds, radians, each in [-pi, pi]
  Vec3 max{0.0f};  // per-axis upper bounds, min <= max
};

// Swing-twist: delta = swing * twist, twist about `twist_axis` (the bone
// axis in the joint's rest frame), swing about an axis perpendicular to it.
// The swing is limited to an ellipse of half-angles (swing_max_1 about the
// first perpendicular axis, swing_max_2 about the second): equal values make
// a cone. The twist angle is limited to [twist_min, twist_max].
struct SwingTwistLimit {
  Vec3 twist_axis{1.0f, 0.0f, 0.0f};  // unit length
  float swing_max_1 = 0.0f;           // radians, [0, pi]
  float swing_max_2 = 0.0f;           // radians, [0, pi]
  float twist_min = 0.0f;             // radians, [-pi, pi]
  float twist_max = 0.0f;
};

enum class LimitKind : std::uint8_t { kFree, kEuler, kSwingTwist };

struct JointLimit {
  LimitKind kind = LimitKind::kFree;
  EulerLimit euler;
  SwingTwistLimit swing_twist;
};

// One entry per joint of a skeleton (kFree where unconstrained).
using JointLimits = std::vector<JointLimit>;

// The allowed rotation closest to `delta` (for Euler limits: per-axis clamp
// of the decomposed angles, which is what a user editing angles expects, on
// whichever of the two decompositions needs less clamping; at gimbal lock
// the outer angles are split to fit their ranges when possible. For
// swing-twist: the allowed rotation nearest in rotation angle: the twist is
// solved exactly for each candidate swing, and the swing found by a search
// over the ellipse seeded with the plain projection of the swing onto it,
// because projecting swing and twist separately can land far from the
// nearest rotation when both are out of range or the swing nears 180
// degrees). Allowed rotations (within 1e-5 rad) are returned unchanged, bit
// for bit. Non-finite input is treated as the identity.
// is_within's tolerance is per Euler angle, or on the twist angle and the
// swing vector's distance from the ellipse; for a swing within about a
// degree of a half turn, where the twist of a float quaternion is
// ill-conditioned, on the rotation angle to the nearest allowed rotation.
Quat clamp_rotation(const JointLimit& limit, const Quat& delta);
bool is_within(const JointLimit& limit, const Quat& delta, float tolerance_radians = 1e-4f);

// Decomposition helpers, exposed for the editor, the pose-space sampler and
// tests.

// The two axes perpendicular to a twist axis that swing_max_1 and
// swing_max_2 refer to: for the twist axis's dominant component i (x = 0),
// axis_1 is the next coordinate axis (i + 1) mod 3 made perpendicular to the
// twist axis, and axis_2 = cross(twist_axis, axis_1). So twist about x
// swings about y then z; about y: z then x; about z: x then y.
void swing_twist_basis(const Vec3& twist_axis, Vec3& axis_1, Vec3& axis_2);

struct EulerAngles {
  Vec3 angles{0.0f};           // by axis (x, y, z), radians, each in [-pi, pi]
  bool gimbal_locked = false;  // middle angle at +-90 degrees: the outer
                               // angles share one degree of freedom; the
                               // first is then reported as 0
};
// delta = compose_euler(order, decompose_euler(order, delta).angles), with
// the middle angle in [-pi/2, pi/2].
EulerAngles decompose_euler(RotationOrder order, const Quat& delta);
Quat compose_euler(RotationOrder order, const Vec3& angles);

struct SwingTwistAngles {
  Vec2 swing{0.0f};  // swing vector (axis * angle) in the swing_twist_basis, |swing| <= pi
  float twist = 0.0f;  // radians, (-pi, pi]
};
SwingTwistAngles decompose_swing_twist(const Vec3& twist_axis, const Quat& delta);
Quat compose_swing_twist(const Vec3& twist_axis, const Vec2& swing, float twist);

// The angle of the rotation taking a to b, in [0, pi] (sign-insensitive).
float rotation_distance(const Quat& a, const Quat& b);

// Clamps every joint of a local pose in place. Errors: kInvalidArgument on a
// size mismatch.
Status apply_joint_limits(const Skeleton& skeleton, std::span<const JointLimit> limits,
                          std::span<JointTransform> local);

// Validates ranges (finite, min <= max, within [-pi, pi], unit twist axis).
Status validate_joint_limits(std::span<const JointLimit> limits, std::string_view source);

// JSON file (content/limits/<model>.json), joints by name:
//   {"version": 1, "joints": {"upperarm_l": {"type": "euler", "order": "xyz",
//     "min_deg": [-90, -30, -45], "max_deg": [90, 30, 120]},
//    "neck": {"type": "swing_twist", "twist_axis": [0, 1, 0],
//     "swing_deg": [40, 30], "twist_deg": [-60, 60]}}}
// Joints not named are free; unknown joint names are an error naming them.
Expected<JointLimits> load_joint_limits(const std::string& path, const Skeleton& skeleton);
Expected<JointLimits> parse_joint_limits(std::string_view json, const Skeleton& skeleton,
                                         std::string_view source);
std::string joint_limits_to_json(std::span<const JointLimit> limits, const Skeleton& skeleton);
Status save_joint_limits(const std::string& path, std::span<const JointLimit> limits,
                         const Skeleton& skeleton);  // atomic write

}  // namespace sinew::anim
