// `ibrdf session init`: a draft session.json from a camera's photos. Every photo's
// exposure time, ISO (as gain), f-number, focal length, make, model and size come from its metadata
// (EXIF, read through OpenImageIO: core/image_io.h); consecutive photos taken within a burst with
// exposures a bracket step apart form one exposure bracket; the camera comes from a calibration file or,
// as a starting guess, from the EXIF focal length and sensor size. What no photo can say (the light,
// the sample, the targets) comes from the options; what is still missing is listed, and the manifest
// is written as session.json only when it validates (Session::Load), else as session.draft.json.
//
// The capture library sits on core only: no OpenCV, Ceres or Embree in this light path.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/camera.h"
#include "core/image_io.h"

namespace ibrdf {

struct SessionInitOptions {
  std::vector<std::string> photos;         // measurement photos, in capture order (files)
  std::vector<std::string> target_photos;  // photos for the alignment only ("role": "targets")
  // Photos of the white reference (calibration.white_reference), which measures the light's intensity:
  // its pose comes from `ibrdf align` when the targets carry the white card's markers
  // (targets.white_reference), so none is drafted; its size (metres, the patch's side) must be given, its
  // reflectance defaults to Spectralon's 0.99 (stated as an assumption).
  std::vector<std::string> white_photos;
  std::optional<double> white_size;
  std::optional<Eigen::Vector3d> white_reflectance;
  // Photos of a colour chart (the colour_chart block, a ColorChecker Classic 24 under the session's
  // light; the exposures of one view): `ibrdf colour` then fits the matrix to linear sRGB. The chart's
  // corner patches (pixel centres of patches 1, 6, 24 and 19: top-left, top-right, bottom-right,
  // bottom-left) when given; absent, `ibrdf colour` detects the chart (OpenCV mcc).
  std::vector<std::string> chart_photos;
  std::optional<std::array<Eigen::Vector2d, 4>> chart_corners;
  std::string name;  // the session's name (empty: the output folder's name)
  // The camera: a JSON file holding a "camera" block (a session.json, an aligned session, or the
  // block itself: {"model": "OPENCV", "width": .., "height": .., "params": [..]}). Empty: a pinhole
  // guess from EXIF (focal length x focal-plane resolution, or the 35 mm equivalent focal length, or
  // sensor_width_mm), the principal point at the image centre, no distortion.
  std::string camera_file;
  double sensor_width_mm = 0.0;  // the sensor's width when EXIF has neither resolution nor 35 mm focal (0: none)
  double base_iso = 0.0;         // the ISO of gain 1 (0: the lowest ISO among the photos)
  // Exposure brackets: 0 groups automatically (consecutive photos at most bracket_gap_s apart whose
  // exposure x gain changes by at least bracket_min_ratio each time, in one direction); n > 0: every n
  // consecutive measurement photos form one bracket; 1: no brackets.
  int bracket_size = 0;
  double bracket_gap_s = 3.0;
  double bracket_min_ratio = 1.5;
  // Exposure times (seconds) for photos whose metadata has none; EXIF's always wins. Empty: a photo
  // without one is an error; one value: every such photo's; one per photo: in the manifest's order
  // (photos, target_photos, white_photos, chart_photos). Stated as an assumption.
  std::vector<double> exposure_s;
  // The targets block: a JSON file holding "targets" (what `ibrdf targets` writes) or the block itself;
  // a ChArUco board file (board.json) is refused.
  std::string targets_file;
  // The scene, which no photo records. Absent: listed as missing (the light's position not, when the
  // targets carry light markers: `ibrdf align` finds it).
  std::optional<Eigen::Vector3d> light_position;   // metres, the targets' frame
  std::optional<Eigen::Vector3d> light_intensity;  // RGB, the session's radiance unit
  std::string sample_kind = "sphere";              // "sphere" (the analytic sample session init drafts)
  std::optional<double> sample_radius;             // metres
  bool radius_known = false;                       // the radius is measured: align fits only the centre
  // The sphere's centre; absent with targets: resting on the platform's centre, (0, 0, radius).
  std::optional<Eigen::Vector3d> sample_center;
  // The response: "linear", "srgb" or empty (linear for RAW, 16-bit and float files, sRGB for 8-bit
  // ones, stated as an assumption).
  std::string response;
  bool overwrite = false;  // replace session.json / session.draft.json in the output folder
  bool Check(std::string* why) const;
};

// One photo as session init read it.
struct InitPhoto {
  std::string file;  // as given
  PhotoMetadata metadata;
  bool target = false;  // role "targets"
  bool white = false;   // a white-reference photo
  bool chart = false;   // a colour-chart photo
  bool exposure_given = false;  // the exposure time came from SessionInitOptions::exposure_s, not EXIF
  int bracket = -1;     // bracket id, -1: none
  double gain = 1.0;    // ISO / base ISO
};

// What session init did; reads as not written until it wrote a file.
struct SessionInitResult {
  bool written = false;
  bool complete = false;          // session.json was written and validates
  std::string path;               // session.json, or session.draft.json when incomplete
  std::vector<InitPhoto> photos;  // in the manifest's order
  int brackets = 0;               // brackets of more than one exposure
  Camera camera;
  std::string camera_source;             // "calibration FILE", "EXIF focal length ..."
  std::vector<std::string> missing;      // what the user must still supply (each a sentence naming the flag)
  std::vector<std::string> assumptions;  // what was assumed (each a sentence)
  // "session init: 20 photos (4 brackets), camera from EXIF ...; complete: DIR/session.json"
  std::string BriefReport() const;
};

// Reads the photos' metadata and writes `out_dir`/session.json (complete) or session.draft.json (with
// a "missing" list) there; the photos stay where they are (the manifest names them relative to
// out_dir). Throws Error for unreadable photos, photos of different sizes, a photo without an exposure
// time (EXIF's or exposure_s), bad options or files (a board.json given as the targets).
SessionInitResult InitSession(const SessionInitOptions& options, const std::string& out_dir);

// Groups measurement photos into brackets (InitPhoto::bracket) by the rule of SessionInitOptions;
// automatically only photos with EXIF exposure times (a time typed for a photo without EXIF says
// nothing about its pose).
// Returns the number of brackets of more than one exposure.
int GroupBrackets(const SessionInitOptions& options, std::vector<InitPhoto>* photos);

// The camera guess from one photo's metadata (pinhole, principal point at the centre); false with
// `why` when the metadata cannot give a focal length in pixels.
bool CameraFromMetadata(const PhotoMetadata& metadata, double sensor_width_mm, Camera* camera, std::string* source);

}  // namespace ibrdf
