#include "reconstruct/reconstruction_stage.h"

#include <cmath>
#include <fstream>
#include <memory>
#include <sstream>

#include "core/brdf_coords.h"
#include "core/brdf_model.h"
#include "core/error.h"
#include "core/file_util.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/npy.h"
#include "reconstruct/truth_comparison.h"

namespace ibrdf {
namespace {

// What the stage reads besides the samples: the evaluation points and the truth.
struct StageInputs {
  std::vector<Eigen::Vector3d> eval_wi, eval_wo;
  std::unique_ptr<BrdfModel> truth;
};

// Checks the options and reads the eval and truth files (before the samples, as the command always did).
StageInputs LoadInputs(const ReconstructOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("reconstruct options", why);
  StageInputs inputs;
  if (!options.eval_file.empty()) {
    std::vector<size_t> shape;
    const std::vector<double> points = ReadNpyArray(options.eval_file, &shape, /*require_finite=*/true);
    if (shape.size() != 2 || shape[1] != 3) ThrowError(options.eval_file, "expected a float64 array of shape (N, 3)");
    for (size_t i = 0; i < shape[0]; ++i) {
      // Validated where read: a point outside the angles' ranges would be answered, wrongly.
      if (!(points[3 * i] >= 0 && points[3 * i] <= M_PI / 2 && points[3 * i + 1] >= 0 &&
            points[3 * i + 1] <= M_PI / 2 && std::abs(points[3 * i + 2]) <= M_PI)) {
        ThrowError(options.eval_file,
                   "row " + std::to_string(i) + ": expected theta_i, theta_e in [0, pi/2] and delta_phi in [-pi, pi]");
      }
      inputs.eval_wi.push_back(FromSpherical(points[3 * i], 0.0));
      inputs.eval_wo.push_back(FromSpherical(points[3 * i + 1], points[3 * i + 2]));
    }
  }
  if (!options.truth_file.empty()) {
    const nlohmann::json json = ReadJsonFile(options.truth_file);
    inputs.truth = json.contains("material") ? LoadTruthMaterial(options.truth_file) : LoadMaterial(options.truth_file);
  }
  return inputs;
}

void WriteText(const std::string& path, const std::string& text) {
  AtomicFile file(path);
  {
    std::ofstream out(file.temporary_path());
    out << text;
    if (!out) ThrowError(path, "write failed");
  }
  file.Commit();
}

// Evaluates the regression at the eval points into eval.npy (and the truth into eval_truth.npy).
void EvaluatePoints(const LocalRegression& regression, const StageInputs& inputs, const std::string& eval_file,
                    const std::string& tmp, nlohmann::json* summary, nlohmann::json* timings) {
  Timer timer;
  const size_t n = inputs.eval_wi.size();
  std::vector<Eigen::Vector3d> uvw(n);
  for (size_t i = 0; i < n; ++i) uvw[i] = RegressionCoordinates(inputs.eval_wi[i], inputs.eval_wo[i]);
  ReliabilityCounts counts;
  const std::vector<Estimate> estimates = regression.EvaluateMany(uvw, &counts);
  (*timings)["eval_s"] = timer.ElapsedSeconds();
  std::vector<double> values(3 * n), true_values;
  for (size_t i = 0; i < n; ++i) {
    const bool supported = estimates[i].status != EstimateStatus::kUnsupported;
    for (int c = 0; c < 3; ++c) values[3 * i + c] = supported ? estimates[i].value[c] : -1.0;
  }
  WriteNpyArray(tmp + "/eval.npy", values, {n, 3});
  if (inputs.truth) {
    true_values.resize(3 * n);
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d f = inputs.truth->Eval(inputs.eval_wi[i], inputs.eval_wo[i]);
      for (int c = 0; c < 3; ++c) true_values[3 * i + c] = f[c];
    }
    WriteNpyArray(tmp + "/eval_truth.npy", true_values, {n, 3});
  }
  (*summary)["eval"] = {{"points", n}, {"file", eval_file}, {"reliability", ToJson(counts)}};
  Log(1, "evaluated " + std::to_string(n) + " points: " + counts.Brief());
}

// The MERL table and its .npy forms, scored against the truth when there is one.
void TabulateAndScore(const LocalRegression& regression, const ReconstructOptions& options, const BrdfModel* truth,
                      const std::string& tmp, ReconstructResult* result, nlohmann::json* timings) {
  nlohmann::json& summary = result->summary;
  TabulateSummary tabulated;
  std::vector<float> ess;
  std::vector<uint8_t> measured_domain;
  const MerlTable table = TabulateMerl(regression, options.tabulate, &tabulated, &ess, &measured_domain);
  (*timings)["tabulate_s"] = tabulated.seconds;
  Log(1, "regression: " + std::to_string(regression.size()) + " samples in " + std::to_string(regression.points()) +
             " points, " + tabulated.reliability.Brief());
  Log(1, tabulated.BriefReport());
  Timer timer;
  WriteMerl(tmp + "/brdf.binary", table);
  WriteNpyArray(tmp + "/brdf.npy", MerlToArray(table), {90, 90, 180, 3});
  WriteNpyArray(tmp + "/effective_samples.npy", ess, {90, 90, 180});
  (*timings)["write_s"] = timer.ElapsedSeconds();
  summary["regression"]["reliability"] = ToJson(tabulated.reliability);
  summary["table"] = {{"cells_measured", tabulated.cells_measured},
                      {"cells_beyond_theta_limit", tabulated.cells_below_horizon},
                      {"cells_unsupported", tabulated.cells_unsupported},
                      {"max_theta_deg", options.tabulate.max_theta_deg}};
  result->tabulated = true;
  result->cells_measured = tabulated.cells_measured;
  if (!truth) return;
  // The measured domain: cells within 80 degrees whose estimate interpolates its samples.
  const ReconstructionError error = CompareTableWithTruth(table, *truth, 80.0, &measured_domain);
  summary["error_against_truth"] = ToJson(error);
  summary["error_against_truth"]["truth"] = options.truth_file;
  summary["error_against_truth"]["domain"] =
      "theta_i, theta_e <= 80 deg; support not grown; samples' centroid within 0.5 kernel radii";
  Log(1, "against the truth (theta <= 80, measured domain): " + error.Brief());
  const ReconstructionError all = CompareTableWithTruth(table, *truth, 80.0);
  summary["error_against_truth_all_tabulated"] = ToJson(all);
  Log(1, "against the truth (theta <= 80, every tabulated cell): " + all.Brief());
  result->scored = true;
  result->error_against_truth = error;
}

// The Lafortune and GGX fits and their material files.
void FitModels(const std::vector<BrdfSample>& samples, const ModelFitOptions& options, const std::string& tmp,
               ReconstructResult* result, nlohmann::json* timings) {
  Timer timer;
  const ModelFitResult lafortune = FitLafortune(samples, options);
  Log(1, lafortune.BriefReport());
  WriteJsonFile(tmp + "/lafortune.json", FitMaterialJson(lafortune, "lafortune-fit"));
  const ModelFitResult ggx = FitGgx(samples, options);
  Log(1, ggx.BriefReport());
  WriteJsonFile(tmp + "/ggx.json", FitMaterialJson(ggx, "ggx-fit"));
  WriteText(tmp + "/ggx.pbrt", PbrtV4Material(*ggx.brdf, "ggx_fit"));
  WriteText(tmp + "/ggx.xml", Mitsuba3Material(*ggx.brdf, "ggx_fit"));
  (*timings)["fits_s"] = timer.ElapsedSeconds();
  result->summary["fits"] = {
      {"lafortune",
       {{"rel_rms_vs_samples", lafortune.rel_rms},
        {"samples", lafortune.samples_used},
        {"seconds", lafortune.seconds}}},
      {"ggx", {{"rel_rms_vs_samples", ggx.rel_rms}, {"samples", ggx.samples_used}, {"seconds", ggx.seconds}}}};
  result->fitted = true;
  result->lafortune_rel_rms = lafortune.rel_rms;
  result->ggx_rel_rms = ggx.rel_rms;
}

nlohmann::json RegressionJson(const ReconstructOptions& options, const LocalRegressionOptions& r,
                              const LocalRegression& regression) {
  return {{"degree", r.degree},
          {"bandwidth", options.select_bandwidth ? BandwidthCriterionName(options.selection.criterion) : "given"},
          {"radius_h_deg", r.radius_h_deg},
          {"radius_d_deg", r.radius_d_deg},
          {"fold_reciprocity", r.fold_reciprocity},
          {"fold_bilateral", r.fold_bilateral},
          {"log_space", r.log_space},
          {"bin_fraction_h", r.bin_fraction_h},
          {"bin_fraction_d", r.bin_fraction_d},
          {"samples_used", regression.size()},
          {"points", regression.points()},
          {"samples_skipped", regression.skipped_samples()}};
}

// The stage after its inputs are read; `total` started before they were.
ReconstructResult Run(const std::vector<BrdfSample>& samples, const ReconstructOptions& options,
                      const StageInputs& inputs, const std::string& out_dir, const std::string& samples_file,
                      const Timer& total) {
  if (samples.empty()) ThrowError(samples_file.empty() ? "samples" : samples_file, "holds no samples");
  ReconstructResult result;
  result.samples = samples.size();
  result.summary = {
      {"format", "ibrdf-reconstruction"}, {"version", 1}, {"samples_file", samples_file}, {"samples", samples.size()}};
  AtomicDirectory dir(out_dir, options.overwrite);
  const std::string tmp = dir.temporary_path();
  nlohmann::json timings;
  result.regression = options.regression;
  if (options.select_bandwidth) {
    const BandwidthSelection selection = SelectBandwidth(samples, options.regression, options.selection);
    Log(1, "bandwidth criterion curve (" + std::string(BandwidthCriterionName(selection.criterion)) + "):\n" +
               selection.CurveTable());
    Log(1, selection.BriefReport());
    if (!selection.success) ThrowError("--bandwidth", "no candidate kernel gave a finite criterion");
    result.summary["bandwidth_selection"] = ToJson(selection);
    timings["bandwidth_selection_s"] = selection.seconds;
    result.regression = selection.selected;
  }
  Timer timer;
  const LocalRegression regression(samples, result.regression);
  timings["build_s"] = timer.ElapsedSeconds();
  result.samples_used = regression.size();
  result.points = regression.points();
  if (!inputs.eval_wi.empty()) {
    EvaluatePoints(regression, inputs, options.eval_file, tmp, &result.summary, &timings);
    result.eval_points = inputs.eval_wi.size();
  }
  result.summary["regression"] = RegressionJson(options, result.regression, regression);
  if (!options.eval_only) TabulateAndScore(regression, options, inputs.truth.get(), tmp, &result, &timings);
  if (options.fits && !options.eval_only) FitModels(samples, options.fit, tmp, &result, &timings);
  result.total_s = total.ElapsedSeconds();
  timings["total_s"] = result.total_s;
  result.summary["timings_s"] = timings;
  WriteJsonFile(tmp + "/summary.json", result.summary);
  dir.Commit();
  Log(1, "reconstruction written to " + out_dir);
  result.success = true;
  return result;
}

}  // namespace

bool ReconstructOptions::Check(std::string* why) const {
  std::string inner;
  const auto fail = [&](const char* group) {
    if (why) *why = std::string(group) + ": " + inner;
    return false;
  };
  if (!regression.Check(&inner)) return fail("regression");
  if (!selection.Check(&inner)) return fail("selection");
  if (!tabulate.Check(&inner)) return fail("tabulate");
  if (!fit.Check(&inner)) return fail("fit");
  IBRDF_CHECK_OPTION(!eval_only || !eval_file.empty());
  return true;
}

std::string ReconstructResult::BriefReport() const {
  std::ostringstream out;
  out << "reconstruct: " << (success ? "" : "FAILED, ") << samples << " samples (" << samples_used << " used, "
      << points << " points)";
  if (eval_points) out << ", " << eval_points << " points evaluated";
  if (tabulated) out << ", " << cells_measured << " cells measured";
  if (fitted) out << ", fits rel. RMS Lafortune " << lafortune_rel_rms << " GGX " << ggx_rel_rms;
  if (scored) out << ", against the truth " << error_against_truth.Brief();
  out << ", " << total_s << " s";
  return out.str();
}

ReconstructResult Reconstruct(const std::vector<BrdfSample>& samples, const ReconstructOptions& options,
                              const std::string& out_dir, const std::string& samples_file) {
  const StageInputs inputs = LoadInputs(options);
  const Timer total;
  return Run(samples, options, inputs, out_dir, samples_file, total);
}

ReconstructResult ReconstructFile(const std::string& samples_file, const ReconstructOptions& options,
                                  const std::string& out_dir) {
  const StageInputs inputs = LoadInputs(options);
  const Timer total;
  const std::vector<BrdfSample> samples = ReadSamples(samples_file);
  return Run(samples, options, inputs, out_dir, samples_file, total);
}

}  // namespace ibrdf
