// Where on the sample each BRDF sample was measured. The sample file keeps each sample's photo and
// pixel, not its surface point (docs/sample-format.md): the point is found again by tracing the pixel
// centre's ray, as the derenderer did, through the session's pose onto the sample's surface (the
// analytic sphere or cylinder, or the scanned mesh placed by world_from_mesh). A sample whose traced
// ray misses, or meets the surface at another exitant angle than the sample records, did not come from
// this session as it is now (another session, or poses changed since derender); callers count them.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/camera.h"
#include "core/sample_file.h"
#include "core/session.h"

namespace ibrdf {

class SampleSurface;  // derender/analytic_sample.h

// The session manifest a sample file was derendered from: `given` when not empty, else the one the
// file's sidecar names ("session"). Throws Error naming the sidecar when it is unreadable or names none
// (the remedy: pass the session).
std::string SessionOfSamples(const std::string& samples_path, const std::string& given);

class SurfaceLocator {
 public:
  // The session's camera, poses and sample surface. Throws Error naming the manifest for a mesh sample
  // whose mesh is missing or unreadable.
  explicit SurfaceLocator(const Session& session);
  ~SurfaceLocator();
  SurfaceLocator(const SurfaceLocator&) = delete;
  SurfaceLocator& operator=(const SurfaceLocator&) = delete;

  // What tracing one sample's pixel found.
  enum class Outcome {
    kFound,     // the surface point, the traced exitant angle within max_theta_e_error of the sample's
    kNoPose,    // the sample's photo index is not a posed photo of the session
    kMissed,    // the ray misses the surface
    kMismatch,  // the ray hits it at another exitant angle than the sample's theta_e
  };
  // The world point of `sample`'s pixel centre on the surface (only for kFound).
  Outcome Locate(const BrdfSample& sample, Eigen::Vector3d* point) const;

  Eigen::Vector3d BoundingCenter() const;
  double BoundingRadius() const;

  // A float's rounding of theta_e and a mesh's interpolated normals stay well inside this (radians,
  // 0.5 degrees): a sample beyond it was not measured through this session's geometry.
  static constexpr double kMaxThetaEError = 0.5 * 3.14159265358979323846 / 180.0;

 private:
  struct Pose {
    Eigen::Matrix3d world_from_camera;
    Eigen::Vector3d centre;
  };
  Camera camera_;
  std::vector<std::optional<Pose>> poses_;  // per session photo
  std::unique_ptr<SampleSurface> surface_;
};

}  // namespace ibrdf
