#include "workflow/workflow_run.h"

#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <thread>

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

std::string WorkflowRun::Decide(Stage* stage) {
  if (stopped()) stage->not_applicable = stopped_;
  if (stage->name == options_.stop_after) stopped_ = "--stop-after " + options_.stop_after;
  IBRDF_CHECK(!outcomes_.count(stage->name)) << "stage " << stage->name << " executed twice";
  stages_.push_back(*stage);
  StageOutcome& outcome = outcomes_[stage->name];
  const std::string heading = "== run " + std::to_string(stages_.size()) + ": " + stage->name;
  if (!stage->not_applicable.empty()) {
    outcome = {StageStatus::kNotApplicable, stage->not_applicable, 0.0};
    Log(1, heading + ": not applicable (" + stage->not_applicable + ")");
    return "";
  }
  const std::string stale = options_.force ? "--force" : WhyStale(options_.run_dir, *stage, options_.build_id);
  if (stale.empty()) {
    outcome = {StageStatus::kSkipped, "up to date", Stamp::Read(StampPath(options_.run_dir, stage->name)).seconds};
    Log(1, heading + ": up to date, skipped (took " + FormatSeconds(outcome.seconds) + " when it ran)");
  }
  return stale;
}

const StageOutcome& WorkflowRun::Execute(Stage stage) {
  const std::string stale = Decide(&stage);
  StageOutcome& outcome = outcomes_[stage.name];
  if (stale.empty()) return outcome;
  if (options_.dry_run) {
    would_run_ = stage.name + " (" + stale + ")";
    stopped_ = "dry run: " + would_run_ + " would run first";
    outcome = {StageStatus::kNotApplicable, stopped_, 0.0};
    return outcome;
  }
  Begin(stage, stages_.size(), stale, "");
  IBRDF_CHECK(stage.action) << "stage " << stage.name << " has no action";
  Timer timer;
  const int code = stage.action();
  Finish(stage, stale, code, timer.ElapsedSeconds());
  return outcome;
}

void WorkflowRun::Begin(const Stage& stage, size_t number, const std::string& stale, const std::string& beside) {
  Log(1, "== run " + std::to_string(number) + ": " + stage.name + " (" + stale + ")" + beside);
  std::error_code ignored;
  fs::remove(StampPath(options_.run_dir, stage.name), ignored);
}

void WorkflowRun::Finish(const Stage& stage, const std::string& stale, int code, double seconds) {
  if (code != 0) {
    ThrowError("ibrdf run", "stage " + stage.name + " failed (exit " + std::to_string(code) +
                                (code > 128 ? ", killed by signal " + std::to_string(code - 128) : "") +
                                "); fix the cause and run again to resume from it");
  }
  StageOutcome& outcome = outcomes_[stage.name];
  outcome = {StageStatus::kRan, stale, seconds};
  WriteJsonFile(StampPath(options_.run_dir, stage.name),
                StampOf(stage, options_.build_id, options_.version, outcome.seconds).ToJson());
  Log(1, "-- run: " + stage.name + ": " + FormatSeconds(outcome.seconds));
}

void WorkflowRun::ExecuteTogether(std::vector<Stage> stages) {
  if (options_.dry_run) {
    for (Stage& stage : stages) Execute(std::move(stage));
    return;
  }
  // Decide every stage first, in order; the ones due are run below.
  struct Due {
    size_t index;  // in stages_
    std::string stale;
  };
  std::vector<Due> due;
  for (Stage& stage : stages) {
    const std::string stale = Decide(&stage);
    if (stale.empty()) continue;
    IBRDF_CHECK(stage.action) << "stage " << stage.name << " has no action";
    due.push_back({stages_.size() - 1, stale});
  }
  // Headings first (each says what runs beside it and where its output goes), then the actions.
  for (const Due& d : due) {
    const Stage& stage = stages_[d.index];
    std::string beside;
    for (const Due& other : due) {
      if (other.index != d.index) beside += (beside.empty() ? "" : ", ") + stages_[other.index].name;
    }
    if (!beside.empty()) {
      beside = "; beside " + beside;
      if (!stage.output_log.empty()) beside += ", its output shown when it ends";
    }
    Begin(stage, d.index + 1, d.stale, beside);
  }
  std::vector<int> codes(due.size(), 0);
  std::vector<double> seconds(due.size(), 0.0);
  std::vector<std::exception_ptr> errors(due.size());
  std::vector<std::thread> threads;
  for (size_t k = 0; k < due.size(); ++k) {
    threads.emplace_back([&, k] {
      Timer timer;
      try {
        codes[k] = stages_[due[k].index].action();
      } catch (...) {
        errors[k] = std::current_exception();
      }
      seconds[k] = timer.ElapsedSeconds();
    });
  }
  for (std::thread& thread : threads) thread.join();
  // In stage order: the captured output, then the outcome; the first failure is thrown last.
  std::exception_ptr first_error;
  for (size_t k = 0; k < due.size(); ++k) {
    const Stage& stage = stages_[due[k].index];
    if (!stage.output_log.empty()) {
      std::ifstream log(stage.output_log);
      std::string line;
      while (std::getline(log, line)) std::printf("%s\n", line.c_str());
      std::fflush(stdout);
    }
    try {
      if (errors[k]) std::rethrow_exception(errors[k]);
      Finish(stage, due[k].stale, codes[k], seconds[k]);
    } catch (...) {
      if (!first_error) first_error = std::current_exception();
    }
  }
  if (first_error) std::rethrow_exception(first_error);
}

}  // namespace ibrdf
