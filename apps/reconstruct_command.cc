// ibrdf reconstruct: samples to a smooth isotropic BRDF (local polynomial regression), tabulated to
// the MERL format and .npy, with Lafortune and GGX fits and a JSON summary.
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "core/brdf_coords.h"
#include "core/error.h"
#include "core/file_util.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/sample_file.h"
#include "reconstruct/bandwidth_selection.h"
#include "reconstruct/local_regression.h"
#include "reconstruct/merl_table.h"
#include "reconstruct/model_fit.h"
#include "core/npy.h"
#include "reconstruct/reconstruction_error.h"
#include "reconstruct/truth_comparison.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

void WriteText(const std::string& path, const std::string& text) {
  AtomicFile file(path);
  {
    std::ofstream out(file.temporary_path());
    out << text;
    if (!out) ThrowError(path, "write failed");
  }
  file.Commit();
}

void AddReconstructCommand(CLI::App& app) {
  auto* command = app.add_subcommand(
      "reconstruct",
      "Reconstruct a smooth isotropic BRDF from samples by local polynomial regression (elliptical kernel\n"
      "in half/difference coordinates, folded by reciprocity and bilateral symmetry); writes into DIR:\n"
      "brdf.binary (MERL 90x90x180), brdf.npy (90,90,180,3; -1 unmeasured), effective_samples.npy,\n"
      "lafortune.json and ggx.json (material files), ggx.pbrt and ggx.xml (pbrt-v4, Mitsuba 3) and\n"
      "summary.json (timings, reliability counts, fit errors; error against the truth with --truth).\n"
      "With --eval POINTS.npy (float64, N x 3: theta_i, theta_e, delta_phi in radians) also eval.npy (N x 3\n"
      "RGB values, -1 where unsupported) and, with --truth, eval_truth.npy (the true values there).\n"
      "--bandwidth loo|gcv selects the kernel radii (both scaled by each of --bandwidth-scales) by\n"
      "leave-one-out or generalized cross-validation; the criterion curve goes to the log and summary.json.");
  struct Args {
    std::string samples, out, truth, eval, bandwidth = "given";
    LocalRegressionOptions regression;
    BandwidthSelectionOptions selection;
    TabulateOptions tabulate;
    ModelFitOptions fit;
    bool no_fold = false, no_fits = false, linear_values = false, overwrite = false, eval_only = false;
  };
  auto args = std::make_shared<Args>();
  command->add_option("samples", args->samples, "Sample file (.npy) from `ibrdf derender`")->required();
  command->add_option("--out", args->out, "Output folder (created; replaced only with --overwrite)")->required();
  command->add_option("--degree", args->regression.degree, "Local polynomial degree: 0, 1 or 2")->capture_default_str();
  command->add_option("--radius-h-deg", args->regression.radius_h_deg, "Kernel radius along the sheets (theta_h)")
      ->capture_default_str();
  command->add_option("--radius-d-deg", args->regression.radius_d_deg, "Kernel radius across the sheets (theta_d)")
      ->capture_default_str();
  command
      ->add_option("--bandwidth", args->bandwidth,
                   "Kernel radii: 'given' (--radius-h-deg, --radius-d-deg), or selected by 'loo' (leave-one-out)\n"
                   "or 'gcv' (generalized cross-validation) among the given radii times --bandwidth-scales")
      ->capture_default_str();
  command
      ->add_option("--bandwidth-scales", args->selection.scales, "Factors on both radii tried by --bandwidth loo|gcv")
      ->delimiter(',')
      ->capture_default_str();
  command->add_option("--bandwidth-samples", args->selection.samples, "Samples each candidate is scored at")
      ->capture_default_str();
  command
      ->add_option("--bin-h", args->regression.bin_fraction_h,
                   "Bin edge along the sheets, fraction of --radius-h-deg (0: no binning)")
      ->capture_default_str();
  command
      ->add_option("--bin-d", args->regression.bin_fraction_d,
                   "Bin edge across the sheets, fraction of --radius-d-deg (0: no binning)")
      ->capture_default_str();
  command->add_flag("--no-fold", args->no_fold, "Do not assume reciprocity and bilateral symmetry");
  command->add_flag("--linear-values", args->linear_values, "Fit f rather than log f");
  command->add_option("--max-theta-deg", args->tabulate.max_theta_deg, "Tabulate cells up to this theta_i, theta_e")
      ->capture_default_str();
  command
      ->add_option("--min-effective-samples", args->tabulate.min_effective_samples,
                   "Cells with fewer are written as unmeasured (-1)")
      ->capture_default_str();
  command->add_option("--lobes", args->fit.lafortune_lobes, "Lafortune lobes (1 to 3)")->capture_default_str();
  command->add_option("--fit-samples", args->fit.max_samples, "Samples used by the model fits")->capture_default_str();
  command->add_flag("--no-fits", args->no_fits, "Skip the Lafortune and GGX fits");
  command->add_option("--truth", args->truth, "truth.json (or a material file) to score the reconstruction against");
  command->add_option("--eval", args->eval,
                      "Also evaluate at these points: .npy float64 (N, 3) theta_i, theta_e, delta_phi (radians)");
  command->add_flag("--eval-only", args->eval_only, "With --eval: skip the MERL table and the fits (for benchmarks)");
  command->add_flag("--overwrite", args->overwrite, "Replace an existing output folder");
  command->callback([args] {
    StageLog stage("reconstruct");
    RequireWritableOutput(args->out, args->overwrite, {args->samples});
    if (args->no_fold) args->regression.fold_reciprocity = args->regression.fold_bilateral = false;
    if (args->linear_values) args->regression.log_space = false;
    std::string why;
    if (!args->regression.Check(&why)) ThrowError("--degree/--radius", why);
    const bool select_bandwidth = args->bandwidth != "given";
    if (select_bandwidth && !ParseBandwidthCriterion(args->bandwidth, &args->selection.criterion)) {
      ThrowError("--bandwidth", "expected 'given', 'loo' or 'gcv', got '" + args->bandwidth + "'");
    }
    if (!args->selection.Check(&why)) ThrowError("--bandwidth-scales/--bandwidth-samples", why);
    if (!args->tabulate.Check(&why)) ThrowError("--max-theta-deg", why);
    if (!args->fit.Check(&why)) ThrowError("--lobes/--fit-samples", why);
    if (args->eval_only && args->eval.empty()) ThrowError("--eval-only", "needs --eval POINTS.npy");
    std::vector<Eigen::Vector3d> eval_wi, eval_wo;
    if (!args->eval.empty()) {
      std::vector<size_t> shape;
      const std::vector<double> points = ReadNpyArray(args->eval, &shape);
      if (shape.size() != 2 || shape[1] != 3) ThrowError(args->eval, "expected a float64 array of shape (N, 3)");
      for (size_t i = 0; i < shape[0]; ++i) {
        eval_wi.push_back(FromSpherical(points[3 * i], 0.0));
        eval_wo.push_back(FromSpherical(points[3 * i + 1], points[3 * i + 2]));
      }
    }
    std::unique_ptr<BrdfModel> truth;
    if (!args->truth.empty()) {
      const nlohmann::json json = ReadJsonFile(args->truth);
      truth = json.contains("material") ? LoadTruthMaterial(args->truth) : LoadMaterial(args->truth);
    }
    Timer total;
    const std::vector<BrdfSample> samples = ReadSamples(args->samples);
    if (samples.empty()) ThrowError(args->samples, "holds no samples");
    nlohmann::json summary = {{"format", "ibrdf-reconstruction"},
                              {"version", 1},
                              {"samples_file", args->samples},
                              {"samples", samples.size()}};
    AtomicDirectory dir(args->out, args->overwrite);
    const std::string tmp = dir.temporary_path();
    nlohmann::json timings;

    Timer timer;
    if (select_bandwidth) {
      const BandwidthSelection selection = SelectBandwidth(samples, args->regression, args->selection);
      Log(1, "bandwidth criterion curve (" + std::string(BandwidthCriterionName(selection.criterion)) + "):\n" +
                 selection.CurveTable());
      Log(1, selection.BriefReport());
      if (!selection.success) ThrowError("--bandwidth", "no candidate kernel gave a finite criterion");
      summary["bandwidth_selection"] = ToJson(selection);
      timings["bandwidth_selection_s"] = selection.seconds;
      args->regression = selection.selected;
    }
    timer.Restart();
    const LocalRegression regression(samples, args->regression);
    timings["build_s"] = timer.ElapsedSeconds();
    if (!eval_wi.empty()) {
      timer.Restart();
      std::vector<Eigen::Vector3d> uvw(eval_wi.size());
      for (size_t i = 0; i < uvw.size(); ++i) uvw[i] = RegressionCoordinates(eval_wi[i], eval_wo[i]);
      ReliabilityCounts counts;
      const std::vector<Estimate> estimates = regression.EvaluateMany(uvw, &counts);
      timings["eval_s"] = timer.ElapsedSeconds();
      std::vector<double> values(3 * uvw.size()), true_values;
      for (size_t i = 0; i < uvw.size(); ++i) {
        const bool supported = estimates[i].status != EstimateStatus::kUnsupported;
        for (int c = 0; c < 3; ++c) values[3 * i + c] = supported ? estimates[i].value[c] : -1.0;
      }
      WriteNpyArray(tmp + "/eval.npy", values, {uvw.size(), 3});
      if (truth) {
        true_values.resize(3 * uvw.size());
        for (size_t i = 0; i < uvw.size(); ++i) {
          const Eigen::Vector3d f = truth->Eval(eval_wi[i], eval_wo[i]);
          for (int c = 0; c < 3; ++c) true_values[3 * i + c] = f[c];
        }
        WriteNpyArray(tmp + "/eval_truth.npy", true_values, {uvw.size(), 3});
      }
      summary["eval"] = {{"points", uvw.size()}, {"file", args->eval}, {"reliability", ToJson(counts)}};
      Log(1, "evaluated " + std::to_string(uvw.size()) + " points: " + counts.Brief());
    }
    const LocalRegressionOptions& r = args->regression;
    summary["regression"] = {{"degree", r.degree},
                             {"bandwidth", args->bandwidth},
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
    if (!args->eval_only) {
      TabulateSummary tabulated;
      std::vector<float> ess;
      std::vector<uint8_t> measured_domain;
      const MerlTable table = TabulateMerl(regression, args->tabulate, &tabulated, &ess, &measured_domain);
      timings["tabulate_s"] = tabulated.seconds;
      Log(1, "regression: " + std::to_string(regression.size()) + " samples in " + std::to_string(regression.points()) +
                 " points, " + tabulated.reliability.Brief());
      Log(1, tabulated.BriefReport());
      timer.Restart();
      WriteMerl(tmp + "/brdf.binary", table);
      WriteNpyArray(tmp + "/brdf.npy", MerlToArray(table), {90, 90, 180, 3});
      WriteNpyArray(tmp + "/effective_samples.npy", ess, {90, 90, 180});
      timings["write_s"] = timer.ElapsedSeconds();
      summary["regression"]["reliability"] = ToJson(tabulated.reliability);
      summary["table"] = {{"cells_measured", tabulated.cells_measured},
                          {"cells_beyond_theta_limit", tabulated.cells_below_horizon},
                          {"cells_unsupported", tabulated.cells_unsupported},
                          {"max_theta_deg", args->tabulate.max_theta_deg}};
      if (truth) {
        // The measured domain: cells within 80 degrees whose estimate interpolates its samples.
        const ReconstructionError error = CompareTableWithTruth(table, *truth, 80.0, &measured_domain);
        summary["error_against_truth"] = ToJson(error);
        summary["error_against_truth"]["truth"] = args->truth;
        summary["error_against_truth"]["domain"] =
            "theta_i, theta_e <= 80 deg; support not grown; samples' centroid within 0.5 kernel radii";
        Log(1, "against the truth (theta <= 80, measured domain): " + error.Brief());
        const ReconstructionError all = CompareTableWithTruth(table, *truth, 80.0);
        summary["error_against_truth_all_tabulated"] = ToJson(all);
        Log(1, "against the truth (theta <= 80, every tabulated cell): " + all.Brief());
      }
    }
    if (!args->no_fits && !args->eval_only) {
      timer.Restart();
      const ModelFitResult lafortune = FitLafortune(samples, args->fit);
      Log(1, lafortune.BriefReport());
      WriteJsonFile(tmp + "/lafortune.json", FitMaterialJson(lafortune, "lafortune-fit"));
      const ModelFitResult ggx = FitGgx(samples, args->fit);
      Log(1, ggx.BriefReport());
      WriteJsonFile(tmp + "/ggx.json", FitMaterialJson(ggx, "ggx-fit"));
      WriteText(tmp + "/ggx.pbrt", PbrtV4Material(*ggx.brdf, "ggx_fit"));
      WriteText(tmp + "/ggx.xml", Mitsuba3Material(*ggx.brdf, "ggx_fit"));
      timings["fits_s"] = timer.ElapsedSeconds();
      summary["fits"] = {
          {"lafortune",
           {{"rel_rms_vs_samples", lafortune.rel_rms},
            {"samples", lafortune.samples_used},
            {"seconds", lafortune.seconds}}},
          {"ggx", {{"rel_rms_vs_samples", ggx.rel_rms}, {"samples", ggx.samples_used}, {"seconds", ggx.seconds}}}};
    }
    timings["total_s"] = total.ElapsedSeconds();
    summary["timings_s"] = timings;
    WriteJsonFile(tmp + "/summary.json", summary);
    dir.Commit();
    Log(1, "reconstruction written to " + args->out);
  });
}

}  // namespace

IBRDF_REGISTER_COMMAND(50, AddReconstructCommand);

}  // namespace ibrdf
