#include "calibrate/light_rig.h"

#include <cstdio>
#include <filesystem>

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
  return result;
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

  const LightRigCalibration calibration = CalibrateLightRig(placements, diffuse ? &*diffuse : nullptr, options);
  if (calibration.intensities) Log(1, calibration.intensities->BriefReport());
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
