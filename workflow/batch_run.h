// `ibrdf batch`'s run: the plan's pending sessions logged, the shipped Snakemake workflow run over the
// batch (one `ibrdf run` job per session), and the outcome read back from the material library's index.
// apps/batch_command.cc only parses flags into SnakemakeRunOptions.
#pragma once

#include <vector>

#include "workflow/batch_config.h"
#include "workflow/batch_plan.h"
#include "workflow/snakemake_workflow.h"

namespace ibrdf {

// Logs each entry of `plan` (up to date, or what it has left to run) and the count to run; then runs
// snakemake with `run` completed from `config` (the program, the Snakefile's folder, the config, the
// batch folder, this binary; --quiet below verbosity 2) and logs every session that failed and where
// the library is. Throws Error when a dry run fails, snakemake wrote no library, or a session failed
// (naming them: the same command runs only those again). Before anything runs, the batch's outputs (each
// session's run folder and log, the library) are checked against its inputs (the config, each
// session or recipe): none may be one or hold one (RequireOutputOutsideInputs, core/output_guard.h).
void RunBatch(const BatchConfig& config, const std::vector<BatchEntryPlan>& plan, SnakemakeRunOptions run);

}  // namespace ibrdf
