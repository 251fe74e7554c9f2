// The light's position from the markers attached to it (the paper's section 3.2: targets on the light).
// Each light marker's pose starts from a square PnP in one photo (of IPPE's two solutions in every
// photo that sees it, the one that best explains all those photos); then one Ceres problem refines the
// light markers' poses together with the poses of the photos that see them, whose layout corners stay
// in the problem as constants (the layout keeps gauge and scale): the light markers, large and seen
// square-on, tie those photos' poses to each other. The light is where the markers say, averaged.
#pragma once

#include <array>
#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/camera.h"
#include "core/rigid3.h"
#include "core/session.h"

namespace ibrdf {

// Options of FitLightToMarkers.
struct LightFitOptions {
  double huber_px = 1.0;     // robust loss scale for marker corners, pixels
  double tolerance = 1e-14;  // Ceres function and parameter tolerance of the joint refinement
  bool Check(std::string* why) const;
};

// A corner of a posed layout marker (known layout, or as the bundle adjustment estimated it) seen in a
// photo: it holds the photo's pose to the layout during the refinement.
struct LayoutCorner {
  Eigen::Vector2d pixel;       // COLMAP convention (pixel centres at +0.5)
  Eigen::Vector3d p_in_world;  // the corner, world frame, metres; constant in the fit
};

// One posed photo as the light fit sees it.
struct LightFitPhoto {
  size_t photo = 0;           // index in the session's photos
  Rigid3d camera_from_world;  // its pose from the bundle adjustment (the start)
  // Detected light markers: id -> the four corners, pixels, OpenCV's order.
  std::map<int, std::array<Eigen::Vector2d, 4>> light_markers;
  std::vector<LayoutCorner> layout_corners;  // inlier corners of posed layout markers
};

// One marker on the light: its pose from every posed photo that sees it, and the light's position it implies.
struct LightMarkerFit {
  int id = -1;
  int photos = 0;       // posed photos that see it; 0 = not seen, no estimate
  double rms_px = 0.0;  // corner reprojection RMS after refinement
  Rigid3d world_from_marker;
  Eigen::Vector3d light_in_world = Eigen::Vector3d::Zero();
};

// What FitLightToMarkers found; reads as not fitted until it ran.
struct LightFit {
  bool fitted = false;                                 // false: the light stays as given (see `reason`)
  std::string reason;                                  // why not fitted
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // metres, world frame: the markers' mean
  double spread_m = 0.0;                               // largest distance of one marker's estimate from the mean
  std::vector<LightMarkerFit> markers;                 // in the order of LightTargetsSpec::markers
  // The refined poses of the photos that see a light marker (photo index -> camera_from_world); empty
  // when the refinement failed (the bundle adjustment's poses then stand).
  std::map<size_t, Rigid3d> refined_camera_from_world;
  // "light at (0.50000, 0.00000, 0.30000) m from 3 markers (spread 0.120 mm)", or the reason.
  std::string BriefReport() const;
};

// Fits the light's position to its markers seen in `photos` (posed photos, in increasing photo
// order). A light marker no photo sees gets photos = 0; with none seen, or a failed refinement, the
// fit is not `fitted` and says why. Throws Error for bad options.
LightFit FitLightToMarkers(const Camera& camera, const LightTargetsSpec& spec, const std::vector<LightFitPhoto>& photos,
                           const LightFitOptions& options);

}  // namespace ibrdf
