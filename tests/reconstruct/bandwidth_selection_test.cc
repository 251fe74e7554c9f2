// Bandwidth selection: leverage and the GCV identity on a case with a closed form, and LOO / GCV
// against the true error of a grid of kernels on a noisy synthetic session.
#include "reconstruct/bandwidth_selection.h"

#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "reconstruct/reconstruction_error.h"
#include "tests/reconstruct/reconstruct_test_util.h"

namespace ibrdf {
namespace {

using testing::MaterialPath;
using testing::SessionSamples;

TEST(BandwidthSelection, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(BandwidthSelectionOptions().Check(&why)) << why;
  BandwidthSelectionOptions bad;
  bad.scales = {};
  EXPECT_FALSE(bad.Check(&why));
  bad.scales = {1.0, -2.0};
  EXPECT_FALSE(bad.Check(&why));
  BandwidthCriterion criterion;
  EXPECT_TRUE(ParseBandwidthCriterion("gcv", &criterion));
  EXPECT_EQ(criterion, BandwidthCriterion::kGeneralizedCrossValidation);
  EXPECT_FALSE(ParseBandwidthCriterion("aic", &criterion));
}

BrdfSample SampleAt(const HalfDiffAngles& angles, double value) {
  Eigen::Vector3d wi, wo;
  FromHalfDiff(angles, &wi, &wo);
  BrdfSample s{};
  for (int k = 0; k < 3; ++k) {
    s.wi[k] = float(wi[k]);
    s.wo[k] = float(wo[k]);
    s.brdf[k] = float(value);
  }
  return s;
}

// Local constant fit without binning: the leverage of a sample is its own weight w(0) = 1 over the
// sum of weights, and for a linear smoother the leave-one-out residual is r_i / (1 - l_ii) exactly.
TEST(BandwidthSelection, LeverageOfALocalConstantFit) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> theta_h(0.2, 0.6), theta_d(0.3, 0.7), phi_d(0.3, 1.2);
  std::normal_distribution<double> noise(0.0, 0.05);
  std::vector<BrdfSample> samples;
  for (int i = 0; i < 3000; ++i) {
    HalfDiffAngles a;
    a.theta_h = theta_h(rng);
    a.theta_d = theta_d(rng);
    a.phi_d = phi_d(rng);
    samples.push_back(SampleAt(a, std::exp(noise(rng))));
  }
  LocalRegressionOptions options;
  options.degree = 0;
  options.bin_fraction_h = options.bin_fraction_d = 0.0;
  options.fold_reciprocity = options.fold_bilateral = false;
  options.range_margin = 1e9;
  const LocalRegression regression(samples, options);
  const CrossValidationScore score = regression.CrossValidate(400);
  ASSERT_EQ(score.points, 400u);
  EXPECT_GT(score.mean_leverage, 0.0);
  EXPECT_LT(score.mean_leverage, 0.2);
  // With leverages this small, LOO and GCV agree to within a few per cent and exceed the residual.
  EXPECT_GT(score.loo_rms, score.residual_rms);
  EXPECT_GT(score.gcv_rms, score.residual_rms);
  EXPECT_NEAR(score.loo_rms, score.gcv_rms, 0.05 * score.gcv_rms);
  // The noise is 0.05 in log f: both estimate it (plus a little bias).
  EXPECT_NEAR(score.gcv_rms, 0.05, 0.01);
}

// On a noisy bluepaint session, the true error over the MERL cells has its minimum inside the grid
// (small kernels: noise; large kernels: the lobe is smoothed). LOO and GCV pick kernels whose true
// error is within 1.5 times the best of the grid.
TEST(BandwidthSelection, LooAndGcvPickNearTheBestKernel) {
  const auto material = LoadMaterial(MaterialPath("bluepaint"));
  const auto samples = SessionSamples(*material, CameraEffects(), 10, 200, 150);
  BandwidthSelectionOptions options;
  options.scales = {0.5, 1.0, 2.0, 4.0};
  options.samples = 1500;
  std::vector<double> truth_error;
  for (double scale : options.scales) {
    LocalRegressionOptions trial;
    trial.radius_h_deg *= scale;
    trial.radius_d_deg *= scale;
    const ReconstructionError error = CompareRegressionWithTruth(LocalRegression(samples, trial), *material, 80.0, 4);
    std::printf("scale %.2f: %s\n", scale, error.Brief().c_str());
    truth_error.push_back(error.coverage() > 0.9 ? error.rel_rms_all : 1e9);
  }
  const double best = *std::min_element(truth_error.begin(), truth_error.end());
  EXPECT_LT(best, truth_error.front());
  EXPECT_LT(best, truth_error.back());
  for (BandwidthCriterion criterion :
       {BandwidthCriterion::kLeaveOneOut, BandwidthCriterion::kGeneralizedCrossValidation}) {
    options.criterion = criterion;
    const BandwidthSelection selection = SelectBandwidth(samples, LocalRegressionOptions(), options);
    ASSERT_TRUE(selection.success);
    ASSERT_EQ(selection.curve.size(), options.scales.size());
    std::printf("%s\n%s", selection.BriefReport().c_str(), selection.CurveTable().c_str());
    EXPECT_LE(truth_error[selection.best], 1.5 * best) << BandwidthCriterionName(criterion);
    EXPECT_DOUBLE_EQ(selection.selected.radius_h_deg,
                     LocalRegressionOptions().radius_h_deg * options.scales[selection.best]);
  }
}

}  // namespace
}  // namespace ibrdf
