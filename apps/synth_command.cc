// ibrdf synth: writes a synthetic session with known truth; the flags fill a SynthRequest (synth/synth_request.h).
#include "apps/commands.h"
#include "core/brdf_model.h"
#include "core/error.h"
#include "core/logging.h"
#include "core/merl_brdf.h"
#include "synth/synth_request.h"
#include "synth/synthetic.h"

namespace ibrdf {
namespace {
void AddSynthCommand(CLI::App& app) {
  auto* command = app.add_subcommand(
      "synth",
      "Render a synthetic measurement session (photos, session.json, truth.json) of an analytic sphere or\n"
      "cylinder with a known BRDF, cameras on an arc from beside the light to opposite it (paper, Fig. 3/4),\n"
      "or (--rig) a light dome or a turntable;\n"
      "or (--shape) of a squash, clay pot or dented sphere as a mesh sample with simulated range scans.");
  struct Args {
    std::string out, material;
    bool overwrite = false;
    SynthRequest request;
    std::vector<double> camera_matrix;  // 9 values, row-major
    bool chart_detect = false;
    std::string colour_space = "linear_srgb";
    std::string no_data = "skip";
    std::string merl_lookup = "nearest";
  };
  auto args = std::make_shared<Args>();
  CLI::App& c = *command;
  SynthRequest& r = args->request;
  SynthOptions& o = r.options;
  // An option whose default --help shows.
  auto add = [&c](const char* n, auto& v, const char* h) { return c.add_option(n, v, h)->capture_default_str(); };
  c.add_option("--out", args->out, "Session folder to write (must not exist unless --overwrite)")->required();
  c.add_option("--material", args->material, "Material JSON (samples/materials/*.json) or a MERL table (.binary)")
      ->required()
      ->check(CLI::ExistingFile);
  add("--no-data", args->no_data,
      "A MERL table's cells without data (-1) where a sample pixel looks one up: skip (render it black and\n"
      "leave it out of the samples through the photo's mask, masks/), zero (render it black and let\n"
      "derender take it as a zero-valued sample: invented data, warned) or error (refuse)")
      ->check(CLI::IsMember({"skip", "zero", "error"}));
  auto* merl_lookup =
      add("--merl-lookup", args->merl_lookup,
          "A MERL table's lookups: nearest (the cell holding the direction pair, as the MERL reader\n"
          "BRDFRead.cpp does; a piecewise-constant BRDF) or linear (trilinear between cell centres in the\n"
          "table's index coordinates); recorded in truth.json, so compare and reconstruct --truth use it too")
          ->check(CLI::IsMember({"nearest", "linear"}));
  add("--sample", r.sample, "sphere or cylinder")->check(CLI::IsMember({"sphere", "cylinder"}));
  AddDeprecatedAlias(c, add("--radius-m", o.scene.sample_radius, "Sample radius"), "--radius", o.scene.sample_radius);
  AddDeprecatedAlias(c, add("--length-m", o.scene.cylinder_length, "Cylinder length (axis vertical)"), "--length",
                     o.scene.cylinder_length);
  add("--rig", r.rig,
      "arc: one light, cameras on an arc (the paper); dome: one fixed camera, a light per photo on the\n"
      "upper hemisphere; turntable: camera and light fixed while the sample turns (a pose and a light\n"
      "per photo in the sample's frame)")
      ->check(CLI::IsMember({"arc", "dome", "turntable"}));
  add("--photos", o.rig.num_photos, "Number of photos (arc: cameras; dome: lights; turntable: turntable stops)");
  add("--arc-start-deg", o.rig.arc_start_deg,
      "First camera azimuth from the light direction (dome: the smallest angle between camera and a light)");
  add("--arc-end-deg", o.rig.arc_end_deg,
      "Last camera azimuth from the light direction (dome: the largest angle between camera and a light)");
  add("--dome-min-elevation-deg", o.rig.dome_min_elevation_deg, "Dome: the lowest lights' elevation");
  add("--turntable-phase-deg", o.rig.turntable_phase_deg, "Turntable: camera azimuth from the light, in the lab");
  add("--turntable-span-deg", o.rig.turntable_span_deg, "Turntable: the sample's turn over all photos");
  AddDeprecatedAlias(c, add("--camera-distance-m", o.rig.camera_distance, "Camera distance from the sample centre"),
                     "--camera-distance", o.rig.camera_distance);
  auto* elevation =
      add("--camera-elevation-deg", o.rig.camera_elevation_deg, "Camera elevation above the light's plane");
  AddDeprecatedAlias(c, add("--light-distance-m", o.scene.light_distance, "Light distance from the sample centre"),
                     "--light-distance", o.scene.light_distance);
  c.add_option("--light-intensity", r.light_intensity, "RGB intensity of the point light")->expected(3);
  add("--width", o.rig.width, "Image width, pixels");
  add("--height", o.rig.height, "Image height, pixels");
  AddDeprecatedAlias(c, c.add_option("--origin-m", r.origin, "Move the whole scene to x y z")->expected(3), "--origin",
                     r.origin);
  add("--effects", r.effects,
      "Camera effects preset: default (12-bit, shot and read noise) or none (float EXR, noise-free)")
      ->check(CLI::IsMember({"default", "none"}));
  c.add_option("--bits", r.bits, "Quantization bits: 8 to 16, or 0 for float EXR");
  c.add_flag("--srgb", r.srgb, "Store photos with the sRGB response");
  c.add_flag("--no-shot-noise", r.no_shot_noise, "No photon shot noise");
  c.add_flag("--no-read-noise", r.no_read_noise, "No read noise");
  c.add_flag("--no-clip", r.no_clip, "Do not clip at saturation (float output only)");
  c.add_option("--black-level", r.black_level, "Black level added to the signal (normalized units)");
  AddDeprecatedAlias(c, c.add_option("--full-well-e", r.full_well_e, "Electrons at saturation"), "--full-well",
                     r.full_well_e);
  AddDeprecatedAlias(c, c.add_option("--read-noise-e", r.read_noise_e, "Read noise, electrons (one sigma)"),
                     "--read-noise", r.read_noise_e);
  c.add_option("--supersample", r.supersample, "n x n rays per pixel");
  c.add_option("--vignetting", r.vignetting,
               "Light lost at the image corners (cos^4 law), 0 to 0.9; writes the matching flat_field.exr");
  add("--brackets", o.radiometry.brackets, "Exposures per pose (an HDR bracket): the auto-exposure and shorter ones");
  add("--bracket-step-ev", o.radiometry.bracket_step_ev, "Stops between a bracket's exposures");
  c.add_flag("--light-unknown", o.radiometry.light_unknown,
             "State no light intensity in session.json and add a white-reference photo per light that measures it");
  c.add_flag("--white-card", o.targets.white_card,
             "With --targets and --light-unknown: the white reference on a card framed by 4 ArUco markers\n"
             "(`ibrdf targets`' white card, ids 40-43, 20 mm), standing where the sample was and seen with the\n"
             "platform, so that `ibrdf align` can pose it (targets.white_reference)");
  add("--exposure-target", o.rig.exposure_target, "Auto-exposure: 99th percentile lands here");
  c.add_option("--camera-matrix", args->camera_matrix,
               "The camera's colour: camera RGB = M * linear sRGB in every photo, M as 9 numbers row by row\n"
               "(the session then states the light's intensity in camera RGB)")
      ->expected(9);
  c.add_flag("--colour-chart", o.colour.chart,
             "Also photograph a ColorChecker Classic (reference linear-sRGB albedos) at the sample's place under\n"
             "the first light, from the first camera: the session's colour_chart block, for `ibrdf colour`");
  c.add_flag("--colour-chart-detect", args->chart_detect,
             "With --colour-chart: leave the corner patches out of the session (`ibrdf colour` must detect the chart)");
  add("--colour-chart-pitch-m", o.colour.chart_pitch, "With --colour-chart: patch centre to centre, metres");
  add("--colour-chart-exposure", o.colour.chart_exposure_scale,
      "With --colour-chart: the chart photo's exposure relative to its auto-exposure (> 1.25 clips the white)");
  add("--colour-space", args->colour_space, "With --colour-chart: the colour_chart block's target space")
      ->check(CLI::IsMember({"linear_srgb", "xyz"}));
  add("--fill-light", o.scene.fill_light,
      "Unmodelled fill light along each normal, as a fraction of the light's irradiance");
  add("--seed", o.seed, "Random seed (output is reproducible)");
  c.add_flag("--targets", r.targets,
             "Put the sample on a platform with a ring of ArUco markers of known layout (for `ibrdf align`);\n"
             "cameras then look down from 45 degrees unless --camera-elevation-deg says otherwise");
  add("--target-dictionary", o.targets.dictionary, "ArUco dictionary of the markers");
  auto* light_photos =
      c.add_option("--light-photos", o.targets.light_photos,
                   "With --targets: a card of ArUco markers on the light, and this many extra photos (role\n"
                   "\"targets\") that see both the platform and the card (default 3 with --targets; 0: none)");
  add("--charuco-photos", r.charuco_photos,
      "Also write this many photos of a ChArUco board (9 x 7 squares of 25 mm, DICT_5X5_100) taken\n"
      "with the session's camera from varied poses into OUT/calibration (for align --calibrate)");
  c.add_option("--shape", r.shape,
               "squash, pot or dent: render this irregular shape instead of --sample, on the marker platform\n"
               "(implies --targets), and write a mesh sample: simulated range scans OUT/scan/view-N.ply in the\n"
               "scanner's frame, the markers' corners as the scanner measured them, and OUT/truth-mesh.ply")
      ->check(CLI::IsMember({"squash", "pot", "dent"}));
  add("--scan-offset-m", o.scan.offset_m, "Distance of the scanner's frame origin from the world's");
  add("--scan-spacing-m", o.scan.scanner.spacing_m, "Range-scan grid spacing at the sample");
  add("--scan-noise-m", o.scan.scanner.noise_m, "Range-scan noise along the ray, one sigma");
  add("--scan-views", o.scan.scanner.views_around, "Range scans around the sample (plus one from above)");
  add("--scan-target-noise-m", o.scan.target_noise_m, "Scanner's error on marker corners, one sigma");
  add("--truth-mesh-spacing-m", o.scan.truth_mesh_spacing_m, "Point spacing of truth-mesh.ply");
  c.add_flag("--overwrite", args->overwrite, "Replace an existing output folder");
  c.callback([args, elevation, light_photos, merl_lookup] {
    SynthRequest& request = args->request;
    request.camera_elevation_given = elevation->count() > 0;
    request.light_photos_given = light_photos->count() > 0;
    if (!args->camera_matrix.empty()) {
      request.options.colour.camera_matrix =
          Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(args->camera_matrix.data());
    }
    request.options.colour.chart_corners = !args->chart_detect;
    ColourSpaceFromName(args->colour_space, &request.options.colour.space);
    SynthOptions options = SynthOptionsFromRequest(request);
    options.no_data = SynthNoDataFromName(args->no_data);
    RequireValidOptions(options, "ibrdf synth");
    StageLog stage("synth");
    RequireWritableOutput(args->out, args->overwrite, {args->material});
    std::unique_ptr<BrdfModel> material = LoadMaterial(args->material);
    if (merl_lookup->count() > 0) {
      const auto* table = dynamic_cast<const MerlBrdf*>(material.get());
      if (!table) ThrowError(args->material, "--merl-lookup applies to MERL tables (.binary) only");
      material = std::make_unique<MerlBrdf>(table->table(), table->path(),
                                            MerlLookupFromName(args->merl_lookup, "synth --merl-lookup"));
    }
    const SynthSummary summary = WriteSyntheticSession(options, *material, args->material, args->out, args->overwrite);
    Log(1, summary.BriefReport());
    if (!summary.NoDataReport().empty()) {
      Log(summary.no_data == SynthNoData::kZero ? 0 : 1,
          std::string(summary.no_data == SynthNoData::kZero ? "warning: " : "") + args->material + ": " +
              summary.NoDataReport() + " (truth.json generator.material_no_data)");
    }
    Log(1, "session written to " + args->out + "/session.json (truth in " + args->out + "/truth.json)");
    if (request.charuco_photos > 0) {
      const CharucoPhotosSummary photos = WriteSessionCharucoPhotos(args->out, request.charuco_photos, options.seed);
      Log(1, photos.BriefReport() + ", written to " + args->out + "/calibration");
    }
  });
}
}  // namespace

IBRDF_REGISTER_COMMAND(10, AddSynthCommand);

}  // namespace ibrdf
