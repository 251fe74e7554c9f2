// Local polynomial regression: accuracy against the truth of synthetic sessions, symmetry, and the
// hard cases (few samples, one sheet, theta = 0, a dark material) that must give a finite estimate
// with a stated reliability.
#include "reconstruct/local_regression.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "core/error.h"
#include "reconstruct/reconstruction_error.h"
#include "tests/reconstruct/reconstruct_test_util.h"

namespace ibrdf {
namespace {

using testing::MakeSession;
using testing::MaterialPath;
using testing::ScratchDir;
using testing::SessionSamples;

TEST(LocalRegression, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(LocalRegressionOptions().Check(&why)) << why;
  LocalRegressionOptions bad;
  bad.degree = 3;
  EXPECT_FALSE(bad.Check(&why));
  bad = LocalRegressionOptions();
  bad.radius_d_deg = 0.0;
  EXPECT_FALSE(bad.Check(&why));
}

// The must-show bounds, at 400 x 300 pixels (a quarter of the default's samples): noise-free under
// 2 %, with the default camera noise under 4 % relative RMS over the measured domain (theta <= 80).
TEST(LocalRegression, BluepaintWithinBounds) {
  const auto material = LoadMaterial(MaterialPath("bluepaint"));
  for (bool noisy : {false, true}) {
    const auto samples = SessionSamples(*material, noisy ? CameraEffects() : CameraEffects::None());
    const LocalRegression regression(samples, LocalRegressionOptions());
    const ReconstructionError error = CompareRegressionWithTruth(regression, *material, 80.0, 3);
    EXPECT_LT(error.rel_rms_all, noisy ? 0.04 : 0.02) << error.Brief();
    EXPECT_GT(error.coverage(), 0.95) << error.Brief();
  }
}

// With folding, light and camera exchanged and the mirror image give the same estimate.
TEST(LocalRegression, FoldedEstimateIsReciprocalAndSymmetric) {
  const auto material = LoadMaterial(MaterialPath("bluepaint"));
  const auto samples = SessionSamples(*material, CameraEffects::None(), 6, 200, 150);
  const LocalRegression regression(samples, LocalRegressionOptions());
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> theta(0.1, 1.3), phi(-M_PI, M_PI);
  for (int i = 0; i < 50; ++i) {
    const Eigen::Vector3d wi = FromSpherical(theta(rng), phi(rng)), wo = FromSpherical(theta(rng), phi(rng));
    const Eigen::Vector3d a = regression.Evaluate(wi, wo).value;
    const Eigen::Vector3d b = regression.Evaluate(wo, wi).value;
    const Eigen::Vector3d mirrored =
        regression.Evaluate(Eigen::Vector3d(wi.x(), -wi.y(), wi.z()), Eigen::Vector3d(wo.x(), -wo.y(), wo.z())).value;
    EXPECT_NEAR((a - b).norm(), 0.0, 1e-5 * (1.0 + a.norm()));
    EXPECT_NEAR((a - mirrored).norm(), 0.0, 1e-5 * (1.0 + a.norm()));
  }
}

void ExpectFiniteWithReliability(const Estimate& e) {
  EXPECT_TRUE(e.value.allFinite());
  EXPECT_TRUE(std::isfinite(e.effective_samples));
  EXPECT_GE(e.degree, -1);
}

BrdfSample MakeSample(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo, double value) {
  BrdfSample s{};
  for (int k = 0; k < 3; ++k) {
    s.wi[k] = float(wi[k]);
    s.wo[k] = float(wo[k]);
    s.brdf[k] = float(value);
  }
  const IsotropicAngles angles = ToIsotropic(wi, wo);
  s.theta_i = float(angles.theta_i);
  s.theta_e = float(angles.theta_e);
  s.delta_phi = float(angles.delta_phi);
  return s;
}

TEST(LocalRegression, TwentySamplesGiveStatedReliability) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> theta(0.0, 1.3), phi(-M_PI, M_PI);
  std::vector<BrdfSample> samples;
  for (int i = 0; i < 20; ++i)
    samples.push_back(MakeSample(FromSpherical(theta(rng), phi(rng)), FromSpherical(theta(rng), phi(rng)), 0.3));
  const LocalRegression regression(samples, LocalRegressionOptions());
  ReliabilityCounts counts;
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 200; ++i)
    points.push_back(RegressionCoordinates(FromSpherical(theta(rng), phi(rng)), FromSpherical(theta(rng), phi(rng))));
  for (const Estimate& e : regression.EvaluateMany(points, &counts)) {
    ExpectFiniteWithReliability(e);
    if (e.status != EstimateStatus::kUnsupported) {
      EXPECT_NEAR(e.value[0], 0.3, 1e-4);
    }
  }
  EXPECT_EQ(counts.evaluations, 200u);
  EXPECT_GT(counts.grown + counts.unsupported + counts.reduced_degree, 0u);
}

// Every sample on one sheet (one angle between wi and wo): across the sheet the design is degenerate,
// so the fit drops degree instead of extrapolating.
TEST(LocalRegression, OneSheetFallsBackAndStaysFinite) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> theta(0.0, 1.2), phi(-M_PI, M_PI);
  std::vector<BrdfSample> samples;
  const double g = 60.0 * M_PI / 180.0;  // angle between wi and wo
  while (samples.size() < 5000) {
    const Eigen::Vector3d wi = FromSpherical(theta(rng), phi(rng));
    const Eigen::Vector3d axis = wi.unitOrthogonal();
    const Eigen::Vector3d wo =
        std::cos(g) * wi + std::sin(g) * (std::cos(phi(rng)) * axis + std::sin(phi(rng)) * wi.cross(axis)).normalized();
    if (wo.z() < 0.05) continue;
    samples.push_back(MakeSample(wi, wo, 0.2 + 0.1 * wi.z()));
  }
  const LocalRegression regression(samples, LocalRegressionOptions());
  ReliabilityCounts counts;
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 300; ++i) {
    HalfDiffAngles a;
    a.theta_h = theta(rng) * 0.5;
    a.theta_d = g / 2 + 0.03 * (i % 3 - 1);  // on and just beside the sheet
    a.phi_d = phi(rng);
    points.push_back(RegressionCoordinates(a));
  }
  for (const Estimate& e : regression.EvaluateMany(points, &counts)) {
    ExpectFiniteWithReliability(e);
    EXPECT_GE(e.value[0], 0.19);
    EXPECT_LE(e.value[0], 0.31);
  }
  EXPECT_GT(counts.reduced_degree + counts.grown, 0u) << counts.Brief();
}

TEST(LocalRegression, SampleAtNormalIncidence) {
  std::vector<BrdfSample> samples;
  samples.push_back(MakeSample(Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitZ(), 0.5));  // theta = 0 both
  samples.push_back(MakeSample(Eigen::Vector3d::UnitZ(), FromSpherical(0.4, 0.3), 0.4));
  const LocalRegression regression(samples, LocalRegressionOptions());
  EXPECT_EQ(regression.size(), 2u);
  for (const Estimate& e : {regression.Evaluate(Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitZ()),
                            regression.Evaluate(Eigen::Vector3d::UnitZ(), FromSpherical(0.4, 0.3)),
                            regression.Evaluate(FromSpherical(1.5, 0.0), FromSpherical(1.5, 3.0))}) {
    ExpectFiniteWithReliability(e);
  }
}

// Felt: a dark material whose samples sit near the quantization floor of the 12-bit camera.
TEST(LocalRegression, FeltNearQuantizationFloorIsFinite) {
  const auto material = LoadMaterial(MaterialPath("felt"));
  const auto samples = SessionSamples(*material, CameraEffects(), 10, 200, 150);
  ASSERT_GT(samples.size(), 1000u);
  const LocalRegression regression(samples, LocalRegressionOptions());
  const ReconstructionError error = CompareRegressionWithTruth(regression, *material, 80.0, 4);
  EXPECT_TRUE(std::isfinite(error.rel_rms_all));
  EXPECT_LT(error.rel_rms_all, 0.25) << error.Brief();
  std::printf("felt (10 photos, 200 x 150, camera noise): %s\n", error.Brief().c_str());
}

// A cylinder (axis vertical, cameras in the light's plane) sees only the incidence plane: its samples
// form one sheet, v = 0 in (u, v, w). The measured domain keeps the cells the sheet covers (within the
// kernel, samples' centroid within half a radius) and leaves out the extrapolations beside it, which
// are off by far more.
TEST(LocalRegression, CylinderIsScoredOverTheDomainItCovers) {
  const auto material = LoadMaterial(MaterialPath("primer"));
  ScratchDir dir;
  SynthOptions options;
  options.effects = CameraEffects::None();
  options.scene.sample = SampleSpec::Kind::kCylinder;
  options.rig.width = 400;
  options.rig.height = 300;
  const Session session = Session::Load(MakeSession(dir / "s", options, *material));
  const auto samples = DerenderAnalytic(session, DerenderOptions()).samples;
  ASSERT_GT(samples.size(), 1000u);
  const LocalRegression regression(samples, LocalRegressionOptions());
  const ReconstructionError error = CompareRegressionWithTruth(regression, *material, 80.0, 3);
  std::printf("primer cylinder (20 photos, 400 x 300, noise-free): %s\n", error.Brief().c_str());
  EXPECT_LT(error.rel_rms_all, 0.02) << error.Brief();
  EXPECT_GT(error.coverage(), 0.1) << error.Brief();
  EXPECT_LT(error.coverage(), 0.6) << error.Brief();
  // Beside the sheet (v = 5 degrees, the samples within about 2) the estimate is an extrapolation.
  HalfDiffAngles beside;
  beside.theta_h = 10.0 * M_PI / 180.0;
  beside.phi_d = std::asin(0.5);
  beside.theta_d = 0.6;
  EXPECT_FALSE(InMeasuredDomain(regression.Evaluate(beside)));
}

// Binning aggregates samples into cells but keeps every sample's weight: the binned fit stays close to
// the per-sample fit, and with cells so small that each holds one sample it is the per-sample fit.
TEST(LocalRegression, BinningAgreesWithPerSampleFit) {
  const auto material = LoadMaterial(MaterialPath("bluepaint"));
  const auto samples = SessionSamples(*material, CameraEffects(), 10, 200, 150);
  LocalRegressionOptions unbinned;
  unbinned.bin_fraction_h = unbinned.bin_fraction_d = 0.0;
  LocalRegressionOptions tiny;
  tiny.bin_fraction_h = tiny.bin_fraction_d = 1e-7;
  const LocalRegression exact(samples, unbinned), binned(samples, LocalRegressionOptions()), singletons(samples, tiny);
  EXPECT_EQ(exact.points(), exact.size());
  EXPECT_LT(binned.points(), binned.size());
  EXPECT_EQ(binned.size(), exact.size());
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> theta(0.1, 1.2), phi(-M_PI, M_PI);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d wi = FromSpherical(theta(rng), phi(rng)), wo = FromSpherical(theta(rng), phi(rng));
    const Estimate a = exact.Evaluate(wi, wo), b = binned.Evaluate(wi, wo), c = singletons.Evaluate(wi, wo);
    EXPECT_TRUE(b.value.allFinite());
    EXPECT_EQ(a.neighbors, c.neighbors);
    EXPECT_NEAR((a.value - c.value).norm(), 0.0, 1e-4 * (1e-3 + a.value.norm()));
    if (a.status == EstimateStatus::kFull && b.status == EstimateStatus::kFull) {
      EXPECT_NEAR((a.value - b.value).norm(), 0.0, 0.05 * a.value.norm());
    }
  }
  // Leave-one-out removes the left-out sample from its cell: finite and close to the unbinned score.
  const CrossValidationScore cv_exact = exact.CrossValidate(300), cv_binned = binned.CrossValidate(300);
  EXPECT_TRUE(std::isfinite(cv_binned.loo_rms));
  EXPECT_NEAR(cv_binned.loo_rms, cv_exact.loo_rms, 0.5 * cv_exact.loo_rms + 0.01);
  EXPECT_NEAR(cv_binned.mean_leverage, cv_exact.mean_leverage, 0.5 * cv_exact.mean_leverage);
}

// Leaving samples out by flag is the regression of a copy without them, to the bit: the held-out photo
// of the report, with a channel some samples did not measure (its own regression) and non-finite
// samples (skipped and counted) among those kept and those left out.
TEST(LocalRegression, LeaveOutFlagsEqualACopyWithoutThem) {
  const auto material = LoadMaterial(MaterialPath("bluepaint"));
  std::vector<BrdfSample> samples = SessionSamples(*material, CameraEffects(), 6, 200, 150);
  ASSERT_GT(samples.size(), 1000u);
  for (size_t i = 0; i < samples.size(); i += 97) samples[i].valid[2] = 0;
  for (size_t i = 5; i < samples.size(); i += 301) samples[i].brdf[1] = NAN;
  std::vector<uint8_t> leave_out(samples.size());
  std::vector<BrdfSample> kept;
  for (size_t i = 0; i < samples.size(); ++i) {
    leave_out[i] = samples[i].image == 2 || i % 11 == 0;
    if (!leave_out[i]) kept.push_back(samples[i]);
  }
  const LocalRegression flagged(samples, leave_out, LocalRegressionOptions()), copied(kept, LocalRegressionOptions()),
      all(samples, LocalRegressionOptions());
  EXPECT_EQ(flagged.size(), copied.size());
  EXPECT_LT(flagged.size(), all.size());
  EXPECT_EQ(flagged.points(), copied.points());
  EXPECT_EQ(flagged.skipped_samples(), copied.skipped_samples());
  EXPECT_GT(flagged.skipped_samples(), 0u);
  EXPECT_EQ(flagged.separate_channels(), copied.separate_channels());
  EXPECT_EQ(flagged.separate_channels(), 4);
  std::vector<Eigen::Vector3d> points;
  for (const BrdfSample& s : samples) {
    if (s.image != 2) continue;
    points.push_back(RegressionCoordinates(Eigen::Vector3d(s.wi[0], s.wi[1], s.wi[2]).normalized(),
                                           Eigen::Vector3d(s.wo[0], s.wo[1], s.wo[2]).normalized()));
  }
  ASSERT_GT(points.size(), 100u);
  const std::vector<Estimate> a = flagged.EvaluateMany(points, nullptr), b = copied.EvaluateMany(points, nullptr),
                              c = all.EvaluateMany(points, nullptr);
  size_t differs_from_all = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    ASSERT_EQ(a[i].value, b[i].value) << "point " << i;
    ASSERT_EQ(a[i].neighbors, b[i].neighbors) << "point " << i;
    ASSERT_EQ(a[i].status, b[i].status) << "point " << i;
    differs_from_all += a[i].value != c[i].value;
  }
  EXPECT_GT(differs_from_all, points.size() / 2);
  std::vector<uint8_t> short_flags(samples.size() - 1);
  EXPECT_THROW({ const LocalRegression bad(samples, short_flags, LocalRegressionOptions()); }, InternalError);
}

}  // namespace
}  // namespace ibrdf
