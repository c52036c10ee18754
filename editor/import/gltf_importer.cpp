#include "editor/import/gltf_importer.h"
#include "editor/import/gltf_container.h"
#include "runtime/io/regular_file.h"
#include "runtime/io/atomic_file.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <new>
#include <set>
#include <string_view>
#include <utility>
#include <vector>

#include <glm/gtc/matrix_inverse.hpp>

namespace sinew::editor {
namespace {

// Far beyond any character; keeps a corrupt count from allocating gigabytes
// before the bounds checks against the (much smaller) buffers run.
constexpr std::size_t kMaxElements = std::size_t{1} << 25;  // values per accessor
constexpr const char* kStaticRootName = "<static>";
constexpr const char* kDefaultMaterialName = "<default>";

using DMat4 = glm::dmat4;
using DVec3 = glm::dvec3;
using DQuat = glm::dquat;

std::string idx(std::string_view base, std::size_t i) {
  std::string s(base);
  s += '[';
  s += std::to_string(i);
  s += ']';
  return s;
}

std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

struct Ctx {
  const tinygltf::Model& model;
  const std::string& file;
  const ImportLimits& limits;

  // The error for a limit, naming the option that raises it.
  Status limit(std::string_view field, std::size_t value, std::string_view what, std::size_t max,
               std::string_view option) const {
    return make_error(ErrorCode::kLimitExceeded, file, field, std::to_string(value),
                      "more " + std::string(what) + " than the import limit of " + std::to_string(max) +
                          " (raise it with " + std::string(option) + ")");
  }

  Status error(ErrorCode code, std::string_view field, std::string_view value,
               std::string_view detail) const {
    return make_error(code, file, field, value, detail);
  }
};

// ---------------------------------------------------------------------------
// Accessors

int component_size(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
  }
}

int type_components(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    case TINYGLTF_TYPE_MAT2: return 4;
    case TINYGLTF_TYPE_MAT3: return 9;
    case TINYGLTF_TYPE_MAT4: return 16;
    default: return 0;
  }
}

// One component at `p`, as the spec defines its value: normalised integers
// map to [0,1] or [-1,1], others keep their integer value.
double read_component(const unsigned char* p, int component_type, bool normalized) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      std::int8_t v;
      std::memcpy(&v, p, 1);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
      std::uint8_t v;
      std::memcpy(&v, p, 1);
      return normalized ? v / 255.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      std::int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      std::uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      std::uint32_t v;
      std::memcpy(&v, p, 4);
      return normalized ? v / 4294967295.0 : v;
    }
    default: {
      float v;
      std::memcpy(&v, p, 4);
      return static_cast<double>(v);
    }
  }
}

struct AccessorData {
  int components = 0;
  std::size_t count = 0;
  std::vector<double> values;  // count * components

  double at(std::size_t element, int component) const {
    return values[element * static_cast<std::size_t>(components) +
                  static_cast<std::size_t>(component)];
  }
};

// `bytes` bytes at `offset` inside buffer view `view`, or an error.
Expected<const unsigned char*> view_bytes(const Ctx& c, int view, std::size_t offset,
                                          std::size_t bytes, const std::string& field) {
  const auto& views = c.model.bufferViews;
  if (view < 0 || static_cast<std::size_t>(view) >= views.size()) {
    return c.error(ErrorCode::kOutOfBounds, field + ".bufferView", std::to_string(view),
                   "no such bufferView (" + std::to_string(views.size()) + " in the file)");
  }
  const tinygltf::BufferView& bv = views[static_cast<std::size_t>(view)];
  const std::string bv_field = idx("bufferViews", static_cast<std::size_t>(view));
  if (bv.buffer < 0 || static_cast<std::size_t>(bv.buffer) >= c.model.buffers.size()) {
    return c.error(ErrorCode::kOutOfBounds, bv_field + ".buffer", std::to_string(bv.buffer),
                   "no such buffer");
  }
  const std::vector<unsigned char>& data = c.model.buffers[static_cast<std::size_t>(bv.buffer)].data;
  if (bv.byteOffset > data.size() || bv.byteLength > data.size() - bv.byteOffset) {
    return c.error(ErrorCode::kTruncated, bv_field + ".byteLength", std::to_string(bv.byteLength),
                   "offset " + std::to_string(bv.byteOffset) + " + length runs past the end of " +
                       idx("buffers", static_cast<std::size_t>(bv.buffer)) + " (" +
                       std::to_string(data.size()) + " bytes)");
  }
  if (offset > bv.byteLength || bytes > bv.byteLength - offset) {
    return c.error(ErrorCode::kOutOfBounds, field, std::to_string(offset),
                   "needs " + std::to_string(bytes) + " bytes at this offset, past the end of " +
                       bv_field + " (" + std::to_string(bv.byteLength) + " bytes)");
  }
  return data.data() + bv.byteOffset + offset;
}

// The most elements an accessor without a bufferView (zeros, then sparse
// substitution) may declare: the byte size of the file's buffers, so what
// the importer allocates stays proportional to its input. Real files use
// such accessors for sparse morph targets or edits of a mesh whose dense
// data is in the same buffers, far below this.
std::size_t unbacked_element_limit(const Ctx& c) {
  std::size_t bytes = 0;
  for (const tinygltf::Buffer& b : c.model.buffers) bytes += b.data.size();
  return bytes;
}

// Decodes accessor `index` (dense data, then sparse substitution). `use`
// names where the accessor is referenced, for messages. Float components
// must be finite.
Expected<AccessorData> read_accessor(const Ctx& c, int index, const std::string& use,
                                     std::initializer_list<int> types,
                                     std::initializer_list<int> component_types) {
  const auto& accessors = c.model.accessors;
  if (index < 0 || static_cast<std::size_t>(index) >= accessors.size()) {
    return c.error(ErrorCode::kOutOfBounds, use, std::to_string(index),
                   "no such accessor (" + std::to_string(accessors.size()) + " in the file)");
  }
  const tinygltf::Accessor& a = accessors[static_cast<std::size_t>(index)];
  const std::string field = use + " -> " + idx("accessors", static_cast<std::size_t>(index));

  if (std::find(types.begin(), types.end(), a.type) == types.end()) {
    return c.error(ErrorCode::kInvalidData, field + ".type", std::to_string(a.type),
                   "wrong accessor type for this use");
  }
  if (std::find(component_types.begin(), component_types.end(), a.componentType) ==
      component_types.end()) {
    return c.error(ErrorCode::kInvalidData, field + ".componentType",
                   std::to_string(a.componentType), "component type not allowed for this use");
  }
  const int comps = type_components(a.type);
  const int csize = component_size(a.componentType);
  if (comps > 4 && csize != 4) {
    // Small-component matrices have column padding; nothing we read uses them.
    return c.error(ErrorCode::kInvalidData, field + ".componentType",
                   std::to_string(a.componentType), "only float matrices are supported");
  }
  AccessorData out;
  out.components = comps;
  out.count = a.count;
  const std::size_t ucomps = static_cast<std::size_t>(comps);
  const std::size_t ucsize = static_cast<std::size_t>(csize);
  if (a.count > kMaxElements / ucomps) {
    return c.error(ErrorCode::kLimitExceeded, field + ".count", std::to_string(a.count),
                   "more values than an importer accepts");
  }

  const std::size_t elem = ucomps * ucsize;
  if (a.bufferView < 0 && a.count > unbacked_element_limit(c)) {
    // All zeros plus sparse values: nothing in the file bounds the count, so
    // a tiny file could make us allocate gigabytes of zeros per accessor.
    return c.error(ErrorCode::kLimitExceeded, field + ".count", std::to_string(a.count),
                   "an accessor without a bufferView may not have more elements than the "
                   "file's buffers have bytes (" + std::to_string(unbacked_element_limit(c)) + ")");
  }
  const unsigned char* base = nullptr;
  std::size_t stride = elem;
  if (a.bufferView >= 0 && a.count > 0) {
    // Bounds first, so a corrupt count cannot make us allocate before failing.
    if (static_cast<std::size_t>(a.bufferView) < c.model.bufferViews.size()) {
      const std::size_t declared = c.model.bufferViews[static_cast<std::size_t>(a.bufferView)].byteStride;
      if (declared != 0) {
        if (declared < elem || declared > 252) {
          return c.error(ErrorCode::kInvalidData,
                         idx("bufferViews", static_cast<std::size_t>(a.bufferView)) + ".byteStride",
                         std::to_string(declared),
                         "stride must be between the element size (" + std::to_string(elem) +
                             ") and 252");
        }
        stride = declared;
      }
    }
    const std::size_t need = (a.count - 1) * stride + elem;
    SINEW_ASSIGN_OR_RETURN(base, view_bytes(c, a.bufferView, a.byteOffset, need, field + ".byteOffset"));
  }
  out.values.assign(a.count * ucomps, 0.0);
  if (base != nullptr) {
    for (std::size_t e = 0; e < a.count; ++e) {
      for (std::size_t k = 0; k < ucomps; ++k) {
        out.values[e * ucomps + k] =
            read_component(base + e * stride + k * ucsize, a.componentType, a.normalized);
      }
    }
  } else if (a.bufferView < -1) {
    return c.error(ErrorCode::kOutOfBounds, field + ".bufferView", std::to_string(a.bufferView),
                   "negative bufferView index");
  }

  if (a.sparse.isSparse) {
    const std::string sfield = field + ".sparse";
    if (a.sparse.count < 1 || static_cast<std::size_t>(a.sparse.count) > a.count) {
      return c.error(ErrorCode::kOutOfBounds, sfield + ".count", std::to_string(a.sparse.count),
                     "must be between 1 and the accessor's count " + std::to_string(a.count));
    }
    const std::size_t n = static_cast<std::size_t>(a.sparse.count);
    const int ict = a.sparse.indices.componentType;
    if (ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
        ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
      return c.error(ErrorCode::kInvalidData, sfield + ".indices.componentType",
                     std::to_string(ict), "sparse indices must be unsigned integers");
    }
    if (a.sparse.indices.byteOffset < 0 || a.sparse.values.byteOffset < 0) {
      return c.error(ErrorCode::kOutOfBounds, sfield + ".byteOffset", "", "negative offset");
    }
    const std::size_t isize = static_cast<std::size_t>(component_size(ict));
    SINEW_ASSIGN_OR_RETURN(
        const unsigned char* ibase,
        view_bytes(c, a.sparse.indices.bufferView,
                   static_cast<std::size_t>(a.sparse.indices.byteOffset), n * isize,
                   sfield + ".indices.byteOffset"));
    SINEW_ASSIGN_OR_RETURN(
        const unsigned char* vbase,
        view_bytes(c, a.sparse.values.bufferView,
                   static_cast<std::size_t>(a.sparse.values.byteOffset), n * elem,
                   sfield + ".values.byteOffset"));
    for (std::size_t i = 0; i < n; ++i) {
      const double target = read_component(ibase + i * isize, ict, false);
      if (target >= static_cast<double>(a.count)) {
        return c.error(ErrorCode::kOutOfBounds, idx(sfield + ".indices", i), num(target),
                       "past the accessor's count " + std::to_string(a.count));
      }
      const std::size_t t = static_cast<std::size_t>(target);
      for (std::size_t k = 0; k < ucomps; ++k) {
        out.values[t * ucomps + k] =
            read_component(vbase + i * elem + k * ucsize, a.componentType, a.normalized);
      }
    }
  }

  if (a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT) {
    for (std::size_t i = 0; i < out.values.size(); ++i) {
      if (!std::isfinite(out.values[i])) {
        return c.error(ErrorCode::kInvalidData, idx(field, i / ucomps), num(out.values[i]),
                       "not a finite number");
      }
    }
  }
  return out;
}

// The accessor index of attribute `name`, or -1.
int attribute(const tinygltf::Primitive& p, const char* name) {
  const auto it = p.attributes.find(name);
  return it == p.attributes.end() ? -1 : it->second;
}

// ---------------------------------------------------------------------------
// Transforms

struct Trs {
  DVec3 t{0.0};
  DQuat r{1.0, 0.0, 0.0, 0.0};
  DVec3 s{1.0};

  DMat4 matrix() const {
    DMat4 m = glm::mat4_cast(r);
    m[0] *= s.x;
    m[1] *= s.y;
    m[2] *= s.z;
    m[3] = glm::dvec4(t, 1.0);
    return m;
  }
};

double max_abs_diff(const DMat4& a, const DMat4& b) {
  double d = 0.0;
  for (int col = 0; col < 4; ++col) {
    for (int row = 0; row < 3; ++row) d = std::max(d, std::abs(a[col][row] - b[col][row]));
  }
  return d;
}

// Splits an affine matrix into TRS. Returns false for
// matrices TRS cannot express: shear, zero scale, a projective row.
bool decompose(const DMat4& m, Trs& out) {
  if (std::abs(m[0][3]) > 1e-6 || std::abs(m[1][3]) > 1e-6 || std::abs(m[2][3]) > 1e-6 ||
      std::abs(m[3][3] - 1.0) > 1e-6) {
    return false;
  }
  const DVec3 c0(m[0]), c1(m[1]), c2(m[2]);
  DVec3 s(glm::length(c0), glm::length(c1), glm::length(c2));
  const double smax = std::max({s.x, s.y, s.z});
  if (!(std::min({s.x, s.y, s.z}) > 1e-12 * std::max(1.0, smax))) return false;
  if (glm::determinant(glm::dmat3(m)) < 0.0) s = -s;
  const glm::dmat3 rot(c0 / s.x, c1 / s.y, c2 / s.z);
  out.t = DVec3(m[3]);
  out.r = glm::normalize(glm::quat_cast(rot));
  out.s = s;
  return max_abs_diff(out.matrix(), m) <= 1e-5 * std::max(1.0, smax);
}

bool is_similarity(const Trs& p) {
  const double m = std::max({std::abs(p.s.x), std::abs(p.s.y), std::abs(p.s.z)});
  return std::abs(p.s.x - p.s.y) <= 1e-6 * m && std::abs(p.s.x - p.s.z) <= 1e-6 * m;
}

bool is_identity(const DMat4& m) { return max_abs_diff(m, DMat4(1.0)) <= 1e-12; }

// Node `i`'s local TRS (from TRS properties, or its matrix decomposed).
Status node_local(const Ctx& c, std::size_t i, DMat4& matrix, Trs& trs, bool& trs_ok) {
  const tinygltf::Node& n = c.model.nodes[i];
  const std::string field = idx("nodes", i);
  trs_ok = true;
  if (!n.matrix.empty()) {
    if (n.matrix.size() != 16) {
      return c.error(ErrorCode::kInvalidData, field + ".matrix", std::to_string(n.matrix.size()),
                     "a matrix has 16 numbers");
    }
    for (int k = 0; k < 16; ++k) {
      const double v = n.matrix[static_cast<std::size_t>(k)];
      if (!std::isfinite(v)) {
        return c.error(ErrorCode::kInvalidData, idx(field + ".matrix", static_cast<std::size_t>(k)),
                       num(v), "not a finite number");
      }
      matrix[k / 4][k % 4] = v;  // column-major, like glm
    }
    trs_ok = decompose(matrix, trs);
    return {};
  }
  auto check = [&](const std::vector<double>& v, std::size_t want, const char* name) -> Status {
    if (v.empty()) return {};
    if (v.size() != want) {
      return c.error(ErrorCode::kInvalidData, field + "." + name, std::to_string(v.size()),
                     "expected " + std::to_string(want) + " numbers");
    }
    for (std::size_t k = 0; k < v.size(); ++k) {
      if (!std::isfinite(v[k])) {
        return c.error(ErrorCode::kInvalidData, idx(field + "." + name, k), num(v[k]),
                       "not a finite number");
      }
    }
    return {};
  };
  SINEW_RETURN_IF_ERROR(check(n.translation, 3, "translation"));
  SINEW_RETURN_IF_ERROR(check(n.rotation, 4, "rotation"));
  SINEW_RETURN_IF_ERROR(check(n.scale, 3, "scale"));
  if (!n.translation.empty()) trs.t = DVec3(n.translation[0], n.translation[1], n.translation[2]);
  if (!n.rotation.empty()) {
    const DQuat q(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]);
    const double len = glm::length(q);
    if (!(len > 1e-12)) {
      return c.error(ErrorCode::kInvalidData, field + ".rotation", "0",
                     "rotation quaternion has zero length");
    }
    trs.r = q / len;
  }
  if (!n.scale.empty()) trs.s = DVec3(n.scale[0], n.scale[1], n.scale[2]);
  matrix = trs.matrix();
  return {};
}

Affine3 to_affine(const DMat4& m) { return Affine3::from_mat4(Mat4(m)); }

// Folds a constant parent-side similarity `p` into a child's TRS value.
DVec3 fold_translation(const Trs& p, const DVec3& t) { return p.t + p.s.x * (p.r * t); }
DQuat fold_rotation(const Trs& p, const DQuat& r) { return p.r * r; }
DVec3 fold_scale(const Trs& p, const DVec3& s) { return p.s.x * s; }

// ---------------------------------------------------------------------------
// The import proper

struct NodeGraph {
  std::vector<int> parent;      // -1 for roots
  std::vector<DMat4> local;
  std::vector<Trs> local_trs;
  std::vector<bool> trs_ok;     // local matrix is expressible as TRS
  std::vector<DMat4> global;
};

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

struct SkeletonPlan {
  std::vector<int> joint_nodes;     // raw joint -> node (-1: synthetic root)
  std::vector<int> node_to_raw;     // node -> raw joint or -1
  std::vector<Trs> fold;            // per raw joint: parent-side transform
  std::vector<bool> fold_needed;
  std::vector<DMat4> inverse_bind;  // per raw joint
  int static_root = -1;             // raw index of "<static>", or -1
};

// Raw joint of the nearest ancestor-or-self node that is a joint, or -1.
int joint_ancestor(const NodeGraph& g, const SkeletonPlan& plan, int node) {
  std::size_t guard = 0;
  while (node != -1 && guard++ <= g.parent.size()) {
    const int raw = plan.node_to_raw[static_cast<std::size_t>(node)];
    if (raw != -1) return raw;
    node = g.parent[static_cast<std::size_t>(node)];
  }
  return -1;
}

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

// ---------------------------------------------------------------------------
// Animations

template <typename T, typename F>
void fill_track(anim::Track<T>& track, anim::Interpolation interp, const AccessorData& in,
                const AccessorData& out, F&& convert) {
  track.interpolation = interp;
  track.times.resize(in.count);
  for (std::size_t k = 0; k < in.count; ++k) track.times[k] = static_cast<float>(in.at(k, 0));
  track.values.resize(out.count);
  const std::size_t per = interp == anim::Interpolation::kCubicSpline ? 3 : 1;
  for (std::size_t k = 0; k < out.count; ++k) {
    // In cubic splines the tangents (slots 0 and 2 of each triple) are
    // derivatives: the folded transform's translation must not apply to them.
    const bool tangent = per == 3 && (k % 3) != 1;
    track.values[k] = convert(out, k, tangent);
  }
}

Expected<std::vector<anim::Clip>> build_clips(const Ctx& c, const SkeletonPlan& plan,
                                              const anim::Skeleton& skeleton,
                                              const std::vector<int>& raw_to_sorted) {
  std::vector<anim::Clip> clips;
  if (c.model.animations.size() > c.limits.max_clips) {
    return c.limit("animations", c.model.animations.size(), "clips", c.limits.max_clips, "--max-clips");
  }
  std::size_t keys = 0;
  for (std::size_t a = 0; a < c.model.animations.size(); ++a) {
    const tinygltf::Animation& anim_in = c.model.animations[a];
    const std::string afield = idx("animations", a);
    anim::RawClip raw;
    raw.name = anim_in.name.empty() ? "animation_" + std::to_string(a) : anim_in.name;
    std::vector<int> track_of(plan.joint_nodes.size(), -1);
    for (std::size_t ch = 0; ch < anim_in.channels.size(); ++ch) {
      const tinygltf::AnimationChannel& channel = anim_in.channels[ch];
      const std::string cfield = idx(afield + ".channels", ch);
      const std::string& path = channel.target_path;
      if (path == "weights") continue;  // morph targets: not supported, ignored
      if (path != "translation" && path != "rotation" && path != "scale") {
        return c.error(ErrorCode::kInvalidData, cfield + ".target.path", path,
                       "unknown animation path");
      }
      const int node = channel.target_node;
      if (node < -1 || node >= static_cast<int>(c.model.nodes.size())) {
        return c.error(ErrorCode::kOutOfBounds, cfield + ".target.node", std::to_string(node),
                       "no such node");
      }
      if (node == -1) continue;  // targets an extension's object
      const int raw_joint = plan.node_to_raw[static_cast<std::size_t>(node)];
      if (raw_joint == -1) continue;  // non-joint nodes are not animated
      if (channel.sampler < 0 ||
          static_cast<std::size_t>(channel.sampler) >= anim_in.samplers.size()) {
        return c.error(ErrorCode::kOutOfBounds, cfield + ".sampler",
                       std::to_string(channel.sampler), "no such sampler");
      }
      const tinygltf::AnimationSampler& sampler =
          anim_in.samplers[static_cast<std::size_t>(channel.sampler)];
      const std::string sfield = idx(afield + ".samplers", static_cast<std::size_t>(channel.sampler));
      anim::Interpolation interp;
      if (sampler.interpolation.empty() || sampler.interpolation == "LINEAR") {
        interp = anim::Interpolation::kLinear;
      } else if (sampler.interpolation == "STEP") {
        interp = anim::Interpolation::kStep;
      } else if (sampler.interpolation == "CUBICSPLINE") {
        interp = anim::Interpolation::kCubicSpline;
      } else {
        return c.error(ErrorCode::kInvalidData, sfield + ".interpolation", sampler.interpolation,
                       "unknown interpolation");
      }
      SINEW_ASSIGN_OR_RETURN(AccessorData in,
                             read_accessor(c, sampler.input, sfield + ".input",
                                           {TINYGLTF_TYPE_SCALAR}, {TINYGLTF_COMPONENT_TYPE_FLOAT}));
      // Channels may share samplers: every use counts, as every use is copied.
      keys += in.count;
      if (keys > c.limits.max_keys) {
        return c.limit(sfield + ".input", keys, "animation keys in all", c.limits.max_keys, "--max-keys");
      }
      const bool rot = path == "rotation";
      SINEW_ASSIGN_OR_RETURN(
          AccessorData out,
          rot ? read_accessor(c, sampler.output, sfield + ".output", {TINYGLTF_TYPE_VEC4},
                              {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE,
                               TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                               TINYGLTF_COMPONENT_TYPE_SHORT,
                               TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT})
              : read_accessor(c, sampler.output, sfield + ".output", {TINYGLTF_TYPE_VEC3},
                              {TINYGLTF_COMPONENT_TYPE_FLOAT}));
      const std::size_t per = interp == anim::Interpolation::kCubicSpline ? 3 : 1;
      if (in.count == 0 || out.count != in.count * per) {
        return c.error(ErrorCode::kInvalidData, sfield + ".output", std::to_string(out.count),
                       "expected " + std::to_string(in.count * per) + " values for " +
                           std::to_string(in.count) + " keys");
      }
      int& t = track_of[static_cast<std::size_t>(raw_joint)];
      if (t == -1) {
        t = static_cast<int>(raw.tracks.size());
        anim::JointTracks jt;
        jt.joint = raw_to_sorted[static_cast<std::size_t>(raw_joint)];
        raw.tracks.push_back(std::move(jt));
      }
      anim::JointTracks& jt = raw.tracks[static_cast<std::size_t>(t)];
      const bool fold = plan.fold_needed[static_cast<std::size_t>(raw_joint)];
      const Trs& p = plan.fold[static_cast<std::size_t>(raw_joint)];
      const bool dup = (path == "translation" && !jt.translation.empty()) ||
                       (rot && !jt.rotation.empty()) || (path == "scale" && !jt.scale.empty());
      if (dup) {
        return c.error(ErrorCode::kDuplicate, cfield + ".target", path,
                       "two channels animate the same property of one node");
      }
      if (path == "translation") {
        fill_track(jt.translation, interp, in, out,
                   [&](const AccessorData& d, std::size_t k, bool tangent) {
                     DVec3 v(d.at(k, 0), d.at(k, 1), d.at(k, 2));
                     if (fold) v = tangent ? p.s.x * (p.r * v) : fold_translation(p, v);
                     return Vec3(v);
                   });
      } else if (rot) {
        fill_track(jt.rotation, interp, in, out,
                   [&](const AccessorData& d, std::size_t k, bool) {
                     DQuat q(d.at(k, 3), d.at(k, 0), d.at(k, 1), d.at(k, 2));
                     if (fold) q = fold_rotation(p, q);  // linear, so tangents too
                     return Quat(q);
                   });
      } else {
        fill_track(jt.scale, interp, in, out,
                   [&](const AccessorData& d, std::size_t k, bool) {
                     DVec3 v(d.at(k, 0), d.at(k, 1), d.at(k, 2));
                     if (fold) v = fold_scale(p, v);
                     return Vec3(v);
                   });
      }
    }
    SINEW_ASSIGN_OR_RETURN(anim::Clip clip, anim::Clip::build(std::move(raw), skeleton, c.file));
    clips.push_back(std::move(clip));
  }
  return clips;
}

// ---------------------------------------------------------------------------
// Meshes

struct MeshBuilder {
  SkinnedMesh mesh;
  bool any_uvs = false;
};

constexpr std::initializer_list<int> kWeightComponentTypes = {
    TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
    TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT};

Status add_primitive(const Ctx& c, const NodeGraph& g, const SkeletonPlan& plan,
                     const std::vector<int>& raw_to_sorted, std::size_t node_index,
                     std::size_t mesh_index, std::size_t prim_index, std::uint32_t material,
                     MeshBuilder& b) {
  const tinygltf::Node& node = c.model.nodes[node_index];
  const tinygltf::Primitive& prim = c.model.meshes[mesh_index].primitives[prim_index];
  const std::string pfield = idx(idx("meshes", mesh_index) + ".primitives", prim_index);
  const int mode = prim.mode == -1 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
  if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN) {
    return c.error(ErrorCode::kInvalidData, pfield + ".mode", std::to_string(prim.mode),
                   "only triangle primitives are supported: TRIANGLES (4), TRIANGLE_STRIP (5), TRIANGLE_FAN (6)");
  }
  const std::string afield = pfield + ".attributes";
  const int pos_acc = attribute(prim, "POSITION");
  if (pos_acc < 0) {
    return c.error(ErrorCode::kNotFound, afield + ".POSITION", "", "primitive has no positions");
  }
  SINEW_ASSIGN_OR_RETURN(AccessorData pos,
                         read_accessor(c, pos_acc, afield + ".POSITION", {TINYGLTF_TYPE_VEC3},
                                       {TINYGLTF_COMPONENT_TYPE_FLOAT}));
  const std::size_t vcount = pos.count;
  const std::size_t base = b.mesh.positions.size();
  if (vcount > kMaxElements || base + vcount > std::numeric_limits<std::uint32_t>::max() / 2) {
    return c.error(ErrorCode::kLimitExceeded, afield + ".POSITION", std::to_string(vcount),
                   "too many vertices");
  }
  auto counted = [&](int acc, const char* name, AccessorData& out,
                     std::initializer_list<int> types,
                     std::initializer_list<int> ctypes) -> Status {
    SINEW_ASSIGN_OR_RETURN(out, read_accessor(c, acc, afield + "." + name, types, ctypes));
    if (out.count != vcount) {
      return c.error(ErrorCode::kInvalidData, afield + "." + name, std::to_string(out.count),
                     "count differs from POSITION's " + std::to_string(vcount));
    }
    return {};
  };

  // Where the vertices go: skinned nodes ignore their own transform (spec),
  // rigid ones are baked into the bind pose of the joint that carries them.
  const bool skinned = node.skin >= 0;
  DMat4 bind(1.0);
  int rigid_raw = -1;
  if (!skinned) {
    rigid_raw = joint_ancestor(g, plan, static_cast<int>(node_index));
    if (rigid_raw == -1) {
      rigid_raw = plan.static_root;
      bind = g.global[node_index];
    } else {
      const int jnode = plan.joint_nodes[static_cast<std::size_t>(rigid_raw)];
      bind = glm::inverse(plan.inverse_bind[static_cast<std::size_t>(rigid_raw)]) *
             glm::inverse(g.global[static_cast<std::size_t>(jnode)]) * g.global[node_index];
    }
    for (int col = 0; col < 4; ++col) {
      for (int row = 0; row < 4; ++row) {
        if (!std::isfinite(bind[col][row])) {
          return c.error(ErrorCode::kInvalidData, idx("nodes", node_index), "",
                         "rigid mesh's bind transform is singular (zero scale?)");
        }
      }
    }
  }
  const glm::dmat3 normal_matrix = glm::inverseTranspose(glm::dmat3(bind));

  std::vector<Vec3> positions(vcount);
  for (std::size_t v = 0; v < vcount; ++v) {
    const glm::dvec4 p = bind * glm::dvec4(pos.at(v, 0), pos.at(v, 1), pos.at(v, 2), 1.0);
    positions[v] = Vec3(DVec3(p));
  }

  std::vector<Vec3> normals;
  const int nrm_acc = attribute(prim, "NORMAL");
  if (nrm_acc >= 0) {
    AccessorData nrm;
    SINEW_RETURN_IF_ERROR(
        counted(nrm_acc, "NORMAL", nrm, {TINYGLTF_TYPE_VEC3}, {TINYGLTF_COMPONENT_TYPE_FLOAT}));
    normals.resize(vcount);
    for (std::size_t v = 0; v < vcount; ++v) {
      const DVec3 n = normal_matrix * DVec3(nrm.at(v, 0), nrm.at(v, 1), nrm.at(v, 2));
      const double len = glm::length(n);
      // Zero normals (seen in the wild) are replaced by computed ones below.
      normals[v] = len > 1e-12 ? Vec3(n / len) : Vec3(0.0f);
    }
  }

  std::vector<Vec2> uvs;
  const int uv_acc = attribute(prim, "TEXCOORD_0");
  if (uv_acc >= 0) {
    AccessorData uv;
    SINEW_RETURN_IF_ERROR(counted(uv_acc, "TEXCOORD_0", uv, {TINYGLTF_TYPE_VEC2},
                                  kWeightComponentTypes));
    uvs.resize(vcount);
    for (std::size_t v = 0; v < vcount; ++v) {
      uvs[v] = Vec2(static_cast<float>(uv.at(v, 0)), static_cast<float>(uv.at(v, 1)));
    }
  }

  std::vector<std::array<std::uint16_t, kMaxInfluences>> joints(vcount);
  std::vector<std::array<float, kMaxInfluences>> weights(vcount);
  for (auto& w : weights) w.fill(0.0f);
  for (auto& j : joints) j.fill(0);
  if (skinned) {
    const tinygltf::Skin& skin = c.model.skins[static_cast<std::size_t>(node.skin)];
    if (attribute(prim, "JOINTS_2") >= 0 || attribute(prim, "WEIGHTS_2") >= 0) {
      return c.error(ErrorCode::kLimitExceeded, afield + ".JOINTS_2", "",
                     "more than 8 influences per vertex");
    }
    bool any_set = false;
    for (int set = 0; set < 2; ++set) {
      const std::string jname = "JOINTS_" + std::to_string(set);
      const std::string wname = "WEIGHTS_" + std::to_string(set);
      const int jacc = attribute(prim, jname.c_str());
      const int wacc = attribute(prim, wname.c_str());
      if (jacc < 0 && wacc < 0) continue;
      if (jacc < 0 || wacc < 0) {
        return c.error(ErrorCode::kNotFound, afield + "." + (jacc < 0 ? jname : wname), "",
                       "JOINTS_n and WEIGHTS_n come in pairs");
      }
      any_set = true;
      AccessorData jd, wd;
      SINEW_RETURN_IF_ERROR(counted(jacc, jname.c_str(), jd, {TINYGLTF_TYPE_VEC4},
                                    {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                                     TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT}));
      SINEW_RETURN_IF_ERROR(
          counted(wacc, wname.c_str(), wd, {TINYGLTF_TYPE_VEC4}, kWeightComponentTypes));
      for (std::size_t v = 0; v < vcount; ++v) {
        for (int k = 0; k < 4; ++k) {
          const std::size_t slot = static_cast<std::size_t>(set * 4 + k);
          const double w = wd.at(v, k);
          const double j = jd.at(v, k);
          if (w < 0.0) {
            return c.error(ErrorCode::kInvalidData, idx(afield + "." + wname, v), num(w),
                           "negative weight");
          }
          if (j >= static_cast<double>(skin.joints.size())) {
            if (w == 0.0) continue;  // unused padding slot: leave joint 0
            return c.error(ErrorCode::kOutOfBounds, idx(afield + "." + jname, v), num(j),
                           "joint index past the skin's " + std::to_string(skin.joints.size()) +
                               " joints (" + idx("skins", static_cast<std::size_t>(node.skin)) +
                               ")");
          }
          const int jnode = skin.joints[static_cast<std::size_t>(j)];
          const int raw = plan.node_to_raw[static_cast<std::size_t>(jnode)];
          joints[v][slot] = static_cast<std::uint16_t>(raw_to_sorted[static_cast<std::size_t>(raw)]);
          weights[v][slot] = static_cast<float>(w);
        }
      }
    }
    if (!any_set) {
      return c.error(ErrorCode::kNotFound, afield + ".JOINTS_0", "",
                     "primitive of a skinned node has no JOINTS_0/WEIGHTS_0");
    }
    for (std::size_t v = 0; v < vcount; ++v) {
      double sum = 0.0;
      for (const float w : weights[v]) sum += static_cast<double>(w);
      if (!(sum > 0.0)) {
        return c.error(ErrorCode::kInvalidData, idx(afield + ".WEIGHTS_0", v), "0",
                       "the vertex's weights are all zero");
      }
    }
  } else {
    const std::uint16_t j = static_cast<std::uint16_t>(raw_to_sorted[static_cast<std::size_t>(rigid_raw)]);
    for (std::size_t v = 0; v < vcount; ++v) {
      joints[v][0] = j;
      weights[v][0] = 1.0f;
    }
  }

  // The vertex sequence: the indices, or 0, 1, 2, ... without them.
  std::vector<std::uint32_t> sequence;
  if (prim.indices >= 0) {
    SINEW_ASSIGN_OR_RETURN(AccessorData ind,
                           read_accessor(c, prim.indices, pfield + ".indices",
                                         {TINYGLTF_TYPE_SCALAR},
                                         {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                                          TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                                          TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT}));
    sequence.resize(ind.count);
    for (std::size_t i = 0; i < ind.count; ++i) {
      const double v = ind.at(i, 0);
      if (v >= static_cast<double>(vcount)) {
        return c.error(ErrorCode::kOutOfBounds, idx(pfield + ".indices", i), num(v),
                       "vertex index past the primitive's " + std::to_string(vcount) +
                           " vertices");
      }
      sequence[i] = static_cast<std::uint32_t>(v);
    }
  } else {
    sequence.resize(vcount);
    for (std::size_t i = 0; i < vcount; ++i) sequence[i] = static_cast<std::uint32_t>(i);
  }
  const std::string count_field = prim.indices >= 0 ? pfield + ".indices" : afield + ".POSITION";
  // Triangles in the spec's order (glTF 2.0, 3.7.2.1): strips alternate
  // their winding so that every triangle faces the same way, fans share the
  // first vertex.
  std::vector<std::array<std::uint32_t, 3>> tris;
  const std::size_t count = sequence.size();
  if (mode == TINYGLTF_MODE_TRIANGLES) {
    if (count % 3 != 0) {
      return c.error(ErrorCode::kInvalidData, count_field, std::to_string(count),
                     prim.indices >= 0 ? "index count is not a multiple of 3"
                                       : "non-indexed primitive whose vertex count is not a multiple of 3");
    }
    tris.resize(count / 3);
    for (std::size_t i = 0; i < count; ++i) tris[i / 3][i % 3] = sequence[i];
  } else {
    if (count < 3) {
      return c.error(ErrorCode::kInvalidData, count_field, std::to_string(count),
                     std::string(mode == TINYGLTF_MODE_TRIANGLE_STRIP ? "a triangle strip" : "a triangle fan") +
                         " needs at least 3 vertices");
    }
    tris.resize(count - 2);
    for (std::size_t i = 0; i + 2 < count; ++i) {
      if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
        tris[i] = {sequence[i], sequence[i + 1 + i % 2], sequence[i + 2 - i % 2]};
      } else {
        tris[i] = {sequence[i + 1], sequence[i + 2], sequence[0]};
      }
    }
  }

  // Computed normals: area-weighted face normals, for missing or zero ones.
  const bool need_normals =
      normals.empty() ||
      std::any_of(normals.begin(), normals.end(), [](const Vec3& n) { return n == Vec3(0.0f); });
  if (need_normals) {
    std::vector<DVec3> acc(vcount, DVec3(0.0));
    for (const auto& t : tris) {
      const DVec3 a(positions[t[0]]), bb(positions[t[1]]), cc(positions[t[2]]);
      const DVec3 n = glm::cross(bb - a, cc - a);
      for (const std::uint32_t v : t) acc[v] += n;
    }
    if (normals.empty()) normals.assign(vcount, Vec3(0.0f));
    for (std::size_t v = 0; v < vcount; ++v) {
      if (normals[v] != Vec3(0.0f)) continue;
      const double len = glm::length(acc[v]);
      normals[v] = len > 0.0 ? Vec3(acc[v] / len) : Vec3(0.0f, 0.0f, 1.0f);
    }
  }

  SkinnedMesh& m = b.mesh;
  if (!uvs.empty() && !b.any_uvs) {
    m.uvs.assign(base, Vec2(0.0f));  // earlier primitives had none
    b.any_uvs = true;
  }
  if (b.any_uvs && uvs.empty()) uvs.assign(vcount, Vec2(0.0f));
  m.positions.insert(m.positions.end(), positions.begin(), positions.end());
  m.normals.insert(m.normals.end(), normals.begin(), normals.end());
  m.uvs.insert(m.uvs.end(), uvs.begin(), uvs.end());
  m.joints.insert(m.joints.end(), joints.begin(), joints.end());
  m.weights.insert(m.weights.end(), weights.begin(), weights.end());
  const std::uint32_t ubase = static_cast<std::uint32_t>(base);
  for (const auto& t : tris) {
    m.triangles.push_back({t[0] + ubase, t[1] + ubase, t[2] + ubase});
    m.triangle_material.push_back(material);
  }
  return {};
}

Expected<ImportedModel> convert(const Ctx& c) {
  ImportedModel out;
  out.source = c.file;
  SINEW_ASSIGN_OR_RETURN(NodeGraph g, build_graph(c));
  SINEW_ASSIGN_OR_RETURN(SkeletonPlan plan, plan_skeleton(c, g));
  if (plan.joint_nodes.empty()) {
    return c.error(ErrorCode::kNotFound, "nodes", "", "no node instantiates a mesh");
  }

  std::vector<bool> animated(c.model.nodes.size(), false);
  for (const tinygltf::Animation& a : c.model.animations) {
    for (const tinygltf::AnimationChannel& ch : a.channels) {
      if (ch.target_node >= 0 && static_cast<std::size_t>(ch.target_node) < animated.size() &&
          ch.target_path != "weights") {
        animated[static_cast<std::size_t>(ch.target_node)] = true;
      }
    }
  }
  std::vector<int> raw_to_sorted;
  SINEW_ASSIGN_OR_RETURN(out.skeleton, build_skeleton(c, g, plan, animated, raw_to_sorted));

  MeshBuilder b;
  // Materials: the file's, then a default one if some primitive has none.
  const std::size_t nmat = c.model.materials.size();
  for (std::size_t i = 0; i < nmat; ++i) {
    const tinygltf::Material& mat = c.model.materials[i];
    const std::vector<double>& f = mat.pbrMetallicRoughness.baseColorFactor;
    Vec3 color(1.0f);
    if (f.size() >= 3) {
      color = Vec3(static_cast<float>(f[0]), static_cast<float>(f[1]), static_cast<float>(f[2]));
      if (!std::isfinite(color.x) || !std::isfinite(color.y) || !std::isfinite(color.z)) {
        return c.error(ErrorCode::kInvalidData,
                       idx("materials", i) + ".pbrMetallicRoughness.baseColorFactor", "",
                       "not a finite colour");
      }
    }
    b.mesh.material_colors.push_back(color);
    out.material_names.push_back(mat.name.empty() ? "material_" + std::to_string(i) : mat.name);
  }
  bool default_used = false;
  for (std::size_t m = 0; m < c.model.meshes.size(); ++m) {
    for (std::size_t n = 0; n < c.model.nodes.size(); ++n) {
      if (c.model.nodes[n].mesh != static_cast<int>(m)) continue;
      const auto& prims = c.model.meshes[m].primitives;
      for (std::size_t p = 0; p < prims.size(); ++p) {
        const int mat = prims[p].material;
        if (mat < -1 || mat >= static_cast<int>(nmat)) {
          return c.error(ErrorCode::kOutOfBounds,
                         idx(idx("meshes", m) + ".primitives", p) + ".material",
                         std::to_string(mat), "no such material");
        }
        if (mat == -1) default_used = true;
        const std::uint32_t material =
            mat == -1 ? static_cast<std::uint32_t>(nmat) : static_cast<std::uint32_t>(mat);
        SINEW_RETURN_IF_ERROR(add_primitive(c, g, plan, raw_to_sorted, n, m, p, material, b));
        // Checked per primitive: a mesh instanced by many nodes is copied
        // per node, so memory stays within the limit plus one primitive.
        if (b.mesh.triangles.size() > c.limits.max_triangles) {
          return c.limit(idx("nodes", n) + ".mesh", b.mesh.triangles.size(), "triangles", c.limits.max_triangles,
                         "--max-triangles");
        }
      }
    }
  }
  out.mesh = std::move(b.mesh);
  if (default_used) {
    out.mesh.material_colors.push_back(Vec3(1.0f));
    out.material_names.push_back(kDefaultMaterialName);
  }
  if (out.mesh.triangles.empty()) {
    return c.error(ErrorCode::kNotFound, "meshes", "", "the file has no triangles");
  }

  SINEW_ASSIGN_OR_RETURN(out.clips, build_clips(c, plan, out.skeleton, raw_to_sorted));
  // Weights that do not sum to 1 are renormalised here, with a warning when
  // they were off by more than rounding (the rule all importers share).
  SINEW_RETURN_IF_ERROR(normalize_skin_weights(out));
  return out;
}

// Images are irrelevant to Sinew (colours come from baseColorFactor):
// skipping their decoding keeps a broken texture from failing the import.
bool skip_image(tinygltf::Image*, const int, std::string*, std::string*, int, int,
                const unsigned char*, int, void*) {
  return true;
}

// tinygltf's file reads, kept inside the asset roots (it also looks in the
// current directory), to regular files, and to the import's byte limit
// (the document's own bytes count first).
struct GuardedFs {
  const AssetRoots* roots = nullptr;
  std::size_t bytes_left = 0;
  std::size_t max_bytes = 0;
  std::string refused, why;  // the first path refused, and why
  bool over_limit = false;
};

bool guarded_read(std::vector<unsigned char>* out, std::string* err, const std::string& filepath, void* user) {
  auto& fs = *static_cast<GuardedFs*>(user);
  std::string why;
  if (fs.roots->root_of(filepath).empty()) {
    why = "outside the asset's folder " + fs.roots->asset_folder().string();
  } else if (Status s = check_regular_file(filepath); !s.ok()) {
    why = s.message();
  } else {
    // The size first, so that a huge file is not read at all; then what
    // was read (the file may have grown in between).
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(filepath, ec);
    const bool fits = !ec && size <= fs.bytes_left;
    if (fits && !tinygltf::ReadWholeFile(out, err, filepath, nullptr)) return false;
    if (fits && out->size() <= fs.bytes_left) {
      fs.bytes_left -= out->size();
      return true;
    }
    if (ec) {
      why = "cannot read its size: " + ec.message();
    } else {
      fs.over_limit = true;
      why = std::to_string(fits ? out->size() : size) + " bytes, past the import limit of " +
            std::to_string(fs.max_bytes) + " bytes for the file and its buffers (raise it with --max-bytes)";
      out->clear();
    }
  }
  if (fs.refused.empty()) {
    fs.refused = filepath;
    fs.why = why;
  }
  if (err) *err += why;
  return false;
}

}  // namespace

Expected<ImportedModel> import_gltf(const std::string& path, const GltfImportOptions& options) {
  const std::size_t max_bytes = options.limits.max_bytes;
  const auto too_big = [&](std::uintmax_t size) {
    return make_error(ErrorCode::kLimitExceeded, path, "size", std::to_string(size) + " bytes",
                      "more bytes than the import limit of " + std::to_string(max_bytes) +
                          " (raise it with --max-bytes)");
  };
  SINEW_RETURN_IF_ERROR(check_regular_file(path));
  std::error_code size_error;
  const std::uintmax_t size = std::filesystem::file_size(path, size_error);
  if (!size_error && size > max_bytes) return too_big(size);
  SINEW_ASSIGN_OR_RETURN(const std::string bytes, read_file_text(path));
  if (bytes.size() > max_bytes) return too_big(bytes.size());
  // tinygltf takes 32-bit lengths.
  if (bytes.size() > std::numeric_limits<unsigned int>::max()) {
    return make_error(ErrorCode::kLimitExceeded, path, "", std::to_string(bytes.size()) + " bytes",
                      "glTF files of 4 GiB or more are not supported");
  }
  const bool binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
  // Bounded nesting before tinygltf's recursive parser sees the JSON.
  std::string_view json = bytes;
  if (binary) {
    const Expected<std::string_view> chunk = check_glb(bytes, path);
    if (!chunk.ok()) return chunk.status();
    json = *chunk;
  } else {
    SINEW_RETURN_IF_ERROR(check_json_nesting(bytes, kMaxJsonNesting, path, "json"));
  }
  // External files only from the asset's folder (and the allowed roots).
  const AssetRoots roots(path, options.asset_roots);
  SINEW_RETURN_IF_ERROR(check_gltf_document(json, path, roots));
  const std::string base_dir = std::filesystem::path(path).parent_path().string();

  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(skip_image, nullptr);
  GuardedFs guarded{&roots, max_bytes - bytes.size(), max_bytes, {}, {}, false};
  loader.SetFsCallbacks(tinygltf::FsCallbacks{&tinygltf::FileExists, &tinygltf::ExpandFilePath, &guarded_read,
                                              &tinygltf::WriteWholeFile, &guarded});
  std::string err, warn;
  bool loaded = false;
  try {
    const auto length = static_cast<unsigned int>(bytes.size());
    loaded = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn,
                                                  reinterpret_cast<const unsigned char*>(bytes.data()), length,
                                                  base_dir)
                    : loader.LoadASCIIFromString(&model, &err, &warn, bytes.data(), length, base_dir);
  } catch (const std::bad_alloc&) {
    return make_error(ErrorCode::kLimitExceeded, path, binary ? "glb" : "json", std::to_string(bytes.size()) + " bytes",
                      "out of memory while tinygltf parsed the file");
  } catch (const std::exception& e) {
    // tinygltf or its JSON parser may throw on hostile input; we must not.
    err = e.what();
    loaded = false;
  } catch (...) {
    err = "unknown exception";
    loaded = false;
  }
  if (!loaded && !guarded.refused.empty()) {
    return make_error(guarded.over_limit ? ErrorCode::kLimitExceeded : ErrorCode::kInvalidData, path, "uri",
                      guarded.refused, "not read: " + guarded.why);
  }
  if (!loaded) {
    while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
    // tinygltf ends each of its messages with a newline: one line here.
    for (std::size_t at = err.find('\n'); at != std::string::npos; at = err.find('\n', at)) err.replace(at, 1, "; ");
    return make_error(ErrorCode::kInvalidData, path, binary ? "glb" : "json", "",
                      "tinygltf could not parse the file: " + (err.empty() ? warn : err));
  }
  // asset.version is "major.minor"; only major version 2 is this format.
  const std::string& version = model.asset.version;
  if (version.rfind("2.", 0) != 0) {
    return make_error(ErrorCode::kUnsupportedVersion, path, "asset.version", version.empty() ? "(none)" : version,
                      version.rfind("1.", 0) == 0 ? "glTF 1.0 is not supported (glTF 2.0 only)"
                                                  : "only glTF 2.x is supported");
  }
  const Ctx c{model, path, options.limits};
  return convert(c);
}

}  // namespace sinew::editor
