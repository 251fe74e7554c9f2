// ibrdf align: a session's geometry from its own photos (coded targets, silhouettes).
#include <filesystem>
#include <optional>

#include <nlohmann/json.hpp>

#include "align/aligner.h"
#include "align/colmap_alignment.h"
#include "align/colmap_runner.h"
#include "align/intrinsic_calibration.h"
#include "align/mesh_registration.h"
#include "apps/commands.h"
#include "core/error.h"
#include "core/file_util.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/session.h"

namespace fs = std::filesystem;

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
    AlignOptions options;
    bool overwrite = false, no_sphere = false, no_light = false, no_cylinder = false;
    // Intrinsics from ChArUco board photos; COLMAP's poses brought into the target frame (issue 4).
    std::string calibrate, colmap;
    bool run_colmap = false;
    IntrinsicCalibrationOptions calibration;
    ColmapAlignmentOptions colmap_alignment;
    ColmapRunnerOptions colmap_runner;
    bool colmap_refine_intrinsics = false;
  };
  auto args = std::make_shared<Args>();
  command->add_option("session", args->session, "Session folder or session.json with a \"targets\" block")->required();
  command->add_option("--out", args->out, "Folder for the aligned session")->required();
  command->add_option("--min-markers", args->options.min_markers_per_image, "Reference markers a photo needs")
      ->capture_default_str();
  command->add_option("--max-rms-px", args->options.max_image_rms_px, "Drop photos whose corner RMS exceeds this")
      ->capture_default_str();
  command->add_flag("--no-sphere", args->no_sphere, "Keep the sphere as given instead of fitting its silhouettes");
  command->add_flag("--no-light", args->no_light, "Keep the light as given instead of finding it from its markers");
  command->add_flag("--no-cylinder", args->no_cylinder,
                    "Keep a cylinder as given instead of fitting it to its markers (targets.sample)");
  command
      ->add_option("--calibrate", args->calibrate,
                   "Calibrate the camera (OPENCV model) from the ChArUco board photos in this folder (with its\n"
                   "board.json) before aligning; the aligned session gets the calibrated intrinsics")
      ->check(CLI::ExistingDirectory);
  command
      ->add_option("--min-board-corners", args->calibration.min_corners_per_view,
                   "Board photos with fewer chessboard corners are left out")
      ->capture_default_str();
  command->add_option("--min-board-photos", args->calibration.min_views, "Usable board photos the calibration needs")
      ->capture_default_str();
  auto* colmap_option = command->add_option(
      "--colmap", args->colmap,
      "A COLMAP sparse model of the session's photos (images named like the photos): its poses, brought\n"
      "into the target frame by the similarity that maps its camera centres onto the target-based ones,\n"
      "replace the target-based poses (and its camera the session's, when all photos share one)");
  auto* run_colmap = command->add_flag(
      "--run-colmap", args->run_colmap,
      "Run COLMAP (feature_extractor, exhaustive_matcher, mapper; CPU) on the photos into OUT/colmap,\n"
      "then use its model as --colmap does");
  colmap_option->excludes(run_colmap);
  command->add_option("--colmap-binary", args->colmap_runner.binary, "The COLMAP executable")->capture_default_str();
  command->add_flag(
      "--colmap-refine-intrinsics", args->colmap_refine_intrinsics,
      "With --run-colmap: let COLMAP refine the session's (or calibrated) intrinsics instead of keeping them");
  command
      ->add_option("--colmap-max-center-error-m", args->colmap_alignment.max_center_error_m,
                   "COLMAP photos whose centre lands further than this from the target-based one are outliers")
      ->capture_default_str();
  command->add_flag("--overwrite", args->overwrite, "Replace an existing output folder");
  command->callback([args] {
    StageLog stage("align");
    Session session = Session::Load(args->session);
    if (SameFile(args->out, session.directory))
      ThrowError(args->out, "is the input session's folder; no stage overwrites its inputs");
    AlignOptions options = args->options;
    options.fit_sphere = !args->no_sphere;
    options.fit_light = !args->no_light;
    options.fit_cylinder = !args->no_cylinder;
    AtomicDirectory directory(args->out, args->overwrite);
    nlohmann::json extra = nlohmann::json::object();
    if (!args->calibrate.empty()) {
      const IntrinsicCalibrationResult calibration = CalibrateIntrinsics(args->calibrate, args->calibration);
      for (const CalibrationView& view : calibration.views) {
        if (!view.used) Log(1, "left out board photo " + view.file + ": " + view.dropped_reason);
      }
      Log(1, calibration.BriefReport());
      if (calibration.camera.width != session.camera.width || calibration.camera.height != session.camera.height) {
        ThrowError(args->calibrate, "the board photos are " + std::to_string(calibration.camera.width) + "x" +
                                        std::to_string(calibration.camera.height) + ", the session's camera " +
                                        std::to_string(session.camera.width) + "x" +
                                        std::to_string(session.camera.height));
      }
      session.camera = calibration.camera;
      extra["intrinsic_calibration"] = ToJson(calibration);
    }
    AlignResult result = AlignSession(session, options);
    for (const ImageAlignment& image : result.images) {
      if (!image.used) Log(1, "dropped photo " + session.photos[image.photo].file + ": " + image.dropped_reason);
    }
    if (!args->colmap.empty() || args->run_colmap) {
      std::string model_dir = args->colmap;
      if (args->run_colmap) {
        ColmapRunnerOptions runner = args->colmap_runner;
        runner.fix_intrinsics = !args->colmap_refine_intrinsics;
        const ColmapRunResult run =
            RunColmap(session, (fs::path(directory.temporary_path()) / "colmap").string(), runner, false);
        Log(1, run.BriefReport());
        model_dir = run.model_dir;
        extra["colmap_run"] = {
            {"model", (fs::path("colmap") / fs::path(run.model_dir).lexically_relative(run.work_dir)).string()},
            {"registered_images", run.registered_images},
            {"models", run.models},
            {"total_s", run.total_s}};
      }
      const ColmapModel model = ColmapModel::Read(model_dir);
      std::vector<std::string> files;
      std::vector<std::optional<Rigid3d>> target_poses;
      for (size_t i = 0; i < session.photos.size(); ++i) {
        files.push_back(session.photos[i].file);
        target_poses.push_back(result.images[i].used ? std::optional<Rigid3d>(result.images[i].camera_from_world)
                                                     : std::nullopt);
      }
      const ColmapAlignment colmap = AlignColmapModel(model, files, target_poses, args->colmap_alignment, model_dir);
      // Every photo COLMAP registered gets its metric pose, except those that disagree with their
      // target-based pose (which keep that); photos COLMAP lacks keep their target-based pose.
      Session aligned = result.session;
      aligned.photos.clear();
      for (size_t i = 0; i < session.photos.size(); ++i) {
        const ColmapPhotoMatch& match = colmap.photos[i];
        PhotoSpec photo = session.photos[i];
        if (match.metric_pose && (match.inlier || !match.target_pose)) {
          photo.camera_from_world = *match.metric_pose;
        } else if (match.target_pose) {
          if (match.metric_pose)
            Log(1, "photo " + photo.file + ": COLMAP's pose disagrees with the targets'; the targets' kept");
          photo.camera_from_world = *match.target_pose;
        } else {
          continue;
        }
        aligned.photos.push_back(photo);
      }
      const Camera* camera = SharedColmapCamera(model, colmap);
      if (!args->calibrate.empty()) {
        Log(1, "the calibrated intrinsics are kept (COLMAP's are in its model)");
      } else if (camera && camera->width == session.camera.width && camera->height == session.camera.height) {
        aligned.camera = *camera;
      } else {
        Log(1,
            "the session's intrinsics are kept: the registered photos do not share one COLMAP camera of the session's "
            "size");
      }
      result.session = aligned;
      Log(1, colmap.BriefReport());
      extra["colmap"] = ToJson(colmap);
    }
    // A scanned mesh whose scan saw the platform's markers: its similarity into the world
    // (align/mesh_registration.h); the mesh and its scans stay in the input session.
    const fs::path final_dir = fs::absolute(args->out).lexically_normal();
    SampleSpec& sample = result.session.sample;
    if (sample.kind == SampleSpec::Kind::kMesh) {
      if (!sample.scan_targets.empty()) {
        if (!session.targets)
          ThrowError(session.manifest_path, "/sample/scan_targets needs a \"targets\" block with the markers' layout");
        const MeshRegistration registration =
            RegisterMeshToTargets(sample.scan_targets, session.targets->reference, MeshRegistrationOptions(),
                                  session.manifest_path + ": /sample/scan_targets");
        sample.world_from_mesh = registration.world_from_mesh;
        extra["mesh_registration"] = ToJson(registration);
        Log(1, registration.BriefReport());
      }
      auto relocate = [&](std::string* file) {
        *file = fs::absolute(ResolvePath(session.directory, *file))
                    .lexically_normal()
                    .lexically_relative(final_dir)
                    .string();
      };
      relocate(&sample.mesh_file);
      for (ScanInputSpec& input : sample.scan_inputs) relocate(&input.file);
    }
    // Photos stay in the input session; the aligned manifest points at them.
    for (PhotoSpec& photo : result.session.photos) {
      const fs::path absolute = fs::absolute(ResolvePath(session.directory, photo.file)).lexically_normal();
      photo.file = absolute.lexically_relative(final_dir).string();
    }
    result.session.name = session.name + "-aligned";
    result.session.Save((fs::path(directory.temporary_path()) / "session.json").string());
    nlohmann::json alignment = ToJson(result);
    alignment.update(extra);
    WriteJsonFile((fs::path(directory.temporary_path()) / "alignment.json").string(), alignment);
    directory.Commit();
    Log(1, result.bundle.BriefReport());
    Log(1, result.BriefReport());
    Log(1, "aligned session written to " + args->out + "/session.json");
  });
}

}  // namespace

IBRDF_REGISTER_COMMAND(30, AddAlignCommand);

}  // namespace ibrdf
