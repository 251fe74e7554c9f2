// ibrdf run: the whole workflow (synth for a recipe, scan, align, derender, check, compare, reconstruct,
// report) into one run folder, each stage a child process of this same binary, skipped when its stamp
// says it is up to date (workflow/: the engine, the plan, the summary). Decisions: docs/workflow.md.
#include <filesystem>
#include <sstream>
#include <tuple>
#include <utility>

#include <tbb/global_control.h>
#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "core/error.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/subprocess.h"
#include "core/version.h"
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
  return [prefix](const std::string& name, const std::vector<std::string>& arguments, const std::string& log_path) {
    std::vector<std::string> argv = prefix;
    argv.insert(argv.end(), arguments.begin(), arguments.end());
    return RunSubprocess(argv, {log_path, {}, name});
  };
}

// The input a run folder belongs to: DIR/run-input.json, or the summary.json of an older run.
std::string RunFolderInput(const fs::path& dir) {
  for (const char* name : {"run-input.json", "summary.json"}) {
    const fs::path path = dir / name;
    if (!fs::is_regular_file(path)) continue;
    const nlohmann::json json = ReadJsonFile(path.string());
    if (json.contains("input") && json["input"].is_string()) return json["input"].get<std::string>();
  }
  return "";
}

// Refuses a run folder that holds another input's run (its results would mix with this one's), unless
// `overwrite`: then the folder's contents go first. Records this run's input in DIR/run-input.json.
void ClaimRunFolder(const std::string& out, const std::string& input, bool overwrite) {
  const fs::path dir(out);
  if (fs::is_directory(dir)) {
    const std::string previous = RunFolderInput(dir);
    const bool other = !previous.empty() && previous != input;
    if (other && !overwrite) {
      ThrowError(out, "holds the run of another input (" + previous + "), not of " + input +
                          ": its results would mix with this run's; choose another --out, or --overwrite to empty it");
    }
    if (other) {
      Log(1, "run: emptying " + out + " (it held the run of " + previous + "; --overwrite)");
      for (const fs::directory_entry& entry : fs::directory_iterator(dir)) fs::remove_all(entry.path());
    }
  }
  fs::create_directories(dir);
  WriteJsonFile((dir / "run-input.json").string(), {{"format", "ibrdf-run-input"}, {"version", 1}, {"input", input}});
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
    bool overwrite = false;
    std::string derender_args, check_args, reconstruct_args, report_args;
    std::vector<std::string> named;  // the named pass-through options, "--flag value" pairs in order
  };
  auto args = std::make_shared<Args>();
  MeasurementOptions& o = args->options;
  command
      ->add_option("session", args->input,
                   "Session folder or session.json; or a recipe folder (samples/<name>, with recipe.json)")
      ->required();
  command
      ->add_option("--out", args->out,
                   "Run folder (created; an existing one of the same input is resumed; one of another input\n"
                   "is refused unless --overwrite)")
      ->required();
  command->add_flag("--overwrite", args->overwrite,
                    "Empty a run folder that holds another input's run before running (nothing else is touched)");
  command->add_option("--stride", o.pixel_stride, "derender: every n-th pixel in x and y")->capture_default_str();
  command->add_option("--degree", o.degree, "reconstruct: local polynomial degree (default: reconstruct's)");
  command->add_option("--radius-h-deg", o.radius_h_deg,
                      "reconstruct: kernel radius along the sheets (default: reconstruct's)");
  command->add_option("--radius-d-deg", o.radius_d_deg,
                      "reconstruct: kernel radius across the sheets (default: reconstruct's)");
  // Plain flags inverted in the callback: CLI11 shows a negated flag ("!--no-fits") as "--no-fits{false}".
  command->add_flag_callback(
      "--no-fits", [args] { args->options.fits = false; }, "reconstruct: skip the Lafortune and GGX fits");
  command->add_flag("--check-regression", o.check_regression, "check: also the regression checks (held-out photos)");
  command->add_flag_callback(
      "--no-report", [args] { args->options.report = false; }, "Skip the HTML report");
  command->add_flag("--force", o.force, "Re-run every stage, up to date or not");
  command->add_flag_callback(
      "--sequential", [args] { args->options.concurrent_sample_stages = false; },
      "Run check and compare after reconstruct, not beside it (by default they run at the same time,\n"
      "their output shown when they end; the outputs are the same)");
  // Named pass-through options: each goes to its stage unchanged.
  struct Named {
    const char* flag;
    const char* stage;
    const char* help;
  };
  for (const Named& named : {Named{"--lobes", "reconstruct", "Lafortune lobes (1 to 3)"},
                             Named{"--bandwidth", "reconstruct", "Kernel radii: given, loo or gcv"},
                             Named{"--max-theta-deg", "reconstruct", "Tabulate up to this theta"},
                             Named{"--visibility", "derender", "Mesh samples' shadow rays: auto, on or off"},
                             Named{"--max-theta-i-deg", "derender", "Reject samples beyond this incidence angle"},
                             Named{"--max-theta-e-deg", "derender", "Reject samples beyond this exitance angle"},
                             Named{"--min-signal", "derender", "Reject pixels below this linear signal"},
                             Named{"--held-out", "report", "Photos shown held out (a fit without each)"}}) {
    const std::string flag = named.flag, stage = named.stage;
    command
        ->add_option_function<std::string>(
            flag,
            [args, flag, stage](const std::string& value) {
              args->named.push_back(stage + "\n" + flag + "\n" + value);
            },
            std::string(named.stage) + ": " + named.help + " (passed to `ibrdf " + named.stage + " " + flag + "`)")
        ->type_name("VALUE");
  }
  for (auto [flag, target, stage, example] :
       {std::tuple{"--derender-args", &args->derender_args, "derender", "--shadow-edge-deg 2"},
        std::tuple{"--check-args", &args->check_args, "check", "--theta-bin-deg 5 --phi-bin-deg 10"},
        std::tuple{"--reconstruct-args", &args->reconstruct_args, "reconstruct", "--degree 1 --no-fold"},
        std::tuple{"--report-args", &args->report_args, "report", "--angles-deg 20,40,60"}}) {
    command
        ->add_option(flag, *target,
                     std::string("More arguments for `ibrdf ") + stage + "`, one string split at spaces, e.g. \"" +
                         example + "\"")
        ->type_name("\"ARGS\"");
  }
  command->add_option("--stop-after", o.stop_after,
                      "Stop after this stage (synth, scan, align, colour, derender, check, compare,\n"
                      "reconstruct, report); later stages are left as they are");
  command->callback([args] {
    Timer wall;
    RequireValidOptions(args->options, "ibrdf run");
    // The output guard: the run folder is resumed, not replaced, but it must not be (or hold) the input.
    RequireOutputOutsideInputs(args->out, {args->input});
    for (auto [text, target] : {std::pair{&args->derender_args, &args->options.derender_args},
                                std::pair{&args->check_args, &args->options.check_args},
                                std::pair{&args->reconstruct_args, &args->options.reconstruct_args},
                                std::pair{&args->report_args, &args->options.report_args}}) {
      std::istringstream words(*text);
      for (std::string word; words >> word;) target->push_back(word);
    }
    for (const std::string& named : args->named) {
      const size_t a = named.find('\n'), b = named.find('\n', a + 1);
      const std::string stage = named.substr(0, a);
      std::vector<std::string>* target = stage == "derender" ? &args->options.derender_args
                                         : stage == "report" ? &args->options.report_args
                                                             : &args->options.reconstruct_args;
      target->push_back(named.substr(a + 1, b - a - 1));
      target->push_back(named.substr(b + 1));
    }

    // The input: a recipe folder, or a session (validated here, so a bad one is one clear line).
    const MeasurementInput input = OpenMeasurementInput(args->input, args->out);
    ClaimRunFolder(args->out, fs::absolute(args->input).lexically_normal().string(), args->overwrite);
    WorkflowRun run({args->out, ExecutableBuildId(), kIbrdfVersionLine, args->options.force, args->options.stop_after});
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
