// The calibrations' report lines: numbers into a printf format, without a stream's formatting state.
#pragma once

#include <cstdio>
#include <string>

namespace ibrdf {

// `format` with up to four doubles (unused ones are ignored): "+- %.2f deg (over %.2f deg)".
inline std::string FormatNumbers(const char* format, double a, double b = 0, double c = 0, double d = 0) {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer), format, a, b, c, d);
  return buffer;
}

}  // namespace ibrdf
