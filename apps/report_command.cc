// ibrdf report: the consistency report of a run folder (report/report_stage.h) behind flags.
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
      "and the PNG figures beside it: sample coverage, incidence-plane plots per channel with the\n"
      "reconstruction, reciprocity and bilateral symmetry, a rendered sphere beside a measured photo,\n"
      "timings and rejected samples. Plots by matplotlib (scripts/report.py, Debian's python3).");
  struct Args {
    std::string run_dir, out;
    ReportOptions options;
  };
  auto args = std::make_shared<Args>();
  command
      ->add_option("run_dir", args->run_dir,
                   "Run folder of `ibrdf run` (samples.npy, consistency.json, reconstruction/ ...)")
      ->required();
  command->add_option("--out", args->out, "Report folder to write (default: RUN_DIR/report)");
  command->add_option("--photo", args->options.photo,
                      "Photo index shown beside the render (default: median phase angle)");
  command->add_option("--render-size", args->options.render_size, "Rendered sphere size, pixels")
      ->capture_default_str();
  command->add_flag("--overwrite", args->options.overwrite, "Replace an existing report folder");
  command->callback([args] {
    StageLog stage("report");
    const int size = args->options.render_size;
    if (size < 16 || size > 4096) ThrowError("ibrdf report", "--render-size must be in [16, 4096]");
    // The output guard: every file of the run folder is an input, except the default report's own.
    const std::filesystem::path own_report = std::filesystem::path(args->run_dir) / "report";
    std::vector<std::string> inputs = {args->run_dir};
    for (const std::string& file : FilesUnder(args->run_dir)) {
      if (std::filesystem::path(file).lexically_relative(own_report).string().rfind("..", 0) != 0) continue;
      inputs.push_back(file);
    }
    RequireWritableOutput(args->out.empty() ? own_report.string() : args->out, args->options.overwrite, inputs);
    WriteReport(args->run_dir, args->options, args->out);
  });
}

}  // namespace

IBRDF_REGISTER_COMMAND(70, AddReportCommand);

}  // namespace ibrdf
