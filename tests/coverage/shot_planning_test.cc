// Next-shot planning (coverage/shot_planning.h): the suggestions add coverage, in falling order of
// gain, within the reachable range and away from the light.
#include "coverage/shot_planning.h"

#include <cmath>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/math.h"

namespace ibrdf {
namespace {

Camera SmallCamera() { return Camera::Create(CameraModelId::kPinhole, 160, 120, {1000.0, 1000.0, 80.0, 60.0}); }

SampleSpec Sphere() {
  SampleSpec s;
  s.kind = SampleSpec::Kind::kSphere;
  s.radius = 0.04;
  return s;
}

// Two photos of a sphere under a light along +x, cameras in the light's plane at 30 and 90 degrees.
std::vector<CoverageView> TwoViews() {
  std::vector<CoverageView> views;
  for (double azimuth_deg : {30.0, 90.0}) {
    const Eigen::Vector3d camera(0.8 * std::cos(azimuth_deg * kDegree), 0.8 * std::sin(azimuth_deg * kDegree), 0.0);
    CoverageView view;
    view.camera_from_world = LookAtCameraFromWorld(camera, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ());
    view.light.position = Eigen::Vector3d(1.2, 0.0, 0.0);
    views.push_back(view);
  }
  return views;
}

ShotPlanOptions FastOptions() {
  ShotPlanOptions options;
  options.coverage.samples_per_view = 4000;
  options.candidate_samples_per_view = 1500;
  options.azimuth_step_deg = 30.0;
  options.elevation_step_deg = 20.0;
  return options;
}

TEST(ShotPlanning, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(ShotPlanOptions().Check(&why)) << why;
  ShotPlanOptions bad;
  bad.min_elevation_deg = 50.0;
  bad.max_elevation_deg = 40.0;
  EXPECT_FALSE(bad.Check(&why));
}

TEST(ShotPlanning, SuggestionsIncreaseThePredictedCoverage) {
  ShotPlanOptions options = FastOptions();
  options.suggestions = 3;
  const ShotPlan plan = PlanShots(SmallCamera(), Sphere(), TwoViews(), options);
  ASSERT_TRUE(plan.success);
  ASSERT_EQ(plan.suggestions.size(), 3u);
  // The reconstruction's classification with the suggested photos measures more of the domain, in
  // the specular band too.
  EXPECT_GT(plan.after.measured, plan.before.measured + plan.before.cells / 20);
  EXPECT_GT(plan.after.bands[0].measured, plan.before.bands[0].measured);
  EXPECT_EQ(plan.after.views, 5u);
  const Eigen::Vector3d to_light = Eigen::Vector3d::UnitX();
  for (size_t n = 0; n < plan.suggestions.size(); ++n) {
    const ShotSuggestion& s = plan.suggestions[n];
    EXPECT_GT(s.cells_gained, 0u);
    if (n > 0) {
      EXPECT_LE(s.weighted_gain, plan.suggestions[n - 1].weighted_gain);  // greedy: falling gains
    }
    // Within the reachable range: on the shell at the views' mean distance, elevation 10 to 80.
    EXPECT_NEAR(s.position.norm(), 0.8, 1e-9);
    EXPECT_GE(s.elevation_deg, 10.0);
    EXPECT_LE(s.elevation_deg, 80.0);
    EXPECT_GE(std::acos(s.position.normalized().dot(to_light)) / kDegree, options.min_light_separation_deg);
    // The pose looks at the centre: the centre projects onto the optical axis.
    const Eigen::Vector3d centre_in_camera = s.camera_from_world * Eigen::Vector3d::Zero();
    EXPECT_NEAR(centre_in_camera.x(), 0.0, 1e-9);
    EXPECT_NEAR(centre_in_camera.y(), 0.0, 1e-9);
    EXPECT_NEAR(centre_in_camera.z(), 0.8, 1e-9);
  }
}

// Without suggestions asked, the plan is the coverage alone; a range of one elevation and azimuth
// gives that one candidate.
TEST(ShotPlanning, RangeBoundsTheCandidates) {
  ShotPlanOptions options = FastOptions();
  options.suggestions = 0;
  const ShotPlan none = PlanShots(SmallCamera(), Sphere(), TwoViews(), options);
  EXPECT_TRUE(none.suggestions.empty());
  EXPECT_EQ(none.after.measured, none.before.measured);
  options.suggestions = 2;
  options.min_elevation_deg = options.max_elevation_deg = 30.0;
  options.min_azimuth_deg = options.max_azimuth_deg = -60.0;
  const ShotPlan one = PlanShots(SmallCamera(), Sphere(), TwoViews(), options);
  EXPECT_EQ(one.candidates, 1u);
  ASSERT_EQ(one.suggestions.size(), 1u);  // the second step has no candidate left
  EXPECT_DOUBLE_EQ(one.suggestions[0].azimuth_deg, -60.0);
  EXPECT_DOUBLE_EQ(one.suggestions[0].elevation_deg, 30.0);
}

}  // namespace
}  // namespace ibrdf
