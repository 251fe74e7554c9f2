// Light directions from photos of a mirror (chrome) sphere: the classic light-probe calibration of
// photometric stereo and light stages. A small light shows on the sphere as one bright highlight; the
// sphere's normal there bisects the view ray and the direction to the light (the law of reflection),
// so L = v_r - 2 (n . v_r) n with v_r the camera ray through the highlight and n the normal where it
// meets the sphere. Three image measurements: the sphere's silhouette (its centre and apparent size,
// from a mask, fitted as the cone of rays tangent to the sphere), the highlight (located to sub-pixel
// accuracy as an intensity-weighted centroid), and the known radius (which sets the scale, needed only
// for point lights). Each direction carries a 1-sigma uncertainty: the highlight's and the silhouette's
// localization errors propagated through the reflection (docs/align.md, "Light calibration").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/camera.h"
#include "core/image_io.h"

namespace ibrdf {

// A usable-pixel mask: non-zero = usable (a session's mask image, any channel count).
struct PixelMask {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> usable;  // row-major, 1 = usable
  bool at(int x, int y) const { return usable[size_t(y) * width + x] != 0; }
};

// Reads a mask image (non-zero in any channel = usable); throws Error naming the file when it cannot be
// read or its size is not width x height.
PixelMask ReadPixelMask(const std::string& path, int width, int height);

// Options of FitSphereSilhouette.
struct SilhouetteFitOptions {
  int max_iterations = 50;             // Gauss-Newton iterations of the cone fit
  double outlier_px = 1.5;             // after the first fit, edge points farther than this are dropped
  double outlier_rms_factor = 3.0;     // ... or farther than this x RMS, whichever is larger
  int min_points = 20;                 // fewer edge points: not fitted
  bool Check(std::string* why) const;  // false, and why, for impossible values
};

// The sphere seen in one camera: the cone of rays tangent to it. Camera frame (x right, y down, z
// forward, core/camera.h). Reads as not fitted until a fit ran.
struct SphereSilhouette {
  bool fitted = false;
  std::string reason;                               // why not fitted
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  // unit ray through the sphere's centre
  double half_angle = 0.0;                          // radians: sin(half_angle) = radius / distance
  // Covariance of (axis_x / axis_z, axis_y / axis_z, half_angle) from the fit's residuals (radians^2).
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  Eigen::Vector2d center_px = Eigen::Vector2d::Zero();  // the axis projected, pixels (COLMAP convention)
  double radius_px = 0.0;                               // apparent radius along x, pixels
  int points = 0;                                       // edge points used
  int rejected = 0;                                     // edge points dropped as outliers
  double rms_px = 0.0;                                  // RMS distance of the edge points to the fit, pixels
  // The sphere's centre in the camera frame for a sphere of `radius` metres.
  Eigen::Vector3d CenterInCamera(double radius) const;
  // The silhouette of a sphere of known centre (camera frame, metres) and radius: exact, zero covariance.
  static SphereSilhouette FromCenter(const Camera& camera, const Eigen::Vector3d& center_in_camera, double radius);
  // "silhouette: centre (253.52, 148.03) px, radius 119.61 px from 742 edge points (RMS 0.31 px)"
  std::string BriefReport() const;
};

// Sub-pixel edge points of a mask: where the mask (as 0/1) crosses 1/2 between horizontally or
// vertically adjacent pixel centres, i.e. on the shared pixel border. Pixels, COLMAP convention.
std::vector<Eigen::Vector2d> MaskEdgePoints(const PixelMask& mask);

// Fits the cone of rays tangent to a sphere to silhouette points (pixels): an algebraic circle for the
// start, then Gauss-Newton on the angle between each point's ray and the cone, an outlier pass, and a
// refit. Exact for any camera model with a single centre of projection (the rays are undistorted);
// the silhouette of an off-axis sphere is an ellipse, which the cone handles.
SphereSilhouette FitSphereSilhouette(const Camera& camera, const std::vector<Eigen::Vector2d>& edge_points,
                                     const SilhouetteFitOptions& options = SilhouetteFitOptions());

// Options of LocateHighlight.
struct HighlightOptions {
  // Pixels brighter than this fraction of the peak, connected to it, form the highlight blob; each is
  // weighted by its brightness above that level (intensity-weighted centroid).
  double blob_fraction = 0.25;
  // The core: blob pixels at or above this fraction of the peak (the saturated core of a clipped
  // highlight); its unweighted centroid is compared with the weighted one.
  double core_fraction = 0.9;
  // Pixels within this distance of the silhouette are not searched (the rim's mixed pixels).
  double rim_margin_px = 2.0;
  // One-sigma noise of a pixel's brightness relative to the peak (8-bit quantization and shot noise):
  // gives the centroid's statistical error.
  double relative_noise = 0.01;
  // Floor of the localization uncertainty, pixels (the centroid's bias on a finite, clipped blob).
  double min_sigma_px = 0.05;
  // A second bright spot on the sphere (outside the blob) brighter than this fraction of the peak makes
  // the highlight ambiguous: refused.
  double max_second_peak = 0.6;
  // The blob may not exceed this many pixels (a lamp too close, or no highlight at all).
  int max_blob_pixels = 20000;
  bool Check(std::string* why) const;  // false, and why, for impossible values
};

// A highlight located in one photo. Reads as not found until located.
struct Highlight {
  bool found = false;
  std::string reason;                               // why not found
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // intensity-weighted centroid, pixels (COLMAP)
  Eigen::Vector2d core = Eigen::Vector2d::Zero();   // centroid of the core, pixels
  double sigma_px = 0.0;                            // one-sigma localization error per axis, pixels
  double peak = 0.0;                                // brightest pixel (mean of channels), image units
  int blob_pixels = 0;                              // pixels in the blob
  int core_pixels = 0;                              // pixels in the core
  double second_peak = 0.0;                         // the brightest spot outside the blob, relative to peak
  // "highlight (285.65, 118.31) px +- 0.12 px, 77 px blob, 12 px core"
  std::string BriefReport() const;
};

// Finds the sphere's brightest spot inside its silhouette (shrunk by rim_margin_px) and the mask: the
// 8-connected blob above blob_fraction x peak around the brightest pixel, its centroid weighted by
// (value - level). The uncertainty combines the centroid's statistical error (relative_noise) with half
// the distance between the weighted centroid and the core's centroid (an asymmetric blob, e.g. a
// streak or a reflection beside the highlight, moves them apart), floored at min_sigma_px.
Highlight LocateHighlight(const Image& image, const SphereSilhouette& sphere, const PixelMask* mask,
                          const HighlightOptions& options = HighlightOptions());

// The direction to a light (camera frame, unit) reflected at the sphere where the ray through `pixel`
// meets it, and that surface point (camera frame, metres, for a sphere of `radius`). False when the
// ray misses the sphere.
bool ReflectedDirection(const Camera& camera, const SphereSilhouette& sphere, double radius,
                        const Eigen::Vector2d& pixel, Eigen::Vector3d* direction, Eigen::Vector3d* surface_point);

// One light's direction from one photo, with its uncertainty. Camera frame.
struct MirrorDirection {
  bool valid = false;
  std::string reason;                                       // why not valid
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();     // unit, towards the light, camera frame
  Eigen::Vector3d surface_point = Eigen::Vector3d::Zero();  // where the highlight is, camera frame, metres
  // Covariance of the direction (3 x 3, rank 2, radians^2): the highlight's sigma_px and the
  // silhouette's covariance propagated by the Jacobian of ReflectedDirection.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  double sigma_deg = 0.0;                 // one-sigma angular uncertainty, sqrt(trace(covariance)), degrees
  double sigma_from_highlight_deg = 0.0;  // the part from the highlight alone
};

// The direction of the highlight's light. A silhouette from FromCenter (a known sphere) has zero
// covariance, so only the highlight's error counts.
MirrorDirection DirectionFromHighlight(const Camera& camera, const SphereSilhouette& sphere, double radius,
                                       const Highlight& highlight);

// The point closest, in least squares, to rays (origin, unit direction) with one-sigma angular errors
// `sigma_rad`; its covariance in `covariance` (metres^2). False when fewer than two rays or they are
// (nearly) parallel.
bool TriangulateRays(const std::vector<Eigen::Vector3d>& origins, const std::vector<Eigen::Vector3d>& directions,
                     const std::vector<double>& sigma_rad, Eigen::Vector3d* point, Eigen::Matrix3d* covariance);

}  // namespace ibrdf
