// The radiometric half of derendering: a photo's file values to radiance. Each step follows the
// session's radiometry block (docs/session-format.md): the response inverted, the black level
// subtracted, divided by exposure time and gain; and each pixel flagged where it cannot be measured
// (clipped, not finite, below the signal floor), with a one-sigma uncertainty from the camera's noise
// model. The geometric half (rays, hits, normals, irradiance) lives in derenderer.cc.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/session.h"

namespace ibrdf {

// Per-pixel flags of a RadianceImage (bits; 0 = measurable).
enum PixelFlag : uint8_t {
  kPixelNonFinite = 1,    // a channel is NaN or infinite in the file
  kPixelSaturated = 2,    // a channel reached the saturation level (in every exposure of a bracket)
  kPixelBelowSignal = 4,  // the darkest channel's linear signal is below the floor (in every exposure)
};

struct RadianceImage {
  int width = 0;
  int height = 0;
  // 3 floats per pixel, row-major: linear signal / (exposure_s * gain), in the session's radiance unit.
  std::vector<float> radiance;
  // 3 floats per pixel: one standard deviation of radiance from the camera noise model (0 without one).
  std::vector<float> sigma;
  std::vector<uint8_t> flags;  // one per pixel, PixelFlag bits

  size_t Index(int x, int y) const { return size_t(y) * width + x; }
};

// The photos to derender, grouped by pose: measurement photos sharing one camera_from_world pose
// (an exposure bracket) form one group; every other measurement photo is a group of its own.
// Alignment-only photos (role "targets") are in no group. Groups are ordered by their first photo.
std::vector<std::vector<size_t>> ExposureGroups(const Session& session);

// Decodes the photos of one group and turns them into one radiance image. `min_signal` is the signal
// floor in linear normalized file units (DerenderOptions::min_signal). `decode_s`, when given, gets
// the seconds spent decoding files. Throws Error naming the photo for an unreadable or mis-sized file.
RadianceImage ReadRadianceImage(const Session& session, const std::vector<size_t>& group, double min_signal,
                                double* decode_s = nullptr);

}  // namespace ibrdf
