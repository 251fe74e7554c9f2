// `ibrdf session init --chart-photos` as a user runs it: a synthetic capture with a
// colour-chart photo (`ibrdf synth --colour-chart`), drafted from the photos' EXIF with the chart's
// photo and corner patches; the drafted session carries the colour_chart block with the chart photo's
// EXIF exposure, and `ibrdf colour` fits its matrix from it. Without corners the block is drafted for
// detection; corners without chart photos, or a missing chart photo, are errors. Triples take commas
// (R,G,B) or words, a board.json given as the targets is refused at once, and photos without EXIF
// exposure take --exposure-s.
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include "core/image_io.h"
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

// A small photo, with EXIF (exposure, ISO, focal length) or without any.
std::string Photo(const testing::ScratchDir& dir, const std::string& name, bool exif) {
  Image image(40, 30, 3);
  for (float& v : image.pixels) v = 0.25f;
  PhotoMetadata m;
  m.exposure_s = 0.02;
  m.iso = 100;
  m.focal_length_mm = 9.0;
  m.pixels_per_mm = 1.0 / 0.0045;
  WriteImage(dir / name, image, PixelFormat::kUint16, exif ? &m : nullptr);
  return dir / name;
}

// `ibrdf targets`' folder: targets.json and the ChArUco board's board.json.
std::string TargetsFolder(const testing::ScratchDir& dir) {
  const auto targets = RunIbrdf("targets --out " + dir / "targets" + " --dpi 72");
  EXPECT_EQ(targets.exit_code, 0) << targets.output;
  return dir / "targets";
}

// The missing list suggests `--light-intensity R,G,B`: the comma form is accepted for every triple, as
// are separate words.
TEST(SessionCommand, TriplesTakeCommasOrWords) {
  testing::ScratchDir dir;
  const std::string photos = " " + Photo(dir, "a.png", true) + " " + Photo(dir, "b.png", true);
  const std::string targets = TargetsFolder(dir) + "/targets.json";
  const auto init = RunIbrdf("session init" + photos + " --out " + dir / "comma" + " --targets " + targets +
                                 " --light-intensity 1,0.9,0.8 --light-position-m 1.2,0,0.5 --sample-radius-m 0.02"
                                 " --sample-center-m 0,0,0.02 --white-reflectance 0.9,0.9,0.9",
                             true);
  ASSERT_EQ(init.exit_code, 0) << init.output;
  const Session session = Session::Load(dir / "comma");
  EXPECT_EQ(session.lights[0].intensity, Eigen::Vector3d(1.0, 0.9, 0.8));
  EXPECT_EQ(session.lights[0].position, Eigen::Vector3d(1.2, 0.0, 0.5));
  EXPECT_EQ(session.sample.center, Eigen::Vector3d(0.0, 0.0, 0.02));
  const auto words = RunIbrdf("session init" + photos + " --out " + dir / "words" + " --targets " + targets +
                              " --light-intensity 1 0.9 0.8 --light-position-m 1.2 0 0.5 --sample-radius-m 0.02");
  ASSERT_EQ(words.exit_code, 0) << words.output;
  EXPECT_EQ(Session::Load(dir / "words").lights[0].intensity, Eigen::Vector3d(1.0, 0.9, 0.8));
  const auto two = RunIbrdf("session init" + photos + " --out " + dir / "two" + " --light-intensity 1,0.9");
  EXPECT_NE(two.exit_code, 0) << two.output;
  EXPECT_NE(two.output.find("--light-intensity"), std::string::npos) << two.output;
}

// board.json (from `ibrdf targets`, for `align --calibrate`) given as --targets: refused at once with
// the file, what it is and what to pass; nothing written.
TEST(SessionCommand, BoardFileIsNoTargetsFile) {
  testing::ScratchDir dir;
  const std::string board = TargetsFolder(dir) + "/board.json";
  const auto init = RunIbrdf("session init " + Photo(dir, "a.png", true) + " --out " + dir / "out" + " --targets " +
                             board + " --light-intensity 1,1,1 --light-position-m 1,0,0 --sample-radius-m 0.02");
  EXPECT_EQ(init.exit_code, 1) << init.output;
  EXPECT_NE(init.output.find(board), std::string::npos) << init.output;
  EXPECT_NE(init.output.find("ChArUco board"), std::string::npos) << init.output;
  EXPECT_NE(init.output.find("targets.json"), std::string::npos) << init.output;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

// Photos without EXIF: --exposure-s for all, or one per photo; said as assumed; bad values name the flag.
TEST(SessionCommand, ExposureTimesWithoutExif) {
  testing::ScratchDir dir;
  const std::string photos = " " + Photo(dir, "a.png", false) + " " + Photo(dir, "b.png", false);
  WriteJsonFile(dir / "camera.json", nlohmann::json{{"camera",
                                                     {{"model", "PINHOLE"},
                                                      {"width", 40},
                                                      {"height", 30},
                                                      {"params", {50.0, 50.0, 20.0, 15.0}}}}});
  const std::string scene = " --camera " + dir / "camera.json" + " --targets " + TargetsFolder(dir) +
                            "/targets.json --light-intensity 1,1,1 --light-position-m 1,0,0 --sample-radius-m 0.02";
  const auto none = RunIbrdf("session init" + photos + " --out " + dir / "none" + scene);
  EXPECT_EQ(none.exit_code, 1) << none.output;
  EXPECT_NE(none.output.find("--exposure-s"), std::string::npos) << none.output;

  const auto all = RunIbrdf("session init" + photos + " --out " + dir / "all" + scene + " --exposure-s 0.01", true);
  ASSERT_EQ(all.exit_code, 0) << all.output;
  EXPECT_NE(all.output.find("assumed: exposure time 0.01 s (--exposure-s, as given) for 2 photo(s)"), std::string::npos)
      << all.output;
  const Session session = Session::Load(dir / "all");
  EXPECT_EQ(session.photos[0].exposure_s, 0.01);
  EXPECT_EQ(session.photos[1].exposure_s, 0.01);

  const auto each = RunIbrdf("session init" + photos + " --out " + dir / "each" + scene + " --exposure-s 0.01,0.04");
  ASSERT_EQ(each.exit_code, 0) << each.output;
  const Session each_session = Session::Load(dir / "each");
  EXPECT_EQ(each_session.photos[1].exposure_s, 0.04);
  // Two stops apart and no capture time, but nothing says they share a pose: no bracket.
  EXPECT_FALSE(each_session.photos[0].bracket);
  EXPECT_FALSE(each_session.photos[1].bracket);

  for (const char* bad : {"0.01,0.02,0.03", "fast", "-1", "0.01,"}) {
    const auto r = RunIbrdf("session init" + photos + " --out " + dir / "bad" + scene + " --exposure-s " + bad);
    EXPECT_NE(r.exit_code, 0) << bad << ": " << r.output;
    EXPECT_NE(r.output.find("--exposure-s"), std::string::npos) << bad << ": " << r.output;
  }
  EXPECT_FALSE(fs::exists(dir / "bad/session.json"));
}

}  // namespace
}  // namespace ibrdf
