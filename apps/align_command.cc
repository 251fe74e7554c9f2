// ibrdf align: a session's geometry from its own photos (align/align_stage.h) behind flags.
#include "align/align_stage.h"
#include "apps/commands.h"
#include "core/session.h"

namespace ibrdf {

IBRDF_COMMAND(30, Align) {
  auto* c = app.add_subcommand(
      "align",
      "Find the session's geometry from its photos: camera poses from ArUco markers (a robust Ceres bundle\n"
      "adjustment; unreliable photos dropped with a reason), the light from markers on it, a sphere from its\n"
      "silhouettes, a cylinder from markers on its cap; \"targets\" photos are posed but not used for the sample.\n"
      "Writes OUT/session.json (the aligned session; photos stay where they are) and OUT/alignment.json.");
  struct Args {
    std::string session, out;
    AlignStageOptions o;
  };
  auto args = std::make_shared<Args>();
  AlignStageOptions& o = args->o;
  c->add_option("session", args->session, "Session folder or session.json with a \"targets\" block")->required();
  AddOutputFlags(*c, args->out, o.overwrite, "Folder for the aligned session", "Replace an existing output folder");
  AddOption(*c, "--min-markers", o.align.min_markers_per_image, "Reference markers a photo needs");
  AddOption(*c, "--max-rms-px", o.align.max_image_rms_px, "Drop photos whose corner RMS exceeds this");
  AddClearingFlag(*c, "--no-sphere", o.align.fit_sphere, "Keep the sphere as given instead of fitting its silhouettes");
  AddClearingFlag(*c, "--no-light", o.align.fit_light, "Keep the light as given (not found from its markers)");
  AddClearingFlag(*c, "--no-cylinder", o.align.fit_cylinder, "Keep a cylinder as given (not fitted to targets.sample)");
  c->add_option("--calibrate", o.calibration_dir, "Calibrate the camera first from the ChArUco photos in this folder")
      ->check(CLI::ExistingDirectory);
  AddOption(*c, "--min-board-corners", o.calibration.min_corners_per_view, "Fewer corners: a board photo left out");
  AddOption(*c, "--min-board-photos", o.calibration.min_views, "Usable board photos the calibration needs");
  auto* colmap = c->add_option("--colmap", o.colmap_model, "A COLMAP sparse model whose poses replace the targets'");
  c->add_flag("--run-colmap", o.run_colmap, "Run COLMAP on the photos into OUT/colmap and use it as --colmap does")
      ->excludes(colmap);
  AddOption(*c, "--colmap-binary", o.colmap_runner.binary, "The COLMAP executable");
  AddClearingFlag(*c, "--colmap-refine-intrinsics", o.colmap_runner.fix_intrinsics,
                  "With --run-colmap: let COLMAP refine the session's (or calibrated) intrinsics");
  AddOption(*c, "--colmap-max-center-error-m", o.colmap_alignment.max_center_error_m,
            "COLMAP photos whose centre lands further than this from the target-based one are outliers");
  c->add_option("--accept", o.accept.names,
                "Proceed although these checks fail (comma-separated names, e.g. sphere.radius, or all);\n"
                "recorded as accepted in alignment.json and the run's summary (docs/verdicts.md)")
      ->delimiter(',')
      ->type_name("CHECK[,CHECK...]");
  c->callback([args] {
    StageLog stage("align");
    const Session session = Session::Load(args->session);
    RequireValidOptions(args->o, "ibrdf align");
    // The output guard: the session, the COLMAP model and the calibration photos.
    std::vector<std::string> inputs = SessionInputs(session);
    for (const std::string& folder : {args->o.colmap_model, args->o.calibration_dir}) {
      if (folder.empty()) continue;
      inputs.push_back(folder);
      for (const std::string& file : FilesUnder(folder)) inputs.push_back(file);
    }
    RequireWritableOutput(args->out, args->o.overwrite, inputs);
    AlignSessionToFolder(session, args->o, args->out);
    Log(1, "aligned session written to " + args->out + "/session.json");
  });
}

}  // namespace ibrdf
