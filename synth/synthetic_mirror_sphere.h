// Synthetic photos of a mirror (chrome) sphere under N known lights from a fixed camera: the input of
// `ibrdf lights calibrate` (calibrate/light_rig.h) with its truth, so the calibration is
// measured against known directions. Each light is a small source with a Gaussian angular profile
// (bright enough to clip its core, as a real highlight does), reflected by a sphere of given
// reflectance in a dim uniform environment; the camera adds shot and read noise and stores 8-bit PNGs
// with a linear response. The session (version 2) lists the lights with their true directions as the
// nominal ones, a default mask (the sphere's silhouette, pixel centres inside it) and one photo per
// light; truth-lights.json repeats the lights (docs/synth.md, "Mirror sphere").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/camera.h"
#include "core/light.h"
#include "core/rigid3.h"

namespace ibrdf {

struct SyntheticMirrorSphereOptions {
  int width = 640;           // pixels
  int height = 480;          // pixels
  double focal_px = 3000.0;  // PINHOLE focal length, pixels (principal point at the centre)
  double distance = 0.75;    // camera centre to the world origin, metres (the camera looks at it)
  double radius = 0.025;     // the sphere's radius, metres
  // The sphere's centre, world frame (x right, y up, z towards the camera), metres: off the optical
  // axis by default, so its silhouette is an ellipse.
  Eigen::Vector3d center = Eigen::Vector3d(0.006, -0.004, 0.0);
  int lights = 12;                     // number of lights
  double max_light_angle_deg = 60.0;   // lights lie within this angle of the direction to the camera
  bool point_lights = false;           // point lights at light_distance from the origin instead of directional
  double light_distance = 1.0;         // metres, point lights only
  double source_sigma_deg = 2.0;       // the source's angular profile, one sigma, degrees (as seen from the sphere)
  double source_peak = 20.0;           // the source's peak radiance relative to the camera's saturation
  double reflectance = 0.6;            // the mirror's reflectance (chrome)
  double environment = 0.03;           // radiance of the uniform environment the sphere reflects
  double background = 0.01;            // radiance of the background behind the sphere
  int supersampling = 4;               // rays per pixel along each axis
  double read_noise = 0.002;           // one sigma, fraction of full scale
  double full_well_e = 20000.0;        // electrons at saturation (shot noise)
  uint64_t seed = 1;                   // noise and light directions
  bool Check(std::string* why) const;  // false, and why, for impossible values
};

// What was written: the truth.
struct SyntheticMirrorSphere {
  Camera camera;
  Rigid3d camera_from_world;
  std::vector<Light> lights;     // the true lights, intensity 1
  std::vector<std::string> ids;  // their ids in the session: L00, L01, ...
  std::string manifest;          // the session.json written
  // "mirror sphere: 12 directional lights, 640 x 480, radius 118.2 px -> /tmp/m"
  std::string BriefReport() const;
};

// Renders the photos, the mask, session.json and truth-lights.json into `out_dir` (created; an existing
// folder is replaced only with `overwrite`; the folder appears only when complete). Throws Error for bad
// options or an existing folder.
SyntheticMirrorSphere WriteSyntheticMirrorSphere(const SyntheticMirrorSphereOptions& options,
                                                 const std::string& out_dir, bool overwrite);

}  // namespace ibrdf
