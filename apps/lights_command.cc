// ibrdf lights: a multi-light rig's lights calibrated from a mirror sphere (align/light_probe_calibration.h)
// and, optionally, their intensities from a diffuse sphere (align/diffuse_sphere_intensity.h); and
// synthetic mirror-sphere sessions with known lights to check it (synth/synthetic_mirror_sphere.h).
#include <filesystem>
#include <memory>
#include <optional>

#include "align/diffuse_sphere_intensity.h"
#include "align/light_probe_calibration.h"
#include "apps/commands.h"
#include "core/error.h"
#include "core/file_util.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/session.h"
#include "synth/synthetic_mirror_sphere.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;

// "lights.json" -> "lights.calibration.json": the calibration's report beside the lights.
std::string ReportPath(const std::string& out) {
  fs::path path(out);
  const std::string stem = path.extension() == ".json" ? path.stem().string() : path.filename().string();
  return (path.parent_path() / (stem + ".calibration.json")).string();
}

Eigen::Vector3d Vector3Option(const std::vector<double>& values, const std::string& flag) {
  if (values.size() != 3) ThrowError(flag, "expected three numbers R,G,B (or x,y,z)");
  return Eigen::Vector3d(values[0], values[1], values[2]);
}

void AddCalibrate(CLI::App& group) {
  auto* command = group.add_subcommand(
      "calibrate",
      "Calibrate the lights of a multi-light rig from photos of a mirror sphere: a session (version 2) whose\n"
      "sample is the chrome sphere and whose photos each name their light. The sphere's centre and size come\n"
      "from its mask's silhouette (or the session's sphere with --known-sphere), each light's highlight is\n"
      "located to sub-pixel accuracy and the law of reflection gives its direction, with an uncertainty.\n"
      "The session's stated light directions are taken as nominal and compared. Intensities from a diffuse\n"
      "sphere (--diffuse, with --albedo for absolute values) or relative (1). Writes the lights (the session\n"
      "format's `lights` array) and, beside them, <out>.calibration.json with every figure.");
  struct Args {
    std::vector<std::string> sessions;
    std::string out, diffuse, apply_to, write_session;
    std::vector<double> albedo;
    LightProbeOptions probe;
    DiffuseSphereOptions diffuse_options;
    bool known_sphere = false, overwrite = false;
  };
  auto args = std::make_shared<Args>();
  command
      ->add_option("sessions", args->sessions,
                   "Mirror-sphere session(s): one for directional lights; two placements of the sphere\n"
                   "triangulate point lights")
      ->required();
  command->add_option("--out", args->out, "The calibrated lights (.json)")->required();
  command->add_option("--kind", args->probe.kind, "What the lights are: directional or point")
      ->check(CLI::IsMember({"directional", "point"}))
      ->capture_default_str();
  AddDeprecatedAlias(*command,
                     command->add_option("--light-distance-m", args->probe.light_distance,
                                         "Point lights from one placement: their distance from the sphere's centre"),
                     "--light-distance", args->probe.light_distance);
  command->add_flag("--known-sphere", args->known_sphere,
                    "Take the session's sphere centre and radius as exact (no silhouette fit)");
  command->add_option("--diffuse", args->diffuse,
                      "A session of a diffuse (Lambertian) sphere under the same lights: measures their intensities");
  command->add_option("--albedo", args->albedo, "The diffuse sphere's albedo R,G,B (absent: relative intensities)")
      ->delimiter(',')
      ->expected(3);
  command
      ->add_option("--max-theta-deg", args->diffuse_options.max_theta_i_deg,
                   "Diffuse sphere: pixels lit or seen more obliquely are not used")
      ->capture_default_str();
  command
      ->add_option("--blob-fraction", args->probe.highlight.blob_fraction,
                   "Highlight: the blob is what exceeds this fraction of its peak")
      ->capture_default_str();
  command
      ->add_option("--rim-margin-px", args->probe.highlight.rim_margin_px,
                   "Highlight: not searched this close to the silhouette")
      ->capture_default_str();
  command->add_option("--apply-to", args->apply_to,
                      "With --write-session: the session to give the calibrated lights (default: the --diffuse one)");
  command->add_option("--write-session", args->write_session,
                      "Write a copy of that session (new folder, its files referenced in place) with the calibrated\n"
                      "lights; for the --diffuse session, also the sphere's fitted centre");
  command->add_flag("--overwrite", args->overwrite, "Replace existing outputs");
  command->callback([args] {
    StageLog stage("lights calibrate");
    args->diffuse_options.max_theta_e_deg = args->diffuse_options.max_theta_i_deg;
    args->probe.fit_silhouette = !args->known_sphere;
    args->diffuse_options.fit_silhouette = !args->known_sphere;
    RequireValidOptions(args->probe, "--kind/--light-distance-m/--blob-fraction/--rim-margin-px");
    RequireValidOptions(args->diffuse_options, "--max-theta-deg");
    std::vector<Session> placements;
    std::vector<std::string> inputs, photos;  // the manifests (recorded in the report), their photos
    for (const std::string& path : args->sessions) {
      placements.push_back(Session::Load(path));
      inputs.push_back(placements.back().manifest_path);
      for (const std::string& file : placements.back().InputFiles()) photos.push_back(file);
    }
    std::optional<Session> diffuse;
    if (!args->diffuse.empty()) {
      diffuse = Session::Load(args->diffuse);
      inputs.push_back(diffuse->manifest_path);
      for (const std::string& file : diffuse->InputFiles()) photos.push_back(file);
    }
    if (!args->albedo.empty() && !diffuse) ThrowError("--albedo", "needs --diffuse (the sphere it describes)");
    const std::string report_path = ReportPath(args->out);
    photos.insert(photos.end(), inputs.begin(), inputs.end());
    RequireWritableOutput(args->out, args->overwrite, photos);
    RequireWritableOutput(report_path, args->overwrite, photos);
    std::optional<Session> target;
    if (!args->write_session.empty()) {
      if (!args->apply_to.empty()) {
        target = Session::Load(args->apply_to);
      } else if (diffuse) {
        target = diffuse;
      } else {
        ThrowError("--write-session", "needs --apply-to SESSION or --diffuse SESSION (the session to give the lights)");
      }
      // The folder written replaces --write-session whole: never the target's folder or its photos.
      std::vector<std::string> target_files = target->InputFiles();
      target_files.push_back(target->manifest_path);
      target_files.push_back(target->directory);
      RequireWritableOutput(args->write_session, args->overwrite, target_files);
    } else if (!args->apply_to.empty()) {
      ThrowError("--apply-to", "needs --write-session (where to write the session with the calibrated lights)");
    }

    LightProbeCalibration calibration = CalibrateLightProbe(placements, args->probe);
    std::optional<DiffuseSphereIntensities> intensities;
    if (diffuse) {
      std::vector<Light> lights;
      for (const CalibratedLight& c : calibration.lights) lights.push_back(c.light);
      const std::optional<Eigen::Vector3d> albedo =
          args->albedo.empty() ? std::nullopt : std::optional<Eigen::Vector3d>(Vector3Option(args->albedo, "--albedo"));
      intensities = MeasureDiffuseSphereIntensities(*diffuse, &lights, albedo, args->diffuse_options);
      for (size_t k = 0; k < lights.size(); ++k) calibration.lights[k].light.intensity = lights[k].intensity;
      calibration.intensity_reference =
          intensities->absolute ? "absolute: a diffuse sphere of known albedo (" + diffuse->manifest_path + ")"
                                : "relative: a diffuse sphere of unknown albedo (" + diffuse->manifest_path +
                                      "); the lights' ratios are measured, their common scale (and so the BRDF's) "
                                      "is not: the mean intensity is set to 1";
      Log(1, intensities->BriefReport());
    } else {
      calibration.intensity_reference =
          "relative: not measured (no diffuse reference); every intensity is 1, so the BRDF's scale and the "
          "lights' ratios are unknown";
    }
    nlohmann::json report = calibration.ReportJson();
    if (intensities) report["diffuse_sphere"] = intensities->ToJson();
    report["inputs"] = inputs;
    nlohmann::json out = {{"format", "ibrdf-lights"}, {"version", 1}};
    out.update(calibration.LightsJson());
    out["intensity_reference"] = calibration.intensity_reference;
    WriteJsonFile(report_path, report);
    WriteJsonFile(args->out, out);
    Log(1, calibration.BriefReport());
    for (const CalibratedLight& c : calibration.lights) {
      char line[256];
      const Eigen::Vector3d& d = c.light.kind == Light::Kind::kPoint ? c.light.position : c.light.direction;
      std::snprintf(line, sizeof(line), "  %-6s %s (%+.4f, %+.4f, %+.4f)  +- %.3f deg  %.3f deg from the nominal",
                    c.light.id.c_str(), c.light.kind == Light::Kind::kPoint ? "at" : "to", d.x(), d.y(), d.z(),
                    c.sigma_deg, c.angle_from_nominal_deg);
      Log(1, line);
    }
    Log(1, "lights written to " + args->out + " (report: " + report_path + ")");

    if (target) {
      Session copy = *target;
      for (Light& light : copy.lights) {
        bool found = false;
        for (const CalibratedLight& c : calibration.lights) {
          if (c.light.id == light.id || (light.id.empty() && calibration.lights.size() == 1)) {
            const std::string id = light.id;
            light = c.light;
            light.id = id;
            light.has_intensity = true;
            found = true;
          }
        }
        if (!found) ThrowError(copy.manifest_path, "light " + light.id + " was not calibrated");
      }
      if (args->apply_to.empty() && intensities && !args->known_sphere) {
        // The diffuse sphere's centre as its silhouette gave it (the radius sets the scale).
        copy.sample.center = intensities->center;
      }
      copy.description = (copy.description.empty() ? "" : copy.description + " ") +
                         "Lights calibrated by `ibrdf lights calibrate` (" + args->out + ").";
      AtomicDirectory directory(args->write_session, args->overwrite);
      const Session rebased = copy.Rebased(args->write_session, Session::PathStyle::kAbsolute);
      rebased.Save((fs::path(directory.temporary_path()) / "session.json").string());
      directory.Commit();
      Log(1, "session with the calibrated lights written to " + args->write_session + "/session.json");
    }
  });
}

void AddSynth(CLI::App& group) {
  auto* command = group.add_subcommand(
      "synth",
      "Render a synthetic mirror-sphere session with known lights (fixed camera, one 8-bit photo per light,\n"
      "a mask, the true lights as the nominal ones and in truth-lights.json), to check `lights calibrate`.");
  struct Args {
    std::string out;
    SyntheticMirrorSphereOptions options;
    std::vector<double> center;
    bool overwrite = false;
  };
  auto args = std::make_shared<Args>();
  command->add_option("--out", args->out, "Session folder to write")->required();
  command->add_option("--lights", args->options.lights, "Number of lights")->capture_default_str();
  command
      ->add_option("--max-light-angle-deg", args->options.max_light_angle_deg,
                   "Lights within this angle of the direction to the camera")
      ->capture_default_str();
  command->add_flag("--point", args->options.point_lights, "Point lights at --light-distance-m instead of directional");
  AddDeprecatedAlias(*command,
                     command->add_option("--light-distance-m", args->options.light_distance, "Point lights' distance")
                         ->capture_default_str(),
                     "--light-distance", args->options.light_distance);
  AddDeprecatedAlias(
      *command,
      command
          ->add_option("--center-m", args->center, "The sphere's centre x,y,z (world: x right, y up, z to the camera)")
          ->delimiter(',')
          ->expected(3),
      "--center", args->center);
  AddDeprecatedAlias(
      *command, command->add_option("--radius-m", args->options.radius, "The sphere's radius")->capture_default_str(),
      "--radius", args->options.radius);
  command->add_option("--focal-px", args->options.focal_px, "Focal length, pixels")->capture_default_str();
  AddDeprecatedAlias(
      *command, command->add_option("--distance-m", args->options.distance, "Camera distance")->capture_default_str(),
      "--distance", args->options.distance);
  command->add_option("--source-sigma-deg", args->options.source_sigma_deg, "The light's angular size, one sigma")
      ->capture_default_str();
  command->add_option("--seed", args->options.seed, "Noise and light layout")->capture_default_str();
  command->add_flag("--overwrite", args->overwrite, "Replace an existing folder");
  command->callback([args] {
    if (!args->center.empty()) args->options.center = Vector3Option(args->center, "--center-m");
    RequireValidOptions(args->options, "ibrdf lights synth");
    StageLog stage("lights synth");
    Log(1, WriteSyntheticMirrorSphere(args->options, args->out, args->overwrite).BriefReport());
  });
}

void AddLightsCommand(CLI::App& app) {
  auto* lights = app.add_subcommand("lights",
                                    "Calibrate a multi-light rig's lights from a mirror sphere (calibrate);\n"
                                    "synthetic mirror-sphere sessions (synth)");
  lights->require_subcommand(1);
  AddCalibrate(*lights);
  AddSynth(*lights);
}

}  // namespace

IBRDF_REGISTER_COMMAND(35, AddLightsCommand);

}  // namespace ibrdf
