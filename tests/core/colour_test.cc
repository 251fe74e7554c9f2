// Tests of core/colour.h (the ColorChecker's reference values in linear sRGB and XYZ) and of the
// session's colour_chart block (core/session.h): parsing, round trip, and bad blocks as Errors naming
// the manifest and the field.
#include "core/colour.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/image_io.h"
#include "core/session.h"
#include "tests/error_of.h"
#include "tests/scratch_dir.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

using nlohmann::json;

TEST(ColourTest, SpaceNamesRoundTrip) {
  for (ColourSpace space : {ColourSpace::kLinearSrgb, ColourSpace::kXyz}) {
    ColourSpace back = ColourSpace::kXyz == space ? ColourSpace::kLinearSrgb : ColourSpace::kXyz;
    ASSERT_TRUE(ColourSpaceFromName(ColourSpaceName(space), &back));
    EXPECT_EQ(back, space);
  }
  ColourSpace unused;
  EXPECT_FALSE(ColourSpaceFromName("srgb", &unused));
}

// Values computed independently (NumPy: CIELab D50 -> XYZ -> Bradford D65 -> IEC 61966-2-1 matrix).
TEST(ColourTest, ReferenceMatchesAnIndependentConversion) {
  const auto srgb = ColorCheckerReference(ColourSpace::kLinearSrgb);
  const struct {
    int patch;
    double r, g, b;
  } expected[] = {{0, 0.1737, 0.0788, 0.0528},  {17, -0.0439, 0.2337, 0.3772}, {18, 0.8797, 0.8849, 0.8342},
                  {23, 0.0314, 0.0315, 0.0323}, {15, 0.8418, 0.5743, 0.0046},  {6, 0.7460, 0.2021, 0.0298}};
  for (const auto& e : expected) {
    EXPECT_NEAR(srgb[e.patch].x(), e.r, 6e-4) << ColorCheckerPatchNames()[e.patch];
    EXPECT_NEAR(srgb[e.patch].y(), e.g, 6e-4) << ColorCheckerPatchNames()[e.patch];
    EXPECT_NEAR(srgb[e.patch].z(), e.b, 6e-4) << ColorCheckerPatchNames()[e.patch];
  }
  EXPECT_STREQ(ColorCheckerPatchNames()[17], "cyan");
  EXPECT_STREQ(ColorCheckerPatchNames()[18], "white 9.5");
}

TEST(ColourTest, XyzAndSrgbReferencesAgree) {
  const auto srgb = ColorCheckerReference(ColourSpace::kLinearSrgb);
  const auto xyz = ColorCheckerReference(ColourSpace::kXyz);
  for (int k = 0; k < kColorCheckerPatches; ++k) {
    EXPECT_LT((XyzFromLinearSrgb() * srgb[k] - xyz[k]).norm(), 1e-9) << k;
  }
  // The neutral patches 20-24 (|a*|, |b*| < 0.8) are grey in linear sRGB (D65) within 3 % (neutral 3.5 is
  // 2.5 % off: a small chroma at a low lightness); the white
  // patch (b* = 2.93) is slightly yellow: its blue 5 % below its red.
  for (int k = 19; k < 24; ++k) {
    EXPECT_LT((srgb[k].array() / srgb[k].mean() - 1.0).abs().maxCoeff(), 0.03) << ColorCheckerPatchNames()[k];
  }
  EXPECT_NEAR(srgb[18].z() / srgb[18].x(), 0.948, 0.002);
  // Linear sRGB white maps to D65's white point.
  EXPECT_NEAR((XyzFromLinearSrgb() * Eigen::Vector3d::Ones()).x(), 0.95047, 1e-4);
  EXPECT_NEAR((XyzFromLinearSrgb() * Eigen::Vector3d::Ones()).z(), 1.08883, 1e-4);
}

// A session folder with one photo and a chart photo.
class ColourChartBlockTest : public ::testing::Test {
 protected:
  void SetUp() override {
    fs::create_directories(fs::path(scratch_.str()) / "photos");
    Image photo(8, 6, 3);
    WriteImage(scratch_ / "photos/img0.png", photo, PixelFormat::kUint8);
    WriteImage(scratch_ / "photos/chart.png", photo, PixelFormat::kUint8);
  }
  json Manifest() const {
    return json::parse(R"({
      "format": "ibrdf-session", "version": 2,
      "camera": {"model": "PINHOLE", "width": 8, "height": 6, "params": [10, 10, 4, 3]},
      "light": {"kind": "point", "position": [1, 0, 0], "intensity": [1, 1, 1]},
      "sample": {"kind": "sphere", "center": [0, 0, 0], "radius": 0.05},
      "photos": [{"file": "photos/img0.png", "exposure_s": 0.5,
                  "camera_from_world": {"rotation": [1, 0, 0, 0], "translation": [0, 0, 1]}}],
      "colour_chart": {"photos": [{"file": "photos/chart.png", "exposure_s": 0.25}],
                       "corners": [[1, 1], [7, 1], [7, 5], [1, 5]]}
    })");
  }
  std::string Write(const json& manifest) const {
    std::ofstream(scratch_ / "session.json") << manifest.dump(2);
    return scratch_ / "session.json";
  }
  testing::ScratchDir scratch_;
};

TEST_F(ColourChartBlockTest, ParsesDefaultsAndRoundTrips) {
  json manifest = Manifest();
  const Session session = Session::Load(Write(manifest));
  ASSERT_TRUE(session.colour_chart.has_value());
  const ColourChartSpec& chart = *session.colour_chart;
  EXPECT_EQ(chart.chart, kColorCheckerClassic24);
  EXPECT_EQ(chart.space, ColourSpace::kLinearSrgb);
  ASSERT_EQ(chart.photos.size(), 1u);
  EXPECT_DOUBLE_EQ(chart.photos[0].exposure_s, 0.25);
  ASSERT_TRUE(chart.corners.has_value());
  EXPECT_EQ((*chart.corners)[2], Eigen::Vector2d(7, 5));
  EXPECT_FALSE(chart.matrix.has_value());
  // The chart's photo is an input of the session (for run's staleness).
  bool listed = false;
  for (const std::string& file : session.InputFiles()) listed |= fs::path(file).filename() == "chart.png";
  EXPECT_TRUE(listed);

  // With a matrix and a patch fit, the block round-trips through ToJson.
  manifest["colour_chart"]["space"] = "xyz";
  manifest["colour_chart"]["matrix"] = {{2, 0.1, 0}, {0, 3, 0}, {0, 0.2, 4}};
  manifest["colour_chart"]["patches"] = json::array();
  for (int k = 0; k < kColorCheckerPatches; ++k) {
    manifest["colour_chart"]["patches"].push_back(k == 5 ? json{{"name", "bluish green"}, {"excluded", "clipped"}}
                                                         : json{{"name", "p"}, {"residual", 0.001 * k}});
  }
  const Session fitted = Session::Load(Write(manifest));
  const json again = fitted.ToJson();
  const Session reread = Session::Load(Write(again));
  ASSERT_TRUE(reread.colour_chart->matrix.has_value());
  EXPECT_EQ(*reread.colour_chart->matrix, *fitted.colour_chart->matrix);
  EXPECT_EQ(reread.colour_chart->space, ColourSpace::kXyz);
  ASSERT_EQ(reread.colour_chart->patches.size(), 24u);
  EXPECT_EQ(reread.colour_chart->patches[5].excluded, "clipped");
  EXPECT_DOUBLE_EQ(reread.colour_chart->patches[7].residual, 0.007);
}

TEST_F(ColourChartBlockTest, BadBlocksNameTheField) {
  struct Case {
    const char* what;
    std::function<void(json&)> edit;
    const char* pointer;
  };
  const Case cases[] = {
      {"unknown chart", [](json& m) { m["colour_chart"]["chart"] = "spyder"; }, "/colour_chart/chart"},
      {"unknown space", [](json& m) { m["colour_chart"]["space"] = "srgb"; }, "/colour_chart/space"},
      {"no photos", [](json& m) { m["colour_chart"]["photos"] = json::array(); }, "/colour_chart/photos"},
      {"missing photo", [](json& m) { m["colour_chart"]["photos"][0]["file"] = "photos/none.png"; },
       "/colour_chart/photos/0/file"},
      {"three corners", [](json& m) { m["colour_chart"]["corners"].erase(3); }, "/colour_chart/corners"},
      {"singular matrix",
       [](json& m) {
         m["colour_chart"]["matrix"] = {{1, 2, 3}, {2, 4, 6}, {0, 0, 1}};
       },
       "/colour_chart/matrix"},
      {"patches without matrix", [](json& m) { m["colour_chart"]["patches"] = json::array(); },
       "/colour_chart/patches"},
      {"unknown key", [](json& m) { m["colour_chart"]["gamma"] = 2.2; }, "/colour_chart"},
  };
  for (const Case& c : cases) {
    json manifest = Manifest();
    c.edit(manifest);
    const std::string path = Write(manifest);
    const std::string message = testing::ErrorOf([&] { Session::Load(path); });
    EXPECT_NE(message.find(path), std::string::npos) << c.what << ": " << message;
    EXPECT_NE(message.find(c.pointer), std::string::npos) << c.what << ": " << message;
  }
}

TEST(ColourSpace, MatricesIntoAndOutOfLinearSrgb) {
  Eigen::Matrix3d m;
  m << 1, 2, 3, 4, 5, 6, 7, 8, 10;
  EXPECT_EQ(LinearSrgbFromSpace(ColourSpace::kLinearSrgb, m), m);
  EXPECT_EQ(SpaceFromLinearSrgb(ColourSpace::kLinearSrgb, m), m);
  EXPECT_EQ(LinearSrgbFromSpace(ColourSpace::kXyz, m), LinearSrgbFromXyz() * m);
  EXPECT_EQ(SpaceFromLinearSrgb(ColourSpace::kXyz, m), XyzFromLinearSrgb() * m);
  EXPECT_STREQ(ColourSpaceLabel(ColourSpace::kLinearSrgb), "linear sRGB (D65)");
  EXPECT_STREQ(ColourSpaceLabel(ColourSpace::kXyz), "CIE XYZ (D65)");
  EXPECT_THROW(ColourSpaceName(static_cast<ColourSpace>(99)), InternalError);
}

}  // namespace
}  // namespace ibrdf
