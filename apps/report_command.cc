// ibrdf report: the consistency report of a run folder (report/report_stage.h) behind flags.
#include <cstdio>
#include <filesystem>

#include "apps/commands.h"
#include "core/error.h"
#include "core/logging.h"
#include "report/report_stage.h"

namespace ibrdf {
namespace {

void AddReportCommand(CLI::App& app) {
  auto* command = app.add_subcommand(
      "report",
      "The consistency report of an `ibrdf run` folder: OUT/index.html (self-contained, figures embedded)\n"
      "with the measured photo beside the sample rendered from its camera by each model (and the signed\n"
      "difference), spheres, sample coverage, incidence-plane plots per channel with every model evaluated\n"
      "where the samples are, the paper's reciprocity figure, reciprocity and bilateral symmetry with the\n"
      "worst bins located, timings; and OUT/explorer.html, an offline BRDF explorer. Plots by matplotlib\n"
      "(scripts/report.py, Debian's python3).");
  struct Args {
    std::string run_dir, out;
    ReportOptions options;
  };
  auto args = std::make_shared<Args>();
  ReportOptions& o = args->options;
  command
      ->add_option("run_dir", args->run_dir,
                   "Run folder of `ibrdf run` (samples.npy, consistency.json, reconstruction/ ...)")
      ->required();
  command->add_option("--out", args->out, "Report folder to write (default: RUN_DIR/report)");
  command->add_option("--reconstruction", o.reconstruction,
                      "Reconstruction folder of `ibrdf reconstruct` (or its brdf.binary) to show, wherever it is\n"
                      "(default: RUN_DIR/reconstruction); the fits beside it are shown too");
  command->add_option("--photo", o.photo, "Photo index shown beside the renders (default: median phase angle)");
  AddDeprecatedAlias(
      *command,
      command->add_option("--angles-deg", o.angles_deg, "Incidence-plane angles theta_0, 1 to 8 in [0, 85]")
          ->delimiter(',')
          ->expected(1, 8)
          ->capture_default_str(),
      "--angles", o.angles_deg);
  command
      ->add_option("--held-out", o.held_out_photos,
                   "Photos shown held out (0 to 16): each beside the sample rendered by the regression fitted\n"
                   "without it (the photos `ibrdf check --regression --held-out N` holds out; one fit each)")
      ->capture_default_str();
  command->add_option("--title", o.title, "Report title (default: the recipe's or session's name)");
  AddDeprecatedAlias(
      *command,
      command->add_option("--render-size-px", o.render_size_px, "Rendered sphere size, pixels")->capture_default_str(),
      "--render-size", o.render_size_px);
  command->add_flag_callback(
      "--no-explorer", [args] { args->options.explorer = false; }, "Skip explorer.html");
  command->add_flag("--overwrite", o.overwrite, "Replace an existing report folder");
  command->callback([args] {
    RequireValidOptions(args->options, "ibrdf report");
    StageLog stage("report");
    // The output guard: every file of the run folder is an input, except the default report's own.
    const std::filesystem::path own_report = std::filesystem::path(args->run_dir) / "report";
    std::vector<std::string> inputs = {args->run_dir};
    if (!args->options.reconstruction.empty()) inputs.push_back(args->options.reconstruction);
    for (const std::string& file : FilesUnder(args->run_dir)) {
      if (std::filesystem::path(file).lexically_relative(own_report).string().rfind("..", 0) != 0) continue;
      inputs.push_back(file);
    }
    RequireWritableOutput(args->out.empty() ? own_report.string() : args->out, args->options.overwrite, inputs);
    const ReportResult result = WriteReport(args->run_dir, args->options, args->out);
    Log(1, result.BriefReport());
    for (const BandAgreement& band : result.bands) Log(1, band.BriefReport());
    if (!result.explorer_html.empty()) Log(1, "explorer: " + result.explorer_html);
  });
}

}  // namespace

IBRDF_REGISTER_COMMAND(70, AddReportCommand);

}  // namespace ibrdf
