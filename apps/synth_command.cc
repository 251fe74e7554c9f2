// ibrdf synth: writes a synthetic measurement session with known truth.
#include <iostream>

#include "apps/commands.h"
#include "core/brdf_model.h"
#include "core/error.h"
#include "core/logging.h"
#include "derender/synthetic.h"

namespace ibrdf {

namespace {
void AddSynthCommand(CLI::App& app) {
  auto* command = app.add_subcommand(
      "synth",
      "Render a synthetic measurement session (photos, session.json, truth.json) of an analytic sphere or\n"
      "cylinder with a known BRDF, cameras on an arc from beside the light to opposite it (paper, Fig. 3/4).");
  struct Args {
    std::string out, material, sample = "sphere", effects = "default";
    SynthOptions options;
    int bits = -1, supersample = -1;
    double black_level = -1, full_well = -1, read_noise = -1;
    bool srgb = false, no_shot = false, no_read = false, no_clip = false, overwrite = false, targets = false;
    std::vector<double> origin, intensity;
    size_t elevation_given = 0;
  };
  auto args = std::make_shared<Args>();
  SynthOptions& o = args->options;
  command->add_option("--out", args->out, "Session folder to write (must not exist unless --overwrite)")->required();
  command->add_option("--material", args->material, "Material JSON (samples/materials/*.json)")->required()->check(CLI::ExistingFile);
  command->add_option("--sample", args->sample, "sphere or cylinder")->check(CLI::IsMember({"sphere", "cylinder"}))->capture_default_str();
  command->add_option("--radius", o.sample_radius, "Sample radius, metres")->capture_default_str();
  command->add_option("--length", o.cylinder_length, "Cylinder length, metres (axis vertical)")->capture_default_str();
  command->add_option("--photos", o.num_photos, "Number of photos on the arc")->capture_default_str();
  command->add_option("--arc-start-deg", o.arc_start_deg, "First camera azimuth from the light direction")->capture_default_str();
  command->add_option("--arc-end-deg", o.arc_end_deg, "Last camera azimuth from the light direction")->capture_default_str();
  command->add_option("--camera-distance", o.camera_distance, "Metres from the sample centre")->capture_default_str();
  auto* elevation = command->add_option("--camera-elevation-deg", o.camera_elevation_deg, "Camera elevation above the light's plane")->capture_default_str();
  command->add_option("--light-distance", o.light_distance, "Metres from the sample centre")->capture_default_str();
  command->add_option("--light-intensity", args->intensity, "RGB intensity of the point light")->expected(3);
  command->add_option("--width", o.width, "Image width, pixels")->capture_default_str();
  command->add_option("--height", o.height, "Image height, pixels")->capture_default_str();
  command->add_option("--origin", args->origin, "Move the whole scene to x y z (metres)")->expected(3);
  command->add_option("--effects", args->effects,
                      "Camera effects preset: default (12-bit, shot and read noise) or none (float EXR, noise-free)")
      ->check(CLI::IsMember({"default", "none"}))->capture_default_str();
  command->add_option("--bits", args->bits, "Quantization bits: 8 to 16, or 0 for float EXR");
  command->add_flag("--srgb", args->srgb, "Store photos with the sRGB response");
  command->add_flag("--no-shot-noise", args->no_shot, "No photon shot noise");
  command->add_flag("--no-read-noise", args->no_read, "No read noise");
  command->add_flag("--no-clip", args->no_clip, "Do not clip at saturation (float output only)");
  command->add_option("--black-level", args->black_level, "Black level added to the signal (normalized units)");
  command->add_option("--full-well", args->full_well, "Electrons at saturation");
  command->add_option("--read-noise", args->read_noise, "Read noise, electrons");
  command->add_option("--supersample", args->supersample, "n x n rays per pixel");
  command->add_option("--exposure-target", o.exposure_target, "Auto-exposure: 99th percentile lands here")->capture_default_str();
  command->add_option("--seed", o.seed, "Random seed (output is reproducible)")->capture_default_str();
  command->add_flag("--targets", args->targets,
                    "Put the sample on a platform with a ring of ArUco markers of known layout (for `ibrdf align`);\n"
                    "cameras then look down from 45 degrees unless --camera-elevation-deg says otherwise");
  command->add_option("--target-dictionary", o.target_dictionary, "ArUco dictionary of the markers")->capture_default_str();
  auto* light_photos = command->add_option("--light-photos", o.light_target_photos,
                      "With --targets: a card of ArUco markers on the light, and this many extra photos (role\n"
                      "\"targets\") that see both the platform and the card (default 3 with --targets; 0: none)");
  command->add_flag("--overwrite", args->overwrite, "Replace an existing output folder");
  command->callback([args, elevation, light_photos] {
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
    if (args->srgb) e.srgb = true;
    if (args->no_shot) e.shot_noise = false;
    if (args->no_read) e.read_noise = false;
    if (args->no_clip) {
      if (e.bits != 0) ThrowError("--no-clip", "unclipped values need float output (--bits 0)");
      e.clip = false;
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
    const SynthSummary summary =
        WriteSyntheticSession(options, *material, args->material, args->out, args->overwrite);
    Log(1, summary.BriefReport());
    Log(1, "session written to " + args->out + "/session.json (truth in " + args->out + "/truth.json)");
  });
}

}  // namespace

IBRDF_REGISTER_COMMAND(10, AddSynthCommand);

}  // namespace ibrdf
