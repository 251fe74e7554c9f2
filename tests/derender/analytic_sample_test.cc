// Ray/sphere and ray/cylinder intersection: hits, misses, tangents, rays from inside, caps, and a scene
// 10 km from the origin.
#include "derender/analytic_sample.h"

#include "core/error.h"

#include <cmath>

#include <gtest/gtest.h>

namespace ibrdf {
namespace {

TEST(SphereSample, HitsFrontSurfaceWithOutwardNormal) {
  const SphereSample sphere(Eigen::Vector3d(0, 0, 0), 1.0);
  SurfaceHit hit;
  ASSERT_TRUE(sphere.Intersect(Eigen::Vector3d(0, 0, -5), Eigen::Vector3d(0, 0, 1), &hit));
  EXPECT_NEAR(hit.t, 4.0, 1e-12);
  EXPECT_NEAR((hit.point - Eigen::Vector3d(0, 0, -1)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((hit.normal - Eigen::Vector3d(0, 0, -1)).norm(), 0.0, 1e-12);
}

TEST(SphereSample, MissesAndRaysPointingAway) {
  const SphereSample sphere(Eigen::Vector3d(0, 0, 0), 1.0);
  SurfaceHit hit;
  EXPECT_FALSE(sphere.Intersect(Eigen::Vector3d(0, 2, -5), Eigen::Vector3d(0, 0, 1), &hit));
  EXPECT_FALSE(sphere.Intersect(Eigen::Vector3d(0, 0, -5), Eigen::Vector3d(0, 0, -1), &hit));
}

TEST(SphereSample, TangentRayHitsAtGrazingWithoutNaN) {
  const SphereSample sphere(Eigen::Vector3d(0, 0, 0), 1.0);
  SurfaceHit hit;
  // Exactly tangent: the discriminant is 0; the hit is at the silhouette with a normal at 90 degrees.
  if (sphere.Intersect(Eigen::Vector3d(1, 0, -5), Eigen::Vector3d(0, 0, 1), &hit)) {
    EXPECT_TRUE(hit.point.allFinite());
    EXPECT_TRUE(hit.normal.allFinite());
    EXPECT_NEAR(hit.normal.dot(Eigen::Vector3d(0, 0, 1)), 0.0, 1e-6);
  }
  // Just outside: a miss.
  EXPECT_FALSE(sphere.Intersect(Eigen::Vector3d(1.0 + 1e-9, 0, -5), Eigen::Vector3d(0, 0, 1), &hit));
}

TEST(SphereSample, CameraInsideSeesNoOuterSurface) {
  const SphereSample sphere(Eigen::Vector3d(0, 0, 0), 1.0);
  SurfaceHit hit;
  EXPECT_TRUE(sphere.Contains(Eigen::Vector3d(0.1, 0, 0)));
  EXPECT_FALSE(sphere.Intersect(Eigen::Vector3d(0.1, 0, 0), Eigen::Vector3d(0, 0, 1), &hit));
}

TEST(SphereSample, FarFromOriginKeepsPrecision) {
  // A 4 cm sphere 10 km from the origin seen from 0.8 m: the normal must still be exact to 1e-9.
  const Eigen::Vector3d center(1e4, -1e4, 3e3);
  const SphereSample sphere(center, 0.04);
  const Eigen::Vector3d camera = center + Eigen::Vector3d(0, 0, -0.8);
  const Eigen::Vector3d target = center + 0.04 * Eigen::Vector3d(0.6, 0.0, -0.8);
  const Eigen::Vector3d direction = (target - camera).normalized();
  SurfaceHit hit;
  ASSERT_TRUE(sphere.Intersect(camera, direction, &hit));
  EXPECT_NEAR((hit.normal - Eigen::Vector3d(0.6, 0.0, -0.8)).norm(), 0.0, 1e-9);
}

TEST(CylinderSample, SideHitHasRadialNormal) {
  const CylinderSample cylinder(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 0, 1), 0.5, 2.0);
  SurfaceHit hit;
  ASSERT_TRUE(cylinder.Intersect(Eigen::Vector3d(-5, 0, 0.3), Eigen::Vector3d(1, 0, 0), &hit));
  EXPECT_NEAR(hit.t, 4.5, 1e-12);
  EXPECT_NEAR((hit.normal - Eigen::Vector3d(-1, 0, 0)).norm(), 0.0, 1e-12);
}

TEST(CylinderSample, CapsAndAxisParallelRaysAreNotMeasured) {
  const CylinderSample cylinder(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 0, 1), 0.5, 2.0);
  SurfaceHit hit;
  // Straight down the axis onto the cap.
  EXPECT_FALSE(cylinder.Intersect(Eigen::Vector3d(0, 0, 5), Eigen::Vector3d(0, 0, -1), &hit));
  // Passing above the side.
  EXPECT_FALSE(cylinder.Intersect(Eigen::Vector3d(-5, 0, 1.5), Eigen::Vector3d(1, 0, 0), &hit));
  // Steeply onto the top cap from above: the side's first root lies above the top.
  EXPECT_FALSE(cylinder.Intersect(Eigen::Vector3d(-1, 0, 3), Eigen::Vector3d(1, 0, -2).normalized(), &hit));
}

TEST(CylinderSample, ContainsOnlyTheSolid) {
  const CylinderSample cylinder(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 0, 1), 0.5, 2.0);
  EXPECT_TRUE(cylinder.Contains(Eigen::Vector3d(0.2, 0.2, 0.9)));
  EXPECT_FALSE(cylinder.Contains(Eigen::Vector3d(0.2, 0.2, 1.1)));
  EXPECT_FALSE(cylinder.Contains(Eigen::Vector3d(0.6, 0.0, 0.0)));
}

TEST(AnalyticSample, MeshSampleIsAnError) {
  SampleSpec spec;
  spec.kind = SampleSpec::Kind::kMesh;
  EXPECT_THROW(AnalyticSample::Create(spec), Error);
}

}  // namespace
}  // namespace ibrdf
