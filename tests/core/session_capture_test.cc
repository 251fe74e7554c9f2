// The session fields of the capture kit, kept out of session_test.cc: `sample.radius_known`
// round-trips; `radiometry.saturation_level` is written back only when the manifest stated it (so a
// rebased session of float photos keeps "no saturation"); `light.intensity` may be left out when a
// white reference measures it, and is still required without one.
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/image_io.h"
#include "core/session.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

class SessionCaptureTest : public ::testing::Test {
 protected:
  void SetUp() override {
    fs::create_directories(fs::path(scratch_.str()) / "photos");
    Image photo(8, 6, 3);
    WriteImage(scratch_ / "photos/a.png", photo, PixelFormat::kUint8);
  }
  json Manifest() const {
    return json::parse(R"({
      "format": "ibrdf-session", "version": 1, "name": "capture",
      "camera": {"model": "PINHOLE", "width": 8, "height": 6, "params": [10.0, 10.0, 4.0, 3.0]},
      "light": {"kind": "point", "position": [1.0, 0.0, 0.0], "intensity": [1.0, 1.0, 1.0]},
      "sample": {"kind": "sphere", "center": [0.0, 0.0, 0.0], "radius": 0.05},
      "photos": [{"file": "photos/a.png", "exposure_s": 0.5}]
    })");
  }
  Session Load(const json& manifest) const {
    std::ofstream(scratch_ / "session.json") << manifest.dump(2);
    return Session::Load(scratch_ / "session.json");
  }
  testing::ScratchDir scratch_;
};

TEST_F(SessionCaptureTest, RadiusKnownRoundTrips) {
  EXPECT_FALSE(Load(Manifest()).sample.radius_known);
  json manifest = Manifest();
  manifest["sample"]["radius_known"] = true;
  const Session session = Load(manifest);
  EXPECT_TRUE(session.sample.radius_known);
  EXPECT_EQ(session.ToJson()["sample"]["radius_known"], true);
  manifest["sample"]["radius_known"] = "yes";
  EXPECT_THROW(Load(manifest), Error);
}

TEST_F(SessionCaptureTest, SaturationIsWrittenOnlyWhenStated) {
  const Session unstated = Load(Manifest());
  EXPECT_FALSE(unstated.radiometry.saturation_stated);
  EXPECT_FALSE(unstated.ToJson()["radiometry"].contains("saturation_level"));
  json manifest = Manifest();
  manifest["radiometry"] = {{"saturation_level", 0.9}};
  const Session stated = Load(manifest);
  EXPECT_TRUE(stated.radiometry.saturation_stated);
  EXPECT_EQ(stated.ToJson()["radiometry"]["saturation_level"], 0.9);
}

TEST_F(SessionCaptureTest, LightIntensityOptionalWithAWhiteReference) {
  json manifest = Manifest();
  manifest["light"].erase("intensity");
  try {
    Load(manifest);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/light"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("white_reference"), std::string::npos) << e.what();
  }
  manifest["calibration"] = json::parse(R"({"white_reference": {
      "reflectance": [0.99, 0.99, 0.99], "center": [0.0, 0.0, 0.0], "normal": [1.0, 0.0, 0.0], "size": 0.05,
      "photos": [{"file": "photos/a.png", "exposure_s": 0.1,
                  "camera_from_world": {"rotation": [1.0, 0.0, 0.0, 0.0], "translation": [0.0, 0.0, 1.0]}}]}})");
  const Session session = Load(manifest);
  EXPECT_FALSE(session.lights[0].has_intensity);  // the white reference's calibration measures it
}

}  // namespace
}  // namespace ibrdf
