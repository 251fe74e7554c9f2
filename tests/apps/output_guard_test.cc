// The output guard of every subcommand: `--out` aimed at one of the command's inputs, or at
// a folder holding one, is refused even with --overwrite, with a one-line message naming the output,
// and the input is left byte for byte as it was. Each case was a data-destroying run before (exit 0).
#include <algorithm>
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
  void ExpectRefused(const std::string& arguments) {
    SCOPED_TRACE(arguments);
    const RunResult result = RunIbrdf(arguments);
    EXPECT_NE(result.exit_code, 0) << result.output;
    EXPECT_TRUE(result.output.find("an input of this stage") != std::string::npos) << result.output;
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

TEST_F(OutputGuardTest, Run) {
  ExpectRefused("run " + session_ + " --out " + session_);
  ExpectRefused("run " + session_ + " --out " + dir_.str());
  ExpectRefused("run " + session_ + "/session.json --out " + session_);
}

}  // namespace
}  // namespace ibrdf
