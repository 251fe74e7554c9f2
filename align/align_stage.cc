#include "align/align_stage.h"

#include <filesystem>
#include <sstream>
#include <vector>

#include <nlohmann/json.hpp>

#include "align/colmap_model.h"
#include "align/mesh_registration.h"
#include "core/error.h"
#include "core/file_util.h"
#include "core/json_reader.h"
#include "core/logging.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

// The camera calibrated from board photos replaces the session's; it must have the session's size.
IntrinsicCalibrationResult CalibrateCamera(const AlignStageOptions& options, Session* session) {
  IntrinsicCalibrationResult calibration = CalibrateIntrinsics(options.calibration_dir, options.calibration);
  for (const CalibrationView& view : calibration.views) {
    if (!view.used) Log(1, "left out board photo " + view.file + ": " + view.dropped_reason);
  }
  Log(1, calibration.BriefReport());
  if (calibration.camera.width != session->camera.width || calibration.camera.height != session->camera.height) {
    ThrowError(options.calibration_dir, "the board photos are " + std::to_string(calibration.camera.width) + "x" +
                                            std::to_string(calibration.camera.height) + ", the session's camera " +
                                            std::to_string(session->camera.width) + "x" +
                                            std::to_string(session->camera.height));
  }
  session->camera = calibration.camera;
  return calibration;
}

// COLMAP's model (given, or run into `work_parent`/colmap) brought into the target frame and merged
// into the aligned session.
ColmapAlignment MergeColmap(const Session& session, const AlignStageOptions& options, const std::string& work_parent,
                            AlignResult* result, nlohmann::json* extra) {
  std::string model_dir = options.colmap_model;
  if (options.run_colmap) {
    const ColmapRunResult run =
        RunColmap(session, (fs::path(work_parent) / "colmap").string(), options.colmap_runner, false);
    Log(1, run.BriefReport());
    model_dir = run.model_dir;
    (*extra)["colmap_run"] = {
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
    target_poses.push_back(result->images[i].used ? std::optional<Rigid3d>(result->images[i].camera_from_world)
                                                  : std::nullopt);
  }
  const ColmapAlignment colmap = AlignColmapModel(model, files, target_poses, options.colmap_alignment, model_dir);
  result->session = MergeColmapPoses(session, result->session, model, colmap, !options.calibration_dir.empty());
  Log(1, colmap.BriefReport());
  (*extra)["colmap"] = ToJson(colmap);
  return colmap;
}

// A scanned mesh whose scan saw the platform's markers: its similarity into the world.
std::optional<MeshRegistration> RegisterScannedMesh(const Session& session, SampleSpec* sample,
                                                    nlohmann::json* extra) {
  if (!IsMeshSample(sample->kind) || sample->scan_targets.empty()) return std::nullopt;
  if (!session.targets)
    ThrowError(session.manifest_path, "/sample/scan_targets needs a \"targets\" block with the markers' layout");
  const MeshRegistration registration =
      RegisterMeshToTargets(sample->scan_targets, session.targets->reference, MeshRegistrationOptions(),
                            session.manifest_path + ": /sample/scan_targets");
  sample->world_from_mesh = registration.world_from_mesh;
  (*extra)["mesh_registration"] = ToJson(registration);
  Log(1, registration.BriefReport());
  return registration;
}

}  // namespace

bool AlignStageOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION(colmap_model.empty() || !run_colmap);
  return true;
}

std::string AlignStageResult::BriefReport() const {
  std::ostringstream out;
  out << "align: " << (success ? session_path : "FAILED") << ", " << alignment.session.photos.size() << " photos"
      << (calibration ? ", calibrated camera" : "") << (colmap ? ", COLMAP poses merged" : "");
  return out.str();
}

AlignStageResult AlignSessionToFolder(const Session& input, const AlignStageOptions& options,
                                      const std::string& out_dir) {
  std::string why;
  if (!options.Check(&why)) ThrowError("align options", why);
  if (SameFile(out_dir, input.directory))
    ThrowError(out_dir, "is the input session's folder; no stage overwrites its inputs");
  Session session = input;
  AlignStageResult stage;
  AtomicDirectory directory(out_dir, options.overwrite);
  nlohmann::json extra = nlohmann::json::object();
  if (!options.calibration_dir.empty()) {
    stage.calibration = CalibrateCamera(options, &session);
    extra["intrinsic_calibration"] = ToJson(*stage.calibration);
  }
  AlignResult& result = stage.alignment;
  result = AlignSession(session, options.align);
  for (const ImageAlignment& image : result.images) {
    if (!image.used) Log(1, "dropped photo " + session.photos[image.photo].file + ": " + image.dropped_reason);
  }
  if (!options.colmap_model.empty() || options.run_colmap) {
    stage.colmap = MergeColmap(session, options, directory.temporary_path(), &result, &extra);
  }
  const std::optional<MeshRegistration> registration = RegisterScannedMesh(session, &result.session.sample, &extra);
  result.mesh_registered = registration.has_value();
  // Nothing is written when a calibration cannot be trusted, unless the user accepted it by name.
  stage.verdicts = AlignmentVerdicts(input, result, registration, options.verdict_bounds);
  EnforceVerdicts(&stage.verdicts, options.accept, input.manifest_path);
  extra["verdicts"] = VerdictsToJson(stage.verdicts);
  // The aligned session's path fields still name files from the input session's folder.
  result.session.directory = session.directory;
  result.session = result.session.Rebased(out_dir);
  // Aligned again (an expert's choice: `ibrdf run` does not), the session keeps its name.
  if (!session.Applied(SessionStage::kAlign)) result.session.name = session.name + "-aligned";
  result.session.MarkApplied(SessionStage::kAlign);
  result.session.Save((fs::path(directory.temporary_path()) / "session.json").string());
  nlohmann::json alignment = ToJson(result);
  alignment.update(extra);
  WriteJsonFile((fs::path(directory.temporary_path()) / "alignment.json").string(), alignment);
  directory.Commit();
  Log(1, result.bundle.BriefReport());
  Log(1, result.BriefReport());
  Log(1, "align verdict: " + std::string(VerdictLevelName(WorstVerdict(stage.verdicts))) + " over " +
             std::to_string(stage.verdicts.size()) + " checks");
  stage.session_path = out_dir + "/session.json";
  stage.success = true;
  return stage;
}

}  // namespace ibrdf
