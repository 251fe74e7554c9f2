#include "workflow/batch_plan.h"

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/logging.h"
#include "core/version.h"
#include "workflow/workflow_run.h"

namespace ibrdf {

std::vector<BatchEntryPlan> PlanBatch(const BatchConfig& config, const std::string& build_id) {
  std::vector<BatchEntryPlan> plan;
  for (const BatchEntry& entry : config.entries) {
    BatchEntryPlan entry_plan{entry, ""};
    try {
      const MeasurementInput input = OpenMeasurementInput(entry.input, entry.run_dir);
      WorkflowOptions options{entry.run_dir, build_id, kIbrdfVersionLine, false, ""};
      options.dry_run = true;
      WorkflowRun run(options);
      // A dry run never calls the launcher: the first stage that would run stops the plan.
      const StageLauncher never = [](const std::string& name, const std::vector<std::string>&,
                                     const std::string&) -> int {
        IBRDF_CHECK(false) << "dry run launched stage " << name;
        return 1;
      };
      const int verbosity = Verbosity();
      SetVerbosity(0);  // the engine's per-stage lines are for a real run
      try {
        RunMeasurement(input, entry.options, never, &run);
      } catch (...) {
        SetVerbosity(verbosity);
        throw;
      }
      SetVerbosity(verbosity);
      entry_plan.pending = run.would_run();
    } catch (const Error& error) {
      entry_plan.pending = std::string("cannot plan: ") + error.what();
    }
    plan.push_back(entry_plan);
  }
  return plan;
}

nlohmann::json BatchPlanJson(const BatchConfig& config, const std::vector<BatchEntryPlan>& plan,
                             const std::string& ibrdf_binary) {
  nlohmann::json sessions = nlohmann::json::array();
  for (const BatchEntryPlan& p : plan) {
    sessions.push_back({{"name", p.entry.name},
                        {"input", p.entry.input},
                        {"run_dir", p.entry.run_dir},
                        {"log", p.entry.log_path},
                        {"arguments", RunArguments(p.entry)},
                        {"pending", p.pending}});
  }
  return {{"format", "ibrdf-batch-plan"},
          {"version", 1},
          {"config", config.path},
          {"out", config.out_dir},
          {"library", config.LibraryDir()},
          {"ibrdf", ibrdf_binary},
          {"threads_per_job", config.threads_per_job},
          {"mem_mb_per_job", config.mem_mb_per_job},
          {"runtime_min_per_job", config.runtime_min_per_job},
          {"sessions", sessions}};
}

}  // namespace ibrdf
