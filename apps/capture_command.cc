// ibrdf capture check: what a session's photos will measure, before leaving the lab (the predicted
// coverage of coverage/coverage.h and the next shots of coverage/shot_planning.h) behind flags.
#include <cstdio>
#include <iostream>
#include <memory>

#include "apps/commands.h"
#include "core/error.h"
#include "core/file_util.h"
#include "core/session.h"
#include "coverage/coverage.h"
#include "coverage/shot_planning.h"

namespace ibrdf {
namespace {

std::string Percent(uint64_t part, uint64_t whole) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.1f %%", whole ? 100.0 * double(part) / double(whole) : 0.0);
  return buffer;
}

void PrintBands(const char* label, const CoverageResult& result) {
  std::cout << label << ": measured " << Percent(result.measured, result.cells) << " of " << result.cells
            << " cells (theta_i, theta_e <= " << 80 << " deg), interpolated " << Percent(result.interpolated, result.cells)
            << "\n  per theta_h band (measured):";
  for (const CoverageBand& b : result.bands) {
    std::cout << " " << int(b.theta_h_low_deg) << "-" << int(b.theta_h_high_deg) << ": "
              << Percent(b.measured, b.cells) << ";";
  }
  std::cout << "\n";
}

}  // namespace

IBRDF_COMMAND(12, Capture) {
  auto* capture = app.add_subcommand("capture", "Capture checks: `capture check` predicts a session's coverage");
  capture->require_subcommand(1);
  auto* c = capture->add_subcommand(
      "check",
      "Predict which cells of the BRDF domain (theta_h, theta_d, phi_d) a posed session's photos will measure,\n"
      "as the reconstruction would classify them, from the sample's geometry (sphere or cylinder; no\n"
      "occlusion: the sample is convex), the poses and the light; then suggest the next photos: camera\n"
      "positions on a shell about the sample (under the session's light) that fill the largest unmeasured\n"
      "regions. Prints per photo what is known, the coverage and the suggestions; with --out writes\n"
      "OUT/capture-check.json and OUT/coverage.png (theta_h down, theta_d across: before, and after in orange).");
  struct Args {
    std::string session, out;
    bool overwrite = false;
    ShotPlanOptions o;
  };
  auto args = std::make_shared<Args>();
  ShotPlanOptions& o = args->o;
  c->add_option("session", args->session, "A session folder or session.json with camera_from_world poses")->required();
  c->add_option("--out", args->out, "Folder for capture-check.json and coverage.png (none: print only)");
  c->add_flag("--overwrite", args->overwrite, "Replace OUT");
  AddOption(*c, "--suggest", o.suggestions, "Photos to suggest (0: coverage only)");
  AddOption(*c, "--distance-m", o.distance_m, "Camera distance of the suggestions, metres (0: the session's mean)");
  AddOption(*c, "--min-elevation-deg", o.min_elevation_deg, "Lowest camera elevation reachable (above world xy)");
  AddOption(*c, "--max-elevation-deg", o.max_elevation_deg, "Highest camera elevation reachable");
  AddOption(*c, "--elevation-step-deg", o.elevation_step_deg, "Candidate grid step in elevation");
  AddOption(*c, "--min-azimuth-deg", o.min_azimuth_deg, "Smallest camera azimuth reachable (about world +z, from +x)");
  AddOption(*c, "--max-azimuth-deg", o.max_azimuth_deg, "Largest camera azimuth reachable");
  AddOption(*c, "--azimuth-step-deg", o.azimuth_step_deg, "Candidate grid step in azimuth");
  AddOption(*c, "--min-light-separation-deg", o.min_light_separation_deg,
            "Candidates this close to the light's direction are left out");
  AddOption(*c, "--specular-theta-h-deg", o.specular_theta_h_deg, "Cells below this theta_h weigh more");
  AddOption(*c, "--specular-weight", o.specular_weight, "Their weight in a candidate's gain");
  AddOption(*c, "--samples-per-view", o.coverage.samples_per_view, "Predicted samples per photo (pixel grid)");
  AddOption(*c, "--candidate-samples-per-view", o.candidate_samples_per_view,
            "Predicted samples per candidate photo, for its score");
  c->callback([args] {
    const ShotPlanOptions& options = args->o;
    RequireValidOptions(options, "ibrdf capture check");
    const Session session = Session::Load(args->session);
    if (!args->out.empty()) RequireWritableOutput(args->out, args->overwrite, SessionInputs(session));
    StageLog stage("capture check");
    size_t measurement = 0;
    for (size_t i = 0; i < session.photos.size(); ++i) {
      const PhotoSpec& photo = session.photos[i];
      if (photo.role != PhotoRole::kMeasurement) continue;
      ++measurement;
      const Light& light = session.PhotoLight(i);
      std::cout << "photo " << photo.file << ": pose " << (photo.camera_from_world ? "yes" : "MISSING") << ", "
                << LightLabel(light) << " " << LightKindName(light.kind) << " "
                << (light.placement_known ? "placed" : "placement UNKNOWN") << "\n";
    }
    std::vector<std::string> missing;
    const std::vector<CoverageView> views = SessionViews(session, &missing);
    for (const std::string& line : missing) std::cout << "missing: " << line << "\n";
    if (views.empty()) {
      ThrowError(session.manifest_path,
                 "none of its " + std::to_string(measurement) +
                     " measurement photos has both a camera_from_world pose and a placed light: nothing to predict "
                     "from (run `ibrdf align` on the session first)");
    }
    if (!missing.empty()) {
      std::cout << "partial: the coverage below is of the " << views.size()
                << " posed views only; the photos listed as missing are left out\n";
    }
    const ShotPlan plan = PlanShots(session.camera, session.sample, views, options);
    PrintBands("predicted coverage", plan.before);
    for (size_t n = 0; n < plan.suggestions.size(); ++n) {
      const ShotSuggestion& s = plan.suggestions[n];
      char line[320];
      std::snprintf(line, sizeof(line),
                    "suggestion %zu: camera at (%.4f, %.4f, %.4f) m (azimuth %.0f deg, elevation %.0f deg, %.3f m) "
                    "looking at (%.4f, %.4f, %.4f): +%llu cells within the measured distance",
                    n + 1, s.position.x(), s.position.y(), s.position.z(), s.azimuth_deg, s.elevation_deg,
                    s.distance_m, s.look_at.x(), s.look_at.y(), s.look_at.z(), (unsigned long long)s.cells_gained);
      std::cout << line << "\n";
    }
    if (!plan.suggestions.empty()) PrintBands("with the suggestions", plan.after);
    Log(1, plan.BriefReport());
    if (args->out.empty()) return;
    WriteCaptureCheck(session, plan, missing, args->out, args->overwrite);
    std::cout << "wrote " << args->out << "/capture-check.json and " << args->out << "/coverage.png\n";
  });
}

}  // namespace ibrdf
