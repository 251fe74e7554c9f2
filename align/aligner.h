// The align stage (the paper's section 3.2, in part): camera poses from coded targets of known layout,
// refined with Ceres under a robust loss, and a sphere sample's centre and radius from its silhouettes
// (rays tangent to the sphere, Ceres). Photos whose pose is unreliable are dropped with a reason.
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
  int silhouette_lines = 360;        // radial search lines per photo
  bool Check(std::string* why) const;
};

struct ImageAlignment {
  size_t photo = 0;
  bool used = false;
  std::string dropped_reason;        // empty when used
  int markers = 0;                   // reference markers detected
  int ignored_markers = 0;           // detections of ids not in the reference layout (or duplicated)
  int outlier_corners = 0;           // corners left out of the final solve (partly hidden markers)
  double rms_px = 0.0;               // reprojection RMS of the inlier corners after refinement
  Rigid3d camera_from_world;
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

struct AlignResult {
  bool success = false;
  Session session;                   // the input session with poses (and sphere) replaced; dropped photos removed
  std::vector<ImageAlignment> images;
  std::vector<MarkerResidual> markers;
  SphereFit sphere;
  double rms_px = 0.0;               // over all corners of used photos
  double total_s = 0.0;
  std::string BriefReport() const;
};

// Aligns a session whose "targets" block gives reference markers of known layout. The sample's
// centre and radius in the session serve as the starting guess of the sphere fit.
AlignResult AlignSession(const Session& session, const AlignOptions& options);

nlohmann::json ToJson(const AlignResult& result);

}  // namespace ibrdf
