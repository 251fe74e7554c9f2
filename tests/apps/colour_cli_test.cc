// `ibrdf colour` as a user runs it: a synthetic session with a chart photo (`ibrdf synth --colour-chart`)
// is fitted by its corner patches and, without them, by OpenCV's mcc detector; derender applies the
// matrix and says so in the sidecar; bad input is a clear error with nothing written.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/json_reader.h"
#include "tests/run_ibrdf.h"
#include "tests/scratch_dir.h"
#include "tests/test_util.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

using testing::RunIbrdf;

std::string SynthArgs(const std::string& out) {
  return "synth --out " + out + " --material " + testing::MaterialPath("bluepaint") +
         " --photos 2 --width 400 --height 300 --light-intensity 1 0.8 0.55"
         " --camera-matrix 0.6 0.3 0.1 0.1 0.75 0.15 0.05 0.2 0.75 --colour-chart";
}

TEST(ColourCliTest, FitsByCornersAndByDetectionThenDerenderApplies) {
  testing::ScratchDir scratch;
  ASSERT_EQ(RunIbrdf(SynthArgs(scratch / "s")).exit_code, 0);
  const auto fitted = RunIbrdf("colour " + scratch / "s" + " --out " + scratch / "c", true);
  ASSERT_EQ(fitted.exit_code, 0) << fitted.output;
  EXPECT_NE(fitted.output.find("24 used"), std::string::npos) << fitted.output;
  const nlohmann::json colour = ReadJsonFile(scratch / "c/colour.json");
  EXPECT_LT(colour.at("rms_residual").get<double>(), 0.01);
  EXPECT_TRUE(fs::exists(scratch / "c/chart.png"));

  // The session as given has corners; a copy without them makes `ibrdf colour` detect the chart.
  nlohmann::json manifest = ReadJsonFile(scratch / "s/session.json");
  manifest["colour_chart"].erase("corners");
  std::ofstream(scratch / "s/detect.json") << manifest.dump(2);
  const auto detected = RunIbrdf("colour " + scratch / "s/detect.json" + " --out " + scratch / "d", true);
  ASSERT_EQ(detected.exit_code, 0) << detected.output;
  EXPECT_NE(detected.output.find("OpenCV mcc"), std::string::npos) << detected.output;
  const nlohmann::json by_mcc = ReadJsonFile(scratch / "d/colour.json");
  EXPECT_LT(by_mcc.at("rms_residual").get<double>(), 0.01);
  // Each patch within a quarter pitch of the corner-point fit's (the read-out square is half a pitch).
  const double pitch =
      (colour["patches"][1]["center_px"][0].get<double>() - colour["patches"][0]["center_px"][0].get<double>());
  for (int k = 0; k < 24; ++k) {
    const double dx =
        by_mcc["patches"][k]["center_px"][0].get<double>() - colour["patches"][k]["center_px"][0].get<double>();
    const double dy =
        by_mcc["patches"][k]["center_px"][1].get<double>() - colour["patches"][k]["center_px"][1].get<double>();
    EXPECT_LT(std::hypot(dx, dy), 0.25 * pitch) << "patch " << k + 1;
  }

  ASSERT_EQ(RunIbrdf("derender " + scratch / "c" + " --out " + scratch / "samples.npy").exit_code, 0);
  const nlohmann::json sidecar = ReadJsonFile(scratch / "samples.npy.json");
  EXPECT_NE(sidecar.at("colour_space").get<std::string>().find("linear sRGB"), std::string::npos);
  EXPECT_EQ(sidecar.at("colour").at("patches").size(), 24u);
  EXPECT_EQ(sidecar.at("colour").at("applied").size(), 1u);
}

// A dim gold paint seen by a camera whose channels mix strongly: the chart's matrix has large negative
// terms and takes the noisy blue (and some green) below zero. Those channels are unmeasured and counted
// in the sidecar and the summary line; `ibrdf check` reads every sample (it refused a negative one).
TEST(ColourCliTest, NegativeCorrectedChannelsAreUnmeasuredAndCheckReadsTheFile) {
  testing::ScratchDir scratch;
  const auto synth = RunIbrdf("synth --out " + scratch / "s" + " --material " + testing::MaterialPath("gold-paint") +
                              " --photos 2 --width 400 --height 300 --light-intensity 1 0.8 0.55"
                              " --camera-matrix 0.45 0.4 0.15 0.3 0.5 0.2 0.15 0.35 0.5 --colour-chart");
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  ASSERT_EQ(RunIbrdf("colour " + scratch / "s" + " --out " + scratch / "c").exit_code, 0);
  const auto derender = RunIbrdf("derender " + scratch / "c" + " --out " + scratch / "samples.npy", true);
  ASSERT_EQ(derender.exit_code, 0) << derender.output;
  EXPECT_NE(derender.output.find("negative after the colour correction"), std::string::npos) << derender.output;
  const nlohmann::json counts = ReadJsonFile(scratch / "samples.npy.json").at("counts");
  EXPECT_GT(counts.at("colour_negative")[2].get<uint64_t>(), 1000u) << counts.dump();
  EXPECT_TRUE(counts.at("rejected").contains("colour_unmeasured"));
  const auto check = RunIbrdf("check " + scratch / "samples.npy" + " --out " + scratch / "check");
  EXPECT_EQ(check.exit_code, 0) << check.output;
}

TEST(ColourCliTest, BadInputIsAClearErrorAndWritesNothing) {
  testing::ScratchDir scratch;
  ASSERT_EQ(RunIbrdf(SynthArgs(scratch / "s")).exit_code, 0);
  // Derendering before the fit.
  const auto early = RunIbrdf("derender " + scratch / "s" + " --out " + scratch / "x.npy");
  EXPECT_NE(early.exit_code, 0);
  EXPECT_NE(early.output.find("ibrdf colour"), std::string::npos) << early.output;
  EXPECT_FALSE(fs::exists(scratch / "x.npy"));
  // A corner outside the photo.
  nlohmann::json manifest = ReadJsonFile(scratch / "s/session.json");
  manifest["colour_chart"]["corners"][2] = {900.0, 100.0};
  std::ofstream(scratch / "s/bad.json") << manifest.dump(2);
  const auto outside = RunIbrdf("colour " + scratch / "s/bad.json" + " --out " + scratch / "c");
  EXPECT_NE(outside.exit_code, 0);
  EXPECT_NE(outside.output.find("/colour_chart/corners/2"), std::string::npos) << outside.output;
  EXPECT_FALSE(fs::exists(scratch / "c"));
  // No chart at all.
  manifest.erase("colour_chart");
  std::ofstream(scratch / "s/none.json") << manifest.dump(2);
  const auto none = RunIbrdf("colour " + scratch / "s/none.json" + " --out " + scratch / "c");
  EXPECT_NE(none.exit_code, 0);
  EXPECT_NE(none.output.find("no colour_chart"), std::string::npos) << none.output;
}

}  // namespace
}  // namespace ibrdf
