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

TEST(ModelFit, LafortuneAnalyticCostMatchesAutoDiffAndNumericGradient) {
  const Eigen::Vector3d wi = FromSpherical(0.5, 0.2), wo = FromSpherical(0.6, 2.9);
  LafortuneAnalyticResidual<3> analytic(wi, wo, 0.7, 0.05);
  LafortuneResidual<3> reference(wi, wo, 0.7, 0.05);
  double p[10] = {0.3, -1.0, 0.8, 20.0, 0.5, 0.6, 3.0, -0.6, 0.4, 2.0};
  const double* parameters[1] = {p};
  double r_analytic = 0.0, r_reference = 0.0;
  ASSERT_TRUE(analytic.Evaluate(parameters, &r_analytic, nullptr));
  ASSERT_TRUE(reference(p, &r_reference));
  EXPECT_NEAR(r_analytic, r_reference, 1e-12 * std::max(1.0, std::abs(r_reference)));
  ceres::NumericDiffOptions numeric;
  const std::vector<const ceres::Manifold*>* no_manifolds = nullptr;
  ceres::GradientChecker checker(&analytic, no_manifolds, numeric);
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(parameters, 1e-6, &results)) << results.error_log;
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

namespace ibrdf {
namespace {

// A one-lobe truth (bluepaint's diffuse and its main specular lobe): the one-lobe fit of its session
// recovers the lobe's exponent within 20 % in every channel, and says when a parameter sits at a bound.
TEST(ModelFitPlausibility, OneLobeFitRecoversTheExponent) {
  const auto bluepaint = LoadMaterial(MaterialPath("bluepaint"));
  const auto& three = dynamic_cast<const LafortuneBrdf&>(*bluepaint);
  const LafortuneBrdf truth(three.diffuse(), {three.lobes()[2]});
  const auto samples = testing::SessionSamples(truth, CameraEffects::None(), 12, 200, 150);
  ModelFitOptions options;
  options.lafortune_lobes = 1;
  options.max_samples = 5000;
  const ModelFitResult fit = FitLafortune(samples, options);
  ASSERT_TRUE(fit.success);
  const auto& fitted = dynamic_cast<const LafortuneBrdf&>(*fit.brdf);
  for (int c = 0; c < 3; ++c) {
    const double n_true = truth.lobes()[0].n[c];
    EXPECT_NEAR(fitted.lobes()[0].n[c], n_true, 0.2 * n_true) << c << ": " << fit.BriefReport();
  }
  EXPECT_TRUE(fit.at_bound.empty()) << fit.BriefReport();
}

// Every bundled material and a Lafortune truth with broad lobes: each fitted model's directional
// albedo stays at most 1 over the whole hemisphere, no fit exceeds 3x the truth at retro-reflection
// up to grazing (never sampled: the cameras start 8 degrees from the light), and the chosen model
// (the lower error against the samples) is within 3x of the truth there up to 80 degrees, the
// derenderer's grazing limit. Beyond it the felt's grazing retro-reflection is under-estimated (5x
// at 85 degrees): reported in docs/benchmarks.md, not tested.
TEST(ModelFitPlausibility, FitsArePlausibleWhereNoCameraLooked) {
  std::vector<std::pair<std::string, std::unique_ptr<BrdfModel>>> truths;
  for (const char* name : {"bluepaint", "clay", "felt", "glossy-ggx", "lambertian50", "primer"}) {
    truths.emplace_back(name, LoadMaterial(MaterialPath(name)));
  }
  const LafortuneLobe broad_retro{Eigen::Vector3d::Constant(0.5), Eigen::Vector3d::Constant(0.5),
                                  Eigen::Vector3d::Constant(2.0)};
  const LafortuneLobe broad_forward{Eigen::Vector3d::Constant(-0.5), Eigen::Vector3d::Constant(0.5),
                                    Eigen::Vector3d::Constant(3.0)};
  truths.emplace_back("broad-lafortune",
                      std::make_unique<LafortuneBrdf>(Eigen::Vector3d(0.3, 0.3, 0.3),
                                                      std::vector<LafortuneLobe>{broad_retro, broad_forward}));
  for (const auto& [name, truth] : truths) {
    ASSERT_LE(MaxDirectionalAlbedo(*truth), 1.0) << name << ": the truth itself must be plausible";
    const auto samples = testing::SessionSamples(*truth, CameraEffects::None(), 10, 200, 150);
    ModelFitOptions options;
    options.max_samples = 4000;
    const ModelFitResult lafortune = FitLafortune(samples, options), ggx = FitGgx(samples, options);
    const ModelFitResult& chosen = lafortune.rel_rms < ggx.rel_rms ? lafortune : ggx;
    for (const ModelFitResult* fit : {&lafortune, &ggx}) {
      ASSERT_TRUE(fit->success);
      EXPECT_LE(fit->max_albedo, 1.0) << name << " " << fit->BriefReport();
      EXPECT_NEAR(fit->max_albedo, MaxDirectionalAlbedo(*fit->brdf), 1e-12);
      for (double theta_deg : {70.0, 80.0, 85.0, 89.0}) {
        const Eigen::Vector3d w = FromSpherical(theta_deg * M_PI / 180.0, 0.3);
        const Eigen::Vector3d f = fit->brdf->Eval(w, w), t = truth->Eval(w, w);
        for (int c = 0; c < 3; ++c) {
          EXPECT_LE(f[c], 3.0 * t[c]) << name << " " << fit->model << " retro at " << theta_deg << " deg, channel " << c
                                      << ": " << fit->brdf->ToJson().dump();
          if (fit != &chosen || theta_deg > 80.0) continue;
          EXPECT_GE(f[c], t[c] / 3.0) << name << " " << fit->model << " retro at " << theta_deg << " deg, channel " << c
                                      << ": " << fit->brdf->ToJson().dump();
        }
      }
    }
  }
}

}  // namespace
}  // namespace ibrdf
