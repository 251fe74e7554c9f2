// A measurement session: a folder with a JSON manifest (session.json) that names the photos, the
// camera, the light, the sample and the radiometric settings. The format is documented in
// docs/session-format.md; lengths are metres, angles radians unless a key says _deg.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "core/camera.h"
#include "core/colour.h"
#include "core/kind.h"
#include "core/light.h"
#include "core/radiometry.h"
#include "core/rigid3.h"

namespace ibrdf {

// The camera's noise model, used to give each sample an uncertainty (shot and read noise, and the
// quantization step of the stored file).
struct CameraNoise {
  double full_well_e = 0.0;   // electrons at the saturation level
  double read_noise_e = 0.0;  // electrons, one sigma
  int bits = 0;               // quantization of the stored values; 0 for floating-point files
};

struct RadiometrySpec {
  Response response;              // file value -> linear signal
  double black_level = 0.0;       // linear signal of a dark pixel, subtracted (normalized file units)
  double saturation_level = 1.0;  // file value at which a channel is clipped (normalized file units)
  // The manifest states saturation_level. When it does not, integer photos clip at 1.0 (full scale)
  // and floating-point photos (EXR, float TIFF) have no saturation (SaturationLevel, linear_image.h).
  bool saturation_stated = false;
  std::optional<CameraNoise> noise;
  // Optional flat-field image (relative to the session folder): the camera's relative sensitivity per
  // pixel (vignetting x pixel response), linear, 1 where exposure and gain alone are right (normally
  // the image centre). Radiance is divided by it. Empty: no flat field.
  std::string flat_field;
  // The lights' intensities are known only up to one common scale ("intensity_scale": "relative"):
  // ratios measured (a diffuse sphere of unknown albedo), the scale not. Every BRDF value downstream is
  // then relative too, and every output says so; false: absolute ("absolute", the default).
  bool relative_intensities = false;
};

// One raw range scan of a mesh sample (what `ibrdf scan` merges into the sample's mesh file); also the
// input type of the scan stage (scan/scan_pipeline.h), where `file` is resolved.
struct ScanInputSpec {
  std::string file;                        // relative to the session folder (or absolute)
  std::optional<Rigid3d> world_from_scan;  // into the mesh's (scan) frame; identity when absent
};

// A marker measured by the range scanner: its four corners in the scan (mesh) frame, in the order of
// targets.reference (top-left, top-right, bottom-right, bottom-left of the print).
struct ScanTargetSpec {
  int id = -1;
  std::array<Eigen::Vector3d, 4> corners;  // scan frame, the mesh file's units
};

// When the mesh derenderer traces shadow rays (docs/derender.md).
enum class Visibility {
  kAuto,  // only where the mesh's convexity report (scan/convexity.h) says needs_shadow_rays
  kOn,    // always
  kOff,   // never
  IBRDF_DUMMY_KIND
};

struct SampleSpec {
  enum class Kind { kSphere, kCylinder, kMesh, IBRDF_DUMMY_KIND };
  Kind kind = Kind::kSphere;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // sphere centre; cylinder axis midpoint
  double radius = 0.0;                               // sphere and cylinder, metres
  // Sphere: the radius is known (a ball bearing's gauge, measured with callipers); the align stage's
  // sphere fit keeps it and fits only the centre (JSON "radius_known", default false).
  bool radius_known = false;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();   // cylinder axis, unit
  double length = 0.0;                               // cylinder length along the axis, metres
  // Mesh samples. The file need not exist when the session is read (the scan stage may write it).
  std::string mesh_file;                     // the scan stage's PLY, relative to the session folder
  Sim3d world_from_mesh;                     // p_world = s R p_mesh + t; identity when absent
  std::vector<ScanInputSpec> scan_inputs;    // raw scans merged into mesh_file (kept, not read)
  std::vector<ScanTargetSpec> scan_targets;  // markers seen by the scanner, mesh frame
  Visibility visibility = Visibility::kAuto;
};

// Coded targets (ArUco markers) seen in the photos. Reference markers have a known layout: their four
// corners in the world frame, in OpenCV's order (top-left, top-right, bottom-right, bottom-left of the
// print). The world frame of an aligned session is the reference structure's.
struct TargetSpec {
  int id = -1;
  std::array<Eigen::Vector3d, 4> corners;  // metres, world frame
};

// A marker attached to the light: its pose is estimated from the photos, and the light lies at
// `light_in_marker` in the marker's own frame (origin at the printed square's centre, x to the right
// and y down the print, +z into the print; see align/markers.h).
struct LightMarkerSpec {
  int id = -1;
  Eigen::Vector3d light_in_marker = Eigen::Vector3d::Zero();  // metres, marker frame
};

// The markers on the light (the paper's section 3.2: the light's position from targets on it).
struct LightTargetsSpec {
  size_t light = 0;                      // the light they sit on: an index into Session::lights
  double size = 0.0;                     // metres, printed side of every light marker (border included)
  std::vector<LightMarkerSpec> markers;  // at least one
};

// Markers whose layout is unknown (align/bundle_adjustment.h): each a rigid printed square of side
// `size` whose pose the bundle adjustment estimates. Without known-layout markers, marker `origin_id`
// fixes the gauge: the world frame has its origin at that marker's centre, x to the right of the print,
// y up the print, z out of the print (up, for a marker lying face-up); the scale comes from `size`.
struct UnknownLayoutSpec {
  double size = 0.0;  // metres, printed side (border included)
  std::vector<int> ids;
  std::optional<int> origin_id;  // required when `reference` is empty, not allowed otherwise
};

// Markers fixed to the sample (a cylinder's end cap): their corners in the sample's own frame (origin
// at the cylinder's centre, z along its axis), in OpenCV's order. Their world corners come from the
// bundle adjustment; the rigid fit of the two gives the cylinder's centre and axis (align/cylinder_fit.h).
struct SampleTargetsSpec {
  std::vector<TargetSpec> markers;  // corners in the sample frame, metres; each a square
};

// Markers on the white reference's card: their corners in the card's own frame
// (origin at the white patch's centre on its surface, x to the right and y up the print, z out of the
// patch: its normal), in OpenCV's order. `ibrdf align` poses the card from them and writes the
// white reference's centre and normal (align/white_reference_pose.h).
struct WhiteReferenceTargetsSpec {
  std::vector<TargetSpec> markers;  // corners in the card frame, metres; each a square
};

struct TargetsSpec {
  std::string dictionary;                           // OpenCV predefined dictionary name, e.g. "DICT_4X4_50"
  std::vector<TargetSpec> reference;                // markers with known layout (may be empty with unknown_layout)
  std::optional<UnknownLayoutSpec> unknown_layout;  // markers of unknown layout, if any
  std::optional<LightTargetsSpec> light;            // markers on the light, if any
  std::optional<SampleTargetsSpec> sample;          // markers on the sample, if any
  std::optional<WhiteReferenceTargetsSpec> white_reference;  // markers on the white reference's card, if any
};

// What a photo is for: measurement photos are derendered; target photos only serve the alignment
// (e.g. views of the light's markers, which lie outside the measurement photos' field of view).
enum class PhotoRole { kMeasurement, kTargets };

struct PhotoSpec {
  std::string file;                          // relative to the session folder
  double exposure_s = 1.0;                   // exposure time, seconds
  double gain = 1.0;                         // linear gain relative to the base ISO
  std::optional<Rigid3d> camera_from_world;  // known pose, if any
  PhotoRole role = PhotoRole::kMeasurement;
  // Exposure bracket: measurement photos with the same bracket id are exposures of one pose under one
  // light, merged into one high-dynamic-range radiance image (radiometry/radiance_image.h). Absent:
  // photos with identical poses and the same light still form one bracket.
  std::optional<int> bracket;
  // The light the photo was taken under: an index into Session::lights (the manifest names it by id).
  size_t light = 0;
  // Optional mask image (relative to the session folder): non-zero pixels are usable, zero pixels are
  // never sampled. Empty: the session's default mask (Session::mask), if any.
  std::string mask;
};

// A white reference (the paper's Spectralon step): a flat Lambertian target of known reflectance at a
// known pose, photographed under the session's light; it gives the light's RGB intensity in the
// session's radiance unit (calibrate/white_reference_intensity.h, `ibrdf lights white`, before derender).
struct WhiteReferenceSpec {
  Eigen::Vector3d reflectance = Eigen::Vector3d::Constant(0.99);  // Lambertian albedo per channel
  Eigen::Vector3d center = Eigen::Vector3d::Zero();               // the target's centre, world frame, metres
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();              // its front face's normal (unit), world frame
  double size = 0.0;              // metres: the side of a square target or the diameter of a round one
  std::vector<PhotoSpec> photos;  // each with a camera_from_world pose (`ibrdf align` poses them)
  // Whether center and normal are known: stated in the manifest or written by `ibrdf align` from the
  // card's markers (targets.white_reference). A manifest may leave them out only when its targets
  // block has the card's markers; the light calibration refuses an unposed white reference.
  bool posed = true;
};

// Radiometric calibration steps that change the session's stated values.
struct CalibrationSpec {
  std::optional<WhiteReferenceSpec> white_reference;
};

// One patch of a colour chart fit (ColourChartSpec::patches): its relative residual, or why the fit
// left it out.
struct ColourPatchFit {
  std::string name;       // the patch's name (ColorCheckerPatchNames)
  double residual = 0.0;  // |M c - r| / |r| of the fitted matrix M, camera RGB c and reference r; used patches
  std::string excluded;   // why it was left out ("clipped", "too dark", ...); empty: used in the fit
};

// An optional colour chart (docs/session-format.md, "colour_chart"): photos of a ColorChecker under
// one of the session's lights, read through the same radiometric chain as the measurement photos.
// `ibrdf colour` locates the chart (OpenCV's mcc detector, or the four corner patches given here),
// fits a 3x3 matrix from camera RGB to `space` and writes it back as `matrix` with the per-patch fit;
// the derenderer then applies it to every sample (derender/colour_correction.h).
struct ColourChartSpec {
  std::string chart = kColorCheckerClassic24;    // the chart type (the only one for now)
  ColourSpace space = ColourSpace::kLinearSrgb;  // what the samples are corrected into
  // The exposures of one view of the chart (one photo, or a bracket merged like the measurement
  // photos'), all under the same light and from the same place; no pose needed.
  std::vector<PhotoSpec> photos;
  // Optional: the pixel positions (docs/conventions.md) of the centres of patches 1 (dark skin),
  // 6 (bluish green), 24 (black) and 19 (white), in that order (the chart's top-left, top-right,
  // bottom-right and bottom-left patch). Absent: the chart is detected (OpenCV mcc).
  std::optional<std::array<Eigen::Vector2d, 4>> corners;
  // Written by `ibrdf colour`: the fitted matrix, space_from_camera (least squares over the used
  // patches, on camera RGB radiance of the chart), and each patch's fit. Absent: not yet fitted.
  std::optional<Eigen::Matrix3d> matrix;
  std::vector<ColourPatchFit> patches;
};

// A stage that writes a session from a session (docs/session-format.md, "stages_applied").
enum class SessionStage {
  kScan,    // `ibrdf scan --session` (in `ibrdf run`): the raw scans merged into the mesh
  kAlign,   // `ibrdf align`: poses from the targets (and the light, the sample, the mesh registration)
  kLights,  // `ibrdf lights white` / `ibrdf lights calibrate`: the lights measured
  kColour,  // `ibrdf colour`: the colour chart's matrix fitted
  kResponse,  // `ibrdf response`: the camera's response curve measured from exposure brackets
  IBRDF_DUMMY_KIND
};
// "scan", "align", "lights", "colour", "response"; and back (false for any other name).
const char* SessionStageName(SessionStage stage);
bool SessionStageFromName(const std::string& name, SessionStage* stage);

struct Session {
  std::string name;
  std::string description;    // free text, optional
  std::string directory;      // folder holding the manifest; relative paths resolve against it
  std::string manifest_path;  // the manifest file
  Camera camera;
  // The lights, at least one; each photo names its own (PhotoSpec::light). A version-1 manifest (or a
  // version-2 one with the single `light` shorthand) has exactly one, with an empty id.
  std::vector<Light> lights{Light()};
  // The default mask of every measurement photo without its own (PhotoSpec::mask); empty: none.
  std::string mask;
  SampleSpec sample;
  RadiometrySpec radiometry;
  std::vector<PhotoSpec> photos;
  std::optional<TargetsSpec> targets;
  std::optional<CalibrationSpec> calibration;
  std::optional<ColourChartSpec> colour_chart;  // a colour chart, if any
  // The calibration stages that wrote this session, in order (SessionStage): `ibrdf run` resumes such
  // a session instead of repeating them (an aligned session is not aligned again).
  std::vector<SessionStage> stages_applied;
  // Whether `stage` is among stages_applied.
  bool Applied(SessionStage stage) const;
  // Appends `stage` to stages_applied unless it is there already.
  void MarkApplied(SessionStage stage);

  // Reads and validates a manifest (a session.json path, or a folder holding session.json). Unknown
  // keys, missing fields, wrong types, missing photo files and impossible values are Errors naming the
  // manifest and the field's JSON pointer.
  static Session Load(const std::string& path);

  // The manifest as JSON (round-trips through Load).
  nlohmann::json ToJson() const;
  // Writes the manifest to `path` atomically.
  void Save(const std::string& path) const;

  // How SaveRebased and Rebased write the manifest's path fields.
  enum class PathStyle {
    kRelative,  // relative to the new folder (absolute only where no relative path exists)
    kAbsolute,  // absolute, normalized
  };
  // A copy of the session whose manifest lives in folder `dir`: `directory` and `manifest_path` name
  // `dir` and `dir`/session.json, and every path field (photos, the flat field, the white-reference
  // photos, the mesh file, the raw scans) is rewritten, field by field, to name the same file from
  // there. For a caller that writes the manifest elsewhere first (e.g. into a temporary folder that
  // becomes `dir`): `session.Rebased(dir).Save(temporary_manifest)`. The colour chart's photos too.
  Session Rebased(const std::string& dir, PathStyle style = PathStyle::kRelative) const;
  // Writes Rebased(dir, style) to `dir`/session.json atomically (the folder must exist); returns that
  // path. The files the session names stay where they are.
  std::string SaveRebased(const std::string& dir, PathStyle style = PathStyle::kRelative) const;

  // A path field of the manifest (relative to `directory`, or absolute) as an absolute, normalized path.
  std::string AbsolutePath(const std::string& file) const;
  // Every file the session references, absolute and normalized, in manifest order: the photos, the
  // flat field, the white-reference photos, and for a mesh sample the mesh file and its raw scans.
  // Not the manifest itself. The mesh file need not exist yet (the scan stage writes it). The colour
  // chart's photos come after the white-reference photos.
  std::vector<std::string> InputFiles() const;

  // Absolute or session-relative path of photo i.
  std::string PhotoPath(size_t i) const;
  // The light photo i was taken under.
  const Light& PhotoLight(size_t i) const;
  // The mask of photo i (its own, else the session's default) resolved against the session folder;
  // empty when it has none.
  std::string PhotoMaskPath(size_t i) const;
  // The index of the light with this id in `lights`; -1 when there is none.
  int LightIndex(const std::string& id) const;

  // Opens every photo's header (and its mask's) and checks its size against the camera; throws Error
  // naming the photo (and, for a mask of the wrong size, both files).
  void CheckPhotos() const;
};

// "sphere", "cylinder", "mesh".
const char* SampleKindName(SampleSpec::Kind kind);
// Whether a sample of this kind is a scanned mesh (SampleSpec::mesh_file) rather than an analytic
// shape (centre, radius, ...).
bool IsMeshSample(SampleSpec::Kind kind);
// "auto", "on", "off"; and back (false for any other name).
const char* VisibilityName(Visibility visibility);
bool VisibilityFromName(const std::string& name, Visibility* visibility);

}  // namespace ibrdf
