// The align stage (the paper's section 3.2, in part): camera poses from coded targets of known layout,
// refined with Ceres under a robust loss; the light's position from the markers attached to it (their
// poses from the posed photos that see them); and a sphere sample's centre and radius from its
// silhouettes (rays tangent to the sphere, Ceres). Photos whose pose is unreliable are dropped with a
// reason.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "core/session.h"

namespace ibrdf {

struct AlignOptions {
  int min_markers_per_image = 2;     // fewer reference markers seen: the photo is dropped
  double max_image_rms_px = 1.0;     // reprojection RMS above this: the photo is dropped
  double huber_px = 1.0;             // robust loss scale for marker corners, pixels
  bool fit_sphere = true;            // refine a sphere sample's centre and radius from silhouettes
  bool fit_light = true;             // the light's position from its markers, when the session has them
  int silhouette_lines = 360;        // radial search lines per photo
  bool Check(std::string* why) const;
};

struct ImageAlignment {
  size_t photo = 0;
  bool used = false;
  std::string dropped_reason;        // empty when used
  int markers = 0;                   // reference markers detected
  int light_markers = 0;             // markers of the light detected
  int ignored_markers = 0;           // detections of ids in no target list (or duplicated)
  int outlier_corners = 0;           // corners left out of the final solve (partly hidden markers)
  double rms_px = 0.0;               // reprojection RMS of the inlier corners after the photo's own refinement
  Rigid3d camera_from_world;         // photos that see light markers: after the joint refinement with them
};

struct MarkerResidual {
  int id = -1;
  int observations = 0;
  double rms_px = 0.0;
};

struct SphereFit {
  bool fitted = false;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double radius = 0.0;
  int silhouette_points = 0;         // tangent rays used
  int rejected_points = 0;           // outliers removed after the first solve
  double rms_m = 0.0;                // RMS of ray-to-sphere distances, metres
};

// One marker on the light: its pose from every posed photo that sees it (square PnP, the candidate that
// best explains all those photos, then one Ceres problem over all light markers and the poses of the
// photos that see them, their reference corners included), and the light's position it implies.
struct LightMarkerFit {
  int id = -1;
  int photos = 0;                    // posed photos that see it; 0 = not seen, no estimate
  double rms_px = 0.0;               // corner reprojection RMS after refinement
  Rigid3d world_from_marker;
  Eigen::Vector3d light_in_world = Eigen::Vector3d::Zero();
};

struct LightFit {
  bool fitted = false;               // false: the light stays as given (see `reason`)
  std::string reason;                // why not fitted
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // metres, world frame: the markers' mean
  double spread_m = 0.0;             // largest distance of one marker's estimate from the mean
  std::vector<LightMarkerFit> markers;
};

struct AlignResult {
  bool success = false;
  Session session;                   // the input session with poses (and sphere) replaced; dropped photos removed
  std::vector<ImageAlignment> images;
  std::vector<MarkerResidual> markers;
  SphereFit sphere;
  LightFit light;
  double rms_px = 0.0;               // over all corners of used photos
  double total_s = 0.0;
  std::string BriefReport() const;
};

// Aligns a session whose "targets" block gives reference markers of known layout (and optionally the
// light's markers). Every photo is posed, target photos (role "targets") included; only measurement
// photos serve the silhouette fits. The sample's centre and radius in the session serve as the starting
// guess of the sphere fit.
AlignResult AlignSession(const Session& session, const AlignOptions& options);

nlohmann::json ToJson(const AlignResult& result);

}  // namespace ibrdf
