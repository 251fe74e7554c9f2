// ibrdf compare: measured samples against the true BRDF of a synthetic session
// (reconstruct/truth_comparison.h) behind flags.
#include <cstdio>

#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/sample_file.h"
#include "reconstruct/truth_comparison.h"

namespace ibrdf {
namespace {

void AddCompareCommand(CLI::App& app) {
  auto* command = app.add_subcommand(
      "compare",
      "Compare measured samples with the true BRDF of a synthetic session: median and 95th-percentile\n"
      "relative error per channel, overall and by band of max(theta_i, theta_e).");
  struct Args {
    std::string samples, truth, out;
    bool overwrite = false;
  };
  auto args = std::make_shared<Args>();
  command->add_option("samples", args->samples, "Sample file (.npy)")->required();
  command->add_option("--truth", args->truth, "truth.json of the session (default: beside the samples' session)");
  command->add_option("--out", args->out, "Write the figures as JSON here");
  command->add_flag("--overwrite", args->overwrite, "Replace an existing output");
  command->callback([args] {
    StageLog stage("compare");
    const std::string truth_path = args->truth.empty() ? TruthPathFromSidecar(args->samples) : args->truth;
    if (!args->out.empty()) {
      RequireWritableOutput(args->out, args->overwrite, {args->samples, SidecarPath(args->samples), truth_path});
    }
    const std::unique_ptr<BrdfModel> truth = LoadTruthMaterial(truth_path);
    const std::vector<BrdfSample> samples = ReadSamples(args->samples);
    const TruthComparison comparison = CompareWithTruth(samples, *truth);
    std::fputs(ComparisonTable(comparison).c_str(), stdout);
    if (!args->out.empty()) {
      nlohmann::json json = ToJson(comparison);
      json["samples"] = args->samples;
      json["truth"] = truth_path;
      WriteJsonFile(args->out, json);
    }
    Log(1, comparison.BriefReport());
  });
}

}  // namespace

IBRDF_REGISTER_COMMAND(90, AddCompareCommand);

}  // namespace ibrdf
