// The options of a synthetic measurement session (synth/synthetic.h), split by concern: the scene
// (sample, light), the camera rig (poses, image, lens), the sensor (CameraEffects), the radiometric
// extras (brackets, an unknown light), the coded targets (align's input) and the simulated range scan
// of an irregular shape. Each has a Check() naming the constraint that failed; SynthOptions::Check
// adds the constraints between them (the camera, light, markers and scanner outside the sample).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/session.h"
#include "synth/synthetic_scan.h"
#include "synth/synthetic_shapes.h"

namespace ibrdf {

// The irregular true shapes synth renders instead of the analytic sphere or cylinder (kNone).
enum class SynthShape { kNone, kSquash, kPot, kDent, IBRDF_DUMMY_KIND };

// "none", "squash", "pot", "dent"; and back (throws Error naming the value otherwise).
const char* SynthShapeName(SynthShape shape);
SynthShape SynthShapeFromName(const std::string& name);

// What is measured and how it is lit: the sample at `origin`, the point light along world +x from it
// (the light and cameras lie in the horizontal plane through it) and an unmodelled fill light.
struct SynthSceneOptions {
  SampleSpec::Kind sample = SampleSpec::Kind::kSphere;  // kSphere or kCylinder (shape kNone)
  double sample_radius = 0.04;                          // metres (the paper's spheres were a few centimetres across)
  // Metres; the axis is vertical (world z), perpendicular to the plane of the light and cameras, so
  // every sample lies within about atan(length / 2 / camera_distance) of its incidence plane (the
  // paper's Figure 4: a short measured strip of a cylinder).
  double cylinder_length = 0.03;
  // Irregular true shapes: kNone renders the analytic `sample` above; the others render the shape
  // (centred at `origin`, resting on the platform, so targets must be on) and write a session whose
  // sample is kind "mesh" measured by a simulated range scanner (SynthScanOptions).
  SynthShape shape = SynthShape::kNone;
  SquashParams squash;                                               // the squash's parameters (shape kSquash)
  PotParams pot;                                                     // the clay pot's (shape kPot)
  DentParams dent;                                                   // the dented sphere's (shape kDent)
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();                  // move the whole scene (far-from-origin tests)
  double light_distance = 1.2;                                       // metres from the sample centre, along world +x
  Eigen::Vector3d light_intensity = Eigen::Vector3d(1.0, 1.0, 1.0);  // RGB
  // A second light the derenderer does not model: irradiance of this fraction of the point light's (at
  // the sample's centre, normal incidence) arriving along every surface point's normal, shadowed or not.
  // A stand-in for room light and interreflections, which reach into self-shadows (the visibility test
  // of the derender issue); 0 = darkness apart from the one light.
  double fill_light = 0.0;

  bool Check(std::string* why) const;
};

// How camera and light move between photos (docs/synth.md). The world frame is the sample's.
enum class SynthRig {
  kArc,        // the paper's: one light along +x, the camera on an arc from beside it to opposite it
  kDome,       // one fixed camera, a light per photo on the upper hemisphere (a light stage or dome)
  kTurntable,  // camera and light fixed in the lab while the sample turns about z: in the sample's
               // frame both turn together, so each photo has its own pose and its own light
};

// "arc", "dome", "turntable"; and back (throws Error naming the value otherwise).
const char* SynthRigName(SynthRig rig);
SynthRig SynthRigFromName(const std::string& name);

// The camera and where it stands: poses on an arc, the image, the lens and the auto-exposure.
struct SynthRigOptions {
  SynthRig rig = SynthRig::kArc;
  double camera_distance = 0.8;  // metres from the sample centre
  double camera_elevation_deg = 0.0;
  int num_photos = 20;
  // Camera azimuths from the light direction, evenly spaced: from beside the light to opposite it.
  // Dome: the angular range of the lights instead, as seen from the sample: lights whose angle from
  // the camera falls outside [arc_start_deg, arc_end_deg] are left out (near the camera they would
  // be in its shadow, nearly opposite it only a rim is lit).
  double arc_start_deg = 8.0;
  double arc_end_deg = 172.0;
  // Dome: num_photos point lights at light_distance, spread evenly over the upper hemisphere (a
  // Fibonacci spiral, equal area) at elevations from dome_min_elevation_deg to 90; the camera fixed
  // along +x at camera_elevation_deg; one photo per light.
  double dome_min_elevation_deg = 5.0;
  // Turntable: the light along +x and the camera at this azimuth from it (both at their elevations),
  // fixed in the lab; the sample turns about the vertical axis through its centre by
  // turntable_span_deg over the photos (360: a full turn, the last photo one step short of the first).
  double turntable_phase_deg = 60.0;
  double turntable_span_deg = 360.0;
  // Arc: more cameras after the arc's num_photos, one at each of these positions (world frame, metres)
  // looking at the sample's centre, image up towards world +z (the photos `ibrdf capture check` suggests).
  std::vector<Eigen::Vector3d> extra_camera_positions;
  // Camera: OPENCV model with the focal length chosen so the sample (or the platform, with targets)
  // spans `frame_fraction` of the shorter image side.
  int width = 800;   // pixels
  int height = 600;  // pixels
  double frame_fraction = 0.7;
  double k1 = -0.08, k2 = 0.02, p1 = 0.0005, p2 = -0.0003;  // OPENCV distortion
  // Auto-exposure: the 99th percentile of the sample's pixels (brightest channel) lands here.
  double exposure_target = 0.8;

  bool Check(std::string* why) const;
};

// Camera positions for SynthRigOptions::extra_camera_positions from a JSON file: a list of [x, y, z]
// (metres, world frame), or a capture-check.json (`ibrdf capture check --out`) whose "suggestions"
// give them. Throws Error naming the file and the entry otherwise.
std::vector<Eigen::Vector3d> ReadCameraPositions(const std::string& path);

// The camera's curve from linear signal to file value.
enum class SensorCurve {
  kLinear,       // file value = signal
  kSrgb,         // the IEC 61966-2-1 sRGB curve
  kToeShoulder,  // a film-like S-curve with a toe and a shoulder (ToeShoulderEncode, synthetic_radiometry.h)
  IBRDF_DUMMY_KIND
};
// "linear", "srgb", "toe-shoulder"; and back (false for any other name).
const char* SensorCurveName(SensorCurve curve);
bool SensorCurveFromName(const std::string& name, SensorCurve* curve);

// What the sensor does to the ideal image. Defaults model a 12-bit camera with shot and read noise.
struct CameraEffects {
  bool shot_noise = true;        // Poisson photon noise on full_well_e electrons at saturation
  bool read_noise = true;        // Gaussian read noise of read_noise_e electrons
  double full_well_e = 20000.0;  // electrons at the saturation level
  double read_noise_e = 4.0;     // electrons, one sigma
  int bits = 12;                 // quantization: 8 to 16 (stored as 8- or 16-bit PNG); 0 = float EXR
  SensorCurve curve = SensorCurve::kLinear;  // applied after clipping, before quantization
  bool clip = true;              // clip at the saturation level (1.0)
  double black_level = 0.0;      // offset added to the linear signal (normalized units)
  int supersample = 1;           // n x n rays per pixel, averaged (1 = the pixel centre only)
  // Vignetting: the fraction of light lost at the image corners (cos^4 law, synthetic_radiometry.h);
  // with it on, the session carries the matching flat-field image. 0 = none.
  double vignetting = 0.0;

  // Every effect off: float EXR of the exact pixel-centre radiance (clipping stays on: a real sensor
  // saturates, and the derenderer rejects what clipped).
  static CameraEffects None();
  bool Check(std::string* why) const;
};

// Exposure brackets and the light's calibration in a synthetic session (synthetic_radiometry.h).
struct SynthRadiometryOptions {
  // Exposures per camera pose: the auto-exposure and brackets - 1 shorter ones, each bracket_step_ev
  // stops below the one before (the highlights a single exposure clips), all with the pose's
  // `bracket` id. 1: no brackets.
  int brackets = 1;
  double bracket_step_ev = 2.0;
  // The session states its response as "unknown" (as a camera's JPEGs leave it) instead of the curve
  // the photos were written with; truth.json keeps the curve. `ibrdf response` measures it from brackets.
  bool response_unknown = false;
  // The session states a unit light intensity (1, 1, 1) instead of the true one and carries a white
  // reference (calibration.white_reference) that recovers it: one photo of a flat target of albedo
  // white_reflectance and side white_size at the sample's centre (the sample taken away), facing
  // between the light and the first camera, from the first camera's pose.
  bool light_unknown = false;
  double white_reflectance = 0.99;
  double white_size = 0.05;  // metres
  // The white-reference photo's exposure relative to its auto-exposure (> 1.25 clips the target).
  double white_exposure_scale = 1.0;

  bool Check(std::string* why) const;
};

// Coded targets (the align stage's input): a dark platform under the sample carrying a ring of ArUco
// markers of known layout, each printed on a white card, lit by the room's ambient light so that every
// photo can read them. The dark platform keeps the sphere's silhouette against black. The frame then
// holds the platform (platform_radius), and cameras should look down on it (camera_elevation_deg > 0).
// Layouts: synth/synthetic_targets.h.
struct SynthTargetOptions {
  bool enabled = false;                    // no platform and no markers when off (the other fields are then unused)
  std::string dictionary = "DICT_4X4_50";  // ArUco dictionary of every marker
  int ring_count = 12;                     // markers on the ring, ids 0 .. ring_count - 1
  double marker_size = 0.028;              // metres, printed side of a ring marker (border included)
  double ring_radius = 0.1;                // metres, sample axis to marker centres
  double platform_radius = 0.135;          // metres
  double card_margin = 0.25;               // white card border around each marker, in marker sides
  double white = 0.55;                     // the cards' white as a fraction of full scale
  double black = 0.02;                     // printed black and the platform, the same way
  // Markers on the light (for the align stage's light estimate): a white card in the vertical plane
  // through the light, facing the sample, with its markers' centres light_card_drop below the light,
  // ids light_marker_first_id on; and light_photos extra photos (role "targets", never derendered) from
  // behind and above the sample, looking past it at the light, that see both the platform's ring (their
  // poses) and the card (the light markers' poses). The placement suits the default scene
  // (light_distance 1.2 m, the default platform); 0 photos (the default): no light markers. 3 photos
  // give the light within 0.3 mm at the default noise.
  int light_photos = 0;
  int light_marker_first_id = 20;
  int light_marker_count = 2;
  double light_marker_size = 0.06;  // metres, printed side (border included)
  double light_card_drop = 0.08;    // metres, light to the markers' centres, straight down
  // The white reference on a card framed by markers (needs radiometry.light_unknown):
  // the card of `ibrdf targets` (align/targets.h WhiteCardLayout: the patch of
  // radiometry.white_size framed by 4 markers of white_marker_size, ids white_marker_first_id ..),
  // printed paper of albedo 0.8 and ink of 0.03 lit by the light like the patch, standing where the
  // sample was (raised so that it clears the platform), seen with the platform in each white-reference
  // photo; the session's targets then carry the card's markers (targets.white_reference) for `ibrdf
  // align` to pose it. Off: the bare patch alone in a black photo.
  bool white_card = false;
  int white_marker_first_id = 40;
  double white_marker_size = 0.02;  // metres, printed side (border included)
  // Markers on a cylinder's top end cap (sample cylinder): their count (0: none), first id, printed
  // side and their centres' distance from the axis (metres).
  int sample_marker_count = 3;
  int sample_marker_first_id = 30;
  double sample_marker_size = 0.018;
  double sample_marker_radius = 0.02;

  // Checks nothing when the targets are off.
  bool Check(std::string* why) const;
};

// The simulated range scan of an irregular shape: scan/view-N.ply range grids in the scanner's own
// frame, the platform markers' corners as the scanner measured them (`scan_targets`), and
// truth-mesh.ply, the true surface in the world frame with exact normals.
struct SynthScanOptions {
  RangeScannerOptions scanner;  // the views, spacing and noise (its seed is SynthOptions::seed)
  // The scanner's frame: p_scan = R p_world + t, R a 35-degree turn about (1, 2, 3) and t of this length
  // along (0.6, -0.48, 0.64) (scanner coordinates are often far from the world's origin).
  double offset_m = 2.0;
  double target_noise_m = 5e-5;        // the scanner's error on each marker-corner coordinate, one sigma
  double truth_mesh_spacing_m = 5e-4;  // truth-mesh.ply: surface sampling at the equator, metres

  bool Check(std::string* why) const;
};

// Colour (synth/synthetic_colour_chart.h): the camera's own RGB and a photo of a colour chart. The
// renderer works in linear sRGB (materials, light intensity); the sensor sees camera RGB =
// camera_matrix * linear sRGB in every photo (measurement, white reference, chart; the platform's
// grey markers are left as they are), and the session states the light's intensity in camera RGB,
// as a calibration of that camera would.
struct SynthColourOptions {
  Eigen::Matrix3d camera_matrix = Eigen::Matrix3d::Identity();  // camera RGB from linear sRGB
  // A photo of a ColorChecker Classic (24 Lambertian patches of the reference linear-sRGB albedo,
  // core/colour.h, on a black card of albedo chart_card_albedo) at the sample's centre (the sample
  // taken away), facing between the light and the first camera, from the first camera's pose, under
  // the first light: the session's colour_chart block, with the corner patches' pixel centres unless
  // chart_corners is off (then `ibrdf colour` must detect the chart).
  bool chart = false;
  bool chart_corners = true;
  double chart_pitch = 0.017;          // metres, patch centre to centre (a ColorChecker Mini's)
  double chart_patch_fraction = 0.85;  // printed patch side / pitch
  double chart_card_albedo = 0.03;     // the card around the patches
  // The chart photo's exposure relative to its auto-exposure (the white patch's brightest channel at
  // exposure_target).
  double chart_exposure_scale = 1.0;
  ColourSpace space = ColourSpace::kLinearSrgb;  // the colour_chart block's target space

  bool Check(std::string* why) const;
};

// What synth does with a sample pixel whose ray looks up a cell without data in a tabulated material
// (a MERL table's negative cells, MERL's "no data"): kSkip renders it black and leaves it out of the
// samples (the photo's mask excludes it: derender counts it as `masked`), kZero renders it black and
// lets derender turn it into zero-valued samples (an invented value: warned), kError refuses the
// material. Materials without such cells never meet it.
enum class SynthNoData { kSkip, kZero, kError };

// "skip", "zero", "error"; and back (throws Error naming the value otherwise).
const char* SynthNoDataName(SynthNoData no_data);
SynthNoData SynthNoDataFromName(const std::string& name);

// Everything a synthetic session is made from. Defaults: a 4 cm sphere, 20 photos of 800 x 600 on an
// arc from 8 to 172 degrees, a 12-bit sensor with noise, no targets.
struct SynthOptions {
  SynthSceneOptions scene;
  SynthRigOptions rig;
  CameraEffects effects;
  SynthRadiometryOptions radiometry;
  SynthTargetOptions targets;
  SynthScanOptions scan;      // used only for an irregular shape (scene.shape != kNone)
  SynthColourOptions colour;  // camera colour matrix and colour-chart photo
  uint64_t seed = 1;          // every random stream (noise, scan) derives from it: output is reproducible
  SynthNoData no_data = SynthNoData::kSkip;  // pixels on a tabulated material's cells without data

  // Each part's Check (the scan's only for an irregular shape; messages start with the part's name, e.g.
  // "rig: num_photos >= 1 failed: num_photos = 0"), then the constraints between parts.
  bool Check(std::string* why) const;
};

}  // namespace ibrdf
