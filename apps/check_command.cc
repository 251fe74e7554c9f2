// ibrdf check: consistency of measured samples (reconstruct/consistency.h) behind flags.
#include "apps/commands.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/sample_file.h"
#include "reconstruct/consistency.h"
#include "reconstruct/prediction_check.h"

namespace ibrdf {
namespace {

void AddCheckCommand(CLI::App& app) {
  auto* command = app.add_subcommand(
      "check",
      "Check measured samples for reciprocity, f(ti, te, dphi) = f(te, ti, -dphi), and bilateral\n"
      "symmetry, f(ti, te, dphi) = f(ti, te, -dphi): each sample against the measured samples around its\n"
      "reciprocal (mirrored) point, binned; headline median and 95th percentile over bins, the worst bins\n"
      "located; writes the figures as JSON (docs/cli.md).");
  struct Args {
    std::string samples, out;
    ConsistencyOptions options;
    PredictionCheckOptions prediction;
    bool regression = false, overwrite = false;
  };
  auto args = std::make_shared<Args>();
  command->add_option("samples", args->samples, "Sample file (.npy) from `ibrdf derender`")->required();
  command->add_option("--out", args->out, "Report to write (.json)")->required();
  command->add_option("--theta-bin-deg", args->options.theta_bin_deg, "Bin width in theta_i and theta_e (5, 10 or 15)")
      ->capture_default_str();
  command->add_option("--phi-bin-deg", args->options.phi_bin_deg, "Bin width in delta_phi (divides 360; 10, 20 or 30)")
      ->capture_default_str();
  AddDeprecatedAlias(
      *command,
      command->add_option("--min-pairs", args->options.min_samples_per_bin, "Sample pairs a bin needs to be reported")
          ->capture_default_str(),
      "--min-samples", args->options.min_samples_per_bin);
  command
      ->add_option("--match-deg", args->options.match_deg,
                   "Partners lie within this angle of the reciprocal (mirrored) point; 0: automatic, the first of\n"
                   "0.5, 1, 2, 4 deg giving both figures 20 bins (the JSON's match_deg_used)")
      ->capture_default_str();
  command->add_option("--max-theta-deg", args->options.max_theta_deg, "Compare bins up to this theta")
      ->capture_default_str();
  command->add_flag("--regression", args->regression,
                    "Also the local-regression checks: reciprocity near the incidence plane, bilateral symmetry\n"
                    "(unfolded fit) and held-out photos (fit without a photo, predict it)");
  command->add_option("--held-out", args->prediction.held_out_photos, "Photos to hold out with --regression")
      ->capture_default_str();
  command->add_flag("--overwrite", args->overwrite, "Replace an existing report");
  command->callback([args] {
    RequireValidOptions(args->options, "--theta-bin-deg/--phi-bin-deg/--min-pairs/--match-deg/--max-theta-deg");
    if (args->regression) RequireValidOptions(args->prediction, "--held-out");
    StageLog stage("check");
    RequireWritableOutput(args->out, args->overwrite, {args->samples, SidecarPath(args->samples)});
    const std::vector<BrdfSample> samples = ReadSamples(args->samples);
    WriteJsonFile(args->out, CheckSamples(samples, args->options, args->regression ? &args->prediction : nullptr));
    Log(1, "report written to " + args->out);
  });
}

}  // namespace

IBRDF_REGISTER_COMMAND(60, AddCheckCommand);

}  // namespace ibrdf
