// Tests of align/targets.h: the layout is the synthetic one's; the printed sheets, read back as a
// camera would see them flat on (the PNG at its DPI), show every marker with the id the targets block
// gives it, its corners where the block says (within a fraction of a pixel); bad layouts are errors.
#include "align/targets.h"

#include <cmath>
#include <filesystem>

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include "align/markers.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/json_reader.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

using testing::ScratchDir;

TEST(Targets, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(TargetSheetsOptions().Check(&why)) << why;
  TargetSheetsOptions bad;
  bad.ring_count = 40;  // cards overlap
  bad.light_marker_first_id = 40;
  EXPECT_FALSE(bad.Check(&why));
  EXPECT_NE(why.find("card_spacing"), std::string::npos) << why;
}

// The platform's PNG at 200 dpi: each marker detected with its id; its corners (pixels -> mm on the
// sheet -> the platform frame) within 0.1 mm of targets.json's.
TEST(Targets, PrintedPlatformShowsTheLayout) {
  ScratchDir dir;
  TargetSheetsOptions options;
  options.dpi = 200.0;
  options.charuco = false;
  const TargetSheetsResult result = WriteTargetSheets(options, dir / "t");
  ASSERT_TRUE(result.written);
  const nlohmann::json block = ReadJsonFile(dir / "t/targets.json")["targets"];
  ASSERT_EQ(block["reference"].size(), 12u);
  const Image sheet = ReadImage(dir / "t/platform.png");
  const double mm_per_px = 25.4 / options.dpi;
  // The sheet's layout (targets.cc): platform centre at (width / 2, 10 mm + radius) on the sheet.
  const double cx = 0.5 * sheet.width * mm_per_px, cy = 10.0 + 1e3 * options.platform_radius;
  ASSERT_NEAR(sheet.width * mm_per_px, 290.0, mm_per_px);
  const std::vector<MarkerDetection> detections = DetectMarkers(sheet, MarkerDictionary(options.dictionary));
  ASSERT_EQ(detections.size(), 12u);
  for (const MarkerDetection& d : detections) {
    ASSERT_GE(d.id, 0);
    ASSERT_LT(d.id, 12);
    const nlohmann::json& corners = block["reference"][d.id]["corners"];
    ASSERT_EQ(block["reference"][d.id]["id"].get<int>(), d.id);
    for (int k = 0; k < 4; ++k) {
      const double x_mm = d.corners[k].x() * mm_per_px - cx, y_mm = cy - d.corners[k].y() * mm_per_px;
      EXPECT_NEAR(x_mm, 1e3 * corners[k][0].get<double>(), 0.1) << "marker " << d.id << " corner " << k;
      EXPECT_NEAR(y_mm, 1e3 * corners[k][1].get<double>(), 0.1) << "marker " << d.id << " corner " << k;
    }
  }
}

// The light card: both markers, and the emitter's cross where light_in_marker puts it.
TEST(Targets, LightCardMatchesItsBlock) {
  ScratchDir dir;
  TargetSheetsOptions options;
  options.dpi = 200.0;
  options.charuco = false;
  WriteTargetSheets(options, dir / "t");
  const Image card = ReadImage(dir / "t/light-card.png");
  const std::vector<MarkerDetection> detections = DetectMarkers(card, MarkerDictionary(options.dictionary));
  ASSERT_EQ(detections.size(), 2u);
  const TargetsSpec layout = TargetLayout(options);
  ASSERT_TRUE(layout.light);
  const double mm_per_px = 25.4 / options.dpi;
  const double cross_x = 0.5 * card.width * mm_per_px, cross_y = 15.0;  // targets.cc: the cross above the row
  for (const MarkerDetection& d : detections) {
    const LightMarkerSpec* spec = nullptr;
    for (const LightMarkerSpec& m : layout.light->markers) spec = m.id == d.id ? &m : spec;
    ASSERT_NE(spec, nullptr) << d.id;
    // The marker frame: origin at its centre, x right, y down the print (mm on the sheet).
    const Eigen::Vector2d centre = 0.25 * (d.corners[0] + d.corners[1] + d.corners[2] + d.corners[3]) * mm_per_px;
    EXPECT_NEAR(centre.x() + 1e3 * spec->light_in_marker.x(), cross_x, 0.1) << d.id;
    EXPECT_NEAR(centre.y() + 1e3 * spec->light_in_marker.y(), cross_y, 0.1) << d.id;
  }
}

// The white reference's card: its 4 markers detected with the block's ids, their
// corners where targets.json's white_reference block puts them in the card's frame (origin at the
// patch's centre, x right, y up), within 0.1 mm.
TEST(Targets, WhiteCardMatchesItsBlock) {
  ScratchDir dir;
  TargetSheetsOptions options;
  options.dpi = 200.0;
  options.charuco = false;
  const TargetSheetsResult result = WriteTargetSheets(options, dir / "t");
  ASSERT_TRUE(result.targets.white_reference);
  const nlohmann::json block = ReadJsonFile(dir / "t/targets.json")["targets"]["white_reference"]["markers"];
  ASSERT_EQ(block.size(), 4u);
  const Image card = ReadImage(dir / "t/white-card.png");
  const double mm_per_px = 25.4 / options.dpi;
  // targets.cc: the card's centre at (width / 2, 10 mm + card / 2) on the sheet.
  const double side =
      1e3 * (options.white_patch_size + 2.0 * options.white_marker_size * (1.0 + 2.0 * options.card_margin));
  const double cx = 0.5 * card.width * mm_per_px, cy = 10.0 + 0.5 * side;
  const std::vector<MarkerDetection> detections = DetectMarkers(card, MarkerDictionary(options.dictionary));
  ASSERT_EQ(detections.size(), 4u);
  for (const MarkerDetection& d : detections) {
    const int k = d.id - options.white_marker_first_id;
    ASSERT_GE(k, 0);
    ASSERT_LT(k, 4);
    ASSERT_EQ(block[k]["id"].get<int>(), d.id);
    for (int c = 0; c < 4; ++c) {
      const double x_mm = d.corners[c].x() * mm_per_px - cx, y_mm = cy - d.corners[c].y() * mm_per_px;
      EXPECT_NEAR(x_mm, 1e3 * block[k]["corners"][c][0].get<double>(), 0.1) << "marker " << d.id << " corner " << c;
      EXPECT_NEAR(y_mm, 1e3 * block[k]["corners"][c][1].get<double>(), 0.1) << "marker " << d.id << " corner " << c;
      EXPECT_EQ(block[k]["corners"][c][2].get<double>(), 0.0);
    }
  }
  // The patch stays clear: no marker reaches into it.
  for (const TargetSpec& marker : result.targets.white_reference->markers) {
    for (const Eigen::Vector3d& corner : marker.corners) {
      EXPECT_GT(std::max(std::abs(corner.x()), std::abs(corner.y())), 0.5 * options.white_patch_size);
    }
  }
  // A thicker patch puts the markers behind its plane; ids colliding with the light's are refused.
  options.white_patch_thickness = 0.012;
  EXPECT_NEAR(TargetLayout(options).white_reference->markers[0].corners[0].z(), -0.012, 1e-15);
  options.white_marker_first_id = 19;  // 19..22 overlaps the light's 20, 21
  std::string why;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("white_marker_first_id"), std::string::npos) << why;
}

TEST(Targets, IdsBeyondTheDictionaryAreAnError) {
  ScratchDir dir;
  TargetSheetsOptions options;
  options.light_marker_first_id = 49;  // ids 49, 50: DICT_4X4_50 ends at 49
  try {
    WriteTargetSheets(options, dir / "t");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("DICT_4X4_50"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "t"));
}

}  // namespace
}  // namespace ibrdf
