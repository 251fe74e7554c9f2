// The align stage as `ibrdf align` runs it: optionally the camera's intrinsics from ChArUco board
// photos first, the target-based alignment (align/aligner.h), optionally COLMAP's poses brought into
// the target frame and merged in (align/colmap_alignment.h), the scanned mesh's registration from the
// platform's markers (align/mesh_registration.h); written as OUT/session.json (photos, mesh and scans
// stay in the input session; the aligned manifest points at them) and OUT/alignment.json.
#pragma once

#include <optional>
#include <string>

#include "align/aligner.h"
#include "align/alignment_verdicts.h"
#include "align/colmap_alignment.h"
#include "align/colmap_runner.h"
#include "align/intrinsic_calibration.h"
#include "core/session.h"

namespace ibrdf {

struct AlignStageOptions {
  AlignOptions align;  // the target-based alignment (which fits to make: sphere, light, cylinder)
  // ChArUco board photos (with their board.json) to calibrate the camera from before aligning; the
  // aligned session gets the calibrated intrinsics (empty: the session's camera is kept).
  std::string calibration_dir;
  IntrinsicCalibrationOptions calibration;
  // A COLMAP sparse model of the session's photos whose poses (and shared camera) replace the
  // target-based ones (empty: none).
  std::string colmap_model;
  // Run COLMAP on the photos into OUT/colmap and use its model (exclusive with colmap_model).
  bool run_colmap = false;
  ColmapRunnerOptions colmap_runner;        // with run_colmap (fix_intrinsics: keep the session's camera)
  ColmapAlignmentOptions colmap_alignment;  // COLMAP's model into the target frame
  bool overwrite = false;                   // replace an existing output folder
  AlignmentVerdictBounds verdict_bounds;    // docs/verdicts.md
  AcceptedChecks accept;                    // failed checks to proceed with anyway (--accept), recorded

  // False with `*why` naming the failing constraint.
  bool Check(std::string* why) const;
};

// What the stage wrote; reads as failure until the folder was committed.
struct AlignStageResult {
  bool success = false;                                   // OUT was committed
  AlignResult alignment;                                  // the target-based alignment; its session is the one written
  std::optional<IntrinsicCalibrationResult> calibration;  // with calibration_dir
  std::optional<ColmapAlignment> colmap;                  // with colmap_model or run_colmap
  std::string session_path;                               // OUT/session.json
  std::vector<Verdict> verdicts;                          // AlignmentVerdicts, accepted failures marked
  // One line: photos aligned and the extra steps taken.
  std::string BriefReport() const;
};

// Runs the stage on `session` into the folder `out_dir` (created; replaced only with
// options.overwrite; never the session's own folder). Logs what it does. Throws Error on bad input
// (naming the file and field) or when a step cannot be done.
AlignStageResult AlignSessionToFolder(const Session& session, const AlignStageOptions& options,
                                      const std::string& out_dir);


}  // namespace ibrdf
