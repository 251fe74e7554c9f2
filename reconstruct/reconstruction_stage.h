// The reconstruct stage: samples to a smooth isotropic BRDF by local polynomial regression
// (reconstruct/local_regression.h), optionally with the kernel radii chosen by cross-validation
// (reconstruct/bandwidth_selection.h), tabulated to the MERL format and .npy
// (reconstruct/merl_table.h), with Lafortune and GGX fits (reconstruct/model_fit.h), scored against the
// truth when one is given, and a JSON summary. `ibrdf reconstruct` is this function behind flags.
//
// The output folder (written atomically: it appears only when complete) holds brdf.binary (MERL
// 90x90x180), brdf.npy (90,90,180,3; -1 unmeasured), domain.npy (each cell measured 2, interpolated 1,
// unmeasured 0), brdf.json (the table's sidecar: counts, fill), effective_samples.npy, lafortune.json
// and ggx.json (material files), the renderer snippets, NAME.bsdf (RGL tensor file), summary.json, and with evaluation
// points eval.npy and eval_domain.npy (and eval_truth.npy with a truth). docs/reconstruct.md describes them.
// EvaluateMaterial evaluates a material file at the points without any samples or regression.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/sample_file.h"
#include "reconstruct/bandwidth_selection.h"
#include "reconstruct/bsdf_export.h"
#include "reconstruct/local_regression.h"
#include "reconstruct/merl_table.h"
#include "reconstruct/model_fit.h"
#include "reconstruct/reconstruction_error.h"

namespace ibrdf {

struct ReconstructOptions {
  // The kernel (degree, radii, binning), the symmetries folded in (fold_reciprocity, fold_bilateral)
  // and whether log f is fitted (log_space). With select_bandwidth its radii are the base that the
  // selection scales.
  LocalRegressionOptions regression;
  // Choose the kernel radii by selection.criterion (leave-one-out or GCV) among the base radii times
  // selection.scales (false: the radii are used as given).
  bool select_bandwidth = false;
  BandwidthSelectionOptions selection;
  TabulateOptions tabulate;  // the MERL table: theta limit, minimum effective samples per cell
  ModelFitOptions fit;       // the Lafortune and GGX fits
  bool fits = true;          // fit the Lafortune and GGX models (false: `--no-fits`)
  // Write NAME.bsdf, the RGL tensor file of Mitsuba 3's and pbrt-v4's `measured` materials
  // (reconstruct/bsdf_export.h; false: `--no-bsdf`), with these table sizes.
  bool bsdf = true;
  BsdfExportOptions bsdf_export;
  // Also evaluate at these points: a float64 .npy of shape (N, 3) holding theta_i, theta_e, delta_phi
  // in radians (empty: none). Writes eval.npy (N x 3 RGB, -1 where unsupported).
  std::string eval_file;
  bool eval_only = false;  // with eval_file: skip the MERL table and the fits (for benchmarks)
  // truth.json of a synthetic session, a material file or a MERL table to score against (empty: none).
  std::string truth_file;
  bool overwrite = false;  // replace an existing output folder
  // Name of the fitted materials in their files and snippets (empty: from the samples' session folder,
  // else the samples file's name).
  std::string name;
  // False with `*why` naming the failing constraint (prefixed with the option group that failed).
  bool Check(std::string* why) const;
};

// What the stage did; reads as failure until the folder was written.
struct ReconstructResult {
  bool success = false;                     // the output folder was committed
  size_t samples = 0;                       // samples given
  size_t samples_used = 0;                  // samples the regression kept
  size_t points = 0;                        // regression points (bins)
  LocalRegressionOptions regression;        // the kernel used (the selected radii with select_bandwidth)
  size_t eval_points = 0;                   // points evaluated (eval_file)
  bool tabulated = false;                   // the MERL table was written (not eval_only)
  uint64_t cells_measured = 0;              // MERL cells classified measured
  uint64_t cells_interpolated = 0;          // interpolated (inside the samples' domain)
  uint64_t cells_unmeasured = 0;            // unmeasured (within the theta limit), written -1 unless filled
  uint64_t cells_filled = 0;                // unmeasured cells filled (--fill)
  bool fitted = false;                      // the Lafortune and GGX fits ran
  double lafortune_rel_rms = 0.0;           // relative RMS of the Lafortune fit against the samples
  double ggx_rel_rms = 0.0;                 // likewise for GGX
  std::string chosen_model;                 // the fit with the lowest error (the one --fill model uses)
  bool scored = false;                      // compared with the truth (a truth and a table)
  ReconstructionError error_against_truth;  // in the measured domain (theta <= 80 degrees)
  bool bsdf_written = false;                // NAME.bsdf was written
  double bsdf_median_error = 0.0;           // the .bsdf against the table over the measured cells: median
  double bsdf_p95_error = 0.0;              // and 95th percentile relative error (all channels)
  double bsdf_p99_error = 0.0;              // 99th percentile
  double bsdf_max_error = 0.0;              // largest
  double bsdf_p99_reciprocity = 0.0;        // the file's reciprocity over the same cells, 99th percentile
  double total_s = 0.0;                     // wall time of the stage
  nlohmann::json summary;                   // summary.json as written
  // One line: samples, points, cells, fit and truth errors, time.
  std::string BriefReport() const;
};

// Runs the stage on `samples` into the folder `out_dir` (created; replaced only with
// options.overwrite). `samples_file` is recorded in summary.json. Logs what it did. Throws Error on
// bad options (naming the constraint), an unreadable eval or truth file, no samples, or a bandwidth
// selection where no candidate gave a finite criterion.
ReconstructResult Reconstruct(const std::vector<BrdfSample>& samples, const ReconstructOptions& options,
                              const std::string& out_dir, const std::string& samples_file = "");

// The same, reading the samples from `samples_file` (.npy of `ibrdf derender`) after the eval and truth
// files, as `ibrdf reconstruct` does; the total time includes reading them.
ReconstructResult ReconstructFile(const std::string& samples_file, const ReconstructOptions& options,
                                  const std::string& out_dir);

// Evaluates `material_file` (a material file, truth.json or MERL table) at the points of
// options.eval_file into `out_dir`/eval.npy (N x 3 RGB; -1 where a MERL table has no data) and
// summary.json, without samples or regression (`ibrdf reconstruct --material M --eval P`). Throws
// Error on an unreadable material or points file.
ReconstructResult EvaluateMaterial(const std::string& material_file, const ReconstructOptions& options,
                                   const std::string& out_dir);

}  // namespace ibrdf
