// ibrdf session init: a draft session.json from a camera's photos (capture/session_init.h) behind flags.
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <sstream>

#include "apps/commands.h"
#include "capture/session_init.h"
#include "core/error.h"

namespace ibrdf {
namespace {

// Three values as a vector (none when not given).
std::optional<Eigen::Vector3d> Vector3(const std::vector<double>& v) {
  if (v.empty()) return std::nullopt;
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

// --exposure-s: one number, or numbers separated by commas (one per photo), each positive seconds.
std::vector<double> ExposureTimes(const std::string& text) {
  std::vector<double> times;
  if (text.empty() || text.back() == ',') {
    ThrowError("--exposure-s", "\"" + text + "\": expected S, or S1,S2,... one per photo (seconds)");
  }
  std::stringstream stream(text);
  std::string word;
  while (std::getline(stream, word, ',')) {
    char* end = nullptr;
    const double t = std::strtod(word.c_str(), &end);
    if (word.empty() || end != word.c_str() + word.size() || !(t > 0.0) || !std::isfinite(t)) {
      ThrowError("--exposure-s", "\"" + word + "\" is not a positive number of seconds (expected S, or S1,S2,... one "
                                 "per photo)");
    }
    times.push_back(t);
  }
  return times;
}

}  // namespace

IBRDF_COMMAND(15, Session) {
  auto* session = app.add_subcommand("session", "Session files: `session init` drafts one from a camera's photos");
  session->require_subcommand(1);
  auto* c = session->add_subcommand(
      "init",
      "Draft OUT/session.json from the photos' EXIF: exposure time, ISO (as gain), focal length and size;\n"
      "exposure brackets grouped; the camera from --camera or guessed from EXIF. Prints what was assumed and\n"
      "what is still missing; writes session.json when it validates, else session.draft.json (exit status 2).");
  struct Args {
    SessionInitOptions o;
    std::string out, exposure_s;
    std::vector<double> light_position, light_intensity, sample_center, white_reflectance, chart_corners;
    double sample_radius = 0.0, white_size = 0.0;
  };
  auto args = std::make_shared<Args>();
  SessionInitOptions& o = args->o;
  const auto files = [c](const char* name, auto& paths, const char* help) {  // one file or several
    c->add_option(name, paths, help)->check(CLI::ExistingFile);
  };
  // N numbers, as N words or one comma-separated word (R,G,B, as the missing list suggests).
  const auto vector = [c](const char* name, std::vector<double>& values, int n, const char* help) {
    return c->add_option(name, values, help)->delimiter(',')->expected(n);
  };
  c->add_option("photos", o.photos, "Measurement photos, in capture order")->required()->check(CLI::ExistingFile);
  c->add_option("--out", args->out, "Folder for session.json (the photos stay where they are)")->required();
  c->add_flag("--overwrite", o.overwrite, "Replace session.json / session.draft.json in OUT");
  files("--target-photos", o.target_photos, "Photos for the alignment only (e.g. of the light's markers)");
  files("--white-photos", o.white_photos, "Photos of the white reference (measures the light's intensity)");
  c->add_option("--white-size-m", args->white_size, "The white reference's size (metres, the patch's side)");
  vector("--white-reflectance", args->white_reflectance, 3, "The white reference's albedo R G B (default 0.99)");
  files("--chart-photos", o.chart_photos, "Photos of a ColorChecker Classic 24 under the session's light");
  vector("--chart-corners", args->chart_corners, 8, "Pixel centres X Y of the chart's patches 1, 6, 24 and 19");
  files("--targets", o.targets_file, "The markers' layout: targets.json from `ibrdf targets`");
  files("--camera", o.camera_file, "A JSON file with a calibrated \"camera\" block (e.g. a session.json)");
  c->add_option("--sensor-width-mm", o.sensor_width_mm, "Sensor width, when EXIF has no focal-plane resolution");
  c->add_option("--exposure-s", args->exposure_s,
                "Exposure time (s) of photos whose EXIF has none: S for all, or S1,S2,... one per photo (the photos,\n"
                "then --target-photos, --white-photos, --chart-photos); EXIF's wins where present");
  c->add_option("--base-iso", o.base_iso, "The ISO of gain 1 (default: the lowest ISO of the photos)");
  AddOption(*c, "--bracket-size", o.bracket_size, "Exposures per bracket (0: by capture time and steps; 1: none)");
  AddOption(*c, "--bracket-gap-s", o.bracket_gap_s, "Longest time between two exposures of one bracket");
  AddDeprecatedAlias(*c, vector("--light-position-m", args->light_position, 3, "The light's X Y Z (targets' frame)"),
                     "--light-position", args->light_position);
  vector("--light-intensity", args->light_intensity, 3, "The light's intensity R,G,B (or R G B; radiance unit)");
  AddDeprecatedAlias(*c, c->add_option("--sample-radius-m", args->sample_radius, "The sphere's radius"),
                     "--sample-radius", args->sample_radius);
  c->add_flag("--radius-known", o.radius_known, "The radius is measured: `ibrdf align` fits only the centre");
  AddDeprecatedAlias(*c,
                     vector("--sample-center-m", args->sample_center, 3,
                            "The sphere's centre X Y Z (default with --targets: on the platform's centre)"),
                     "--sample-center", args->sample_center);
  c->add_option("--response", o.response, "\"linear\" or \"srgb\" (default: from the file format)");
  c->add_option("--name", o.name, "The session's name (default: the output folder's)");
  c->callback([args] {
    SessionInitOptions& options = args->o;
    options.light_position = Vector3(args->light_position);
    options.light_intensity = Vector3(args->light_intensity);
    options.sample_center = Vector3(args->sample_center);
    options.white_reflectance = Vector3(args->white_reflectance);
    if (!args->exposure_s.empty()) options.exposure_s = ExposureTimes(args->exposure_s);
    if (args->sample_radius > 0.0) options.sample_radius = args->sample_radius;
    if (args->white_size != 0.0) options.white_size = args->white_size;
    if (args->chart_corners.size() == 8) {
      const std::vector<double>& x = args->chart_corners;
      options.chart_corners = {{{x[0], x[1]}, {x[2], x[3]}, {x[4], x[5]}, {x[6], x[7]}}};
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

}  // namespace ibrdf
