#include "synth/synth_options.h"

#include <cmath>
#include <fstream>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/kind.h"
#include "synth/synthetic.h"

namespace ibrdf {
namespace {

// The radius about the scene's origin within which the sample lies (the scene must be valid).
double SampleBoundingRadius(const SynthSceneOptions& scene) {
  if (scene.shape != SynthShape::kNone) return MakeTrueShape(scene)->BoundingRadius();
  switch (scene.sample) {
    case SampleSpec::Kind::kSphere:
      return scene.sample_radius;
    case SampleSpec::Kind::kCylinder:
      return std::hypot(scene.sample_radius, 0.5 * scene.cylinder_length);
    case SampleSpec::Kind::kMesh:
      break;  // a scene's mesh is a shape (handled above); SynthSceneOptions::Check refuses kMesh
  }
  UnhandledKind("SampleSpec::Kind", static_cast<int>(scene.sample));
}

// A part's Check, its message prefixed with the part's name ("rig: num_photos >= 1 failed: ...").
template <typename Part>
bool CheckPart(const char* name, const Part& part, std::string* why) {
  if (part.Check(why)) return true;
  if (why) *why = std::string(name) + ": " + *why;
  return false;
}

}  // namespace

const char* SynthShapeName(SynthShape shape) {
  switch (shape) {
    case SynthShape::kNone:
      return "none";
    case SynthShape::kSquash:
      return "squash";
    case SynthShape::kPot:
      return "pot";
    case SynthShape::kDent:
      return "dent";
  }
  UnhandledKind("SynthShape", static_cast<int>(shape));
}

SynthShape SynthShapeFromName(const std::string& name) {
  for (SynthShape shape : {SynthShape::kNone, SynthShape::kSquash, SynthShape::kPot, SynthShape::kDent}) {
    if (name == SynthShapeName(shape)) return shape;
  }
  ThrowError("synth shape", "unknown shape \"" + name + "\" (expected squash, pot or dent)");
}

const char* SynthNoDataName(SynthNoData no_data) {
  switch (no_data) {
    case SynthNoData::kSkip:
      return "skip";
    case SynthNoData::kZero:
      return "zero";
    case SynthNoData::kError:
      return "error";
  }
  UnhandledKind("SynthNoData", static_cast<int>(no_data));
}

SynthNoData SynthNoDataFromName(const std::string& name) {
  for (SynthNoData no_data : {SynthNoData::kSkip, SynthNoData::kZero, SynthNoData::kError}) {
    if (name == SynthNoDataName(no_data)) return no_data;
  }
  ThrowError("synth --no-data", "unknown policy \"" + name + "\" (expected skip, zero or error)");
}

const char* SynthRigName(SynthRig rig) {
  switch (rig) {
    case SynthRig::kArc:
      return "arc";
    case SynthRig::kDome:
      return "dome";
    case SynthRig::kTurntable:
      return "turntable";
  }
  UnhandledKind("SynthRig", static_cast<int>(rig));
}

SynthRig SynthRigFromName(const std::string& name) {
  for (SynthRig rig : {SynthRig::kArc, SynthRig::kDome, SynthRig::kTurntable}) {
    if (name == SynthRigName(rig)) return rig;
  }
  ThrowError("synth rig", "unknown rig \"" + name + "\" (expected arc, dome or turntable)");
}

bool SynthSceneOptions::Check(std::string* why) const {
  // synth renders a sphere or a cylinder (or, with `shape`, a squash, pot or dent as a mesh sample).
  IBRDF_CHECK_OPTION(sample != SampleSpec::Kind::kMesh);
  IBRDF_CHECK_OPTION_GT(sample_radius, 0.0);
  IBRDF_CHECK_OPTION_GT(cylinder_length, 0.0);
  if (shape != SynthShape::kNone) {
    if (!squash.Check(why) || !pot.Check(why) || !dent.Check(why)) return false;
  }
  IBRDF_CHECK_OPTION_GT(light_distance, 0.0);
  IBRDF_CHECK_OPTION(!(light_intensity.array() < 0.0).any());
  IBRDF_CHECK_OPTION_GT(light_intensity.maxCoeff(), 0.0);
  IBRDF_CHECK_OPTION_GE(fill_light, 0.0);
  IBRDF_CHECK_OPTION_LT(fill_light, 1.0);
  return true;
}

std::vector<Eigen::Vector3d> ReadCameraPositions(const std::string& path) {
  std::ifstream file(path);
  if (!file) ThrowError(path, "cannot open the camera positions");
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(file);
  } catch (const nlohmann::json::exception& e) {
    ThrowError(path, std::string("not JSON: ") + e.what());
  }
  const bool report = json.is_object();
  if (report && !json.contains("suggestions")) {
    ThrowError(path, "an object without \"suggestions\": expected a list of [x, y, z] or a capture-check.json");
  }
  const nlohmann::json& list = report ? json["suggestions"] : json;
  if (!list.is_array()) ThrowError(path, "expected a list of [x, y, z] or a capture-check.json");
  std::vector<Eigen::Vector3d> positions;
  for (size_t i = 0; i < list.size(); ++i) {
    const nlohmann::json& p = report ? (list[i].is_object() && list[i].contains("position") ? list[i]["position"]
                                                                                           : nlohmann::json())
                                     : list[i];
    const std::string where = report ? "/suggestions/" + std::to_string(i) + "/position" : "/" + std::to_string(i);
    if (!p.is_array() || p.size() != 3 || !p[0].is_number() || !p[1].is_number() || !p[2].is_number()) {
      ThrowError(path, where + ": expected [x, y, z] in metres");
    }
    positions.emplace_back(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
    if (!positions.back().allFinite()) ThrowError(path, where + ": not finite");
  }
  return positions;
}

bool SynthRigOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_GT(camera_distance, 0.0);
  IBRDF_CHECK_OPTION(extra_camera_positions.empty() || rig == SynthRig::kArc);
  IBRDF_CHECK_OPTION_RANGE(num_photos, 1, 100000);
  IBRDF_CHECK_OPTION_RANGE(width, 8, 20000);
  IBRDF_CHECK_OPTION_RANGE(height, 8, 20000);
  IBRDF_CHECK_OPTION_GT(frame_fraction, 0.0);
  IBRDF_CHECK_OPTION_LE(frame_fraction, 1.0);
  IBRDF_CHECK_OPTION_GT(exposure_target, 0.0);
  IBRDF_CHECK_OPTION_LE(exposure_target, 1.0);
  if (rig == SynthRig::kDome) {
    // The dome reads the arc's range as angles between camera and light: within [0, 180].
    IBRDF_CHECK_OPTION_GE(arc_start_deg, 0.0);
    IBRDF_CHECK_OPTION_LE(arc_end_deg, 180.0);
    IBRDF_CHECK_OPTION_LT(arc_start_deg, arc_end_deg);
  }
  IBRDF_CHECK_OPTION_GE(dome_min_elevation_deg, 0.0);
  IBRDF_CHECK_OPTION_LT(dome_min_elevation_deg, 90.0);
  IBRDF_CHECK_OPTION_GT(turntable_phase_deg, 0.0);
  IBRDF_CHECK_OPTION_LT(turntable_phase_deg, 180.0);
  IBRDF_CHECK_OPTION_GT(turntable_span_deg, 0.0);
  IBRDF_CHECK_OPTION_LE(turntable_span_deg, 360.0);
  return true;
}

const char* SensorCurveName(SensorCurve curve) {
  switch (curve) {
    case SensorCurve::kLinear:
      return "linear";
    case SensorCurve::kSrgb:
      return "srgb";
    case SensorCurve::kToeShoulder:
      return "toe-shoulder";
  }
  UnhandledKind("SensorCurve", static_cast<int>(curve));
}

bool SensorCurveFromName(const std::string& name, SensorCurve* curve) {
  for (SensorCurve candidate : {SensorCurve::kLinear, SensorCurve::kSrgb, SensorCurve::kToeShoulder}) {
    if (name == SensorCurveName(candidate)) {
      *curve = candidate;
      return true;
    }
  }
  return false;
}

CameraEffects CameraEffects::None() {
  CameraEffects effects;
  effects.shot_noise = false;
  effects.read_noise = false;
  effects.bits = 0;
  effects.curve = SensorCurve::kLinear;
  effects.black_level = 0.0;
  effects.supersample = 1;
  return effects;
}

bool CameraEffects::Check(std::string* why) const {
  // 0 (float) or 8 to 16.
  if (bits != 0) IBRDF_CHECK_OPTION_RANGE(bits, 8, 16);
  IBRDF_CHECK_OPTION_GT(full_well_e, 0.0);
  IBRDF_CHECK_OPTION_GE(read_noise_e, 0.0);
  IBRDF_CHECK_OPTION_GE(black_level, 0.0);
  IBRDF_CHECK_OPTION_LT(black_level, 0.5);
  IBRDF_CHECK_OPTION_RANGE(supersample, 1, 16);
  IBRDF_CHECK_OPTION_GE(vignetting, 0.0);
  IBRDF_CHECK_OPTION_LT(vignetting, 0.9);
  return true;
}

bool SynthRadiometryOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_RANGE(brackets, 1, 16);
  IBRDF_CHECK_OPTION_GT(bracket_step_ev, 0.0);
  IBRDF_CHECK_OPTION_LE(bracket_step_ev, 8.0);
  IBRDF_CHECK_OPTION_GT(white_reflectance, 0.0);
  IBRDF_CHECK_OPTION_LE(white_reflectance, 1.0);
  IBRDF_CHECK_OPTION_GT(white_size, 0.0);
  IBRDF_CHECK_OPTION_GT(white_exposure_scale, 0.0);
  return true;
}

bool SynthTargetOptions::Check(std::string* why) const {
  if (!enabled) return true;
  IBRDF_CHECK_OPTION_GE(ring_count, 1);
  IBRDF_CHECK_OPTION_GT(marker_size, 0.0);
  IBRDF_CHECK_OPTION_GT(platform_radius, ring_radius + marker_size);
  IBRDF_CHECK_OPTION_GE(black, 0.0);
  IBRDF_CHECK_OPTION_GT(white, black);
  IBRDF_CHECK_OPTION_LE(white, 1.0);
  IBRDF_CHECK_OPTION_GE(light_photos, 0);
  if (light_photos > 0) {
    // The light's markers: ids above the ring's, a positive size, and a card below the light.
    IBRDF_CHECK_OPTION_GE(light_marker_count, 1);
    IBRDF_CHECK_OPTION_GE(light_marker_first_id, ring_count);
    IBRDF_CHECK_OPTION_GT(light_marker_size, 0.0);
    IBRDF_CHECK_OPTION_GT(light_card_drop, 0.5 * light_marker_size * (1.0 + 2.0 * card_margin));
  }
  return true;
}

bool SynthScanOptions::Check(std::string* why) const {
  if (!scanner.Check(why)) return false;
  IBRDF_CHECK_OPTION_GE(offset_m, 0.0);
  IBRDF_CHECK_OPTION_GE(target_noise_m, 0.0);
  IBRDF_CHECK_OPTION_GT(truth_mesh_spacing_m, 0.0);
  return true;
}

bool SynthOptions::Check(std::string* why) const {
  if (!CheckPart("scene", scene, why) || !CheckPart("rig", rig, why) || !CheckPart("effects", effects, why) ||
      !CheckPart("radiometry", radiometry, why) || !CheckPart("targets", targets, why) ||
      !CheckPart("colour", colour, why)) {
    return false;
  }
  const double sample_bounding_radius = SampleBoundingRadius(scene);
  if (scene.shape != SynthShape::kNone) {
    // The platform's markers register an irregular shape's scan to the photos.
    IBRDF_CHECK_OPTION(targets.enabled);
    if (!CheckPart("scan", scan, why)) return false;
    IBRDF_CHECK_OPTION_GT(scan.scanner.distance_m, 1.5 * sample_bounding_radius);
    IBRDF_CHECK_OPTION_LT(scan.truth_mesh_spacing_m, 0.1 * sample_bounding_radius);
  }
  // The coded targets assume the arc's one light along +x (its marker card) and a platform fixed
  // with the camera's world; the dome and the turntable render the sample alone.
  if (rig.rig != SynthRig::kArc) IBRDF_CHECK_OPTION(!targets.enabled);
  // The camera and the light well outside the sample, the marker ring around it.
  IBRDF_CHECK_OPTION_GT(rig.camera_distance, 1.5 * sample_bounding_radius);
  IBRDF_CHECK_OPTION_GT(scene.light_distance, sample_bounding_radius);
  if (targets.enabled) IBRDF_CHECK_OPTION_GT(targets.ring_radius, sample_bounding_radius + targets.marker_size);
  if (targets.white_card) {
    // The card needs the platform (its photos' poses) and a white reference to carry.
    IBRDF_CHECK_OPTION(targets.enabled);
    IBRDF_CHECK_OPTION(radiometry.light_unknown);
    IBRDF_CHECK_OPTION_GT(targets.white_marker_size, 0.0);
    IBRDF_CHECK_OPTION_GE(targets.white_marker_first_id, targets.ring_count);
    IBRDF_CHECK_OPTION(targets.light_photos == 0 ||
                       targets.white_marker_first_id >= targets.light_marker_first_id + targets.light_marker_count ||
                       targets.white_marker_first_id + 4 <= targets.light_marker_first_id);
  }
  return true;
}

}  // namespace ibrdf
