// Synthetic measurement sessions with known truth (COLMAP's scene/synthetic.h in spirit): a forward
// renderer for the analytic sphere and cylinder under one point light, photographed from camera
// positions on an arc from beside the light to opposite it (the paper's Figures 3 and 4), with the
// camera effects of a real sensor that can each be switched off. Irregular true shapes (a squash, a
// clay pot, a dented sphere: derender/synthetic_shapes.h) are rendered exactly, with shadow rays, on
// the target platform, and written as a mesh sample measured by a simulated range scanner (docs/synth.md).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include <Eigen/Core>

#include "core/brdf_model.h"
#include "core/image_io.h"
#include "core/session.h"
#include "derender/synthetic_radiometry.h"
#include "derender/synthetic_shapes.h"
#include "scan/synthetic_scan.h"

namespace ibrdf {

// What the sensor does to the ideal image. Defaults model a 12-bit camera with shot and read noise.
struct CameraEffects {
  bool shot_noise = true;        // Poisson photon noise on full_well_e electrons at saturation
  bool read_noise = true;        // Gaussian read noise of read_noise_e electrons
  double full_well_e = 20000.0;  // electrons at the saturation level
  double read_noise_e = 4.0;     // electrons, one sigma
  int bits = 12;                 // quantization: 8 to 16 (stored as 8- or 16-bit PNG); 0 = float EXR
  bool srgb = false;             // encode with the sRGB curve before quantization
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

struct SynthOptions {
  SampleSpec::Kind sample = SampleSpec::Kind::kSphere;
  double sample_radius = 0.04;  // metres (the paper's spheres were a few centimetres across)
  // Metres; the axis is vertical (world z), perpendicular to the plane of the light and cameras, so
  // every sample lies within about atan(length / 2 / camera_distance) of its incidence plane (the
  // paper's Figure 4: a short measured strip of a cylinder).
  double cylinder_length = 0.03;
  // Scene: the sample at `origin`, the light and cameras in the horizontal plane through it.
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();                  // move the whole scene (far-from-origin tests)
  double light_distance = 1.2;                                       // metres from the sample centre, along world +x
  Eigen::Vector3d light_intensity = Eigen::Vector3d(1.0, 1.0, 1.0);  // RGB
  double camera_distance = 0.8;                                      // metres from the sample centre
  double camera_elevation_deg = 0.0;
  int num_photos = 20;
  // Camera azimuths from the light direction, evenly spaced: from beside the light to opposite it.
  double arc_start_deg = 8.0;
  double arc_end_deg = 172.0;
  // Camera: OPENCV model with the focal length chosen so the sample spans `frame_fraction` of the
  // shorter image side.
  int width = 800;
  int height = 600;
  double frame_fraction = 0.7;
  double k1 = -0.08, k2 = 0.02, p1 = 0.0005, p2 = -0.0003;
  // Auto-exposure: the 99th percentile of the sample's pixels (brightest channel) lands here.
  double exposure_target = 0.8;
  // A second light the derenderer does not model: irradiance of this fraction of the point light's (at
  // the sample's centre, normal incidence) arriving along every surface point's normal, shadowed or not.
  // A stand-in for room light and interreflections, which reach into self-shadows (the visibility test
  // of the derender issue); 0 = darkness apart from the one light.
  double fill_light = 0.0;
  CameraEffects effects;
  // Exposure brackets and an unknown light with its white reference (synthetic_radiometry.h).
  SynthRadiometryOptions radiometry;
  uint64_t seed = 1;

  // Coded targets (the align stage's input): a dark platform under the sample carrying a ring of ArUco
  // markers of known layout, each printed on a white card, lit by the room's ambient light so that every
  // photo can read them. The dark platform keeps the sphere's silhouette against black. The
  // frame then holds the platform (target_frame_radius), and cameras should look down on it
  // (camera_elevation_deg > 0).
  bool targets = false;
  std::string target_dictionary = "DICT_4X4_50";
  int target_count = 12;            // markers on the ring, ids 0 .. target_count - 1
  double target_size = 0.028;       // metres, printed side of a marker (border included)
  double target_ring_radius = 0.1;  // metres, sample axis to marker centres
  double platform_radius = 0.135;   // metres
  double card_margin = 0.25;        // white card border around each marker, in marker sides
  double target_white = 0.55;       // the cards' white as a fraction of full scale
  double target_black = 0.02;       // printed black and the platform, the same way
  // Markers on the light (for the align stage's light estimate): a white card in the vertical plane
  // through the light, facing the sample, with its markers' centres light_card_drop below the light,
  // ids light_marker_first_id on; and light_target_photos extra photos (role "targets", never
  // derendered) from behind and above the sample, looking past it at the light, that see both the
  // platform's ring (their poses) and the card (the light markers' poses). The placement suits the
  // default scene (light_distance 1.2 m, the default platform); 0 photos (the default): no light
  // markers. 3 photos give the light within 0.3 mm at the default noise.
  int light_target_photos = 0;
  int light_marker_first_id = 20;
  int light_marker_count = 2;
  double light_marker_size = 0.06;  // metres, printed side (border included)
  double light_card_drop = 0.08;    // metres, light to the markers' centres, straight down
  // Markers on a cylinder's top end cap (targets on, sample cylinder; derender/synthetic_targets.h):
  // their count (0: none), first id, printed side and their centres' distance from the axis.
  int sample_marker_count = 3;
  int sample_marker_first_id = 30;
  double sample_marker_size = 0.018;
  double sample_marker_radius = 0.02;

  // Irregular true shapes: kNone renders the analytic `sample` above; the others render the shape
  // (centred at `origin`, resting on the platform, so `targets` must be on) and write a session whose
  // sample is kind "mesh": scan/view-N.ply range grids from a simulated scanner in the scanner's own
  // frame, the platform markers' corners as the scanner measured them (`scan_targets`), and
  // truth-mesh.ply, the true surface in the world frame with exact normals.
  enum class Shape { kNone, kSquash, kPot, kDent };
  Shape shape = Shape::kNone;
  SquashParams squash;
  PotParams pot;
  DentParams dent;
  RangeScannerOptions scanner;  // the simulated range scan's views, spacing and noise
  // The scanner's frame: p_scan = R p_world + t, R a 35-degree turn about (1, 2, 3) and t of this length
  // along (0.6, -0.48, 0.64) (scanner coordinates are often far from the world's origin).
  double scan_offset_m = 2.0;
  double scan_target_noise_m = 5e-5;   // the scanner's error on each marker-corner coordinate, one sigma
  double truth_mesh_spacing_m = 5e-4;  // truth-mesh.ply: surface sampling at the equator, metres

  bool Check(std::string* why) const;
};

// "none", "squash", "pot", "dent"; and back (throws Error naming the value otherwise).
const char* SynthShapeName(SynthOptions::Shape shape);
SynthOptions::Shape SynthShapeFromName(const std::string& name);

// The true shape of an irregular-shape session (centred at options.origin); null for kNone.
std::unique_ptr<ImplicitSample> MakeTrueShape(const SynthOptions& options);

// The scanner's frame of an irregular-shape session (see SynthOptions::scan_offset_m).
Rigid3d ScanFromWorld(const SynthOptions& options);

// Renders the ideal (noise-free, unclipped) radiance image of one photo; radiance is 0 off the sample.
// `hit_mask` (optional) gets 1 where the pixel centre sees the sample.
Image RenderRadiance(const Session& session, size_t photo_index, const BrdfModel& material, int supersample,
                     std::vector<uint8_t>* hit_mask);
// The same for a given true shape; with `shadow_rays` a hit is lit only where the segment to the light
// is free of the shape (non-convex truths cast shadows on themselves).
Image RenderRadiance(const Session& session, size_t photo_index, const AnalyticSample& truth, bool shadow_rays,
                     const BrdfModel& material, int supersample, std::vector<uint8_t>* hit_mask);

// The reference markers' corners of a target session (empty when options.targets is off).
std::vector<TargetSpec> TargetLayout(const SynthOptions& options);

// The light's markers of a target session: their world corners (`corners`, optional) and the session's
// description of them (the light's offset in each marker's frame). Empty when there are none.
LightTargetsSpec LightTargetLayout(const SynthOptions& options, std::vector<TargetSpec>* corners);

// Writes a complete session folder: session.json, photos/, and truth.json with the material and the
// generator options. The folder appears only when complete.
struct SynthSummary {
  bool success = false;
  int photos = 0;
  uint64_t saturated_pixels = 0;  // pixels with a clipped channel
  uint64_t shadowed_pixels = 0;   // sample pixels facing the light but in the shape's own shadow
  int scan_views = 0;             // irregular shapes: range grids written
  uint64_t scan_points = 0;       // their points
  double total_s = 0.0;
  std::string BriefReport() const;
};
SynthSummary WriteSyntheticSession(const SynthOptions& options, const BrdfModel& material,
                                   const std::string& material_name, const std::string& out_dir, bool overwrite);

}  // namespace ibrdf
