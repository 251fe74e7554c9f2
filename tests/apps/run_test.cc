// `ibrdf run` end to end on a tiny synthetic sphere session: every stage, the summary's fields, the
// skip rule, re-running on changed options, and resuming after a derender killed mid-way.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/run_ibrdf.h"
#include "tests/scratch_dir.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

using testing::RunIbrdf;
using testing::RunResult;
using testing::ScratchDir;

const std::string kSynth = std::string("synth --material ") + IBRDF_SAMPLES_DIR +
                           "/materials/bluepaint.json --width 160 --height 120 --photos 6 --out ";

std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

nlohmann::json ReadJson(const std::string& path) { return nlohmann::json::parse(Slurp(path)); }

TEST(RunCommand, AllStagesWriteTheSummaryAndASecondRunSkipsEveryStage) {
  ScratchDir dir;
  ASSERT_EQ(RunIbrdf(kSynth + dir / "s").exit_code, 0);
  const RunResult first = RunIbrdf("run " + dir / "s" + " --out " + dir / "run" + " --no-fits", true);
  ASSERT_EQ(first.exit_code, 0) << first.output;
  const nlohmann::json summary = ReadJson(dir / "run/summary.json");

  for (const char* stage : {"derender", "check", "compare", "reconstruct", "report"}) {
    EXPECT_EQ(summary["stages"][stage]["status"], "ran") << stage;
    EXPECT_GT(summary["timings_s"][stage].get<double>(), 0.0) << stage;
  }
  // No scans and no targets: the session's poses are used as given.
  EXPECT_EQ(summary["stages"]["scan"]["status"], "not_applicable");
  EXPECT_EQ(summary["stages"]["align"]["status"], "not_applicable");
  // No white reference: no light stage in the plan at all.
  EXPECT_FALSE(summary["stages"].contains("lights"));

  const nlohmann::json& samples = summary["samples"];
  const uint64_t accepted = samples["accepted"];
  uint64_t rejected = 0;
  for (const auto& item : samples["rejected"].items()) rejected += item.value().get<uint64_t>();
  EXPECT_GT(accepted, 5000u);
  EXPECT_GT(samples["rejected"]["off_sample"].get<uint64_t>(), 0u);
  EXPECT_EQ(accepted + rejected, samples["pixels_examined"].get<uint64_t>());

  // Consistency of a reciprocal, isotropic BRDF measured with camera noise: small, not zero.
  const double reciprocity = summary["consistency"]["reciprocity"];
  const double bilateral = summary["consistency"]["bilateral_symmetry"];
  EXPECT_GT(reciprocity, 0.0);
  EXPECT_LT(reciprocity, 0.05);
  EXPECT_GT(bilateral, 0.0);
  EXPECT_LT(bilateral, 0.05);

  // Against the truth: the foundation bound on the samples (5 % median), and a finite reconstruction
  // error (6 photos leave most of the MERL grid to extrapolation, so its figure is loose).
  ASSERT_EQ(summary["truth"]["samples_median_rel_error"].size(), 3u);
  ASSERT_EQ(summary["truth"]["brdf_rel_rmse"].size(), 3u);
  for (int c = 0; c < 3; ++c) {
    const double median = summary["truth"]["samples_median_rel_error"][c];
    const double rmse = summary["truth"]["brdf_rel_rmse"][c];
    EXPECT_GT(median, 0.0);
    EXPECT_LT(median, 0.05);
    EXPECT_GT(rmse, 0.0);
    EXPECT_LT(rmse, 0.5);
  }
  EXPECT_TRUE(fs::exists(dir / "run/report/index.html"));
  EXPECT_TRUE(fs::exists(dir / "run/reconstruction/brdf.binary"));

  const auto samples_time = fs::last_write_time(dir / "run/samples.npy");
  const RunResult second = RunIbrdf("run " + dir / "s" + " --out " + dir / "run" + " --no-fits", true);
  ASSERT_EQ(second.exit_code, 0) << second.output;
  const nlohmann::json again = ReadJson(dir / "run/summary.json");
  for (const auto& stage : again["stages"].items()) {
    EXPECT_NE(stage.value()["status"], "ran") << stage.key() << " ran again:\n" << second.output;
  }
  EXPECT_EQ(fs::last_write_time(dir / "run/samples.npy"), samples_time);
  // Recorded timings survive a skipped stage.
  EXPECT_EQ(again["timings_s"]["derender"], summary["timings_s"]["derender"]);
}

// check and compare run beside reconstruct: their output is captured and printed after the three
// ended (DIR/logs/), the order and outputs are those of --sequential (the same bytes).
TEST(RunCommand, SampleStagesRunTogetherWithTheSequentialOutputs) {
  ScratchDir dir;
  ASSERT_EQ(RunIbrdf(kSynth + dir / "s").exit_code, 0);
  const RunResult together =
      RunIbrdf("run " + dir / "s" + " --out " + dir / "together" + " --no-fits --no-report", true);
  ASSERT_EQ(together.exit_code, 0) << together.output;
  EXPECT_NE(together.output.find("== run 5: check (no record of a completed run); beside compare, reconstruct"),
            std::string::npos)
      << together.output;
  EXPECT_TRUE(fs::exists(dir / "together/logs/check.log"));
  // check's own line is printed after reconstruct's, not interleaved with it.
  EXPECT_LT(together.output.find("-- reconstruct:"), together.output.find("\ncheck: "));
  EXPECT_NE(together.output.find("\ncheck: "), std::string::npos);
  const RunResult sequential =
      RunIbrdf("run " + dir / "s" + " --out " + dir / "sequential" + " --no-fits --no-report --sequential", true);
  ASSERT_EQ(sequential.exit_code, 0) << sequential.output;
  EXPECT_EQ(sequential.output.find("beside"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "sequential/logs"));
  EXPECT_EQ(Slurp(dir / "together/consistency.json"), Slurp(dir / "sequential/consistency.json"));
  EXPECT_EQ(Slurp(dir / "together/reconstruction/brdf.binary"), Slurp(dir / "sequential/reconstruction/brdf.binary"));
  const nlohmann::json a = ReadJson(dir / "together/truth-comparison.json");
  const nlohmann::json b = ReadJson(dir / "sequential/truth-comparison.json");
  EXPECT_EQ(a["overall"], b["overall"]);
  EXPECT_EQ(a["bands"], b["bands"]);
  const nlohmann::json summary = ReadJson(dir / "together/summary.json");
  for (const char* stage : {"check", "compare", "reconstruct"}) {
    EXPECT_EQ(summary["stages"][stage]["status"], "ran") << stage;
  }
}

TEST(RunCommand, ChangedOptionsOrInputsRerunTheStage) {
  ScratchDir dir;
  ASSERT_EQ(RunIbrdf(kSynth + dir / "s").exit_code, 0);
  const std::string run = "run " + dir / "s" + " --out " + dir / "run" + " --stop-after derender";
  ASSERT_EQ(RunIbrdf(run).exit_code, 0);
  const uint64_t full = ReadJson(dir / "run/summary.json")["samples"]["pixels_examined"];

  RunResult result = RunIbrdf(run + " --stride 2", true);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  nlohmann::json summary = ReadJson(dir / "run/summary.json");
  EXPECT_EQ(summary["stages"]["derender"]["status"], "ran");
  EXPECT_EQ(summary["stages"]["derender"]["reason"], "options changed");
  EXPECT_LT(summary["samples"]["pixels_examined"].get<uint64_t>(), full / 3);

  // A photo rewritten (same bytes, new time) re-runs derender; nothing after --stop-after runs.
  const std::string photo = dir / "s/photos/003.png";
  ASSERT_TRUE(fs::exists(photo));
  fs::last_write_time(photo, fs::file_time_type::clock::now());
  result = RunIbrdf(run + " --stride 2", true);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  summary = ReadJson(dir / "run/summary.json");
  EXPECT_EQ(summary["stages"]["derender"]["reason"], "an input changed");
  EXPECT_EQ(summary["stages"]["check"]["status"], "not_applicable");
  EXPECT_FALSE(fs::exists(dir / "run/consistency.json"));
}

TEST(RunCommand, ResumesAfterAnInterruptedDerenderWithIdenticalSamples) {
  ScratchDir dir;
  ASSERT_EQ(RunIbrdf(kSynth + dir / "s").exit_code, 0);
  ASSERT_EQ(RunIbrdf("run " + dir / "s" + " --out " + dir / "clean --stop-after derender").exit_code, 0);

  // The test hook kills derender's process with SIGKILL, as a power cut or `kill -9` would.
  ::setenv("IBRDF_RUN_INTERRUPT", "derender", 1);
  ::setenv("IBRDF_RUN_INTERRUPT_AFTER_S", "0", 1);
  const RunResult killed = RunIbrdf("run " + dir / "s" + " --out " + dir / "resumed --stop-after derender");
  ::unsetenv("IBRDF_RUN_INTERRUPT");
  ::unsetenv("IBRDF_RUN_INTERRUPT_AFTER_S");
  EXPECT_NE(killed.exit_code, 0);
  EXPECT_NE(killed.output.find("stage derender failed"), std::string::npos) << killed.output;
  EXPECT_FALSE(fs::exists(dir / "resumed/samples.npy"));
  EXPECT_FALSE(fs::exists(dir / "resumed/stamps/derender.json"));
  // What a writer killed mid-file leaves: a hidden temporary named after its (now dead) process.
  { std::ofstream(dir / "resumed/.samples.npy.tmp-999999999-0") << "partial"; }

  const RunResult resumed = RunIbrdf("run " + dir / "s" + " --out " + dir / "resumed --stop-after derender", true);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_FALSE(fs::exists(dir / "resumed/.samples.npy.tmp-999999999-0"));
  const std::string clean = Slurp(dir / "clean/samples.npy");
  ASSERT_GT(clean.size(), 1000u);
  EXPECT_TRUE(clean == Slurp(dir / "resumed/samples.npy")) << "resumed samples differ from an uninterrupted run's";
}

// A session whose light is measured by its white reference: the light stage (`ibrdf lights white`)
// runs before derender, which reads the session it writes.
TEST(RunCommand, WhiteReferenceSessionRunsTheLightStageBeforeDerender) {
  ScratchDir dir;
  ASSERT_EQ(RunIbrdf(kSynth + dir / "s" + " --light-unknown --light-intensity 0.7 0.9 1.2").exit_code, 0);
  const RunResult run = RunIbrdf("run " + dir / "s" + " --out " + dir / "run" + " --stop-after derender", true);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json summary = ReadJson(dir / "run/summary.json");
  EXPECT_EQ(summary["stages"]["lights"]["status"], "ran");
  EXPECT_EQ(summary["stages"]["derender"]["status"], "ran");
  const nlohmann::json calibrated = ReadJson(dir / "run/lights/session.json");
  EXPECT_FALSE(calibrated.contains("calibration"));
  const nlohmann::json light = calibrated.contains("light") ? calibrated["light"] : calibrated["lights"][0];
  ASSERT_TRUE(light.contains("intensity"));
  EXPECT_NEAR(light["intensity"][0].get<double>(), 0.7, 0.02);
  EXPECT_NEAR(light["intensity"][2].get<double>(), 1.2, 0.03);
  const std::string sidecar_session = ReadJson(dir / "run/samples.npy.json")["session"];
  EXPECT_TRUE(fs::equivalent(sidecar_session, dir / "run/lights/session.json")) << sidecar_session;
  EXPECT_TRUE(fs::exists(dir / "run/lights/white-reference.json"));
}

// A session `ibrdf align` wrote (stages_applied holds "align") is resumed, not aligned again: its name
// does not grow, and aligning it again by hand keeps the name; align's options pass through run.
TEST(RunCommand, AnAlignedSessionIsResumedNotAlignedAgain) {
  ScratchDir dir;
  ASSERT_EQ(RunIbrdf("synth --material " + std::string(IBRDF_SAMPLES_DIR) +
                     "/materials/bluepaint.json --targets --photos 3 --out " + dir / "s")
                .exit_code,
            0);
  RunResult result = RunIbrdf("align " + dir / "s" + " --out " + dir / "aligned");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const nlohmann::json aligned = ReadJson(dir / "aligned/session.json");
  const std::string name = aligned["name"];
  EXPECT_EQ(name, ReadJson(dir / "s/session.json")["name"].get<std::string>() + "-aligned");
  EXPECT_EQ(aligned["stages_applied"], nlohmann::json({"align"}));

  result = RunIbrdf("run " + dir / "aligned" + " --out " + dir / "run" + " --stop-after derender --stride 4", true);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const nlohmann::json summary = ReadJson(dir / "run/summary.json");
  EXPECT_EQ(summary["stages"]["align"]["status"], "not_applicable");
  EXPECT_NE(summary["stages"]["align"]["reason"].get<std::string>().find("aligned already"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "run/align"));
  EXPECT_EQ(ReadJson(dir / "run/samples.npy.json")["session_name"], name);

  result = RunIbrdf("align " + dir / "aligned" + " --out " + dir / "again");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(ReadJson(dir / "again/session.json")["name"], name);
  EXPECT_EQ(ReadJson(dir / "again/session.json")["stages_applied"], nlohmann::json({"align"}));

  // --align-args and --min-markers reach align: more markers than a photo shows drop every photo.
  for (const std::string flags : {" --align-args \"--min-markers 500\"", " --min-markers 500"}) {
    result = RunIbrdf("run " + dir / "s" + " --out " + dir / "run-markers" + " --stop-after align --overwrite" + flags);
    EXPECT_NE(result.exit_code, 0) << flags << ":\n" << result.output;
    EXPECT_NE(result.output.find("align"), std::string::npos) << result.output;
    EXPECT_FALSE(fs::exists(dir / "run-markers/align/session.json")) << flags;
  }
}

TEST(RunCommand, BadInputIsOneClearLine) {
  ScratchDir dir;
  RunResult result = RunIbrdf("run " + dir / "missing" + " --out " + dir / "run");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("ibrdf: error: " + dir / "missing" + ": does not exist"), std::string::npos)
      << result.output;
  EXPECT_EQ(std::count(result.output.begin(), result.output.end(), '\n'), 1) << result.output;

  ASSERT_EQ(RunIbrdf(kSynth + dir / "s").exit_code, 0);
  nlohmann::json manifest = ReadJson(dir / "s/session.json");
  manifest["light"]["intensty"] = 1.0;
  { std::ofstream(dir / "s/session.json") << manifest.dump(2); }
  result = RunIbrdf("run " + dir / "s" + " --out " + dir / "run");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("/light/intensty: unknown key"), std::string::npos) << result.output;
  EXPECT_EQ(std::count(result.output.begin(), result.output.end(), '\n'), 1) << result.output;
  EXPECT_FALSE(fs::exists(dir / "run/summary.json"));
}

}  // namespace
}  // namespace ibrdf
