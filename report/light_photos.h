// Multi-light sessions in the report (the real-rigs issue): a light dome or a turntable has a light
// per photo, so the report lists the session's lights with what each gave (photos, samples, the
// typical angle between light and view) and shows a small photo taken under each.
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "report/photo_statistics.h"

namespace ibrdf {

// For a session (the samples' sidecar names it) with more than one light: writes one thumbnail per
// light that gave samples (its photo with the most samples, linearized, cropped to the samples' box,
// tone-mapped, at most `thumbnail_size` pixels on a side) as `tmp_dir`/lights/NNN.png, and returns the
// report data's "lights" array: per light its id, kind, position or direction, photos, samples,
// median phase angle (degrees), the photo shown and its thumbnail ("" where it gave no samples).
// Returns null for a one-light session or when the session cannot be read (the report's photo note
// says why).
nlohmann::json WriteLightPhotos(const std::string& samples_path, const std::map<uint32_t, PhotoStats>& photos,
                                const std::string& tmp_dir, int thumbnail_size = 160);

}  // namespace ibrdf
