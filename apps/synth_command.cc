// ibrdf synth: writes a synthetic measurement session with known truth.
#include <iostream>

#include "apps/commands.h"
#include "core/brdf_model.h"
#include "core/error.h"
#include "core/logging.h"
#include "derender/synthetic.h"
#include "derender/synthetic_charuco.h"

namespace ibrdf {

namespace {
void AddSynthCommand(CLI::App& app) {
  auto* command = app.add_subcommand(
      "synth",
      "Render a synthetic measurement session (photos, session.json, truth.json) of an analytic sphere or\n"
      "cylinder with a known BRDF, cameras on an arc from beside the light to opposite it (paper, Fig. 3/4);\n"
      "or (--shape) of a squash, clay pot or dented sphere as a mesh sample with simulated range scans.");
  struct Args {
    std::string out, material, sample = "sphere", effects = "default", shape;
    SynthOptions options;
    int bits = -1, supersample = -1;
    double black_level = -1, full_well = -1, read_noise = -1, vignetting = -1;
    bool srgb = false, no_shot = false, no_read = false, no_clip = false, overwrite = false, targets = false;
    std::vector<double> origin, intensity;
    size_t elevation_given = 0;
  };
  auto args = std::make_shared<Args>();
  SynthOptions& o = args->options;
  command->add_option("--out", args->out, "Session folder to write (must not exist unless --overwrite)")->required();
  command->add_option("--material", args->material, "Material JSON (samples/materials/*.json)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--sample", args->sample, "sphere or cylinder")
      ->check(CLI::IsMember({"sphere", "cylinder"}))
      ->capture_default_str();
  command->add_option("--radius", o.sample_radius, "Sample radius, metres")->capture_default_str();
  command->add_option("--length", o.cylinder_length, "Cylinder length, metres (axis vertical)")->capture_default_str();
  command->add_option("--photos", o.num_photos, "Number of photos on the arc")->capture_default_str();
  command->add_option("--arc-start-deg", o.arc_start_deg, "First camera azimuth from the light direction")
      ->capture_default_str();
  command->add_option("--arc-end-deg", o.arc_end_deg, "Last camera azimuth from the light direction")
      ->capture_default_str();
  command->add_option("--camera-distance", o.camera_distance, "Metres from the sample centre")->capture_default_str();
  auto* elevation =
      command->add_option("--camera-elevation-deg", o.camera_elevation_deg, "Camera elevation above the light's plane")
          ->capture_default_str();
  command->add_option("--light-distance", o.light_distance, "Metres from the sample centre")->capture_default_str();
  command->add_option("--light-intensity", args->intensity, "RGB intensity of the point light")->expected(3);
  command->add_option("--width", o.width, "Image width, pixels")->capture_default_str();
  command->add_option("--height", o.height, "Image height, pixels")->capture_default_str();
  command->add_option("--origin", args->origin, "Move the whole scene to x y z (metres)")->expected(3);
  command
      ->add_option("--effects", args->effects,
                   "Camera effects preset: default (12-bit, shot and read noise) or none (float EXR, noise-free)")
      ->check(CLI::IsMember({"default", "none"}))
      ->capture_default_str();
  command->add_option("--bits", args->bits, "Quantization bits: 8 to 16, or 0 for float EXR");
  command->add_flag("--srgb", args->srgb, "Store photos with the sRGB response");
  command->add_flag("--no-shot-noise", args->no_shot, "No photon shot noise");
  command->add_flag("--no-read-noise", args->no_read, "No read noise");
  command->add_flag("--no-clip", args->no_clip, "Do not clip at saturation (float output only)");
  command->add_option("--black-level", args->black_level, "Black level added to the signal (normalized units)");
  command->add_option("--full-well", args->full_well, "Electrons at saturation");
  command->add_option("--read-noise", args->read_noise, "Read noise, electrons");
  command->add_option("--supersample", args->supersample, "n x n rays per pixel");
  command->add_option("--vignetting", args->vignetting,
                      "Light lost at the image corners (cos^4 law), 0 to 0.9; writes the matching flat_field.exr");
  command
      ->add_option("--brackets", o.radiometry.brackets,
                   "Exposures per pose (an HDR bracket): the auto-exposure and shorter ones")
      ->capture_default_str();
  command->add_option("--bracket-step-ev", o.radiometry.bracket_step_ev, "Stops between a bracket's exposures")
      ->capture_default_str();
  command->add_flag("--light-unknown", o.radiometry.light_unknown,
                    "State a unit light intensity in session.json and add a white-reference photo that calibrates it");
  command->add_option("--exposure-target", o.exposure_target, "Auto-exposure: 99th percentile lands here")
      ->capture_default_str();
  command
      ->add_option("--fill-light", o.fill_light,
                   "Unmodelled fill light along each normal, as a fraction of the light's irradiance")
      ->capture_default_str();
  command->add_option("--seed", o.seed, "Random seed (output is reproducible)")->capture_default_str();
  command->add_flag("--targets", args->targets,
                    "Put the sample on a platform with a ring of ArUco markers of known layout (for `ibrdf align`);\n"
                    "cameras then look down from 45 degrees unless --camera-elevation-deg says otherwise");
  command->add_option("--target-dictionary", o.target_dictionary, "ArUco dictionary of the markers")
      ->capture_default_str();
  auto* light_photos =
      command->add_option("--light-photos", o.light_target_photos,
                          "With --targets: a card of ArUco markers on the light, and this many extra photos (role\n"
                          "\"targets\") that see both the platform and the card (default 3 with --targets; 0: none)");
  // ChArUco board photos through the session's camera, for `ibrdf align --calibrate OUT/calibration`.
  auto charuco = std::make_shared<CharucoPhotoOptions>();
  charuco->num_photos = 0;
  command
      ->add_option("--charuco-photos", charuco->num_photos,
                   "Also write this many photos of a ChArUco board (9 x 7 squares of 25 mm, DICT_5X5_100) taken\n"
                   "with the session's camera from varied poses into OUT/calibration (for align --calibrate)")
      ->capture_default_str();
  // Irregular shapes (docs/synth.md): a mesh sample with a simulated range scan.
  command
      ->add_option("--shape", args->shape,
                   "squash, pot or dent: render this irregular shape instead of --sample, on the marker platform\n"
                   "(implies --targets), and write a mesh sample: simulated range scans OUT/scan/view-N.ply in the\n"
                   "scanner's frame, the markers' corners as the scanner measured them, and OUT/truth-mesh.ply")
      ->check(CLI::IsMember({"squash", "pot", "dent"}));
  command->add_option("--scan-offset-m", o.scan_offset_m, "Distance of the scanner's frame origin from the world's")
      ->capture_default_str();
  command->add_option("--scan-spacing-m", o.scanner.spacing_m, "Range-scan grid spacing at the sample")
      ->capture_default_str();
  command->add_option("--scan-noise-m", o.scanner.noise_m, "Range-scan noise along the ray, one sigma")
      ->capture_default_str();
  command->add_option("--scan-views", o.scanner.views_around, "Range scans around the sample (plus one from above)")
      ->capture_default_str();
  command->add_option("--scan-target-noise-m", o.scan_target_noise_m, "Scanner's error on marker corners, one sigma")
      ->capture_default_str();
  command->add_option("--truth-mesh-spacing-m", o.truth_mesh_spacing_m, "Point spacing of truth-mesh.ply")
      ->capture_default_str();
  command->add_flag("--overwrite", args->overwrite, "Replace an existing output folder");
  command->callback([args, elevation, light_photos, charuco] {
    args->elevation_given = elevation->count();
    const bool light_photos_given = light_photos->count() > 0;
    SynthOptions options = args->options;
    options.sample = args->sample == "cylinder" ? SampleSpec::Kind::kCylinder : SampleSpec::Kind::kSphere;
    options.effects = args->effects == "none" ? CameraEffects::None() : CameraEffects();
    CameraEffects& e = options.effects;
    if (args->bits >= 0) e.bits = args->bits;
    if (args->supersample >= 0) e.supersample = args->supersample;
    if (args->black_level >= 0) e.black_level = args->black_level;
    if (args->full_well >= 0) e.full_well_e = args->full_well;
    if (args->read_noise >= 0) e.read_noise_e = args->read_noise;
    if (args->vignetting >= 0) e.vignetting = args->vignetting;
    if (args->srgb) e.srgb = true;
    if (args->no_shot) e.shot_noise = false;
    if (args->no_read) e.read_noise = false;
    if (args->no_clip) {
      if (e.bits != 0) ThrowError("--no-clip", "unclipped values need float output (--bits 0)");
      e.clip = false;
    }
    if (!args->shape.empty()) {
      options.shape = SynthShapeFromName(args->shape);
      args->targets = true;
    }
    if (args->targets) {
      options.targets = true;
      if (args->elevation_given == 0) options.camera_elevation_deg = 45.0;
      if (!light_photos_given) options.light_target_photos = 3;
    }
    if (!args->origin.empty()) options.origin = Eigen::Vector3d(args->origin[0], args->origin[1], args->origin[2]);
    if (!args->intensity.empty()) {
      options.light_intensity = Eigen::Vector3d(args->intensity[0], args->intensity[1], args->intensity[2]);
    }
    StageLog stage("synth");
    const std::unique_ptr<BrdfModel> material = LoadMaterial(args->material);
    const SynthSummary summary = WriteSyntheticSession(options, *material, args->material, args->out, args->overwrite);
    Log(1, summary.BriefReport());
    Log(1, "session written to " + args->out + "/session.json (truth in " + args->out + "/truth.json)");
    if (charuco->num_photos > 0) {
      CharucoPhotoOptions board = *charuco;
      board.seed = options.seed + 1000;
      const std::string calibration_dir = args->out + "/calibration";
      const CharucoPhotosSummary photos =
          WriteCharucoPhotos(Session::Load(args->out).camera, board, calibration_dir, /*overwrite=*/false);
      Log(1, photos.BriefReport() + ", written to " + calibration_dir);
    }
  });
}

}  // namespace

IBRDF_REGISTER_COMMAND(10, AddSynthCommand);

}  // namespace ibrdf
