// Model fits: the Ceres cost functions' derivatives, and a 3-lobe Lafortune fit that recovers the
// BRDF it was sampled from.
#include "reconstruct/model_fit.h"

#include <cmath>

#include <ceres/ceres.h>
#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/brdf_coords.h"
#include "reconstruct/model_cost_functions.h"
#include "tests/reconstruct/reconstruct_test_util.h"

namespace ibrdf {
namespace {

using testing::MaterialPath;

TEST(ModelFit, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(ModelFitOptions().Check(&why)) << why;
  ModelFitOptions bad;
  bad.lafortune_lobes = 4;
  EXPECT_FALSE(bad.Check(&why));
}

TEST(ModelFit, LafortuneCostGradientIsCorrect) {
  const Eigen::Vector3d wi = FromSpherical(0.5, 0.2), wo = FromSpherical(0.6, 2.9);
  auto* cost =
      new ceres::AutoDiffCostFunction<LafortuneResidual<3>, 1, 10>(new LafortuneResidual<3>(wi, wo, 0.7, 0.05));
  double p[10] = {0.3, -1.0, 0.8, 20.0, 0.5, 0.6, 3.0, -0.6, 0.4, 2.0};
  const double* parameters[1] = {p};
  ceres::NumericDiffOptions numeric;
  const std::vector<const ceres::Manifold*>* no_manifolds = nullptr;
  ceres::GradientChecker checker(cost, no_manifolds, numeric);
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(parameters, 1e-6, &results)) << results.error_log;
  delete cost;
}

TEST(ModelFit, GgxCostGradientIsCorrect) {
  const Eigen::Vector3d wi = FromSpherical(0.5, 0.2), wo = FromSpherical(0.6, 2.9);
  auto* cost = new ceres::AutoDiffCostFunction<GgxResidual, 3, 3, 3, 1>(
      new GgxResidual(wi, wo, Eigen::Vector3d(0.2, 0.3, 0.4), Eigen::Vector3d::Constant(0.01)));
  double diffuse[3] = {0.3, 0.4, 0.5}, f0[3] = {0.04, 0.05, 0.06}, alpha[1] = {0.2};
  const double* parameters[3] = {diffuse, f0, alpha};
  ceres::NumericDiffOptions numeric;
  const std::vector<const ceres::Manifold*>* no_manifolds = nullptr;
  ceres::GradientChecker checker(cost, no_manifolds, numeric);
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(parameters, 1e-6, &results)) << results.error_log;
  delete cost;
}

double RelativeRmsAgainst(const BrdfModel& fit, const BrdfModel& truth, const std::vector<BrdfSample>& samples) {
  double sum = 0.0;
  size_t count = 0;
  for (size_t i = 0; i < samples.size(); i += 7) {
    const BrdfSample& s = samples[i];
    const Eigen::Vector3d wi = Eigen::Vector3d(s.wi[0], s.wi[1], s.wi[2]).normalized();
    const Eigen::Vector3d wo = Eigen::Vector3d(s.wo[0], s.wo[1], s.wo[2]).normalized();
    const Eigen::Vector3d f = fit.Eval(wi, wo), t = truth.Eval(wi, wo);
    for (int c = 0; c < 3; ++c) {
      sum += std::pow((f[c] - t[c]) / t[c], 2);
      ++count;
    }
  }
  return std::sqrt(sum / count);
}

// Samples of the 3-lobe bluepaint material (noise-free session): the fitted BRDF must be within 1 %
// RMS of it over the measured directions. Parameters need not match (lobes can trade places).
TEST(ModelFit, LafortuneRecoversThreeLobeMaterial) {
  const auto material = LoadMaterial(MaterialPath("bluepaint"));
  const auto samples = testing::SessionSamples(*material, CameraEffects::None(), 20, 200, 150);
  ModelFitOptions options;
  options.max_samples = 8000;
  const ModelFitResult fit = FitLafortune(samples, options);
  ASSERT_TRUE(fit.success);
  const double rms = RelativeRmsAgainst(*fit.brdf, *material, samples);
  EXPECT_LT(rms, 0.01) << fit.BriefReport() << "\n" << fit.brdf->ToJson().dump();
  // The material file loads back as a material.
  const nlohmann::json json = FitMaterialJson(fit, "bluepaint-fit");
  EXPECT_EQ(MaterialFromJson(json, "fit")->ModelName(), "lafortune");
}

TEST(ModelFit, GgxRecoversGgxMaterialAndWritesSnippets) {
  const auto material = LoadMaterial(MaterialPath("glossy-ggx"));
  const auto samples = testing::SessionSamples(*material, CameraEffects::None(), 10, 200, 150);
  ModelFitOptions options;
  options.max_samples = 5000;
  const ModelFitResult fit = FitGgx(samples, options);
  ASSERT_TRUE(fit.success);
  EXPECT_LT(RelativeRmsAgainst(*fit.brdf, *material, samples), 0.01) << fit.BriefReport();
  const RendererSnippets snippets = RendererMaterials(fit, "m");
  EXPECT_NE(snippets.pbrt.find("coateddiffuse"), std::string::npos);
  EXPECT_NE(snippets.mitsuba.find("roughplastic"), std::string::npos);
}

}  // namespace
}  // namespace ibrdf
