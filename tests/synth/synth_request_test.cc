// `ibrdf synth`'s flags into options: presets, overrides, and the defaults that targets and shapes imply.
#include "synth/synth_request.h"

#include <gtest/gtest.h>

#include "core/colour.h"
#include "core/error.h"

namespace ibrdf {
namespace {

TEST(SynthRequest, DefaultRequestGivesDefaultOptions) {
  const SynthOptions options = SynthOptionsFromRequest(SynthRequest());
  EXPECT_EQ(options.scene.sample, SampleSpec::Kind::kSphere);
  EXPECT_EQ(options.scene.shape, SynthShape::kNone);
  EXPECT_FALSE(options.targets.enabled);
  EXPECT_EQ(options.targets.light_photos, 0);
  EXPECT_EQ(options.rig.camera_elevation_deg, 0.0);
  EXPECT_EQ(options.effects.bits, CameraEffects().bits);
  EXPECT_TRUE(options.effects.shot_noise);
  std::string why;
  EXPECT_TRUE(options.Check(&why)) << why;
}

TEST(SynthRequest, TargetsLookDownAndAddLightPhotosUnlessGiven) {
  SynthRequest request;
  request.targets = true;
  SynthOptions options = SynthOptionsFromRequest(request);
  EXPECT_TRUE(options.targets.enabled);
  EXPECT_EQ(options.rig.camera_elevation_deg, 45.0);
  EXPECT_EQ(options.targets.light_photos, 3);
  request.camera_elevation_given = true;
  request.light_photos_given = true;
  request.options.rig.camera_elevation_deg = 30.0;
  request.options.targets.light_photos = 0;
  options = SynthOptionsFromRequest(request);
  EXPECT_EQ(options.rig.camera_elevation_deg, 30.0);
  EXPECT_EQ(options.targets.light_photos, 0);
}

TEST(SynthRequest, ShapeImpliesTargets) {
  SynthRequest request;
  request.shape = "pot";
  const SynthOptions options = SynthOptionsFromRequest(request);
  EXPECT_EQ(options.scene.shape, SynthShape::kPot);
  EXPECT_TRUE(options.targets.enabled);
  request.shape = "cube";
  EXPECT_THROW(SynthOptionsFromRequest(request), Error);
}

TEST(SynthRequest, EffectsPresetAndOverrides) {
  SynthRequest request;
  request.effects = "none";
  request.vignetting = 0.2;
  request.no_clip = true;
  SynthOptions options = SynthOptionsFromRequest(request);
  EXPECT_EQ(options.effects.bits, 0);
  EXPECT_FALSE(options.effects.shot_noise);
  EXPECT_FALSE(options.effects.clip);
  EXPECT_EQ(options.effects.vignetting, 0.2);
  request.bits = 12;  // --no-clip needs float output
  EXPECT_THROW(SynthOptionsFromRequest(request), Error);
  request = SynthRequest();
  request.sample = "cylinder";
  request.srgb = true;
  request.no_read_noise = true;
  request.origin = {1.0, 2.0, 3.0};
  request.light_intensity = {2.0, 2.0, 1.0};
  options = SynthOptionsFromRequest(request);
  EXPECT_EQ(options.scene.sample, SampleSpec::Kind::kCylinder);
  EXPECT_EQ(options.effects.curve, SensorCurve::kSrgb);
  EXPECT_FALSE(options.effects.read_noise);
  EXPECT_EQ(options.scene.origin, Eigen::Vector3d(1.0, 2.0, 3.0));
  EXPECT_EQ(options.scene.light_intensity, Eigen::Vector3d(2.0, 2.0, 1.0));
  request.origin = {1.0};
  EXPECT_THROW(SynthOptionsFromRequest(request), Error);
}

TEST(SynthRequest, ColourAndNoDataByName) {
  SynthRequest request;
  request.camera_matrix = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  request.colour_chart_detect = true;
  request.colour_space = "xyz";
  request.no_data = "zero";
  const SynthOptions options = SynthOptionsFromRequest(request);
  EXPECT_EQ(options.colour.camera_matrix(0, 1), 2.0);  // row by row
  EXPECT_EQ(options.colour.camera_matrix(1, 0), 4.0);
  EXPECT_FALSE(options.colour.chart_corners);
  EXPECT_EQ(options.colour.space, ColourSpace::kXyz);
  EXPECT_EQ(options.no_data, SynthNoData::kZero);
  EXPECT_TRUE(SynthOptionsFromRequest(SynthRequest()).colour.chart_corners);
  SynthRequest bad;
  bad.camera_matrix = {1, 2};
  EXPECT_THROW(SynthOptionsFromRequest(bad), Error);
  bad = SynthRequest();
  bad.colour_space = "lab";
  EXPECT_THROW(SynthOptionsFromRequest(bad), Error);
  bad = SynthRequest();
  bad.no_data = "maybe";
  EXPECT_THROW(SynthOptionsFromRequest(bad), Error);
}

TEST(SynthRequest, MerlLookupOnlyForTables) {
  SynthRequest request;
  const std::string material = std::string(IBRDF_SAMPLES_DIR) + "/materials/lambertian50.json";
  EXPECT_NE(LoadRequestedMaterial(request, material), nullptr);
  request.merl_lookup_given = true;
  try {
    LoadRequestedMaterial(request, material);
    FAIL() << "a lookup for a material that is no MERL table";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--merl-lookup"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(material), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ibrdf
