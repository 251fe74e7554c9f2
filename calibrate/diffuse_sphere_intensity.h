// Light intensities from a diffuse reference sphere photographed under each light of a calibrated rig
// (`ibrdf lights calibrate --diffuse`, docs/align.md "Light calibration"). A Lambertian sphere of
// albedo rho reflects L = rho / pi * E with E = I cos(theta_i) (directional; I cos(theta_i) / r^2 for a
// point light), so every pixel gives I = pi L / (rho cos(theta_i)); the median over the sphere's
// well-lit, well-seen pixels is the light's intensity in the session's radiance unit. Without a known
// albedo the intensities are relative (their mean is 1): the ratios between lights are right, the
// absolute scale, and so the BRDF's, is not; the report says so. The same pixels test the camera's
// response: on a Lambertian sphere the linear signal falls off as cos(theta_i), so the fitted exponent
// of signal ~ cos(theta_i)^k is 1 for a linear response (about 1 / 2.2 for an sRGB-encoded one), and
// the per-pixel spread compares the calibrated directions with the session's nominal ones.
// (calibrate/white_reference_intensity.h is the flat white reference for the single light of version-1 sessions.)
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "calibrate/mirror_sphere.h"
#include "core/light.h"
#include "core/session.h"

namespace ibrdf {

struct DiffuseSphereOptions {
  // The sphere's centre and apparent size from its mask's silhouette; false: the session's sample
  // centre and radius are exact.
  bool fit_silhouette = true;
  double max_theta_i_deg = 70.0;  // pixels lit more obliquely are not used (degrees)
  double max_theta_e_deg = 70.0;  // pixels seen more obliquely are not used (degrees)
  // Linear signal floor (normalized file units, darkest channel): below it, 8-bit quantization and
  // the black level dominate.
  double min_signal = 0.02;
  double rim_margin_px = 3.0;  // pixels this close to the silhouette are not used
  int min_pixels = 200;        // usable pixels a light needs
  SilhouetteFitOptions silhouette;
  bool Check(std::string* why) const;  // false, and why, for impossible values
};

// One light's intensity as the diffuse sphere measured it.
struct DiffuseLightIntensity {
  std::string id;
  Eigen::Vector3d intensity = Eigen::Vector3d::Zero();  // RGB, session radiance unit (relative: mean 1)
  // Per channel, 1.4826 MAD / median of the per-pixel estimates with the calibrated direction, and
  // with the session's nominal one: a wrong direction tilts the cosine and widens the spread.
  Eigen::Vector3d spread = Eigen::Vector3d::Zero();
  Eigen::Vector3d nominal_spread = Eigen::Vector3d::Zero();
  double cosine_exponent = 0.0;  // k of signal ~ cos(theta_i)^k over the pixels used (1: linear response)
  int pixels = 0;                // pixels used
  int saturated = 0;             // pixels refused as clipped
};

// What the diffuse reference gave; reads as failed until it ran.
struct DiffuseSphereIntensities {
  bool success = false;
  bool absolute = false;  // an albedo was given; false: relative intensities (mean 1)
  Eigen::Vector3d albedo = Eigen::Vector3d::Ones();
  SphereSilhouette silhouette;                       // of the first photo's mask (or the known sphere)
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // the diffuse sphere's centre, world frame, metres
  std::vector<DiffuseLightIntensity> lights;         // in the order of the `lights` given
  double median_cosine_exponent = 0.0;
  double median_spread = 0.0;          // over lights, of the mean channel spread, calibrated directions
  double median_nominal_spread = 0.0;  // ... with the session's nominal directions
  // "diffuse sphere: 12 lights, relative intensities (no albedo), 31,400 pixels; cosine exponent 1.01
  // (linear response); spread 4.1 % (calibrated directions) / 6.3 % (nominal)"
  std::string BriefReport() const;
  // The figures above, per light.
  nlohmann::json ToJson() const;
};

// Measures the intensity of each light in `lights` (calibrated: id, kind, direction or position) from
// the photos of `diffuse`, a session whose sample is the diffuse sphere and whose photos name those
// lights by id, and writes it into `lights`. `albedo`: the sphere's Lambertian albedo per channel; none:
// relative intensities. Throws Error naming the manifest or photo for a sample that is not a sphere, a
// photo without a pose, a light with no photo or a photo of an unknown light, no mask while fitting the
// silhouette, or too few usable pixels.
DiffuseSphereIntensities MeasureDiffuseSphereIntensities(const Session& diffuse, std::vector<Light>* lights,
                                                         const std::optional<Eigen::Vector3d>& albedo,
                                                         const DiffuseSphereOptions& options = DiffuseSphereOptions());

}  // namespace ibrdf
