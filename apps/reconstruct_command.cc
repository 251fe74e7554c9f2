// ibrdf reconstruct: samples to a smooth isotropic BRDF (reconstruct/reconstruction_stage.h) behind flags.
#include "apps/commands.h"
#include "core/error.h"
#include "core/sample_file.h"
#include "reconstruct/reconstruction_stage.h"
#include "reconstruct/sample_domain.h"

namespace ibrdf {

IBRDF_COMMAND(50, Reconstruct) {
  auto* c = app.add_subcommand(
      "reconstruct",
      "Reconstruct a smooth isotropic BRDF from samples by local polynomial regression (elliptical kernel in\n"
      "half/difference coordinates, folded by reciprocity and bilateral symmetry) into DIR: brdf.binary (MERL),\n"
      "brdf.npy, domain.npy, brdf.json, lafortune.json, ggx.json, NAME.pbrt, NAME.xml, NAME.bsdf, summary.json;\n"
      "with --eval POINTS.npy also eval.npy and eval_domain.npy (docs/cli.md).");
  struct Args {
    std::string samples, out, material;
    ReconstructOptions o;
  };
  auto args = std::make_shared<Args>();
  ReconstructOptions& o = args->o;
  LocalRegressionOptions& r = o.regression;
  c->add_option("samples", args->samples, "Sample file (.npy) from `ibrdf derender` (not with --material)");
  AddOutputFlags(*c, args->out, o.overwrite, "Output folder (created; replaced only with --overwrite)",
                 "Replace an existing output folder");
  AddOption(*c, "--degree", r.degree, "Local polynomial degree: 0, 1 or 2");
  AddOption(*c, "--radius-h-deg", r.radius_h_deg, "Kernel radius along the sheets (theta_h)");
  AddOption(*c, "--radius-d-deg", r.radius_d_deg, "Kernel radius across the sheets (theta_d)");
  const auto bandwidth = [&o](const std::string& name) {
    o.select_bandwidth = name != "given";
    if (o.select_bandwidth) ParseBandwidthCriterion(name, &o.selection.criterion);
  };
  c->add_option_function<std::string>("--bandwidth", bandwidth,
                                      "Kernel radii: given, or selected by loo or gcv among them x --bandwidth-scales")
      ->check(CLI::IsMember({"given", "loo", "gcv"}))
      ->default_str("given");
  AddOption(*c, "--bandwidth-scales", o.selection.scales, "Factors on both radii tried by --bandwidth loo|gcv")
      ->delimiter(',');
  AddOption(*c, "--bandwidth-samples", o.selection.samples, "Samples each candidate is scored at");
  AddOption(*c, "--bin-h", r.bin_fraction_h, "Bin edge along the sheets, fraction of --radius-h-deg (0: no binning)");
  AddOption(*c, "--bin-d", r.bin_fraction_d, "Bin edge across the sheets, fraction of --radius-d-deg (0: no binning)");
  c->add_flag_callback(
      "--no-fold", [&r] { r.fold_reciprocity = r.fold_bilateral = false; },
      "Do not assume reciprocity and bilateral symmetry");
  AddClearingFlag(*c, "--linear-values", r.log_space, "Fit f rather than log f");
  AddOption(*c, "--max-theta-deg", o.tabulate.max_theta_deg, "Tabulate cells up to this theta_i, theta_e");
  AddOption(*c, "--min-effective-samples", o.tabulate.min_effective_samples, "Fewer: the cell is unmeasured (-1)");
  AddOption(*c, "--lobes", o.fit.lafortune_lobes, "Lafortune lobes (1 to 3)");
  AddOption(*c, "--fit-samples", o.fit.max_samples, "Samples used by the model fits");
  AddOption(*c, "--fit-start-samples", o.fit.start_samples, "Samples the fits' starts are ranked on (0: all)");
  AddClearingFlag(*c, "--no-fits", o.fits, "Skip the Lafortune and GGX fits");
  AddClearingFlag(*c, "--no-bsdf", o.bsdf, "Skip NAME.bsdf (RGL tensor file: Mitsuba 3's, pbrt-v4's measured)");
  c->add_option("--truth", o.truth_file, "truth.json, a material file, a MERL table or an RGL .bsdf to score against");
  c->add_option("--eval", o.eval_file, "Also evaluate at these points: .npy float64 (N, 3), radians");
  c->add_option("--material", args->material, "With --eval and no samples: evaluate this material at the points");
  const auto fill = [&o](const std::string& name) { ParseFillMode(name, &o.tabulate.fill); };
  c->add_option_function<std::string>("--fill", fill,
                                      "Unmeasured cells and points: none (-1), model (the fit) or extrapolate")
      ->check(CLI::IsMember({"none", "model", "extrapolate"}))
      ->default_str("none");
  c->add_option("--name", o.name, "Name of the fitted materials (default: the samples' session folder)");
  c->add_flag("--eval-only", o.eval_only, "With --eval: skip the MERL table and the fits (for benchmarks)");
  c->callback([args] {
    StageLog stage("reconstruct");
    ReconstructOptions& options = args->o;
    if (!args->material.empty()) {
      if (!args->samples.empty()) {
        ThrowError("--material", "evaluates a material without samples: drop " + args->samples);
      }
      if (options.eval_file.empty()) ThrowError("--material", "needs --eval POINTS.npy");
      RequireWritableOutput(args->out, options.overwrite, {args->material, options.eval_file});
      EvaluateMaterial(args->material, options, args->out);
      return;
    }
    if (args->samples.empty()) ThrowError("reconstruct", "a sample file is required (or --material with --eval)");
    RequireWritableOutput(args->out, options.overwrite,
                          {args->samples, SidecarPath(args->samples), options.truth_file, options.eval_file});
    if (options.tabulate.fill == FillMode::kModel && (!options.fits || options.eval_only)) {
      ThrowError("--fill model", "fills with the chosen fit: drop --no-fits / --eval-only");
    }
    // The option groups checked here too, so that a message names the flags.
    RequireValidOptions(options.regression, "--degree/--radius-h-deg/--radius-d-deg/--bin-h/--bin-d");
    RequireValidOptions(options.selection, "--bandwidth-scales/--bandwidth-samples");
    RequireValidOptions(options.tabulate, "--max-theta-deg/--min-effective-samples");
    RequireValidOptions(options.fit, "--lobes/--fit-samples/--fit-start-samples");
    if (options.eval_only && options.eval_file.empty()) ThrowError("--eval-only", "needs --eval POINTS.npy");
    ReconstructFile(args->samples, options, args->out);
  });
}

}  // namespace ibrdf
