// What a batch has left to do, decided by `ibrdf run`'s own skip rule (stamp.h) without running or
// changing anything: the plan the Snakemake workflow (snakemake/Snakefile) builds its jobs from, so
// that Snakemake schedules exactly the sessions `ibrdf run` would not skip (docs/workflow.md, "Batches").
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "workflow/batch_config.h"

namespace ibrdf {

// An entry's state.
struct BatchEntryPlan {
  BatchEntry entry;
  // "" when `ibrdf run` would skip every stage; otherwise the first stage that would run and why,
  // "derender (an input changed)", or the error that will fail the job ("cannot plan: ...").
  std::string pending;
};

// Plans every entry of `config` for the binary `build_id` (ExecutableBuildId()): a dry run of the
// workflow engine (WorkflowOptions::dry_run) over the entry's stamps. A session that cannot be opened
// is pending with its error, so that its job runs and fails with that error in its log.
std::vector<BatchEntryPlan> PlanBatch(const BatchConfig& config, const std::string& build_id);

// The plan as the Snakefile reads it: {"format": "ibrdf-batch-plan", "version": 1, "config", "out",
// "library", "ibrdf", "threads_per_job", "mem_mb_per_job", "runtime_min_per_job", "sessions": [{"name",
// "input", "run_dir", "log", "arguments", "pending"}]}, `ibrdf` the binary the jobs run.
nlohmann::json BatchPlanJson(const BatchConfig& config, const std::vector<BatchEntryPlan>& plan,
                             const std::string& ibrdf_binary);

}  // namespace ibrdf
