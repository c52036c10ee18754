// Numbers in messages: nine significant digits, enough for every float to
// read back as the same value, so an error names exactly the value it
// refused ("nan", "inf" and "-inf" as such). The one formatter behind the
// library's and the tools' messages.
#pragma once

#include <cstdio>
#include <string>

namespace sinew {

inline std::string format_number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", v);
  return text;
}
inline std::string format_number(float v) { return format_number(static_cast<double>(v)); }

}  // namespace sinew
