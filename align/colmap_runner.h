// Runs the real COLMAP (Debian's colmap 3.8, CPU only, headless) on a session's photos:
// feature_extractor, exhaustive_matcher and mapper into a work folder, which appears only when
// a model was found. COLMAP reads 8-bit copies of the photos (linearized with the session's response,
// scaled to their 99.9th percentile, sRGB-encoded), stored under the photos' session-relative names so
// that the model's images match the session's photos by name (align/colmap_alignment.h).
//
// Work folder: images/ (the copies), database.db, sparse/N/ (COLMAP's models), logs/<step>.log, and
// model.txt naming the largest model (most registered images).
#pragma once

#include <string>
#include <vector>

#include "core/session.h"

namespace ibrdf {

struct ColmapRunnerOptions {
  std::string binary = "colmap";       // the COLMAP executable; without a '/', searched on PATH
  bool single_camera = true;           // one camera for every photo (one physical camera and lens)
  bool use_session_intrinsics = true;  // the session's camera (model and parameters) as COLMAP's starting intrinsics
  // Keep them fixed in COLMAP's bundle adjustment: the session's camera is given or calibrated, and
  // COLMAP refining it on a (near-)planar target scene fails to initialize (docs/align-colmap.md).
  bool fix_intrinsics = true;
  int num_threads = -1;       // COLMAP's threads; -1 = every core
  int max_image_size = 3200;  // SIFT works on images downscaled to this longer side
  bool Check(std::string* why) const;
};

// One COLMAP call: the step's name and its arguments (without the binary).
struct ColmapCommand {
  std::string step;
  std::vector<std::string> arguments;
};

// The three calls for a work folder at `work_dir` (exposed for tests and for the log).
std::vector<ColmapCommand> ColmapCommands(const Session& session, const std::string& work_dir,
                                          const ColmapRunnerOptions& options);

struct ColmapStepTime {
  std::string step;
  double seconds = 0.0;
};

// What RunColmap did. A step that fails throws Error; a returned result names a committed model.
struct ColmapRunResult {
  std::string work_dir;       // the committed work folder
  std::string model_dir;      // its largest model, work_dir/sparse/N
  int models = 0;             // models the mapper wrote
  int registered_images = 0;  // images of the largest model
  int photos = 0;             // photos handed to COLMAP
  std::vector<ColmapStepTime> steps;
  double total_s = 0.0;
  std::string BriefReport() const;
};

// The executable `binary` names (searched on PATH without a '/'); empty if none.
std::string FindExecutable(const std::string& binary);

// Runs COLMAP into `work_dir` (replaced only when `overwrite`). Errors: the binary missing, a step
// failing (its exit code and the end of its log), the mapper finding no model.
ColmapRunResult RunColmap(const Session& session, const std::string& work_dir, const ColmapRunnerOptions& options,
                          bool overwrite);

}  // namespace ibrdf
