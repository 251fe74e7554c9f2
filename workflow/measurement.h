// The plan of a measurement: (synth, for a recipe) -> scan -> (response) -> align -> (lights) -> (colour) -> derender
// -> check -> compare -> reconstruct -> uniformity -> (materials) -> report, each stage an `ibrdf` subcommand run through a launcher the caller
// gives (apps/run_command.cc: a child process of the same binary), with the inputs, outputs and applicability of
// docs/workflow.md. Each stage is planned from the session the previous one wrote (core/session.h), never from raw
// JSON.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "workflow/recipe.h"
#include "workflow/workflow_run.h"

namespace ibrdf {

// The stages in order, the names --stop-after accepts.
const std::vector<std::string>& MeasurementStageNames();

// Options of `ibrdf run` (the flag each maps to in brackets); passed on to the stages unchanged.
struct MeasurementOptions {
  int pixel_stride = 1;           // derender --stride
  int degree = -1;                // reconstruct --degree (-1: its default)
  double radius_h_deg = -1.0;     // reconstruct --radius-h-deg (-1: its default)
  double radius_d_deg = -1.0;     // reconstruct --radius-d-deg (-1: its default)
  bool fits = true;               // reconstruct's Lafortune and GGX fits (--no-fits)
  bool check_regression = false;  // check --regression (slower: three held-out fits)
  bool report = true;             // the HTML report (--no-report)
  bool spatial = false;           // each group of the uniformity check's cells measured as a material (--spatial)
  bool force = false;             // re-run every stage (--force)
  // check and compare run beside reconstruct (they only read the samples; their output is shown when
  // they end); false: one stage after another (--sequential).
  bool concurrent_sample_stages = true;
  std::string stop_after;  // the last stage to run ("": all of them) (--stop-after)
  // Extra arguments appended to a stage's command line as given (--scan-args, --response-args,
  // --align-args, --lights-args, --colour-args, --derender-args, --check-args, --reconstruct-args,
  // --uniformity-args, --materials-args, --report-args, and run's named pass-through options); part of the
  // stage's stamp.
  std::vector<std::string> scan_args, response_args, align_args, lights_args, colour_args;
  std::vector<std::string> derender_args, check_args, reconstruct_args, uniformity_args, materials_args, report_args;

  // The messages name the flag: "--stride must be at least 1".
  bool Check(std::string* why) const;
};

// What `ibrdf run` was given: a recipe, or a session.
struct MeasurementInput {
  std::optional<Recipe> recipe;  // a recipe folder or recipe.json
  std::string manifest_path;     // a session's manifest, absolute (empty for a recipe)
};

// Opens the SESSION argument (a session folder or session.json, validated here; or a recipe folder or
// recipe.json) for a run into `out`. Throws Error for a missing input, an invalid session or recipe, an
// `out` that is the session's folder or exists and is not a folder.
MeasurementInput OpenMeasurementInput(const std::string& input, const std::string& out);

// Runs a stage's `ibrdf` command line (the arguments after the program and its global flags) for the
// stage `name`, its output into the file `log_path` ("": this process's output); returns its exit
// status (0: success; 128 + N: killed by signal N).
using StageLauncher =
    std::function<int(const std::string& name, const std::vector<std::string>& arguments, const std::string& log_path)>;

// Plans and executes every stage of the measurement in `run`; returns the truth.json used ("" for a
// real session). Throws Error when a stage fails or a session written by one is invalid.
std::string RunMeasurement(const MeasurementInput& input, const MeasurementOptions& options,
                           const StageLauncher& launch, WorkflowRun* run);

}  // namespace ibrdf
