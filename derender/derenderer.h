// The derenderer (the paper's section 3.1): every pixel of every photo is a BRDF sample. For each
// pixel: the viewing ray (distortion included), its hit on the sample, the normal there, the
// point-source irradiance E = I cos(theta_i) / r^2, and f = L / E per colour channel, with L the
// pixel's radiance (radiance_image.h). The sample is an analytic sphere or cylinder (exact hits and
// normals) or a scanned mesh (mesh_sample.h: Embree, normals interpolated from the scan's local-plane
// fits), with masks for silhouette pixels, markers in front of the sample, back faces, poor normals
// and, where the sample is not convex, shadows (docs/derender.md).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "core/image_io.h"
#include "core/logging.h"
#include "core/sample_file.h"
#include "core/session.h"
#include "radiometry/exposure_advice.h"

namespace ibrdf {

struct DerenderOptions {
  // Grazing limits: samples with theta_i or theta_e above these are rejected (degrees). Near grazing a
  // pixel covers a large, strongly foreshortened patch and tiny normal errors swing cos(theta).
  double max_theta_i_deg = 80.0;
  double max_theta_e_deg = 80.0;
  // Signal floor, per channel: a channel whose expected linear signal (normalized file units, after
  // the black level; the mean of the ring of neighbours around the pixel, radiance_image.h) is below
  // this is not measured there (the sample's `valid` flag is 0); a pixel is kept while any channel is
  // measured, and rejected as below_signal when none is.
  double min_signal = 0.002;
  // When clipping or the floor removes a region of theta_h in a channel: warn and name the remedy.
  ExposureAdviceOptions exposure_advice;
  // Use every n-th pixel in x and in y (1 = all pixels).
  int pixel_stride = 1;

  // Mesh samples only (docs/derender.md).
  // Shadow rays: overrides the session's sample.visibility (auto: only where the scan's convexity
  // report says needs_shadow_rays) when set.
  std::optional<Visibility> visibility;
  // Silhouette (mixed) pixels: rays through the pixel's four corners must all hit the sample, at
  // distances within mixed_pixel_depth_factor pixel footprints of the centre's (a footprint: the
  // centre's distance times the pixel's half-diagonal angle). At theta_e <= 80 degrees a smooth
  // surface changes depth by at most 5.7 footprints across the pixel, so 8 catches steps only.
  bool mask_mixed_pixels = true;
  double mixed_pixel_depth_factor = 8.0;
  // Normal quality from the scan's local-plane fit: a hit whose interpolated fit RMS exceeds this
  // (metres; 0: no limit), or one of whose face's corners had fewer than min_fit_neighbours points
  // in its fit (0 = no fit: the mesh's own normal), is rejected. Meshes without fit data pass.
  double max_normal_fit_rms_m = 0.0005;
  int min_fit_neighbours = 5;
  // With shadow rays on: a shadow ray starts this many local fit RMS residuals (plus a tiny epsilon)
  // off the surface along the normal, so scanner noise on the faces around the hit (bumps the fitted
  // normal smooths over) does not shadow it.
  double shadow_ray_offset_fit_rms = 3.0;
  // Shadow edges: shadow_edge_rays extra rays to points on a disc around the light, perpendicular to
  // the light direction, of angular radius shadow_edge_deg seen from the hit; if any is blocked the
  // pixel lies within that angle of a shadow edge (where mesh and light-position errors decide
  // lit or not) and is rejected. 0 rays: no test.
  double shadow_edge_deg = 0.5;
  int shadow_edge_rays = 8;

  bool Check(std::string* why) const;
};

// What the derender stage did (it throws Error for bad input; a returned summary is complete).
struct DerenderSummary {
  std::string sample;            // "sphere", "cylinder" or "mesh"
  uint64_t photos = 0;           // measurement photos (alignment-only photos are skipped)
  uint64_t pixels_examined = 0;  // pixels looked at (after the stride)
  uint64_t accepted = 0;
  RejectionCounts rejected;  // reason -> count; see RejectionReasons()
  // Mesh samples: the mesh, whether shadow rays were traced and why, how many.
  uint64_t mesh_faces = 0;
  bool shadow_rays_on = false;
  std::string visibility_reason;      // "visibility on (session)", "auto: convex (scan sidecar)" ...
  uint64_t shadow_rays = 0;           // shadow rays traced (shadow-edge rays included)
  uint64_t shadow_tests_skipped = 0;  // pixels that would have had shadow rays, with visibility off
  double decode_s = 0.0;              // summed over threads: time to decode the photos
  double total_s = 0.0;               // wall clock
  double mesh_setup_s = 0.0;          // mesh: reading it, the ray-tracing scene, the convexity verdict
  // With a colour chart: the matrix applied to the samples' brdf, per light (colour_correction.h).
  std::vector<Eigen::Matrix3d> colour_matrices;
  // Accepted samples whose channel c (R, G, B) is not measured (valid 0), counted after the colour
  // correction where there is one.
  std::array<uint64_t, 3> channels_not_measured{};
  // With a colour chart: the channels the correction made negative, marked unmeasured
  // (colour_correction.h); samples it left with none measured are rejected as colour_unmeasured.
  std::array<uint64_t, 3> colour_negative{};
  ExposureTally exposure;                          // per theta_h band and channel, what was lost
  std::vector<ExposureWarning> exposure_warnings;  // AdviseExposure of `exposure`
  // "derender: 1234567 samples from 20 photos in 2.1 s; rejected: off_sample 10, saturated 3"
  std::string BriefReport() const;
};

struct DerenderResult {
  std::vector<BrdfSample> samples;  // ordered by photo, then row, then column
  DerenderSummary summary;
};

// The rejection reasons in the order they are tested, each with a one-line meaning.
const std::vector<std::pair<std::string, std::string>>& RejectionReasons();

// Derenders every measurement photo of a calibrated session: the analytic path for a sphere or
// cylinder, the mesh path for a scanned mesh, then the colour chart's matrix where the session has
// one. Every photo needs a known camera_from_world pose. Throws Error for a session whose white
// reference is not applied yet (calibrate/white_reference_intensity.h: `ibrdf lights white`), a
// missing or mis-sized photo, a photo without a pose, a camera inside the sample, a sample that no
// photo sees, and (mesh) a missing or corrupt mesh file or one without normals.
DerenderResult Derender(const Session& session, const DerenderOptions& options);

// The analytic path alone, the session's light taken as stated (throws Error for a mesh sample).
DerenderResult DerenderAnalytic(const Session& session, const DerenderOptions& options);

// One photo's (exposure group's) part of the stage's result, as DerenderSetup::DerenderPhoto fills it.
struct PhotoSamples {
  // The accepted samples in row-major order, one buffer per block of rows (their concatenation is the
  // photo's samples); the buffers are kept from photo to photo, so their memory is touched once.
  std::vector<std::vector<BrdfSample>> blocks;
  RejectionCounts rejected;  // every pixel of the photo (after the stride) not accepted, by reason
  ExposureTally exposure;    // the pixels that reach the radiometric tests, by theta_h band
  uint64_t shadow_rays = 0;           // mesh: shadow rays traced (shadow-edge rays included)
  uint64_t shadow_tests_skipped = 0;  // mesh: pixels that would have had shadow rays, with visibility off
};

class RadianceWindow;  // radiance_image.h

// The derender stage's set-up of one session, shared by all its photos: the checks that need no photo
// decoded, the exposure groups (the photos derendered, radiance_image.h), the sample's geometry (the
// analytic shape, or the mesh's ray-tracing scene, marker occluders and shadow-ray verdict), the rays
// of the pixels that can see the sample, the radiometric chain and the masks several photos share.
// Derender and DerenderAnalytic run the stage through it; tests and benchmarks may call its per-photo
// steps directly. `session` must outlive it.
class DerenderSetup {
 public:
  // Throws Error as Derender does for bad options, a missing or corrupt mesh, a photo without a pose,
  // a camera inside the sample, a measurement light without intensity and a sample no photo sees.
  DerenderSetup(const Session& session, const DerenderOptions& options);
  ~DerenderSetup();
  DerenderSetup(const DerenderSetup&) = delete;
  DerenderSetup& operator=(const DerenderSetup&) = delete;

  // The photos (exposure groups) to derender, in ExposureGroups order.
  size_t NumPhotos() const;
  // Decodes photo `photo`'s exposures inside the pixels that can see the sample, with its mask, into
  // `image` (buffers reused from photo to photo); `decode_s` gets the seconds spent decoding added.
  void ReadPhoto(size_t photo, RadianceWindow* image, double* decode_s = nullptr) const;
  // The per-pixel kernel on photo `photo` as ReadPhoto prepared it: fills `out` (its buffers reused).
  // `parallel`: the blocks of rows across threads; else all on the calling thread.
  void DerenderPhoto(size_t photo, const RadianceWindow& image, bool parallel, PhotoSamples* out) const;
  // Every photo, decoded and derendered in a pipeline, the samples in photo order.
  DerenderResult DerenderAll() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Undistorted image-plane points of every pixel centre of the session's camera, row-major.
std::vector<Eigen::Vector2f> PixelRays(const Camera& camera);
// The same for the (width + 1) x (height + 1) pixel corners, row-major.
std::vector<Eigen::Vector2f> PixelCornerRays(const Camera& camera);

// The sample file's sidecar: units, colour space, counts, options and the session it came from.
nlohmann::json DerenderSidecar(const Session& session, const DerenderOptions& options, const DerenderSummary& summary);

// The derender stage as `ibrdf derender` runs it: logs the session, derenders it as Derender does and
// writes the samples to `samples_path` (.npy, byte for byte what WriteSamples writes for Derender's
// samples) and the sidecar to SidecarPath(samples_path); logs the summary. The samples are streamed:
// each photo's are appended to a temporary file as it is done (memory independent of the number of
// photos), and the file is moved into place, with its sidecar, only when the stage is complete; a
// stage that fails or is interrupted leaves no file. Returns the summary (ReadSamples reads the samples).
DerenderSummary DerenderToFile(const Session& session, const DerenderOptions& options,
                               const std::string& samples_path);

}  // namespace ibrdf
