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
  Response response;             // file value -> linear signal
  double black_level = 0.0;      // linear signal of a dark pixel, subtracted (normalized file units)
  double saturation_level = 1.0; // file value at which a channel is clipped (normalized file units)
  std::optional<CameraNoise> noise;
};

struct SampleSpec {
  enum class Kind { kSphere, kCylinder, kMesh };
  Kind kind = Kind::kSphere;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // sphere centre; cylinder axis midpoint
  double radius = 0.0;                               // sphere and cylinder, metres
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();   // cylinder axis, unit
  double length = 0.0;                               // cylinder length along the axis, metres
  std::string mesh_file;                             // mesh: path relative to the session folder
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
  double size = 0.0;                     // metres, printed side of every light marker (border included)
  std::vector<LightMarkerSpec> markers;  // at least one
};

struct TargetsSpec {
  std::string dictionary;              // OpenCV predefined dictionary name, e.g. "DICT_4X4_50"
  std::vector<TargetSpec> reference;   // markers with known layout
  std::optional<LightTargetsSpec> light;  // markers on the light, if any
};

// What a photo is for: measurement photos are derendered; target photos only serve the alignment
// (e.g. views of the light's markers, which lie outside the measurement photos' field of view).
enum class PhotoRole { kMeasurement, kTargets };

struct PhotoSpec {
  std::string file;          // relative to the session folder
  double exposure_s = 1.0;   // exposure time, seconds
  double gain = 1.0;         // linear gain relative to the base ISO
  std::optional<Rigid3d> camera_from_world;  // known pose, if any
  PhotoRole role = PhotoRole::kMeasurement;
};

struct Session {
  std::string name;
  std::string description;    // free text, optional
  std::string directory;      // folder holding the manifest; relative paths resolve against it
  std::string manifest_path;  // the manifest file
  Camera camera;
  Light light;
  SampleSpec sample;
  RadiometrySpec radiometry;
  std::vector<PhotoSpec> photos;
  std::optional<TargetsSpec> targets;

  // Reads and validates a manifest (a session.json path, or a folder holding session.json). Unknown
  // keys, missing fields, wrong types, missing photo files and impossible values are Errors naming the
  // manifest and the field's JSON pointer.
  static Session Load(const std::string& path);

  // The manifest as JSON (round-trips through Load).
  nlohmann::json ToJson() const;
  // Writes the manifest to `path` atomically.
  void Save(const std::string& path) const;

  // Absolute or session-relative path of photo i.
  std::string PhotoPath(size_t i) const;

  // Opens every photo's header and checks its size against the camera; throws Error naming the photo.
  void CheckPhotos() const;
};

// "sphere", "cylinder", "mesh".
const char* SampleKindName(SampleSpec::Kind kind);

}  // namespace ibrdf
