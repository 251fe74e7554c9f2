// The ibrdf tool as a user meets it: --help on every subcommand, the workflow end to end, and bad input
// answered with a clear message naming the file and field, a non-zero exit, and nothing written.
#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/image_io.h"
#include "tests/run_ibrdf.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

using testing::MaterialPath;
using testing::RunIbrdf;
using testing::RunResult;
using testing::ScratchDir;
namespace fs = std::filesystem;

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

void WriteJson(const std::string& path, const nlohmann::json& json) { std::ofstream(path) << json.dump(2); }

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    session_ = dir_ / "session";
    const RunResult synth = RunIbrdf("synth --out " + session_ + " --material " + MaterialPath("lambertian50") +
                                     " --photos 2 --width 96 --height 72");
    ASSERT_EQ(synth.exit_code, 0) << synth.output;
    manifest_ = session_ + "/session.json";
  }
  // Edits the manifest and returns its path.
  std::string Edit(const std::function<void(nlohmann::json&)>& edit) {
    nlohmann::json json = ReadJson(manifest_);
    edit(json);
    WriteJson(manifest_, json);
    return manifest_;
  }
  // A derender that must fail: non-zero exit, the message contains every `expected` piece, and no
  // output appears.
  void ExpectDerenderError(const std::vector<std::string>& expected) {
    const std::string out = dir_ / "samples.npy";
    const RunResult result = RunIbrdf("derender " + session_ + " --out " + out);
    EXPECT_NE(result.exit_code, 0);
    for (const std::string& piece : expected) {
      EXPECT_NE(result.output.find(piece), std::string::npos) << "missing \"" << piece << "\" in: " << result.output;
    }
    EXPECT_FALSE(fs::exists(out));
    EXPECT_FALSE(fs::exists(out + ".json"));
  }

  ScratchDir dir_;
  std::string session_, manifest_;
};

TEST(Cli, HelpOnEverySubcommand) {
  const RunResult top = RunIbrdf("--help");
  EXPECT_EQ(top.exit_code, 0);
  for (const std::string command : {"synth", "align", "derender", "check", "compare"}) {
    EXPECT_NE(top.output.find(command), std::string::npos) << command;
    const RunResult help = RunIbrdf(command + " --help");
    EXPECT_EQ(help.exit_code, 0) << command;
    EXPECT_NE(help.output.find("--out"), std::string::npos) << command << ": " << help.output;
  }
}

TEST(Cli, NoSubcommandOrUnknownOptionFails) {
  EXPECT_NE(RunIbrdf("").exit_code, 0);
  EXPECT_NE(RunIbrdf("derender --no-such-option x").exit_code, 0);
}

TEST_F(CliTest, WorkflowEndToEnd) {
  const std::string samples = dir_ / "samples.npy";
  RunResult result = RunIbrdf("derender " + session_ + " --out " + samples);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  ASSERT_TRUE(fs::exists(samples));
  const nlohmann::json sidecar = ReadJson(samples + ".json");
  EXPECT_GT(sidecar["counts"]["accepted"].get<int>(), 1000);
  result = RunIbrdf("check " + samples + " --out " + (dir_ / "check.json") + " --min-samples 10");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_TRUE(ReadJson(dir_ / "check.json").contains("reciprocity"));
  result = RunIbrdf("compare " + samples + " --out " + (dir_ / "compare.json"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const nlohmann::json compare = ReadJson(dir_ / "compare.json");
  EXPECT_GT(compare["overall"]["count"].get<int>(), 1000);
  EXPECT_LT(compare["overall"]["median_rel_error"][0].get<double>(), 0.05);
}

TEST_F(CliTest, UnknownKeyNamesTheField) {
  Edit([](nlohmann::json& j) { j["light"]["intensty"] = {1, 1, 1}; });
  ExpectDerenderError({manifest_, "/light/intensty", "unknown key"});
}

TEST_F(CliTest, UnknownRootKeyNamesTheField) {
  Edit([](nlohmann::json& j) { j["photoz"] = 1; });
  ExpectDerenderError({manifest_, "/photoz", "unknown key"});
}

TEST_F(CliTest, MissingPhotoNamesThePhoto) {
  fs::remove(session_ + "/photos/001.png");
  ExpectDerenderError({manifest_, "/photos/1/file", "001.png", "does not exist"});
}

TEST_F(CliTest, PhotoOfWrongSizeNamesThePhoto) {
  WriteImage(session_ + "/photos/000.png", Image(50, 40, 3), PixelFormat::kUint16);
  ExpectDerenderError({"000.png", "50x40", "96x72"});
}

// Real rigs (domes, turntables), bad input through the CLI: one clear error each, no output.
TEST_F(CliTest, PhotoNamingAnUnknownLightNamesPhotoAndLights) {
  Edit([](nlohmann::json& j) {
    j["lights"] = {j["light"], j["light"]};
    j["lights"][0]["id"] = "L01";
    j["lights"][1]["id"] = "L02";
    j.erase("light");
    j["photos"][0]["light"] = "L01";
    j["photos"][1]["light"] = "L07";
  });
  ExpectDerenderError({manifest_, "/photos/1/light", "\"L07\"", "L01, L02"});
}

TEST_F(CliTest, MaskOfTheWrongSizeNamesBothFiles) {
  WriteImage(session_ + "/mask.png", Image(50, 40, 1), PixelFormat::kUint8);
  Edit([](nlohmann::json& j) { j["mask"] = "mask.png"; });
  ExpectDerenderError({"mask.png", "000.png", "50x40", "96x72"});
}

TEST_F(CliTest, LightWithoutIntensityAndNoCalibrationNamesTheLight) {
  Edit([](nlohmann::json& j) { j["light"].erase("intensity"); });
  ExpectDerenderError({manifest_, "/light", "has no intensity and no calibration measures it"});
}

TEST_F(CliTest, NegativeExposureNamesTheField) {
  Edit([](nlohmann::json& j) { j["photos"][0]["exposure_s"] = -0.01; });
  ExpectDerenderError({manifest_, "/photos/0/exposure_s", "positive"});
}

TEST_F(CliTest, WrongTypeNamesTheField) {
  Edit([](nlohmann::json& j) { j["sample"]["radius"] = "four centimetres"; });
  ExpectDerenderError({manifest_, "/sample/radius", "expected a number", "string"});
}

TEST_F(CliTest, NaNInTheManifestIsAnError) {
  // JSON has no NaN literal; a manifest that spells one is not JSON, and the line is named.
  std::string text;
  {
    std::ifstream in(manifest_);
    std::stringstream buffer;
    buffer << in.rdbuf();
    text = buffer.str();
  }
  const size_t at = text.find("\"radius\": ");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, text.find(',', at) - at, "\"radius\": NaN");
  std::ofstream(manifest_) << text;
  ExpectDerenderError({manifest_ + ":", "invalid JSON"});
}

TEST_F(CliTest, WrongPathIsOneClearLine) {
  const RunResult result = RunIbrdf("derender " + (dir_ / "nowhere") + " --out " + (dir_ / "x.npy"));
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("nowhere"), std::string::npos);
  EXPECT_EQ(std::count(result.output.begin(), result.output.end(), '\n'), 1) << result.output;
}

TEST_F(CliTest, NeverOverwritesInputsOrExistingOutputs) {
  // The manifest as the output: refused, and the manifest is untouched.
  const std::string before = ReadJson(manifest_).dump();
  RunResult result = RunIbrdf("derender " + session_ + " --out " + manifest_ + " --overwrite");
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("input"), std::string::npos) << result.output;
  EXPECT_EQ(ReadJson(manifest_).dump(), before);
  // An existing output needs --overwrite.
  const std::string samples = dir_ / "samples.npy";
  ASSERT_EQ(RunIbrdf("derender " + session_ + " --out " + samples).exit_code, 0);
  result = RunIbrdf("derender " + session_ + " --out " + samples);
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("--overwrite"), std::string::npos) << result.output;
  EXPECT_EQ(RunIbrdf("derender " + session_ + " --out " + samples + " --overwrite").exit_code, 0);
  // synth into an existing folder.
  result = RunIbrdf("synth --out " + session_ + " --material " + MaterialPath("lambertian50"));
  EXPECT_NE(result.exit_code, 0);
  EXPECT_TRUE(fs::exists(manifest_));
}

TEST(Cli, AlignWritesAnAlignedSessionThatDerenders) {
  ScratchDir dir;
  const std::string session = dir / "targets";
  RunResult result =
      RunIbrdf("synth --out " + session + " --material " + MaterialPath("lambertian50") + " --targets --photos 3");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  result = RunIbrdf("align " + session + " --out " + (dir / "aligned"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const nlohmann::json report = ReadJson(dir / "aligned/alignment.json");
  EXPECT_EQ(report["images"].size(), 6u);  // 3 measurement photos and 3 of the light's markers
  EXPECT_LT(report["rms_px"].get<double>(), 0.5);
  result = RunIbrdf("derender " + (dir / "aligned") + " --out " + (dir / "samples.npy"));
  EXPECT_EQ(result.exit_code, 0) << result.output;
  // Aligning into the input folder is refused.
  result = RunIbrdf("align " + session + " --out " + session + " --overwrite");
  EXPECT_NE(result.exit_code, 0);
  EXPECT_TRUE(fs::exists(session + "/session.json"));
}

TEST_F(CliTest, AlignWithoutTargetsNamesTheMissingBlock) {
  const RunResult result = RunIbrdf("align " + session_ + " --out " + (dir_ / "aligned"));
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("/targets"), std::string::npos) << result.output;
  EXPECT_FALSE(fs::exists(dir_ / "aligned"));
}

TEST_F(CliTest, CorruptSampleFileIsAnError) {
  const std::string bad = dir_ / "bad.npy";
  std::ofstream(bad) << "not a numpy file";
  const RunResult result = RunIbrdf("check " + bad + " --out " + (dir_ / "check.json"));
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("bad.npy"), std::string::npos) << result.output;
  EXPECT_FALSE(fs::exists(dir_ / "check.json"));
}

TEST_F(CliTest, CompareWithoutTruthSaysSo) {
  const std::string samples = dir_ / "samples.npy";
  ASSERT_EQ(RunIbrdf("derender " + session_ + " --out " + samples).exit_code, 0);
  fs::remove(session_ + "/truth.json");
  const RunResult result = RunIbrdf("compare " + samples);
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("truth.json"), std::string::npos) << result.output;
}

// `ibrdf reconstruct`: a bad --bandwidth is a clear message naming the flag and the value, a non-zero
// exit and nothing written; bad --bandwidth-scales too.
TEST_F(CliTest, ReconstructUnknownBandwidthCriterionIsAClearError) {
  const std::string samples = dir_ / "samples.npy", out = dir_ / "rec";
  ASSERT_EQ(RunIbrdf("derender " + session_ + " --out " + samples).exit_code, 0);
  const RunResult run = RunIbrdf("reconstruct " + samples + " --out " + out + " --bandwidth aic");
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.output.find("--bandwidth"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("aic"), std::string::npos) << run.output;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_NE(RunIbrdf("reconstruct " + samples + " --out " + out + " --bandwidth loo --bandwidth-scales 0,1").exit_code,
            0);
  EXPECT_FALSE(fs::exists(out));
}

// `ibrdf report` on a folder that is not a run folder: one line naming the missing samples.npy, exit 1.
// ChArUco photos with a colour chart and a white reference: all three write into OUT/calibration, and
// the board's files join the session's calibration photos there; `align --calibrate` on that folder
// uses the board photos and leaves the other two out.
TEST(Cli, SynthCharucoPhotosBesideTheChartAndTheWhiteReference) {
  ScratchDir dir;
  const RunResult synth = RunIbrdf("synth --out " + dir / "s" + " --material " + MaterialPath("bluepaint") +
                                   " --photos 4 --targets --light-photos 0 --colour-chart --light-unknown"
                                   " --charuco-photos 12");
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const Session session = Session::Load(dir / "s");
  ASSERT_TRUE(session.colour_chart);
  ASSERT_TRUE(session.calibration && session.calibration->white_reference);
  EXPECT_TRUE(fs::is_regular_file(fs::path(session.directory) / session.colour_chart->photos[0].file));
  EXPECT_TRUE(fs::is_regular_file(fs::path(session.directory) / session.calibration->white_reference->photos[0].file));
  for (const char* file : {"board.json", "truth.json", "charuco-000.png", "charuco-011.png"}) {
    EXPECT_TRUE(fs::is_regular_file(dir / "s/calibration/" + file)) << file;
  }
  EXPECT_FALSE(fs::exists(dir / "s/.calibration-charuco"));
  const RunResult align =
      RunIbrdf("align " + dir / "s" + " --calibrate " + dir / "s/calibration" + " --out " + dir / "aligned");
  ASSERT_EQ(align.exit_code, 0) << align.output;
  const nlohmann::json calibration = ReadJson(dir / "aligned/alignment.json")["intrinsic_calibration"];
  EXPECT_EQ(calibration["views_used"].get<int>(), 12);
  EXPECT_LT(calibration["rms_px"].get<double>(), 0.2);
  EXPECT_EQ(calibration["views"].size(), 14u);  // the chart and the white reference, left out
}

// A session folder given to `ibrdf library` (no run done): refused, naming it and the remedy.
TEST_F(CliTest, LibraryOfASessionFolderSaysToRunItFirst) {
  const RunResult library = RunIbrdf("library " + session_ + " --out " + dir_ / "library");
  EXPECT_EQ(library.exit_code, 1) << library.output;
  EXPECT_NE(library.output.find(session_ + ": is a session folder"), std::string::npos) << library.output;
  EXPECT_NE(library.output.find("ibrdf run"), std::string::npos) << library.output;
  EXPECT_FALSE(fs::exists(dir_ / "library"));
}

TEST(Cli, ReportOnAFolderWithoutSamplesIsOneClearLine) {
  ScratchDir dir;
  const RunResult result = RunIbrdf("report " + dir.str());
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("ibrdf: error: " + dir / "samples.npy"), std::string::npos) << result.output;
  EXPECT_EQ(std::count(result.output.begin(), result.output.end(), '\n'), 1) << result.output;
}

}  // namespace
}  // namespace ibrdf
