// `ibrdf run` on a camera whose response nobody stated: a synthetic session with a film-like
// toe-and-shoulder curve (synth --response toe-shoulder --response-unknown, brackets of 5 exposures
// 1.5 EV apart, a white reference per light) is measured by the run's own response stage; the white
// reference and the photos are then read through the curve it measured, and the samples come out
// close to those of the same scene shot by a linear camera.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/run_ibrdf.h"
#include "tests/scratch_dir.h"
#include "tests/test_util.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

using testing::RunIbrdf;

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

std::string SynthArgs(const std::string& out, const std::string& response) {
  return "synth --out " + out + " --material " + testing::MaterialPath("bluepaint") +
         " --photos 8 --width 320 --height 240 --brackets 5 --bracket-step-ev 1.5 --light-unknown " + response;
}

// The samples' median relative error against the truth (compare's figure), averaged over the channels.
double MedianError(const std::string& run) {
  const nlohmann::json median = ReadJson(run + "/truth-comparison.json").at("overall").at("median_rel_error");
  return (median.at(0).get<double>() + median.at(1).get<double>() + median.at(2).get<double>()) / 3;
}

TEST(ResponseCliTest, RunMeasuresAnUnknownResponseAndItsSamplesMatchALinearCamera) {
  testing::ScratchDir scratch;
  ASSERT_EQ(RunIbrdf(SynthArgs(scratch / "linear", "")).exit_code, 0);
  ASSERT_EQ(RunIbrdf(SynthArgs(scratch / "curve", "--response toe-shoulder --response-unknown")).exit_code, 0);

  const auto linear = RunIbrdf("run " + scratch / "linear" + " --out " + scratch / "run-linear --stop-after compare");
  ASSERT_EQ(linear.exit_code, 0) << linear.output;
  const nlohmann::json linear_summary = ReadJson(scratch / "run-linear/summary.json");
  EXPECT_EQ(linear_summary.at("stages").count("response"), 0u) << "a stated response needs no response stage";

  const auto curve = RunIbrdf("run " + scratch / "curve" + " --out " + scratch / "run-curve --stop-after compare");
  ASSERT_EQ(curve.exit_code, 0) << curve.output;
  const nlohmann::json summary = ReadJson(scratch / "run-curve/summary.json");
  EXPECT_EQ(summary.at("stages").at("response").at("status"), "ran");
  ASSERT_TRUE(fs::exists(scratch / "run-curve/response/response.json"));
  const nlohmann::json derender_sidecar = ReadJson(scratch / "run-curve/samples.npy.json");
  EXPECT_NE(derender_sidecar.dump().find("response"), std::string::npos) << "the derendered session names its curve";

  // The measured curve's shape error (1.5-3 % over mid-tones, tests/calibrate/response_calibration_test.cc)
  // reaches the samples: measured 1.8x the linear camera's median error (docs/benchmarks.md), against
  // a goal of 1.2x that the curve does not meet; this guards the measured figure.
  const double linear_error = MedianError(scratch / "run-linear"), curve_error = MedianError(scratch / "run-curve");
  std::printf("median error against the truth: linear camera %.3f %%, measured response %.3f %% (%.2fx)\n",
              100 * linear_error, 100 * curve_error, curve_error / linear_error);
  EXPECT_LT(curve_error, 2.3 * linear_error);

  // Run again: up to date, nothing re-runs (the response stage's stamp holds).
  const auto again = RunIbrdf("run " + scratch / "curve" + " --out " + scratch / "run-curve --stop-after compare");
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_EQ(ReadJson(scratch / "run-curve/summary.json").at("stages").at("response").at("status"), "skipped");
}

// A failed verdict stops the run at the response stage with its remedy; an accepted one is recorded.
TEST(ResponseCliTest, NarrowBracketsStopTheRunUnlessAccepted) {
  testing::ScratchDir scratch;
  ASSERT_EQ(RunIbrdf("synth --out " + scratch / "s" + " --material " + testing::MaterialPath("bluepaint") +
                     " --photos 4 --width 240 --height 180 --brackets 3 --bracket-step-ev 0.5"
                     " --response toe-shoulder --response-unknown")
                .exit_code,
            0);
  const auto refused = RunIbrdf("run " + scratch / "s" + " --out " + scratch / "r --stop-after derender");
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_NE(refused.output.find("response.span"), std::string::npos) << refused.output;
  EXPECT_FALSE(fs::exists(scratch / "r/samples.npy"));

  const auto accepted = RunIbrdf("run " + scratch / "s" + " --out " + scratch / "r --stop-after derender" +
                                 " --response-args \"--accept all\"");
  ASSERT_EQ(accepted.exit_code, 0) << accepted.output;
  const nlohmann::json response = ReadJson(scratch / "r/response/response.json");
  EXPECT_NE(response.dump().find("\"accepted\":true"), std::string::npos);
}

}  // namespace
}  // namespace ibrdf
