// `ibrdf session init --chart-photos` as a user runs it: a synthetic capture with a
// colour-chart photo (`ibrdf synth --colour-chart`), drafted from the photos' EXIF with the chart's
// photo and corner patches; the drafted session carries the colour_chart block with the chart photo's
// EXIF exposure, and `ibrdf colour` fits its matrix from it. Without corners the block is drafted for
// detection; corners without chart photos, or a missing chart photo, are errors.
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include "core/json_reader.h"
#include "core/session.h"
#include "tests/run_ibrdf.h"
#include "tests/scratch_dir.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;
using testing::RunIbrdf;

TEST(SessionCommand, ChartPhotosBecomeTheColourChartBlock) {
  testing::ScratchDir scratch;
  const auto synth = RunIbrdf("synth --out " + scratch / "s" + " --material " + testing::MaterialPath("bluepaint") +
                              " --photos 2 --width 400 --height 300 --light-intensity 1 0.8 0.55"
                              " --camera-matrix 0.6 0.3 0.1 0.1 0.75 0.15 0.05 0.2 0.75 --colour-chart");
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const Session truth = Session::Load(scratch / "s");
  ASSERT_TRUE(truth.colour_chart && truth.colour_chart->corners);
  const ColourChartSpec& chart = *truth.colour_chart;
  std::string photos, corners;
  for (size_t i = 0; i < truth.photos.size(); ++i) photos += " " + truth.PhotoPath(i);
  for (const Eigen::Vector2d& p : *chart.corners) corners += " " + std::to_string(p.x()) + " " + std::to_string(p.y());
  const std::string chart_photo = (fs::path(truth.directory) / chart.photos[0].file).string();
  // The markers' layout (the photos would be posed by `ibrdf align`; the chart photo needs no pose).
  ASSERT_EQ(RunIbrdf("targets --out " + scratch / "targets" + " --no-charuco --dpi 72").exit_code, 0);
  const std::string scene =
      " --light-position-m 1.2 0 0 --light-intensity 1 0.8 0.55 --sample-radius-m 0.04"
      " --sample-center-m 0 0 0 --camera " +
      scratch / "s/session.json" + " --targets " + scratch / "targets/targets.json";

  const auto init = RunIbrdf("session init" + photos + " --out " + scratch / "init" + scene + " --chart-photos " +
                                 chart_photo + " --chart-corners" + corners,
                             true);
  ASSERT_EQ(init.exit_code, 0) << init.output;
  EXPECT_NE(init.output.find("assumed: colour chart"), std::string::npos) << init.output;
  const Session session = Session::Load(scratch / "init");
  ASSERT_TRUE(session.colour_chart);
  EXPECT_EQ(session.photos.size(), truth.photos.size());  // the chart photo is no measurement photo
  ASSERT_EQ(session.colour_chart->photos.size(), 1u);
  EXPECT_NEAR(session.colour_chart->photos[0].exposure_s / chart.photos[0].exposure_s, 1.0, 1e-6);  // EXIF
  ASSERT_TRUE(session.colour_chart->corners);
  for (int k = 0; k < 4; ++k) EXPECT_LT(((*session.colour_chart->corners)[k] - (*chart.corners)[k]).norm(), 1e-5);
  EXPECT_EQ(session.colour_chart->space, ColourSpace::kLinearSrgb);
  const auto colour = RunIbrdf("colour " + scratch / "init" + " --out " + scratch / "c", true);
  ASSERT_EQ(colour.exit_code, 0) << colour.output;
  EXPECT_LT(ReadJsonFile(scratch / "c/colour.json").at("rms_residual").get<double>(), 0.01);

  // Without corners: the block for detection, said so.
  const auto detect = RunIbrdf(
      "session init" + photos + " --out " + scratch / "detect" + scene + " --chart-photos " + chart_photo, true);
  ASSERT_EQ(detect.exit_code, 0) << detect.output;
  EXPECT_NE(detect.output.find("OpenCV mcc"), std::string::npos) << detect.output;
  const nlohmann::json drafted = ReadJsonFile(scratch / "detect/session.json");
  EXPECT_FALSE(drafted["colour_chart"].contains("corners"));

  // Errors: corners without chart photos; a chart photo that does not exist; seven numbers.
  const auto no_photos =
      RunIbrdf("session init" + photos + " --out " + scratch / "bad" + scene + " --chart-corners" + corners);
  EXPECT_NE(no_photos.exit_code, 0);
  EXPECT_NE(no_photos.output.find("chart_corners"), std::string::npos) << no_photos.output;
  const auto missing = RunIbrdf("session init" + photos + " --out " + scratch / "bad" + scene + " --chart-photos " +
                                scratch / "nowhere.png");
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_NE(missing.output.find("nowhere.png"), std::string::npos) << missing.output;
  const auto seven = RunIbrdf("session init" + photos + " --out " + scratch / "bad" + scene + " --chart-photos " +
                              chart_photo + " --chart-corners 1 2 3 4 5 6 7");
  EXPECT_NE(seven.exit_code, 0) << seven.output;
  EXPECT_FALSE(fs::exists(scratch / "bad/session.json"));
}

}  // namespace
}  // namespace ibrdf
