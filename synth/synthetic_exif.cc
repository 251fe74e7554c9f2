#include "synth/synthetic_exif.h"

#include <cmath>
#include <cstdio>

namespace ibrdf {

PhotoMetadata SyntheticPhotoMetadata(const Session& session, const PhotoSpec& photo, size_t index) {
  const Camera& camera = session.camera;
  PhotoMetadata metadata;
  metadata.exposure_s = photo.exposure_s;
  metadata.iso = 100.0 * photo.gain;
  metadata.f_number = 8.0;
  metadata.pixels_per_mm = 1.0 / kSyntheticPixelPitchMm;
  metadata.focal_length_mm = camera.FocalX() * kSyntheticPixelPitchMm;
  const double diagonal_mm = kSyntheticPixelPitchMm * std::hypot(camera.width, camera.height);
  metadata.focal_length_35mm = *metadata.focal_length_mm * std::hypot(36.0, 24.0) / diagonal_mm;
  metadata.make = "ibrdf";
  metadata.model = "synth";
  size_t seconds = 12 * 3600;
  for (size_t i = 1; i <= index && i <= session.photos.size(); ++i) {
    const std::optional<int>& bracket = i < session.photos.size() ? session.photos[i].bracket : photo.bracket;
    seconds += bracket && bracket == session.photos[i - 1].bracket ? 1 : 10;
  }
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "2026:01:01 %02d:%02d:%02d", int(seconds / 3600 % 24), int(seconds / 60 % 60),
                int(seconds % 60));
  metadata.date_time = buffer;
  return metadata;
}

}  // namespace ibrdf
