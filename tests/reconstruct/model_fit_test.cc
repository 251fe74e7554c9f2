// Model fits: the Ceres cost functions' derivatives, and a 3-lobe Lafortune fit that recovers the
// BRDF it was sampled from.
#include "reconstruct/model_fit.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include <ceres/ceres.h>
#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/brdf_coords.h"
#include "core/json_reader.h"
#include "core/sample_file.h"
#include "reconstruct/model_cost_functions.h"
#include "reconstruct/reconstruction_stage.h"
#include "tests/reconstruct/reconstruct_test_util.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

using testing::MaterialPath;

TEST(ModelFit, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(ModelFitOptions().Check(&why)) << why;
  ModelFitOptions bad;
  bad.lafortune_lobes = 4;
  EXPECT_FALSE(bad.Check(&why));
  ModelFitOptions few_starts;
  few_starts.start_samples = 5;
  EXPECT_FALSE(few_starts.Check(&why));
  EXPECT_NE(why.find("start_samples"), std::string::npos) << why;
  ModelFitOptions no_cap;
  no_cap.min_lobe_cap = 0.0;
  EXPECT_FALSE(no_cap.Check(&why));
  EXPECT_NE(why.find("min_lobe_cap"), std::string::npos) << why;
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

// The plausibility penalties: analytic derivatives agree with numeric ones where the bound is broken,
// and the penalty is 0 where it holds (a Lambertian's albedo is its diffuse coefficient exactly).
TEST(ModelFit, PlausibilityPenaltiesHaveCorrectGradients) {
  const Eigen::Vector3d wi = FromSpherical(0.5, 0.2);
  std::vector<std::pair<double, double>> xy_z;
  std::vector<double> weights;
  constexpr int kRings = 8, kSectors = 16;
  for (int r = 0; r < kRings; ++r) {
    for (int k = 0; k < kSectors; ++k) {
      const Eigen::Vector3d wo = FromSpherical(std::acos(std::sqrt((r + 0.5) / kRings)), 2 * M_PI * (k + 0.5) / kSectors);
      xy_z.emplace_back(wi.x() * wo.x() + wi.y() * wo.y(), wi.z() * wo.z());
      weights.push_back(0.5 / kRings * 2 * M_PI / kSectors);
    }
  }
  double p[10] = {0.3, -1.0, 0.8, 20.0, 0.5, 0.6, 3.0, -0.6, 0.4, 2.0};
  const double* parameters[1] = {p};
  ceres::NumericDiffOptions numeric;
  const std::vector<const ceres::Manifold*>* no_manifolds = nullptr;
  ceres::GradientChecker::ProbeResults results;
  // 1e-4: the central differences' own error on these sums of steep lobes is about 1e-5.
  const LafortuneAlbedoPenalty<3> albedo(xy_z, weights, 0.05);
  EXPECT_TRUE(ceres::GradientChecker(&albedo, no_manifolds, numeric).Probe(parameters, 1e-4, &results))
      << results.error_log;
  const LafortuneCeilingPenalty<3> ceiling(wi, FromSpherical(0.6, 2.9), 0.01);
  EXPECT_TRUE(ceres::GradientChecker(&ceiling, no_manifolds, numeric).Probe(parameters, 1e-4, &results))
      << results.error_log;
  // A Lambertian of diffuse 0.5: albedo 0.5, so a bound of 0.25 gives
  // weight x (0.5 / 0.25 - 1), a bound of 0.6 nothing (Cxy 0, Cz -1: every base negative).
  double lambertian[10] = {0.5, 0.0, -1.0, 2.0, 0.0, -1.0, 2.0, 0.0, -1.0, 2.0};
  const double* lambertian_parameters[1] = {lambertian};
  double residual = 0.0;
  ASSERT_TRUE(LafortuneAlbedoPenalty<3>(xy_z, weights, 0.25).Evaluate(lambertian_parameters, &residual, nullptr));
  EXPECT_NEAR(residual, kPlausibilityPenaltyWeight, 1e-9);
  ASSERT_TRUE(LafortuneAlbedoPenalty<3>(xy_z, weights, 0.6).Evaluate(lambertian_parameters, &residual, nullptr));
  EXPECT_EQ(residual, 0.0);
  // The GGX albedo penalty on the same quadrature: F0 = 0 (dielectric) leaves the diffuse albedo.
  std::vector<GgxResidual> points;
  for (int r = 0; r < kRings; ++r) {
    for (int k = 0; k < kSectors; ++k) {
      const Eigen::Vector3d wo = FromSpherical(std::acos(std::sqrt((r + 0.5) / kRings)), 2 * M_PI * (k + 0.5) / kSectors);
      points.emplace_back(wi, wo, Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones(), true);
    }
  }
  const GgxAlbedoPenalty ggx(points, weights, Eigen::Vector3d(0.25, 0.6, std::numeric_limits<double>::infinity()));
  double diffuse[3] = {0.5, 0.5, 0.5}, s[3] = {0.0, 0.0, 0.0}, alpha[1] = {0.3}, r[3];
  ASSERT_TRUE(ggx(diffuse, s, alpha, r));
  EXPECT_NEAR(r[0], kPlausibilityPenaltyWeight, 1e-9);
  EXPECT_EQ(r[1], 0.0);
  EXPECT_EQ(r[2], 0.0);
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

double RelativeRmsAgainst(const BrdfModel& fit, const BrdfModel& truth, const std::vector<BrdfSample>& samples);

TEST(ModelFit, GgxDielectricCostGradientIsCorrect) {
  const Eigen::Vector3d wi = FromSpherical(0.5, 0.2), wo = FromSpherical(0.6, 2.9);
  const ceres::AutoDiffCostFunction<GgxResidual, 3, 3, 3, 1> cost(
      new GgxResidual(wi, wo, Eigen::Vector3d(0.2, 0.3, 0.4), Eigen::Vector3d::Constant(0.01), true));
  // s = sqrt(F0); at s = 0 (the lower bound, where the specular term vanishes) the derivative is the
  // one-sided 0. Central differences per parameter (ceres::GradientChecker's numeric derivative
  // disagreed with both this and the Jet's at s = 0.03 by 1 %; the closed form agrees with these).
  for (double s0 : {0.0, 0.03, 0.1, 0.2}) {
    double diffuse[3] = {0.3, 0.4, 0.5}, s[3] = {s0, 0.22, 0.25}, alpha[1] = {0.2};
    double* blocks[3] = {diffuse, s, alpha};
    const double* parameters[3] = {diffuse, s, alpha};
    double residual[3], j_diffuse[9], j_s[9], j_alpha[3];
    double* jacobians[3] = {j_diffuse, j_s, j_alpha};
    ASSERT_TRUE(cost.Evaluate(parameters, residual, jacobians));
    const int sizes[3] = {3, 3, 1};
    for (int b = 0; b < 3; ++b) {
      for (int k = 0; k < sizes[b]; ++k) {
        const double x = blocks[b][k], h = 1e-7;
        if (b == 1 && x == 0.0) {
          for (int r = 0; r < 3; ++r) EXPECT_EQ(jacobians[b][r * sizes[b] + k], 0.0);
          continue;
        }
        double plus[3], minus[3];
        blocks[b][k] = x + h;
        cost.Evaluate(parameters, plus, nullptr);
        blocks[b][k] = x - h;
        cost.Evaluate(parameters, minus, nullptr);
        blocks[b][k] = x;
        for (int r = 0; r < 3; ++r) {
          const double numeric = (plus[r] - minus[r]) / (2 * h);
          EXPECT_NEAR(jacobians[b][r * sizes[b] + k], numeric, 1e-5 * (1.0 + std::abs(numeric)))
              << "s0 " << s0 << " block " << b << " parameter " << k << " residual " << r;
        }
      }
    }
    // The residual is the core model's (dielectric Fresnel of eta(F0)).
    const GgxBrdf model(Eigen::Vector3d(0.3, 0.4, 0.5), Eigen::Vector3d(s0 * s0, 0.22 * 0.22, 0.25 * 0.25), 0.2,
                        GgxFresnel::kDielectric);
    const Eigen::Vector3d f = model.Eval(wi, wo);
    const double values[3] = {0.2, 0.3, 0.4};
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(residual[c], (f[c] - values[c]) / 0.01, 1e-9);
  }
}

// A Lambertian truth: the GGX fit keeps the dielectric variant, whose specular term vanishes (F0 = 0
// makes it exactly Lambertian), and says which variant won and by what error.
TEST(ModelFit, GgxFitOfALambertianChoosesTheDielectricVariant) {
  const LambertianBrdf material(Eigen::Vector3d(0.6, 0.4, 0.2));
  const auto samples = testing::SessionSamples(material, CameraEffects::None(), 8, 160, 120);
  ModelFitOptions options;
  options.max_samples = 4000;
  const ModelFitResult fit = FitGgx(samples, options);
  ASSERT_TRUE(fit.success);
  EXPECT_EQ(fit.variant, "dielectric") << fit.BriefReport();
  ASSERT_EQ(fit.variants.size(), 2u);
  EXPECT_LT(fit.rel_rms, 0.005) << fit.BriefReport();
  EXPECT_LT(RelativeRmsAgainst(*fit.brdf, material, samples), 0.005) << fit.BriefReport();
  EXPECT_NE(fit.BriefReport().find("Fresnel variant dielectric chosen by error"), std::string::npos);
  EXPECT_EQ(fit.brdf->ToJson()["fresnel"], "dielectric");
  // The error by theta band, in the summary's JSON and the log line.
  ASSERT_EQ(fit.band_rel_rms.size(), 3u);
  for (double band : fit.band_rel_rms) EXPECT_LT(band, 0.01);
  EXPECT_TRUE(ToJson(fit).contains("rel_rms_by_theta_max_deg"));
  EXPECT_NE(fit.BriefReport().find("by max(theta_i, theta_o) 0-25"), std::string::npos);
}

// A copper-like conductor (no diffuse, coloured F0): the conductor variant wins and keeps the colour.
TEST(ModelFit, GgxFitOfACopperChoosesTheConductorVariant) {
  const GgxBrdf material(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.95, 0.64, 0.54), 0.25);
  const auto samples = testing::SessionSamples(material, CameraEffects::None(), 8, 160, 120);
  ModelFitOptions options;
  options.max_samples = 4000;
  const ModelFitResult fit = FitGgx(samples, options);
  ASSERT_TRUE(fit.success);
  EXPECT_EQ(fit.variant, "conductor") << fit.BriefReport();
  EXPECT_LT(RelativeRmsAgainst(*fit.brdf, material, samples), 0.01) << fit.BriefReport();
  EXPECT_EQ(RendererMaterials(fit, "copper").kind, "conductor");
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
  // The starts ranked on 4000 samples (the default), the best refined on all 8000: the same error as
  // every start solved on all of them.
  EXPECT_EQ(fit.start_samples, 4000u) << fit.BriefReport();
  ModelFitOptions every_start_on_all = options;
  every_start_on_all.start_samples = 0;
  const ModelFitResult reference = FitLafortune(samples, every_start_on_all);
  EXPECT_EQ(reference.start_samples, 0u);
  EXPECT_LE(rms, RelativeRmsAgainst(*reference.brdf, *material, samples) + 0.001) << reference.BriefReport();
  // The material file loads back as a material.
  const nlohmann::json json = FitMaterialJson(fit, "bluepaint-fit", "linear sRGB (D65)");
  EXPECT_EQ(json["colour_space"], "linear sRGB (D65)");
  EXPECT_EQ(MaterialFromJson(json, "fit")->ModelName(), "lafortune");
  EXPECT_EQ(FitMaterialJson(fit, "bluepaint-fit")["colour_space"], "unknown (not stated with the samples)");
}

// The reconstruct stage carries the samples' colour space (their sidecar's "colour_space") into
// lafortune.json, ggx.json and both renderer snippets, which warn for camera RGB.
TEST(ModelFit, FitOutputsStateTheSamplesColourSpace) {
  const auto material = LoadMaterial(MaterialPath("glossy-ggx"));
  const auto samples = testing::SessionSamples(*material, CameraEffects::None(), 4, 120, 90);
  testing::ScratchDir dir;
  const std::string samples_file = dir / "samples.npy";
  WriteSamples(samples_file, samples);
  const std::string space = "camera RGB, linear (the session's response inverted, black level subtracted)";
  WriteJsonFile(SidecarPath(samples_file), {{"colour_space", space}});
  ReconstructOptions options;
  options.fit.max_samples = 2000;
  options.bsdf = false;
  options.name = "squash";
  ASSERT_TRUE(Reconstruct(samples, options, dir / "out", samples_file).fitted);
  for (const char* file : {"lafortune.json", "ggx.json"}) {
    const nlohmann::json json = ReadJsonFile(dir / "out" + "/" + file);
    EXPECT_EQ(json.at("colour_space"), space) << file;
    EXPECT_NO_THROW(LoadMaterial(dir / "out" + "/" + file)) << file;
  }
  for (const char* file : {"squash.pbrt", "squash.xml"}) {
    std::ifstream in(dir / "out" + "/" + file);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("Colour space of the values: " + space), std::string::npos) << file << "\n" << text;
    EXPECT_NE(text.find("WARNING: not linear sRGB"), std::string::npos) << file << "\n" << text;
  }
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
  EXPECT_NE(snippets.pbrt.find("\"string type\" \"mix\""), std::string::npos) << snippets.pbrt;
  EXPECT_NE(snippets.mitsuba.find("<bsdf type=\"twosided\" id=\"m\">"), std::string::npos) << snippets.mitsuba;
  EXPECT_NE(snippets.mitsuba.find("<bsdf type=\"blendbsdf\">"), std::string::npos) << snippets.mitsuba;
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

// The truths the plausibility test fits: every bundled material, the seed paper's materials as
// published Lafortune fits (../shared/data; skipped with a message where absent) and synthetic truths
// with broad lobes.
std::vector<std::pair<std::string, std::unique_ptr<BrdfModel>>> PlausibilityTruths() {
  namespace fs = std::filesystem;
  std::vector<std::pair<std::string, std::unique_ptr<BrdfModel>>> truths;
  std::vector<fs::path> bundled;
  for (const auto& entry : fs::directory_iterator(fs::path(IBRDF_SAMPLES_DIR) / "materials")) {
    if (entry.path().extension() == ".json") bundled.push_back(entry.path());
  }
  std::sort(bundled.begin(), bundled.end());
  for (const fs::path& path : bundled) truths.emplace_back(path.stem().string(), LoadMaterial(path.string()));
  const std::string cornell = std::string(IBRDF_SHARED_DATA_DIR) + "/materials/cornell-lafortune.json";
  if (fs::is_regular_file(cornell)) {
    const nlohmann::json file = ReadJsonFile(cornell);
    for (const auto& [name, m] : file.at("materials").items()) {
      std::vector<LafortuneLobe> lobes;
      for (const auto& lobe : m.at("lobes")) {
        const auto v = [&](const char* key) {
          return Eigen::Vector3d(lobe.at(key)[0], lobe.at(key)[1], lobe.at(key)[2]);
        };
        lobes.push_back({v("Cxy"), v("Cz"), v("n")});
      }
      const auto& d = m.at("diffuse");
      truths.emplace_back("cornell-" + name,
                          std::make_unique<LafortuneBrdf>(Eigen::Vector3d(d[0], d[1], d[2]), std::move(lobes)));
    }
  } else {
    std::printf("SKIPPED the seed paper's materials: %s is absent\n", cornell.c_str());
  }
  const auto lobe = [](double cxy, double cz, double n) {
    return LafortuneLobe{Eigen::Vector3d::Constant(cxy), Eigen::Vector3d::Constant(cz), Eigen::Vector3d::Constant(n)};
  };
  truths.emplace_back("broad-lafortune", std::make_unique<LafortuneBrdf>(
                                             Eigen::Vector3d::Constant(0.3),
                                             std::vector<LafortuneLobe>{lobe(0.5, 0.5, 2.0), lobe(-0.5, 0.5, 3.0)}));
  truths.emplace_back("broad-forward-lafortune",
                      std::make_unique<LafortuneBrdf>(Eigen::Vector3d(0.25, 0.2, 0.15),
                                                      std::vector<LafortuneLobe>{lobe(-0.7, 0.7, 4.0)}));
  truths.emplace_back("broad-retro-lafortune",
                      std::make_unique<LafortuneBrdf>(Eigen::Vector3d(0.1, 0.15, 0.2),
                                                      std::vector<LafortuneLobe>{lobe(0.75, 0.75, 3.0)}));
  truths.emplace_back("broad-ggx", std::make_unique<GgxBrdf>(Eigen::Vector3d(0.3, 0.25, 0.2),
                                                             Eigen::Vector3d::Constant(0.04), 0.6));
  truths.emplace_back("broad-metal-ggx", std::make_unique<GgxBrdf>(Eigen::Vector3d::Zero(),
                                                                   Eigen::Vector3d(0.9, 0.7, 0.5), 0.45));
  return truths;
}

// The worst ratio of `fit` over `truth` (over) and of truth over fit (under) at retro-reflection
// (w_i = w_o at phi 0.3), per channel, at theta from `from_deg` to `to_deg` degrees every `step_deg`.
std::pair<double, double> RetroRatios(const BrdfModel& fit, const BrdfModel& truth, double from_deg, double to_deg,
                                      double step_deg) {
  double over = 0.0, under = 0.0;
  for (double theta_deg = from_deg; theta_deg <= to_deg + 1e-9; theta_deg += step_deg) {
    const Eigen::Vector3d w = FromSpherical(theta_deg * M_PI / 180.0, 0.3);
    const Eigen::Vector3d f = fit.Eval(w, w), t = truth.Eval(w, w);
    for (int c = 0; c < 3; ++c) {
      over = std::max(over, f[c] / t[c]);
      under = std::max(under, t[c] / f[c]);
    }
  }
  return {over, under};
}

// On every truth of PlausibilityTruths (sessions of 10 photos at 200 x 150, no camera noise, 4000
// samples; the cameras start 8 degrees from the light and the samples stop at 80 degrees, so no sample
// is at retro-reflection and none beyond 80): every plausible fit's directional albedo is at most 1 and
// its retro-reflection at most 3x the truth up to 89 degrees; the fit the stage would choose (the
// plausible one of lower error) exists and is within 3x of the truth both ways there. The felt's narrow
// grazing retro-reflection (1.5 /sr at 89 degrees, 15 times its largest sample) is kept by a lobe at the
// 1 /sr floor of the lobe cap. Prints each truth's figures (docs/reconstruct.md).
TEST(ModelFitPlausibility, FitsArePlausibleWhereNoCameraLooked) {
  std::printf("%-24s %-9s %8s %8s %8s %10s %10s %7s %7s\n", "truth", "chosen", "rel.rms", "albedoL", "albedoG",
              "retro<=80", "retro85-89", "beside", "fits_s");
  for (const auto& [name, truth] : PlausibilityTruths()) {
    ASSERT_LE(MaxDirectionalAlbedo(*truth), 1.0) << name << ": the truth itself must be plausible";
    const auto samples = testing::SessionSamples(*truth, CameraEffects::None(), 10, 200, 150);
    ModelFitOptions options;
    options.max_samples = 4000;
    const ModelFitResult lafortune = FitLafortune(samples, options), ggx = FitGgx(samples, options);
    const ModelFitResult* chosen = nullptr;
    for (const ModelFitResult* fit : {&lafortune, &ggx}) {
      ASSERT_TRUE(fit->success);
      EXPECT_NEAR(fit->max_albedo, MaxDirectionalAlbedo(*fit->brdf), 1e-12);
      if (!fit->plausible) continue;
      if (!chosen || fit->rel_rms < chosen->rel_rms) chosen = fit;
      EXPECT_LE(fit->max_albedo, 1.0) << name << " " << fit->BriefReport();
      const auto [over, under] = RetroRatios(*fit->brdf, *truth, 0.0, 89.0, 1.0);
      EXPECT_LE(over, 3.0) << name << " " << fit->BriefReport() << "\n" << fit->brdf->ToJson().dump();
    }
    ASSERT_NE(chosen, nullptr) << name << ": neither fit is plausible\n"
                               << lafortune.BriefReport() << "\n"
                               << ggx.BriefReport();
    const auto [over, under] = RetroRatios(*chosen->brdf, *truth, 0.0, 89.0, 1.0);
    EXPECT_LE(under, 3.0) << name << " " << chosen->BriefReport() << "\n" << chosen->brdf->ToJson().dump();
    if (name == "felt") {  // its retro lobe is held at the cap, and says so
      EXPECT_NE(lafortune.BriefReport().find("held by the lobe cap (max(|Cxy|, |Cz|)^n at it): lobe"),
                std::string::npos)
          << lafortune.BriefReport();
    }
    const auto near = RetroRatios(*chosen->brdf, *truth, 0.0, 80.0, 1.0);
    const auto grazing = RetroRatios(*chosen->brdf, *truth, 85.0, 89.0, 1.0);
    std::printf("%-24s %-9s %7.2f%% %8.3f %8.3f %4.2f/%4.2f %4.2f/%4.2f %7.2f %7.1f\n", name.c_str(),
                chosen->model.c_str(), 100.0 * chosen->rel_rms, lafortune.max_albedo, ggx.max_albedo, near.first,
                near.second, grazing.first, grazing.second, chosen->max_retro_ratio, lafortune.seconds + ggx.seconds);
    for (const ModelFitResult* fit : {&lafortune, &ggx}) {
      for (const std::string& held : fit->held_by_plausibility) std::printf("  %s: %s\n", fit->model.c_str(), held.c_str());
      for (const std::string& why : fit->implausible) std::printf("  %s rejected: %s\n", fit->model.c_str(), why.c_str());
    }
  }
}

// A dark material with one sharp mirror lobe, photographed with camera noise: without the plausibility
// constraints the Lafortune fit grows a retro-reflection lobe (Cxy 1.002, Cz 0.70, n 463 in red) that
// no sample sees, 5 times the truth at 80 degrees and 268 times at 89; with them it stays within 3
// times of the truth at retro-reflection up to 89 degrees, and is the fit chosen.
TEST(ModelFitPlausibility, ARetroReflectionSpikeIsHeldByTheCeiling) {
  const LafortuneBrdf truth(Eigen::Vector3d(0.03, 0.03, 0.04),
                            {LafortuneLobe{Eigen::Vector3d::Constant(-1.0), Eigen::Vector3d::Constant(1.0),
                                           Eigen::Vector3d::Constant(300.0)}});
  const auto samples = testing::SessionSamples(truth, CameraEffects(), 20, 200, 150);
  ModelFitOptions options;
  ModelFitOptions unconstrained = options;
  unconstrained.plausibility_constraints = false;
  const ModelFitResult spiking = FitLafortune(samples, unconstrained);
  EXPECT_GT(RetroRatios(*spiking.brdf, truth, 0.0, 89.0, 1.0).first, 10.0) << spiking.BriefReport();
  const ModelFitResult lafortune = FitLafortune(samples, options), ggx = FitGgx(samples, options);
  ASSERT_TRUE(lafortune.plausible) << lafortune.BriefReport();
  const auto [over, under] = RetroRatios(*lafortune.brdf, truth, 0.0, 89.0, 1.0);
  EXPECT_LE(over, 3.0) << lafortune.BriefReport() << "\n" << lafortune.brdf->ToJson().dump();
  EXPECT_LE(under, 3.0) << lafortune.BriefReport() << "\n" << lafortune.brdf->ToJson().dump();
  EXPECT_LE(lafortune.max_retro_ratio, options.max_unmeasured_ratio * (1.0 + options.plausibility_tolerance));
  EXPECT_LT(lafortune.rel_rms, ggx.rel_rms) << ggx.BriefReport();
  if (ggx.plausible) {
    EXPECT_LE(RetroRatios(*ggx.brdf, truth, 0.0, 89.0, 1.0).first, 3.0) << ggx.BriefReport();
  }
  std::printf("retro spike: unconstrained Lafortune %.1f x the truth, constrained %.2f / %.2f (over / under)\n",
              RetroRatios(*spiking.brdf, truth, 0.0, 89.0, 1.0).first, over, under);
}

}  // namespace
}  // namespace ibrdf
