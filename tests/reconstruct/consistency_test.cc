// Reciprocity and bilateral-symmetry checks: small on a reciprocal, isotropic measurement, large where
// the samples were made to break either symmetry.
#include "reconstruct/consistency.h"

#include <cmath>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/session.h"
#include "derender/derenderer.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

using testing::MakeSession;
using testing::MaterialPath;
using testing::ScratchDir;

std::vector<BrdfSample> BluepaintSamples(const CameraEffects& effects) {
  ScratchDir dir;
  const auto material = LoadMaterial(MaterialPath("bluepaint"));
  SynthOptions options;
  options.effects = effects;
  const Session session = Session::Load(MakeSession(dir / "s", options, *material));
  return DerenderAnalytic(session, DerenderOptions()).samples;
}

TEST(Consistency, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(ConsistencyOptions().Check(&why)) << why;
  ConsistencyOptions bad;
  bad.phi_bin_deg = 7.0;  // does not divide 360
  EXPECT_FALSE(bad.Check(&why));
}

// The bluepaint sphere session: a reciprocal BRDF, so this tests the derenderer's geometry.
TEST(Consistency, BluepaintSphereIsReciprocalAndIsotropic) {
  for (const CameraEffects& effects : {CameraEffects::None(), CameraEffects()}) {
    const std::vector<BrdfSample> samples = BluepaintSamples(effects);
    const ConsistencyReport report = CheckConsistency(samples, ConsistencyOptions());
    ASSERT_TRUE(report.success);
    ASSERT_GT(report.reciprocity.bins.size(), 100u);
    ASSERT_GT(report.isotropy.bins.size(), 100u);
    EXPECT_LT(report.reciprocity.overall_rel_error, 0.02);
    EXPECT_LT(report.isotropy.overall_rel_error, 0.02);
  }
}

// Breaking reciprocity (10 % more wherever theta_i > theta_e) must show as a ~10 % figure, while
// bilateral symmetry stays intact.
TEST(Consistency, DetectsBrokenReciprocity) {
  std::vector<BrdfSample> samples = BluepaintSamples(CameraEffects::None());
  for (BrdfSample& s : samples) {
    if (s.theta_i > s.theta_e) {
      for (float& f : s.brdf) f *= 1.1f;
    }
  }
  const ConsistencyReport report = CheckConsistency(samples, ConsistencyOptions());
  EXPECT_NEAR(report.reciprocity.overall_rel_error, 0.095, 0.02);
  EXPECT_LT(report.isotropy.overall_rel_error, 0.01);
}

TEST(Consistency, DetectsBrokenBilateralSymmetry) {
  std::vector<BrdfSample> samples = BluepaintSamples(CameraEffects::None());
  for (BrdfSample& s : samples) {
    if (s.delta_phi > 0.0f) {
      for (float& f : s.brdf) f *= 1.2f;
    }
  }
  const ConsistencyReport report = CheckConsistency(samples, ConsistencyOptions());
  EXPECT_GT(report.isotropy.overall_rel_error, 0.12);
}

TEST(Consistency, TooFewSamplesGiveNoFigureNotNaN) {
  std::vector<BrdfSample> samples(10);
  for (size_t i = 0; i < samples.size(); ++i) {
    samples[i].theta_i = 0.3f;
    samples[i].theta_e = 0.5f;
    samples[i].delta_phi = 0.1f;
    for (float& f : samples[i].brdf) f = 0.2f;
  }
  const ConsistencyReport report = CheckConsistency(samples, ConsistencyOptions());
  EXPECT_FALSE(report.reciprocity.valid());
  EXPECT_FALSE(report.isotropy.valid());
  EXPECT_EQ(report.reciprocity.overall_rel_error, 0.0);
  const nlohmann::json json = ToJson(report, ConsistencyOptions());
  EXPECT_FALSE(json["reciprocity"]["valid"].get<bool>());
}

}  // namespace
}  // namespace ibrdf
