// Tests of calibrate/colour_chart.h: the patch layout from the corner patches, the light-balanced
// sample matrix, and the chart fit on synthetic chart photos (synth/synthetic_colour_chart.h) with a
// known camera matrix and light tint: residuals, clipped patches left out and said, too few patches.
#include "calibrate/colour_chart.h"

#include <cmath>

#include <gtest/gtest.h>

#include "core/brdf_model.h"
#include "core/error.h"
#include "derender/colour_correction.h"
#include "tests/error_of.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

Eigen::Matrix3d CameraMatrix() {
  Eigen::Matrix3d m;
  m << 0.6, 0.3, 0.1, 0.1, 0.75, 0.15, 0.05, 0.2, 0.75;
  return m;
}
const Eigen::Vector3d kTint(1.0, 0.8, 0.55);

// A small noise-free session with a chart photo under a tinted light, seen by a camera with its own RGB.
SynthOptions ChartOptions() {
  SynthOptions options;
  options.rig.width = 320;
  options.rig.height = 240;
  options.rig.num_photos = 2;
  options.effects = CameraEffects::None();
  options.scene.light_intensity = kTint;
  options.colour.camera_matrix = CameraMatrix();
  options.colour.chart = true;
  return options;
}

TEST(ColourChartTest, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(ColourChartOptions().Check(&why)) << why;
  ColourChartOptions bad;
  bad.min_patches = 2;
  EXPECT_FALSE(bad.Check(&why));
  EXPECT_NE(why.find("min_patches"), std::string::npos) << why;
}

TEST(ColourChartTest, PatchCentresFillTheGridOfAPinholeCamera) {
  const Camera camera = Camera::Create(CameraModelId::kPinhole, 640, 480, {500, 500, 320, 240});
  const std::array<Eigen::Vector2d, 4> corners = {Eigen::Vector2d(100, 100), Eigen::Vector2d(600, 100),
                                                  Eigen::Vector2d(600, 400), Eigen::Vector2d(100, 400)};
  const auto centers = ColourPatchCenters(camera, corners);
  for (int k = 0; k < kColorCheckerPatches; ++k) {
    EXPECT_NEAR(centers[k].x(), 100 + 100 * (k % 6), 1e-6) << k;
    EXPECT_NEAR(centers[k].y(), 100 + 100 * (k / 6), 1e-6) << k;
  }
}

// With the chart's matrix A = k (M diag(s))^-1 of a camera M under a light of sRGB colour s, the
// sample matrix takes the derenderer's camera-RGB BRDF back to the linear-sRGB (or XYZ) BRDF.
TEST(ColourChartTest, SampleMatrixRecoversTheBrdfUnderAnyLightColour) {
  const Eigen::Matrix3d m = CameraMatrix();
  const Eigen::Vector3d chart_light(0.9, 1.0, 0.7), sample_light(1.0, 0.8, 0.55);
  const double brightness = 3.7;
  ColourChartSpec chart;
  chart.matrix = 0.42 * (m * chart_light.asDiagonal()).inverse().eval();
  const Eigen::Vector3d intensity = brightness * m * sample_light;  // the light as the camera states it
  const Eigen::Vector3d f_srgb(0.3, 0.12, 0.05);
  // f_camera = L / (I cos / r^2) per channel, L = M diag(s) f I0 cos / r^2.
  const Eigen::Vector3d f_camera = (brightness * m * sample_light.asDiagonal() * f_srgb).cwiseQuotient(intensity);
  EXPECT_LT((SampleColourMatrix(chart, intensity) * f_camera - f_srgb).norm(), 1e-12);
  // A white diffuser reads 1/pi in every channel.
  EXPECT_LT(
      (SampleColourMatrix(chart, intensity) * Eigen::Vector3d::Constant(1 / M_PI) - Eigen::Vector3d::Constant(1 / M_PI))
          .norm(),
      1e-12);
  chart.space = ColourSpace::kXyz;
  chart.matrix = (XyzFromLinearSrgb() * *chart.matrix).eval();
  EXPECT_LT((SampleColourMatrix(chart, intensity) * f_camera - XyzFromLinearSrgb() * f_srgb).norm(), 1e-12);
}

TEST(ColourChartTest, FitsTheChartOfATintedLightAndACameraMatrix) {
  testing::ScratchDir scratch;
  const auto material = LoadMaterial(testing::MaterialPath("bluepaint"));
  const Session session = Session::Load(testing::MakeSession(scratch.str(), ChartOptions(), *material));
  ASSERT_TRUE(session.colour_chart && session.colour_chart->corners);
  const ColourChartFit fit = FitColourChart(session, *session.colour_chart->corners, {}, "test");
  ASSERT_TRUE(fit.success);
  EXPECT_EQ(fit.used, 24) << fit.BriefReport();
  // Noise-free: what remains is the light's fall-off across the chart (about 1 % side to side).
  EXPECT_LT(fit.rms_residual, 0.01) << fit.BriefReport();
  // The light-balanced matrix is (M diag(tint))^-1 diag(I) / I0 (the sRGB-white light), within 1 %.
  const Eigen::Matrix3d expected =
      (CameraMatrix() * kTint.asDiagonal()).inverse() * session.lights[0].intensity.asDiagonal();
  ColourChartSpec chart = *session.colour_chart;
  StoreColourFit(fit, &chart);
  const Eigen::Matrix3d got = SampleColourMatrix(chart, session.lights[0].intensity);
  EXPECT_LT((got - expected).cwiseAbs().maxCoeff(), 0.01 * expected.cwiseAbs().maxCoeff()) << got << "\n" << expected;
  // The stored fit names every patch.
  ASSERT_EQ(chart.patches.size(), 24u);
  EXPECT_EQ(chart.patches[17].name, "cyan");
}

TEST(ColourChartTest, ClippedPatchesAreLeftOutAndSaid) {
  testing::ScratchDir scratch;
  SynthOptions options = ChartOptions();
  options.colour.chart_exposure_scale = 1.6;  // the white patch's brightest channel at 1.28: clipped
  const auto material = LoadMaterial(testing::MaterialPath("bluepaint"));
  const Session session = Session::Load(testing::MakeSession(scratch.str(), options, *material));
  const ColourChartFit fit = FitColourChart(session, *session.colour_chart->corners, {}, "test");
  ASSERT_TRUE(fit.success);
  EXPECT_LT(fit.used, 24);
  EXPECT_NE(fit.patches[18].excluded.find("clipped"), std::string::npos) << fit.BriefReport();
  EXPECT_NE(fit.BriefReport().find("white 9.5: clipped"), std::string::npos) << fit.BriefReport();
  EXPECT_LT(fit.rms_residual, 0.01) << fit.BriefReport();

  // Far too bright: too few patches is an Error naming the block and what was left out.
  ColourChartOptions strict;
  strict.min_patches = 24;
  const std::string message =
      testing::ErrorOf([&] { FitColourChart(session, *session.colour_chart->corners, strict, "test"); });
  EXPECT_NE(message.find("/colour_chart"), std::string::npos) << message;
  EXPECT_NE(message.find("white 9.5: clipped"), std::string::npos) << message;
}

// The camera's own RGB equal to linear sRGB: the cyan patch's red, negative in linear sRGB, reaches the
// sensor as 0 (a black channel). That patch is left out and said; the matrix is then the identity
// balanced by the light within 1 % (with it in the fit, every row leans towards the cut).
TEST(ColourChartTest, ABlackChannelPatchIsLeftOutAndSaid) {
  testing::ScratchDir scratch;
  SynthOptions options = ChartOptions();
  options.colour.camera_matrix = Eigen::Matrix3d::Identity();
  const auto material = LoadMaterial(testing::MaterialPath("bluepaint"));
  const Session session = Session::Load(testing::MakeSession(scratch.str(), options, *material));
  const ColourChartFit fit = FitColourChart(session, *session.colour_chart->corners, {}, "test");
  ASSERT_TRUE(fit.success);
  EXPECT_NE(fit.patches[17].excluded.find("black channel: camera red"), std::string::npos) << fit.BriefReport();
  int black = 0;
  for (const ColourPatch& patch : fit.patches) black += patch.excluded.find("black channel") != std::string::npos;
  EXPECT_EQ(black, 1) << fit.BriefReport();
  ColourChartSpec chart = *session.colour_chart;
  StoreColourFit(fit, &chart);
  const Eigen::Matrix3d got = SampleColourMatrix(chart, session.lights[0].intensity);
  const Eigen::Matrix3d expected = session.lights[0].intensity.cwiseQuotient(kTint).asDiagonal();
  EXPECT_LT((got - expected).cwiseAbs().maxCoeff(), 0.01 * expected.cwiseAbs().maxCoeff()) << got << "\n" << expected;
  // Kept in, the cut patch pulls the matrix off (the failure this guards against).
  ColourChartOptions keep;
  keep.min_channel_fraction = 0.0;
  ColourChartFit kept = FitColourChart(session, *session.colour_chart->corners, keep, "test");
  ColourChartSpec biased = *session.colour_chart;
  StoreColourFit(kept, &biased);
  EXPECT_GT((SampleColourMatrix(biased, session.lights[0].intensity) - expected).cwiseAbs().maxCoeff(),
            (got - expected).cwiseAbs().maxCoeff());
}

// The fit's verdicts: a synthetic chart passes both; a residual over 3 % warns, over 10 % fails; fewer
// than 18 patches warn. A failure stops `ibrdf colour` unless accepted (core/verdict.h).
TEST(ColourChartTest, VerdictsGradeTheResidualAndThePatchesUsed) {
  ColourChartFit fit;
  fit.used = 24;
  fit.rms_residual = 0.0055;
  EXPECT_EQ(WorstVerdict(ColourChartVerdicts(fit)), VerdictLevel::kOk);
  fit.rms_residual = 0.05;
  EXPECT_EQ(ColourChartVerdicts(fit)[0].level, VerdictLevel::kWarn);
  fit.rms_residual = 0.3;
  std::vector<Verdict> verdicts = ColourChartVerdicts(fit);
  EXPECT_EQ(verdicts[0].check, "colour.fit_residual");
  EXPECT_EQ(verdicts[0].level, VerdictLevel::kFail);
  EXPECT_THROW(EnforceVerdicts(&verdicts, AcceptedChecks(), "test"), Error);
  fit.rms_residual = 0.01;
  fit.used = 12;
  EXPECT_EQ(ColourChartVerdicts(fit)[1].level, VerdictLevel::kWarn);
  fit.rms_residual = std::nan("");
  EXPECT_EQ(ColourChartVerdicts(fit)[0].level, VerdictLevel::kFail);
}

TEST(ColourChartTest, ADerenderWithoutTheFittedMatrixIsAnError) {
  testing::ScratchDir scratch;
  const auto material = LoadMaterial(testing::MaterialPath("bluepaint"));
  const Session session = Session::Load(testing::MakeSession(scratch.str(), ChartOptions(), *material));
  std::vector<BrdfSample> samples(1);
  const std::string message = testing::ErrorOf([&] { ApplyColourCorrection(session, &samples); });
  EXPECT_NE(message.find("ibrdf colour"), std::string::npos) << message;
}

}  // namespace
}  // namespace ibrdf
