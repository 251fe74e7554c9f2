// Tests of workflow/workflow_run.h and stamp.h with fake stages (plain functions, no child processes):
// a stage is skipped when up to date and re-run, with the reason, when an input, its options or the
// binary's build id change, or after an interruption (outputs missing, a temporary left behind).
#include "workflow/workflow_run.h"

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/logging.h"
#include "tests/scratch_dir.h"
#include "workflow/stamp.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

using testing::ScratchDir;

void WriteText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

// A fake stage that copies its input to its output (prefixed with its option), counting its runs.
class FakeStages : public ::testing::Test {
 protected:
  void SetUp() override {
    SetVerbosity(0);
    WriteText(Input(), "photons");
  }
  std::string Input() const { return dir_ / "input.txt"; }
  std::string RunDir() const { return dir_ / "run"; }
  std::string Output() const { return dir_ / "run/output.txt"; }

  WorkflowOptions Options(const std::string& build_id = "build-1") const {
    WorkflowOptions options;
    options.run_dir = RunDir();
    options.build_id = build_id;
    options.version = "ibrdf test";
    return options;
  }
  Stage Copy(const std::string& option = "--gain 1") {
    Stage stage{"copy", {"copy", option}, {Input()}, {Output()}, "", nullptr, ""};
    stage.action = [this, option] {
      ++runs_;
      std::ifstream in(Input());
      std::string text;
      std::getline(in, text);
      WriteText(Output(), option + " " + text);
      return 0;
    };
    return stage;
  }
  // Runs the copy stage in a fresh invocation (a new WorkflowRun, as a new `ibrdf run` would).
  StageOutcome RunCopy(const std::string& option = "--gain 1", const std::string& build_id = "build-1") {
    WorkflowRun run(Options(build_id));
    return run.Execute(Copy(option));
  }

  ScratchDir dir_;
  int runs_ = 0;
};

TEST_F(FakeStages, RunsOnceThenSkipsWhenUpToDate) {
  const StageOutcome first = RunCopy();
  EXPECT_EQ(first.status, StageStatus::kRan);
  EXPECT_EQ(first.reason, "no record of a completed run");
  EXPECT_TRUE(fs::exists(StampPath(RunDir(), "copy")));
  const StageOutcome second = RunCopy();
  EXPECT_EQ(second.status, StageStatus::kSkipped);
  EXPECT_EQ(second.reason, "up to date");
  EXPECT_EQ(second.seconds, first.seconds);  // the recorded time of the run that made the outputs
  EXPECT_EQ(runs_, 1);
  EXPECT_STREQ(StageStatusName(second.status), "skipped");
}

TEST_F(FakeStages, RerunsWhenAnInputChanges) {
  RunCopy();
  WriteText(Input(), "more photons");  // another size
  EXPECT_EQ(RunCopy().reason, "an input changed");
  // Same bytes, a new modification time.
  fs::last_write_time(Input(), fs::last_write_time(Input()) - std::chrono::seconds(5));
  EXPECT_EQ(RunCopy().reason, "an input changed");
  EXPECT_EQ(runs_, 3);
  EXPECT_EQ(RunCopy().status, StageStatus::kSkipped);
}

TEST_F(FakeStages, RerunsWhenItsOptionsChange) {
  RunCopy("--gain 1");
  const StageOutcome changed = RunCopy("--gain 2");
  EXPECT_EQ(changed.status, StageStatus::kRan);
  EXPECT_EQ(changed.reason, "options changed");
  EXPECT_EQ(RunCopy("--gain 2").status, StageStatus::kSkipped);
}

TEST_F(FakeStages, RerunsWhenTheBuildIdChanges) {
  RunCopy("--gain 1", "build-1");
  const StageOutcome rebuilt = RunCopy("--gain 1", "build-2");
  EXPECT_EQ(rebuilt.status, StageStatus::kRan);
  EXPECT_EQ(rebuilt.reason, "the ibrdf binary changed");
  EXPECT_EQ(Stamp::Read(StampPath(RunDir(), "copy")).build_id, "build-2");
  EXPECT_EQ(RunCopy("--gain 1", "build-2").status, StageStatus::kSkipped);
}

TEST_F(FakeStages, RerunsWhenAnOutputIsMissingOrOlderThanAnInput) {
  RunCopy();
  fs::remove(Output());
  EXPECT_EQ(RunCopy().reason, Output() + " is missing");
  // An output older than an input whose fingerprint was recorded as it is now (e.g. restored).
  fs::last_write_time(Output(), fs::last_write_time(Input()) - std::chrono::seconds(10));
  EXPECT_EQ(RunCopy().reason, Output() + " is older than an input");
}

// An interrupted stage (killed: exit 137) leaves no stamp and a temporary of its dead writer; the next
// invocation removes the temporary and runs the stage again from its start.
TEST_F(FakeStages, ResumesAfterAnInterruptedStage) {
  RunCopy();
  {
    WorkflowRun run(Options());
    Stage killed = Copy("--gain 3");
    killed.action = [this] {
      WriteText(RunDir() + "/.output.txt.tmp-999999999-0", "half");
      return 137;
    };
    try {
      run.Execute(killed);
      ADD_FAILURE() << "expected an Error";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("stage copy failed (exit 137, killed by signal 9); fix the cause"),
                std::string::npos)
          << e.what();
    }
  }
  EXPECT_FALSE(fs::exists(StampPath(RunDir(), "copy")));
  EXPECT_TRUE(fs::exists(RunDir() + "/.output.txt.tmp-999999999-0"));
  // A temporary of a live writer (this process) is kept.
  const std::string live = RunDir() + "/.other.tmp-" + std::to_string(::getpid()) + "-0";
  WriteText(live, "busy");
  const StageOutcome resumed = RunCopy("--gain 3");
  EXPECT_EQ(resumed.status, StageStatus::kRan);
  EXPECT_EQ(resumed.reason, "no record of a completed run");
  EXPECT_FALSE(fs::exists(RunDir() + "/.output.txt.tmp-999999999-0"));
  EXPECT_TRUE(fs::exists(live));
}

// A stamp of an older ibrdf (keyed on the version string, no build id) counts as another binary's.
TEST_F(FakeStages, StampWithoutBuildIdCountsAsAnotherBinary) {
  RunCopy();
  nlohmann::json stamp = Stamp::Read(StampPath(RunDir(), "copy")).ToJson();
  stamp.erase("build_id");
  WriteText(StampPath(RunDir(), "copy"), stamp.dump());
  EXPECT_EQ(RunCopy().reason, "the ibrdf binary changed");
}

TEST_F(FakeStages, UnreadableStampRerunsTheStage) {
  RunCopy();
  WriteText(StampPath(RunDir(), "copy"), R"({"stage": "copy", "args": ["copy"]})");  // no build_id
  EXPECT_EQ(RunCopy().reason, "its record is unreadable");
}

TEST_F(FakeStages, ForceNotApplicableAndStopAfter) {
  RunCopy();
  WorkflowOptions options = Options();
  options.force = true;
  options.stop_after = "copy";
  WorkflowRun run(options);
  Stage skipped = Copy();
  skipped.name = "inapplicable";
  skipped.not_applicable = "no scans";
  EXPECT_EQ(run.Execute(skipped).status, StageStatus::kNotApplicable);
  EXPECT_FALSE(run.stopped());
  EXPECT_EQ(run.Execute(Copy()).reason, "--force");
  EXPECT_TRUE(run.stopped());
  Stage later = Copy();
  later.name = "later";
  const StageOutcome after = run.Execute(later);
  EXPECT_EQ(after.status, StageStatus::kNotApplicable);
  EXPECT_EQ(after.reason, "--stop-after copy");
  EXPECT_EQ(runs_, 2);
  ASSERT_EQ(run.stages().size(), 3u);
  EXPECT_EQ(run.outcome("inapplicable").reason, "no scans");
}

// The stamp records the build id, the options and the inputs' fingerprints, and reads back.
TEST_F(FakeStages, StampRoundTrips) {
  const StageOutcome outcome = RunCopy();
  const Stamp stamp = Stamp::Read(StampPath(RunDir(), "copy"));
  EXPECT_EQ(stamp.stage, "copy");
  EXPECT_EQ(stamp.build_id, "build-1");
  EXPECT_EQ(stamp.version, "ibrdf test");
  EXPECT_EQ(stamp.arguments, (std::vector<std::string>{"copy", "--gain 1"}));
  ASSERT_EQ(stamp.inputs.size(), 1u);
  EXPECT_EQ(stamp.inputs[0], Fingerprint(Input()));
  EXPECT_EQ(stamp.inputs[0].size, 7);
  EXPECT_EQ(stamp.outputs, (std::vector<std::string>{Output()}));
  EXPECT_EQ(stamp.seconds, outcome.seconds);
  EXPECT_EQ(Fingerprint(dir_ / "absent").size, -1);
}

// Stages run together (the sample stages of `ibrdf run`): each waits until the other has started, so
// they pass only when they really run at the same time; they are recorded in the order given, stamped,
// and skipped together when up to date; a failed one is reported after the other ended and stamped.
TEST_F(FakeStages, ExecuteTogetherRunsStagesAtTheSameTime) {
  std::atomic<int> started{0};
  auto waiting_stage = [&](const std::string& name, int code) {
    Stage stage{name, {name}, {Input()}, {dir_ / ("run/" + name + ".txt")}, "", nullptr, ""};
    stage.action = [&started, code, output = stage.outputs[0]] {
      ++started;
      for (int i = 0; i < 10000 && started < 2; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
      if (started < 2) return 99;  // ran alone
      WriteText(output, "done");
      return code;
    };
    return stage;
  };
  {
    WorkflowRun run(Options());
    run.ExecuteTogether({waiting_stage("a", 0), waiting_stage("b", 0)});
    ASSERT_EQ(run.stages().size(), 2u);
    EXPECT_EQ(run.stages()[0].name, "a");
    EXPECT_EQ(run.outcome("a").status, StageStatus::kRan);
    EXPECT_EQ(run.outcome("b").status, StageStatus::kRan);
  }
  {
    started = 0;
    WorkflowRun run(Options());
    run.ExecuteTogether({waiting_stage("a", 0), waiting_stage("b", 0)});
    EXPECT_EQ(run.outcome("a").status, StageStatus::kSkipped);
    EXPECT_EQ(run.outcome("b").status, StageStatus::kSkipped);
  }
  {
    started = 0;
    WorkflowOptions options = Options();
    options.force = true;
    WorkflowRun run(options);
    EXPECT_THROW(run.ExecuteTogether({waiting_stage("a", 3), waiting_stage("b", 0)}), Error);
    EXPECT_FALSE(fs::exists(StampPath(RunDir(), "a")));
    EXPECT_TRUE(fs::exists(StampPath(RunDir(), "b")));  // it succeeded beside the failure
  }
  {
    // --stop-after inside the group: the later stage does not apply.
    WorkflowOptions options = Options();
    options.force = true;
    options.stop_after = "copy";
    WorkflowRun run(options);
    run.ExecuteTogether({Copy(), waiting_stage("b", 0)});
    EXPECT_EQ(run.outcome("copy").status, StageStatus::kRan);
    EXPECT_EQ(run.outcome("b").status, StageStatus::kNotApplicable);
  }
}

TEST(WorkflowOptions, RunDirAndBuildIdAreRequired) {
  std::string why;
  EXPECT_FALSE(WorkflowOptions().Check(&why));
  EXPECT_FALSE(why.empty());
  WorkflowOptions options;
  options.run_dir = "run";
  options.build_id = "x";
  EXPECT_TRUE(options.Check(&why)) << why;
}

}  // namespace
}  // namespace ibrdf
