// The predicted coverage (coverage/coverage.h): the predicted samples are the derenderer's pixels and
// angles, a light at the camera covers theta_d ~ 0 only, the theta limit is the tabulation's, and
// what cannot be predicted is refused.
#include "coverage/coverage.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include <gtest/gtest.h>

#include "core/brdf_coords.h"
#include "core/error.h"
#include "core/math.h"
#include "core/merl_format.h"
#include "derender/derenderer.h"
#include "reconstruct/sample_domain.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

using testing::MakeSession;
using testing::ScratchDir;

Camera SmallCamera() { return Camera::Create(CameraModelId::kPinhole, 160, 120, {1000.0, 1000.0, 80.0, 60.0}); }

SampleSpec Sphere() {
  SampleSpec s;
  s.kind = SampleSpec::Kind::kSphere;
  s.radius = 0.04;
  return s;
}

CoverageView ViewAt(const Eigen::Vector3d& camera, const Eigen::Vector3d& light_position) {
  CoverageView view;
  view.camera_from_world = LookAtCameraFromWorld(camera, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ());
  view.light.position = light_position;
  return view;
}

TEST(Coverage, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(CoverageOptions().Check(&why)) << why;
  CoverageOptions bad;
  bad.samples_per_view = 0;
  EXPECT_FALSE(bad.Check(&why));
}

// A point light at the camera's centre: wi = wo at every pixel, so every sample has theta_d = 0, and
// the reconstruction's rule that cells beyond the samples' theta_d range are unmeasured
// (reconstruct/sample_domain.cc, ClassifyEstimate) leaves no cell measured: every cell centre lies
// at theta_d >= 0.5 degrees.
TEST(Coverage, LightAtTheCameraCoversThetaDZeroOnly) {
  const Eigen::Vector3d camera(0.8, 0.0, 0.0);
  CoverageOptions options;
  options.samples_per_view = 3000;
  double stride = 0.0;
  const std::vector<BrdfSample> samples =
      PredictSamples(SmallCamera(), Sphere(), {ViewAt(camera, camera)}, options, &stride);
  ASSERT_GT(samples.size(), 1000u);
  for (const BrdfSample& s : samples) {
    HalfDiffAngles a;
    ASSERT_TRUE(ToHalfDiff(Eigen::Vector3d(s.wi[0], s.wi[1], s.wi[2]), Eigen::Vector3d(s.wo[0], s.wo[1], s.wo[2]), &a));
    EXPECT_LT(a.theta_d, 1e-3);
  }
  const CoverageResult at_camera = ClassifyCoverage(samples, stride, 1, options);
  EXPECT_EQ(at_camera.measured, 0u);
  EXPECT_LT(at_camera.theta_d_max_deg, 0.1);
  // The light 8 degrees from the camera: theta_d about 4 degrees, and only cells within the samples'
  // theta_d range are measured.
  const Eigen::Vector3d light = 1.2 * Eigen::Vector3d(std::cos(8.0 * kDegree), std::sin(8.0 * kDegree), 0.0);
  const CoverageResult near = PredictCoverage(SmallCamera(), Sphere(), {ViewAt(camera, light)}, options);
  ASSERT_TRUE(near.success);
  EXPECT_GT(near.measured, 1000u);
  EXPECT_GT(near.theta_d_min_deg, 2.0);
  EXPECT_LT(near.theta_d_max_deg, 6.0);
  uint64_t measured_seen = 0;
  for (int i = 0; i < kMerlThetaH; ++i) {
    for (int j = 0; j < kMerlThetaD; ++j) {
      for (int k = 0; k < kMerlPhiD; ++k) {
        if (near.domain[MerlFlatIndex(i, j, k)] != uint8_t(DomainClass::kMeasured)) continue;
        ++measured_seen;
        const double theta_d_deg = MerlCellCentre(i, j, k).theta_d / kDegree;
        EXPECT_GE(theta_d_deg, near.theta_d_min_deg);
        EXPECT_LE(theta_d_deg, near.theta_d_max_deg);
      }
    }
  }
  EXPECT_EQ(measured_seen, near.measured);
  // The grazing limits (80 degrees) leave the band above 80 degrees of theta_h empty.
  EXPECT_EQ(near.bands.back().measured, 0u);
}

// The predicted samples of a synthetic session are the derenderer's: the same pixels (the derenderer
// also drops silhouette pixels, so it keeps a subset) with the same angles.
TEST(Coverage, PredictedSamplesAreTheDerenderersPixels) {
  ScratchDir dir;
  SynthOptions synth;
  synth.effects = CameraEffects::None();
  synth.rig.num_photos = 2;
  synth.rig.width = 96;
  synth.rig.height = 72;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  const Session session = Session::Load(MakeSession(dir / "s", synth, material));
  const DerenderResult derendered = Derender(session, DerenderOptions());
  ASSERT_GT(derendered.samples.size(), 1000u);
  const std::vector<CoverageView> views = SessionViews(session);
  ASSERT_EQ(views.size(), 2u);
  const ViewTracer tracer(session.camera, session.sample, CoverageOptions());
  std::map<std::tuple<uint32_t, uint32_t, uint32_t>, BrdfSample> predicted;
  for (uint32_t v = 0; v < views.size(); ++v) {
    for (const BrdfSample& s : tracer.Samples(views[v], 1.0, v)) predicted[{v, s.pixel[0], s.pixel[1]}] = s;
  }
  double worst_deg = 0.0;
  for (const BrdfSample& d : derendered.samples) {
    const auto found = predicted.find({d.image, d.pixel[0], d.pixel[1]});
    ASSERT_NE(found, predicted.end()) << "photo " << d.image << " pixel " << d.pixel[0] << " " << d.pixel[1];
    const BrdfSample& p = found->second;
    for (const auto& [a, b] : {std::pair{d.wi, p.wi}, std::pair{d.wo, p.wo}}) {
      const Eigen::Vector3d x(a[0], a[1], a[2]), y(b[0], b[1], b[2]);
      worst_deg = std::max(worst_deg, std::acos(std::clamp(x.normalized().dot(y.normalized()), -1.0, 1.0)) / kDegree);
    }
  }
  // The camera's rays come from a lattice every 4 pixels (coverage.h): well under a pixel's angle.
  EXPECT_LT(worst_deg, 0.05);
  EXPECT_GE(double(derendered.samples.size()), 0.9 * double(predicted.size()));
}

// The closed-form theta limit is the tabulation's FromHalfDiff test (reconstruct/merl_table.cc,
// TabulateMerl: wi.z, wo.z > cos(limit) and > 0), cell by cell.
TEST(Coverage, ThetaLimitIsTheTabulations) {
  const std::vector<uint8_t> inside = CellsWithinLimit(80.0);
  const double cos_limit = std::cos(80.0 * kDegree);
  uint64_t differ = 0, count = 0;
  for (int i = 0; i < kMerlThetaH; i += 3) {
    for (int j = 0; j < kMerlThetaD; ++j) {
      for (int k = 0; k < kMerlPhiD; ++k) {
        Eigen::Vector3d wi, wo;
        FromHalfDiff(MerlCellCentre(i, j, k), &wi, &wo);
        const bool expected = wi.z() > cos_limit && wo.z() > cos_limit && wi.z() > 0.0 && wo.z() > 0.0;
        differ += expected != bool(inside[MerlFlatIndex(i, j, k)]);
        count += expected;
      }
    }
  }
  EXPECT_EQ(differ, 0u);
  EXPECT_GT(count, 100000u);
}

TEST(Coverage, RefusesWhatItCannotPredict) {
  SampleSpec mesh;
  mesh.kind = SampleSpec::Kind::kMesh;
  EXPECT_THROW(ViewTracer(SmallCamera(), mesh, CoverageOptions()), Error);
  EXPECT_THROW(PredictCoverage(SmallCamera(), Sphere(), {}, CoverageOptions()), Error);
  // A view that sees the sphere unlit (light behind it): no samples, a clear error.
  const std::vector<CoverageView> dark = {ViewAt({0.8, 0, 0}, {-1.2, 0, 0})};
  EXPECT_THROW(PredictCoverage(SmallCamera(), Sphere(), dark, CoverageOptions()), Error);
}

TEST(Coverage, SessionViewsNameThePhotosWithoutAPose) {
  Session session;
  session.photos.resize(3);
  for (int i = 0; i < 3; ++i) session.photos[i].file = "p" + std::to_string(i) + ".png";
  session.photos[0].camera_from_world = Rigid3d();
  session.photos[2].camera_from_world = Rigid3d();  // the same pose and light: one view (a bracket)
  std::vector<std::string> missing;
  const std::vector<CoverageView> views = SessionViews(session, &missing);
  EXPECT_EQ(views.size(), 1u);
  ASSERT_EQ(missing.size(), 1u);
  EXPECT_EQ(missing[0], "photo p1.png: no camera_from_world");
}

}  // namespace
}  // namespace ibrdf
