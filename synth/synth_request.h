// What the `ibrdf synth` command was asked for, before it becomes SynthOptions: the choices whose
// meaning depends on other choices (presets, implied targets, defaults that change with targets), and
// the ChArUco board photos that go beside the session. apps/synth_command.cc only parses flags into
// a SynthRequest; the logic that turns it into options lives here, where it can be tested.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/brdf_model.h"
#include "synth/synth_options.h"
#include "synth/synthetic_charuco.h"

namespace ibrdf {

// Values as given on the command line; negative numbers and empty strings or vectors mean "not given".
struct SynthRequest {
  SynthOptions options;             // the fields set directly (sizes, photos, arc, scan, ...)
  std::string sample = "sphere";    // "sphere" or "cylinder"
  std::string rig = "arc";          // "arc", "dome" or "turntable" (SynthRig)
  std::string shape;                // "", "squash", "pot" or "dent"; a shape implies targets
  std::string effects = "default";  // the camera-effects preset: "default" (12-bit, noise) or "none"
  // Overrides of the preset's camera effects (< 0: the preset's value).
  int bits = -1, supersample = -1;
  double black_level = -1, full_well_e = -1, read_noise_e = -1, vignetting = -1;
  bool srgb = false, no_shot_noise = false, no_read_noise = false;
  std::string response;  // the sensor's curve by name (SensorCurveFromName); "" = the preset's (srgb with --srgb)
  bool no_clip = false;  // needs float output (bits 0)
  // The marker platform; with it, cameras look down from 45 degrees and 3 light-target photos are
  // taken unless camera_elevation_given or light_photos_given.
  bool targets = false;
  bool camera_elevation_given = false, light_photos_given = false;
  std::vector<double> origin, light_intensity;  // 3 values each when given
  int charuco_photos = 0;             // ChArUco board photos to write beside the session (WriteSessionCharucoPhotos)
  std::vector<double> camera_matrix;  // 9 values row by row when given: camera RGB = M * linear sRGB
  bool colour_chart_detect = false;   // leave the chart's corners out (`ibrdf colour` detects it)
  std::string colour_space = "linear_srgb";  // the colour_chart block's target space (ColourSpaceFromName)
  std::string no_data = "skip";              // a MERL table's cells without data (SynthNoDataFromName)
  // A MERL table's lookups (MerlLookupFromName), applied only when given: other materials have none.
  std::string merl_lookup = "nearest";
  bool merl_lookup_given = false;
  // A material map file (MaterialMap::Load): the sample is spatially varying; it replaces the material,
  // so exactly one of the two is given.
  std::string material_map;
};

// The options a request describes. Throws Error naming the flag for contradictory choices (--no-clip
// without float output), an unknown shape or no-data policy, or a vector of the wrong size.
SynthOptions SynthOptionsFromRequest(const SynthRequest& request);

// The material at `path` (LoadMaterial), a MERL table with the request's lookup when one was given.
// Throws Error naming the file when a lookup is given for a material that is not a MERL table.
std::unique_ptr<BrdfModel> LoadRequestedMaterial(const SynthRequest& request, const std::string& path);

// Writes `num_photos` photos of the default ChArUco board (CharucoPhotoOptions) taken with the camera
// of the session in `session_dir` into `session_dir`/calibration (for `ibrdf align --calibrate`),
// seeded from the session's seed + 1000, beside the session's own calibration photos (colour chart,
// white reference) when it has them (the calibration reads only the photos that show the board).
CharucoPhotosSummary WriteSessionCharucoPhotos(const std::string& session_dir, int num_photos, uint64_t session_seed);

// `ibrdf synth` as a stage, once `options` (SynthOptionsFromRequest) passed their Check(): the output
// guard (`out` is not the material and holds it not), the material (`material_path`) or the request's
// material map, the session written to `out` (synthetic.h) and its ChArUco photos when the request asks
// for them; logs what was written and warns when a MERL table's cells without data were rendered as
// zero. Throws Error naming both flags when both or neither of --material and --material-map are
// given, and naming the map's file and field for a bad map.
void WriteSynthStage(const SynthRequest& request, const SynthOptions& options, const std::string& material_path,
                     const std::string& out, bool overwrite);

}  // namespace ibrdf
