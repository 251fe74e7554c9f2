// Tone mapping for the report's images: linear RGB radiance to sRGB values ready for an 8-bit PNG.
#pragma once

#include "core/image_io.h"

namespace ibrdf {

// Linear RGB (NaN marks "no value") to an sRGB image in [0, 1], scaled so that the 99th percentile
// (core/statistics.h) of the positive finite luminance lands at 0.8; NaN pixels are drawn magenta.
// `scale_out` (optional) gets the scale applied to the linear values.
Image ToneMap(const Image& linear, double* scale_out = nullptr);

// As ToneMap with a given scale (e.g. ToneMap's of the photo, so renders of it compare by eye).
Image ToneMapWithScale(const Image& linear, double scale);

}  // namespace ibrdf
