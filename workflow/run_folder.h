// The run folder of `ibrdf run`: claimed for one input (a folder holding another input's run is
// refused, or emptied with --overwrite), its stages run as child `ibrdf` processes, its summary.json
// written at the end. apps/run_command.cc only parses flags and prints what this returns.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/logging.h"
#include "workflow/measurement.h"

namespace ibrdf {

// Runs each stage as a child `ibrdf` process (ExecutablePath()) with this process's verbosity
// (Verbosity(): --silent, -q or nothing) and `--threads threads`, then the stage's arguments.
StageLauncher ChildStageLauncher(int threads);

// The input whose run a run folder holds: DIR/run-input.json, or the summary.json of an older run ("":
// none).
std::string RunFolderInput(const std::string& dir);

// Refuses a run folder that holds another input's run (its results would mix with this one's), unless
// `overwrite`: then the folder's contents go first. Creates the folder and records `input` (absolute)
// in DIR/run-input.json.
void ClaimRunFolder(const std::string& out, const std::string& input, bool overwrite);

// `ibrdf run`: refuses an `out` that is (or holds) the input, opens the input (OpenMeasurementInput),
// claims the run folder, runs the measurement's stages through `launch` as `version` (the stamps' tool
// version), writes DIR/summary.json and returns it (BuildRunSummary; `wall`: the run's stopwatch).
nlohmann::json RunInFolder(const std::string& input, const std::string& out, const MeasurementOptions& options,
                           bool overwrite, const StageLauncher& launch, const std::string& version, const Timer& wall);

// What `ibrdf run` prints at the end: RunHeadline(summary), the timings, the summary's and the report's paths.
std::vector<std::string> RunFolderReport(const nlohmann::json& summary, const std::string& out, double wall_s);

}  // namespace ibrdf
