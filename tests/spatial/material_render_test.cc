// A photo predicted from the model: each of its samples against its cell's combination of the bases,
// beside the one BRDF; samples of other photos and of cells not fitted are not predicted.
#include "spatial/material_render.h"

#include <cmath>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "spatial/uniformity.h"

namespace ibrdf {
namespace {

const GgxBrdf kGlossy(Eigen::Vector3d(0.05, 0.1, 0.4), Eigen::Vector3d(0.04, 0.04, 0.04), 0.15);
const LambertianBrdf kMatte(Eigen::Vector3d(0.5, 0.25, 0.15));

LocatedSample At(const Eigen::Vector3f& point, uint32_t image, const Eigen::Vector3d& wi, const Eigen::Vector3d& wo,
                 double scale) {
  LocatedSample s;
  const Eigen::Vector3d f = 0.5 * kGlossy.Eval(wi, wo) + 0.5 * kMatte.Eval(wi, wo);
  for (int k = 0; k < 3; ++k) {
    s.sample.wi[k] = float(wi[k]);
    s.sample.wo[k] = float(wo[k]);
    s.sample.brdf[k] = float(scale * f[k]);
  }
  s.sample.image = image;
  s.point = point;
  return s;
}

TEST(MaterialRender, SamplesArePredictedFromTheirCellsCombination) {
  const double cell_m = 0.01;
  MaterialWeightsResult weights;
  weights.bases = 2;
  CellWeights cell;
  cell.key = UniformityCellKey(Eigen::Vector3d(0.005, 0.005, 0.005), Eigen::Vector3d::Zero(), cell_m);
  cell.fitted = true;
  cell.weights = Eigen::Vector2d(0.5, 0.5);
  weights.cells = {cell};
  const Eigen::Vector3d wi = Eigen::Vector3d(0.3, 0.1, 1.0).normalized(), wo = Eigen::Vector3d(-0.2, 0.0, 1.0).normalized();
  // Measured 1.25x the model: |model / measured - 1| = 0.2 in every channel.
  const std::vector<LocatedSample> samples = {At({0.004f, 0.006f, 0.002f}, 0, wi, wo, 1.25),
                                              At({0.006f, 0.001f, 0.009f}, 0, wi, wo, 1.25),
                                              At({0.004f, 0.006f, 0.002f}, 1, wi, wo, 3.0),     // another photo
                                              At({0.025f, 0.006f, 0.002f}, 0, wi, wo, 3.0)};  // no fitted cell
  Session session;
  const PhotoPrediction p = PredictPhoto(session, 0, true, samples, weights, {&kGlossy, &kMatte},
                                         Eigen::Vector3d::Zero(), cell_m, &kMatte, nullptr, "/nonexistent");
  ASSERT_TRUE(p.done);
  EXPECT_TRUE(p.held_out);
  EXPECT_EQ(p.samples, 3u);
  EXPECT_EQ(p.predicted, 2u);
  EXPECT_NEAR(p.model_error_all, 0.2, 1e-6);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(p.model_error[k], 0.2, 1e-6);
  // The one BRDF (the matte alone) against the same samples.
  const Eigen::Vector3d f = 0.5 * kGlossy.Eval(wi, wo) + 0.5 * kMatte.Eval(wi, wo), m = kMatte.Eval(wi, wo);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(p.single_error[k], std::abs(m[k] / (1.25 * f[k]) - 1.0), 1e-6);
  EXPECT_TRUE(std::isnan(p.truth_error_all));
  EXPECT_TRUE(p.image.empty());  // no photo to draw on
  const nlohmann::json json = p.ToJson();
  EXPECT_TRUE(json.at("truth_median_abs_rel_error_all").is_null());
  EXPECT_EQ(json.at("predicted"), 2);
  EXPECT_NE(p.BriefReport().find("(held out): 2 of 3 samples predicted"), std::string::npos) << p.BriefReport();
}

}  // namespace
}  // namespace ibrdf
