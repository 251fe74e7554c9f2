#include "workflow/workflow_run.h"

#include <cstdio>
#include <filesystem>

#include "core/error.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "workflow/stamp.h"
#include "workflow/temporaries.h"

namespace fs = std::filesystem;

namespace ibrdf {

bool WorkflowOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION(!run_dir.empty());
  IBRDF_CHECK_OPTION(!build_id.empty());
  return true;
}

std::string FormatSeconds(double seconds) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.2f s", seconds);
  return buffer;
}

WorkflowRun::WorkflowRun(WorkflowOptions options) : options_(std::move(options)) {
  std::string why;
  if (!options_.Check(&why)) ThrowError("workflow options", why);
  options_.run_dir = fs::absolute(options_.run_dir).lexically_normal().string();
  if (fs::exists(options_.run_dir) && !fs::is_directory(options_.run_dir)) {
    ThrowError(options_.run_dir, "exists and is not a folder");
  }
  if (options_.dry_run) return;
  fs::create_directories(fs::path(options_.run_dir) / "stamps");
  RemoveStaleTemporaries(options_.run_dir);
}

std::string WorkflowRun::Path(const std::string& name) const { return (fs::path(options_.run_dir) / name).string(); }

const StageOutcome& WorkflowRun::outcome(const std::string& stage) const {
  const auto it = outcomes_.find(stage);
  IBRDF_CHECK(it != outcomes_.end()) << "stage " << stage << " was not executed";
  return it->second;
}

const StageOutcome& WorkflowRun::Execute(Stage stage) {
  if (stopped()) stage.not_applicable = stopped_;
  if (stage.name == options_.stop_after) stopped_ = "--stop-after " + options_.stop_after;
  IBRDF_CHECK(!outcomes_.count(stage.name)) << "stage " << stage.name << " executed twice";
  stages_.push_back(stage);
  StageOutcome& outcome = outcomes_[stage.name];
  const std::string heading = "== run " + std::to_string(stages_.size()) + ": " + stage.name;
  if (!stage.not_applicable.empty()) {
    outcome = {StageStatus::kNotApplicable, stage.not_applicable, 0.0};
    Log(1, heading + ": not applicable (" + stage.not_applicable + ")");
    return outcome;
  }
  const std::string stamp_path = StampPath(options_.run_dir, stage.name);
  const std::string stale = options_.force ? "--force" : WhyStale(options_.run_dir, stage, options_.build_id);
  if (stale.empty()) {
    outcome = {StageStatus::kSkipped, "up to date", Stamp::Read(stamp_path).seconds};
    Log(1, heading + ": up to date, skipped (took " + FormatSeconds(outcome.seconds) + " when it ran)");
    return outcome;
  }
  if (options_.dry_run) {
    would_run_ = stage.name + " (" + stale + ")";
    stopped_ = "dry run: " + would_run_ + " would run first";
    outcome = {StageStatus::kNotApplicable, stopped_, 0.0};
    return outcome;
  }
  Log(1, heading + " (" + stale + ")");
  std::error_code ignored;
  fs::remove(stamp_path, ignored);
  IBRDF_CHECK(stage.action) << "stage " << stage.name << " has no action";
  Timer timer;
  const int code = stage.action();
  if (code != 0) {
    ThrowError("ibrdf run", "stage " + stage.name + " failed (exit " + std::to_string(code) +
                                (code > 128 ? ", killed by signal " + std::to_string(code - 128) : "") +
                                "); fix the cause and run again to resume from it");
  }
  outcome = {StageStatus::kRan, stale, timer.ElapsedSeconds()};
  WriteJsonFile(stamp_path, StampOf(stage, options_.build_id, options_.version, outcome.seconds).ToJson());
  Log(1, "-- run: " + stage.name + ": " + FormatSeconds(outcome.seconds));
  return outcome;
}

}  // namespace ibrdf
