#include "workflow/batch_run.h"

#include <filesystem>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/output_guard.h"
#include "core/subprocess.h"
#include "workflow/build_id.h"
#include "workflow/workflow_run.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

std::string Join(const std::vector<std::string>& words) {
  std::string line;
  for (const std::string& word : words) line += (line.empty() ? "" : " ") + word;
  return line;
}

}  // namespace

void RunBatch(const BatchConfig& config, const std::vector<BatchEntryPlan>& plan, SnakemakeRunOptions run) {
  // Each run resumes its own folder rather than replacing it, and the library replaces its folder: an
  // input inside any of them would be lost, so none may hold one (the runs' own guards would stop only
  // that job, after others had run).
  std::vector<std::string> inputs = {config.path};
  for (const BatchEntry& entry : config.entries) inputs.push_back(entry.input);
  for (const BatchEntry& entry : config.entries) {
    RequireOutputOutsideInputs(entry.run_dir, inputs);
    RequireOutputOutsideInputs(entry.log_path, inputs);
  }
  RequireOutputOutsideInputs(config.LibraryDir(), inputs);
  int pending = 0;
  for (const BatchEntryPlan& p : plan) {
    if (p.pending.empty()) {
      Log(2, "batch: " + p.entry.name + ": up to date");
    } else {
      ++pending;
      Log(1, "batch: " + p.entry.name + ": to run: " + p.pending);
    }
  }
  Log(1, "batch: " + std::to_string(config.entries.size()) + " sessions, " + std::to_string(pending) +
             " to run; out: " + config.out_dir);

  run.snakemake = FindSnakemake();
  run.snakemake_dir = FindSnakemakeDir();
  run.config = config.path;
  run.out_dir = config.out_dir;
  run.ibrdf = ExecutablePath();
  run.quiet = Verbosity() < 2;
  fs::create_directories(config.out_dir);
  const std::vector<std::string> argv = SnakemakeArguments(run);
  Log(2, "batch: " + Join(argv));
  Timer wall;
  const int code = RunSubprocess(argv);
  if (run.dry_run) {
    if (code != 0) ThrowError("ibrdf batch", "snakemake --dry-run failed (exit " + std::to_string(code) + ")");
    return;
  }

  // The library's index says how every session stands, including those that failed.
  const std::string index_path = (fs::path(config.LibraryDir()) / "index.json").string();
  if (!fs::exists(index_path)) {
    ThrowError("ibrdf batch", "snakemake exited " + std::to_string(code) + " and wrote no library (" + index_path +
                                  "); see its output above");
  }
  const nlohmann::json index = ReadJsonFile(index_path);
  std::vector<std::string> failed;
  for (const nlohmann::json& m : index.at("materials")) {
    const std::string status = m.at("status").get<std::string>();
    if (status != "ok") {
      failed.push_back(m.at("name").get<std::string>());
      Log(0, "batch: " + m.at("name").get<std::string>() + ": " + status + ": " + m.value("error", std::string()) +
                 (m.contains("log") ? " (log: " + m["log"].get<std::string>() + ")" : ""));
    }
  }
  Log(1, "batch: " + std::to_string(index.at("counts").at("ok").get<int>()) + " of " +
             std::to_string(config.entries.size()) + " materials in the library (" +
             FormatSeconds(wall.ElapsedSeconds()) + "): " + (fs::path(config.LibraryDir()) / "index.html").string());
  if (!failed.empty() || code != 0) {
    ThrowError("ibrdf batch", std::to_string(failed.size()) + " of " + std::to_string(config.entries.size()) +
                                  " sessions failed (" + Join(failed) +
                                  "); fix them and run the same command again: only they will run");
  }
}

}  // namespace ibrdf
