// The align stage's Ceres cost functions: analytic values and autodiff derivatives checked against
// numeric differentiation with ceres::GradientChecker.
#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include "align/cost_functions/marker_corner_error.h"
#include "align/cost_functions/reprojection_error.h"
#include "align/cost_functions/rigid_point_error.h"
#include "align/cost_functions/sphere_tangent_error.h"

namespace ibrdf {
namespace {

TEST(ReprojectionError, ZeroAtTheTrueProjectionAndGradientsCheck) {
  const std::array<double, 8> intrinsics = {1200, 1210, 400, 300, -0.08, 0.02, 5e-4, -3e-4};
  double rotation[3] = {0.1, -0.2, 0.05};
  double translation[3] = {0.01, -0.02, 0.8};
  double point[3] = {0.03, -0.01, 0.02};
  // The observation where the point projects: the residual must vanish there.
  double residual[2];
  ReprojectionError(intrinsics, 0.0, 0.0)(rotation, translation, point, residual);
  const double u = residual[0], v = residual[1];
  ReprojectionError(intrinsics, u, v)(rotation, translation, point, residual);
  EXPECT_NEAR(residual[0], 0.0, 1e-12);
  EXPECT_NEAR(residual[1], 0.0, 1e-12);

  std::unique_ptr<ceres::CostFunction> cost(ReprojectionError::Create(intrinsics, u + 0.3, v - 0.2));
  ceres::NumericDiffOptions numeric;
  ceres::GradientChecker checker(cost.get(), static_cast<const std::vector<const ceres::Manifold*>*>(nullptr), numeric);
  ceres::GradientChecker::ProbeResults results;
  std::vector<double*> parameters = {rotation, translation, point};
  EXPECT_TRUE(checker.Probe(parameters.data(), 1e-6, &results)) << results.error_log;
}

// A marker corner through the marker's pose equals the world point through ReprojectionError.
TEST(MarkerCornerError, MatchesReprojectionOfTheWorldCornerAndGradientsCheck) {
  const std::array<double, 8> intrinsics = {1200, 1210, 400, 300, -0.08, 0.02, 5e-4, -3e-4};
  double camera_rotation[3] = {0.1, -0.2, 0.05};
  double camera_translation[3] = {0.01, -0.02, 0.8};
  double marker_rotation[3] = {0.3, 0.2, -0.4};
  double marker_translation[3] = {0.05, 0.02, -0.03};
  const Eigen::Vector3d corner(-0.015, 0.015, 0.0);
  double point[3];
  const double c[3] = {corner.x(), corner.y(), corner.z()};
  ceres::AngleAxisRotatePoint(marker_rotation, c, point);
  for (int k = 0; k < 3; ++k) point[k] += marker_translation[k];
  double expected[2], residual[2];
  ReprojectionError(intrinsics, 410.0, 290.0)(camera_rotation, camera_translation, point, expected);
  MarkerCornerError(intrinsics, corner, 410.0, 290.0)(camera_rotation, camera_translation, marker_rotation,
                                                      marker_translation, residual);
  EXPECT_NEAR(residual[0], expected[0], 1e-12);
  EXPECT_NEAR(residual[1], expected[1], 1e-12);

  std::unique_ptr<ceres::CostFunction> cost(MarkerCornerError::Create(intrinsics, corner, 410.0, 290.0));
  ceres::NumericDiffOptions numeric;
  ceres::GradientChecker checker(cost.get(), static_cast<const std::vector<const ceres::Manifold*>*>(nullptr), numeric);
  ceres::GradientChecker::ProbeResults results;
  std::vector<double*> parameters = {camera_rotation, camera_translation, marker_rotation, marker_translation};
  EXPECT_TRUE(checker.Probe(parameters.data(), 1e-6, &results)) << results.error_log;
}

TEST(SphereTangentError, DistanceMinusRadiusAndGradientsCheck) {
  const Eigen::Vector3d origin(0, 0, -1), direction(0, 0, 1);
  double center[3] = {0.3, 0.4, 0.0};
  double radius = 0.5;
  double residual;
  SphereTangentError(origin, direction)(center, &radius, &residual);
  EXPECT_NEAR(residual, 0.0, 1e-12);  // the ray passes at distance 0.5 from the centre
  radius = 0.4;
  SphereTangentError(origin, direction)(center, &radius, &residual);
  EXPECT_NEAR(residual, 0.1, 1e-12);

  std::unique_ptr<ceres::CostFunction> cost(SphereTangentError::Create(origin, Eigen::Vector3d(0.1, 0.05, 1.0)));
  ceres::NumericDiffOptions numeric;
  ceres::GradientChecker checker(cost.get(), static_cast<const std::vector<const ceres::Manifold*>*>(nullptr), numeric);
  ceres::GradientChecker::ProbeResults results;
  std::vector<double*> parameters = {center, &radius};
  EXPECT_TRUE(checker.Probe(parameters.data(), 1e-6, &results)) << results.error_log;
}

// A body point through the body's pose: zero at its true world position, the offset otherwise.
TEST(RigidPointError, OffsetFromTheMovedPointAndGradientsCheck) {
  double rotation[3] = {0.2, -0.1, 0.7};
  double translation[3] = {0.01, 0.05, -0.02};
  const Eigen::Vector3d p_in_body(0.02, -0.01, 0.015);
  const double p[3] = {p_in_body.x(), p_in_body.y(), p_in_body.z()};
  double moved[3];
  ceres::AngleAxisRotatePoint(rotation, p, moved);
  const Eigen::Vector3d p_in_world(moved[0] + translation[0], moved[1] + translation[1], moved[2] + translation[2]);
  double residual[3];
  RigidPointError(p_in_body, p_in_world)(rotation, translation, residual);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(residual[k], 0.0, 1e-15);
  RigidPointError(p_in_body, p_in_world + Eigen::Vector3d(1e-3, -2e-3, 0.0))(rotation, translation, residual);
  EXPECT_NEAR(residual[0], -1e-3, 1e-15);
  EXPECT_NEAR(residual[1], 2e-3, 1e-15);

  std::unique_ptr<ceres::CostFunction> cost(
      RigidPointError::Create(p_in_body, p_in_world + Eigen::Vector3d(1e-3, 0, 0)));
  ceres::NumericDiffOptions numeric;
  ceres::GradientChecker checker(cost.get(), static_cast<const std::vector<const ceres::Manifold*>*>(nullptr), numeric);
  ceres::GradientChecker::ProbeResults results;
  std::vector<double*> parameters = {rotation, translation};
  EXPECT_TRUE(checker.Probe(parameters.data(), 1e-6, &results)) << results.error_log;
}

}  // namespace
}  // namespace ibrdf
