// ibrdf batch: many sessions through the shipped Snakemake workflow (snakemake/Snakefile): one `ibrdf
// run` per session as a job, on local cores or a Slurm cluster, then the material library
// (workflow/batch_run.h). Docs: docs/workflow.md, "Batches".
#include <iostream>

#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "workflow/batch_run.h"
#include "workflow/build_id.h"

namespace ibrdf {

IBRDF_COMMAND(85, Batch) {
  auto* c = app.add_subcommand(
      "batch",
      "Measure many sessions (folders, recipes or globs in a JSON config): one `ibrdf run` each as a Snakemake\n"
      "job, on local cores or Slurm (--slurm), skipped when up to date; a failed session fails alone and is\n"
      "retried by the next call. Ends with the material library OUT/library. Needs snakemake (docs/workflow.md).");
  struct Args {
    std::string config;
    SnakemakeRunOptions run;
    bool plan = false;
  };
  auto args = std::make_shared<Args>();
  c->add_option("config", args->config, "Batch config (JSON, format ibrdf-batch)")->required();
  c->add_option("--cores", args->run.cores, "Local cores Snakemake may use (default: all)");
  auto* slurm = c->add_flag_callback(
      "--slurm", [args] { args->run.profile = "slurm"; }, "Submit the jobs to Slurm through the shipped profile");
  c->add_option("--profile", args->run.profile, "A Snakemake profile folder of your own")->excludes(slurm);
  c->add_flag("-n,--dry-run", args->run.dry_run, "List the jobs and their commands; run nothing");
  c->add_flag("--plan", args->plan,
              "Print the plan (JSON: each session, its `ibrdf run` command, what it has left to do)\n"
              "and exit; the Snakefile reads it");
  c->add_option("--snakemake-args", args->run.extra, "More snakemake arguments (after --snakemake-args)")
      ->allow_extra_args();
  c->callback([args] {
    const BatchConfig config = ReadBatchConfig(args->config);
    const std::vector<BatchEntryPlan> plan = PlanBatch(config, ExecutableBuildId());
    if (args->plan) {
      std::cout << BatchPlanJson(config, plan, ExecutablePath()).dump(1) << std::endl;
      return;
    }
    RunBatch(config, plan, args->run);
  });
}

}  // namespace ibrdf
