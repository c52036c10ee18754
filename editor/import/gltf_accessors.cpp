// Accessor decoding (gltf_accessors.h): component reads as the spec defines
// them, bufferView bounds, strides and sparse substitution.
#include "editor/import/gltf_accessors.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace sinew::editor::gltf_detail {
namespace {

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

}  // namespace

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

int attribute(const tinygltf::Primitive& p, const char* name) {
  const auto it = p.attributes.find(name);
  return it == p.attributes.end() ? -1 : it->second;
}

}  // namespace sinew::editor::gltf_detail
