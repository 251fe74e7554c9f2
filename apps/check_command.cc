// ibrdf check: consistency of measured samples (reconstruct/consistency.h) behind flags.
#include "apps/commands.h"
#include "core/json_reader.h"
#include "core/sample_file.h"
#include "reconstruct/consistency.h"
#include "reconstruct/prediction_check.h"

namespace ibrdf {

IBRDF_COMMAND(60, Check) {
  auto* c = app.add_subcommand(
      "check",
      "Check measured samples for reciprocity, f(ti, te, dphi) = f(te, ti, -dphi), and bilateral symmetry,\n"
      "f(ti, te, dphi) = f(ti, te, -dphi): each sample against those around its reciprocal (mirrored) point, binned;\n"
      "median and 95th percentile over bins, the worst bins located; the figures as JSON (docs/cli.md).");
  struct Args {
    std::string samples, out;
    ConsistencyOptions o;
    PredictionCheckOptions prediction;
    bool regression = false, overwrite = false;
  };
  auto args = std::make_shared<Args>();
  ConsistencyOptions& o = args->o;
  c->add_option("samples", args->samples, "Sample file (.npy) from `ibrdf derender`")->required();
  AddOutputFlags(*c, args->out, args->overwrite, "Report to write (.json)", "Replace an existing report");
  AddOption(*c, "--theta-bin-deg", o.theta_bin_deg, "Bin width in theta_i and theta_e (5, 10 or 15)");
  AddOption(*c, "--phi-bin-deg", o.phi_bin_deg, "Bin width in delta_phi (divides 360; 10, 20 or 30)");
  AddRenamedOption(*c, "--min-pairs", "--min-samples", o.min_samples_per_bin, "Sample pairs a reported bin needs");
  AddOption(*c, "--match-deg", o.match_deg,
            "Partners lie within this angle of the reciprocal (mirrored) point; 0: automatic, the first of\n"
            "0.5, 1, 2, 4 deg giving both figures 20 bins (the JSON's match_deg_used)");
  AddOption(*c, "--max-theta-deg", o.max_theta_deg, "Compare bins up to this theta");
  c->add_flag("--regression", args->regression,
              "Also the local-regression checks: reciprocity near the incidence plane, bilateral symmetry\n"
              "(unfolded fit) and held-out photos (fit without a photo, predict it)");
  AddOption(*c, "--held-out", args->prediction.held_out_photos, "Photos to hold out with --regression");
  c->callback([args] {
    RequireValidOptions(args->o, "--theta-bin-deg/--phi-bin-deg/--min-pairs/--match-deg/--max-theta-deg");
    if (args->regression) RequireValidOptions(args->prediction, "--held-out");
    StageLog stage("check");
    RequireWritableOutput(args->out, args->overwrite, {args->samples, SidecarPath(args->samples)});
    WriteJsonFile(args->out,
                  CheckSamples(ReadSamples(args->samples), args->o, args->regression ? &args->prediction : nullptr));
    Log(1, "report written to " + args->out);
  });
}

}  // namespace ibrdf
