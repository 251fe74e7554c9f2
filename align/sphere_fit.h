// A sphere sample's centre and radius from its silhouettes (the paper's section 3.2: the sample's pose
// from the photos). Rays through sub-pixel limb points are tangent to the sphere. Three rounds, each
// extracting limb points in a band around the current estimate's silhouette (wide, then narrow) and
// fitting with a Cauchy loss, so edges of other things (a card behind the limb) do not pull the fit;
// the last round drops points beyond a multiple of the RMS and refits.
//
// Limb points come from both limbs where they can: the lit limb drops to a dark background, an unlit
// limb rises to a brighter one. On a black background only the lit side of the limb is seen, and from
// one side the centre and the radius trade off (moving the centre towards the light and shrinking the
// radius keeps every lit tangent ray tangent). The fit measures that: its covariance (from the
// tangent rays' geometry at the residual RMS) and the radius amplification (how much worse the radius
// is determined than by limb points all around the sphere), and warns when the evidence is one-sided.
// A known radius (SampleSpec::radius_known) removes the trade-off: only the centre is fitted.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/camera.h"
#include "core/image_io.h"
#include "core/rigid3.h"

namespace ibrdf {

// How a limb point is placed once a radial profile's threshold edge has found it (SilhouettePoints):
// the profile around it is fitted by the limb's shading I(d) = a + b sqrt(d) + c d at depth d inside
// the contour (near a contour the normal's component towards the camera grows like sqrt(d), so a lit
// limb darkens steeply to its edge and a threshold sits inside it) and the background's level, both
// seen through a Gaussian blur whose sigma is fitted with the edge (the lens, the pixel's footprint,
// the interpolation): no renderer's or camera's convention is assumed.
struct LimbEdgeOptions {
  bool enabled = true;        // false: the threshold edge (the mid level of the steepest drop) alone
  double inside_px = 8.0;     // the fit's reach inside the first guess, pixels
  double outside_px = 5.0;    // and outside it
  double max_shift_px = 1.5;  // a refined edge further from the first guess is dropped (no model)
  double max_blur_px = 3.0;   // a fitted blur sigma reaching this is dropped (not an edge)
  // Each profile sample is the mean of samples 0.5 px apart along the arc through it about the
  // sphere's projected centre (parallel to the silhouette), this many pixels each side: it averages
  // over the pixel grid's phase along the limb (0: the radial line alone).
  double arc_px = 1.5;
  bool Check(std::string* why) const;
};

// Options of FitSphereToSilhouettes and FitSphereToTangentRays (the defaults are the align stage's).
struct SphereFitOptions {
  int silhouette_lines = 360;         // radial search lines per photo
  double first_band_fraction = 0.15;  // round 1: limb points searched within this fraction of the radius
  double second_band_px = 3.0;        // round 2: within this many pixels of the silhouette
  double final_band_px = 1.5;         // round 3 (with outlier rejection): within this many pixels
  double cauchy_m = 2e-4;             // robust loss scale on ray-to-sphere distances, metres
  double outlier_rms_factor = 3.0;    // the last round drops rays farther than this x RMS and refits
  int min_points = 8;                 // fewer tangent rays: no fit (the sphere stays as given)
  double tolerance = 1e-15;           // Ceres function and parameter tolerance
  bool fix_radius = false;            // keep the start radius (a known radius): fit only the centre
  // Warn (SphereFit::warning) when the radius is fitted from one-sided limb evidence: a limb balance
  // over max_limb_balance (0 all around, 0.5 a uniformly covered hemisphere: the lit limb alone on a
  // black background), where a bias of the lit limb that varies with its brightness (blur, the soft
  // terminator) moves the centre towards the light with nothing on the other side to hold it; or a
  // radius amplification over max_radius_amplification (1 all around, 2 a uniform hemisphere), where
  // the noise alone trades centre against radius.
  double max_limb_balance = 0.3;
  double max_radius_amplification = 3.0;
  LimbEdgeOptions limb_edge;  // the limb point's model (above)
  bool Check(std::string* why) const;
};

// A ray tangent to the sphere: through a camera centre and a silhouette point. World frame.
struct TangentRay {
  Eigen::Vector3d origin;     // the camera centre
  Eigen::Vector3d direction;  // unit
};

// One photo of the sphere: a linear image (radiometry/linear_image.h) and its pose. The image is not owned.
struct SilhouettePhoto {
  const Image* image = nullptr;
  Rigid3d camera_from_world;
};

// What the sphere fit found; reads as not fitted until it ran.
struct SphereFit {
  bool fitted = false;
  std::string reason;  // why not fitted
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double radius = 0.0;
  int silhouette_points = 0;  // tangent rays used
  int rejected_points = 0;    // outliers removed after the first solve
  double rms_m = 0.0;         // RMS of ray-to-sphere distances, metres
  bool radius_fixed = false;  // the radius was kept (known), only the centre fitted
  // Covariance of (centre x, y, z, radius), metres squared: the Gauss-Newton covariance of the inlier
  // tangent rays scaled by their residual variance. Radius row and column zero when radius_fixed.
  Eigen::Matrix4d covariance = Eigen::Matrix4d::Zero();
  // Limb coverage: the length of the mean of the unit vectors from the centre to the tangent points
  // (0: all around, 0.5: a uniformly covered hemisphere, 1: one point), and the radius amplification
  // sqrt(N var(radius)) / RMS the geometry gives a free radius (1: all around; large: one-sided).
  double limb_balance = 0.0;
  double radius_amplification = 0.0;
  Eigen::Vector3d drift_direction = Eigen::Vector3d::Zero();  // the centre's direction of largest variance
  bool one_sided = false;                                     // amplification over the option's bound
  std::string warning;  // non-empty when the radius was fitted from one-sided limb evidence
  // "sphere centre (0.00001, 0.00002, 0.05000) m, radius 0.05000 m from 1234 silhouette points (RMS ...)"
  std::string BriefReport() const;
};

// Silhouette edge points of a sphere (centre `center`, radius `radius`, world frame) in one photo:
// along `lines` radial lines from the sphere's projected centre, within `band_px` of its predicted
// silhouette, the sharpest drop from a lit limb to the dark background (or rise from an unlit limb to a
// brighter one), found where the profile crosses the mid level and refined by the limb's profile
// (LimbEdgeOptions). Edges against anything bright (the platform) or without contrast are skipped.
// Pixels, COLMAP convention.
std::vector<Eigen::Vector2d> SilhouettePoints(const Image& image, const Camera& camera,
                                              const Rigid3d& camera_from_world, const Eigen::Vector3d& center,
                                              double radius, int lines, double band_px,
                                              const LimbEdgeOptions& edge = LimbEdgeOptions());

// The ray through pixel `p` of a camera at `camera_from_world`.
TangentRay RayThroughPixel(const Camera& camera, const Rigid3d& camera_from_world, const Eigen::Vector2d& p);

// One round of the fit: the sphere tangent to `rays` (Cauchy loss), from the start `center`, `radius`.
// With `reject_outliers`, rays beyond options.outlier_rms_factor x RMS are then dropped and the fit
// repeated. Fewer than options.min_points rays: not fitted (the start is returned, with the reason).
SphereFit FitSphereToTangentRays(const std::vector<TangentRay>& rays, const Eigen::Vector3d& center, double radius,
                                 bool reject_outliers, const SphereFitOptions& options);

// The whole fit: three rounds of SilhouettePoints in `photos` and FitSphereToTangentRays, from the
// start `center`, `radius` (the session's). Throws Error for bad options.
SphereFit FitSphereToSilhouettes(const Camera& camera, const std::vector<SilhouettePhoto>& photos,
                                 const Eigen::Vector3d& center, double radius, const SphereFitOptions& options);

}  // namespace ibrdf
