// Regression-based consistency checks: small on a reciprocal, isotropic measurement; held-out photos
// are predicted within a few per cent.
#include "reconstruct/prediction_check.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace ibrdf
