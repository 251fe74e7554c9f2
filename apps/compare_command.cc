// ibrdf compare: measured samples against the true BRDF of a synthetic session
// (reconstruct/truth_comparison.h) behind flags.
#include <cstdio>

#include "apps/commands.h"
#include "core/error.h"
#include "core/json_reader.h"
#include "core/merl_brdf.h"
#include "reconstruct/truth_comparison.h"

namespace ibrdf {

IBRDF_COMMAND(90, Compare) {
  auto* c = app.add_subcommand(
      "compare",
      "Compare measured samples with the true BRDF of a synthetic session (truth.json, a material file or a MERL\n"
      "table): median and 95th-percentile relative error per channel, overall and by band of max(theta_i, theta_e).\n"
      "Given a MERL table instead of samples: the fraction of random lookups that hit a cell with data, their error.");
  struct Args {
    std::string samples, truth, out;
    bool overwrite = false;
    size_t lookups = 200000;
  };
  auto args = std::make_shared<Args>();
  c->add_option("samples", args->samples, "Sample file (.npy), or a MERL table (.binary) to check")->required();
  c->add_option("--truth", args->truth,
                "truth.json, a material file or a MERL table (default: beside the samples' session)");
  AddOption(*c, "--lookups", args->lookups, "With a MERL table: random direction pairs looked up");
  c->add_option("--out", args->out, "Write the figures as JSON here");
  c->add_flag("--overwrite", args->overwrite, "Replace an existing output");
  c->callback([args] {
    StageLog stage("compare");
    if (IsMerlPath(args->samples) && args->truth.empty()) {
      ThrowError(args->samples, "a MERL table has no session: pass --truth");
    }
    const std::string truth = args->truth.empty() ? TruthPathFromSidecar(args->samples) : args->truth;
    if (!args->out.empty()) {
      RequireWritableOutput(args->out, args->overwrite, {args->samples, SidecarPath(args->samples), truth});
    }
    const CompareOutcome outcome = CompareFileWithTruth(args->samples, truth, args->lookups);
    std::fputs(outcome.text.c_str(), stdout);
    if (!args->out.empty()) WriteJsonFile(args->out, outcome.json);
    if (!outcome.brief.empty()) Log(1, outcome.brief);
  });
}

}  // namespace ibrdf
