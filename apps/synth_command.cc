// ibrdf synth: writes a synthetic session with known truth; the flags fill a SynthRequest (synth/synth_request.h).
#include "apps/commands.h"
#include "synth/synth_request.h"

namespace ibrdf {
namespace {

struct SynthArgs {
  std::string out, material, camera_positions;
  bool overwrite = false;
  SynthRequest request;
  CLI::Option *elevation = nullptr, *light_photos = nullptr, *merl_lookup = nullptr;
};

void RunSynth(SynthArgs& args) {
  SynthRequest& request = args.request;
  // A usage error (exit 2, with the usage line), as CLI11's own ->required() would give.
  if (args.material.empty() && request.material_map.empty()) throw CLI::RequiredError("--material or --material-map");
  request.camera_elevation_given = args.elevation->count() > 0;
  request.light_photos_given = args.light_photos->count() > 0;
  request.merl_lookup_given = args.merl_lookup->count() > 0;
  if (!args.camera_positions.empty()) request.options.rig.extra_camera_positions = ReadCameraPositions(args.camera_positions);
  const SynthOptions options = SynthOptionsFromRequest(request);
  RequireValidOptions(options, "ibrdf synth");
  StageLog stage("synth");
  WriteSynthStage(request, options, args.material, args.out, args.overwrite);
}

}  // namespace

IBRDF_COMMAND(10, Synth) {
  CLI::App& c = *app.add_subcommand(
      "synth",
      "Render a synthetic session (photos, session.json, truth.json) with a known BRDF: an analytic sphere or\n"
      "cylinder, or (--shape) a mesh sample with range scans, on an arc, a dome or a turntable (docs/cli.md).");
  auto args = std::make_shared<SynthArgs>();
  SynthRequest& r = args->request;
  SynthOptions& o = r.options;
  AddOutputFlags(c, args->out, args->overwrite, "Session folder to write", "Replace an existing output folder");
  c.add_option("--material", args->material,
               "Material JSON (samples/materials/*.json) or a MERL table (.binary); required unless --material-map")
      ->check(CLI::ExistingFile);
  c.add_option("--material-map", r.material_map,
               "A spatially varying sample: stripes of basis materials (JSON, docs/synth.md), instead of --material")
      ->check(CLI::ExistingFile)
      ->excludes("--material");
  AddOption(c, "--no-data", r.no_data, "A MERL table's cells without data: skip (masked out), zero (warned) or error")
      ->check(CLI::IsMember({"skip", "zero", "error"}));
  args->merl_lookup = AddOption(c, "--merl-lookup", r.merl_lookup,
                                "A MERL table's lookups: nearest (its cell, as BRDFRead.cpp) or linear (trilinear)")
                          ->check(CLI::IsMember({"nearest", "linear"}));
  AddOption(c, "--sample", r.sample, "sphere or cylinder")->check(CLI::IsMember({"sphere", "cylinder"}));
  AddRenamedOption(c, "--radius-m", "--radius", o.scene.sample_radius, "Sample radius");
  AddRenamedOption(c, "--length-m", "--length", o.scene.cylinder_length, "Cylinder length (axis vertical)");
  AddOption(c, "--rig", r.rig, "arc (cameras on an arc), dome (a light per photo) or turntable (the sample turns)")
      ->check(CLI::IsMember({"arc", "dome", "turntable"}));
  AddOption(c, "--photos", o.rig.num_photos, "Number of photos (arc: cameras; dome: lights; turntable: stops)");
  c.add_option("--camera-positions", args->camera_positions,
               "Arc: a camera more at each position of this JSON file (a list of [x, y, z], metres, or a\n"
               "capture-check.json's suggestions), looking at the sample")
      ->check(CLI::ExistingFile);
  AddOption(c, "--arc-start-deg", o.rig.arc_start_deg, "First camera azimuth from the light (dome: smallest angle)");
  AddOption(c, "--arc-end-deg", o.rig.arc_end_deg, "Last camera azimuth from the light (dome: largest angle)");
  AddOption(c, "--dome-min-elevation-deg", o.rig.dome_min_elevation_deg, "Dome: the lowest lights' elevation");
  AddOption(c, "--turntable-phase-deg", o.rig.turntable_phase_deg, "Turntable: camera azimuth from the light");
  AddOption(c, "--turntable-span-deg", o.rig.turntable_span_deg, "Turntable: the sample's turn over all photos");
  AddRenamedOption(c, "--camera-distance-m", "--camera-distance", o.rig.camera_distance, "Camera distance");
  args->elevation = AddOption(c, "--camera-elevation-deg", o.rig.camera_elevation_deg, "Above the light's plane");
  AddRenamedOption(c, "--light-distance-m", "--light-distance", o.scene.light_distance, "Light distance");
  c.add_option("--light-intensity", r.light_intensity, "RGB intensity of the point light")->expected(3);
  AddOption(c, "--width", o.rig.width, "Image width, pixels");
  AddOption(c, "--height", o.rig.height, "Image height, pixels");
  AddDeprecatedAlias(c, c.add_option("--origin-m", r.origin, "Move the whole scene to x y z")->expected(3), "--origin",
                     r.origin);
  AddOption(c, "--fill-light", o.scene.fill_light, "Unmodelled fill light, a fraction of the light's irradiance");
  AddOption(c, "--seed", o.seed, "Random seed (output is reproducible)");
  AddOption(c, "--exposure-target", o.rig.exposure_target, "Auto-exposure: 99th percentile lands here");
  // The camera's effects and colour, the colour chart, the targets and the simulated scans.
  AddOption(c, "--effects", r.effects, "Camera effects: default (12-bit, noise) or none (float EXR, noise-free)")
      ->check(CLI::IsMember({"default", "none"}));
  c.add_option("--bits", r.bits, "Quantization bits: 8 to 16, or 0 for float EXR");
  c.add_flag("--srgb", r.srgb, "Store photos with the sRGB response");
  c.add_option("--response", r.response, "The sensor's curve: linear, srgb or toe-shoulder (a film-like S-curve)")
      ->check(CLI::IsMember({"linear", "srgb", "toe-shoulder"}));
  c.add_flag("--no-shot-noise", r.no_shot_noise, "No photon shot noise");
  c.add_flag("--no-read-noise", r.no_read_noise, "No read noise");
  c.add_flag("--no-clip", r.no_clip, "Do not clip at saturation (float output only)");
  c.add_option("--black-level", r.black_level, "Black level added to the signal (normalized units)");
  AddDeprecatedAlias(c, c.add_option("--full-well-e", r.full_well_e, "Electrons at saturation"), "--full-well",
                     r.full_well_e);
  AddDeprecatedAlias(c, c.add_option("--read-noise-e", r.read_noise_e, "Read noise, electrons (one sigma)"),
                     "--read-noise", r.read_noise_e);
  c.add_option("--supersample", r.supersample, "n x n rays per pixel");
  c.add_option("--vignetting", r.vignetting, "Corner light loss (cos^4), 0 to 0.9; writes flat_field.exr");
  AddOption(c, "--brackets", o.radiometry.brackets, "Exposures per pose (an HDR bracket, shorter than the auto one)");
  AddOption(c, "--bracket-step-ev", o.radiometry.bracket_step_ev, "Stops between a bracket's exposures");
  c.add_flag("--light-unknown", o.radiometry.light_unknown, "No light intensity; a white-reference photo per light");
  c.add_flag("--response-unknown", o.radiometry.response_unknown,
             "The session states its response as \"unknown\" (measure it: `ibrdf response`, from --brackets)");
  c.add_option("--camera-matrix", r.camera_matrix, "Camera RGB = M * linear sRGB, M as 9 numbers row by row")
      ->expected(9);
  c.add_flag("--colour-chart", o.colour.chart, "Also photograph a ColorChecker Classic (for `ibrdf colour`)");
  c.add_flag("--colour-chart-detect", r.colour_chart_detect, "No chart corners in the session (colour detects it)");
  AddOption(c, "--colour-chart-pitch-m", o.colour.chart_pitch, "With --colour-chart: patch centre to centre");
  AddOption(c, "--colour-chart-exposure", o.colour.chart_exposure_scale, "Chart photo's exposure (> 1.25 clips)");
  AddOption(c, "--colour-space", r.colour_space, "With --colour-chart: the colour_chart block's target space")
      ->check(CLI::IsMember({"linear_srgb", "xyz"}));
  c.add_flag("--targets", r.targets, "Sample on an ArUco marker platform (for `ibrdf align`; cameras at 45 deg)");
  AddOption(c, "--target-dictionary", o.targets.dictionary, "ArUco dictionary of the markers");
  args->light_photos = c.add_option("--light-photos", o.targets.light_photos,
                                    "With --targets: photos of the light's marker card (default 3; 0: none)");
  c.add_flag("--white-card", o.targets.white_card, "With --targets --light-unknown: the white reference on a card");
  AddOption(c, "--charuco-photos", r.charuco_photos, "ChArUco board photos into OUT/calibration (align --calibrate)");
  c.add_option("--shape", r.shape, "squash, pot or dent: a mesh sample with simulated range scans (with --targets)")
      ->check(CLI::IsMember({"squash", "pot", "dent"}));
  AddOption(c, "--scan-offset-m", o.scan.offset_m, "Distance of the scanner's frame origin from the world's");
  AddOption(c, "--scan-spacing-m", o.scan.scanner.spacing_m, "Range-scan grid spacing at the sample");
  AddOption(c, "--scan-noise-m", o.scan.scanner.noise_m, "Range-scan noise along the ray, one sigma");
  AddOption(c, "--scan-views", o.scan.scanner.views_around, "Range scans around the sample (plus one from above)");
  AddOption(c, "--scan-target-noise-m", o.scan.target_noise_m, "Scanner's error on marker corners, one sigma");
  AddOption(c, "--truth-mesh-spacing-m", o.scan.truth_mesh_spacing_m, "Point spacing of truth-mesh.ply");
  c.callback([args] { RunSynth(*args); });
}

}  // namespace ibrdf
