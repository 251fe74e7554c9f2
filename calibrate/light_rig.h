// A multi-light rig's lights calibrated as `ibrdf lights calibrate` does it: their directions or
// positions from a mirror sphere (light_probe_calibration.h), their intensities from a diffuse sphere
// under the same lights when one is given (diffuse_sphere_intensity.h; absolute with its albedo,
// relative without), else relative (1). The result is the "ibrdf-lights" file (the session format's
// `lights` array and where the intensities come from), its report, and a session given those lights.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "calibrate/diffuse_sphere_intensity.h"
#include "calibrate/light_probe_calibration.h"
#include "core/session.h"
#include "core/verdict.h"

namespace ibrdf {

struct LightRigOptions {
  LightProbeOptions probe;
  DiffuseSphereOptions diffuse;
  // The diffuse sphere's albedo (absolute intensities); absent: relative intensities (mean 1).
  std::optional<Eigen::Vector3d> albedo;
  bool Check(std::string* why) const;
};

struct LightRigCalibration {
  LightProbeCalibration probe;                          // the lights, intensities included
  std::optional<DiffuseSphereIntensities> intensities;  // with a diffuse sphere
  std::vector<std::string> inputs;                      // the sessions' manifests, placements then diffuse
  std::vector<Verdict> verdicts;                        // LightRigVerdicts

  // "ibrdf-lights" version 1: the lights as the session format writes them, and intensity_reference.
  nlohmann::json LightsFileJson() const;
  // <out>.calibration.json: the probe's report, the diffuse sphere's, the verdicts, the inputs.
  nlohmann::json ReportJson() const;
  // One line per light: "  L01    to (+0.1000, ...)  +- 0.020 deg  0.310 deg from the nominal".
  std::vector<std::string> LightLines() const;
};

// Calibrates the lights from the mirror sphere's `placements` and, when `diffuse` is given, measures
// their intensities on it. Throws Error naming the session for bad input (light_probe_calibration.h,
// diffuse_sphere_intensity.h), and naming "--albedo" for an albedo without a diffuse sphere.
LightRigCalibration CalibrateLightRig(const std::vector<Session>& placements, const Session* diffuse,
                                      const LightRigOptions& options);

// The calibration's verdicts (docs/verdicts.md, "lights"):
//  - lights.direction_sigma: the least certain light's direction, one sigma (warn over the probe's
//    warn_sigma_deg, fail over 2 degrees: a light that far off moves a sharp highlight's samples by
//    twice that in theta_h);
//  - lights.nominal: the largest angle between a calibrated light and the session's stated one (warn
//    over 10, fail over 30 degrees: a light that far from where the rig says is a photo named for the
//    wrong light, or a rig description of another rig);
//  - with a diffuse sphere, lights.response_linearity: the cosine exponent k of its signal against
//    cos(theta_i), |k - 1| (warn over 0.05, fail over 0.1: the photos do not read linearly, and every
//    BRDF value is off by the same power);
//  - with a diffuse sphere, lights.intensity_spread: the median over lights of the per-pixel spread of
//    the intensity (warn over 5 %, fail over 15 %: the sphere is not Lambertian, its mask is wrong, or
//    the directions are).
std::vector<Verdict> LightRigVerdicts(const LightRigCalibration& calibration, const LightRigOptions& options);

// "lights.json" -> "lights.calibration.json": the calibration's report beside the lights.
std::string LightRigReportPath(const std::string& lights_path);

// Writes the lights to `lights_path` and the report beside it (LightRigReportPath).
void WriteLightRig(const LightRigCalibration& calibration, const std::string& lights_path);

// `target` with each light replaced by the calibrated light of the same id (the only one, for a
// session's one unnamed light), its id kept; with `diffuse_center`, the sample's centre becomes the
// diffuse sphere's as its silhouette gave it. The description names `lights_path`. Throws Error naming
// the manifest for a light that was not calibrated.
Session WithCalibratedLights(const Session& target, const LightRigCalibration& calibration,
                             const std::string& lights_path, bool diffuse_center);

// `ibrdf lights calibrate` as a stage: the files it reads and writes, as the command line names them.
struct LightRigStageRequest {
  std::vector<std::string> placements;  // the mirror-sphere sessions
  std::string diffuse;                  // a diffuse-sphere session under the same lights ("": none)
  std::string out;                      // the lights file; its report beside it (LightRigReportPath)
  std::string write_session;            // a folder for a session given the lights ("": none)
  std::string apply_to;                 // that session ("": the diffuse one)
  bool known_sphere = false;            // the sessions' spheres are exact: no silhouette fit, no new centre
  bool overwrite = false;
  AcceptedChecks accept;  // failed verdicts to proceed with (--accept)
};

// Loads the sessions, checks every output against every input before anything is read or written
// (core/output_guard.h: the lights, their report and the session folder, which is replaced whole),
// calibrates, enforces the verdicts (nothing is written when one fails and is not accepted), writes the
// lights and their report and, with write_session, the session with the
// calibrated lights (for the diffuse session, its fitted centre too). Logs each result's brief report.
// Throws Error naming the flag for an inconsistent request (--albedo without --diffuse, --apply-to
// without --write-session).
LightRigCalibration RunLightRigStage(const LightRigStageRequest& request, const LightRigOptions& options);

}  // namespace ibrdf
