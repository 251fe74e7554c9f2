// Regression-based consistency checks: small on a reciprocal, isotropic measurement; held-out photos
// are predicted within a few per cent.
#include "reconstruct/prediction_check.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/reconstruct/reconstruct_test_util.h"

namespace ibrdf {
namespace {

TEST(PredictionCheck, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(PredictionCheckOptions().Check(&why)) << why;
}

TEST(PredictionCheck, BluepaintIsConsistentAndPredictable) {
  const auto material = LoadMaterial(testing::MaterialPath("bluepaint"));
  const auto samples = testing::SessionSamples(*material, CameraEffects::None(), 20, 400, 300);
  PredictionCheckOptions options;
  options.held_out_photos = 2;
  const PredictionReport report = CheckWithRegression(samples, options);
  ASSERT_TRUE(report.success);
  EXPECT_GT(report.reciprocity.pairs, 50u);
  EXPECT_GT(report.bilateral.pairs, 50u);
  EXPECT_LT(report.reciprocity.mean, 0.03);
  EXPECT_LT(report.bilateral.mean, 0.03);
  ASSERT_EQ(report.held_out.size(), 2u);
  EXPECT_LT(report.held_out_rms.maxCoeff(), 0.10) << report.BriefReport();
}

// A held-out photo with nothing to predict (every sample beyond max_theta_deg) has no figures: it is
// invalid with a note, its errors are null in the JSON and the summary says nothing was predicted,
// never a median of 0. A channel no sample measured is null too, the others are reported.
TEST(PredictionCheck, NothingPredictedIsInvalidNotZero) {
  const auto material = LoadMaterial(testing::MaterialPath("bluepaint"));
  auto samples = testing::SessionSamples(*material, CameraEffects::None(), 6, 200, 150);
  PredictionCheckOptions options;
  options.held_out_photos = 2;
  options.max_theta_deg = 0.5;  // no sample has both angles this small
  PredictionReport report = CheckWithRegression(samples, options);
  ASSERT_TRUE(report.success);
  ASSERT_EQ(report.held_out.size(), 2u);
  for (const HeldOutPhoto& photo : report.held_out) {
    EXPECT_FALSE(photo.valid());
    EXPECT_EQ(photo.predicted, 0u);
    EXPECT_NE(photo.note.find("below 0.5 deg"), std::string::npos) << photo.note;
  }
  EXPECT_FALSE(report.held_out_valid());
  EXPECT_FALSE(report.reciprocity.valid());
  const nlohmann::json json = ToJson(report, options);
  EXPECT_FALSE(json["held_out_valid"].get<bool>());
  EXPECT_TRUE(json["held_out_rms_rel_error"][0].is_null());
  EXPECT_TRUE(json["held_out_photos"][0]["median_rel_error"][1].is_null());
  EXPECT_FALSE(json["held_out_photos"][0]["valid"].get<bool>());
  EXPECT_TRUE(json["reciprocity_near_incidence_plane"]["median_rel_error"].is_null());
  EXPECT_NE(report.BriefReport().find("nothing predicted"), std::string::npos) << report.BriefReport();

  // Blue measured nowhere: its figures are null, red and green are reported.
  for (BrdfSample& s : samples) s.valid[2] = 0;
  options.max_theta_deg = 70.0;
  report = CheckWithRegression(samples, options);
  ASSERT_TRUE(report.held_out_valid()) << report.BriefReport();
  EXPECT_EQ(report.held_out_measured[2], 0u);
  EXPECT_GT(report.held_out_measured[0], 0u);
  const nlohmann::json partial = ToJson(report, options);
  EXPECT_TRUE(partial["held_out_rms_rel_error"][2].is_null());
  EXPECT_TRUE(partial["held_out_rms_rel_error"][0].is_number());
  EXPECT_NE(report.BriefReport().find("n/a %"), std::string::npos) << report.BriefReport();
}

}  // namespace
}  // namespace ibrdf
