// The lights of a multi-light rig (a dome, a light stage) calibrated from photos of a mirror sphere,
// the light probe (`ibrdf lights calibrate`, docs/align.md "Light calibration"). The input is a session
// (version 2) whose sample is the chrome sphere and whose photos each name their light: the lights'
// stated directions or positions are taken as nominal (a rig's design values) and only compared with
// what the calibration finds. Per light: the highlight in its photo (calibrate/mirror_sphere.h), the law of
// reflection gives its direction; a directional light keeps it, a point light needs two sphere
// placements (two sessions, the rays from both highlights triangulated) or a known distance from the
// sphere's centre. Intensities come from a diffuse reference (calibrate/diffuse_sphere_intensity.h) or
// stay relative (1); the sidecar says which.
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

struct LightProbeOptions {
  // The sphere's centre and apparent size from its mask's silhouette (the session's mask, per photo
  // or default); false: the session's sample centre and radius are taken as exact.
  bool fit_silhouette = true;
  // "directional" or "point": what each light becomes.
  std::string kind = "directional";
  // Point lights from a single placement: the light's distance from the sphere's centre, metres (0:
  // not given; then point lights need two placements).
  double light_distance = 0.0;
  // A light whose direction is less certain than this (one sigma, degrees) is reported as uncertain.
  double warn_sigma_deg = 0.5;
  SilhouetteFitOptions silhouette;
  HighlightOptions highlight;
  bool Check(std::string* why) const;  // false, and why, for impossible values
};

// One light as calibrated.
struct CalibratedLight {
  Light light;                            // id, kind, direction (unit, world) or position (metres, world); intensity
  int photos = 0;                         // highlights used (over all placements)
  double sigma_deg = 0.0;                 // one-sigma uncertainty of the direction, degrees (highlight + silhouette)
  double sigma_from_highlight_deg = 0.0;  // the highlight's part alone
  double position_sigma_m = 0.0;          // point lights: one-sigma uncertainty of the position, metres
  std::vector<Highlight> highlights;      // per photo used, in order
  std::vector<std::string> files;         // the photos used
  // The session's stated (nominal) light, for comparison; the angle between its direction and the
  // calibrated one (for point lights, as seen from the first sphere's centre), degrees.
  Light nominal;
  double angle_from_nominal_deg = 0.0;
  double position_from_nominal_m = 0.0;  // point lights: distance between nominal and calibrated
};

// What the calibration found; reads as failed until it ran.
struct LightProbeCalibration {
  bool success = false;
  std::vector<SphereSilhouette> silhouettes;  // one per placement
  std::vector<Eigen::Vector3d> centers;       // the sphere's centre per placement, world frame, metres
  std::vector<CalibratedLight> lights;        // in the first session's order
  double median_sigma_deg = 0.0;
  double max_sigma_deg = 0.0;
  double median_angle_from_nominal_deg = 0.0;
  double max_angle_from_nominal_deg = 0.0;
  // How the intensities were set: "relative" (all 1: ratios unknown), "relative (diffuse sphere)",
  // "absolute (diffuse sphere of albedo ...)"; filled by whoever sets them.
  std::string intensity_reference = "relative";
  double total_s = 0.0;
  // "light probe: 12 directional lights from 1 placement, sigma median 0.05 / max 0.09 deg; from the
  // nominal: median 2.3 / max 8.8 deg"
  std::string BriefReport() const;
  // {"lights": [...]} in the session format's version-2 schema (id, kind, direction or position,
  // intensity): ready for a session's "lights".
  nlohmann::json LightsJson() const;
  // Everything else: per light its uncertainty, highlight(s), nominal comparison; the silhouettes; the
  // intensity reference.
  nlohmann::json ReportJson() const;
};

// Calibrates the lights named by the photos of `placements` (sessions of one mirror sphere, each at
// its own place: one for directional lights). Every light of the first session must have a photo in
// it. Throws Error naming the manifest (and the photo) for: a sample that is not a sphere, a photo
// without a pose, no mask while fitting the silhouette, a silhouette that does not fit, a light without
// a highlight, point lights from one placement without a distance, or lights whose rays do not meet.
LightProbeCalibration CalibrateLightProbe(const std::vector<Session>& placements,
                                          const LightProbeOptions& options = LightProbeOptions());

}  // namespace ibrdf
