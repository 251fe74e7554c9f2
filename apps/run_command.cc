// ibrdf run: the whole workflow (synth for a recipe, scan, align, derender, check, compare, reconstruct,
// report) into one run folder, each stage a child process of this same binary, skipped when its stamp
// says it is up to date (workflow/: the engine, the plan, the summary). Decisions: docs/workflow.md.
#include <filesystem>

#include <tbb/global_control.h>
#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "core/error.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/subprocess.h"
#include "workflow/build_id.h"
#include "workflow/measurement.h"
#include "workflow/run_summary.h"
#include "workflow/workflow_run.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

// Runs a stage as a child `ibrdf` process with this run's verbosity and thread count.
StageLauncher ChildLauncher() {
  std::vector<std::string> prefix = {ExecutablePath()};
  if (Verbosity() == 0) prefix.push_back("--silent");
  if (Verbosity() == 1) prefix.push_back("-q");
  prefix.push_back("--threads");
  prefix.push_back(std::to_string(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism)));
  return [prefix](const std::string& name, const std::vector<std::string>& arguments) {
    std::vector<std::string> argv = prefix;
    argv.insert(argv.end(), arguments.begin(), arguments.end());
    return RunSubprocess(argv, {"", {}, name});
  };
}

void AddRunCommand(CLI::App& app) {
  auto* command = app.add_subcommand(
      "run",
      "The whole workflow into one folder: (synth, for a recipe) -> scan -> align -> derender -> check ->\n"
      "compare (synthetic sessions) -> reconstruct -> report, each stage a child `ibrdf` process. A stage is\n"
      "skipped when its outputs are newer than its inputs and its options are unchanged (DIR/stamps/), so an\n"
      "interrupted run resumes where it stopped. Writes DIR/summary.json (docs/workflow.md).");
  struct Args {
    std::string input, out;
    MeasurementOptions options;
  };
  auto args = std::make_shared<Args>();
  MeasurementOptions& o = args->options;
  command
      ->add_option("session", args->input,
                   "Session folder or session.json; or a recipe folder (samples/<name>, with recipe.json)")
      ->required();
  command->add_option("--out", args->out, "Run folder (created; an existing one is resumed)")->required();
  command->add_option("--stride", o.pixel_stride, "derender: every n-th pixel in x and y")->capture_default_str();
  command->add_option("--degree", o.degree, "reconstruct: local polynomial degree (default: reconstruct's)");
  command->add_option("--radius-h-deg", o.radius_h_deg,
                      "reconstruct: kernel radius along the sheets (default: reconstruct's)");
  command->add_option("--radius-d-deg", o.radius_d_deg,
                      "reconstruct: kernel radius across the sheets (default: reconstruct's)");
  command->add_flag("!--no-fits", o.fits, "reconstruct: skip the Lafortune and GGX fits");
  command->add_flag("--check-regression", o.check_regression, "check: also the regression checks (held-out photos)");
  command->add_flag("!--no-report", o.report, "Skip the HTML report");
  command->add_flag("--force", o.force, "Re-run every stage, up to date or not");
  command->add_option("--stop-after", o.stop_after,
                      "Stop after this stage (synth, scan, align, derender, check, compare,\n"
                      "reconstruct, report); later stages are left as they are");
  command->callback([args] {
    Timer wall;
    std::string why;
    if (!args->options.Check(&why)) ThrowError("ibrdf run", why);
    // The output guard: the run folder is resumed, not replaced, but it must not be (or hold) the input.
    RequireOutputOutsideInputs(args->out, {args->input});
    // The input: a recipe folder, or a session (validated here, so a bad one is one clear line).
    const MeasurementInput input = OpenMeasurementInput(args->input, args->out);
    WorkflowRun run({args->out, ExecutableBuildId(), "ibrdf 0.1.0", args->options.force, args->options.stop_after});
    const std::string truth_path = RunMeasurement(input, args->options, ChildLauncher(), &run);

    const nlohmann::json summary =
        BuildRunSummary(run, fs::absolute(args->input).lexically_normal().string(), truth_path, wall.ElapsedSeconds());
    WriteJsonFile(run.Path("summary.json"), summary);
    for (const std::string& line : RunHeadline(summary)) Log(1, line);
    Log(1, "-- run: " + FormatSeconds(wall.ElapsedSeconds()) + " (stages as recorded: " +
               FormatSeconds(summary.at("timings_s").at("stages_total").get<double>()) + ")");
    Log(1, "summary: " + run.Path("summary.json"));
    if (summary.contains("report")) Log(1, "report: " + summary.at("report").get<std::string>());
  });
}

}  // namespace

IBRDF_REGISTER_COMMAND(80, AddRunCommand);

}  // namespace ibrdf
