// ibrdf align: a session's geometry from its own photos (align/align_stage.h) behind flags.
#include "align/align_stage.h"
#include "apps/commands.h"
#include "core/logging.h"
#include "core/session.h"

namespace ibrdf {
namespace {

void AddAlignCommand(CLI::App& app) {
  auto* command = app.add_subcommand(
      "align",
      "Find the session's geometry from its photos: camera poses from ArUco markers of known or unknown\n"
      "layout (a Ceres bundle adjustment with a robust loss; unreliable photos dropped with a reason), the\n"
      "light from markers on it, a sphere's centre and radius from its silhouettes, a cylinder's centre and\n"
      "axis from markers on its cap. Photos with \"role\": \"targets\" are posed and kept but not used for the sample. "
      "Writes\n"
      "OUT/session.json (the aligned session; photos stay where they are) and OUT/alignment.json (residuals).");
  struct Args {
    std::string session, out;
    AlignStageOptions o;
    bool no_sphere = false, no_light = false, no_cylinder = false, colmap_refine_intrinsics = false;
  };
  auto args = std::make_shared<Args>();
  AlignStageOptions& o = args->o;
  command->add_option("session", args->session, "Session folder or session.json with a \"targets\" block")->required();
  command->add_option("--out", args->out, "Folder for the aligned session")->required();
  command->add_option("--min-markers", o.align.min_markers_per_image, "Reference markers a photo needs")
      ->capture_default_str();
  command->add_option("--max-rms-px", o.align.max_image_rms_px, "Drop photos whose corner RMS exceeds this")
      ->capture_default_str();
  command->add_flag("--no-sphere", args->no_sphere, "Keep the sphere as given instead of fitting its silhouettes");
  command->add_flag("--no-light", args->no_light, "Keep the light as given instead of finding it from its markers");
  command->add_flag("--no-cylinder", args->no_cylinder,
                    "Keep a cylinder as given instead of fitting it to its markers (targets.sample)");
  command
      ->add_option("--calibrate", o.calibration_dir,
                   "Calibrate the camera (OPENCV model) from the ChArUco board photos in this folder (with its\n"
                   "board.json) before aligning; the aligned session gets the calibrated intrinsics")
      ->check(CLI::ExistingDirectory);
  command
      ->add_option("--min-board-corners", o.calibration.min_corners_per_view,
                   "Board photos with fewer chessboard corners are left out")
      ->capture_default_str();
  command->add_option("--min-board-photos", o.calibration.min_views, "Usable board photos the calibration needs")
      ->capture_default_str();
  auto* colmap_option = command->add_option(
      "--colmap", o.colmap_model,
      "A COLMAP sparse model of the session's photos (images named like the photos): its poses, brought\n"
      "into the target frame by the similarity that maps its camera centres onto the target-based ones,\n"
      "replace the target-based poses (and its camera the session's, when all photos share one)");
  auto* run_colmap = command->add_flag(
      "--run-colmap", o.run_colmap,
      "Run COLMAP (feature_extractor, exhaustive_matcher, mapper; CPU) on the photos into OUT/colmap,\n"
      "then use its model as --colmap does");
  colmap_option->excludes(run_colmap);
  command->add_option("--colmap-binary", o.colmap_runner.binary, "The COLMAP executable")->capture_default_str();
  command->add_flag(
      "--colmap-refine-intrinsics", args->colmap_refine_intrinsics,
      "With --run-colmap: let COLMAP refine the session's (or calibrated) intrinsics instead of keeping them");
  command
      ->add_option("--colmap-max-center-error-m", o.colmap_alignment.max_center_error_m,
                   "COLMAP photos whose centre lands further than this from the target-based one are outliers")
      ->capture_default_str();
  command->add_flag("--overwrite", o.overwrite, "Replace an existing output folder");
  command->callback([args] {
    StageLog stage("align");
    const Session session = Session::Load(args->session);
    AlignStageOptions& options = args->o;
    options.align.fit_sphere = !args->no_sphere;
    options.align.fit_light = !args->no_light;
    options.align.fit_cylinder = !args->no_cylinder;
    options.colmap_runner.fix_intrinsics = !args->colmap_refine_intrinsics;
    RequireValidOptions(options, "ibrdf align");
    // The output guard: the session folder, its files, the COLMAP model and the calibration photos.
    std::vector<std::string> inputs = session.InputFiles();
    inputs.push_back(session.manifest_path);
    inputs.push_back(session.directory);
    for (const std::string& folder : {options.colmap_model, options.calibration_dir}) {
      if (folder.empty()) continue;
      inputs.push_back(folder);
      for (const std::string& file : FilesUnder(folder)) inputs.push_back(file);
    }
    RequireWritableOutput(args->out, options.overwrite, inputs);
    AlignSessionToFolder(session, options, args->out);
    Log(1, "aligned session written to " + args->out + "/session.json");
  });
}

}  // namespace

IBRDF_REGISTER_COMMAND(30, AddAlignCommand);

}  // namespace ibrdf
