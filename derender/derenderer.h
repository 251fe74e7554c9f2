// The analytic derenderer (the paper's section 3.1): every pixel of every photo is a BRDF sample.
// For each pixel: the viewing ray (distortion included), its hit on the sphere or cylinder, the exact
// normal, the point-source irradiance E = I cos(theta_i) / r^2, and f = L / E per colour channel, with
// L the pixel's linear signal divided by exposure time and gain.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "core/image_io.h"
#include "core/logging.h"
#include "core/sample_file.h"
#include "core/session.h"

namespace ibrdf {

struct DerenderOptions {
  // Grazing limits: samples with theta_i or theta_e above these are rejected (degrees). Near grazing a
  // pixel covers a large, strongly foreshortened patch and tiny normal errors swing cos(theta).
  double max_theta_i_deg = 80.0;
  double max_theta_e_deg = 80.0;
  // Signal floor: a pixel whose darkest channel has a linear signal below this (normalized file
  // units, after the black level) is rejected as below the noise floor.
  double min_signal = 0.002;
  // Use every n-th pixel in x and in y (1 = all pixels).
  int pixel_stride = 1;

  bool Check(std::string* why) const;
};

struct DerenderSummary {
  bool success = false;           // false until the stage ran to the end
  uint64_t photos = 0;            // measurement photos (alignment-only photos are skipped)
  uint64_t pixels_examined = 0;   // pixels looked at (after the stride)
  uint64_t accepted = 0;
  RejectionCounts rejected;       // reason -> count; see RejectionReasons()
  double decode_s = 0.0;          // summed over threads: time to decode the photos
  double total_s = 0.0;           // wall clock
  // "derender: 1234567 samples from 20 photos in 2.1 s; rejected: off_sample 10, saturated 3"
  std::string BriefReport() const;
};

struct DerenderResult {
  std::vector<BrdfSample> samples;  // ordered by photo, then row, then column
  DerenderSummary summary;
};

// The rejection reasons in the order they are tested, each with a one-line meaning.
const std::vector<std::pair<std::string, std::string>>& RejectionReasons();

// Derenders every photo of a session with a sphere or cylinder sample. Every photo needs a known
// camera_from_world pose. Throws Error for a missing or mis-sized photo, a photo without a pose, or a
// camera inside the sample.
DerenderResult DerenderAnalytic(const Session& session, const DerenderOptions& options);

// The per-pixel core, for one photo's radiance image (radiance_image.h; photo_index gives the pose):
// appends accepted samples and counts rejections. `rays` holds the undistorted image-plane point
// (x, y) of every pixel centre, row-major.
class AnalyticSample;
struct RadianceImage;
void DerenderPhoto(const Session& session, size_t photo_index, const RadianceImage& image,
                   const std::vector<Eigen::Vector2f>& rays, const AnalyticSample& sample,
                   const DerenderOptions& options, std::vector<BrdfSample>* samples,
                   RejectionCounts* rejected);

// Undistorted image-plane points of every pixel centre of the session's camera, row-major.
std::vector<Eigen::Vector2f> PixelRays(const Camera& camera);

// The sample file's sidecar: units, colour space, counts, options and the session it came from.
nlohmann::json DerenderSidecar(const Session& session, const DerenderOptions& options,
                               const DerenderSummary& summary);

}  // namespace ibrdf
