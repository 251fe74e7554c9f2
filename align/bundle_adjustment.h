// Bundle adjustment over coded targets (the paper's section 3.2): camera poses and the poses of
// markers whose layout is unknown, from every photo's detected corners, in one Ceres problem under a
// robust loss. Each free marker is a rigid printed square of known side (6 unknowns, not 4 free
// points), which also gives the scale; markers of known layout (or the one origin marker) keep their
// corners fixed and so fix the gauge. The start comes from chaining: photos posed by PnP from the
// markers already posed, then markers posed from those photos (square PnP), in turns.
//
// Also the per-photo reliability checks of the align stage: the pose's predicted uncertainty from the
// corners' geometry (the inverse of the Gauss-Newton normal matrix) and the planar pose ambiguity (the
// second solution of IPPE). OpenCV stays in the .cc file.
#pragma once

#include <array>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/camera.h"
#include "core/rigid3.h"

namespace ibrdf {

// fx, fy, cx, cy, k1, k2, p1, p2 of any supported camera model: the form the cost functions take
// (align/cost_functions/reprojection_error.h).
std::array<double, 8> ProjectionIntrinsics(const Camera& camera);

// A pose as Ceres' parameter blocks (angle-axis rotation, translation) and back.
void AngleAxisFromPose(const Rigid3d& pose, double* rotation, double* translation);
Rigid3d PoseFromAngleAxis(const double* rotation, const double* translation);

// The printed square's outer corners in a marker's own frame (align/markers.h), OpenCV's order.
std::array<Eigen::Vector3d, 4> MarkerCornersInMarker(double size);

// A marker in the adjustment.
struct BundleMarker {
  int id = -1;
  bool fixed = false;                      // corners known and held constant (known layout, or the origin marker)
  double size = 0.0;                       // free markers: printed side, metres
  bool posed = false;                      // has a pose estimate (fixed markers always)
  Rigid3d world_from_marker;               // free markers: the estimate
  std::array<Eigen::Vector3d, 4> corners;  // world frame: given (fixed) or from the pose (free)
  // Outputs: used photos that see the marker, and the reprojection RMS of its inlier corners.
  int images = 0;
  double rms_px = 0.0;

  // Corners from world_from_marker and size (free markers).
  void UpdateCorners();
};

struct CornerObservation {
  int marker_id = -1;
  int corner = 0;         // 0..3, OpenCV's order
  Eigen::Vector2d pixel;  // COLMAP convention (pixel centres at +0.5)
  bool inlier = true;     // false: left out (a corner of a partly hidden marker)
};

// One photo in the adjustment.
struct BundleImage {
  std::vector<CornerObservation> corners;
  bool posed = false;  // has a pose estimate and takes part
  Rigid3d camera_from_world;
  // Outputs: inlier corners of posed markers, their RMS, and the outliers left out.
  int inliers = 0;
  int outliers = 0;
  double rms_px = 0.0;
};

struct BundleAdjustmentOptions {
  double huber_px = 1.0;         // robust loss scale for marker corners, pixels
  int max_num_iterations = 200;  // Ceres iterations per solve
  double tolerance = 1e-12;      // Ceres function and parameter tolerance
  double min_outlier_px = 0.25;  // outlier pass: a corner beyond max(this, 3 robust sigmas) of its photo
                                 // leaves its marker out of that photo
  bool Check(std::string* why) const;
};

struct BundleAdjustmentSummary {
  // False when Ceres found no usable solution (`message` says why; the poses are then unchanged), and
  // until BundleAdjust ran. Bad input throws instead.
  bool success = false;
  int images = 0;         // posed photos in the problem
  int free_markers = 0;   // markers whose pose was adjusted
  int fixed_markers = 0;  // markers held constant (gauge)
  int corners = 0;        // inlier corner observations
  int outliers = 0;       // corners left out by the outlier pass
  double initial_rms_px = 0.0;
  double final_rms_px = 0.0;
  int iterations = 0;
  double total_s = 0.0;
  std::string message;  // Ceres' when it failed
  std::string BriefReport() const;
};

// Jointly refines every posed photo's pose and every posed free marker's pose from the inlier corners
// of posed markers (Huber loss), then leaves out, per photo, every marker with a corner beyond
// max(min_outlier_px, 3 robust sigmas) of that photo's residuals, and solves again. Fixed markers stay constant;
// without any fixed marker in the problem the gauge is free and the call fails. Updates poses, corners, inlier flags
// and the per-photo and per-marker residuals.
BundleAdjustmentSummary BundleAdjust(const Camera& camera, const BundleAdjustmentOptions& options,
                                     std::vector<BundleImage>* images, std::map<int, BundleMarker>* markers);

// The start for BundleAdjust: poses, in turns, the unposed photo that sees the most posed markers
// (SQPnP on their corners, then a robust refinement), and every unposed free marker that a posed
// photo sees (square PnP in each such photo, the candidate that best explains them all), until
// nothing more can be posed. Returns the number of photos posed.
int InitializeByChaining(const Camera& camera, double huber_px, std::vector<BundleImage>* images,
                         std::map<int, BundleMarker>* markers);

// How well one photo's corners determine its pose: the standard deviations of the camera's position
// (metres) and of its rotation (degrees) along their worst directions, from sigma^2 (J^T J)^-1 with J
// the Jacobian of the inlier corners' projections with respect to the camera's centre and rotation
// (the markers taken as exact), for corner noise `pixel_sigma`. Nearly collinear corners, a single
// small marker or far-away markers give large values; degenerate geometry gives infinity.
struct PoseUncertainty {
  double position_sigma_m = 0.0;
  double rotation_sigma_deg = 0.0;
};
PoseUncertainty EstimatePoseUncertainty(const Camera& camera, const BundleImage& image,
                                        const std::map<int, BundleMarker>& markers, double pixel_sigma);

// The planar pose ambiguity (a plane seen nearly fronto-parallel or small in the frame has two poses
// that project it almost alike): when the photo's inlier corners are coplanar, the IPPE solution
// farther from the photo's pose, refined (Huber), and its reprojection RMS; a negative RMS when the
// corners are not coplanar or no second pose exists.
double AlternativePoseRms(const Camera& camera, const BundleImage& image, const std::map<int, BundleMarker>& markers,
                          double huber_px, Rigid3d* alternative);

}  // namespace ibrdf
