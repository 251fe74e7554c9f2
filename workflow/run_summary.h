// DIR/summary.json of `ibrdf run` (fields: docs/workflow.md), built from the workflow's outcomes and
// the stages' own outputs read through typed readers (stage_json.h): a figure a stage always writes
// that is missing or wrongly typed is an Error naming the file and the key, an optional one is left
// absent or at its default, and a file that is absent leaves its section out.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "workflow/workflow_run.h"

namespace ibrdf {

// The summary of `run`: `input` is the SESSION argument (absolute), `truth_path` the truth.json used
// ("" for a real session), `wall_s` this invocation's wall-clock seconds.
nlohmann::json BuildRunSummary(const WorkflowRun& run, const std::string& input, const std::string& truth_path,
                               double wall_s);

// The headline figures of a summary as `ibrdf run` prints them, one line each: the samples and their
// rejections, the consistency figures, the errors against the truth (each where the summary has it).
std::vector<std::string> RunHeadline(const nlohmann::json& summary);

}  // namespace ibrdf
