// The regression's stated standard errors (Estimate::standard_error, reconstruct/local_regression.cc
// StandardErrors): the noise part falls as 1 / sqrt(photos) on noise-only data, the bias part grows at
// a peak narrower than the kernel, and on a synthetic session the 2-sigma band covers the measured
// cells' true errors as documented (docs/reconstruct.md, "Per-cell uncertainty").
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "core/math.h"
#include "reconstruct/local_regression.h"
#include "reconstruct/merl_table.h"
#include "reconstruct/reconstruction_error.h"
#include "tests/reconstruct/reconstruct_test_util.h"

namespace ibrdf {
namespace {

using testing::MaterialPath;
using testing::SessionSamples;

BrdfSample MakeSample(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo, double value) {
  BrdfSample s{};
  for (int k = 0; k < 3; ++k) {
    s.wi[k] = float(wi[k]);
    s.wo[k] = float(wo[k]);
    s.brdf[k] = float(value);
    s.valid[k] = 1;
  }
  const IsotropicAngles angles = ToIsotropic(wi, wo);
  s.theta_i = float(angles.theta_i);
  s.theta_e = float(angles.theta_e);
  s.delta_phi = float(angles.delta_phi);
  return s;
}

// `photos` noisy copies (lognormal, `noise` in log units) of one set of random direction pairs: each
// copy is what another photo of the same geometry would give.
std::vector<BrdfSample> NoisyConstant(int photos, double noise, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> theta(0.1, 1.2), phi(-M_PI, M_PI);
  std::normal_distribution<double> gauss(0.0, noise);
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> pairs;
  std::mt19937_64 geometry(7);
  for (int i = 0; i < 40000; ++i) {
    pairs.push_back({FromSpherical(theta(geometry), phi(geometry)), FromSpherical(theta(geometry), phi(geometry))});
  }
  std::vector<BrdfSample> samples;
  for (int p = 0; p < photos; ++p) {
    for (const auto& [wi, wo] : pairs) samples.push_back(MakeSample(wi, wo, 0.3 * std::exp(gauss(rng))));
  }
  return samples;
}

std::vector<Eigen::Vector3d> QueryPoints() {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> theta(0.3, 1.0), phi(-M_PI, M_PI);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 300; ++i) points.push_back(RegressionCoordinates(FromSpherical(theta(rng), phi(rng)),
                                                                       FromSpherical(theta(rng), phi(rng))));
  return points;
}

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

TEST(Uncertainty, NoiseOnlyShrinksAsOneOverSqrtPhotos) {
  const std::vector<Eigen::Vector3d> points = QueryPoints();
  double median_se[2] = {0, 0};
  const int photos[2] = {1, 4};
  for (int k = 0; k < 2; ++k) {
    const LocalRegression regression(NoisyConstant(photos[k], 0.05, 3 + k), LocalRegressionOptions());
    std::vector<double> errors;
    size_t covered = 0, scored = 0;
    for (const Estimate& e : regression.EvaluateMany(points, nullptr)) {
      // The noise term alone: fits of the requested degree (a reduced one adds a conservative bias).
      if (e.status != EstimateStatus::kFull) continue;
      ASSERT_TRUE(std::isfinite(e.standard_error[0]));
      errors.push_back(e.standard_error[0]);
      // The truth is 0.3 everywhere: the 2-sigma band should cover the error about 95 % of the time.
      covered += std::abs(std::log(e.value[0] / 0.3)) <= 2.0 * e.standard_error[0];
      ++scored;
    }
    ASSERT_GT(scored, 150u);
    median_se[k] = Median(errors);
    const double coverage = double(covered) / double(scored);
    // The band of docs/reconstruct.md at 4 photos; with one photo (a few samples per kernel) the stated
    // error is conservative (measured 99.6 %), so only its lower bound is asserted.
    std::printf("%d photo(s): median standard error %.4f %%, 2-sigma coverage %.1f %% (bound %s)\n", photos[k],
                100.0 * median_se[k], 100.0 * coverage, photos[k] == 1 ? ">= 90 %" : "90-98 %");
    EXPECT_GE(coverage, 0.90);
    if (photos[k] > 1) {
      EXPECT_LE(coverage, 0.98);
    }
  }
  // Four times the photos: half the standard error (1 / sqrt(4)).
  EXPECT_NEAR(median_se[0] / median_se[1], 2.0, 0.3);
}

TEST(Uncertainty, GrowsAtASharpPeak) {
  // A lobe of 1 degree (a tenth of the kernel's 2.5-degree radius along the sheets) on a constant
  // base, nearly noise-free: the fit under-reaches the peak (bias, not noise).
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> theta(0.0, 1.2), phi(-M_PI, M_PI);
  std::normal_distribution<double> gauss(0.0, 0.002);
  const double width = 1.0 * kDegree;
  auto truth = [width](const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) {
    HalfDiffAngles a;
    ToHalfDiff(wi, wo, &a);
    return 0.1 + 20.0 * std::exp(-0.5 * a.theta_h * a.theta_h / (width * width));
  };
  std::vector<BrdfSample> samples;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int i = 0; i < 100000; ++i) {
    // Camera directions within 12 degrees of the mirror direction (theta_h up to about 6 degrees),
    // uniform over that disk, and a few over the hemisphere.
    const Eigen::Vector3d wi = FromSpherical(0.2 + 0.4 * unit(rng), phi(rng));
    const Eigen::Vector3d mirror(-wi.x(), -wi.y(), wi.z());
    const Eigen::Vector3d t1 = mirror.cross(Eigen::Vector3d::UnitZ()).normalized(), t2 = mirror.cross(t1);
    const double r = 12.0 * kDegree * std::sqrt(unit(rng)), a = 2.0 * M_PI * unit(rng);
    const Eigen::Vector3d wo = i % 10 ? (mirror + r * (std::cos(a) * t1 + std::sin(a) * t2)).normalized()
                                      : FromSpherical(theta(rng), phi(rng));
    if (wo.z() < 0.05) continue;
    samples.push_back(MakeSample(wi, wo, truth(wi, wo) * std::exp(gauss(rng))));
  }
  const LocalRegression regression(samples, LocalRegressionOptions());
  const Eigen::Vector3d wi = FromSpherical(0.4, 0.0);
  const Eigen::Vector3d peak(-wi.x(), -wi.y(), wi.z());
  const Eigen::Vector3d away = FromSpherical(0.4 + 16.0 * kDegree, M_PI);  // theta_h 8 degrees, on the base
  const Estimate at_peak = regression.Evaluate(wi, peak), off_peak = regression.Evaluate(wi, away);
  ASSERT_NE(at_peak.status, EstimateStatus::kUnsupported);
  ASSERT_NE(off_peak.status, EstimateStatus::kUnsupported);
  const double error = std::abs(std::log(at_peak.value[0] / truth(wi, peak)));
  std::printf("peak: estimate %.3f, truth %.3f (error %.2f %%), standard error %.2f %%; off the peak %.3f %%\n",
              at_peak.value[0], truth(wi, peak), 100.0 * error, 100.0 * at_peak.standard_error[0],
              100.0 * off_peak.standard_error[0]);
  EXPECT_GT(at_peak.standard_error[0], 10.0 * off_peak.standard_error[0]);
  EXPECT_LE(error, 2.0 * at_peak.standard_error[0]) << "the peak's error is outside its 2-sigma band";
}

// A 10-photo bluepaint session at 400 x 300 with the default camera: the measured cells' true errors
// fall within 2 standard errors for 90-98 % of the cell channels (measured 91.5 %, scripts/
// bench-uncertainty); halving the stated errors loses the band (the test can fail).
TEST(Uncertainty, TwoSigmaBandCoversMeasuredCellsOfATenPhotoSession) {
  const auto truth = LoadMaterial(MaterialPath("bluepaint"));
  const auto samples = SessionSamples(*truth, CameraEffects(), 10);
  const LocalRegression regression(samples, LocalRegressionOptions());
  TabulateSummary summary;
  std::vector<uint8_t> domain;
  std::vector<float> uncertainty;
  const MerlTable table =
      TabulateMerl(regression, TabulateOptions(), &summary, nullptr, &domain, nullptr, &uncertainty);
  const UncertaintyCoverage coverage =
      CompareUncertaintyWithTruth(table, uncertainty, domain, uint8_t(DomainClass::kMeasured), *truth);
  std::vector<float> halved = uncertainty;
  for (float& u : halved) u = u > 0.0f ? 0.5f * u : u;
  const UncertaintyCoverage half =
      CompareUncertaintyWithTruth(table, halved, domain, uint8_t(DomainClass::kMeasured), *truth);
  std::printf("measured cells: %s (bound 90-98 %%); with the errors halved %.1f %%\n", coverage.Brief().c_str(),
              100.0 * half.within_2sigma);
  ASSERT_GT(coverage.values, 100000u);
  EXPECT_GE(coverage.within_2sigma, 0.90);
  EXPECT_LE(coverage.within_2sigma, 0.98);
  EXPECT_LT(half.within_2sigma, 0.90) << "halved errors would still pass: the test could not fail";
}

}  // namespace
}  // namespace ibrdf
