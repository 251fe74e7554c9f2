// The engine of `ibrdf run`: stages executed one by one into a run folder, each skipped when its stamp
// says it is up to date (stamp.h), re-run otherwise with the reason printed, and stamped once its
// action succeeds. Stages are planned one at a time because a later stage's plan depends on the files
// earlier ones wrote (measurement.h). Decisions: docs/workflow.md.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "workflow/stage.h"

namespace ibrdf {

struct WorkflowOptions {
  std::string run_dir;     // the run folder (created, with stamps/); made absolute
  std::string build_id;    // the binary whose stages run (ExecutableBuildId()); a different one re-runs them
  std::string version;     // recorded in stamps for the reader, kIbrdfVersionLine (core/version.h)
  bool force = false;      // re-run every stage that applies, up to date or not
  std::string stop_after;  // the last stage to run ("": all); later ones are not applicable
  // Decide only (`ibrdf batch`'s plan): nothing is created, removed or run; the first stage that would
  // run stops the plan there, and would_run() says which and why.
  bool dry_run = false;

  bool Check(std::string* why) const;
};

class WorkflowRun {
 public:
  // Creates the run folder and DIR/stamps, and removes the temporaries an interrupted stage left
  // (temporaries.h). Throws Error for invalid options.
  explicit WorkflowRun(WorkflowOptions options);

  // Runs `stage` unless it does not apply, comes after stop_after, or is up to date; logs a line per
  // stage ("== run 4: derender (an input changed)") and records the outcome. The old stamp is removed
  // before the action runs and the new one written only after it succeeds, so an interrupted stage
  // runs again. Throws Error when the action fails ("stage NAME failed (exit N) ...").
  const StageOutcome& Execute(Stage stage);

  // Decides `stages` in order as Execute does, then runs those that are due at the same time (each
  // action on its own thread; they must not read each other's outputs), and records them in order once
  // all have ended: the output_log of each is printed, then its time, and its stamp written if it
  // succeeded. Throws Error for the first that failed, after the others have ended (a stage that
  // succeeded beside it keeps its stamp). With dry_run, or one stage due, it is Execute one by one.
  void ExecuteTogether(std::vector<Stage> stages);

  // True once the stop_after stage has been executed: the stages after it do not run.
  bool stopped() const { return !stopped_.empty(); }
  // The stages executed so far, in order.
  const std::vector<Stage>& stages() const { return stages_; }
  // The outcome of an executed stage (an InternalError for an unknown one).
  const StageOutcome& outcome(const std::string& stage) const;
  const WorkflowOptions& options() const { return options_; }
  // With dry_run: "" while every stage so far is up to date (or does not apply); otherwise the first
  // stage that would run and why, "derender (an input changed)".
  const std::string& would_run() const { return would_run_; }
  // The absolute run folder, and `name` inside it.
  const std::string& run_dir() const { return options_.run_dir; }
  std::string Path(const std::string& name) const;

 private:
  // Records `stage` (not applicable once the run stopped) and decides it: returns why it must run, or
  // "" when it is not applicable or up to date (its outcome then recorded and logged).
  std::string Decide(Stage* stage);
  // Logs the heading of a stage that runs and removes its old stamp.
  void Begin(const Stage& stage, size_t number, const std::string& stale, const std::string& beside);
  // Records a finished action: throws Error when `code` is a failure, else stamps it and logs its time.
  void Finish(const Stage& stage, const std::string& stale, int code, double seconds);

  WorkflowOptions options_;
  std::string stopped_;    // why later stages do not run ("--stop-after NAME"), once they do not
  std::string would_run_;  // dry_run: the first stage that would run, and why
  std::vector<Stage> stages_;
  std::map<std::string, StageOutcome> outcomes_;
};

// "1.52 s".
std::string FormatSeconds(double seconds);

}  // namespace ibrdf
