// Per-photo statistics of a sample file for the report: how many samples each photo gave, the pixel
// box they cover, and the phase angle (between wi and wo) typical of the photo; and the photo the
// report shows.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <vector>

#include "core/sample_file.h"

namespace ibrdf {

// One photo's samples.
struct PhotoStats {
  size_t count = 0;                                  // samples from the photo
  int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;  // their pixel box, inclusive
  std::vector<float> phase;                          // angles between wi and wo, radians (a subset beyond 4096 samples)
};

// The statistics of every photo that gave samples, by photo index.
std::map<uint32_t, PhotoStats> CollectPhotoStats(const std::vector<BrdfSample>& samples);

// A photo and its median phase angle (radians).
struct ChosenPhoto {
  uint32_t photo = 0;
  double phase = 0.0;
};

// The photo `requested` (>= 0), or with -1 the one whose median phase angle is the median over photos
// (the upper middle one). `photos` must not be empty. Throws Error naming --photo when the requested
// photo has no samples.
ChosenPhoto ChoosePhoto(const std::map<uint32_t, PhotoStats>& photos, int requested);

}  // namespace ibrdf
