#include "derender/radiance_image.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/image_io.h"
#include "core/logging.h"

namespace ibrdf {
namespace {

// Variance of a linear signal v (normalized units) from the camera noise model: shot noise
// v / full_well, read noise (read / full_well)^2, and the file's quantization step through the slope
// of the response.
double SignalVariance(const RadiometrySpec& radiometry, double encoded, double linear) {
  const CameraNoise& noise = *radiometry.noise;
  double variance = std::max(linear, 0.0) / noise.full_well_e +
                    (noise.read_noise_e / noise.full_well_e) * (noise.read_noise_e / noise.full_well_e);
  if (noise.bits > 0) {
    const double step = 1.0 / (std::ldexp(1.0, noise.bits) - 1.0);
    const double slope = (radiometry.response.ToLinear(std::min(encoded + 0.5 * step, 1.0)) -
                          radiometry.response.ToLinear(std::max(encoded - 0.5 * step, 0.0))) / step;
    variance += (step * slope) * (step * slope) / 12.0;
  }
  return variance;
}

}  // namespace

std::vector<std::vector<size_t>> ExposureGroups(const Session& session) {
  std::vector<std::vector<size_t>> groups;
  for (size_t i = 0; i < session.photos.size(); ++i) {
    if (session.photos[i].role == PhotoRole::kTargets) continue;
    groups.push_back({i});
  }
  return groups;
}

RadianceImage ReadRadianceImage(const Session& session, const std::vector<size_t>& group, double min_signal,
                                double* decode_s) {
  IBRDF_CHECK(group.size() == 1);
  const size_t photo_index = group.front();
  const PhotoSpec& photo = session.photos[photo_index];
  const RadiometrySpec& radiometry = session.radiometry;
  Timer timer;
  const Image image = ReadImage(session.PhotoPath(photo_index));
  if (decode_s) *decode_s += timer.ElapsedSeconds();
  if (image.width != session.camera.width || image.height != session.camera.height) {
    ThrowError(session.PhotoPath(photo_index), "is " + std::to_string(image.width) + "x" +
                                                   std::to_string(image.height) + ", the camera is " +
                                                   std::to_string(session.camera.width) + "x" +
                                                   std::to_string(session.camera.height));
  }
  RadianceImage out;
  out.width = image.width;
  out.height = image.height;
  const size_t n = size_t(image.width) * image.height;
  out.radiance.resize(3 * n);
  out.sigma.assign(3 * n, 0.0f);
  out.flags.assign(n, 0);
  const double scale = 1.0 / (photo.exposure_s * photo.gain);
  const bool grey = image.channels == 1;
  for (size_t p = 0; p < n; ++p) {
    double encoded[3], linear[3];
    bool finite = true, saturated = false;
    for (int c = 0; c < 3; ++c) {
      encoded[c] = image.pixels[p * image.channels + (grey ? 0 : c)];
      finite = finite && std::isfinite(encoded[c]);
      saturated = saturated || encoded[c] >= radiometry.saturation_level;
      linear[c] = radiometry.response.ToLinear(encoded[c]) - radiometry.black_level;
    }
    uint8_t flags = 0;
    if (!finite) flags |= kPixelNonFinite;
    if (saturated) flags |= kPixelSaturated;
    if (!(std::min({linear[0], linear[1], linear[2]}) >= min_signal)) flags |= kPixelBelowSignal;
    out.flags[p] = flags;
    for (int c = 0; c < 3; ++c) {
      out.radiance[3 * p + c] = static_cast<float>(linear[c] * scale);
      if (radiometry.noise && finite) {
        out.sigma[3 * p + c] = static_cast<float>(std::sqrt(SignalVariance(radiometry, encoded[c], linear[c])) * scale);
      }
    }
  }
  return out;
}

}  // namespace ibrdf
