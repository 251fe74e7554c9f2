// The output guard of every subcommand: `--out` aimed at one of the command's inputs, or at
// a folder holding one, is refused even with --overwrite, with a one-line message naming the output,
// and the input is left byte for byte as it was. Each case was a data-destroying run before (exit 0).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/sample_file.h"
#include "tests/run_ibrdf.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

using testing::MaterialPath;
using testing::RunIbrdf;
using testing::RunResult;
using testing::ScratchDir;
namespace fs = std::filesystem;

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

class OutputGuardTest : public ::testing::Test {
 protected:
  void SetUp() override {
    session_ = dir_ / "session";
    const RunResult synth = RunIbrdf("synth --out " + session_ + " --material " + MaterialPath("lambertian50") +
                                     " --photos 2 --width 48 --height 36 --effects none");
    ASSERT_EQ(synth.exit_code, 0) << synth.output;
    fs::create_directories(dir_ / "work");
    samples_ = dir_ / "work/samples.npy";
    BrdfSample s{};
    s.wi[2] = s.wo[2] = 1.0f;
    s.brdf[0] = s.brdf[1] = s.brdf[2] = 0.1f;
    WriteSamples(samples_, std::vector<BrdfSample>(8, s));
    std::ofstream(SidecarPath(samples_)) << "{\"session\": \"" << session_ << "/session.json\"}\n";
    fs::create_directories(dir_ / "mat");
    material_ = dir_ / "mat/material.json";
    fs::copy_file(MaterialPath("lambertian50"), material_);
    fs::create_directories(dir_ / "scan");
    ply_ = dir_ / "scan/a.ply";
    std::ofstream(ply_) << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                           "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                           "0 0 0\n0.01 0 0\n0 0.01 0\n3 0 1 2\n";
    fs::create_directories(dir_ / "eval");
    eval_ = dir_ / "eval/points.npy";
    fs::create_directories(dir_ / "run");
    fs::copy_file(samples_, dir_ / "run/samples.npy");
    std::ofstream(dir_ / "run/consistency.json") << "{}\n";
    for (const std::string& path : {session_ + "/session.json", session_ + "/truth.json", samples_,
                                    SidecarPath(samples_), material_, ply_, dir_ / "run/samples.npy"}) {
      before_.emplace_back(path, ReadBytes(path));
    }
  }

  // Runs `arguments`, which aim --out at an input; expects a refusal naming the output and every
  // input unchanged.
  void ExpectRefused(const std::string& arguments, const std::string& why = "an input of this stage") {
    SCOPED_TRACE(arguments);
    const RunResult result = RunIbrdf(arguments);
    EXPECT_NE(result.exit_code, 0) << result.output;
    EXPECT_TRUE(result.output.find(why) != std::string::npos) << result.output;
    EXPECT_LE(std::count(result.output.begin(), result.output.end(), '\n'), 1) << "one line: " << result.output;
    for (const auto& [path, bytes] : before_) {
      ASSERT_TRUE(fs::exists(path)) << path << " was destroyed";
      EXPECT_EQ(ReadBytes(path), bytes) << path << " was changed";
    }
  }

  ScratchDir dir_;
  std::string session_, samples_, material_, ply_, eval_;
  std::vector<std::pair<std::string, std::string>> before_;
};

TEST_F(OutputGuardTest, Synth) {
  ExpectRefused("synth --material " + material_ + " --out " + dir_ / "mat" + " --overwrite");
  ExpectRefused("synth --material " + material_ + " --out " + material_ + " --overwrite");
  ExpectRefused("synth --material " + material_ + " --out " + dir_.str() + " --overwrite");
}

TEST_F(OutputGuardTest, Scan) {
  ExpectRefused("scan " + ply_ + " --out " + ply_ + " --overwrite");
  ExpectRefused("scan " + ply_ + " --out " + dir_ / "scan" + " --overwrite");
}

TEST_F(OutputGuardTest, Align) {
  ExpectRefused("align " + session_ + " --out " + dir_.str() + " --overwrite");
  ExpectRefused("align " + session_ + " --out " + session_ + " --overwrite");
  ExpectRefused("align " + session_ + "/session.json --out " + session_ + "/ --overwrite");
}

TEST_F(OutputGuardTest, Derender) {
  ExpectRefused("derender " + session_ + " --out " + session_ + "/session.json --overwrite");
  ExpectRefused("derender " + session_ + " --out " + session_ + " --overwrite");
  // The sidecar <out>.json must not land on the manifest either.
  ExpectRefused("derender " + session_ + " --out " + session_ + "/session --overwrite");
}

// The sidecar <out>.json is a file the user did not name: with --out SESSION/truth it would fall on
// the session's truth.json, which no --overwrite may replace.
TEST_F(OutputGuardTest, DerenderSidecarOnTheSessionsTruthFile) {
  ExpectRefused("derender " + session_ + " --out " + session_ + "/truth --overwrite", "not a file this stage wrote");
  ExpectRefused("derender " + session_ + " --out " + material_.substr(0, material_.size() - 5) + " --overwrite",
                "not a file this stage wrote");
  // Its own earlier sidecar is replaced.
  const std::string out = dir_ / "work/derendered.npy";
  ASSERT_EQ(RunIbrdf("derender " + session_ + " --out " + out).exit_code, 0);
  const RunResult again = RunIbrdf("derender " + session_ + " --out " + out + " --overwrite");
  EXPECT_EQ(again.exit_code, 0) << again.output;
}

// `scan X --out mat` writes mat and mat.json: beside a material file mat.json, refused.
TEST_F(OutputGuardTest, ScanSidecarOnAnUnrelatedFile) {
  const std::string material_stem = material_.substr(0, material_.size() - 5);
  ExpectRefused("scan " + ply_ + " --out " + material_stem + " --overwrite", "not a file this stage wrote");
  // Its own earlier sidecar is replaced (a patch of 8 x 8 points: enough for the scan to run).
  const std::string patch = dir_ / "scan/patch.ply";
  {
    std::ofstream ply(patch);
    ply << "ply\nformat ascii 1.0\nelement vertex 64\nproperty float x\nproperty float y\nproperty float z\n"
           "element face 98\nproperty list uchar int vertex_indices\nend_header\n";
    for (int i = 0; i < 8; ++i) {
      for (int j = 0; j < 8; ++j) ply << 0.01 * i << " " << 0.01 * j << " " << 0.001 * std::sin(i + j) << "\n";
    }
    for (int i = 0; i < 7; ++i) {
      for (int j = 0; j < 7; ++j) {
        const int a = i * 8 + j;
        ply << "3 " << a << " " << a + 1 << " " << a + 8 << "\n3 " << a + 1 << " " << a + 9 << " " << a + 8 << "\n";
      }
    }
  }
  const std::string out = dir_ / "scan/clean.ply";
  const RunResult first = RunIbrdf("scan " + patch + " --out " + out);
  ASSERT_EQ(first.exit_code, 0) << first.output;
  const RunResult again = RunIbrdf("scan " + patch + " --out " + out + " --overwrite");
  EXPECT_EQ(again.exit_code, 0) << again.output;
}

// An input named like a temporary of the output would be removed as a leftover of an interrupted write.
TEST_F(OutputGuardTest, InputNamedLikeATemporaryOfTheOutput) {
  const std::string hidden = dir_ / "work/.checked.tmp-999999-0.npy";
  fs::copy_file(samples_, hidden);
  fs::copy_file(SidecarPath(samples_), SidecarPath(hidden));
  before_.emplace_back(SidecarPath(hidden), ReadBytes(SidecarPath(hidden)));
  ExpectRefused("check " + hidden + " --out " + dir_ / "work/checked.json --overwrite",
                "named like a temporary of this output");
}

// lights calibrate: --out and its report beside it on a placement's photo, and --write-session (a whole
// folder, replaced) on the session it applies the lights to.
TEST_F(OutputGuardTest, LightsCalibrate) {
  const std::string mirror = dir_ / "mirror";
  const RunResult synth = RunIbrdf("lights synth --out " + mirror + " --lights 4");
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  std::string photo;
  for (const auto& entry : fs::recursive_directory_iterator(mirror)) {
    if (entry.is_regular_file() && entry.path().filename() != "session.json") photo = entry.path().string();
  }
  ASSERT_FALSE(photo.empty());
  before_.emplace_back(photo, ReadBytes(photo));
  before_.emplace_back(mirror + "/session.json", ReadBytes(mirror + "/session.json"));
  ExpectRefused("lights calibrate " + mirror + " --out " + photo + " --overwrite");
  const std::string lights = dir_ / "work/lights.json";
  ExpectRefused("lights calibrate " + mirror + " --out " + lights + " --apply-to " + session_ + " --write-session " +
                session_ + " --overwrite");
  ExpectRefused("lights calibrate " + mirror + " --out " + lights + " --apply-to " + session_ + " --write-session " +
                dir_.str() + " --overwrite");
  EXPECT_FALSE(fs::exists(lights));
}

// lights white: the session's folder (or one holding it) is no place for the calibrated session.
TEST_F(OutputGuardTest, LightsWhite) {
  ExpectRefused("lights white " + session_ + " --out " + session_ + " --overwrite");
  ExpectRefused("lights white " + session_ + " --out " + dir_.str() + " --overwrite");
}

// session init writes OUT/session.json (or OUT/session.draft.json) beside the photos when OUT is their
// folder, but never onto an input: here the camera file is that session.json.
TEST_F(OutputGuardTest, SessionInit) {
  std::string photo;
  for (const auto& entry : fs::recursive_directory_iterator(session_)) {
    if (entry.path().extension() == ".exr") photo = entry.path().string();
  }
  ASSERT_FALSE(photo.empty());
  before_.emplace_back(photo, ReadBytes(photo));
  ExpectRefused("session init " + photo + " --camera " + session_ + "/session.json --out " + session_ + " --overwrite");
  ExpectRefused("session init " + photo + " --out " + photo + " --overwrite", "is a file");
}

// targets and lights synth read nothing: their one rule is that an existing output is replaced only
// with --overwrite (and then by their own whole folder).
TEST_F(OutputGuardTest, TargetsAndLightsSynthReadNoInputs) {
  for (const std::string command : {"targets --no-charuco --dpi 72", "lights synth --lights 2"}) {
    const std::string out = dir_ / ("made-by-" + command.substr(0, command.find(' ')));
    ASSERT_EQ(RunIbrdf(command + " --out " + out).exit_code, 0) << command;
    const std::string marker = out + "/mine.txt";
    std::ofstream(marker) << "kept\n";
    before_.emplace_back(marker, ReadBytes(marker));
    ExpectRefused(command + " --out " + out, "already exists");
    before_.pop_back();
    const RunResult again = RunIbrdf(command + " --out " + out + " --overwrite");
    EXPECT_EQ(again.exit_code, 0) << again.output;
    EXPECT_FALSE(fs::exists(marker)) << "--overwrite replaces the folder whole";
  }
}

// batch writes OUT/runs/NAME, OUT/logs/NAME.log and OUT/library: a session inside any of them is
// refused before any job runs.
TEST_F(OutputGuardTest, Batch) {
  const fs::path batch = dir_ / "batch";
  for (const char* inside : {"library/s1", "runs/s1"}) {
    SCOPED_TRACE(inside);
    fs::remove_all(batch);
    fs::create_directories(batch / inside);
    fs::copy(session_, batch / inside, fs::copy_options::recursive);
    const std::string copy = ReadBytes((batch / inside / "session.json").string());
    std::ofstream(batch / "batch.json") << "{\"format\": \"ibrdf-batch\", \"version\": 1, \"out\": \".\", "
                                           "\"sessions\": [{\"path\": \"" << inside << "\", \"name\": \"s1\"}]}\n";
    ExpectRefused("batch " + (batch / "batch.json").string(), "an input of this stage");
    EXPECT_EQ(ReadBytes((batch / inside / "session.json").string()), copy);
  }
}

TEST_F(OutputGuardTest, Reconstruct) {
  ExpectRefused("reconstruct " + samples_ + " --out " + dir_ / "work" + " --overwrite");
  ExpectRefused("reconstruct " + samples_ + " --out " + samples_ + " --overwrite");
  ExpectRefused("reconstruct " + samples_ + " --truth " + session_ + "/truth.json --out " + session_ + " --overwrite");
  std::ofstream(eval_) << "x";
  ExpectRefused("reconstruct " + samples_ + " --eval " + eval_ + " --out " + eval_ + " --overwrite");
  ExpectRefused("reconstruct " + samples_ + " --eval " + eval_ + " --out " + dir_ / "eval" + " --overwrite");
}

TEST_F(OutputGuardTest, Check) {
  ExpectRefused("check " + samples_ + " --out " + SidecarPath(samples_) + " --overwrite");
  ExpectRefused("check " + samples_ + " --out " + samples_ + " --overwrite");
  // Not vacuous: the same command with a free output runs.
  const RunResult ok = RunIbrdf("check " + samples_ + " --out " + dir_ / "check.json");
  EXPECT_EQ(ok.exit_code, 0) << ok.output;
}

TEST_F(OutputGuardTest, Compare) {
  const std::string truth = session_ + "/truth.json";
  ExpectRefused("compare " + samples_ + " --truth " + truth + " --out " + truth + " --overwrite");
  ExpectRefused("compare " + samples_ + " --truth " + truth + " --out " + SidecarPath(samples_) + " --overwrite");
  ExpectRefused("compare " + samples_ + " --out " + SidecarPath(samples_) + " --overwrite");
  const RunResult ok = RunIbrdf("compare " + samples_ + " --truth " + truth + " --out " + dir_ / "compare.json");
  EXPECT_EQ(ok.exit_code, 0) << ok.output;
}

TEST_F(OutputGuardTest, Report) {
  ExpectRefused("report " + dir_ / "run" + " --out " + dir_ / "run" + " --overwrite");
  ExpectRefused("report " + dir_ / "run" + " --out " + dir_.str() + " --overwrite");
  ExpectRefused("report " + dir_ / "run" + " --out " + dir_ / "run/samples.npy --overwrite");
}

TEST_F(OutputGuardTest, Colour) {
  const std::string chart = dir_ / "chart";
  const RunResult synth = RunIbrdf("synth --out " + chart + " --material " + MaterialPath("lambertian50") +
                                   " --photos 2 --width 64 --height 48 --colour-chart");
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const std::string manifest = ReadBytes(chart + "/session.json");
  ExpectRefused("colour " + chart + " --out " + chart + " --overwrite");
  ExpectRefused("colour " + chart + " --out " + dir_.str() + " --overwrite");
  EXPECT_EQ(ReadBytes(chart + "/session.json"), manifest);
}

TEST_F(OutputGuardTest, Library) {
  ExpectRefused("library " + dir_ / "run" + " --out " + dir_ / "run" + " --overwrite", "contain one another");
  ExpectRefused("library " + dir_ / "run" + " --out " + dir_.str() + " --overwrite", "contain one another");
}

TEST_F(OutputGuardTest, Run) {
  ExpectRefused("run " + session_ + " --out " + session_);
  ExpectRefused("run " + session_ + " --out " + dir_.str());
  ExpectRefused("run " + session_ + "/session.json --out " + session_);
}

}  // namespace
}  // namespace ibrdf
