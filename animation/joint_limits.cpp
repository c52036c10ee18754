// Joint-limit math: Euler decomposition per rotation order, swing-twist
// decomposition, clamping, and validation. The JSON side lives in
// joint_limits_json.cpp.
//
// Everything is computed in double from the float quaternion: near gimbal
// lock the outer Euler angles are ill-conditioned, and double keeps the
// decomposition of an exactly representable float rotation accurate.
#include "animation/joint_limits.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include "animation/skeleton.h"
#include "runtime/core/format_number.h"

namespace sinew::anim {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kTwoPi = 2.0 * kPi;
// Rotations whose limit violation is below this are returned bit-for-bit:
// a quaternion built from in-range angles decomposes a few ulps off them,
// and re-synthesising it would drift an allowed pose every frame.
constexpr float kUnchangedTolerance = 1e-5f;
// float(pi) is slightly larger than pi; a range edge written as +-180
// degrees must still validate.
constexpr double kRangeSlack = 1e-5;
// cos(middle angle) below this is treated as gimbal lock: the first and
// last axes coincide and only their sum (or difference) is determined.
// Treating it as exact lock moves the rotation by at most ~this many radians.
constexpr double kLockEpsilon = 1e-6;

using DQuat = glm::dquat;
using DVec3 = glm::dvec3;
using DVec2 = glm::dvec2;

// Wraps into (-pi, pi].
double wrap_angle(double a) {
  if (!std::isfinite(a)) return 0.0;
  a = std::fmod(a, kTwoPi);
  if (a > kPi) a -= kTwoPi;
  if (a <= -kPi) a += kTwoPi;
  return a;
}

double circular_distance(double a, double b) {
  return std::abs(wrap_angle(a - b));
}

struct ClampedAngle {
  double angle;
  double violation;  // circular distance from the input to `angle`
};

// Clamps an angle to [lo, hi] on the circle: an angle outside the range goes
// to whichever end is nearer around the circle, so 179 degrees against
// [-90, 170] goes to 170 but -179 degrees against [-170, 90] goes to -170
// (and 175 against [-170, 90] also to -170: 15 degrees, not 85).
ClampedAngle clamp_angle(double a, double lo, double hi) {
  if (hi - lo >= kTwoPi - 2.0 * kRangeSlack) return {a, 0.0};
  for (double shift : {0.0, kTwoPi, -kTwoPi}) {
    const double s = a + shift;
    if (s >= lo && s <= hi) return {s, 0.0};
  }
  const double dlo = circular_distance(a, lo);
  const double dhi = circular_distance(a, hi);
  return dlo <= dhi ? ClampedAngle{lo, dlo} : ClampedAngle{hi, dhi};
}

DQuat to_unit_dquat(const Quat& q) {
  DQuat d(static_cast<double>(q.w), static_cast<double>(q.x), static_cast<double>(q.y),
          static_cast<double>(q.z));
  const double n = std::sqrt(d.w * d.w + d.x * d.x + d.y * d.y + d.z * d.z);
  if (!std::isfinite(n) || n < 1e-30) return DQuat(1.0, 0.0, 0.0, 0.0);
  return DQuat(d.w / n, d.x / n, d.y / n, d.z / n);
}

Quat to_float_quat(const DQuat& d, const DQuat& hemisphere) {
  // Same hemisphere as the input so clamping does not flip signs frame to
  // frame (blending and slerp downstream take the short way anyway).
  const double dot = d.w * hemisphere.w + d.x * hemisphere.x + d.y * hemisphere.y + d.z * hemisphere.z;
  const double s = dot < 0.0 ? -1.0 : 1.0;
  return Quat(static_cast<float>(s * d.w), static_cast<float>(s * d.x), static_cast<float>(s * d.y),
              static_cast<float>(s * d.z));
}

DVec3 unit_axis(int i) {
  DVec3 e(0.0);
  e[i] = 1.0;
  return e;
}

DQuat axis_angle(const DVec3& axis, double angle) {
  const double h = 0.5 * angle;
  const double s = std::sin(h);
  return DQuat(std::cos(h), axis.x * s, axis.y * s, axis.z * s);
}

// The rotation angle of a unit quaternion's rotation, in [0, pi].
double rotation_angle(const DQuat& q) {
  const double v = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z);
  return 2.0 * std::atan2(v, std::abs(q.w));
}

// ---- Euler ------------------------------------------------------------------

struct OrderInfo {
  std::array<int, 3> axes;  // first, middle, last axis index (0 = x)
  bool odd;                 // odd permutation of xyz: a left-handed relabelling
};

OrderInfo order_info(RotationOrder order) {
  switch (order) {
    case RotationOrder::kXYZ: return {{0, 1, 2}, false};
    case RotationOrder::kYZX: return {{1, 2, 0}, false};
    case RotationOrder::kZXY: return {{2, 0, 1}, false};
    case RotationOrder::kXZY: return {{0, 2, 1}, true};
    case RotationOrder::kYXZ: return {{1, 0, 2}, true};
    case RotationOrder::kZYX: return {{2, 1, 0}, true};
  }
  return {{0, 1, 2}, false};
}

struct Decomposition {
  std::array<double, 3> angle;  // by position in the order
  bool locked = false;
  int lock_sign = 1;  // at lock: +1 means first + last is fixed, -1 last - first
};

// delta = R_a(angle[0]) * R_b(angle[1]) * R_c(angle[2]). The matrix is
// relabelled so the order reads as xyz; for an odd order that relabelling is
// a reflection, which negates every angle, so the xyz formulas still apply.
Decomposition decompose_euler(const DQuat& q, const OrderInfo& info) {
  const double w = q.w, x = q.x, y = q.y, z = q.z;
  const double m[3][3] = {
      {1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y)},
      {2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x)},
      {2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y)},
  };
  double p[3][3];
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) p[r][c] = m[info.axes[r]][info.axes[c]];
  }
  // Rx(a) Ry(b) Rz(c): p02 = sin b, p12 = -sin a cos b, p22 = cos a cos b,
  // p01 = -cos b sin c, p00 = cos b cos c.
  Decomposition d;
  const double sb = std::clamp(p[0][2], -1.0, 1.0);
  const double cb = std::hypot(p[0][0], p[0][1]);
  double a = 0.0, b = std::atan2(sb, cb), c = 0.0;
  if (cb < kLockEpsilon) {
    // At lock p10 = sin(a + c) when sin b = 1 and sin(c - a) when sin b =
    // -1; pick a = 0 and let the limit fit choose the split.
    d.locked = true;
    d.lock_sign = sb > 0.0 ? 1 : -1;
    b = sb > 0.0 ? kPi / 2.0 : -kPi / 2.0;
    c = std::atan2(p[1][0], p[1][1]);
  } else {
    a = std::atan2(-p[1][2], p[2][2]);
    c = std::atan2(-p[0][1], p[0][0]);
  }
  if (info.odd) {
    a = -a;
    b = -b;
    c = -c;
  }
  d.angle = {a, b, c};
  return d;
}

struct EulerFit {
  std::array<double, 3> angle{};
  double total = 0.0;  // sum of per-axis violations
  double worst = 0.0;  // largest per-axis violation
};

EulerFit fit_free(const std::array<double, 3>& angle, const std::array<double, 3>& lo,
                  const std::array<double, 3>& hi) {
  EulerFit f;
  for (int i = 0; i < 3; ++i) {
    const ClampedAngle c = clamp_angle(angle[i], lo[i], hi[i]);
    f.angle[i] = c.angle;
    f.total += c.violation;
    f.worst = std::max(f.worst, c.violation);
  }
  return f;
}

// At gimbal lock only s = first + last (lock_sign +1) or s = last - first
// (-1) is determined, modulo 2 pi. Any split with the same s is the same
// rotation, so pick one inside both ranges when one exists, else the end of
// the feasible interval of s nearest around the circle.
EulerFit fit_locked(const Decomposition& d, const std::array<double, 3>& lo,
                    const std::array<double, 3>& hi) {
  EulerFit f;
  const ClampedAngle mid = clamp_angle(d.angle[1], lo[1], hi[1]);
  // With first' = lock_sign * first the relation is always first' + last = s.
  const double lo0 = d.lock_sign > 0 ? lo[0] : -hi[0];
  const double hi0 = d.lock_sign > 0 ? hi[0] : -lo[0];
  const double s0 = d.lock_sign > 0 ? d.angle[0] + d.angle[2] : d.angle[2] - d.angle[0];
  const double low = lo0 + lo[2];
  const double high = hi0 + hi[2];
  // Smallest representative of s0 that is >= low.
  const double s_up = s0 + kTwoPi * std::ceil((low - s0) / kTwoPi);
  double s = s_up;
  double violation = 0.0;
  if (s_up > high) {
    const double above = s_up - high;
    const double below = low - (s_up - kTwoPi);
    if (above <= below) {
      s = high;
      violation = above;
    } else {
      s = low;
      violation = below;
    }
  }
  const double first_p = std::clamp(s - 0.5 * (lo[2] + hi[2]), lo0, hi0);
  const double last = std::clamp(s - first_p, lo[2], hi[2]);
  f.angle = {d.lock_sign > 0 ? first_p : -first_p, mid.angle, last};
  f.total = mid.violation + violation;
  f.worst = std::max(mid.violation, violation);
  return f;
}

struct EulerResult {
  EulerFit fit;
  OrderInfo info;
};

EulerResult fit_euler(const EulerLimit& limit, const DQuat& q) {
  const OrderInfo info = order_info(limit.order);
  std::array<double, 3> lo{}, hi{};
  for (int i = 0; i < 3; ++i) {
    lo[i] = static_cast<double>(limit.min[info.axes[i]]);
    hi[i] = static_cast<double>(limit.max[info.axes[i]]);
  }
  const Decomposition d = decompose_euler(q, info);
  if (d.locked) return {fit_locked(d, lo, hi), info};
  // Away from lock every rotation has two decompositions: (a, b, c) and
  // (a + pi, pi - b, c + pi). A middle range wider than +-90 degrees may
  // contain only the second, so fit both and keep the closer.
  const EulerFit f1 = fit_free(d.angle, lo, hi);
  const std::array<double, 3> alt = {wrap_angle(d.angle[0] + kPi), wrap_angle(kPi - d.angle[1]),
                                     wrap_angle(d.angle[2] + kPi)};
  const EulerFit f2 = fit_free(alt, lo, hi);
  return {f2.total < f1.total ? f2 : f1, info};
}

DQuat compose_euler(const std::array<double, 3>& angle, const OrderInfo& info) {
  return axis_angle(unit_axis(info.axes[0]), angle[0]) * axis_angle(unit_axis(info.axes[1]), angle[1]) *
         axis_angle(unit_axis(info.axes[2]), angle[2]);
}

// ---- Swing-twist ------------------------------------------------------------

struct SwingTwistParts {
  DVec3 axis{1.0, 0.0, 0.0};
  DVec3 b1{0.0, 1.0, 0.0};
  DVec3 b2{0.0, 0.0, 1.0};
  double twist = 0.0;
  ClampedAngle twist_clamped{0.0, 0.0};
  DVec2 swing{0.0};  // swing vector (axis * angle) in the (b1, b2) basis
};

DVec3 safe_unit(const Vec3& v) {
  DVec3 d(static_cast<double>(v.x), static_cast<double>(v.y), static_cast<double>(v.z));
  const double n = glm::length(d);
  if (!std::isfinite(n) || n < 1e-12) return DVec3(1.0, 0.0, 0.0);
  return d / n;
}

void basis_for(const DVec3& t, DVec3& b1, DVec3& b2) {
  int dominant = 0;
  for (int i = 1; i < 3; ++i) {
    if (std::abs(t[i]) > std::abs(t[dominant])) dominant = i;
  }
  const DVec3 e = unit_axis((dominant + 1) % 3);
  b1 = glm::normalize(e - glm::dot(e, t) * t);
  b2 = glm::cross(t, b1);
}

// Nearest point of the ellipse (x/a)^2 + (y/b)^2 <= 1 to p, Euclidean. A zero
// semi-axis degenerates to a segment (or the origin).
DVec2 project_ellipse(const DVec2& p, double a, double b) {
  if (!(a > 0.0) && !(b > 0.0)) return DVec2(0.0);
  if (!(a > 0.0)) return DVec2(0.0, std::clamp(p.y, -b, b));
  if (!(b > 0.0)) return DVec2(std::clamp(p.x, -a, a), 0.0);
  const double ex = p.x / a, ey = p.y / b;
  if (ex * ex + ey * ey <= 1.0) return p;
  // The nearest point is (a^2 x / (t + a^2), b^2 y / (t + b^2)) for the root
  // t >= 0 of F(t) = (a x / (t + a^2))^2 + (b y / (t + b^2))^2 - 1, which
  // decreases monotonically from F(0) > 0; F(hypot(a x, b y)) <= 0.
  const double x = std::abs(p.x), y = std::abs(p.y);
  const double a2 = a * a, b2 = b * b;
  double t0 = 0.0, t1 = std::hypot(a * x, b * y);
  for (int i = 0; i < 200 && t1 - t0 > 1e-15 * std::max(1.0, t1); ++i) {
    const double t = 0.5 * (t0 + t1);
    const double u = a * x / (t + a2), v = b * y / (t + b2);
    if (u * u + v * v - 1.0 > 0.0) {
      t0 = t;
    } else {
      t1 = t;
    }
  }
  const double t = 0.5 * (t0 + t1);
  DVec2 r(a2 * x / (t + a2), b2 * y / (t + b2));
  // Land exactly on the boundary so is_within of the result never fails by
  // a rounding error.
  const double k = std::sqrt((r.x / a) * (r.x / a) + (r.y / b) * (r.y / b));
  if (k > 1.0) r /= k;
  return DVec2(std::copysign(r.x, p.x), std::copysign(r.y, p.y));
}

DQuat twist_quat(const DVec3& axis, double angle) {
  return axis_angle(axis, angle);
}

SwingTwistParts split_swing_twist(const SwingTwistLimit& limit, const DQuat& q) {
  SwingTwistParts parts;
  parts.axis = safe_unit(limit.twist_axis);
  basis_for(parts.axis, parts.b1, parts.b2);
  const DVec3 v(q.x, q.y, q.z);
  const double proj = glm::dot(v, parts.axis);
  const double lo = static_cast<double>(limit.twist_min);
  const double hi = static_cast<double>(limit.twist_max);
  if (q.w * q.w + proj * proj < 1e-24) {
    // A half-turn swing: any twist fits (the swing axis turns with it), so
    // take the allowed twist nearest to none.
    parts.twist_clamped = clamp_angle(0.0, lo, hi);
    parts.twist = parts.twist_clamped.angle;
    parts.twist_clamped.violation = 0.0;
  } else {
    parts.twist = wrap_angle(2.0 * std::atan2(proj, q.w));
    parts.twist_clamped = clamp_angle(parts.twist, lo, hi);
  }
  DQuat swing = q * glm::conjugate(twist_quat(parts.axis, parts.twist));
  if (swing.w < 0.0) swing = -swing;
  const DVec3 sv(swing.x, swing.y, swing.z);
  const double sn = glm::length(sv);
  if (sn > 0.0) {
    const double angle = 2.0 * std::atan2(sn, swing.w);
    parts.swing = DVec2(glm::dot(sv, parts.b1), glm::dot(sv, parts.b2)) * (angle / sn);
  }
  return parts;
}

DQuat swing_quat(const SwingTwistParts& parts, const DVec2& s) {
  const double angle = glm::length(s);
  if (angle <= 0.0) return DQuat(1.0, 0.0, 0.0, 0.0);
  const DVec3 axis = (s.x * parts.b1 + s.y * parts.b2) / angle;
  return axis_angle(axis, angle);
}

// For a fixed swing S the best twist is analytic: |<S^-1 q, T(theta)>| is
// |A cos(theta/2 - c)|, unimodal on the circle, so the circularly clamped
// twist of S^-1 q maximises it. Returns that |dot| (cos of half the
// distance) and the twist.
double best_twist_for_swing(const DQuat& swing, const DQuat& q, const DVec3& axis, double lo, double hi,
                            double& theta) {
  const DQuat r = glm::conjugate(swing) * q;
  const double p = r.x * axis.x + r.y * axis.y + r.z * axis.z;
  const double twist = r.w * r.w + p * p < 1e-30 ? 0.0 : wrap_angle(2.0 * std::atan2(p, r.w));
  theta = clamp_angle(twist, lo, hi).angle;
  return std::abs(r.w * std::cos(0.5 * theta) + p * std::sin(0.5 * theta));
}

// The allowed rotation nearest to q in rotation angle. Clamping swing and
// twist separately is only exact when one of them is in range; with both
// out (or a swing near a half turn, where the twist is ill-defined) the
// nearest allowed rotation can have a quite different swing direction. So:
// the twist is solved exactly per swing, and the swing (ellipse coordinates
// rho in [0, 1], angle alpha) by a coarse grid plus the separate projection
// as candidates, refined by a shrinking pattern search (to ~1e-7 rad, float
// precision). A few hundred quaternion products, paid only by rotations
// outside their limits.
DQuat nearest_swing_twist(const SwingTwistLimit& st, const SwingTwistParts& parts, const DQuat& q,
                          const DVec2& projected) {
  const double m1 = std::max(0.0, static_cast<double>(st.swing_max_1));
  const double m2 = std::max(0.0, static_cast<double>(st.swing_max_2));
  const double lo = static_cast<double>(st.twist_min), hi = static_cast<double>(st.twist_max);
  const auto swing_at = [&](double rho, double alpha) {
    return swing_quat(parts, DVec2(m1 * rho * std::cos(alpha), m2 * rho * std::sin(alpha)));
  };
  double best_rho = 0.0, best_alpha = 0.0, best_theta = 0.0;
  double best = -1.0;
  const auto consider = [&](double rho, double alpha) {
    double theta = 0.0;
    const double score = best_twist_for_swing(swing_at(rho, alpha), q, parts.axis, lo, hi, theta);
    if (score > best) {
      best = score;
      best_rho = rho;
      best_alpha = alpha;
      best_theta = theta;
      return true;
    }
    return false;
  };
  // The separate projection first: on ties it wins, which keeps the simple
  // answer whenever it is the nearest.
  {
    const double e1 = m1 > 0.0 ? projected.x / m1 : 0.0, e2 = m2 > 0.0 ? projected.y / m2 : 0.0;
    consider(std::min(1.0, std::hypot(e1, e2)), std::atan2(e2, e1));
  }
  if (m1 > 0.0 || m2 > 0.0) {
    constexpr int kRings = 6, kSpokes = 24;
    for (int i = 1; i <= kRings; ++i) {
      for (int k = 0; k < kSpokes; ++k) consider(static_cast<double>(i) / kRings, kTwoPi * k / kSpokes);
    }
    consider(0.0, 0.0);
    double step_rho = 0.5 / kRings, step_alpha = kPi / kSpokes;
    for (int iter = 0; iter < 200 && step_alpha > 1e-7; ++iter) {
      const double r0 = best_rho, a0 = best_alpha;
      bool moved = false;
      moved = consider(std::min(1.0, r0 + step_rho), a0) || moved;
      moved = consider(std::max(0.0, r0 - step_rho), a0) || moved;
      moved = consider(r0, a0 + step_alpha) || moved;
      moved = consider(r0, a0 - step_alpha) || moved;
      if (!moved) {
        step_rho *= 0.5;
        step_alpha *= 0.5;
      }
    }
  }
  return swing_at(best_rho, best_alpha) * twist_quat(parts.axis, best_theta);
}

// Near a half-turn swing the twist is ill-conditioned: it is
// 2 atan2(proj, w) with both arguments (cos of half the swing angle) near
// zero, so the 6e-8 rounding of a float quaternion moves it by about
// 6e-8 / hypot(w, proj) and the swing turns with it. Inside this band
// (swing within ~1.1 degrees of a half turn) the separate swing and twist
// violations can call an allowed rotation far outside, so the true distance
// to the allowed set decides instead. Outside the band the rounding error
// stays below ~1e-5 rad, the unchanged-tolerance.
constexpr double kHalfTurnBand = 1e-2;

bool near_half_turn(const SwingTwistParts& parts, const DQuat& q) {
  const double proj = q.x * parts.axis.x + q.y * parts.axis.y + q.z * parts.axis.z;
  return q.w * q.w + proj * proj < kHalfTurnBand * kHalfTurnBand;
}

// How far q lies outside a swing-twist limit, with the allowed rotation
// nearest to it when that had to be found (left untouched otherwise).
// Away from the half-turn band: the larger of the twist's violation and the
// swing vector's distance from the ellipse. In the band: the smaller of that
// and the rotation angle to the nearest allowed rotation.
struct SwingTwistViolation {
  double amount = 0.0;
  bool has_nearest = false;
  DQuat nearest{1.0, 0.0, 0.0, 0.0};
};

SwingTwistViolation swing_twist_violation(const SwingTwistLimit& st, const DQuat& q) {
  const SwingTwistParts parts = split_swing_twist(st, q);
  const DVec2 s =
      project_ellipse(parts.swing, static_cast<double>(st.swing_max_1), static_cast<double>(st.swing_max_2));
  SwingTwistViolation v;
  v.amount = std::max(parts.twist_clamped.violation, glm::length(s - parts.swing));
  if (v.amount == 0.0 || !near_half_turn(parts, q)) return v;
  v.nearest = nearest_swing_twist(st, parts, q, s);
  v.has_nearest = true;
  v.amount = std::min(v.amount, rotation_angle(glm::conjugate(v.nearest) * q));
  return v;
}

bool valid_quat(const Quat& q) {
  return std::isfinite(q.w) && std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z);
}

}  // namespace

void swing_twist_basis(const Vec3& twist_axis, Vec3& axis_1, Vec3& axis_2) {
  DVec3 b1, b2;
  basis_for(safe_unit(twist_axis), b1, b2);
  axis_1 = Vec3(b1);
  axis_2 = Vec3(b2);
}

EulerAngles decompose_euler(RotationOrder order, const Quat& delta) {
  const OrderInfo info = order_info(order);
  const Decomposition d = decompose_euler(to_unit_dquat(delta), info);
  EulerAngles out;
  for (int i = 0; i < 3; ++i) out.angles[info.axes[i]] = static_cast<float>(d.angle[i]);
  out.gimbal_locked = d.locked;
  return out;
}

Quat compose_euler(RotationOrder order, const Vec3& angles) {
  const OrderInfo info = order_info(order);
  std::array<double, 3> a{};
  for (int i = 0; i < 3; ++i) a[i] = static_cast<double>(angles[info.axes[i]]);
  const DQuat q = compose_euler(a, info);
  return to_float_quat(q, DQuat(1.0, 0.0, 0.0, 0.0));
}

SwingTwistAngles decompose_swing_twist(const Vec3& twist_axis, const Quat& delta) {
  SwingTwistLimit l;
  l.twist_axis = twist_axis;
  l.twist_min = -3.14159265f;
  l.twist_max = 3.14159265f;
  const SwingTwistParts parts = split_swing_twist(l, to_unit_dquat(delta));
  return {Vec2(static_cast<float>(parts.swing.x), static_cast<float>(parts.swing.y)),
          static_cast<float>(parts.twist)};
}

Quat compose_swing_twist(const Vec3& twist_axis, const Vec2& swing, float twist) {
  SwingTwistParts parts;
  parts.axis = safe_unit(twist_axis);
  basis_for(parts.axis, parts.b1, parts.b2);
  const DQuat q = swing_quat(parts, DVec2(static_cast<double>(swing.x), static_cast<double>(swing.y))) *
                  twist_quat(parts.axis, static_cast<double>(twist));
  return to_float_quat(q, DQuat(1.0, 0.0, 0.0, 0.0));
}

float rotation_distance(const Quat& a, const Quat& b) {
  const DQuat r = glm::conjugate(to_unit_dquat(a)) * to_unit_dquat(b);
  return static_cast<float>(rotation_angle(r));
}

Quat clamp_rotation(const JointLimit& limit, const Quat& delta) {
  if (limit.kind == LimitKind::kFree) return delta;
  // Garbage in (NaN, zero quaternion) is treated as no rotation, then clamped.
  const Quat in = valid_quat(delta) ? delta : Quat(1.0f, 0.0f, 0.0f, 0.0f);
  const DQuat q = to_unit_dquat(in);
  if (limit.kind == LimitKind::kEuler) {
    const EulerResult r = fit_euler(limit.euler, q);
    if (r.fit.worst <= static_cast<double>(kUnchangedTolerance) && valid_quat(delta)) return delta;
    return to_float_quat(compose_euler(r.fit.angle, r.info), q);
  }
  const SwingTwistLimit& st = limit.swing_twist;
  const SwingTwistViolation v = swing_twist_violation(st, q);
  if (v.amount <= static_cast<double>(kUnchangedTolerance) && valid_quat(delta)) return delta;
  if (v.has_nearest) return to_float_quat(v.nearest, q);
  const SwingTwistParts parts = split_swing_twist(st, q);
  const DVec2 s =
      project_ellipse(parts.swing, static_cast<double>(st.swing_max_1), static_cast<double>(st.swing_max_2));
  return to_float_quat(nearest_swing_twist(st, parts, q, s), q);
}

bool is_within(const JointLimit& limit, const Quat& delta, float tolerance_radians) {
  if (limit.kind == LimitKind::kFree) return true;
  if (!valid_quat(delta)) return false;
  const DQuat q = to_unit_dquat(delta);
  const double tol = static_cast<double>(tolerance_radians);
  if (limit.kind == LimitKind::kEuler) {
    const OrderInfo info = order_info(limit.euler.order);
    std::array<double, 3> lo{}, hi{};
    for (int i = 0; i < 3; ++i) {
      lo[i] = static_cast<double>(limit.euler.min[info.axes[i]]);
      hi[i] = static_cast<double>(limit.euler.max[info.axes[i]]);
    }
    const Decomposition d = decompose_euler(q, info);
    if (d.locked) return fit_locked(d, lo, hi).worst <= tol;
    const std::array<double, 3> alt = {wrap_angle(d.angle[0] + kPi), wrap_angle(kPi - d.angle[1]),
                                       wrap_angle(d.angle[2] + kPi)};
    return fit_free(d.angle, lo, hi).worst <= tol || fit_free(alt, lo, hi).worst <= tol;
  }
  return swing_twist_violation(limit.swing_twist, q).amount <= tol;
}

Status apply_joint_limits(const Skeleton& skeleton, std::span<const JointLimit> limits,
                          std::span<JointTransform> local) {
  const std::size_t n = skeleton.joint_count();
  if (limits.size() != n) {
    return invalid_argument("limits.size", std::to_string(limits.size()),
                            "expected one limit per joint (" + std::to_string(n) + ")");
  }
  if (local.size() != n) {
    return invalid_argument("local.size", std::to_string(local.size()),
                            "expected one transform per joint (" + std::to_string(n) + ")");
  }
  const auto rest = skeleton.rest_pose();
  for (std::size_t j = 0; j < n; ++j) {
    if (limits[j].kind == LimitKind::kFree) continue;
    const Quat rest_rot = glm::normalize(rest[j].rotation);
    const Quat delta = glm::conjugate(rest_rot) * local[j].rotation;
    // Leave allowed joints untouched: rest * (rest^-1 * local) is not
    // bit-identical to local.
    if (valid_quat(delta) && is_within(limits[j], delta, kUnchangedTolerance)) continue;
    local[j].rotation = rest_rot * clamp_rotation(limits[j], delta);
  }
  return {};
}

Status validate_joint_limits(std::span<const JointLimit> limits, std::string_view source) {
  const double pi_hi = kPi + kRangeSlack;
  auto bad = [&](std::size_t j, const std::string& field, double value, const char* detail) {
    return make_error(ErrorCode::kInvalidData, source, "joints[" + std::to_string(j) + "]." + field,
                      format_number(value), detail);
  };
  static constexpr const char* kAxis[3] = {"x", "y", "z"};
  for (std::size_t j = 0; j < limits.size(); ++j) {
    const JointLimit& l = limits[j];
    if (l.kind == LimitKind::kEuler) {
      if (static_cast<unsigned>(l.euler.order) > static_cast<unsigned>(RotationOrder::kZYX)) {
        return bad(j, "euler.order", static_cast<double>(l.euler.order), "unknown rotation order");
      }
      for (int a = 0; a < 3; ++a) {
        const double lo = static_cast<double>(l.euler.min[a]);
        const double hi = static_cast<double>(l.euler.max[a]);
        const std::string min_field = std::string("euler.min.") + kAxis[a];
        const std::string max_field = std::string("euler.max.") + kAxis[a];
        if (!std::isfinite(lo)) return bad(j, min_field, lo, "not a finite number");
        if (!std::isfinite(hi)) return bad(j, max_field, hi, "not a finite number");
        if (lo < -pi_hi || lo > pi_hi) return bad(j, min_field, lo, "outside [-pi, pi]");
        if (hi < -pi_hi || hi > pi_hi) return bad(j, max_field, hi, "outside [-pi, pi]");
        if (lo > hi) return bad(j, min_field, lo, "greater than max");
      }
    } else if (l.kind == LimitKind::kSwingTwist) {
      const SwingTwistLimit& st = l.swing_twist;
      const double len = static_cast<double>(glm::length(st.twist_axis));
      if (!std::isfinite(len) || std::abs(len - 1.0) > 1e-4) {
        return bad(j, "swing_twist.twist_axis.length", len, "twist axis must be unit length");
      }
      const double s1 = static_cast<double>(st.swing_max_1), s2 = static_cast<double>(st.swing_max_2);
      const double t0 = static_cast<double>(st.twist_min), t1 = static_cast<double>(st.twist_max);
      if (!std::isfinite(s1) || s1 < 0.0 || s1 > pi_hi)
        return bad(j, "swing_twist.swing_max_1", s1, "outside [0, pi]");
      if (!std::isfinite(s2) || s2 < 0.0 || s2 > pi_hi)
        return bad(j, "swing_twist.swing_max_2", s2, "outside [0, pi]");
      if (!std::isfinite(t0) || t0 < -pi_hi || t0 > pi_hi)
        return bad(j, "swing_twist.twist_min", t0, "outside [-pi, pi]");
      if (!std::isfinite(t1) || t1 < -pi_hi || t1 > pi_hi)
        return bad(j, "swing_twist.twist_max", t1, "outside [-pi, pi]");
      if (t0 > t1) return bad(j, "swing_twist.twist_min", t0, "greater than twist_max");
    } else if (l.kind != LimitKind::kFree) {
      return bad(j, "kind", static_cast<double>(l.kind), "unknown limit kind");
    }
  }
  return {};
}

}  // namespace sinew::anim
