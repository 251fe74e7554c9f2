#include "report/tone_map.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/radiometry.h"
#include "core/statistics.h"

namespace ibrdf {

Image ToneMap(const Image& linear, double* scale_out) {
  std::vector<double> luminance;
  for (int y = 0; y < linear.height; ++y) {
    for (int x = 0; x < linear.width; ++x) {
      const double l = 0.2126 * linear.at(x, y, 0) + 0.7152 * linear.at(x, y, 1) + 0.0722 * linear.at(x, y, 2);
      if (std::isfinite(l) && l > 0.0) luminance.push_back(l);
    }
  }
  const double p99 = Percentile(luminance, 0.99);
  const double scale = p99 > 0.0 ? 0.8 / p99 : 1.0;
  if (scale_out) *scale_out = scale;
  return ToneMapWithScale(linear, scale);
}

Image ToneMapWithScale(const Image& linear, double scale) {
  Image out(linear.width, linear.height, 3);
  for (int y = 0; y < linear.height; ++y) {
    for (int x = 0; x < linear.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        const double v = linear.at(x, y, c);
        out.at(x, y, c) =
            std::isfinite(v) ? float(LinearToSrgb(std::clamp(v * scale, 0.0, 1.0))) : (c == 1 ? 0.0f : 1.0f);
      }
    }
  }
  return out;
}

}  // namespace ibrdf
