// The local regression's bias at a sharp specular peak: exact (noise-free) GGX values on the sample
// geometry of a sphere session, regressed with the default kernel and with the kernel bandwidth
// selection picks, against the model at the samples' own directions at and near the peak. Noise-free
// values leave only the kernel's smoothing bias, which grows with the kernel's radius along the sheets
// against the peak's width.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/brdf_coords.h"
#include "core/brdf_model.h"
#include "core/math.h"
#include "reconstruct/bandwidth_selection.h"
#include "reconstruct/local_regression.h"
#include "tests/reconstruct/reconstruct_test_util.h"

namespace ibrdf {
namespace {

// A glossy GGX plastic (F0 0.04, diffuse 0.1) of roughness `alpha`: its peak stands 10 to 40 times
// above the diffuse floor.
std::unique_ptr<BrdfModel> GgxMaterial(double alpha) {
  return MaterialFromJson(
      {{"model", "ggx"}, {"diffuse_albedo", {0.1, 0.1, 0.1}}, {"specular_f0", {0.04, 0.04, 0.04}}, {"alpha", alpha}},
      "sharp GGX test material");
}

Eigen::Vector3d Wi(const BrdfSample& s) { return Eigen::Vector3f(s.wi[0], s.wi[1], s.wi[2]).cast<double>(); }
Eigen::Vector3d Wo(const BrdfSample& s) { return Eigen::Vector3f(s.wo[0], s.wo[1], s.wo[2]).cast<double>(); }

// The directions of a noise-free sphere session (20 photos at 800 x 600 pixels, the default rig) of
// a Lambertian sphere (no pixel clipped, so the peak has every sample), made once, with the exact values
// of `material` at each sample's own directions.
std::vector<BrdfSample> ExactSamples(const BrdfModel& material) {
  static const std::vector<BrdfSample> geometry = [] {
    return testing::SessionSamples(LambertianBrdf(Eigen::Vector3d::Constant(0.5)), CameraEffects::None(), 20, 800, 600);
  }();
  std::vector<BrdfSample> samples = geometry;
  for (BrdfSample& s : samples) {
    const Eigen::Vector3d f = material.Eval(Wi(s), Wo(s));
    for (int c = 0; c < 3; ++c) {
      s.brdf[c] = float(f[c]);
      s.sigma[c] = 0.0f;
      s.valid[c] = 1;
    }
  }
  return samples;
}

// The regression against the model at every 4th sample of a band of theta_h (neighbours share their
// kernel, so this loses nothing), split into the interior sheets and the two sheets at the ends of the
// samples' theta_d range (within 1 degree of it: the photos with camera and light closest together and
// the grazing one), where the kernel, long in theta_d, reaches past the data on one side.
struct BandErrors {
  double interior_worst = 0.0, interior_median = 0.0, edge_worst = 0.0;  // relative errors
  size_t interior = 0, edge = 0;                                         // samples compared
};

BandErrors ErrorsInBand(const LocalRegression& regression, const BrdfModel& material,
                        const std::vector<BrdfSample>& samples, double from, double to) {
  constexpr double kEdge = 1.0 * kDegree;
  std::vector<double> interior;
  BandErrors band;
  size_t seen = 0;
  for (const BrdfSample& s : samples) {
    HalfDiffAngles angles;
    if (!ToHalfDiff(Wi(s).normalized(), Wo(s).normalized(), &angles)) continue;
    if (angles.theta_h < from || angles.theta_h >= to || seen++ % 4 != 0) continue;
    const double truth = material.Eval(Wi(s), Wo(s))[0];
    const double error = std::abs(regression.Evaluate(Wi(s), Wo(s)).value[0] / truth - 1.0);
    if (angles.theta_d < regression.theta_d_min() + kEdge || angles.theta_d > regression.theta_d_max() - kEdge) {
      band.edge_worst = std::max(band.edge_worst, error);
      ++band.edge;
    } else {
      interior.push_back(error);
    }
  }
  band.interior = interior.size();
  if (!interior.empty()) {
    band.interior_worst = *std::max_element(interior.begin(), interior.end());
    std::nth_element(interior.begin(), interior.begin() + interior.size() / 2, interior.end());
    band.interior_median = interior[interior.size() / 2];
  }
  return band;
}

// The peak itself (theta_h below alpha / 4) and near it (alpha / 4 to alpha, where the value has fallen
// to a quarter of the peak's).
struct PeakErrors {
  BandErrors at, near;
};

PeakErrors MeasurePeak(double alpha, const LocalRegressionOptions& options, const char* kernel) {
  const auto material = GgxMaterial(alpha);
  const std::vector<BrdfSample> samples = ExactSamples(*material);
  const LocalRegression regression(samples, options);
  const PeakErrors errors{ErrorsInBand(regression, *material, samples, 0.0, 0.25 * alpha),
                          ErrorsInBand(regression, *material, samples, 0.25 * alpha, alpha)};
  for (const auto& [name, band] : {std::make_pair("at the peak", errors.at), std::make_pair("near it", errors.near)}) {
    std::printf("alpha %.2f, %s kernel (radius_h %.2f deg, radius_d %.2f deg), %s: interior sheets median %.2f %%, "
                "worst %.2f %% (%zu samples); end sheets worst %.2f %% (%zu samples)\n",
                alpha, kernel, options.radius_h_deg, options.radius_d_deg, name, 100.0 * band.interior_median,
                100.0 * band.interior_worst, band.interior, 100.0 * band.edge_worst, band.edge);
  }
  EXPECT_GT(errors.at.interior, 50u);
  EXPECT_GT(errors.near.interior, 500u);
  EXPECT_GT(errors.at.edge, 5u);
  return errors;
}

// The default kernel (radius 2.5 degrees along the sheets) meets 2 % at alpha 0.1 (measured: worst
// 0.51 % at the peak, 0.38 % near it on the interior sheets; 1.13 % on the end sheets). At alpha 0.05
// it misses 2 %: the peak is flattened by 2.6 % (median over the interior sheets; worst 3.3 %, 2.7 %
// near it) and the end sheets reach 5.9 %; asserted is what holds, with a margin of a fifth.
TEST(RegressionBias, DefaultKernelAtASharpGgxPeak) {
  const PeakErrors sharp = MeasurePeak(0.05, LocalRegressionOptions(), "default");
  EXPECT_LT(sharp.at.interior_median, 0.031);
  EXPECT_LT(sharp.at.interior_worst, 0.04);
  EXPECT_LT(sharp.near.interior_worst, 0.033);
  EXPECT_LT(std::max(sharp.at.edge_worst, sharp.near.edge_worst), 0.071);
  const PeakErrors wide = MeasurePeak(0.1, LocalRegressionOptions(), "default");
  EXPECT_LT(wide.at.interior_worst, 0.02);
  EXPECT_LT(wide.near.interior_worst, 0.02);
  EXPECT_LT(std::max(wide.at.edge_worst, wide.near.edge_worst), 0.02);
}

// The kernel leave-one-out picks on these noise-free samples (0.7 times the default) meets 2 % on the
// interior sheets at both roughnesses (measured worst: 1.18 % at the peak and 0.97 % near it at alpha
// 0.05; 0.19 % and 0.15 % at 0.1). On the grazing end sheet (theta_d 79 degrees, where its shorter
// reach across the sheets finds data on one side only) it misses: 8.8 % at alpha 0.05, 2.5 % at 0.1;
// asserted is what holds, with a margin of a fifth.
TEST(RegressionBias, SelectedKernelAtASharpGgxPeak) {
  for (const double alpha : {0.05, 0.1}) {
    SCOPED_TRACE("alpha " + std::to_string(alpha));
    const auto material = GgxMaterial(alpha);
    const BandwidthSelection selection =
        SelectBandwidth(ExactSamples(*material), LocalRegressionOptions(), BandwidthSelectionOptions());
    ASSERT_TRUE(selection.success);
    const PeakErrors errors = MeasurePeak(alpha, selection.selected, "selected");
    EXPECT_LT(errors.at.interior_worst, 0.02);
    EXPECT_LT(errors.near.interior_worst, 0.02);
    EXPECT_LT(std::max(errors.at.edge_worst, errors.near.edge_worst), alpha < 0.07 ? 0.106 : 0.03);
  }
}

}  // namespace
}  // namespace ibrdf
