// Accessor decoding: a typed accessor's elements (its bufferView's bytes,
// then sparse substitution) as doubles, every index, count, stride and byte
// range checked against the file's buffers first. Separate because it is
// the one part that reads raw buffer bytes; the others see decoded values.
#pragma once

#include <cstddef>
#include <initializer_list>
#include <string>
#include <vector>

#include "editor/import/gltf_context.h"

namespace sinew::editor::gltf_detail {

// Far beyond any character; keeps a corrupt count from allocating gigabytes
// before the bounds checks against the (much smaller) buffers run.
inline constexpr std::size_t kMaxElements = std::size_t{1} << 25;  // values per accessor

struct AccessorData {
  int components = 0;
  std::size_t count = 0;
  std::vector<double> values;  // count * components

  double at(std::size_t element, int component) const {
    return values[element * static_cast<std::size_t>(components) +
                  static_cast<std::size_t>(component)];
  }
};

// Decodes accessor `index` (dense data, then sparse substitution). `use`
// names where the accessor is referenced, for messages. Float components
// must be finite.
Expected<AccessorData> read_accessor(const Ctx& c, int index, const std::string& use,
                                     std::initializer_list<int> types,
                                     std::initializer_list<int> component_types);

// The accessor index of attribute `name`, or -1.
int attribute(const tinygltf::Primitive& p, const char* name);

}  // namespace sinew::editor::gltf_detail
