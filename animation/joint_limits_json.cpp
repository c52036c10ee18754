// Joint limits <-> JSON (content/limits/<model>.json). The file is edited by
// hand and by the editor, so it stores degrees and names joints; every
// problem is reported as a Status naming the file and the JSON path of the
// field, and no nlohmann exception escapes.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>

#include "animation/joint_limits.h"
#include "animation/skeleton.h"
#include "runtime/io/atomic_file.h"
#include "runtime/io/json_nesting.h"

namespace sinew::anim {
namespace {

using nlohmann::json;

constexpr double kPi = 3.14159265358979323846;
constexpr double kRadPerDeg = kPi / 180.0;
constexpr int kVersion = 1;
// The format nests four levels (root, joints, a joint, its euler block).
constexpr std::size_t kMaxNesting = 16;

struct OrderName {
  RotationOrder order;
  const char* name;
};
constexpr OrderName kOrders[] = {
    {RotationOrder::kXYZ, "xyz"}, {RotationOrder::kXZY, "xzy"}, {RotationOrder::kYXZ, "yxz"},
    {RotationOrder::kYZX, "yzx"}, {RotationOrder::kZXY, "zxy"}, {RotationOrder::kZYX, "zyx"},
};

std::string short_dump(const json& j) {
  std::string s = j.dump(-1, ' ', false, json::error_handler_t::replace);
  if (s.size() > 60) s = s.substr(0, 57) + "...";
  return s;
}

class Parser {
 public:
  explicit Parser(std::string_view source) : source_(source) {}

  Status error(const std::string& field, const json& value, std::string_view detail) const {
    return make_error(ErrorCode::kInvalidData, source_, field, short_dump(value), detail);
  }

  // A fixed-size array of finite numbers, converted from degrees.
  template <std::size_t N>
  Status degrees(const json& obj, const std::string& base, const char* key, float (&out)[N]) const {
    const std::string field = base + "." + key;
    const auto it = obj.find(key);
    if (it == obj.end()) return make_error(ErrorCode::kInvalidData, source_, field, "", "missing field");
    SINEW_RETURN_IF_ERROR(numbers(*it, field, out));
    for (float& v : out) v = static_cast<float>(static_cast<double>(v) * kRadPerDeg);
    return {};
  }

  template <std::size_t N>
  Status numbers(const json& value, const std::string& field, float (&out)[N]) const {
    if (!value.is_array() || value.size() != N) {
      return error(field, value, "expected an array of " + std::to_string(N) + " numbers");
    }
    for (std::size_t i = 0; i < N; ++i) {
      const json& e = value[i];
      const std::string f = field + "[" + std::to_string(i) + "]";
      if (!e.is_number()) return error(f, e, "expected a number");
      const double d = e.get<double>();
      if (!std::isfinite(d) || std::abs(d) > 1e6) return error(f, e, "not a finite number in range");
      out[i] = static_cast<float>(d);
    }
    return {};
  }

  Status check_keys(const json& obj, const std::string& base,
                    std::initializer_list<const char*> allowed) const {
    for (auto it = obj.begin(); it != obj.end(); ++it) {
      bool known = false;
      for (const char* a : allowed) known = known || it.key() == a;
      // A typo such as "max_degs" would otherwise silently free the joint.
      if (!known) return error(base + "." + it.key(), it.value(), "unknown field");
    }
    return {};
  }

  Expected<JointLimit> joint(const json& obj, const std::string& base) const {
    if (!obj.is_object()) return error(base, obj, "expected an object");
    const auto type_it = obj.find("type");
    if (type_it == obj.end()) {
      return make_error(ErrorCode::kInvalidData, source_, base + ".type", "", "missing field");
    }
    if (!type_it->is_string()) return error(base + ".type", *type_it, "expected a string");
    const std::string type = type_it->get<std::string>();
    JointLimit limit;
    if (type == "free") {
      SINEW_RETURN_IF_ERROR(check_keys(obj, base, {"type"}));
      return limit;
    }
    if (type == "euler") {
      SINEW_RETURN_IF_ERROR(check_keys(obj, base, {"type", "order", "min_deg", "max_deg"}));
      limit.kind = LimitKind::kEuler;
      const auto order_it = obj.find("order");
      if (order_it == obj.end()) {
        return make_error(ErrorCode::kInvalidData, source_, base + ".order", "", "missing field");
      }
      bool found = false;
      if (order_it->is_string()) {
        const std::string name = order_it->get<std::string>();
        for (const OrderName& o : kOrders) {
          if (name == o.name) {
            limit.euler.order = o.order;
            found = true;
          }
        }
      }
      if (!found) return error(base + ".order", *order_it, "expected one of xyz, xzy, yxz, yzx, zxy, zyx");
      float lo[3], hi[3];
      SINEW_RETURN_IF_ERROR(degrees(obj, base, "min_deg", lo));
      SINEW_RETURN_IF_ERROR(degrees(obj, base, "max_deg", hi));
      limit.euler.min = Vec3(lo[0], lo[1], lo[2]);
      limit.euler.max = Vec3(hi[0], hi[1], hi[2]);
      for (int a = 0; a < 3; ++a) {
        const std::string idx = "[" + std::to_string(a) + "]";
        SINEW_RETURN_IF_ERROR(range_check(obj["min_deg"][a], base + ".min_deg" + idx, -kPi, kPi, lo[a]));
        SINEW_RETURN_IF_ERROR(range_check(obj["max_deg"][a], base + ".max_deg" + idx, -kPi, kPi, hi[a]));
        if (lo[a] > hi[a])
          return error(base + ".min_deg" + idx, obj["min_deg"][a], "greater than max_deg" + idx);
      }
      return limit;
    }
    if (type == "swing_twist") {
      SINEW_RETURN_IF_ERROR(check_keys(obj, base, {"type", "twist_axis", "swing_deg", "twist_deg"}));
      limit.kind = LimitKind::kSwingTwist;
      const auto axis_it = obj.find("twist_axis");
      if (axis_it == obj.end()) {
        return make_error(ErrorCode::kInvalidData, source_, base + ".twist_axis", "", "missing field");
      }
      float axis[3];
      SINEW_RETURN_IF_ERROR(numbers(*axis_it, base + ".twist_axis", axis));
      const Vec3 a(axis[0], axis[1], axis[2]);
      const float len = glm::length(a);
      // Hand-written axes such as [1, 1, 0] are normalised; only a zero axis
      // has no direction.
      if (!(len > 1e-6f) || !std::isfinite(len))
        return error(base + ".twist_axis", *axis_it, "zero-length axis");
      limit.swing_twist.twist_axis = a / len;
      float swing[2], twist[2];
      SINEW_RETURN_IF_ERROR(degrees(obj, base, "swing_deg", swing));
      SINEW_RETURN_IF_ERROR(degrees(obj, base, "twist_deg", twist));
      for (int i = 0; i < 2; ++i) {
        const std::string idx = "[" + std::to_string(i) + "]";
        SINEW_RETURN_IF_ERROR(
            range_check(obj["swing_deg"][i], base + ".swing_deg" + idx, 0.0, kPi, swing[i]));
        SINEW_RETURN_IF_ERROR(
            range_check(obj["twist_deg"][i], base + ".twist_deg" + idx, -kPi, kPi, twist[i]));
      }
      if (twist[0] > twist[1])
        return error(base + ".twist_deg[0]", obj["twist_deg"][0], "greater than twist_deg[1]");
      limit.swing_twist.swing_max_1 = swing[0];
      limit.swing_twist.swing_max_2 = swing[1];
      limit.swing_twist.twist_min = twist[0];
      limit.swing_twist.twist_max = twist[1];
      return limit;
    }
    return error(base + ".type", *type_it, "expected \"euler\", \"swing_twist\" or \"free\"");
  }

 private:
  // Degrees in [lo, hi] radians; float(pi) > pi, hence the slack.
  Status range_check(const json& value, const std::string& field, double lo, double hi, float radians) const {
    const double r = static_cast<double>(radians);
    if (r < lo - 1e-5 || r > hi + 1e-5) {
      return error(field, value, lo < 0.0 ? "outside [-180, 180] degrees" : "outside [0, 180] degrees");
    }
    return {};
  }

  std::string source_;
};

// The shortest decimal degree value that reads back as the same float
// radians, so a hand-written 90 stays 90 after the editor saves the file.
double to_degrees(float radians) {
  const double exact = static_cast<double>(radians) / kRadPerDeg;
  for (int precision = 1; precision <= 17; ++precision) {
    char buf[64];
    std::snprintf(buf, sizeof(buf), "%.*g", precision, exact);
    const double d = std::strtod(buf, nullptr);
    if (static_cast<float>(d * kRadPerDeg) == radians) return d;
  }
  return exact;
}

// The shortest decimal that reads back as the same float.
double shortest(float v) {
  for (int precision = 1; precision <= 17; ++precision) {
    char buf[64];
    std::snprintf(buf, sizeof(buf), "%.*g", precision, static_cast<double>(v));
    const double d = std::strtod(buf, nullptr);
    if (static_cast<float>(d) == v) return d;
  }
  return static_cast<double>(v);
}

}  // namespace

Expected<JointLimits> parse_joint_limits(std::string_view text, const Skeleton& skeleton,
                                         std::string_view source) {
  SINEW_RETURN_IF_ERROR(check_json_nesting(text, kMaxNesting, std::string(source), "(top level)"));
  json root;
  try {
    root = json::parse(text.begin(), text.end());
  } catch (const json::exception& e) {
    return make_error(ErrorCode::kInvalidData, source, "", "", std::string("not valid JSON: ") + e.what());
  }
  Parser p(source);
  if (!root.is_object()) return p.error("", root, "expected a JSON object");
  const auto version_it = root.find("version");
  if (version_it == root.end()) {
    return make_error(ErrorCode::kInvalidData, source, "version", "", "missing field");
  }
  if (!version_it->is_number_integer()) return p.error("version", *version_it, "expected an integer");
  if (version_it->get<std::int64_t>() != kVersion) {
    return make_error(ErrorCode::kUnsupportedVersion, source, "version", short_dump(*version_it),
                      "this build reads version 1");
  }
  SINEW_RETURN_IF_ERROR(p.check_keys(root, "", {"version", "joints"}));
  JointLimits limits(skeleton.joint_count());
  const auto joints_it = root.find("joints");
  if (joints_it == root.end()) return limits;  // every joint free
  if (!joints_it->is_object()) return p.error("joints", *joints_it, "expected an object keyed by joint name");
  for (auto it = joints_it->begin(); it != joints_it->end(); ++it) {
    const std::string field = "joints." + it.key();
    const std::optional<int> index = it.key().empty() ? std::nullopt : skeleton.find(it.key());
    if (!index) {
      return make_error(ErrorCode::kNotFound, source, field, it.key(),
                        "no joint of that name in the skeleton");
    }
    SINEW_ASSIGN_OR_RETURN(JointLimit limit, p.joint(it.value(), field));
    limits[static_cast<std::size_t>(*index)] = limit;
  }
  SINEW_RETURN_IF_ERROR(validate_joint_limits(limits, source));
  return limits;
}

Expected<JointLimits> load_joint_limits(const std::string& path, const Skeleton& skeleton) {
  SINEW_ASSIGN_OR_RETURN(std::string text, read_file_text(path));
  return parse_joint_limits(text, skeleton, path);
}

std::string joint_limits_to_json(std::span<const JointLimit> limits, const Skeleton& skeleton) {
  // ordered_json keeps the skeleton's joint order, which reads (and diffs)
  // better than alphabetical.
  nlohmann::ordered_json joints = nlohmann::ordered_json::object();
  const auto names = skeleton.names();
  const std::size_t n = std::min(limits.size(), names.size());
  for (std::size_t j = 0; j < n; ++j) {
    const JointLimit& l = limits[j];
    if (l.kind == LimitKind::kFree || names[j].empty()) continue;
    nlohmann::ordered_json o;
    if (l.kind == LimitKind::kEuler) {
      o["type"] = "euler";
      const char* order = "xyz";
      for (const OrderName& on : kOrders) {
        if (on.order == l.euler.order) order = on.name;
      }
      o["order"] = order;
      o["min_deg"] = {to_degrees(l.euler.min.x), to_degrees(l.euler.min.y), to_degrees(l.euler.min.z)};
      o["max_deg"] = {to_degrees(l.euler.max.x), to_degrees(l.euler.max.y), to_degrees(l.euler.max.z)};
    } else {
      const SwingTwistLimit& st = l.swing_twist;
      o["type"] = "swing_twist";
      o["twist_axis"] = {shortest(st.twist_axis.x), shortest(st.twist_axis.y), shortest(st.twist_axis.z)};
      o["swing_deg"] = {to_degrees(st.swing_max_1), to_degrees(st.swing_max_2)};
      o["twist_deg"] = {to_degrees(st.twist_min), to_degrees(st.twist_max)};
    }
    joints[names[j]] = std::move(o);
  }
  nlohmann::ordered_json root;
  root["version"] = kVersion;
  root["joints"] = std::move(joints);
  return root.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
}

Status save_joint_limits(const std::string& path, std::span<const JointLimit> limits,
                         const Skeleton& skeleton) {
  if (limits.size() != skeleton.joint_count()) {
    return invalid_argument("limits.size", std::to_string(limits.size()),
                            "expected one limit per joint (" + std::to_string(skeleton.joint_count()) + ")");
  }
  for (std::size_t j = 0; j < limits.size(); ++j) {
    if (limits[j].kind != LimitKind::kFree && skeleton.names()[j].empty()) {
      // The file names joints; a limit on an unnamed joint would be lost.
      return invalid_argument("limits[" + std::to_string(j) + "]", "",
                              "joint has no name to store the limit under");
    }
  }
  SINEW_RETURN_IF_ERROR(validate_joint_limits(limits, path));
  return write_file_atomic(path, joint_limits_to_json(limits, skeleton));
}

}  // namespace sinew::anim
