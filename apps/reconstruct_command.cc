// ibrdf reconstruct: samples to a smooth isotropic BRDF (reconstruct/reconstruction_stage.h) behind flags.
#include "apps/commands.h"
#include "core/error.h"
#include "core/logging.h"
#include "core/sample_file.h"
#include "reconstruct/reconstruction_stage.h"
#include "reconstruct/sample_domain.h"

namespace ibrdf {
namespace {

void AddReconstructCommand(CLI::App& app) {
  auto* command = app.add_subcommand(
      "reconstruct",
      "Reconstruct a smooth isotropic BRDF from samples by local polynomial regression (elliptical kernel\n"
      "in half/difference coordinates, folded by reciprocity and bilateral symmetry); writes into DIR:\n"
      "brdf.binary (MERL 90x90x180), brdf.npy (90,90,180,3; -1 unmeasured), domain.npy (per cell: 2\n"
      "measured, 1 interpolated, 0 unmeasured), brdf.json (the table's counts and fill), effective_samples.npy,\n"
      "lafortune.json and ggx.json (material files), NAME.pbrt and NAME.xml (pbrt-v4, Mitsuba 3), NAME.bsdf\n"
      "(RGL tensor file for Mitsuba 3's and pbrt-v4's measured material; --no-bsdf skips it) and\n"
      "summary.json (timings, counts by class, fit errors; error against the truth with --truth).\n"
      "With --eval POINTS.npy (float64, N x 3: theta_i, theta_e, delta_phi in radians) also eval.npy (N x 3\n"
      "RGB values, -1 where unmeasured unless --fill), eval_domain.npy (the class per point) and, with\n"
      "--truth, eval_truth.npy (the true values there). --material M --eval P evaluates a material instead.\n"
      "--bandwidth loo|gcv selects the kernel radii (both scaled by each of --bandwidth-scales) by\n"
      "leave-one-out or generalized cross-validation; the criterion curve goes to the log and summary.json.");
  struct Args {
    std::string samples, out, bandwidth = "given", fill = "none", material;
    ReconstructOptions o;
    bool no_fold = false, no_fits = false, no_bsdf = false, linear_values = false;
  };
  auto args = std::make_shared<Args>();
  ReconstructOptions& o = args->o;
  command->add_option("samples", args->samples, "Sample file (.npy) from `ibrdf derender` (not with --material)");
  command->add_option("--out", args->out, "Output folder (created; replaced only with --overwrite)")->required();
  command->add_option("--degree", o.regression.degree, "Local polynomial degree: 0, 1 or 2")->capture_default_str();
  command->add_option("--radius-h-deg", o.regression.radius_h_deg, "Kernel radius along the sheets (theta_h)")
      ->capture_default_str();
  command->add_option("--radius-d-deg", o.regression.radius_d_deg, "Kernel radius across the sheets (theta_d)")
      ->capture_default_str();
  command
      ->add_option("--bandwidth", args->bandwidth,
                   "Kernel radii: 'given' (--radius-h-deg, --radius-d-deg), or selected by 'loo' (leave-one-out)\n"
                   "or 'gcv' (generalized cross-validation) among the given radii times --bandwidth-scales")
      ->capture_default_str();
  command->add_option("--bandwidth-scales", o.selection.scales, "Factors on both radii tried by --bandwidth loo|gcv")
      ->delimiter(',')
      ->capture_default_str();
  command->add_option("--bandwidth-samples", o.selection.samples, "Samples each candidate is scored at")
      ->capture_default_str();
  command
      ->add_option("--bin-h", o.regression.bin_fraction_h,
                   "Bin edge along the sheets, fraction of --radius-h-deg (0: no binning)")
      ->capture_default_str();
  command
      ->add_option("--bin-d", o.regression.bin_fraction_d,
                   "Bin edge across the sheets, fraction of --radius-d-deg (0: no binning)")
      ->capture_default_str();
  command->add_flag("--no-fold", args->no_fold, "Do not assume reciprocity and bilateral symmetry");
  command->add_flag("--linear-values", args->linear_values, "Fit f rather than log f");
  command->add_option("--max-theta-deg", o.tabulate.max_theta_deg, "Tabulate cells up to this theta_i, theta_e")
      ->capture_default_str();
  command
      ->add_option("--min-effective-samples", o.tabulate.min_effective_samples,
                   "Cells with fewer are written as unmeasured (-1)")
      ->capture_default_str();
  command->add_option("--lobes", o.fit.lafortune_lobes, "Lafortune lobes (1 to 3)")->capture_default_str();
  command->add_option("--fit-samples", o.fit.max_samples, "Samples used by the model fits")->capture_default_str();
  command
      ->add_option("--fit-start-samples", o.fit.start_samples,
                   "The fits' starting points are ranked on this many of them, the best refined on all (0: every "
                   "start on all)")
      ->capture_default_str();
  command->add_flag("--no-fits", args->no_fits, "Skip the Lafortune and GGX fits");
  command->add_flag("--no-bsdf", args->no_bsdf,
                    "Skip NAME.bsdf (the RGL tensor file of Mitsuba 3's and pbrt-v4's measured material)");
  command->add_option("--truth", o.truth_file,
                      "truth.json, a material file, a MERL table or an RGL .bsdf to score the reconstruction against");
  command->add_option("--eval", o.eval_file,
                      "Also evaluate at these points: .npy float64 (N, 3) theta_i, theta_e, delta_phi (radians)");
  command->add_option("--material", args->material,
                      "With --eval and no samples: evaluate this material file, truth.json or MERL table (.binary)\n"
                      "at the points (eval.npy; no regression)");
  command
      ->add_option("--fill", args->fill,
                   "Unmeasured cells and points: 'none' (-1, MERL's no data), 'model' (the chosen fit) or\n"
                   "'extrapolate' (the regression's own estimate); recorded in summary.json and brdf.json")
      ->capture_default_str();
  command->add_option("--name", o.name, "Name of the fitted materials (default: the samples' session folder)");
  command->add_flag("--eval-only", o.eval_only, "With --eval: skip the MERL table and the fits (for benchmarks)");
  command->add_flag("--overwrite", o.overwrite, "Replace an existing output folder");
  command->callback([args] {
    StageLog stage("reconstruct");
    ReconstructOptions& options = args->o;
    if (!args->material.empty()) {
      if (!args->samples.empty())
        ThrowError("--material", "evaluates a material without samples: drop " + args->samples);
      if (options.eval_file.empty()) ThrowError("--material", "needs --eval POINTS.npy");
      RequireWritableOutput(args->out, options.overwrite, {args->material, options.eval_file});
      EvaluateMaterial(args->material, options, args->out);
      return;
    }
    if (args->samples.empty()) ThrowError("reconstruct", "a sample file is required (or --material with --eval)");
    RequireWritableOutput(args->out, options.overwrite,
                          {args->samples, SidecarPath(args->samples), options.truth_file, options.eval_file});
    if (!ParseFillMode(args->fill, &options.tabulate.fill)) {
      throw OptionValueError("--fill", "expected 'none', 'model' or 'extrapolate', got '" + args->fill + "'");
    }
    if (args->no_fold) options.regression.fold_reciprocity = options.regression.fold_bilateral = false;
    if (args->linear_values) options.regression.log_space = false;
    options.fits = !args->no_fits;
    options.bsdf = !args->no_bsdf;
    if (options.tabulate.fill == FillMode::kModel && (!options.fits || options.eval_only)) {
      ThrowError("--fill model", "fills with the chosen fit: drop --no-fits / --eval-only");
    }
    // The option groups checked here too, so that a message names the flags.
    RequireValidOptions(options.regression, "--degree/--radius-h-deg/--radius-d-deg/--bin-h/--bin-d");
    options.select_bandwidth = args->bandwidth != "given";
    if (options.select_bandwidth && !ParseBandwidthCriterion(args->bandwidth, &options.selection.criterion)) {
      throw OptionValueError("--bandwidth", "expected 'given', 'loo' or 'gcv', got '" + args->bandwidth + "'");
    }
    RequireValidOptions(options.selection, "--bandwidth-scales/--bandwidth-samples");
    RequireValidOptions(options.tabulate, "--max-theta-deg/--min-effective-samples");
    RequireValidOptions(options.fit, "--lobes/--fit-samples/--fit-start-samples");
    if (options.eval_only && options.eval_file.empty()) ThrowError("--eval-only", "needs --eval POINTS.npy");
    ReconstructFile(args->samples, options, args->out);
  });
}

}  // namespace

IBRDF_REGISTER_COMMAND(50, AddReconstructCommand);

}  // namespace ibrdf
