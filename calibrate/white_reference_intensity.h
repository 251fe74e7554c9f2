// The light's intensity from a white reference (the paper's section 3.1: a Spectralon target
// photographed under the measurement light). A flat Lambertian target of known albedo rho at a known
// pose reflects radiance L = rho / pi * E, with E = I cos(theta_i) / r^2 for a point light (E = I
// cos(theta_i) for a directional one), so every pixel on it gives I = pi L r^2 / (rho cos(theta_i)) in
// the session's radiance unit: the camera's sensitivity and the light's power are calibrated together.
// The estimate is the median over the target's interior, in every white-reference photo. A calibration
// of its own, before derender (`ibrdf lights white`, a stage of `ibrdf run`): it writes the measured
// intensities into the session, which the derenderer then reads as stated.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "core/logging.h"
#include "core/session.h"
#include "core/verdict.h"

namespace ibrdf {

struct LightCalibrationOptions {
  // The interior used: a disc of this fraction of the target's size (the side of a square target,
  // the diameter of a round one) around its centre; the rim is left out (mixed pixels, pose error).
  double interior_fraction = 0.8;
  // Signal floor, linear normalized file units (as DerenderOptions::min_signal).
  double min_signal = 0.002;
  // A photo whose interior has more than this fraction of clipped pixels is refused as saturated.
  double max_saturated_fraction = 0.01;
  // Measurable interior pixels needed over all photos together.
  int min_pixels = 25;
  // Interior pixels seen or lit more obliquely than this are not used (degrees).
  double max_theta_deg = 80.0;

  bool Check(std::string* why) const;
};

// One light's white-reference measurement.
struct LightIntensityReport {
  std::string light;    // the light's id; empty for a session's one unnamed light
  int photos = 0;       // white-reference photos taken under this light
  bool stated = false;  // whether the session states an intensity for this light
  Eigen::Vector3d stated_intensity = Eigen::Vector3d::Zero();      // the session's (zero when not stated)
  Eigen::Vector3d calibrated_intensity = Eigen::Vector3d::Zero();  // the white reference's
  uint64_t interior_pixels = 0;  // pixel centres on the target's interior, over this light's photos
  uint64_t pixels_used = 0;
  RejectionCounts rejected;  // non_finite, saturated, below_signal, grazing
  // Per channel, the robust relative spread of the per-pixel estimates (1.4826 MAD / median): noise
  // plus any unevenness (a wrong pose or reflectance shows here).
  Eigen::Vector3d spread = Eigen::Vector3d::Zero();
};

struct LightCalibrationReport {
  // The report is filled as the step goes: true once ApplyLightCalibration returned; false when it
  // threw (the report then holds what was counted before the error).
  bool success = false;
  bool calibrated = false;  // false where the session has no white reference (the lights are unchanged)
  int photos = 0;           // white-reference photos, all lights together
  // One entry per light that has white-reference photos, in the session's order of lights.
  std::vector<LightIntensityReport> lights;
  std::vector<Verdict> verdicts;  // WhiteReferenceVerdicts, filled by ApplyLightCalibration
  double total_s = 0.0;
  // "light calibration: white reference, 2 photos, 4210 pixels: intensity (1, 1, 1) -> (0.41, ...)"
  // (one clause per light).
  std::string BriefReport() const;
  // OUT/white-reference.json: the summary, and per light its photos, pixels, rejections, stated and
  // calibrated intensity and spread; the verdicts.
  nlohmann::json ToJson() const;
};

// The white reference's verdicts (docs/verdicts.md, "lights white"):
//  - white.spread: the largest per-pixel spread of a light's estimate over the target (warn over 5 %,
//    fail over 15 %: noise alone gives about 1 %; an uneven target means a wrong pose, a target that
//    is not flat or not Lambertian, or a light that is not where the session says);
//  - white.pixels: the fewest pixels a light's estimate used (warn under 1000: the median's own noise
//    then exceeds a tenth of the spread).
std::vector<Verdict> WhiteReferenceVerdicts(const LightCalibrationReport& report);

// The session with each light's intensity replaced by the white reference's measurement under that
// light (the white-reference photos that name it), when the session has a white reference
// (calibration.white_reference); otherwise the session unchanged. Lights without white-reference
// photos keep their stated intensity. The white-reference
// photos go through the same radiometric chain as the measurement photos (radiance_image.h: response,
// black level, exposure and gain, flat field). Throws Error naming the photo for a target that is
// saturated (more than max_saturated_fraction of its interior clipped), and naming the manifest's
// white_reference for a target that no photo sees, a photo without a pose, a target facing away from
// the light or the camera, or too few measurable pixels.
Session ApplyLightCalibration(const Session& session, LightCalibrationReport* report,
                              const LightCalibrationOptions& options = LightCalibrationOptions());

// The light stage as `ibrdf lights white` runs it: ApplyLightCalibration, then OUT/session.json (the
// session with the measured intensities and its white reference consumed: the block is left out, so
// that the derenderer, which refuses a session with a white reference, reads the lights as stated;
// paths rebased to name the same files) and OUT/white-reference.json (LightCalibrationReport::ToJson),
// as one folder that appears complete, once the verdicts hold (a failed one not in `accept` stops it
// with nothing written). Throws Error naming the manifest for a session without a white reference,
// and as ApplyLightCalibration.
LightCalibrationReport WriteLightCalibrationStage(const Session& session, const LightCalibrationOptions& options,
                                                  const std::string& out_dir, bool overwrite,
                                                  const AcceptedChecks& accept = AcceptedChecks());

}  // namespace ibrdf
