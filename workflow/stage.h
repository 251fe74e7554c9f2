// One stage of a workflow (`ibrdf run`): what it reads and writes, its options, and how to run it.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace ibrdf {

struct Stage {
  std::string name;                    // unique in a run; names its stamp, DIR/stamps/<name>.json
  std::vector<std::string> arguments;  // its options as a command line: a changed one re-runs the stage
  std::vector<std::string> inputs;     // files whose change (size, modification time) re-runs it
  std::vector<std::string> outputs;    // files it must leave behind, none older than an input
  std::string not_applicable;          // non-empty: the stage is skipped with this reason
  // Runs the stage: 0 on success, otherwise an exit status (128 + N: killed by signal N). `ibrdf run`
  // runs a child `ibrdf` process here (apps/run_command.cc); tests use plain functions.
  std::function<int()> action;
  // Run beside other stages (WorkflowRun::ExecuteTogether): the file the action sends its output to
  // ("": this process's output, live); printed, in stage order, once the stages have ended.
  std::string output_log;
};

// What happened to a stage in one invocation.
enum class StageStatus {
  kRan,            // it ran in this invocation
  kSkipped,        // up to date
  kNotApplicable,  // does not apply (or comes after --stop-after)
};

// "ran", "skipped", "not_applicable" (summary.json's stages.<name>.status).
const char* StageStatusName(StageStatus status);

struct StageOutcome {
  StageStatus status = StageStatus::kNotApplicable;
  std::string reason;    // why it ran (the staleness reason), "up to date", or why it does not apply
  double seconds = 0.0;  // this invocation's wall time, or the recorded time of the run that made the outputs
};

}  // namespace ibrdf
