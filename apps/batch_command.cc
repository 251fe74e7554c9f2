// ibrdf batch: many sessions through the shipped Snakemake workflow (snakemake/Snakefile): one `ibrdf
// run` per session as a job, on local cores or a Slurm cluster, then the material library. A thin
// front end: it plans (which sessions `ibrdf run` would not skip), runs snakemake and summarizes the
// library's index. Docs: docs/workflow.md, "Batches".
#include <filesystem>
#include <iostream>

#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "core/error.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/subprocess.h"
#include "workflow/batch_config.h"
#include "workflow/batch_plan.h"
#include "workflow/build_id.h"
#include "workflow/snakemake_workflow.h"
#include "workflow/workflow_run.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

std::string Join(const std::vector<std::string>& argv) {
  std::string line;
  for (const std::string& a : argv) line += (line.empty() ? "" : " ") + a;
  return line;
}

void AddBatchCommand(CLI::App& app) {
  auto* command = app.add_subcommand(
      "batch",
      "Measure many sessions: one `ibrdf run` per session (folders, recipes or glob patterns listed in a\n"
      "JSON config) as a Snakemake job, in parallel on local cores or on a Slurm cluster (--slurm), each\n"
      "skipped when `ibrdf run` would skip it; a failed session fails alone (its error in OUT/logs/ and in\n"
      "the library's index) and is retried by the next call. Ends with the material library in\n"
      "OUT/library (`ibrdf library`). Needs snakemake (Debian's package). Docs: docs/workflow.md.");
  struct Args {
    std::string config;
    SnakemakeRunOptions run;
    bool plan = false, slurm = false;
  };
  auto args = std::make_shared<Args>();
  command->add_option("config", args->config, "Batch config (JSON, format ibrdf-batch)")->required();
  command->add_option("--cores", args->run.cores, "Local cores Snakemake may use (default: all)");
  command->add_flag("--slurm", args->slurm, "Submit the jobs to Slurm through the shipped profile");
  command->add_option("--profile", args->run.profile, "A Snakemake profile folder of your own")
      ->excludes(command->get_option("--slurm"));
  command->add_flag("-n,--dry-run", args->run.dry_run, "List the jobs and their commands; run nothing");
  command->add_flag("--plan", args->plan,
                    "Print the plan (JSON: each session, its `ibrdf run` command, what it has left to do)\n"
                    "and exit; the Snakefile reads it");
  command->add_option("--snakemake-args", args->run.extra, "More snakemake arguments (after --snakemake-args)")
      ->allow_extra_args();
  command->callback([args] {
    const BatchConfig config = ReadBatchConfig(args->config);
    const std::vector<BatchEntryPlan> plan = PlanBatch(config, ExecutableBuildId());
    if (args->plan) {
      std::cout << BatchPlanJson(config, plan, ExecutablePath()).dump(1) << std::endl;
      return;
    }
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

    SnakemakeRunOptions run = args->run;
    run.snakemake = FindSnakemake();
    run.snakemake_dir = FindSnakemakeDir();
    run.config = config.path;
    run.out_dir = config.out_dir;
    run.ibrdf = ExecutablePath();
    run.quiet = Verbosity() < 2;
    if (args->slurm) run.profile = "slurm";
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
  });
}

}  // namespace

IBRDF_REGISTER_COMMAND(85, AddBatchCommand);

}  // namespace ibrdf
