// Tests of calibrate/light_rig.h without photos: the report's path beside the lights, the "ibrdf-lights"
// file as the session format writes lights, and a session given the calibrated lights.
#include "calibrate/light_rig.h"

#include <string>

#include <gtest/gtest.h>

#include "core/error.h"

namespace ibrdf {
namespace {

CalibratedLight Calibrated(const std::string& id, const Eigen::Vector3d& direction, const Eigen::Vector3d& intensity) {
  CalibratedLight c;
  c.light.id = id;
  c.light.kind = Light::Kind::kDirectional;
  c.light.direction = direction;
  c.light.intensity = intensity;
  c.light.has_intensity = false;  // as the probe leaves a light whose session stated none
  return c;
}

LightRigCalibration TwoLights() {
  LightRigCalibration calibration;
  calibration.probe.success = true;
  calibration.probe.lights = {Calibrated("L1", Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(1, 1, 1)),
                              Calibrated("L2", Eigen::Vector3d(0, 0.6, 0.8), Eigen::Vector3d(0.5, 0.6, 0.7))};
  calibration.probe.intensity_reference = "relative: test";
  return calibration;
}

TEST(LightRig, ReportPathSitsBesideTheLights) {
  EXPECT_EQ(LightRigReportPath("out/lights.json"), "out/lights.calibration.json");
  EXPECT_EQ(LightRigReportPath("out/lights"), "out/lights.calibration.json");
}

TEST(LightRig, LightsFileHasEveryLightWithItsIntensity) {
  const nlohmann::json file = TwoLights().LightsFileJson();
  EXPECT_EQ(file.at("format"), "ibrdf-lights");
  EXPECT_EQ(file.at("version"), 1);
  EXPECT_EQ(file.at("intensity_reference"), "relative: test");
  ASSERT_EQ(file.at("lights").size(), 2u);
  const nlohmann::json& second = file.at("lights")[1];
  EXPECT_EQ(second.at("id"), "L2");
  EXPECT_EQ(second.at("kind"), "directional");
  EXPECT_DOUBLE_EQ(second.at("direction")[1].get<double>(), 0.6);
  EXPECT_DOUBLE_EQ(second.at("intensity")[2].get<double>(), 0.7);
  EXPECT_FALSE(second.contains("position"));
}

TEST(LightRig, SessionTakesTheCalibratedLightsByIdAndRefusesAMissingOne) {
  Session target;
  target.manifest_path = "rig/session.json";
  Light l2;
  l2.id = "L2";
  l2.has_intensity = false;
  Light l1 = l2;
  l1.id = "L1";
  target.lights = {l2, l1};
  const Session copy = WithCalibratedLights(target, TwoLights(), "lights.json", false);
  ASSERT_EQ(copy.lights.size(), 2u);
  EXPECT_EQ(copy.lights[0].id, "L2");
  EXPECT_TRUE(copy.lights[0].has_intensity);
  EXPECT_EQ(copy.lights[0].intensity, Eigen::Vector3d(0.5, 0.6, 0.7));
  EXPECT_EQ(copy.lights[1].direction, Eigen::Vector3d(0, 0, 1));
  EXPECT_NE(copy.description.find("lights.json"), std::string::npos) << copy.description;

  Light l3 = l1;
  l3.id = "L3";
  target.lights.push_back(l3);
  try {
    WithCalibratedLights(target, TwoLights(), "lights.json", false);
    FAIL() << "a light without calibration was accepted";
  } catch (const Error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("rig/session.json"), std::string::npos) << message;
    EXPECT_NE(message.find("L3"), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace ibrdf
