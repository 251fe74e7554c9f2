// Tests of core/rigid3.h: rigid transforms and the look-at camera pose.
#include "core/rigid3.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "core/error.h"

namespace ibrdf {
namespace {

Rigid3d RandomRigid(std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  q.normalize();
  return Rigid3d(q, Eigen::Vector3d(normal(rng), normal(rng), normal(rng)));
}

Eigen::Vector3d RandomPoint(std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 3.0);
  return {normal(rng), normal(rng), normal(rng)};
}

// The default transform is the identity.
TEST(Rigid3d, DefaultIsIdentity) {
  const Rigid3d identity;
  const Eigen::Vector3d p(1.5, -2.0, 0.25);
  EXPECT_EQ(identity * p, p);
  EXPECT_TRUE(identity.ToMatrix().isApprox(
      (Eigen::Matrix<double, 3, 4>() << Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()).finished()));
}

// x -> R x + t, and ToMatrix() is [R | t].
TEST(Rigid3d, ApplyAndMatrixAgree) {
  std::mt19937 rng(1);
  for (int i = 0; i < 100; ++i) {
    const Rigid3d b_from_a = RandomRigid(rng);
    const Eigen::Vector3d p = RandomPoint(rng);
    const Eigen::Vector3d expected = b_from_a.rotation.toRotationMatrix() * p + b_from_a.translation;
    EXPECT_LT((b_from_a * p - expected).norm(), 1e-12);
    EXPECT_LT((b_from_a.ToMatrix() * p.homogeneous() - expected).norm(), 1e-12);
  }
}

// b_from_a.Inverse() maps points back: a_from_b * (b_from_a * p) == p, both ways round.
TEST(Rigid3d, InverseUndoesTransform) {
  std::mt19937 rng(2);
  for (int i = 0; i < 100; ++i) {
    const Rigid3d b_from_a = RandomRigid(rng);
    const Rigid3d a_from_b = b_from_a.Inverse();
    const Eigen::Vector3d p = RandomPoint(rng);
    EXPECT_LT((a_from_b * (b_from_a * p) - p).norm(), 1e-12);
    EXPECT_LT((b_from_a * (a_from_b * p) - p).norm(), 1e-12);
    const Rigid3d identity = b_from_a * a_from_b;
    EXPECT_LT(identity.translation.norm(), 1e-12);
    EXPECT_LT(identity.rotation.angularDistance(Eigen::Quaterniond::Identity()), 1e-12);
  }
}

// Composition: (c_from_b * b_from_a) * p == c_from_b * (b_from_a * p), and it is not commutative.
TEST(Rigid3d, CompositionAppliesRightFirst) {
  std::mt19937 rng(3);
  for (int i = 0; i < 100; ++i) {
    const Rigid3d b_from_a = RandomRigid(rng);
    const Rigid3d c_from_b = RandomRigid(rng);
    const Eigen::Vector3d p = RandomPoint(rng);
    const Rigid3d c_from_a = c_from_b * b_from_a;
    EXPECT_LT((c_from_a * p - c_from_b * (b_from_a * p)).norm(), 1e-12);
    // (c_from_b * b_from_a)^-1 == b_from_a^-1 * c_from_b^-1
    const Rigid3d a_from_c = b_from_a.Inverse() * c_from_b.Inverse();
    EXPECT_LT((a_from_c * (c_from_a * p) - p).norm(), 1e-12);
  }
  // A rotation then a translation differs from the translation then the rotation.
  const Rigid3d rotate(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ())),
                       Eigen::Vector3d::Zero());
  const Rigid3d shift(Eigen::Quaterniond::Identity(), Eigen::Vector3d(1, 0, 0));
  const Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  EXPECT_LT(((rotate * shift) * origin - Eigen::Vector3d(0, 1, 0)).norm(), 1e-15);
  EXPECT_LT(((shift * rotate) * origin - Eigen::Vector3d(1, 0, 0)).norm(), 1e-15);
}

// The look-at pose puts the camera centre at the origin of the camera frame and the target on the
// +z axis at its distance; its rotation is proper (det +1, no mirror).
TEST(LookAtCameraFromWorld, TargetOnOpticalAxis) {
  const Eigen::Vector3d center(0.3, -1.2, 2.0), target(0.1, 0.4, -0.5), up(0, 0, 1);
  const Rigid3d camera_from_world = LookAtCameraFromWorld(center, target, up);
  EXPECT_LT((camera_from_world * center).norm(), 1e-12);
  const Eigen::Vector3d target_in_camera = camera_from_world * target;
  EXPECT_NEAR(target_in_camera.x(), 0.0, 1e-12);
  EXPECT_NEAR(target_in_camera.y(), 0.0, 1e-12);
  EXPECT_NEAR(target_in_camera.z(), (target - center).norm(), 1e-12);
  EXPECT_NEAR(camera_from_world.rotation.norm(), 1.0, 1e-12);
  EXPECT_NEAR(camera_from_world.rotation.toRotationMatrix().determinant(), 1.0, 1e-12);
}

// `up` appears upwards in the image: image y points down, so a point above the target has negative
// camera y and zero x. World right (forward x up) has positive camera x.
TEST(LookAtCameraFromWorld, UpMapsToNegativeImageY) {
  const Eigen::Vector3d center(0, 0, 5), target(0, 0, 0), up(0, 1, 0);
  const Rigid3d camera_from_world = LookAtCameraFromWorld(center, target, up);
  const Eigen::Vector3d above = camera_from_world * (target + 0.1 * up);
  EXPECT_LT(above.y(), -0.05);
  EXPECT_NEAR(above.x(), 0.0, 1e-12);
  // Looking down -z with +y up, +x is to the right (a right-handed camera, x right, y down, z forward).
  const Eigen::Vector3d right = camera_from_world * Eigen::Vector3d(0.1, 0, 0);
  EXPECT_GT(right.x(), 0.05);
  EXPECT_NEAR(right.y(), 0.0, 1e-12);
}

// `up` need not be perpendicular to the viewing direction: only its component across the view counts.
TEST(LookAtCameraFromWorld, ObliqueUpStillPointsUp) {
  std::mt19937 rng(4);
  for (int i = 0; i < 50; ++i) {
    const Eigen::Vector3d center = RandomPoint(rng), target = RandomPoint(rng);
    const Eigen::Vector3d view = (target - center).normalized();
    Eigen::Vector3d up = RandomPoint(rng).normalized();
    if (view.cross(up).norm() < 0.1) continue;
    const Rigid3d camera_from_world = LookAtCameraFromWorld(center, target, up);
    const Eigen::Vector3d up_in_camera = camera_from_world.rotation * up;
    EXPECT_LT(up_in_camera.y(), 0.0);
    EXPECT_NEAR(up_in_camera.x(), 0.0, 1e-12);
    const Eigen::Vector3d target_in_camera = camera_from_world * target;
    EXPECT_NEAR(target_in_camera.head<2>().norm(), 0.0, 1e-12);
    EXPECT_GT(target_in_camera.z(), 0.0);
  }
}

// Looking along `up` leaves the roll undefined: an internal check, not a silent NaN pose.
TEST(LookAtCameraFromWorld, UpParallelToViewIsAnInternalError) {
  EXPECT_THROW(LookAtCameraFromWorld(Eigen::Vector3d(0, 0, 5), Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 1)),
               InternalError);
}

}  // namespace
}  // namespace ibrdf
