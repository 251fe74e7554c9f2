// The batch config (workflow/batch_config.h): globs, names, options and the errors that name the
// field; RunArguments; and the plan's dry run over a run folder's stamps (workflow/batch_plan.h).
#include "workflow/batch_config.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "tests/error_of.h"
#include "tests/scratch_dir.h"
#include "workflow/batch_plan.h"
#include "workflow/workflow_run.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

using testing::ScratchDir;

void Write(const std::string& path, const std::string& text) {
  fs::create_directories(fs::path(path).parent_path());
  std::ofstream(path) << text;
}

// Folders that look like sessions and recipes (their contents are not read by the config).
void MakeInputs(const ScratchDir& dir) {
  Write(dir / "sessions/b-sphere/session.json", "{}");
  Write(dir / "sessions/a-cylinder/session.json", "{}");
  Write(dir / "sessions/notes/readme.txt", "not a session");
  Write(dir / "recipes/felt/recipe.json", "{}");
}

TEST(BatchConfig, GlobsExpandSortedToSessionFoldersAndNamesComeFromFolders) {
  ScratchDir dir;
  MakeInputs(dir);
  Write(dir / "batch.json", R"({"format": "ibrdf-batch", "version": 1, "out": "out",
      "sessions": ["sessions/*", {"path": "recipes/felt/recipe.json", "name": "felt-hat",
                                  "options": {"stride": 3}}],
      "options": {"stride": 2, "fits": false}, "threads_per_job": 2})");
  const BatchConfig config = ReadBatchConfig(dir / "batch.json");
  ASSERT_EQ(config.entries.size(), 3u);
  EXPECT_EQ(config.entries[0].name, "a-cylinder");
  EXPECT_EQ(config.entries[1].name, "b-sphere");
  EXPECT_EQ(config.entries[2].name, "felt-hat");
  EXPECT_EQ(config.out_dir, fs::path(dir / "out").string());
  EXPECT_EQ(config.entries[0].run_dir, dir / "out/runs/a-cylinder");
  EXPECT_EQ(config.entries[0].log_path, dir / "out/logs/a-cylinder.log");
  EXPECT_EQ(config.entries[0].options.pixel_stride, 2);
  EXPECT_EQ(config.entries[2].options.pixel_stride, 3);
  EXPECT_FALSE(config.entries[2].options.fits);
  EXPECT_EQ(config.threads_per_job, 2);
  EXPECT_EQ(RunArguments(config.entries[2]),
            (std::vector<std::string>{"run", dir / "recipes/felt/recipe.json", "--out", dir / "out/runs/felt-hat",
                                      "--stride", "3", "--no-fits"}));
}

// The stages' arguments of `ibrdf run` (--align-args, ...) from the options block; an entry's own
// replace the batch's, and RunArguments passes each as one string.
TEST(BatchConfig, StageArgumentsPassThroughToRun) {
  ScratchDir dir;
  MakeInputs(dir);
  Write(dir / "batch.json", R"({"format": "ibrdf-batch", "version": 1, "out": "out",
      "sessions": ["sessions/a-cylinder", {"path": "sessions/b-sphere", "options": {"align_args": "--no-light"}}],
      "options": {"align_args": "--max-rms-px 2  --no-cylinder", "colour_args": "--detect"}})");
  const BatchConfig config = ReadBatchConfig(dir / "batch.json");
  ASSERT_EQ(config.entries.size(), 2u);
  EXPECT_EQ(config.entries[0].options.align_args, (std::vector<std::string>{"--max-rms-px", "2", "--no-cylinder"}));
  EXPECT_EQ(config.entries[1].options.align_args, (std::vector<std::string>{"--no-light"}));
  EXPECT_EQ(config.entries[1].options.colour_args, (std::vector<std::string>{"--detect"}));
  EXPECT_EQ(RunArguments(config.entries[0]),
            (std::vector<std::string>{"run", dir / "sessions/a-cylinder", "--out", dir / "out/runs/a-cylinder",
                                      "--align-args", "--max-rms-px 2 --no-cylinder", "--colour-args", "--detect"}));
  Write(dir / "bad.json", R"({"format": "ibrdf-batch", "version": 1, "out": "out", "sessions": ["sessions/*"],
      "options": {"align_args": ["--no-light"]}})");
  const std::string message = testing::ErrorOf([&] { ReadBatchConfig(dir / "bad.json"); });
  EXPECT_NE(message.find("/options/align_args"), std::string::npos) << message;
}

TEST(BatchConfig, ErrorsNameTheFileAndTheField) {
  ScratchDir dir;
  MakeInputs(dir);
  auto error = [&](const std::string& text) {
    Write(dir / "batch.json", text);
    return testing::ErrorOf([&] { ReadBatchConfig(dir / "batch.json"); });
  };
  const std::string head = R"({"format": "ibrdf-batch", "version": 1, "out": "out", )";
  EXPECT_NE(error(head + R"("sessions": ["nothing*"]})").find("/sessions/0: the pattern \"" + dir / "nothing*"),
            std::string::npos);
  EXPECT_NE(error(head + R"("sessions": ["missing"]})").find("/sessions/0: \"missing\""), std::string::npos);
  EXPECT_NE(error(head + R"("sessions": ["sessions/notes"]})").find("neither a session"), std::string::npos);
  EXPECT_NE(error(head + R"("sessions": ["sessions/*", "sessions/a-cylinder"]})")
                .find("/sessions/1: a second session named \"a-cylinder\""),
            std::string::npos);
  EXPECT_NE(error(head + R"("sessions": [{"path": "recipes/felt", "name": "a b"}]})").find("the name \"a b\""),
            std::string::npos);
  EXPECT_NE(error(head + R"("sessions": ["recipes/felt"], "option": {}})").find("option"), std::string::npos);
  EXPECT_NE(error(head + R"("sessions": ["recipes/felt"], "options": {"stride": 0}})").find("--stride"),
            std::string::npos);
  EXPECT_NE(error(head + R"("sessions": []})").find("/sessions"), std::string::npos);
  EXPECT_NE(error(R"({"format": "ibrdf-run", "version": 1, "out": "o", "sessions": ["recipes/felt"]})").find("/format"),
            std::string::npos);
}

// The dry run of the engine decides without touching anything: the first stale stage stops the plan.
TEST(BatchPlan, DryRunCreatesNothingAndNamesTheFirstStageThatWouldRun) {
  ScratchDir dir;
  WorkflowOptions options{dir / "run", "build-1", "ibrdf test", false, ""};
  options.dry_run = true;
  WorkflowRun run(options);
  EXPECT_FALSE(fs::exists(dir / "run"));
  Stage stage;
  stage.name = "first";
  stage.outputs = {dir / "run/out.txt"};
  stage.action = [] {
    ADD_FAILURE() << "a dry run ran a stage";
    return 1;
  };
  run.Execute(stage);
  EXPECT_EQ(run.would_run(), "first (no record of a completed run)");
  EXPECT_TRUE(run.stopped());
  stage.name = "second";
  run.Execute(stage);
  EXPECT_EQ(run.would_run(), "first (no record of a completed run)");
  EXPECT_FALSE(fs::exists(dir / "run"));
}

TEST(BatchPlan, ASessionThatCannotBeOpenedIsPendingWithItsError) {
  ScratchDir dir;
  Write(dir / "bad/session.json", "{\"format\": 3}");
  Write(dir / "batch.json", R"({"format": "ibrdf-batch", "version": 1, "out": "out", "sessions": ["bad"]})");
  const std::vector<BatchEntryPlan> plan = PlanBatch(ReadBatchConfig(dir / "batch.json"), "build-1");
  ASSERT_EQ(plan.size(), 1u);
  EXPECT_NE(plan[0].pending.find("cannot plan: "), std::string::npos) << plan[0].pending;
  EXPECT_NE(plan[0].pending.find("session.json"), std::string::npos) << plan[0].pending;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

}  // namespace
}  // namespace ibrdf
