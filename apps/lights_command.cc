// ibrdf lights: a multi-light rig's lights calibrated from a mirror sphere and, optionally, their
// intensities from a diffuse sphere (calibrate/light_rig.h); a session's light intensities from its
// white reference (calibrate/white_reference_intensity.h); and synthetic mirror-sphere sessions with
// known lights to check the first (synth/synthetic_mirror_sphere.h).
#include <memory>

#include "apps/commands.h"
#include "calibrate/light_rig.h"
#include "calibrate/white_reference_intensity.h"
#include "core/error.h"
#include "core/logging.h"
#include "core/session.h"
#include "synth/synthetic_mirror_sphere.h"

namespace ibrdf {
namespace {

Eigen::Vector3d Vector3Option(const std::vector<double>& values, const std::string& flag) {
  if (values.size() != 3) ThrowError(flag, "expected three numbers R,G,B (or x,y,z)");
  return Eigen::Vector3d(values[0], values[1], values[2]);
}

struct CalibrateArgs {
  LightRigStageRequest request;
  std::vector<double> albedo;
  LightRigOptions options;
};

void AddCalibrateFlags(CLI::App* command, CalibrateArgs* args) {
  LightProbeOptions& probe = args->options.probe;
  command
      ->add_option("sessions", args->request.placements,
                   "Mirror-sphere session(s): one for directional lights; two placements of the sphere\n"
                   "triangulate point lights")
      ->required();
  command->add_option("--out", args->request.out, "The calibrated lights (.json)")->required();
  command->add_option("--kind", probe.kind, "What the lights are: directional or point")
      ->check(CLI::IsMember({"directional", "point"}))
      ->capture_default_str();
  AddDeprecatedAlias(*command,
                     command->add_option("--light-distance-m", probe.light_distance,
                                         "Point lights from one placement: their distance from the sphere's centre"),
                     "--light-distance", probe.light_distance);
  command->add_flag("--known-sphere", args->request.known_sphere,
                    "Take the session's sphere centre and radius as exact (no silhouette fit)");
  command->add_option("--diffuse", args->request.diffuse,
                      "A session of a diffuse (Lambertian) sphere under the same lights: measures their intensities");
  command->add_option("--albedo", args->albedo, "The diffuse sphere's albedo R,G,B (absent: relative intensities)")
      ->delimiter(',')
      ->expected(3);
  command
      ->add_option("--max-theta-deg", args->options.diffuse.max_theta_i_deg,
                   "Diffuse sphere: pixels lit or seen more obliquely are not used")
      ->capture_default_str();
  command
      ->add_option("--blob-fraction", probe.highlight.blob_fraction,
                   "Highlight: the blob is what exceeds this fraction of its peak")
      ->capture_default_str();
  command
      ->add_option("--rim-margin-px", probe.highlight.rim_margin_px,
                   "Highlight: not searched this close to the silhouette")
      ->capture_default_str();
  command->add_option("--apply-to", args->request.apply_to,
                      "With --write-session: the session to give the calibrated lights (default: the --diffuse one)");
  command->add_option("--write-session", args->request.write_session,
                      "Write a copy of that session (new folder, its files referenced in place) with the calibrated\n"
                      "lights; for the --diffuse session, also the sphere's fitted centre");
  command->add_flag("--overwrite", args->request.overwrite, "Replace existing outputs");
  command
      ->add_option("--accept", args->request.accept.names,
                   "Proceed although these checks fail (comma-separated, or all); recorded in the report")
      ->delimiter(',')
      ->type_name("CHECK[,CHECK...]");
}

void RunCalibrate(CalibrateArgs& args) {
  StageLog stage("lights calibrate");
  LightRigOptions& options = args.options;
  options.diffuse.max_theta_e_deg = options.diffuse.max_theta_i_deg;
  options.probe.fit_silhouette = !args.request.known_sphere;
  options.diffuse.fit_silhouette = !args.request.known_sphere;
  RequireValidOptions(options.probe, "--kind/--light-distance-m/--blob-fraction/--rim-margin-px");
  RequireValidOptions(options.diffuse, "--max-theta-deg");
  if (!args.albedo.empty()) options.albedo = Vector3Option(args.albedo, "--albedo");
  RunLightRigStage(args.request, options);
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
  auto args = std::make_shared<CalibrateArgs>();
  AddCalibrateFlags(command, args.get());
  command->callback([args] { RunCalibrate(*args); });
}

void AddWhite(CLI::App& group) {
  auto* command = group.add_subcommand(
      "white",
      "Measure the session's light intensities from its white reference (calibration.white_reference: a\n"
      "flat Lambertian target of known albedo at a known pose, photographed under each light), read through\n"
      "the session's radiometric chain. Writes OUT/session.json (the session with the measured intensities,\n"
      "the white reference consumed: `ibrdf derender` reads it) and OUT/white-reference.json (per light:\n"
      "pixels used, rejections, spread). `ibrdf run` runs it for sessions with a white reference.");
  struct Args {
    std::string session, out;
    LightCalibrationOptions options;
    bool overwrite = false;
    AcceptedChecks accept;
  };
  auto args = std::make_shared<Args>();
  command->add_option("session", args->session, "Session folder or session.json with a white reference")->required();
  command->add_option("--out", args->out, "Folder for the session with the calibrated lights")->required();
  command->add_option("--min-signal", args->options.min_signal, "Signal floor, linear normalized file units")
      ->capture_default_str();
  command->add_flag("--overwrite", args->overwrite, "Replace an existing output folder");
  command
      ->add_option("--accept", args->accept.names,
                   "Proceed although these checks fail (comma-separated, or all); recorded in white-reference.json")
      ->delimiter(',')
      ->type_name("CHECK[,CHECK...]");
  command->callback([args] {
    StageLog stage("lights white");
    RequireValidOptions(args->options, "--min-signal");
    const Session session = Session::Load(args->session);
    RequireWritableOutput(args->out, args->overwrite, SessionInputs(session));
    const LightCalibrationReport report =
        WriteLightCalibrationStage(session, args->options, args->out, args->overwrite, args->accept);
    Log(1, report.BriefReport());
    Log(1, "session with the calibrated lights written to " + args->out + "/session.json");
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
                                    "Calibrate a multi-light rig's lights from a mirror sphere (calibrate); a\n"
                                    "session's light intensities from its white reference (white); synthetic\n"
                                    "mirror-sphere sessions (synth)");
  lights->require_subcommand(1);
  AddCalibrate(*lights);
  AddWhite(*lights);
  AddSynth(*lights);
}

}  // namespace

IBRDF_REGISTER_COMMAND(35, AddLightsCommand);

}  // namespace ibrdf
