// Tests of core/light.h: the irradiance a surface point receives from the session's light.
#include "core/light.h"

#include <cmath>

#include <gtest/gtest.h>

#include "core/error.h"

namespace ibrdf {
namespace {

Light PointLight(const Eigen::Vector3d& position, const Eigen::Vector3d& intensity) {
  Light light;
  light.kind = Light::Kind::kPoint;
  light.position = position;
  light.intensity = intensity;
  return light;
}

void ExpectAllFinite(const Incidence& incidence) {
  EXPECT_TRUE(incidence.wi.allFinite());
  EXPECT_TRUE(incidence.irradiance.allFinite());
  EXPECT_FALSE(std::isnan(incidence.cos_theta));
  EXPECT_FALSE(std::isnan(incidence.distance));
}

// E = I cos(theta_i) / r^2 against a hand computation: light at (0, 0, 2), point (1, 0, 0), normal +z:
// r^2 = 5, cos = 2 / sqrt(5), so E = I * 2 / 5^1.5.
TEST(Light, PointLightInverseSquareCosineLaw) {
  const Light light = PointLight(Eigen::Vector3d(0, 0, 2), Eigen::Vector3d(1, 2, 3));
  const Incidence incidence = IncidenceAt(light, Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 0, 1));
  ASSERT_TRUE(incidence.lit);
  EXPECT_NEAR(incidence.distance, std::sqrt(5.0), 1e-15);
  EXPECT_NEAR(incidence.cos_theta, 2.0 / std::sqrt(5.0), 1e-15);
  EXPECT_LT((incidence.wi - Eigen::Vector3d(-1, 0, 2) / std::sqrt(5.0)).norm(), 1e-15);
  const double factor = 2.0 / std::pow(5.0, 1.5);
  EXPECT_LT((incidence.irradiance - Eigen::Vector3d(1, 2, 3) * factor).norm(), 1e-15);
}

// Doubling the distance along the normal quarters the irradiance.
TEST(Light, PointLightFallsOffAsInverseSquare) {
  const Light light = PointLight(Eigen::Vector3d(0.2, -0.1, 3.0), Eigen::Vector3d(4, 4, 4));
  const Eigen::Vector3d normal = Eigen::Vector3d(0.2, -0.1, 1.0).normalized();
  const Eigen::Vector3d near_point = light.position - 1.0 * normal;
  const Eigen::Vector3d far_point = light.position - 2.0 * normal;
  const Incidence near = IncidenceAt(light, near_point, normal);
  const Incidence far = IncidenceAt(light, far_point, normal);
  ASSERT_TRUE(near.lit && far.lit);
  EXPECT_NEAR(near.cos_theta, 1.0, 1e-15);
  EXPECT_NEAR(near.irradiance.x(), 4.0, 1e-14);
  EXPECT_NEAR(far.irradiance.x(), 1.0, 1e-14);
}

// A light behind the surface does not light it: lit = false, zero irradiance, cos_theta <= 0.
TEST(Light, PointLightBehindSurfaceIsUnlit) {
  const Light light = PointLight(Eigen::Vector3d(0.5, 0, -1), Eigen::Vector3d(1, 1, 1));
  const Incidence incidence = IncidenceAt(light, Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 1));
  EXPECT_FALSE(incidence.lit);
  EXPECT_EQ(incidence.irradiance, Eigen::Vector3d::Zero());
  EXPECT_LT(incidence.cos_theta, 0.0);
  ExpectAllFinite(incidence);
}

// A light exactly in the tangent plane (cos_theta = 0) delivers nothing.
TEST(Light, PointLightInTangentPlaneIsUnlit) {
  const Light light = PointLight(Eigen::Vector3d(2, 0, 0), Eigen::Vector3d(1, 1, 1));
  const Incidence incidence = IncidenceAt(light, Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 1));
  EXPECT_FALSE(incidence.lit);
  EXPECT_EQ(incidence.irradiance, Eigen::Vector3d::Zero());
  ExpectAllFinite(incidence);
}

// A point at the light's position has no direction to the light: unlit, and no NaN or infinity.
TEST(Light, PointCoincidentWithLightIsUnlitAndFinite) {
  const Light light = PointLight(Eigen::Vector3d(0.1, 0.2, 0.3), Eigen::Vector3d(1, 1, 1));
  const Incidence incidence = IncidenceAt(light, light.position, Eigen::Vector3d(0, 0, 1));
  EXPECT_FALSE(incidence.lit);
  EXPECT_EQ(incidence.irradiance, Eigen::Vector3d::Zero());
  ExpectAllFinite(incidence);
}

// A directional light gives E = I cos(theta_i), whatever the position; its direction need not be
// given normalized; the distance is infinite.
TEST(Light, DirectionalLightCosineLaw) {
  Light light;
  light.kind = Light::Kind::kDirectional;
  light.direction = Eigen::Vector3d(1, 0, 1);  // 45 degrees from +z, not unit
  light.intensity = Eigen::Vector3d(2, 3, 4);
  for (const Eigen::Vector3d& point : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(100, -50, 7)}) {
    const Incidence incidence = IncidenceAt(light, point, Eigen::Vector3d(0, 0, 1));
    ASSERT_TRUE(incidence.lit);
    EXPECT_TRUE(std::isinf(incidence.distance));
    EXPECT_NEAR(incidence.wi.norm(), 1.0, 1e-15);
    EXPECT_NEAR(incidence.cos_theta, std::sqrt(0.5), 1e-15);
    EXPECT_LT((incidence.irradiance - Eigen::Vector3d(2, 3, 4) * std::sqrt(0.5)).norm(), 1e-14);
  }
}

// A directional light from below the surface leaves it unlit.
TEST(Light, DirectionalLightBehindSurfaceIsUnlit) {
  Light light;
  light.kind = Light::Kind::kDirectional;
  light.direction = Eigen::Vector3d(0, 1, -1).normalized();
  const Incidence incidence = IncidenceAt(light, Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 1));
  EXPECT_FALSE(incidence.lit);
  EXPECT_EQ(incidence.irradiance, Eigen::Vector3d::Zero());
  ExpectAllFinite(incidence);
}

// Defaults: a point light of unit intensity at the origin.
TEST(Light, Defaults) {
  const Light light;
  EXPECT_EQ(light.kind, Light::Kind::kPoint);
  EXPECT_EQ(light.intensity, Eigen::Vector3d::Ones());
  const Incidence unlit;
  EXPECT_FALSE(unlit.lit);
  EXPECT_EQ(unlit.irradiance, Eigen::Vector3d::Zero());
}

TEST(Light, KindNamesAndPlacement) {
  Light point;
  point.kind = Light::Kind::kPoint;
  point.position = Eigen::Vector3d(1, 2, 3);
  Light directional;
  directional.kind = Light::Kind::kDirectional;
  directional.direction = Eigen::Vector3d(0, 0, 2);
  EXPECT_STREQ(LightKindName(Light::Kind::kPoint), "point");
  EXPECT_STREQ(LightKindName(Light::Kind::kDirectional), "directional");
  EXPECT_STREQ(LightPlacementKey(Light::Kind::kPoint), "position");
  EXPECT_STREQ(LightPlacementKey(Light::Kind::kDirectional), "direction");
  EXPECT_EQ(&LightPlacement(point), &point.position);
  EXPECT_EQ(&LightPlacement(directional), &directional.direction);
  EXPECT_EQ(DirectionToLight(point, Eigen::Vector3d(1, 2, 0)), Eigen::Vector3d(0, 0, 1));
  EXPECT_EQ(DirectionToLight(directional, Eigen::Vector3d(5, 5, 5)), Eigen::Vector3d(0, 0, 1));
}

TEST(Light, KindOutsideTheEnumIsAnInternalError) {
  EXPECT_THROW(LightKindName(static_cast<Light::Kind>(99)), InternalError);
}

}  // namespace
}  // namespace ibrdf
