// ibrdf session init: a draft session.json from a camera's photos (capture/session_init.h) behind flags.
#include <iostream>
#include <memory>

#include "apps/commands.h"
#include "capture/session_init.h"
#include "core/error.h"
#include "core/logging.h"

namespace ibrdf {
namespace {

std::optional<Eigen::Vector3d> Vector(const std::vector<double>& values) {
  if (values.empty()) return std::nullopt;
  return Eigen::Vector3d(values[0], values[1], values[2]);
}

void AddSessionCommand(CLI::App& app) {
  auto* session = app.add_subcommand("session", "Session files: `session init` drafts one from a camera's photos");
  session->require_subcommand(1);
  auto* init = session->add_subcommand(
      "init",
      "Draft OUT/session.json from the photos' EXIF: exposure time, ISO (as gain), focal length and size;\n"
      "exposure brackets grouped; the camera from --camera or guessed from EXIF. Prints what was assumed and\n"
      "what is still missing; writes session.json when it validates, else session.draft.json (exit status 2).");
  struct Args {
    SessionInitOptions o;
    std::string out;
    std::vector<double> light_position, light_intensity, sample_center;
    double sample_radius = 0.0, white_size = 0.0;
    std::vector<double> white_reflectance;
    std::vector<double> chart_corners;
  };
  auto args = std::make_shared<Args>();
  SessionInitOptions& o = args->o;
  init->add_option("photos", o.photos, "Measurement photos, in capture order")->required()->check(CLI::ExistingFile);
  init->add_option("--out", args->out, "Folder for session.json (the photos stay where they are)")->required();
  init->add_option("--target-photos", o.target_photos, "Photos for the alignment only (e.g. of the light's markers)")
      ->check(CLI::ExistingFile);
  init->add_option("--white-photos", o.white_photos,
                   "Photos of the white reference (its card's markers pose it in `ibrdf align`); it measures the "
                   "light's intensity")
      ->check(CLI::ExistingFile);
  init->add_option("--white-size-m", args->white_size, "The white reference's size (metres, the patch's side)");
  init->add_option("--white-reflectance", args->white_reflectance,
                   "The white reference's albedo R G B (default 0.99: Spectralon)")
      ->expected(3);
  init->add_option("--chart-photos", o.chart_photos,
                   "Photos of a ColorChecker Classic 24 under the session's light (one view; `ibrdf colour` fits the "
                   "matrix to linear sRGB)")
      ->check(CLI::ExistingFile);
  init->add_option("--chart-corners", args->chart_corners,
                   "Pixel centres X Y of the chart's patches 1, 6, 24 and 19 (top-left, top-right, bottom-right, "
                   "bottom-left); without them `ibrdf colour` detects the chart (OpenCV mcc)")
      ->expected(8);
  init->add_option("--targets", o.targets_file, "The markers' layout: targets.json from `ibrdf targets`")
      ->check(CLI::ExistingFile);
  init->add_option("--camera", o.camera_file, "A JSON file with a calibrated \"camera\" block (e.g. a session.json)")
      ->check(CLI::ExistingFile);
  init->add_option("--sensor-width-mm", o.sensor_width_mm, "Sensor width, when EXIF has no focal-plane resolution");
  init->add_option("--base-iso", o.base_iso, "The ISO of gain 1 (default: the lowest ISO of the photos)");
  init->add_option("--bracket-size", o.bracket_size,
                   "Exposures per bracket (0: group by capture time and exposure steps; 1: no brackets)")
      ->capture_default_str();
  init->add_option("--bracket-gap-s", o.bracket_gap_s, "Longest time between two exposures of one bracket")
      ->capture_default_str();
  AddDeprecatedAlias(
      *init,
      init->add_option("--light-position-m", args->light_position, "The light's position X Y Z (targets' frame)")
          ->expected(3),
      "--light-position", args->light_position);
  init->add_option("--light-intensity", args->light_intensity, "The light's RGB intensity (session radiance unit)")
      ->expected(3);
  AddDeprecatedAlias(*init, init->add_option("--sample-radius-m", args->sample_radius, "The sphere's radius"),
                     "--sample-radius", args->sample_radius);
  init->add_flag("--radius-known", o.radius_known, "The radius is measured: `ibrdf align` fits only the centre");
  AddDeprecatedAlias(*init,
                     init->add_option("--sample-center-m", args->sample_center,
                                      "The sphere's centre X Y Z (default with --targets: on the platform's centre)")
                         ->expected(3),
                     "--sample-center", args->sample_center);
  init->add_option("--response", o.response, "\"linear\" or \"srgb\" (default: from the file format)");
  init->add_option("--name", o.name, "The session's name (default: the output folder's)");
  init->add_flag("--overwrite", o.overwrite, "Replace session.json / session.draft.json in OUT");
  init->callback([args] {
    SessionInitOptions& options = args->o;
    options.light_position = Vector(args->light_position);
    options.light_intensity = Vector(args->light_intensity);
    options.sample_center = Vector(args->sample_center);
    if (args->sample_radius > 0.0) options.sample_radius = args->sample_radius;
    if (args->white_size != 0.0) options.white_size = args->white_size;
    options.white_reflectance = Vector(args->white_reflectance);
    if (args->chart_corners.size() == 8) {
      std::array<Eigen::Vector2d, 4> corners;
      for (int k = 0; k < 4; ++k)
        corners[k] = Eigen::Vector2d(args->chart_corners[2 * k], args->chart_corners[2 * k + 1]);
      options.chart_corners = corners;
    }
    RequireValidOptions(options, "ibrdf session init");
    const SessionInitResult result = InitSession(options, args->out);
    for (const std::string& line : result.assumptions) std::cout << "assumed: " << line << "\n";
    for (const std::string& line : result.missing) std::cout << "missing: " << line << "\n";
    Log(1, result.BriefReport());
    if (!result.complete) {
      std::cout << "incomplete: supply the missing items and run again; the draft is " << result.path << "\n";
      throw CLI::RuntimeError(2);
    }
    std::cout << "session: " << result.path << "\n";
  });
}

}  // namespace

IBRDF_REGISTER_COMMAND(15, AddSessionCommand);

}  // namespace ibrdf
