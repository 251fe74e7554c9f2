// A camera's radiometric behaviour: its response curve, black level and saturation level.
//
// File values are what OpenImageIO reads, normalized to [0, 1] for integer formats (value / 65535 for
// 16-bit). The linear signal of a pixel is Response^-1(file value) - black_level, in the same
// normalized units; it is proportional to radiance x exposure time x gain. A pixel whose file value in
// any channel reaches saturation_level is clipped and never measured.
#pragma once

#include <string>
#include <vector>

#include "core/kind.h"

namespace ibrdf {

struct Response {
  enum class Kind {
    kLinear,  // file value = linear value
    kSrgb,    // IEC 61966-2-1 sRGB transfer curve
    kGamma,   // file value = linear^(1/gamma)
    kTable,   // measured: linear value at N file values evenly spaced over [0, 1]
    kUnknown,  // not known: nothing may read the photos linearly until it is measured (`ibrdf response`)
    IBRDF_DUMMY_KIND
  };
  Kind kind = Kind::kLinear;
  double gamma = 2.2;         // kGamma only
  std::vector<double> table;  // kTable only: strictly increasing, table.front() at 0, table.back() at 1
  // kTable only, optional: each entry's relative standard error (as measured by `ibrdf response`).
  std::vector<double> uncertainty;

  // Encoded (file) value to linear, and back. Both are monotonic; table lookups interpolate linearly.
  // An unknown response has neither (a programming error: the radiometric chain refuses it first).
  double ToLinear(double encoded) const;
  double FromLinear(double linear) const;
  // "linear", "srgb", "gamma 2.2", "table (256 entries)", "unknown".
  std::string Describe() const;
  // Checks the parameters; false with a reason when they cannot describe a response.
  bool Check(std::string* why) const;
};

double SrgbToLinear(double encoded);
double LinearToSrgb(double linear);

}  // namespace ibrdf
