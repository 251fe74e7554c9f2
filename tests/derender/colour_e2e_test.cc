// End to end, by library calls: a synthetic session under a tinted light seen by a camera with its own
// RGB (camera = M * linear sRGB) and a chart photo -> the chart fit -> derender -> samples in linear
// sRGB within 1 % of the true BRDF (the colour must-show, small). Without the correction the
// samples are far off (the control that shows the check can fail).
#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "calibrate/colour_chart.h"
#include "core/brdf_model.h"
#include "core/statistics.h"
#include "derender/derenderer.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

SynthOptions TintedOptions(bool noise) {
  SynthOptions options;
  options.rig.width = 400;
  options.rig.height = 300;
  options.rig.num_photos = 4;
  if (!noise) options.effects = CameraEffects::None();
  options.scene.light_intensity = Eigen::Vector3d(1.0, 0.8, 0.55);
  options.colour.camera_matrix << 0.6, 0.3, 0.1, 0.1, 0.75, 0.15, 0.05, 0.2, 0.75;
  options.colour.chart = true;
  return options;
}

// Per channel: the median relative error |f / f_true - 1| and the median signed one.
struct ChannelErrors {
  Eigen::Vector3d median_abs, median_signed;
};

ChannelErrors Errors(const std::vector<BrdfSample>& samples, const BrdfModel& truth) {
  std::vector<double> abs_errors[3], signed_errors[3];
  for (const BrdfSample& s : samples) {
    const Eigen::Vector3d f = truth.Eval(Eigen::Vector3d(s.wi[0], s.wi[1], s.wi[2]).cast<double>(),
                                         Eigen::Vector3d(s.wo[0], s.wo[1], s.wo[2]).cast<double>());
    for (int c = 0; c < 3; ++c) {
      const double e = s.brdf[c] / f[c] - 1.0;
      abs_errors[c].push_back(std::abs(e));
      signed_errors[c].push_back(e);
    }
  }
  ChannelErrors errors;
  for (int c = 0; c < 3; ++c) {
    errors.median_abs[c] = PercentileInPlace(&abs_errors[c], 0.5);
    errors.median_signed[c] = PercentileInPlace(&signed_errors[c], 0.5);
  }
  return errors;
}

// Fits the chart, stores the matrix and derenders.
std::vector<BrdfSample> CorrectedSamples(const Session& session) {
  Session corrected = session;
  const ColourChartFit fit = FitColourChart(session, *session.colour_chart->corners, {}, "test");
  EXPECT_EQ(fit.used, 24) << fit.BriefReport();
  StoreColourFit(fit, &*corrected.colour_chart);
  DerenderResult result = Derender(corrected, DerenderOptions());
  EXPECT_EQ(result.summary.colour_matrices.size(), 1u);
  return result.samples;
}

TEST(ColourE2eTest, CorrectedSamplesAreWithinOnePercentOfTheLinearSrgbTruth) {
  testing::ScratchDir scratch;
  const auto material = LoadMaterial(testing::MaterialPath("bluepaint"));
  const Session session = Session::Load(testing::MakeSession(scratch.str(), TintedOptions(false), *material));
  const std::vector<BrdfSample> samples = CorrectedSamples(session);
  ASSERT_GT(samples.size(), 10000u);
  const ChannelErrors errors = Errors(samples, *material);
  for (int c = 0; c < 3; ++c) EXPECT_LT(errors.median_abs[c], 0.01) << "channel " << c;

  // The control: the same samples left in camera RGB.
  Session uncorrected = session;
  uncorrected.colour_chart.reset();
  const ChannelErrors raw = Errors(Derender(uncorrected, DerenderOptions()).samples, *material);
  EXPECT_GT(raw.median_abs.maxCoeff(), 0.05) << raw.median_abs.transpose();
}

TEST(ColourE2eTest, WithSensorNoiseTheCorrectedSamplesAreUnbiased) {
  testing::ScratchDir scratch;
  const auto material = LoadMaterial(testing::MaterialPath("bluepaint"));
  const Session session = Session::Load(testing::MakeSession(scratch.str(), TintedOptions(true), *material));
  const ChannelErrors errors = Errors(CorrectedSamples(session), *material);
  for (int c = 0; c < 3; ++c) EXPECT_LT(std::abs(errors.median_signed[c]), 0.01) << "channel " << c;
}

}  // namespace
}  // namespace ibrdf
