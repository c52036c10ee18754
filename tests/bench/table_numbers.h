// The benchmarks' numbers in their Markdown tables and notes, one way each.
#pragma once

#include <cstdio>
#include <string>

namespace sinew::bench {

// `decimals` digits after the point: fixed(2.345, 1) == "2.3".
inline std::string fixed(double value, int decimals) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

// Three significant digits in scientific notation: sci(0.000123) == "1.23e-04".
inline std::string sci(double value) {
  char text[64];
  std::snprintf(text, sizeof text, "%.2e", value);
  return text;
}

// `digits` significant digits, the shorter of fixed and scientific.
inline std::string general(double value, int digits = 6) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*g", digits, value);
  return text;
}

}  // namespace sinew::bench
