// ibrdf compare: measured samples against the true BRDF of a synthetic session.
#include <cstdio>
#include <filesystem>
#include <iostream>

#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "core/error.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/sample_file.h"
#include "reconstruct/truth_comparison.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

// truth.json beside the session the samples came from, as the sidecar records it.
std::string TruthFromSidecar(const std::string& samples_path) {
  const std::string sidecar = SidecarPath(samples_path);
  if (!fs::exists(sidecar)) ThrowError(samples_path, "has no sidecar " + sidecar + "; pass --truth");
  const nlohmann::json json = ReadJsonFile(sidecar);
  if (!json.contains("session") || !json["session"].is_string()) {
    ThrowError(sidecar + ": /session", "missing; pass --truth");
  }
  const std::string truth = (fs::path(json["session"].get<std::string>()).parent_path() / "truth.json").string();
  if (!fs::exists(truth)) {
    ThrowError(truth, "does not exist: the samples' session is not synthetic (pass --truth for a known BRDF)");
  }
  return truth;
}

void PrintTable(const TruthComparison& comparison) {
  std::printf("%-12s %9s  %-26s  %-26s\n", "theta band", "samples", "median |rel error| R G B %",
              "p95 |rel error| R G B %");
  auto row = [](const std::string& name, const ErrorStats& s) {
    std::printf("%-12s %9zu  %7.3f %7.3f %7.3f    %7.2f %7.2f %7.2f\n", name.c_str(), s.count, 100 * s.median[0],
                100 * s.median[1], 100 * s.median[2], 100 * s.p95[0], 100 * s.p95[1], 100 * s.p95[2]);
  };
  for (const ThetaBand& band : comparison.bands) {
    if (band.stats.count == 0) continue;
    row(std::to_string(int(band.low_deg)) + "-" + std::to_string(int(band.high_deg)) + " deg", band.stats);
  }
  row("all", comparison.overall);
}

}  // namespace

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
    if (!args->out.empty()) RequireWritableOutput(args->out, args->overwrite, {args->samples});
    const std::string truth_path = args->truth.empty() ? TruthFromSidecar(args->samples) : args->truth;
    const std::unique_ptr<BrdfModel> truth = LoadTruthMaterial(truth_path);
    const std::vector<BrdfSample> samples = ReadSamples(args->samples);
    const TruthComparison comparison = CompareWithTruth(samples, *truth);
    PrintTable(comparison);
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
