#include "calibrate/light_rig.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "calibrate/report_format.h"
#include "core/error.h"
#include "core/file_util.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/output_guard.h"

namespace fs = std::filesystem;

namespace ibrdf {

bool LightRigOptions::Check(std::string* why) const { return probe.Check(why) && diffuse.Check(why); }

nlohmann::json LightRigCalibration::LightsFileJson() const {
  nlohmann::json out = {{"format", "ibrdf-lights"}, {"version", 1}};
  out.update(probe.LightsJson());
  out["intensity_reference"] = probe.intensity_reference;
  return out;
}

nlohmann::json LightRigCalibration::ReportJson() const {
  nlohmann::json report = probe.ReportJson();
  if (intensities) report["diffuse_sphere"] = intensities->ToJson();
  report["verdicts"] = VerdictsToJson(verdicts);
  report["inputs"] = inputs;
  return report;
}

std::vector<std::string> LightRigCalibration::LightLines() const {
  std::vector<std::string> lines;
  for (const CalibratedLight& c : probe.lights) {
    char line[256];
    const Eigen::Vector3d& d = LightPlacement(c.light);
    const char* preposition = "";
    switch (c.light.kind) {
      case Light::Kind::kPoint:
        preposition = "at";
        break;
      case Light::Kind::kDirectional:
        preposition = "to";
        break;
    }
    std::snprintf(line, sizeof(line), "  %-6s %s (%+.4f, %+.4f, %+.4f)  +- %.3f deg  %.3f deg from the nominal",
                  c.light.id.c_str(), preposition, d.x(), d.y(), d.z(), c.sigma_deg, c.angle_from_nominal_deg);
    lines.push_back(line);
  }
  return lines;
}

LightRigCalibration CalibrateLightRig(const std::vector<Session>& placements, const Session* diffuse,
                                      const LightRigOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("light rig calibration options", why);
  if (options.albedo && diffuse == nullptr) ThrowError("--albedo", "needs --diffuse (the sphere it describes)");
  LightRigCalibration result;
  for (const Session& session : placements) result.inputs.push_back(session.manifest_path);
  if (diffuse != nullptr) result.inputs.push_back(diffuse->manifest_path);
  result.probe = CalibrateLightProbe(placements, options.probe);
  LightProbeCalibration& calibration = result.probe;
  if (diffuse == nullptr) {
    calibration.intensity_reference =
        "relative: not measured (no diffuse reference); every intensity is 1, so the BRDF's scale and the "
        "lights' ratios are unknown";
    result.verdicts = LightRigVerdicts(result, options);
    return result;
  }
  std::vector<Light> lights;
  for (const CalibratedLight& c : calibration.lights) lights.push_back(c.light);
  result.intensities = MeasureDiffuseSphereIntensities(*diffuse, &lights, options.albedo, options.diffuse);
  for (size_t k = 0; k < lights.size(); ++k) calibration.lights[k].light.intensity = lights[k].intensity;
  calibration.intensity_reference =
      result.intensities->absolute
          ? "absolute: a diffuse sphere of known albedo (" + diffuse->manifest_path + ")"
          : "relative: a diffuse sphere of unknown albedo (" + diffuse->manifest_path +
                "); the lights' ratios are measured, their common scale (and so the BRDF's) is not: the mean "
                "intensity is set to 1";
  result.verdicts = LightRigVerdicts(result, options);
  return result;
}

std::vector<Verdict> LightRigVerdicts(const LightRigCalibration& calibration, const LightRigOptions& options) {
  constexpr double kFailSigmaDeg = 2.0, kWarnNominalDeg = 10.0, kFailNominalDeg = 30.0;
  constexpr double kWarnExponent = 0.05, kFailExponent = 0.1, kWarnSpread = 0.05, kFailSpread = 0.15;
  const LightProbeCalibration& probe = calibration.probe;
  std::string least_certain, farthest;
  double max_sigma = 0.0, max_nominal = 0.0;
  for (const CalibratedLight& c : probe.lights) {
    if (c.sigma_deg >= max_sigma) max_sigma = c.sigma_deg, least_certain = c.light.id;
    if (c.angle_from_nominal_deg >= max_nominal) max_nominal = c.angle_from_nominal_deg, farthest = c.light.id;
  }
  std::vector<Verdict> verdicts;
  verdicts.push_back(MakeVerdict(
      "lights.direction_sigma", max_sigma,
      FormatNumbers("largest direction sigma %.3f deg (", max_sigma) + least_certain + ")",
      FormatNumbers("warn over %.2f deg, fail over %.1f deg", options.probe.warn_sigma_deg, kFailSigmaDeg),
      VerdictAbove(max_sigma, options.probe.warn_sigma_deg, kFailSigmaDeg),
      "a sharper highlight: an exposure that does not clip it, a larger mirror sphere in the frame, or a second "
      "placement of the sphere"));
  verdicts.push_back(MakeVerdict(
      "lights.nominal", max_nominal,
      FormatNumbers("largest angle from the session's stated light %.2f deg (", max_nominal) + farthest + ")",
      FormatNumbers("warn over %.0f deg, fail over %.0f deg", kWarnNominalDeg, kFailNominalDeg),
      VerdictAbove(max_nominal, kWarnNominalDeg, kFailNominalDeg),
      "check that each photo names the light it was taken under and that the session's lights describe this "
      "rig; if the stated lights are only placeholders, accept this check"));
  if (calibration.intensities) {
    const DiffuseSphereIntensities& diffuse = *calibration.intensities;
    const double exponent_error = std::abs(diffuse.median_cosine_exponent - 1.0);
    verdicts.push_back(MakeVerdict(
        "lights.response_linearity", exponent_error,
        FormatNumbers("the diffuse sphere's signal goes as cos(theta_i)^%.3f", diffuse.median_cosine_exponent),
        FormatNumbers("exponent within 1 +- %.2f (warn), 1 +- %.2f (fail)", kWarnExponent, kFailExponent),
        VerdictAbove(exponent_error, kWarnExponent, kFailExponent),
        "the photos do not read linearly: measure the camera's response from exposure brackets (`ibrdf "
        "response`) or state it (radiometry.response); every BRDF value is otherwise off by the same power"));
    verdicts.push_back(
        MakeVerdict("lights.intensity_spread", diffuse.median_spread,
                    FormatNumbers("median per-pixel spread of the intensities %.2f %%", 100.0 * diffuse.median_spread),
                    FormatNumbers("warn over %.0f %%, fail over %.0f %%", 100.0 * kWarnSpread, 100.0 * kFailSpread),
                    VerdictAbove(diffuse.median_spread, kWarnSpread, kFailSpread),
                    "check the diffuse sphere's mask and that it is matte (Lambertian), and the light directions"));
  }
  return verdicts;
}

std::string LightRigReportPath(const std::string& lights_path) {
  const fs::path path(lights_path);
  const std::string stem = path.extension() == ".json" ? path.stem().string() : path.filename().string();
  return (path.parent_path() / (stem + ".calibration.json")).string();
}

void WriteLightRig(const LightRigCalibration& calibration, const std::string& lights_path) {
  WriteJsonFile(LightRigReportPath(lights_path), calibration.ReportJson());
  WriteJsonFile(lights_path, calibration.LightsFileJson());
}

Session WithCalibratedLights(const Session& target, const LightRigCalibration& calibration,
                             const std::string& lights_path, bool diffuse_center) {
  Session copy = target;
  const std::vector<CalibratedLight>& calibrated = calibration.probe.lights;
  for (Light& light : copy.lights) {
    bool found = false;
    for (const CalibratedLight& c : calibrated) {
      if (c.light.id == light.id || (light.id.empty() && calibrated.size() == 1)) {
        const std::string id = light.id;
        light = c.light;
        light.id = id;
        light.has_intensity = true;
        found = true;
      }
    }
    if (!found) ThrowError(copy.manifest_path, "light " + light.id + " was not calibrated");
  }
  // Without a diffuse sphere of known albedo only the lights' ratios are known: the scale is relative.
  copy.radiometry.relative_intensities = !calibration.intensities || !calibration.intensities->absolute;
  if (diffuse_center && calibration.intensities) {
    // The diffuse sphere's centre as its silhouette gave it (the radius sets the scale).
    copy.sample.center = calibration.intensities->center;
  }
  copy.description = (copy.description.empty() ? "" : copy.description + " ") +
                     "Lights calibrated by `ibrdf lights calibrate` (" + lights_path + ").";
  return copy;
}

LightRigCalibration RunLightRigStage(const LightRigStageRequest& request, const LightRigOptions& options) {
  std::vector<Session> placements;
  std::vector<std::string> inputs;
  for (const std::string& path : request.placements) {
    placements.push_back(Session::Load(path));
    for (const std::string& input : SessionInputs(placements.back())) inputs.push_back(input);
  }
  std::optional<Session> diffuse;
  if (!request.diffuse.empty()) {
    diffuse = Session::Load(request.diffuse);
    for (const std::string& input : SessionInputs(*diffuse)) inputs.push_back(input);
  }
  if (options.albedo && !diffuse) ThrowError("--albedo", "needs --diffuse (the sphere it describes)");
  const std::string report_path = LightRigReportPath(request.out);
  RequireWritableOutput(request.out, request.overwrite, inputs);
  RequireWritableOutput(report_path, request.overwrite, inputs);
  std::optional<Session> target;
  if (!request.write_session.empty()) {
    if (!request.apply_to.empty()) {
      target = Session::Load(request.apply_to);
    } else if (diffuse) {
      target = diffuse;
    } else {
      ThrowError("--write-session", "needs --apply-to SESSION or --diffuse SESSION (the session to give the lights)");
    }
    // The folder written replaces --write-session whole: never the target's folder or its photos.
    RequireWritableOutput(request.write_session, request.overwrite, SessionInputs(*target));
  } else if (!request.apply_to.empty()) {
    ThrowError("--apply-to", "needs --write-session (where to write the session with the calibrated lights)");
  }

  LightRigCalibration calibration = CalibrateLightRig(placements, diffuse ? &*diffuse : nullptr, options);
  if (calibration.intensities) Log(1, calibration.intensities->BriefReport());
  // Nothing is written when the lights cannot be trusted, unless the user accepted the check by name.
  EnforceVerdicts(&calibration.verdicts, request.accept, request.placements.front() + ": lights");
  WriteLightRig(calibration, request.out);
  Log(1, calibration.probe.BriefReport());
  for (const std::string& line : calibration.LightLines()) Log(1, line);
  Log(1, "lights written to " + request.out + " (report: " + report_path + ")");
  if (target) {
    const bool diffuse_center = request.apply_to.empty() && !request.known_sphere;
    Session copy = WithCalibratedLights(*target, calibration, request.out, diffuse_center);
    copy.MarkApplied(SessionStage::kLights);
    AtomicDirectory directory(request.write_session, request.overwrite);
    copy.Rebased(request.write_session, Session::PathStyle::kAbsolute)
        .Save((fs::path(directory.temporary_path()) / "session.json").string());
    directory.Commit();
    Log(1, "session with the calibrated lights written to " + request.write_session + "/session.json");
  }
  return calibration;
}

}  // namespace ibrdf
