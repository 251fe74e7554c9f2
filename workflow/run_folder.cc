#include "workflow/run_folder.h"

#include <filesystem>

#include "core/error.h"
#include "core/json_reader.h"
#include "core/output_guard.h"
#include "core/subprocess.h"
#include "workflow/build_id.h"
#include "workflow/run_summary.h"
#include "workflow/workflow_run.h"

namespace fs = std::filesystem;

namespace ibrdf {

StageLauncher ChildStageLauncher(int threads) {
  std::vector<std::string> prefix = {ExecutablePath()};
  if (Verbosity() == 0) prefix.push_back("--silent");
  if (Verbosity() == 1) prefix.push_back("-q");
  prefix.push_back("--threads");
  prefix.push_back(std::to_string(threads));
  return [prefix](const std::string& name, const std::vector<std::string>& arguments, const std::string& log_path) {
    std::vector<std::string> argv = prefix;
    argv.insert(argv.end(), arguments.begin(), arguments.end());
    return RunSubprocess(argv, {log_path, {}, name});
  };
}

std::string RunFolderInput(const std::string& dir) {
  for (const char* name : {"run-input.json", "summary.json"}) {
    const fs::path path = fs::path(dir) / name;
    if (!fs::is_regular_file(path)) continue;
    const nlohmann::json json = ReadJsonFile(path.string());
    if (json.contains("input") && json["input"].is_string()) return json["input"].get<std::string>();
  }
  return "";
}

void ClaimRunFolder(const std::string& out, const std::string& input, bool overwrite) {
  const fs::path dir(out);
  if (fs::is_directory(dir)) {
    const std::string previous = RunFolderInput(out);
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

nlohmann::json RunInFolder(const std::string& input, const std::string& out, const MeasurementOptions& options,
                           bool overwrite, const StageLauncher& launch, const std::string& version, const Timer& wall) {
  // The output guard: the run folder is resumed, not replaced, but it must not be (or hold) the input.
  RequireOutputOutsideInputs(out, {input});
  // The input: a recipe folder, or a session (validated here, so a bad one is one clear line).
  const MeasurementInput opened = OpenMeasurementInput(input, out);
  const std::string absolute = fs::absolute(input).lexically_normal().string();
  ClaimRunFolder(out, absolute, overwrite);
  WorkflowRun run({out, ExecutableBuildId(), version, options.force, options.stop_after});
  const std::string truth_path = RunMeasurement(opened, options, launch, &run);
  const nlohmann::json summary = BuildRunSummary(run, absolute, truth_path, wall.ElapsedSeconds());
  WriteJsonFile(run.Path("summary.json"), summary);
  return summary;
}

std::vector<std::string> RunFolderReport(const nlohmann::json& summary, const std::string& out, double wall_s) {
  std::vector<std::string> lines = RunHeadline(summary);
  lines.push_back("-- run: " + FormatSeconds(wall_s) + " (stages as recorded: " +
                  FormatSeconds(summary.at("timings_s").at("stages_total").get<double>()) + ")");
  lines.push_back("summary: " + (fs::path(out) / "summary.json").string());
  if (summary.contains("report")) lines.push_back("report: " + summary.at("report").get<std::string>());
  return lines;
}

}  // namespace ibrdf
